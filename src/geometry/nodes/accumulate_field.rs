//! Accumulate Field (`node_geo_accumulate_field`): running totals of a field over a domain,
//! per group ID, in element order. Transforms accumulate by multiplication (the running
//! product `accumulated * value`, from the identity); integers wrap as Blender's do.

use std::collections::HashMap;

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{Field, FieldContext, FieldInput};
use super::super::math::mat4_mul;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Leading,
    Trailing,
    Total,
}

#[derive(Debug)]
struct Accumulate {
    value: Field,
    group: Field,
    domain: Domain,
    mode: Mode,
}

fn initial(t: DataType) -> Value {
    Value::zero(t)
}

fn add(a: Value, b: Value) -> Value {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => Value::Float(x + y),
        (Value::Int(x), Value::Int(y)) => Value::Int(x.wrapping_add(y)),
        (Value::Vector(x), Value::Vector(y)) => {
            Value::Vector([x[0] + y[0], x[1] + y[1], x[2] + y[2]])
        }
        (Value::Matrix(x), Value::Matrix(y)) => Value::Matrix(mat4_mul(&x, &y)),
        (a, _) => a,
    }
}

impl FieldInput for Accumulate {
    fn data_type(&self) -> DataType {
        self.value.data_type()
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let t = self.data_type();
        let n = ctx.component.domain_size(self.domain);
        if n == 0 || !ctx.component.has_domain(self.domain) {
            return Ok(Array::zeros(t, ctx.component.domain_size(domain)));
        }
        let values = self.value.evaluate(ctx, self.domain)?;
        let groups = ctx.eval(&self.group, self.domain, DataType::Int)?;
        let groups = groups.as_int();
        let mut out = Array::zeros(t, n);
        let mut running: HashMap<i32, Value> = HashMap::new();
        for i in 0..n {
            let acc = running.entry(groups[i]).or_insert_with(|| initial(t));
            let next = add(*acc, values.get(i));
            match self.mode {
                Mode::Leading => out.set(i, next),
                Mode::Trailing => out.set(i, *acc),
                Mode::Total => {}
            }
            *acc = next;
        }
        if self.mode == Mode::Total {
            for i in 0..n {
                out.set(i, running[&groups[i]]);
            }
        }
        Ok(ctx.component.adapt(&out, self.domain, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(self.domain)
    }
}

pub fn accumulate_field(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = match ctx.prop_str("data_type")? {
        "FLOAT" => DataType::Float,
        "INT" => DataType::Int,
        "FLOAT_VECTOR" => DataType::Vector,
        "TRANSFORM" => DataType::Matrix,
        other => return Err(ctx.err(format!("data type {other} is not supported"))),
    };
    let d = ctx.prop_str("domain")?;
    let domain = Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))?;
    let value_id = ctx
        .flat()
        .inputs
        .iter()
        .find(|i| i.socket.name == "Value")
        .map(|i| i.socket.identifier.clone())
        .ok_or_else(|| ctx.err("no Value input"))?;
    let value = ctx.field(&value_id, ty)?;
    let group_id = ctx
        .flat()
        .inputs
        .iter()
        .find(|i| i.socket.name == "Group ID" || i.socket.name == "Group Index")
        .map(|i| i.socket.identifier.clone())
        .ok_or_else(|| ctx.err("no Group ID input"))?;
    let group = ctx.field(&group_id, DataType::Int)?;
    let mut out = Outputs::new();
    for (name, mode) in [
        ("Leading", Mode::Leading),
        ("Trailing", Mode::Trailing),
        ("Total", Mode::Total),
    ] {
        let id = ctx
            .node()
            .outputs
            .iter()
            .find(|o| o.name == name && o.enabled)
            .map(|o| o.identifier.clone())
            .unwrap_or_else(|| name.to_string());
        let f = Field::input(Accumulate {
            value: value.clone(),
            group: group.clone(),
            domain,
            mode,
        });
        out.insert(id, SocketValue::Field(f));
    }
    Ok(out)
}
