//! Bezier handles as Blender derives them (`bke::curves::bezier`): auto and vector handles
//! computed from the neighbouring control points, aligned handles kept opposite their
//! partner, and a handle moved by hand (`set_handle_position`).

use super::curves::{
    Curves, CURVE_TYPE_BEZIER, HANDLE_ALIGN, HANDLE_AUTO, HANDLE_FREE, HANDLE_VECTOR,
};
use super::math::{add, length, normalize, scale, sub, V3};
use super::types::Domain;

fn lerp(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// The handle opposite `other`, keeping the length `aligned` had.
fn aligned_handle(position: V3, other: V3, aligned: V3) -> V3 {
    let len = length(sub(aligned, position));
    let dir = normalize(sub(other, position));
    sub(position, scale(dir, len))
}

/// One control point's derived handles (`calculate_point_handles`).
fn point_handles(types: (i8, i8), position: V3, prev: V3, next: V3, left: &mut V3, right: &mut V3) {
    let (tl, tr) = types;
    if tl == HANDLE_AUTO || tr == HANDLE_AUTO {
        let prev_diff = sub(position, prev);
        let next_diff = sub(next, position);
        let mut prev_len = length(prev_diff);
        let mut next_len = length(next_diff);
        if prev_len == 0.0 {
            prev_len = 1.0;
        }
        if next_len == 0.0 {
            next_len = 1.0;
        }
        let dir = add(
            scale(next_diff, 1.0 / next_len),
            scale(prev_diff, 1.0 / prev_len),
        );
        // Blender's constant for auto handle length.
        let len = length(dir) * 2.5614;
        if len != 0.0 {
            if tl == HANDLE_AUTO {
                let l = prev_len.min(next_len * 5.0);
                *left = add(position, scale(dir, -(l / len)));
            }
            if tr == HANDLE_AUTO {
                let l = next_len.min(prev_len * 5.0);
                *right = add(position, scale(dir, l / len));
            }
        }
    }
    if tl == HANDLE_VECTOR {
        *left = lerp(position, prev, 1.0 / 3.0);
    }
    if tr == HANDLE_VECTOR {
        *right = lerp(position, next, 1.0 / 3.0);
    }
    if tl == HANDLE_ALIGN && tr != HANDLE_ALIGN {
        *left = aligned_handle(position, *right, *left);
    } else if tl != HANDLE_ALIGN && tr == HANDLE_ALIGN {
        *right = aligned_handle(position, *left, *right);
    }
}

/// Writes the Bezier handle types and positions of every point, then recomputes the
/// auto and vector handles from them (Blender's `calculate_bezier_auto_handles` after a
/// handle edit).
pub fn write_handles(c: &mut Curves, left: Vec<i8>, right: Vec<i8>, hl: Vec<V3>, hr: Vec<V3>) {
    c.set_i8("handle_type_left", Domain::Point, left);
    c.set_i8("handle_type_right", Domain::Point, right);
    c.attributes.set(
        super::attribute::AttrId::named("handle_left"),
        Domain::Point,
        super::types::Array::Vector(hl),
    );
    c.attributes.set(
        super::attribute::AttrId::named("handle_right"),
        Domain::Point,
        super::types::Array::Vector(hr),
    );
    calculate_auto_handles(c);
}

/// Recomputes the derived handles of every Bezier curve
/// (`CurvesGeometry::calculate_bezier_auto_handles`). Curves without handle attributes
/// are left alone.
pub fn calculate_auto_handles(c: &mut Curves) {
    let (Some(mut hl), Some(mut hr)) = (
        c.point_vectors("handle_left"),
        c.point_vectors("handle_right"),
    ) else {
        return;
    };
    let types = c.ints("curve_type", Domain::Curve, 0);
    let cyclic = c.cyclic();
    let tl = c.ints("handle_type_left", Domain::Point, 0);
    let tr = c.ints("handle_type_right", Domain::Point, 0);
    let p = &c.positions;
    for i in 0..c.curve_count() {
        let r = c.points(i);
        if types[i] as i8 != CURVE_TYPE_BEZIER || r.len() < 2 {
            continue;
        }
        let (f, l) = (r.start, r.end - 1);
        for k in r.clone() {
            let prev = if k > f {
                p[k - 1]
            } else if cyclic[i] {
                p[l]
            } else {
                sub(scale(p[f], 2.0), p[f + 1])
            };
            let next = if k < l {
                p[k + 1]
            } else if cyclic[i] {
                p[f]
            } else {
                sub(scale(p[l], 2.0), p[l - 1])
            };
            point_handles(
                (tl[k] as i8, tr[k] as i8),
                p[k],
                prev,
                next,
                &mut hl[k],
                &mut hr[k],
            );
        }
    }
    let a = &mut c.attributes;
    a.set(
        super::attribute::AttrId::named("handle_left"),
        Domain::Point,
        super::types::Array::Vector(hl),
    );
    a.set(
        super::attribute::AttrId::named("handle_right"),
        Domain::Point,
        super::types::Array::Vector(hr),
    );
}

/// Moves one handle by hand (`bezier::set_handle_position`): derived handles keep their
/// place, an aligned partner turns to stay opposite.
pub fn set_handle_position(
    position: V3,
    types: (i8, i8),
    new_handle: V3,
    handle: &mut V3,
    other: &mut V3,
) {
    let (t, t_other) = types;
    if t == HANDLE_AUTO || t == HANDLE_VECTOR {
        return;
    }
    *handle = new_handle;
    if t_other == HANDLE_ALIGN {
        *other = aligned_handle(position, *handle, *other);
    }
}

/// Handle types after one side is moved by hand (`update_handle_types_for_movement`).
pub fn types_for_movement(t: &mut i8, other: &mut i8) {
    match *t {
        HANDLE_AUTO => {
            if *other == HANDLE_AUTO {
                *t = HANDLE_ALIGN;
                *other = HANDLE_ALIGN;
            } else {
                *t = HANDLE_FREE;
            }
        }
        HANDLE_VECTOR => *t = HANDLE_FREE,
        // An aligned handle stays aligned only beside another aligned one.
        HANDLE_ALIGN if *other != HANDLE_ALIGN => *t = HANDLE_FREE,
        _ => {}
    }
}
