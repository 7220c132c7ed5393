//! Subdivide Mesh: simple (bilinear) subdivision with the vertex, edge, face and corner
//! order of Blender's subdivision-to-mesh traversal (`blenkernel/intern/subdiv_foreach.cc`).
//!
//! Every coarse face is a set of "ptex" patches: a quad is one patch, an n-gon one quad
//! patch per corner (corner vertex, midpoint of its next edge, face centre, midpoint of
//! its previous edge). New vertices are numbered: coarse vertices, then each coarse edge's
//! inner vertices, then each face's inner vertices; edges: each coarse edge's pieces, then
//! each face's inner edges; faces are emitted per coarse face. Positions and attributes are
//! bilinear over the patches, which is what OpenSubdiv's bilinear scheme evaluates.

// The traversal keeps Blender's running indices, which reads best as counters.
#![allow(clippy::explicit_counter_loop)]

use super::super::attribute::Attributes;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::limits;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::modify_geometry_sets;

/// A point of a coarse face as weights over its corners (corner index, weight).
/// Source elements and their weights: four for a quad corner, inline (no allocation).
type Weights = smallvec::SmallVec<[(usize, f64); 4]>;

struct Ctx<'a> {
    m: &'a Mesh,
    res: i64,
    face_ptex: Vec<i64>,
    ptex_face: Vec<(usize, usize)>,
    vert_offset: Vec<i64>,
    edge_offset: Vec<i64>,
    face_offset: Vec<i64>,
    vertices_edge_offset: i64,
    vertices_inner_offset: i64,
    edge_inner_offset: i64,
    n_verts: usize,
    n_edges: usize,
    n_faces: usize,
}

fn ptex_count(size: usize) -> usize {
    if size == 4 {
        1
    } else {
        size
    }
}
fn edges_per_ptex(res: i64) -> i64 {
    2 * (res - 1) * res
}
fn inner_edges_per_ptex(res: i64) -> i64 {
    if res < 2 {
        0
    } else {
        (res - 2) * res + (res - 1) * (res - 1)
    }
}
fn faces_per_ptex(res: i64) -> i64 {
    (res - 1) * (res - 1)
}
fn ptex_res(size: usize, res: i64) -> i64 {
    if size == 4 {
        res
    } else {
        (res >> 1) + 1
    }
}

