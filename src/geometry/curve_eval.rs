//! Evaluated curves as Blender computes them (`bke::curves` and `curves::poly`,
//! `curves::bezier`): evaluated points per curve (Bezier segments by forward differencing
//! at the curve's resolution, poly points as they are), attributes interpolated to the
//! evaluated points, segment lengths, tangents, and minimum-twist / Z-up normals with tilt.
//!
//! NURBS and Catmull-Rom curves are reported as unsupported rather than approximated.

use super::curves::{Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_POLY};
use super::math::{add, cross, dot, length, normalize, scale, sub, V3};
use super::types::{Array, Domain};

/// Blender's `NormalMode` values as stored in the `normal_mode` curve attribute.
pub const NORMAL_MODE_MINIMUM_TWIST: i8 = 0;
pub const NORMAL_MODE_Z_UP: i8 = 1;

/// Bezier handle type VECTOR as stored in `handle_type_left` / `handle_type_right`.
pub const HANDLE_VECTOR: i8 = 2;

fn curve_attr_i8(c: &Curves, name: &str, default: i8) -> Vec<i8> {
    match c.attributes.named(name) {
        Some(a) if a.domain == Domain::Curve => a.data.as_int().iter().map(|v| *v as i8).collect(),
        _ => vec![default; c.curve_count()],
    }
}

pub fn curve_types(c: &Curves) -> Vec<i8> {
    curve_attr_i8(c, "curve_type", CURVE_TYPE_CATMULL_ROM_DEFAULT)
}

/// Curves without a `curve_type` attribute are Catmull-Rom in Blender.
const CURVE_TYPE_CATMULL_ROM_DEFAULT: i8 = 0;

pub fn cyclic(c: &Curves) -> Vec<bool> {
    match c.attributes.named("cyclic") {
        Some(a) => a.data.as_bool().into_owned(),
        None => vec![false; c.curve_count()],
    }
}

pub fn resolutions(c: &Curves) -> Vec<i32> {
    match c.attributes.named("resolution") {
        Some(a) => a.data.as_int().into_owned(),
        None => vec![12; c.curve_count()],
    }
}

pub fn normal_modes(c: &Curves) -> Vec<i8> {
    curve_attr_i8(c, "normal_mode", NORMAL_MODE_MINIMUM_TWIST)
}

fn point_float(c: &Curves, name: &str, default: f32) -> Vec<f32> {
    match c.attributes.named(name) {
        Some(a) if a.domain == Domain::Point => a.data.as_float().into_owned(),
        _ => vec![default; c.point_count()],
    }
}

fn point_i8(c: &Curves, name: &str) -> Vec<i8> {
    match c.attributes.named(name) {
        Some(a) if a.domain == Domain::Point => a.data.as_int().iter().map(|v| *v as i8).collect(),
        _ => vec![0; c.point_count()],
    }
}

fn point_vec(c: &Curves, name: &str) -> Vec<V3> {
    match c.attributes.named(name) {
        Some(a) if a.domain == Domain::Point => a.data.as_vector().into_owned(),
        _ => c.positions.clone(),
    }
}

/// Per-curve facts needed to evaluate: evaluated point offsets and, for Bezier curves,
/// each control point's first evaluated point.
pub struct Evaluated {
    pub offsets: Vec<u32>,
    pub cyclic: Vec<bool>,
    types: Vec<i8>,
    /// For Bezier curves: per control point, the offset of its segment's first evaluated
    /// point within the curve (`n + 1` entries per curve, in point order plus one).
    bezier_offsets: Vec<Vec<u32>>,
}

