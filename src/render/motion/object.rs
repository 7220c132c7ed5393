//! Object motion blur as Cycles renders it. An object whose world transform at any motion
//! step differs from the shutter centre's keeps its triangles in object space with its
//! transforms at the steps decomposed (`motion::decompose`); a ray is moved into the
//! object's space at the ray's time (Cycles' bvh_instance_motion_push: the direction is
//! not normalised, so hit distances stay world distances) and the hit is shaded with the
//! transform interpolated at that time. The static rest of the scene stays in one
//! world-space BVH; moving objects are few, so each has its own BVH behind a bound of
//! everywhere it reaches over the shutter, tested in a loop.
//!
//! Deformation motion blur (a mesh that changes within the shutter) is not rendered:
//! meshes are taken at the shutter centre, and a render says so once.

use std::sync::Arc;

use crate::anim::Mat4;
use crate::render::accel::{visibility, Accel, Bvh, Hit};
use crate::render::build::{Geometry, MeshInstance};
use crate::render::math::*;
use crate::render::motion::{decompose, interpolate, Decomposed};

/// The ray time at the shutter's centre, where the scene was synced (and the time of
/// every ray when motion blur is off).
pub const CENTRE_TIME: f32 = 0.5;

/// An instance's object-to-world transforms at the motion steps, evenly spread over the
/// shutter (time 0 at its opening, 1 at its closing).
#[derive(Debug, Clone)]
pub struct ObjectMotion {
    steps: Vec<Decomposed>,
}

impl ObjectMotion {
    /// Object to world at shutter time `time` in [0, 1].
    #[inline]
    pub fn at(&self, time: f32) -> Affine {
        interpolate(&self.steps, time)
    }
}

impl MeshInstance {
    /// Object-to-world and world-to-object at shutter time `time`: the synced transform
    /// for a static instance, the interpolated one for a moving instance.
    #[inline]
    pub fn pose_at(&self, time: f32) -> (Affine, Affine) {
        match &self.motion {
            None => (self.to_world, self.to_object),
            Some(m) => {
                let w = m.at(time);
                // A transform interpolated between invertible steps can only be singular
                // when a scale passes through zero; the synced inverse is then as good.
                (w, w.inverse().unwrap_or(self.to_object))
            }
        }
    }

    /// World-space corners of the instance's triangle `tri` posed by `to_world` (`synced`
    /// is the triangle at the shutter centre, used as it is for a static instance).
    #[inline]
    pub fn posed_triangle(&self, synced: &[V3; 3], tri: u32, to_world: &Affine) -> [V3; 3] {
        if self.motion.is_none() {
            return *synced;
        }
        let m = &self.mesh;
        m.triangles[tri as usize]
            .map(|c| to_world.point(m.positions[m.corner_verts[c as usize] as usize]))
    }
}

fn affine_mul(a: &Affine, b: &Affine) -> Affine {
    let mut o = Affine { m: [[0.0; 4]; 3] };
    for r in 0..3 {
        for c in 0..4 {
            let mut v = a.m[r][0] as f64 * b.m[0][c] as f64
                + a.m[r][1] as f64 * b.m[1][c] as f64
                + a.m[r][2] as f64 * b.m[2][c] as f64;
            if c == 3 {
                v += a.m[r][3] as f64;
            }
            o.m[r][c] = v as f32;
        }
    }
    o
}

/// Cycles' motion step count of an object (BlenderSync::object_motion_steps): none
/// when its motion blur is off, else 2^(motion_steps - 1) * 2 + 1 (the default 1 gives
/// 3), so objects with fewer steps are sampled at a subset of the others' times.
pub fn step_count(obj: &crate::scene::Object) -> usize {
    let get = |k: &str| obj.cycles.as_ref().and_then(|c| c.get(k));
    if get("use_motion_blur").and_then(serde_json::Value::as_bool) == Some(false) {
        return 0;
    }
    let steps = get("motion_steps")
        .and_then(serde_json::Value::as_i64)
        .unwrap_or(1)
        .clamp(1, 7);
    ((2usize << (steps - 1)) + 1).min(MAX_MOTION_STEPS)
}

/// Cycles' Object::MAX_MOTION_STEPS.
const MAX_MOTION_STEPS: usize = 129;

