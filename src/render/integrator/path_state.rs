//! The state of one camera path between its vertices (Cycles' integrator path state):
//! the ray to trace next, what the path has gathered, its bounce counts, and what MIS,
//! Filter Glossy, transparent film and subsurface exits need from earlier vertices.
//! `next` is Cycles' `path_state_next`: the bookkeeping after a BSDF sample.

use crate::shader::point::{ray, PathState};

use crate::render::accel::Hit;
use crate::render::bsdf::{BsdfSample, LobeKind};
use crate::render::integrator::Settings;
use crate::render::light::tree::Viewer;
use crate::render::math::*;

/// Sampler dimensions a vertex uses, from its `set`: the BSDF sample at `set`, the light
/// sample at `set + 1`; `set + 2` is left free (Cycles reserves one for the BSSRDF, whose
/// walk draws from `subsurface::bssrdf_dimensions(set)` instead). The camera ray's own
/// dimensions come before the first set.
pub const FIRST_SET: u32 = 1;
pub const SETS_PER_VERTEX: u32 = 3;

/// The bounce counter a sampled lobe advances (Cycles labels each closure's sample).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Counter {
    Diffuse,
    Glossy,
    Transmission,
}

/// Diffuse-like lobes (sheen and velvet are REFLECT | DIFFUSE in Cycles) count as diffuse
/// bounces; a glass lobe counts by the side it sampled; transparency and subsurface entry
/// are no bounce of their own.
fn counter(kind: &LobeKind, transmit: bool) -> Option<Counter> {
    match kind {
        LobeKind::Diffuse
        | LobeKind::Translucent
        | LobeKind::OrenNayar(_)
        | LobeKind::Sheen(_)
        | LobeKind::Velvet(_) => Some(Counter::Diffuse),
        // Cycles labels every Huang hair sample a glossy reflection, through the fibre or not.
        LobeKind::Glossy { .. }
        | LobeKind::Reflection(_)
        | LobeKind::GlossyAniso { .. }
        | LobeKind::Huang(_) => Some(Counter::Glossy),
        LobeKind::Toon(t) if t.glossy => Some(Counter::Glossy),
        LobeKind::Toon(_) => Some(Counter::Diffuse),
        LobeKind::Glass(_) | LobeKind::Hair(_) | LobeKind::Chiang(_) if transmit => {
            Some(Counter::Transmission)
        }
        LobeKind::Glass(_) | LobeKind::Hair(_) | LobeKind::Chiang(_) => Some(Counter::Glossy),
        LobeKind::Transparent | LobeKind::Subsurface(_) | LobeKind::RayPortal(_) => None,
    }
}

/// What happens after a BSDF sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    Continue,
    Stop,
}

#[derive(Debug, Clone)]
pub struct Path {
    /// Radiance gathered so far.
    pub l: V3,
    pub throughput: V3,
    /// The ray to trace next.
    pub o: V3,
    pub d: V3,
    pub t0: f32,
    pub t1: f32,
    /// Ray flags and bounce counts, as the Light Path node reads them.
    pub state: PathState,
    /// A bounce limit was reached: the next surface ends the path unless it is
    /// transparent (Cycles' TERMINATE_AFTER_TRANSPARENT).
    pub terminate_next: bool,
    /// The sampler dimension set of the next vertex.
    pub set: u32,
    /// MIS state of the ray being traced: the BSDF pdf that chose it, or singular.
    pub prev_pdf: f32,
    pub prev_singular: bool,
    /// Smallest pdf of the non-singular bounces so far (Cycles' min_ray_pdf), for Filter
    /// Glossy.
    pub min_ray_pdf: f32,
    /// Where the ray being traced was sampled, as light selection saw it (Cycles'
    /// mis_origin_n and PATH_RAY_MIS_HAD_TRANSMISSION): the probability of picking what
    /// the ray finds, for its MIS weight, is computed there.
    pub mis_n: V3,
    pub mis_trans: bool,
    /// Where the ray being traced started as Cycles sees it, and `o`'s distance from
    /// there: past a transparent surface or a volume boundary Cycles keeps the ray's
    /// origin and only raises its start distance (integrate_surface_volume_only_bounce,
    /// the transparent case of integrate_surface_bsdf_bssrdf_bounce), so what the ray
    /// then finds is light-selected from that origin and its pdf taken at the whole
    /// distance. blendsynth moves `o` past such surfaces; these keep Cycles' view.
    pub mis_o: V3,
    pub mis_t: f32,
    /// After a volume scatter, the segment it scattered in (origin, direction, length):
    /// its light was picked for the whole segment (Cycles' in_volume_segment light
    /// selection), and what the next ray hits is weighted by that selection's pdf.
    pub mis_segment: Option<(V3, V3, f32)>,
    /// Where a subsurface random walk left the object: the next vertex, shaded white
    /// diffuse (Cycles' subsurface_shader_data_setup).
    pub sss_exit: Option<Hit>,
    /// The path has taken a diffuse bounce (a BSSRDF then falls back to diffuse).
    pub diffuse_ancestor: bool,
    /// Cycles' PATH_RAY_TRANSPARENT_BACKGROUND: camera rays, kept through transparent
    /// surfaces and (with Transparent Glass) through smooth enough refraction.
    pub transparent_bg: bool,
    /// Ray differentials, carried through bounces as Cycles does: the next ray's dP is
    /// the hit's; dD stays, except that a subsurface bounce zeroes it.
    pub ray_dp: f32,
    pub ray_dd: f32,
}

