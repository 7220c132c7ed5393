//! Trim Curve (`node_geo_curve_trim`, `geometry::trim_curves`): each selected curve cut
//! to the part between Start and End (factors of, or lengths along, its evaluated
//! length). The cut points are looked up on the evaluated curve and mapped back to a
//! control-point segment and parameter; poly curves mix the two control points linearly,
//! Bezier curves are split by de Casteljau so the shape stays; every other point
//! attribute mixes linearly at the segment parameter. On an open curve End before Start
//! gives one point; on a cyclic curve the trim wraps past the seam, and equal ends cut the
//! loop open there. Trimmed curves are no longer cyclic.
//!
//!
//! The cut points of NURBS and Catmull-Rom curves are found on their evaluated points.
//! NURBS curves become poly curves of their evaluated points (attributes evaluated by the
//! basis); Catmull-Rom curves stay Catmull-Rom: their control points are kept and the
//! ends inserted on the cubic (positions and every point attribute mixed by it).

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curve_eval::{
    accumulated_lengths, bezier_segment, catmull_rom_array, catmull_rom_sample, curve_types,
    lerp_gather,
};
use super::super::curves::{
    Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_CATMULL_ROM, CURVE_TYPE_NURBS, CURVE_TYPE_POLY,
};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::limits;
use super::super::math::V3;
use super::super::nurbs::Basis;
use super::super::types::{Array, DataType, Domain};
use super::curve::sample_at_length;
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

const HANDLE_VECTOR: i8 = 2;

/// A point on a curve: between control (or evaluated) points `index` and `next` at
/// `param` in [0, 1] (`bke::curves::CurvePoint`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct CurvePoint {
    index: usize,
    next: usize,
    param: f32,
}

impl CurvePoint {
    fn is_control_point(&self) -> bool {
        self.param == 0.0 || self.param == 1.0
    }
    /// Whether `self` comes before `other`; the cyclic closing segment counts as first.
    fn before(&self, other: &CurvePoint) -> bool {
        if self.index == other.index {
            return self.param < other.param;
        }
        self.next < other.next
            && !(self.next == other.index && self.param == 1.0 && other.param == 0.0)
    }
}

/// `bke::curves::IndexRangeCyclic`: [start, end) over `size` elements, passing the end of
/// the array `cycles` times.
#[derive(Clone, Copy, Debug, Default)]
struct CyclicRange {
    start: usize,
    end: usize,
    size: usize,
    cycles: usize,
}

impl CyclicRange {
    fn from_size(start: usize, count: usize, size: usize) -> CyclicRange {
        let until_loop = size - start;
        if count < until_loop {
            return CyclicRange {
                start,
                end: start + count,
                size,
                cycles: 0,
            };
        }
        let remaining = count - until_loop;
        let full = remaining / size;
        CyclicRange {
            start,
            end: remaining - full * size,
            size,
            cycles: full + 1,
        }
    }

    /// The control points within [start, end], including either end on a control point.
    fn between(start: CurvePoint, end: CurvePoint, size: usize) -> CyclicRange {
        let s = if start.param == 0.0 {
            start.index
        } else {
            start.next
        };
        let mut e = if end.param == 0.0 {
            end.index
        } else {
            end.next
        };
        let cycles = if end.is_control_point() {
            e += 1;
            if e == size {
                e = 0;
            }
            e <= s
        } else {
            end.before(&start) || e < s
        };
        CyclicRange {
            start: s,
            end: e,
            size,
            cycles: cycles as usize,
        }
    }

    fn push_loop(self) -> CyclicRange {
        CyclicRange {
            cycles: self.cycles + 1,
            ..self
        }
    }

    /// The indices Blender copies for the range: up to the array's end and from its start
    /// when it cycles, else start..end.
    fn copied(&self) -> Vec<usize> {
        if self.cycles > 0 {
            (self.start..self.size).chain(0..self.end).collect()
        } else {
            (self.start..self.end.max(self.start)).collect()
        }
    }
}

