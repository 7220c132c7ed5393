//! The path tracer: next-event estimation toward one emitter per vertex (a light object,
//! an emissive triangle or the world, picked as Cycles picks it: `light_tree`), combined
//! with BSDF sampling by multiple importance sampling wherever Cycles combines them (every
//! light with extent and Multiple Importance on), Cycles' per-type
//! bounce limits (terminating after the next surface, as Cycles does), Russian roulette on sqrt of throughput, and
//! Cycles' clamping (direct and indirect limits on the sum of a contribution).

pub mod path_state;
pub mod shade;

use crate::scene::AttributeData;
use crate::shader::point::{ray, PathState, Undisplaced};
use crate::shader::ShadingPoint;

use crate::render::accel::{visibility, Accel};
use crate::render::bsdf::tables::Tables;
use crate::render::bsdf::{LobeKind, LobeSet};
use crate::render::build::Geometry;
use crate::render::integrator::path_state::{Next, Path, SETS_PER_VERTEX};
use crate::render::integrator::shade::{Context, Material};
use crate::render::light::tree::{LightSelect, Pick, Viewer};
use crate::render::light::Light;
use crate::render::math::*;
use crate::render::sampler::PixelSampler;
use crate::render::shader_rays::ShaderRays;
use crate::shader::trace::{NoTrace, Trace};
use std::cell::Cell;

#[derive(Debug, Clone, Copy)]
pub struct Settings {
    pub max_bounces: u32,
    pub max_diffuse: u32,
    pub max_glossy: u32,
    pub max_transmission: u32,
    pub max_transparent: u32,
    /// Limits on the sum of a contribution's three channels (Cycles' kernel values: the
    /// per-channel settings times three; 0 is off).
    pub clamp_direct: f32,
    pub clamp_indirect: f32,
    pub min_light_bounces: u32,
    pub min_transparent_bounces: u32,
    /// Cycles' Filter Glossy (`blur_glossy`).
    pub filter_glossy: f32,
    /// Film > Transparent: the background seen by camera rays (directly or through
    /// transparent surfaces) becomes alpha instead of colour.
    pub film_transparent: bool,
    /// Film > Transparent Glass: the bound on a refraction's alpha_x * alpha_y (Cycles'
    /// `transparent_roughness_squared_threshold`) under which it keeps a camera path
    /// transparent to the background; negative when off.
    pub transparent_glass: f32,
    /// Some material can be transparent: shadow rays then run the materials they pass
    /// through (`shadow_transmittance`); otherwise any hit blocks them.
    pub transparent_shadows: bool,
}

#[inline]
pub(super) fn power_heuristic(a: f32, b: f32) -> f32 {
    if a.is_infinite() {
        return 1.0;
    }
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 {
        a2 / (a2 + b2)
    } else {
        0.0
    }
}

pub struct Scene<'a> {
    /// How light sampling picks its emitter.
    pub light_select: &'a LightSelect,
    pub accel: &'a dyn Accel,
    pub geo: &'a Geometry,
    pub materials: &'a [Material],
    pub lights: &'a [Light],
    pub background: V3,
    /// Ray types the world is hidden from (World > Ray Visibility, `ray::` flags).
    pub world_exclude: u32,
    pub tables: &'a Tables,
    pub settings: Settings,
    /// The world's node program when it varies with direction (else `background`).
    pub world: Option<&'a crate::render::light::world::WorldShader>,
    /// The camera as Texture Coordinate > Camera/Window and Camera Data see it.
    pub view: crate::shader::view::View,
    /// Each object's own BVH for the shaders' local ray queries (Bevel, AO Only Local).
    pub local: &'a crate::render::shader_rays::LocalAccels,
    /// The materials' volumes (render/volume.rs).
    pub volumes: &'a crate::render::volume::Volumes,
    /// The view layer's shader AOV passes (`film::aov`).
    pub aovs: &'a crate::render::film::aov::Layout,
}

/// Per-thread scratch, reused across samples (no allocation per ray).
pub struct Scratch {
    pub stacks: Vec<Vec<f32>>,
    pub lobes: LobeSet,
    pub light_lobes: LobeSet,
    pub rays: u64,
    /// The camera ray's compact differentials (Cycles' ray.dP and ray.dD: spread of the
    /// origin and of the direction per pixel), set by the caller before `radiance`.
    pub ray_dp: f32,
    pub ray_dd: f32,
    /// The camera ray's shutter time in [0, 1], shared by every ray of its path (set by
    /// the caller before `radiance`, like the differentials).
    pub time: f32,
    /// The denoiser's guides of the sample `radiance` last traced.
    pub features: crate::render::film::denoise_features::Features,
    /// The transparency (1 - alpha) of the sample `radiance` last traced: transparent
    /// background and holdouts seen by the camera, as Cycles accumulates it in the
    /// combined pass's alpha.
    pub transparent: f32,
    /// The volumes the path being traced is inside, and its volume bounces so far.
    pub volume_stack: super::volume::Stack,
    pub volume_bounce: u32,
    /// The AOV values of the sample `radiance` last traced (`film::aov::Layout`), and
    /// whether a surface has ended its AOV writes (Cycles' PATH_RAY_SINGLE_PASS_DONE).
    pub aov: Vec<f32>,
    pub aov_done: bool,
}

impl Scratch {
    /// Clears what a camera sample leaves besides its colour (guides, transparency, AOV
    /// values with `aov_stride` floats, volume bounces) before `radiance` traces it.
    /// Resets what one sample accumulates. Rays leaving a hair skip its curve (Cycles'
    /// self prim): none on the camera ray, and none left for other rays once the sample
    /// ends (the returned guard clears it).
    #[must_use]
    fn start_sample(&mut self, aov_stride: usize) -> crate::render::curves::RaySelfGuard {
        crate::render::curves::set_ray_self(None);
        self.features = Default::default();
        self.transparent = 0.0;
        self.aov.clear();
        self.aov.resize(aov_stride, 0.0);
        self.aov_done = false;
        self.volume_bounce = 0;
        crate::render::curves::RaySelfGuard
    }

    pub fn new(n_materials: usize) -> Scratch {
        Scratch {
            stacks: vec![Vec::new(); n_materials + 1],
            lobes: LobeSet::default(),
            light_lobes: LobeSet::default(),
            rays: 0,
            ray_dp: 0.0,
            ray_dd: 0.0,
            time: crate::render::motion::object::CENTRE_TIME,
            features: Default::default(),
            transparent: 0.0,
            volume_stack: Default::default(),
            volume_bounce: 0,
            aov: Vec::new(),
            aov_done: false,
        }
    }
}

/// A surface hit, resolved for shading.
pub struct SurfaceHit {
    pub p: V3,
    pub ng: V3,
    pub sp: ShadingPoint,
    pub inst: u32,
    pub material: Option<usize>,
    pub backfacing: bool,
    /// The shutter time the hit's object was posed at.
    pub time: f32,
    /// The triangle and the weights of its corners 1 and 2 (shadow terminator offset).
    pub prim: u32,
    pub uv: [f32; 2],
}

