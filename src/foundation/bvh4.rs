//! A 4-wide BVH: the binary SAH BVH (`bvh::Bvh`) collapsed so each node holds up to four
//! children's boxes side by side, tested at once by one slab test the compiler vectorises
//! (four lanes of plain `f32` arithmetic). Fewer, wider nodes mean fewer dependent loads
//! per ray, the reason Embree and Cycles traverse wide BVHs on CPUs.
//!
//! It keeps the binary BVH's leaves (same triangles in the same order) and tests them with
//! the same watertight test and tie rule (`Bvh::leaf`), so every query returns exactly
//! the hit the binary BVH returns and images are bit-identical.

use super::bvh::{visibility, Bvh, Hit, Watertight};
use super::math::*;
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Traversal stack entries: up to three per level of a tree far deeper than SAH builds.
const STACK: usize = 96;

/// Lane marker of an unused child slot.
const EMPTY: u32 = u32::MAX;

/// Four children's boxes as structure-of-arrays lanes.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct Node4 {
    lo: [[f32; 4]; 3],
    hi: [[f32; 4]; 3],
    /// Inner child: its node index; leaf child: its first triangle pack.
    child: [u32; 4],
    /// Leaf child: its triangle count; 0 for an inner child, `EMPTY` for no child.
    count: [u32; 4],
    /// Bit per lane holding a child.
    valid: u32,
}

/// Up to four consecutive triangles of one leaf as structure-of-arrays lanes, tested at
/// once (`tri4`): `v[vertex][axis][lane]`, and their primitive ids. The ids sit in the
/// pack's last 16 bytes, in a cache line the vertex loads already brought in (read from
/// the binary BVH's id list, a hit's id load was a cache miss: 6% of `intersect_vis`'s
/// samples on endo_colon). 160 bytes aligned to 32, so the ids never start a new line.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct TriPack {
    v: [[[f32; 4]; 3]; 3],
    /// Lane `l`'s primitive id (unused lanes: 0; the leaf's count says which are used).
    id: [u32; 4],
}

impl TriPack {
    fn tri(&self, lane: usize) -> [V3; 3] {
        std::array::from_fn(|k| std::array::from_fn(|a| self.v[k][a][lane]))
    }
}

/// A triangle a traversal passes (`u32::MAX`: none) and the least distance it met it at.
struct Skip {
    prim: u32,
    t: f32,
}

impl Skip {
    const NONE: Skip = Skip {
        prim: u32::MAX,
        t: f32::INFINITY,
    };
}

pub struct Bvh4 {
    nodes: Vec<Node4>,
    /// A leaf's triangles, in the binary BVH's leaf order, four to a pack.
    packs: Vec<TriPack>,
    /// Each pack's lanes' visibility masks (empty when the binary BVH has none), read only
    /// by rays that filter.
    pack_masks: Vec<[u32; 4]>,
    /// The binary BVH without its triangles and ids (the packs hold them), kept for
    /// whether a ray's mask filters (`Bvh::filters`).
    bin: Bvh,
}

impl Bvh4 {
    /// The wide BVH of the same triangles and visibility masks as `Bvh::build_masked`.
    pub fn build_masked(tris: &[[V3; 3]], masks: &[u32]) -> Bvh4 {
        Bvh4::from_binary(Bvh::build_masked(tris, masks))
    }

    pub fn build(tris: &[[V3; 3]]) -> Bvh4 {
        Bvh4::from_binary(Bvh::build(tris))
    }

