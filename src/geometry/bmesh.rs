//! The part of Blender's BMesh (`source/blender/bmesh/intern/bmesh_core.cc`) that decides
//! element order, for modifiers that run through BMesh in Blender: each vertex's disk
//! cycle of edges, each edge's radial cycle of loops, each face's loop cycle from its
//! first loop, and elements in memory-pool order (killed elements leave holes; nothing
//! here allocates after a kill). Attributes are carried as sources: each element knows
//! the input elements (and weights) it was copied or interpolated from, and `into_mesh`
//! builds the output attributes from those, as `CustomData_bmesh_interp` would.

use super::math::V3;
use super::mesh::Mesh;
use super::types::{Array, Domain};

pub const NONE: u32 = u32::MAX;

/// Input elements and weights an element's attributes come from (empty: defaults).
pub type Src = Vec<(u32, f32)>;

#[derive(Clone, Copy)]
pub struct Edge {
    pub v: [u32; 2],
    /// (prev, next) in the disk cycle of `v[0]` and of `v[1]`.
    disk: [(u32, u32); 2],
    /// A loop of the radial cycle, NONE without faces.
    pub l: u32,
    pub alive: bool,
}

#[derive(Clone, Copy)]
pub struct Loop {
    pub v: u32,
    pub e: u32,
    pub f: u32,
    pub next: u32,
    pub prev: u32,
    pub radial_next: u32,
    pub radial_prev: u32,
}

#[derive(Clone, Copy)]
pub struct Face {
    pub first: u32,
    pub len: u32,
    pub alive: bool,
    pub no: V3,
}

pub struct BMesh {
    pub co: Vec<V3>,
    pub vert_e: Vec<u32>,
    pub vert_alive: Vec<bool>,
    pub vert_src: Vec<Src>,
    pub edges: Vec<Edge>,
    /// The input edge each edge copies (NONE: defaults).
    pub edge_src: Vec<u32>,
    /// A tag per edge (`BM_ELEM_TAG`), copied to edges made from it.
    pub edge_tag: Vec<bool>,
    /// Freed edge slots, the last freed first (`BLI_mempool` reuses them so).
    free_edges: Vec<u32>,
    pub loops: Vec<Loop>,
    pub loop_src: Vec<Src>,
    pub faces: Vec<Face>,
    pub face_src: Vec<u32>,
}

impl BMesh {
    /// `BM_mesh_bm_from_me`: vertices, then edges in order (each appended to its
    /// vertices' disks), then faces in order, each loop appended to its edge's radial
    /// cycle; face normals as `calc_face_normal` gives them.
    pub fn from_mesh(m: &Mesh) -> BMesh {
        let nv = m.vertex_count();
        let mut bm = BMesh {
            co: m.positions.clone(),
            vert_e: vec![NONE; nv],
            vert_alive: vec![true; nv],
            vert_src: (0..nv as u32).map(|v| vec![(v, 1.0)]).collect(),
            edges: Vec::with_capacity(m.edge_count()),
            edge_src: Vec::with_capacity(m.edge_count()),
            edge_tag: Vec::with_capacity(m.edge_count()),
            free_edges: Vec::new(),
            loops: Vec::with_capacity(m.corner_count()),
            loop_src: (0..m.corner_count() as u32)
                .map(|c| vec![(c, 1.0)])
                .collect(),
            faces: Vec::with_capacity(m.face_count()),
            face_src: (0..m.face_count() as u32).collect(),
        };
        for (i, e) in m.edges.iter().enumerate() {
            bm.edge_create(e[0], e[1], i as u32);
        }
        let normals = m.face_normals();
        for f in 0..m.face_count() {
            let r = m.face(f);
            let (s, n) = (r.start as u32, r.len() as u32);
            for c in r.clone() {
                let k = c as u32 - s;
                bm.loops.push(Loop {
                    v: m.corner_verts[c],
                    e: NONE,
                    f: f as u32,
                    next: s + (k + 1) % n,
                    prev: s + (k + n - 1) % n,
                    radial_next: NONE,
                    radial_prev: NONE,
                });
            }
            for c in r {
                bm.radial_append(m.corner_edges[c], c as u32);
            }
            bm.faces.push(Face {
                first: s,
                len: n,
                alive: true,
                no: normals[f],
            });
        }
        bm
    }