pub(super) fn clamp_contrib(l: V3, limit: f32) -> V3 {
    if limit > 0.0 {
        let s = l[0].abs() + l[1].abs() + l[2].abs();
        if s > limit {
            return scale(l, limit / s);
        }
    }
    l
}

impl Scene<'_> {
    pub fn surface(&self, prim: u32, u: f32, v: f32, wo: V3) -> SurfaceHit {
        self.surface_at(prim, u, v, wo, crate::render::motion::object::CENTRE_TIME)
    }

    /// `surface` with a moving object posed at shutter time `time`.
    pub fn surface_at(&self, prim: u32, u: f32, v: f32, wo: V3, time: f32) -> SurfaceHit {
        let r = self.geo.refs[prim as usize];
        let inst = &self.geo.instances[r.inst as usize];
        if let Some(c) = &inst.curves {
            return self.curve_surface(c, prim, u, v, wo, time);
        }
        let m = &inst.mesh;
        let c = m.triangles[r.tri as usize].map(|c| c as usize);
        let w0 = 1.0 - u - v;
        let (to_world, to_object) = inst.pose_at(time);
        let tri = &inst.posed_triangle(&self.geo.tris[prim as usize], r.tri, &to_world);
        let p = add(add(scale(tri[0], w0), scale(tri[1], u)), scale(tri[2], v));
        let mut ng = normalize(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])));
        let lp = c.map(|c| m.positions[m.corner_verts[c] as usize]);
        let local = add(add(scale(lp[0], w0), scale(lp[1], u)), scale(lp[2], v));
        // Cycles applies the object transform to the mesh: each vertex normal goes to world
        // space before interpolation (it differs under non-uniform scale), and Texture
        // Coordinate > Normal transforms the result back.
        let (mut n, mut n_obj) = if m.corner_normals.len() == m.corner_verts.len() {
            let cn =
                c.map(|c| normalize(Affine::normal_by_inverse(&to_object, m.corner_normals[c])));
            let n = normalize(add(add(scale(cn[0], w0), scale(cn[1], u)), scale(cn[2], v)));
            (n, normalize(Affine::normal_by_inverse(&to_world, n)))
        } else {
            let n_obj = normalize(cross(sub(lp[1], lp[0]), sub(lp[2], lp[0])));
            (
                normalize(Affine::normal_by_inverse(&to_object, n_obj)),
                n_obj,
            )
        };
        if !finite(n) || is_zero(n) {
            n = ng;
        }
        let backfacing = dot(ng, wo) < 0.0;
        if backfacing {
            ng = neg(ng);
            n = neg(n);
            n_obj = neg(n_obj);
        }
        let face = m.triangle_faces[r.tri as usize] as usize;
        let slot = inst.face_slot.get(face).copied().unwrap_or(0) as usize;
        let material = inst.slots.get(slot).copied().flatten();
        let mut sp = ShadingPoint {
            position: p,
            normal: n,
            object_position: local,
            object_normal: n_obj,
            triangle: *tri,
            ..Default::default()
        };
        // Generated coordinates (and a displacement bump) read the mesh before true
        // displacement moved it.
        let before = inst.undisplaced.as_ref().map(|orig| {
            let up = c.map(|c| orig[m.corner_verts[c] as usize]);
            add(add(scale(up[0], w0), scale(up[1], u)), scale(up[2], v))
        });
        let orco = before.unwrap_or(local);
        sp.generated = inst.generated(orco);
        if let Some(b) = before {
            sp.undisplaced = Some(Undisplaced {
                position: to_world.point(b),
                object_position: b,
                ..Undisplaced::default()
            });
        }
        if let Some(uv) = &inst.uv {
            let t = c.map(|c| uv[c]);
            sp.uv = [
                t[0][0] * w0 + t[1][0] * u + t[2][0] * v,
                t[0][1] * w0 + t[1][1] * u + t[2][1] * v,
                0.0,
            ];
        }
        self.fill_context(&mut sp, inst, wo, ng, backfacing, u, v);
        // Tangent-space normal maps turn their normal to world space with it.
        sp.transform = crate::shader::bump::ObjectTransform {
            to_world: to_world.m,
            to_object: to_object.m,
        };
        if let Some(Some(bound)) = inst.attributes.get(slot) {
            bound.fill(
                m,
                r.tri as usize,
                c,
                face,
                [w0, u, v],
                &inst.instancer_values,
                &mut sp,
            );
        }
        if inst.motion.is_some() {
            // Object Info reads the object's transform at the ray's time, as in Cycles.
            sp.object.location = to_world.column(3);
            sp.object.world_to_object = to_object.m;
        }
        SurfaceHit {
            p,
            ng,
            sp,
            inst: r.inst,
            material,
            backfacing,
            time,
            prim,
            uv: [u, v],
        }
    }

    /// A hair ribbon hit (`render::curves`) as Cycles' curve_shader_setup gives it: the
    /// rounded normal, the true normal facing the ray (never backfacing), the object
    /// position of the hit and Generated from the curve's root in the emitter's texture
    /// space (Cycles' hair Generated attribute).
    fn curve_surface(
        &self,
        c: &crate::render::curves::ObjectCurves,
        prim: u32,
        u: f32,
        v: f32,
        wo: V3,
        time: f32,
    ) -> SurfaceHit {
        if c.points {
            return self.point_surface(c, prim, u, v, wo, time);
        }
        let r = self.geo.refs[prim as usize];
        let inst = &self.geo.instances[r.inst as usize];
        let cp = c.control_points(r.tri);
        // Thick curves: the tube's normal is the true normal too, turned to the viewer
        // (Cycles' backfacing flip) and v reads 0; ribbons face the ray.
        let (p, mut n, dpdu, ng, v_read, backfacing) = if c.thick {
            let (p, n, dpdu) = crate::render::thick_curves::tube_point(&cp, u, v);
            if dot(n, wo) < 0.0 {
                (p, neg(n), dpdu, neg(n), 0.0, true)
            } else {
                (p, n, dpdu, n, 0.0, false)
            }
        } else {
            let (p, n, dpdu) = crate::render::curves::ribbon_shading(&cp, c.pieces, u, v, neg(wo));
            (p, n, dpdu, wo, v, false)
        };
        if !finite(n) {
            n = wo;
        }
        let (to_world, to_object) = (&inst.to_world, &inst.to_object);
        let curve = c.segments[r.tri as usize].0 as usize;
        let root = c.keys[c.curves[curve].0 as usize];
        let mut sp = ShadingPoint {
            position: p,
            normal: n,
            object_position: to_object.point(p),
            object_normal: normalize(Affine::normal_by_inverse(to_world, n)),
            generated: inst.generated(to_object.point([root[0], root[1], root[2]])),
            dpdu,
            hair: c.hair_point(r.tri, u, dpdu, wo),
            uv: c.uv_at(r.tri, u),
            ..Default::default()
        };
        self.fill_context(&mut sp, inst, wo, ng, backfacing, u, v_read);
        let (_, k0) = c.segments[r.tri as usize];
        if let Some(Some(bound)) = inst.attributes.get(c.slot[curve] as usize) {
            bound.fill_curve(curve, k0 as usize, u, &inst.instancer_values, &mut sp);
        }
        sp.transform = crate::shader::bump::ObjectTransform {
            to_world: to_world.m,
            to_object: to_object.m,
        };
        SurfaceHit {
            p,
            ng,
            sp,
            inst: r.inst,
            material: inst.material_of(r.tri as usize),
            backfacing,
            time,
            prim,
            uv: [u, v],
        }
    }

    /// A point cloud hit (`render::points`) as Cycles' point_shader_setup gives it: on the
    /// sphere, its normal as both the shading and the true normal, never backfacing.
    fn point_surface(
        &self,
        c: &crate::render::curves::ObjectCurves,
        prim: u32,
        u: f32,
        v: f32,
        wo: V3,
        time: f32,
    ) -> SurfaceHit {
        let r = self.geo.refs[prim as usize];
        let inst = &self.geo.instances[r.inst as usize];
        let k = c.keys[r.tri as usize];
        let center = [k[0], k[1], k[2]];
        let (p, n) = crate::render::points::point_hit(c, r.tri as usize, u, v);
        let (to_world, to_object) = (&inst.to_world, &inst.to_object);
        let mut sp = ShadingPoint {
            position: p,
            normal: n,
            object_position: to_object.point(p),
            object_normal: normalize(Affine::normal_by_inverse(to_world, n)),
            generated: inst.generated(to_object.point(center)),
            point: crate::shader::point::PointPoint {
                position: center,
                radius: crate::render::points::point_radius(c, r.tri as usize),
                random: crate::nodes::random::hash_to_float2(
                    c.point_index.get(r.tri as usize).copied().unwrap_or(r.tri),
                    0,
                ),
            },
            ..Default::default()
        };
        // Cycles gives points no parametric coordinates (sd->u = sd->v = 0).
        self.fill_context(&mut sp, inst, wo, n, false, 0.0, 0.0);
        // Point attributes: one value per point, each point its own "curve".
        let point = r.tri as usize;
        if let Some(Some(bound)) = c
            .slot
            .get(point)
            .and_then(|&s| inst.attributes.get(s as usize))
        {
            bound.fill_curve(point, point, 0.0, &inst.instancer_values, &mut sp);
        }
        sp.transform = crate::shader::bump::ObjectTransform {
            to_world: to_world.m,
            to_object: to_object.m,
        };
        SurfaceHit {
            p,
            ng: n,
            sp,
            inst: r.inst,
            material: inst.material_of(r.tri as usize),
            backfacing: false,
            time,
            prim,
            uv: [0.0, 0.0],
        }
    }

    /// Shades `hit` without ray tracing (Ambient Occlusion 1, Bevel the shading normal):
    /// the label passes' pixel-centre shading.
    pub fn shade(&self, hit: &SurfaceHit, wo: V3, scratch: &mut Scratch) {
        self.shade_into(hit, wo, &mut scratch.stacks, &mut scratch.lobes, &NoTrace);
    }

    /// Shades a path vertex, its Ambient Occlusion and Bevel nodes tracing from it with
    /// the vertex's free sampler set.
    fn shade_path(
        &self,
        hit: &SurfaceHit,
        wo: V3,
        path: &Path,
        rng: &PixelSampler,
        index: u32,
        scratch: &mut Scratch,
    ) {
        let rays = ShaderRays {
            scene: self,
            hit,
            rng,
            index,
            set: path.set + 2,
            min_ray_pdf: path.min_ray_pdf,
            rays: Cell::new(0),
        };
        self.shade_into(hit, wo, &mut scratch.stacks, &mut scratch.lobes, &rays);
        scratch.rays += rays.rays.get();
    }

    fn shade_into(
        &self,
        hit: &SurfaceHit,
        wo: V3,
        stacks: &mut [Vec<f32>],
        lobes: &mut LobeSet,
        trace: &dyn Trace,
    ) {
        // Points are shaded as surfaces: only hair ribbons skip the specular correction.
        let curve = self.geo.instances[hit.inst as usize]
            .curves
            .as_ref()
            .is_some_and(|c| !c.points);
        let ctx = Context {
            tables: self.tables,
            wo,
            backfacing: hit.backfacing,
            // Cycles raises no specular normal on curves (maybe_ensure_valid_specular_reflection).
            bump_correction: !curve,
            trace,
        };
        match hit.material {
            Some(mi) => self.materials[mi].shade(&hit.sp, &mut stacks[mi], &ctx, lobes),
            None => {
                lobes.clear();
                lobes.push(LobeKind::Diffuse, [0.8; 3], hit.sp.normal);
            }
        }
        // Sampled directions are checked against each closure's normal on curves (Cycles'
        // bsdf_sample), whose ribbons' true normal faces the ray.
        lobes.own_normal_as_ng = curve;
    }

    /// One path sample: radiance along the camera ray. Each vertex runs the steps Cycles'
    /// kernels run: lights the ray passes and the world it may miss into, then at a
    /// surface its shader, emission, Russian roulette, one light sample, and the BSDF
    /// sample that `Path::next` turns into the next ray (or a subsurface walk).
    // The shading state is passed apart, as Cycles passes it to its kernels.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        rng: &PixelSampler,
        index: u32,
        scratch: &mut Scratch,
    ) -> V3 {
        let st = &self.settings;
        let _self_guard = scratch.start_sample(self.aovs.stride);
        self.volume_stack_init(org, scratch);
        let mut path = Path::camera(org, dir, tmin, tmax, scratch.ray_dp, scratch.ray_dd);
        loop {
            let from_sss = path.sss_exit.take();
            let hit_opt = if from_sss.is_some() {
                from_sss
            } else {
                scratch.rays += 1;
                self.accel.intersect_vis(
                    path.o,
                    path.d,
                    path.t0,
                    path.t1,
                    scratch.time,
                    visibility::of_path(path.state.flags),
                )
            };
            // Inside volumes the segment to the hit runs first (render/volume.rs); a ray
            // leaving the scene leaves every volume but the world's (Cycles'
            // volume_stack_clean), and crosses that one to FLT_MAX (volume_world.rs).
            if from_sss.is_none() && hit_opt.is_none() {
                scratch.volume_stack.keep_world();
            }
            if from_sss.is_none() && !scratch.volume_stack.is_empty() {
                match self.through_volumes(&mut path, hit_opt.map(|h| h.t), rng, index, scratch) {
                    Through::Surface => {}
                    Through::Again => continue,
                    Through::End => break,
                }
            }
            let clamp_limit = path.hit_clamp(st);
            if from_sss.is_none() {
                self.lights_along(&mut path, hit_opt.map(|h| h.t), clamp_limit, scratch);
            }
            crate::render::curves::set_ray_self(hit_opt.as_ref().map(|h| h.prim));
            let Some(h) = hit_opt else {
                self.miss(&mut path, clamp_limit, scratch);
                break;
            };
            let wo = neg(path.d);
            let hit = self.vertex(&mut path, &h, wo, scratch);
            if from_sss.is_none() && self.volume_boundary(&mut path, &hit, scratch) {
                continue;
            }
            if !self.shade_vertex(&path, &hit, wo, from_sss.is_some(), rng, index, scratch) {
                break;
            }
            scratch.lobes.terminator_frequency =
                self.geo.instances[hit.inst as usize].terminator_frequency;
            if path.diffuse_ancestor {
                crate::render::subsurface::to_diffuse(&mut scratch.lobes);
            }
            filter_glossy(&mut scratch.lobes, path.min_ray_pdf, st.filter_glossy);
            self.emission_at_hit(&mut path, &h, &hit, clamp_limit, scratch);
            // A subsurface exit is not a surface the camera path saw (Cycles writes no
            // guides there).
            if from_sss.is_none() {
                scratch.features.surface(&scratch.lobes);
                self.end_aov_writes(&path, scratch);
            }
            let u_bsdf = rng.get4(index, path.set);
            let u_light = rng.get4(index, path.set + 1);
            path.set += SETS_PER_VERTEX;
            // Only transparent surfaces let a path at its bounce limit continue.
            if path.terminate_next && is_zero(scratch.lobes.transparent) {
                break;
            }
            // Not again at a subsurface exit: decided at the entry.
            if from_sss.is_none() && !path.survives_roulette(st, u_light[3]) {
                break;
            }
            // Light selection sees the vertex by its shading normal and whether its BSDF
            // transmits; the next ray's MIS weights are computed from there.
            let n_sel = if is_zero(scratch.lobes.smooth_n) {
                hit.sp.normal
            } else {
                scratch.lobes.smooth_n
            };
            let trans_sel = scratch.lobes.has_transmission();
            if !path.terminate_next && scratch.lobes.len > 0 {
                let u = [u_light[0], u_light[1], u_light[2]];
                if let Some(c) =
                    self.direct_light(&path, &hit, h.prim, wo, u, n_sel, trans_sel, scratch)
                {
                    path.l = add(path.l, c);
                }
            }
            let lobes = &scratch.lobes;
            let Some(bs) = lobes.sample(wo, hit.ng, [u_bsdf[0], u_bsdf[1], u_bsdf[2]], self.tables)
            else {
                break;
            };
            if !finite(bs.weight) || is_zero(bs.weight) {
                break;
            }
            if path.terminate_next && !matches!(bs.kind, LobeKind::Transparent) {
                break;
            }
            path.throughput = mul(path.throughput, bs.weight);
            if let LobeKind::Subsurface(b) = bs.kind {
                // Not a bounce of its own: the walk's exit is the next vertex.
                let exit = crate::render::subsurface::enter_and_walk(
                    self,
                    &b,
                    &hit,
                    wo,
                    bs.wi,
                    rng,
                    index,
                    path.set,
                    &mut path.throughput,
                    &mut scratch.rays,
                );
                let Some((exit_hit, dir)) = exit else { break };
                path.leave_subsurface(exit_hit, dir);
                continue;
            }
            if bs.transmit || matches!(bs.kind, LobeKind::Transparent) {
                self.volume_cross(&hit, scratch);
            }
            if path.next(&bs, hit.p, hit.ng, n_sel, trans_sel, st) == Next::Stop {
                break;
            }
        }
        path.l
    }

    /// Lights are not in the BVH: a ray collects every light it passes before the
    /// surface at `t_hit` (or its end).
    fn lights_along(&self, path: &mut Path, t_hit: Option<f32>, clamp: f32, scratch: &mut Scratch) {
        let t_surface = t_hit.unwrap_or(if path.t1.is_finite() {
            path.t1
        } else {
            f32::INFINITY
        });
        let flags = path.state.flags;
        for (li, light) in self
            .lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.visible_to(flags))
        {
            // Rays other than the camera's see only lights shared with BSDF sampling
            // (Cycles' lights_intersect skips those without SHADER_USE_MIS).
            if !light.mis && flags & ray::CAMERA == 0 {
                continue;
            }
            // From Cycles' ray origin (`mis_o`), beyond the surfaces passed since.
            let found = light.intersect(path.mis_o, path.d, path.mis_t + t_surface);
            if let Some(lh) = found.filter(|lh| lh.t > path.mis_t) {
                let w = if path.prev_singular {
                    1.0
                } else {
                    power_heuristic(
                        path.prev_pdf,
                        lh.pdf
                            * self
                                .light_select
                                .pdf_for(path.mis_viewer(), Pick::Lamp(li as u32)),
                    )
                };
                scratch
                    .features
                    .add_emission(scale(mul(path.throughput, lh.radiance), w));
                let c = clamp_contrib(scale(mul(path.throughput, lh.radiance), w), clamp);
                if finite(c) {
                    path.l = add(path.l, c);
                }
            }
        }
    }

    /// The ray left the scene: the world (or, for a camera ray with Film > Transparent,
    /// alpha).
    fn miss(&self, path: &mut Path, clamp: f32, scratch: &mut Scratch) {
        if self.settings.film_transparent && path.transparent_bg {
            scratch.transparent += average(path.throughput);
            return;
        }
        // A world hidden from this ray type gives it nothing (Cycles'
        // integrator_eval_background_shader).
        if !crate::render::light::visible_to(self.world_exclude, path.state.flags) {
            return;
        }
        let d = path.d;
        let w = self.world_mis_weight(d, path.prev_singular, path.prev_pdf, path.mis_viewer());
        let bg = scale(
            mul(
                path.throughput,
                self.background_toward(d, path.state, scratch),
            ),
            w,
        );
        // The world's AOV Outputs, run with it (Cycles evaluates the background shader
        // with the render buffer).
        if path.transparent_bg && !scratch.aov_done {
            if let (Some(world), Some(stack)) = (self.world, scratch.stacks.last()) {
                self.write_aovs(&world.program, stack, &mut scratch.aov);
            }
        }
        scratch.features.add_emission(bg);
        let c = clamp_contrib(bg, clamp);
        if finite(c) {
            path.l = add(path.l, c);
        }
    }

    /// The surface the ray hit, with the path state its shader sees and the ray
    /// differentials carried to it.
    fn vertex(
        &self,
        path: &mut Path,
        h: &crate::render::accel::Hit,
        wo: V3,
        scratch: &Scratch,
    ) -> SurfaceHit {
        let mut hit = self.surface_at(h.prim, h.u, h.v, wo, scratch.time);
        hit.sp.ray_length = h.t;
        hit.sp.path = path.state;
        path.ray_dp += h.t * path.ray_dd;
        self.fill_differentials(&mut hit, h.prim, path.ray_dp);
        hit
    }

    /// Runs the vertex's shader into `scratch.lobes`; false when a holdout ends the path.
    #[allow(clippy::too_many_arguments)]
    fn shade_vertex(
        &self,
        path: &Path,
        hit: &SurfaceHit,
        wo: V3,
        sss_exit: bool,
        rng: &PixelSampler,
        index: u32,
        scratch: &mut Scratch,
    ) -> bool {
        if sss_exit {
            // With a bumped BSSRDF Cycles runs the material at the exit and lights
            // with the BSSRDF's normal there (corrected as seen along the true normal).
            let (n, smooth) = match hit.material {
                Some(mi) if self.materials[mi].bssrdf_bump => {
                    self.shade_path(hit, wo, path, rng, index, scratch);
                    let smooth = scratch.lobes.smooth_n;
                    (
                        crate::render::subsurface::exit_normal(&scratch.lobes, smooth),
                        smooth,
                    )
                }
                _ => (hit.sp.normal, hit.sp.normal),
            };
            let correction = hit
                .material
                .map(|mi| self.materials[mi].bump_correction)
                .unwrap_or(true);
            scratch.lobes.clear();
            scratch.lobes.smooth_n = smooth;
            scratch.lobes.bump_correction = correction;
            scratch.lobes.push(LobeKind::Diffuse, [1.0; 3], n);
            return true;
        }
        self.shade_path(hit, wo, path, rng, index, scratch);
        // Cycles runs the AOV Outputs with the shader, before the holdout.
        if path.transparent_bg && !scratch.aov_done {
            if let Some(p) = hit
                .material
                .and_then(|mi| self.materials[mi].program.as_ref())
            {
                let stack = &scratch.stacks[hit.material.unwrap_or(0)];
                self.write_aovs(p, stack, &mut scratch.aov);
            }
        }
        // A holdout object seen by the camera (directly or through transparent
        // surfaces: Cycles' PATH_RAY_TRANSPARENT_BACKGROUND) keeps only its
        // transparency; the rest is a hole in the film.
        if path.transparent_bg && self.geo.instances[hit.inst as usize].holdout {
            // The holdout weight (Cycles' surface_shader_apply_holdout) is what
            // the object's transparency does not let through.
            let weight = sub(
                [1.0; 3],
                scratch.lobes.transparent.map(|t| t.clamp(0.0, 1.0)),
            );
            scratch.transparent += average(mul(weight, path.throughput));
            if !holdout_keep_transparent(&mut scratch.lobes) {
                return false;
            }
        } else if path.transparent_bg && !is_zero(scratch.lobes.holdout) {
            // Holdout closures (the Holdout shader node) seen by the camera.
            let weight = scratch.lobes.holdout;
            scratch.transparent += average(mul(weight, path.throughput));
            if weight.iter().all(|&w| w == 1.0) {
                return false;
            }
        }
        true
    }

    /// Cycles' film_write_data_passes: a surface the camera sees that is opaque enough
    /// ends its sample's AOV writes (PATH_RAY_SINGLE_PASS_DONE).
    fn end_aov_writes(&self, path: &Path, scratch: &mut Scratch) {
        if path.transparent_bg && self.aovs.ends_primary(scratch.lobes.transparent) {
            scratch.aov_done = true;
        }
    }

    /// Adds the values of program `p`'s AOV Outputs (in `stack` after it ran) to the
    /// sample's AOV values, as Cycles' film_write_aov_pass_value / _color do.
    fn write_aovs(&self, p: &crate::shader::Program, stack: &[f32], out: &mut [f32]) {
        for w in &p.aovs {
            let Some(pass) = self.aovs.pass(w.aov) else {
                continue;
            };
            let (s, o) = (w.slot as usize, pass.offset);
            if w.color {
                for k in 0..3 {
                    out[o + k] += stack[s + k];
                }
                out[o + 3] += 1.0;
            } else {
                out[o] += stack[s];
            }
        }
    }

    /// Emission of the surface the ray found, shared by MIS with light sampling on the
    /// sides light sampling draws from (Cycles' SD_MIS_FRONT / SD_MIS_BACK).
    fn emission_at_hit(
        &self,
        path: &mut Path,
        h: &crate::render::accel::Hit,
        hit: &SurfaceHit,
        clamp: f32,
        scratch: &mut Scratch,
    ) {
        let lobes = &scratch.lobes;
        if is_zero(lobes.emission) {
            return;
        }
        let (front, back) = self.emission_sides(h.prim);
        let w = if path.prev_singular || !(if hit.backfacing { back } else { front }) {
            1.0
        } else {
            let pick = self
                .light_select
                .pdf_for(path.mis_viewer(), Pick::Triangle(h.prim));
            if pick > 0.0 {
                power_heuristic(
                    path.prev_pdf,
                    pick * crate::render::light::triangle::pdf(
                        &self.geo.tris[h.prim as usize],
                        path.mis_o,
                        path.d,
                        path.mis_t + h.t,
                    ),
                )
            } else {
                1.0
            }
        };
        let e = scale(mul(path.throughput, lobes.emission), w);
        scratch.features.add_emission(e);
        let c = clamp_contrib(scale(mul(path.throughput, lobes.emission), w), clamp);
        if finite(c) {
            path.l = add(path.l, c);
        }
    }

    /// Next-event estimation: one emitter, picked as Cycles picks it at this vertex, the
    /// sample divided by the probability of the pick; the clamped contribution, if any.
    #[allow(clippy::too_many_arguments)]
    fn direct_light(
        &self,
        path: &Path,
        hit: &SurfaceHit,
        prim: u32,
        wo: V3,
        u: [f32; 3],
        n_sel: V3,
        trans_sel: bool,
        scratch: &mut Scratch,
    ) -> Option<V3> {
        let clamp = path.light_clamp(&self.settings);
        let throughput = path.throughput;
        let bounce = path.state.bounce;
        let picked = self.light_select.select(hit.p, n_sel, trans_sel, u[2]);
        match picked {
            Some((Pick::Lamp(li), p_sel)) if bounce <= self.lights[li as usize].max_bounces => {
                let light = &self.lights[li as usize];
                let ls = light.sample(hit.p, [u[0], u[1]])?;
                let (f, pdf_b) =
                    scratch
                        .lobes
                        .eval_excluding(wo, ls.wi, hit.ng, self.tables, light.exclude);
                // Lights with extent are shared with BSDF sampling at every vertex, as
                // Cycles does (light_sample_mis_weight_nee).
                let w = if light.mis {
                    power_heuristic(ls.pdf * p_sel, pdf_b)
                } else {
                    1.0
                };
                let c = scale(mul(mul(throughput, f), ls.value), w / p_sel);
                if is_zero(c) || !finite(c) {
                    return None;
                }
                let start = self.shadow_origin(hit, scratch.lobes.smooth_n, ls.wi);
                let tr = if light.cast_shadow {
                    let stack = self.shadow_stack(hit, ls.wi, scratch);
                    self.shadow_transmittance(
                        start,
                        ls.wi,
                        if ls.dist.is_finite() {
                            ls.dist * (1.0 - 1e-4)
                        } else {
                            f32::INFINITY
                        },
                        stack,
                        scratch,
                    )
                } else {
                    [1.0; 3]
                };
                (!is_zero(tr)).then(|| clamp_contrib(mul(c, tr), clamp))
            }
            Some((Pick::Triangle(tri), p_sel)) if tri != prim => {
                let (front, back) = self.emission_sides(tri);
                let ts = crate::render::light::triangle::sample(
                    &self.geo.tris[tri as usize],
                    hit.p,
                    [u[0], u[1]],
                    front,
                    back,
                )?;
                // The emitter's object hidden from some ray types lights only the
                // closures of the others (Cycles' SHADER_EXCLUDE_* of mesh lights).
                let seen_by =
                    self.geo.instances[self.geo.refs[tri as usize].inst as usize].visibility;
                let exclude =
                    !seen_by & (ray::DIFFUSE | ray::GLOSSY | ray::TRANSMIT | ray::VOLUME_SCATTER);
                let (f, pdf_b) = if exclude == 0 {
                    scratch.lobes.eval(wo, ts.wi, hit.ng, self.tables)
                } else {
                    scratch
                        .lobes
                        .eval_excluding(wo, ts.wi, hit.ng, self.tables, exclude)
                };
                if is_zero(f) {
                    return None;
                }
                let pdf_l = p_sel * ts.pdf;
                let start = self.shadow_origin(hit, scratch.lobes.smooth_n, ts.wi);
                let stack = self.shadow_stack(hit, ts.wi, scratch);
                let tr =
                    self.shadow_transmittance(start, ts.wi, ts.dist * (1.0 - 1e-4), stack, scratch);
                if is_zero(tr) {
                    return None;
                }
                let le =
                    self.light_emission(tri, ts.b1, ts.b2, neg(ts.wi), ts.dist, bounce, scratch);
                let w = power_heuristic(pdf_l, pdf_b);
                let c = mul(scale(mul(mul(throughput, f), le), w / pdf_l), tr);
                finite(c).then(|| clamp_contrib(c, clamp))
            }
            Some((Pick::World, p_sel)) => {
                let c = self.world_light_sample(hit, wo, [u[0], u[1]], p_sel, scratch);
                let c = mul(throughput, c);
                (finite(c) && !is_zero(c)).then(|| clamp_contrib(c, clamp))
            }
            _ => None,
        }
    }
}

