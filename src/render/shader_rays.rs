//! The renderer's answer to a shader's ray queries (`shader::trace::Trace`): Cycles'
//! Ambient Occlusion (svm/ao.h) and Bevel (svm/bevel.h) traced against the scene from
//! the point being shaded. Cycles draws each node's samples as branches of the pixel
//! sample (`path_branched_rng_2D`); here sample `k` of `n` is point `index * n + k` of
//! the vertex's free sampler set (Bevel's set apart from AO's), which the index scramble
//! keeps stratified per pixel sample when `n` is a power of two.

use std::cell::Cell;
use std::sync::OnceLock;

use crate::foundation::bvh::{Accel, Bvh};

use crate::shader::trace::Trace;
use crate::shader::ShadingPoint;

use super::accel::visibility;
use super::build::Geometry;
use super::integrator::{Scene, SurfaceHit};
use super::math::*;
use super::sampler::{hash_combine, PixelSampler};
use super::subsurface::disk::ProbeAxis;

/// Cycles' LOCAL_MAX_HITS: the Bevel probe keeps a random subset of this many hits.
const LOCAL_MAX_HITS: usize = 4;
/// Hits walked along one probe ray before the rest are ignored (a bound on the work a
/// degenerate mesh can cause; Cycles' local intersection has none).
const MAX_PROBE_HITS: u32 = 256;
/// Bevel's sampler set beside AO's (both from the vertex's free set).
const BEVEL_SET: u32 = 0x4000_0000;
/// Cycles skips Bevel on rays whose path went through a blurry bounce (svm_bevel:
/// `min_ray_pdf < 8`).
const BEVEL_MIN_RAY_PDF: f32 = 8.0;

/// Each object's own BVH, built when a shader first asks for it: Cycles' local
/// intersection (Bevel, AO Only Local) traverses the shaded object alone, so another
/// object's face lying on it (a cube resting on a floor) cannot hide its faces.
pub struct LocalAccels {
    per_instance: Vec<OnceLock<Option<LocalBvh>>>,
}

struct LocalBvh {
    bvh: Bvh,
    /// The scene primitive of each of its triangles.
    prims: Vec<u32>,
}

impl LocalAccels {
    pub fn new(geo: &Geometry) -> LocalAccels {
        LocalAccels {
            per_instance: (0..geo.instances.len()).map(|_| OnceLock::new()).collect(),
        }
    }

    /// The instance's BVH; None for a moving object (its triangles move with the ray's
    /// time: the scene's BVH is walked instead).
    fn get(&self, geo: &Geometry, inst: u32) -> Option<&LocalBvh> {
        self.per_instance
            .get(inst as usize)?
            .get_or_init(|| {
                if geo.instances[inst as usize].motion.is_some() {
                    return None;
                }
                let prims: Vec<u32> = (0..geo.refs.len() as u32)
                    .filter(|&p| geo.refs[p as usize].inst == inst)
                    .collect();
                let tris: Vec<[V3; 3]> = prims.iter().map(|&p| geo.tris[p as usize]).collect();
                Some(LocalBvh {
                    bvh: Bvh::build(&tris),
                    prims,
                })
            })
            .as_ref()
    }
}

/// A hit on the shaded object: its scene primitive, barycentrics and distance.
#[derive(Clone, Copy)]
struct LocalHit {
    prim: u32,
    u: f32,
    v: f32,
    t: f32,
}

/// Ray queries from one shaded surface point of a path.
pub struct ShaderRays<'a, 's> {
    pub scene: &'a Scene<'s>,
    pub hit: &'a SurfaceHit,
    pub rng: &'a PixelSampler,
    /// The pixel sample and the vertex's free sampler set (`Path::set + 2`).
    pub index: u32,
    pub set: u32,
    /// The path's smallest non-singular bounce pdf (Cycles' min_ray_pdf).
    pub min_ray_pdf: f32,
    /// Rays traced, for the render's statistics.
    pub rays: Cell<u64>,
}