/// One curve's trim: where it starts and ends, the copied control points between, and
/// the resulting point count.
struct Trim {
    start: CurvePoint,
    end: CurvePoint,
    range: CyclicRange,
    count: usize,
}

/// Blender's de Casteljau split of a Bezier segment (`curves::bezier::insert`).
struct Insertion {
    handle_prev: V3,
    left_handle: V3,
    position: V3,
    right_handle: V3,
    handle_next: V3,
}

fn mix(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

fn insert(p0: V3, h0: V3, h1: V3, p1: V3, t: f32) -> Insertion {
    let center = mix(h0, h1, t);
    let handle_prev = mix(p0, h0, t);
    let handle_next = mix(h1, p1, t);
    let left_handle = mix(handle_prev, center, t);
    let right_handle = mix(center, handle_next, t);
    Insertion {
        handle_prev,
        left_handle,
        position: mix(left_handle, right_handle, t),
        right_handle,
        handle_next,
    }
}

/// A curve's control data (local to the curve).
struct Src<'a> {
    pos: &'a [V3],
    hl: &'a [V3],
    hr: &'a [V3],
    tl: &'a [i8],
    tr: &'a [i8],
}

/// Bezier evaluated point offsets per control point (`n + 1` entries) and evaluated
/// positions, as `curves::bezier::calculate_evaluated_offsets` / `evaluate_segment`.
fn bezier_evaluate(s: &Src, cyclic: bool, resolution: i32) -> (Vec<usize>, Vec<V3>) {
    let n = s.pos.len();
    let res = resolution.max(1) as usize;
    let mut offsets = Vec::with_capacity(n + 1);
    if n == 1 {
        return (vec![0, 1], vec![s.pos[0]]);
    }
    let mut acc = 0;
    for i in 0..n - 1 {
        offsets.push(acc);
        acc += if s.tr[i] == HANDLE_VECTOR && s.tl[i + 1] == HANDLE_VECTOR {
            1
        } else {
            res
        };
    }
    offsets.push(acc);
    // The closing segment of a cyclic curve, like any segment, is one point when both
    // its handles are vector handles; an open curve adds its last point.
    let closing_vector = s.tr[n - 1] == HANDLE_VECTOR && s.tl[0] == HANDLE_VECTOR;
    acc += if !cyclic || closing_vector { 1 } else { res };
    offsets.push(acc);
    let mut ev = vec![[0.0f32; 3]; acc];
    for i in 0..n {
        let seg = offsets[i]..offsets[i + 1];
        if i + 1 == n && !cyclic {
            ev[seg.start] = s.pos[i];
            continue;
        }
        let j = if i + 1 == n { 0 } else { i + 1 };
        bezier_segment(s.pos[i], s.hr[i], s.hl[j], s.pos[j], &mut ev[seg]);
    }
    (offsets, ev)
}

/// The curve point at `len` along accumulated `lengths` of `count` segments' ends, by
/// the evaluated point found (`lookup_point_polygonal` / `_uniform_spacing` / `_bezier`).
enum Lookup<'a> {
    Polygonal,
    Uniform(usize),
    Bezier(&'a [usize]),
}

fn lookup(
    how: &Lookup,
    lengths: &[f32],
    len: f32,
    cyclic: bool,
    points: usize,
    evaluated: usize,
) -> CurvePoint {
    let last = match how {
        Lookup::Polygonal => evaluated - 1,
        _ => points - 1,
    };
    if len <= 0.0 {
        return CurvePoint {
            index: 0,
            next: 1,
            param: 0.0,
        };
    }
    if len >= lengths[lengths.len() - 1] {
        return if cyclic {
            CurvePoint {
                index: last,
                next: 0,
                param: 1.0,
            }
        } else {
            CurvePoint {
                index: last - 1,
                next: last,
                param: 1.0,
            }
        };
    }
    let (ei, ef) = sample_at_length(lengths, len);
    match how {
        Lookup::Polygonal => CurvePoint {
            index: ei,
            next: if ei == last { 0 } else { ei + 1 },
            param: ef,
        },
        Lookup::Uniform(res) => {
            let index = ei / res;
            CurvePoint {
                index,
                next: if index == last { 0 } else { index + 1 },
                param: (ef + ei as f32) / *res as f32 - index as f32,
            }
        }
        Lookup::Bezier(offsets) => {
            let left = offsets.partition_point(|&o| o <= ei) - 1;
            let offset_in_segment = ef + (ei - offsets[left]) as f32;
            let seg = (offsets[left + 1] - offsets[left]) as f32;
            CurvePoint {
                index: left,
                next: if left == last { 0 } else { left + 1 },
                param: (offset_in_segment / seg).clamp(0.0, 1.0),
            }
        }
    }
}

