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

use super::super::bmesh::{BMesh, NONE};
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
    *g.mesh_mut().unwrap() = split(&m, &tags)?;
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

/// `BM_vert_separate_hflag` with the tag: each tagged edge of `v` with several faces is
/// separated (stopping before the copies appended to the disk), then `v`'s fans, then
/// copies still joining the same vertices as their edge merge back into it
/// (`bmesh_kernel_vert_separate__cleanup`, the last separated edge first).
fn vert_separate_tagged(bm: &mut BMesh, v: u32) {
    let mut separated: Vec<Vec<u32>> = Vec::new();
    let mut e_first = bm.vert_e[v as usize];
    if e_first == NONE {
        return;
    }
    let mut e_iter = e_first;
    loop {
        if bm.edge_tag[e_iter as usize] && bm.separable(e_iter) {
            let e = e_iter;
            let mut copies = Vec::new();
            while bm.separable(e) {
                let l_sep = bm.edges[e as usize].l;
                let e_new = bm.edge_separate(e, l_sep);
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
        e_iter = bm.disk_next(e_iter, v);
        if e_iter == e_first {
            break;
        }
    }
    bm.vert_separate(v);
    for list in separated.iter().rev() {
        let mut live = list.clone();
        let mut i = 0;
        while i + 1 < live.len() {
            let orig = live[i];
            let mut j = i + 1;
            while j < live.len() {
                let e = live[j];
                if bm.edges[e as usize].v == bm.edges[orig as usize].v {
                    bm.edge_splice(orig, e);
                    live.remove(j);
                } else {
                    j += 1;
                }
            }
            i += 1;
        }
    }
}

/// `BM_mesh_edgesplit(bm, use_verts=false, tag_only=true)` and back to a mesh.
fn split(m: &Mesh, tags: &[bool]) -> Result<Mesh, String> {
    let mut bm = BMesh::from_mesh(m);
    let mut vert_tag = vec![false; m.vertex_count()];
    for (i, &t) in tags.iter().enumerate() {
        bm.edge_tag[i] = t;
        if t {
            for v in m.edges[i] {
                vert_tag[v as usize] = true;
            }
        }
    }
    // Edges made on the way are visited too (the pool is iterated live), but none of
    // their vertices is tagged any more (new vertices never are).
    let mut i = 0;
    while i < bm.edges.len() {
        if bm.edges[i].alive && bm.edge_tag[i] {
            for k in 0..2 {
                let v = bm.edges[i].v[k] as usize;
                if vert_tag.get(v).copied().unwrap_or(false) {
                    vert_tag[v] = false;
                    vert_separate_tagged(&mut bm, v as u32);
                }
            }
        }
        i += 1;
    }
    bm.into_mesh(m)
}
