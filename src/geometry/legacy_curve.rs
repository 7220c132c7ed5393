//! A curve object's data (the exported legacy `Curve`: Bezier, poly and NURBS splines) as
//! the curves geometry Blender's evaluated curve object carries
//! (`bke::curve_legacy_to_curves`): positions, Bezier handles and handle types, radius,
//! tilt, per-curve type, cyclic flag, resolution and normal mode from the twist mode.

use super::attribute::AttrId;
use super::curve_eval::{NORMAL_MODE_MINIMUM_TWIST, NORMAL_MODE_Z_UP};
use super::curves::{Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_NURBS, CURVE_TYPE_POLY};
use super::error::GeometryError;
use super::types::{Array, Domain};
use crate::scene::Curve;

fn handle_type(s: &str) -> i8 {
    match s {
        "AUTO" => 1,
        "VECTOR" => 2,
        "ALIGNED" => 3,
        _ => 0,
    }
}

fn f3(v: &[f64]) -> [f32; 3] {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}

pub fn to_curves(cu: &Curve) -> Result<Curves, GeometryError> {
    let here = format!("curves[{:?}]", cu.name);
    let mut c = Curves {
        curve_offsets: vec![0],
        ..Default::default()
    };
    let (mut types, mut cyclic, mut res) = (Vec::new(), Vec::new(), Vec::new());
    let (mut hl, mut hr, mut htl, mut htr) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut radius, mut tilt, mut weight, mut order) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut knots: Vec<i8> = Vec::new();
    let mut any_bezier = false;
    let mut any_nurbs = false;
    for (i, s) in cu.splines.iter().enumerate() {
        let t = match s.kind.as_str() {
            "BEZIER" => CURVE_TYPE_BEZIER,
            "POLY" => CURVE_TYPE_POLY,
            "NURBS" => CURVE_TYPE_NURBS,
            other => {
                return Err(GeometryError::new(format!(
                    "{here}.splines[{i}]: spline type {other} is not supported"
                )))
            }
        };
        if t == CURVE_TYPE_BEZIER {
            any_bezier = true;
            for p in &s.bezier_points {
                c.positions.push(f3(&p.co));
                hl.push(f3(&p.handle_left));
                hr.push(f3(&p.handle_right));
                htl.push(handle_type(&p.handle_left_type) as i32);
                htr.push(handle_type(&p.handle_right_type) as i32);
                radius.push(p.radius as f32);
                tilt.push(p.tilt as f32);
                weight.push(1.0f32);
            }
        } else {
            any_nurbs |= t == CURVE_TYPE_NURBS;
            for p in &s.points {
                let co = f3(&p.co);
                c.positions.push(co);
                hl.push(co);
                hr.push(co);
                htl.push(0);
                htr.push(0);
                radius.push(p.radius as f32);
                tilt.push(p.tilt as f32);
                weight.push(p.co.get(3).copied().unwrap_or(1.0) as f32);
            }
        }
        types.push(t as i32);
        cyclic.push(s.use_cyclic_u);
        res.push(s.resolution_u as i32);
        order.push(s.order_u as i32);
        // `knots_mode_from_legacy`: the endpoint and Bezier flags.
        knots.push(match (s.use_endpoint_u, s.use_bezier_u) {
            (false, false) => 0i8,
            (true, false) => 1,
            (false, true) => 2,
            (true, true) => 3,
        });
        c.curve_offsets.push(c.positions.len() as u32);
    }
    let twist = cu
        .properties
        .get("twist_mode")
        .and_then(|v| v.as_str())
        .unwrap_or("MINIMUM");
    let mode = if twist == "Z_UP" {
        NORMAL_MODE_Z_UP
    } else {
        NORMAL_MODE_MINIMUM_TWIST
    };
    let n = types.len();
    let a = &mut c.attributes;
    a.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(types.iter().map(|t| *t as i8).collect()),
    );
    a.set(AttrId::named("cyclic"), Domain::Curve, Array::Bool(cyclic));
    a.set(AttrId::named("resolution"), Domain::Curve, Array::Int(res));
    a.set(
        AttrId::named("normal_mode"),
        Domain::Curve,
        Array::Int8(vec![mode; n]),
    );
    a.set(AttrId::named("radius"), Domain::Point, Array::Float(radius));
    a.set(AttrId::named("tilt"), Domain::Point, Array::Float(tilt));
    if any_bezier {
        a.set(
            AttrId::named("handle_left"),
            Domain::Point,
            Array::Vector(hl),
        );
        a.set(
            AttrId::named("handle_right"),
            Domain::Point,
            Array::Vector(hr),
        );
        a.set(
            AttrId::named("handle_type_left"),
            Domain::Point,
            Array::Int8(htl.iter().map(|t| *t as i8).collect()),
        );
        a.set(
            AttrId::named("handle_type_right"),
            Domain::Point,
            Array::Int8(htr.iter().map(|t| *t as i8).collect()),
        );
    }
    if any_nurbs {
        a.set(
            AttrId::named("nurbs_weight"),
            Domain::Point,
            Array::Float(weight),
        );
        a.set(
            AttrId::named("nurbs_order"),
            Domain::Curve,
            Array::Int8(order.iter().map(|t| *t as i8).collect()),
        );
        a.set(
            AttrId::named("knots_mode"),
            Domain::Curve,
            Array::Int8(knots),
        );
    }
    c.materials = cu.materials.clone();
    Ok(c)
}
