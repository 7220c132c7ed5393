//! Field function nodes: Math, Vector Math, Compare, Boolean Math, Map Range, Clamp,
//! Mix (float, vector), Combine/Separate XYZ, Random Value, Noise Texture, Switch, Index Switch.
//!
//! Shared shader-node arithmetic comes from `crate::nodes` (Cycles semantics); where
//! Geometry Nodes computes differently (BLI's double-precision cross product, its
//! normalize, Map Range of an empty range, the degree constants) that is done here.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use crate::nodes::math::{math_node, safe_divide, vector_math, MathOp, VectorMathOp};
use crate::nodes::noise::{noise_texture, NoiseParams, NoiseType};
use crate::nodes::random::{random_bool, random_float, random_int, random_vector};

fn f(x: Field) -> SocketValue {
    SocketValue::Field(x)
}

fn op_err(ctx: &NodeCtx, e: String) -> GeometryError {
    ctx.err(e)
}

/// An input that the node's mode may hide (then unused: its type's zero).
fn opt_field(ctx: &NodeCtx, id: &str, ty: DataType) -> Result<Field, GeometryError> {
    if ctx.has_input(id) {
        ctx.field(id, ty)
    } else {
        Ok(Field::Constant(Value::zero(ty)))
    }
}

pub fn value(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = &ctx.node().outputs[0];
    let v = s
        .default_value
        .as_ref()
        .and_then(|v| v.as_f64())
        .unwrap_or(0.0) as f32;
    Ok(outputs([(s.identifier.as_str(), SocketValue::float(v))]))
}

pub fn integer(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let v = ctx
        .prop("integer")
        .and_then(|v| v.as_i64())
        .ok_or_else(|| ctx.err("property \"integer\" missing"))?;
    Ok(outputs([("Integer", SocketValue::int(v as i32))]))
}

pub fn boolean(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let v = ctx.prop_bool("boolean")?;
    Ok(outputs([("Boolean", f(Field::Constant(Value::Bool(v))))]))
}

pub fn vector(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let v = ctx
        .prop("vector")
        .and_then(|v| v.as_array())
        .ok_or_else(|| ctx.err("property \"vector\" missing"))?;
    let c = |i: usize| v.get(i).and_then(|x| x.as_f64()).unwrap_or(0.0) as f32;
    Ok(outputs([(
        "Vector",
        f(Field::Constant(Value::Vector([c(0), c(1), c(2)]))),
    )]))
}

/// Geometry Nodes' Math: Cycles' operations except the angle constants, which Blender
/// rounds from double (`M_PI / 180.0`).
fn gn_math(op: MathOp, clamp: bool, a: f32, b: f32, c: f32) -> f32 {
    let r = match op {
        MathOp::Radians => a * (std::f64::consts::PI / 180.0) as f32,
        MathOp::Degrees => a * (180.0 / std::f64::consts::PI) as f32,
        _ => return math_node(op, clamp, a, b, c),
    };
    if clamp {
        r.clamp(0.0, 1.0)
    } else {
        r
    }
}

pub fn math(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let op_name = ctx.prop_str("operation")?;
    let op = MathOp::from_blender(op_name)
        .ok_or_else(|| ctx.err(format!("unknown operation {op_name}")))?;
    let clamp = ctx.prop_bool("use_clamp").unwrap_or(false);
    let a = ctx.field("Value", DataType::Float)?;
    let b = if ctx.has_input("Value_001") {
        ctx.field("Value_001", DataType::Float)?
    } else {
        Field::Constant(Value::Float(0.0))
    };
    let c = if ctx.has_input("Value_002") {
        ctx.field("Value_002", DataType::Float)?
    } else {
        Field::Constant(Value::Float(0.0))
    };
    let out = Field::op1(
        format!("Math {op_name}"),
        vec![a, b, c],
        DataType::Float,
        move |n, x| {
            let (a, b, c) = (x[0].as_float(), x[1].as_float(), x[2].as_float());
            Ok(Array::Float(
                (0..n)
                    .map(|i| gn_math(op, clamp, a[i], b[i], c[i]))
                    .collect(),
            ))
        },
    )
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Value", f(out))]))
}

/// BLI `cross_high_precision`: products in double.
fn cross_hp(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    let (ax, ay, az) = (a[0] as f64, a[1] as f64, a[2] as f64);
    [
        (ay * b[2] as f64 - az * b[1] as f64) as f32,
        (az * b[0] as f64 - ax * b[2] as f64) as f32,
        (ax * b[1] as f64 - ay * b[0] as f64) as f32,
    ]
}

