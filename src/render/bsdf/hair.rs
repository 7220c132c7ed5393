//! Hair BSDF (Cycles' closure/bsdf_hair.h, from OSL): a Marschner-like lobe around the
//! hair's tangent, Reflection or Transmission component. The longitudinal angle is a
//! Cauchy lobe (width RoughnessU) about the mirror cone shifted by Offset; the azimuth a
//! cosine lobe (Reflection, width RoughnessV) or a Cauchy lobe about the back direction
//! (Transmission). As Cycles returns it, the value equals the pdf (BSDF times cosine).
//!
//! Cycles' reflection sample gives the pdf of its azimuth as cos(phi / 2) / (4 v), where
//! its evaluation (and the true density of the sampled azimuth) is cos(phi / (2 v)) /
//! (4 v): the two agree only at RoughnessV 1. The sampled direction's weight and MIS pdf
//! use the sample's figure, as in Cycles (`sample`), so they are kept apart here.

use std::f32::consts::{FRAC_PI_2, PI};

use crate::render::math::{Vec3, V3};

/// Where a hit lies across the fibre, for the Principled Hair models' offset h: on a hair
/// ribbon from its parametric v (h = -v); on a thick curve from the tube's normal `n`
/// (true and shading alike); on a mesh's faces, which Cycles shades with the same
/// closures, from the triangle's true normal `ng` (Chiang) or its shading normal `n`
/// (Huang), both facing the ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Across {
    Ribbon { v: f32 },
    Tube { n: V3 },
    Surface { ng: V3, n: V3 },
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hair {
    /// Unit tangent the lobes turn about.
    pub tangent: V3,
    /// Longitudinal (RoughnessU) and azimuthal (RoughnessV) widths, in [0.001, 1].
    pub roughness1: f32,
    pub roughness2: f32,
    /// Cuticle tilt in radians, already negated as Cycles' setup does.
    pub offset: f32,
    /// Transmission component (else Reflection).
    pub transmission: bool,
}

/// A sampled direction with the value and pdf Cycles' sample function returns (equal).
#[derive(Debug, Clone, Copy)]
pub struct HairSample {
    pub wi: Vec3,
    pub pdf: f32,
}

impl Hair {
    /// Cycles' bsdf_hair_*_setup: both roughnesses clamped to [0.001, 1].
    pub fn new(
        tangent: V3,
        roughness_u: f32,
        roughness_v: f32,
        offset: f32,
        transmission: bool,
    ) -> Hair {
        Hair {
            tangent,
            roughness1: roughness_u.clamp(0.001, 1.0),
            roughness2: roughness_v.clamp(0.001, 1.0),
            offset,
            transmission,
        }
    }

    /// The longitudinal bounds (atan of the Cauchy lobe's ends) for a viewer at
    /// elevation `theta_r`.
    fn theta_bounds(&self, theta_r: f32) -> (f32, f32) {
        let inv = 1.0 / self.roughness1;
        let a = (((FRAC_PI_2 + theta_r) * 0.5 - self.offset) * inv).atan();
        let b = (((-FRAC_PI_2 + theta_r) * 0.5 - self.offset) * inv).atan();
        (a, b)
    }

    fn theta_pdf(&self, t: f32, a: f32, b: f32, cos_theta_i: f32) -> f32 {
        let r = self.roughness1;
        r / (2.0 * (t * t + r * r) * (a - b) * cos_theta_i)
    }

