//! Texture nodes as fields (Voronoi, White Noise, Gradient, Wave, Magic, Checker, Brick):
//! the shared texture functions of `crate::nodes`, evaluated per element. An unlinked
//! Vector is the Position field (the evaluator's `implicit_field`), and colour outputs
//! have alpha 1, as Blender's multi-functions write them.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use crate::nodes::brick::{brick_texture, BrickSettings};
use crate::nodes::checker::checker_texture;
use crate::nodes::gradient::{gradient_unclamped, GradientType};
use crate::nodes::magic::magic;
use crate::nodes::voronoi::{voronoi_texture, VoronoiFeature, VoronoiMetric, VoronoiParams};
use crate::nodes::wave::{
    wave, BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType,
};
use crate::nodes::white_noise::white_noise;

fn f(x: Field) -> SocketValue {
    SocketValue::Field(x)
}

fn rgba(c: [f32; 3]) -> [f32; 4] {
    [c[0], c[1], c[2], 1.0]
}

/// Input `id` as a field of `ty`, or the type's zero when the node's mode hides it.
fn opt(ctx: &NodeCtx, id: &str, ty: DataType) -> Result<Field, GeometryError> {
    if ctx.has_input(id) {
        ctx.field(id, ty)
    } else {
        Ok(Field::Constant(Value::zero(ty)))
    }
}

/// The floats inputs `ids` (hidden ones zero).
fn floats(ctx: &NodeCtx, ids: &[&str]) -> Result<Vec<Field>, GeometryError> {
    ids.iter().map(|id| opt(ctx, id, DataType::Float)).collect()
}

/// An enum property parsed with `parse`, or an error naming the property and value.
fn mode<T>(ctx: &NodeCtx, key: &str, parse: fn(&str) -> Option<T>) -> Result<T, GeometryError> {
    let s = ctx.prop_str(key)?;
    parse(s).ok_or_else(|| ctx.err(format!("{key} {s:?} is not supported")))
}

fn dimensions(ctx: &NodeCtx, key: &str) -> Result<u8, GeometryError> {
    match ctx.prop_str(key)? {
        "1D" => Ok(1),
        "2D" => Ok(2),
        "3D" => Ok(3),
        "4D" => Ok(4),
        d => Err(ctx.err(format!("{key} {d:?} is not supported"))),
    }
}

fn int_prop(ctx: &NodeCtx, key: &str) -> Result<i32, GeometryError> {
    ctx.prop(key)
        .and_then(|v| v.as_i64())
        .map(|v| v as i32)
        .ok_or_else(|| ctx.err(format!("property {key:?} missing")))
}

fn float_prop(ctx: &NodeCtx, key: &str) -> Result<f32, GeometryError> {
    ctx.prop(key)
        .and_then(|v| v.as_f64())
        .map(|v| v as f32)
        .ok_or_else(|| ctx.err(format!("property {key:?} missing")))
}

/// Builds a multi-output field op; `e` names the node in errors.
fn op(
    ctx: &NodeCtx,
    label: &str,
    ins: Vec<Field>,
    outs: Vec<DataType>,
    func: impl Fn(usize, &[Array]) -> Result<Vec<Array>, String> + Send + Sync + 'static,
) -> Result<Vec<Field>, GeometryError> {
    Field::op(label, ins, outs, func).map_err(|e| ctx.err(e))
}

pub fn voronoi(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dims = dimensions(ctx, "voronoi_dimensions")?;
    let feature = mode(ctx, "feature", VoronoiFeature::from_blender)?;
    let metric = mode(ctx, "distance", VoronoiMetric::from_blender)?;
    let normalize = ctx.prop_bool("normalize").unwrap_or(false);
    let mut ins = vec![opt(ctx, "Vector", DataType::Vector)?];
    ins.extend(floats(
        ctx,
        &[
            "W",
            "Scale",
            "Detail",
            "Roughness",
            "Lacunarity",
            "Smoothness",
            "Exponent",
            "Randomness",
        ],
    )?);
    let types = vec![
        DataType::Float,
        DataType::Color,
        DataType::Vector,
        DataType::Float,
        DataType::Float,
    ];
    let outs = op(ctx, "Voronoi Texture", ins, types, move |n, x| {
        let v = x[0].as_vector();
        let s: Vec<_> = x[1..].iter().map(|a| a.as_float()).collect();
        let (mut dist, mut col, mut pos, mut w, mut rad) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for i in 0..n {
            let p = VoronoiParams::new(
                feature, metric, normalize, s[1][i], s[2][i], s[3][i], s[4][i], s[5][i], s[6][i],
                s[7][i],
            );
            let o = voronoi_texture(dims, v[i], s[0][i], p);
            dist.push(o.distance);
            col.push(rgba(o.color));
            pos.push(o.position);
            w.push(o.w);
            rad.push(o.radius);
        }
        Ok(vec![
            Array::Float(dist),
            Array::Color(col),
            Array::Vector(pos),
            Array::Float(w),
            Array::Float(rad),
        ])
    })?;
    let mut it = outs.into_iter();
    let mut next = || f(it.next().unwrap());
    Ok(outputs([
        ("Distance", next()),
        ("Color", next()),
        ("Position", next()),
        ("W", next()),
        ("Radius", next()),
    ]))
}