impl Evaluated {
    pub fn new(c: &Curves) -> Result<Evaluated, String> {
        let types = curve_types(c);
        let cyclic = cyclic(c);
        let res = resolutions(c);
        let hl = point_i8(c, "handle_type_left");
        let hr = point_i8(c, "handle_type_right");
        let mut offsets = vec![0u32];
        let mut bezier_offsets = Vec::with_capacity(c.curve_count());
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            let n = pts.len();
            let count = match types[i] {
                CURVE_TYPE_POLY => {
                    bezier_offsets.push(Vec::new());
                    n
                }
                CURVE_TYPE_BEZIER => {
                    // Each segment gets `resolution` points, or one when both of its
                    // handles are vector handles (a straight segment); an open curve
                    // adds its last control point.
                    let r = res[i].max(1) as u32;
                    let mut offs = Vec::with_capacity(n + 1);
                    let mut acc = 0u32;
                    for s in 0..n {
                        offs.push(acc);
                        let next = if s + 1 == n { 0 } else { s + 1 };
                        if s + 1 == n && !cyclic[i] {
                            acc += 1;
                            continue;
                        }
                        let vector = hr[pts.start + s] == HANDLE_VECTOR
                            && hl[pts.start + next] == HANDLE_VECTOR;
                        acc += if vector { 1 } else { r };
                    }
                    offs.push(acc);
                    bezier_offsets.push(offs);
                    if n == 0 {
                        0
                    } else {
                        acc as usize
                    }
                }
                t => {
                    return Err(format!(
                        "curve {i}: {} curves are not supported yet (only Bezier and poly)",
                        type_name(t)
                    ))
                }
            };
            offsets.push(offsets[i] + count as u32);
        }
        Ok(Evaluated {
            offsets,
            cyclic,
            types,
            bezier_offsets,
        })
    }

    /// The evaluated point (within curve `i`) where control point `p` (within the curve)
    /// lies.
    pub fn control_point_evaluated(&self, i: usize, p: usize) -> usize {
        match self.types[i] {
            CURVE_TYPE_BEZIER => self.bezier_offsets[i][p] as usize,
            _ => p,
        }
    }

    pub fn total(&self) -> usize {
        *self.offsets.last().unwrap_or(&0) as usize
    }

    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Evaluated positions of every curve, concatenated.
    pub fn positions(&self, c: &Curves) -> Vec<V3> {
        let mut out = vec![[0.0f32; 3]; self.total()];
        let hl = point_vec(c, "handle_left");
        let hr = point_vec(c, "handle_right");
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            let dst = &mut out[self.range(i)];
            match self.types[i] {
                CURVE_TYPE_BEZIER => {
                    let offs = &self.bezier_offsets[i];
                    let n = pts.len();
                    for s in 0..n {
                        let seg = offs[s] as usize..offs[s + 1] as usize;
                        if seg.is_empty() {
                            continue;
                        }
                        let a = pts.start + s;
                        if s + 1 == n && !self.cyclic[i] {
                            dst[seg.start] = c.positions[a];
                            continue;
                        }
                        let b = pts.start + if s + 1 == n { 0 } else { s + 1 };
                        bezier_segment(c.positions[a], hr[a], hl[b], c.positions[b], &mut dst[seg]);
                    }
                }
                _ => dst.copy_from_slice(&c.positions[pts]),
            }
        }
        out
    }

    /// Evaluated tangents of every curve; open Bezier curves take their end tangents
    /// from the inner handles, as Blender corrects them.
    pub fn tangents(&self, c: &Curves, evaluated: &[V3]) -> Vec<V3> {
        let mut out = Vec::with_capacity(evaluated.len());
        let hl = point_vec(c, "handle_left");
        let hr = point_vec(c, "handle_right");
        for i in 0..c.curve_count() {
            let r = self.range(i);
            let start = out.len();
            out.extend(tangents(&evaluated[r.clone()], self.cyclic[i]));
            let pts = c.points(i);
            if self.types[i] == CURVE_TYPE_BEZIER
                && !self.cyclic[i]
                && !r.is_empty()
                && !pts.is_empty()
            {
                let (f, l) = (pts.start, pts.end - 1);
                if !almost_equal_relative(hr[f], c.positions[f], 1e-6) {
                    out[start] = normalize(sub(hr[f], c.positions[f]));
                }
                if !almost_equal_relative(hl[l], c.positions[l], 1e-6) {
                    let last = out.len() - 1;
                    out[last] = normalize(sub(c.positions[l], hl[l]));
                }
            }
        }
        out
    }

    /// Evaluated normals of every curve (normal mode per curve, tilt interpolated).
    pub fn normals(&self, c: &Curves, tangents_all: &[V3]) -> Vec<V3> {
        let tilt = match c.attributes.named("tilt") {
            Some(a) if a.domain == Domain::Point => {
                self.interpolate(c, &a.data).as_float().into_owned()
            }
            _ => vec![0.0; self.total()],
        };
        let modes = normal_modes(c);
        let mut out = Vec::with_capacity(self.total());
        for i in 0..c.curve_count() {
            let r = self.range(i);
            out.extend(normals(
                &tangents_all[r.clone()],
                self.cyclic[i],
                modes[i],
                &tilt[r],
            ));
        }
        out
    }

    /// A point-domain attribute interpolated to the evaluated points (Bezier segments
    /// linearly, as Blender does for generic attributes).
    pub fn interpolate(&self, c: &Curves, data: &Array) -> Array {
        let mut idx_a = Vec::with_capacity(self.total());
        let mut idx_b = Vec::with_capacity(self.total());
        let mut fac = Vec::with_capacity(self.total());
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            match self.types[i] {
                CURVE_TYPE_BEZIER => {
                    let offs = &self.bezier_offsets[i];
                    let n = pts.len();
                    for s in 0..n {
                        let len = (offs[s + 1] - offs[s]) as usize;
                        let a = pts.start + s;
                        let b = pts.start + if s + 1 == n { 0 } else { s + 1 };
                        let step = 1.0 / len.max(1) as f32;
                        for j in 0..len {
                            idx_a.push(a);
                            idx_b.push(b);
                            fac.push(j as f32 * step);
                        }
                    }
                }
                _ => {
                    for p in pts {
                        idx_a.push(p);
                        idx_b.push(p);
                        fac.push(0.0);
                    }
                }
            }
        }
        lerp_gather(data, &idx_a, &idx_b, &fac)
    }
}

