//! Attribute Statistic (`node_geo_attribute_statistic`): mean, median, sum, min, max,
//! range, standard deviation and variance of a float or vector field over the selected
//! elements of a domain, gathered from the mesh, point cloud, curves and instances in that
//! order. Vectors per component; the variance is the population variance; nothing
//! selected gives zeros.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::types::{DataType, Domain, Value};
use super::super::value::SocketValue;
use super::geometry_ops::eval_fields;

const OUTPUTS: [&str; 8] = [
    "Mean",
    "Median",
    "Sum",
    "Min",
    "Max",
    "Range",
    "Standard Deviation",
    "Variance",
];

/// The eight statistics of one channel, in `OUTPUTS` order.
fn stats(mut x: Vec<f32>) -> [f32; 8] {
    if x.is_empty() {
        return [0.0; 8];
    }
    let n = x.len() as f32;
    let sum: f32 = x.iter().sum();
    let mean = sum / n;
    let min = x.iter().copied().fold(f32::MAX, f32::min);
    let max = x.iter().copied().fold(f32::MIN, f32::max);
    let variance = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / n;
    x.sort_by(f32::total_cmp);
    let h = x.len() / 2;
    let median = if x.len().is_multiple_of(2) {
        (x[h - 1] + x[h]) * 0.5
    } else {
        x[h]
    };
    [
        mean,
        median,
        sum,
        min,
        max,
        max - min,
        variance.sqrt(),
        variance,
    ]
}

pub fn attribute_statistic(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let vector = match ctx.prop_str("data_type")? {
        "FLOAT" => false,
        "FLOAT_VECTOR" => true,
        other => return Err(ctx.err(format!("data type {other:?} is not supported"))),
    };
    let domain = Domain::parse(ctx.prop_str("domain")?).ok_or_else(|| ctx.err("unknown domain"))?;
    let ty = if vector {
        DataType::Vector
    } else {
        DataType::Float
    };
    // The inputs of the current data type (vector mode has its own sockets).
    let id_of = |name: &str| -> Result<String, GeometryError> {
        ctx.node()
            .inputs
            .iter()
            .find(|s| s.name == name && ctx.has_input(&s.identifier))
            .map(|s| s.identifier.clone())
            .ok_or_else(|| ctx.err(format!("input {name:?} is not available")))
    };
    let g = ctx.geometry(&id_of("Geometry")?)?;
    let attribute: Field = ctx.field(&id_of("Attribute")?, ty)?;
    let selection: Field = ctx.field(&id_of("Selection")?, DataType::Bool)?;
    let mut values: Vec<[f32; 3]> = Vec::new();
    let mut comps: Vec<ComponentRef> = Vec::new();
    if let Some(m) = &g.mesh {
        comps.push(ComponentRef::Mesh(m));
    }
    if let Some(p) = &g.points {
        comps.push(ComponentRef::Points(p));
    }
    if let Some(c) = &g.curves {
        comps.push(ComponentRef::Curves(c));
    }
    if let Some(i) = &g.instances {
        comps.push(ComponentRef::Instances(i));
    }
    for comp in comps {
        if !comp.has_domain(domain) || comp.domain_size(domain) == 0 {
            continue;
        }
        let arrays = eval_fields(
            comp,
            domain,
            &[(&attribute, ty), (&selection, DataType::Bool)],
        )
        .map_err(|e| ctx.err(e))?;
        let sel = arrays[1].as_bool();
        if vector {
            let v = arrays[0].as_vector();
            values.extend(
                v.iter()
                    .zip(sel.iter())
                    .filter(|(_, s)| **s)
                    .map(|(v, _)| *v),
            );
        } else {
            let v = arrays[0].as_float();
            values.extend(
                v.iter()
                    .zip(sel.iter())
                    .filter(|(_, s)| **s)
                    .map(|(v, _)| [*v, 0.0, 0.0]),
            );
        }
    }
    let channels = if vector { 3 } else { 1 };
    let per: Vec<[f32; 8]> = (0..channels)
        .map(|k| stats(values.iter().map(|v| v[k]).collect()))
        .collect();
    let mut out = Outputs::new();
    for (j, name) in OUTPUTS.iter().enumerate() {
        let value = if vector {
            Value::Vector([per[0][j], per[1][j], per[2][j]])
        } else {
            Value::Float(per[0][j])
        };
        // Each output of the data type's sockets, under its identifier.
        for s in ctx.node().outputs.iter().filter(|s| s.name == *name) {
            let matches = DataType::from_socket(&s.kind) == Some(ty);
            if matches {
                out.insert(
                    s.identifier.clone(),
                    SocketValue::Field(Field::Constant(value)),
                );
            }
        }
    }
    Ok(out)
}