/// BLI `math::normalize`: zero below a tiny squared length, else divided by the length.
fn normalize_bli(a: [f32; 3]) -> [f32; 3] {
    let l2 = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    if l2 > 1.0e-35 {
        let l = l2.sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    } else {
        [0.0; 3]
    }
}

/// BLI `math::reflect`.
fn reflect_bli(i: [f32; 3], n: [f32; 3]) -> [f32; 3] {
    let d = 2.0 * (n[0] * i[0] + n[1] * i[1] + n[2] * i[2]);
    [i[0] - d * n[0], i[1] - d * n[1], i[2] - d * n[2]]
}

/// BLI `math::refract`.
fn refract_bli(i: [f32; 3], n: [f32; 3], eta: f32) -> [f32; 3] {
    let d = n[0] * i[0] + n[1] * i[1] + n[2] * i[2];
    let k = 1.0 - eta * eta * (1.0 - d * d);
    if k < 0.0 {
        return [0.0; 3];
    }
    let s = eta * d + k.sqrt();
    [
        eta * i[0] - s * n[0],
        eta * i[1] - s * n[1],
        eta * i[2] - s * n[2],
    ]
}

pub fn vector_math_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let op_name = ctx.prop_str("operation")?;
    let op = VectorMathOp::from_blender(op_name)
        .ok_or_else(|| ctx.err(format!("unknown operation {op_name}")))?;
    let get = |id: &str, t: DataType, d: Value| -> Result<Field, GeometryError> {
        if ctx.has_input(id) {
            ctx.field(id, t)
        } else {
            Ok(Field::Constant(d))
        }
    };
    let a = get("Vector", DataType::Vector, Value::Vector([0.0; 3]))?;
    let b = get("Vector_001", DataType::Vector, Value::Vector([0.0; 3]))?;
    let c = get("Vector_002", DataType::Vector, Value::Vector([0.0; 3]))?;
    let s = get("Scale", DataType::Float, Value::Float(1.0))?;
    let outs = Field::op(
        format!("Vector Math {op_name}"),
        vec![a, b, c, s],
        vec![DataType::Vector, DataType::Float],
        move |n, x| {
            let (a, b, c, s) = (
                x[0].as_vector(),
                x[1].as_vector(),
                x[2].as_vector(),
                x[3].as_float(),
            );
            let mut vv = Vec::with_capacity(n);
            let mut fv = Vec::with_capacity(n);
            for i in 0..n {
                let r = match op {
                    VectorMathOp::CrossProduct => crate::nodes::math::VectorMathResult {
                        vector: cross_hp(a[i], b[i]),
                        value: 0.0,
                    },
                    VectorMathOp::Normalize => crate::nodes::math::VectorMathResult {
                        vector: normalize_bli(a[i]),
                        value: 0.0,
                    },
                    VectorMathOp::Reflect => crate::nodes::math::VectorMathResult {
                        vector: reflect_bli(a[i], normalize_bli(b[i])),
                        value: 0.0,
                    },
                    VectorMathOp::Refract => crate::nodes::math::VectorMathResult {
                        vector: refract_bli(a[i], normalize_bli(b[i]), s[i]),
                        value: 0.0,
                    },
                    VectorMathOp::Scale => crate::nodes::math::VectorMathResult {
                        vector: [a[i][0] * s[i], a[i][1] * s[i], a[i][2] * s[i]],
                        value: 0.0,
                    },
                    _ => vector_math(op, a[i], b[i], c[i], s[i]),
                };
                vv.push(r.vector);
                fv.push(r.value);
            }
            Ok(vec![Array::Vector(vv), Array::Float(fv)])
        },
    )
    .map_err(|e| op_err(ctx, e))?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Vector", f(it.next().unwrap())),
        ("Value", f(it.next().unwrap())),
    ]))
}