impl<'a> Ctx<'a> {
    fn new(m: &'a Mesh, level: u32) -> Ctx<'a> {
        let res = (1i64 << level) + 1;
        let nq = (res >> 1) + 1;
        let per_edge = res - 2;
        let (mut vo, mut eo, mut fo) = (0i64, 0i64, 0i64);
        let mut vert_offset = Vec::new();
        let mut edge_offset = Vec::new();
        let mut face_offset = Vec::new();
        let mut face_ptex = Vec::new();
        let mut ptex_face = Vec::new();
        for f in 0..m.face_count() {
            let size = m.face_size(f);
            face_ptex.push(ptex_face.len() as i64);
            for c in 0..ptex_count(size) {
                ptex_face.push((f, c));
            }
            vert_offset.push(vo);
            edge_offset.push(eo);
            face_offset.push(fo);
            if size == 4 {
                vo += (res - 2) * (res - 2);
                eo += edges_per_ptex(res - 2) + 4 * per_edge;
                fo += faces_per_ptex(res);
            } else {
                let n = size as i64;
                vo += 1 + n * (nq - 2) * (nq - 1);
                eo += n * (inner_edges_per_ptex(nq - 1) + (nq - 2) + per_edge);
                if nq >= 3 {
                    eo += n;
                }
                fo += n * faces_per_ptex(nq);
            }
        }
        face_offset.push(fo);
        let nv = m.vertex_count() as i64;
        let ne = m.edge_count() as i64;
        let vertices_edge_offset = nv;
        let vertices_inner_offset = nv + ne * per_edge;
        let edge_inner_offset = ne * (res - 1);
        Ctx {
            m,
            res,
            face_ptex,
            ptex_face,
            vert_offset,
            edge_offset,
            face_offset,
            vertices_edge_offset,
            vertices_inner_offset,
            edge_inner_offset,
            n_verts: (vertices_inner_offset + vo) as usize,
            n_edges: (edge_inner_offset + eo) as usize,
            n_faces: fo as usize,
        }
    }

    /// The coarse-face corner weights of point (u, v) of a ptex patch.
    fn weights(&self, ptex: usize, u: f64, v: f64) -> (usize, Weights) {
        let (f, c) = self.ptex_face[ptex];
        let r = self.m.face(f);
        let n = r.len();
        let bil = [(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v];
        let mut w = Weights::new();
        if n == 4 {
            for k in 0..4 {
                w.push((r.start + k, bil[k]));
            }
        } else {
            let next = (c + 1) % n;
            let prev = (c + n - 1) % n;
            // Patch corners: corner c, mid(c, next), centre, mid(prev, c).
            w.push((r.start + c, bil[0]));
            w.push((r.start + c, bil[1] * 0.5));
            w.push((r.start + next, bil[1] * 0.5));
            for k in 0..n {
                w.push((r.start + k, bil[2] / n as f64));
            }
            w.push((r.start + prev, bil[3] * 0.5));
            w.push((r.start + c, bil[3] * 0.5));
        }
        (f, w)
    }
}

/// How each new element is made from old ones.
struct Build {
    positions: Vec<[f32; 3]>,
    /// Per new vertex: weights over coarse vertices.
    vert_src: Vec<Weights>,
    edges: Vec<[u32; 2]>,
    /// Per new edge: the coarse edge it lies on.
    edge_src: Vec<Option<usize>>,
    corner_verts: Vec<u32>,
    corner_edges: Vec<u32>,
    /// Per new corner: weights over coarse corners (left empty when the mesh has no
    /// corner attributes to interpolate: a weight list per corner is most of the time).
    corner_src: Vec<Weights>,
    corner_weights: bool,
    face_src: Vec<usize>,
    /// Per new vertex: where it lies on the coarse mesh (for smooth schemes).
    vert_loc: Vec<Loc>,
}

/// Where a vertex of the subdivided mesh lies: a coarse vertex, the `i`-th inner point of
/// a coarse edge (from its first vertex), or grid point (x, y) of a ptex patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loc {
    Vertex(usize),
    Edge(usize, usize),
    Ptex(usize, usize, usize),
}

fn blend(m: &Mesh, w: &[(usize, f64)]) -> [f32; 3] {
    let mut p = [0.0f64; 3];
    for &(v, x) in w {
        for k in 0..3 {
            p[k] += m.positions[v][k] as f64 * x;
        }
    }
    [p[0] as f32, p[1] as f32, p[2] as f32]
}

pub fn subdivide_mesh(m: &Mesh, level: u32) -> Mesh {
    subdivide_with_locations(m, level).0
}

/// Simple subdivision, and where each new vertex lies on the coarse mesh (Blender's
/// Subdivision Surface uses the same topology and moves the vertices).
pub fn subdivide_with_locations(m: &Mesh, level: u32) -> (Mesh, Vec<Loc>) {
    let ctx = Ctx::new(m, level);
    let res = ctx.res;
    let per_edge = res - 2;
    let edges_per_coarse = res - 1;
    let corner_weights = m.attributes.on(Domain::Corner).next().is_some();
    // Built in place: `vec![w; n]` would clone an empty SmallVec n times.
    let empty = |n: usize| {
        let mut v = Vec::with_capacity(n);
        v.resize_with(n, Weights::new);
        v
    };
    let mut b = Build {
        positions: vec![[0.0; 3]; ctx.n_verts],
        vert_src: empty(ctx.n_verts),
        edges: vec![[0, 0]; ctx.n_edges],
        edge_src: vec![None; ctx.n_edges],
        corner_verts: vec![0; ctx.n_faces * 4],
        corner_edges: vec![0; ctx.n_faces * 4],
        corner_src: empty(if corner_weights { ctx.n_faces * 4 } else { 0 }),
        corner_weights,
        face_src: vec![0; ctx.n_faces],
        vert_loc: vec![Loc::Vertex(0); ctx.n_verts],
    };
    // Coarse vertices, then vertices along coarse edges (linear from edge[0]).
    for v in 0..m.vertex_count() {
        b.vert_src[v] = smallvec::smallvec![(v, 1.0)];
        b.vert_loc[v] = Loc::Vertex(v);
    }
    let inv = 1.0 / (res - 1) as f64;
    for (e, ev) in m.edges.iter().enumerate() {
        for i in 0..per_edge {
            let t = (i + 1) as f64 * inv;
            let idx = (ctx.vertices_edge_offset + e as i64 * per_edge + i) as usize;
            b.vert_src[idx] = smallvec::smallvec![(ev[0] as usize, 1.0 - t), (ev[1] as usize, t)];
            b.vert_loc[idx] = Loc::Edge(e, i as usize);
        }
    }
    let corner_to_vert = |w: &Weights| -> Weights {
        w.iter()
            .map(|&(c, x)| (m.corner_verts[c] as usize, x))
            .collect()
    };
    // Inner vertices.
    for f in 0..m.face_count() {
        let size = m.face_size(f);
        let ptex = ctx.face_ptex[f] as usize;
        let mut idx = (ctx.vertices_inner_offset + ctx.vert_offset[f]) as usize;
        if size == 4 {
            for y in 1..res - 1 {
                for x in 1..res - 1 {
                    let (_, w) = ctx.weights(ptex, x as f64 * inv, y as f64 * inv);
                    b.vert_src[idx] = corner_to_vert(&w);
                    b.vert_loc[idx] = Loc::Ptex(ptex, x as usize, y as usize);
                    idx += 1;
                }
            }
        } else {
            let pr = ptex_res(size, res);
            let pinv = 1.0 / (pr - 1) as f64;
            let (_, w) = ctx.weights(ptex, 1.0, 1.0);
            b.vert_src[idx] = corner_to_vert(&w);
            b.vert_loc[idx] = Loc::Ptex(ptex, (pr - 1) as usize, (pr - 1) as usize);
            idx += 1;
            for c in 0..size {
                for y in 1..pr - 1 {
                    for x in 1..pr {
                        let (_, w) = ctx.weights(ptex + c, x as f64 * pinv, y as f64 * pinv);
                        b.vert_src[idx] = corner_to_vert(&w);
                        b.vert_loc[idx] = Loc::Ptex(ptex + c, x as usize, y as usize);
                        idx += 1;
                    }
                }
            }
        }
    }
    for (i, w) in b.vert_src.iter().enumerate() {
        b.positions[i] = blend(m, w);
    }
    // Edges: coarse edge pieces.
    for (e, ev) in m.edges.iter().enumerate() {
        let base = e as i64 * edges_per_coarse;
        let mut last = ev[0] as i64;
        for i in 0..edges_per_coarse - 1 {
            let v2 = ctx.vertices_edge_offset + e as i64 * per_edge + i;
            b.edges[(base + i) as usize] = [last as u32, v2 as u32];
            b.edge_src[(base + i) as usize] = Some(e);
            last = v2;
        }
        b.edges[(base + edges_per_coarse - 1) as usize] = [last as u32, ev[1]];
        b.edge_src[(base + edges_per_coarse - 1) as usize] = Some(e);
    }
    for f in 0..m.face_count() {
        if m.face_size(f) == 4 {
            edges_regular(&ctx, &mut b, f);
            loops_regular(&ctx, &mut b, f);
        } else {
            edges_special(&ctx, &mut b, f);
            loops_special(&ctx, &mut b, f);
        }
    }
    // Assemble with attributes.
    let mut out = Mesh::new();
    out.positions = b.positions;
    out.edges = b.edges;
    out.face_offsets = (0..=ctx.n_faces as u32).map(|i| i * 4).collect();
    out.corner_verts = b.corner_verts;
    out.corner_edges = b.corner_edges;
    out.materials = m.materials.clone();
    out.attributes =
        interpolate_attributes(m, &b.vert_src, &b.edge_src, &b.corner_src, &b.face_src);
    (out, b.vert_loc)
}

fn mix_array(src: &Array, weights: &[Weights]) -> Array {
    let n = weights.len();
    let t = src.data_type();
    let mut out = Array::zeros(t, n);
    match (src, &mut out) {
        // Float lanes without a per-element allocation (the same sums in the same order).
        (Array::Float(s), Array::Float(o)) => {
            for (o, w) in o.iter_mut().zip(weights) {
                if !w.is_empty() {
                    *o = w.iter().fold(0.0f64, |a, &(k, x)| a + s[k] as f64 * x) as f32;
                }
            }
        }
        (Array::Float2(s), Array::Float2(o)) => mix_lanes(s, weights, o),
        (Array::Vector(s), Array::Vector(o)) => mix_lanes(s, weights, o),
        (Array::Color(s), Array::Color(o)) | (Array::ByteColor(s), Array::ByteColor(o)) => {
            mix_lanes(s, weights, o)
        }
        (Array::Bool(s), Array::Bool(o)) => {
            for (i, w) in weights.iter().enumerate() {
                o[i] = w.iter().any(|&(k, x)| x > 0.0 && s[k]);
            }
        }
        _ => {
            for (i, w) in weights.iter().enumerate() {
                if w.is_empty() {
                    continue;
                }
                let vals: Vec<Vec<f64>> = w.iter().map(|&(k, _)| lanes(&src.get(k))).collect();
                let mut acc = vec![0.0f64; vals[0].len()];
                for (v, &(_, x)) in vals.iter().zip(w) {
                    for (a, b) in acc.iter_mut().zip(v) {
                        *a += b * x;
                    }
                }
                out.set(i, from_lanes(t, &acc));
            }
        }
    }
    out
}

/// Each output element the weighted sum of its sources, in double precision; elements
/// without sources stay zero.
fn mix_lanes<const N: usize>(src: &[[f32; N]], weights: &[Weights], out: &mut [[f32; N]]) {
    for (o, w) in out.iter_mut().zip(weights) {
        if w.is_empty() {
            continue;
        }
        let mut acc = [0.0f64; N];
        for &(k, x) in w {
            for (a, &v) in acc.iter_mut().zip(&src[k]) {
                *a += v as f64 * x;
            }
        }
        *o = acc.map(|a| a as f32);
    }
}

fn lanes(v: &super::super::types::Value) -> Vec<f64> {
    use super::super::types::Value as V;
    match *v {
        V::Float(x) => vec![x as f64],
        V::Int(x) => vec![x as f64],
        V::Bool(x) => vec![x as u8 as f64],
        V::Float2(x) => x.iter().map(|c| *c as f64).collect(),
        V::Vector(x) => x.iter().map(|c| *c as f64).collect(),
        V::Color(x) | V::ByteColor(x) | V::Quaternion(x) => x.iter().map(|c| *c as f64).collect(),
        V::Matrix(m) => m.iter().flat_map(|c| c.iter().map(|x| *x as f64)).collect(),
        V::Int8(x) => vec![x as f64],
        V::Int2(x) => x.iter().map(|c| *c as f64).collect(),
    }
}

fn from_lanes(t: super::super::types::DataType, a: &[f64]) -> super::super::types::Value {
    use super::super::types::{DataType as T, Value as V};
    let f = |i: usize| a[i] as f32;
    match t {
        T::Float => V::Float(f(0)),
        T::Int => V::Int(a[0].round() as i32),
        T::Bool => V::Bool(a[0] != 0.0),
        T::Float2 => V::Float2([f(0), f(1)]),
        T::Vector => V::Vector([f(0), f(1), f(2)]),
        T::Color => V::Color([f(0), f(1), f(2), f(3)]),
        T::ByteColor => V::ByteColor([f(0), f(1), f(2), f(3)]),
        T::Quaternion => {
            V::Quaternion(super::super::math::normalize_quat([f(0), f(1), f(2), f(3)]))
        }
        T::Matrix => {
            let mut m = [[0.0f32; 4]; 4];
            for k in 0..16 {
                m[k / 4][k % 4] = f(k);
            }
            V::Matrix(m)
        }
        T::Int8 => V::Int8(a[0].round().clamp(-128.0, 127.0) as i8),
        T::Int2 => V::Int2([a[0].round() as i32, a[1].round() as i32]),
    }
}

fn interpolate_attributes(
    m: &Mesh,
    verts: &[Weights],
    edges: &[Option<usize>],
    corners: &[Weights],
    faces: &[usize],
) -> Attributes {
    let mut out = Attributes::default();
    for a in m.attributes.iter() {
        let data = match a.domain {
            Domain::Point => mix_array(&a.data, verts),
            Domain::Corner => mix_array(&a.data, corners),
            Domain::Face => a.data.gather(faces),
            Domain::Edge => {
                // Pieces of a coarse edge keep its values; edges inside faces get defaults.
                let mut d = Array::zeros(a.data.data_type(), edges.len());
                for (i, s) in edges.iter().enumerate() {
                    if let Some(e) = s {
                        d.set(i, a.data.get(*e));
                    }
                }
                d
            }
            _ => continue,
        };
        out.set(a.id.clone(), a.domain, data);
    }
    out
}

fn edge_row(b: &mut Build, mut e: i64, start: i64, n: i64) -> i64 {
    let mut v = start;
    for _ in 0..n - 1 {
        b.edges[e as usize] = [v as u32, (v + 1) as u32];
        e += 1;
        v += 1;
    }
    e
}

fn edge_column(b: &mut Build, mut e: i64, start: i64, n: i64) -> i64 {
    let mut v = start;
    for _ in 0..n {
        b.edges[e as usize] = [v as u32, (v + n) as u32];
        e += 1;
        v += 1;
    }
    e
}

fn edges_regular(ctx: &Ctx, b: &mut Build, f: usize) {
    let m = ctx.m;
    let res = ctx.res;
    let start_vert = ctx.vertices_inner_offset + ctx.vert_offset[f];
    let per_edge = res - 2;
    let mut e = ctx.edge_inner_offset + ctx.edge_offset[f];
    e = edge_row(b, e, start_vert, res - 2);
    for row in 0..res - 3 {
        let rs = start_vert + row * (res - 2);
        e = edge_column(b, e, rs, res - 2);
        e = edge_row(b, e, rs + res - 2, res - 2);
    }
    let r = m.face(f);
    for (corner, c) in r.clone().enumerate() {
        let cv = m.corner_verts[c];
        let ce = m.corner_edges[c] as usize;
        let start_edge_vert = ctx.vertices_edge_offset + ce as i64 * per_edge;
        let flip = m.edges[ce][1] == cv;
        let (mut side_start, side_stride) = (start_vert, 0i64);
        let stride = match corner {
            0 => 1,
            1 => {
                side_start += res - 3;
                res - 2
            }
            2 => {
                side_start += per_edge * per_edge - 1;
                -1
            }
            _ => {
                side_start += per_edge * (per_edge - 1);
                -(res - 2)
            }
        };
        let _ = side_stride;
        for i in 0..res - 2 {
            let v1 = if flip {
                start_edge_vert + (res - i - 3)
            } else {
                start_edge_vert + i
            };
            let v2 = side_start + stride * i;
            b.edges[e as usize] = [v1 as u32, v2 as u32];
            e += 1;
        }
    }
}

fn edges_special(ctx: &Ctx, b: &mut Build, f: usize) {
    let m = ctx.m;
    let res = ctx.res;
    let r = m.face(f);
    let n = r.len() as i64;
    let pr = ptex_res(r.len(), res);
    let pir = pr - 2;
    let inner_per_ptex = (pr - 1) * (pr - 2);
    let per_edge = res - 2;
    let center = ctx.vertices_inner_offset + ctx.vert_offset[f];
    let start_vert = center + 1;
    let mut e = ctx.edge_inner_offset + ctx.edge_offset[f];
    for corner in 0..n {
        let s = start_vert + corner * inner_per_ptex;
        e = edge_row(b, e, s, pir + 1);
        for row in 0..pir - 1 {
            let rs = s + row * (pir + 1);
            e = edge_column(b, e, rs, pir + 1);
            e = edge_row(b, e, rs + pir + 1, pir + 1);
        }
    }
    for corner in 0..n {
        let next = (corner + 1) % n;
        let mut cur = start_vert + corner * inner_per_ptex + pir;
        let mut nxt = start_vert + next * inner_per_ptex + inner_per_ptex - pr + 1;
        for _ in 0..pir {
            b.edges[e as usize] = [cur as u32, nxt as u32];
            e += 1;
            cur += pir + 1;
            nxt += 1;
        }
    }
    if pr >= 3 {
        for corner in 0..n {
            let end = start_vert + corner * inner_per_ptex + inner_per_ptex - 1;
            b.edges[e as usize] = [center as u32, end as u32];
            e += 1;
        }
    }
    let mut prev = n - 1;
    for corner in 0..n {
        let c = r.start + corner as usize;
        let cv = m.corner_verts[c];
        let ce = m.corner_edges[c] as usize;
        let pe = m.corner_edges[r.start + prev as usize] as usize;
        {
            let sev = ctx.vertices_edge_offset + ce as i64 * per_edge;
            let flip = m.edges[ce][1] == cv;
            let side = if pr >= 3 {
                start_vert + inner_per_ptex * corner
            } else {
                center
            };
            for i in 0..pr - 1 {
                let v1 = if flip { sev + (res - i - 3) } else { sev + i };
                b.edges[e as usize] = [v1 as u32, (side + i) as u32];
                e += 1;
            }
        }
        if pr >= 3 {
            let sev = ctx.vertices_edge_offset + pe as i64 * per_edge;
            let flip = m.edges[pe][1] == cv;
            let side = start_vert + inner_per_ptex * corner;
            for i in 0..pr - 2 {
                let v1 = if flip { sev + (res - i - 3) } else { sev + i };
                b.edges[e as usize] = [v1 as u32, (side + (pir + 1) * i) as u32];
                e += 1;
            }
        }
        prev = corner;
    }
}

/// One sub-face: vertex and edge indices rotated by `rot`, corners at the patch points
/// (u, v), (u+du, v), (u+du, v+dv), (u, v+dv).
#[allow(clippy::too_many_arguments)]
fn face(
    ctx: &Ctx,
    b: &mut Build,
    loop_start: i64,
    ptex: usize,
    rot: usize,
    v: [i64; 4],
    e: [i64; 4],
    u0: f64,
    v0: f64,
    du: f64,
    dv: f64,
) {
    let rotate = |x: [i64; 4]| {
        [
            x[(4 - rot) % 4],
            x[(5 - rot) % 4],
            x[(6 - rot) % 4],
            x[(7 - rot) % 4],
        ]
    };
    let (v, e) = (rotate(v), rotate(e));
    let uv = [(u0, v0), (u0 + du, v0), (u0 + du, v0 + dv), (u0, v0 + dv)];
    let l = loop_start as usize;
    let (f, _) = ctx.ptex_face[ptex];
    b.face_src[l / 4] = f;
    for k in 0..4 {
        b.corner_verts[l + k] = v[k] as u32;
        b.corner_edges[l + k] = e[k] as u32;
        if b.corner_weights {
            b.corner_src[l + k] = ctx.weights(ptex, uv[k].0, uv[k].1).1;
        }
    }
}

fn loops_regular(ctx: &Ctx, b: &mut Build, f: usize) {
    let m = ctx.m;
    let res = ctx.res;
    let r = m.face(f);
    let pr = res;
    let pir = pr - 2;
    let edges_per_coarse = res - 1;
    let per_edge = res - 2;
    let inv = 1.0 / (pr - 1) as f64;
    let ptex = ctx.face_ptex[f] as usize;
    let start_vert = ctx.vertices_inner_offset + ctx.vert_offset[f];
    let start_edge = ctx.edge_inner_offset + ctx.edge_offset[f];
    let mut l = 4 * ctx.face_offset[f];
    let (du, dv) = (inv, inv);
    for y in 1..pr - 2 {
        let vv = y as f64 * inv;
        let iy = y - 1;
        for x in 1..pr - 2 {
            let ix = x - 1;
            let u = x as f64 * inv;
            let v0 = start_vert + iy * pir + ix;
            let e0 = start_edge + iy * (2 * pir - 1) + ix;
            face(
                ctx,
                b,
                l,
                ptex,
                0,
                [v0, v0 + 1, v0 + pir + 1, v0 + pir],
                [e0, e0 + pir, e0 + 2 * pir - 1, e0 + pir - 1],
                u,
                vv,
                du,
                dv,
            );
            l += 4;
        }
    }
    let mut prev = r.len() - 1;
    for corner in 0..r.len() {
        let c = r.start + corner;
        let cv = m.corner_verts[c];
        let ce = m.corner_edges[c] as usize;
        let pv = m.corner_verts[r.start + prev];
        let pe = m.corner_edges[r.start + prev] as usize;
        let sev = ctx.vertices_edge_offset + ce as i64 * per_edge;
        let flip = m.edges[ce][1] == cv;
        let mut v0 = cv as i64;
        let (mut v3, mut e3) = if pv == m.edges[pe][0] {
            (
                ctx.vertices_edge_offset + pe as i64 * per_edge + per_edge - 1,
                pe as i64 * edges_per_coarse + edges_per_coarse - 1,
            )
        } else {
            (
                ctx.vertices_edge_offset + pe as i64 * per_edge,
                pe as i64 * edges_per_coarse,
            )
        };
        let (mut side_start, side_stride, e2_offset, e2_stride, u, v, delta_u, delta_v);
        side_start = start_vert;
        match corner {
            0 => {
                side_stride = 1;
                e2_offset = 0;
                e2_stride = 1;
                u = 0.0;
                v = 0.0;
                delta_u = du;
                delta_v = 0.0;
            }
            1 => {
                side_start += res - 3;
                side_stride = res - 2;
                e2_offset = 2 * edges_per_coarse - 4;
                e2_stride = 2 * edges_per_coarse - 3;
                u = 1.0 - du;
                v = 0.0;
                delta_u = 0.0;
                delta_v = dv;
            }
            2 => {
                side_start += per_edge * per_edge - 1;
                side_stride = -1;
                e2_offset = edges_per_ptex(res - 2) - 1;
                e2_stride = -1;
                u = 1.0 - du;
                v = 1.0 - dv;
                delta_u = -du;
                delta_v = 0.0;
            }
            _ => {
                side_start += per_edge * (per_edge - 1);
                side_stride = -(res - 2);
                e2_offset = edges_per_ptex(res - 2) - (2 * edges_per_coarse - 3);
                e2_stride = -(2 * edges_per_coarse - 3);
                u = 0.0;
                v = 1.0 - dv;
                delta_u = 0.0;
                delta_v = -dv;
            }
        }
        for i in 0..res - 2 {
            let v1 = if flip { sev + (res - i - 3) } else { sev + i };
            let v2 = side_start + side_stride * i;
            let e0 = if flip {
                ce as i64 * edges_per_coarse + edges_per_coarse - i - 1
            } else {
                ce as i64 * edges_per_coarse + i
            };
            let e1 = start_edge + edges_per_ptex(res - 2) + corner as i64 * per_edge + i;
            let e2 = if i == 0 {
                start_edge
                    + edges_per_ptex(res - 2)
                    + ((corner as i64 - 1 + r.len() as i64) % r.len() as i64) * per_edge
                    + per_edge
                    - 1
            } else {
                start_edge + e2_offset + e2_stride * (i - 1)
            };
            let lu = u + delta_u * i as f64;
            let lv = v + delta_v * i as f64;
            face(
                ctx,
                b,
                l,
                ptex,
                corner,
                [v0, v1, v2, v3],
                [e0, e1, e2, e3],
                lu,
                lv,
                du,
                dv,
            );
            l += 4;
            v0 = v1;
            v3 = v2;
            e3 = e1;
        }
        prev = corner;
    }
}

// Long because it follows Blender's subdivision pattern table case by case.
fn loops_special(ctx: &Ctx, b: &mut Build, f: usize) {
    let m = ctx.m;
    let res = ctx.res;
    let r = m.face(f);
    let n = r.len() as i64;
    let pr = ptex_res(r.len(), res);
    let pir = pr - 2;
    let inv = 1.0 / (pr - 1) as f64;
    let inner_per_ptex = (pr - 1) * (pr - 2);
    let inner_edges = inner_edges_per_ptex(pir + 1);
    let per_edge = res - 2;
    let edges_per_coarse = res - 1;
    let ptex = ctx.face_ptex[f] as usize;
    let center = ctx.vertices_inner_offset + ctx.vert_offset[f];
    let start_vert = center + 1;
    let start_edge = ctx.edge_inner_offset + ctx.edge_offset[f];
    let mut l = 4 * ctx.face_offset[f];
    let (du, dv) = (inv, inv);
    for corner in 0..n {
        let cvi = start_vert + corner * inner_per_ptex;
        let cei = start_edge + corner * inner_edges;
        for y in 1..pir {
            let vv = y as f64 * inv;
            let iy = y - 1;
            for x in 1..pir + 1 {
                let ix = x - 1;
                let u = x as f64 * inv;
                let v0 = cvi + iy * (pir + 1) + ix;
                let e0 = cei + iy * (2 * pir + 1) + ix;
                face(
                    ctx,
                    b,
                    l,
                    ptex + corner as usize,
                    0,
                    [v0, v0 + 1, v0 + pir + 2, v0 + pir + 1],
                    [e0, e0 + pir + 1, e0 + 2 * pir + 1, e0 + pir],
                    u,
                    vv,
                    du,
                    dv,
                );
                l += 4;
            }
        }
    }
    for corner in 0..n {
        let next = (corner + 1) % n;
        let cei = start_edge + corner * inner_edges;
        let nei = start_edge + next * inner_edges;
        let mut cur = start_vert + corner * inner_per_ptex + pir;
        let mut nxt = start_vert + next * inner_per_ptex + inner_per_ptex - pr + 1;
        let mut v0 = cur;
        let mut v1 = nxt;
        cur += pir + 1;
        nxt += 1;
        let mut e0 = start_edge + n * inner_edges + corner * (pr - 2);
        let mut e1 = nei + inner_edges - pr + 2;
        let mut e3 = cei + 2 * pr - 4;
        for row in 1..pir {
            let v2 = nxt;
            let v3 = cur;
            let e2 = e0 + 1;
            let u = row as f64 * du;
            let vv = 1.0 - dv;
            face(
                ctx,
                b,
                l,
                ptex + next as usize,
                3,
                [v0, v1, v2, v3],
                [e0, e1, e2, e3],
                u,
                vv,
                du,
                dv,
            );
            l += 4;
            cur += pir + 1;
            nxt += 1;
            v0 = v3;
            v1 = v2;
            e0 = e2;
            e1 += 1;
            e3 += 2 * pr - 3;
        }
    }
    if pr >= 3 {
        let start_center_edge = start_edge + (inner_edges + pir) * n;
        let start_boundary_edge = start_edge + n * inner_edges + pir - 1;
        let mut prev = n - 1;
        for corner in 0..n {
            let cei = start_edge + corner * inner_edges;
            let end = start_vert + corner * inner_per_ptex + inner_per_ptex - 1;
            let prev_end = start_vert + prev * inner_per_ptex + inner_per_ptex - 1;
            face(
                ctx,
                b,
                l,
                ptex + corner as usize,
                2,
                [center, prev_end, end - 1, end],
                [
                    start_center_edge + prev,
                    start_boundary_edge + prev * pir,
                    cei + inner_edges - 1,
                    start_center_edge + corner,
                ],
                1.0 - du,
                1.0 - dv,
                du,
                dv,
            );
            l += 4;
            prev = corner;
        }
    }
    let mut prev = n - 1;
    for corner in 0..n {
        let c = r.start + corner as usize;
        let cv = m.corner_verts[c];
        let ce = m.corner_edges[c] as usize;
        let pv = m.corner_verts[r.start + prev as usize];
        let pe = m.corner_edges[r.start + prev as usize] as usize;
        let flip = m.edges[ce][1] == cv;
        let sev = ctx.vertices_edge_offset + ce as i64 * per_edge;
        let cvi = start_vert + corner * inner_per_ptex;
        let cei = start_edge + corner * inner_edges;
        let mut v0 = cv as i64;
        let (mut v3, mut e3) = if pv == m.edges[pe][0] {
            (
                ctx.vertices_edge_offset + pe as i64 * per_edge + per_edge - 1,
                pe as i64 * edges_per_coarse + edges_per_coarse - 1,
            )
        } else {
            (
                ctx.vertices_edge_offset + pe as i64 * per_edge,
                pe as i64 * edges_per_coarse,
            )
        };
        for i in 0..=pir {
            let v1 = if flip { sev + (res - i - 3) } else { sev + i };
            let v2 = if pir >= 1 { cvi + i } else { center };
            let e0 = if flip {
                ce as i64 * edges_per_coarse + edges_per_coarse - i - 1
            } else {
                ce as i64 * edges_per_coarse + i
            };
            let mut e1 = start_edge + corner * (2 * pir + 1);
            if pr >= 3 {
                e1 += n * (inner_edges + pir + 1) + i;
            }
            let e2 = if i == 0 && pr >= 3 {
                start_edge + n * (inner_edges + pir + 1) + corner * (2 * pir + 1) + pir + 1
            } else if i == 0 {
                start_edge + prev * (2 * pir + 1)
            } else {
                cei + i - 1
            };
            face(
                ctx,
                b,
                l,
                ptex + corner as usize,
                0,
                [v0, v1, v2, v3],
                [e0, e1, e2, e3],
                du * i as f64,
                0.0,
                du,
                dv,
            );
            l += 4;
            v0 = v1;
            v3 = v2;
            e3 = e1;
        }
        let flip_prev = m.edges[pe][1] == cv;
        v0 = cvi;
        v3 = if pv == m.edges[pe][0] {
            ctx.vertices_edge_offset + pe as i64 * per_edge + per_edge - 1
        } else {
            ctx.vertices_edge_offset + pe as i64 * per_edge
        };
        e3 = start_edge + n * (inner_edges + pir + 1) + corner * (2 * pir + 1) + pir + 1;
        for i in 0..pir {
            let (v1, e0, e1);
            if i == pir - 1 {
                v1 = start_vert + prev * inner_per_ptex + pir;
                e1 = start_edge + n * (inner_edges + pir + 1) + prev * (2 * pir + 1) + pir;
                e0 = start_edge + n * inner_edges + prev * pir;
            } else {
                v1 = v0 + pir + 1;
                e0 = cei + pir + i * (2 * pir + 1);
                e1 = e3 + 1;
            }
            let v2 = if flip_prev { v3 - 1 } else { v3 + 1 };
            let e2 = if flip_prev {
                pe as i64 * edges_per_coarse + edges_per_coarse - 2 - i
            } else {
                pe as i64 * edges_per_coarse + 1 + i
            };
            face(
                ctx,
                b,
                l,
                ptex + corner as usize,
                1,
                [v0, v1, v2, v3],
                [e0, e1, e2, e3],
                0.0,
                du * (i + 1) as f64,
                du,
                dv,
            );
            l += 4;
            v0 = v1;
            v3 = v2;
            e3 = e1;
        }
        prev = corner;
    }
}

pub fn subdivide_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let level = ctx.int("Level")?.clamp(0, 11) as u32;
    if level > 0 {
        modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
            if let Some(m) = s.mesh.clone() {
                if m.face_count() > 0 {
                    limits::check(
                        limits::subdivided_corners(m.corner_count() as u64, level),
                        &format!("Level {level} on a mesh of {} faces", m.face_count()),
                    )?;
                    // A new Arc: `mesh_mut` would first deep-copy the shared input.
                    s.mesh = Some(std::sync::Arc::new(subdivide_mesh(&m, level)));
                }
            }
            Ok(())
        })
        .map_err(|e| ctx.err(e))?;
    }
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}
