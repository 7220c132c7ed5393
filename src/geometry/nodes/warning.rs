//! Warning (`node_geo_warning`): logs its Message on the node (in the editor only) when
//! Show is true, whatever its Warning Type (an Error does not stop the evaluation), and
//! passes Show on.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};

pub fn warning(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Show", ctx.input("Show")?)]))
}
