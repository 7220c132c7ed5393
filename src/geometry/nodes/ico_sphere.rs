//! The Ico Sphere node (`node_geo_mesh_primitive_ico_sphere.cc`): BMesh's
//! `create_icosphere`, the icosahedron with its UVs, then for Subdivisions n > 1 one
//! `subdivide_edges` with 2^(n-1) - 1 cuts, grid fill and `use_sphere`
//! (`bmo_subdivide.cc`): every edge cut in edge order, then every face, last first, cut
//! into rows (`tri_3edge_subdivide`), each new vertex pushed onto the sphere.
//!
//! `Bm` below keeps just enough of BMesh to give its element order: vertices, edges and
//! faces in creation order (nothing is freed, so the memory pools hand them out in that
//! order), each face's loop cycle from its first loop, edge and face splits with
//! BMesh's rules for which half keeps the old element and where the first loop goes,
//! and the UV interpolation of an edge split (`BM_data_interp_face_vert_edge`).

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::math::V3;
use super::super::mesh::Mesh;
use super::primitives::{mesh_out, with_uv};

/// The icosahedron of BMesh's `create_icosphere` (vertices in units of 1/200 radius).
const ICO_VERTS: [[f32; 3]; 12] = [
    [0.0, 0.0, -200.0],
    [144.72, -105.144, -89.443],
    [-55.277, -170.128, -89.443],
    [-178.885, 0.0, -89.443],
    [-55.277, 170.128, -89.443],
    [144.72, 105.144, -89.443],
    [55.277, -170.128, 89.443],
    [-144.72, -105.144, 89.443],
    [-144.72, 105.144, 89.443],
    [55.277, 170.128, 89.443],
    [178.885, 0.0, 89.443],
    [0.0, 0.0, 200.0],
];
const ICO_FACES: [[u32; 3]; 20] = [
    [0, 1, 2],
    [1, 0, 5],
    [0, 2, 3],
    [0, 3, 4],
    [0, 4, 5],
    [1, 5, 10],
    [2, 1, 6],
    [3, 2, 7],
    [4, 3, 8],
    [5, 4, 9],
    [1, 10, 6],
    [2, 6, 7],
    [3, 7, 8],
    [4, 8, 9],
    [5, 9, 10],
    [6, 10, 11],
    [7, 6, 11],
    [8, 7, 11],
    [9, 8, 11],
    [10, 9, 11],
];
const ICO_UVS: [[f32; 2]; 60] = [
    [0.181819, 0.0],
    [0.272728, 0.157461],
    [0.090910, 0.157461],
    [0.272728, 0.157461],
    [0.363637, 0.0],
    [0.454546, 0.157461],
    [0.909091, 0.0],
    [1.0, 0.157461],
    [0.818182, 0.157461],
    [0.727273, 0.0],
    [0.818182, 0.157461],
    [0.636364, 0.157461],
    [0.545455, 0.0],
    [0.636364, 0.157461],
    [0.454546, 0.157461],
    [0.272728, 0.157461],
    [0.454546, 0.157461],
    [0.363637, 0.314921],
    [0.090910, 0.157461],
    [0.272728, 0.157461],
    [0.181819, 0.314921],
    [0.818182, 0.157461],
    [1.0, 0.157461],
    [0.909091, 0.314921],
    [0.636364, 0.157461],
    [0.818182, 0.157461],
    [0.727273, 0.314921],
    [0.454546, 0.157461],
    [0.636364, 0.157461],
    [0.545455, 0.314921],
    [0.272728, 0.157461],
    [0.363637, 0.314921],
    [0.181819, 0.314921],
    [0.090910, 0.157461],
    [0.181819, 0.314921],
    [0.0, 0.314921],
    [0.818182, 0.157461],
    [0.909091, 0.314921],
    [0.727273, 0.314921],
    [0.636364, 0.157461],
    [0.727273, 0.314921],
    [0.545455, 0.314921],
    [0.454546, 0.157461],
    [0.545455, 0.314921],
    [0.363637, 0.314921],
    [0.181819, 0.314921],
    [0.363637, 0.314921],
    [0.272728, 0.472382],
    [0.0, 0.314921],
    [0.181819, 0.314921],
    [0.090910, 0.472382],
    [0.727273, 0.314921],
    [0.909091, 0.314921],
    [0.818182, 0.472382],
    [0.545455, 0.314921],
    [0.727273, 0.314921],
    [0.636364, 0.472382],
    [0.363637, 0.314921],
    [0.545455, 0.314921],
    [0.454546, 0.472382],
];

