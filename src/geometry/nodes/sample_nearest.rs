//! Sample Nearest (`node_geo_sample_nearest.cc`) and Sample Nearest Surface
//! (`node_geo_sample_nearest_surface.cc`).
//!
//! Sample Nearest gives the index of the nearest element of the chosen domain: mesh
//! vertices, edges (as segments), faces (through their corner triangles) or corners (the
//! nearest corner of the nearest face, the first of equally near ones); a mesh without
//! elements of that domain falls back to the point cloud's points (point domain only), and
//! with neither every index is 0. Instances are not looked into.
//!
//! Sample Nearest Surface finds the nearest point on the mesh's corner triangles, among
//! the faces whose Group ID equals the sample's Sample Group ID (none: Is Valid false and
//! the cleared value), and samples the value there by barycentric weights (`mesh_sample`).
//!
//! Among exactly equally near elements the lowest index wins (`nearest`); Blender's choice
//! there depends on its BVH's layout.

use std::collections::HashMap;
use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext};
use super::super::math::V3;
use super::super::mesh::Mesh;
use super::super::mesh_sample::{cleared, corner_values, sample, Triangles};
use super::super::nearest::{
    bounds_of, closest_on_segment, closest_on_triangle, dist_sq, nearest_tree,
};
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::raycast::sample_data_type;
use crate::foundation::box_tree::BoxTree;

/// What Sample Nearest searches.
enum Target {
    /// Every index 0 (no component has elements of the domain).
    Nothing,
    Points(Vec<V3>, BoxTree),
    Edges(Vec<[V3; 2]>, BoxTree),
    /// Triangles and the face of each.
    Faces(Triangles, BoxTree),
    /// Triangles, and the mesh for the corners of the nearest face.
    Corners(Triangles, BoxTree, Arc<Mesh>),
}

fn tri_tree(t: &Triangles) -> BoxTree {
    nearest_tree(&t.positions.iter().map(|p| bounds_of(p)).collect::<Vec<_>>())
}

fn nearest_tri(tris: &Triangles, tree: &BoxTree, q: V3) -> Option<(u32, V3)> {
    tree.nearest(q, |t| {
        let [a, b, c] = tris.positions[t as usize];
        let p = closest_on_triangle(q, a, b, c);
        (dist_sq(q, p), p)
    })
    .map(|(t, _, p)| (t, p))
}

impl Target {
    fn index(&self, q: V3) -> i32 {
        let found = match self {
            Target::Nothing => return 0,
            Target::Points(p, tree) => tree
                .nearest(q, |i| (dist_sq(p[i as usize], q), ()))
                .map(|r| r.0),
            Target::Edges(s, tree) => tree
                .nearest(q, |i| {
                    (
                        dist_sq(closest_on_segment(q, s[i as usize][0], s[i as usize][1]), q),
                        (),
                    )
                })
                .map(|r| r.0),
            Target::Faces(tris, tree) => {
                nearest_tri(tris, tree, q).map(|(t, _)| tris.faces[t as usize])
            }
            Target::Corners(tris, tree, m) => {
                let Some((t, _)) = nearest_tri(tris, tree, q) else {
                    return -1;
                };
                let face = m.face(tris.faces[t as usize] as usize);
                let mut best = (face.start, f32::MAX);
                for c in face {
                    let d = dist_sq(q, m.positions[m.corner_verts[c] as usize]);
                    if d < best.1 {
                        best = (c, d);
                    }
                }
                Some(best.0 as u32)
            }
        };
        found.map_or(-1, |i| i as i32)
    }
}

