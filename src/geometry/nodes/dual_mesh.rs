//! Dual Mesh (`node_geo_dual_mesh.cc`): faces become vertices (at their centres, in face
//! order) and manifold vertices become faces (their faces sorted around them in the first
//! face's winding). Boundary vertices are dropped, or with Keep Boundaries closed off
//! through the midpoints of their boundary edges (appended after the face centres, in
//! edge order) and a copy of the vertex. Vertices between exactly two faces are dissolved
//! into one edge first. Face attributes move to the vertices, vertex attributes to the
//! faces, edge and corner attributes follow the edge / corner each new one came from.
//! The result is flat shaded.

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::mesh::Mesh;
use super::super::types::{Array, Domain};
use super::geometry_ops::{geo, modify_geometry_sets};

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum EdgeType {
    Loose,
    Boundary,
    Normal,
    NonManifold,
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum VertType {
    Loose,
    Normal,
    Boundary,
    NonManifold,
}

fn classify(m: &Mesh) -> (Vec<VertType>, Vec<EdgeType>) {
    let mut et = vec![EdgeType::Loose; m.edge_count()];
    for &e in &m.corner_edges {
        let t = &mut et[e as usize];
        *t = match *t {
            EdgeType::Loose => EdgeType::Boundary,
            EdgeType::Boundary => EdgeType::Normal,
            _ => EdgeType::NonManifold,
        };
    }
    let mut vt = vec![VertType::Loose; m.vertex_count()];
    for (e, ev) in m.edges.iter().enumerate() {
        match et[e] {
            EdgeType::Boundary => {
                for v in ev {
                    let t = &mut vt[*v as usize];
                    *t = match *t {
                        VertType::Loose => VertType::Normal,
                        VertType::Normal => VertType::Boundary,
                        _ => VertType::NonManifold,
                    };
                }
            }
            EdgeType::NonManifold => {
                vt[ev[0] as usize] = VertType::NonManifold;
                vt[ev[1] as usize] = VertType::NonManifold;
            }
            _ => {}
        }
    }
    for (e, ev) in m.edges.iter().enumerate() {
        if et[e] == EdgeType::Normal {
            for v in ev {
                if vt[*v as usize] == VertType::Loose {
                    vt[*v as usize] = VertType::Normal;
                }
            }
        }
    }
    (vt, et)
}

fn edge_has(m: &Mesh, e: usize, v: usize) -> bool {
    m.edges[e][0] as usize == v || m.edges[e][1] as usize == v
}

/// Sorts `faces` around vertex `v` (`sort_vertex_faces`); fills the shared edges and each
/// face's corner. False when the faces do not form a fan.
fn sort_faces(
    m: &Mesh,
    v: usize,
    boundary: bool,
    et: &[EdgeType],
    faces: &mut [usize],
    shared: &mut Vec<usize>,
    sorted: &mut Vec<usize>,
) -> bool {
    let n = faces.len();
    sorted.clear();
    sorted.resize(n, 0);
    shared.clear();
    shared.resize(if boundary { n.saturating_sub(1) } else { n }, 0);
    if n <= 2 && (!boundary || n == 0) {
        return true;
    }
    // The two corners of each face whose edge touches the vertex, in face order.
    let mut fc: Vec<(usize, usize)> = faces
        .iter()
        .map(|&f| {
            let mut it = m
                .face(f)
                .filter(|&c| edge_has(m, m.corner_edges[c] as usize, v));
            let a = it.next().unwrap_or(0);
            (a, it.next().unwrap_or(a))
        })
        .collect();
    let ce = |c: usize| m.corner_edges[c] as usize;
    let cv = |c: usize| m.corner_verts[c] as usize;
    let mut shared_edge: Option<usize> = None;
    if boundary {
        for pass in 0..2 {
            for i in 0..n {
                let (c1, c2) = fc[i];
                let pick = if et[ce(c1)] == EdgeType::Boundary && (pass == 1 || cv(c1) == v) {
                    Some((ce(c2), c1))
                } else if et[ce(c2)] == EdgeType::Boundary && (pass == 1 || cv(c2) == v) {
                    Some((ce(c1), c2))
                } else {
                    None
                };
                if let Some((e, c)) = pick {
                    shared_edge = Some(e);
                    sorted[0] = c;
                    faces.swap(i, 0);
                    fc.swap(i, 0);
                    break;
                }
            }
            if shared_edge.is_some() {
                break;
            }
        }
    } else {
        let (c1, c2) = fc[0];
        if cv(c1) == v {
            shared_edge = Some(ce(c2));
            sorted[0] = c1;
        } else {
            sorted[0] = c2;
            shared_edge = Some(ce(c1));
        }
    }
    let Some(mut se) = shared_edge else {
        return false;
    };
    for i in 0..n - 1 {
        shared[i] = se;
        let mut found = None;
        for j in i + 1..n {
            let (c1, c2) = fc[j];
            if ce(c1) == se {
                sorted[i + 1] = c1;
                se = ce(c2);
                found = Some(j);
                break;
            }
            if ce(c2) == se {
                sorted[i + 1] = c2;
                se = ce(c1);
                found = Some(j);
                break;
            }
        }
        let Some(j) = found else { return false };
        faces.swap(i + 1, j);
        fc.swap(i + 1, j);
    }
    if !boundary {
        shared[n - 1] = se;
    }
    true
}

fn boundary_edge_on_face(m: &Mesh, f: usize, v: usize, et: &[EdgeType]) -> usize {
    m.face(f)
        .map(|c| m.corner_edges[c] as usize)
        .find(|&e| et[e] == EdgeType::Boundary && edge_has(m, e, v))
        .unwrap_or(0)
}

/// The two boundary edges of `f` at `v`, in the face's winding.
fn boundary_edges_on_face(m: &Mesh, f: usize, v: usize, et: &[EdgeType]) -> (usize, usize) {
    let (mut e1, mut e2) = (0, 0);
    let mut first = false;
    let mut swap = false;
    for c in m.face(f) {
        let e = m.corner_edges[c] as usize;
        if et[e] == EdgeType::Boundary && edge_has(m, e, v) {
            if first {
                if swap {
                    e2 = e1;
                    e1 = e;
                } else {
                    e2 = e;
                }
                return (e1, e2);
            }
            e1 = e;
            first = true;
            if m.corner_verts[c] as usize == v {
                swap = true;
            }
        }
    }
    (e1, e2)
}

// Long because it follows Blender's Dual Mesh node step by step.
pub fn dual(m: &Mesh, keep_boundaries: bool) -> Mesh {
    let (mut vt, et) = classify(m);
    let nv = m.vertex_count();
    // Faces of each vertex in face order (one entry per corner, as Blender's map).
    let mut vert_faces: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            vert_faces[m.corner_verts[c] as usize].push(f);
        }
    }
    let usable = |t: VertType| {
        !(t == VertType::Loose
            || t >= VertType::NonManifold
            || (!keep_boundaries && t == VertType::Boundary))
    };
    let mut sorted_faces = vert_faces.clone();
    let mut shared_edges: Vec<Vec<usize>> = vec![Vec::new(); nv];
    let mut sorted_corners: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for v in 0..nv {
        if !usable(vt[v]) {
            continue;
        }
        let (mut sh, mut so) = (Vec::new(), Vec::new());
        if !sort_faces(
            m,
            v,
            vt[v] == VertType::Boundary,
            &et,
            &mut sorted_faces[v],
            &mut sh,
            &mut so,
        ) {
            vt[v] = VertType::NonManifold;
            continue;
        }
        shared_edges[v] = sh;
        sorted_corners[v] = so;
    }
    let mut positions: Vec<[f32; 3]> = (0..m.face_count())
        .map(|f| {
            let r = m.face(f);
            let mut s = [0.0f32; 3];
            for c in r.clone() {
                let p = m.positions[m.corner_verts[c] as usize];
                for k in 0..3 {
                    s[k] += p[k];
                }
            }
            let inv = 1.0 / r.len() as f32;
            s.map(|x| x * inv)
        })
        .collect();
    let mut midpoint = vec![0usize; m.edge_count()];
    if keep_boundaries {
        for (e, ev) in m.edges.iter().enumerate() {
            if et[e] == EdgeType::Boundary {
                let (a, b) = (m.positions[ev[0] as usize], m.positions[ev[1] as usize]);
                midpoint[e] = positions.len();
                positions.push([
                    (a[0] + b[0]) * 0.5,
                    (a[1] + b[1]) * 0.5,
                    (a[2] + b[2]) * 0.5,
                ]);
            }
        }
    }
    let mut out = Mesh::new();
    let mut new_edges: Vec<[u32; 2]> = Vec::new();
    let mut edge_src: Vec<usize> = Vec::new();
    let mut corner_src: Vec<usize> = Vec::new();
    let mut face_src_vert: Vec<usize> = Vec::new();
    let mut boundary_face_of: Vec<(usize, usize)> = Vec::new();
    let mut old_to_new = vec![usize::MAX; m.edge_count()];

    // Vertices between exactly two faces dissolve into one edge between the faces.
    let needs_dissolve = |vt: &[VertType], x: usize, f0: usize, f1: usize| {
        vt[x] != VertType::Boundary
            && vert_faces[x].len() == 2
            && vert_faces[x][0] == f0
            && vert_faces[x][1] == f1
    };
    for v in 0..nv {
        if vert_faces[v].len() != 2 || vt[v] != VertType::Normal {
            continue;
        }
        let (f0, f1) = (vert_faces[v][0], vert_faces[v][1]);
        let new_index = new_edges.len();
        let mut created = false;
        for c in m.face(f0) {
            let e = m.corner_edges[c] as usize;
            let [a, b] = m.edges[e];
            let mut mark = false;
            for x in [a as usize, b as usize] {
                if needs_dissolve(&vt, x, f0, f1) {
                    vt[x] = VertType::Loose;
                    mark = true;
                }
            }
            if mark {
                if !created {
                    edge_src.push(e);
                    new_edges.push([f0 as u32, f1 as u32]);
                    created = true;
                }
                old_to_new[e] = new_index;
            }
        }
    }

    for v in 0..nv {
        if !usable(vt[v]) {
            continue;
        }
        let mut ring: Vec<usize> = sorted_faces[v].clone();
        let shared = &shared_edges[v];
        let sorted = &sorted_corners[v];
        let mut add_shared = |i: usize,
                              a: usize,
                              b: usize,
                              out: &mut Mesh,
                              new_edges: &mut Vec<[u32; 2]>,
                              edge_src: &mut Vec<usize>| {
            let e = shared[i];
            if old_to_new[e] == usize::MAX {
                edge_src.push(e);
                old_to_new[e] = new_edges.len();
                new_edges.push([a as u32, b as u32]);
            }
            out.corner_edges.push(old_to_new[e] as u32);
        };
        if vt[v] == VertType::Normal {
            if ring.len() <= 2 {
                continue;
            }
            for i in 0..shared.len() {
                add_shared(
                    i,
                    ring[i],
                    ring[(i + 1) % ring.len()],
                    &mut out,
                    &mut new_edges,
                    &mut edge_src,
                );
            }
            corner_src.extend(sorted.iter().copied());
        } else {
            for i in 0..shared.len() {
                add_shared(
                    i,
                    ring[i],
                    ring[i + 1],
                    &mut out,
                    &mut new_edges,
                    &mut edge_src,
                );
            }
            corner_src.extend(sorted.iter().copied());
            let (e1, e2) = if ring.len() >= 2 {
                (
                    boundary_edge_on_face(m, *ring.last().unwrap(), v, &et),
                    boundary_edge_on_face(m, ring[0], v, &et),
                )
            } else {
                boundary_edges_on_face(m, ring[0], v, &et)
            };
            let push_edge = |e: usize,
                             a: usize,
                             b: usize,
                             out: &mut Mesh,
                             new_edges: &mut Vec<[u32; 2]>,
                             edge_src: &mut Vec<usize>| {
                edge_src.push(e);
                new_edges.push([a as u32, b as u32]);
                out.corner_edges.push((new_edges.len() - 1) as u32);
            };
            let last_center = *ring.last().unwrap();
            ring.push(midpoint[e1]);
            corner_src.push(*sorted.last().unwrap());
            let first_mid = midpoint[e1];
            if old_to_new[e1] == usize::MAX {
                push_edge(
                    e1,
                    last_center,
                    first_mid,
                    &mut out,
                    &mut new_edges,
                    &mut edge_src,
                );
                old_to_new[e1] = new_edges.len() - 1;
                boundary_face_of.push((first_mid, last_center));
            } else {
                out.corner_edges.push(old_to_new[e1] as u32);
            }
            let bv = positions.len();
            ring.push(bv);
            corner_src.push(sorted[0]);
            boundary_face_of.push((bv, last_center));
            positions.push(m.positions[v]);
            push_edge(e1, first_mid, bv, &mut out, &mut new_edges, &mut edge_src);
            let second_mid = midpoint[e2];
            ring.push(second_mid);
            corner_src.push(sorted[0]);
            push_edge(e2, bv, second_mid, &mut out, &mut new_edges, &mut edge_src);
            if old_to_new[e2] == usize::MAX {
                let first_center = ring[0];
                push_edge(
                    e2,
                    second_mid,
                    first_center,
                    &mut out,
                    &mut new_edges,
                    &mut edge_src,
                );
                old_to_new[e2] = new_edges.len() - 1;
                boundary_face_of.push((second_mid, first_center));
            } else {
                out.corner_edges.push(old_to_new[e2] as u32);
            }
        }
        face_src_vert.push(v);
        out.corner_verts.extend(ring.iter().map(|&x| x as u32));
        out.face_offsets.push(out.corner_verts.len() as u32);
    }
    out.positions = positions;
    out.edges = new_edges;
    out.materials = m.materials.clone();
    out.set_smooth(false);
    let nf_src = m.face_count();
    for a in m.attributes.iter() {
        if a.id.name() == Some("sharp_face") {
            continue;
        }
        let data = match a.domain {
            Domain::Point => (Domain::Face, a.data.gather(&face_src_vert)),
            Domain::Edge => (Domain::Edge, a.data.gather(&edge_src)),
            Domain::Corner => (Domain::Corner, a.data.gather(&corner_src)),
            Domain::Face => {
                let mut d = Array::zeros(a.data.data_type(), out.positions.len());
                d.scatter(&(0..nf_src).collect::<Vec<_>>(), &a.data);
                if keep_boundaries {
                    for &(nv_, f) in &boundary_face_of {
                        d.set(nv_, a.data.get(f));
                    }
                }
                (Domain::Point, d)
            }
            _ => continue,
        };
        out.attributes.set(a.id.clone(), data.0, data.1);
    }
    out
}

pub fn dual_mesh(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let keep = ctx.bool("Keep Boundaries")?;
    modify_geometry_sets(&mut g, &mut |s| {
        if let Some(m) = s.mesh.clone() {
            s.mesh = Some(Arc::new(dual(&m, keep)));
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Dual Mesh", geo(g))]))
}
