//! What Field Average, Field Min & Max and Field Variance share (4.5's field statistics,
//! `node_geo_field_*`): a statistic of a field over a domain, per Group ID, read back on
//! any domain. Blender takes one path when Group ID is a single value (unlinked or
//! constant) and another when it is a field, and the two sum differently, so both are
//! kept apart here.

use std::collections::HashMap;

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

/// The group of each element, numbered in order of first appearance.
pub(super) struct Groups {
    pub of: Vec<usize>,
    pub count: usize,
}

impl Groups {
    fn new(ids: &[i32]) -> Groups {
        let mut slot: HashMap<i32, usize> = HashMap::new();
        let of = ids
            .iter()
            .map(|id| {
                let next = slot.len();
                *slot.entry(*id).or_insert(next)
            })
            .collect();
        Groups {
            of,
            count: slot.len(),
        }
    }
}

/// One statistic per group of one float channel (vectors go per component, as Blender's
/// `float3` arithmetic does); `None`: Group ID is a single value, one result.
pub(super) type FloatStat = fn(&[f32], Option<&Groups>) -> Vec<f32>;
pub(super) type IntStat = fn(&[i32], Option<&Groups>) -> Vec<i32>;

/// `std::reduce(first, last, init, op)` as libstdc++ runs it on a random-access range
/// (Blender 4.5's Linux build is GCC's): each block of four is combined as
/// `op(op(a0, a1), op(a2, a3))` and folded into the running value, the rest one by one.
/// `op` is applied to whatever pair comes, exactly so, even where it is not symmetric.
pub(super) fn reduce(v: &[f32], init: f32, op: impl Fn(f32, f32) -> f32) -> f32 {
    let mut acc = init;
    let mut blocks = v.chunks_exact(4);
    for b in &mut blocks {
        let v3 = op(op(b[0], b[1]), op(b[2], b[3]));
        acc = op(acc, v3);
    }
    for &x in blocks.remainder() {
        acc = op(acc, x);
    }
    acc
}

/// Per-group sums and counts in element order (Blender's `Map<int, pair<T, int>>` pass).
pub(super) fn group_sums(v: &[f32], g: &Groups) -> (Vec<f32>, Vec<u32>) {
    let mut sum = vec![0.0f32; g.count];
    let mut count = vec![0u32; g.count];
    for (x, &k) in v.iter().zip(&g.of) {
        sum[k] += *x;
        count[k] += 1;
    }
    (sum, count)
}

#[derive(Debug)]
struct Statistic {
    label: &'static str,
    value: Field,
    group: Field,
    domain: Domain,
    ty: DataType,
    float: FloatStat,
    int: Option<IntStat>,
}

impl Statistic {
    fn per_group(&self, values: &Array, groups: Option<&Groups>) -> Result<Array, String> {
        Ok(match self.ty {
            DataType::Int => {
                let f = self
                    .int
                    .ok_or_else(|| format!("{}: integer values are not taken", self.label))?;
                Array::Int(f(&values.as_int(), groups))
            }
            DataType::Vector => {
                let v = values.as_vector();
                let ch: Vec<Vec<f32>> = (0..3)
                    .map(|k| (self.float)(&v.iter().map(|p| p[k]).collect::<Vec<_>>(), groups))
                    .collect();
                Array::Vector(
                    (0..ch[0].len())
                        .map(|i| [ch[0][i], ch[1][i], ch[2][i]])
                        .collect(),
                )
            }
            _ => Array::Float((self.float)(&values.as_float(), groups)),
        })
    }
}

impl FieldInput for Statistic {
    fn data_type(&self) -> DataType {
        self.ty
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(self.domain);
        if n == 0 || !ctx.component.has_domain(self.domain) {
            // Blender returns no values: the defaults.
            return Ok(Array::zeros(self.ty, ctx.component.domain_size(domain)));
        }
        let values = ctx.eval(&self.value, self.domain, self.ty)?;
        let out = match &self.group {
            // A single Group ID: Blender's `is_single()` path, whose single result any
            // domain reads as is (adapting a single value does no arithmetic).
            Field::Constant(_) => {
                let v = self.per_group(&values, None)?.get(0);
                return Ok(Array::filled(v, ctx.component.domain_size(domain)));
            }
            g => {
                let ids = ctx.eval(g, self.domain, DataType::Int)?;
                let groups = Groups::new(&ids.as_int());
                self.per_group(&values, Some(&groups))?.gather(&groups.of)
            }
        };
        Ok(ctx.component.adapt(&out, self.domain, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(self.domain)
    }
}

/// The node: `data_type` among `types`, `domain`, the Value and Group ID inputs, and one
/// output field per `(output name, float statistic, integer statistic)`.
pub(super) fn statistics_node(
    ctx: &NodeCtx,
    label: &'static str,
    types: &[&str],
    outputs: &[(&str, FloatStat, Option<IntStat>)],
) -> Result<Outputs, GeometryError> {
    let t = ctx.prop_str("data_type")?;
    let ty = match t {
        "FLOAT" => DataType::Float,
        "INT" => DataType::Int,
        "FLOAT_VECTOR" => DataType::Vector,
        _ => DataType::Bool,
    };
    if !types.contains(&t) || ty == DataType::Bool {
        return Err(ctx.err(format!("data type {t} is not one {label} takes")));
    }
    let d = ctx.prop_str("domain")?;
    let domain = Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))?;
    let value = ctx.field("Value", ty)?;
    let group = ctx.field("Group Index", DataType::Int)?;
    let mut out = Outputs::new();
    for (name, float, int) in outputs {
        let f = Field::input(Statistic {
            label,
            value: value.clone(),
            group: group.clone(),
            domain,
            ty,
            float: *float,
            int: *int,
        });
        out.insert(name.to_string(), SocketValue::Field(f));
    }
    Ok(out)
}