impl ShaderRays<'_, '_> {
    /// Branch `k` of `n` of the node's 2D sample (`set` apart per node type): dimensions
    /// 0 and 1, the pair the Sobol sequence stratifies best.
    fn sample(&self, k: u32, n: u32, set: u32) -> [f32; 2] {
        let u = self
            .rng
            .get4(self.index.wrapping_mul(n).wrapping_add(k), set);
        [u[0], u[1]]
    }

    /// Calls `each` with the shaded object's hits along the ray before `tmax`, nearest
    /// first, until it returns false (Cycles' scene_intersect_local: other objects are
    /// not seen).
    fn local_hits(&self, o: V3, d: V3, tmax: f32, mut each: impl FnMut(LocalHit) -> bool) {
        let geo = self.scene.geo;
        let local = self.scene.local.get(geo, self.hit.inst);
        let mut tmin = 0.0f32;
        for _ in 0..MAX_PROBE_HITS {
            self.rays.set(self.rays.get() + 1);
            let found = match local {
                Some(l) => l.bvh.intersect(o, d, tmin, tmax).map(|x| LocalHit {
                    prim: l.prims[x.prim as usize],
                    u: x.u,
                    v: x.v,
                    t: x.t,
                }),
                None => self
                    .scene
                    .accel
                    .intersect_at(o, d, tmin, tmax, self.hit.time)
                    .map(|x| LocalHit {
                        prim: x.prim,
                        u: x.u,
                        v: x.v,
                        t: x.t,
                    }),
            };
            let Some(x) = found else { return };
            tmin = x.t * (1.0 + 1e-6) + 1e-7;
            if geo.refs[x.prim as usize].inst == self.hit.inst && !each(x) {
                return;
            }
        }
    }

    fn local_blocked(&self, o: V3, d: V3, tmax: f32) -> bool {
        let mut blocked = false;
        self.local_hits(o, d, tmax, |_| {
            blocked = true;
            false
        });
        blocked
    }
}

impl Trace for ShaderRays<'_, '_> {
    fn ambient_occlusion(
        &self,
        sp: &ShadingPoint,
        n: V3,
        max_dist: f32,
        samples: u32,
        only_local: bool,
    ) -> f32 {
        let n = Vec3::from(n);
        let (t, b) = n.basis();
        let mut unoccluded = 0u32;
        for k in 0..samples {
            let u = self.sample(k, samples, self.set);
            // Cosine-weighted about n: a uniform disk point lifted to the hemisphere.
            let d = super::camera::concentric_disk([u[0], u[1]]);
            let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
            let dir: V3 = (t * d[0] + b * d[1] + n * z).normalize().into();
            // Off the shaded triangle on the ray's side (Cycles skips its own primitive).
            let o = offset_origin(sp.position, self.hit.ng, dir);
            let blocked = if only_local {
                self.local_blocked(o, dir, max_dist)
            } else {
                self.rays.set(self.rays.get() + 1);
                self.scene.accel.occluded_vis(
                    o,
                    dir,
                    0.0,
                    max_dist,
                    self.hit.time,
                    visibility::SHADOW,
                )
            };
            if !blocked {
                unoccluded += 1;
            }
        }
        unoccluded as f32 / samples as f32
    }