/// `compute_curve_trim_parameters` for one curve.
#[allow(clippy::too_many_arguments)]
fn plan(
    how: &Lookup,
    lengths: &[f32],
    cyclic: bool,
    points: usize,
    evaluated: usize,
    start_in: f32,
    end_in: f32,
    factor_mode: bool,
) -> Trim {
    if points == 1 {
        let p = CurvePoint {
            index: 0,
            next: 0,
            param: 0.0,
        };
        return Trim {
            start: p,
            end: p,
            range: CyclicRange {
                start: 0,
                end: 0,
                size: 1,
                cycles: 1,
            },
            count: 1,
        };
    }
    let total = lengths[lengths.len() - 1];
    let clamp = |v: f32| {
        let l = if factor_mode { v * total } else { v };
        l.clamp(0.0, total)
    };
    let start_len = clamp(start_in);
    let (end_len, equal) = if cyclic {
        let e = clamp(end_in);
        let cs = if start_len == total { 0.0 } else { start_len };
        let ce = if e == total { 0.0 } else { e };
        (e, cs == ce)
    } else {
        let e = if end_in <= start_in {
            start_len
        } else {
            clamp(end_in)
        };
        (e, start_len == e)
    };
    let start = lookup(how, lengths, start_len, cyclic, points, evaluated);
    let size = evaluated_size(how, points, evaluated);
    if equal {
        if end_len <= start_len {
            let range = if start.is_control_point() {
                let i = if start.param == 1.0 {
                    start.next
                } else {
                    start.index
                };
                CyclicRange::from_size(i, 1, size)
            } else {
                CyclicRange::default()
            };
            return Trim {
                start,
                end: start,
                range,
                count: 1,
            };
        }
        // The whole loop, cut open at the start.
        let range = CyclicRange::between(start, start, size).push_loop();
        return Trim {
            start,
            end: start,
            range,
            count: 1 + !start.is_control_point() as usize + size,
        };
    }
    let end = lookup(how, lengths, end_len, cyclic, points, evaluated);
    let range = CyclicRange::between(start, end, size);
    let count =
        range_size(&range) + !start.is_control_point() as usize + !end.is_control_point() as usize;
    Trim {
        start,
        end,
        range,
        count,
    }
}

fn evaluated_size(how: &Lookup, points: usize, evaluated: usize) -> usize {
    match how {
        Lookup::Polygonal => evaluated,
        _ => points,
    }
}

/// `IndexRangeCyclic::size`.
fn range_size(r: &CyclicRange) -> usize {
    if r.cycles > 0 {
        r.size - r.start + r.end + (r.cycles - 1) * r.size
    } else {
        r.end.saturating_sub(r.start)
    }
}

/// The linear samples of one trimmed curve (`sample_interval_linear`): per new point, the
/// two source points (local) and the factor.
fn linear_samples(t: &Trim) -> Vec<(usize, usize, f32)> {
    let mut out = Vec::with_capacity(t.count);
    if !t.start.is_control_point() {
        out.push((t.start.index, t.start.next, t.start.param));
    }
    out.extend(t.range.copied().into_iter().map(|i| (i, i, 0.0)));
    if t.count == 1 {
        return out;
    }
    if !t.end.is_control_point() {
        out.push((t.end.index, t.end.next, t.end.param));
    }
    out
}

