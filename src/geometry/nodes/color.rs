//! Colour and vector utility nodes as fields: Color Ramp, RGB/Vector Curves, Separate/
//! Combine Color, Mix (colour) and MixRGB, Vector Rotate, Rotate Vector, Float to
//! Integer, Blackbody.
//!
//! Geometry Nodes evaluate these with Blender's own code rather than Cycles': the ramp is
//! `BKE_colorband_evaluate` on the stops (no 257-entry table), curves are
//! `BKE_curvemap_evaluateF` on each curve, HSV/HSL are BLI's conversions. The shared
//! maths comes from `crate::nodes`; the choice of flavour is made here.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{quat_to_mat4, transform_direction};
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use crate::nodes::blackbody::blackbody;
use crate::nodes::color::bli;
use crate::nodes::curves::{mapping_from_json, BlenderCurve};
use crate::nodes::mix::{mix_color, MixBlend};
use crate::nodes::ramp::band_from_json;
use crate::nodes::sepcomb::ColorMode;
use crate::nodes::vector_rotate::{vector_rotate, VectorRotateType};

fn f(x: Field) -> SocketValue {
    SocketValue::Field(x)
}

fn opt(ctx: &NodeCtx, id: &str, ty: DataType) -> Result<Field, GeometryError> {
    if ctx.has_input(id) {
        ctx.field(id, ty)
    } else {
        Ok(Field::Constant(Value::zero(ty)))
    }
}

fn mode<T>(ctx: &NodeCtx, key: &str, parse: fn(&str) -> Option<T>) -> Result<T, GeometryError> {
    let s = ctx.prop_str(key)?;
    parse(s).ok_or_else(|| ctx.err(format!("{key} {s:?} is not supported")))
}

fn op1(
    ctx: &NodeCtx,
    label: &str,
    ins: Vec<Field>,
    out: DataType,
    func: impl Fn(usize, &[Array]) -> Result<Array, String> + Send + Sync + 'static,
) -> Result<Field, GeometryError> {
    Field::op1(label, ins, out, func).map_err(|e| ctx.err(e))
}

