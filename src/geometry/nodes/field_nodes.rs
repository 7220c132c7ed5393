//! Field utility nodes: Evaluate on Domain, Field at Index, Sample Index, Face Area,
//! rotation conversions (Euler to Rotation, Rotation to Euler, Rotation input).

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, EvaluateOnDomain, Field, FieldContext, FieldInput};
use super::super::math::{euler_to_quat, quat_to_euler};
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;

fn domain_prop(ctx: &NodeCtx) -> Result<Domain, GeometryError> {
    let d = ctx.prop_str("domain")?;
    Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))
}

fn data_type_prop(ctx: &NodeCtx) -> Result<DataType, GeometryError> {
    let d = ctx.prop_str("data_type")?;
    DataType::parse(d)
        .map(|t| t.socket_type())
        .ok_or_else(|| ctx.err(format!("data type {d} is not supported")))
}

fn value_input(ctx: &NodeCtx) -> Option<String> {
    ctx.flat()
        .inputs
        .iter()
        .find(|i| i.socket.name == "Value")
        .map(|i| i.socket.identifier.clone())
}

fn value_output(ctx: &NodeCtx, name: &str) -> String {
    ctx.node()
        .outputs
        .iter()
        .find(|o| o.name == name && o.enabled)
        .map(|o| o.identifier.clone())
        .unwrap_or_else(|| name.to_string())
}

pub fn evaluate_on_domain(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let domain = domain_prop(ctx)?;
    let ty = data_type_prop(ctx)?;
    let id = value_input(ctx).ok_or_else(|| ctx.err("no Value input"))?;
    let field = ctx.field(&id, ty)?;
    let out = match field {
        Field::Constant(v) => Field::Constant(v),
        f => Field::input(EvaluateOnDomain { field: f, domain }),
    };
    Ok(outputs([(
        value_output(ctx, "Value").as_str(),
        SocketValue::Field(out),
    )]))
}

/// Field at Index: `value` evaluated on `domain`, read at `index` (evaluated where used).
#[derive(Debug)]
struct FieldAtIndex {
    value: Field,
    index: Field,
    domain: Domain,
}

impl FieldInput for FieldAtIndex {
    fn data_type(&self) -> DataType {
        self.value.data_type()
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        if !ctx.component.has_domain(self.domain) {
            return Ok(Array::zeros(self.data_type(), n));
        }
        let values = self.value.evaluate(ctx, self.domain)?;
        let idx = ctx.eval(&self.index, domain, DataType::Int)?;
        let idx = idx.as_int();
        let mut out = Array::zeros(self.data_type(), n);
        for i in 0..n {
            let k = idx[i];
            if k >= 0 && (k as usize) < values.len() {
                out.set(i, values.get(k as usize));
            }
        }
        Ok(out)
    }
}

pub fn field_at_index(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let domain = domain_prop(ctx)?;
    let ty = data_type_prop(ctx)?;
    let id = value_input(ctx).ok_or_else(|| ctx.err("no Value input"))?;
    let value = ctx.field(&id, ty)?;
    let index = ctx.field("Index", DataType::Int)?;
    let f = Field::input(FieldAtIndex {
        value,
        index,
        domain,
    });
    Ok(outputs([(
        value_output(ctx, "Value").as_str(),
        SocketValue::Field(f),
    )]))
}

/// Sample Index: `value` evaluated on another geometry, read at `index`.
#[derive(Debug)]
struct SampleIndex {
    geometry: Arc<GeometrySet>,
    value: Field,
    index: Field,
    domain: Domain,
    clamp: bool,
}

