//! The string nodes, as Blender 4.5's function nodes compute them
//! (`source/blender/nodes/function/nodes/node_fn_*string*.cc`). Strings are single values
//! in Geometry Nodes (no string fields), so each node computes one string; positions and
//! lengths count UTF-8 characters, as `BLI_strlen_utf8` does.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::Value;
use super::super::value::SocketValue;

fn string(s: String) -> SocketValue {
    SocketValue::String(s)
}

fn chars(s: &str) -> i32 {
    i32::try_from(s.chars().count()).unwrap_or(i32::MAX)
}

/// Value to String: a float with Decimals digits after the point (C++ `std::fixed`,
/// `setprecision(max(0, decimals))`), or an integer (4.5's Integer mode).
pub fn value_to_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = if ctx.prop("data_type").and_then(|v| v.as_str()) == Some("INT") {
        ctx.int("Value")?.to_string()
    } else {
        let v = ctx.float("Value")?;
        let decimals = ctx.int("Decimals")?.clamp(0, 1000) as usize;
        fixed(v, decimals)
    };
    Ok(outputs([("String", string(s))]))
}

/// `std::fixed` formatting of a float: both it and Rust's `{:.N}` print the exact
/// decimal value of the number rounded to N digits; only the spellings of NaN and
/// infinity differ.
fn fixed(v: f32, decimals: usize) -> String {
    if v.is_nan() {
        return if v.is_sign_negative() { "-nan" } else { "nan" }.to_string();
    }
    if v.is_infinite() {
        return if v < 0.0 { "-inf" } else { "inf" }.to_string();
    }
    format!("{:.*}", decimals, v as f64)
}

/// Join Strings: the linked strings in Blender's multi-input order, Delimiter between.
pub fn join_strings(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let delimiter = ctx.string("Delimiter")?;
    let mut parts = Vec::new();
    for v in ctx.inputs_multi("Strings")? {
        match v {
            SocketValue::String(s) => parts.push(s),
            other => {
                return Err(ctx.err(format!(
                    "input \"Strings\" is a {}, expected a string",
                    other.kind()
                )))
            }
        }
    }
    Ok(outputs([("String", string(parts.join(&delimiter)))]))
}

/// Slice String: Length characters from character Position, both clamped to the string.
pub fn slice_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx.string("String")?;
    let position = ctx.int("Position")?;
    let length = ctx.int("Length")?;
    let len = chars(&s);
    let start = position.clamp(0, len);
    let end = position.saturating_add(length).clamp(0, len);
    let out: String = if end > start {
        s.chars()
            .skip(start as usize)
            .take((end - start) as usize)
            .collect()
    } else {
        String::new()
    };
    Ok(outputs([("String", string(out))]))
}

pub fn string_length(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx.string("String")?;
    Ok(outputs([("Length", SocketValue::int(chars(&s)))]))
}

pub fn special_characters(_ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Line Break", string("\n".into())),
        ("Tab", string("\t".into())),
    ]))
}

/// Replace String: every non-overlapping match, left to right; an empty Find changes
/// nothing.
pub fn replace_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx.string("String")?;
    let find = ctx.string("Find")?;
    let replace = ctx.string("Replace")?;
    let out = if find.is_empty() {
        s
    } else {
        s.replace(&find, &replace)
    };
    Ok(outputs([("String", string(out))]))
}

/// Find in String: the character position of the first match and the number of
/// non-overlapping matches; 0 and 0 for an empty string or search, and First Found 0
/// when nothing matches (as Blender 4.5 gives it).
pub fn find_in_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx.string("String")?;
    let search = ctx.string("Search")?;
    let (first, count) = if s.is_empty() || search.is_empty() {
        (0, 0)
    } else {
        let first = match s.find(&search) {
            Some(byte) => chars(&s[..byte]),
            None => 0,
        };
        (first, s.matches(search.as_str()).count() as i32)
    };
    Ok(outputs([
        ("First Found", SocketValue::int(first)),
        ("Count", SocketValue::int(count)),
    ]))
}

/// Match String: Starts With, Ends With or Contains the Key.
pub fn match_string(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = ctx.string("String")?;
    let key = ctx.string("Key")?;
    let op = match ctx.prop("operation").and_then(|v| v.as_str()) {
        Some(op) => op.to_string(),
        None => match ctx.input("Operation")? {
            SocketValue::Menu(m) => m,
            other => {
                return Err(ctx.err(format!(
                    "input \"Operation\" is a {}, expected a menu item",
                    other.kind()
                )))
            }
        },
    };
    let r = match op.as_str() {
        "STARTS_WITH" => s.starts_with(&key),
        "ENDS_WITH" => s.ends_with(&key),
        "CONTAINS" => s.contains(&key),
        other => return Err(ctx.err(format!("operation {other:?} is not supported"))),
    };
    Ok(outputs([(
        "Result",
        SocketValue::Field(Field::Constant(Value::Bool(r))),
    )]))
}

/// Compare on strings (Equal / Not Equal; the node offers no other operation for
/// strings): byte equality.
pub fn compare_strings(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let a = ctx.string("A_STR")?;
    let b = ctx.string("B_STR")?;
    let op = ctx.prop_str("operation")?;
    let r = match op {
        "EQUAL" => a == b,
        "NOT_EQUAL" => a != b,
        other => {
            return Err(ctx.err(format!(
                "operation {other} is not valid for strings (Equal, Not Equal)"
            )))
        }
    };
    Ok(outputs([(
        "Result",
        SocketValue::Field(Field::Constant(Value::Bool(r))),
    )]))
}
