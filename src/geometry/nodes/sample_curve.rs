//! Sample Curve (`node_geo_curve_sample.cc`): position, tangent, normal and a value field
//! at a factor of / length along a curve (chosen by the Curve Index field, or along all
//! curves end to end), interpolated between the curve's evaluated points; tangents and
//! normals are normalized after interpolating. The value field is evaluated on the curve
//! points and interpolated to the evaluated points first. Out-of-range curve indices give
//! zeros.

use std::sync::Arc;

use super::super::curve_eval::{accumulated_lengths, Evaluated};
use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext};
use super::super::math::{normalize, V3};
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::curve::sample_at_length;

/// Everything sampled from the curves, computed once.
struct Source {
    ev: Evaluated,
    positions: Vec<V3>,
    tangents: Vec<V3>,
    normals: Vec<V3>,
    values: Array,
    /// Per curve: accumulated evaluated segment lengths.
    lengths: Vec<Vec<f32>>,
    /// Accumulated total lengths of the curves (for "all curves").
    curve_ends: Vec<f32>,
}

fn lerp(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

pub fn sample_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Curves")?;
    let factor_mode = ctx.prop_str("mode")? == "FACTOR";
    let all_curves = ctx.prop_bool("use_all_curves").unwrap_or(false);
    let ty = match ctx.prop_str("data_type").unwrap_or("FLOAT") {
        "FLOAT" => DataType::Float,
        "INT" => DataType::Int,
        "FLOAT_VECTOR" => DataType::Vector,
        "FLOAT_COLOR" => DataType::Color,
        "BOOLEAN" => DataType::Bool,
        "QUATERNION" => DataType::Quaternion,
        other => return Err(ctx.err(format!("data type {other} is not supported"))),
    };
    let length = ctx.field(
        if factor_mode { "Factor" } else { "Length" },
        DataType::Float,
    )?;
    let index = if ctx.has_input("Curve Index") {
        ctx.field("Curve Index", DataType::Int)?
    } else {
        Field::Constant(Value::Int(0))
    };
    let value = ctx.field("Value", ty)?;
    let Some(c) = g.curves.clone().filter(|c| c.point_count() > 0) else {
        return Ok(outputs([
            (
                "Position",
                SocketValue::Field(Field::Constant(Value::Vector([0.0; 3]))),
            ),
            (
                "Tangent",
                SocketValue::Field(Field::Constant(Value::Vector([0.0; 3]))),
            ),
            (
                "Normal",
                SocketValue::Field(Field::Constant(Value::Vector([0.0; 3]))),
            ),
            (
                "Value",
                SocketValue::Field(Field::Constant(Value::zero(ty))),
            ),
        ]));
    };
    let src = build_source(&c, &value, ty).map_err(|e| ctx.err(e))?;
    let src = Arc::new(src);
    let n_curves = c.curve_count();
    let fields = Field::op(
        "Sample Curve",
        vec![index, length],
        vec![DataType::Vector, DataType::Vector, DataType::Vector, ty],
        move |n, a| {
            let idx = a[0].as_int();
            let len = a[1].as_float();
            let mut pos = vec![[0.0f32; 3]; n];
            let mut tan = vec![[0.0f32; 3]; n];
            let mut nor = vec![[0.0f32; 3]; n];
            let mut val = Array::zeros(ty, n);
            for i in 0..n {
                // Which curve, and the length (or factor) within it.
                let (curve, l, factor) = if n_curves == 1 {
                    (0i64, len[i], factor_mode)
                } else if all_curves {
                    let ends = &src.curve_ends;
                    let total = *ends.last().unwrap();
                    let s = if factor_mode { len[i] * total } else { len[i] };
                    let (k, f) = sample_at_length(ends, s.max(0.0).min(total));
                    let start = if k == 0 { 0.0 } else { ends[k - 1] };
                    (k as i64, f * (ends[k] - start), false)
                } else {
                    (idx[i] as i64, len[i], factor_mode)
                };
                if curve < 0 || curve as usize >= n_curves {
                    continue;
                }
                let curve = curve as usize;
                let lengths = &src.lengths[curve];
                if lengths.is_empty() {
                    continue;
                }
                let total = *lengths.last().unwrap();
                let s = if factor { l * total } else { l };
                let (seg, f) = sample_at_length(lengths, s.max(0.0).min(total));
                let r = src.ev.range(curve);
                let last = r.len() - 1;
                let (ia, ib) = if seg == last {
                    (r.start + last, r.start)
                } else {
                    (r.start + seg, r.start + seg + 1)
                };
                pos[i] = lerp(src.positions[ia], src.positions[ib], f);
                tan[i] = normalize(lerp(src.tangents[ia], src.tangents[ib], f));
                nor[i] = normalize(lerp(src.normals[ia], src.normals[ib], f));
                val.set(
                    i,
                    super::super::curve_eval::lerp_gather(&src.values, &[ia], &[ib], &[f]).get(0),
                );
            }
            Ok(vec![
                Array::Vector(pos),
                Array::Vector(tan),
                Array::Vector(nor),
                val,
            ])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter();
    let (p, t, nrm, v) = (
        it.next().unwrap(),
        it.next().unwrap(),
        it.next().unwrap(),
        it.next().unwrap(),
    );
    Ok(outputs([
        ("Position", SocketValue::Field(p)),
        ("Tangent", SocketValue::Field(t)),
        ("Normal", SocketValue::Field(nrm)),
        ("Value", SocketValue::Field(v)),
    ]))
}

fn build_source(c: &Curves, value: &Field, ty: DataType) -> Result<Source, String> {
    let ev = Evaluated::new(c)?;
    let positions = ev.positions(c);
    let tangents = ev.tangents(c, &positions);
    let normals = ev.normals(c, &tangents)?;
    let on_points = FieldContext::new(ComponentRef::Curves(c)).eval(value, Domain::Point, ty)?;
    let values = ev.interpolate(c, &on_points)?;
    let mut lengths = Vec::with_capacity(c.curve_count());
    let mut curve_ends = Vec::with_capacity(c.curve_count());
    let mut acc = 0.0f32;
    for i in 0..c.curve_count() {
        let l = accumulated_lengths(&positions[ev.range(i)], ev.cyclic[i]);
        acc += l.last().copied().unwrap_or(0.0);
        curve_ends.push(acc);
        lengths.push(l);
    }
    Ok(Source {
        ev,
        positions,
        tangents,
        normals,
        values,
        lengths,
        curve_ends,
    })
}