/// Cycles' surface_shader_prepare_closures. Its 3.x defensive sampling (a floor on each
/// closure's selection weight at the first hit) is gone in 4.x: the firefly histograms
/// of a sharp specular over a diffuse base match Cycles 4.5 only without it. Filter
/// Glossy: after diffuse-like bounces (a finite `min_ray_pdf`), glossy lobes are
/// roughened.
fn filter_glossy(lobes: &mut LobeSet, min_ray_pdf: f32, filter_glossy: f32) {
    if filter_glossy <= 0.0 || !min_ray_pdf.is_finite() {
        return;
    }
    // Cycles' kernel uses 1 / blur_glossy.
    let blur_pdf = min_ray_pdf / filter_glossy;
    if blur_pdf >= 1.0 {
        return;
    }
    let blur = (1.0 - blur_pdf).sqrt() * 0.5;
    let n = lobes.len;
    for lobe in &mut lobes.lobes[..n] {
        if let LobeKind::Glossy { alpha, .. } = &mut lobe.kind {
            *alpha = alpha.max(blur);
        }
        if let LobeKind::Glass(g) = &mut lobe.kind {
            g.alpha = g.alpha.max(blur);
        }
        if let LobeKind::Reflection(r) = &mut lobe.kind {
            r.alpha = r.alpha.max(blur);
        }
        if let LobeKind::GlossyAniso { lobe: a, .. } = &mut lobe.kind {
            a.alpha_x = a.alpha_x.max(blur);
            a.alpha_y = a.alpha_y.max(blur);
        }
        // Cycles blurs the Principled Hair closures too; the Hair BSDF has no blur.
        if let LobeKind::Chiang(c) = &mut lobe.kind {
            c.blur(blur);
        }
        if let LobeKind::Huang(c) = &mut lobe.kind {
            c.blur(blur);
        }
    }
}