pub fn sample_nearest(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    let d = ctx.prop_str("domain")?;
    let domain = match Domain::parse(d) {
        Some(x @ (Domain::Point | Domain::Edge | Domain::Face | Domain::Corner)) => x,
        _ => return Err(ctx.err(format!("domain {d} is not supported"))),
    };
    let mesh = g.mesh.clone().filter(|m| m.domain_size(domain) > 0);
    let points = g
        .points
        .clone()
        .filter(|p| domain == Domain::Point && !p.positions.is_empty());
    let target = if let Some(m) = mesh {
        match domain {
            Domain::Point => Target::Points(
                m.positions.clone(),
                nearest_tree(&m.positions.iter().map(|p| (*p, *p)).collect::<Vec<_>>()),
            ),
            Domain::Edge => {
                let segs: Vec<[V3; 2]> = m
                    .edges
                    .iter()
                    .map(|e| [m.positions[e[0] as usize], m.positions[e[1] as usize]])
                    .collect();
                let tree = nearest_tree(&segs.iter().map(|s| bounds_of(s)).collect::<Vec<_>>());
                Target::Edges(segs, tree)
            }
            Domain::Face => {
                let tris = Triangles::new(&m).map_err(|e| ctx.err(e))?;
                let tree = tri_tree(&tris);
                Target::Faces(tris, tree)
            }
            _ => {
                let tris = Triangles::new(&m).map_err(|e| ctx.err(e))?;
                let tree = tri_tree(&tris);
                Target::Corners(tris, tree, m)
            }
        }
    } else if let Some(p) = points {
        Target::Points(
            p.positions.clone(),
            nearest_tree(&p.positions.iter().map(|p| (*p, *p)).collect::<Vec<_>>()),
        )
    } else {
        Target::Nothing
    };
    let target = Arc::new(target);
    let pos = ctx.field("Sample Position", DataType::Vector)?;
    let f = Field::op1("Sample Nearest", vec![pos], DataType::Int, move |_, a| {
        Ok(Array::Int(
            a[0].as_vector().iter().map(|q| target.index(*q)).collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Index", SocketValue::Field(f))]))
}

/// The triangles of one Group ID and their tree.
struct Group {
    tris: Vec<u32>,
    tree: BoxTree,
}

pub fn sample_nearest_surface(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Mesh")?;
    let ty = sample_data_type(ctx)?;
    let value = ctx.field("Value", ty)?;
    let group_id = ctx.field("Group ID", DataType::Int)?;
    // No mesh, no vertices, or no faces (Blender warns about the latter): default outputs.
    let Some(mesh) = g
        .mesh
        .clone()
        .filter(|m| m.vertex_count() > 0 && m.face_count() > 0)
    else {
        return Ok(outputs([
            (
                "Value",
                SocketValue::Field(Field::Constant(Value::zero(ty))),
            ),
            (
                "Is Valid",
                SocketValue::Field(Field::Constant(Value::Bool(false))),
            ),
        ]));
    };
    let tris = Triangles::new(&mesh).map_err(|e| ctx.err(e))?;
    let values = corner_values(&mesh, &value, ty).map_err(|e| ctx.err(format!("Value: {e}")))?;
    let ids = FieldContext::new(ComponentRef::Mesh(&mesh))
        .eval(&group_id, Domain::Face, DataType::Int)
        .map_err(|e| ctx.err(format!("Group ID: {e}")))?;
    let ids = ids.as_int();
    let mut index: HashMap<i32, usize> = HashMap::new();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for (t, &f) in tris.faces.iter().enumerate() {
        let id = ids[f as usize];
        let k = *index.entry(id).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[k].push(t as u32);
    }
    let groups: Vec<Group> = groups
        .into_iter()
        .map(|tris_of| {
            let tree = nearest_tree(
                &tris_of
                    .iter()
                    .map(|&t| bounds_of(&tris.positions[t as usize]))
                    .collect::<Vec<_>>(),
            );
            Group {
                tris: tris_of,
                tree,
            }
        })
        .collect();
    let shared = Arc::new((tris, values, index, groups));
    let pos = ctx.field("Sample Position", DataType::Vector)?;
    let sample_id = ctx.field("Sample Group ID", DataType::Int)?;
    let fields = Field::op(
        "Sample Nearest Surface",
        vec![pos, sample_id],
        vec![ty, DataType::Bool],
        move |n, a| {
            let (tris, values, index, groups) = &*shared;
            let (pos, sid) = (a[0].as_vector(), a[1].as_int());
            let mut out = Array::filled(cleared(ty), n);
            let mut valid = vec![false; n];
            for i in 0..n {
                let Some(group) = index.get(&sid[i]).map(|&k| &groups[k]) else {
                    continue;
                };
                let q = pos[i];
                // The tree's elements are the group's triangles by position in `group.tris`.
                let found = group.tree.nearest(q, |k| {
                    let [a, b, c] = tris.positions[group.tris[k as usize] as usize];
                    let p = closest_on_triangle(q, a, b, c);
                    (dist_sq(q, p), p)
                });
                valid[i] = true;
                if let Some((k, _, p)) = found {
                    let t = group.tris[k as usize] as usize;
                    out.set(i, sample(values, tris, t, tris.bary_weights(t, p)));
                }
            }
            Ok(vec![out, Array::Bool(valid)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter().map(SocketValue::Field);
    let (v, ok) = (it.next().unwrap(), it.next().unwrap());
    Ok(outputs([("Value", v), ("Is Valid", ok)]))
}