    fn slot(&self, e: u32, v: u32) -> usize {
        if self.edges[e as usize].v[0] == v {
            0
        } else {
            1
        }
    }

    pub fn disk_next(&self, e: u32, v: u32) -> u32 {
        self.edges[e as usize].disk[self.slot(e, v)].1
    }

    /// `bmesh_disk_edge_append`: at the end of `v`'s cycle (just before its first edge).
    fn disk_append(&mut self, e: u32, v: u32) {
        let s = self.slot(e, v);
        let first = self.vert_e[v as usize];
        if first == NONE {
            self.vert_e[v as usize] = e;
            self.edges[e as usize].disk[s] = (e, e);
            return;
        }
        let fs = self.slot(first, v);
        let last = self.edges[first as usize].disk[fs].0;
        self.edges[e as usize].disk[s] = (last, first);
        self.edges[first as usize].disk[fs].0 = e;
        let ls = self.slot(last, v);
        self.edges[last as usize].disk[ls].1 = e;
    }

    /// `bmesh_disk_edge_remove`.
    fn disk_remove(&mut self, e: u32, v: u32) {
        let s = self.slot(e, v);
        let (prev, next) = self.edges[e as usize].disk[s];
        let ps = self.slot(prev, v);
        self.edges[prev as usize].disk[ps].1 = next;
        let ns = self.slot(next, v);
        self.edges[next as usize].disk[ns].0 = prev;
        if self.vert_e[v as usize] == e {
            self.vert_e[v as usize] = if next != e { next } else { NONE };
        }
        self.edges[e as usize].disk[s] = (NONE, NONE);
    }

    /// `BM_edge_create` without the double check; `src` is the input edge it copies. A
    /// freed slot is taken first.
    pub fn edge_create(&mut self, a: u32, b: u32, src: u32) -> u32 {
        let e = Edge {
            v: [a, b],
            disk: [(NONE, NONE); 2],
            l: NONE,
            alive: true,
        };
        let id = match self.free_edges.pop() {
            Some(id) => {
                self.edges[id as usize] = e;
                self.edge_src[id as usize] = src;
                self.edge_tag[id as usize] = false;
                id
            }
            None => {
                self.edges.push(e);
                self.edge_src.push(src);
                self.edge_tag.push(false);
                (self.edges.len() - 1) as u32
            }
        };
        self.disk_append(id, a);
        self.disk_append(id, b);
        id
    }

    /// An edge copying `example` (attributes and tag), as `BM_edge_create` with one.
    fn edge_create_like(&mut self, a: u32, b: u32, example: u32) -> u32 {
        let e = self.edge_create(a, b, self.edge_src[example as usize]);
        self.edge_tag[e as usize] = self.edge_tag[example as usize];
        e
    }

    /// Frees an edge without faces (`BM_edge_kill` once its faces are gone).
    fn edge_kill(&mut self, e: u32) {
        let [a, b] = self.edges[e as usize].v;
        self.disk_remove(e, a);
        self.disk_remove(e, b);
        self.edges[e as usize].alive = false;
        self.free_edges.push(e);
    }

    /// The edge joining `a` and `b`, if any.
    pub fn edge_between(&self, a: u32, b: u32) -> Option<u32> {
        let first = self.vert_e[a as usize];
        if first == NONE {
            return None;
        }
        let mut e = first;
        loop {
            if self.edges[e as usize].v.contains(&b) {
                return Some(e);
            }
            e = self.disk_next(e, a);
            if e == first {
                return None;
            }
        }
    }

    /// `bmesh_radial_loop_append`: after the edge's loop, becoming its loop.
    fn radial_append(&mut self, e: u32, l: u32) {
        let head = self.edges[e as usize].l;
        if head == NONE {
            self.loops[l as usize].radial_next = l;
            self.loops[l as usize].radial_prev = l;
        } else {
            let after = self.loops[head as usize].radial_next;
            self.loops[l as usize].radial_prev = head;
            self.loops[l as usize].radial_next = after;
            self.loops[after as usize].radial_prev = l;
            self.loops[head as usize].radial_next = l;
        }
        self.edges[e as usize].l = l;
        self.loops[l as usize].e = e;
    }

