//! Arc (`node_geo_curve_primitive_arc`): a poly curve on a circle, from a radius and
//! angles or through three points (then also the circle's centre, normal and radius).

use std::f32::consts::PI;
use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curves::{Curves, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{add, cross, dot, length, normalize, scale, sub, V3};
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain, Value};
use super::super::value::SocketValue;

fn poly(positions: Vec<V3>, cyclic: bool) -> GeometrySet {
    let n = positions.len() as u32;
    let mut c = Curves {
        positions,
        curve_offsets: vec![0, n],
        ..Default::default()
    };
    c.attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY]),
    );
    if cyclic {
        c.attributes.set(
            AttrId::named("cyclic"),
            Domain::Curve,
            Array::Bool(vec![true]),
        );
    }
    GeometrySet {
        curves: Some(Arc::new(c)),
        ..Default::default()
    }
}

fn lerp(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

fn mid(a: V3, b: V3) -> V3 {
    scale(add(a, b), 0.5)
}

/// Rotation of `v` about the unit `axis` by `angle` (right hand), as Blender's
/// axis_angle_normalized_to_mat3 applied to a vector.
fn rotate(v: V3, axis: V3, angle: f32) -> V3 {
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = axis;
    let m = [
        [c + t * x * x, t * x * y + s * z, t * x * z - s * y],
        [t * x * y - s * z, c + t * y * y, t * y * z + s * x],
        [t * x * z + s * y, t * y * z - s * x, c + t * z * z],
    ];
    // Column-major as BLI: result = m[0] * v.x + m[1] * v.y + m[2] * v.z.
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

/// Blender's angle_signed_on_axis_v3v3_v3 (unit `axis`): the angle between the projected
/// vectors, taken the long way round when `b x a` points against the axis.
fn angle_signed_on_axis(a: V3, b: V3, axis: V3) -> f32 {
    let project = |v: V3| sub(v, scale(axis, dot(v, axis)));
    let (pa, pb) = (project(a), project(b));
    let angle = angle_normalized(normalize(pa), normalize(pb));
    if dot(cross(pb, pa), axis) < 0.0 {
        2.0 * PI - angle
    } else {
        angle
    }
}

/// Blender's angle_normalized_v3v3: accurate for small and near-opposite angles.
fn angle_normalized(a: V3, b: V3) -> f32 {
    if dot(a, b) >= 0.0 {
        2.0 * (length(sub(b, a)) / 2.0).clamp(-1.0, 1.0).asin()
    } else {
        PI - 2.0 * (length(add(a, b)) / 2.0).clamp(-1.0, 1.0).asin()
    }
}

/// The intersection point of three planes given by point and normal, if they meet in one.
fn three_planes(p: [(V3, V3); 3]) -> Option<V3> {
    let d = |(pt, n): (V3, V3)| -dot(n, pt);
    let (n1, n2, n3) = (p[0].1, p[1].1, p[2].1);
    let det = dot(n1, cross(n2, n3));
    if det == 0.0 {
        return None;
    }
    let (d1, d2, d3) = (d(p[0]), d(p[1]), d(p[2]));
    let v = add(
        add(scale(cross(n2, n3), -d1), scale(cross(n3, n1), -d2)),
        scale(cross(n1, n2), -d3),
    );
    Some(scale(v, 1.0 / det))
}

fn normal_tri(a: V3, b: V3, c: V3) -> V3 {
    normalize(cross(sub(a, b), sub(b, c)))
}

pub fn arc(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let res = ctx.int("Resolution")?.max(2) as usize;
    let connect = ctx.bool("Connect Center")?;
    let invert = ctx.bool("Invert Arc")?;
    let steps = (res - 1) as f32;
    match ctx.prop_str("mode")? {
        "RADIUS" => {
            let r = ctx.float("Radius")?;
            let start = ctx.float("Start Angle")?;
            let sweep = ctx.float("Sweep Angle")?;
            let sweep = if invert { -(2.0 * PI - sweep) } else { sweep };
            let step = sweep / steps;
            let mut p: Vec<V3> = (0..res)
                .map(|i| {
                    let t = step * i as f32 + start;
                    [r * t.cos(), r * t.sin(), 0.0]
                })
                .collect();
            if connect {
                p.push([0.0; 3]);
            }
            Ok(outputs([(
                "Curve",
                SocketValue::Geometry(poly(p, connect)),
            )]))
        }
        "POINTS" => {
            let a = ctx.vector("Start")?;
            let b = ctx.vector("Middle")?;
            let c = ctx.vector("End")?;
            let offset = ctx.float("Offset Angle")?;
            let (curve, center, normal, radius) = arc_from_points(res, a, b, c, offset, invert);
            let curve = curve.map(|mut p| {
                if connect {
                    p.push(center);
                }
                poly(p, connect)
            });
            let mut normal = normal;
            if normal[2] < 0.0 {
                normal = scale(normal, -1.0);
            }
            let v = |x: V3| SocketValue::Field(Field::Constant(Value::Vector(x)));
            Ok(outputs([
                ("Curve", SocketValue::Geometry(curve.unwrap_or_default())),
                ("Center", v(center)),
                ("Normal", v(normal)),
                ("Radius", SocketValue::float(radius)),
            ]))
        }
        other => Err(ctx.err(format!("mode {other:?} is not supported"))),
    }
}

/// The arc's points (None: no circle through them), centre, normal (not yet turned to +Z)
/// and radius.
fn arc_from_points(
    res: usize,
    a: V3,
    b: V3,
    c: V3,
    offset: f32,
    invert: bool,
) -> (Option<Vec<V3>>, V3, V3, f32) {
    let steps = (res - 1) as f32;
    let na = normalize(sub(b, a));
    let nb = normalize(sub(c, a));
    let colinear = na == nb || na == scale(nb, -1.0);
    let mid_ac = mid(a, c);
    let normal = normal_tri(a, c, b);
    if colinear || a == c || a == b || b == c || res == 2 {
        let dist2 = |x: V3, y: V3| dot(sub(x, y), sub(x, y));
        let (ab, ac, bc) = (dist2(a, b), dist2(a, c), dist2(b, c));
        let (p1, p2) = if ab > ac && ab > bc {
            (a, b)
        } else if bc > ab && bc > ac {
            (b, c)
        } else {
            (a, c)
        };
        let step = 1.0 / steps;
        let p = (0..res).map(|i| lerp(p1, p2, step * i as f32)).collect();
        return (Some(p), mid_ac, normal, 0.0);
    }
    let mid_ab = mid(a, b);
    let mid_bc = mid(c, b);
    let nba = normalize(sub(b, a));
    let ncb = normalize(sub(c, b));
    let nabc = normalize(cross(nba, ncb));
    let Some(center) = three_planes([(mid_ab, nabc), (mid_ab, nba), (mid_bc, ncb)]) else {
        return (None, mid_ac, normal, 0.0);
    };
    let rad_a = normalize(sub(a, center));
    let rad_b = normalize(sub(b, center));
    let rad_c = normalize(sub(c, center));
    let radius = length(sub(center, b));
    let angle_ab = angle_signed_on_axis(rad_a, rad_b, normal) + 2.0 * PI;
    let angle_ac = angle_signed_on_axis(rad_a, rad_c, normal) + 2.0 * PI;
    let mut angle = if angle_ac > angle_ab {
        angle_ac
    } else {
        angle_ab
    };
    angle -= 2.0 * PI;
    if invert {
        angle = -(2.0 * PI - angle);
    }
    let step = angle / steps;
    let neg = scale(normal, -1.0);
    let p = (0..res)
        .map(|i| {
            add(
                scale(rotate(rad_a, neg, step * i as f32 + offset), radius),
                center,
            )
        })
        .collect();
    (Some(p), center, normal, radius)
}
