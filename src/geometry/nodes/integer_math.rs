//! Integer function nodes (`function/nodes/node_fn_integer_math`, `node_fn_bit_math`,
//! `node_fn_hash_value`): 32-bit integer arithmetic with Blender's safe division (zero by
//! zero divisors), floored forms and wrapping overflow; bitwise operations with Blender's
//! shift and rotate ranges; and the Hash Value node's Jenkins hashes of each value type.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use crate::nodes::random::{hash1, hash2, hash3, hash4};

/// `divide_floor_i`.
fn divide_floor(a: i32, b: i32) -> i32 {
    let d = a.wrapping_div(b);
    let r = a.wrapping_rem(b);
    if r != 0 {
        d - ((a < 0) ^ (b < 0)) as i32
    } else {
        d
    }
}

fn safe_div(a: i32, b: i32) -> i32 {
    if b == 0 {
        0
    } else {
        a.wrapping_div(b)
    }
}

/// `safe_divide_round_i`: rounds half away from zero for either sign.
fn divide_round(a: i32, b: i32) -> i32 {
    let c = b.wrapping_abs();
    let sign = b.signum();
    if a >= 0 {
        safe_div(a.wrapping_mul(2).wrapping_add(c), c.wrapping_mul(2)).wrapping_mul(sign)
    } else {
        safe_div(
            a.wrapping_neg().wrapping_mul(2).wrapping_add(c),
            c.wrapping_mul(2),
        )
        .wrapping_neg()
        .wrapping_mul(sign)
    }
}

fn gcd(a: i32, b: i32) -> i32 {
    let (mut a, mut b) = (a.unsigned_abs(), b.unsigned_abs());
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a as i32
}

fn lcm(a: i32, b: i32) -> i32 {
    if a == 0 || b == 0 {
        return 0;
    }
    let g = gcd(a, b);
    (a / g).wrapping_mul(b).wrapping_abs()
}

fn integer_op(op: &str) -> Option<fn(i32, i32, i32) -> i32> {
    Some(match op {
        "ADD" => |a, b, _| a.wrapping_add(b),
        "SUBTRACT" => |a, b, _| a.wrapping_sub(b),
        "MULTIPLY" => |a, b, _| a.wrapping_mul(b),
        "DIVIDE" => |a, b, _| safe_div(a, b),
        "DIVIDE_FLOOR" => |a, b, _| if b != 0 { divide_floor(a, b) } else { 0 },
        "DIVIDE_CEIL" => |a, b, _| {
            if b != 0 {
                divide_floor(a, b.wrapping_neg()).wrapping_neg()
            } else {
                0
            }
        },
        "DIVIDE_ROUND" => |a, b, _| divide_round(a, b),
        // `std::pow(int, int)` in double, converted back (x86 gives INT_MIN out of range).
        "POWER" => |a, b, _| {
            let p = (a as f64).powf(b as f64).trunc();
            if p >= i32::MIN as f64 && p <= i32::MAX as f64 {
                p as i32
            } else {
                i32::MIN
            }
        },
        "MULTIPLY_ADD" => |a, b, c| a.wrapping_mul(b).wrapping_add(c),
        "FLOORED_MODULO" => |a, b, _| {
            if b != 0 {
                a.wrapping_rem(b).wrapping_add(b).wrapping_rem(b)
            } else {
                0
            }
        },
        "MODULO" => |a, b, _| if b != 0 { a.wrapping_rem(b) } else { 0 },
        "ABSOLUTE" => |a, _, _| a.wrapping_abs(),
        "SIGN" => |a, _, _| a.signum(),
        "MINIMUM" => |a, b, _| a.min(b),
        "MAXIMUM" => |a, b, _| a.max(b),
        "GCD" => |a, b, _| gcd(a, b),
        "LCM" => |a, b, _| lcm(a, b),
        "NEGATE" => |a, _, _| a.wrapping_neg(),
        _ => return None,
    })
}

/// The node's available inputs in order (the unused ones are zero).
fn int_inputs(ctx: &NodeCtx, ids: &[&str]) -> Result<Vec<Field>, GeometryError> {
    ids.iter()
        .map(|id| {
            if ctx.has_input(id) {
                ctx.field(id, DataType::Int)
            } else {
                Ok(Field::Constant(Value::Int(0)))
            }
        })
        .collect()
}

