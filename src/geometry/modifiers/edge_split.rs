//! The Edge Split modifier (`MOD_edgesplit.cc`, `BM_mesh_edgesplit`): edges whose faces
//! meet at more than the split angle (`use_edge_angle`; an edge with three or more faces
//! always), and edges marked sharp (`use_edge_sharp`), are cut apart: each such edge with
//! several faces is separated into one edge per face (`bmesh_kernel_edge_separate`), then
//! each of its vertices into one vertex per fan of faces (`bmesh_kernel_vert_separate`),
//! and copies that still join the same vertices are merged back.
//!
//! Element order follows BMesh, which this module keeps just enough of to reproduce it:
//! each vertex's disk cycle of edges (new edges appended at its end), each edge's radial
//! cycle of loops, and the edge memory pool (an edge merged back frees its slot, which
//! the next new edge takes). Vertices are processed edge by edge, first vertex then
//! second, the first fan found from a vertex's first edge getting a new vertex and the
//! last fan keeping the old one. Faces and corners keep their order.

use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::Domain;
use super::{flag, float, Props};

pub fn unsupported(_p: &Props) -> Option<String> {
    None
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let by_angle = flag(p, "use_edge_angle");
    let by_flag = flag(p, "use_edge_sharp");
    if !by_angle && !by_flag {
        return Ok(g);
    }
    let angle = float(p, "split_angle")?;
    let tags = tag_edges(&m, by_angle, angle, by_flag);
    *g.mesh_mut().unwrap() = split(&m, &tags);
    Ok(g)
}

/// The edges to split: `doEdgeSplit`'s tests, in float as Blender makes them.
fn tag_edges(m: &Mesh, by_angle: bool, angle: f32, by_flag: bool) -> Vec<bool> {
    let ne = m.edge_count();
    let mut faces_of: Vec<Vec<usize>> = vec![Vec::new(); ne];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            faces_of[m.corner_edges[c] as usize].push(f);
        }
    }
    let mut tag = vec![false; ne];
    let do_angle = by_angle && angle < std::f32::consts::PI;
    if do_angle {
        let split_all = angle < f32::EPSILON;
        let threshold = (angle + 0.000000175).cos();
        let normals = m.face_normals();
        let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for (e, faces) in faces_of.iter().enumerate() {
            tag[e] = match faces.len() {
                0 | 1 => false,
                2 => split_all || dot(normals[faces[0]], normals[faces[1]]) < threshold,
                _ => true,
            };
        }
    }
    if by_flag {
        if let Some(a) = m.attributes.named("sharp_edge") {
            if a.domain == Domain::Edge {
                let sharp = a.data.as_bool();
                for e in 0..ne {
                    // Any edge with a face (Blender tests the face's next loop, which is
                    // never the edge's own).
                    tag[e] |= sharp[e] && !faces_of[e].is_empty();
                }
            }
        }
    }
    tag
}

const NONE: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct Edge {
    v: [u32; 2],
    /// (prev, next) in the disk cycle of `v[0]` and of `v[1]`.
    disk: [(u32, u32); 2],
    /// A loop of the radial cycle, NONE without faces.
    l: u32,
    tag: bool,
    /// The input edge whose attributes this edge carries.
    src: u32,
    alive: bool,
}

#[derive(Clone, Copy)]
struct Loop {
    v: u32,
    e: u32,
    next: u32,
    prev: u32,
    radial_next: u32,
    radial_prev: u32,
}

struct Bm {
    /// Each vertex's first disk edge, and its input vertex (attributes).
    vert_e: Vec<u32>,
    vert_src: Vec<u32>,
    vert_tag: Vec<bool>,
    edges: Vec<Edge>,
    /// Freed edge slots, the last freed first (`BLI_mempool`).
    free: Vec<u32>,
    loops: Vec<Loop>,
}

