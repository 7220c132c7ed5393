//! A curve's animation path, as Blender builds it for Follow Path and curve parenting:
//! every spline is turned into a "bevel list" of points (Bezier segments by forward
//! differencing at the spline's resolution, NURBS by their basis functions, poly as is),
//! with tilt and radius interpolated and an orientation quaternion per point (twist mode,
//! smoothing, tilt), duplicates removed; the path is the first list plus its cumulative
//! lengths (`curve.cc` `BKE_curve_bevelList_make`, `anim_path.cc`).
//!
//! Single precision on purpose: Blender sums segment lengths in `float`, and a path
//! position depends on that sum, so doing the same operations in the same order is what
//! keeps us within 1e-5 of Blender on long paths.

use super::error::AnimError;
use super::math::*;
use crate::scene::{Curve, Spline};

/// Blender's `DEG2RADF(90.0f)`.
const DEG90: f32 = 90.0 * (std::f64::consts::PI / 180.0) as f32;

#[derive(Debug, Clone, Copy, Default)]
struct BevPoint {
    vec: Vec3,
    tan: Vec3,
    quat: Quat,
    dir: Vec3,
    tilt: f32,
    radius: f32,
    offset: f32,
    dupe: bool,
}

#[derive(Debug, Clone, Default)]
struct BevList {
    p: Vec<BevPoint>,
    cyclic: bool,
    /// Per-list copy of whether Blender allocated segment lengths for it.
    has_seglen: bool,
    hole: bool,
}

/// The animation path of a curve (its first spline), ready for `where_on_path`.
#[derive(Debug, Clone)]
pub struct Path {
    points: Vec<BevPoint>,
    cyclic: bool,
    accum: Vec<f32>,
}

/// A point on the path in the curve object's space.
#[derive(Debug, Clone, Copy)]
pub struct PathSample {
    pub pos: Vec3,
    pub quat: Quat,
    pub radius: f32,
}

/// Curve-level settings that shape the path.
struct CurveSettings {
    is_3d: bool,
    do_radius: bool,
    twist_mode: TwistMode,
    twist_smooth: f32,
    need_seglen: bool,
    render_resolution: u32,
}

#[derive(Clone, Copy, PartialEq)]
enum TwistMode {
    ZUp,
    Minimum,
    Tangent,
}

fn rna_f(c: &Curve, key: &str, default: f64) -> f64 {
    c.properties
        .get(key)
        .and_then(|v| v.as_f64())
        .unwrap_or(default)
}
fn rna_s<'a>(c: &'a Curve, key: &str, default: &'a str) -> &'a str {
    c.properties
        .get(key)
        .and_then(|v| v.as_str())
        .unwrap_or(default)
}
fn rna_b(c: &Curve, key: &str) -> bool {
    c.properties
        .get(key)
        .and_then(|v| v.as_bool())
        .unwrap_or(false)
}

