//! Toon BSDF (Cycles' closure/bsdf_toon.h): full intensity within `size` (a fraction of
//! 90 degrees) of the normal (Diffuse) or of the mirror direction (Glossy), fading
//! linearly over `smooth` beyond it; sampled uniformly in the cone it covers. As Cycles
//! returns it, the value is the cone's pdf times the intensity (BSDF times cosine).

use std::f32::consts::{FRAC_PI_2, PI};

use crate::render::math::*;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Toon {
    /// Radians of full intensity.
    max_angle: f32,
    /// Radians of the linear fade beyond it.
    smooth: f32,
    /// Around the mirror direction (Glossy component) instead of the normal.
    pub glossy: bool,
}

impl Toon {
    /// Cycles' bsdf_toon_setup_common: Size clamped to [1e-5, 1] and Smooth to [0, 1],
    /// both times 90 degrees.
    pub fn new(size: f32, smooth: f32, glossy: bool) -> Toon {
        Toon {
            max_angle: size.clamp(1e-5, 1.0) * FRAC_PI_2,
            smooth: smooth.clamp(0.0, 1.0) * FRAC_PI_2,
            glossy,
        }
    }

    fn intensity(&self, angle: f32) -> f32 {
        if angle < self.max_angle {
            1.0
        } else if angle < self.max_angle + self.smooth && self.smooth != 0.0 {
            1.0 - (angle - self.max_angle) / self.smooth
        } else {
            0.0
        }
    }

    fn sample_angle(&self) -> f32 {
        (self.max_angle + self.smooth).min(FRAC_PI_2)
    }

    fn pdf(&self) -> f32 {
        1.0 / (2.0 * PI * (1.0 - self.sample_angle().cos()))
    }

    /// The cone's axis for view direction `wo` (toward the viewer): the normal, or the
    /// mirror direction. None where Glossy sees the surface from below.
    fn axis(&self, n: Vec3, wo: Vec3) -> Option<Vec3> {
        if !self.glossy {
            return Some(n);
        }
        let c = n.dot(wo);
        (c > 0.0).then(|| n * (2.0 * c) - wo)
    }

    /// (BSDF times cosine, pdf) toward `wi` (toward the light), seen from `wo`.
    pub fn eval(&self, n: Vec3, wo: Vec3, wi: Vec3) -> (f32, f32) {
        let cos_n = n.dot(wi);
        let ok = if self.glossy {
            cos_n > 0.0
        } else {
            cos_n >= 0.0
        };
        let Some(axis) = self.axis(n, wo).filter(|_| ok) else {
            return (0.0, 0.0);
        };
        // Cycles' safe_acosf(fmaxf(cos, 0)): NaN and rounding past 1 stay in range.
        let c = axis.dot(wi).max(0.0);
        let angle = if c >= 1.0 { 0.0 } else { c.acos() };
        if angle < self.sample_angle() {
            let pdf = self.pdf();
            (pdf * self.intensity(angle), pdf)
        } else {
            (0.0, 0.0)
        }
    }

    /// A direction uniformly in the cone (Cycles' sample_uniform_cone), above the true
    /// normal `ng` (and above `n` for Glossy).
    pub fn sample(&self, n: Vec3, wo: Vec3, ng: Vec3, u: [f32; 2]) -> Option<Vec3> {
        let axis = self.axis(n, wo)?;
        let one_minus_cos = 1.0 - self.sample_angle().cos();
        let d = crate::render::camera::concentric_disk(u);
        let r2 = d[0] * d[0] + d[1] * d[1];
        let cos_theta = 1.0 - r2 * one_minus_cos;
        let k = (one_minus_cos * (2.0 - one_minus_cos * r2)).max(0.0).sqrt();
        let (t, b) = axis.basis();
        let wi = t * (d[0] * k) + b * (d[1] * k) + axis * cos_theta;
        if ng.dot(wi) <= 0.0 || (self.glossy && n.dot(wi) <= 0.0) {
            return None;
        }
        Some(wi)
    }
}