impl Scene<'_> {
    /// Radiance from the world along a ray leaving the scene in direction `d`. The world
    /// program runs on the scratch's spare stack (the one after the materials').
    /// The world's radiance toward `d` for a ray in `path` (its flags with Emission added,
    /// as Cycles evaluates the background).
    pub fn background_toward(&self, d: V3, path: PathState, scratch: &mut Scratch) -> V3 {
        let path = PathState {
            flags: path.flags | ray::EMISSION,
            ..path
        };
        match (self.world, scratch.stacks.last_mut()) {
            (Some(w), Some(stack)) => w.eval(d, path, stack),
            _ => self.background,
        }
    }
}

impl Scene<'_> {
    /// MIS weight of world radiance reached by a BSDF-sampled ray (1 when the world is
    /// not light-sampled or the ray came from a singular lobe or the camera).
    fn world_mis_weight(&self, d: V3, prev_singular: bool, prev_pdf: f32, from: Viewer) -> f32 {
        match self.world.and_then(|w| w.map.as_ref()) {
            Some(map) if !prev_singular => power_heuristic(
                prev_pdf,
                map.pdf(d) * self.light_select.pdf_for(from, Pick::World),
            ),
            _ => 1.0,
        }
    }

    /// Next-event estimate toward the world from surface point `hit` (BSDF in
    /// `scratch.lobes`), MIS-weighted against BSDF sampling; zero if unoccluded paths
    /// see nothing or the world is not light-sampled.
    fn world_light_sample(
        &self,
        hit: &SurfaceHit,
        wo: V3,
        u: [f32; 2],
        p_sel: f32,
        scratch: &mut Scratch,
    ) -> V3 {
        let Some(map) = self.world.and_then(|w| w.map.as_ref()) else {
            return [0.0; 3];
        };
        let Some((wi, pdf_l)) = map.sample(u) else {
            return [0.0; 3];
        };
        let pdf_l = pdf_l * p_sel;
        // Closures of the ray types the world is hidden from do not see it.
        let (f, pdf_b) =
            scratch
                .lobes
                .eval_excluding(wo, wi, hit.ng, self.tables, self.world_exclude);
        if is_zero(f) || pdf_l.is_nan() || pdf_l <= 0.0 {
            return [0.0; 3];
        }
        let start = self.shadow_origin(hit, scratch.lobes.smooth_n, wi);
        let stack = self.shadow_stack(hit, wi, scratch);
        let tr = self.shadow_transmittance(start, wi, f32::INFINITY, stack, scratch);
        if is_zero(tr) {
            return [0.0; 3];
        }
        // A light sample sees the world with the Emission flag alone and the shading
        // point's bounces (Cycles' light_sample_shader_eval).
        let path = PathState {
            flags: 0,
            ..hit.sp.path
        };
        let le = self.background_toward(wi, path, scratch);
        mul(scale(mul(f, le), power_heuristic(pdf_l, pdf_b) / pdf_l), tr)
    }

    /// Where a shadow ray from `hit` toward `wi` (unit) starts: just off the surface on the
    /// light's side, lifted to the smooth surface of the vertex normals at grazing angles
    /// (Cycles' shadow terminator geometry offset, `terminator`). A lifted ray toward a
    /// light behind the true normal may hit its own triangle, as in Cycles ("otherwise
    /// we're meant to hit this surface"): it then starts on the near side, so it does.
    fn shadow_origin(&self, hit: &SurfaceHit, smooth_n: V3, wi: V3) -> V3 {
        let mut p = hit.p;
        let mut skip_self = true;
        let inst = &self.geo.instances[hit.inst as usize];
        let m = &inst.mesh;
        // Cycles' shadow terminator offset is for triangles only (not hair).
        if inst.shadow_terminator > 0.0
            && inst.curves.is_none()
            && m.corner_normals.len() == m.corner_verts.len()
        {
            // Cycles' sd->N: the shading normal after the material's displacement bump.
            let n = if is_zero(smooth_n) {
                hit.sp.normal
            } else {
                smooth_n
            };
            let (amount, ng) =
                crate::render::bsdf::terminator::amount(inst.shadow_terminator, n, hit.ng, wi);
            let r = self.geo.refs[hit.prim as usize];
            let flat = || {
                let face = m.triangle_faces[r.tri as usize] as usize;
                matches!(m.attribute("sharp_face").map(|a| &a.data), Some(AttributeData::Bool(f)) if f.get(face) == Some(&true))
            };
            if amount > 0.0 && !flat() {
                let (to_world, to_object) = inst.pose_at(hit.time);
                let v = inst.posed_triangle(&self.geo.tris[hit.prim as usize], r.tri, &to_world);
                let c = m.triangles[r.tri as usize];
                // World-space vertex normals, as Cycles has them once it applied the
                // object's transform (the same normals `surface_at` shades with).
                let n = c.map(|c| {
                    normalize(Affine::normal_by_inverse(
                        &to_object,
                        m.corner_normals[c as usize],
                    ))
                });
                let [u, w] = hit.uv;
                let lift = crate::render::bsdf::terminator::smooth_surface_offset(
                    v,
                    n,
                    [1.0 - u - w, u, w],
                    ng,
                );
                if finite(lift) {
                    p = madd(p, lift, amount);
                }
                skip_self = dot(ng, wi) > 0.0;
            }
        }
        // Off the surface on the light's side (the ray leaves its own triangle), or, when
        // it is meant to hit it, on the other side.
        offset_origin(p, hit.ng, if skip_self { wi } else { neg(wi) })
    }

    /// What a shadow ray from `start` along `dir` (unit) lets through up to `tmax`: zero at
    /// the first opaque surface; through surfaces whose material can be transparent, the
    /// product of their transparent closures' weights (Cycles' transparent shadows), and
    /// opaque past the transparent bounce limit. Inside volumes (`stack`: those it starts
    /// in) each segment is attenuated by them; a volume-only boundary is passed freely.
    pub(super) fn shadow_transmittance(
        &self,
        start: V3,
        dir: V3,
        tmax: f32,
        mut stack: super::volume::Stack,
        scratch: &mut Scratch,
    ) -> V3 {
        scratch.rays += 1;
        if !self.settings.transparent_shadows && !self.volumes.any {
            let blocked =
                self.accel
                    .occluded_vis(start, dir, 0.0, tmax, scratch.time, visibility::SHADOW);
            return if blocked { [0.0; 3] } else { [1.0; 3] };
        }
        let mut through = [1.0f32; 3];
        let (mut o, mut left) = (start, tmax);
        let mut crossed = 0;
        loop {
            let found =
                self.accel
                    .intersect_vis(o, dir, 0.0, left, scratch.time, visibility::SHADOW);
            let seg = found.map_or(left, |h| h.t);
            if !stack.is_empty() && seg.is_finite() {
                let tr = self.volume_transmittance(o, dir, seg, &stack, scratch);
                through = mul(through, tr);
                if is_zero(through) {
                    return [0.0; 3];
                }
            }
            let Some(h) = found else {
                if !seg.is_finite() {
                    // Escaping the scene: the world volume's extinction to FLT_MAX.
                    through = mul(through, self.world_escape_transmittance(o, dir, scratch));
                }
                return through;
            };
            let mut hit = self.surface_at(h.prim, h.u, h.v, neg(dir), scratch.time);
            match hit.material {
                Some(mi) if self.volumes.only_volume(mi) => {}
                Some(mi) if self.materials[mi].transparent_shadow => {
                    if crossed >= self.settings.max_transparent {
                        return [0.0; 3];
                    }
                    crossed += 1;
                    hit.sp.ray_length = h.t;
                    hit.sp.path = PathState {
                        flags: ray::SHADOW,
                        ..Default::default()
                    };
                    self.shade_into(
                        &hit,
                        neg(dir),
                        &mut scratch.stacks,
                        &mut scratch.light_lobes,
                        &NoTrace,
                    );
                    through = mul(through, scratch.light_lobes.shadow_transparency());
                    if is_zero(through) {
                        return [0.0; 3];
                    }
                }
                _ => return [0.0; 3],
            }
            if let Some(mi) = hit.material.filter(|&m| self.volumes.has_volume(m)) {
                stack.enter_exit(hit.inst, mi as u32, hit.backfacing);
            }
            o = offset_origin(hit.p, hit.ng, dir);
            left -= h.t;
            scratch.rays += 1;
        }
    }
}