    /// `bmesh_radial_loop_remove`.
    fn radial_remove(&mut self, e: u32, l: u32) {
        let (next, prev) = (
            self.loops[l as usize].radial_next,
            self.loops[l as usize].radial_prev,
        );
        if next != l {
            if self.edges[e as usize].l == l {
                self.edges[e as usize].l = next;
            }
            self.loops[next as usize].radial_prev = prev;
            self.loops[prev as usize].radial_next = next;
        } else if self.edges[e as usize].l == l {
            self.edges[e as usize].l = NONE;
        }
        self.loops[l as usize].radial_next = NONE;
        self.loops[l as usize].radial_prev = NONE;
    }

    fn add_vert(&mut self, co: V3, src: Src) -> u32 {
        self.co.push(co);
        self.vert_e.push(NONE);
        self.vert_alive.push(true);
        self.vert_src.push(src);
        (self.co.len() - 1) as u32
    }

    fn add_loop(&mut self, l: Loop, src: Src) -> u32 {
        self.loops.push(l);
        self.loop_src.push(src);
        (self.loops.len() - 1) as u32
    }

    fn other(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.edges[e as usize].v;
        if a == v {
            b
        } else {
            a
        }
    }

    /// Weighted sum of two sources (`interp` of two elements with weights 1-t and t).
    fn mix(a: &Src, b: &Src, t: f32) -> Src {
        let mut out: Src = a.iter().map(|&(i, w)| (i, w * (1.0 - t))).collect();
        out.extend(b.iter().map(|&(i, w)| (i, w * t)));
        out
    }

    /// `BM_edge_split(e, tv, fac)` (`bmesh_kernel_split_edge_make_vert` and the data
    /// interpolation): a new vertex `fac` of the way from `tv` to the other end, the new
    /// edge joining `tv` and it (copying `e`), `e` keeping the other half; a new loop
    /// after each loop of `e`, with corner data interpolated along the edge.
    pub fn split_edge(&mut self, e: u32, tv: u32, fac: f32) -> u32 {
        let v_other = self.other(e, tv);
        let src = Self::mix(
            &self.vert_src[tv as usize],
            &self.vert_src[v_other as usize],
            fac,
        );
        let (a, b) = (self.co[tv as usize], self.co[v_other as usize]);
        let co = [
            a[0] + (b[0] - a[0]) * fac,
            a[1] + (b[1] - a[1]) * fac,
            a[2] + (b[2] - a[2]) * fac,
        ];
        let v_new = self.add_vert(co, src);
        let e_new = self.edge_create_like(tv, v_new, e);
        // `bmesh_disk_vert_replace(e, v_new, tv)`.
        self.disk_remove(e, tv);
        let s = self.slot(e, tv);
        self.edges[e as usize].v[s] = v_new;
        self.disk_append(e, v_new);
        // Split the radial cycle: each loop gets a new loop after it.
        let mut l_next = self.edges[e as usize].l;
        self.edges[e as usize].l = NONE;
        while l_next != NONE {
            let l = l_next;
            let li = l as usize;
            let rn = self.loops[li].radial_next;
            l_next = if rn != l { rn } else { NONE };
            // `bmesh_radial_loop_unlink`.
            if rn != l {
                let rp = self.loops[li].radial_prev;
                self.loops[rn as usize].radial_prev = rp;
                self.loops[rp as usize].radial_next = rn;
            }
            let (f, next) = (self.loops[li].f, self.loops[li].next);
            let l_new = self.add_loop(
                Loop {
                    v: v_new,
                    e: NONE,
                    f,
                    next,
                    prev: l,
                    radial_next: NONE,
                    radial_prev: NONE,
                },
                self.loop_src[li].clone(),
            );
            self.loops[li].next = l_new;
            self.loops[next as usize].prev = l_new;
            self.faces[f as usize].len += 1;
            let next_v = self.loops[next as usize].v;
            let ev = self.edges[e as usize].v;
            if ev.contains(&v_new) && ev.contains(&next_v) {
                self.radial_append(e, l_new);
                self.radial_append(e_new, l);
            } else {
                self.radial_append(e_new, l_new);
                self.radial_append(e, l);
            }
        }
        // `BM_data_interp_face_vert_edge(v_other, tv, v_new, e, fac)`.
        let first = self.edges[e as usize].l;
        if first != NONE {
            let mut l = first;
            loop {
                let lp = self.loops[l as usize];
                let tri = if lp.v == v_other {
                    Some((l, lp.next, self.loops[lp.next as usize].next))
                } else if lp.v == v_new {
                    Some((lp.next, l, lp.prev))
                } else {
                    None
                };
                if let Some((l1, lv, l2)) = tri {
                    // Weights: `fac` for the loop at the other end, 1 - fac at `tv`.
                    let src = Self::mix(
                        &self.loop_src[l2 as usize],
                        &self.loop_src[l1 as usize],
                        fac,
                    );
                    self.loop_src[lv as usize] = src;
                }
                l = lp.radial_next;
                if l == first {
                    break;
                }
            }
        }
        v_new
    }

