//! Curve > Topology: Curve of Point, Points of Curve and Offset Point in Curve
//! (`node_geo_curve_topology_curve_of_point`, `_points_of_curve`,
//! `node_geo_offset_point_in_curve`). Indices out of range give 0 (false), as Blender's
//! field-at-index lookups do; on components other than curves every output is 0.

use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
enum Kind {
    /// Curve Index / Index in Curve of the point at `index`.
    CurveOfPoint { index: Field, in_curve: bool },
    /// Point count of the curve at `index`.
    Total { index: Field },
    PointOfCurve {
        index: Field,
        sort_index: Field,
        weights: Field,
    },
    Offset {
        index: Field,
        offset: Field,
        valid: bool,
    },
}

#[derive(Debug)]
struct Topology(Kind);

/// Blender's `mod_i`: the remainder with the sign of the divisor.
fn mod_i(i: i32, n: i32) -> i32 {
    ((i % n) + n) % n
}

/// `apply_offset_in_cyclic_range`.
fn cyclic_offset(start: usize, len: usize, point: usize, offset: i32) -> usize {
    let m = (point - start) as i64 + offset as i64;
    let m = m % len as i64;
    if m >= 0 {
        start + m as usize
    } else {
        start + len - (-(m + 1)) as usize - 1
    }
}

impl Topology {
    fn eval(&self, ctx: &FieldContext, c: &Curves, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let points = c.point_count();
        let int = |f: &Field| -> Result<Vec<i32>, String> {
            Ok(ctx.eval(f, domain, DataType::Int)?.as_int().into_owned())
        };
        match &self.0 {
            Kind::CurveOfPoint { index, in_curve } => {
                let map = c.point_to_curve();
                let idx = int(index)?;
                Ok(Array::Int(
                    idx.iter()
                        .map(|&p| match usize::try_from(p) {
                            Ok(p) if p < points => {
                                let curve = map[p];
                                if *in_curve {
                                    (p - c.points(curve).start) as i32
                                } else {
                                    curve as i32
                                }
                            }
                            _ => 0,
                        })
                        .collect(),
                ))
            }
            Kind::Total { index } => Ok(Array::Int(
                int(index)?
                    .iter()
                    .map(|&i| match usize::try_from(i) {
                        Ok(i) if i < c.curve_count() => c.points(i).len() as i32,
                        _ => 0,
                    })
                    .collect(),
            )),
            Kind::PointOfCurve {
                index,
                sort_index,
                weights,
            } => {
                let curve = int(index)?;
                let sort = int(sort_index)?;
                // Blender sorts only when the weights are not one value for all points.
                let use_sorting = weights.as_constant().is_none();
                let w = if use_sorting {
                    ctx.eval(weights, Domain::Point, DataType::Float)?
                        .as_float()
                        .into_owned()
                } else {
                    Vec::new()
                };
                let mut out = vec![0i32; n];
                for i in 0..n {
                    let Ok(ci) = usize::try_from(curve[i]) else {
                        continue;
                    };
                    if ci >= c.curve_count() {
                        continue;
                    }
                    let r = c.points(ci);
                    if r.is_empty() {
                        continue;
                    }
                    let k = mod_i(sort[i], r.len() as i32) as usize;
                    out[i] = if use_sorting {
                        let mut order: Vec<usize> = (0..r.len()).collect();
                        // A stable sort, as Blender's.
                        order.sort_by(|a, b| {
                            w[r.start + a]
                                .partial_cmp(&w[r.start + b])
                                .unwrap_or(std::cmp::Ordering::Equal)
                        });
                        (r.start + order[k]) as i32
                    } else {
                        (r.start + k) as i32
                    };
                }
                Ok(Array::Int(out))
            }
            Kind::Offset {
                index,
                offset,
                valid,
            } => {
                let idx = int(index)?;
                let off = int(offset)?;
                let cyclic = c.cyclic();
                let map = c.point_to_curve();
                if *valid {
                    return Ok(Array::Bool(
                        (0..n)
                            .map(|i| match usize::try_from(idx[i]) {
                                Ok(p) if p < points => {
                                    let curve = map[p];
                                    if cyclic[curve] {
                                        return true;
                                    }
                                    let r = c.points(curve);
                                    let q = p as i64 + off[i] as i64;
                                    q >= r.start as i64 && q < r.end as i64
                                }
                                _ => false,
                            })
                            .collect(),
                    ));
                }
                if points == 0 {
                    return Ok(Array::Int(vec![0; n]));
                }
                Ok(Array::Int(
                    (0..n)
                        .map(|i| {
                            let p = idx[i].clamp(0, points as i32 - 1) as usize;
                            let curve = map[p];
                            let r = c.points(curve);
                            if cyclic[curve] {
                                cyclic_offset(r.start, r.len(), p, off[i]) as i32
                            } else {
                                // Clamped to the whole geometry, not the curve, as Blender.
                                (p as i64 + off[i] as i64).clamp(0, points as i64 - 1) as i32
                            }
                        })
                        .collect(),
                ))
            }
        }
    }
}

impl FieldInput for Topology {
    fn data_type(&self) -> DataType {
        match self.0 {
            Kind::Offset { valid: true, .. } => DataType::Bool,
            _ => DataType::Int,
        }
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Curves(c) = ctx.component else {
            return Ok(Array::zeros(
                self.data_type(),
                ctx.component.domain_size(domain),
            ));
        };
        self.eval(ctx, c, domain)
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(match self.0 {
            Kind::Total { .. } | Kind::PointOfCurve { .. } => Domain::Curve,
            _ => Domain::Point,
        })
    }
}

fn field(k: Kind) -> SocketValue {
    SocketValue::Field(Field::input(Topology(k)))
}

pub fn curve_of_point(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let index = ctx.field("Point Index", DataType::Int)?;
    Ok(outputs([
        (
            "Curve Index",
            field(Kind::CurveOfPoint {
                index: index.clone(),
                in_curve: false,
            }),
        ),
        (
            "Index in Curve",
            field(Kind::CurveOfPoint {
                index,
                in_curve: true,
            }),
        ),
    ]))
}

pub fn points_of_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let index = ctx.field("Curve Index", DataType::Int)?;
    Ok(outputs([
        (
            "Point Index",
            field(Kind::PointOfCurve {
                index: index.clone(),
                sort_index: ctx.field("Sort Index", DataType::Int)?,
                weights: ctx.field("Weights", DataType::Float)?,
            }),
        ),
        ("Total", field(Kind::Total { index })),
    ]))
}

pub fn offset_point_in_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let index = ctx.field("Point Index", DataType::Int)?;
    let offset = ctx.field("Offset", DataType::Int)?;
    Ok(outputs([
        (
            "Is Valid Offset",
            field(Kind::Offset {
                index: index.clone(),
                offset: offset.clone(),
                valid: true,
            }),
        ),
        (
            "Point Index",
            field(Kind::Offset {
                index,
                offset,
                valid: false,
            }),
        ),
    ]))
}
