//! Hair curves as Cycles' 3D Curves (Render > Curves > Shape THICK): each Catmull-Rom
//! segment is the surface a circle of the interpolated radius sweeps along it, open at
//! the curve's ends, found by Cycles' recursive subdivision into bounding cylinders
//! refined by Newton steps (kernel/geom/curve_intersect.h: curve_intersect_recursive,
//! curve_intersect_iterative), and shaded with the tube's true normal, from the curve's
//! centre at the hit's u to the hit (curve_shader_setup). Cycles' subdivisions setting
//! does not reach this shape: its depths are fixed.
//!
//! The inside of the tube is hit too. Cycles' own kernel culls it, but on the CPU Cycles
//! 4.5 hands these curves to Embree (round Catmull-Rom curves), which does not: measured
//! on a strand seen from above its open end (96 px), culling left a hollow end where
//! Cycles renders the inner wall (999 pixels differ; none without culling; spheres closing
//! the ends instead matched there but bulged below the roots of scene hair_thick, -2%),
//! and on scene hair_thick culling let light through the open roots onto the floor
//! (+0.8% to +1.6%).

use crate::render::curves::{catmull_rom, catmull_rom_derivative, RibbonHit};
use crate::render::math::*;

/// Pieces each level cuts a span into (Cycles' CURVE_NUM_BEZIER_STEPS).
const STEPS: usize = 2;
/// Levels of subdivision before the Newton refinement (Cycles'
/// CURVE_NUM_BEZIER_SUBDIVISIONS_UNSTABLE: its kernel takes every span as unstable).
const DEPTH: usize = 4;
/// Newton steps (CURVE_NUM_JACOBIAN_ITERATIONS).
const ITERATIONS: usize = 5;

/// Second derivative of the Catmull-Rom segment (catmull_rom_basis_derivative2).
#[inline]
fn catmull_rom_derivative2(c: &[[f32; 4]; 4], u: f32) -> V3 {
    let t = u;
    let n = [-3.0 * t + 2.0, 9.0 * t - 5.0, -9.0 * t + 4.0, 3.0 * t - 1.0];
    std::array::from_fn(|i| c[0][i] * n[0] + c[1][i] * n[1] + c[2][i] * n[2] + c[3][i] * n[3])
}

fn xyz(p: [f32; 4]) -> V3 {
    [p[0], p[1], p[2]]
}

/// d(p / |p|) along `dp`.
#[inline]
fn dnormalize(p: V3, dp: V3) -> V3 {
    let pp = dot(p, p);
    let pdp = dot(p, dp);
    scale(sub(scale(dp, pp), scale(p, pdp)), 1.0 / (pp * pp.sqrt()))
}

/// Squared distance of the point `pq0` (relative to the line's start) from the line along
/// `d`.
#[inline]
fn sqr_point_to_line_distance(pq0: V3, d: V3) -> f32 {
    let n = cross(pq0, d);
    dot(n, n) / dot(d, d)
}

/// One crossing of a ray with a cylinder: t, and u along its axis (start 0, end 1).
#[derive(Clone, Copy)]
struct Crossing {
    t: [f32; 2],
    u: [f32; 2],
}

/// The ray from the origin along `d` against the infinite cylinder of radius `r` about the
/// line from `a` to `b`: the entry and exit t (FLT_MAX, -FLT_MAX on a miss; the whole line
/// for a ray along the axis inside it) and where along the axis they lie.
fn cylinder(a: V3, b: V3, r: f32, d: V3) -> (bool, Crossing) {
    let miss = Crossing {
        t: [f32::MAX, -f32::MAX],
        u: [0.0; 2],
    };
    let rl = 1.0 / len(sub(b, a));
    let dp = scale(sub(b, a), rl);
    let o = neg(a);
    let dodo = dot(d, d);
    let odo = dot(d, o);
    let oo = dot(o, o);
    let doz = dot(dp, d);
    let oz = dot(dp, o);
    let qa = dodo - doz * doz;
    let qb = 2.0 * (odo - doz * oz);
    let qc = oo - oz * oz - r * r;
    let disc = qb * qb - 4.0 * qa * qc;
    if !(disc >= 0.0) {
        return (false, miss);
    }
    let eps = 16.0 * f32::EPSILON * dodo.abs().max(doz * doz);
    if qa.abs() < eps {
        let all = Crossing {
            t: [-f32::MAX, f32::MAX],
            u: [0.0; 2],
        };
        return (qc <= 0.0, all);
    }
    let q = disc.sqrt();
    let rcp = 1.0 / (2.0 * qa);
    let t = [(-qb - q) * rcp, (-qb + q) * rcp];
    (
        true,
        Crossing {
            t,
            u: t.map(|t| (t * doz + oz) * rl),
        },
    )
}

