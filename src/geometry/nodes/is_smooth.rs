//! Is Face Smooth and Is Edge Smooth (`node_geo_input_shade_smooth.cc`,
//! `node_geo_input_edge_smooth.cc`): the negated `sharp_face` / `sharp_edge` attributes,
//! true where they are missing (a mesh without them is smooth everywhere, and so is any
//! other component).

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, Field};
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;

fn not_sharp(ctx: &NodeCtx, attribute: &str) -> Result<Outputs, GeometryError> {
    let sharp = Field::input(AttributeInput {
        id: AttrId::named(attribute),
        ty: DataType::Bool,
    });
    let smooth = Field::op1(
        format!("not {attribute}"),
        vec![sharp],
        DataType::Bool,
        |_, x| Ok(Array::Bool(x[0].as_bool().iter().map(|s| !s).collect())),
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Smooth", SocketValue::Field(smooth))]))
}

pub fn is_face_smooth(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    not_sharp(ctx, "sharp_face")
}

pub fn is_edge_smooth(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    not_sharp(ctx, "sharp_edge")
}