pub fn compare(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dt = ctx.prop_str("data_type")?;
    if dt == "STRING" {
        return super::string::compare_strings(ctx);
    }
    let op = ctx.prop_str("operation")?.to_string();
    let mode = ctx
        .prop("mode")
        .and_then(|v| v.as_str())
        .unwrap_or("ELEMENT")
        .to_string();
    let eps = if ctx.has_input("Epsilon") {
        ctx.field("Epsilon", DataType::Float)?
    } else {
        Field::Constant(Value::Float(0.0))
    };
    let label = format!("Compare {dt} {op}");
    let cmp_f = |op: &str, a: f32, b: f32, e: f32| -> Option<bool> {
        Some(match op {
            "LESS_THAN" => a < b,
            "LESS_EQUAL" => a <= b,
            "GREATER_THAN" => a > b,
            "GREATER_EQUAL" => a >= b,
            "EQUAL" => (a - b).abs() <= e,
            "NOT_EQUAL" => (a - b).abs() > e,
            _ => return None,
        })
    };
    let result = match dt {
        "FLOAT" => {
            let a = ctx.field("A", DataType::Float)?;
            let b = ctx.field("B", DataType::Float)?;
            if cmp_f(&op, 0.0, 0.0, 0.0).is_none() {
                return Err(ctx.err(format!("operation {op} is not valid for floats")));
            }
            Field::op1(label, vec![a, b, eps], DataType::Bool, move |n, x| {
                let (a, b, e) = (x[0].as_float(), x[1].as_float(), x[2].as_float());
                Ok(Array::Bool(
                    (0..n)
                        .map(|i| cmp_f(&op, a[i], b[i], e[i]).unwrap())
                        .collect(),
                ))
            })
        }
        "INT" => {
            let a = ctx.field("A_INT", DataType::Int)?;
            let b = ctx.field("B_INT", DataType::Int)?;
            Field::op1(label, vec![a, b], DataType::Bool, move |n, x| {
                let (a, b) = (x[0].as_int(), x[1].as_int());
                let r: Result<Vec<bool>, String> = (0..n)
                    .map(|i| {
                        Ok(match op.as_str() {
                            "LESS_THAN" => a[i] < b[i],
                            "LESS_EQUAL" => a[i] <= b[i],
                            "GREATER_THAN" => a[i] > b[i],
                            "GREATER_EQUAL" => a[i] >= b[i],
                            "EQUAL" => a[i] == b[i],
                            "NOT_EQUAL" => a[i] != b[i],
                            o => return Err(format!("operation {o} is not valid for integers")),
                        })
                    })
                    .collect();
                Ok(Array::Bool(r?))
            })
        }
        "VECTOR" => {
            let a = ctx.field("A_VEC3", DataType::Vector)?;
            let b = ctx.field("B_VEC3", DataType::Vector)?;
            let c = if ctx.has_input("C") {
                ctx.field("C", DataType::Float)?
            } else {
                Field::Constant(Value::Float(0.0))
            };
            let angle = if ctx.has_input("Angle") {
                ctx.field("Angle", DataType::Float)?
            } else {
                Field::Constant(Value::Float(0.0))
            };
            Field::op1(
                label,
                vec![a, b, c, angle, eps],
                DataType::Bool,
                move |n, x| {
                    let (a, b, c, ang, e) = (
                        x[0].as_vector(),
                        x[1].as_vector(),
                        x[2].as_float(),
                        x[3].as_float(),
                        x[4].as_float(),
                    );
                    let mut out = Vec::with_capacity(n);
                    for i in 0..n {
                        let (va, vb) = (a[i], b[i]);
                        let r = match mode.as_str() {
                            "ELEMENT" => match op.as_str() {
                                "EQUAL" => (0..3).all(|k| (va[k] - vb[k]).abs() <= e[i]),
                                "NOT_EQUAL" => (0..3).any(|k| (va[k] - vb[k]).abs() > e[i]),
                                o => (0..3).all(|k| cmp_f(o, va[k], vb[k], e[i]).unwrap_or(false)),
                            },
                            "LENGTH" => cmp_f(&op, len(va), len(vb), e[i]).unwrap_or(false),
                            "AVERAGE" => cmp_f(
                                &op,
                                (va[0] + va[1] + va[2]) / 3.0,
                                (vb[0] + vb[1] + vb[2]) / 3.0,
                                e[i],
                            )
                            .unwrap_or(false),
                            "DOT_PRODUCT" => cmp_f(
                                &op,
                                va[0] * vb[0] + va[1] * vb[1] + va[2] * vb[2],
                                c[i],
                                e[i],
                            )
                            .unwrap_or(false),
                            "DIRECTION" => {
                                cmp_f(&op, angle_between(va, vb), ang[i], e[i]).unwrap_or(false)
                            }
                            m => return Err(format!("vector mode {m} is not supported")),
                        };
                        out.push(r);
                    }
                    Ok(Array::Bool(out))
                },
            )
        }
        "RGBA" => {
            let a = ctx.field("A_COL", DataType::Color)?;
            let b = ctx.field("B_COL", DataType::Color)?;
            Field::op1(label, vec![a, b, eps], DataType::Bool, move |n, x| {
                let (a, b, e) = (x[0].as_color(), x[1].as_color(), x[2].as_float());
                let lum = |c: [f32; 4]| Value::Color(c).as_float();
                let r: Result<Vec<bool>, String> = (0..n)
                    .map(|i| {
                        Ok(match op.as_str() {
                            "EQUAL" => (0..3).all(|k| (a[i][k] - b[i][k]).abs() <= e[i]),
                            "NOT_EQUAL" => (0..3).any(|k| (a[i][k] - b[i][k]).abs() > e[i]),
                            "BRIGHTER" => lum(a[i]) > lum(b[i]),
                            "DARKER" => lum(a[i]) < lum(b[i]),
                            o => return Err(format!("operation {o} is not valid for colours")),
                        })
                    })
                    .collect();
                Ok(Array::Bool(r?))
            })
        }
        other => return Err(ctx.err(format!("data type {other} is not supported"))),
    }
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Result", f(result))]))
}

