//! Radius (`node_geo_input_radius`): the `radius` of curve control points and point cloud
//! points (their built-in defaults where the attribute is absent); zero on meshes and
//! instances.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

/// Built-in `radius` where a component has none: curves 0 (as Blender 4.5 reads an absent
/// curve radius, fixture `tangent_radius_bezier`), points 0.01 (Blender's point cloud
/// default; no fixture covers it).
const CURVES_DEFAULT: f32 = 0.0;
const POINTS_DEFAULT: f32 = 0.01;

#[derive(Debug)]
struct Radius;

impl FieldInput for Radius {
    fn data_type(&self) -> DataType {
        DataType::Float
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let default = match ctx.component {
            ComponentRef::Curves(_) => CURVES_DEFAULT,
            ComponentRef::Points(_) => POINTS_DEFAULT,
            _ => return Ok(Array::zeros(DataType::Float, n)),
        };
        let points = ctx.component.domain_size(Domain::Point);
        let data = match ctx.component.attribute(&AttrId::named("radius")) {
            Some((d, a)) => ctx.component.adapt(&a, d, Domain::Point),
            None => Array::Float(vec![default; points]),
        }
        .convert(DataType::Float);
        Ok(ctx.component.adapt(&data, Domain::Point, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Point)
    }
}

pub fn radius(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Radius",
        SocketValue::Field(Field::input(Radius)),
    )]))
}
