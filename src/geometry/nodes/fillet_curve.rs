//! Fillet Curve (`node_geo_curve_fillet`, `geometry::fillet_curves`): every control point
//! (not the ends of open curves, not where Radius is 0) becomes a circular arc of Radius
//! tangent to its two segments, measured on the control polygon whatever the curve type.
//! Poly mode puts Count points inside each arc (vector handles on Bezier curves); Bezier
//! mode makes each arc two points with aligned handles approximating the circle and
//! vector handles outward. Limit Radius shrinks radii so neighbouring arcs meet at most
//! in the middle of a segment. Other point attributes are copied to every arc point.

use std::sync::Arc;

use super::super::curve_eval::curve_types;
use super::super::curves::{Curves, CURVE_TYPE_BEZIER, HANDLE_ALIGN, HANDLE_VECTOR};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::limits;
use super::super::math::{
    add, axis_angle_normalized_to_mat3, cross, dot, normalize, normalize_v3, scale, sub, V3,
};
use super::super::types::{Array, DataType, Domain, Value};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};
use super::rotation::angle_normalized;

fn neg(a: V3) -> V3 {
    [-a[0], -a[1], -a[2]]
}

fn distance(a: V3, b: V3) -> f32 {
    dot(sub(a, b), sub(a, b)).sqrt()
}

/// `angle_v3v3`: both vectors normalized first.
fn angle_v3v3(a: V3, b: V3) -> f32 {
    angle_normalized(normalize_v3(a).0, normalize_v3(b).0)
}

/// `math::rotate_around_axis` (`axis_angle_normalized_to_mat3` about `center`).
fn rotate_around_axis(v: V3, center: V3, axis: V3, angle: f32) -> V3 {
    let m = axis_angle_normalized_to_mat3(axis, angle);
    let d = sub(v, center);
    let r = [0, 1, 2].map(|i| m[0][i] * d[0] + m[1][i] * d[1] + m[2][i] * d[2]);
    add(r, center)
}

/// `bezier::calculate_vector_handle`.
fn vector_handle(p: V3, next: V3) -> V3 {
    let t = 1.0f32 / 3.0;
    [0, 1, 2].map(|k| p[k] * (1.0 - t) + next[k] * t)
}

fn safe_divide(a: f32, b: f32) -> f32 {
    if b == 0.0 {
        0.0
    } else {
        a / b
    }
}

#[allow(clippy::too_many_arguments)]
fn limit_radius(
    p_prev: V3,
    p: V3,
    p_next: V3,
    a_prev: f32,
    a: f32,
    a_next: f32,
    r_prev: f32,
    r: f32,
    r_next: f32,
) -> f32 {
    let d = r * (a / 2.0).tan();
    let d_prev = r_prev * (a_prev / 2.0).tan();
    let f_prev = safe_divide(distance(p, p_prev), d_prev + d).clamp(0.0, 1.0);
    let d_next = r_next * (a_next / 2.0).tan();
    let f_next = safe_divide(distance(p, p_next), d_next + d).clamp(0.0, 1.0);
    r * f_prev.min(f_next)
}

fn limit_radii(p: &[V3], angles: &[f32], radii: &[f32], cyclic: bool) -> Vec<f32> {
    let n = p.len();
    if n < 2 {
        // A single point has no segments to limit against (and no fillet).
        return radii.to_vec();
    }
    let mut out = vec![0.0f32; n];
    let at = |i: usize, rp: f32, rn: f32, ip: usize, inx: usize| {
        limit_radius(
            p[ip],
            p[i],
            p[inx],
            angles[ip],
            angles[i],
            angles[inx],
            rp,
            radii[i],
            rn,
        )
    };
    if cyclic {
        out[0] = at(0, radii[n - 1], radii[1], n - 1, 1);
        for i in 1..n - 1 {
            out[i] = at(i, radii[i - 1], radii[i + 1], i - 1, i + 1);
        }
        out[n - 1] = at(n - 1, radii[n - 2], radii[0], n - 2, 0);
    } else {
        // The ends have no fillets: their radius counts as zero.
        for i in 1..n - 1 {
            let rp = if i - 1 == 0 { 0.0 } else { radii[i - 1] };
            let rn = if i + 1 == n - 1 { 0.0 } else { radii[i + 1] };
            out[i] = at(i, rp, rn, i - 1, i + 1);
        }
    }
    out
}

/// One curve's fillet: new positions and, per source point, its range of new points.
struct Fillet {
    positions: Vec<V3>,
    arcs: Vec<std::ops::Range<usize>>,
    angles: Vec<f32>,
    radii: Vec<f32>,
    directions: Vec<V3>,
}