impl Path {
    /// A camera ray with its differentials.
    pub fn camera(o: V3, d: V3, t0: f32, t1: f32, ray_dp: f32, ray_dd: f32) -> Path {
        Path {
            l: [0.0; 3],
            throughput: [1.0; 3],
            o,
            d,
            t0,
            t1,
            state: PathState {
                flags: ray::CAMERA,
                ..PathState::default()
            },
            terminate_next: false,
            set: FIRST_SET,
            prev_pdf: f32::INFINITY,
            prev_singular: true,
            min_ray_pdf: f32::INFINITY,
            mis_n: [0.0; 3],
            mis_trans: false,
            mis_o: o,
            mis_t: 0.0,
            mis_segment: None,
            sss_exit: None,
            diffuse_ancestor: false,
            transparent_bg: true,
            ray_dp,
            ray_dd,
        }
    }

    /// What light selection saw where the ray being traced was sampled, for the MIS
    /// weight of what it hits.
    #[inline]
    pub fn mis_viewer(&self) -> Viewer {
        match self.mis_segment {
            Some((p, d, t)) => Viewer::Segment { p, d, t },
            None => Viewer::Point {
                p: self.mis_o,
                n: self.mis_n,
                trans: self.mis_trans,
            },
        }
    }

    /// The clamp on emission a ray finds: as the bounce before it (Cycles: light found
    /// after one bounce is direct light, like the light sample at that vertex).
    pub fn hit_clamp(&self, st: &Settings) -> f32 {
        if self.state.bounce <= 1 {
            st.clamp_direct
        } else {
            st.clamp_indirect
        }
    }

    /// The clamp on the light sampled at this vertex.
    pub fn light_clamp(&self, st: &Settings) -> f32 {
        if self.state.bounce == 0 {
            st.clamp_direct
        } else {
            st.clamp_indirect
        }
    }

    /// Russian roulette as Cycles (path_state_continuation_probability): sqrt of the
    /// throughput, but never within the minimum bounces, which Cycles' kernel takes as
    /// the setting plus one (so the first indirect hit always continues), counted in
    /// transparent bounces when the ray just passed a transparent surface. None ends the
    /// path; otherwise the probability it went on with (1 where no roulette applies), by
    /// which a survivor's throughput is divided.
    pub fn continuation(&self, st: &Settings, u: f32) -> Option<f32> {
        let s = &self.state;
        let roulette = if s.flags & ray::TRANSPARENT != 0 {
            s.transparent > st.min_transparent_bounces + 1
        } else {
            s.bounce > st.min_light_bounces + 1
        };
        if !roulette {
            return Some(1.0);
        }
        let q = max3(self.throughput.map(f32::abs)).sqrt().min(1.0);
        (q > 0.0 && u < q).then_some(q)
    }

    /// `continuation`, the survivor's throughput divided by its probability.
    pub fn survives_roulette(&mut self, st: &Settings, u: f32) -> bool {
        match self.continuation(st, u) {
            Some(q) => {
                if q != 1.0 {
                    self.throughput = scale(self.throughput, 1.0 / q);
                }
                true
            }
            None => false,
        }
    }

