//! Set Spline Type (`node_geo_curve_spline_type`, `geometry::convert_curves`). Converting
//! to Poly or Catmull-Rom keeps the control points as they are (Blender's trivial
//! conversion: a Bezier curve loses its handles, a NURBS curve its weights and knots);
//! to Bezier and NURBS as `set_curve_type.cc` converts. Bezier handle and NURBS
//! attributes are dropped once no curve of that type is left. NURBS to Bezier is refused
//! by name (it depends on the knots mode, which curve objects do not carry here yet).

use super::super::attribute::AttrId;
use super::super::bezier_handles::write_handles;
use super::super::curves::{
    Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_CATMULL_ROM, CURVE_TYPE_NURBS, CURVE_TYPE_POLY,
    HANDLE_ALIGN, HANDLE_VECTOR,
};
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::math::{add, scale, sub, V3};
use super::super::types::Array;
use super::super::types::{DataType, Domain};

/// Removes the built-ins of curve types no curve has any more
/// (`remove_attributes_based_on_types`).
pub fn remove_attributes_based_on_types(c: &mut Curves) {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let any = |t: i8| types.iter().any(|v| *v as i8 == t);
    let mut drop: Vec<&str> = Vec::new();
    if !any(CURVE_TYPE_BEZIER) {
        drop.extend([
            "handle_left",
            "handle_right",
            "handle_type_left",
            "handle_type_right",
        ]);
    }
    if !any(CURVE_TYPE_NURBS) {
        drop.extend(["nurbs_weight", "nurbs_order", "knots_mode"]);
    }
    c.attributes
        .0
        .retain(|a| !a.id.name().is_some_and(|n| drop.contains(&n)));
}

/// Blender's `KnotsMode` values as stored in `knots_mode`.
const KNOTS_NORMAL: i8 = 0;
const KNOTS_ENDPOINT: i8 = 1;
const KNOTS_BEZIER: i8 = 2;

/// A Catmull-Rom curve's equivalent Bezier handles (`catmull_rom_to_bezier_handles`).
fn catmull_rom_handles(p: &[V3], cyclic: bool) -> (Vec<V3>, Vec<V3>) {
    const SCALE: f32 = 1.0 / 6.0;
    let n = p.len();
    let (mut hl, mut hr) = (p.to_vec(), p.to_vec());
    if n < 2 {
        return (hl, hr);
    }
    let first = if cyclic {
        sub(p[1], p[n - 1])
    } else {
        sub(p[1], p[0])
    };
    hr[0] = add(p[0], scale(first, SCALE));
    hl[0] = sub(p[0], scale(first, SCALE));
    let last = if cyclic {
        sub(p[0], p[n - 2])
    } else {
        sub(p[n - 1], p[n - 2])
    };
    hl[n - 1] = sub(p[n - 1], scale(last, SCALE));
    hr[n - 1] = add(p[n - 1], scale(last, SCALE));
    for i in 1..n - 1 {
        hl[i] = add(p[i], scale(sub(p[i - 1], p[i + 1]), SCALE));
        hr[i] = add(p[i], scale(sub(p[i + 1], p[i - 1]), SCALE));
    }
    (hl, hr)
}

/// Converts the selected curves to Bezier (`convert_curves_to_bezier`): poly curves get
/// vector handles, Catmull-Rom curves aligned handles on their tangents, Bezier curves
/// keep theirs; derived handles are recomputed. NURBS curves are refused.
fn to_bezier(c: &mut Curves, sel: &[bool]) -> Result<(), String> {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let cyclic = c.cyclic();
    let n = c.point_count();
    let mut hl = c.point_vectors("handle_left").unwrap_or(vec![[0.0; 3]; n]);
    let mut hr = c.point_vectors("handle_right").unwrap_or(vec![[0.0; 3]; n]);
    let mut tl: Vec<i8> = c
        .ints("handle_type_left", Domain::Point, 0)
        .iter()
        .map(|v| *v as i8)
        .collect();
    let mut tr: Vec<i8> = c
        .ints("handle_type_right", Domain::Point, 0)
        .iter()
        .map(|v| *v as i8)
        .collect();
    for i in 0..c.curve_count() {
        if !sel[i] {
            continue;
        }
        let r = c.points(i);
        match types[i] as i8 {
            CURVE_TYPE_POLY => {
                tl[r.clone()].fill(HANDLE_VECTOR);
                tr[r].fill(HANDLE_VECTOR);
            }
            CURVE_TYPE_CATMULL_ROM => {
                let (l, rr) = catmull_rom_handles(&c.positions[r.clone()], cyclic[i]);
                hl[r.clone()].copy_from_slice(&l);
                hr[r.clone()].copy_from_slice(&rr);
                tl[r.clone()].fill(HANDLE_ALIGN);
                tr[r].fill(HANDLE_ALIGN);
            }
            CURVE_TYPE_BEZIER => {}
            _ => {
                return Err(format!(
                    "curve {i}: converting NURBS curves to Bezier is not supported"
                ))
            }
        }
    }
    c.set_i8_selected("curve_type", Domain::Curve, 0, sel, CURVE_TYPE_BEZIER);
    write_handles(c, tl, tr, hl, hr);
    Ok(())
}