fn type_name(t: i8) -> &'static str {
    match t {
        0 => "Catmull-Rom",
        1 => "poly",
        2 => "Bezier",
        3 => "NURBS",
        _ => "unknown",
    }
}

/// `data[a] * (1 - f) + data[b] * f` per output, for the numeric types (others take `a`).
pub fn lerp_gather(data: &Array, a: &[usize], b: &[usize], f: &[f32]) -> Array {
    fn lanes<const K: usize>(v: &[[f32; K]], a: &[usize], b: &[usize], f: &[f32]) -> Vec<[f32; K]> {
        (0..a.len())
            .map(|i| {
                let (x, y, t) = (&v[a[i]], &v[b[i]], f[i]);
                let mut o = [0.0f32; K];
                for k in 0..K {
                    o[k] = x[k] * (1.0 - t) + y[k] * t;
                }
                o
            })
            .collect()
    }
    match data {
        Array::Float(v) => Array::Float(
            (0..a.len())
                .map(|i| v[a[i]] * (1.0 - f[i]) + v[b[i]] * f[i])
                .collect(),
        ),
        Array::Float2(v) => Array::Float2(lanes(v, a, b, f)),
        Array::Vector(v) => Array::Vector(lanes(v, a, b, f)),
        Array::Color(v) => Array::Color(lanes(v, a, b, f)),
        // Blender's `mix2` for integers and booleans: the float mix, rounded / thresholded.
        Array::Int(v) => Array::Int(
            (0..a.len())
                .map(|i| ((1.0 - f[i]) * v[a[i]] as f32 + f[i] * v[b[i]] as f32).round() as i32)
                .collect(),
        ),
        Array::Int8(v) => Array::Int8(
            (0..a.len())
                .map(|i| ((1.0 - f[i]) * v[a[i]] as f32 + f[i] * v[b[i]] as f32).round() as i8)
                .collect(),
        ),
        Array::Bool(v) => Array::Bool(
            (0..a.len())
                .map(|i| (1.0 - f[i]) * v[a[i]] as u8 as f32 + f[i] * v[b[i]] as u8 as f32 >= 0.5)
                .collect(),
        ),
        other => other.gather(a),
    }
}

