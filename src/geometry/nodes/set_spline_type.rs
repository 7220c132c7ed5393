//! Set Spline Type (`node_geo_curve_spline_type`, `geometry::convert_curves`). Converting
//! to Poly or Catmull-Rom keeps the control points as they are (Blender's trivial
//! conversion: a Bezier curve loses its handles, a NURBS curve its weights and knots);
//! to Bezier and NURBS as `set_curve_type.cc` converts. Bezier handle and NURBS
//! attributes are dropped once no curve of that type is left.

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

/// Whether a NURBS curve's Bezier conversion maps hull segments to Bezier segments one to
/// one (`is_nurbs_to_bezier_one_to_one`): normal and endpoint knots; the others take every
/// third control point as a Bezier point.
fn one_to_one(knots: i8) -> bool {
    knots == KNOTS_NORMAL || knots == KNOTS_ENDPOINT
}

/// `create_nurbs_to_bezier_handles`: the Bezier handles, left and right of each point in
/// turn, placed on the NURBS hull.
fn nurbs_handles(p: &[V3], knots: i8) -> Vec<V3> {
    let n = p.len();
    let third = |a: V3, b: V3| add(b, div(sub(a, b), 3.0));
    let mut h = Vec::with_capacity(2 * n);
    if one_to_one(knots) {
        let periodic = knots == KNOTS_NORMAL;
        if periodic {
            h.push(third(p[0], p[1]));
        } else {
            h.push(sub(scale(p[0], 2.0), p[1]));
            h.push(p[1]);
        }
        // Interior hull segments hold one handle at their middle or two at their thirds.
        let segments = n - 1;
        if segments != 3 || periodic {
            let mid = (segments - 1) as f32 / 2.0;
            for i in 1..segments.saturating_sub(1) {
                let divisor = if periodic {
                    3
                } else {
                    3.min((-(i as f32 - mid).abs() + mid + 1.0) as i32)
                };
                let d = div(sub(p[i + 1], p[i]), divisor as f32);
                let count = if divisor < 3 { 1 } else { 2 };
                for j in 1..=count {
                    h.push(add(p[i], scale(d, j as f32)));
                }
            }
        }
        let l = n - 1;
        if periodic {
            h.push(add(p[l - 1], div(sub(p[l], p[l - 1]), 3.0)));
        } else {
            h.push(p[l - 1]);
            h.push(sub(scale(p[l], 2.0), p[l - 1]));
        }
    } else {
        h.extend((0..n).filter(|i| i % 3 != 1).map(|i| p[i]));
        if n % 3 == 1 {
            h.pop();
        } else if n % 3 == 2 {
            h.push(sub(scale(p[n - 1], 2.0), p[n - 2]));
        }
    }
    h
}

fn div(a: V3, d: f32) -> V3 {
    [a[0] / d, a[1] / d, a[2] / d]
}

/// The source point of each Bezier point for point attributes (`nurbs_to_bezier_assign`,
/// by the curve's own knots mode even when cyclic).
fn nurbs_to_bezier_source(n: usize, dst: usize, knots: i8) -> Vec<usize> {
    match knots {
        KNOTS_NORMAL => (0..dst).map(|i| (i + 1) % n).collect(),
        KNOTS_ENDPOINT => {
            let mut v: Vec<usize> = (0..dst).map(|i| (i + 1).min(n - 1)).collect();
            v[0] = 0;
            v[dst - 1] = n - 1;
            v
        }
        _ => (0..dst).map(|i| i * 3 + 1).collect(),
    }
}

