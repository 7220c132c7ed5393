//! Scattering closures with light transport, as Cycles defines them: Lambert diffuse,
//! translucent, GGX microfacet reflection (with Cycles' multiple-scattering energy
//! compensation), Fresnel models (constant colour, dielectric, F82-tinted Schlick, thin
//! film), transparent. `eval` returns BSDF times the cosine, as Cycles' closures do.

pub mod anisotropic;
pub mod bump_correction;
pub mod hair;
pub mod hair_chiang;
pub mod hair_huang;
pub mod metallic;
pub mod microfacet;
pub mod oren_nayar;
pub mod ray_portal;
pub mod sheen;
pub mod sheen_ltc;
pub mod tables;
pub mod terminator;
pub mod thin_film;
pub mod toon;

use crate::render::bsdf::microfacet::{Dielectric, Reflection};
use crate::render::bsdf::oren_nayar::OrenNayar;
use crate::render::bsdf::tables::Tables;
use crate::render::math::*;
use crate::render::subsurface::Bssrdf;
use std::f32::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fresnel {
    /// Glossy BSDF: the colour is the reflectance at every angle.
    Constant,
    /// Dielectric with relative IOR `eta`, tinted.
    Dielectric { eta: f32 },
    /// Cycles' generalized Schlick with a negative exponent (the Principled specular
    /// layer): the dielectric Fresnel of `eta` remapped from its own F0..1 to `f0`..1, so a
    /// Specular Tint colours normal incidence and grazing reflection stays white.
    Schlick { f0: V3, eta: f32 },
    /// Metals: F0 colour, F82 tint factor `b` (precomputed).
    F82 { f0: V3, b: V3 },
    /// Dielectric under a thin film (Principled specular layer): coloured by interference.
    ThinFilm(crate::render::bsdf::thin_film::ThinFilm),
    /// Physical conductor with complex IOR `eta` + i `k` per channel (Metallic BSDF).
    Conductor { eta: V3, k: V3 },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LobeKind {
    Diffuse,
    Translucent,
    Glossy {
        alpha: f32,
        fresnel: Fresnel,
        energy: f32,
    },
    Transparent,
    /// Dielectric interface (Glass and Refraction BSDFs, Principled transmission), rough
    /// or sharp: reflects or refracts by Fresnel (see `microfacet`).
    Glass(Dielectric),
    /// BSSRDF (random walk subsurface scattering): picked like a BSDF, never evaluated;
    /// the integrator walks the medium (see `subsurface`).
    Subsurface(Bssrdf),
    /// Oren-Nayar diffuse (Diffuse BSDF with roughness > 0).
    OrenNayar(OrenNayar),
    /// Glossy reflection with the Beckmann distribution.
    Reflection(Reflection),
    /// Microfiber sheen (Sheen BSDF, Principled sheen); scatters like diffuse.
    Sheen(crate::render::bsdf::sheen::Sheen),
    /// Ashikhmin velvet (Sheen BSDF, Ashikhmin distribution); scatters like diffuse.
    Velvet(crate::render::bsdf::sheen::Velvet),
    /// Toon BSDF, Diffuse or Glossy component.
    Toon(crate::render::bsdf::toon::Toon),
    /// Anisotropic GGX reflection (Glossy BSDF anisotropy, Principled anisotropic).
    GlossyAniso {
        lobe: crate::render::bsdf::anisotropic::AnisoGgx,
        fresnel: Fresnel,
        energy: f32,
    },
    /// Hair BSDF, Reflection or Transmission component (hair curves).
    Hair(crate::render::bsdf::hair::Hair),
    /// Principled Hair BSDF, Chiang model (hair curves); its normal is the fibre frame's Y.
    Chiang(crate::render::bsdf::hair_chiang::Chiang),
    /// Ray Portal BSDF: the path goes on from another position and direction.
    RayPortal(crate::render::bsdf::ray_portal::RayPortal),
    /// Principled Hair BSDF, Huang model (hair curves); its normal is the frame's x axis.
    Huang(crate::render::bsdf::hair_huang::Huang),
}

#[derive(Debug, Clone, Copy)]
pub struct Lobe {
    pub kind: LobeKind,
    pub weight: V3,
    pub n: V3,
    /// Selection weight (Cycles' `sample_weight`: the sum of |weight|).
    pub sample_weight: f32,
}

pub const MAX_LOBES: usize = 8;

/// The closures of one shading point, fixed size (no allocation per hit).
#[derive(Clone)]
pub struct LobeSet {
    pub lobes: [Lobe; MAX_LOBES],
    pub len: usize,
    pub emission: V3,
    pub holdout: V3,
    pub transparent: V3,
    /// The Ray Portal closures' weights, which Cycles adds to the surface's transparency
    /// (`closure_transparent_extinction`).
    pub portal_extinction: V3,
    /// The smooth shading normal (Cycles' sd->N, after the displacement's bump): lobes
    /// bumped away from it get Cycles' bump shadowing term. Zero when unset.
    pub smooth_n: V3,
    /// The material's bump map correction, which also softens diffuse bump shadows.
    pub bump_correction: bool,
    /// The object's shadow terminator shading offset as a frequency (1: none), set by the
    /// integrator after shading.
    pub terminator_frequency: f32,
    /// Sampling checks each lobe's direction against the lobe's own normal instead of the
    /// true normal: Cycles does so on curves, whose ribbons' true normal faces the ray
    /// ("the geometric normal gives too much darkening otherwise", bsdf_sample).
    pub own_normal_as_ng: bool,
    /// A closure other than a diffuse or translucent one was given a normal that is not a
    /// number (an Object-space Normal Map of colour 0.5 normalises a zero vector). Cycles
    /// keeps it, and its evaluation and pdf are NaN, which takes every closure of the point
    /// with it: the surface reflects nothing and a path that reaches it ends there. (Diffuse
    /// and translucent closures test their cosine as `> 0`, so with a NaN normal they only
    /// give nothing themselves: see `nan_normal`.)
    pub poisoned: bool,
}

pub struct BsdfSample {
    pub wi: V3,
    /// eval / pdf (already weighted by the closure's weight).
    pub weight: V3,
    pub pdf: f32,
    pub singular: bool,
    pub glossy: bool,
    pub transmit: bool,
    /// Closure kind label for bounce limits.
    pub kind: LobeKind,
}

const EMPTY: Lobe = Lobe {
    kind: LobeKind::Diffuse,
    weight: [0.0; 3],
    n: [0.0, 0.0, 1.0],
    sample_weight: 0.0,
};

impl Default for LobeSet {
    fn default() -> Self {
        LobeSet {
            lobes: [EMPTY; MAX_LOBES],
            len: 0,
            emission: [0.0; 3],
            holdout: [0.0; 3],
            transparent: [0.0; 3],
            portal_extinction: [0.0; 3],
            smooth_n: [0.0; 3],
            bump_correction: true,
            terminator_frequency: 1.0,
            own_normal_as_ng: false,
            poisoned: false,
        }
    }
}

/// Whether a light hidden from these ray types (`ray::` flags) skips this closure in
/// next-event estimation: Cycles' diffuse range (diffuse, Oren-Nayar, sheen,
/// translucent), glossy range (microfacet reflection) and transmission range
/// (translucent, refraction and glass).
fn excluded(kind: &LobeKind, exclude: u32) -> bool {
    use crate::shader::point::ray;
    match kind {
        LobeKind::Diffuse | LobeKind::OrenNayar(_) | LobeKind::Sheen(_) | LobeKind::Velvet(_) => {
            exclude & ray::DIFFUSE != 0
        }
        LobeKind::Translucent => exclude & (ray::DIFFUSE | ray::TRANSMIT) != 0,
        LobeKind::Glossy { .. } | LobeKind::Reflection(_) | LobeKind::GlossyAniso { .. } => {
            exclude & ray::GLOSSY != 0
        }
        LobeKind::Glass(_) => exclude & ray::TRANSMIT != 0,
        LobeKind::Toon(t) if t.glossy => exclude & ray::GLOSSY != 0,
        LobeKind::Toon(_) => exclude & ray::DIFFUSE != 0,
        // Cycles' closure ranges: hair transmission is a transmission closure, hair
        // reflection and the Chiang hair glossy ones.
        LobeKind::Hair(h) if h.transmission => exclude & ray::TRANSMIT != 0,
        LobeKind::Hair(_) | LobeKind::Chiang(_) | LobeKind::Huang(_) => exclude & ray::GLOSSY != 0,
        LobeKind::Transparent | LobeKind::Subsurface(_) | LobeKind::RayPortal(_) => false,
    }
}

/// A closure normal that is not a number (see `LobeSet::poisoned`).
#[inline]
fn nan_normal(n: V3) -> bool {
    !(n[0].is_finite() && n[1].is_finite() && n[2].is_finite())
}

/// Singular (mirror) below this alpha, as Cycles treats very low roughness.
const SINGULAR_ALPHA: f32 = 1e-4;

impl LobeSet {
    /// Cycles' SD_BSDF_HAS_TRANSMISSION: some closure transmits (translucent, refraction,
    /// glass). Light selection then counts lights behind the surface too.
    pub fn has_transmission(&self) -> bool {
        self.lobes[..self.len].iter().any(|l| match l.kind {
            LobeKind::Translucent
            | LobeKind::Glass(_)
            | LobeKind::Chiang(_)
            | LobeKind::Huang(_) => true,
            LobeKind::Hair(h) => h.transmission,
            _ => false,
        })
    }

    /// What a shadow ray passes here (Cycles' surface_shader_transparency under a shadow
    /// ray, which allocates no closures): the transparent weights, and the portals' with
    /// them; a portal alone lets nothing through, as SD_TRANSPARENT is then unset.
    pub fn shadow_transparency(&self) -> V3 {
        let transparent = Vec3::from(self.transparent);
        if transparent.is_zero() {
            self.transparent
        } else {
            (transparent + self.portal_extinction.into()).into()
        }
    }

    pub fn clear(&mut self) {
        self.len = 0;
        self.emission = [0.0; 3];
        self.holdout = [0.0; 3];
        self.transparent = [0.0; 3];
        self.portal_extinction = [0.0; 3];
        self.smooth_n = [0.0; 3];
        self.bump_correction = true;
        self.terminator_frequency = 1.0;
        self.own_normal_as_ng = false;
        self.poisoned = false;
    }

    pub fn push(&mut self, kind: LobeKind, weight: V3, n: V3) {
        self.push_scaled(kind, weight, n, 1.0);
    }

    /// `push` with the selection weight scaled by the lobe's estimated albedo, as Cycles
    /// does for Fresnel-weighted microfacet closures (a dim specular layer is picked less).
    pub fn push_scaled(&mut self, kind: LobeKind, weight: V3, n: V3, albedo: f32) {
        if !(weight.iter().all(|w| w.is_finite())) {
            return;
        }
        // Cycles' bsdf_alloc allows no negative weight (a colour input below zero, from a
        // Mapping node say): each channel is clamped at zero. Transparent and subsurface
        // closures are allocated without that clamp.
        let weight = match kind {
            // Ray Portal too (closure_alloc, not bsdf_alloc).
            LobeKind::Transparent | LobeKind::Subsurface(_) | LobeKind::RayPortal(_) => weight,
            _ => weight.map(|w| w.max(0.0)),
        };
        // Cycles' bsdf_alloc drops closures whose mean weight is below CLOSURE_WEIGHT_CUTOFF
        // (which matters beyond their light: they would take a share of the selection).
        let mean = (weight[0] + weight[1] + weight[2]).abs() / 3.0;
        if !(mean >= 1e-5) {
            return;
        }
        let sw = (weight[0].abs() + weight[1].abs() + weight[2].abs()) * albedo.clamp(0.0, 1.0);
        if sw <= 0.0 {
            return;
        }
        if nan_normal(n) && !matches!(kind, LobeKind::Diffuse | LobeKind::Translucent) {
            self.poisoned = true;
        }
        if let LobeKind::Transparent = kind {
            self.transparent = (Vec3::from(self.transparent) + weight.into()).into();
        }
        if let LobeKind::RayPortal(_) = kind {
            self.portal_extinction = (Vec3::from(self.portal_extinction) + weight.into()).into();
        }
        if self.len < MAX_LOBES {
            self.lobes[self.len] = Lobe {
                kind,
                weight,
                n,
                sample_weight: sw,
            };
            self.len += 1;
        }
    }

    /// Sum of the closures' BSDF times cosine toward `wi`, and the combined pdf, for a
    /// viewer in direction `wo`; `ng` is the geometric normal facing the viewer.
    pub fn eval(&self, wo: V3, wi: V3, ng: V3, tables: &Tables) -> (V3, f32) {
        self.eval_excluding(wo, wi, ng, tables, 0)
    }

    /// `eval` toward a light that some ray types do not see (`exclude`, `ray::` flags):
    /// the closures of those types give nothing but keep their share of the pdf, as in
    /// Cycles' _surface_shader_exclude.
    pub fn eval_excluding(
        &self,
        wo: V3,
        wi: V3,
        ng: V3,
        tables: &Tables,
        exclude: u32,
    ) -> (V3, f32) {
        let (wo, wi, ng) = (Vec3::from(wo), Vec3::from(wi), Vec3::from(ng));
        let (f, pdf, total) = self.eval_sum(wo, wi, ng, tables, exclude, None);
        (f.into(), if total > 0.0 { pdf / total } else { pdf })
    }

    /// The closures' value toward `wi`, their pdfs times selection weights, and the total
    /// selection weight; lobe `skip` is left out of the first two (Cycles'
    /// _surface_shader_bsdf_eval_mis, for the lobe that sampled `wi` itself).
    fn eval_sum(
        &self,
        wo: Vec3,
        wi: Vec3,
        ng: Vec3,
        tables: &Tables,
        exclude: u32,
        skip: Option<usize>,
    ) -> (Vec3, f32, f32) {
        let mut f = Vec3::ZERO;
        let mut pdf = 0.0;
        let mut total = 0.0;
        if self.poisoned {
            let total = self.lobes[..self.len].iter().map(|l| l.sample_weight).sum();
            return (f, pdf, total);
        }
        for (i, l) in self.lobes[..self.len].iter().enumerate() {
            total += l.sample_weight;
            if skip == Some(i) || (exclude != 0 && excluded(&l.kind, exclude)) || nan_normal(l.n) {
                continue;
            }
            let bump = self.bump_term(l, wi);
            if bump == 0.0 {
                continue;
            }
            let (e, p) = eval_lobe(l, wo, wi, ng, tables);
            let e = self.terminator(e * bump, l, wi);
            f += e * Vec3::from(l.weight);
            pdf += p * l.sample_weight;
        }
        (f, pdf, total)
    }

    /// The value and pdf toward `wi`, which lobe `pick` sampled: the other closures as in
    /// `eval`, the sampling one as Cycles' bsdf_sample returns it, where the bump shadowing
    /// term (with its rejection of directions across the smooth surface) applies to
    /// diffuse closures only and to no transmission.
    fn eval_sampled(
        &self,
        pick: usize,
        wo: Vec3,
        wi: Vec3,
        ng: Vec3,
        transmit: bool,
        tables: &Tables,
    ) -> (Vec3, f32) {
        let (rest, rest_pdf, total) = self.eval_sum(wo, wi, ng, tables, 0, Some(pick));
        let l = &self.lobes[pick];
        let diffuse = matches!(
            l.kind,
            LobeKind::Diffuse | LobeKind::OrenNayar(_) | LobeKind::Translucent
        );
        let bump = if diffuse && !transmit {
            self.bump_term(l, wi)
        } else {
            1.0
        };
        let (e, p) = eval_lobe(l, wo, wi, ng, tables);
        let own = self.terminator(e * bump, l, wi);
        let f = rest + own * Vec3::from(l.weight);
        let pdf = rest_pdf + p * l.sample_weight;
        (f, if total > 0.0 { pdf / total } else { pdf })
    }

    fn bump_term(&self, l: &Lobe, wi: Vec3) -> f32 {
        // Cycles' bsdf_eval shadows bumped diffuse and microfacet closures only; the hair
        // closures' normals are no bumped shading normals (Chiang's is across the fibre).
        if Vec3::from(self.smooth_n).is_zero()
            || matches!(
                l.kind,
                LobeKind::Hair(_) | LobeKind::Chiang(_) | LobeKind::Huang(_)
            )
        {
            return 1.0;
        }
        let diffuse = matches!(
            l.kind,
            LobeKind::Diffuse | LobeKind::OrenNayar(_) | LobeKind::Translucent
        );
        crate::render::bsdf::bump_correction::bump_shadowing_term(
            self.smooth_n.into(),
            l.n.into(),
            wi,
            diffuse,
            self.bump_correction,
        )
    }

    fn terminator(&self, e: Vec3, l: &Lobe, wi: Vec3) -> Vec3 {
        if self.terminator_frequency > 1.0 {
            let c = wi.dot(l.n.into());
            if c >= 0.0 {
                return e * crate::render::bsdf::terminator::shift_cos_in(
                    c,
                    self.terminator_frequency,
                );
            }
        }
        e
    }

    /// A hair lobe's own sample (Cycles' bsdf_sample with the value and pdf the closure's
    /// sample function returns, which for the Hair BSDF's reflection differ from its
    /// evaluation), combined with the other closures' evaluation as Cycles does.
    fn sample_hair(
        &self,
        pick: usize,
        wo: Vec3,
        ng: Vec3,
        u: [f32; 3],
        tables: &Tables,
    ) -> Option<BsdfSample> {
        let l = &self.lobes[pick];
        let (wi, own, own_pdf, transmit) = match l.kind {
            LobeKind::Hair(h) => {
                let s = h.sample(wo, [u[0], u[1]])?;
                (s.wi, Vec3::splat(s.pdf), s.pdf, h.transmission)
            }
            LobeKind::Chiang(c) => {
                let (wi, f, pdf, transmit) = c.sample(l.n.into(), wo, u)?;
                (wi, f, pdf, transmit)
            }
            // Cycles labels every Huang sample a glossy reflection.
            LobeKind::Huang(c) => {
                let (wi, f, pdf) = c.sample(u, tables)?;
                (wi, f, pdf, false)
            }
            _ => return None,
        };
        let own = self.terminator(own * self.bump_term(l, wi), l, wi);
        let (rest, rest_pdf, total) = self.eval_sum(wo, wi, ng, tables, 0, Some(pick));
        let f = rest + own * Vec3::from(l.weight);
        let pdf = (rest_pdf + own_pdf * l.sample_weight) / total;
        if !(pdf > 0.0) || !pdf.is_finite() || f.is_zero() {
            return None;
        }
        Some(BsdfSample {
            wi: wi.into(),
            weight: (f * (1.0 / pdf)).into(),
            pdf,
            singular: false,
            glossy: true,
            transmit,
            kind: l.kind,
        })
    }

    pub fn sample(&self, wo: V3, ng: V3, u: [f32; 3], tables: &Tables) -> Option<BsdfSample> {
        let (wo, ng) = (Vec3::from(wo), Vec3::from(ng));
        let total: f32 = self.lobes[..self.len].iter().map(|l| l.sample_weight).sum();
        if total <= 0.0 || self.poisoned {
            return None;
        }
        // Pick a lobe by sample weight; the rest of u[2] (rescaled) is the lobe's own third
        // number, as Cycles reuses it.
        let mut x = u[2] * total;
        let mut pick = self.len - 1;
        for (i, l) in self.lobes[..self.len].iter().enumerate() {
            if x < l.sample_weight {
                pick = i;
                break;
            }
            x -= l.sample_weight;
        }
        let l = &self.lobes[pick];
        // A diffuse or translucent closure with a NaN normal samples no direction (Cycles'
        // `dot(Ng, wo) > 0` fails): the path ends.
        if nan_normal(l.n) {
            return None;
        }
        let (n, weight) = (Vec3::from(l.n), Vec3::from(l.weight));
        let ng = if self.own_normal_as_ng { n } else { ng };
        let sel = l.sample_weight / total;
        if let LobeKind::Subsurface(_) = l.kind {
            return Some(BsdfSample {
                wi: l.n,
                weight: (weight * (1.0 / sel)).into(),
                pdf: 0.0,
                singular: false,
                glossy: false,
                transmit: true,
                kind: l.kind,
            });
        }
        if let LobeKind::Glass(g) = l.kind {
            let u3 = (x / l.sample_weight).clamp(0.0, 1.0 - f32::EPSILON);
            let ds = g.sample(n, wo, ng, [u[0], u[1], u3])?;
            let (glossy, transmit) = (!ds.transmit, ds.transmit);
            if ds.singular {
                let shift = if self.terminator_frequency > 1.0 && !transmit {
                    crate::render::bsdf::terminator::shift_cos_in(
                        ds.l.dot(n),
                        self.terminator_frequency,
                    )
                } else {
                    1.0
                };
                return Some(BsdfSample {
                    wi: ds.l.into(),
                    weight: (ds.weight * weight * (shift / sel)).into(),
                    pdf: f32::INFINITY,
                    singular: true,
                    glossy,
                    transmit,
                    kind: l.kind,
                });
            }
            let (f, pdf) = self.eval_sampled(pick, wo, ds.l, ng, transmit, tables);
            if !(pdf > 0.0) || !pdf.is_finite() {
                return None;
            }
            return Some(BsdfSample {
                wi: ds.l.into(),
                weight: (f * (1.0 / pdf)).into(),
                pdf,
                singular: false,
                glossy,
                transmit,
                kind: l.kind,
            });
        }
        if let LobeKind::Hair(_) | LobeKind::Chiang(_) | LobeKind::Huang(_) = l.kind {
            let u3 = (x / l.sample_weight).clamp(0.0, 1.0 - f32::EPSILON);
            return self.sample_hair(pick, wo, ng, [u[0], u[1], u3], tables);
        }
        let (wi, singular) = sample_lobe(l, wo, ng, [u[0], u[1]])?;
        // The true normal is checked here, when sampling, and not in `eval_lobe` (as
        // Cycles): a reflection must leave above the surface, a translucent
        // transmission below it.
        if !singular && (ng.dot(wi) > 0.0) == matches!(l.kind, LobeKind::Translucent) {
            return None;
        }
        let glossy = matches!(l.kind, LobeKind::Glossy { .. } | LobeKind::Reflection(_));
        let glossy = glossy || matches!(l.kind, LobeKind::GlossyAniso { .. });
        let glossy = glossy || matches!(l.kind, LobeKind::Toon(t) if t.glossy);
        let transmit = matches!(
            l.kind,
            LobeKind::Translucent | LobeKind::Transparent | LobeKind::RayPortal(_)
        );
        if singular {
            // Mirror or pass-through: only this lobe contributes, with its discrete probability.
            let w = match l.kind {
                LobeKind::Glossy {
                    fresnel, energy, ..
                } => {
                    let h = n;
                    fresnel_eval(fresnel, wo.dot(h), weight) * energy
                }
                LobeKind::Reflection(r) => fresnel_eval(r.fresnel, wo.dot(n), weight),
                _ => weight,
            };
            // Cycles' bsdf_sample shifts every sample that does not transmit.
            let w = if self.terminator_frequency > 1.0 && !transmit {
                w * crate::render::bsdf::terminator::shift_cos_in(
                    wi.dot(n),
                    self.terminator_frequency,
                )
            } else {
                w
            };
            return Some(BsdfSample {
                wi: wi.into(),
                weight: (w * (1.0 / sel)).into(),
                pdf: f32::INFINITY,
                singular: true,
                glossy,
                transmit,
                kind: l.kind,
            });
        }
        let (f, pdf) = self.eval_sampled(pick, wo, wi, ng, transmit, tables);
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some(BsdfSample {
            wi: wi.into(),
            weight: (f * (1.0 / pdf)).into(),
            pdf,
            singular: false,
            glossy,
            transmit,
            kind: l.kind,
        })
    }

    /// Diffuse-like albedo of the closures (for the albedo pass).
    pub fn albedo(&self) -> V3 {
        let mut a = Vec3::ZERO;
        for l in &self.lobes[..self.len] {
            a += l.weight.into();
        }
        a.into()
    }
}

/// Fresnel reflectance at normal incidence for relative IOR `ior`.
pub fn f0_from_ior(ior: f32) -> f32 {
    let r = (ior - 1.0) / (ior + 1.0);
    r * r
}

pub fn fresnel_dielectric(cosi: f32, eta: f32) -> f32 {
    let c = cosi.abs();
    let g2 = eta * eta - 1.0 + c * c;
    // Cycles: total reflection unless g is positive (g = 0 would divide 0 by 0).
    if g2 <= 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

fn fresnel_eval(f: Fresnel, cos_h: f32, tint: Vec3) -> Vec3 {
    match f {
        Fresnel::Constant => tint,
        Fresnel::Dielectric { eta } => tint * fresnel_dielectric(cos_h, eta),
        Fresnel::Schlick { f0, eta } => {
            // F0 of eta by formula: at an IOR near 0 the Fresnel at normal incidence is
            // total reflection in f32 and the remap would divide 0 by 0.
            let real_f0 = f0_from_ior(eta);
            let s = (fresnel_dielectric(cos_h, eta) - real_f0) / (1.0 - real_f0);
            Vec3::from([0, 1, 2].map(|k| (f0[k] + (1.0 - f0[k]) * s) * tint[k]))
        }
        Fresnel::F82 { f0, b } => {
            let c = cos_h.clamp(0.0, 1.0);
            let m = 1.0 - c;
            let m5 = m * m * m * m * m;
            let mut out = Vec3::ZERO;
            for k in 0..3 {
                let s = f0[k] + (1.0 - f0[k]) * m5;
                out[k] = (s - b[k] * c * m5 * m).clamp(0.0, 1.0) * tint[k];
            }
            out
        }
        Fresnel::ThinFilm(tf) => tint * Vec3::from(tf.eval(cos_h)),
        Fresnel::Conductor { eta, k } => fresnel_conductor(cos_h, eta.into(), k.into()) * tint,
    }
}

/// Cycles' fresnel_conductor: unpolarised reflectance of a conductor with complex IOR
/// `eta` + i `k` at incidence cosine `cosi`.
pub fn fresnel_conductor(cosi: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let c2 = cosi * cosi;
    let mut out = Vec3::ZERO;
    for i in 0..3 {
        let tmp_f = eta[i] * eta[i] + k[i] * k[i];
        let tmp = tmp_f * c2;
        let two_ec = 2.0 * eta[i] * cosi;
        let parl = (tmp - two_ec + 1.0) / (tmp + two_ec + 1.0);
        let perp = (tmp_f - two_ec + c2) / (tmp_f + two_ec + c2);
        out[i] = (parl + perp) * 0.5;
    }
    out
}

#[inline]
pub fn ggx_d(cos_h: f32, a2: f32) -> f32 {
    let c2 = cos_h * cos_h;
    let d = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

#[inline]
pub fn ggx_lambda(cos: f32, a2: f32) -> f32 {
    let c2 = cos * cos;
    if c2 >= 1.0 {
        return 0.0;
    }
    let t2 = (1.0 - c2) / c2.max(1e-12);
    0.5 * (-1.0 + (1.0 + a2 * t2).sqrt())
}

/// Visible-normal sampling of isotropic GGX (Heitz 2018), local frame with N = +z.
pub fn sample_vndf(v: Vec3, alpha: f32, u: [f32; 2]) -> Vec3 {
    let vh = vec3(alpha * v[0], alpha * v[1], v[2]).normalize();
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let t1 = if lensq > 0.0 {
        vec3(-vh[1], vh[0], 0.0) * (1.0 / lensq.sqrt())
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u[0].sqrt();
    let phi = 2.0 * PI * u[1];
    let p1 = r * phi.cos();
    let mut p2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh[2]);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    vec3(alpha * nh[0], alpha * nh[1], nh[2].max(0.0)).normalize()
}

fn to_local(n: Vec3, v: Vec3) -> Vec3 {
    let (t, b) = n.basis();
    vec3(v.dot(t), v.dot(b), v.dot(n))
}
fn from_local(n: Vec3, v: Vec3) -> Vec3 {
    let (t, b) = n.basis();
    t * v[0] + b * v[1] + n * v[2]
}

/// (BSDF * cos without the closure weight, pdf) of one lobe.
fn eval_lobe(l: &Lobe, wo: Vec3, wi: Vec3, _ng: Vec3, tables: &Tables) -> (Vec3, f32) {
    // Cycles checks directions against the true normal only when sampling, never when
    // evaluating (bsdf_microfacet_sample: "required in order to avoid shadow terminator
    // artifacts on smooth geometry"; the same for every closure): a light below a smooth
    // triangle's plane but above its shading normal's horizon is lit if its shadow ray
    // gets through. So evaluation sees only the closure's own normal.
    let n = Vec3::from(l.n);
    let ng = n;
    let cos_i = n.dot(wi);
    let same_side = ng.dot(wi) > 0.0;
    match l.kind {
        LobeKind::Diffuse => {
            if cos_i > 0.0 && same_side {
                let v = cos_i / PI;
                (Vec3::splat(v), v)
            } else {
                (Vec3::ZERO, 0.0)
            }
        }
        LobeKind::Translucent => {
            if cos_i < 0.0 && !same_side {
                let v = -cos_i / PI;
                (Vec3::splat(v), v)
            } else {
                (Vec3::ZERO, 0.0)
            }
        }
        LobeKind::Transparent | LobeKind::Subsurface(_) | LobeKind::RayPortal(_) => {
            (Vec3::ZERO, 0.0)
        }
        LobeKind::Reflection(r) => {
            let (f, p) = r.eval(n, wo, wi, ng);
            let h = (wo + wi).normalize();
            (fresnel_eval(r.fresnel, wo.dot(h), Vec3::splat(f)), p)
        }
        LobeKind::OrenNayar(on) => {
            if cos_i > 0.0 && same_side {
                (on.eval(n, wo, wi), cos_i / PI)
            } else {
                (Vec3::ZERO, 0.0)
            }
        }
        LobeKind::Glass(g) => g.eval(n, wo, wi, ng),
        LobeKind::Glossy {
            alpha,
            fresnel,
            energy,
        } => {
            if alpha < SINGULAR_ALPHA || !same_side || cos_i <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let cos_o = n.dot(wo);
            if cos_o <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let h = (wo + wi).normalize();
            let cos_h = n.dot(h);
            let a2 = alpha * alpha;
            let d = ggx_d(cos_h, a2);
            let lo = ggx_lambda(cos_o, a2);
            let li = ggx_lambda(cos_i, a2);
            let g2 = 1.0 / (1.0 + lo + li);
            let g1 = 1.0 / (1.0 + lo);
            let f = fresnel_eval(fresnel, wo.dot(h), Vec3::ONE);
            let common = d * g2 / (4.0 * cos_o) * energy;
            let pdf = g1 * d / (4.0 * cos_o);
            (f * common, pdf)
        }
        LobeKind::Sheen(sh) => {
            let (f, p) = sh.eval(n, wi, ng);
            (Vec3::splat(f), p)
        }
        LobeKind::Velvet(ve) => {
            let (f, p) = ve.eval(n, wo, wi, ng);
            (Vec3::splat(f), p)
        }
        LobeKind::Toon(t) => {
            let (f, p) = t.eval(n, wo, wi);
            (Vec3::splat(f), p)
        }
        LobeKind::Hair(h) => {
            let p = h.eval(l.n.into(), wo, wi);
            (Vec3::splat(p), p)
        }
        LobeKind::Chiang(c) => c.eval(l.n.into(), wo, wi),
        LobeKind::Huang(c) => c.eval(wi, tables),
        LobeKind::GlossyAniso {
            lobe,
            fresnel,
            energy,
        } => {
            let (f, p, cos_hv) = lobe.eval(n, wo, wi, ng);
            if !(p > 0.0) {
                return (Vec3::ZERO, 0.0);
            }
            (fresnel_eval(fresnel, cos_hv, Vec3::ONE) * (f * energy), p)
        }
    }
}

fn sample_lobe(l: &Lobe, wo: Vec3, ng: Vec3, u: [f32; 2]) -> Option<(Vec3, bool)> {
    let n = Vec3::from(l.n);
    match l.kind {
        LobeKind::Diffuse | LobeKind::Translucent | LobeKind::OrenNayar(_) => {
            let d = crate::render::camera::concentric_disk(u);
            let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
            let n = if let LobeKind::Translucent = l.kind {
                -n
            } else {
                n
            };
            let wi = from_local(n, vec3(d[0], d[1], z));
            Some((wi, false))
        }
        LobeKind::Transparent => Some((-wo, true)),
        LobeKind::RayPortal(r) => Some((r.direction.into(), true)),
        // Sampled elsewhere.
        LobeKind::Glass(_)
        | LobeKind::Subsurface(_)
        | LobeKind::Hair(_)
        | LobeKind::Chiang(_)
        | LobeKind::Huang(_) => None,
        LobeKind::Reflection(r) => r.sample(n, wo, ng, u),
        LobeKind::Glossy { alpha, .. } => {
            // Cycles' bsdf_microfacet_sample rejects a view below the shading normal, sharp
            // or rough (strong bumps make it common: a mirror would reflect "through" N).
            let v = to_local(n, wo);
            if v[2] <= 0.0 {
                return None;
            }
            if alpha < SINGULAR_ALPHA {
                let wi = n * (2.0 * v[2]) - wo;
                if wi.dot(ng) <= 0.0 {
                    return None;
                }
                return Some((wi, true));
            }
            let h = sample_vndf(v, alpha, u);
            let wi_l = h * (2.0 * v.dot(h)) - v;
            if wi_l[2] <= 0.0 {
                return None;
            }
            Some((from_local(n, wi_l), false))
        }
        LobeKind::Sheen(sh) => sh.sample(n, ng, u).map(|wi| (wi, false)),
        LobeKind::Velvet(ve) => ve.sample(n, ng, u).map(|wi| (wi, false)),
        LobeKind::Toon(t) => t.sample(n, wo, ng, u).map(|wi| (wi, false)),
        LobeKind::GlossyAniso { lobe, .. } => lobe.sample(n, wo, ng, u).map(|wi| (wi, false)),
    }
}