/// The t interval of the ray from the origin along `d` on the side of the plane through
/// `p` that `n` points to.
#[inline]
fn half_plane(p: V3, n: V3, d: V3) -> [f32; 2] {
    let on = -dot(p, n);
    let dn = dot(d, n);
    let tiny = dn.abs() < 1e-18;
    let t = -on / dn;
    let lower = if tiny || dn < 0.0 { -f32::MAX } else { t };
    let upper = if tiny || dn > 0.0 { f32::MAX } else { t };
    [lower, upper]
}

/// Newton steps from (u, t) to where the ray (from the origin along `d`, shifted by `dt`)
/// meets the tube, accepted within [tmin, tmax] on its front side: (t, u).
#[allow(clippy::too_many_arguments)]
fn refine(
    d: V3,
    tmin: f32,
    tmax: f32,
    dt: f32,
    c: &[[f32; 4]; 4],
    mut u: f32,
    mut t: f32,
) -> Option<(f32, f32)> {
    let len_d = len(d);
    // Cycles' bound takes the min of the first two keys for its maximum (kept, as it sets
    // the tolerance).
    let lo: [f32; 4] = std::array::from_fn(|i| c[0][i].min(c[1][i]).min(c[2][i].min(c[3][i])));
    let hi: [f32; 4] = std::array::from_fn(|i| c[0][i].min(c[1][i]).max(c[2][i].max(c[3][i])));
    let abs: [f32; 4] = std::array::from_fn(|i| lo[i].abs().max(hi[i].abs()));
    let p_err = 16.0 * f32::EPSILON * abs[0].max(abs[1].max(abs[2].max(abs[3])));
    let radius_max = hi[3];
    for _ in 0..ITERATIONS {
        let q = scale(d, t);
        let q_err = 16.0 * f32::EPSILON * len_d * t;
        let p4 = catmull_rom(c, u);
        let dp4 = catmull_rom_derivative(c, u);
        let (p, dpdu, radius, dradius) = (xyz(p4), xyz(dp4), p4[3], dp4[3]);
        let ddpdu = catmull_rom_derivative2(c, u);
        let r = sub(q, p);
        let len_r = len(r);
        let r_err = q_err.max(p_err);
        let drdu = neg(dpdu);
        let tangent = normalize(dpdu);
        let dtangent = dnormalize(dpdu, ddpdu);
        let cos_err = p_err / len(dpdu);
        let f = dot(r, tangent);
        let f_err = len_r * p_err + r_err + cos_err * (1.0 + len_r);
        let dfdu = dot(drdu, tangent) + dot(r, dtangent);
        let dfdt = dot(d, tangent);
        let k = dot(r, r) - f * f;
        let dkdu = dot(r, drdu) - f * dfdu;
        let dkdt = dot(r, d) - f * dfdt;
        let rsqrt_k = 1.0 / k.sqrt();
        let g = k.sqrt() - radius;
        let g_err = r_err + f_err + 16.0 * f32::EPSILON * radius_max;
        let dgdu = dkdu * rsqrt_k - dradius;
        let dgdt = dkdt * rsqrt_k;
        let invdet = 1.0 / (dfdu * dgdt - dgdu * dfdt);
        u -= (dgdt * f - dfdt * g) * invdet;
        t -= (-dgdu * f + dfdu * g) * invdet;
        if f.abs() < f_err && g.abs() < g_err {
            let t = t + dt;
            if !(t >= tmin && t <= tmax && (0.0..=1.0).contains(&u)) {
                return None;
            }
            // Embree keeps the tube's inside (module doc): no back-face culling.
            return Some((t, u));
        }
    }
    None
}