fn len(a: [f32; 3]) -> f32 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// `angle_v3v3`: via the normalized vectors, as BLI computes it.
fn angle_between(a: [f32; 3], b: [f32; 3]) -> f32 {
    let (na, _) = super::super::math::normalize_v3(a);
    let (nb, _) = super::super::math::normalize_v3(b);
    let d = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
    if d >= 0.0 {
        let v = [na[0] - nb[0], na[1] - nb[1], na[2] - nb[2]];
        2.0 * (len(v) / 2.0).clamp(-1.0, 1.0).asin()
    } else {
        let v = [na[0] + nb[0], na[1] + nb[1], na[2] + nb[2]];
        std::f32::consts::PI - 2.0 * (len(v) / 2.0).clamp(-1.0, 1.0).asin()
    }
}

pub fn boolean_math(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let op = ctx.prop_str("operation")?.to_string();
    let a = ctx.field("Boolean", DataType::Bool)?;
    let b = if ctx.has_input("Boolean_001") {
        ctx.field("Boolean_001", DataType::Bool)?
    } else {
        Field::Constant(Value::Bool(false))
    };
    let out = Field::op1(
        format!("Boolean Math {op}"),
        vec![a, b],
        DataType::Bool,
        move |n, x| {
            let (a, b) = (x[0].as_bool(), x[1].as_bool());
            let r: Result<Vec<bool>, String> = (0..n)
                .map(|i| {
                    let (a, b) = (a[i], b[i]);
                    Ok(match op.as_str() {
                        "AND" => a && b,
                        "OR" => a || b,
                        "NOT" => !a,
                        "NAND" => !(a && b),
                        "NOR" => !(a || b),
                        "XNOR" => a == b,
                        "XOR" => a != b,
                        "IMPLY" => !a || b,
                        "NIMPLY" => a && !b,
                        o => return Err(format!("unknown operation {o}")),
                    })
                })
                .collect();
            Ok(Array::Bool(r?))
        },
    )
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Boolean", f(out))]))
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if x < e0 {
        0.0
    } else if x >= e1 {
        1.0
    } else {
        let t = (x - e0) / (e1 - e0);
        (3.0 - 2.0 * t) * (t * t)
    }
}
fn smootherstep(e0: f32, e1: f32, x: f32) -> f32 {
    let x = safe_divide(x - e0, e1 - e0).clamp(0.0, 1.0);
    x * x * x * (x * (x * 6.0 - 15.0) + 10.0)
}
fn clamp_range(v: f32, a: f32, b: f32) -> f32 {
    // max/min rather than f32::clamp, which panics on a NaN bound from the graph.
    if a < b {
        v.max(a).min(b)
    } else {
        v.max(b).min(a)
    }
}