    /// BSDF times cosine toward `light` (equal to its pdf) for a viewer along `view`;
    /// `n` is the closure's normal, which only decides the side.
    pub fn eval(&self, n: Vec3, view: Vec3, light: Vec3) -> f32 {
        let side = n.dot(light);
        if (self.transmission && side >= 0.0) || (!self.transmission && side < 0.0) {
            return 0.0;
        }
        let t = Vec3::from(self.tangent);
        let iz = t.dot(view);
        let locy = (view - t * iz).normalize();
        let theta_r = FRAC_PI_2 - iz.clamp(-1.0, 1.0).acos();
        let wz = t.dot(light);
        let wy = (light - t * wz).normalize();
        let theta_i = FRAC_PI_2 - wz.clamp(-1.0, 1.0).acos();
        let cosphi = wy.dot(locy);
        if FRAC_PI_2 - theta_i.abs() < 0.001 || !cosphi.is_finite() {
            return 0.0;
        }
        let (a, b) = self.theta_bounds(theta_r);
        let th = (theta_i + theta_r) * 0.5 - self.offset;
        let theta_pdf = self.theta_pdf(th, a, b, theta_i.cos());
        let phi_pdf = if self.transmission {
            let r2 = self.roughness2;
            let c = 2.0 * (FRAC_PI_2 / r2).atan();
            let p = PI - cosphi.clamp(-1.0, 1.0).acos().abs();
            r2 / (c * (p * p + r2 * r2))
        } else {
            if cosphi < 0.0 {
                return 0.0;
            }
            let inv = 1.0 / self.roughness2;
            let phi = cosphi.clamp(-1.0, 1.0).acos() * inv;
            let phi = if phi.abs() < PI { phi } else { PI };
            (phi * 0.5).cos() * 0.25 * inv
        };
        let pdf = phi_pdf * theta_pdf;
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    /// Cycles' bsdf_hair_*_sample: a direction and the pdf (= value) Cycles gives it;
    /// None where Cycles' pdf is zero (the path ends there).
    pub fn sample(&self, view: Vec3, u: [f32; 2]) -> Option<HairSample> {
        let t = Vec3::from(self.tangent);
        let iz = t.dot(view);
        let locy = (view - t * iz).normalize();
        let locx = locy.cross(t);
        let theta_r = FRAC_PI_2 - iz.clamp(-1.0, 1.0).acos();
        let (a, b) = self.theta_bounds(theta_r);
        let th = self.roughness1 * (u[0] * (a - b) + b).tan();
        let theta_i = 2.0 * (th + self.offset) - theta_r;
        let (sin_ti, cos_ti) = theta_i.sin_cos();
        let theta_pdf = self.theta_pdf(th, a, b, cos_ti);
        let r2 = self.roughness2;
        let (phi, phi_pdf) = if self.transmission {
            let c = 2.0 * (FRAC_PI_2 / r2).atan();
            let p = r2 * (c * (u[1] - 0.5)).tan();
            (p + PI, r2 / (c * (p * p + r2 * r2)))
        } else {
            let phi = 2.0 * (1.0 - 2.0 * u[1]).clamp(-1.0, 1.0).asin() * r2;
            (phi, (phi * 0.5).cos() * 0.25 / r2)
        };
        let (sin_p, cos_p) = phi.sin_cos();
        let wi = locy * (cos_p * cos_ti) + locx * (-sin_p * cos_ti) + t * sin_ti;
        let pdf = (phi_pdf * theta_pdf).abs();
        if FRAC_PI_2 - theta_i.abs() < 0.001 || !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some(HairSample { wi, pdf })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::render::math::vec3;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        vec3(
            theta.cos() * phi.cos(),
            theta.cos() * phi.sin(),
            theta.sin(),
        )
    }

    /// Tangent +z, normal +x toward a viewer in the x-z plane.
    fn setup(transmission: bool, r1: f32, r2: f32) -> (Hair, Vec3, Vec3) {
        let h = Hair::new([0.0, 0.0, 1.0], r1, r2, -0.05, transmission);
        let view = vec3(1.0, 0.0, 0.4).normalize();
        (h, Vec3::X, view)
    }

    /// The sample's pdf is evaluation's wherever Cycles' two formulas agree: the
    /// transmission lobe always, the reflection lobe at RoughnessV 1.
    #[test]
    fn sample_pdf_matches_eval_pdf() {
        for (transmission, r2) in [(true, 0.3), (true, 1.0), (false, 1.0)] {
            let (h, n, view) = setup(transmission, 0.2, r2);
            let mut checked = 0;
            for i in 0..16 {
                for j in 0..16 {
                    let u = [(i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0];
                    let Some(s) = h.sample(view, u) else { continue };
                    let e = h.eval(n, view, s.wi);
                    if e == 0.0 {
                        continue; // sampled on the side this component does not give
                    }
                    assert!(
                        (e - s.pdf).abs() <= 2e-3 * s.pdf.max(1.0),
                        "{transmission} {r2} {u:?}: eval {e} sample {}",
                        s.pdf
                    );
                    checked += 1;
                }
            }
            assert!(checked > 100, "{checked}");
        }
    }

    /// Cycles' reflection sample misstates its azimuth pdf below RoughnessV 1: kept.
    #[test]
    fn reflection_sample_pdf_is_cycles_not_evals() {
        let (h, n, view) = setup(false, 0.2, 0.3);
        let s = h.sample(view, [0.5, 0.2]).unwrap();
        let e = h.eval(n, view, s.wi);
        assert!(e > 0.0 && (e - s.pdf).abs() > 0.05 * e, "{e} {}", s.pdf);
    }

    /// Evaluation is a density over the sphere: it integrates to at most one (each
    /// component alone; its lobe loses what falls on the other side).
    #[test]
    fn pdf_integrates_to_at_most_one() {
        for transmission in [false, true] {
            let (h, n, view) = setup(transmission, 0.3, 0.5);
            let (nt, np) = (400, 800);
            let mut sum = 0.0f64;
            for i in 0..nt {
                let theta = -FRAC_PI_2 + (i as f32 + 0.5) / nt as f32 * PI;
                for j in 0..np {
                    let phi = (j as f32 + 0.5) / np as f32 * 2.0 * PI;
                    let w = theta.cos() * (PI / nt as f32) * (2.0 * PI / np as f32);
                    // dir's z is the tangent.
                    sum += (h.eval(n, view, dir(theta, phi)) * w) as f64;
                }
            }
            assert!(sum > 0.3 && sum < 1.01, "{transmission}: {sum}");
        }
    }

    #[test]
    fn sides() {
        let (r, n, view) = setup(false, 0.2, 0.5);
        let (t, _, _) = setup(true, 0.2, 0.5);
        let front = vec3(1.0, 0.2, -0.1).normalize();
        let back = vec3(-1.0, 0.2, -0.1).normalize();
        assert!(r.eval(n, view, front) > 0.0 && r.eval(n, view, back) == 0.0);
        assert!(t.eval(n, view, back) > 0.0 && t.eval(n, view, front) == 0.0);
    }
}