    fn cycle(&self, start: u32) -> Vec<u32> {
        let mut out = vec![start];
        let mut l = self.loops[start as usize].next;
        while l != start {
            out.push(l);
            l = self.loops[l as usize].next;
        }
        out
    }

    /// The loops of face `f` from its first.
    pub fn face_loops(&self, f: u32) -> Vec<u32> {
        self.cycle(self.faces[f as usize].first)
    }

    /// `BM_face_split` (`bmesh_kernel_split_face_make_edge`): face `f` is cut from `l_a`
    /// to `l_b`; `f` keeps the loops from `l_a` on plus a new loop at `l_b`'s vertex, the
    /// new face the loops from `l_b` on plus a new loop at `l_a`'s vertex, and the first
    /// loops follow BMesh's rule. `no_double` reuses an edge already joining them.
    /// Returns the new face.
    pub fn split_face(&mut self, f: u32, l_v1: u32, l_v2: u32, no_double: bool) -> u32 {
        let (v1, v2) = (self.loops[l_v1 as usize].v, self.loops[l_v2 as usize].v);
        let e = match no_double.then(|| self.edge_between(v1, v2)).flatten() {
            Some(e) => e,
            None => self.edge_create(v1, v2, NONE),
        };
        let f2 = self.faces.len() as u32;
        self.faces.push(Face {
            first: NONE,
            len: 0,
            alive: true,
            no: self.faces[f as usize].no,
        });
        self.face_src.push(self.face_src[f as usize]);
        let p2 = self.loops[l_v2 as usize].prev;
        let p1 = self.loops[l_v1 as usize].prev;
        let l_f1 = self.add_loop(
            Loop {
                v: v2,
                e: NONE,
                f,
                next: l_v1,
                prev: p2,
                radial_next: NONE,
                radial_prev: NONE,
            },
            self.loop_src[l_v2 as usize].clone(),
        );
        let l_f2 = self.add_loop(
            Loop {
                v: v1,
                e: NONE,
                f: f2,
                next: l_v2,
                prev: p1,
                radial_next: NONE,
                radial_prev: NONE,
            },
            self.loop_src[l_v1 as usize].clone(),
        );
        self.loops[p2 as usize].next = l_f1;
        self.loops[p1 as usize].next = l_f2;
        self.loops[l_v1 as usize].prev = l_f1;
        self.loops[l_v2 as usize].prev = l_f2;
        let first = self.faces[f as usize].first;
        let in_f1 = self.cycle(l_f1).contains(&first);
        let (fp, fnx) = (
            self.loops[first as usize].prev,
            self.loops[first as usize].next,
        );
        if in_f1 {
            self.faces[f2 as usize].first = if fp == l_f1 {
                self.loops[l_f2 as usize].prev
            } else if fnx == l_f1 {
                self.loops[l_f2 as usize].next
            } else {
                l_f2
            };
        } else {
            self.faces[f2 as usize].first = first;
            self.faces[f as usize].first = if fp == l_f2 {
                self.loops[l_f1 as usize].prev
            } else if fnx == l_f2 {
                self.loops[l_f1 as usize].next
            } else {
                l_f1
            };
        }
        let c2 = self.face_loops(f2);
        for &l in &c2 {
            self.loops[l as usize].f = f2;
        }
        self.faces[f2 as usize].len = c2.len() as u32;
        self.faces[f as usize].len = self.face_loops(f).len() as u32;
        self.radial_append(e, l_f1);
        self.radial_append(e, l_f2);
        f2
    }