/// Converts the selected curves to NURBS (`convert_curves_to_nurbs`): order 4; a Bezier
/// or Catmull-Rom point becomes three (left handle, point, right handle; Bezier knots),
/// poly points stay (endpoint knots, normal ones when cyclic).
fn to_nurbs(c: &Curves, sel: &[bool]) -> Curves {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let cyclic = c.cyclic();
    let hl = c.point_vectors("handle_left");
    let hr = c.point_vectors("handle_right");
    let mut order: Vec<i8> = c
        .ints("nurbs_order", Domain::Curve, 4)
        .iter()
        .map(|v| *v as i8)
        .collect();
    let mut knots: Vec<i8> = c
        .ints("knots_mode", Domain::Curve, 0)
        .iter()
        .map(|v| *v as i8)
        .collect();
    let mut weights_src = c.point_floats("nurbs_weight", 1.0);
    // Per result point: its source point, position, and whether its weight resets to 1.
    let (mut src, mut pos, mut reset) = (Vec::new(), Vec::new(), Vec::new());
    let mut offsets = vec![0u32];
    for i in 0..c.curve_count() {
        let r = c.points(i);
        let t = types[i] as i8;
        let tripled = sel[i] && (t == CURVE_TYPE_BEZIER || t == CURVE_TYPE_CATMULL_ROM);
        if tripled {
            let (l, rr) = if t == CURVE_TYPE_BEZIER {
                (
                    hl.as_ref()
                        .map(|h| h[r.clone()].to_vec())
                        .unwrap_or_default(),
                    hr.as_ref()
                        .map(|h| h[r.clone()].to_vec())
                        .unwrap_or_default(),
                )
            } else {
                catmull_rom_handles(&c.positions[r.clone()], cyclic[i])
            };
            for (k, p) in r.clone().enumerate() {
                for q in [l[k], c.positions[p], rr[k]] {
                    src.push(p);
                    pos.push(q);
                    reset.push(true);
                }
            }
            order[i] = 4;
            knots[i] = KNOTS_BEZIER;
        } else {
            for p in r.clone() {
                src.push(p);
                pos.push(c.positions[p]);
                reset.push(sel[i] && t != CURVE_TYPE_NURBS);
            }
            if sel[i] && t != CURVE_TYPE_NURBS {
                order[i] = 4;
                knots[i] = if cyclic[i] {
                    KNOTS_NORMAL
                } else {
                    KNOTS_ENDPOINT
                };
            }
        }
        offsets.push(src.len() as u32);
    }
    let mut out = Curves {
        positions: pos,
        curve_offsets: offsets,
        attributes: Default::default(),
        materials: c.materials.clone(),
    };
    for a in c.attributes.iter() {
        let data = match a.domain {
            Domain::Curve => a.data.clone(),
            Domain::Point => a.data.gather(&src),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    let mut t: Vec<i8> = types.iter().map(|v| *v as i8).collect();
    for i in 0..t.len() {
        if sel[i] {
            t[i] = CURVE_TYPE_NURBS;
        }
    }
    out.set_i8("curve_type", Domain::Curve, t);
    out.set_i8("nurbs_order", Domain::Curve, order);
    out.set_i8("knots_mode", Domain::Curve, knots);
    weights_src = src.iter().map(|&p| weights_src[p]).collect();
    // Converted points weigh 1 (Blender's default weight when none was stored).
    for (w, r) in weights_src.iter_mut().zip(&reset) {
        if *r {
            *w = 1.0;
        }
    }
    out.attributes.set(
        AttrId::named("nurbs_weight"),
        Domain::Point,
        Array::Float(weights_src),
    );
    out
}

pub fn set_spline_type(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let target = match ctx.prop_str("spline_type")? {
        "POLY" => CURVE_TYPE_POLY,
        "CATMULL_ROM" => CURVE_TYPE_CATMULL_ROM,
        "BEZIER" => CURVE_TYPE_BEZIER,
        "NURBS" => CURVE_TYPE_NURBS,
        other => return Err(ctx.err(format!("spline type {other:?} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    super::curve_write::edit_curves(
        ctx,
        "Curve",
        Domain::Curve,
        &[(&sel, DataType::Bool)],
        &mut |c, r| {
            let sel = r[0].as_bool();
            match target {
                CURVE_TYPE_BEZIER => to_bezier(c, &sel)?,
                CURVE_TYPE_NURBS => *c = to_nurbs(c, &sel),
                _ => {
                    // Poly and Catmull-Rom keep the points as they are.
                    c.set_i8_selected("curve_type", Domain::Curve, 0, &sel, target);
                }
            }
            remove_attributes_based_on_types(c);
            Ok(())
        },
    )
}
