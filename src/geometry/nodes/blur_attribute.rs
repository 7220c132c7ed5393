//! Blur Attribute (`node_geo_blur_attribute`): each iteration replaces a value by the
//! weighted mean of itself (weight 1) and its neighbours (each the element's Weight), as
//! Blender's default attribute mixers do: vertices through edges, edges through their
//! vertices, faces through their edges, curve points along their curve (cyclic curves
//! wrap). Corners and other components are passed through unblurred.

use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;

#[derive(Debug)]
struct Blur {
    value: Field,
    weight: Field,
    iterations: i32,
}

/// Each element's neighbours on a mesh domain, in Blender's order.
fn mesh_neighbors(m: &Mesh, domain: Domain) -> Option<Vec<Vec<usize>>> {
    let vert_edges = || {
        let mut out = vec![Vec::new(); m.vertex_count()];
        for (i, e) in m.edges.iter().enumerate() {
            out[e[0] as usize].push(i);
            out[e[1] as usize].push(i);
        }
        out
    };
    Some(match domain {
        Domain::Point => {
            let ve = vert_edges();
            ve.iter()
                .enumerate()
                .map(|(v, es)| {
                    es.iter()
                        .map(|&e| {
                            let [a, b] = m.edges[e];
                            if a as usize == v {
                                b as usize
                            } else {
                                a as usize
                            }
                        })
                        .collect()
                })
                .collect()
        }
        Domain::Edge => {
            let ve = vert_edges();
            m.edges
                .iter()
                .enumerate()
                .map(|(i, e)| {
                    e.iter()
                        .flat_map(|&v| ve[v as usize].iter().copied().filter(|&x| x != i))
                        .collect()
                })
                .collect()
        }
        Domain::Face => {
            let mut edge_faces = vec![Vec::new(); m.edge_count()];
            for f in 0..m.face_count() {
                for c in m.face(f) {
                    edge_faces[m.corner_edges[c] as usize].push(f);
                }
            }
            (0..m.face_count())
                .map(|f| {
                    m.face(f)
                        .flat_map(|c| {
                            edge_faces[m.corner_edges[c] as usize]
                                .iter()
                                .copied()
                                .filter(|&g| g != f)
                        })
                        .collect()
                })
                .collect()
        }
        _ => return None,
    })
}

fn curve_neighbors(c: &Curves) -> Vec<Vec<usize>> {
    let cyclic = super::super::curve_eval::cyclic(c);
    let mut out = vec![Vec::new(); c.positions.len()];
    for k in 0..c.curve_count() {
        let r = c.points(k);
        if r.len() < 2 {
            continue;
        }
        let (first, last) = (r.start, r.end - 1);
        for p in r.clone() {
            if p > first {
                out[p].push(p - 1);
            }
            if p < last {
                out[p].push(p + 1);
            }
        }
        if cyclic[k] {
            out[first].push(last);
            out[last].push(first);
        }
    }
    out
}

/// One weighted mean as Blender's `DefaultMixer` computes it (floats scaled by the
/// inverse total weight, integers through doubles and rounded; zero weight gives the
/// type's default).
fn mix(values: &Array, items: &[(usize, f32)]) -> Value {
    let total: f32 = items.iter().map(|(_, w)| *w).sum();
    match values {
        Array::Int(v) => {
            let acc: f64 = items.iter().map(|&(i, w)| v[i] as f64 * w as f64).sum();
            if total > 0.0 {
                Value::Int((acc / total as f64).round() as i32)
            } else {
                Value::Int(0)
            }
        }
        Array::Float(v) => {
            let acc: f32 = items.iter().map(|&(i, w)| v[i] * w).sum();
            Value::Float(if total > 0.0 {
                acc * (1.0 / total)
            } else {
                0.0
            })
        }
        Array::Vector(v) => {
            let mut acc = [0.0f32; 3];
            for &(i, w) in items {
                for k in 0..3 {
                    acc[k] += v[i][k] * w;
                }
            }
            let s = if total > 0.0 { 1.0 / total } else { 0.0 };
            Value::Vector(acc.map(|x| x * s))
        }
        Array::Color(v) => {
            let mut acc = [0.0f32; 4];
            for &(i, w) in items {
                for k in 0..4 {
                    acc[k] += v[i][k] * w;
                }
            }
            if total > 0.0 {
                let s = 1.0 / total;
                Value::Color(acc.map(|x| x * s))
            } else {
                Value::Color([0.0, 0.0, 0.0, 1.0])
            }
        }
        other => other.get(items[0].0),
    }
}

impl FieldInput for Blur {
    fn data_type(&self) -> DataType {
        self.value.data_type()
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let mut values = self.value.evaluate(ctx, domain)?;
        let n = values.len();
        if n <= 1 || self.iterations <= 0 {
            return Ok(values);
        }
        let weights = ctx.eval(&self.weight, domain, DataType::Float)?;
        let weights = weights.as_float();
        let neighbors = match ctx.component {
            ComponentRef::Mesh(m) => mesh_neighbors(m, domain),
            ComponentRef::Curves(c) if domain == Domain::Point => Some(curve_neighbors(c)),
            _ => None,
        };
        let Some(neighbors) = neighbors else {
            return Ok(values);
        };
        let mut items = Vec::new();
        for _ in 0..self.iterations {
            let mut next = values.clone();
            for (i, ns) in neighbors.iter().enumerate() {
                items.clear();
                items.push((i, 1.0));
                items.extend(ns.iter().map(|&j| (j, weights[i])));
                next.set(i, mix(&values, &items));
            }
            values = next;
        }
        Ok(values)
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        match self.value.preferred_domain(ctx) {
            Some(Domain::Corner) => Some(Domain::Point),
            d => d,
        }
    }
}

pub fn blur_attribute(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = match ctx.prop_str("data_type")? {
        "FLOAT" => DataType::Float,
        "INT" => DataType::Int,
        "FLOAT_VECTOR" => DataType::Vector,
        "FLOAT_COLOR" => DataType::Color,
        other => return Err(ctx.err(format!("data type {other} is not supported"))),
    };
    let value_id = ctx
        .flat()
        .inputs
        .iter()
        .find(|i| i.socket.name == "Value")
        .map(|i| i.socket.identifier.clone())
        .ok_or_else(|| ctx.err("no Value input"))?;
    let value = ctx.field(&value_id, ty)?;
    let weight = ctx.field("Weight", DataType::Float)?;
    let iterations = ctx.int("Iterations")?;
    let out_id = ctx
        .node()
        .outputs
        .iter()
        .find(|o| o.name == "Value" && o.enabled)
        .map(|o| o.identifier.clone())
        .unwrap_or_else(|| "Value".to_string());
    let f = Field::input(Blur {
        value,
        weight,
        iterations,
    });
    let mut out = Outputs::new();
    out.insert(out_id, SocketValue::Field(f));
    Ok(out)
}
