//! Curve inputs: Spline Parameter (factor, length and index along each curve) and Curve
//! Length (`node_geo_input_spline_parameter`, `node_geo_curve_length`).

use super::super::curve_eval::{accumulated_lengths, Evaluated};
use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::math::{length as length_of, sub};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

/// Lengths per control point, per-curve totals for factors, per-curve evaluated lengths.
type PointLengths = (Vec<f32>, Vec<f32>, Vec<f32>);

/// Per control point: length from the curve's start; per curve: the total its factors
/// divide by, and the evaluated length. NURBS control points are not on the curve, so
/// Blender measures them along the control polygon, and their factors by its length.
fn point_lengths(c: &Curves) -> Result<PointLengths, String> {
    let ev = Evaluated::new(c)?;
    let pos = ev.positions(c);
    let mut out = vec![0.0f32; c.point_count()];
    let mut point_totals = Vec::with_capacity(c.curve_count());
    let mut totals = Vec::with_capacity(c.curve_count());
    for i in 0..c.curve_count() {
        let lengths = accumulated_lengths(&pos[ev.range(i)], ev.cyclic[i]);
        let total = lengths.last().copied().unwrap_or(0.0);
        totals.push(total);
        let pts = c.points(i);
        if ev.is_nurbs(i) {
            let p = &c.positions[pts.clone()];
            let mut length = 0.0f32;
            for k in 0..p.len() {
                out[pts.start + k] = length;
                if k + 1 < p.len() {
                    length += length_of(sub(p[k + 1], p[k]));
                }
            }
            if ev.cyclic[i] && !p.is_empty() {
                length += length_of(sub(p[0], p[p.len() - 1]));
            }
            point_totals.push(length);
            continue;
        }
        for (k, p) in pts.clone().enumerate().skip(1) {
            let e = ev.control_point_evaluated(i, k).unwrap_or(0);
            out[p] = if e == 0 { 0.0 } else { lengths[e - 1] };
        }
        point_totals.push(total);
    }
    Ok((out, point_totals, totals))
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Param {
    Factor,
    Length,
    Index,
}

#[derive(Debug)]
struct SplineParameter(Param);

impl FieldInput for SplineParameter {
    fn data_type(&self) -> DataType {
        if self.0 == Param::Index {
            DataType::Int
        } else {
            DataType::Float
        }
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Curves(c) = ctx.component else {
            return Ok(Array::zeros(self.data_type(), n));
        };
        match domain {
            Domain::Point => {
                if self.0 == Param::Index {
                    let mut idx = vec![0i32; c.point_count()];
                    for i in 0..c.curve_count() {
                        let pts = c.points(i);
                        for (k, p) in pts.clone().enumerate() {
                            idx[p] = k as i32;
                        }
                    }
                    return Ok(Array::Int(idx));
                }
                let (mut lengths, totals, _) = point_lengths(c)?;
                if self.0 == Param::Factor {
                    for i in 0..c.curve_count() {
                        let pts = c.points(i);
                        let total = totals[i];
                        if total > 0.0 {
                            let inv = 1.0 / total;
                            for p in pts {
                                lengths[p] *= inv;
                            }
                        } else if pts.len() == 1 {
                            lengths[pts.start] = 0.0;
                        } else {
                            let last = pts.len() as f32 - 1.0;
                            for (k, p) in pts.enumerate() {
                                lengths[p] = k as f32 / last;
                            }
                        }
                    }
                }
                Ok(Array::Float(lengths))
            }
            Domain::Curve => {
                if self.0 == Param::Index {
                    return Ok(Array::Int((0..n as i32).collect()));
                }
                let (_, _, totals) = point_lengths(c)?;
                let mut acc = vec![0.0f32; n];
                let mut sum = 0.0f32;
                for i in 0..n {
                    acc[i] = sum;
                    sum += totals[i];
                }
                if self.0 == Param::Factor {
                    if sum > 0.0 {
                        let inv = 1.0 / sum;
                        acc.iter_mut().for_each(|x| *x *= inv);
                    } else {
                        let last = (n.max(2) - 1) as f32;
                        acc.iter_mut()
                            .enumerate()
                            .for_each(|(i, x)| *x = i as f32 / last);
                    }
                }
                Ok(Array::Float(acc))
            }
            _ => Ok(Array::zeros(self.data_type(), n)),
        }
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Point)
    }
}

pub fn spline_parameter(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        (
            "Factor",
            SocketValue::Field(Field::input(SplineParameter(Param::Factor))),
        ),
        (
            "Length",
            SocketValue::Field(Field::input(SplineParameter(Param::Length))),
        ),
        (
            "Index",
            SocketValue::Field(Field::input(SplineParameter(Param::Index))),
        ),
    ]))
}

pub fn curve_length(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Curve")?;
    let total = match &g.curves {
        Some(c) => point_lengths(c)
            .map_err(|e| ctx.err(e))?
            .2
            .iter()
            .sum::<f32>(),
        None => 0.0,
    };
    Ok(outputs([("Length", SocketValue::float(total))]))
}