impl Scene<'_> {
    /// Fills a hit's ray differentials from the compact differential `dp` at the hit, as
    /// Cycles' shader_setup_from_ray: expanded around Ng, with the UV and Generated
    /// attribute differentials the Bump node's coordinate copies read.
    pub fn fill_differentials(&self, hit: &mut SurfaceHit, prim: u32, dp: f32) {
        use crate::shader::bump::{
            attribute_differential, differential_dudv, differential_from_compact, ObjectTransform,
        };
        let r = self.geo.refs[prim as usize];
        let inst = &self.geo.instances[r.inst as usize];
        if inst.curves.is_some() {
            // Hair: the position's differentials only; Cycles gives curves no du, dv, so
            // no attribute differentials.
            let (dx, dy) = differential_from_compact(hit.ng, dp);
            hit.sp.ng = hit.ng;
            hit.sp.dp_dx = dx;
            hit.sp.dp_dy = dy;
            return;
        }
        let m = &inst.mesh;
        let c = m.triangles[r.tri as usize].map(|c| c as usize);
        let (to_world, to_object) = inst.pose_at(hit.time);
        let sp = &mut hit.sp;
        sp.ng = hit.ng;
        sp.backfacing = hit.backfacing;
        sp.transform = ObjectTransform {
            to_world: to_world.m,
            to_object: to_object.m,
        };
        let (dx, dy) = differential_from_compact(hit.ng, dp);
        sp.dp_dx = dx;
        sp.dp_dy = dy;
        // Only a Bump's dx/dy copies read the attribute differentials (and the displacement
        // bump the undisplaced ones): elsewhere they stay zero and unread.
        let reads = hit
            .material
            .and_then(|mi| self.materials[mi].program.as_ref())
            .is_some_and(|p| p.reads_differentials);
        if !reads && sp.undisplaced.is_none() {
            return;
        }
        let tri = &inst.posed_triangle(&self.geo.tris[prim as usize], r.tri, &to_world);
        // Seen from the back, Cycles flips dPdu and dPdv with the normals, so every
        // attribute differential (and the bump read from them) turns over too.
        let (mut dpdu, mut dpdv) = (sub(tri[1], tri[0]), sub(tri[2], tri[0]));
        if hit.backfacing {
            (dpdu, dpdv) = (neg(dpdu), neg(dpdv));
        }
        let d = differential_dudv(dpdu, dpdv, [dx, dy], hit.ng);
        let lp = match &inst.undisplaced {
            Some(u) => c.map(|c| u[m.corner_verts[c] as usize]),
            None => c.map(|c| m.positions[m.corner_verts[c] as usize]),
        };
        if let Some(und) = &mut sp.undisplaced {
            // The undisplaced position's differentials: the hit's barycentric ones
            // applied to the triangle before displacement (Cycles' attribute dx/dy).
            let w = lp.map(|l| to_world.point(l));
            und.dp_dx = attribute_differential(w, d[0]);
            und.dp_dy = attribute_differential(w, d[1]);
        }
        if !reads {
            return;
        }
        let generated = lp.map(|l| inst.generated(l));
        sp.generated_dx = attribute_differential(generated, d[0]);
        sp.generated_dy = attribute_differential(generated, d[1]);
        if let Some(uv) = &inst.uv {
            let t = c.map(|c| [uv[c][0], uv[c][1], 0.0]);
            sp.uv_dx = attribute_differential(t, d[0]);
            sp.uv_dy = attribute_differential(t, d[1]);
        }
        let face = m.triangle_faces[r.tri as usize] as usize;
        let slot = inst.face_slot.get(face).copied().unwrap_or(0) as usize;
        if let Some(Some(bound)) = inst.attributes.get(slot) {
            bound.fill_differentials(m, r.tri as usize, c, d, sp);
        }
    }
}