impl Bm {
    /// `BM_mesh_bm_from_me`: edges in order (each appended to its vertices' disks),
    /// then faces in order, each loop appended to its edge's radial cycle.
    fn from_mesh(m: &Mesh, tags: &[bool]) -> Bm {
        let nv = m.vertex_count();
        let mut bm = Bm {
            vert_e: vec![NONE; nv],
            vert_src: (0..nv as u32).collect(),
            vert_tag: vec![false; nv],
            edges: Vec::with_capacity(m.edge_count()),
            free: Vec::new(),
            loops: Vec::with_capacity(m.corner_count()),
        };
        for (i, e) in m.edges.iter().enumerate() {
            let id = bm.edge_create(e[0], e[1], None);
            bm.edges[id as usize].tag = tags[i];
            bm.edges[id as usize].src = i as u32;
        }
        for f in 0..m.face_count() {
            let r = m.face(f);
            let (s, n) = (r.start as u32, r.len() as u32);
            for c in r.clone() {
                let k = c as u32 - s;
                bm.loops.push(Loop {
                    v: m.corner_verts[c],
                    e: NONE,
                    next: s + (k + 1) % n,
                    prev: s + (k + n - 1) % n,
                    radial_next: NONE,
                    radial_prev: NONE,
                });
            }
            for c in r {
                bm.radial_append(m.corner_edges[c], c as u32);
            }
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

    fn disk_next(&self, e: u32, v: u32) -> u32 {
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

    /// `BM_edge_create` (no double check), copying `example`'s tag and attributes.
    fn edge_create(&mut self, a: u32, b: u32, example: Option<u32>) -> u32 {
        let (tag, src) = example.map_or((false, 0), |x| {
            (self.edges[x as usize].tag, self.edges[x as usize].src)
        });
        let e = Edge {
            v: [a, b],
            disk: [(NONE, NONE); 2],
            l: NONE,
            tag,
            src,
            alive: true,
        };
        let id = match self.free.pop() {
            Some(id) => {
                self.edges[id as usize] = e;
                id
            }
            None => {
                self.edges.push(e);
                (self.edges.len() - 1) as u32
            }
        };
        self.disk_append(id, a);
        self.disk_append(id, b);
        id
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
        self.loops[l as usize].e = NONE;
    }

    /// Two or more faces (`bm_edge_supports_separate`).
    fn separable(&self, e: u32) -> bool {
        let l = self.edges[e as usize].l;
        l != NONE && self.loops[l as usize].radial_next != l
    }

    /// `bmesh_kernel_edge_separate`: `l_sep` moves to a new copy of `e`.
    fn edge_separate(&mut self, e: u32, l_sep: u32) -> u32 {
        if self.edges[e as usize].l == l_sep {
            self.edges[e as usize].l = self.loops[l_sep as usize].radial_next;
        }
        let [a, b] = self.edges[e as usize].v;
        let e_new = self.edge_create(a, b, Some(e));
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
        let s = if self.edges[e as usize].v[0] == v_src {
            0
        } else {
            1
        };
        self.edges[e as usize].v[s] = v_dst;
        self.disk_append(e, v_dst);
    }

    /// `BM_edge_splice`: `e_src`'s loops join `e_dst`, `e_src` is freed.
    fn edge_splice(&mut self, e_dst: u32, e_src: u32) {
        while self.edges[e_src as usize].l != NONE {
            let l = self.edges[e_src as usize].l;
            self.radial_remove(e_src, l);
            self.radial_append(e_dst, l);
        }
        let [a, b] = self.edges[e_src as usize].v;
        self.disk_remove(e_src, a);
        self.disk_remove(e_src, b);
        self.edges[e_src as usize].alive = false;
        self.free.push(e_src);
    }

    /// `bmesh_kernel_vert_separate`: one vertex per fan of edges connected through faces
    /// around `v`; fans are found from `v`'s first edge, depth first, and each but the
    /// last moves to a new vertex.
    fn vert_separate(&mut self, v: u32) {
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
            let v_new = self.vert_e.len() as u32;
            self.vert_e.push(NONE);
            self.vert_src.push(self.vert_src[v as usize]);
            self.vert_tag.push(false);
            while let Some(e) = fan.pop() {
                self.edge_vert_swap(e, v_new, v);
            }
        }
    }

    /// `BM_vert_separate_hflag` with the tag.
    fn vert_separate_tagged(&mut self, v: u32) {
        let mut separated: Vec<Vec<u32>> = Vec::new();
        let mut e_first = self.vert_e[v as usize];
        let mut e_iter = e_first;
        if e_iter == NONE {
            return;
        }
        loop {
            if self.edges[e_iter as usize].tag && self.separable(e_iter) {
                let e = e_iter;
                let mut copies = Vec::new();
                while self.separable(e) {
                    let l_sep = self.edges[e as usize].l;
                    let e_new = self.edge_separate(e, l_sep);
                    // Stop before the copies appended to the disk.
                    if separated.is_empty() && copies.is_empty() {
                        e_first = e_new;
                    }
                    copies.push(e_new);
                }
                // The list BMesh builds by prepending: the edge, then its copies last first.
                let mut list = vec![e];
                list.extend(copies.iter().rev());
                separated.push(list);
            }
            e_iter = self.disk_next(e_iter, v);
            if e_iter == e_first {
                break;
            }
        }
        self.vert_separate(v);
        // `bmesh_kernel_vert_separate__cleanup`, the lists last made first.
        for list in separated.iter().rev() {
            let mut live: Vec<u32> = list.clone();
            let mut i = 0;
            while i + 1 < live.len() {
                let orig = live[i];
                let mut j = i + 1;
                while j < live.len() {
                    let e = live[j];
                    if self.edges[e as usize].v == self.edges[orig as usize].v {
                        self.edge_splice(orig, e);
                        live.remove(j);
                    } else {
                        j += 1;
                    }
                }
                i += 1;
            }
        }
    }
}

/// `BM_mesh_edgesplit(bm, use_verts=false, tag_only=true)` and back to a mesh.
fn split(m: &Mesh, tags: &[bool]) -> Mesh {
    let mut bm = Bm::from_mesh(m, tags);
    for (i, e) in bm.edges.iter().enumerate() {
        if tags[i] {
            bm.vert_tag[e.v[0] as usize] = true;
            bm.vert_tag[e.v[1] as usize] = true;
        }
    }
    // Edges made on the way are visited too (the pool is iterated live), but their
    // vertices are no longer tagged.
    let mut i = 0;
    while i < bm.edges.len() {
        if bm.edges[i].alive && bm.edges[i].tag {
            for k in 0..2 {
                let v = bm.edges[i].v[k];
                if bm.vert_tag[v as usize] {
                    bm.vert_tag[v as usize] = false;
                    bm.vert_separate_tagged(v);
                }
            }
        }
        i += 1;
    }
    let mut out = m.clone();
    let alive: Vec<usize> = (0..bm.edges.len()).filter(|&e| bm.edges[e].alive).collect();
    let mut index = vec![u32::MAX; bm.edges.len()];
    for (k, &e) in alive.iter().enumerate() {
        index[e] = k as u32;
    }
    out.edges = alive.iter().map(|&e| bm.edges[e].v).collect();
    out.corner_verts = bm.loops.iter().map(|l| l.v).collect();
    out.corner_edges = bm.loops.iter().map(|l| index[l.e as usize]).collect();
    let vsrc: Vec<usize> = bm.vert_src.iter().map(|&v| v as usize).collect();
    out.positions = vsrc.iter().map(|&v| m.positions[v]).collect();
    out.attributes.gather_domain(Domain::Point, &vsrc);
    let esrc: Vec<usize> = alive.iter().map(|&e| bm.edges[e].src as usize).collect();
    out.attributes.gather_domain(Domain::Edge, &esrc);
    out.custom_vert_normals = None;
    out
}
