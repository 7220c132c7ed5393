//! The path tracer: next-event estimation toward light objects, BSDF sampling for
//! emissive surfaces and the world, Cycles' per-type bounce limits (terminating after
//! the next surface, as Cycles does), Russian roulette on sqrt of throughput, and
//! Cycles' clamping (direct and indirect limits on the sum of a contribution).

use crate::shader::ShadingPoint;

use super::accel::Accel;
use super::bsdf::{LobeKind, LobeSet};
use super::build::Geometry;
use super::light::Light;
use super::math::*;
use super::sampler::PixelSampler;
use super::shade::{Context, Material};
use super::tables::Tables;

#[derive(Debug, Clone, Copy)]
pub struct Settings {
    pub max_bounces: u32,
    pub max_diffuse: u32,
    pub max_glossy: u32,
    pub max_transmission: u32,
    pub max_transparent: u32,
    pub clamp_direct: f32,
    pub clamp_indirect: f32,
    pub min_light_bounces: u32,
}

pub struct Scene<'a> {
    pub accel: &'a dyn Accel,
    pub geo: &'a Geometry,
    pub materials: &'a [Material],
    pub lights: &'a [Light],
    pub background: V3,
    pub tables: &'a Tables,
    pub settings: Settings,
}

/// Per-thread scratch, reused across samples (no allocation per ray).
pub struct Scratch {
    pub stacks: Vec<Vec<f32>>,
    pub lobes: LobeSet,
    pub rays: u64,
}

