//! Triangulating n-gons as Blender's mesh tessellation does: the face projected on the
//! plane of its normal (`axis_dominant_v3_to_m3_negate`) and clipped by Blender's ear
//! clipping (`BLI_polyfill_calc`: clip-even, sweep, convex skip), so the triangles come
//! out in Blender's order (point distribution seeds by triangle index).

use super::math::V3;

const CONCAVE: i8 = -1;
const TANGENTIAL: i8 = 0;
const CONVEX: i8 = 1;

fn signum(a: f32) -> i8 {
    if a > 0.0 {
        CONVEX
    } else if a == 0.0 {
        TANGENTIAL
    } else {
        CONCAVE
    }
}

fn area2(v1: [f32; 2], v2: [f32; 2], v3: [f32; 2]) -> f32 {
    let d2 = [v2[0] - v1[0], v2[1] - v1[1]];
    let d3 = [v3[0] - v1[0], v3[1] - v1[1]];
    d2[0] * d3[1] - d3[0] * d2[1]
}

fn span_sign(v1: [f32; 2], v2: [f32; 2], v3: [f32; 2]) -> i8 {
    signum(area2(v3, v2, v1))
}

struct Fill<'a> {
    co: &'a [[f32; 2]],
    next: Vec<usize>,
    prev: Vec<usize>,
    sign: Vec<i8>,
    /// Vertices the inside test looks at: those not convex at the start, until they are
    /// clipped or become convex (Blender's kd-tree holds exactly these).
    tested: Vec<bool>,
    head: usize,
    count: usize,
    concave: usize,
    tris: Vec<[u32; 3]>,
}

impl Fill<'_> {
    fn calc_sign(&mut self, i: usize) {
        self.sign[i] = span_sign(self.co[self.prev[i]], self.co[i], self.co[self.next[i]]);
    }

    fn ear_check(&self, ear: usize, accept: i8) -> bool {
        if self.concave == 0 {
            return true;
        }
        if self.sign[ear] != accept {
            return false;
        }
        let t = [ear, self.next[ear], self.prev[ear]];
        let (a, b, c) = (self.co[t[0]], self.co[t[1]], self.co[t[2]]);
        let (minx, maxx) = (a[0].min(b[0]).min(c[0]), a[0].max(b[0]).max(c[0]));
        let (miny, maxy) = (a[1].min(b[1]).min(c[1]), a[1].max(b[1]).max(c[1]));
        for (i, p) in self.co.iter().enumerate() {
            if !self.tested[i] || t.contains(&i) {
                continue;
            }
            if p[0] < minx || p[0] > maxx || p[1] < miny || p[1] > maxy {
                continue;
            }
            if span_sign(a, b, *p) != CONCAVE
                && span_sign(b, c, *p) != CONCAVE
                && span_sign(c, a, *p) != CONCAVE
            {
                return false;
            }
        }
        true
    }

    fn find_ear(&self, init: usize, reverse: bool) -> usize {
        for accept in [CONVEX, TANGENTIAL] {
            let mut ear = init;
            for _ in 0..self.count {
                if self.ear_check(ear, accept) {
                    return ear;
                }
                ear = if reverse {
                    self.prev[ear]
                } else {
                    self.next[ear]
                };
            }
        }
        // Degenerate polygon: any convex or tangential vertex, else the last one visited.
        let mut ear = init;
        for _ in 0..self.count {
            if self.sign[ear] != CONCAVE {
                return ear;
            }
            ear = self.next[ear];
        }
        ear
    }

    fn remove(&mut self, i: usize) {
        self.tested[i] = false;
        let (p, n) = (self.prev[i], self.next[i]);
        self.next[p] = n;
        self.prev[n] = p;
        if self.head == i {
            self.head = n;
        }
        self.count -= 1;
    }
}

/// Triangles (indices into `co`) of a polygon whose projected winding is clockwise, as
/// `BLI_polyfill_calc(coords, n, 1, tris)`.
pub fn polyfill(co: &[[f32; 2]]) -> Vec<[u32; 3]> {
    let n = co.len();
    let mut f = Fill {
        co,
        next: (0..n).map(|i| (i + 1) % n).collect(),
        prev: (0..n).map(|i| (i + n - 1) % n).collect(),
        sign: vec![0; n],
        tested: vec![false; n],
        head: 0,
        count: n,
        concave: 0,
        tris: Vec::with_capacity(n.saturating_sub(2)),
    };
    for i in 0..n {
        f.calc_sign(i);
        if f.sign[i] != CONVEX {
            f.concave += 1;
            f.tested[i] = true;
        }
    }
    let mut init = f.head;
    let mut reverse = false;
    while f.count > 3 {
        let ear = f.find_ear(init, reverse);
        if f.sign[ear] != CONVEX {
            f.concave -= 1;
        }
        let (p, nx) = (f.prev[ear], f.next[ear]);
        f.tris.push([p as u32, ear as u32, nx as u32]);
        f.remove(ear);
        for v in [p, nx] {
            if f.sign[v] != CONVEX {
                f.calc_sign(v);
                if f.sign[v] == CONVEX {
                    f.concave -= 1;
                    f.tested[v] = false;
                }
            }
        }
        init = if reverse { f.prev[p] } else { f.next[nx] };
        if f.sign[init] != CONVEX {
            init = if reverse { f.prev[init] } else { f.next[init] };
            reverse = !reverse;
        }
    }
    if f.count == 3 {
        let a = f.head;
        let b = f.next[a];
        let c = f.next[b];
        f.tris.push([a as u32, b as u32, c as u32]);
    }
    f.tris
}

/// Projects a face's vertices on the plane of its unit normal the way Blender's
/// tessellation does (`axis_dominant_v3_to_m3_negate`, then `mul_v2_m3v3`).
pub fn project(normal: V3, points: impl Iterator<Item = V3>) -> Vec<[f32; 2]> {
    let n = [-normal[0], -normal[1], -normal[2]];
    let (n1, n2);
    let f = n[0] * n[0] + n[1] * n[1];
    if f > f32::EPSILON {
        let d = 1.0 / f.sqrt();
        let a = [n[1] * d, -n[0] * d, 0.0];
        n2 = [-n[2] * a[1], n[2] * a[0], n[0] * a[1] - n[1] * a[0]];
        n1 = a;
    } else {
        n1 = [if n[2] < 0.0 { -1.0 } else { 1.0 }, 0.0, 0.0];
        n2 = [0.0, 1.0, 0.0];
    }
    points
        .map(|p| {
            [
                n1[0] * p[0] + n1[1] * p[1] + n1[2] * p[2],
                n2[0] * p[0] + n2[1] * p[1] + n2[2] * p[2],
            ]
        })
        .collect()
}
