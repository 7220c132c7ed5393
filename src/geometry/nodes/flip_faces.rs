//! Flip Faces: reverses the winding of the selected faces, keeping each face's first
//! corner (`bke::mesh_flip_faces`), corner attributes moving with their corners.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

pub fn flip_faces(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        if m.face_count() == 0 {
            return Ok(());
        }
        let sel = eval_fields(
            ComponentRef::Mesh(&m),
            Domain::Face,
            &[(&sel, DataType::Bool)],
        )?;
        let sel = sel[0].as_bool();
        // New corner order: each selected face's first corner, then the rest reversed.
        let mut order: Vec<usize> = (0..m.corner_count()).collect();
        let mm = s.mesh_mut().unwrap();
        for f in 0..m.face_count() {
            if !sel[f] {
                continue;
            }
            let r = m.face(f);
            order[r.start + 1..r.end].reverse();
            // Corner k's edge runs to the next corner: the old edges, reversed.
            let edges: Vec<u32> = m.corner_edges[r.clone()].iter().rev().copied().collect();
            mm.corner_edges[r.clone()].copy_from_slice(&edges);
        }
        mm.corner_verts = order.iter().map(|&c| m.corner_verts[c]).collect();
        let ids: Vec<_> = m
            .attributes
            .iter()
            .filter(|a| a.domain == Domain::Corner)
            .map(|a| a.id.clone())
            .collect();
        for id in ids {
            let data = m.attributes.get(&id).unwrap().data.gather(&order);
            mm.attributes.set(id, Domain::Corner, data);
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}