    fn bevel(&self, sp: &ShadingPoint, radius: f32, samples: u32) -> V3 {
        if self.min_ray_pdf < BEVEL_MIN_RAY_PDF {
            return sp.normal;
        }
        let mut sum = Vec3::ZERO;
        for k in 0..samples {
            let u = self.sample(k, samples, self.set ^ BEVEL_SET);
            let (xi_axis, xi_r) = (u[0], u[1]);
            // A disk about the geometric normal half the time, each tangent a quarter.
            let (axis, xi_phi) = ProbeAxis::pick(self.hit.ng, xi_axis);
            let (disk_r, height) = cubic_sample(radius, xi_r);
            let o = axis.origin(sp.position, xi_phi, disk_r, height);
            let dir: V3 = (-Vec3::from(axis.n)).into();
            let tmax = 2.0 * height;
            // Every hit on the shaded object along the probe; a uniformly random subset
            // of LOCAL_MAX_HITS kept (reservoir sampling, as Cycles' local intersection).
            let mut kept = [LocalHit {
                prim: 0,
                u: 0.0,
                v: 0.0,
                t: 0.0,
            }; LOCAL_MAX_HITS];
            let mut found = 0u32;
            let mut state = hash_combine(self.index, hash_combine(self.set, k ^ 0x64c6_a40e));
            self.local_hits(o, dir, tmax, |h| {
                if (found as usize) < LOCAL_MAX_HITS {
                    kept[found as usize] = h;
                } else {
                    state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    let j = ((state as u64 * (found as u64 + 1)) >> 32) as usize;
                    if j < LOCAL_MAX_HITS {
                        kept[j] = h;
                    }
                }
                found += 1;
                true
            });
            let n_kept = (found as usize).min(LOCAL_MAX_HITS);
            let disk_pdf = cubic_pdf(radius, disk_r);
            for h in &kept[..n_kept] {
                let s = self.scene.surface_at(
                    h.prim,
                    h.u,
                    h.v,
                    (-Vec3::from(dir)).into(),
                    self.hit.time,
                );
                // The hit's own normals, not turned toward the probe.
                let (ng, n) = (Vec3::from(s.ng), Vec3::from(s.sp.normal));
                let (ng, n) = if s.backfacing { (-ng, -n) } else { (ng, n) };
                let (pn, denom) = axis.mis(ng.into());
                if !(denom > 0.0) || !(disk_pdf > 0.0) {
                    continue;
                }
                let mut w = pn / denom;
                if found as usize > LOCAL_MAX_HITS {
                    w *= found as f32 / LOCAL_MAX_HITS as f32;
                }
                let r = (Vec3::from(s.p) - sp.position.into()).length();
                w *= cubic_pdf(radius, r) / disk_pdf;
                sum += n * w;
            }
        }
        let l = sum.length();
        if !(l > 0.0) || !l.is_finite() {
            return sp.normal;
        }
        let n = sum * (1.0 / l);
        if self.hit.backfacing {
            (-n).into()
        } else {
            n.into()
        }
    }
}

/// Cycles' planar cubic falloff (svm_bevel_cubic_eval): 10 (R - r)^3 / (pi R^5), which
/// integrates to 1 over the disk of radius R. Also the sampling pdf.
fn cubic_pdf(radius: f32, r: f32) -> f32 {
    if r >= radius {
        return 0.0;
    }
    let r5 = radius * radius * radius * radius * radius;
    let f = radius - r;
    10.0 * f * f * f / (r5 * std::f32::consts::PI)
}

/// A disk radius with density `cubic_pdf` (the quintic CDF 10x^2 - 20x^3 + 15x^4 - 4x^5
/// inverted by Newton's method as Cycles does), and the height of the sphere of radius
/// `radius` above it.
fn cubic_sample(radius: f32, xi: f32) -> (f32, f32) {
    let mut x = 0.25f32;
    for _ in 0..10 {
        let x2 = x * x;
        let x3 = x2 * x;
        let nx = 1.0 - x;
        let f = 10.0 * x2 - 20.0 * x3 + 15.0 * x2 * x2 - 4.0 * x2 * x3 - xi;
        let df = 20.0 * (x * nx) * (nx * nx);
        if f.abs() < 1e-6 || df == 0.0 {
            break;
        }
        x = (x - f / df).clamp(0.0, 1.0);
    }
    let r = x * radius;
    (r, (radius * radius - r * r).max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sampled radii follow the cubic pdf: the fraction below R/2 is the CDF there,
    /// 10/4 - 20/8 + 15/16 - 4/32 = 0.8125.
    #[test]
    fn cubic_sampling_inverts_its_cdf() {
        let n = 4096;
        let below = (0..n)
            .filter(|i| cubic_sample(2.0, (*i as f32 + 0.5) / n as f32).0 < 1.0)
            .count();
        assert!((below as f32 / n as f32 - 0.8125).abs() < 1e-3, "{below}");
        // The pdf integrates to 1 over the disk.
        let steps = 10000;
        let total: f32 = (0..steps)
            .map(|i| {
                let r = (i as f32 + 0.5) / steps as f32 * 2.0;
                cubic_pdf(2.0, r) * std::f32::consts::TAU * r * (2.0 / steps as f32)
            })
            .sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
    }
}