    /// Collapses a binary BVH: each wide node takes a binary node's children and keeps
    /// opening its largest inner child (by surface area) until it has four.
    pub fn from_binary(mut bin: Bvh) -> Bvh4 {
        let src = std::mem::take(&mut bin.tree.nodes);
        let mut nodes: Vec<Node4> = Vec::with_capacity(src.len() / 2 + 1);
        let tris = std::mem::take(&mut bin.tris);
        // Each pack's (first triangle, lanes), in pack order; the packs themselves are
        // filled afterwards on rayon's threads (filling them here, on one thread, was a
        // serial part of the published colon's set-up).
        let mut spans: Vec<(u32, u32)> = Vec::with_capacity(tris.len() / 2 + 1);
        if src.is_empty() || tris.is_empty() {
            return Bvh4 {
                nodes,
                packs: Vec::new(),
                pack_masks: Vec::new(),
                bin,
            };
        }
        let blank = Node4 {
            lo: [[f32::INFINITY; 4]; 3],
            hi: [[f32::NEG_INFINITY; 4]; 3],
            child: [0; 4],
            count: [EMPTY; 4],
            valid: 0,
        };
        nodes.push(blank);
        // (binary node whose children fill wide node `at`, at)
        let mut work = vec![(0usize, 0usize)];
        while let Some((b, at)) = work.pop() {
            // At most four, kept inline: a heap list per node was an allocation per wide
            // node of the published colon's (serial) collapse.
            let mut kids: smallvec::SmallVec<[usize; 4]> = if src[b].count > 0 {
                smallvec::smallvec![b]
            } else {
                smallvec::smallvec![src[b].start as usize, src[b].start as usize + 1]
            };
            while kids.len() < 4 {
                let open = kids
                    .iter()
                    .enumerate()
                    .filter(|(_, &k)| src[k].count == 0)
                    .max_by(|(_, &x), (_, &y)| {
                        super::box_tree::area(src[x].min, src[x].max)
                            .total_cmp(&super::box_tree::area(src[y].min, src[y].max))
                    })
                    .map(|(i, _)| i);
                let Some(i) = open else { break };
                let k = kids.remove(i);
                kids.insert(i, src[k].start as usize + 1);
                kids.insert(i, src[k].start as usize);
            }
            let mut node = blank;
            for (lane, &k) in kids.iter().enumerate() {
                node.valid |= 1 << lane;
                for a in 0..3 {
                    node.lo[a][lane] = src[k].min[a];
                    node.hi[a][lane] = src[k].max[a];
                }
                if src[k].count > 0 {
                    node.child[lane] = spans.len() as u32;
                    node.count[lane] = src[k].count;
                    let (start, end) = (src[k].start, src[k].start + src[k].count);
                    for first in (start..end).step_by(4) {
                        spans.push((first, (end - first).min(4)));
                    }
                } else {
                    node.child[lane] = nodes.len() as u32;
                    node.count[lane] = 0;
                    nodes.push(blank);
                    work.push((k, node.child[lane] as usize));
                }
            }
            nodes[at] = node;
        }
        let packs = spans
            .par_iter()
            .map(|&(first, n)| {
                let mut pack = TriPack {
                    v: [[[0.0; 4]; 3]; 3],
                    id: [0; 4],
                };
                for l in 0..n as usize {
                    let t = &tris[first as usize + l];
                    for (k, vert) in t.iter().enumerate() {
                        for a in 0..3 {
                            pack.v[k][a][l] = vert[a];
                        }
                    }
                    pack.id[l] = bin.tree.ids[first as usize + l];
                }
                pack
            })
            .collect();
        let pack_masks = if bin.masks.is_empty() {
            Vec::new()
        } else {
            spans
                .iter()
                .map(|&(first, n)| {
                    std::array::from_fn(|l| {
                        if l < n as usize {
                            bin.masks[first as usize + l]
                        } else {
                            0
                        }
                    })
                })
                .collect()
        };
        // The packs and pack masks hold the ids and masks traversal reads.
        bin.tree.ids = Vec::new();
        Bvh4 {
            nodes,
            packs,
            pack_masks,
            bin,
        }
    }

