//! Anisotropic GGX reflection as Cycles 4.x has it (closure/bsdf_microfacet.h with
//! alpha_x != alpha_y): the stretched GGX distribution in the frame of the closure's
//! tangent, the anisotropic Smith Lambda, visible-normal sampling of the stretched
//! distribution. Used by the Glossy BSDF (Anisotropy, Rotation, Tangent) and the
//! Principled BSDF's metallic and specular layers (Anisotropic, Anisotropic Rotation,
//! Tangent). The Fresnel factor is the caller's (`bsdf`), applied with the cosine between
//! the viewer and the microfacet normal this returns.
//!
//! Directions: `v` toward the viewer, `l` toward the light.

use crate::render::bsdf::microfacet::{ggx_vndf, ROUGHNESS_SQ_THRESH};
use crate::render::math::*;
use std::f32::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnisoGgx {
    pub alpha_x: f32,
    pub alpha_y: f32,
    /// Tangent (alpha_x direction) and bitangent, orthonormal to the closure normal.
    pub x: Vec3,
    pub y: Vec3,
}

/// Cycles' rotate_around_axis: `p` rotated by `angle` radians about unit `axis`.
pub fn rotate_around_axis(p: V3, axis: V3, angle: f32) -> V3 {
    let (p, axis) = (Vec3::from(p), Vec3::from(axis));
    let (s, c) = angle.sin_cos();
    (p * c + axis.cross(p) * s + axis * (axis.dot(p) * (1.0 - c))).into()
}

/// Glossy BSDF roughness parameters: alpha = roughness^2 stretched by the anisotropy
/// (clamped to +-0.99), as Cycles' SVM sets them up before clamping alphas to [0, 1].
pub fn glossy_alphas(roughness: f32, anisotropy: f32) -> (f32, f32) {
    let r = roughness.clamp(0.0, 1.0);
    let a = r * r;
    let k = anisotropy.clamp(-0.99, 0.99);
    let (ax, ay) = if k < 0.0 {
        (a / (1.0 + k), a * (1.0 + k))
    } else {
        (a * (1.0 - k), a / (1.0 - k))
    };
    (ax.clamp(0.0, 1.0), ay.clamp(0.0, 1.0))
}

/// Principled BSDF roughness parameters: aspect sqrt(1 - 0.9 anisotropic).
pub fn principled_alphas(roughness: f32, anisotropic: f32) -> (f32, f32) {
    let a = roughness.clamp(0.0, 1.0).powi(2);
    let k = anisotropic.clamp(0.0, 1.0);
    if k <= 0.0 {
        return (a, a);
    }
    let aspect = (1.0 - k * 0.9).sqrt();
    ((a / aspect).clamp(0.0, 1.0), (a * aspect).clamp(0.0, 1.0))
}

impl AnisoGgx {
    /// The closure for normal `n` and tangent `t` (not necessarily orthogonal to `n`;
    /// Cycles' make_orthonormals_tangent). A tangent along the normal leaves any frame.
    pub fn new(n: V3, t: V3, alpha_x: f32, alpha_y: f32) -> AnisoGgx {
        let (n, t) = (Vec3::from(n), Vec3::from(t));
        let c = n.cross(t);
        let (x, y) = if c.dot(c) > 1e-12 && c.is_finite() {
            let y = c.normalize();
            (y.cross(n), y)
        } else {
            n.basis()
        };
        AnisoGgx {
            alpha_x,
            alpha_y,
            x,
            y,
        }
    }

    pub fn singular(&self) -> bool {
        self.alpha_x * self.alpha_y <= ROUGHNESS_SQ_THRESH
    }

    /// Roughness whose isotropic albedo tables stand for this lobe (Cycles:
    /// sqrt(sqrt(alpha_x * alpha_y))).
    pub fn table_roughness(&self) -> f32 {
        (self.alpha_x * self.alpha_y).sqrt().sqrt()
    }

    fn local(&self, n: Vec3, w: Vec3) -> Vec3 {
        vec3(self.x.dot(w), self.y.dot(w), n.dot(w))
    }

    fn lambda(&self, w: Vec3) -> f32 {
        let t2 = ((self.alpha_x * w[0]).powi(2) + (self.alpha_y * w[1]).powi(2)) / (w[2] * w[2]);
        0.5 * ((1.0 + t2).sqrt() - 1.0)
    }

