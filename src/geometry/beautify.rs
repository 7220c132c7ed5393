//! Blender's "beauty" edge rotation (`polyfill_2d_beautify.cc`): the cost of turning the
//! diagonal of a quad from (2-4) to (1-3), and the iterative rotation of a polygon fill's
//! inner edges, cheapest first, with a binary heap that breaks ties as `BLI_heap` does
//! (the element order of the result depends on it).

use super::math::{cross, sub, V3};

fn cross_tri_v2(a: [f32; 2], b: [f32; 2], c: [f32; 2]) -> f32 {
    (a[0] - b[0]) * (b[1] - c[1]) + (a[1] - b[1]) * (c[0] - b[0])
}

fn len_v2(a: [f32; 2], b: [f32; 2]) -> f32 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    (dx * dx + dy * dy).sqrt()
}

/// `BLI_polyfill_beautify_quad_rotate_calc_ex`: negative when the (1-3) diagonal beats
/// the current (2-4) one; `f32::MAX` when (1-3) is unusable; `-f32::MAX` when (2-4) is
/// degenerate and (1-3) is not. `area` receives the quad's area (for the epsilon).
pub fn quad_rotate_cost(
    v1: [f32; 2],
    v2: [f32; 2],
    v3: [f32; 2],
    v4: [f32; 2],
    lock_degenerate: bool,
    area: Option<&mut f32>,
) -> f32 {
    let eps_zero_area = 1e-12f32;
    let a234 = cross_tri_v2(v2, v3, v4);
    let a241 = cross_tri_v2(v2, v4, v1);
    let a123 = cross_tri_v2(v1, v2, v3);
    let a134 = cross_tri_v2(v1, v3, v4);
    if let Some(r) = area {
        *r = (a234.abs() + a241.abs() + a123.abs() + a134.abs()) / 8.0;
    }
    if (a123 >= 0.0) != (a134 >= 0.0) {
        return f32::MAX;
    }
    if a123.abs() <= eps_zero_area || a134.abs() <= eps_zero_area {
        return f32::MAX;
    }
    if (a234 >= 0.0) != (a241 >= 0.0) {
        return if lock_degenerate { f32::MAX } else { -f32::MAX };
    }
    if a234.abs() <= eps_zero_area || a241.abs() <= eps_zero_area {
        return -f32::MAX;
    }
    let (l12, l23, l34, l41) = (
        len_v2(v1, v2),
        len_v2(v2, v3),
        len_v2(v3, v4),
        len_v2(v4, v1),
    );
    let (l13, l24) = (len_v2(v1, v3), len_v2(v2, v4));
    let fac_24 = a234.abs() / (l23 + l34 + l24) + a241.abs() / (l41 + l12 + l24);
    let fac_13 = a123.abs() / (l12 + l23 + l13) + a134.abs() / (l34 + l41 + l13);
    fac_24 - fac_13
}

