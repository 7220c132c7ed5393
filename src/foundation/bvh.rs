//! Ray queries behind one trait, with a binned-SAH BVH over world-space triangles as the
//! default implementation and a watertight ray/triangle test (Woop, Benthin, Wald 2013),
//! so rays through shared edges and vertices never slip between triangles.

use super::box_tree::{BoxTree, Node, PAR_MIN};
use super::math::*;
use rayon::prelude::*;

/// A ray hit: distance, triangle (index into the scene's triangle list) and barycentrics
/// (`u` weights vertex 1, `v` vertex 2).
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
    pub u: f32,
    pub v: f32,
}

/// What the integrator needs from an acceleration structure.
pub trait Accel: Sync {
    fn intersect(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> Option<Hit>;
    fn occluded(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> bool;
    /// `intersect` at shutter time `time` in [0, 1] (only moving objects care).
    fn intersect_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, _time: f32) -> Option<Hit> {
        self.intersect(org, dir, tmin, tmax)
    }
    /// `occluded` at shutter time `time` in [0, 1].
    fn occluded_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, _time: f32) -> bool {
        self.occluded(org, dir, tmin, tmax)
    }
    /// `intersect_at` seeing only objects visible to a ray of visibility `mask` (Cycles'
    /// ray visibility: `ray::` bits, see `visibility`); others are passed through, as
    /// Cycles' BVH skips primitives whose visibility lacks the ray's. The default ignores
    /// the mask (every object visible to every ray).
    fn intersect_vis(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        time: f32,
        _mask: u32,
    ) -> Option<Hit> {
        self.intersect_at(org, dir, tmin, tmax, time)
    }
    /// `occluded_at` by objects visible to a ray of visibility `mask`.
    fn occluded_vis(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32, _mask: u32) -> bool {
        self.occluded_at(org, dir, tmin, tmax, time)
    }
    /// The nearest hit beyond 0 of a ray that starts on triangle `skip` and passes it:
    /// `intersect_at` from 0 and, when that finds `skip`, again from just past it (the
    /// subsurface walk's first ray). Returns the hit and whether `skip` came first (the
    /// definition's second query was needed).
    fn intersect_past(
        &self,
        org: V3,
        dir: V3,
        tmax: f32,
        time: f32,
        skip: u32,
    ) -> (Option<Hit>, bool) {
        let h = self.intersect_at(org, dir, 0.0, tmax, time);
        match h {
            Some(s) if s.prim == skip => {
                (self.intersect_at(org, dir, s.t.next_up(), tmax, time), true)
            }
            _ => (h, false),
        }
    }
}

/// Visibility masks: an object's is the `ray::` bits of the rays that see it, a ray's the
/// bits of its type; the object is hit when they share a bit (Cycles' PATH_RAY_* masks).
pub mod visibility {
    use crate::foundation::ray;

    /// Every ray type an object can be hidden from.
    pub const ALL: u32 = ray::CAMERA
        | ray::DIFFUSE
        | ray::GLOSSY
        | ray::TRANSMIT
        | ray::SHADOW
        | ray::VOLUME_SCATTER;

    /// The mask of a shadow ray (next-event estimation).
    pub const SHADOW: u32 = ray::SHADOW;

    /// A camera or bounce ray's mask from its path flags, as Cycles'
    /// path_state_ray_visibility: diffuse and glossy count for reflection only, so a
    /// transmitted ray is seen by objects visible to transmission.
    #[inline]
    pub fn of_path(flags: u32) -> u32 {
        let mut v = flags
            & (ray::CAMERA | ray::DIFFUSE | ray::GLOSSY | ray::TRANSMIT | ray::VOLUME_SCATTER);
        if v & ray::TRANSMIT != 0 {
            v &= !(ray::DIFFUSE | ray::GLOSSY);
        }
        if flags & ray::VOLUME_SCATTER != 0 {
            v |= ray::DIFFUSE;
        }
        v
    }
}

/// Which acceleration structure renders build: the 4-wide BVH (`bvh4`, the default, the
/// faster one measured in docs/speed.md), the binary one (`bvh2`) or Embree's (`embree`,
/// when `libembree3.so.3` is installed: `foundation/embree.rs`). All return the same hits,
/// so images are identical; `BLENDSYNTH_ACCEL` chooses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Backend {
    Binary,
    Wide4,
    Embree,
}

