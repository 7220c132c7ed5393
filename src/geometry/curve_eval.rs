//! Evaluated curves as Blender computes them (`bke::curves` and `curves::poly`,
//! `curves::bezier`): evaluated points per curve (Bezier segments by forward differencing
//! at the curve's resolution, poly points as they are), attributes interpolated to the
//! evaluated points, segment lengths, tangents, and minimum-twist / Z-up / free (custom)
//! normals with tilt.
//!
//! Catmull-Rom curves by their uniform cubic basis (`curves::catmull_rom`), NURBS by their
//! basis (`nurbs.rs`); NURBS control points are not on the curve, so per-control-point
//! values (normals, tangents, lengths) treat them as a poly curve, as Blender does.

use super::curves::{
    Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_CATMULL_ROM, CURVE_TYPE_NURBS, CURVE_TYPE_POLY,
};
use super::math::{add, cross, dot, length, normalize, scale, sub, V3};
use super::nurbs::Basis;
use super::types::{Array, DataType, Domain, Value};
use crate::anim::qslerp;

/// Blender's `NormalMode` values as stored in the `normal_mode` curve attribute.
pub const NORMAL_MODE_MINIMUM_TWIST: i8 = 0;
pub const NORMAL_MODE_Z_UP: i8 = 1;
/// Free: the `custom_normal` point attribute, interpolated to the evaluated points.
pub const NORMAL_MODE_FREE: i8 = 2;

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

/// How one curve's evaluated points come from its control points.
enum Kind {
    Poly,
    /// Per control point, the offset of its segment's first evaluated point within the
    /// curve (`n + 1` entries: point order plus one).
    Bezier(Vec<u32>),
    /// Evaluated points per segment (the curve's resolution).
    CatmullRom(usize),
    /// The curve's basis, or `None` when it evaluates to its control points.
    Nurbs(Option<Basis>),
}

/// Per-curve facts needed to evaluate: evaluated point offsets and how each curve's
/// evaluated points are made.
pub struct Evaluated {
    pub offsets: Vec<u32>,
    pub cyclic: Vec<bool>,
    kinds: Vec<Kind>,
    /// The `nurbs_weight` point attribute, when there is one (rational NURBS).
    nurbs_weights: Option<Vec<f32>>,
}