    /// `Bvh::leaf` over the packs of a leaf of `count` triangles from pack `first`: the
    /// same tests and tie rule in the same triangle order, the watertight test four
    /// triangles at a time (`tri4`), so the same hit.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn leaf<const ANY: bool, const SKIP: bool>(
        &self,
        first: u32,
        count: u32,
        wt: &Watertight,
        org: V3,
        tmin: f32,
        tfar: &mut f32,
        best: &mut Option<Hit>,
        filter: bool,
        mask: u32,
        skip: &mut Skip,
    ) -> bool {
        let mut found = false;
        let packs = first as usize..(first + count.div_ceil(4)) as usize;
        let mut left = count;
        for (pi, p) in self.packs[packs.clone()].iter().enumerate() {
            let n = left.min(4);
            left -= n;
            let lanes = (1u32 << n) - 1;
            let (t, u, v, pass, exact) = tri4(p, wt, org, tmin);
            let (pass, exact) = (pass & lanes, exact & lanes);
            if pass | exact == 0 {
                continue;
            }
            for l in 0..n as usize {
                if filter && self.pack_masks[packs.start + pi][l] & mask == 0 {
                    continue;
                }
                let hit = if exact >> l & 1 != 0 {
                    // An edge function rounded to zero: the scalar test's double path.
                    wt.intersect(org, &p.tri(l), tmin, *tfar)
                } else if pass >> l & 1 != 0 && t[l] <= *tfar {
                    Some((t[l], u[l], v[l]))
                } else {
                    None
                };
                if let Some((t, u, v)) = hit {
                    let prim = p.id[l];
                    if SKIP && prim == skip.prim {
                        // Not a hit; where it was met decides whether the result stands.
                        skip.t = skip.t.min(t);
                        continue;
                    }
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
        }
        found
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
        let mut none = Skip::NONE;
        self.traverse_skip::<ANY, false>(org, dir, tmin, tmax, mask, &mut none)
    }

    /// `Accel::intersect_past` in one traversal where it can: the traversal leaves out
    /// triangle `skip` and notes the least distance it was met at, t_s. The two-query
    /// definition returns the nearest other hit h as well unless `skip` comes first
    /// (t_s, skip) < (h.t, h.prim) and h.t <= next_up(t_s): that second query starts past
    /// next_up(t_s), and only then can it miss a hit at t_s or next_up(t_s) that h is;
    /// that case (a tie on a shared edge) is queried again as defined. A `skip` met
    /// beyond h is not always noted (its box culled), and then it does not matter.
    pub fn intersect_past(&self, org: V3, dir: V3, tmax: f32, skip: u32) -> (Option<Hit>, bool) {
        let mut sk = Skip {
            prim: skip,
            t: f32::INFINITY,
        };
        let h = self.traverse_skip::<false, true>(org, dir, 0.0, tmax, visibility::ALL, &mut sk);
        let ts = sk.t;
        match h {
            _ if ts == f32::INFINITY => (h, false),
            Some(h) if h.t < ts || (h.t == ts && h.prim < skip) => (Some(h), false),
            Some(h) if h.t > ts.next_up() => (Some(h), true),
            None => (None, true),
            Some(_) => (
                self.traverse::<false>(org, dir, ts.next_up(), tmax, visibility::ALL),
                true,
            ),
        }
    }

    #[inline(always)]
    fn traverse_skip<const ANY: bool, const SKIP: bool>(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        mask: u32,
        skip: &mut Skip,
    ) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let filter = self.bin.filters(mask);
        let slab = RaySlab::new(org, [1.0 / dir[0], 1.0 / dir[1], 1.0 / dir[2]]);
        let wt = Watertight::new(dir);
        let mut best: Option<Hit> = None;
        let mut tfar = tmax;
        // Entries: (node or first triangle, triangle count (0: node), entry distance).
        // Left uninitialised: only entries below `sp`, all written, are read (zeroing
        // 1 kB per ray showed as memset in the profile).
        let mut stack: [MaybeUninit<(u32, u32, f32)>; STACK] = [MaybeUninit::uninit(); STACK];
        stack[0].write((0, 0, tmin));
        let mut sp = 1usize;
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below the old `sp` were written before `sp` passed them.
            let (idx, count, t_enter) = unsafe { stack[sp].assume_init() };
            // A box entered beyond the nearest hit so far holds nothing nearer (the
            // slab test's widening keeps ties at tfar).
            if t_enter > tfar * 1.000_000_24 {
                continue;
            }
            if count > 0 {
                if self.leaf::<ANY, SKIP>(
                    idx, count, &wt, org, tmin, &mut tfar, &mut best, filter, mask, skip,
                ) && ANY
                {
                    return best;
                }
                continue;
            }
            let n = &self.nodes[idx as usize];
            let (near, mut hit) = slab4(n, &slab, tmin, tfar);
            if sp + 4 > STACK {
                // Deeper than any SAH tree over f32 boxes gets (the binary BVH drops
                // such entries too).
                hit &= (1 << (STACK - sp)) - 1;
            }
            if ANY {
                // Any hit ends the walk and only whether there is one is returned, so the
                // order does not matter: no sorting.
                while hit != 0 {
                    let lane = hit.trailing_zeros() as usize;
                    hit &= hit - 1;
                    stack[sp].write((n.child[lane], n.count[lane], near[lane]));
                    sp += 1;
                }
                continue;
            }
            // Insert the hit children farthest first, so the nearest is visited next.
            let base = sp;
            while hit != 0 {
                let lane = hit.trailing_zeros() as usize;
                hit &= hit - 1;
                let e = (n.child[lane], n.count[lane], near[lane]);
                let mut j = sp;
                // SAFETY: base <= j - 1 < sp, written in this loop.
                while j > base && unsafe { stack[j - 1].assume_init() }.2 < e.2 {
                    stack[j] = stack[j - 1];
                    j -= 1;
                }
                stack[j].write(e);
                sp += 1;
            }
        }
        best
    }

    /// The nearest hit (`ANY` false) or any hit (`ANY` true).
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

