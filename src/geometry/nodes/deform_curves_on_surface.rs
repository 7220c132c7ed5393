//! Deform Curves on Surface (`node_geo_deform_curves_on_surface.cc`). In a tree of any
//! object but a Curves object Blender passes the curves through unchanged and reports
//! "Node only works for curves objects": that is evaluated here (the report printed as
//! a warning). On a Curves object the node moves each hair by the change of its
//! attachment triangle (found by `surface_uv_coordinate` in the UV map the Curves'
//! `surface_uv_map` names) between the surface object's original mesh and its evaluated
//! one, turned by the `rest_position` attribute and corner normals; blendsynth does not
//! evaluate Curves objects' trees (their evaluated hair is exported and rendered as
//! exported), so there the node is refused by name.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::value::SocketValue;

pub fn deform_curves_on_surface(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let curves = ctx.geometry("Curves")?;
    if ctx.ev.object.kind == "CURVES" {
        return Err(ctx.err(
            "deforming hair on its surface (the surface object's original and evaluated \
             meshes, its rest_position and the surface_uv_map UV map) is not evaluated: \
             blendsynth renders a Curves object's exported evaluated hair",
        ));
    }
    eprintln!(
        "warning: {}",
        ctx.err(format!(
            "Node only works for curves objects (object {:?} is a {}): the curves pass through unchanged, as Blender gives",
            ctx.ev.object.name, ctx.ev.object.kind
        ))
    );
    Ok(outputs([("Curves", SocketValue::Geometry(curves))]))
}