/// Blender clamps Subdivisions to 10 (5.2 million faces); below 2 it is the icosahedron.
const MAX_SUBDIVISIONS: i32 = 10;

pub fn ico_sphere(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let radius = ctx.float("Radius")?.abs();
    let subdivisions = ctx.int("Subdivisions")?.min(MAX_SUBDIVISIONS);
    let mut bm = Bm::icosahedron(radius);
    if subdivisions > 1 {
        bm.subdivide_sphere((1u32 << (subdivisions - 1)) - 1, radius);
    }
    let (mut m, uvs) = bm.into_mesh();
    m.set_smooth(false);
    m.materials = vec![None];
    let extra = with_uv(ctx, &mut m, |_| uvs);
    Ok(mesh_out(m, extra))
}

const NONE: u32 = u32::MAX;

#[derive(Clone, Copy)]
struct Loop {
    v: u32,
    e: u32,
    f: u32,
    next: u32,
    prev: u32,
    uv: [f32; 2],
}

#[derive(Default)]
struct Bm {
    /// Current coordinates, and the subdivision's displaced ones (its temporary shape key,
    /// copied back after the edge pass and after the face pass).
    co: Vec<V3>,
    shape: Vec<V3>,
    edges: Vec<[u32; 2]>,
    /// Each edge's loops (its radial cycle).
    edge_loops: Vec<Vec<u32>>,
    loops: Vec<Loop>,
    /// Each vertex's loops, for finding the faces two vertices share.
    vert_loops: Vec<Vec<u32>>,
    /// Each face's first loop and length.
    faces: Vec<(u32, u32)>,
}