/// Color Ramp: `BKE_colorband_evaluate` of Fac (a vector or colour Fac converts
/// implicitly, as for any float socket).
pub fn color_ramp(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx
        .prop("color_ramp")
        .ok_or_else(|| ctx.err("property \"color_ramp\" missing"))?;
    let band = band_from_json(r).map_err(|e| ctx.err(e))?;
    let outs = Field::op(
        "Color Ramp",
        vec![ctx.field("Fac", DataType::Float)?],
        vec![DataType::Color, DataType::Float],
        move |n, x| {
            let fac = x[0].as_float();
            let (mut col, mut alpha) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for &t in fac.iter() {
                let c = band.evaluate(t);
                col.push(c);
                alpha.push(c[3]);
            }
            Ok(vec![Array::Color(col), Array::Float(alpha)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Color", f(it.next().unwrap())),
        ("Alpha", f(it.next().unwrap())),
    ]))
}

/// `interp_v3_v3v3(out, in, out, fac)` when fac is not 1.
fn blend_in(fac: f32, input: f32, curve: f32) -> f32 {
    if fac != 1.0 {
        (1.0 - fac) * input + fac * curve
    } else {
        curve
    }
}

/// RGB Curves: the combined curve then each channel's (`BKE_curvemapping_evaluateRGBF`,
/// no clipping), mixed with the input by Fac; the output's alpha is 1.
pub fn rgb_curves(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = mapping_from_json(
        ctx.prop("mapping")
            .ok_or_else(|| ctx.err("property \"mapping\" missing"))?,
    )
    .map_err(|e| ctx.err(e.0))?;
    let curves: Vec<BlenderCurve> = (0..4)
        .map(|k| BlenderCurve::new(&m, k))
        .collect::<Result<_, _>>()
        .map_err(|e| ctx.err(e.0))?;
    let ins = vec![
        ctx.field("Fac", DataType::Float)?,
        ctx.field("Color", DataType::Color)?,
    ];
    let out = op1(ctx, "RGB Curves", ins, DataType::Color, move |n, x| {
        let (fac, col) = (x[0].as_float(), x[1].as_color());
        Ok(Array::Color(
            (0..n)
                .map(|i| {
                    let c = col[i];
                    let ch = |k: usize| {
                        blend_in(
                            fac[i],
                            c[k],
                            curves[k].eval_unclipped(curves[3].eval_unclipped(c[k])),
                        )
                    };
                    [ch(0), ch(1), ch(2), 1.0]
                })
                .collect(),
        ))
    })?;
    Ok(outputs([("Color", f(out))]))
}

/// Vector Curves: each component through its curve (`BKE_curvemapping_evaluate3F`: no
/// clipping, unlike Float Curve), mixed with the input by Fac.
pub fn vector_curves(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = mapping_from_json(
        ctx.prop("mapping")
            .ok_or_else(|| ctx.err("property \"mapping\" missing"))?,
    )
    .map_err(|e| ctx.err(e.0))?;
    let curves: Vec<BlenderCurve> = (0..3)
        .map(|k| BlenderCurve::new(&m, k))
        .collect::<Result<_, _>>()
        .map_err(|e| ctx.err(e.0))?;
    let ins = vec![
        ctx.field("Fac", DataType::Float)?,
        ctx.field("Vector", DataType::Vector)?,
    ];
    let out = op1(ctx, "Vector Curves", ins, DataType::Vector, move |n, x| {
        let (fac, v) = (x[0].as_float(), x[1].as_vector());
        Ok(Array::Vector(
            (0..n)
                .map(|i| {
                    std::array::from_fn(|k| {
                        blend_in(fac[i], v[i][k], curves[k].eval_unclipped(v[i][k]))
                    })
                })
                .collect(),
        ))
    })?;
    Ok(outputs([("Vector", f(out))]))
}

/// Separate Color (Geometry Nodes' function node): RGB, or BLI's HSV/HSL; alpha as is.
pub fn separate_color(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let cm = mode(ctx, "mode", ColorMode::from_blender)?;
    let outs = Field::op(
        "Separate Color",
        vec![ctx.field("Color", DataType::Color)?],
        vec![DataType::Float; 4],
        move |n, x| {
            let c = x[0].as_color();
            let mut o: Vec<Vec<f32>> = (0..4).map(|_| Vec::with_capacity(n)).collect();
            for c in c.iter() {
                let rgb = [c[0], c[1], c[2]];
                let v = match cm {
                    ColorMode::Rgb => rgb,
                    ColorMode::Hsv => bli::rgb_to_hsv(rgb),
                    ColorMode::Hsl => bli::rgb_to_hsl(rgb),
                };
                for k in 0..3 {
                    o[k].push(v[k]);
                }
                o[3].push(c[3]);
            }
            Ok(o.into_iter().map(Array::Float).collect())
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = outs.into_iter();
    let mut next = || f(it.next().unwrap());
    Ok(outputs([
        ("Red", next()),
        ("Green", next()),
        ("Blue", next()),
        ("Alpha", next()),
    ]))
}

/// Combine Color (function node): RGB, or BLI's HSV/HSL to RGB; alpha as given.
pub fn combine_color(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let cm = mode(ctx, "mode", ColorMode::from_blender)?;
    let ins = ["Red", "Green", "Blue", "Alpha"]
        .iter()
        .map(|id| ctx.field(id, DataType::Float))
        .collect::<Result<Vec<_>, _>>()?;
    let out = op1(ctx, "Combine Color", ins, DataType::Color, move |n, x| {
        let a: Vec<_> = x.iter().map(|a| a.as_float()).collect();
        Ok(Array::Color(
            (0..n)
                .map(|i| {
                    let v = [a[0][i], a[1][i], a[2][i]];
                    let rgb = match cm {
                        ColorMode::Rgb => v,
                        ColorMode::Hsv => bli::hsv_to_rgb(v),
                        ColorMode::Hsl => bli::hsl_to_rgb(v),
                    };
                    [rgb[0], rgb[1], rgb[2], a[3][i]]
                })
                .collect(),
        ))
    })?;
    Ok(outputs([("Color", f(out))]))
}

/// A colour blend of `a` and `b` (alpha from `a`).
fn blend_field(
    ctx: &NodeCtx,
    label: &str,
    ins: Vec<Field>,
    blend: MixBlend,
    clamp_factor: bool,
    clamp_result: bool,
) -> Result<Field, GeometryError> {
    op1(ctx, label, ins, DataType::Color, move |n, x| {
        let (t, a, b) = (x[0].as_float(), x[1].as_color(), x[2].as_color());
        Ok(Array::Color(
            (0..n)
                .map(|i| {
                    let r = mix_color(
                        blend,
                        clamp_factor,
                        clamp_result,
                        t[i],
                        [a[i][0], a[i][1], a[i][2]],
                        [b[i][0], b[i][1], b[i][2]],
                    );
                    [r[0], r[1], r[2], a[i][3]]
                })
                .collect(),
        ))
    })
}

/// Mix with the colour data type (the float and vector types are `function::mix`).
pub fn mix_rgba(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let blend = mode(ctx, "blend_type", MixBlend::from_blender)?;
    let clamp_factor = ctx.prop_bool("clamp_factor").unwrap_or(true);
    let clamp_result = ctx.prop_bool("clamp_result").unwrap_or(false);
    let ins = vec![
        ctx.field("Factor_Float", DataType::Float)?,
        ctx.field("A_Color", DataType::Color)?,
        ctx.field("B_Color", DataType::Color)?,
    ];
    Ok(outputs([(
        "Result_Color",
        f(blend_field(
            ctx,
            "Mix",
            ins,
            blend,
            clamp_factor,
            clamp_result,
        )?),
    )]))
}

/// Legacy MixRGB: the factor always clamped, "Clamp" clamps the result.
pub fn mix_rgb(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let blend = mode(ctx, "blend_type", MixBlend::from_blender)?;
    let clamp = ctx.prop_bool("use_clamp").unwrap_or(false);
    let ins = vec![
        ctx.field("Fac", DataType::Float)?,
        ctx.field("Color1", DataType::Color)?,
        ctx.field("Color2", DataType::Color)?,
    ];
    Ok(outputs([(
        "Color",
        f(blend_field(ctx, "MixRGB", ins, blend, true, clamp)?),
    )]))
}

pub fn vector_rotate_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let kind = mode(ctx, "rotation_type", VectorRotateType::from_blender)?;
    let invert = ctx.prop_bool("invert").unwrap_or(false);
    let ins = vec![
        ctx.field("Vector", DataType::Vector)?,
        ctx.field("Center", DataType::Vector)?,
        opt(ctx, "Axis", DataType::Vector)?,
        opt(ctx, "Angle", DataType::Float)?,
        opt(ctx, "Rotation", DataType::Vector)?,
    ];
    let out = op1(ctx, "Vector Rotate", ins, DataType::Vector, move |n, x| {
        let (v, c, ax, an, r) = (
            x[0].as_vector(),
            x[1].as_vector(),
            x[2].as_vector(),
            x[3].as_float(),
            x[4].as_vector(),
        );
        Ok(Array::Vector(
            (0..n)
                .map(|i| vector_rotate(kind, invert, v[i], c[i], ax[i], an[i], r[i]))
                .collect(),
        ))
    })?;
    Ok(outputs([("Vector", f(out))]))
}

/// Rotate Vector: the vector turned by the rotation (a quaternion).
pub fn rotate_vector(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ins = vec![
        ctx.field("Vector", DataType::Vector)?,
        ctx.field("Rotation", DataType::Quaternion)?,
    ];
    let out = op1(ctx, "Rotate Vector", ins, DataType::Vector, |n, x| {
        let (v, q) = (x[0].as_vector(), x[1].as_quat());
        Ok(Array::Vector(
            (0..n)
                .map(|i| transform_direction(&quat_to_mat4(q[i]), v[i]))
                .collect(),
        ))
    })?;
    Ok(outputs([("Vector", f(out))]))
}

/// Float to Integer: C's `round` (halves away from zero), `floor`, `ceil`, `trunc`.
pub fn float_to_int(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx.prop_str("rounding_mode")?;
    let round: fn(f32) -> f32 = match m {
        "ROUND" => f32::round,
        "FLOOR" => f32::floor,
        "CEILING" => f32::ceil,
        "TRUNCATE" => f32::trunc,
        other => return Err(ctx.err(format!("rounding_mode {other:?} is not supported"))),
    };
    let out = op1(
        ctx,
        "Float to Integer",
        vec![ctx.field("Float", DataType::Float)?],
        DataType::Int,
        move |_, x| {
            Ok(Array::Int(
                x[0].as_float().iter().map(|v| round(*v) as i32).collect(),
            ))
        },
    )?;
    Ok(outputs([("Integer", f(out))]))
}

/// Blackbody: the Rec.709 fit with negatives clamped, alpha 1.
pub fn blackbody_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let out = op1(
        ctx,
        "Blackbody",
        vec![ctx.field("Temperature", DataType::Float)?],
        DataType::Color,
        |_, x| {
            Ok(Array::Color(
                x[0].as_float()
                    .iter()
                    .map(|t| {
                        let c = blackbody(*t);
                        [c[0], c[1], c[2], 1.0]
                    })
                    .collect(),
            ))
        },
    )?;
    Ok(outputs([("Color", f(out))]))
}
