//! Cycles' area lights (kernel/light/area.h): rectangles sampled by solid angle (Ureña et
//! al., "An Area-Preserving Parametrization for Spherical Rectangles"), ellipses by area,
//! and Spread: the soft-box attenuation by angle, with sampling restricted to the part of
//! the light that can reach the shading point.

use std::f32::consts::PI;

use crate::render::math::{vec3, Vec3};

/// The region of an area light that light sampling draws from: the whole light, or (with
/// a spread) a smaller rectangle, ellipse or circle in its plane.
#[derive(Debug, Clone, Copy)]
pub struct Region {
    pub centre: Vec3,
    pub axis_u: Vec3,
    pub len_u: f32,
    pub axis_v: Vec3,
    pub len_v: f32,
    /// Sampled by solid angle as a rectangle (else uniformly by area as an ellipse).
    pub rectangle: bool,
}

/// An area light's spread: Cycles' `tan_half_spread` and `normalize_spread`.
#[derive(Debug, Clone, Copy)]
pub struct Spread {
    pub tan_half: f32,
    pub normalize: f32,
}

impl Spread {
    /// The spread of Blender's `spread` angle (radians), or None at the full 180 degrees,
    /// where Cycles' attenuation is 1 and its clamp keeps the whole light.
    pub fn new(spread: f32) -> Option<Spread> {
        if !(spread < PI) {
            return None;
        }
        let half = 0.5 * spread.max(0.0);
        let tan_half = half.tan();
        // Cycles integrates cos(x) (1 - tan(x) / tan(a)) sin(x) over [0, a], a the half
        // angle, divided by tan(a); a Taylor expansion below 0.05 keeps it accurate.
        let normalize = if half <= 0.0 {
            f32::MAX
        } else if half > 0.05 {
            1.0 / (tan_half - half)
        } else {
            3.0 / (half * half * half)
        };
        Some(Spread {
            tan_half,
            normalize,
        })
    }

    /// The fraction of the light's radiance leaving along `d` (from the shading point
    /// toward the light) past the soft box's slats; `ng` is the light's emission direction.
    pub fn attenuation(&self, d: Vec3, ng: Vec3) -> f32 {
        let cos_a = -d.dot(ng);
        if self.tan_half == 0.0 {
            // A zero spread emits only along its normal; pi integrates it over the hemisphere.
            return if cos_a > 0.9999997 { PI } else { 0.0 };
        }
        let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
        ((self.tan_half - sin_a / cos_a) * self.normalize).max(0.0)
    }

    /// The smallest region of `full` (the light seen without spread) that light from the
    /// spread can reach `p` through, as Cycles' area_light_spread_clamp_light; None when
    /// no part of the light can.
    pub fn clamp(&self, p: Vec3, ng: Vec3, full: Region) -> Option<Region> {
        let mut r = full;
        let closest = p - ng * ng.dot(p - r.centre);
        let t = (closest - p).length();
        // The circle of the light plane whose light reaches p.
        let r_spread = t * self.tan_half;
        let su = r.axis_u.dot(closest - r.centre);
        let sv = r.axis_v.dot(closest - r.centre);
        let round = !r.rectangle && r.len_u == r.len_v;
        let mut sample_spread = r_spread == 0.0;
        if round && !sample_spread {
            let dist = (su * su + sv * sv).sqrt();
            let rad = r.len_u * 0.5;
            if dist >= rad + r_spread {
                return None;
            }
            sample_spread = dist <= (rad - r_spread).abs() && r_spread < rad;
            if dist > (rad - r_spread).abs() {
                // The two circles cross: the smallest rectangle covering the lens.
                let lu = rad + r_spread - dist;
                let lv = if (rad * rad - r_spread * r_spread).abs() >= dist * dist {
                    2.0 * rad.min(r_spread)
                } else {
                    let k = dist + (r_spread * r_spread - rad * rad) / dist;
                    (4.0 * r_spread * r_spread - k * k).max(0.0).sqrt()
                };
                let rect_area = lu * lv;
                let circle_area = PI * rad * rad;
                let spread_area = PI * r_spread * r_spread;
                if rect_area < circle_area.min(spread_area) {
                    let axis_u = (r.centre - closest).normalize();
                    // Rotated a quarter turn about the light's normal.
                    let axis_v = ng.cross(axis_u);
                    let centre = (r.centre + closest + axis_u * (r_spread - rad)) * 0.5;
                    return Some(Region {
                        centre,
                        axis_u,
                        len_u: lu,
                        axis_v,
                        len_v: lv,
                        rectangle: true,
                    });
                }
                sample_spread = spread_area < circle_area;
            }
        } else if !round && !sample_spread {
            // The rectangle around the spread circle, clamped to the light's bounds.
            let min_u = (su - r_spread).max(-r.len_u * 0.5);
            let max_u = (su + r_spread).min(r.len_u * 0.5);
            let min_v = (sv - r_spread).max(-r.len_v * 0.5);
            let max_v = (sv + r_spread).min(r.len_v * 0.5);
            if min_u >= max_u || min_v >= max_v {
                return None;
            }
            let (lu, lv) = (max_u - min_u, max_v - min_v);
            let rect_area = lu * lv;
            let ellipse_area = if r.rectangle {
                f32::MAX
            } else {
                PI / 4.0 * r.len_u * r.len_v
            };
            let spread_area = PI * r_spread * r_spread;
            // A rectangle light stays a (smaller) rectangle: solid-angle sampling beats
            // sampling the circle by area.
            if r.rectangle || rect_area < ellipse_area.min(spread_area) {
                let cu = 0.5 * (min_u + max_u);
                let cv = 0.5 * (min_v + max_v);
                r.centre += r.axis_u * cu + r.axis_v * cv;
                r.len_u = lu;
                r.len_v = lv;
                r.rectangle = true;
                return Some(r);
            }
            r.rectangle = false;
            sample_spread = spread_area < ellipse_area;
        }
        if sample_spread {
            r.rectangle = false;
            r.centre += r.axis_u * su + r.axis_v * sv;
            r.len_u = 2.0 * r_spread;
            r.len_v = 2.0 * r_spread;
        }
        Some(r)
    }
}