/// Converts the selected curves to Bezier (`convert_curves_to_bezier`): poly curves get
/// vector handles, Catmull-Rom curves aligned handles on their tangents, Bezier curves
/// keep theirs, NURBS curves aligned handles on their hull (one Bezier segment per hull
/// segment with normal and endpoint knots, every third point otherwise); derived handles
/// are recomputed.
fn to_bezier(c: &Curves, sel: &[bool]) -> Result<Curves, String> {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let cyclic = c.cyclic();
    let knots_modes = c.ints("knots_mode", Domain::Curve, 0);
    let n = c.point_count();
    let hl_src = c.point_vectors("handle_left").unwrap_or(vec![[0.0; 3]; n]);
    let hr_src = c.point_vectors("handle_right").unwrap_or(vec![[0.0; 3]; n]);
    let tl_src = c.ints("handle_type_left", Domain::Point, 0);
    let tr_src = c.ints("handle_type_right", Domain::Point, 0);
    // Per result point: source point (for point attributes), position, handles, types.
    let (mut src, mut pos) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut hl, mut hr) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut tl, mut tr) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut offsets = vec![0u32];
    for i in 0..c.curve_count() {
        let r = c.points(i);
        let p = &c.positions[r.clone()];
        let t = types[i] as i8;
        if sel[i] && t == CURVE_TYPE_NURBS && !p.is_empty() {
            let knots = knots_modes[i] as i8;
            let count = if one_to_one(knots) {
                if cyclic[i] {
                    p.len()
                } else {
                    p.len().saturating_sub(2).max(1)
                }
            } else {
                (p.len() + 1) / 3
            };
            if count == 0 {
                return Err(format!(
                    "curve {i}: a NURBS curve of {} point(s) with Bezier knots has no Bezier point",
                    p.len()
                ));
            }
            src.extend(
                nurbs_to_bezier_source(p.len(), count, knots)
                    .into_iter()
                    .map(|k| r.start + k),
            );
            tl.extend(std::iter::repeat_n(HANDLE_ALIGN, count));
            tr.extend(std::iter::repeat_n(HANDLE_ALIGN, count));
            if count == 1 {
                pos.push(p[0]);
                hl.push(p[0]);
                hr.push(p[0]);
            } else {
                // A cyclic curve is converted as a periodic one, its hull extended by its
                // first two points.
                let mut hull = p.to_vec();
                let mut mode = knots;
                if cyclic[i] && one_to_one(knots) {
                    hull.push(p[0]);
                    hull.push(p[1]);
                    mode = KNOTS_NORMAL;
                }
                let h = nurbs_handles(&hull, mode);
                if h.len() < 2 * count {
                    return Err(format!("curve {i}: NURBS to Bezier handle count mismatch"));
                }
                for k in 0..count {
                    let (a, b) = (h[2 * k], h[2 * k + 1]);
                    hl.push(a);
                    hr.push(b);
                    pos.push(if one_to_one(mode) {
                        [0, 1, 2].map(|j| a[j] * (1.0 - 0.5) + b[j] * 0.5)
                    } else {
                        hull[3 * k + 1]
                    });
                }
            }
        } else {
            src.extend(r.clone());
            pos.extend_from_slice(p);
            let (mut l, mut rr) = (hl_src[r.clone()].to_vec(), hr_src[r.clone()].to_vec());
            let (mut a, mut b): (Vec<i8>, Vec<i8>) = (
                tl_src[r.clone()].iter().map(|v| *v as i8).collect(),
                tr_src[r.clone()].iter().map(|v| *v as i8).collect(),
            );
            if sel[i] && t == CURVE_TYPE_POLY {
                a.fill(HANDLE_VECTOR);
                b.fill(HANDLE_VECTOR);
            } else if sel[i] && t == CURVE_TYPE_CATMULL_ROM {
                (l, rr) = catmull_rom_handles(p, cyclic[i]);
                a.fill(HANDLE_ALIGN);
                b.fill(HANDLE_ALIGN);
            }
            hl.extend(l);
            hr.extend(rr);
            tl.extend(a);
            tr.extend(b);
        }
        offsets.push(pos.len() as u32);
    }
    let mut out = rebuilt(c, pos, offsets, &src);
    out.set_i8_selected("curve_type", Domain::Curve, 0, sel, CURVE_TYPE_BEZIER);
    write_handles(&mut out, tl, tr, hl, hr);
    Ok(out)
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
    let mut out = rebuilt(c, pos, offsets, &src);
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
                CURVE_TYPE_BEZIER => *c = to_bezier(c, &sel)?,
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

/// `c`'s curves with new points: `pos` and `offsets`, each point's attributes taken from
/// source point `src[i]`, the curve attributes and materials kept.
fn rebuilt(c: &Curves, pos: Vec<V3>, offsets: Vec<u32>, src: &[usize]) -> Curves {
    let mut out = Curves {
        positions: pos,
        curve_offsets: offsets,
        attributes: Default::default(),
        materials: c.materials.clone(),
    };
    for a in c.attributes.iter() {
        let data = match a.domain {
            Domain::Curve => a.data.clone(),
            Domain::Point => a.data.gather(src),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    out
}