fn int_op3(
    ctx: &NodeCtx,
    label: &str,
    inputs: Vec<Field>,
    f: fn(i32, i32, i32) -> i32,
) -> Result<Field, GeometryError> {
    Field::op1(label, inputs, DataType::Int, move |n, x| {
        let (a, b, c) = (x[0].as_int(), x[1].as_int(), x[2].as_int());
        Ok(Array::Int((0..n).map(|i| f(a[i], b[i], c[i])).collect()))
    })
    .map_err(|e| ctx.err(e))
}

pub fn integer_math(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let op = ctx.prop_str("operation")?;
    let f = integer_op(op).ok_or_else(|| ctx.err(format!("operation {op} is not supported")))?;
    let inputs = int_inputs(ctx, &["Value", "Value_001", "Value_002"])?;
    let out = int_op3(ctx, "Integer Math", inputs, f)?;
    Ok(outputs([("Value", SocketValue::Field(out))]))
}

/// Bit Math's Shift: left for positive amounts, logical right for negative, through a
/// 64-bit value as Blender computes it (amounts clamped to 32).
fn shift(a: i32, b: i32) -> i32 {
    let s = b.clamp(-32, 32);
    let wide = (a as u32 as u64) << 16;
    let r = if s > 0 { wide << s } else { wide >> -s };
    (r >> 16) as u32 as i32
}

/// Bit Math's Rotate: by the amount modulo 32.
fn rotate(a: i32, b: i32) -> i32 {
    (a as u32).rotate_left(b.rem_euclid(32) as u32) as i32
}

pub fn bit_math(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let op = ctx.prop_str("operation")?;
    let f: fn(i32, i32, i32) -> i32 = match op {
        "AND" => |a, b, _| a & b,
        "OR" => |a, b, _| a | b,
        "XOR" => |a, b, _| a ^ b,
        "NOT" => |a, _, _| !a,
        "SHIFT" => |a, _, s| shift(a, s),
        "ROTATE" => |a, _, s| rotate(a, s),
        _ => return Err(ctx.err(format!("operation {op} is not supported"))),
    };
    let inputs = int_inputs(ctx, &["A", "B", "Shift"])?;
    let out = int_op3(ctx, "Bit Math", inputs, f)?;
    Ok(outputs([("Value", SocketValue::Field(out))]))
}

/// `noise::hash_float` of a value's floats (by their bits), as the Hash Value node hashes
/// it before mixing in the seed.
fn hash_floats(f: &[f32]) -> u32 {
    let b = |i: usize| f[i].to_bits();
    match f.len() {
        1 => hash1(b(0)),
        3 => hash3(b(0), b(1), b(2)),
        _ => hash4(b(0), b(1), b(2), b(3)),
    }
}

fn hash_value_of(v: Value) -> u32 {
    match v {
        Value::Int(i) => hash1(i as u32),
        Value::Float(x) => hash_floats(&[x]),
        Value::Vector(x) => hash_floats(&x),
        Value::Color(x) | Value::Quaternion(x) => hash_floats(&x),
        // `hash_float(float4x4)`: the four columns' hashes hashed together.
        Value::Matrix(m) => hash4(
            hash_floats(&m[0]),
            hash_floats(&m[1]),
            hash_floats(&m[2]),
            hash_floats(&m[3]),
        ),
        other => hash1(other.as_int() as u32),
    }
}

pub fn hash_value(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = match ctx.prop_str("data_type")? {
        "FLOAT" => DataType::Float,
        "INT" => DataType::Int,
        "VECTOR" => DataType::Vector,
        "RGBA" => DataType::Color,
        "ROTATION" => DataType::Quaternion,
        "MATRIX" => DataType::Matrix,
        other => return Err(ctx.err(format!("data type {other} is not supported"))),
    };
    let value = ctx.field("Value", ty)?;
    let seed = ctx.field("Seed", DataType::Int)?;
    let f = Field::op1("Hash Value", vec![value, seed], DataType::Int, |n, x| {
        let seed = x[1].as_int();
        Ok(Array::Int(
            (0..n)
                .map(|i| hash2(hash_value_of(x[0].get(i)), seed[i] as u32) as i32)
                .collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Hash", SocketValue::Field(f))]))
}