/// The ray `org + t dir` against the tube of the Catmull-Rom segment `c` (x, y, z, radius
/// per control point): the nearest front-side hit within [tmin, tmax], its t, u along the
/// segment and in v the hit's angle about the curve (`tube_point` turns it back into the
/// point and normal).
pub fn thick_intersect(
    org: V3,
    dir: V3,
    tmin: f32,
    tmax: f32,
    c: &[[f32; 4]; 4],
) -> Option<RibbonHit> {
    // Cycles moves the ray's origin next to the segment first, for stable numbers.
    let center = scale(
        add(add(xyz(c[0]), xyz(c[1])), add(xyz(c[2]), xyz(c[3]))),
        0.25,
    );
    let dt = dot(sub(center, org), dir) / dot(dir, dir);
    let reference = add(org, scale(dir, dt));
    let curve: [[f32; 4]; 4] = c.map(|p| {
        [
            p[0] - reference[0],
            p[1] - reference[1],
            p[2] - reference[2],
            p[3],
        ]
    });
    let step_size = 1.0 / STEPS as f32;
    let mut tmax = tmax;
    let mut found: Option<(f32, f32)> = None;
    // The spans still to visit: (u0, u1, next step) per level, as Cycles' stack.
    let mut stack = [(0.0f32, 0.0f32, 0usize); DEPTH];
    let mut depth = 0usize;
    let (mut u0, mut u1, mut i) = (0.0f32, 1.0f32, 0usize);
    loop {
        while i < STEPS {
            let step = i as f32 * step_size;
            let dscale = (u1 - u0) * (1.0 / 3.0) * step_size;
            let vu0 = u0 + (u1 - u0) * step;
            let vu1 = u0 + (u1 - u0) * (step + step_size);
            let p0 = catmull_rom(&curve, vu0);
            let dp0 = catmull_rom_derivative(&curve, vu0).map(|x| x * dscale);
            let p3 = catmull_rom(&curve, vu1);
            let dp3 = catmull_rom_derivative(&curve, vu1).map(|x| x * dscale);
            let p1: [f32; 4] = std::array::from_fn(|k| p0[k] + dp0[k]);
            let p2: [f32; 4] = std::array::from_fn(|k| p3[k] - dp3[k]);
            let chord = sub(xyz(p3), xyz(p0));
            let rr1 = sqr_point_to_line_distance(xyz(dp0), chord);
            let rr2 = sqr_point_to_line_distance(xyz(dp3), chord);
            let maxr12 = rr1.max(rr2).sqrt();
            let r_outer =
                (1.0 + 2.0 * f32::EPSILON) * (p0[3].max(p1[3]).max(p2[3].max(p3[3])) + maxr12);
            let r_inner = ((1.0 - 2.0 * f32::EPSILON)
                * (p0[3].min(p1[3]).min(p2[3].min(p3[3])) - maxr12))
                .max(0.0);
            let (hit_outer, outer) = cylinder(xyz(p0), xyz(p3), r_outer, dir);
            if !hit_outer {
                i += 1;
                continue;
            }
            // The outer cylinder's span between the planes capping the piece's ends.
            let mut tp = [(tmin - dt).max(outer.t[0]), (tmax - dt).min(outer.t[1])];
            let h0 = half_plane(xyz(p0), xyz(dp0), dir);
            tp = [tp[0].max(h0[0]), tp[1].min(h0[1])];
            let h1 = half_plane(xyz(p3), neg(xyz(dp3)), dir);
            tp = [tp[0].max(h1[0]), tp[1].min(h1[1])];
            if tp[0] > tp[1] {
                i += 1;
                continue;
            }
            let su = |x: f32| {
                u0 + (u1 - u0) * ((step + x.clamp(0.0, 1.0)) * (1.0 / (STEPS as f32 + 1.0)))
            };
            let (uo0, uo1) = (su(outer.u[0]), su(outer.u[1]));
            // Less the inner cylinder, which the tube surely covers.
            let (_, inner) = cylinder(xyz(p0), xyz(p3), r_inner, dir);
            let eps = 0.001f32;
            let tp0 = [tp[0], tp[1].min(inner.t[0])];
            let tp1 = [tp[0].max(inner.t[1]), tp[1]];
            let valid0 = tp0[0] - tp0[1] < eps;
            let valid1 = tp1[0] - tp1[1] < eps;
            if !(valid0 || valid1) {
                i += 1;
                continue;
            }
            let mut recurse = false;
            if valid0 {
                if depth >= DEPTH {
                    if let Some(h) = refine(dir, tmin, tmax, dt, &curve, uo0, tp0[0]) {
                        tmax = h.0;
                        found = Some(h);
                    }
                } else {
                    recurse = true;
                }
            }
            let t1 = tp1[0] + dt;
            if valid1 && t1 >= tmin && t1 <= tmax {
                if depth >= DEPTH {
                    if let Some(h) = refine(dir, tmin, tmax, dt, &curve, uo1, tp1[1]) {
                        tmax = h.0;
                        found = Some(h);
                    }
                } else {
                    recurse = true;
                }
            }
            if recurse {
                stack[depth] = (u0, u1, i + 1);
                depth += 1;
                u0 = vu0;
                u1 = vu1;
                i = 0;
            } else {
                i += 1;
            }
        }
        if depth == 0 {
            break;
        }
        depth -= 1;
        (u0, u1, i) = stack[depth];
    }
    let (t, u) = found?;
    let hit = add(org, scale(dir, t));
    let (a, b) = around(c, u);
    let off = sub(hit, xyz(catmull_rom(c, u)));
    Some(RibbonHit {
        t,
        u,
        v: dot(off, b).atan2(dot(off, a)),
    })
}