/// The objects' world matrices at the motion steps of the object with the most of
/// them, spread evenly over the shutter in time order (the synced centre among them),
/// as Cycles syncs motion: frame = centre + relative time x shutter / 2. Empty when no
/// rendered mesh object blurs.
pub fn evaluate_steps(
    scene: &crate::scene::Scene,
    centre: &crate::anim::EvaluatedScene,
    shutter: &crate::render::motion::Shutter,
) -> Result<Vec<Vec<Mat4>>, crate::render::RenderError> {
    let n = centre
        .data
        .objects
        .iter()
        .filter(|o| o.kind == "MESH" && !o.hide_render)
        .map(step_count)
        .max()
        .unwrap_or(0);
    if n < 3 {
        return Ok(Vec::new());
    }
    (0..n)
        .map(|k| {
            let rel = 2.0 * k as f64 / (n - 1) as f64 - 1.0;
            if 2 * k == n - 1 {
                return Ok(centre.world_matrices.clone());
            }
            let f = centre.frame + rel * 0.5 * shutter.length;
            crate::anim::evaluate_scene(scene, f)
                .map(|e| e.world_matrices)
                .map_err(|e| {
                    crate::render::RenderError(format!(
                        "evaluating the scene at frame {f} (motion blur): {e}"
                    ))
                })
        })
        .collect()
}

/// Gives every instance whose object moves within the shutter its motion. `steps` holds
/// the objects' world matrices at each motion step in time order (`evaluate_steps`);
/// `centre` those the geometry was built with; `objects` the objects' settings. Returns
/// how many instances move. Cycles keeps an object's motion only when some step
/// differs from the centre.
pub fn attach(
    geo: &mut Geometry,
    objects: &[crate::scene::Object],
    centre: &[Mat4],
    all_steps: &[Vec<Mat4>],
) -> usize {
    if all_steps.len() < 3 {
        return 0;
    }
    let mut moving = 0;
    for inst in geo.instances.iter_mut() {
        let oi = inst.object;
        let Some(count) = objects.get(oi).map(step_count).filter(|&c| c >= 3) else {
            continue;
        };
        // This object's steps are every stride-th of the finest set.
        let stride = (all_steps.len() - 1) / (count - 1);
        let steps: Vec<&Vec<Mat4>> = all_steps.iter().step_by(stride.max(1)).collect();
        if steps.iter().all(|s| s.get(oi) == centre.get(oi)) {
            continue;
        }
        let synced = Affine::from_rows(&centre[oi]);
        // Geometry Nodes instances sit at `local` inside their object; the whole object moves.
        let local = match (inst.instance_index, synced.inverse()) {
            (Some(_), Some(inv)) => Some(affine_mul(&inv, &inst.to_world)),
            _ => None,
        };
        let at_steps: Vec<Affine> = steps
            .iter()
            .map(|s| {
                let w = Affine::from_rows(&s[oi]);
                match &local {
                    Some(l) => affine_mul(&w, l),
                    None => w,
                }
            })
            .collect();
        if at_steps.iter().any(|a| a.inverse().is_none()) {
            // A singular step cannot take rays into object space; render it sharp.
            continue;
        }
        inst.motion = Some(Arc::new(ObjectMotion {
            steps: decompose(&at_steps),
        }));
        moving += 1;
    }
    moving
}

/// One moving instance: its triangles in object space and where it reaches in the world.
struct Mover {
    bvh: Bvh,
    /// Scene triangle index of each of `bvh`'s triangles.
    prims: Vec<u32>,
    motion: Arc<ObjectMotion>,
    lo: V3,
    hi: V3,
    /// The instance's visibility mask (`accel::visibility`).
    mask: u32,
}

/// The two-level structure: static triangles in world space, moving instances each in
/// its own space.
pub struct MotionAccel {
    fixed: Bvh,
    fixed_prims: Vec<u32>,
    movers: Vec<Mover>,
}