/// Map Range as Geometry Nodes computes it (`node_shader_map_range.cc` multi-functions):
/// an empty "from" range maps to "to min" (Cycles gives 0).
#[allow(clippy::too_many_arguments)]
fn map_range_gn(
    interp: &str,
    clamp: bool,
    v: f32,
    fmin: f32,
    fmax: f32,
    tmin: f32,
    tmax: f32,
    steps: f32,
) -> f32 {
    match interp {
        "LINEAR" => {
            let factor = safe_divide(v - fmin, fmax - fmin);
            let r = tmin + factor * (tmax - tmin);
            if clamp {
                clamp_range(r, tmin, tmax)
            } else {
                r
            }
        }
        "STEPPED" => {
            let mut factor = safe_divide(v - fmin, fmax - fmin);
            factor = if steps > 0.0 {
                (factor * (steps + 1.0)).floor() / steps
            } else {
                0.0
            };
            let r = tmin + factor * (tmax - tmin);
            if clamp {
                clamp_range(r, tmin, tmax)
            } else {
                r
            }
        }
        "SMOOTHSTEP" => {
            let factor = if fmin > fmax {
                1.0 - smoothstep(fmax, fmin, v)
            } else {
                smoothstep(fmin, fmax, v)
            };
            tmin + factor * (tmax - tmin)
        }
        _ => {
            let factor = if fmin > fmax {
                1.0 - smootherstep(fmax, fmin, v)
            } else {
                smootherstep(fmin, fmax, v)
            };
            tmin + factor * (tmax - tmin)
        }
    }
}

pub fn map_range(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dt = ctx.prop_str("data_type")?;
    let interp = ctx.prop_str("interpolation_type")?.to_string();
    if !matches!(
        interp.as_str(),
        "LINEAR" | "STEPPED" | "SMOOTHSTEP" | "SMOOTHERSTEP"
    ) {
        return Err(ctx.err(format!("interpolation {interp} is not supported")));
    }
    let clamp = ctx.prop_bool("clamp").unwrap_or(false);
    match dt {
        "FLOAT" => {
            let ids = ["Value", "From Min", "From Max", "To Min", "To Max", "Steps"];
            let ins: Vec<Field> = ids
                .iter()
                .map(|id| opt_field(ctx, id, DataType::Float))
                .collect::<Result<_, _>>()?;
            let out = Field::op1("Map Range", ins, DataType::Float, move |n, x| {
                let a: Vec<_> = x.iter().map(|a| a.as_float()).collect();
                Ok(Array::Float(
                    (0..n)
                        .map(|i| {
                            map_range_gn(
                                &interp, clamp, a[0][i], a[1][i], a[2][i], a[3][i], a[4][i],
                                a[5][i],
                            )
                        })
                        .collect(),
                ))
            })
            .map_err(|e| op_err(ctx, e))?;
            Ok(outputs([("Result", f(out))]))
        }
        "FLOAT_VECTOR" => {
            let ids = [
                "Vector",
                "From_Min_FLOAT3",
                "From_Max_FLOAT3",
                "To_Min_FLOAT3",
                "To_Max_FLOAT3",
                "Steps_FLOAT3",
            ];
            let ins: Vec<Field> = ids
                .iter()
                .map(|id| opt_field(ctx, id, DataType::Vector))
                .collect::<Result<_, _>>()?;
            let out = Field::op1("Map Range", ins, DataType::Vector, move |n, x| {
                let a: Vec<_> = x.iter().map(|a| a.as_vector()).collect();
                let mut out = Vec::with_capacity(n);
                for i in 0..n {
                    let mut r = [0.0; 3];
                    for k in 0..3 {
                        let (v, fmin, fmax, tmin, tmax, steps) = (
                            a[0][i][k], a[1][i][k], a[2][i][k], a[3][i][k], a[4][i][k], a[5][i][k],
                        );
                        let mut factor = safe_divide(v - fmin, fmax - fmin);
                        let clamp_it = match interp.as_str() {
                            "LINEAR" => true,
                            "STEPPED" => {
                                factor = if steps > 0.0 {
                                    (factor * (steps + 1.0)).floor() / steps
                                } else {
                                    0.0
                                };
                                true
                            }
                            "SMOOTHSTEP" => {
                                let t = factor.clamp(0.0, 1.0);
                                factor = (3.0 - 2.0 * t) * (t * t);
                                false
                            }
                            _ => {
                                let t = factor.clamp(0.0, 1.0);
                                factor = t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
                                false
                            }
                        };
                        let v = factor * (tmax - tmin) + tmin;
                        r[k] = if clamp && clamp_it {
                            clamp_range(v, tmin, tmax)
                        } else {
                            v
                        };
                    }
                    out.push(r);
                }
                Ok(Array::Vector(out))
            })
            .map_err(|e| op_err(ctx, e))?;
            Ok(outputs([("Vector", f(out))]))
        }
        other => Err(ctx.err(format!("data type {other} is not supported"))),
    }
}