/// New positions, handles and handle types of one trimmed Bezier curve
/// (`sample_interval_bezier`).
#[allow(clippy::type_complexity)]
fn bezier_trim(s: &Src, t: &Trim) -> (Vec<V3>, Vec<V3>, Vec<V3>, Vec<i8>, Vec<i8>) {
    let (st, en) = (t.start, t.end);
    // Written by index as Blender does: the start's next handle may land in the end
    // point's slot before the end point itself is written.
    let n = t.count;
    let mut pos = vec![[0.0f32; 3]; n];
    let mut hl = vec![[0.0f32; 3]; n];
    let mut hr = vec![[0.0f32; 3]; n];
    let mut tl = vec![0i8; n];
    let mut tr = vec![0i8; n];
    let mut k = 0;
    let mut ins_start = None;
    if !st.is_control_point() {
        let ins = insert(
            s.pos[st.index],
            s.hr[st.index],
            s.hl[st.next],
            s.pos[st.next],
            st.param,
        );
        pos[0] = ins.position;
        hl[0] = ins.left_handle;
        hr[0] = ins.right_handle;
        tl[0] = s.tl[st.index];
        tr[0] = s.tr[st.index];
        ins_start = Some(ins);
        k = 1;
    }
    for i in t.range.copied() {
        pos[k] = s.pos[i];
        hl[k] = s.hl[i];
        hr[k] = s.hr[i];
        tl[k] = s.tl[i];
        tr[k] = s.tr[i];
        k += 1;
    }
    if n == 1 {
        return (pos, hl, hr, tl, tr);
    }
    if let Some(ins) = &ins_start {
        hl[1] = ins.handle_next;
    }
    let last = n - 1;
    let same_point_or_inside = |hl: &mut Vec<V3>, hr: &mut Vec<V3>, pos: &Vec<V3>| {
        if st.param == 0.0 {
            hl[0] = pos[0];
            hr[last] = pos[0];
        } else if st.param == 1.0 {
        } else if let Some(ins) = &ins_start {
            hr[last] = ins.handle_prev;
        }
    };
    if en.param == 0.0 {
        if en.index == st.index {
            same_point_or_inside(&mut hl, &mut hr, &pos);
        }
    } else if en.param == 1.0 {
        if en.next == st.index {
            same_point_or_inside(&mut hl, &mut hr, &pos);
        }
    } else {
        let p = k - 1;
        let end_ins = if st.index == en.index && st.param < 1.0 {
            match &ins_start {
                Some(ins) if st.param > en.param => {
                    let e = insert(
                        pos[p],
                        ins.handle_prev,
                        ins.left_handle,
                        ins.position,
                        en.param / st.param,
                    );
                    hl[0] = e.handle_next;
                    e
                }
                _ => {
                    let f = (en.param - st.param) / (1.0 - st.param);
                    let handle_next = match &ins_start {
                        Some(ins) if st.param != 0.0 => ins.handle_next,
                        _ => s.hl[en.next],
                    };
                    insert(pos[p], hr[p], handle_next, s.pos[en.next], f)
                }
            }
        } else {
            let e = insert(
                s.pos[en.index],
                s.hr[en.index],
                s.hl[en.next],
                s.pos[en.next],
                en.param,
            );
            if (st.param >= en.param && en.index == st.index)
                || (st.param == 0.0 && en.next == st.index)
            {
                hl[0] = e.handle_next;
            }
            e
        };
        hr[p] = end_ins.handle_prev;
        tr[p] = s.tl[en.index];
        pos[k] = end_ins.position;
        hl[k] = end_ins.left_handle;
        hr[k] = end_ins.right_handle;
        tl[k] = s.tl[en.next];
        tr[k] = s.tr[en.next];
    }
    (pos, hl, hr, tl, tr)
}

fn vectors(c: &Curves, name: &str) -> Vec<V3> {
    c.point_vectors(name).unwrap_or_else(|| c.positions.clone())
}

fn i8s(c: &Curves, name: &str) -> Vec<i8> {
    c.ints(name, Domain::Point, 0)
        .iter()
        .map(|v| *v as i8)
        .collect()
}