fn lerp(a: V3, b: V3, t: f32) -> V3 {
    // `sub_v3_v3v3` then `madd_v3_v3v3fl`, as `BM_edge_split`.
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// `normalize_v3_length`: onto the sphere of radius `len` (the origin stays).
fn on_sphere(p: V3, len: f32) -> V3 {
    let d = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    if d > 1e-35 {
        let s = len / d.sqrt();
        [p[0] * s, p[1] * s, p[2] * s]
    } else {
        p
    }
}

impl Bm {
    fn icosahedron(radius: f32) -> Bm {
        let div = radius / 200.0;
        let mut bm = Bm::default();
        for v in ICO_VERTS {
            bm.add_vert([div * v[0], div * v[1], div * v[2]]);
        }
        for (k, f) in ICO_FACES.iter().enumerate() {
            let uv = [ICO_UVS[3 * k], ICO_UVS[3 * k + 1], ICO_UVS[3 * k + 2]];
            bm.add_triangle(*f, uv);
        }
        bm
    }

    fn add_vert(&mut self, co: V3) -> u32 {
        self.co.push(co);
        self.shape.push(co);
        self.vert_loops.push(Vec::new());
        (self.co.len() - 1) as u32
    }

    fn add_edge(&mut self, a: u32, b: u32) -> u32 {
        self.edges.push([a, b]);
        self.edge_loops.push(Vec::new());
        (self.edges.len() - 1) as u32
    }

    fn find_edge(&self, a: u32, b: u32) -> Option<u32> {
        self.vert_loops[a as usize]
            .iter()
            .map(|&l| self.loops[l as usize].e)
            .chain(
                self.vert_loops[b as usize]
                    .iter()
                    .map(|&l| self.loops[l as usize].e),
            )
            .find(|&e| {
                let [x, y] = self.edges[e as usize];
                (x == a && y == b) || (x == b && y == a)
            })
    }

    fn add_loop(&mut self, l: Loop) -> u32 {
        let id = self.loops.len() as u32;
        self.vert_loops[l.v as usize].push(id);
        if l.e != NONE {
            self.edge_loops[l.e as usize].push(id);
        }
        self.loops.push(l);
        id
    }

    fn set_loop_edge(&mut self, l: u32, e: u32) {
        let old = self.loops[l as usize].e;
        if old != NONE {
            self.edge_loops[old as usize].retain(|&x| x != l);
        }
        self.loops[l as usize].e = e;
        self.edge_loops[e as usize].push(l);
    }

    /// `BM_face_create_quad_tri` with its edges made as `BM_edges_from_verts_ensure`
    /// makes them: (last, first) first, then each (previous, next).
    fn add_triangle(&mut self, v: [u32; 3], uv: [[f32; 2]; 3]) {
        let mut e = [0u32; 3];
        for k in 0..3 {
            let prev = (k + 2) % 3;
            let (a, b) = (v[prev], v[k]);
            e[prev] = match self.find_edge(a, b) {
                Some(x) => x,
                None => self.add_edge(a, b),
            };
        }
        let f = self.faces.len() as u32;
        let first = self.loops.len() as u32;
        for k in 0..3 {
            let k = k as u32;
            self.add_loop(Loop {
                v: v[k as usize],
                e: e[k as usize],
                f,
                next: first + (k + 1) % 3,
                prev: first + (k + 2) % 3,
                uv: uv[k as usize],
            });
        }
        self.faces.push((first, 3));
    }

    fn other(&self, e: u32, v: u32) -> u32 {
        let [a, b] = self.edges[e as usize];
        if a == v {
            b
        } else {
            a
        }
    }

    /// `BM_edge_split(e, tv, fac)`: a new vertex `fac` of the way from `tv` to the other
    /// end; the new edge joins `tv` and the new vertex, `e` keeps the other half (the new
    /// vertex takes `tv`'s place in it). Returns (new vertex, new edge).
    fn split_edge(&mut self, e: u32, tv: u32, fac: f32) -> (u32, u32) {
        let v_other = self.other(e, tv);
        let v_new = self.add_vert(self.co[tv as usize]);
        self.shape[v_new as usize] = self.shape[tv as usize];
        let e_new = self.add_edge(tv, v_new);
        let slot = if self.edges[e as usize][0] == tv {
            0
        } else {
            1
        };
        self.edges[e as usize][slot] = v_new;
        let radial = std::mem::take(&mut self.edge_loops[e as usize]);
        for &l in &radial {
            let li = l as usize;
            let (f, next) = (self.loops[li].f, self.loops[li].next);
            let l_new = self.add_loop(Loop {
                v: v_new,
                e: NONE,
                f,
                next,
                prev: l,
                uv: self.loops[li].uv,
            });
            self.loops[li].next = l_new;
            self.loops[next as usize].prev = l_new;
            self.faces[f as usize].1 += 1;
            let next_v = self.loops[next as usize].v;
            let [a, b] = self.edges[e as usize];
            // (`l` was taken out of `e`'s cycle above.)
            self.loops[li].e = NONE;
            if (v_new == a && next_v == b) || (v_new == b && next_v == a) {
                self.set_loop_edge(l_new, e);
                self.set_loop_edge(l, e_new);
            } else {
                self.set_loop_edge(l_new, e_new);
                self.set_loop_edge(l, e);
            }
        }
        self.co[v_new as usize] = lerp(self.co[tv as usize], self.co[v_other as usize], fac);
        // `BM_data_interp_face_vert_edge(v_other, tv, v_new, e, fac)`.
        for l in self.edge_loops[e as usize].clone() {
            let lp = self.loops[l as usize];
            let (l1, lv, l2) = if lp.v == v_other {
                let lv = lp.next;
                (l, lv, self.loops[lv as usize].next)
            } else if lp.v == v_new {
                (lp.next, l, lp.prev)
            } else {
                continue;
            };
            let (a, b) = (self.loops[l1 as usize].uv, self.loops[l2 as usize].uv);
            self.loops[lv as usize].uv = [
                a[0] * fac + b[0] * (1.0 - fac),
                a[1] * fac + b[1] * (1.0 - fac),
            ];
        }
        (v_new, e_new)
    }

    /// `bmesh_kernel_split_face_make_edge`: face `f` is cut from `l_a` to `l_b`; `f`
    /// keeps the loops from `l_a` on plus a new loop at `l_b`'s vertex, the new face the
    /// loops from `l_b` on plus a new loop at `l_a`'s vertex, and the first loops follow
    /// BMesh's rule. Returns the new edge (from `l_a`'s vertex to `l_b`'s).
    fn split_face(&mut self, f: u32, l_v1: u32, l_v2: u32) -> u32 {
        let (v1, v2) = (self.loops[l_v1 as usize].v, self.loops[l_v2 as usize].v);
        let e = self.add_edge(v1, v2);
        let f2 = self.faces.len() as u32;
        self.faces.push((NONE, 0));
        let l_f1 = self.add_loop(Loop {
            v: v2,
            e,
            f,
            next: l_v1,
            prev: self.loops[l_v2 as usize].prev,
            uv: self.loops[l_v2 as usize].uv,
        });
        let l_f2 = self.add_loop(Loop {
            v: v1,
            e,
            f: f2,
            next: l_v2,
            prev: self.loops[l_v1 as usize].prev,
            uv: self.loops[l_v1 as usize].uv,
        });
        let p2 = self.loops[l_v2 as usize].prev;
        let p1 = self.loops[l_v1 as usize].prev;
        self.loops[p2 as usize].next = l_f1;
        self.loops[p1 as usize].next = l_f2;
        self.loops[l_v1 as usize].prev = l_f1;
        self.loops[l_v2 as usize].prev = l_f2;
        let first = self.faces[f as usize].0;
        let cycle = |bm: &Bm, start: u32| {
            let mut out = vec![start];
            let mut l = bm.loops[start as usize].next;
            while l != start {
                out.push(l);
                l = bm.loops[l as usize].next;
            }
            out
        };
        let in_f1 = cycle(self, l_f1).contains(&first);
        let (fp, fnx) = (
            self.loops[first as usize].prev,
            self.loops[first as usize].next,
        );
        if in_f1 {
            self.faces[f2 as usize].0 = if fp == l_f1 {
                self.loops[l_f2 as usize].prev
            } else if fnx == l_f1 {
                self.loops[l_f2 as usize].next
            } else {
                l_f2
            };
        } else {
            self.faces[f2 as usize].0 = first;
            self.faces[f as usize].0 = if fp == l_f2 {
                self.loops[l_f1 as usize].prev
            } else if fnx == l_f2 {
                self.loops[l_f1 as usize].next
            } else {
                l_f1
            };
        }
        let c2 = cycle(self, self.faces[f2 as usize].0);
        for &l in &c2 {
            self.loops[l as usize].f = f2;
        }
        self.faces[f2 as usize].1 = c2.len() as u32;
        self.faces[f as usize].1 = cycle(self, self.faces[f as usize].0).len() as u32;
        e
    }

    /// `connect_smallest_face`: splits the smallest face holding both vertices (the first
    /// found among `v_a`'s loops on a tie). Returns the new edge.
    fn connect(&mut self, v_a: u32, v_b: u32) -> Option<u32> {
        let mut best: Option<(u32, u32, u32)> = None;
        for &l_a in &self.vert_loops[v_a as usize] {
            let f = self.loops[l_a as usize].f;
            let len = self.faces[f as usize].1;
            if best.is_some_and(|(bf, _, _)| len >= self.faces[bf as usize].1) {
                continue;
            }
            let first = self.faces[f as usize].0;
            let mut l = first;
            loop {
                if self.loops[l as usize].v == v_b {
                    best = Some((f, l_a, l));
                    break;
                }
                l = self.loops[l as usize].next;
                if l == first {
                    break;
                }
            }
        }
        let (f, l_a, l_b) = best?;
        Some(self.split_face(f, l_a, l_b))
    }

    /// `subdivide_edges` with `cuts` cuts, grid fill and `use_sphere` (radius `radius`) on
    /// a mesh of triangles.
    fn subdivide_sphere(&mut self, cuts: u32, radius: f32) {
        let n = cuts as usize;
        // The pattern matches every face at its first loop's vertex.
        let starts: Vec<u32> = self
            .faces
            .iter()
            .map(|&(first, _)| self.loops[first as usize].v)
            .collect();
        for e in 0..self.edges.len() as u32 {
            let [v1, v2] = self.edges[e as usize];
            for i in 0..cuts {
                let tv = self.edges[e as usize][0];
                let (v, _) = self.split_edge(e, tv, 1.0 / (cuts + 1 - i) as f32);
                self.shape[v as usize] = on_sphere(self.co[v as usize], radius);
            }
            for v in [v1, v2] {
                self.shape[v as usize] = on_sphere(self.co[v as usize], radius);
            }
        }
        self.co.clone_from(&self.shape);
        // Faces come off a stack: last first.
        for f in (0..starts.len()).rev() {
            let first = self.faces[f].0;
            let mut ring = Vec::with_capacity(3 * n + 3);
            let mut l = first;
            loop {
                ring.push(self.loops[l as usize].v);
                l = self.loops[l as usize].next;
                if l == first {
                    break;
                }
            }
            // verts[0] is the vertex after the pattern's start.
            let a = ring.iter().position(|&v| v == starts[f]).unwrap_or(0) + 1;
            let len = ring.len();
            let verts: Vec<u32> = (0..len).map(|b| ring[(b + a) % len]).collect();
            self.tri_3edge(&verts, n, radius);
        }
        self.co.clone_from(&self.shape);
    }

    /// `tri_3edge_subdivide`: rows of vertices from the apex down, each row a cut edge
    /// from the third side to the second cut again, then the rows joined into triangles.
    fn tri_3edge(&mut self, verts: &[u32], n: usize, radius: f32) {
        let mut lines: Vec<Vec<u32>> = vec![Vec::new(); n + 2];
        lines[0] = vec![verts[2 * n + 1]];
        let mut base = vec![verts[3 * n + 2]];
        base.extend_from_slice(&verts[..n]);
        base.push(verts[n]);
        lines[n + 1] = base;
        for i in 0..n {
            let (a, b) = (verts[2 * n + 2 + i], verts[2 * n - i]);
            let Some(e) = self.connect(a, b) else {
                return;
            };
            let mut row = vec![a];
            for j in 0..i {
                let tv = self.edges[e as usize][0];
                let (v, _) = self.split_edge(e, tv, 1.0 / (i + 1 - j) as f32);
                self.shape[v as usize] = on_sphere(self.co[v as usize], radius);
                row.push(v);
            }
            row.push(b);
            lines[i + 1] = row;
        }
        for i in 1..=n {
            for j in 0..i {
                self.connect(lines[i][j], lines[i + 1][j + 1]);
                self.connect(lines[i][j + 1], lines[i + 1][j + 1]);
            }
        }
    }

    /// `BM_mesh_bm_to_me`: elements in creation order, each face from its first loop.
    fn into_mesh(self) -> (Mesh, Vec<[f32; 2]>) {
        let mut m = Mesh::new();
        m.positions = self.co;
        m.edges = self.edges;
        let mut uvs = Vec::with_capacity(self.loops.len());
        for &(first, _) in &self.faces {
            let mut l = first;
            loop {
                let lp = &self.loops[l as usize];
                m.corner_verts.push(lp.v);
                m.corner_edges.push(lp.e);
                uvs.push(lp.uv);
                l = lp.next;
                if l == first {
                    break;
                }
            }
            m.face_offsets.push(m.corner_verts.len() as u32);
        }
        (m, uvs)
    }
}