pub fn clamp(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = ctx.prop_str("clamp_type")?;
    let range = ty == "RANGE";
    let ins = vec![
        ctx.field("Value", DataType::Float)?,
        ctx.field("Min", DataType::Float)?,
        ctx.field("Max", DataType::Float)?,
    ];
    let out = Field::op1("Clamp", ins, DataType::Float, move |n, x| {
        let (v, a, b) = (x[0].as_float(), x[1].as_float(), x[2].as_float());
        Ok(Array::Float(
            (0..n)
                .map(|i| {
                    let (mut lo, mut hi) = (a[i], b[i]);
                    if range && lo > hi {
                        std::mem::swap(&mut lo, &mut hi);
                    }
                    v[i].max(lo).min(hi)
                })
                .collect(),
        ))
    })
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Result", f(out))]))
}

pub fn mix(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dt = ctx.prop_str("data_type")?;
    let clamp_factor = ctx.prop_bool("clamp_factor").unwrap_or(true);
    match dt {
        "FLOAT" => {
            let ins = vec![
                ctx.field("Factor_Float", DataType::Float)?,
                ctx.field("A_Float", DataType::Float)?,
                ctx.field("B_Float", DataType::Float)?,
            ];
            let out = Field::op1("Mix", ins, DataType::Float, move |n, x| {
                let (t, a, b) = (x[0].as_float(), x[1].as_float(), x[2].as_float());
                Ok(Array::Float(
                    (0..n)
                        .map(|i| {
                            let t = if clamp_factor {
                                t[i].clamp(0.0, 1.0)
                            } else {
                                t[i]
                            };
                            // BLI interpf(target, origin, t)
                            t * b[i] + (1.0 - t) * a[i]
                        })
                        .collect(),
                ))
            })
            .map_err(|e| op_err(ctx, e))?;
            Ok(outputs([("Result_Float", f(out))]))
        }
        "VECTOR" => {
            let uniform = ctx.prop_str("factor_mode").unwrap_or("UNIFORM") == "UNIFORM";
            let tf = if uniform {
                ctx.field("Factor_Float", DataType::Float)?
                    .convert(DataType::Vector)
            } else {
                ctx.field("Factor_Vector", DataType::Vector)?
            };
            let ins = vec![
                tf,
                ctx.field("A_Vector", DataType::Vector)?,
                ctx.field("B_Vector", DataType::Vector)?,
            ];
            let out = Field::op1("Mix", ins, DataType::Vector, move |n, x| {
                let (t, a, b) = (x[0].as_vector(), x[1].as_vector(), x[2].as_vector());
                Ok(Array::Vector(
                    (0..n)
                        .map(|i| {
                            let mut r = [0.0; 3];
                            for k in 0..3 {
                                let tk = if clamp_factor {
                                    t[i][k].clamp(0.0, 1.0)
                                } else {
                                    t[i][k]
                                };
                                r[k] = (1.0 - tk) * a[i][k] + tk * b[i][k];
                            }
                            r
                        })
                        .collect(),
                ))
            })
            .map_err(|e| op_err(ctx, e))?;
            Ok(outputs([("Result_Vector", f(out))]))
        }
        "RGBA" => super::color::mix_rgba(ctx),
        other => Err(ctx.err(format!(
            "Mix of {other} is not supported in Geometry Nodes yet"
        ))),
    }
}

pub fn combine_xyz(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ins = vec![
        ctx.field("X", DataType::Float)?,
        ctx.field("Y", DataType::Float)?,
        ctx.field("Z", DataType::Float)?,
    ];
    let out = Field::op1("Combine XYZ", ins, DataType::Vector, |n, x| {
        let (a, b, c) = (x[0].as_float(), x[1].as_float(), x[2].as_float());
        Ok(Array::Vector((0..n).map(|i| [a[i], b[i], c[i]]).collect()))
    })
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Vector", f(out))]))
}

pub fn separate_xyz(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let v = ctx.field("Vector", DataType::Vector)?;
    let outs = Field::op("Separate XYZ", vec![v], vec![DataType::Float; 3], |_, x| {
        let v = x[0].as_vector();
        Ok((0..3)
            .map(|k| Array::Float(v.iter().map(|p| p[k]).collect()))
            .collect())
    })
    .map_err(|e| op_err(ctx, e))?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("X", f(it.next().unwrap())),
        ("Y", f(it.next().unwrap())),
        ("Z", f(it.next().unwrap())),
    ]))
}