/// Two unit axes across the curve's tangent at `u`, in which a hit's angle is measured.
fn around(c: &[[f32; 4]; 4], u: f32) -> (V3, V3) {
    let t = xyz(catmull_rom_derivative(c, u));
    let t = if is_zero(t) {
        [0.0, 0.0, 1.0]
    } else {
        normalize(t)
    };
    let a = if t[0].abs() > 0.5 {
        [-t[1], t[0], 0.0]
    } else {
        [0.0, -t[2], t[1]]
    };
    let a = normalize(a);
    (a, cross(t, a))
}

/// The point and outward unit normal of a `thick_intersect` hit at (`u`, angle `v`) on
/// segment `c`, and the curve's tangent dP/du there: the normal points from the curve's
/// centre at u to the hit, as Cycles' curve_shader_setup takes it for thick curves (away
/// from the viewer on the tube's inside).
pub fn tube_point(c: &[[f32; 4]; 4], u: f32, v: f32) -> (V3, V3, V3) {
    let (a, b) = around(c, u);
    let (s, co) = v.sin_cos();
    let n = add(scale(a, co), scale(b, s));
    let centre = catmull_rom(c, u);
    let p = add(xyz(centre), scale(n, centre[3]));
    (p, n, xyz(catmull_rom_derivative(c, u)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight tube along x through keys at 0..3, radius 0.1 (segment 1 to 2).
    fn straight() -> [[f32; 4]; 4] {
        std::array::from_fn(|i| [i as f32, 0.0, 0.0, 0.1])
    }

    #[test]
    fn a_ray_meets_the_tube_at_its_surface() {
        let c = straight();
        // From above at x = 1.5: the top of the tube, t = 5 - 0.1, normal up.
        let h = thick_intersect([1.5, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).unwrap();
        assert!(
            (h.t - 4.9).abs() < 1e-4 && (h.u - 0.5).abs() < 1e-4,
            "{h:?}"
        );
        let (p, n, _) = tube_point(&c, h.u, h.v);
        assert!(
            len(sub(p, [1.5, 0.0, 0.1])) < 1e-4 && len(sub(n, [0.0, 0.0, 1.0])) < 1e-4,
            "{p:?} {n:?}"
        );
        // Half way to the side: the circle's height there, normal tilted by 30 degrees.
        let h = thick_intersect([1.25, 0.05, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).unwrap();
        let z = (0.01f32 - 0.0025).sqrt();
        assert!((h.t - (5.0 - z)).abs() < 1e-4, "{h:?}");
        let (p, n, _) = tube_point(&c, h.u, h.v);
        assert!(len(sub(p, [1.25, 0.05, z])) < 1e-4, "{p:?}");
        assert!(
            (n[1] - 0.5).abs() < 1e-3 && (n[2] - z / 0.1).abs() < 1e-3,
            "{n:?}"
        );
        // Beside it or beyond tmax: none; from the axis, the wall's inside.
        assert!(thick_intersect([1.25, 0.11, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).is_none());
        assert!(thick_intersect([1.5, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 4.8, &c).is_none());
        let h = thick_intersect([1.5, 0.0, 0.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).unwrap();
        assert!((h.t - 0.1).abs() < 1e-4, "{h:?}");
        // The segment ends at its keys: a ray past x = 2 meets the next segment, not this.
        assert!(thick_intersect([2.2, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).is_none());
    }

    #[test]
    fn the_tube_is_open_at_its_end_and_its_inside_is_hit() {
        // The last segment of a strand along x ending at x = 3 (its last key repeated).
        let c = [
            [1.0, 0.0, 0.0, 0.1],
            [2.0, 0.0, 0.0, 0.1],
            [3.0, 0.0, 0.0, 0.1],
            [3.0, 0.0, 0.0, 0.1],
        ];
        // Into the open end at a slant: the inner wall, its normal (outward) away from
        // the viewer.
        let d = normalize([-1.0, 0.0, -0.3]);
        let h = thick_intersect([3.2, 0.0, 0.09], d, 0.0, 100.0, &c).unwrap();
        let (p, n, _) = tube_point(&c, h.u, h.v);
        assert!(p[0] < 3.0 && (p[2] + 0.1).abs() < 1e-3, "{p:?}");
        assert!(dot(n, d) > 0.2, "{n:?}");
        // Past the end, beside the strand: nothing.
        assert!(thick_intersect([3.2, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c).is_none());
    }

    #[test]
    fn a_tapered_bent_tube_is_hit_where_the_swept_circle_is() {
        // Keys bending up, radius 0.3 down to 0.1; rays from far above at many x: each
        // hit lies at the interpolated radius from the curve's centre at its u.
        let c = [
            [0.0, 0.0, 0.0, 0.3],
            [1.0, 0.0, 0.2, 0.25],
            [2.0, 0.0, 0.6, 0.15],
            [3.0, 0.0, 1.2, 0.1],
        ];
        let mut hits = 0;
        for k in 0..40 {
            let x = 0.8 + 1.4 * k as f32 / 39.0;
            if let Some(h) = thick_intersect([x, 0.03, 10.0], [0.0, 0.0, -1.0], 0.0, 100.0, &c) {
                hits += 1;
                let p = [x, 0.03, 10.0 - h.t];
                let centre = catmull_rom(&c, h.u);
                let d = len(sub(p, xyz(centre)));
                assert!((d - centre[3]).abs() < 1e-3, "x {x}: {d} vs {}", centre[3]);
                let (q, _, _) = tube_point(&c, h.u, h.v);
                assert!(len(sub(q, p)) < 1e-3, "x {x}: {q:?} {p:?}");
            }
        }
        assert!(hits >= 30, "{hits}");
    }
}