/// One Bezier segment by forward differencing, `dst.len()` points from `p0` (t = 0)
/// up to but excluding `p3`, as `curves::bezier::evaluate_segment`.
pub fn bezier_segment(p0: V3, p1: V3, p2: V3, p3: V3, dst: &mut [V3]) {
    let inv = 1.0 / dst.len() as f32;
    let inv2 = inv * inv;
    let inv3 = inv2 * inv;
    let rt1 = scale(scale(sub(p1, p0), 3.0), inv);
    let rt2 = scale(scale(add(sub(p0, scale(p1, 2.0)), p2), 3.0), inv2);
    let rt3 = scale(add(sub(p3, p0), scale(sub(p1, p2), 3.0)), inv3);
    let mut q0 = p0;
    let mut q1 = add(add(rt1, rt2), rt3);
    let mut q2 = add(scale(rt2, 2.0), scale(rt3, 6.0));
    let q3 = scale(rt3, 6.0);
    for d in dst.iter_mut() {
        *d = q0;
        q0 = add(q0, q1);
        q1 = add(q1, q2);
        q2 = add(q2, q3);
    }
}

/// Accumulated segment lengths of one evaluated curve (`segments` entries).
pub fn accumulated_lengths(p: &[V3], cyclic: bool) -> Vec<f32> {
    let mut out = Vec::with_capacity(p.len());
    let mut len = 0.0f32;
    for i in 0..p.len().saturating_sub(1) {
        len += length(sub(p[i + 1], p[i]));
        out.push(len);
    }
    if cyclic && p.len() > 1 {
        len += length(sub(p[0], p[p.len() - 1]));
        out.push(len);
    }
    out
}

fn almost_equal_relative(a: V3, b: V3, eps: f32) -> bool {
    // Relative to `a` only, as Blender's `math::almost_equal_relative`.
    (0..3).all(|k| (a[k] - b[k]).abs() <= eps * a[k].abs())
}

fn direction_bisect(prev: V3, mid: V3, next: V3) -> V3 {
    let eps = 1e-6;
    let pe = almost_equal_relative(prev, mid, eps);
    let ne = almost_equal_relative(mid, next, eps);
    if pe && ne {
        return [0.0, 0.0, 0.0];
    }
    if pe {
        return normalize(sub(next, mid));
    }
    if ne {
        return normalize(sub(mid, prev));
    }
    let dp = normalize(sub(mid, prev));
    let dn = normalize(sub(next, mid));
    normalize(add(dp, dn))
}

/// Tangents of one evaluated poly line (`curves::poly::calculate_tangents`).
pub fn tangents(p: &[V3], cyclic: bool) -> Vec<V3> {
    let n = p.len();
    if n == 1 {
        return vec![[0.0, 0.0, 1.0]];
    }
    let mut t = vec![[0.0f32; 3]; n];
    for i in 1..n.saturating_sub(1) {
        t[i] = direction_bisect(p[i - 1], p[i], p[i + 1]);
    }
    if n == 0 {
        return t;
    }
    if cyclic {
        t[0] = direction_bisect(p[n - 1], p[0], p[1]);
        t[n - 1] = direction_bisect(p[n - 2], p[n - 1], p[0]);
    } else {
        t[0] = normalize(sub(p[1], p[0]));
        t[n - 1] = normalize(sub(p[n - 1], p[n - 2]));
    }
    t
}

fn rotate_around_axis(d: V3, axis: V3, angle: f32) -> V3 {
    let axis_scaled = scale(axis, dot(d, axis));
    let diff = sub(d, axis_scaled);
    let c = cross(axis, diff);
    add(
        add(axis_scaled, scale(diff, angle.cos())),
        scale(c, angle.sin()),
    )
}