/// `axis_dominant_v3_to_m3` then `mul_v2_m3v3`: `p` in the plane of unit normal `n`.
fn project(n: V3, p: V3) -> [f32; 2] {
    let f = n[0] * n[0] + n[1] * n[1];
    let (a, b) = if f > f32::EPSILON {
        let d = 1.0 / f.sqrt();
        let a = [n[1] * d, -n[0] * d, 0.0];
        (a, [-n[2] * a[1], n[2] * a[0], n[0] * a[1] - n[1] * a[0]])
    } else {
        (
            [if n[2] < 0.0 { -1.0 } else { 1.0 }, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        )
    };
    [
        a[0] * p[0] + a[1] * p[1] + a[2] * p[2],
        b[0] * p[0] + b[1] * p[1] + b[2] * p[2],
    ]
}

/// `BLI_polyfill_edge_calc_rotate_beauty__area` (3D quads, as `BM_verts_calc_rotate_beauty`
/// calls it): projected on the plane of the two triangles' summed normals.
pub fn rotate_beauty_3d(v1: V3, v2: V3, v3: V3, v4: V3, lock_degenerate: bool) -> f32 {
    let tri = |a: V3, b: V3, c: V3| cross(sub(a, b), sub(b, c));
    let (na, nb) = (tri(v2, v3, v4), tri(v2, v4, v1));
    let no = [na[0] + nb[0], na[1] + nb[1], na[2] + nb[2]];
    let d2 = no[0] * no[0] + no[1] * no[1] + no[2] * no[2];
    if d2 <= 1e-35 {
        return f32::MAX;
    }
    let scale = d2.sqrt();
    let inv = 1.0 / scale;
    let no = [no[0] * inv, no[1] * inv, no[2] * inv];
    let (p1, p2, p3, p4) = (
        project(no, v1),
        project(no, v2),
        project(no, v3),
        project(no, v4),
    );
    let signum = |a: f32| -> i32 {
        let eps = 1e-5f32;
        if a > eps {
            1
        } else if a < -eps {
            -1
        } else {
            0
        }
    };
    if signum(cross_tri_v2(p2, p3, p4) / scale) + signum(cross_tri_v2(p2, p4, p1) / scale) == 0 {
        return f32::MAX;
    }
    quad_rotate_cost(p1, p2, p3, p4, lock_degenerate, None)
}

/// `BLI_heap`: a binary min-heap whose nodes keep their slot, moving up past equal values
/// on insert (as Blender's `heap_up` does).
struct Heap {
    tree: Vec<usize>,
    value: Vec<f32>,
    index: Vec<usize>,
    payload: Vec<usize>,
    free: Vec<usize>,
}

impl Heap {
    fn new() -> Heap {
        Heap {
            tree: Vec::new(),
            value: Vec::new(),
            index: Vec::new(),
            payload: Vec::new(),
            free: Vec::new(),
        }
    }
    fn swap(&mut self, i: usize, j: usize) {
        self.tree.swap(i, j);
        self.index[self.tree[i]] = i;
        self.index[self.tree[j]] = j;
    }
    fn less(&self, a: usize, b: usize) -> bool {
        self.value[self.tree[a]] < self.value[self.tree[b]]
    }
    fn down(&mut self, mut i: usize) {
        let size = self.tree.len();
        loop {
            let (l, r) = (2 * i + 1, 2 * i + 2);
            let mut s = i;
            if l < size && self.less(l, s) {
                s = l;
            }
            if r < size && self.less(r, s) {
                s = r;
            }
            if s == i {
                break;
            }
            self.swap(i, s);
            i = s;
        }
    }
    fn up(&mut self, mut i: usize) {
        while i > 0 {
            let p = (i - 1) / 2;
            if self.less(p, i) {
                break;
            }
            self.swap(p, i);
            i = p;
        }
    }
    fn insert(&mut self, value: f32, payload: usize) -> usize {
        let node = match self.free.pop() {
            Some(n) => n,
            None => {
                self.value.push(0.0);
                self.index.push(0);
                self.payload.push(0);
                self.value.len() - 1
            }
        };
        self.value[node] = value;
        self.payload[node] = payload;
        self.index[node] = self.tree.len();
        self.tree.push(node);
        self.up(self.tree.len() - 1);
        node
    }
    fn pop_min(&mut self) -> usize {
        let node = self.tree[0];
        self.free.push(node);
        let last = self.tree.len() - 1;
        if last > 0 {
            self.swap(0, last);
            self.tree.pop();
            self.down(0);
        } else {
            self.tree.pop();
        }
        self.payload[node]
    }
    fn remove(&mut self, node: usize) {
        let mut i = self.index[node];
        while i > 0 {
            let p = (i - 1) / 2;
            self.swap(p, i);
            i = p;
        }
        self.pop_min();
    }
    fn update(&mut self, node: usize, value: f32, payload: usize) {
        self.payload[node] = payload;
        if value < self.value[node] {
            self.value[node] = value;
            self.up(self.index[node]);
        } else if value > self.value[node] {
            self.value[node] = value;
            self.down(self.index[node]);
        }
    }
}

const NONE: usize = usize::MAX;

#[derive(Clone, Copy)]
struct HalfEdge {
    v: usize,
    next: usize,
    radial: usize,
    base: usize,
}

fn half_edge_cost(co: &[[f32; 2]], he: &[HalfEdge], e: usize, area: Option<&mut f32>) -> f32 {
    let b = he[e].radial;
    let a_other = he[he[he[e].next].next].v;
    let b_other = he[he[he[b].next].next].v;
    quad_rotate_cost(
        co[a_other],
        co[he[e].v],
        co[b_other],
        co[he[b].v],
        false,
        area,
    )
}

/// `BLI_polyfill_beautify`: rotates the inner edges of a fill of polygon `co` (from
/// `polyfill`) while that improves it, and returns the triangles in Blender's order.
pub fn beautify(co: &[[f32; 2]], tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let n = co.len();
    if tris.len() < 2 {
        return tris.to_vec();
    }
    let last = n - 1;
    let mut he = vec![
        HalfEdge {
            v: NONE,
            next: NONE,
            radial: NONE,
            base: NONE
        };
        3 * tris.len()
    ];
    // (v0, v1, half edge) of every inner edge, sorted to pair the halves.
    let mut order: Vec<(usize, usize, usize)> = Vec::new();
    for (i, t) in tris.iter().enumerate() {
        for (j_prev, j) in [(2, 0), (0, 1), (1, 2)] {
            let e = 3 * i + j_prev;
            he[e].v = t[j_prev] as usize;
            he[e].next = 3 * i + j;
            let (a, b) = (t[j_prev] as usize, t[j] as usize);
            let (a, b) = (a.min(b), a.max(b));
            let boundary = a + 1 == b || (a == 0 && b == last);
            if !boundary {
                order.push((a, b, e));
            }
        }
    }
    order.sort_unstable();
    for (base, pair) in order.chunks(2).enumerate() {
        if pair.len() != 2 || (pair[0].0, pair[0].1) != (pair[1].0, pair[1].1) {
            // Not a fill of a simple polygon: leave it as it is.
            return tris.to_vec();
        }
        let (a, b) = (pair[0].2, pair[1].2);
        he[a].radial = b;
        he[b].radial = a;
        he[a].base = base;
        he[b].base = base;
    }
    let mut heap = Heap::new();
    let mut table = vec![NONE; order.len() / 2];
    for i in 0..he.len() {
        if he[i].radial != NONE && he[i].radial < i {
            let cost = half_edge_cost(co, &he, i, None);
            if cost < 0.0 {
                table[he[i].base] = heap.insert(cost, i);
            }
        }
    }
    while !heap.tree.is_empty() {
        let e = heap.pop_min();
        table[he[e].base] = NONE;
        rotate(&mut he, e);
        // The four outer edges of the new pair of triangles.
        let e0 = he[e].next;
        let e1 = he[e0].next;
        let r = he[e].radial;
        let e2 = he[r].next;
        let e3 = he[e2].next;
        for x in [e0, e1, e2, e3] {
            if he[x].base == NONE {
                continue;
            }
            let i = he[x].base;
            let mut area = 0.0f32;
            let cost = half_edge_cost(co, &he, x, Some(&mut area));
            if cost < -1e-6 * area.max(1.0) {
                if table[i] == NONE {
                    table[i] = heap.insert(cost, x);
                } else {
                    heap.update(table[i], cost, x);
                }
            } else if table[i] != NONE {
                heap.remove(table[i]);
                table[i] = NONE;
            }
        }
    }
    let mut out = Vec::with_capacity(tris.len());
    for i in 0..he.len() {
        if he[i].v != NONE {
            let mut t = [0u32; 3];
            let mut e = i;
            for slot in t.iter_mut() {
                *slot = he[e].v as u32;
                he[e].v = NONE;
                e = he[e].next;
            }
            out.push(t);
        }
    }
    out
}

/// `polyedge_rotate`: turns the shared edge of two triangles to the other diagonal.
fn rotate(he: &mut [HalfEdge], e: usize) {
    let e0 = e;
    let e1 = he[e0].next;
    let e2 = he[e1].next;
    let e3 = he[e].radial;
    let e4 = he[e3].next;
    let e5 = he[e4].next;
    he[e0].next = e2;
    he[e1].next = e3;
    he[e2].next = e4;
    he[e3].next = e5;
    he[e4].next = e0;
    he[e5].next = e1;
    he[e0].v = he[e5].v;
    he[e3].v = he[e2].v;
}