/// Cycles' surface_shader_apply_holdout for a holdout object: keeps only the transparent
/// closures (no emission); false when nothing is transparent and the path ends.
fn holdout_keep_transparent(lobes: &mut LobeSet) -> bool {
    lobes.emission = [0.0; 3];
    if is_zero(lobes.transparent) {
        lobes.len = 0;
        return false;
    }
    let mut k = 0;
    for i in 0..lobes.len {
        if matches!(lobes.lobes[i].kind, LobeKind::Transparent) {
            lobes.lobes[k] = lobes.lobes[i];
            k += 1;
        }
    }
    lobes.len = k;
    true
}

impl Scene<'_> {
    /// The shading context besides position, normals and UV: what the input nodes read
    /// (incoming direction, true normal, barycentrics in Cycles' convention, camera and
    /// window coordinates, object). Path state and ray length are the caller's.
    // The shading state is passed apart, as Cycles passes it to its kernels.
    #[allow(clippy::too_many_arguments)]
    fn fill_context(
        &self,
        sp: &mut ShadingPoint,
        inst: &crate::render::build::MeshInstance,
        wo: V3,
        ng: V3,
        backfacing: bool,
        u: f32,
        v: f32,
    ) {
        sp.incoming = wo;
        sp.true_normal = ng;
        sp.backfacing = backfacing;
        sp.parametric = [u, v];
        sp.camera_position = self.view.camera_space(sp.position);
        sp.camera = self.view.camera();
        sp.window = self.view.window(sp.camera_position);
        sp.object = inst.info;
        sp.path = PathState::CAMERA;
        sp.ray_length = 1.0;
    }

    /// Emission of an emissive triangle for a light sample from a vertex at depth
    /// `bounce`, `dist` away: Cycles evaluates it with only PATH_RAY_EMISSION set (so
    /// Ray Depth reads one more) and the sample distance as the ray length.
    /// The sides of triangle `prim` light sampling draws from: its material's Emission
    /// Sampling (Front, Back, or both for Auto and Front and Back).
    pub(super) fn emission_sides(&self, prim: u32) -> (bool, bool) {
        let r = self.geo.refs[prim as usize];
        match self.geo.instances[r.inst as usize]
            .material_of(r.tri as usize)
            .map(|mi| self.materials[mi].sampling.as_str())
        {
            Some("FRONT") => (true, false),
            Some("BACK") => (false, true),
            _ => (true, true),
        }
    }

    // The shading state is passed apart, as Cycles passes it to its kernels.
    #[allow(clippy::too_many_arguments)]
    pub fn light_emission(
        &self,
        prim: u32,
        u: f32,
        v: f32,
        wo: V3,
        dist: f32,
        bounce: u32,
        scratch: &mut Scratch,
    ) -> V3 {
        let mut hit = self.surface(prim, u, v, wo);
        hit.sp.ray_length = dist;
        hit.sp.path = PathState {
            flags: ray::EMISSION,
            bounce,
            ..PathState::default()
        };
        self.shade_into(
            &hit,
            wo,
            &mut scratch.stacks,
            &mut scratch.light_lobes,
            &NoTrace,
        );
        scratch.light_lobes.emission
    }
}

