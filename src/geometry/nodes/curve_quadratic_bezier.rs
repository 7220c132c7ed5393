//! Quadratic Bézier (`node_geo_curve_primitive_quadratic_bezier`): one poly curve of
//! Resolution + 1 points (Resolution at least 3) on the parabola through Start, Middle
//! and End, by de Casteljau's two lerps at factors i / Resolution.

use super::super::curves::CURVE_TYPE_POLY;
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::math::V3;
use super::curve_primitives::{out, single};

/// BLI's `math::interpolate`: a * (1 - t) + b * t.
fn interpolate(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

pub fn quadratic_bezier(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let resolution = ctx.int("Resolution")?.max(3);
    let (p1, p2, p3) = (
        ctx.vector("Start")?,
        ctx.vector("Middle")?,
        ctx.vector("End")?,
    );
    let step = 1.0 / resolution as f32;
    let positions = (0..=resolution)
        .map(|i| {
            let t = step * i as f32;
            interpolate(interpolate(p1, p2, t), interpolate(p2, p3, t), t)
        })
        .collect();
    Ok(out(single(positions, CURVE_TYPE_POLY, false)))
}
