//! Subdivision Surface (node and modifier): Subdivide Mesh's topology and attribute
//! interpolation (Blender's subdivision-to-mesh traversal is the same for both schemes),
//! with the vertices moved to the Catmull-Clark surface (`geometry::catmull_clark`).

use super::super::catmull_clark::{self, crease_to_sharpness, Options};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::limits;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};
use super::subdivide::{subdivide_with_locations, Loc};

/// Catmull-Clark subdivision of `m`: `edge_crease` and `vert_crease` are Blender's crease
/// values (0..1) per edge and vertex; `boundary_corners` is Boundary Smooth "Keep Corners".
/// `isolation` is the modifier's quality (the node isolates to the level).
pub fn subdivision_surface(
    m: &Mesh,
    level: u32,
    isolation: u32,
    edge_crease: &[f32],
    vert_crease: &[f32],
    boundary_corners: bool,
    limit: bool,
) -> Mesh {
    let (mut out, locs) = subdivide_with_locations(m, level);
    let es: Vec<f32> = edge_crease
        .iter()
        .map(|c| crease_to_sharpness(c.clamp(0.0, 1.0)))
        .collect();
    let vs: Vec<f32> = vert_crease
        .iter()
        .map(|c| crease_to_sharpness(c.clamp(0.0, 1.0)))
        .collect();
    let r = catmull_clark::refine(
        m,
        level,
        isolation,
        &es,
        &vs,
        Options {
            boundary_corners,
            limit,
        },
    );
    for (p, loc) in out.positions.iter_mut().zip(&locs) {
        let q = match *loc {
            Loc::Vertex(v) => r.vertex(v),
            Loc::Edge(e, i) => r.edge_point(e, i),
            Loc::Ptex(ptex, x, y) => r.ptex_point(ptex, x, y),
        };
        *p = [q[0] as f32, q[1] as f32, q[2] as f32];
    }
    out
}

pub fn subdivision_surface_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let level = ctx.int("Level")?.clamp(0, 11) as u32;
    let limit = if ctx.has_input("Limit Surface") {
        ctx.bool("Limit Surface")?
    } else {
        true
    };
    let boundary_corners = match ctx
        .prop("boundary_smooth")
        .and_then(|v| v.as_str())
        .unwrap_or("ALL")
    {
        "ALL" => false,
        "PRESERVE_CORNERS" => true,
        other => return Err(ctx.err(format!("Boundary Smooth {other:?} is not supported"))),
    };
    let edge_crease = ctx.field("Edge Crease", DataType::Float)?;
    let vert_crease = ctx.field("Vertex Crease", DataType::Float)?;
    if level > 0 {
        modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
            let Some(m) = s.mesh.clone() else {
                return Ok(());
            };
            if m.face_count() == 0 {
                return Ok(());
            }
            limits::check(
                limits::subdivided_corners(m.corner_count() as u64, level),
                &format!("Level {level} on a mesh of {} faces", m.face_count()),
            )?;
            let ec = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Edge,
                &[(&edge_crease, DataType::Float)],
            )?;
            let vc = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Point,
                &[(&vert_crease, DataType::Float)],
            )?;
            // A new Arc: `mesh_mut` would first deep-copy the shared input.
            s.mesh = Some(std::sync::Arc::new(subdivision_surface(
                &m,
                level,
                level,
                &ec[0].as_float(),
                &vc[0].as_float(),
                boundary_corners,
                limit,
            )));
            Ok(())
        })
        .map_err(|e| ctx.err(e))?;
    }
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}

/// The Subdivision Surface modifier at render settings: render levels; Catmull-Clark or
/// simple; creases from the mesh's `crease_edge` / `crease_vert` when "Use Creases" is on.
pub fn subsurf_modifier(
    props: &serde_json::Map<String, serde_json::Value>,
    mut g: GeometrySet,
) -> Result<GeometrySet, String> {
    let get = |k: &str| {
        props
            .get(k)
            .ok_or_else(|| format!("property {k:?} missing"))
    };
    let level = get("render_levels")?
        .as_i64()
        .ok_or("render_levels is not an integer")?
        .clamp(0, 11) as u32;
    let simple = get("subdivision_type")?.as_str() == Some("SIMPLE");
    let limit = get("use_limit_surface")?.as_bool().unwrap_or(true);
    let creases = get("use_creases")?.as_bool().unwrap_or(true);
    let boundary_corners = match get("boundary_smooth")?.as_str() {
        Some("ALL") => false,
        Some("PRESERVE_CORNERS") => true,
        other => return Err(format!("boundary_smooth {other:?} is not supported")),
    };
    if level == 0 {
        return Ok(g);
    }
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    if m.face_count() == 0 {
        return Ok(g);
    }
    limits::check(
        limits::subdivided_corners(m.corner_count() as u64, level),
        &format!(
            "render_levels {level} on a mesh of {} faces",
            m.face_count()
        ),
    )?;
    let crease = |name: &str, domain: Domain| -> Vec<f32> {
        match m.attributes.named(name) {
            Some(a) if creases && a.domain == domain => a.data.as_float().into_owned(),
            _ => vec![0.0; m.domain_size(domain)],
        }
    };
    let out = if simple {
        super::subdivide::subdivide_mesh(&m, level)
    } else {
        let quality = get("quality")?.as_i64().unwrap_or(3).clamp(1, 10) as u32;
        subdivision_surface(
            &m,
            level,
            quality,
            &crease("crease_edge", Domain::Edge),
            &crease("crease_vert", Domain::Point),
            boundary_corners,
            limit,
        )
    };
    *g.mesh_mut().unwrap() = out;
    Ok(g)
}