impl Evaluated {
    pub fn new(c: &Curves) -> Result<Evaluated, String> {
        let types = curve_types(c);
        let cyclic = cyclic(c);
        let res = resolutions(c);
        let hl = point_i8(c, "handle_type_left");
        let hr = point_i8(c, "handle_type_right");
        let (mut orders, mut knots_modes) = (Vec::new(), Vec::new());
        if types.contains(&CURVE_TYPE_NURBS) {
            orders = c.ints("nurbs_order", Domain::Curve, 4);
            knots_modes = c.ints("knots_mode", Domain::Curve, 0);
        }
        let mut offsets = vec![0u32];
        let mut kinds = Vec::with_capacity(c.curve_count());
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            let n = pts.len();
            let (kind, count) = match types[i] {
                CURVE_TYPE_POLY => (Kind::Poly, n),
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
                    let count = if n == 0 { 0 } else { acc as usize };
                    (Kind::Bezier(offs), count)
                }
                CURVE_TYPE_CATMULL_ROM => {
                    // Checked before allocating: a hostile resolution is an error.
                    let r = res[i].max(1) as usize;
                    let segments = if cyclic[i] { n } else { n.saturating_sub(1) };
                    super::limits::check(
                        super::limits::product(&[r as u64, segments as u64]),
                        "the Catmull-Rom curve's resolution",
                    )?;
                    (Kind::CatmullRom(r), catmull_rom_count(n, cyclic[i], r))
                }
                CURVE_TYPE_NURBS => {
                    let basis = Basis::new(n, orders[i], cyclic[i], res[i], knots_modes[i] as i8)
                        .map_err(|e| format!("curve {i}: {e}"))?;
                    let count = basis.as_ref().map_or(n, |b| b.len());
                    (Kind::Nurbs(basis), count)
                }
                t => {
                    return Err(format!(
                        "curve {i}: curve type {} is not supported",
                        type_name(t)
                    ))
                }
            };
            kinds.push(kind);
            offsets.push(offsets[i] + count as u32);
        }
        let nurbs_weights = match c.attributes.named("nurbs_weight") {
            Some(a) if a.domain == Domain::Point && types.contains(&CURVE_TYPE_NURBS) => {
                Some(a.data.as_float().into_owned())
            }
            _ => None,
        };
        Ok(Evaluated {
            offsets,
            cyclic,
            kinds,
            nurbs_weights,
        })
    }

    /// The evaluated point (within curve `i`) where control point `p` (within the curve)
    /// lies; `None` for NURBS curves, whose control points are not on the curve.
    pub fn control_point_evaluated(&self, i: usize, p: usize) -> Option<usize> {
        match &self.kinds[i] {
            Kind::Poly => Some(p),
            Kind::Bezier(offs) => Some(offs[p] as usize),
            Kind::CatmullRom(r) => Some(r * p),
            Kind::Nurbs(_) => None,
        }
    }

    pub fn is_nurbs(&self, i: usize) -> bool {
        matches!(self.kinds[i], Kind::Nurbs(_))
    }

    pub fn total(&self) -> usize {
        *self.offsets.last().unwrap_or(&0) as usize
    }

    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    fn weights(&self, pts: std::ops::Range<usize>) -> Option<&[f32]> {
        self.nurbs_weights.as_deref().map(|w| &w[pts])
    }

    /// Evaluated positions of every curve, concatenated.
    pub fn positions(&self, c: &Curves) -> Vec<V3> {
        let mut out = vec![[0.0f32; 3]; self.total()];
        let hl = point_vec(c, "handle_left");
        let hr = point_vec(c, "handle_right");
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            let dst = &mut out[self.range(i)];
            match &self.kinds[i] {
                Kind::Bezier(offs) => {
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
                Kind::CatmullRom(r) => {
                    catmull_rom(&c.positions[pts], self.cyclic[i], *r, dst, &mix_vector)
                }
                Kind::Nurbs(Some(b)) => dst.copy_from_slice(
                    &b.evaluate_vectors(&c.positions[pts.clone()], self.weights(pts)),
                ),
                Kind::Poly | Kind::Nurbs(None) => dst.copy_from_slice(&c.positions[pts]),
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
            if matches!(self.kinds[i], Kind::Bezier(_))
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

    /// Evaluated normals of every curve (normal mode per curve, tilt interpolated), as
    /// `CurvesGeometry::evaluated_normals`: Free curves take `custom_normal` interpolated
    /// to their evaluated points and normalized (Z up without the attribute), then every
    /// mode is rotated by the tilt.
    pub fn normals(&self, c: &Curves, tangents_all: &[V3]) -> Result<Vec<V3>, String> {
        let tilt = match c.attributes.named("tilt") {
            Some(a) if a.domain == Domain::Point => {
                self.interpolate(c, &a.data)?.as_float().into_owned()
            }
            _ => vec![0.0; self.total()],
        };
        let modes = checked_normal_modes(c)?;
        let custom = match custom_normals(c) {
            Some(n) if modes.contains(&NORMAL_MODE_FREE) => Some(
                self.interpolate(c, &Array::Vector(n))?
                    .as_vector()
                    .into_owned(),
            ),
            _ => None,
        };
        let mut out = Vec::with_capacity(self.total());
        for i in 0..c.curve_count() {
            let r = self.range(i);
            let base = match (&custom, modes[i]) {
                (Some(n), NORMAL_MODE_FREE) => n[r.clone()].iter().map(|v| normalize(*v)).collect(),
                (None, NORMAL_MODE_FREE) => {
                    base_normals(&tangents_all[r.clone()], false, NORMAL_MODE_Z_UP)
                }
                (_, mode) => base_normals(&tangents_all[r.clone()], self.cyclic[i], mode),
            };
            out.extend(tilted(base, &tangents_all[r.clone()], &tilt[r]));
        }
        Ok(out)
    }

    /// A point-domain attribute interpolated to the evaluated points as Blender's
    /// `interpolate_to_evaluated` does per curve type: Bezier segments linearly, Catmull-Rom
    /// by its cubic basis, NURBS by the curve's basis (rational with `nurbs_weight`).
    pub fn interpolate(&self, c: &Curves, data: &Array) -> Result<Array, String> {
        let simple = self
            .kinds
            .iter()
            .all(|k| matches!(k, Kind::Poly | Kind::Bezier(_)));
        if simple {
            return Ok(self.interpolate_linear(c, data, 0..c.curve_count()));
        }
        let mut out = Array::zeros(data.data_type(), 0);
        for i in 0..c.curve_count() {
            let pts = c.points(i);
            let piece = match &self.kinds[i] {
                Kind::Poly | Kind::Bezier(_) => self.interpolate_linear(c, data, i..i + 1),
                Kind::CatmullRom(r) => {
                    catmull_rom_array(&data.gather(&pts.collect::<Vec<_>>()), self.cyclic[i], *r)
                        .ok_or_else(|| unmixable(data, "Catmull-Rom", i))?
                }
                Kind::Nurbs(None) => data.gather(&pts.collect::<Vec<_>>()),
                Kind::Nurbs(Some(b)) => b
                    .evaluate(
                        &data.gather(&pts.clone().collect::<Vec<_>>()),
                        self.weights(pts),
                    )
                    .ok_or_else(|| unmixable(data, "NURBS", i))?,
            };
            out.extend(&piece);
        }
        Ok(out)
    }

    /// Poly and Bezier curves `curves`: control values, or Bezier segments mixed linearly.
    fn interpolate_linear(
        &self,
        c: &Curves,
        data: &Array,
        curves: std::ops::Range<usize>,
    ) -> Array {
        let size = self.offsets[curves.end] as usize - self.offsets[curves.start] as usize;
        let mut idx_a = Vec::with_capacity(size);
        let mut idx_b = Vec::with_capacity(size);
        let mut fac = Vec::with_capacity(size);
        for i in curves {
            let pts = c.points(i);
            match &self.kinds[i] {
                Kind::Bezier(offs) => {
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

fn unmixable(data: &Array, kind: &str, i: usize) -> String {
    format!(
        "curve {i}: a {:?} attribute cannot be interpolated along a {kind} curve",
        data.data_type()
    )
}

/// The curves' normal modes, refusing values outside Blender's (its attribute validator
/// clamps them to Minimum Twist ..= Free).
fn checked_normal_modes(c: &Curves) -> Result<Vec<i8>, String> {
    let modes = normal_modes(c);
    if let Some(i) = modes
        .iter()
        .position(|m| !(NORMAL_MODE_MINIMUM_TWIST..=NORMAL_MODE_FREE).contains(m))
    {
        return Err(format!(
            "curve {i}: normal mode {} is not one of Blender's",
            modes[i]
        ));
    }
    Ok(modes)
}

/// The `custom_normal` point attribute Free curves read, when there is one.
fn custom_normals(c: &Curves) -> Option<Vec<V3>> {
    match c.attributes.named("custom_normal") {
        Some(a) if a.domain == Domain::Point && a.data.data_type() == DataType::Vector => {
            Some(a.data.as_vector().into_owned())
        }
        _ => None,
    }
}

/// `catmull_rom::calculate_evaluated_num`: `resolution` points per segment, plus the last
/// control point of an open curve (at least one point for a cyclic curve with points).
fn catmull_rom_count(points: usize, cyclic: bool, resolution: usize) -> usize {
    match (points, cyclic) {
        (0, _) => 0,
        (_, true) => (resolution * points).max(1),
        (_, false) => resolution * (points - 1) + 1,
    }
}

/// `catmull_rom::calculate_basis`: the uniform Catmull-Rom weights, twice their value.
fn catmull_rom_basis(t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    [
        -t * s * s,
        2.0 + t * t * (3.0 * t - 5.0),
        2.0 + s * s * (3.0 * s - 5.0),
        -s * t * t,
    ]
}

/// `catmull_rom::interpolate` for float vectors: mixed with the doubled weights, then
/// halved (Blender saves the multiplications so for float types).
fn mix_vector(v: [&V3; 4], t: f32) -> V3 {
    let w = catmull_rom_basis(t);
    let mut o = [0.0f32; 3];
    for k in 0..3 {
        o[k] = 0.5 * (w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k] + w[3] * v[3][k]);
    }
    o
}

/// `catmull_rom::interpolate_to_evaluated`: one curve's control values `src` to its
/// evaluated points `dst` at `resolution` points per segment.
fn catmull_rom<T: Copy>(
    src: &[T],
    cyclic: bool,
    resolution: usize,
    dst: &mut [T],
    mix: &dyn Fn([&T; 4], f32) -> T,
) {
    catmull_rom_segments(
        src,
        cyclic,
        &|s| s * resolution..(s + 1) * resolution,
        dst,
        mix,
    )
}

/// `catmull_rom::interpolate_to_evaluated` with segment `s` written to `range(s)` of
/// `dst`, segment by segment, the end segments of an open curve repeating the end points.
fn catmull_rom_segments<T: Copy>(
    src: &[T],
    cyclic: bool,
    range: &dyn Fn(usize) -> std::ops::Range<usize>,
    dst: &mut [T],
    mix: &dyn Fn([&T; 4], f32) -> T,
) {
    let n = src.len();
    if n == 0 || dst.is_empty() {
        return;
    }
    if n == 1 {
        dst[0] = src[0];
        return;
    }
    let segment = |a: &T, b: &T, c: &T, d: &T, out: &mut [T]| {
        let step = 1.0 / out.len() as f32;
        out[0] = *b;
        for (j, o) in out.iter_mut().enumerate().skip(1) {
            *o = mix([a, b, c, d], j as f32 * step);
        }
    };
    if n == 2 {
        segment(&src[0], &src[0], &src[1], &src[1], &mut dst[range(0)]);
        if cyclic {
            segment(&src[1], &src[1], &src[0], &src[0], &mut dst[range(1)]);
        } else {
            dst[dst.len() - 1] = src[1];
        }
        return;
    }
    if cyclic {
        segment(&src[n - 1], &src[0], &src[1], &src[2], &mut dst[range(0)]);
        segment(
            &src[n - 3],
            &src[n - 2],
            &src[n - 1],
            &src[0],
            &mut dst[range(n - 2)],
        );
        segment(
            &src[n - 2],
            &src[n - 1],
            &src[0],
            &src[1],
            &mut dst[range(n - 1)],
        );
    } else {
        segment(&src[0], &src[0], &src[1], &src[2], &mut dst[range(0)]);
        segment(
            &src[n - 3],
            &src[n - 2],
            &src[n - 1],
            &src[n - 1],
            &mut dst[range(n - 2)],
        );
        dst[dst.len() - 1] = src[n - 1];
    }
    for s in 1..n - 2 {
        segment(
            &src[s - 1],
            &src[s],
            &src[s + 1],
            &src[s + 2],
            &mut dst[range(s)],
        );
    }
}

/// One curve's control values on its Catmull-Rom evaluated points, mixed as Blender's
/// `mix4` mixes each type; `None` for types it does not mix here.
pub fn catmull_rom_array(src: &Array, cyclic: bool, resolution: usize) -> Option<Array> {
    let count = catmull_rom_count(src.len(), cyclic, resolution);
    catmull_rom_array_segments(src, cyclic, count, &|s| {
        s * resolution..(s + 1) * resolution
    })
}

/// `catmull_rom_array` with `count` points, segment `s` at `range(s)` (as Subdivide
/// Curve places its cuts).
pub fn catmull_rom_array_segments(
    src: &Array,
    cyclic: bool,
    count: usize,
    range: &dyn Fn(usize) -> std::ops::Range<usize>,
) -> Option<Array> {
    fn run<T: Copy + Default>(
        v: &[T],
        cyclic: bool,
        range: &dyn Fn(usize) -> std::ops::Range<usize>,
        count: usize,
        mix: &dyn Fn([&T; 4], f32) -> T,
    ) -> Vec<T> {
        let mut out = vec![T::default(); count];
        catmull_rom_segments(v, cyclic, range, &mut out, mix);
        out
    }
    // Types other than float, float2 and float3 mix with halved weights.
    let halved = |t: f32| catmull_rom_basis(t).map(|w| w * 0.5);
    Some(match src {
        Array::Float(v) => Array::Float(run(v, cyclic, range, count, &|x, t| {
            let w = catmull_rom_basis(t);
            0.5 * (w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3])
        })),
        Array::Float2(v) => Array::Float2(run(v, cyclic, range, count, &|x, t| {
            let w = catmull_rom_basis(t);
            [0, 1]
                .map(|k| 0.5 * (w[0] * x[0][k] + w[1] * x[1][k] + w[2] * x[2][k] + w[3] * x[3][k]))
        })),
        Array::Vector(v) => Array::Vector(run(v, cyclic, range, count, &mix_vector)),
        Array::Color(v) => Array::Color(run(v, cyclic, range, count, &|x, t| {
            let w = halved(t);
            [0, 1, 2, 3].map(|k| x[0][k] * w[0] + x[1][k] * w[1] + x[2][k] * w[2] + x[3][k] * w[3])
        })),
        Array::Int(v) => Array::Int(run(v, cyclic, range, count, &|x, t| {
            let w = halved(t);
            (w[0] * *x[0] as f32 + w[1] * *x[1] as f32 + w[2] * *x[2] as f32 + w[3] * *x[3] as f32)
                .round() as i32
        })),
        Array::Int8(v) => Array::Int8(run(v, cyclic, range, count, &|x, t| {
            let w = halved(t);
            (w[0] * *x[0] as f32 + w[1] * *x[1] as f32 + w[2] * *x[2] as f32 + w[3] * *x[3] as f32)
                .round() as i8
        })),
        Array::Bool(v) => Array::Bool(run(v, cyclic, range, count, &|x, t| {
            let w = halved(t);
            let f = |b: &bool| *b as u8 as f32;
            w[0] * f(x[0]) + w[1] * f(x[1]) + w[2] * f(x[2]) + w[3] * f(x[3]) >= 0.5
        })),
        _ => return None,
    })
}

/// `catmull_rom::interpolate` of the values at `idx` (previous, start, end, next) at `t`
/// (as Trim Curve inserts a point on a Catmull-Rom segment), mixed per type as
/// `catmull_rom_array` mixes them; `None` for types Blender's mixers do not take here.
pub fn catmull_rom_sample(src: &Array, idx: [usize; 4], t: f32) -> Option<Value> {
    let w = catmull_rom_basis(t);
    let h = w.map(|x| x * 0.5);
    Some(match src {
        Array::Float(v) => {
            let x = idx.map(|i| v[i]);
            Value::Float(0.5 * (w[0] * x[0] + w[1] * x[1] + w[2] * x[2] + w[3] * x[3]))
        }
        Array::Float2(v) => {
            let x = idx.map(|i| v[i]);
            Value::Float2(
                [0, 1].map(|k| {
                    0.5 * (w[0] * x[0][k] + w[1] * x[1][k] + w[2] * x[2][k] + w[3] * x[3][k])
                }),
            )
        }
        Array::Vector(v) => {
            let x = idx.map(|i| &v[i]);
            Value::Vector(mix_vector(x, t))
        }
        Array::Color(v) => {
            let x = idx.map(|i| v[i]);
            Value::Color(
                [0, 1, 2, 3]
                    .map(|k| x[0][k] * h[0] + x[1][k] * h[1] + x[2][k] * h[2] + x[3][k] * h[3]),
            )
        }
        Array::Int(v) => {
            let x = idx.map(|i| v[i] as f32);
            Value::Int((h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + h[3] * x[3]).round() as i32)
        }
        Array::Int8(v) => {
            let x = idx.map(|i| v[i] as f32);
            Value::Int8((h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + h[3] * x[3]).round() as i8)
        }
        Array::Bool(v) => {
            let x = idx.map(|i| v[i] as u8 as f32);
            Value::Bool(h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + h[3] * x[3] >= 0.5)
        }
        _ => return None,
    })
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

/// `data[a] * (1 - f) + data[b] * f` per output, for the numeric types; rotations by
/// Blender's slerp (others take `a`).
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
        Array::Quaternion(v) => Array::Quaternion(
            (0..a.len())
                // Blender's `mix2` for rotations: `interp_dot_slerp`'s weights, as the
                // animation system's quaternion interpolation.
                .map(|i| qslerp(v[a[i]], v[b[i]], f[i]))
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
    tilted(base_normals(tangents, cyclic, mode), tangents, tilts)
}

/// Minimum-twist or Z-up normals of one evaluated curve, before tilt
/// (`curves::poly::calculate_normals_minimum` / `calculate_normals_z_up`).
fn base_normals(tangents: &[V3], cyclic: bool, mode: i8) -> Vec<V3> {
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
    out
}

/// `normals` rotated about the tangents by the tilts (`rotate_directions_around_axes`).
fn tilted(mut normals: Vec<V3>, tangents: &[V3], tilts: &[f32]) -> Vec<V3> {
    for i in 0..normals.len() {
        if tilts[i] != 0.0 {
            normals[i] = rotate_around_axis(normals[i], tangents[i], tilts[i]);
        }
    }
    normals
}

/// Radius / tilt style float attribute of the control points (default when absent).
pub fn point_floats(c: &Curves, name: &str, default: f32) -> Vec<f32> {
    point_float(c, name, default)
}

/// Per control point, the evaluated normal where it lies (`curve_normal_point_domain`):
/// poly points their own, Bezier and Catmull-Rom points the evaluated point where they
/// lie; NURBS control points, not on the curve, the normals of their control polygon
/// taken as a poly curve (without tilt, as Blender does), or for Free curves their
/// `custom_normal` as stored ((0, 0, 1) without it).
pub fn control_point_normals(c: &Curves) -> Result<Vec<V3>, String> {
    let ev = Evaluated::new(c)?;
    let pos = ev.positions(c);
    let tangents_all = ev.tangents(c, &pos);
    let normals_all = ev.normals(c, &tangents_all)?;
    let modes = normal_modes(c);
    let custom = custom_normals(c);
    let mut out = vec![[0.0f32; 3]; c.point_count()];
    for i in 0..c.curve_count() {
        let r = ev.range(i);
        let pts = c.points(i);
        if ev.is_nurbs(i) && modes[i] == NORMAL_MODE_FREE {
            for p in pts {
                out[p] = custom.as_ref().map_or([0.0, 0.0, 1.0], |n| n[p]);
            }
            continue;
        }
        if ev.is_nurbs(i) {
            let t = tangents(&c.positions[pts.clone()], ev.cyclic[i]);
            let zero = vec![0.0; t.len()];
            out[pts].copy_from_slice(&normals(&t, ev.cyclic[i], modes[i], &zero));
            continue;
        }
        for (k, p) in pts.enumerate() {
            if let Some(n) = ev
                .control_point_evaluated(i, k)
                .and_then(|e| normals_all.get(r.start + e))
            {
                out[p] = *n;
            }
        }
    }
    Ok(out)
}