fn fillet_curve(p: &[V3], cyclic: bool, radius_in: &[f32], counts: &[i32], limit: bool) -> Fillet {
    let n = p.len();
    let mut sizes: Vec<usize> = counts.iter().map(|c| (*c).max(0) as usize + 1).collect();
    if !cyclic {
        sizes[0] = 1;
        sizes[n - 1] = 1;
    }
    for (s, r) in sizes.iter_mut().zip(radius_in) {
        if *r == 0.0 {
            *s = 1;
        }
    }
    let mut directions: Vec<V3> = (0..n.saturating_sub(1))
        .map(|i| normalize(sub(p[i + 1], p[i])))
        .collect();
    directions.push(normalize(sub(p[0], p[n - 1])));
    let mut angles = vec![0.0f32; n];
    angles[0] = std::f32::consts::PI - angle_v3v3(neg(directions[n - 1]), directions[0]);
    for i in 1..n {
        angles[i] = std::f32::consts::PI - angle_v3v3(neg(directions[i - 1]), directions[i]);
    }
    let radii = if limit {
        limit_radii(p, &angles, radius_in, cyclic)
    } else {
        radius_in.to_vec()
    };
    let mut arcs = Vec::with_capacity(n);
    let mut positions = Vec::new();
    for i in 0..n {
        let start = positions.len();
        let size = sizes[i];
        arcs.push(start..start + size);
        if size == 1 {
            positions.push(p[i]);
            continue;
        }
        let prev = if i == 0 { n - 1 } else { i - 1 };
        let (angle, radius) = (angles[i], radii[i]);
        let displacement = radius * (angle / 2.0).tan();
        let prev_dir = neg(directions[prev]);
        let next_dir = directions[i];
        let arc_start = add(p[i], scale(prev_dir, displacement));
        let arc_end = add(p[i], scale(next_dir, displacement));
        positions.push(arc_start);
        let middle = size - 2;
        if middle > 0 {
            let axis = neg(normalize(cross(prev_dir, next_dir)));
            let mid = scale(add(next_dir, prev_dir), 0.5);
            let center_dir = normalize(mid);
            let to_center = (radius * radius + displacement * displacement).sqrt();
            let center = add(p[i], scale(center_dir, to_center));
            let seg = angle / (middle + 1) as f32;
            for k in 0..middle {
                positions.push(rotate_around_axis(
                    arc_start,
                    center,
                    axis,
                    seg * (k + 1) as f32,
                ));
            }
        }
        positions.push(arc_end);
    }
    Fillet {
        positions,
        arcs,
        angles,
        radii,
        directions,
    }
}

/// New handles and handle types of one filleted curve
/// (`calculate_bezier_handles_bezier_mode` / `_poly_mode`).
#[allow(clippy::type_complexity)]
fn fillet_handles(
    f: &Fillet,
    bezier_mode: bool,
    hl: &[V3],
    hr: &[V3],
    tl: &[i8],
    tr: &[i8],
) -> (Vec<V3>, Vec<V3>, Vec<i8>, Vec<i8>) {
    let m = f.positions.len();
    let (mut dl, mut dr) = (vec![[0.0f32; 3]; m], vec![[0.0f32; 3]; m]);
    let (mut dtl, mut dtr) = (vec![0i8; m], vec![0i8; m]);
    let n = f.arcs.len();
    let pos = &f.positions;
    for (i, arc) in f.arcs.iter().enumerate() {
        let (a, b) = (arc.start, arc.end - 1);
        if arc.len() == 1 {
            dl[a] = hl[i];
            dr[a] = hr[i];
            dtl[a] = tl[i];
            dtr[a] = tr[i];
            continue;
        }
        let prev = if a == 0 { m - 1 } else { a - 1 };
        let next = if b == m - 1 { 0 } else { b + 1 };
        dl[a] = vector_handle(pos[a], pos[prev]);
        dr[b] = vector_handle(pos[b], pos[next]);
        if bezier_mode {
            let i_prev = if i == 0 { n - 1 } else { i - 1 };
            let prev_dir = neg(f.directions[i_prev]);
            let next_dir = f.directions[i];
            dtl[a] = HANDLE_VECTOR;
            dtr[b] = HANDLE_VECTOR;
            let len = (4.0 / 3.0) * f.radii[i] * (f.angles[i] / 4.0).tan();
            dr[a] = sub(pos[a], scale(prev_dir, len));
            dl[b] = sub(pos[b], scale(next_dir, len));
            dtr[a] = HANDLE_ALIGN;
            dtl[b] = HANDLE_ALIGN;
        } else {
            for k in arc.clone() {
                dtl[k] = HANDLE_VECTOR;
                dtr[k] = HANDLE_VECTOR;
            }
            for k in a + 1..b {
                dr[k] = vector_handle(pos[k], pos[k - 1]);
                dl[k] = vector_handle(pos[k], pos[k + 1]);
            }
        }
    }
    (dl, dr, dtl, dtr)
}