/// `geometry::trim_curves`: every curve's new points, then the attributes.
// Long because it follows Blender's trim_curves step by step: one plan per curve type
// (poly, Bezier, NURBS on evaluated points, unselected copies) feeding one set of samples
// that every point attribute, handle and weight is then built from.
fn trim_curves(
    c: &Curves,
    sel: &[bool],
    starts: &[f32],
    ends: &[f32],
    factor_mode: bool,
) -> Result<Curves, String> {
    let mut types = curve_types(c);
    let cyclic = c.cyclic();
    let res = c.ints("resolution", Domain::Curve, 12);
    let orders = c.ints("nurbs_order", Domain::Curve, 4);
    let knots_modes = c.ints("knots_mode", Domain::Curve, 0);
    let nurbs_weights = match c.attributes.named("nurbs_weight") {
        Some(a) if a.domain == Domain::Point => Some(a.data.as_float().into_owned()),
        _ => None,
    };
    let (hl, hr) = (vectors(c, "handle_left"), vectors(c, "handle_right"));
    let (tl, tr) = (i8s(c, "handle_type_left"), i8s(c, "handle_type_right"));
    let any_bezier = types.contains(&CURVE_TYPE_BEZIER);

    // Per new point: source point pair and factor for the linearly mixed attributes.
    let mut samples: Vec<(usize, usize, f32)> = Vec::with_capacity(c.point_count());
    let mut offsets = vec![0u32];
    let mut positions = Vec::with_capacity(c.point_count());
    let (mut new_hl, mut new_hr) = (Vec::new(), Vec::new());
    let (mut new_tl, mut new_tr) = (Vec::new(), Vec::new());
    // Selected NURBS curves are trimmed on their evaluated points: per curve its source
    // points and basis; their evaluated values follow the source points in the arrays the
    // samples index (from `c.point_count()` on).
    let mut evaluated: Vec<(std::ops::Range<usize>, Option<Basis>)> = Vec::new();
    let mut ext_len = c.point_count();
    // Points whose nurbs_weight Blender fills with 0 (trimmed curves).
    let mut trimmed_point = Vec::with_capacity(c.point_count());
    // Ends inserted on Catmull-Rom segments: new point, the four source points (previous,
    // start, end, next) and the parameter; their values are mixed by the cubic.
    let mut cubic: Vec<(usize, [usize; 4], f32)> = Vec::new();
    for i in 0..c.curve_count() {
        let pts = c.points(i);
        let base = pts.start;
        if !sel[i] || pts.is_empty() {
            samples.extend(pts.clone().map(|p| (p, p, 0.0)));
            positions.extend_from_slice(&c.positions[pts.clone()]);
            if any_bezier {
                new_hl.extend_from_slice(&hl[pts.clone()]);
                new_hr.extend_from_slice(&hr[pts.clone()]);
                new_tl.extend_from_slice(&tl[pts.clone()]);
                new_tr.extend_from_slice(&tr[pts.clone()]);
            }
            trimmed_point.extend(pts.clone().map(|_| false));
            offsets.push(positions.len() as u32);
            continue;
        }
        let n = pts.len();
        let src = Src {
            pos: &c.positions[pts.clone()],
            hl: &hl[pts.clone()],
            hr: &hr[pts.clone()],
            tl: &tl[pts.clone()],
            tr: &tr[pts.clone()],
        };
        let mut base = base;
        let mut nurbs_ev = None;
        let mut catmull_rom = false;
        let (trim, bezier) = match types[i] {
            CURVE_TYPE_POLY => {
                let lengths = accumulated_lengths(src.pos, cyclic[i]);
                let t = if n == 1 {
                    plan(&Lookup::Polygonal, &[], false, 1, 1, 0.0, 0.0, factor_mode)
                } else {
                    plan(
                        &Lookup::Polygonal,
                        &lengths,
                        cyclic[i],
                        n,
                        n,
                        starts[i],
                        ends[i],
                        factor_mode,
                    )
                };
                (t, false)
            }
            CURVE_TYPE_BEZIER => {
                limits::check(
                    limits::product(&[res[i].max(1) as u64, n as u64]),
                    &format!("curve {i}: its resolution"),
                )?;
                let (offs, ev) = bezier_evaluate(&src, cyclic[i], res[i]);
                let lengths = accumulated_lengths(&ev, cyclic[i]);
                let t = if n == 1 {
                    plan(&Lookup::Polygonal, &[], false, 1, 1, 0.0, 0.0, factor_mode)
                } else {
                    let segments = if cyclic[i] { n } else { n - 1 };
                    let vector =
                        ev.len() - !cyclic[i] as usize != segments * res[i].max(0) as usize;
                    let how = if vector {
                        Lookup::Bezier(&offs)
                    } else {
                        Lookup::Uniform(res[i].max(1) as usize)
                    };
                    plan(
                        &how,
                        &lengths,
                        cyclic[i],
                        n,
                        ev.len(),
                        starts[i],
                        ends[i],
                        factor_mode,
                    )
                };
                (t, true)
            }
            CURVE_TYPE_NURBS => {
                let weights = nurbs_weights.as_ref().map(|w| &w[pts.clone()]);
                let basis = Basis::new(n, orders[i], cyclic[i], res[i], knots_modes[i] as i8)
                    .map_err(|e| format!("curve {i}: {e}"))?;
                let ev = match &basis {
                    Some(b) => b.evaluate_vectors(src.pos, weights),
                    None => src.pos.to_vec(),
                };
                let m = ev.len();
                let t = if m == 1 {
                    plan(&Lookup::Polygonal, &[], false, 1, 1, 0.0, 0.0, factor_mode)
                } else {
                    let lengths = accumulated_lengths(&ev, cyclic[i]);
                    plan(
                        &Lookup::Polygonal,
                        &lengths,
                        cyclic[i],
                        m,
                        m,
                        starts[i],
                        ends[i],
                        factor_mode,
                    )
                };
                base = ext_len;
                ext_len += m;
                evaluated.push((pts.clone(), basis));
                // The trimmed curve is a poly curve of evaluated points.
                types[i] = CURVE_TYPE_POLY;
                nurbs_ev = Some(ev);
                (t, false)
            }
            CURVE_TYPE_CATMULL_ROM => {
                // Looked up on the evaluated points (uniform per segment), but the curve
                // stays Catmull-Rom: control points are kept and the ends inserted on the
                // cubic (`trim_catmull_rom_curves`).
                let r = res[i].max(1) as usize;
                limits::check(
                    limits::product(&[r as u64, n as u64]),
                    &format!("curve {i}: its resolution"),
                )?;
                let t = if n == 1 {
                    plan(&Lookup::Polygonal, &[], false, 1, 1, 0.0, 0.0, factor_mode)
                } else {
                    let ev = catmull_rom_array(&Array::Vector(src.pos.to_vec()), cyclic[i], r)
                        .map(|a| a.as_vector().into_owned())
                        .unwrap_or_default();
                    let lengths = accumulated_lengths(&ev, cyclic[i]);
                    plan(
                        &Lookup::Uniform(r),
                        &lengths,
                        cyclic[i],
                        n,
                        ev.len(),
                        starts[i],
                        ends[i],
                        factor_mode,
                    )
                };
                catmull_rom = true;
                (t, false)
            }
            t => return Err(format!("curve {i}: unknown curve type {t}")),
        };
        if trim.range.cycles > 1 || trim.range.copied().len() + 2 < trim.count {
            return Err(format!(
                "curve {i}: a cyclic curve cut open exactly at its last control point is not supported"
            ));
        }
        let lin = linear_samples(&trim);
        if lin.len() != trim.count {
            return Err(format!("curve {i}: trim sample count mismatch"));
        }
        samples.extend(lin.iter().map(|&(a, b, f)| (base + a, base + b, f)));
        trimmed_point.extend(lin.iter().map(|_| true));
        if bezier {
            let (p, l, r, a, b) = bezier_trim(&src, &trim);
            positions.extend(p);
            new_hl.extend(l);
            new_hr.extend(r);
            new_tl.extend(a);
            new_tr.extend(b);
        } else {
            let p = nurbs_ev.as_deref().unwrap_or(src.pos);
            if catmull_rom {
                let cyc = cyclic[i];
                let pa = Array::Vector(p.to_vec());
                for &(a, b, f) in &lin {
                    if a == b && f == 0.0 {
                        positions.push(p[a]);
                        continue;
                    }
                    // `interpolate_catmull_rom`: the neighbours, or the ends repeated.
                    let i0 = match a {
                        0 if cyc => n - 1,
                        0 => 0,
                        _ => a - 1,
                    };
                    let i3 = match b + 1 {
                        x if x == n && cyc => 0,
                        x if x == n => b,
                        x => x,
                    };
                    let idx = [i0, a, b, i3];
                    let v = catmull_rom_sample(&pa, idx, f);
                    cubic.push((positions.len(), idx.map(|k| k + base), f));
                    positions.push(v.map_or(p[a], |v| v.as_vector()));
                }
            } else {
                positions.extend(lin.iter().map(|&(a, b, f)| mix(p[a], p[b], f)));
            }
            if any_bezier {
                // Trimmed poly curves among Bezier ones get zero, free handles.
                new_hl.extend(lin.iter().map(|_| [0.0f32; 3]));
                new_hr.extend(lin.iter().map(|_| [0.0f32; 3]));
                new_tl.extend(lin.iter().map(|_| 0i8));
                new_tr.extend(lin.iter().map(|_| 0i8));
            }
        }
        offsets.push(positions.len() as u32);
    }

    let mut out = Curves {
        positions,
        curve_offsets: offsets,
        attributes: Default::default(),
        materials: c.materials.clone(),
    };
    let copies: Vec<usize> = samples.iter().map(|s| s.0).collect();
    let (mut mi, mut ma, mut mb, mut mf) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, &(a, b, f)) in samples.iter().enumerate() {
        if a != b || f != 0.0 {
            mi.push(k);
            ma.push(a);
            mb.push(b);
            mf.push(f);
        }
    }
    for a in c.attributes.iter() {
        match a.domain {
            Domain::Curve => out.attributes.0.push(a.clone()),
            Domain::Point => {
                let mut src_data = a.data.clone();
                if is_nurbs_skipped(a.id.name()) {
                    // Written below, not sampled: placeholders keep the indices valid.
                    for (range, basis) in &evaluated {
                        src_data.extend_default(basis.as_ref().map_or(range.len(), |b| b.len()));
                    }
                } else {
                    for (range, basis) in &evaluated {
                        let idx: Vec<usize> = range.clone().collect();
                        let part = a.data.gather(&idx);
                        let weights = nurbs_weights.as_ref().map(|w| &w[range.clone()]);
                        let ev = match basis {
                            Some(b) => b.evaluate(&part, weights).ok_or_else(|| {
                                format!(
                                    "attribute {:?} of a NURBS curve: its type cannot be evaluated",
                                    a.id.label()
                                )
                            })?,
                            None => part,
                        };
                        src_data.extend(&ev);
                    }
                }
                let a = &super::super::attribute::Attribute {
                    id: a.id.clone(),
                    domain: a.domain,
                    data: src_data,
                };
                let data = match a.id.name() {
                    Some("handle_left") => Array::Vector(new_hl.clone()),
                    Some("handle_right") => Array::Vector(new_hr.clone()),
                    Some("handle_type_left") => Array::Int8(new_tl.clone()),
                    Some("handle_type_right") => Array::Int8(new_tr.clone()),
                    Some("nurbs_weight") => {
                        let mut d = a.data.gather(&copies);
                        let w = d.as_float().into_owned();
                        let w = w
                            .iter()
                            .zip(&trimmed_point)
                            .map(|(w, t)| if *t { 0.0 } else { *w })
                            .collect();
                        d = Array::Float(w);
                        d
                    }
                    _ => {
                        let mut d = a.data.gather(&copies);
                        d.scatter(&mi, &lerp_gather(&a.data, &ma, &mb, &mf));
                        for &(k, idx, f) in &cubic {
                            let v = catmull_rom_sample(&a.data, idx, f).ok_or_else(|| {
                                format!(
                                    "attribute {:?} of a Catmull-Rom curve: its type cannot be mixed",
                                    a.id.label()
                                )
                            })?;
                            d.set(k, v);
                        }
                        d
                    }
                };
                out.attributes.set(a.id.clone(), Domain::Point, data);
            }
            _ => {}
        }
    }
    // Handles that were absent (implicit) still need writing when Bezier curves exist.
    if any_bezier {
        for (name, data) in [
            ("handle_left", Array::Vector(new_hl)),
            ("handle_right", Array::Vector(new_hr)),
            ("handle_type_left", Array::Int8(new_tl)),
            ("handle_type_right", Array::Int8(new_tr)),
        ] {
            if out.attributes.named(name).is_none() {
                out.attributes.set(AttrId::named(name), Domain::Point, data);
            }
        }
    }
    if !evaluated.is_empty() {
        out.attributes.set(
            AttrId::named("curve_type"),
            Domain::Curve,
            Array::Int8(types.clone()),
        );
    }
    if sel.iter().all(|s| *s) {
        out.attributes.remove(&AttrId::named("cyclic"));
    } else if let Some(a) = out.attributes.named("cyclic") {
        let mut cy = a.data.as_bool().into_owned();
        for (v, s) in cy.iter_mut().zip(sel) {
            if *s {
                *v = false;
            }
        }
        out.attributes
            .set(AttrId::named("cyclic"), Domain::Curve, Array::Bool(cy));
    }
    remove_attributes_based_on_types(&mut out);
    Ok(out)
}