    /// Cycles' path_state_next after the BSDF sample `bs` (its weight already in the
    /// throughput) at a vertex at `p` with geometric normal `ng`: bounce counts and limits,
    /// ray flags, MIS state, and the next ray. `n_sel` and `trans_sel` are what light
    /// selection saw at the vertex.
    pub fn next(
        &mut self,
        bs: &BsdfSample,
        p: V3,
        ng: V3,
        n_sel: V3,
        trans_sel: bool,
        st: &Settings,
    ) -> Next {
        if let LobeKind::Transparent = bs.kind {
            // Transparent bounces keep the bounce count and continue from the hit.
            self.state.transparent += 1;
            self.state.flags |= ray::TRANSPARENT;
            if self.state.transparent > st.max_transparent {
                return Next::Stop;
            }
            self.o = offset_origin(p, ng, self.d);
            self.t0 = 0.0;
            self.t1 = f32::INFINITY;
            self.passed_through(p);
            return Next::Continue;
        }
        if let LobeKind::RayPortal(portal) = bs.kind {
            // Cycles' integrate_surface_ray_portal and path_state_next: a transparent
            // bounce (flags kept, the transparent count and limit) whose next hit skips
            // MIS (PATH_RAY_MIS_SKIP), as nothing was light-sampled for it.
            self.state.transparent += 1;
            self.state.flags |= ray::TRANSPARENT;
            if self.state.transparent > st.max_transparent {
                return Next::Stop;
            }
            self.prev_singular = true;
            self.o = if portal.moved {
                portal.position
            } else {
                offset_origin(p, ng, portal.direction)
            };
            self.d = portal.direction;
            self.t0 = 0.0;
            self.t1 = f32::INFINITY;
            self.new_origin();
            return Next::Continue;
        }
        if let Some(c) = counter(&bs.kind, bs.transmit) {
            let s = &mut self.state;
            let (count, max) = match c {
                Counter::Diffuse => (&mut s.diffuse, st.max_diffuse),
                Counter::Glossy => (&mut s.glossy, st.max_glossy),
                Counter::Transmission => (&mut s.transmission, st.max_transmission),
            };
            if *count >= max {
                self.terminate_next = true;
            }
            *count += 1;
            if c == Counter::Diffuse {
                self.diffuse_ancestor = true;
            }
        }
        // Cycles (bsdf_sample, path_state_next): only a refraction whose roughness
        // squared (alpha_x * alpha_y) is within the threshold keeps the path
        // transparent to the background; every other bounce ends that.
        self.transparent_bg = self.transparent_bg
            && match bs.kind {
                LobeKind::Glass(g) if bs.transmit => {
                    st.transparent_glass >= 0.0 && g.alpha * g.alpha <= st.transparent_glass
                }
                _ => false,
            };
        if self.state.bounce >= st.max_bounces {
            self.terminate_next = true;
        }
        self.state.bounce += 1;
        self.state.flags = bounce_flags(bs.kind, bs.transmit, bs.singular);
        self.mis_n = n_sel;
        self.mis_trans = trans_sel;
        self.mis_segment = None;
        self.prev_pdf = bs.pdf;
        self.prev_singular = bs.singular;
        if !bs.singular {
            self.min_ray_pdf = self.min_ray_pdf.min(bs.pdf);
        }
        self.o = offset_origin(p, ng, bs.wi);
        self.d = bs.wi;
        self.t0 = 0.0;
        self.t1 = f32::INFINITY;
        self.new_origin();
        Next::Continue
    }

    /// The ray starts afresh at `o` (a bounce): Cycles' ray origin is there too.
    pub fn new_origin(&mut self) {
        self.mis_o = self.o;
        self.mis_t = 0.0;
    }

    /// The ray went on past a surface at `p` without a bounce (transparency, a volume
    /// boundary): Cycles' ray keeps its origin, so `o`'s distance from it grows.
    pub fn passed_through(&mut self, p: V3) {
        self.mis_t = len(sub(p, self.mis_o));
    }

    /// After a subsurface walk left the object at `exit` in direction `dir` (toward the
    /// surface): that exit is the next vertex.
    pub fn leave_subsurface(&mut self, exit: Hit, dir: V3) {
        self.sss_exit = Some(exit);
        // The exit is no longer a camera ray (Cycles' subsurface_bounce clears
        // PATH_RAY_CAMERA): its Light Path node sees it so.
        self.state.flags &= !ray::CAMERA;
        // Cycles' probe and walk rays carry no direction differential, and the exit's
        // bounce keeps that: from here on the footprint no longer widens with distance.
        self.ray_dd = 0.0;
        self.d = neg(dir);
    }
}

/// Cycles' path flags after a non-transparent bounce of lobe `kind`.
pub fn bounce_flags(kind: LobeKind, transmit: bool, singular: bool) -> u32 {
    let mut f = match kind {
        LobeKind::Diffuse => ray::DIFFUSE | ray::REFLECT,
        LobeKind::Translucent => ray::DIFFUSE | ray::TRANSMIT,
        LobeKind::Glossy { .. } => ray::GLOSSY | ray::REFLECT,
        LobeKind::Glass { .. } | LobeKind::Hair(_) | LobeKind::Chiang(_) => {
            ray::GLOSSY
                | if transmit {
                    ray::TRANSMIT
                } else {
                    ray::REFLECT
                }
        }
        LobeKind::Transparent | LobeKind::RayPortal(_) => ray::TRANSPARENT,
        // The walk's exit scatters diffusely, as Cycles' subsurface exit closure does.
        LobeKind::OrenNayar(_) | LobeKind::Subsurface(_) => ray::DIFFUSE | ray::REFLECT,
        LobeKind::Reflection(_) => ray::GLOSSY | ray::REFLECT,
        LobeKind::Sheen(_) | LobeKind::Velvet(_) => ray::DIFFUSE | ray::REFLECT,
        LobeKind::GlossyAniso { .. } | LobeKind::Huang(_) => ray::GLOSSY | ray::REFLECT,
        LobeKind::Toon(t) if t.glossy => ray::GLOSSY | ray::REFLECT,
        LobeKind::Toon(_) => ray::DIFFUSE | ray::REFLECT,
    };
    if singular {
        f |= ray::SINGULAR;
    }
    f
}
