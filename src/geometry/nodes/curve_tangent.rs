//! Curve Tangent (`node_geo_input_tangent`): per control point, the direction of the
//! evaluated curve where the point lies; on the curve domain their average. Zero on
//! other components.

use super::super::curve_eval::{self, Evaluated};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct Tangent;

impl FieldInput for Tangent {
    fn data_type(&self) -> DataType {
        DataType::Vector
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Curves(c) = ctx.component else {
            return Ok(Array::zeros(DataType::Vector, n));
        };
        let ev = Evaluated::new(c)?;
        let pos = ev.positions(c);
        let tangents = ev.tangents(c, &pos);
        let mut out = vec![[0.0f32; 3]; c.point_count()];
        for i in 0..c.curve_count() {
            let r = ev.range(i);
            let pts = c.points(i);
            if ev.is_nurbs(i) {
                // NURBS control points are not on the curve: Blender takes the tangents
                // of the control polygon as a poly curve.
                let t = curve_eval::tangents(&c.positions[pts.clone()], ev.cyclic[i]);
                out[pts].copy_from_slice(&t);
                continue;
            }
            for (k, p) in pts.enumerate() {
                if let Some(t) = ev
                    .control_point_evaluated(i, k)
                    .and_then(|e| tangents.get(r.start + e))
                {
                    out[p] = *t;
                }
            }
        }
        Ok(ctx
            .component
            .adapt(&Array::Vector(out), Domain::Point, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Point)
    }
}

pub fn curve_tangent(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Tangent",
        SocketValue::Field(Field::input(Tangent)),
    )]))
}