    /// The loop of face `f` at vertex `v`.
    pub fn face_vert_loop(&self, f: u32, v: u32) -> Option<u32> {
        self.face_loops(f)
            .into_iter()
            .find(|&l| self.loops[l as usize].v == v)
    }

    /// `BM_LOOPS_OF_VERT` (`bmiter__loop_of_vert_*`): from the first disk edge with faces
    /// (its loop at `v`, which may sit on the face's next edge), each edge's loops at `v`
    /// in radial order, then the following disk edges with loops at `v`, until every loop
    /// at `v` was given.
    pub fn vert_loops(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::new();
        let start = self.vert_e[v as usize];
        if start == NONE {
            return out;
        }
        let at_v = |l: u32| self.loops[l as usize].v == v;
        let radial = |l0: u32| {
            let mut r = vec![l0];
            let mut l = self.loops[l0 as usize].radial_next;
            while l != l0 {
                r.push(l);
                l = self.loops[l as usize].radial_next;
            }
            r
        };
        let mut count = 0;
        let mut l_first = NONE;
        let mut e = start;
        loop {
            let l = self.edges[e as usize].l;
            if l != NONE {
                count += radial(l).into_iter().filter(|&x| at_v(x)).count();
                if l_first == NONE {
                    l_first = if at_v(l) {
                        l
                    } else {
                        self.loops[l as usize].next
                    };
                }
            }
            e = self.disk_next(e, v);
            if e == start {
                break;
            }
        }
        if count == 0 {
            return out;
        }
        let mut e_next = self.loops[l_first as usize].e;
        let mut l_next = l_first;
        while out.len() < count {
            out.push(l_next);
            // `bmesh_radial_faceloop_find_next`.
            let mut it = self.loops[l_next as usize].radial_next;
            while it != l_next && !at_v(it) {
                it = self.loops[it as usize].radial_next;
            }
            l_next = it;
            if l_next == l_first {
                // `bmesh_disk_faceedge_find_next`, then the edge's first loop at `v`.
                let mut f = self.disk_next(e_next, v);
                while f != e_next {
                    let l = self.edges[f as usize].l;
                    if l != NONE && radial(l).into_iter().any(at_v) {
                        break;
                    }
                    f = self.disk_next(f, v);
                }
                e_next = f;
                let l = self.edges[e_next as usize].l;
                match radial(l).into_iter().find(|&x| at_v(x)) {
                    Some(x) => {
                        l_first = x;
                        l_next = x;
                    }
                    None => break,
                }
            }
        }
        out
    }

    /// Two or more faces (`bm_edge_supports_separate`).
    pub fn separable(&self, e: u32) -> bool {
        let l = self.edges[e as usize].l;
        l != NONE && self.loops[l as usize].radial_next != l
    }

    /// `bmesh_kernel_edge_separate`: `l_sep` moves to a new copy of `e`.
    pub fn edge_separate(&mut self, e: u32, l_sep: u32) -> u32 {
        if self.edges[e as usize].l == l_sep {
            self.edges[e as usize].l = self.loops[l_sep as usize].radial_next;
        }
        let [a, b] = self.edges[e as usize].v;
        let e_new = self.edge_create_like(a, b, e);
        self.radial_remove(e, l_sep);
        self.radial_append(e_new, l_sep);
        e_new
    }

