//! Viewer (`node_geo_viewer`): shows its input in the editor's viewport and spreadsheet.
//! It has no outputs, and a render evaluation logs nothing, so it changes nothing.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};

pub fn viewer(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(Outputs::default())
}