/// The solid angle a rectangle subtends at `p` and, with `u`, a point on it drawn
/// uniformly by solid angle (Ureña et al.'s parametrization, as Cycles'
/// area_light_rect_sample). Computed in f64: at grazing or far views the f32 angle sum
/// loses the solid angle to cancellation.
pub fn rect_solid_angle(p: Vec3, r: &Region, u: Option<[f32; 2]>) -> (f32, Option<Vec3>) {
    let d3 = |a: Vec3| [a.x as f64, a.y as f64, a.z as f64];
    let dot64 = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (x, y) = (d3(r.axis_u), d3(r.axis_v));
    let mut z = [
        x[1] * y[2] - x[2] * y[1],
        x[2] * y[0] - x[0] * y[2],
        x[0] * y[1] - x[1] * y[0],
    ];
    let (lu, lv) = (r.len_u as f64, r.len_v as f64);
    let c = d3(r.centre);
    let corner = [0, 1, 2].map(|i| c[i] - x[i] * lu * 0.5 - y[i] * lv * 0.5);
    let pp = d3(p);
    let dir = [0, 1, 2].map(|i| corner[i] - pp[i]);
    let mut z0 = dot64(dir, z);
    // z points away from the rectangle.
    if z0 > 0.0 {
        z = z.map(|a| -a);
        z0 = -z0;
    }
    let x0 = dot64(dir, x);
    let y0 = dot64(dir, y);
    let x1 = x0 + lu;
    let y1 = y0 + lv;
    // Normals of the four planes through p and the rectangle's edges, and the internal
    // angles between them.
    let diff = [x0 - x1, y1 - y0, x1 - x0, y0 - y1];
    let nz0 = [y0, x1, y1, x0];
    let nz: [f64; 4] = [0, 1, 2, 3].map(|i| {
        let n = nz0[i] * diff[i];
        n / (z0 * z0 * diff[i] * diff[i] + n * n).sqrt()
    });
    let acos = |v: f64| v.clamp(-1.0, 1.0).acos();
    let g0 = acos(-nz[0] * nz[1]);
    let g1 = acos(-nz[1] * nz[2]);
    let g2 = acos(-nz[2] * nz[3]);
    let g3 = acos(-nz[3] * nz[0]);
    let (b0, b1) = (nz[0], nz[2]);
    let k = 2.0 * std::f64::consts::PI - g2 - g3;
    let s = g0 + g1 - k;
    if !(s > 0.0) || !s.is_finite() {
        return (0.0, None);
    }
    let point = u.map(|u| {
        let au = u[0] as f64 * s + k;
        let fu = (au.cos() * b0 - b1) / au.sin();
        let cu =
            (1.0 / (fu * fu + b0 * b0).sqrt() * if fu > 0.0 { 1.0 } else { -1.0 }).clamp(-1.0, 1.0);
        let xu = (-(cu * z0) / (1.0 - cu * cu).sqrt().max(1e-7)).clamp(x0, x1);
        let dd = (xu * xu + z0 * z0).sqrt();
        let h0 = y0 / (dd * dd + y0 * y0).sqrt();
        let h1 = y1 / (dd * dd + y1 * y1).sqrt();
        let hv = h0 + u[1] as f64 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            hv * dd / (1.0 - hv2).sqrt()
        } else {
            y1
        };
        let c = |i: usize| (pp[i] + xu * x[i] + yv * y[i] + z0 * z[i]) as f32;
        vec3(c(0), c(1), c(2))
    });
    (s as f32, point)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(len: f32) -> Region {
        Region {
            centre: Vec3::ZERO,
            axis_u: Vec3::X,
            len_u: len,
            axis_v: Vec3::Y,
            len_v: len,
            rectangle: true,
        }
    }

    #[test]
    fn solid_angle_of_a_square_matches_the_closed_form() {
        // A square of side 2a seen from height h on its axis: 4 asin(a^2 / (a^2 + h^2)).
        for (a, h) in [(1.0f32, 1.0f32), (0.5, 3.0), (2.0, 0.1), (0.01, 10.0)] {
            let (s, _) = rect_solid_angle(vec3(0.0, 0.0, h), &square(2.0 * a), None);
            let want = 4.0 * ((a * a) / (a * a + h * h)).asin();
            assert!(
                (s - want).abs() <= 1e-5 * want.max(1e-3),
                "a {a} h {h}: {s} vs {want}"
            );
        }
    }

    #[test]
    fn samples_lie_on_the_rectangle_and_are_uniform_in_solid_angle() {
        // Off-axis: split the rectangle into quadrants; each holds its share of the
        // solid angle (the quadrants' own solid angles) to sampling accuracy.
        let r = square(2.0);
        let p = vec3(0.7, -0.3, 0.8);
        let (s, _) = rect_solid_angle(p, &r, None);
        let quad = |cu: f32, cv: f32| Region {
            centre: vec3(cu, cv, 0.0),
            len_u: 1.0,
            len_v: 1.0,
            ..r
        };
        let quads = [
            quad(-0.5, -0.5),
            quad(0.5, -0.5),
            quad(-0.5, 0.5),
            quad(0.5, 0.5),
        ];
        let mut count = [0u32; 4];
        let n = 64;
        for i in 0..n {
            for j in 0..n {
                let u = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                let (_, q) = rect_solid_angle(p, &r, Some(u));
                let q = q.unwrap();
                assert!(
                    q[2].abs() < 1e-5 && q[0].abs() <= 1.0 + 1e-5 && q[1].abs() <= 1.0 + 1e-5,
                    "{q:?}"
                );
                count[(q[0] > 0.0) as usize + 2 * (q[1] > 0.0) as usize] += 1;
            }
        }
        for (qi, q) in quads.iter().enumerate() {
            let want = rect_solid_angle(p, q, None).0 / s;
            let got = count[qi] as f32 / (n * n) as f32;
            assert!((got - want).abs() < 0.01, "quadrant {qi}: {got} vs {want}");
        }
    }

    #[test]
    fn spread_attenuation_integrates_to_one() {
        // Cycles' normalisation: over the hemisphere, attenuation x cos integrates to pi
        // (the radiance of a spreadless light).
        for deg in [10.0f32, 40.0, 90.0, 150.0] {
            let sp = Spread::new(deg.to_radians()).unwrap();
            let n = 20000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let d = vec3(-(theta.sin() as f32), 0.0, -(theta.cos() as f32));
                let a = sp.attenuation(d, Vec3::Z) as f64;
                sum += a * theta.cos() * theta.sin() * std::f64::consts::FRAC_PI_2 / n as f64
                    * 2.0
                    * std::f64::consts::PI;
            }
            assert!(
                (sum - std::f64::consts::PI).abs() < 2e-3 * std::f64::consts::PI,
                "{deg}: {sum}"
            );
        }
        assert!(Spread::new(PI).is_none());
    }
}
