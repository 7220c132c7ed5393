//! Edge Paths to Curves (`node_geo_edge_paths_to_curves`): one poly curve per start
//! vertex whose next vertex is another valid one, following Next Vertex Index links until
//! a vertex already on this curve or an index out of range. Point attributes (other
//! domains moved to points) follow the vertices; the mesh is replaced by the curves.

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curves::{Curves, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// The vertices of each path, concatenated, and the curve offsets.
fn paths(n: usize, start: &[bool], next: &[i32]) -> (Vec<usize>, Vec<u32>) {
    let mut verts = Vec::new();
    let mut offsets = vec![0u32];
    let mut visited = vec![false; n];
    let valid = |v: i32| v >= 0 && (v as usize) < n;
    for first in (0..n).filter(|&i| start[i]) {
        let second = next[first];
        if second == first as i32 || !valid(second) {
            continue;
        }
        let begin = verts.len();
        let mut at = first;
        while !visited[at] {
            visited[at] = true;
            verts.push(at);
            if !valid(next[at]) {
                break;
            }
            at = next[at] as usize;
        }
        for &v in &verts[begin..] {
            visited[v] = false;
        }
        offsets.push(verts.len() as u32);
    }
    (verts, offsets)
}

fn to_curves(m: &Mesh, verts: &[usize], offsets: Vec<u32>) -> Curves {
    let n_curves = offsets.len() - 1;
    let mut c = Curves {
        positions: verts.iter().map(|&v| m.positions[v]).collect(),
        curve_offsets: offsets,
        ..Default::default()
    };
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY; n_curves]),
    );
    for a in m.attributes.iter() {
        // Mesh built-ins that curves do not have stay behind.
        if a.id.name().is_some_and(|x| {
            x.starts_with('.') || matches!(x, "sharp_face" | "sharp_edge" | "material_index")
        }) {
            continue;
        }
        let on_points = ComponentRef::Mesh(m).adapt(&a.data, a.domain, Domain::Point);
        c.attributes
            .set(a.id.clone(), Domain::Point, on_points.gather(verts));
    }
    c.materials = m.materials.clone();
    c
}

pub fn edge_paths_to_curves(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let start = ctx.field("Start Vertices", DataType::Bool)?;
    let next = ctx.field("Next Vertex Index", DataType::Int)?;
    modify_geometry_sets(&mut g, &mut |s| {
        // Only the curves made here and instances stay.
        let mesh = s.mesh.take();
        s.curves = None;
        s.points = None;
        let Some(m) = mesh else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            Domain::Point,
            &[(&next, DataType::Int), (&start, DataType::Bool)],
        )?;
        let (verts, offsets) = paths(m.vertex_count(), &r[1].as_bool(), &r[0].as_int());
        if !verts.is_empty() {
            s.curves = Some(Arc::new(to_curves(&m, &verts, offsets)));
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curves", geo(g))]))
}