impl Backend {
    pub const DEFAULT: Backend = Backend::Wide4;

    /// `BLENDSYNTH_ACCEL` (`bvh4`, `bvh2` or `embree`), or the default when it is unset or
    /// empty; `embree` is an error naming the library where Embree cannot be loaded.
    pub fn from_env() -> Result<Backend, String> {
        match std::env::var("BLENDSYNTH_ACCEL") {
            Ok(v) => Backend::parse(&v),
            Err(_) => Ok(Backend::DEFAULT),
        }
    }

    pub fn parse(name: &str) -> Result<Backend, String> {
        match name.trim() {
            "" => Ok(Backend::DEFAULT),
            "bvh4" => Ok(Backend::Wide4),
            "bvh2" => Ok(Backend::Binary),
            "embree" => match super::embree::available() {
                Ok(()) => Ok(Backend::Embree),
                Err(e) => Err(format!("BLENDSYNTH_ACCEL=embree: {e}")),
            },
            other => Err(format!(
                "BLENDSYNTH_ACCEL={other:?} is not a ray acceleration backend (bvh4, bvh2 or embree)"
            )),
        }
    }

    /// The structure over `tris` with visibility `masks` (as `Bvh::build_masked`); only
    /// Embree's can fail (its error names the library).
    pub fn build_masked(self, tris: &[[V3; 3]], masks: &[u32]) -> Result<Box<dyn Accel>, String> {
        Ok(match self {
            Backend::Binary => Box::new(Bvh::build_masked(tris, masks)),
            Backend::Wide4 => Box::new(super::bvh4::Bvh4::build_masked(tris, masks)),
            Backend::Embree => Box::new(super::embree::EmbreeAccel::build_masked(tris, masks)?),
        })
    }
}

pub struct Bvh {
    /// The tree over the triangles' boxes (`box_tree`, binned SAH).
    pub(super) tree: BoxTree,
    /// Triangles in leaf order (`tree.ids` holds their index in the caller's list).
    pub(super) tris: Vec<[V3; 3]>,
    /// Per triangle in leaf order: the visibility mask of its object; empty when every
    /// triangle is visible to every ray (then no test is made).
    pub(super) masks: Vec<u32>,
}

impl Bvh {
    /// A BVH whose triangle `i` is seen only by rays sharing a bit with `masks[i]`
    /// (`visibility`); `masks` empty, or every mask `visibility::ALL`, means all visible.
    /// The render's structures are built this way, with the full SAH sweep when small
    /// (`box_tree::SWEEP_MAX`); `build` (a node's or a shader's ray queries, built per
    /// evaluation) keeps the binned build's set-up.
    pub fn build_masked(tris: &[[V3; 3]], masks: &[u32]) -> Bvh {
        let mut bvh = Bvh::build_split_from(tris, PAR_MIN, true);
        if masks.len() == tris.len()
            && masks
                .iter()
                .any(|&m| m & visibility::ALL != visibility::ALL)
        {
            bvh.masks = bvh.tree.ids.iter().map(|&i| masks[i as usize]).collect();
        }
        bvh
    }

    pub fn build(tris: &[[V3; 3]]) -> Bvh {
        Bvh::build_split_from(tris, PAR_MIN, false)
    }

    /// The build, with subtrees of at least `par_min` triangles split on rayon's threads
    /// (`BoxTree::build_sah`: the same tree at any thread count).
    fn build_split_from(tris: &[[V3; 3]], par_min: usize, sweep: bool) -> Bvh {
        let tree = BoxTree::build_sah(
            tris.len(),
            |i| {
                let t = &tris[i];
                (vmin(vmin(t[0], t[1]), t[2]), vmax(vmax(t[0], t[1]), t[2]))
            },
            par_min,
            sweep,
        );
        let tris_sorted = tree.ids.par_iter().map(|&i| tris[i as usize]).collect();
        Bvh {
            tree,
            tris: tris_sorted,
            masks: Vec::new(),
        }
    }