pub fn white_noise_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let dims = dimensions(ctx, "noise_dimensions")?;
    let ins = vec![
        opt(ctx, "Vector", DataType::Vector)?,
        opt(ctx, "W", DataType::Float)?,
    ];
    let outs = op(
        ctx,
        "White Noise Texture",
        ins,
        vec![DataType::Float, DataType::Color],
        move |n, x| {
            let (v, w) = (x[0].as_vector(), x[1].as_float());
            let (mut val, mut col) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for i in 0..n {
                let (a, c) = white_noise(dims, v[i], w[i]);
                val.push(a);
                col.push(rgba(c));
            }
            Ok(vec![Array::Float(val), Array::Color(col)])
        },
    )?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Value", f(it.next().unwrap())),
        ("Color", f(it.next().unwrap())),
    ]))
}

/// (Fac, Color) outputs from a per-element function of the inputs.
fn fac_color(
    ctx: &NodeCtx,
    label: &str,
    ins: Vec<Field>,
    func: impl Fn(&[Array], usize) -> ([f32; 3], f32) + Send + Sync + 'static,
) -> Result<Outputs, GeometryError> {
    let outs = op(
        ctx,
        label,
        ins,
        vec![DataType::Float, DataType::Color],
        move |n, x| {
            let (mut fac, mut col) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for i in 0..n {
                let (c, v) = func(x, i);
                fac.push(v);
                col.push(rgba(c));
            }
            Ok(vec![Array::Float(fac), Array::Color(col)])
        },
    )?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Fac", f(it.next().unwrap())),
        ("Color", f(it.next().unwrap())),
    ]))
}

pub fn gradient_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let kind = mode(ctx, "gradient_type", GradientType::from_blender)?;
    fac_color(
        ctx,
        "Gradient Texture",
        vec![opt(ctx, "Vector", DataType::Vector)?],
        move |x, i| {
            let v = gradient_unclamped(kind, x[0].get(i).as_vector());
            ([v; 3], v)
        },
    )
}

pub fn wave_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let settings = WaveSettings {
        kind: mode(ctx, "wave_type", WaveType::from_blender)?,
        bands: mode(ctx, "bands_direction", BandsDirection::from_blender)?,
        rings: mode(ctx, "rings_direction", RingsDirection::from_blender)?,
        profile: mode(ctx, "wave_profile", WaveProfile::from_blender)?,
    };
    let mut ins = vec![opt(ctx, "Vector", DataType::Vector)?];
    ins.extend(floats(
        ctx,
        &[
            "Scale",
            "Distortion",
            "Detail",
            "Detail Scale",
            "Detail Roughness",
            "Phase Offset",
        ],
    )?);
    fac_color(ctx, "Wave Texture", ins, move |x, i| {
        let a = |k: usize| x[k].get(i).as_float();
        let v = wave(
            settings,
            x[0].get(i).as_vector(),
            a(1),
            a(2),
            a(3),
            a(4),
            a(5),
            a(6),
        );
        ([v; 3], v)
    })
}

pub fn magic_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let depth = int_prop(ctx, "turbulence_depth")?;
    let ins = vec![
        opt(ctx, "Vector", DataType::Vector)?,
        opt(ctx, "Scale", DataType::Float)?,
        opt(ctx, "Distortion", DataType::Float)?,
    ];
    fac_color(ctx, "Magic Texture", ins, move |x, i| {
        magic(
            x[0].get(i).as_vector(),
            x[1].get(i).as_float(),
            depth,
            x[2].get(i).as_float(),
        )
    })
}

pub fn checker_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ins = vec![
        opt(ctx, "Vector", DataType::Vector)?,
        opt(ctx, "Color1", DataType::Color)?,
        opt(ctx, "Color2", DataType::Color)?,
        opt(ctx, "Scale", DataType::Float)?,
    ];
    let outs = op(
        ctx,
        "Checker Texture",
        ins,
        vec![DataType::Float, DataType::Color],
        |n, x| {
            let (v, c1, c2, s) = (
                x[0].as_vector(),
                x[1].as_color(),
                x[2].as_color(),
                x[3].as_float(),
            );
            let (mut fac, mut col) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for i in 0..n {
                // The chosen colour keeps its own alpha.
                let (_, v) = checker_texture(v[i], [0.0; 3], [0.0; 3], s[i]);
                fac.push(v);
                col.push(if v == 1.0 { c1[i] } else { c2[i] });
            }
            Ok(vec![Array::Float(fac), Array::Color(col)])
        },
    )?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Fac", f(it.next().unwrap())),
        ("Color", f(it.next().unwrap())),
    ]))
}

pub fn brick_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let settings = BrickSettings {
        offset: float_prop(ctx, "offset")?,
        offset_frequency: int_prop(ctx, "offset_frequency")?,
        squash: float_prop(ctx, "squash")?,
        squash_frequency: int_prop(ctx, "squash_frequency")?,
    };
    let mut ins = vec![
        opt(ctx, "Vector", DataType::Vector)?,
        opt(ctx, "Color1", DataType::Color)?,
        opt(ctx, "Color2", DataType::Color)?,
        opt(ctx, "Mortar", DataType::Color)?,
    ];
    ins.extend(floats(
        ctx,
        &[
            "Scale",
            "Mortar Size",
            "Mortar Smooth",
            "Bias",
            "Brick Width",
            "Row Height",
        ],
    )?);
    fac_color(ctx, "Brick Texture", ins, move |x, i| {
        let c = |k: usize| {
            let c = x[k].get(i).as_color();
            [c[0], c[1], c[2]]
        };
        let a = |k: usize| x[k].get(i).as_float();
        let (col, fac) = brick_texture(
            x[0].get(i).as_vector(),
            c(1),
            c(2),
            c(3),
            a(4),
            a(5),
            a(6),
            a(7),
            a(8),
            a(9),
            settings,
        );
        (col, fac)
    })
}
