//! Mesh to Curve (`geometry::mesh_to_curve_convert`): the selected edges become poly
//! curves. Runs start at every vertex without exactly two selected edges (in vertex
//! order, each unused edge in the order the edges list it) and follow two-edge vertices
//! until a vertex with another count; what is left are closed loops, cyclic curves
//! started at their lowest vertex. Point attributes follow the vertices. In Faces mode
//! every selected face becomes a cyclic curve (`mesh_faces_to_curves`).

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curves::{Curves, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// Vertex indices of each curve, curve offsets, and where the cyclic curves begin.
pub fn edges_to_curve_points(verts: usize, edges: &[[u32; 2]]) -> (Vec<u32>, Vec<u32>, usize) {
    let mut offs = vec![0usize; verts + 1];
    for e in edges {
        offs[e[0] as usize] += 1;
        offs[e[1] as usize] += 1;
    }
    let mut acc = 0;
    for o in offs.iter_mut() {
        let n = *o;
        *o = acc;
        acc += n;
    }
    let count = |v: usize| offs[v + 1] - offs[v];
    let mut used = vec![0usize; verts];
    let mut neighbors = vec![0u32; edges.len() * 2];
    for e in edges {
        let (a, b) = (e[0] as usize, e[1] as usize);
        neighbors[offs[a] + used[a]] = b as u32;
        neighbors[offs[b] + used[b]] = a as u32;
        used[a] += 1;
        used[b] += 1;
    }
    let mut unused = used;
    let mut points = Vec::with_capacity(edges.len() + 1);
    let mut curve_offsets = Vec::new();
    for start in 0..verts {
        if count(start) == 2 || unused[start] == 0 {
            continue;
        }
        for k in offs[start]..offs[start + 1] {
            let mut current = start;
            let mut next = neighbors[k] as usize;
            if unused[next] == 0 {
                continue;
            }
            curve_offsets.push(points.len() as u32);
            points.push(current as u32);
            loop {
                let last = current;
                current = next;
                points.push(current as u32);
                unused[current] -= 1;
                unused[last] -= 1;
                if count(current) != 2 {
                    break;
                }
                let (a, b) = (
                    neighbors[offs[current]] as usize,
                    neighbors[offs[current] + 1] as usize,
                );
                next = if last == a { b } else { a };
            }
        }
    }
    let cyclic_start = curve_offsets.len();
    for start in 0..verts {
        if unused[start] != 2 {
            continue;
        }
        let mut current = start;
        let mut next = neighbors[offs[start]] as usize;
        curve_offsets.push(points.len() as u32);
        points.push(current as u32);
        while next != start {
            let last = current;
            current = next;
            points.push(current as u32);
            unused[current] -= 1;
            unused[last] -= 1;
            let (a, b) = (
                neighbors[offs[current]] as usize,
                neighbors[offs[current] + 1] as usize,
            );
            next = if last == a { b } else { a };
        }
    }
    (points, curve_offsets, cyclic_start)
}

fn is_mesh_builtin(n: &str) -> bool {
    n.starts_with('.') || matches!(n, "sharp_face" | "sharp_edge" | "material_index")
}

/// The curves made of `edges` of `m`.
pub fn mesh_edges_to_curves(m: &Mesh, edges: &[[u32; 2]]) -> Curves {
    let (points, mut offsets, cyclic_start) = edges_to_curve_points(m.vertex_count(), edges);
    let n_curves = offsets.len();
    offsets.push(points.len() as u32);
    let idx: Vec<usize> = points.iter().map(|&v| v as usize).collect();
    let mut c = Curves {
        positions: idx.iter().map(|&v| m.positions[v]).collect(),
        curve_offsets: offsets,
        ..Default::default()
    };
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY; n_curves]),
    );
    if cyclic_start < n_curves {
        c.attributes.set(
            AttrId::named("cyclic"),
            Domain::Curve,
            Array::Bool((0..n_curves).map(|i| i >= cyclic_start).collect()),
        );
    }
    for a in m.attributes.iter() {
        if a.id.name().is_some_and(is_mesh_builtin) {
            continue;
        }
        let on_points = ComponentRef::Mesh(m).adapt(&a.data, a.domain, Domain::Point);
        c.attributes
            .set(a.id.clone(), Domain::Point, on_points.gather(&idx));
    }
    c.materials = m.materials.clone();
    c
}

/// `mesh_faces_to_curves_convert`: each selected face a cyclic poly curve through its
/// corners' vertices; point and edge attributes follow the vertices, corner attributes
/// the corners, face attributes go to the curves.
pub fn mesh_faces_to_curves(m: &Mesh, faces: &[usize]) -> Curves {
    let mut offsets = vec![0u32];
    let mut corners: Vec<usize> = Vec::new();
    for &f in faces {
        corners.extend(m.face(f));
        offsets.push(corners.len() as u32);
    }
    let verts: Vec<usize> = corners
        .iter()
        .map(|&c| m.corner_verts[c] as usize)
        .collect();
    let n = faces.len();
    let mut c = Curves {
        positions: verts.iter().map(|&v| m.positions[v]).collect(),
        curve_offsets: offsets,
        ..Default::default()
    };
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY; n]),
    );
    c.attributes.set(
        AttrId::named("cyclic"),
        Domain::Curve,
        Array::Bool(vec![true; n]),
    );
    for a in m.attributes.iter() {
        if a.id
            .name()
            .is_some_and(|x| x.starts_with('.') || matches!(x, "sharp_face" | "sharp_edge"))
        {
            continue;
        }
        match a.domain {
            Domain::Point | Domain::Edge => {
                let on_points = ComponentRef::Mesh(m).adapt(&a.data, a.domain, Domain::Point);
                c.attributes
                    .set(a.id.clone(), Domain::Point, on_points.gather(&verts));
            }
            Domain::Corner => {
                c.attributes
                    .set(a.id.clone(), Domain::Point, a.data.gather(&corners))
            }
            Domain::Face => c
                .attributes
                .set(a.id.clone(), Domain::Curve, a.data.gather(faces)),
            _ => {}
        }
    }
    c.materials = m.materials.clone();
    c
}

pub fn mesh_to_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let faces_mode = match ctx.prop_str("mode").unwrap_or("EDGES") {
        "EDGES" => false,
        "FACES" => true,
        other => return Err(ctx.err(format!("mode {other} is not a Mesh to Curve mode"))),
    };
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let curves = if faces_mode {
            let r = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Face,
                &[(&sel, DataType::Bool)],
            )?;
            let sel = r[0].as_bool();
            let faces: Vec<usize> = (0..m.face_count()).filter(|&f| sel[f]).collect();
            (!faces.is_empty()).then(|| mesh_faces_to_curves(&m, &faces))
        } else {
            let r = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Edge,
                &[(&sel, DataType::Bool)],
            )?;
            let sel = r[0].as_bool();
            let edges: Vec<[u32; 2]> = (0..m.edge_count())
                .filter(|&e| sel[e])
                .map(|e| m.edges[e])
                .collect();
            (!edges.is_empty()).then(|| mesh_edges_to_curves(&m, &edges))
        };
        s.mesh = None;
        s.points = None;
        s.curves = curves.map(Arc::new);
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}