    #[inline(always)]
    fn traverse<const ANY: bool>(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        mask: u32,
    ) -> Option<Hit> {
        if self.tris.is_empty() {
            return None;
        }
        // Only a scene with hidden objects and a ray some of them hide from tests masks.
        let filter = self.filters(mask);
        let inv = [1.0 / dir[0], 1.0 / dir[1], 1.0 / dir[2]];
        let wt = Watertight::new(dir);
        let mut best: Option<Hit> = None;
        let mut tfar = tmax;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut ni = 0u32;
        loop {
            let node = &self.tree.nodes[ni as usize];
            if node.count > 0 {
                let range = node.start..node.start + node.count;
                if self.leaf::<ANY>(range, &wt, org, tmin, &mut tfar, &mut best, filter, mask)
                    && ANY
                {
                    return best;
                }
            } else {
                let l = &self.tree.nodes[node.start as usize];
                let r = &self.tree.nodes[node.start as usize + 1];
                let tl = slab(l, org, inv, tmin, tfar);
                let tr = slab(r, org, inv, tmin, tfar);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b {
                            (node.start, node.start + 1)
                        } else {
                            (node.start + 1, node.start)
                        };
                        if sp < 64 {
                            stack[sp] = far;
                            sp += 1;
                        }
                        ni = near;
                        continue;
                    }
                    (Some(_), None) => {
                        ni = node.start;
                        continue;
                    }
                    (None, Some(_)) => {
                        ni = node.start + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            ni = stack[sp];
        }
        best
    }
}

impl Bvh {
    /// Tests the triangles `range` (leaf order) and keeps the nearest hit in `best`
    /// (`tfar` its distance); true when one was found. A hit at exactly `tfar` replaces
    /// the best when its triangle comes first in the caller's list, so the nearest hit is
    /// the least (t, prim) whatever order a structure visits its leaves in: every backend
    /// (`Bvh`, `Bvh4`) returns the same hit, and images are identical.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn leaf<const ANY: bool>(
        &self,
        range: std::ops::Range<u32>,
        wt: &Watertight,
        org: V3,
        tmin: f32,
        tfar: &mut f32,
        best: &mut Option<Hit>,
        filter: bool,
        mask: u32,
    ) -> bool {
        let mut found = false;
        for i in range {
            if filter && self.masks[i as usize] & mask == 0 {
                continue;
            }
            if let Some((t, u, v)) = wt.intersect(org, &self.tris[i as usize], tmin, *tfar) {
                let prim = self.tree.ids[i as usize];
                if t == *tfar && best.is_none_or(|b| prim > b.prim) {
                    continue;
                }
                *tfar = t;
                *best = Some(Hit { t, prim, u, v });
                found = true;
                if ANY {
                    return true;
                }
            }
        }
        found
    }

    /// Whether a ray of visibility `mask` must test triangles' masks.
    #[inline(always)]
    pub(super) fn filters(&self, mask: u32) -> bool {
        !self.masks.is_empty() && mask & visibility::ALL != visibility::ALL
    }
}