/// `Watertight::intersect` of a pack's four triangles at once, without its upper bound
/// (the caller compares with the best distance as it goes through the lanes in order):
/// (t, u, v, lanes that hit beyond `tmin`, lanes whose single-precision edge functions
/// include a zero, which the scalar test recomputes in double). The same operations in
/// the same order as the scalar test, lane by lane, so the same bits.
#[inline(always)]
fn tri4(
    p: &TriPack,
    wt: &Watertight,
    org: V3,
    tmin: f32,
) -> ([f32; 4], [f32; 4], [f32; 4], u32, u32) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is always available on x86_64; the loads read the pack's own
        // [f32; 4] rows (16-byte aligned by `TriPack`'s alignment).
        unsafe {
            let (kx, ky, kz) = (wt.kx, wt.ky, wt.kz);
            let (sx, sy, sz) = (_mm_set1_ps(wt.sx), _mm_set1_ps(wt.sy), _mm_set1_ps(wt.sz));
            let rel = |k: usize, a: usize| {
                _mm_sub_ps(_mm_load_ps(p.v[k][a].as_ptr()), _mm_set1_ps(org[a]))
            };
            // Vertex k relative to the origin, sheared: (x, y, z before scaling).
            let shear = |k: usize| {
                let z = rel(k, kz);
                (
                    _mm_sub_ps(rel(k, kx), _mm_mul_ps(sx, z)),
                    _mm_sub_ps(rel(k, ky), _mm_mul_ps(sy, z)),
                    z,
                )
            };
            let (ax, ay, az) = shear(0);
            let (bx, by, bz) = shear(1);
            let (cx, cy, cz) = shear(2);
            let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
            let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
            let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
            let zero = _mm_setzero_ps();
            let either = |x: __m128, y: __m128, z: __m128| _mm_or_ps(_mm_or_ps(x, y), z);
            let exact = _mm_movemask_ps(either(
                _mm_cmpeq_ps(u, zero),
                _mm_cmpeq_ps(v, zero),
                _mm_cmpeq_ps(w, zero),
            )) as u32;
            let outside = _mm_and_ps(
                either(
                    _mm_cmplt_ps(u, zero),
                    _mm_cmplt_ps(v, zero),
                    _mm_cmplt_ps(w, zero),
                ),
                either(
                    _mm_cmpgt_ps(u, zero),
                    _mm_cmpgt_ps(v, zero),
                    _mm_cmpgt_ps(w, zero),
                ),
            );
            let det = _mm_add_ps(_mm_add_ps(u, v), w);
            let (az, bz, cz) = (_mm_mul_ps(sz, az), _mm_mul_ps(sz, bz), _mm_mul_ps(sz, cz));
            let t = _mm_add_ps(
                _mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)),
                _mm_mul_ps(w, cz),
            );
            let inv = _mm_div_ps(_mm_set1_ps(1.0), det);
            let t = _mm_mul_ps(t, inv);
            let pass = _mm_andnot_ps(
                _mm_or_ps(outside, _mm_cmpeq_ps(det, zero)),
                _mm_cmpgt_ps(t, _mm_set1_ps(tmin)),
            );
            let arr = |x: __m128| {
                let mut o = [0.0f32; 4];
                _mm_storeu_ps(o.as_mut_ptr(), x);
                o
            };
            (
                arr(t),
                arr(_mm_mul_ps(v, inv)),
                arr(_mm_mul_ps(w, inv)),
                _mm_movemask_ps(pass) as u32 & !exact,
                exact,
            )
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // Every lane through the scalar test.
        let _ = (p, wt, org, tmin);
        ([0.0; 4], [0.0; 4], [0.0; 4], 0, 0b1111)
    }
}