pub fn random_value(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dt = ctx.prop_str("data_type")?;
    let id = ctx.field("ID", DataType::Int)?;
    let seed = ctx.field("Seed", DataType::Int)?;
    let e = |x| op_err(ctx, x);
    match dt {
        "FLOAT" => {
            let ins = vec![
                ctx.field("Min_001", DataType::Float)?,
                ctx.field("Max_001", DataType::Float)?,
                id,
                seed,
            ];
            let out = Field::op1("Random Value", ins, DataType::Float, |n, x| {
                let (a, b, id, s) = (
                    x[0].as_float(),
                    x[1].as_float(),
                    x[2].as_int(),
                    x[3].as_int(),
                );
                Ok(Array::Float(
                    (0..n)
                        .map(|i| random_float(a[i], b[i], id[i], s[i]))
                        .collect(),
                ))
            })
            .map_err(e)?;
            Ok(outputs([("Value_001", f(out))]))
        }
        "INT" => {
            let ins = vec![
                ctx.field("Min_002", DataType::Int)?,
                ctx.field("Max_002", DataType::Int)?,
                id,
                seed,
            ];
            let out = Field::op1("Random Value", ins, DataType::Int, |n, x| {
                let (a, b, id, s) = (x[0].as_int(), x[1].as_int(), x[2].as_int(), x[3].as_int());
                Ok(Array::Int(
                    (0..n)
                        .map(|i| random_int(a[i], b[i], id[i], s[i]))
                        .collect(),
                ))
            })
            .map_err(e)?;
            Ok(outputs([("Value_002", f(out))]))
        }
        "FLOAT_VECTOR" => {
            let ins = vec![
                ctx.field("Min", DataType::Vector)?,
                ctx.field("Max", DataType::Vector)?,
                id,
                seed,
            ];
            let out = Field::op1("Random Value", ins, DataType::Vector, |n, x| {
                let (a, b, id, s) = (
                    x[0].as_vector(),
                    x[1].as_vector(),
                    x[2].as_int(),
                    x[3].as_int(),
                );
                Ok(Array::Vector(
                    (0..n)
                        .map(|i| random_vector(a[i], b[i], id[i], s[i]))
                        .collect(),
                ))
            })
            .map_err(e)?;
            Ok(outputs([("Value", f(out))]))
        }
        "BOOLEAN" => {
            let ins = vec![ctx.field("Probability", DataType::Float)?, id, seed];
            let out = Field::op1("Random Value", ins, DataType::Bool, |n, x| {
                let (p, id, s) = (x[0].as_float(), x[1].as_int(), x[2].as_int());
                Ok(Array::Bool(
                    (0..n).map(|i| random_bool(p[i], id[i], s[i])).collect(),
                ))
            })
            .map_err(e)?;
            Ok(outputs([("Value_003", f(out))]))
        }
        other => Err(ctx.err(format!("data type {other} is not supported"))),
    }
}

pub fn noise_texture_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dims: u8 = match ctx.prop_str("noise_dimensions")? {
        "1D" => 1,
        "2D" => 2,
        "3D" => 3,
        "4D" => 4,
        d => return Err(ctx.err(format!("dimensions {d} not supported"))),
    };
    let kind_name = ctx.prop_str("noise_type").unwrap_or("FBM");
    let kind = NoiseType::from_blender(kind_name)
        .ok_or_else(|| ctx.err(format!("noise type {kind_name} not supported")))?;
    let normalize = ctx.prop_bool("normalize").unwrap_or(true);
    let zero = Field::Constant(Value::Float(0.0));
    let opt = |id: &str| -> Result<Field, GeometryError> {
        if ctx.has_input(id) {
            ctx.field(id, DataType::Float)
        } else {
            Ok(zero.clone())
        }
    };
    let vector = if ctx.has_input("Vector") {
        ctx.field("Vector", DataType::Vector)?
    } else {
        Field::Constant(Value::Vector([0.0; 3]))
    };
    let ins = vec![
        vector,
        opt("W")?,
        opt("Scale")?,
        opt("Detail")?,
        opt("Roughness")?,
        opt("Lacunarity")?,
        opt("Offset")?,
        opt("Gain")?,
        opt("Distortion")?,
    ];
    let want_color = ctx.output_used("Color");
    let outs = Field::op(
        "Noise Texture",
        ins,
        vec![DataType::Float, DataType::Color],
        move |n, x| {
            let v = x[0].as_vector();
            let s: Vec<_> = x[1..].iter().map(|a| a.as_float()).collect();
            let mut fac = Vec::with_capacity(n);
            let mut col = Vec::with_capacity(n);
            for i in 0..n {
                let p = NoiseParams {
                    kind,
                    normalize,
                    detail: s[2][i],
                    roughness: s[3][i],
                    lacunarity: s[4][i],
                    offset: s[5][i],
                    gain: s[6][i],
                    distortion: s[7][i],
                };
                let (fv, c) = noise_texture(dims, v[i], s[0][i], s[1][i], p, want_color);
                fac.push(fv);
                col.push(c);
            }
            Ok(vec![Array::Float(fac), Array::Color(col)])
        },
    )
    .map_err(|e| op_err(ctx, e))?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Fac", f(it.next().unwrap())),
        ("Color", f(it.next().unwrap())),
    ]))
}