impl MotionAccel {
    pub fn build(geo: &Geometry) -> MotionAccel {
        let mut fixed_tris = Vec::new();
        let mut fixed_prims = Vec::new();
        let mut fixed_masks = Vec::new();
        let mut per_inst: Vec<(Vec<[V3; 3]>, Vec<u32>)> = geo
            .instances
            .iter()
            .map(|_| (Vec::new(), Vec::new()))
            .collect();
        for (prim, r) in geo.refs.iter().enumerate() {
            let inst = &geo.instances[r.inst as usize];
            if inst.motion.is_none() {
                fixed_tris.push(geo.tris[prim]);
                fixed_prims.push(prim as u32);
                fixed_masks.push(inst.visibility);
            } else {
                let m = &inst.mesh;
                let tri = m.triangles[r.tri as usize]
                    .map(|c| m.positions[m.corner_verts[c as usize] as usize]);
                per_inst[r.inst as usize].0.push(tri);
                per_inst[r.inst as usize].1.push(prim as u32);
            }
        }
        let mut movers = Vec::new();
        for (inst, (tris, prims)) in geo.instances.iter().zip(per_inst) {
            let Some(motion) = &inst.motion else { continue };
            if tris.is_empty() {
                continue;
            }
            let (mut olo, mut ohi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for t in &tris {
                for p in t {
                    olo = vmin(olo, *p);
                    ohi = vmax(ohi, *p);
                }
            }
            let (lo, hi) = reach_bounds(&motion.steps, olo, ohi);
            movers.push(Mover {
                bvh: Bvh::build(&tris),
                prims,
                motion: motion.clone(),
                lo,
                hi,
                mask: inst.visibility,
            });
        }
        MotionAccel {
            fixed: Bvh::build_masked(&fixed_tris, &fixed_masks),
            fixed_prims,
            movers,
        }
    }

    /// Moving instances (for the render summary and tests).
    pub fn movers(&self) -> usize {
        self.movers.len()
    }
}

/// A world box holding the object-space box (olo, ohi) at every time across the steps.
/// Translation is linear between steps and the rest reaches no farther than at a step,
/// so the steps' translations grown by the largest reach bound it.
fn reach_bounds(steps: &[Decomposed], olo: V3, ohi: V3) -> (V3, V3) {
    let (olo, ohi) = (Vec3::from(olo), Vec3::from(ohi));
    let c = ((olo + ohi) * 0.5).into();
    let r = 0.5 * (ohi - olo).length();
    let reach = steps.iter().map(|s| s.reach(c, r)).fold(0.0f32, f32::max) * (1.0 + 1e-5) + 1e-6;
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for s in steps {
        lo = vmin(lo, s.translation());
        hi = vmax(hi, s.translation());
    }
    (lo.map(|v| v - reach), hi.map(|v| v + reach))
}

/// Whether the ray meets the box within [tmin, tmax].
#[inline]
fn meets_box(lo: V3, hi: V3, org: V3, dir: V3, tmin: f32, tmax: f32) -> bool {
    let (mut t0, mut t1) = (tmin, tmax);
    for a in 0..3 {
        let inv = 1.0 / dir[a];
        let ta = (lo[a] - org[a]) * inv;
        let tb = (hi[a] - org[a]) * inv;
        t0 = t0.max(ta.min(tb));
        t1 = t1.min(ta.max(tb));
    }
    t0 <= t1 * 1.000_000_24
}

impl MotionAccel {
    #[inline]
    fn trace<const ANY: bool>(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        time: f32,
        mask: u32,
    ) -> Option<Hit> {
        let mut best = self
            .fixed
            .intersect_or_occluded::<ANY>(org, dir, tmin, tmax, mask)
            .map(|h| Hit {
                prim: self.fixed_prims[h.prim as usize],
                ..h
            });
        if ANY && best.is_some() {
            return best;
        }
        for mv in &self.movers {
            if mv.mask & mask == 0 {
                continue;
            }
            let tfar = best.map_or(tmax, |h| h.t);
            if !meets_box(mv.lo, mv.hi, org, dir, tmin, tfar) {
                continue;
            }
            let Some(to_object) = mv.motion.at(time).inverse() else {
                continue;
            };
            let (o, d) = (to_object.point(org), to_object.vector(dir));
            if let Some(h) = mv
                .bvh
                .intersect_or_occluded::<ANY>(o, d, tmin, tfar, visibility::ALL)
            {
                best = Some(Hit {
                    prim: mv.prims[h.prim as usize],
                    ..h
                });
                if ANY {
                    return best;
                }
            }
        }
        best
    }
}

impl Accel for MotionAccel {
    fn intersect(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> Option<Hit> {
        self.trace::<false>(org, dir, tmin, tmax, CENTRE_TIME, visibility::ALL)
    }
    fn occluded(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> bool {
        self.trace::<true>(org, dir, tmin, tmax, CENTRE_TIME, visibility::ALL)
            .is_some()
    }
    fn intersect_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32) -> Option<Hit> {
        self.trace::<false>(org, dir, tmin, tmax, time, visibility::ALL)
    }
    fn occluded_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32) -> bool {
        self.trace::<true>(org, dir, tmin, tmax, time, visibility::ALL)
            .is_some()
    }
    fn intersect_vis(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        time: f32,
        mask: u32,
    ) -> Option<Hit> {
        self.trace::<false>(org, dir, tmin, tmax, time, mask)
    }
    fn occluded_vis(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32, mask: u32) -> bool {
        self.trace::<true>(org, dir, tmin, tmax, time, mask)
            .is_some()
    }
}

/// Says once per process that mesh changes within the shutter are not blurred, when
/// motion blur is on and a rendered object's mesh comes from Geometry Nodes (whose
/// output can change over time) with Cycles' deformation blur on.
pub fn warn_deformation(eval: &crate::anim::EvaluatedScene) {
    let deform =
        |o: &crate::scene::Object| crate::scene::settings::ObjectSettings::of(o).use_deform_motion;
    let generated = eval.data.objects.iter().any(|o| {
        o.kind == "MESH"
            && !o.hide_render
            && step_count(o) > 0
            && deform(o)
            && o.modifiers
                .iter()
                .any(|m| m.kind == "NODES" && m.show_render)
    });
    if generated {
        static WARN: std::sync::Once = std::sync::Once::new();
        WARN.call_once(|| eprintln!("warning: motion blur: objects are blurred by their transforms only; deformation motion blur (a mesh that changes within the shutter) is not rendered, meshes are taken at the shutter's centre"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_test_sees_through_the_bound() {
        assert!(meets_box(
            [-1.0; 3],
            [1.0; 3],
            [0.0, 0.0, -5.0],
            [0.0, 0.0, 1.0],
            0.0,
            f32::INFINITY
        ));
        assert!(!meets_box(
            [-1.0; 3],
            [1.0; 3],
            [2.0, 0.0, -5.0],
            [0.0, 0.0, 1.0],
            0.0,
            f32::INFINITY
        ));
        assert!(!meets_box(
            [-1.0; 3],
            [1.0; 3],
            [0.0, 0.0, -5.0],
            [0.0, 0.0, 1.0],
            0.0,
            3.0
        ));
    }

    #[test]
    fn reach_bounds_hold_the_object_at_every_time() {
        // A box off its origin, turning half a turn, growing and moving: its corners at
        // many times between the steps stay inside the bound.
        let step = |a: f32, k: f32, t: V3| {
            let (c, s) = (a.cos(), a.sin());
            Affine {
                m: [
                    [c * k, -s, 0.0, t[0]],
                    [s * k, c, 0.0, t[1]],
                    [0.0, 0.0, 1.0 + 0.5 * k, t[2]],
                ],
            }
        };
        let steps = decompose(&[
            step(0.0, 1.0, [0.0; 3]),
            step(1.6, 2.0, [1.0, 0.5, 0.0]),
            step(3.1, 0.5, [3.0, -1.0, 2.0]),
        ]);
        let (olo, ohi) = ([1.0, 2.0, -0.5], [2.0, 3.0, 0.5]);
        let (lo, hi) = reach_bounds(&steps, olo, ohi);
        for i in 0..=200 {
            let m = interpolate(&steps, i as f32 / 200.0);
            for k in 0..8 {
                let p = m.point([0, 1, 2].map(|a| if k >> a & 1 == 1 { ohi[a] } else { olo[a] }));
                assert!(
                    (0..3).all(|a| p[a] >= lo[a] && p[a] <= hi[a]),
                    "time {}: {p:?} outside {lo:?}..{hi:?}",
                    i as f32 / 200.0
                );
            }
        }
    }
}