    /// `bmesh_edge_vert_swap`: `e` and its loops move from `v_src` to `v_dst`.
    fn edge_vert_swap(&mut self, e: u32, v_dst: u32, v_src: u32) {
        let first = self.edges[e as usize].l;
        if first != NONE {
            let mut l = first;
            loop {
                let lp = self.loops[l as usize];
                if lp.v == v_src {
                    self.loops[l as usize].v = v_dst;
                } else if self.loops[lp.next as usize].v == v_src {
                    self.loops[lp.next as usize].v = v_dst;
                }
                l = lp.radial_next;
                if l == first {
                    break;
                }
            }
        }
        self.disk_remove(e, v_src);
        let s = self.slot(e, v_src);
        self.edges[e as usize].v[s] = v_dst;
        self.disk_append(e, v_dst);
    }

    /// `BM_edge_splice`: `e_src`'s loops join `e_dst`, `e_src` is freed.
    pub fn edge_splice(&mut self, e_dst: u32, e_src: u32) {
        while self.edges[e_src as usize].l != NONE {
            let l = self.edges[e_src as usize].l;
            self.radial_remove(e_src, l);
            self.radial_append(e_dst, l);
        }
        self.edge_kill(e_src);
    }

    /// `bmesh_kernel_vert_separate`: one vertex per fan of edges connected through faces
    /// around `v`; fans are found from `v`'s first edge, depth first, and each but the
    /// last moves to a new vertex (a copy of `v`).
    pub fn vert_separate(&mut self, v: u32) {
        let first = self.vert_e[v as usize];
        if first == NONE {
            return;
        }
        let mut visit = std::collections::HashSet::new();
        let mut e = first;
        loop {
            visit.insert(e);
            e = self.disk_next(e, v);
            if e == first {
                break;
            }
        }
        let total = visit.len();
        let mut found = 0;
        loop {
            let mut fan = Vec::new();
            let mut search = Vec::new();
            let mut e = self.vert_e[v as usize];
            visit.remove(&e);
            loop {
                fan.push(e);
                found += 1;
                let l0 = self.edges[e as usize].l;
                if l0 != NONE {
                    let mut l = l0;
                    loop {
                        let lp = self.loops[l as usize];
                        let adj = if lp.v == v { lp.prev } else { lp.next };
                        let ae = self.loops[adj as usize].e;
                        if visit.remove(&ae) {
                            search.push(ae);
                        }
                        l = lp.radial_next;
                        if l == l0 {
                            break;
                        }
                    }
                }
                match search.pop() {
                    Some(x) => e = x,
                    None => break,
                }
            }
            if found == total {
                break;
            }
            let v_new = self.add_vert(self.co[v as usize], self.vert_src[v as usize].clone());
            while let Some(e) = fan.pop() {
                self.edge_vert_swap(e, v_new, v);
            }
        }
    }

    /// `BM_vert_kill`: the vertex, its edges and their faces.
    pub fn kill_vert(&mut self, v: u32) {
        while self.vert_e[v as usize] != NONE {
            let e = self.vert_e[v as usize];
            while self.edges[e as usize].l != NONE {
                let f = self.loops[self.edges[e as usize].l as usize].f;
                self.kill_face(f);
            }
            self.edge_kill(e);
        }
        self.vert_alive[v as usize] = false;
    }

    fn kill_face(&mut self, f: u32) {
        for l in self.face_loops(f) {
            let e = self.loops[l as usize].e;
            self.radial_remove(e, l);
        }
        self.faces[f as usize].alive = false;
    }

