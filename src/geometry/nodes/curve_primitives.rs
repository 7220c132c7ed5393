//! Curve primitives (`node_geo_curve_primitive_*`): Line, Circle, Bezier Segment, Spiral,
//! Quadrilateral, Star, each a single curve with Blender's point order.

use std::f64::consts::PI;
use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curves::{Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_POLY, HANDLE_ALIGN};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::math::{add, normalize, scale, sub, V3};
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::geometry_ops::geo;

pub(super) fn single(positions: Vec<V3>, kind: i8, cyclic: bool) -> Curves {
    let n = positions.len() as u32;
    let mut c = Curves {
        positions,
        curve_offsets: vec![0, n],
        ..Default::default()
    };
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![kind]),
    );
    if cyclic {
        c.attributes.set(
            AttrId::named("cyclic"),
            Domain::Curve,
            Array::Bool(vec![true]),
        );
    }
    c
}

pub(super) fn out(c: Curves) -> Outputs {
    outputs([(
        "Curve",
        geo(GeometrySet {
            curves: Some(Arc::new(c)),
            ..Default::default()
        }),
    )])
}

fn not_used(ctx: &NodeCtx, output: &str) -> Result<(), GeometryError> {
    if ctx.output_used(output) {
        return Err(ctx.err(format!("the {output:?} output is not supported yet")));
    }
    Ok(())
}

pub fn line(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let start = ctx.vector("Start")?;
    let end = match ctx.prop_str("mode")? {
        "DIRECTION" => add(
            start,
            scale(normalize(ctx.vector("Direction")?), ctx.float("Length")?),
        ),
        _ => ctx.vector("End")?,
    };
    Ok(out(single(vec![start, end], CURVE_TYPE_POLY, false)))
}

pub fn circle(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    if ctx.prop_str("mode")? != "RADIUS" {
        return Err(ctx.err("the POINTS mode is not supported yet"));
    }
    not_used(ctx, "Center")?;
    let res = ctx.int("Resolution")?.max(3);
    let r = ctx.float("Radius")?;
    let step = ((2.0 * PI) / res as f64) as f32;
    let p = (0..res)
        .map(|i| {
            let t = step * i as f32;
            [r * t.cos(), r * t.sin(), 0.0]
        })
        .collect();
    Ok(out(single(p, CURVE_TYPE_POLY, true)))
}

pub fn star(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    not_used(ctx, "Outer Points")?;
    let points = ctx.int("Points")?.max(3);
    let (inner, outer, twist) = (
        ctx.float("Inner Radius")?,
        ctx.float("Outer Radius")?,
        ctx.float("Twist")?,
    );
    let step = ((2.0 * PI) / points as f64) as f32;
    let mut p = Vec::with_capacity(2 * points as usize);
    for i in 0..points {
        let t = i as f32 * step;
        p.push([outer * t.cos(), outer * t.sin(), 0.0]);
        let ti = t + step * 0.5 + twist;
        p.push([inner * ti.cos(), inner * ti.sin(), 0.0]);
    }
    Ok(out(single(p, CURVE_TYPE_POLY, true)))
}

pub fn spiral(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let res = ctx.int("Resolution")?;
    let rotations = ctx.float("Rotations")?;
    let (r0, r1, height) = (
        ctx.float("Start Radius")?,
        ctx.float("End Radius")?,
        ctx.float("Height")?,
    );
    let reverse = ctx.bool("Reverse")?;
    let total = ((res as f32 * rotations) as i32).max(1);
    let dr = (r1 - r0) / total as f32;
    let dh = height / total as f32;
    let dt =
        ((PI * 2.0 * rotations as f64) as f32) / total as f32 * if reverse { 1.0 } else { -1.0 };
    let p = (0..=total)
        .map(|i| {
            let t = i as f32 * dt;
            let r = r0 + i as f32 * dr;
            [r * t.cos(), r * t.sin(), dh * i as f32]
        })
        .collect();
    Ok(out(single(p, CURVE_TYPE_POLY, false)))
}

pub fn quadrilateral(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let p = match ctx.prop_str("mode")? {
        "RECTANGLE" => {
            let (w, h) = (ctx.float("Width")?, ctx.float("Height")?);
            vec![
                [w / 2.0, h / 2.0, 0.0],
                [-w / 2.0, h / 2.0, 0.0],
                [-w / 2.0, -h / 2.0, 0.0],
                [w / 2.0, -h / 2.0, 0.0],
            ]
        }
        "POINTS" => vec![
            ctx.vector("Point 1")?,
            ctx.vector("Point 2")?,
            ctx.vector("Point 3")?,
            ctx.vector("Point 4")?,
        ],
        m => return Err(ctx.err(format!("mode {m} is not supported yet"))),
    };
    Ok(out(single(p, CURVE_TYPE_POLY, true)))
}

pub fn bezier_segment(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let res = ctx.int("Resolution")?.max(1);
    let (start, end) = (ctx.vector("Start")?, ctx.vector("End")?);
    let (sh, eh) = (ctx.vector("Start Handle")?, ctx.vector("End Handle")?);
    let (right0, left1) = if ctx.prop_str("mode")? == "OFFSET" {
        (add(start, sh), add(end, eh))
    } else {
        (sh, eh)
    };
    // The outer handles mirror the inner ones through the end points.
    let left0 = sub(scale(start, 2.0), right0);
    let right1 = sub(scale(end, 2.0), left1);
    let mut c = single(vec![start, end], CURVE_TYPE_BEZIER, false);
    c.attributes.set(
        AttrId::named("resolution"),
        Domain::Curve,
        Array::Int(vec![res]),
    );
    c.attributes.set(
        AttrId::named("handle_left"),
        Domain::Point,
        Array::Vector(vec![left0, left1]),
    );
    c.attributes.set(
        AttrId::named("handle_right"),
        Domain::Point,
        Array::Vector(vec![right0, right1]),
    );
    // Blender makes both handles Aligned (so Set Handle Type and Handle Type Selection see
    // a Bezier curve, and moved points keep their handles aligned).
    c.set_i8("handle_type_left", Domain::Point, vec![HANDLE_ALIGN; 2]);
    c.set_i8("handle_type_right", Domain::Point, vec![HANDLE_ALIGN; 2]);
    Ok(out(c))
}