/// Per-ray constants of the four-lane slab test: for each axis the origin and inverse
/// direction, and which of a node's bounds is the near plane (by the direction's sign).
struct RaySlab {
    org: [f32; 3],
    inv: [f32; 3],
    /// Per axis: the near plane is `hi` (the direction is negative).
    flip: [bool; 3],
}

impl RaySlab {
    #[inline(always)]
    fn new(org: V3, inv: V3) -> RaySlab {
        RaySlab {
            org,
            inv,
            flip: [inv[0] < 0.0, inv[1] < 0.0, inv[2] < 0.0],
        }
    }
}

/// Entry distances of the ray into the four boxes and a bit per box it meets within
/// [tmin, tmax]. Per axis the same arithmetic as the binary BVH's slab test, (plane -
/// origin) * inverse direction, with the near and far planes chosen by the direction's
/// sign, and the exit widened as the binary test widens it (Ize 2013). A NaN plane
/// distance (0 * inf, the origin on a plane of an axis the ray is parallel to) is ignored
/// as the binary test ignores it.
#[inline(always)]
fn slab4(n: &Node4, r: &RaySlab, tmin: f32, tmax: f32) -> ([f32; 4], u32) {
    #[cfg(target_arch = "x86_64")]
    {
        // SSE2 is part of x86_64, so this needs no runtime check.
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is always available on x86_64, and the loads read the node's own
        // [f32; 4] rows.
        unsafe {
            let mut t0 = _mm_set1_ps(tmin);
            let mut t1 = _mm_set1_ps(tmax);
            for a in 0..3 {
                let (near, far) = if r.flip[a] {
                    (&n.hi[a], &n.lo[a])
                } else {
                    (&n.lo[a], &n.hi[a])
                };
                let o = _mm_set1_ps(r.org[a]);
                let inv = _mm_set1_ps(r.inv[a]);
                let tn = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(near.as_ptr()), o), inv);
                let tf = _mm_mul_ps(_mm_sub_ps(_mm_loadu_ps(far.as_ptr()), o), inv);
                // maxps/minps return the second operand when either is NaN.
                t0 = _mm_max_ps(tn, t0);
                t1 = _mm_min_ps(tf, t1);
            }
            let hit = _mm_cmple_ps(t0, _mm_mul_ps(t1, _mm_set1_ps(1.000_000_24)));
            let mut out = [0f32; 4];
            _mm_storeu_ps(out.as_mut_ptr(), t0);
            (out, _mm_movemask_ps(hit) as u32 & n.valid)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let mut t0 = [tmin; 4];
        let mut t1 = [tmax; 4];
        for a in 0..3 {
            let (near, far) = if r.flip[a] {
                (&n.hi[a], &n.lo[a])
            } else {
                (&n.lo[a], &n.hi[a])
            };
            for l in 0..4 {
                let tn = (near[l] - r.org[a]) * r.inv[a];
                let tf = (far[l] - r.org[a]) * r.inv[a];
                t0[l] = if tn > t0[l] { tn } else { t0[l] };
                t1[l] = if tf < t1[l] { tf } else { t1[l] };
            }
        }
        let mut hit = 0;
        for l in 0..4 {
            hit |= ((t0[l] <= t1[l] * 1.000_000_24) as u32) << l;
        }
        (t0, hit & n.valid)
    }
}

super::bvh::accel_by_traverse!(Bvh4, past);