/// Point built-ins Trim Curve writes itself rather than sampling.
fn is_nurbs_skipped(name: Option<&str>) -> bool {
    matches!(
        name,
        Some(
            "handle_left"
                | "handle_right"
                | "handle_type_left"
                | "handle_type_right"
                | "nurbs_weight"
        )
    )
}

/// `CurvesGeometry::remove_attributes_based_on_types`.
fn remove_attributes_based_on_types(c: &mut Curves) {
    let types = curve_types(c);
    let mut drop = Vec::new();
    if !types.contains(&CURVE_TYPE_BEZIER) {
        drop.extend([
            "handle_type_left",
            "handle_type_right",
            "handle_left",
            "handle_right",
        ]);
    }
    if !types.contains(&CURVE_TYPE_NURBS) {
        drop.extend(["nurbs_weight", "nurbs_order", "knots_mode"]);
    }
    if types.iter().all(|t| *t == CURVE_TYPE_POLY) {
        drop.push("resolution");
    }
    for n in drop {
        c.attributes.remove(&AttrId::named(n));
    }
}

pub fn trim_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let factor_mode = match ctx.prop_str("mode")? {
        "FACTOR" => true,
        "LENGTH" => false,
        other => return Err(ctx.err(format!("mode {other:?} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let (s, e) = if factor_mode {
        ("Start", "End")
    } else {
        ("Start_001", "End_001")
    };
    let start = ctx.field(s, DataType::Float)?;
    let end = ctx.field(e, DataType::Float)?;
    modify_geometry_sets(&mut g, &mut |set| {
        let Some(c) = set.curves.clone() else {
            return Ok(());
        };
        if c.curve_count() == 0 {
            return Ok(());
        }
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Curve,
            &[
                (&sel, DataType::Bool),
                (&start, DataType::Float),
                (&end, DataType::Float),
            ],
        )?;
        let sel = r[0].as_bool();
        if !sel.iter().any(|s| *s) {
            return Ok(());
        }
        let out = trim_curves(&c, &sel, &r[1].as_float(), &r[2].as_float(), factor_mode)?;
        set.curves = Some(Arc::new(out));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}