impl FieldInput for SampleIndex {
    fn data_type(&self) -> DataType {
        self.value.data_type()
    }
    fn samples_other_geometry(&self) -> bool {
        true
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let g = &*self.geometry;
        let comp = match self.domain {
            Domain::Point | Domain::Edge | Domain::Face | Domain::Corner if g.mesh.is_some() => {
                ComponentRef::Mesh(g.mesh.as_ref().unwrap())
            }
            Domain::Point if g.points.is_some() => ComponentRef::Points(g.points.as_ref().unwrap()),
            Domain::Point | Domain::Curve if g.curves.is_some() => {
                ComponentRef::Curves(g.curves.as_ref().unwrap())
            }
            Domain::Instance if g.instances.is_some() => {
                ComponentRef::Instances(g.instances.as_ref().unwrap())
            }
            _ => return Ok(Array::zeros(self.data_type(), n)),
        };
        let source = FieldContext::new(comp);
        let values = self.value.evaluate(&source, self.domain)?;
        let idx = ctx.eval(&self.index, domain, DataType::Int)?;
        let idx = idx.as_int();
        let mut out = Array::zeros(self.data_type(), n);
        let len = values.len() as i64;
        for i in 0..n {
            let mut k = idx[i] as i64;
            if self.clamp && len > 0 {
                k = k.clamp(0, len - 1);
            }
            if k >= 0 && k < len {
                out.set(i, values.get(k as usize));
            }
        }
        Ok(out)
    }
}

pub fn sample_index(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let geometry = Arc::new(ctx.geometry("Geometry")?);
    let domain = domain_prop(ctx)?;
    let ty = data_type_prop(ctx)?;
    let clamp = ctx.prop_bool("clamp").unwrap_or(false);
    let id = value_input(ctx).ok_or_else(|| ctx.err("no Value input"))?;
    let value = ctx.field(&id, ty)?;
    let index = ctx.field("Index", DataType::Int)?;
    let f = Field::input(SampleIndex {
        geometry,
        value,
        index,
        domain,
        clamp,
    });
    Ok(outputs([(
        value_output(ctx, "Value").as_str(),
        SocketValue::Field(f),
    )]))
}

/// Face areas (`face_area_calc`), moved to the requested domain.
#[derive(Debug)]
struct FaceArea;

impl FieldInput for FaceArea {
    fn data_type(&self) -> DataType {
        DataType::Float
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::zeros(
                DataType::Float,
                ctx.component.domain_size(domain),
            ));
        };
        let areas: Vec<f32> = (0..m.face_count())
            .map(|f| {
                // Newell's method: half the length of the summed cross products.
                let r = m.face(f);
                let p = |c: usize| m.positions[m.corner_verts[c] as usize];
                let mut n = [0.0f64; 3];
                let mut prev = p(r.end - 1);
                for c in r.clone() {
                    let cur = p(c);
                    n[0] += (prev[1] as f64) * (cur[2] as f64) - (prev[2] as f64) * (cur[1] as f64);
                    n[1] += (prev[2] as f64) * (cur[0] as f64) - (prev[0] as f64) * (cur[2] as f64);
                    n[2] += (prev[0] as f64) * (cur[1] as f64) - (prev[1] as f64) * (cur[0] as f64);
                    prev = cur;
                }
                ((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() * 0.5) as f32
            })
            .collect();
        Ok(ctx
            .component
            .adapt(&Array::Float(areas), Domain::Face, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Face)
    }
}

pub fn face_area(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([(
        "Area",
        SocketValue::Field(Field::input(FaceArea)),
    )]))
}

pub fn euler_to_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let e = ctx.field("Euler", DataType::Vector)?;
    let f = Field::op1(
        "Euler to Rotation",
        vec![e],
        DataType::Quaternion,
        |_, x| {
            Ok(Array::Quaternion(
                x[0].as_vector().iter().map(|v| euler_to_quat(*v)).collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

pub fn rotation_to_euler(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx.field("Rotation", DataType::Quaternion)?;
    let f = Field::op1("Rotation to Euler", vec![r], DataType::Vector, |_, x| {
        Ok(Array::Vector(
            x[0].as_quat().iter().map(|q| quat_to_euler(*q)).collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Euler", SocketValue::Field(f))]))
}

pub fn input_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let e = ctx
        .prop("rotation_euler")
        .and_then(|v| v.as_array())
        .ok_or_else(|| ctx.err("property \"rotation_euler\" missing"))?;
    let c = |i: usize| e.get(i).and_then(|x| x.as_f64()).unwrap_or(0.0) as f32;
    Ok(outputs([(
        "Rotation",
        SocketValue::Field(Field::Constant(Value::Quaternion(euler_to_quat([
            c(0),
            c(1),
            c(2),
        ])))),
    )]))
}
