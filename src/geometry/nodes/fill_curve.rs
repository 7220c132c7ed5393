//! Fill Curve (`node_geo_curve_fill.cc`): each geometry's curves (inside instances too)
//! become a flat mesh on the XY plane. The curves' evaluated points, z dropped, are the
//! input of Blender's constrained Delaunay triangulation (`cdt`), every curve one closed
//! polygon whatever its `cyclic`; curves with the same Group ID are triangulated together
//! (nested curves make holes, crossings make vertices), each group apart and appended in
//! order of first appearance. Triangles mode keeps the triangles, N-gons mode the input
//! faces as n-gons. The mesh replaces any mesh of that geometry, its faces flat; other
//! components pass through.

use std::sync::Arc;

use super::super::cdt::{self, Output};
use super::super::curve_eval::Evaluated;
use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::mesh::Mesh;
use super::super::types::{DataType, Domain};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// The filled mesh of `c`, curves grouped by `group_ids` (one per curve).
pub fn fill(c: &Curves, group_ids: &[i32], output: Output) -> Result<Mesh, String> {
    let ev = Evaluated::new(c)?;
    let pos = ev.positions(c);
    let mut order: Vec<i32> = Vec::new();
    let mut members: std::collections::HashMap<i32, Vec<usize>> = std::collections::HashMap::new();
    for (i, &g) in group_ids.iter().enumerate().take(c.curve_count()) {
        members
            .entry(g)
            .or_insert_with(|| {
                order.push(g);
                Vec::new()
            })
            .push(i);
    }
    let mut m = Mesh::new();
    for g in order {
        let mut verts = Vec::new();
        let mut faces = Vec::new();
        for &i in &members[&g] {
            let r = ev.offsets[i] as usize..ev.offsets[i + 1] as usize;
            let start = verts.len() as u32;
            verts.extend(pos[r.clone()].iter().map(|p| [p[0] as f64, p[1] as f64]));
            faces.push((start..start + r.len() as u32).collect());
        }
        let res = cdt::triangulate(&verts, &faces, output)?;
        let base = m.positions.len() as u32;
        m.positions
            .extend(res.verts.iter().map(|p| [p[0] as f32, p[1] as f32, 0.0]));
        m.edges
            .extend(res.edges.iter().map(|e| [e[0] + base, e[1] + base]));
        for f in &res.faces {
            m.corner_verts.extend(f.iter().map(|v| v + base));
            m.face_offsets.push(m.corner_verts.len() as u32);
        }
    }
    // The triangulation's edges, then the faces' (`mesh_calc_edges` keeping existing ones).
    m.calc_edges(true);
    m.set_smooth(false);
    Ok(m)
}

pub fn fill_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    // Blender 4.5 has a Mode menu socket; older files a `mode` property.
    let mode = if ctx.has_input("Mode") {
        ctx.string("Mode")?
    } else {
        ctx.prop_str("mode").unwrap_or("TRIANGLES").to_string()
    };
    let output = match mode.as_str() {
        "TRIANGLES" => Output::InsideWithHoles,
        "NGONS" => Output::ValidBmeshWithHoles,
        other => return Err(ctx.err(format!("mode {other:?} is not a Fill Curve mode"))),
    };
    let group = ctx.field("Group ID", DataType::Int)?;
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        if c.curve_count() > 0 {
            let ids = eval_fields(
                ComponentRef::Curves(&c),
                Domain::Curve,
                &[(&group, DataType::Int)],
            )?
            .remove(0)
            .as_int()
            .into_owned();
            s.mesh = Some(Arc::new(fill(&c, &ids, output)?));
        }
        s.curves = None;
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", geo(g))]))
}