/// `Accel` for a BVH with `traverse::<ANY_HIT>(org, dir, tmin, tmax, mask)`: both BVH
/// layouts answer every query by it (static geometry: the shutter time is ignored).
macro_rules! accel_by_traverse {
    ($t:ty) => {
        $crate::foundation::bvh::accel_by_traverse!($t, {});
    };
    ($t:ty, { $($extra:item)* }) => {
        impl $crate::foundation::bvh::Accel for $t {
            $($extra)*
            fn intersect(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> Option<Hit> {
                self.traverse::<false>(
                    org,
                    dir,
                    tmin,
                    tmax,
                    $crate::foundation::bvh::visibility::ALL,
                )
            }
            fn occluded(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> bool {
                self.traverse::<true>(
                    org,
                    dir,
                    tmin,
                    tmax,
                    $crate::foundation::bvh::visibility::ALL,
                )
                .is_some()
            }
            fn intersect_vis(
                &self,
                org: V3,
                dir: V3,
                tmin: f32,
                tmax: f32,
                _time: f32,
                mask: u32,
            ) -> Option<Hit> {
                self.traverse::<false>(org, dir, tmin, tmax, mask)
            }
            fn occluded_vis(
                &self,
                org: V3,
                dir: V3,
                tmin: f32,
                tmax: f32,
                _time: f32,
                mask: u32,
            ) -> bool {
                self.traverse::<true>(org, dir, tmin, tmax, mask).is_some()
            }
        }
    };
    // With the layout's own `intersect_past` (one traversal that passes the triangle).
    ($t:ty, past) => {
        $crate::foundation::bvh::accel_by_traverse!($t, {
            fn intersect_past(
                &self,
                org: V3,
                dir: V3,
                tmax: f32,
                _time: f32,
                skip: u32,
            ) -> (Option<Hit>, bool) {
                <$t>::intersect_past(self, org, dir, tmax, skip)
            }
        });
    };
}
pub(crate) use accel_by_traverse;

accel_by_traverse!(Bvh);

#[inline(always)]
fn slab(n: &Node, org: V3, inv: V3, tmin: f32, tmax: f32) -> Option<f32> {
    let mut t0 = tmin;
    let mut t1 = tmax;
    for a in 0..3 {
        let ta = (n.min[a] - org[a]) * inv[a];
        let tb = (n.max[a] - org[a]) * inv[a];
        // The near plane by the direction's sign; a NaN distance (0 * inf: the origin on
        // the plane of an axis the ray is parallel to) is ignored by max/min, so such a
        // grazing ray still enters the box (the 4-wide BVH's test does the same).
        let (near, far) = if inv[a] < 0.0 { (tb, ta) } else { (ta, tb) };
        t0 = t0.max(near);
        t1 = t1.min(far);
    }
    // Robust slab test: widen slightly for rounding (Ize 2013).
    if t0 <= t1 * 1.000_000_24 {
        Some(t0)
    } else {
        None
    }
}

/// Per-ray precomputation of the watertight test.
pub(super) struct Watertight {
    pub(super) kx: usize,
    pub(super) ky: usize,
    pub(super) kz: usize,
    pub(super) sx: f32,
    pub(super) sy: f32,
    pub(super) sz: f32,
}

impl Watertight {
    #[inline(always)]
    pub(super) fn new(dir: V3) -> Watertight {
        let a = [dir[0].abs(), dir[1].abs(), dir[2].abs()];
        let kz = if a[0] > a[1] {
            if a[0] > a[2] {
                0
            } else {
                2
            }
        } else if a[1] > a[2] {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        Watertight {
            kx,
            ky,
            kz,
            sx: dir[kx] / dir[kz],
            sy: dir[ky] / dir[kz],
            sz: 1.0 / dir[kz],
        }
    }

    #[inline(always)]
    pub(super) fn intersect(
        &self,
        org: V3,
        tri: &[V3; 3],
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32, f32)> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = sub(tri[0], org);
        let b = sub(tri[1], org);
        let c = sub(tri[2], org);
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Edge cases in double precision, as the paper does.
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let t = u * az + v * bz + w * cz;
        let inv = 1.0 / det;
        let t = t * inv;
        // Up to tmax inclusive: `Bvh::leaf` decides a tie at the best distance so far
        // (with no hit yet, tmax itself is excluded there).
        if !(t > tmin && t <= tmax) {
            return None;
        }
        // u weights vertex 0, v vertex 1, w vertex 2 here.
        Some((t, v * inv, w * inv))
    }
}

impl Bvh {
    /// The nearest hit (`ANY` false) or any hit (`ANY` true), for structures built of BVHs.
    #[inline(always)]
    pub fn intersect_or_occluded<const ANY: bool>(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        mask: u32,
    ) -> Option<Hit> {
        self.traverse::<ANY>(org, dir, tmin, tmax, mask)
    }
}

#[cfg(test)]
mod tests {
    use super::super::box_tree::{area, BINS, MAX_LEAF};
    use super::*;

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles of a quad; rays through the diagonal must hit one of them.
        let tris = vec![
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        ];
        let bvh = Bvh::build(&tris);
        for i in 0..1000 {
            let s = i as f32 / 1000.0;
            assert!(
                bvh.intersect([s, s, 1.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY)
                    .is_some(),
                "miss at {s}"
            );
        }
    }

    #[test]
    fn masked_triangles_are_passed_through() {
        use crate::foundation::ray;
        // Two stacked quads' worth of triangles: the near one hidden from the camera and
        // shadow rays, the far one visible to all.
        let near = [[-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [0.0, 1.0, 1.0]];
        let far = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
        let bvh = Bvh::build_masked(
            &[near, far],
            &[
                visibility::ALL & !(ray::CAMERA | ray::SHADOW),
                visibility::ALL,
            ],
        );
        let (o, d) = ([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]);
        let cam = bvh
            .intersect_vis(
                o,
                d,
                0.0,
                f32::INFINITY,
                0.5,
                visibility::of_path(ray::CAMERA),
            )
            .unwrap();
        assert_eq!(cam.prim, 1);
        assert!((cam.t - 5.0).abs() < 1e-5);
        let diffuse = bvh
            .intersect_vis(
                o,
                d,
                0.0,
                f32::INFINITY,
                0.5,
                visibility::of_path(ray::DIFFUSE | ray::REFLECT),
            )
            .unwrap();
        assert_eq!(diffuse.prim, 0);
        assert!(!bvh.occluded_vis(o, d, 0.0, 4.5, 0.5, visibility::SHADOW));
        assert!(bvh.occluded_vis(
            o,
            d,
            0.0,
            4.5,
            0.5,
            visibility::of_path(ray::GLOSSY | ray::REFLECT)
        ));
        // A transmitted glossy ray is seen as transmission only.
        assert_eq!(
            visibility::of_path(ray::GLOSSY | ray::TRANSMIT),
            ray::TRANSMIT
        );
        assert_eq!(bvh.intersect(o, d, 0.0, f32::INFINITY).unwrap().prim, 0);
    }
    /// The build before its items were laid out side by side (commit e7cf549), kept to
    /// check that the layout changed no node.
    fn reference_build(tris: &[[V3; 3]]) -> Bvh {
        let n = tris.len();
        let mut ids: Vec<u32> = (0..n as u32).collect();
        let bounds: Vec<(V3, V3)> = tris
            .iter()
            .map(|t| (vmin(vmin(t[0], t[1]), t[2]), vmax(vmax(t[0], t[1]), t[2])))
            .collect();
        let centroids: Vec<V3> = bounds.iter().map(|b| scale(add(b.0, b.1), 0.5)).collect();
        let mut nodes = Vec::with_capacity(2 * n.max(1));
        nodes.push(Node {
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            start: 0,
            count: n as u32,
        });
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
            let (mut bmin, mut bmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for &id in &ids[start..start + count] {
                let b = bounds[id as usize];
                bmin = vmin(bmin, b.0);
                bmax = vmax(bmax, b.1);
                cmin = vmin(cmin, centroids[id as usize]);
                cmax = vmax(cmax, centroids[id as usize]);
            }
            nodes[ni].min = bmin;
            nodes[ni].max = bmax;
            if count <= MAX_LEAF {
                continue;
            }
            // Binned SAH over the axis of largest centroid extent, then the others.
            let mut best = (f32::INFINITY, 0usize, 0usize);
            for axis in 0..3 {
                let ext = cmax[axis] - cmin[axis];
                if ext <= 0.0 {
                    continue;
                }
                let mut bins = [([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize); BINS];
                let k = BINS as f32 / ext;
                for &id in &ids[start..start + count] {
                    let b =
                        (((centroids[id as usize][axis] - cmin[axis]) * k) as usize).min(BINS - 1);
                    let bb = bounds[id as usize];
                    bins[b].0 = vmin(bins[b].0, bb.0);
                    bins[b].1 = vmax(bins[b].1, bb.1);
                    bins[b].2 += 1;
                }
                let mut right_cost = [0.0f32; BINS];
                let (mut rmin, mut rmax, mut rc) =
                    ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize);
                for i in (1..BINS).rev() {
                    rmin = vmin(rmin, bins[i].0);
                    rmax = vmax(rmax, bins[i].1);
                    rc += bins[i].2;
                    right_cost[i] = area(rmin, rmax) * rc as f32;
                }
                let (mut lmin, mut lmax, mut lc) =
                    ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize);
                for i in 0..BINS - 1 {
                    lmin = vmin(lmin, bins[i].0);
                    lmax = vmax(lmax, bins[i].1);
                    lc += bins[i].2;
                    let cost = area(lmin, lmax) * lc as f32 + right_cost[i + 1];
                    if lc > 0 && lc < count && cost < best.0 {
                        best = (cost, axis, i);
                    }
                }
            }
            let leaf_cost = area(bmin, bmax) * count as f32;
            let mid = if best.0.is_finite() && (best.0 < leaf_cost || count > 16) {
                let (axis, split) = (best.1, best.2);
                let ext = cmax[axis] - cmin[axis];
                let k = BINS as f32 / ext;
                let slice = &mut ids[start..start + count];
                let mut i = 0;
                let mut j = slice.len();
                while i < j {
                    let b = (((centroids[slice[i] as usize][axis] - cmin[axis]) * k) as usize)
                        .min(BINS - 1);
                    if b <= split {
                        i += 1;
                    } else {
                        j -= 1;
                        slice.swap(i, j);
                    }
                }
                i
            } else if count > 16 {
                // All centroids equal: split in the middle of the list.
                count / 2
            } else {
                continue;
            };
            if mid == 0 || mid == count {
                continue;
            }
            let left = nodes.len();
            nodes.push(Node {
                min: bmin,
                max: bmax,
                start: start as u32,
                count: mid as u32,
            });
            nodes.push(Node {
                min: bmin,
                max: bmax,
                start: (start + mid) as u32,
                count: (count - mid) as u32,
            });
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push(left);
            stack.push(left + 1);
        }
        let tris_sorted = ids.iter().map(|&i| tris[i as usize]).collect();
        Bvh {
            tree: BoxTree { nodes, ids },
            tris: tris_sorted,
            masks: Vec::new(),
        }
    }

    /// xorshift: reproducible triangles without a dependency.
    fn soup(n: usize, seed: u64) -> Vec<[V3; 3]> {
        let mut x = seed;
        let mut f = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 40) as f32 / (1u64 << 24) as f32
        };
        let mut tris = Vec::new();
        for i in 0..n {
            let c = [f() * 10.0, f() * 10.0, f() * 10.0];
            let s = if i % 7 == 0 { 3.0 } else { 0.2 };
            tris.push(std::array::from_fn(|_| {
                [c[0] + s * f(), c[1] + s * f(), c[2] + s * f()]
            }));
        }
        // A grid of quads in a plane (equal extents, shared edges) and a stack of
        // identical triangles (all centroids equal: the middle split).
        for y in 0..20 {
            for x in 0..20 {
                let (x, y) = (x as f32, y as f32);
                tris.push([[x, y, 0.0], [x + 1.0, y, 0.0], [x + 1.0, y + 1.0, 0.0]]);
                tris.push([[x, y, 0.0], [x + 1.0, y + 1.0, 0.0], [x, y + 1.0, 0.0]]);
            }
        }
        tris.extend(std::iter::repeat_n(
            [[0.0, 0.0, 5.0], [1.0, 0.0, 5.0], [0.0, 1.0, 5.0]],
            40,
        ));
        tris
    }

    #[test]
    fn build_matches_the_reference_build_node_for_node() {
        // par_min 1 and 40 split nearly every node on rayon's threads; 64k items take
        // the default split point.
        let cases = [(0, 1), (1, 2), (5, 3), (300, 4), (5000, 5)]
            .into_iter()
            .flat_map(|c| [(c, PAR_MIN), (c, 1), (c, 40)])
            .chain([((64 * 1024, 6), PAR_MIN)]);
        for ((n, seed), par_min) in cases {
            let tris = soup(n, seed);
            let a = Bvh::build_split_from(&tris, par_min, false);
            let b = reference_build(&tris);
            assert_eq!(a.tree.ids, b.tree.ids, "{n}");
            assert_eq!(a.tree.nodes.len(), b.tree.nodes.len(), "{n}");
            for (x, y) in a.tree.nodes.iter().zip(&b.tree.nodes) {
                assert_eq!((x.start, x.count), (y.start, y.count), "{n}");
                assert_eq!(x.min.map(f32::to_bits), y.min.map(f32::to_bits), "{n}");
                assert_eq!(x.max.map(f32::to_bits), y.max.map(f32::to_bits), "{n}");
            }
            assert!(a.tris == b.tris, "{n}");
        }
    }
}
