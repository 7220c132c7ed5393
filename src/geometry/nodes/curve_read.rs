//! Curve > Read inputs: Is Spline Cyclic, Spline Resolution, Curve Tilt, Spline Length,
//! Endpoint Selection, Curve Handle Positions and Handle Type Selection
//! (`node_geo_input_spline_cyclic`, `_spline_resolution`, `_curve_tilt`,
//! `_spline_length`, `node_geo_curve_endpoint_selection`, `node_geo_input_curve_handles`,
//! `node_geo_curve_handle_type_selection`). On components other than curves they are
//! zero, as Blender's curve field inputs are.

use super::super::curve_eval::{accumulated_lengths, Evaluated};
use super::super::curves::{Curves, CURVE_TYPE_BEZIER};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
enum Kind {
    Cyclic,
    Resolution,
    Tilt,
    Length,
    PointCount,
    Endpoints { start: Field, end: Field },
    Handle { left: bool, relative: Field },
    HandleType { ty: i8, left: bool, right: bool },
}

#[derive(Debug)]
struct CurveInput(Kind);

/// Total evaluated length of every curve.
pub fn curve_lengths(c: &Curves) -> Result<Vec<f32>, String> {
    let ev = Evaluated::new(c)?;
    let pos = ev.positions(c);
    Ok((0..c.curve_count())
        .map(|i| {
            accumulated_lengths(&pos[ev.range(i)], ev.cyclic[i])
                .last()
                .copied()
                .unwrap_or(0.0)
        })
        .collect())
}

impl CurveInput {
    /// The values on the input's own domain.
    fn values(&self, ctx: &FieldContext, c: &Curves) -> Result<(Domain, Array), String> {
        let n = c.point_count();
        Ok(match &self.0 {
            Kind::Cyclic => (Domain::Curve, Array::Bool(c.cyclic())),
            Kind::Resolution => (
                Domain::Curve,
                Array::Int(c.ints("resolution", Domain::Curve, 12)),
            ),
            Kind::Tilt => (Domain::Point, Array::Float(c.point_floats("tilt", 0.0))),
            Kind::Length => (Domain::Curve, Array::Float(curve_lengths(c)?)),
            Kind::PointCount => (
                Domain::Curve,
                Array::Int(
                    (0..c.curve_count())
                        .map(|i| c.points(i).len() as i32)
                        .collect(),
                ),
            ),
            Kind::Endpoints { start, end } => {
                let s = ctx.eval(start, Domain::Curve, DataType::Int)?;
                let e = ctx.eval(end, Domain::Curve, DataType::Int)?;
                let (s, e) = (s.as_int(), e.as_int());
                let mut sel = vec![false; n];
                for i in 0..c.curve_count() {
                    let r = c.points(i);
                    let front = (s[i].max(0) as usize).min(r.len());
                    let back = (e[i].max(0) as usize).min(r.len());
                    sel[r.start..r.start + front].fill(true);
                    sel[r.end - back..r.end].fill(true);
                }
                (Domain::Point, Array::Bool(sel))
            }
            Kind::Handle { left, relative } => {
                let name = if *left { "handle_left" } else { "handle_right" };
                let mut h = c.point_vectors(name).unwrap_or_else(|| vec![[0.0; 3]; n]);
                let rel = ctx.eval(relative, Domain::Point, DataType::Bool)?;
                for (i, r) in rel.as_bool().iter().enumerate() {
                    if *r {
                        let p = c.positions[i];
                        h[i] = [h[i][0] - p[0], h[i][1] - p[1], h[i][2] - p[2]];
                    }
                }
                (Domain::Point, Array::Vector(h))
            }
            Kind::HandleType { ty, left, right } => {
                let types = c.ints("curve_type", Domain::Curve, 0);
                let tl = c.ints("handle_type_left", Domain::Point, 0);
                let tr = c.ints("handle_type_right", Domain::Point, 0);
                let mut sel = vec![false; n];
                for i in 0..c.curve_count() {
                    if types[i] as i8 != CURVE_TYPE_BEZIER {
                        continue;
                    }
                    for p in c.points(i) {
                        sel[p] = (*left && tl[p] as i8 == *ty) || (*right && tr[p] as i8 == *ty);
                    }
                }
                (Domain::Point, Array::Bool(sel))
            }
        })
    }
}

