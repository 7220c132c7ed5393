//! Mesh modifiers blendsynth evaluates itself, one module per modifier, each following
//! Blender's `MOD_*.cc` (element order included, so the result equals Blender's
//! evaluated mesh index for index). `unsupported` names the options a module does not
//! evaluate: an object with such a modifier keeps Blender's evaluated mesh ("frozen").

use serde_json::{Map, Value as Json};

use super::math::Mat4f;
use super::set::GeometrySet;

pub mod array;
pub mod displace;
pub mod edge_split;
pub mod mirror;
pub mod screw;
pub mod smooth;
pub mod solidify;
pub mod triangulate;
pub mod weld;
pub mod wireframe;

pub type Props = Map<String, Json>;

/// Modifier types (`Modifier.kind`) with a module here.
pub const KINDS: &[&str] = &[
    "ARRAY",
    "MIRROR",
    "TRIANGULATE",
    "SMOOTH",
    "WELD",
    "DISPLACE",
    "SOLIDIFY",
    "EDGE_SPLIT",
    "WIREFRAME",
    "SCREW",
];

/// What a modifier may read besides its mesh: the object's name and objects' world
/// matrices (offset, mirror and axis objects).
pub struct Context<'a> {
    pub object: &'a str,
    pub world: &'a dyn Fn(&str) -> Option<Mat4f>,
}

/// The options of a `kind` modifier blendsynth does not evaluate, by name (None: all of
/// its settings are evaluated). Only meaningful for `KINDS`.
pub fn unsupported(kind: &str, p: &Props) -> Option<String> {
    match kind {
        "ARRAY" => array::unsupported(p),
        "MIRROR" => mirror::unsupported(p),
        "TRIANGULATE" => triangulate::unsupported(p),
        "SMOOTH" => smooth::unsupported(p),
        "WELD" => weld::unsupported(p),
        "DISPLACE" => displace::unsupported(p),
        "SOLIDIFY" => solidify::unsupported(p),
        "EDGE_SPLIT" => edge_split::unsupported(p),
        "WIREFRAME" => wireframe::unsupported(p),
        "SCREW" => screw::unsupported(p),
        _ => Some("not evaluated by blendsynth".into()),
    }
}

/// Applies a `kind` modifier to the set's mesh.
pub fn apply(kind: &str, p: &Props, ctx: &Context, g: GeometrySet) -> Result<GeometrySet, String> {
    if let Some(why) = unsupported(kind, p) {
        return Err(format!("{kind} options not evaluated: {why}"));
    }
    match kind {
        "ARRAY" => array::apply(p, ctx.object, ctx.world, g),
        "MIRROR" => mirror::apply(p, ctx, g),
        "TRIANGULATE" => triangulate::apply(p, g),
        "SMOOTH" => smooth::apply(p, g),
        "WELD" => weld::apply(p, g),
        "DISPLACE" => displace::apply(p, ctx, g),
        "SOLIDIFY" => solidify::apply(p, g),
        "EDGE_SPLIT" => edge_split::apply(p, g),
        "WIREFRAME" => wireframe::apply(p, g),
        "SCREW" => screw::apply(p, ctx, g),
        _ => unreachable!("unsupported() refuses other kinds"),
    }
}

pub(crate) fn flag(p: &Props, k: &str) -> bool {
    p.get(k).and_then(Json::as_bool).unwrap_or(false)
}

/// A boolean vector property (`use_axis`, ...), false where absent.
pub(crate) fn flags3(p: &Props, k: &str) -> [bool; 3] {
    let a = p.get(k).and_then(Json::as_array);
    let f = |i: usize| {
        a.and_then(|a| a.get(i))
            .and_then(Json::as_bool)
            .unwrap_or(false)
    };
    [f(0), f(1), f(2)]
}

pub(crate) fn vec3(p: &Props, k: &str) -> Result<[f32; 3], String> {
    let a = p
        .get(k)
        .and_then(Json::as_array)
        .ok_or_else(|| format!("property {k:?} missing"))?;
    let f = |i: usize| a.get(i).and_then(Json::as_f64).unwrap_or(0.0) as f32;
    Ok([f(0), f(1), f(2)])
}

pub(crate) fn float(p: &Props, k: &str) -> Result<f32, String> {
    p.get(k)
        .and_then(Json::as_f64)
        .map(|v| v as f32)
        .ok_or_else(|| format!("property {k:?} missing"))
}

pub(crate) fn int(p: &Props, k: &str) -> Result<i64, String> {
    p.get(k)
        .and_then(Json::as_i64)
        .ok_or_else(|| format!("property {k:?} missing"))
}

pub(crate) fn text<'a>(p: &'a Props, k: &str) -> Result<&'a str, String> {
    p.get(k)
        .and_then(Json::as_str)
        .ok_or_else(|| format!("property {k:?} missing"))
}

/// The name of an object (or other ID) property, None when unset.
pub(crate) fn id_name(p: &Props, k: &str) -> Option<String> {
    match p.get(k)? {
        Json::Object(o) => o.get("name").and_then(Json::as_str).map(str::to_string),
        Json::String(s) if !s.is_empty() => Some(s.clone()),
        _ => None,
    }
}
