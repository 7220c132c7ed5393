//! The one bounding-box tree (issue 25): a binary tree over primitives' boxes, built by
//! the split rule its caller's results were made with (`Split`), with the queries that
//! only need the boxes: a ray walk handing primitives to a caller's intersection
//! (`traverse`, the renderer's hair curves) and a nearest search by a caller's distance
//! (`nearest`, Geometry Nodes' Sample Nearest, Proximity, ...). The renderer's triangle
//! BVH (`bvh::Bvh`) is this tree over its triangles' boxes, with its triangles in leaf
//! order and its own watertight ray walk.

use super::math::*;
use rayon::prelude::*;

#[derive(Debug, Clone, Copy)]
pub(super) struct Node {
    pub(super) min: V3,
    pub(super) max: V3,
    /// Leaf: first entry in `ids`; inner: index of the left child (right = left + 1).
    pub(super) start: u32,
    /// Primitive count; 0 for inner nodes.
    pub(super) count: u32,
}

pub struct BoxTree {
    pub(super) nodes: Vec<Node>,
    /// Primitive indices (into the caller's list) in leaf order.
    pub(super) ids: Vec<u32>,
}

/// How a node's primitives are split. Each caller keeps the rule its results were made
/// with: the tree's shape decides which of two equally near primitives a ray walk meets
/// first, so changing a rule could change a hair image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// Binned SAH, built on rayon's threads (triangles: the renderer's BVH).
    Sah,
    /// Median of the box centres along their widest extent (the first such axis on a
    /// tie); boxes with a non-finite corner are left out, no ray hitting them (hair).
    Median,
    /// As `Median`, but the last widest axis on a tie and equal centres ordered by index;
    /// every box kept (Geometry Nodes' nearest queries).
    MedianByIndex,
}

impl BoxTree {
    /// The tree over `boxes` (min, max); a primitive's id is its index there.
    pub fn build(boxes: &[(V3, V3)], split: Split) -> BoxTree {
        match split {
            Split::Sah => BoxTree::build_sah(boxes.len(), |i| boxes[i], PAR_MIN, false),
            Split::Median | Split::MedianByIndex => {
                let by_index = split == Split::MedianByIndex;
                let ok = |b: &(V3, V3)| by_index || (finite(b.0) && finite(b.1));
                let mut ids: Vec<u32> = (0..boxes.len() as u32)
                    .filter(|&i| ok(&boxes[i as usize]))
                    .collect();
                let nodes = build_serial(&mut ids, 0, |s| split_median(s, boxes, by_index));
                BoxTree { nodes, ids }
            }
        }
    }