    /// `BM_mesh_bm_to_me`: living elements in pool order, each face from its first loop;
    /// attributes of `m` (the input) built from each element's sources.
    pub fn into_mesh(&self, m: &Mesh) -> Result<Mesh, String> {
        let mut vindex = vec![NONE; self.co.len()];
        let verts: Vec<usize> = (0..self.co.len()).filter(|&v| self.vert_alive[v]).collect();
        for (k, &v) in verts.iter().enumerate() {
            vindex[v] = k as u32;
        }
        let mut eindex = vec![NONE; self.edges.len()];
        let edges: Vec<usize> = (0..self.edges.len())
            .filter(|&e| self.edges[e].alive)
            .collect();
        for (k, &e) in edges.iter().enumerate() {
            eindex[e] = k as u32;
        }
        let faces: Vec<usize> = (0..self.faces.len())
            .filter(|&f| self.faces[f].alive)
            .collect();
        let mut out = Mesh::new();
        out.materials = m.materials.clone();
        out.positions = verts.iter().map(|&v| self.co[v]).collect();
        out.edges = edges
            .iter()
            .map(|&e| self.edges[e].v.map(|v| vindex[v as usize]))
            .collect();
        let mut corners = Vec::new();
        for &f in &faces {
            for l in self.face_loops(f as u32) {
                let lp = self.loops[l as usize];
                out.corner_verts.push(vindex[lp.v as usize]);
                out.corner_edges.push(eindex[lp.e as usize]);
                corners.push(l as usize);
            }
            out.face_offsets.push(out.corner_verts.len() as u32);
        }
        for a in m.attributes.iter() {
            let data = match a.domain {
                Domain::Point => mix_array(&a.data, verts.iter().map(|&v| &self.vert_src[v])),
                Domain::Corner => mix_array(&a.data, corners.iter().map(|&l| &self.loop_src[l])),
                Domain::Edge => {
                    let src: Vec<Src> = edges
                        .iter()
                        .map(|&e| match self.edge_src[e] {
                            NONE => Vec::new(),
                            s => vec![(s, 1.0)],
                        })
                        .collect();
                    mix_array(&a.data, src.iter())
                }
                Domain::Face => {
                    let idx: Vec<usize> =
                        faces.iter().map(|&f| self.face_src[f] as usize).collect();
                    a.data.gather(&idx)
                }
                _ => continue,
            };
            out.attributes.set(a.id.clone(), a.domain, data);
        }
        Ok(out)
    }
}

/// Each output element as its sources' weighted sum (`CustomData_bmesh_interp`: floats
/// and vectors summed in order, integers rounded, booleans true when any source with
/// weight is), a single source copied, none the type's default.
fn mix_array<'a>(data: &Array, srcs: impl Iterator<Item = &'a Src>) -> Array {
    let srcs: Vec<&Src> = srcs.collect();
    let mut out = data.empty_like();
    out.extend_default(srcs.len());
    for (i, s) in srcs.iter().enumerate() {
        match s.as_slice() {
            [] => {}
            [(j, w)] if *w == 1.0 => out.set(i, data.get(*j as usize)),
            _ => match (&mut out, data) {
                (Array::Float(o), Array::Float(d)) => {
                    o[i] = s.iter().fold(0.0, |acc, &(j, w)| acc + d[j as usize] * w);
                }
                (Array::Float2(o), Array::Float2(d)) => {
                    let mut r = [0.0f32; 2];
                    for &(j, w) in s.iter() {
                        for k in 0..2 {
                            r[k] += d[j as usize][k] * w;
                        }
                    }
                    o[i] = r;
                }
                (Array::Vector(o), Array::Vector(d)) => {
                    let mut r = [0.0f32; 3];
                    for &(j, w) in s.iter() {
                        for k in 0..3 {
                            r[k] += d[j as usize][k] * w;
                        }
                    }
                    o[i] = r;
                }
                (Array::Color(o), Array::Color(d)) => {
                    let mut r = [0.0f32; 4];
                    for &(j, w) in s.iter() {
                        for k in 0..4 {
                            r[k] += d[j as usize][k] * w;
                        }
                    }
                    o[i] = r;
                }
                (Array::Int(o), Array::Int(d)) => {
                    let r = s
                        .iter()
                        .fold(0.0f32, |acc, &(j, w)| acc + d[j as usize] as f32 * w);
                    o[i] = r.round() as i32;
                }
                (Array::Bool(o), Array::Bool(d)) => {
                    o[i] = s.iter().any(|&(j, w)| d[j as usize] && w > 0.0);
                }
                _ => out.set(i, data.get(s[0].0 as usize)),
            },
        }
    }
    out
}