/// Switch: a single condition picks one input, evaluating only that one; a field
/// condition selects per element (field types only).
pub fn switch(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let cond = ctx.field("Switch", DataType::Bool)?;
    match cond {
        Field::Constant(v) => {
            let pick = if v.as_bool() { "True" } else { "False" };
            Ok(outputs([("Output", ctx.input(pick)?)]))
        }
        c => {
            let (SocketValue::Field(a), SocketValue::Field(b)) =
                (ctx.input("False")?, ctx.input("True")?)
            else {
                return Err(ctx.err("a field condition can only switch between fields"));
            };
            let t = if super::super::types::Value::can_convert(a.data_type(), b.data_type()) {
                b.data_type()
            } else {
                a.data_type()
            };
            let out = Field::op1("Switch", vec![c, a.convert(t), b.convert(t)], t, |n, x| {
                let s = x[0].as_bool();
                let mut out = x[1].clone();
                for i in 0..n {
                    if s[i] {
                        out.set(i, x[2].get(i));
                    }
                }
                Ok(out)
            })
            .map_err(|e| op_err(ctx, e))?;
            Ok(outputs([("Output", f(out))]))
        }
    }
}

/// Index Switch (`node_geo_index_switch.cc`): the item input at Index; an index outside
/// the items gives the type's default (zero, identity, empty geometry). A field index
/// picks per element, for field types only.
pub fn index_switch(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let node = ctx.node();
    // Inputs after Index, without the virtual "extend" socket Blender adds for links.
    let items: Vec<&str> = node
        .inputs
        .iter()
        .skip(1)
        .filter(|s| s.identifier != "__extend__" && ctx.has_input(&s.identifier))
        .map(|s| s.identifier.as_str())
        .collect();
    let out_kind = node
        .outputs
        .first()
        .map(|s| s.kind.as_str())
        .ok_or_else(|| ctx.err("has no output"))?;
    let index = match ctx.input("Index")? {
        SocketValue::Field(x) => x.convert(DataType::Int),
        other => {
            return Err(ctx.err(format!(
                "input \"Index\" is a {}, expected an integer",
                other.kind()
            )))
        }
    };
    let Some(t) = DataType::from_socket(out_kind) else {
        // Geometry, strings, data-blocks: a single index only.
        let Field::Constant(i) = index else {
            return Err(ctx.err(format!(
                "a field index cannot switch {out_kind} values (Blender takes one value)"
            )));
        };
        let v = match usize::try_from(i.as_int()).ok().and_then(|i| items.get(i)) {
            Some(id) => ctx.input(id)?,
            None => SocketValue::zero(out_kind),
        };
        return Ok(outputs([("Output", v)]));
    };
    if let Field::Constant(i) = &index {
        let v = match usize::try_from(i.as_int()).ok().and_then(|i| items.get(i)) {
            Some(id) => f(ctx.field(id, t)?),
            None => f(Field::Constant(Value::zero(t))),
        };
        return Ok(outputs([("Output", v)]));
    }
    let mut inputs = vec![index];
    for id in &items {
        inputs.push(ctx.field(id, t)?);
    }
    let out = Field::op1("Index Switch", inputs, t, move |n, x| {
        let idx = x[0].as_int();
        let mut out = Array::zeros(t, n);
        for (i, k) in idx.iter().enumerate().take(n) {
            if let Some(a) = usize::try_from(*k).ok().and_then(|k| x.get(k + 1)) {
                out.set(i, a.get(i));
            }
        }
        Ok(out)
    })
    .map_err(|e| op_err(ctx, e))?;
    Ok(outputs([("Output", f(out))]))
}