    /// The binned-SAH tree over `n` primitives whose boxes `bounds` gives, with subtrees
    /// of at least `par_min` primitives split on rayon's threads. Every slice is
    /// partitioned by the same `split_sah` whichever thread runs it, and the nodes are
    /// numbered as the one-thread loop numbers them, so the tree is the same node for
    /// node at any thread count (images stay bit-identical).
    pub(super) fn build_sah(
        n: usize,
        bounds: impl Fn(usize) -> (V3, V3) + Sync,
        par_min: usize,
        sweep: bool,
    ) -> BoxTree {
        // Each box, its centre and index side by side, partitioned in place: the passes
        // over a node read them in order (separate arrays indexed through a shuffled id
        // list missed the cache on every item; the build was 15% of a published-colon
        // render at 64x64).
        let mut items: Vec<Item> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (lo, hi) = bounds(i);
                Item {
                    lo,
                    hi,
                    c: scale(add(lo, hi), 0.5),
                    id: i as u32,
                }
            })
            .collect();
        let top = Subtree::build(&mut items, 0, par_min, 0, sweep && n <= SWEEP_MAX);
        let mut nodes = vec![
            Node {
                min: [0.0; 3],
                max: [0.0; 3],
                start: 0,
                count: 0,
            };
            1 + top.descendants()
        ];
        nodes[0] = top.emit(1, &mut nodes);
        BoxTree {
            nodes,
            ids: items.iter().map(|it| it.id).collect(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// Visits the primitives whose boxes the ray `org + t dir`, `t` in [tmin, tmax],
    /// passes, nearer nodes first. `hit(id, tmax)` intersects primitive `id` and returns
    /// the new far end of the segment (a hit's distance) or None; `stop` ends the walk
    /// after the first hit (occlusion queries). Returns the last far end when any hit.
    pub fn traverse(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        stop: bool,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> Option<f32> {
        if self.ids.is_empty() {
            return None;
        }
        let inv = dir.map(|d| 1.0 / d);
        let mut far = tmax;
        let mut found = None;
        let mut stack = [0u32; 64];
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if slab_entry(node, org, inv, tmin, far).is_none() {
                continue;
            }
            if node.count > 0 {
                for &id in &self.ids[node.start as usize..(node.start + node.count) as usize] {
                    if let Some(t) = hit(id, far) {
                        far = t;
                        found = Some(t);
                        if stop {
                            return found;
                        }
                    }
                }
                continue;
            }
            let (l, r) = (node.start, node.start + 1);
            let tl = slab_entry(&self.nodes[l as usize], org, inv, tmin, far);
            let tr = slab_entry(&self.nodes[r as usize], org, inv, tmin, far);
            // Push the farther child first so the nearer one is visited next.
            let order = match (tl, tr) {
                (Some(a), Some(b)) if b < a => [Some(l), Some(r)],
                (Some(_), Some(_)) => [Some(r), Some(l)],
                (Some(_), None) => [None, Some(l)],
                (None, Some(_)) => [None, Some(r)],
                (None, None) => [None, None],
            };
            for c in order.into_iter().flatten() {
                if sp < stack.len() {
                    stack[sp] = c;
                    sp += 1;
                }
            }
        }
        found
    }

    /// The element with the smallest `dist(element)` (a squared distance from `q`, with any
    /// payload it computed along), the lowest index among equal ones; None when there are
    /// no elements or no distance is a number.
    pub fn nearest<T>(
        &self,
        q: V3,
        mut dist: impl FnMut(u32) -> (f32, T),
    ) -> Option<(u32, f32, T)> {
        if self.ids.is_empty() {
            return None;
        }
        let mut best: Option<(u32, f32, T)> = None;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni as usize];
            // Box distances are rounded differently from element distances: prune only
            // boxes clearly beyond the best, so equal elements still meet the tie rule.
            if let Some((_, d, _)) = &best {
                if box_dist_sq(node, q) > *d * (1.0 + 1e-5) {
                    continue;
                }
            }
            if node.count > 0 {
                for &i in &self.ids[node.start as usize..(node.start + node.count) as usize] {
                    let (d, payload) = dist(i);
                    let better = match &best {
                        None => !d.is_nan(),
                        Some((bi, bd, _)) => d < *bd || (d == *bd && i < *bi),
                    };
                    if better {
                        best = Some((i, d, payload));
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let (dl, dr) = (
                    box_dist_sq(&self.nodes[l as usize], q),
                    box_dist_sq(&self.nodes[r as usize], q),
                );
                // The nearer child is searched first (pushed last).
                if dl <= dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best
    }
}

/// Where the ray enters `node`'s box within [tmin, tmax], or None when it misses (the
/// hair walk's test; `bvh`'s triangle walk has its own, which orders a slab's planes by
/// the direction's sign rather than by their distances: they differ on NaN distances).
#[inline]
fn slab_entry(node: &Node, org: V3, inv: V3, tmin: f32, tmax: f32) -> Option<f32> {
    let (mut t0, mut t1) = (tmin, tmax);
    for k in 0..3 {
        let a = (node.min[k] - org[k]) * inv[k];
        let b = (node.max[k] - org[k]) * inv[k];
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        // NaN (a zero direction component on the slab's plane) keeps the bound.
        t0 = if lo > t0 { lo } else { t0 };
        t1 = if hi < t1 { hi } else { t1 };
    }
    (t0 <= t1 * (1.0 + 2.0 * f32::EPSILON)).then_some(t0)
}

fn box_dist_sq(n: &Node, q: V3) -> f32 {
    let mut d = 0.0f32;
    for k in 0..3 {
        let g = if q[k] < n.min[k] {
            n.min[k] - q[k]
        } else if q[k] > n.max[k] {
            q[k] - n.max[k]
        } else {
            0.0
        };
        d += g * g;
    }
    d
}

pub(super) const BINS: usize = 16;

/// A triangle while the BVH is built: its box, the box's centre, its index.
#[derive(Clone, Copy)]
struct Item {
    lo: V3,
    hi: V3,
    c: V3,
    id: u32,
}
/// Most primitives in a leaf (every split rule).
pub(super) const MAX_LEAF: usize = 4;

pub(super) fn area(min: V3, max: V3) -> f32 {
    let d = sub(max, min);
    if d[0] < 0.0 {
        return 0.0;
    }
    2.0 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0])
}

/// Below this many triangles a subtree is built by the one-thread loop (a rayon task per
/// node would cost more than it saves).
pub(super) const PAR_MIN: usize = 16 * 1024;

/// Builds of at most this many triangles asked for it place every split by the full SAH
/// sweep (`split_sweep`) instead of 16 bins. Its sorts cost O(n log^2 n): 0.05 s more
/// set-up at 35 k triangles, a second at the published colon's 1.3 M (which keeps the
/// bins).
pub(super) const SWEEP_MAX: usize = 64 * 1024;

/// A node's bounds and, when it is split, where its items are partitioned (left items
/// first): binned SAH over the three axes, binned in one pass, chosen in axis order; with
/// `sweep`, the full sweep instead.
fn split_sah(slice: &mut [Item], sweep: bool) -> (V3, V3, Option<usize>) {
    let count = slice.len();
    let (mut bmin, mut bmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for it in slice.iter() {
        bmin = vmin(bmin, it.lo);
        bmax = vmax(bmax, it.hi);
        cmin = vmin(cmin, it.c);
        cmax = vmax(cmax, it.c);
    }
    if count <= MAX_LEAF {
        return (bmin, bmax, None);
    }
    if sweep {
        return split_sweep(slice, bmin, bmax);
    }
    let mut best = (f32::INFINITY, 0usize, 0usize);
    let ext = sub(cmax, cmin);
    let k = [0, 1, 2].map(|a| BINS as f32 / ext[a]);
    let mut bins = [[([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize); BINS]; 3];
    for it in slice.iter() {
        for axis in 0..3 {
            if ext[axis] <= 0.0 {
                continue;
            }
            let b = (((it.c[axis] - cmin[axis]) * k[axis]) as usize).min(BINS - 1);
            let bin = &mut bins[axis][b];
            bin.0 = vmin(bin.0, it.lo);
            bin.1 = vmax(bin.1, it.hi);
            bin.2 += 1;
        }
    }
    for (axis, bins) in bins.iter().enumerate() {
        if ext[axis] <= 0.0 {
            continue;
        }
        let mut right_cost = [0.0f32; BINS];
        let (mut rmin, mut rmax, mut rc) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize);
        for i in (1..BINS).rev() {
            rmin = vmin(rmin, bins[i].0);
            rmax = vmax(rmax, bins[i].1);
            rc += bins[i].2;
            right_cost[i] = area(rmin, rmax) * rc as f32;
        }
        let (mut lmin, mut lmax, mut lc) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3], 0usize);
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
        let k = k[axis];
        let mut i = 0;
        let mut j = slice.len();
        while i < j {
            let b = (((slice[i].c[axis] - cmin[axis]) * k) as usize).min(BINS - 1);
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
        return (bmin, bmax, None);
    };
    (bmin, bmax, (mid != 0 && mid != count).then_some(mid))
}

/// `split_sah` by every split between the items sorted by centre along each axis, not
/// only between 16 bins: the same cost (each side's box area times its count) and rules
/// (a leaf when no split costs less, up to 16 items), the least cost in axis order. The
/// bins put the top splits of a scene of a few objects of very different sizes coarsely:
/// on shading_light the sweep's tree takes 18% fewer node visits.
fn split_sweep(slice: &mut [Item], bmin: V3, bmax: V3) -> (V3, V3, Option<usize>) {
    let count = slice.len();
    // Centre, then index: a total order, so the same tree whatever the input order.
    let by = |axis: usize| {
        move |x: &Item, y: &Item| x.c[axis].total_cmp(&y.c[axis]).then(x.id.cmp(&y.id))
    };
    let mut best = (f32::INFINITY, 0usize, 0usize);
    let mut right = vec![0.0f32; count];
    for axis in 0..3 {
        slice.sort_unstable_by(by(axis));
        let (mut rmin, mut rmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for i in (1..count).rev() {
            rmin = vmin(rmin, slice[i].lo);
            rmax = vmax(rmax, slice[i].hi);
            right[i] = area(rmin, rmax) * (count - i) as f32;
        }
        let (mut lmin, mut lmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for i in 0..count - 1 {
            lmin = vmin(lmin, slice[i].lo);
            lmax = vmax(lmax, slice[i].hi);
            let cost = area(lmin, lmax) * (i + 1) as f32 + right[i + 1];
            if cost < best.0 {
                best = (cost, axis, i + 1);
            }
        }
    }
    let leaf_cost = area(bmin, bmax) * count as f32;
    if !(best.0.is_finite() && (best.0 < leaf_cost || count > 16)) {
        return (bmin, bmax, (count > 16).then_some(count / 2));
    }
    slice.sort_unstable_by(by(best.1));
    (bmin, bmax, Some(best.2))
}

/// The one-thread build of the items `slice` (the `offset`-th onwards of the whole list)
/// by `split` (a node's bounds and where its items are partitioned, or None for a leaf):
/// its nodes with the subtree's root at 0, numbered in the loop's order (a split node's
/// children are appended as a pair; the right child's subtree is built before the left's).
fn build_serial<T>(
    slice: &mut [T],
    offset: usize,
    split: impl Fn(&mut [T]) -> (V3, V3, Option<usize>),
) -> Vec<Node> {
    let mut nodes = Vec::with_capacity(2 * slice.len().max(1));
    nodes.push(Node {
        min: [f32::INFINITY; 3],
        max: [f32::NEG_INFINITY; 3],
        start: offset as u32,
        count: slice.len() as u32,
    });
    let mut stack = vec![0usize];
    while let Some(ni) = stack.pop() {
        let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
        let (bmin, bmax, mid) = split(&mut slice[start - offset..start - offset + count]);
        nodes[ni].min = bmin;
        nodes[ni].max = bmax;
        let Some(mid) = mid else { continue };
        let left = nodes.len();
        for (s, c) in [(start, mid), (start + mid, count - mid)] {
            nodes.push(Node {
                min: bmin,
                max: bmax,
                start: s as u32,
                count: c as u32,
            });
        }
        nodes[ni].start = left as u32;
        nodes[ni].count = 0;
        stack.push(left);
        stack.push(left + 1);
    }
    nodes
}

/// The top of a parallel build: splits made on rayon's threads down to subtrees small
/// enough for `build_serial`, kept apart until their sizes are known and they can be
/// written where the one-thread loop would have put them.
enum Subtree {
    Serial(Vec<Node>),
    Split {
        min: V3,
        max: V3,
        left: Box<Subtree>,
        right: Box<Subtree>,
        /// Nodes below this one.
        size: usize,
    },
}

impl Subtree {
    /// Splits stop `MAX_PAR_DEPTH` levels down whatever the sizes: an input whose splits
    /// peel off a few items at a time must not recurse as deep as it has items.
    fn build(
        slice: &mut [Item],
        offset: usize,
        par_min: usize,
        depth: u32,
        sweep: bool,
    ) -> Subtree {
        const MAX_PAR_DEPTH: u32 = 20;
        if slice.len() < par_min || depth >= MAX_PAR_DEPTH {
            return Subtree::Serial(build_serial(slice, offset, |s: &mut [Item]| {
                split_sah(s, sweep)
            }));
        }
        let (min, max, mid) = split_sah(slice, sweep);
        let Some(mid) = mid else {
            return Subtree::Serial(vec![Node {
                min,
                max,
                start: offset as u32,
                count: slice.len() as u32,
            }]);
        };
        let (l, r) = slice.split_at_mut(mid);
        let (left, right) = rayon::join(
            || Subtree::build(l, offset, par_min, depth + 1, sweep),
            || Subtree::build(r, offset + mid, par_min, depth + 1, sweep),
        );
        let size = 2 + left.descendants() + right.descendants();
        Subtree::Split {
            min,
            max,
            left: Box::new(left),
            right: Box::new(right),
            size,
        }
    }

    fn descendants(&self) -> usize {
        match self {
            Subtree::Serial(nodes) => nodes.len() - 1,
            Subtree::Split { size, .. } => *size,
        }
    }

    /// Writes the nodes below this subtree's root from `out[base]` on and returns the
    /// root: a split's two children first, then the right child's nodes, then the left's.
    fn emit(self, base: usize, out: &mut [Node]) -> Node {
        match self {
            Subtree::Serial(nodes) => {
                // Local index i > 0 lands at base + i - 1.
                let shift = |n: Node| {
                    if n.count == 0 {
                        Node {
                            start: n.start + base as u32 - 1,
                            ..n
                        }
                    } else {
                        n
                    }
                };
                for (o, n) in out[base..].iter_mut().zip(&nodes[1..]) {
                    *o = shift(*n);
                }
                shift(nodes[0])
            }
            Subtree::Split {
                min,
                max,
                left,
                right,
                ..
            } => {
                let right_size = right.descendants();
                out[base + 1] = right.emit(base + 2, out);
                out[base] = left.emit(base + 2 + right_size, out);
                Node {
                    min,
                    max,
                    start: base as u32,
                    count: 0,
                }
            }
        }
    }
}

/// `Split::Median` (`by_index` false) or `Split::MedianByIndex` over the ids `slice`.
fn split_median(slice: &mut [u32], boxes: &[(V3, V3)], by_index: bool) -> (V3, V3, Option<usize>) {
    // The hair rule halves the corner sums, the nearest rule does not (the same order but
    // for subnormal sums): each kept as its results were made.
    let centre = |i: u32, a: usize| {
        let s = boxes[i as usize].0[a] + boxes[i as usize].1[a];
        if by_index {
            s
        } else {
            s * 0.5
        }
    };
    let count = slice.len();
    let (mut bmin, mut bmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for &id in slice.iter() {
        let c = [0, 1, 2].map(|a| centre(id, a));
        bmin = vmin(bmin, boxes[id as usize].0);
        bmax = vmax(bmax, boxes[id as usize].1);
        cmin = vmin(cmin, c);
        cmax = vmax(cmax, c);
    }
    if count <= MAX_LEAF {
        return (bmin, bmax, None);
    }
    let d = sub(cmax, cmin);
    let axis = if by_index {
        (0..3).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap()
    } else if d[0] >= d[1] && d[0] >= d[2] {
        0
    } else if d[1] >= d[2] {
        1
    } else {
        2
    };
    let mid = count / 2;
    if by_index {
        slice.select_nth_unstable_by(mid, |&x, &y| {
            centre(x, axis).total_cmp(&centre(y, axis)).then(x.cmp(&y))
        });
    } else {
        slice.select_nth_unstable_by(mid, |&x, &y| centre(x, axis).total_cmp(&centre(y, axis)));
    }
    (bmin, bmax, Some(mid))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visits_the_boxes_a_ray_passes_nearest_first() {
        let boxes: Vec<(V3, V3)> = (0..100)
            .map(|i| {
                let x = i as f32;
                ([x, -0.1, -0.1], [x + 0.5, 0.1, 0.1])
            })
            .collect();
        let bvh = BoxTree::build(&boxes, Split::Median);
        let mut seen = Vec::new();
        let got = bvh.traverse(
            [-1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            0.0,
            1e9,
            false,
            |id, far| {
                seen.push(id);
                let t = id as f32 + 1.0;
                (id >= 40 && t < far).then_some(t)
            },
        );
        assert_eq!(got, Some(41.0));
        // Nothing beyond the hit's distance is visited once it is found.
        assert!(seen.iter().all(|&i| i < 48), "{seen:?}");
        assert!(bvh
            .traverse(
                [-1.0, 5.0, 0.0],
                [1.0, 0.0, 0.0],
                0.0,
                1e9,
                false,
                |_, _| Some(0.0)
            )
            .is_none());
    }

    #[test]
    fn nearest_finds_what_a_scan_finds_and_lowest_index_on_ties() {
        // A pseudo-random cloud with duplicated points (exact ties).
        let mut s = 12345u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32 - 0.5
        };
        let mut pts: Vec<V3> = (0..300).map(|_| [r(), r(), r()]).collect();
        pts.extend_from_slice(&pts.clone()[..50]);
        let dist_sq = |a: V3, b: V3| dot(sub(a, b), sub(a, b));
        for split in [Split::MedianByIndex, Split::Median, Split::Sah] {
            let tree = BoxTree::build(&pts.iter().map(|p| (*p, *p)).collect::<Vec<_>>(), split);
            for _ in 0..200 {
                let q = [r() * 1.5, r() * 1.5, r() * 1.5];
                let (i, d, _) = tree
                    .nearest(q, |i| (dist_sq(pts[i as usize], q), ()))
                    .unwrap();
                let mut best = (0u32, f32::INFINITY);
                for (k, p) in pts.iter().enumerate() {
                    let dk = dist_sq(*p, q);
                    if dk < best.1 {
                        best = (k as u32, dk);
                    }
                }
                assert_eq!((i, d), best, "{split:?}");
            }
        }
    }

    /// The hair tree's former builder (`bvh_boxes.rs`, removed in the merge) and the
    /// nearest tree's (`geometry/nearest.rs`), kept to check the median rules build the
    /// same trees node for node (ties in both queries depend on the shape).
    fn reference_median(boxes: &[(V3, V3)], by_index: bool) -> BoxTree {
        let ok = |b: &(V3, V3)| by_index || (finite(b.0) && finite(b.1));
        let mut ids: Vec<u32> = (0..boxes.len() as u32)
            .filter(|&i| ok(&boxes[i as usize]))
            .collect();
        let centre = |i: u32| scale(add(boxes[i as usize].0, boxes[i as usize].1), 0.5);
        let sum = |i: u32, a: usize| boxes[i as usize].0[a] + boxes[i as usize].1[a];
        let mut nodes = vec![Node {
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            start: 0,
            count: ids.len() as u32,
        }];
        let mut stack = vec![0usize];
        while let Some(ni) = stack.pop() {
            let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
            let (mut bmin, mut bmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let (mut cmin, mut cmax) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for &id in &ids[start..start + count] {
                bmin = vmin(bmin, boxes[id as usize].0);
                bmax = vmax(bmax, boxes[id as usize].1);
                let c = if by_index {
                    [0, 1, 2].map(|a| sum(id, a))
                } else {
                    centre(id)
                };
                cmin = vmin(cmin, c);
                cmax = vmax(cmax, c);
            }
            nodes[ni].min = bmin;
            nodes[ni].max = bmax;
            if count <= 4 {
                continue;
            }
            let half = count / 2;
            if by_index {
                let axis = (0..3)
                    .max_by(|&a, &b| (cmax[a] - cmin[a]).total_cmp(&(cmax[b] - cmin[b])))
                    .unwrap();
                ids[start..start + count].select_nth_unstable_by(half, |&x, &y| {
                    sum(x, axis).total_cmp(&sum(y, axis)).then(x.cmp(&y))
                });
            } else {
                let d = sub(cmax, cmin);
                let axis = if d[0] >= d[1] && d[0] >= d[2] {
                    0
                } else if d[1] >= d[2] {
                    1
                } else {
                    2
                };
                ids[start..start + count].select_nth_unstable_by(half, |&a, &b| {
                    centre(a)[axis].total_cmp(&centre(b)[axis])
                });
            }
            let left = nodes.len();
            for (s, c) in [(start, half), (start + half, count - half)] {
                nodes.push(Node {
                    min: bmin,
                    max: bmax,
                    start: s as u32,
                    count: c as u32,
                });
            }
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push(left);
            stack.push(left + 1);
        }
        BoxTree { nodes, ids }
    }

    #[test]
    fn median_rules_build_the_former_trees_node_for_node() {
        let mut x = 7u64;
        let mut f = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 40) as f32 / (1u64 << 24) as f32
        };
        for n in [0, 1, 3, 4, 5, 17, 300, 5000] {
            // Boxes on a coarse grid (many equal centres and extents: ties of both
            // kinds), some points, and every 97th with a non-finite corner.
            let boxes: Vec<(V3, V3)> = (0..n)
                .map(|i| {
                    let lo = [0, 1, 2].map(|_| (f() * 8.0).floor() * 0.25);
                    let hi = if i % 5 == 0 {
                        lo
                    } else {
                        [0, 1, 2].map(|k| lo[k] + (f() * 3.0).floor() * 0.5)
                    };
                    if i % 97 == 50 {
                        ([f32::NAN, lo[1], lo[2]], [f32::INFINITY, hi[1], hi[2]])
                    } else {
                        (lo, hi)
                    }
                })
                .collect();
            for (split, by_index) in [(Split::Median, false), (Split::MedianByIndex, true)] {
                let a = BoxTree::build(&boxes, split);
                let b = reference_median(&boxes, by_index);
                assert_eq!(a.ids, b.ids, "{n} {split:?}");
                assert_eq!(a.nodes.len(), b.nodes.len(), "{n} {split:?}");
                for (p, q) in a.nodes.iter().zip(&b.nodes) {
                    assert_eq!((p.start, p.count), (q.start, q.count), "{n} {split:?}");
                    assert_eq!(p.min.map(f32::to_bits), q.min.map(f32::to_bits));
                    assert_eq!(p.max.map(f32::to_bits), q.max.map(f32::to_bits));
                }
            }
        }
    }
}