fn settings(c: &Curve) -> Result<CurveSettings, AnimError> {
    let is_3d = match rna_s(c, "dimensions", "3D") {
        "3D" => true,
        "2D" => false,
        other => {
            return Err(AnimError::new(
                "properties.dimensions",
                format!("unknown dimensions {other:?}"),
            ))
        }
    };
    let twist_mode = match rna_s(c, "twist_mode", "MINIMUM") {
        "Z_UP" => TwistMode::ZUp,
        "MINIMUM" => TwistMode::Minimum,
        "TANGENT" => TwistMode::Tangent,
        other => {
            return Err(AnimError::new(
                "properties.twist_mode",
                format!("unknown twist mode {other:?}"),
            ))
        }
    };
    let has_bevel_object = c
        .properties
        .get("bevel_object")
        .is_some_and(|v| !v.is_null());
    // Blender's CU_DO_RADIUS: radius is only interpolated when something uses it.
    let do_radius = rna_b(c, "use_radius")
        || is_3d
        || has_bevel_object
        || rna_f(c, "extrude", 0.0) != 0.0
        || rna_f(c, "bevel_depth", 0.0) != 0.0;
    let maps_segments = |k: &str| matches!(rna_s(c, k, "RESOLUTION"), "SEGMENTS" | "SPLINE");
    Ok(CurveSettings {
        is_3d,
        do_radius,
        twist_mode,
        twist_smooth: rna_f(c, "twist_smooth", 0.0) as f32,
        need_seglen: maps_segments("bevel_factor_mapping_start")
            || maps_segments("bevel_factor_mapping_end"),
        render_resolution: rna_f(c, "render_resolution_u", 0.0).max(0.0) as u32,
    })
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum NurbType {
    Poly,
    Bezier,
    Nurbs,
}

fn nurb_type(s: &Spline) -> Result<NurbType, AnimError> {
    Ok(match s.kind.as_str() {
        "POLY" => NurbType::Poly,
        "BEZIER" => NurbType::Bezier,
        "NURBS" => NurbType::Nurbs,
        other => {
            return Err(AnimError::new(
                "type",
                format!("unknown spline type {other:?}"),
            ))
        }
    })
}

fn point_count(s: &Spline, t: NurbType) -> usize {
    if t == NurbType::Bezier {
        s.bezier_points.len()
    } else {
        s.points.len()
    }
}

/// Blender's `nurb_check_valid` for the U direction.
fn valid(s: &Spline, t: NurbType) -> bool {
    let pnts = point_count(s, t) as i32;
    if pnts <= 1 {
        return false;
    }
    if t == NurbType::Nurbs {
        let order = s.order_u as i32;
        if pnts < order {
            return false;
        }
        if s.use_bezier_u {
            let needed = if s.use_cyclic_u {
                let rem = pnts % (order - 1);
                if rem > 0 {
                    order - 1 - rem
                } else {
                    0
                }
            } else if !s.use_endpoint_u && pnts <= order {
                order + 1 - pnts
            } else {
                0
            };
            if needed != 0 {
                return false;
            }
        }
    }
    true
}

fn segments(s: &Spline, t: NurbType) -> usize {
    let n = point_count(s, t);
    if s.use_cyclic_u {
        n
    } else {
        n - 1
    }
}

/// Blender's `key_curve_position_weights` for the spline tilt/radius interpolations.
#[allow(clippy::excessive_precision)] // Blender's literals, rounded to f32 as in C.
fn position_weights(t: f32, kind: i32) -> [f32; 4] {
    match kind {
        1 => {
            let (t2, t3, fc) = (t * t, t * t * t, 0.71f32);
            [
                -fc * t3 + 2.0 * fc * t2 - fc * t,
                (2.0 - fc) * t3 + (fc - 3.0) * t2 + 1.0,
                (fc - 2.0) * t3 + (3.0 - 2.0 * fc) * t2 + fc * t,
                fc * t3 - fc * t2,
            ]
        }
        2 => {
            let (t2, t3) = (t * t, t * t * t);
            [
                -0.16666666 * t3 + 0.5 * t2 - 0.5 * t + 0.16666666,
                0.5 * t3 - t2 + 0.66666666,
                -0.5 * t3 + 0.5 * t2 + 0.5 * t + 0.16666666,
                0.16666666 * t3,
            ]
        }
        _ => [0.0, -t + 1.0, t, 0.0],
    }
}

/// 0 linear, 1 cardinal, 2 b-spline, 3 ease.
fn interp_kind(s: &Option<String>) -> Result<i32, AnimError> {
    Ok(match s.as_deref().unwrap_or("LINEAR") {
        "LINEAR" => 0,
        "CARDINAL" => 1,
        "BSPLINE" => 2,
        "EASE" => 3,
        other => {
            return Err(AnimError::new(
                "tilt/radius interpolation",
                format!("unknown interpolation {other:?}"),
            ))
        }
    })
}

/// Blender's `BKE_curve_forward_diff_bezier` for one coordinate: `it + 1` values.
fn forward_diff(q0: f32, q1: f32, q2: f32, q3: f32, it: usize, out: &mut dyn FnMut(usize, f32)) {
    let mut f = it as f32;
    let rt0 = q0;
    let rt1 = 3.0f32 * (q1 - q0) / f;
    f *= f;
    let rt2 = 3.0f32 * (q0 - 2.0f32 * q1 + q2) / f;
    f *= it as f32;
    let rt3 = (q3 - q0 + 3.0f32 * (q1 - q2)) / f;
    let (mut a, mut b, mut c, d) = (rt0, rt1 + rt2 + rt3, 2.0 * rt2 + 6.0 * rt3, 6.0 * rt3);
    for i in 0..=it {
        out(i, a);
        a += b;
        b += c;
        c += d;
    }
}

fn f3(v: [f64; 3]) -> Vec3 {
    vec3(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn bezier_list(s: &Spline, cs: &CurveSettings, resolu: usize) -> Result<BevList, AnimError> {
    let bz = &s.bezier_points;
    let n = bz.len();
    let cyclic = s.use_cyclic_u;
    let segcount = segments(s, NurbType::Bezier);
    let tilt_interp = interp_kind(&s.tilt_interpolation)?;
    let radius_interp = interp_kind(&s.radius_interpolation)?;
    let mut p = vec![BevPoint::default(); segcount * resolu + 1];
    let has_seglen = cs.need_seglen && !cyclic;
    let vect = |h: &str| h == "VECTOR";
    let (mut prev, mut cur, mut a) = if cyclic {
        (n - 1, 0usize, n)
    } else {
        (0usize, 1usize, n - 1)
    };
    p[0].dir = normalized(f3(bz[prev].handle_right) - f3(bz[prev].co));
    let mut k = 0usize; // write cursor
    while a > 0 {
        a -= 1;
        let (pb, b) = (&bz[prev], &bz[cur]);
        if vect(&pb.handle_right_type) && vect(&b.handle_left_type) {
            p[k].vec = f3(pb.co);
            p[k].tilt = pb.tilt as f32;
            p[k].radius = pb.radius as f32;
            p[k].dupe = false;
            k += 1;
            if has_seglen {
                p[k].offset = len_between(f3(pb.co), f3(b.co));
            }
        } else {
            let (q0, q1, q2, q3) = (f3(pb.co), f3(pb.handle_right), f3(b.handle_left), f3(b.co));
            for j in 0..3 {
                forward_diff(q0[j], q1[j], q2[j], q3[j], resolu, &mut |i, v| {
                    p[k + i].vec[j] = v
                });
            }
            // Tilt and radius between the two keys, using the neighbours for smooth kinds.
            let pprev = if prev == 0 {
                if cyclic {
                    n - 1
                } else {
                    prev
                }
            } else {
                prev - 1
            };
            let next = if cur == n - 1 {
                if cyclic {
                    0
                } else {
                    cur
                }
            } else {
                cur + 1
            };
            let (tp, t0, t1, tn) = (
                bz[pprev].tilt as f32,
                pb.tilt as f32,
                b.tilt as f32,
                bz[next].tilt as f32,
            );
            let (rp, r0, r1, rn) = (
                bz[pprev].radius as f32,
                pb.radius as f32,
                b.radius as f32,
                bz[next].radius as f32,
            );
            let dfac = 1.0f32 / resolu as f32;
            let mut fac = 0.0f32;
            for i in 0..resolu {
                if cs.is_3d {
                    p[k + i].tilt = if tilt_interp == 3 {
                        t0 + (t1 - t0) * (3.0 * fac * fac - 2.0 * fac * fac * fac)
                    } else {
                        let w = position_weights(fac, tilt_interp);
                        w[0] * tp + w[1] * t0 + w[2] * t1 + w[3] * tn
                    };
                }
                if cs.do_radius {
                    p[k + i].radius = if radius_interp == 3 {
                        r0 + (r1 - r0) * (3.0 * fac * fac - 2.0 * fac * fac * fac)
                    } else {
                        let w = position_weights(fac, radius_interp);
                        w[0] * rp + w[1] * r0 + w[2] * r1 + w[3] * rn
                    };
                }
                fac += dfac;
            }
            if cs.twist_mode == TwistMode::Tangent {
                for i in 0..=resolu {
                    let t = i as f32 / resolu as f32;
                    let mut v = Vec3::ZERO;
                    for j in 0..3 {
                        v[j] = (-6.0 * t + 6.0) * q0[j]
                            + (18.0 * t - 12.0) * q1[j]
                            + (-18.0 * t + 6.0) * q2[j]
                            + (6.0 * t) * q3[j];
                    }
                    normalize(&mut v);
                    p[k + i].tan = v;
                }
            }
            if has_seglen {
                for j in 0..resolu {
                    p[k + j + 1].offset = len_between(p[k + j].vec, p[k + j + 1].vec);
                }
            }
            k += resolu;
        }
        prev = cur;
        cur += 1;
    }
    if !cyclic {
        let pb = &bz[prev];
        p[k].vec = f3(pb.co);
        p[k].tilt = pb.tilt as f32;
        p[k].radius = pb.radius as f32;
        p[k].dir = normalized(f3(pb.co) - f3(pb.handle_left));
        k += 1;
    }
    p.truncate(k);
    Ok(BevList {
        p,
        cyclic,
        has_seglen,
        hole: false,
    })
}

fn poly_list(s: &Spline, cs: &CurveSettings) -> BevList {
    let cyclic = s.use_cyclic_u;
    let has_seglen = cs.need_seglen && !cyclic;
    let mut p: Vec<BevPoint> = s
        .points
        .iter()
        .map(|bp| BevPoint {
            vec: vec3(bp.co[0] as f32, bp.co[1] as f32, bp.co[2] as f32),
            tilt: bp.tilt as f32,
            radius: bp.radius as f32,
            ..Default::default()
        })
        .collect();
    if has_seglen {
        for i in 1..p.len() {
            p[i].offset = len_between(p[i - 1].vec, p[i].vec);
        }
    }
    if !cyclic {
        firstlast_dir_from_points(s, &mut p);
    }
    BevList {
        p,
        cyclic,
        has_seglen,
        hole: false,
    }
}

fn firstlast_dir_from_points(s: &Spline, p: &mut [BevPoint]) {
    let bp = &s.points;
    if bp.len() > 1 && !p.is_empty() {
        let v = |i: usize| vec3(bp[i].co[0] as f32, bp[i].co[1] as f32, bp[i].co[2] as f32);
        let n = bp.len();
        let last = p.len() - 1;
        p[0].dir = normalized(v(1) - v(0));
        p[last].dir = normalized(v(n - 1) - v(n - 2));
    }
}

/// Blender's `calcknots`: uniform knots with endpoint / Bezier / cyclic variants.
fn calc_knots(pnts: usize, order: usize, cyclic: bool, bezier: bool, endpoint: bool) -> Vec<f32> {
    let repeat_inner = if bezier { order - 1 } else { 1 };
    let head = if endpoint {
        order - usize::from(cyclic)
    } else if bezier {
        repeat_inner.min(2)
    } else {
        1
    };
    let tail = if cyclic {
        2 * order - 1
    } else if endpoint {
        order
    } else {
        0
    };
    let count = pnts + order + if cyclic { order - 1 } else { 0 };
    let mut knots = vec![0.0f32; count + 1];
    let mut r = head as isize;
    let mut current = 0.0f32;
    let offset = usize::from(endpoint && cyclic);
    if offset == 1 {
        knots[0] = current;
        current += 1.0;
    }
    for k in knots.iter_mut().take(count - tail).skip(offset) {
        *k = current;
        r -= 1;
        if r == 0 {
            current += 1.0;
            r = repeat_inner as isize;
        }
    }
    let tail_index = count - tail;
    for i in 0..tail {
        knots[tail_index + i] = current + (knots[i] - knots[0]);
    }
    knots
}

/// Blender's `basisNurb`: B-spline basis values at `t`, and the non-zero index range.
fn basis_nurb(
    mut t: f32,
    order: usize,
    pnts: usize,
    knots: &[f32],
    basis: &mut [f32],
) -> (usize, usize) {
    let opp = order + pnts;
    let opp2 = opp - 1;
    if t < knots[0] {
        t = knots[0];
    } else if t > knots[opp2] {
        t = knots[opp2];
    }
    let o2 = order as isize + 1;
    let (mut i1, mut i2) = (0isize, 0isize);
    let mut i = 0usize;
    while i < opp2 {
        if knots[i] != knots[i + 1] && t >= knots[i] && t <= knots[i + 1] {
            basis[i] = 1.0;
            i1 = (i as isize - o2).max(0);
            i2 = i as isize;
            i += 1;
            while i < opp2 {
                basis[i] = 0.0;
                i += 1;
            }
            break;
        }
        basis[i] = 0.0;
        i += 1;
    }
    basis[i] = 0.0;
    for j in 2..=order {
        if i2 as usize + j >= opp {
            i2 = (opp2 - j) as isize;
        }
        for ii in i1..=i2 {
            let ii = ii as usize;
            let d = if basis[ii] != 0.0 {
                ((t - knots[ii]) * basis[ii]) / (knots[ii + j - 1] - knots[ii])
            } else {
                0.0
            };
            let e = if basis[ii + 1] != 0.0 {
                ((knots[ii + j] - t) * basis[ii + 1]) / (knots[ii + j] - knots[ii + 1])
            } else {
                0.0
            };
            basis[ii] = d + e;
        }
    }
    let (mut start, mut end) = (1000usize, 0usize);
    for ii in i1..=i2 {
        let ii = ii as usize;
        if basis[ii] > 0.0 {
            end = ii;
            if start == 1000 {
                start = ii;
            }
        }
    }
    (start, end)
}

fn nurbs_list(s: &Spline, cs: &CurveSettings, resolu: usize) -> BevList {
    let cyclic = s.use_cyclic_u;
    let has_seglen = cs.need_seglen && !cyclic;
    let bp = &s.points;
    let pntsu = bp.len();
    let order = s.order_u as usize;
    let segcount = segments(s, NurbType::Nurbs);
    let len = resolu * segcount;
    let mut p = vec![BevPoint::default(); len];
    let knots = calc_knots(pntsu, order, cyclic, s.use_bezier_u, s.use_endpoint_u);
    let knots_len = order + pntsu + if cyclic { order - 1 } else { 0 };
    let total = resolu * segcount;
    if total > 0 {
        let ustart = knots[order - 1];
        let uend = if cyclic {
            knots[pntsu + order - 1]
        } else {
            knots[pntsu]
        };
        let ustep = (uend - ustart) / (total as f32 - if cyclic { 0.0 } else { 1.0 });
        let cycl = if cyclic { order - 1 } else { 0 };
        let mut basis = vec![0.0f32; knots_len + 1];
        let mut sum = vec![0.0f32; pntsu.max(1) + cycl + order];
        let mut u = ustart;
        let eps = 1e-6f32;
        for pt in p.iter_mut() {
            let (istart, iend) = basis_nurb(u, order, pntsu + cycl, &knots, &mut basis);
            let at = |i: usize| &bp[if i >= pntsu { i - pntsu } else { i }];
            let mut sumdiv = 0.0f32;
            if istart <= iend {
                for i in istart..=iend {
                    sum[i - istart] = basis[i] * at(i).co[3] as f32;
                    sumdiv += sum[i - istart];
                }
                if sumdiv != 0.0 && (sumdiv < 1.0 - eps || sumdiv > 1.0 + eps) {
                    for i in istart..=iend {
                        sum[i - istart] /= sumdiv;
                    }
                }
                for i in istart..=iend {
                    let w = sum[i - istart];
                    if w != 0.0 {
                        let b = at(i);
                        for j in 0..3 {
                            pt.vec[j] += b.co[j] as f32 * w;
                        }
                        if cs.is_3d {
                            pt.tilt += w * b.tilt as f32;
                        }
                        if cs.do_radius {
                            pt.radius += w * b.radius as f32;
                        }
                    }
                }
            }
            u += ustep;
        }
    }
    if has_seglen {
        for i in 1..p.len() {
            p[i].offset = len_between(p[i - 1].vec, p[i].vec);
        }
    }
    if !cyclic {
        firstlast_dir_from_points(s, &mut p);
    }
    BevList {
        p,
        cyclic,
        has_seglen,
        hole: false,
    }
}

// ---- orientation (Blender's make_bevel_list_* functions) ---------------------------------

/// The points visited as (previous, current, next) by Blender's pointer walk that starts
/// with the current point at the end of the list: current = n-1, 0, 1, ..., n-2.
fn ring(n: usize, k: usize) -> (usize, usize, usize) {
    ((k + 2 * n - 2) % n, (k + n - 1) % n, k % n)
}

fn calc_bisect(l: &mut BevList) {
    let n = l.p.len();
    if l.cyclic {
        for k in 0..n {
            let (a, b, c) = ring(n, k);
            l.p[b].dir = bisect(l.p[a].vec, l.p[b].vec, l.p[c].vec);
        }
    } else {
        for b in 1..n - 1 {
            l.p[b].dir = bisect(l.p[b - 1].vec, l.p[b].vec, l.p[b + 1].vec);
        }
        // Fallback for zero-length end handles (computed from the neighbour instead).
        if l.p[0].dir.is_zero() {
            let mut d = l.p[1].vec - l.p[0].vec;
            if normalize(&mut d) == 0.0 {
                d = l.p[1].dir;
            }
            l.p[0].dir = d;
        }
        if l.p[n - 1].dir.is_zero() {
            let mut d = l.p[n - 1].vec - l.p[n - 2].vec;
            if normalize(&mut d) == 0.0 {
                d = l.p[n - 2].dir;
            }
            l.p[n - 1].dir = d;
        }
    }
}

fn minimum_twist_between(cur: &mut BevPoint, prev: &BevPoint) {
    let angle = angle_normalized(prev.dir, cur.dir);
    if angle > 0.0 {
        let q = axis_angle_to_quat(prev.dir.cross(cur.dir), angle);
        cur.quat = qmul(q, prev.quat);
    } else {
        cur.quat = prev.quat;
    }
}

fn list_minimum_twist(l: &mut BevList) {
    let n = l.p.len();
    calc_bisect(l);
    let nr_init = n - if l.cyclic { 1 } else { 2 };
    for k in 0..n {
        let (a, b, _) = ring(n, k);
        let remaining = n - 1 - k;
        if remaining >= nr_init {
            l.p[b].quat = vec_to_quat(l.p[b].dir, 5, 1);
        } else {
            let prev = l.p[a];
            minimum_twist_between(&mut l.p[b], &prev);
        }
    }
    if l.cyclic {
        // Spread the roll mismatch between the last and the second last point over the
        // whole loop (Blender's real order is 1, 2, ..., n-1, 0).
        let (first, last) = (n - 1, n - 2);
        let mut v1 = qrotate(l.p[first].quat, Vec3::Y);
        let mut v2 = qrotate(l.p[last].quat, Vec3::Y);
        normalize(&mut v1);
        normalize(&mut v2);
        let c = l.p[last].dir.cross(l.p[first].dir);
        let angle = angle_normalized(l.p[first].dir, l.p[last].dir);
        let q = axis_angle_to_quat(c, angle);
        v2 = qrotate(q, v2);
        let mut angle = angle_normalized(v1, v2);
        let mut c = v1.cross(v2);
        normalize(&mut c);
        if angle_normalized(l.p[first].dir, c) < DEG90 {
            angle = -angle;
        }
        for k in 0..n {
            let (_, b, _) = ring(n, k);
            let remaining = (n - 1 - k) as f32;
            let ang_fac = angle * (1.0 - (remaining / n as f32));
            let q = axis_angle_to_quat(l.p[b].dir, ang_fac);
            l.p[b].quat = qmul(q, l.p[b].quat);
        }
    } else {
        let second = l.p[1];
        minimum_twist_between(&mut l.p[0], &second);
        let before_last = l.p[n - 2];
        minimum_twist_between(&mut l.p[n - 1], &before_last);
    }
}

fn list_tangent(l: &mut BevList) {
    let n = l.p.len();
    calc_bisect(l);
    for k in 0..n {
        let (a, b, _) = ring(n, k);
        if angle_normalized(l.p[a].tan, l.p[b].tan) > DEG90 {
            l.p[b].tan *= -1.0;
        }
    }
    for k in 0..n {
        let (_, b, _) = ring(n, k);
        let c = l.p[b].tan.cross(l.p[b].dir);
        l.p[b].tan = normalized(c.cross(l.p[b].dir));
    }
    for k in 0..n {
        let (_, b, _) = ring(n, k);
        let c = normalized(l.p[b].tan.cross(l.p[b].dir));
        l.p[b].quat = tri_to_quat(Vec3::ZERO, c, l.p[b].tan);
    }
}

fn list_zup(l: &mut BevList) {
    calc_bisect(l);
    for p in l.p.iter_mut() {
        p.quat = vec_to_quat(p.dir, 5, 1);
    }
}

fn list_smooth(l: &mut BevList, iterations: i32) {
    let n = l.p.len();
    for _ in 0..iterations {
        // Visit order of Blender's walk; non-cyclic lists skip the first and last point.
        let visits: Vec<(usize, usize, usize)> = if l.cyclic {
            (0..n).map(|k| ring(n, k)).collect()
        } else {
            (1..n - 1).map(|b| (b - 1, b, b + 1)).collect()
        };
        let mut prev_quat = l.p[visits[0].0].quat;
        for &(_, b, c) in &visits {
            let mut q = qslerp(prev_quat, l.p[c].quat, 0.5);
            qnormalize(&mut q);
            let z = qrotate(q, Vec3::Z);
            let cr = z.cross(l.p[b].dir);
            let mut q2 = axis_angle_to_quat(cr, angle_normalized(z, l.p[b].dir));
            qnormalize(&mut q2);
            prev_quat = l.p[b].quat;
            let q = qmul(q2, q);
            let mut r = qslerp(l.p[b].quat, q, 0.5);
            qnormalize(&mut r);
            l.p[b].quat = r;
        }
    }
}

fn apply_tilt(l: &mut BevList) {
    for p in l.p.iter_mut() {
        let q = axis_angle_to_quat(p.dir, p.tilt);
        p.quat = qmul(q, p.quat);
        qnormalize(&mut p.quat);
    }
}

fn segment_3d(l: &mut BevList) {
    let d = normalized(l.p[1].vec - l.p[0].vec);
    for i in [1usize, 0] {
        l.p[i].dir = d;
        let q0 = vec_to_quat(d, 5, 1);
        let q = axis_angle_to_quat(d, l.p[i].tilt);
        let mut r = qmul(q, q0);
        qnormalize(&mut r);
        l.p[i].quat = r;
    }
}

fn list_2d(l: &mut BevList) {
    let n = l.p.len();
    let visits: Vec<(usize, usize, usize)> = if l.cyclic {
        (0..n).map(|k| ring(n, k)).collect()
    } else {
        (1..n - 1).map(|b| (b - 1, b, b + 1)).collect()
    };
    for (a, b, c) in visits {
        l.p[b].dir = bisect(l.p[a].vec, l.p[b].vec, l.p[c].vec);
        l.p[b].quat = vec_to_quat(l.p[b].dir, 5, 1);
    }
    if !l.cyclic {
        for i in [0, n - 1] {
            l.p[i].quat = vec_to_quat(l.p[i].dir, 5, 1);
        }
    }
}

/// Whether `inner`'s first point lies inside polygon `outer` (Blender's `bevelinside`,
/// counting crossings left and right of a horizontal ray).
fn bevel_inside(outer: &BevList, inner: &BevList) -> bool {
    let h1 = [inner.p[0].vec[0], inner.p[0].vec[1]];
    let h2 = [h1[0] + 1000.0, h1[1]];
    let (mut left, mut right) = (0, 0);
    let n = outer.p.len();
    let mut prev = n - 1;
    for cur in 0..n {
        let (pv, cv) = (outer.p[prev].vec, outer.p[cur].vec);
        let (mut min, mut max) = (pv[1], cv[1]);
        if max < min {
            min = max;
            max = pv[1];
        }
        if min != max && min <= h1[1] && max >= h1[1] {
            // Intersection of edge pv-cv with the ray (cu_isectLL on x/y).
            let deler = (pv[0] - cv[0]) * (h1[1] - h2[1]) - (h1[0] - h2[0]) * (pv[1] - cv[1]);
            if deler != 0.0 {
                let mut lambda =
                    (pv[1] - h1[1]) * (h1[0] - h2[0]) - (pv[0] - h1[0]) * (h1[1] - h2[1]);
                lambda = -(lambda / deler);
                let x = lambda * (cv[0] - pv[0]) + pv[0];
                if lambda != 0.0 {
                    if x < h1[0] {
                        left += 1;
                    } else {
                        right += 1;
                    }
                }
            }
        }
        prev = cur;
    }
    (left & 1) == 1 && (right & 1) == 1
}

/// 2D curves: holes are detected and polygon winding normalized, which can reverse a
/// list (and so the direction of a path along a closed 2D curve).
fn orient_2d_polys(lists: &mut [BevList]) {
    let polys: Vec<usize> = (0..lists.len())
        .filter(|&i| !lists[i].p.is_empty() && lists[i].cyclic)
        .collect();
    if polys.is_empty() {
        return;
    }
    let mut sort: Vec<(usize, f32, bool)> = polys
        .iter()
        .map(|&i| {
            let p = &lists[i].p;
            let n = p.len();
            let mut m = 0;
            for (j, q) in p.iter().enumerate() {
                if p[m].vec[0] > q.vec[0] {
                    m = j;
                }
            }
            let b0 = if m == 0 { n - 1 } else { m - 1 };
            let b2 = if m == n - 1 { 0 } else { m + 1 };
            let (v0, v1, v2) = (p[b0].vec, p[m].vec, p[b2].vec);
            let inp = (v1[0] - v0[0]) * (v0[1] - v2[1]) + (v0[1] - v1[1]) * (v0[0] - v2[0]);
            (i, p[m].vec[0], inp > 0.0)
        })
        .collect();
    sort.sort_by(|a, b| a.1.total_cmp(&b.1));
    for l in lists.iter_mut() {
        l.hole = false;
    }
    for a in 1..sort.len() {
        for b in (0..a).rev() {
            let (outer, inner) = (sort[b].0, sort[a].0);
            if bevel_inside(&lists[outer], &lists[inner]) {
                lists[inner].hole = !lists[outer].hole;
                break;
            }
        }
    }
    for &(i, _, dir) in &sort {
        if lists[i].hole == dir {
            lists[i].p.reverse();
        }
    }
}

/// Builds the path of `curve` (its first spline), or None when Blender would have none
/// (no valid spline, or fewer than two distinct points).
pub fn build_path(curve: &Curve, for_render: bool) -> Result<Option<Path>, AnimError> {
    let cs = settings(curve)?;
    let mut lists: Vec<BevList> = Vec::new();
    let mut resolu = 0usize;
    let mut last_has_seglen = false;
    for (si, s) in curve.splines.iter().enumerate() {
        let at = |e: AnimError| e.within(&format!("splines[{si}]"));
        let t = nurb_type(s).map_err(at)?;
        if !valid(s, t) {
            lists.push(BevList::default());
            continue;
        }
        resolu = if for_render && cs.render_resolution != 0 {
            cs.render_resolution as usize
        } else {
            s.resolution_u as usize
        };
        if resolu == 0 {
            return Err(AnimError::new(
                format!("splines[{si}].resolution_u"),
                "is 0",
            ));
        }
        let l = match t {
            NurbType::Poly => poly_list(s, &cs),
            NurbType::Bezier => bezier_list(s, &cs, resolu).map_err(at)?,
            NurbType::Nurbs => nurbs_list(s, &cs, resolu),
        };
        last_has_seglen = l.has_seglen;
        lists.push(l);
    }
    // Step 2: drop duplicate points (Blender uses the last spline's settings here).
    let threshold_resolu = 0.00001f32 / resolu as f32;
    for l in lists.iter_mut() {
        let n = l.p.len();
        if n == 0 {
            continue;
        }
        let (mut b0, mut b1) = if l.cyclic {
            (n - 1, 0usize)
        } else {
            (0usize, 1usize)
        };
        if !l.cyclic {
            l.p[0].offset = 0.0;
        }
        for _ in 0..n - 1 {
            let dupe = if last_has_seglen {
                l.p[b1].offset.abs() < 0.00001
            } else {
                let (a, b) = (l.p[b0].vec, l.p[b1].vec);
                (a[0] - b[0]).abs() <= threshold_resolu
                    && (a[1] - b[1]).abs() <= threshold_resolu
                    && (a[2] - b[2]).abs() <= threshold_resolu
            };
            if dupe {
                l.p[b0].dupe = true;
            }
            b0 = b1;
            b1 += 1;
        }
        l.p.retain(|p| !p.dupe);
    }
    if !cs.is_3d {
        orient_2d_polys(&mut lists);
    }
    // Step 4: orientation of the first list (the only one the path uses).
    let Some(first) = lists.first_mut() else {
        return Ok(None);
    };
    let n = first.p.len();
    if n < 2 {
        // Blender has no usable path then (it would not even build one for n == 0).
        return Ok(None);
    }
    if n == 2 {
        segment_3d(first);
    } else if cs.is_3d {
        match cs.twist_mode {
            TwistMode::Tangent => list_tangent(first),
            TwistMode::Minimum => list_minimum_twist(first),
            TwistMode::ZUp => list_zup(first),
        }
        let smooth = (resolu as f32 * cs.twist_smooth) as i32;
        if smooth != 0 {
            list_smooth(first, smooth);
        }
        apply_tilt(first);
    } else {
        list_2d(first);
    }
    let l = lists.swap_remove(0);
    // Cumulative segment lengths (one more segment closing a cyclic path).
    let seg = if l.cyclic { n } else { n - 1 };
    let mut accum = vec![0.0f32; seg];
    let mut prev_len = 0.0f32;
    for i in 0..n - 1 {
        prev_len += len_between(l.p[i].vec, l.p[i + 1].vec);
        accum[i] = prev_len;
    }
    if l.cyclic {
        accum[seg - 1] = prev_len + len_between(l.p[0].vec, l.p[n - 1].vec);
    }
    Ok(Some(Path {
        points: l.p,
        cyclic: l.cyclic,
        accum,
    }))
}

impl Path {
    /// The four points around segment `idx` (Blender's `get_curve_points_from_idx`).
    fn points_at(&self, idx: usize) -> [usize; 4] {
        let n = self.points.len();
        if idx == 0 {
            let p0 = if self.cyclic { n - 1 } else { 0 };
            let p3 = if n > 2 { 2 } else { 1 };
            return [p0, 0, 1, p3];
        }
        if idx == n - 2 {
            return [idx - 1, idx, idx + 1, if self.cyclic { 0 } else { idx + 1 }];
        }
        if idx == n - 1 {
            return [idx - 1, idx, 0, 1];
        }
        [idx - 1, idx, idx + 1, idx + 2]
    }

    fn search(&self, goal: f32) -> (usize, f32) {
        let a = &self.accum;
        let (mut base, mut step) = (0usize, a.len() - 1);
        loop {
            let cur = base + step / 2;
            // Blender reads one past the end for single-segment paths; the value never matters.
            let (l, r) = (a[cur], a.get(cur + 1).copied().unwrap_or(f32::INFINITY));
            if l <= goal && r > goal {
                return (cur + 1, (goal - l) / (r - l));
            }
            if cur == 0 {
                return (0, goal / a[0]);
            }
            if step == 0 {
                // Blender asserts here; the last segment is the sane answer.
                let i = a.len() - 1;
                return (i, (goal - a[i - 1]) / (a[i] - a[i - 1]));
            }
            if l < goal {
                base = cur + 1;
                step -= 1;
            }
            step /= 2;
        }
    }

    /// Blender's `BKE_where_on_path` at path fraction `ctime` (0..1; cyclic paths wrap,
    /// open paths extrapolate the position linearly past the ends).
    pub fn sample(&self, mut ctime: f32) -> PathSample {
        if self.cyclic && !(0.0..=1.0).contains(&ctime) {
            ctime -= ctime.floor();
        }
        let seg = self.accum.len();
        let goal = ctime * self.accum[seg - 1];
        let (idx, frac) = if ctime <= 0.0 || ctime >= 1.0 {
            let clamp = ctime.clamp(0.0, 1.0);
            let idx = (clamp * (seg - 1) as f32) as usize;
            let frac = if idx == 0 {
                goal / self.accum[0]
            } else {
                (goal - self.accum[idx - 1]) / (self.accum[idx] - self.accum[idx - 1])
            };
            (idx, frac)
        } else {
            self.search(goal)
        };
        let [i0, i1, i2, i3] = self.points_at(idx);
        let (p0, p1, p2, p3) = (
            &self.points[i0],
            &self.points[i1],
            &self.points[i2],
            &self.points[i3],
        );
        // Poly, Bezier and NURBS paths interpolate linearly between their points.
        let mut w = [0.0f32, -frac + 1.0, frac, 0.0];
        let mut pos = Vec3::ZERO;
        for j in 0..3 {
            pos[j] = w[0] * p0.vec[j] + w[1] * p1.vec[j] + w[2] * p2.vec[j] + w[3] * p3.vec[j];
        }
        for x in w.iter_mut() {
            *x = x.clamp(0.0, 1.0);
        }
        let eps = f32::EPSILON;
        let tot = w[0] + w[3];
        let q1 = if tot > eps {
            qslerp(p0.quat, p3.quat, w[3] / tot)
        } else {
            p1.quat
        };
        let tot = w[1] + w[2];
        let q2 = if tot > eps {
            qslerp(p1.quat, p2.quat, w[2] / tot)
        } else {
            p3.quat
        };
        let tot = w[0] + w[1] + w[2] + w[3];
        let quat = if tot > eps {
            qslerp(q1, q2, (w[1] + w[2]) / tot)
        } else {
            q2
        };
        let radius = w[0] * p0.radius + w[1] * p1.radius + w[2] * p2.radius + w[3] * p3.radius;
        PathSample { pos, quat, radius }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoint_knots_clamp_both_ends() {
        let k = calc_knots(5, 4, false, false, true);
        assert_eq!(&k[..9], &[0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0]);
    }

    #[test]
    fn uniform_knots() {
        let k = calc_knots(4, 3, false, false, false);
        assert_eq!(&k[..7], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
    }
}