impl FieldInput for CurveInput {
    fn data_type(&self) -> DataType {
        match self.0 {
            Kind::Cyclic | Kind::Endpoints { .. } | Kind::HandleType { .. } => DataType::Bool,
            Kind::Resolution | Kind::PointCount => DataType::Int,
            Kind::Tilt | Kind::Length => DataType::Float,
            Kind::Handle { .. } => DataType::Vector,
        }
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Curves(c) = ctx.component else {
            return Ok(Array::zeros(
                self.data_type(),
                ctx.component.domain_size(domain),
            ));
        };
        // Endpoint and Handle Type Selection have no value off the point domain (false),
        // as in Blender, rather than their points' adapted to curves.
        if matches!(self.0, Kind::Endpoints { .. } | Kind::HandleType { .. })
            && domain != Domain::Point
        {
            return Ok(Array::Bool(vec![false; ctx.component.domain_size(domain)]));
        }
        let (from, data) = self.values(ctx, c)?;
        Ok(ctx.component.adapt(&data, from, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(match self.0 {
            Kind::Cyclic | Kind::Resolution | Kind::Length | Kind::PointCount => Domain::Curve,
            _ => Domain::Point,
        })
    }
}

fn field(k: Kind) -> SocketValue {
    SocketValue::Field(Field::input(CurveInput(k)))
}

pub fn is_spline_cyclic(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Cyclic", field(Kind::Cyclic))]))
}

pub fn spline_resolution(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Resolution", field(Kind::Resolution))]))
}

pub fn curve_tilt(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Tilt", field(Kind::Tilt))]))
}

pub fn spline_length(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Length", field(Kind::Length)),
        ("Point Count", field(Kind::PointCount)),
    ]))
}

pub fn endpoint_selection(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let start = ctx.field("Start Size", DataType::Int)?;
    let end = ctx.field("End Size", DataType::Int)?;
    Ok(outputs([(
        "Selection",
        field(Kind::Endpoints { start, end }),
    )]))
}

/// The absolute handle positions of one side (Set Handle Positions' implicit Position).
pub fn handle_positions_field(left: bool) -> Field {
    Field::input(CurveInput(Kind::Handle {
        left,
        relative: Field::constant(super::super::types::Value::Bool(false)),
    }))
}

pub fn curve_handle_positions(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let relative = ctx.field("Relative", DataType::Bool)?;
    Ok(outputs([
        (
            "Left",
            field(Kind::Handle {
                left: true,
                relative: relative.clone(),
            }),
        ),
        (
            "Right",
            field(Kind::Handle {
                left: false,
                relative,
            }),
        ),
    ]))
}

/// A handle type enum item as stored (`FREE`, `AUTO`, `VECTOR`, `ALIGN`).
pub fn handle_type(ctx: &NodeCtx) -> Result<i8, GeometryError> {
    use super::super::curves::{HANDLE_ALIGN, HANDLE_AUTO, HANDLE_FREE, HANDLE_VECTOR};
    match ctx.prop_str("handle_type")? {
        "FREE" => Ok(HANDLE_FREE),
        "AUTO" => Ok(HANDLE_AUTO),
        "VECTOR" => Ok(HANDLE_VECTOR),
        "ALIGN" => Ok(HANDLE_ALIGN),
        other => Err(ctx.err(format!("handle type {other:?} is not supported"))),
    }
}

/// The Left / Right flags of an enum-set `mode` property.
pub fn handle_sides(ctx: &NodeCtx) -> Result<(bool, bool), GeometryError> {
    let items: Vec<&str> = match ctx.prop("mode") {
        Some(serde_json::Value::Array(a)) => a.iter().filter_map(|v| v.as_str()).collect(),
        Some(serde_json::Value::String(s)) => vec![s.as_str()],
        _ => return Err(ctx.err("property \"mode\" missing")),
    };
    Ok((items.contains(&"LEFT"), items.contains(&"RIGHT")))
}

pub fn handle_type_selection(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = handle_type(ctx)?;
    let (left, right) = handle_sides(ctx)?;
    Ok(outputs([(
        "Selection",
        field(Kind::HandleType { ty, left, right }),
    )]))
}