fn fillet_curves(
    c: &Curves,
    radius: &[f32],
    counts: &[i32],
    limit: bool,
    bezier_mode: bool,
) -> Curves {
    let cyclic = c.cyclic();
    let any_bezier = curve_types(c).contains(&CURVE_TYPE_BEZIER);
    let hl = c.point_vectors("handle_left");
    let hr = c.point_vectors("handle_right");
    let ints = |name| -> Vec<i8> {
        c.ints(name, Domain::Point, 0)
            .iter()
            .map(|v| *v as i8)
            .collect()
    };
    let (tl, tr) = (ints("handle_type_left"), ints("handle_type_right"));
    let (hl, hr) = (
        hl.unwrap_or_else(|| c.positions.clone()),
        hr.unwrap_or_else(|| c.positions.clone()),
    );
    let mut out = Curves {
        curve_offsets: vec![0],
        materials: c.materials.clone(),
        ..Default::default()
    };
    // Per new point, the source point it copies its other attributes from.
    let mut src = Vec::new();
    let (mut nl, mut nr, mut ntl, mut ntr) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..c.curve_count() {
        let pts = c.points(i);
        if pts.is_empty() {
            out.curve_offsets.push(out.positions.len() as u32);
            continue;
        }
        let f = fillet_curve(
            &c.positions[pts.clone()],
            cyclic[i],
            &radius[pts.clone()],
            &counts[pts.clone()],
            limit,
        );
        for (k, arc) in f.arcs.iter().enumerate() {
            src.extend(arc.clone().map(|_| pts.start + k));
        }
        if any_bezier {
            let (l, r, a, b) = fillet_handles(
                &f,
                bezier_mode,
                &hl[pts.clone()],
                &hr[pts.clone()],
                &tl[pts.clone()],
                &tr[pts.clone()],
            );
            nl.extend(l);
            nr.extend(r);
            ntl.extend(a);
            ntr.extend(b);
        }
        out.positions.extend(f.positions);
        out.curve_offsets.push(out.positions.len() as u32);
    }
    for a in c.attributes.iter() {
        let data = match (a.domain, a.id.name()) {
            (Domain::Curve, _) => a.data.clone(),
            (Domain::Point, Some("handle_left")) => Array::Vector(std::mem::take(&mut nl)),
            (Domain::Point, Some("handle_right")) => Array::Vector(std::mem::take(&mut nr)),
            (Domain::Point, Some("handle_type_left")) => Array::Int8(std::mem::take(&mut ntl)),
            (Domain::Point, Some("handle_type_right")) => Array::Int8(std::mem::take(&mut ntr)),
            (Domain::Point, _) => a.data.gather(&src),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    if any_bezier {
        use super::super::attribute::AttrId;
        for (name, data) in [
            ("handle_left", Array::Vector(nl)),
            ("handle_right", Array::Vector(nr)),
            ("handle_type_left", Array::Int8(ntl)),
            ("handle_type_right", Array::Int8(ntr)),
        ] {
            if out.attributes.named(name).is_none() {
                out.attributes.set(AttrId::named(name), Domain::Point, data);
            }
        }
    }
    out
}

pub fn fillet_curve_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let bezier_mode = match ctx.prop_str("mode")? {
        "BEZIER" => true,
        "POLY" => false,
        other => return Err(ctx.err(format!("mode {other:?} is not supported"))),
    };
    let radius = ctx.field("Radius", DataType::Float)?;
    let limit = ctx.bool("Limit Radius")?;
    // Bezier mode makes two points per fillet: one cut.
    let count = if bezier_mode {
        Field::Constant(Value::Int(1))
    } else {
        ctx.field("Count", DataType::Int)?
    };
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        if c.point_count() == 0 {
            return Ok(());
        }
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Point,
            &[(&radius, DataType::Float), (&count, DataType::Int)],
        )?;
        // Checked before allocating: a hostile Count is an error, not an abort.
        let total = r[1]
            .as_int()
            .iter()
            .try_fold(0u64, |acc, k| acc.checked_add((*k).max(0) as u64 + 1));
        limits::check(total, "Count")?;
        let out = fillet_curves(&c, &r[0].as_float(), &r[1].as_int(), limit, bezier_mode);
        s.curves = Some(Arc::new(out));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}