    fn d(&self, h: Vec3) -> f32 {
        let s = vec3(h[0] / self.alpha_x, h[1] / self.alpha_y, h[2]);
        let l2 = s.dot(s);
        1.0 / (PI * self.alpha_x * self.alpha_y * l2 * l2)
    }

    /// (BSDF * cos without Fresnel, pdf, cos(view, microfacet normal)) toward `l`.
    pub fn eval(&self, n: Vec3, v: Vec3, l: Vec3, ng: Vec3) -> (f32, f32, f32) {
        let (cos_v, cos_l) = (n.dot(v), n.dot(l));
        if cos_v <= 0.0 || cos_l <= 0.0 || ng.dot(l) <= 0.0 || self.singular() {
            return (0.0, 0.0, 0.0);
        }
        let h = (v + l).normalize();
        let (lv, ll, lh) = (self.local(n, v), self.local(n, l), self.local(n, h));
        let d = self.d(lh);
        let (lam_v, lam_l) = (self.lambda(lv), self.lambda(ll));
        let common = d * 0.25 / cos_v;
        (
            common / (1.0 + lam_v + lam_l),
            common / (1.0 + lam_v),
            v.dot(h),
        )
    }

    /// A reflected direction from a visible microfacet normal.
    pub fn sample(&self, n: Vec3, v: Vec3, ng: Vec3, u: [f32; 2]) -> Option<Vec3> {
        let lv = self.local(n, v);
        if lv[2] <= 0.0 {
            return None;
        }
        let h = ggx_vndf(lv, self.alpha_x, self.alpha_y, u);
        let hv = h.dot(lv);
        let ll = h * (2.0 * hv) - lv;
        if ll[2] <= 0.0 {
            return None;
        }
        let l = self.x * ll[0] + self.y * ll[1] + n * ll[2];
        if ng.dot(l) <= 0.0 {
            return None;
        }
        Some(l)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isotropic_limit_is_ggx() {
        // With equal alphas the anisotropic lobe is the isotropic GGX of bsdf.rs.
        let n = Vec3::Z;
        let g = AnisoGgx::new(n.into(), [1.0, 0.0, 0.0], 0.3, 0.3);
        let v = vec3(0.4, 0.1, 0.8).normalize();
        let l = vec3(-0.3, 0.2, 0.7).normalize();
        let (f, pdf, _) = g.eval(n, v, l, n);
        let h = (v + l).normalize();
        let a2 = 0.09;
        let d = crate::render::bsdf::ggx_d(h[2], a2);
        let (lv, ll) = (
            crate::render::bsdf::ggx_lambda(v[2], a2),
            crate::render::bsdf::ggx_lambda(l[2], a2),
        );
        assert!((f - d / (4.0 * v[2]) / (1.0 + lv + ll)).abs() < 1e-5 * f.max(1.0));
        assert!((pdf - d / (4.0 * v[2]) / (1.0 + lv)).abs() < 1e-5 * pdf.max(1.0));
    }

    #[test]
    fn sampling_matches_eval_pdf() {
        // Mean of f / pdf over samples equals the integral of f by uniform sampling.
        let n = Vec3::Z;
        let g = AnisoGgx::new(n.into(), [0.6, 0.8, 0.0], 0.15, 0.6);
        let v = vec3(0.5, -0.2, 0.6).normalize();
        let s = crate::render::sampler::PixelSampler::new(4, 5, 6);
        let count = 40000;
        let (mut by_sample, mut uniform) = (0.0f64, 0.0f64);
        for i in 0..count {
            let u = s.get4(i, 0);
            if let Some(l) = g.sample(n, v, n, [u[0], u[1]]) {
                let (f, p, _) = g.eval(n, v, l, n);
                if p > 0.0 {
                    by_sample += (f / p) as f64;
                }
            }
            let z = u[2];
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = 2.0 * PI * u[3];
            let (f, _, _) = g.eval(n, v, vec3(r * phi.cos(), r * phi.sin(), z), n);
            uniform += (f * 2.0 * PI) as f64;
        }
        let (a, b) = (by_sample / count as f64, uniform / count as f64);
        assert!((a - b).abs() < 0.02, "{a} vs {b}");
    }

    #[test]
    fn rotation_about_the_normal() {
        let r = rotate_around_axis(
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            std::f32::consts::FRAC_PI_2,
        );
        assert!((r[0]).abs() < 1e-6 && (r[1] - 1.0).abs() < 1e-6 && r[2].abs() < 1e-6);
    }
}