fn z_up_normal(t: V3) -> V3 {
    if t[0].abs() + t[1].abs() < 1e-4 {
        [1.0, 0.0, 0.0]
    } else {
        normalize([t[1], -t[0], 0.0])
    }
}

fn angle_normalized(a: V3, b: V3) -> f32 {
    // Blender's `angle_normalized_v3v3`: stable for small and near-opposite angles.
    if dot(a, b) >= 0.0 {
        2.0 * (length(sub(b, a)) / 2.0).clamp(-1.0, 1.0).asin()
    } else {
        std::f32::consts::PI - 2.0 * (length(add(a, b)) / 2.0).clamp(-1.0, 1.0).asin()
    }
}

fn next_normal(last_normal: V3, last_tangent: V3, tangent: V3) -> V3 {
    if last_tangent == [0.0; 3] || tangent == [0.0; 3] {
        return last_normal;
    }
    let angle = angle_normalized(last_tangent, tangent);
    if angle != 0.0 {
        let axis = normalize(cross(last_tangent, tangent));
        return normalize(rotate_around_axis(last_normal, axis, angle));
    }
    last_normal
}

fn angle_signed_on_axis(v1: V3, v2: V3, axis: V3) -> f32 {
    // Blender's `angle_signed_on_axis_v3v3_v3`: both vectors projected on the plane.
    let p1 = sub(v1, scale(axis, dot(v1, axis)));
    let p2 = sub(v2, scale(axis, dot(v2, axis)));
    let mut angle = angle_normalized(normalize(p1), normalize(p2));
    let tproj = cross(p2, p1);
    if dot(tproj, axis) < 0.0 {
        angle = 2.0 * std::f32::consts::PI - angle;
    }
    angle
}

/// Normals of one evaluated curve: minimum twist or Z up, then rotated by tilt.
pub fn normals(tangents: &[V3], cyclic: bool, mode: i8, tilts: &[f32]) -> Vec<V3> {
    let n = tangents.len();
    let mut out = vec![[0.0f32; 3]; n];
    if n == 0 {
        return out;
    }
    if mode == NORMAL_MODE_Z_UP {
        for i in 0..n {
            out[i] = z_up_normal(tangents[i]);
        }
    } else {
        out[0] = z_up_normal(tangents[0]);
        for i in 1..n {
            out[i] = next_normal(out[i - 1], tangents[i - 1], tangents[i]);
        }
        if cyclic {
            let uncorrected = next_normal(out[n - 1], tangents[n - 1], tangents[0]);
            let mut correction = angle_signed_on_axis(out[0], uncorrected, tangents[0]);
            if correction > std::f32::consts::PI {
                correction -= 2.0 * std::f32::consts::PI;
            }
            let step = correction / n as f32;
            for i in 0..n {
                out[i] = rotate_around_axis(out[i], tangents[i], step * i as f32);
            }
        }
    }
    for i in 0..n {
        if tilts[i] != 0.0 {
            out[i] = rotate_around_axis(out[i], tangents[i], tilts[i]);
        }
    }
    out
}

/// Radius / tilt style float attribute of the control points (default when absent).
pub fn point_floats(c: &Curves, name: &str, default: f32) -> Vec<f32> {
    point_float(c, name, default)
}

/// Per control point, the evaluated normal where it lies (`curve_normal_point_domain`):
/// poly points their own, Bezier points their segment's first evaluated point.
pub fn control_point_normals(c: &Curves) -> Result<Vec<V3>, String> {
    let ev = Evaluated::new(c)?;
    let pos = ev.positions(c);
    let tangents = ev.tangents(c, &pos);
    let normals = ev.normals(c, &tangents);
    let mut out = vec![[0.0f32; 3]; c.point_count()];
    for i in 0..c.curve_count() {
        let r = ev.range(i);
        for (k, p) in c.points(i).enumerate() {
            if let Some(n) = normals.get(r.start + ev.control_point_evaluated(i, k)) {
                out[p] = *n;
            }
        }
    }
    Ok(out)
}