impl Scratch {
    pub fn new(n_materials: usize) -> Scratch {
        Scratch { stacks: vec![Vec::new(); n_materials + 1], lobes: LobeSet::default(), rays: 0 }
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
}

fn clamp_contrib(l: V3, limit: f32) -> V3 {
    if limit > 0.0 {
        let s = l[0].abs() + l[1].abs() + l[2].abs();
        if s > limit {
            return scale(l, limit / s);
        }
    }
    l
}

fn finite(v: V3) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl Scene<'_> {
    pub fn surface(&self, prim: u32, u: f32, v: f32, wo: V3) -> SurfaceHit {
        let r = self.geo.refs[prim as usize];
        let inst = &self.geo.instances[r.inst as usize];
        let m = &inst.mesh;
        let c = m.triangles[r.tri as usize].map(|c| c as usize);
        let w0 = 1.0 - u - v;
        let tri = &self.geo.tris[prim as usize];
        let p = add(add(scale(tri[0], w0), scale(tri[1], u)), scale(tri[2], v));
        let mut ng = normalize(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])));
        let lp = c.map(|c| m.positions[m.corner_verts[c] as usize]);
        let local = add(add(scale(lp[0], w0), scale(lp[1], u)), scale(lp[2], v));
        let mut n_obj = if m.corner_normals.len() == m.corner_verts.len() {
            let cn = c.map(|c| m.corner_normals[c]);
            normalize(add(add(scale(cn[0], w0), scale(cn[1], u)), scale(cn[2], v)))
        } else {
            normalize(cross(sub(lp[1], lp[0]), sub(lp[2], lp[0])))
        };
        let mut n = normalize(Affine::normal_by_inverse(&inst.to_object, n_obj));
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
        let mut sp = ShadingPoint::default();
        sp.position = p;
        sp.normal = n;
        sp.object_position = local;
        sp.object_normal = n_obj;
        sp.generated = [0, 1, 2].map(|k| (local[k] - inst.tex_loc[k]) / (2.0 * inst.tex_size[k]) + 0.5);
        if let Some(uv) = &inst.uv {
            let t = c.map(|c| uv[c]);
            sp.uv = [t[0][0] * w0 + t[1][0] * u + t[2][0] * v, t[0][1] * w0 + t[1][1] * u + t[2][1] * v, 0.0];
        }
        SurfaceHit { p, ng, sp, inst: r.inst, material, backfacing }
    }

    pub fn shade(&self, hit: &SurfaceHit, wo: V3, scratch: &mut Scratch) {
        let ctx = Context { tables: self.tables, wo };
        match hit.material {
            Some(mi) => {
                let (stacks, lobes) = (&mut scratch.stacks, &mut scratch.lobes);
                self.materials[mi].shade(&hit.sp, &mut stacks[mi], &ctx, lobes)
            }
            None => {
                scratch.lobes.clear();
                scratch.lobes.push(LobeKind::Diffuse, [0.8; 3], hit.sp.normal);
            }
        }
    }

    /// One path sample: radiance along the camera ray.
    pub fn radiance(&self, org: V3, dir: V3, tmin: f32, tmax: f32, rng: &PixelSampler, index: u32, scratch: &mut Scratch) -> V3 {
        let st = &self.settings;
        let mut l = [0.0f32; 3];
        let mut throughput = [1.0f32; 3];
        let (mut o, mut d, mut t0, mut t1) = (org, dir, tmin, tmax);
        let (mut bounce, mut diffuse, mut glossy, mut transmission, mut transparent) = (0u32, 0u32, 0u32, 0u32, 0u32);
        let mut terminate_next = false;
        let mut set = 1u32;
        loop {
            scratch.rays += 1;
            let Some(h) = self.accel.intersect(o, d, t0, t1) else {
                let c = clamp_contrib(mul(throughput, self.background), if bounce == 0 { st.clamp_direct } else { st.clamp_indirect });
                if finite(c) {
                    l = add(l, c);
                }
                break;
            };
            let wo = neg(d);
            let hit = self.surface(h.prim, h.u, h.v, wo);
            self.shade(&hit, wo, scratch);
            let lobes = &scratch.lobes;
            if !is_zero(lobes.emission) {
                let c = clamp_contrib(mul(throughput, lobes.emission), if bounce == 0 { st.clamp_direct } else { st.clamp_indirect });
                if finite(c) {
                    l = add(l, c);
                }
            }
            let u_bsdf = rng.get4(index, set);
            let u_light = rng.get4(index, set + 1);
            set += 2;
            if terminate_next {
                // Only transparent surfaces let such a path continue (Cycles'
                // TERMINATE_AFTER_TRANSPARENT).
                if is_zero(lobes.transparent) {
                    break;
                }
            }
            // Russian roulette, as Cycles: none up to the minimum bounce, then sqrt of throughput.
            if bounce > st.min_light_bounces {
                let q = max3(throughput.map(f32::abs)).sqrt().min(1.0);
                if q <= 0.0 || u_light[3] >= q {
                    break;
                }
                throughput = scale(throughput, 1.0 / q);
            }
            let p_off = |dir: V3| {
                let eps = 1e-5 * (1.0 + max3(hit.p.map(f32::abs)));
                if dot(dir, hit.ng) >= 0.0 {
                    madd(hit.p, hit.ng, eps)
                } else {
                    madd(hit.p, hit.ng, -eps)
                }
            };
            // Next-event estimation toward every light.
            if !terminate_next && lobes.len > 0 {
                for (li, light) in self.lights.iter().enumerate() {
                    let uu = if li == 0 { [u_light[0], u_light[1]] } else { let r = rng.get4(index, 0x4000_0000 + set * 64 + li as u32); [r[0], r[1]] };
                    let Some(ls) = light.sample(hit.p, uu) else { continue };
                    let (f, _pdf) = lobes.eval(wo, ls.wi, hit.ng, self.tables);
                    if is_zero(f) {
                        continue;
                    }
                    let c = mul(mul(throughput, f), ls.value);
                    if is_zero(c) || !finite(c) {
                        continue;
                    }
                    let start = p_off(ls.wi);
                    scratch.rays += 1;
                    if light.cast_shadow && self.accel.occluded(start, ls.wi, 0.0, if ls.dist.is_finite() { ls.dist * (1.0 - 1e-4) } else { f32::INFINITY }) {
                        continue;
                    }
                    l = add(l, clamp_contrib(c, if bounce == 0 { st.clamp_direct } else { st.clamp_indirect }));
                }
            }
            if terminate_next && !is_zero(lobes.transparent) {
                // Only continue through the transparent part.
            }
            let Some(bs) = lobes.sample(wo, hit.ng, [u_bsdf[0], u_bsdf[1], u_bsdf[2]], self.tables) else { break };
            if !finite(bs.weight) || is_zero(bs.weight) {
                break;
            }
            if terminate_next && !matches!(bs.kind, LobeKind::Transparent) {
                break;
            }
            throughput = mul(throughput, bs.weight);
            match bs.kind {
                LobeKind::Transparent => {
                    transparent += 1;
                    if transparent > st.max_transparent {
                        break;
                    }
                    // Transparent bounces keep the bounce count and continue from the hit.
                    o = p_off(d);
                    t0 = 0.0;
                    t1 = f32::INFINITY;
                    continue;
                }
                LobeKind::Diffuse => {
                    if diffuse >= st.max_diffuse {
                        terminate_next = true;
                    }
                    diffuse += 1;
                }
                LobeKind::Translucent => {
                    if diffuse >= st.max_diffuse {
                        terminate_next = true;
                    }
                    diffuse += 1;
                }
                LobeKind::Glossy { .. } => {
                    if glossy >= st.max_glossy {
                        terminate_next = true;
                    }
                    glossy += 1;
                }
            }
            let _ = &mut transmission;
            if bounce >= st.max_bounces {
                terminate_next = true;
            }
            bounce += 1;
            o = p_off(bs.wi);
            d = bs.wi;
            t0 = 0.0;
            t1 = f32::INFINITY;
        }
        l
    }
}