/// What a path does after the volume segment in front of it.
enum Through {
    /// Go on to the surface hit (or the miss).
    Surface,
    /// Trace again: it scattered, or passed a light inside the volume.
    Again,
    End,
}

impl Scene<'_> {
    /// The volume segment up to the hit at `t_hit` (None: the ray leaves the scene and
    /// crosses the world volume to FLT_MAX), or up to a light inside it, which the path
    /// reaches with the transmittance up to it and then goes past (Cycles' shade_light
    /// continues the path).
    fn through_volumes(
        &self,
        path: &mut Path,
        t_hit: Option<f32>,
        rng: &PixelSampler,
        index: u32,
        scratch: &mut Scratch,
    ) -> Through {
        let st = &self.settings;
        let t_hit_or_escape = t_hit.unwrap_or(crate::render::volume_world::ESCAPE);
        let t_light = self.light_in_segment(path, t_hit_or_escape);
        let t_end = t_light.unwrap_or(t_hit_or_escape);
        // Cycles plays Russian roulette when a ray is cast (integrator_intersect_terminate);
        // inside a volume also for a ray that leaves the scene or meets a light, whose
        // survivor neither the background nor the light divides by its probability. Such
        // paths lose 1 - q of what they bring back: a bias (a darker world-volume scene),
        // which we match.
        let survives = (t_hit.is_some() && t_light.is_none())
            || path
                .continuation(st, rng.get4(index, path.set + 1)[3])
                .is_some();
        match self.volume_segment(path, t_end, rng, index, scratch) {
            super::volume::Segment::Passed if survives => {}
            super::volume::Segment::Passed | super::volume::Segment::Stop => return Through::End,
            super::volume::Segment::Scattered => return Through::Again,
        }
        match t_light {
            Some(t) => {
                let clamp = path.hit_clamp(st);
                self.lights_along(path, Some(t), clamp, scratch);
                self.past_light(path, t);
                Through::Again
            }
            None => Through::Surface,
        }
    }
}
