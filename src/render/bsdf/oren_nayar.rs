//! Oren-Nayar diffuse as Cycles 4.x has it (closure/bsdf_oren_nayar.h): Fujii's improved
//! Oren-Nayar model plus the energy-preserving multiple-scattering term of OpenPBR.
//! Sampled like Lambert (cosine hemisphere).

use crate::render::math::*;
use std::f32::consts::{FRAC_PI_2, PI};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrenNayar {
    pub a: f32,
    pub b: f32,
    /// Multiple-scattering term without its (1 - E(light)) factor.
    pub ms: Vec3,
}

/// Fujii's directional albedo integral G(cos theta).
fn g(cos: f32) -> f32 {
    if cos < 1e-6 {
        // tan(theta) misbehaves near grazing: Taylor expansion.
        return (FRAC_PI_2 - 2.0 / 3.0) - cos;
    }
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let theta = cos.clamp(-1.0, 1.0).acos();
    sin * (theta - 2.0 / 3.0 - sin * cos) + 2.0 / 3.0 * (sin / cos) * (1.0 - sin * sin * sin)
}

impl OrenNayar {
    /// Setup for roughness sigma, surface colour `albedo` (clamped to [0, 1]) and the
    /// cosine between the normal and the viewer.
    pub fn new(roughness: f32, albedo: V3, cos_nv: f32) -> OrenNayar {
        let sigma = roughness.clamp(0.0, 1.0);
        let a = 1.0 / (PI + sigma * (FRAC_PI_2 - 2.0 / 3.0));
        let b = sigma * a;
        let e_avg = a * PI + ((2.0 * PI - 5.6) / 3.0) * b;
        let ev = a * PI + b * g(cos_nv.max(0.0));
        let ms = Vec3::from(albedo).map(|c| {
            let c = c.clamp(0.0, 1.0);
            (1.0 / PI) * c * c * (e_avg / (1.0 - e_avg)) / (1.0 - c * (1.0 - e_avg)) * (1.0 - ev)
        });
        OrenNayar { a, b, ms }
    }

    /// BSDF times cos toward `l` (normal `n`, viewer `v`); zero below the surface.
    pub fn eval(&self, n: Vec3, v: Vec3, l: Vec3) -> Vec3 {
        let nl = n.dot(l).max(0.0);
        let nv = n.dot(v).max(0.0);
        let mut t = l.dot(v) - nl * nv;
        if t > 0.0 {
            t /= nl.max(nv) + f32::MIN_POSITIVE;
        }
        let single = self.a + self.b * t;
        let el = self.a * PI + self.b * g(nl);
        let ms = self.ms * (1.0 - el);
        (Vec3::splat(single) + ms) * nl
    }
}
