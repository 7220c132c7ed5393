//! Float Curve as a field (`node_shader_curves.cc`): Blender's curve evaluation of the
//! value, mixed with the value by the factor.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;
use crate::nodes::curves::{mapping_from_json, BlenderCurve};

pub fn float_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx
        .prop("mapping")
        .ok_or_else(|| ctx.err("property \"mapping\" missing"))?;
    let m = mapping_from_json(m).map_err(|e| ctx.err(e.0))?;
    let curve = std::sync::Arc::new(BlenderCurve::new(&m, 0).map_err(|e| ctx.err(e.0))?);
    let ins = vec![
        ctx.field("Factor", DataType::Float)?,
        ctx.field("Value", DataType::Float)?,
    ];
    let f = Field::op1("Float Curve", ins, DataType::Float, move |_, x| {
        let (fac, v) = (x[0].as_float(), x[1].as_float());
        Ok(Array::Float(
            (0..v.len())
                .map(|i| {
                    let r = curve.eval(v[i]);
                    if fac[i] != 1.0 {
                        (1.0 - fac[i]) * v[i] + fac[i] * r
                    } else {
                        r
                    }
                })
                .collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Value", SocketValue::Field(f))]))
}
