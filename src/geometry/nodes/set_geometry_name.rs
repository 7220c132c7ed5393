//! Set Geometry Name (`node_geo_set_geometry_name`): names the geometry set. The name is
//! read by the editor (spreadsheet, instance names) and by nothing blendsynth's outputs
//! hold (meshes, curves, points, their attributes), so the geometry passes on as it is.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::geometry_ops::geo;

pub fn set_geometry_name(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    // The name is still read so that a bad link into it is an error, as elsewhere.
    ctx.string("Name")?;
    Ok(outputs([("Geometry", geo(ctx.geometry("Geometry")?))]))
}
