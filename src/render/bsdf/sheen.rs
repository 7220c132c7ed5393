//! Sheen closures as Cycles 4.x has them: the microfiber sheen of Zeltner, Burley and
//! Chiang 2022 (closure/bsdf_sheen.h), a linearly transformed cosine whose two
//! coefficients and albedo come from a 32x32 table over (roughness, cos(N, view))
//! (`sheen_ltc`), and Ashikhmin's velvet (closure/bsdf_ashikhmin_velvet.h), the Sheen
//! BSDF node's other distribution. Both scatter like diffuse (Cycles labels them
//! REFLECT | DIFFUSE). `eval` returns BSDF times the light cosine, like every closure here.
//!
//! Directions: `v` toward the viewer, `l` toward the light.

use crate::render::bsdf::sheen_ltc::SHEEN_LTC;
use crate::render::math::*;
use std::f32::consts::PI;

const TABLE: usize = 32;

/// Cycles' lookup_table_read over one row of `TABLE` values: `x` clamped to [0, 1],
/// linear between the two nearest entries.
fn read_row(row: &[f32], x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0) * (TABLE - 1) as f32;
    let i = (x as usize).min(TABLE - 1);
    let j = (i + 1).min(TABLE - 1);
    let t = x - i as f32;
    if t == 0.0 {
        return row[i];
    }
    (1.0 - t) * row[i] + t * row[j]
}

/// Cycles' lookup_table_read_2D on table plane `plane`: columns by `x`, rows by `y`.
fn read_2d(plane: usize, x: f32, y: f32) -> f32 {
    let base = plane * TABLE * TABLE;
    let y = y.clamp(0.0, 1.0) * (TABLE - 1) as f32;
    let i = (y as usize).min(TABLE - 1);
    let j = (i + 1).min(TABLE - 1);
    let t = y - i as f32;
    let r0 = read_row(&SHEEN_LTC[base + i * TABLE..base + (i + 1) * TABLE], x);
    if t == 0.0 {
        return r0;
    }
    let r1 = read_row(&SHEEN_LTC[base + j * TABLE..base + (j + 1) * TABLE], x);
    (1.0 - t) * r0 + t * r1
}

/// The microfiber sheen lobe at one shading point (its frame follows the viewer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sheen {
    /// LTC coefficients: the inverse transform is [[a, 0, b], [0, a, 0], [0, 0, 1]].
    pub a: f32,
    pub b: f32,
    /// Tangent toward the viewer and bitangent (with the normal, a right-handed frame).
    pub t: Vec3,
    pub bt: Vec3,
}

impl Sheen {
    /// Setup for normal `n`, viewer `v` and roughness (clamped to [1e-3, 1]); returns the
    /// lobe and its albedo, which scales the closure weight (and its selection weight).
    pub fn new(n: V3, v: V3, roughness: f32) -> (Sheen, f32) {
        let (n, v) = (Vec3::from(n), Vec3::from(v));
        let r = if roughness.is_finite() {
            roughness.clamp(1e-3, 1.0)
        } else {
            1.0
        };
        // Cycles' make_orthonormals_tangent(N, view); a viewer along N has any frame.
        let c = n.cross(v);
        let (t, bt) = if c.dot(c) > 1e-12 {
            let bt = c.normalize();
            (bt.cross(n), bt)
        } else {
            n.basis()
        };
        let mu = n.dot(v);
        let a = read_2d(0, mu, r);
        let b = read_2d(1, mu, r);
        let albedo = read_2d(2, mu, r);
        (Sheen { a, b, t, bt }, albedo)
    }

    /// LTC density at a local direction (z along the normal): the cosine-weighted BSDF,
    /// which is also its sampling pdf.
    fn density(&self, l: Vec3) -> f32 {
        let (a, b) = (self.a, self.b);
        let len_sq = (a * l[0] + b * l[2]).powi(2) + (a * l[1]).powi(2) + l[2] * l[2];
        if !(len_sq > 0.0) {
            return 0.0;
        }
        l[2] * (a / len_sq).powi(2) / PI
    }

    /// (BSDF * cos, pdf) toward `l`; `ng` faces the viewer.
    pub fn eval(&self, n: Vec3, l: Vec3, ng: Vec3) -> (f32, f32) {
        let z = n.dot(l);
        if z <= 0.0 || ng.dot(l) <= 0.0 || self.a <= 0.0 {
            return (0.0, 0.0);
        }
        let p = self.density(vec3(self.t.dot(l), self.bt.dot(l), z));
        (p, p)
    }

    /// A direction drawn from the LTC: a cosine-distributed direction (from the uniform
    /// disk) mapped through the transform.
    pub fn sample(&self, n: Vec3, ng: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if self.a <= 0.0 {
            return None;
        }
        let d = crate::render::camera::concentric_disk(u);
        let dz = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
        let local = vec3((d[0] - dz * self.b) / self.a, d[1] / self.a, dz).normalize();
        let l = self.t * local[0] + self.bt * local[1] + n * local[2];
        if ng.dot(l) <= 0.0 || n.dot(l) <= 0.0 {
            return None;
        }
        Some(l)
    }
}

/// Ashikhmin's velvet (Sheen BSDF with the Ashikhmin distribution), sampled uniformly
/// over the hemisphere.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Velvet {
    pub inv_sigma2: f32,
}

impl Velvet {
    /// Setup for roughness sigma (the node's Roughness, clamped to [0, 1] by the node and
    /// to at least 0.01 here, as Cycles does).
    pub fn new(sigma: f32) -> Velvet {
        let s = if sigma.is_finite() {
            sigma.clamp(0.0, 1.0)
        } else {
            1.0
        }
        .max(0.01);
        Velvet {
            inv_sigma2: 1.0 / (s * s),
        }
    }

    /// (BSDF * cos, pdf) toward `l` for a viewer at `v`.
    pub fn eval(&self, n: Vec3, v: Vec3, l: Vec3, ng: Vec3) -> (f32, f32) {
        let cos_nv = n.dot(v);
        let cos_nl = n.dot(l);
        if !(cos_nv > 0.0 && cos_nl > 0.0) || ng.dot(l) <= 0.0 {
            return (0.0, 0.0);
        }
        let h = (v + l).normalize();
        let cos_nh = n.dot(h);
        let cos_hv = v.dot(h).abs();
        if !(cos_nh.abs() < 1.0 - 1e-5 && cos_hv > 1e-5) {
            return (0.0, 0.0);
        }
        let k = (cos_nh / cos_hv).max(1e-5);
        let g = (2.0 * (k * cos_nv).abs())
            .min(2.0 * (k * cos_nl).abs())
            .min(1.0);
        let sin2 = 1.0 - cos_nh * cos_nh;
        let cot2 = cos_nh * cos_nh / sin2;
        let d = (-cot2 * self.inv_sigma2).exp() * self.inv_sigma2 / (PI * sin2 * sin2);
        (0.25 * d * g / cos_nv, 0.5 / PI)
    }

    pub fn sample(&self, n: Vec3, ng: Vec3, u: [f32; 2]) -> Option<Vec3> {
        // Uniform hemisphere about n.
        let z = u[0];
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u[1];
        let (t, b) = n.basis();
        let l = t * (r * phi.cos()) + b * (r * phi.sin()) + n * z;
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
    fn table_lookup_matches_its_grid() {
        // On grid points the lookup returns the entry itself (row = roughness, column = mu).
        let (row, col) = (20usize, 7usize);
        let got = read_2d(2, col as f32 / 31.0, row as f32 / 31.0);
        assert!((got - SHEEN_LTC[2 * 1024 + row * 32 + col]).abs() < 1e-6);
        // Between entries it is bilinear.
        let mid = read_2d(0, 7.5 / 31.0, 20.5 / 31.0);
        let e = |r: usize, c: usize| SHEEN_LTC[r * 32 + c];
        let want = 0.25 * (e(20, 7) + e(20, 8) + e(21, 7) + e(21, 8));
        assert!((mid - want).abs() < 1e-5, "{mid} vs {want}");
    }

    #[test]
    fn ltc_is_a_normalised_density_that_its_sampler_draws() {
        // The LTC's integral over the upper hemisphere is at most 1 (the transform keeps
        // the cosine lobe's mass; clipping below the horizon removes some), and the mean
        // of 1 over sampled directions' pdf-weighted counts is consistent with eval.
        let n = Vec3::Z;
        for (mu, r) in [(0.9f32, 0.3f32), (0.4, 0.7), (0.15, 1.0)] {
            let v = vec3((1.0 - mu * mu).sqrt(), 0.0, mu);
            let (s, _) = Sheen::new(n.into(), v.into(), r);
            let sampler = crate::render::sampler::PixelSampler::new(1, 2, 3);
            let count = 20000;
            let (mut hits, mut integral) = (0, 0.0f64);
            for i in 0..count {
                let u = sampler.get4(i, 0);
                if let Some(l) = s.sample(n, n, [u[0], u[1]]) {
                    let (f, p) = s.eval(n, l, n);
                    assert!((f - p).abs() <= 1e-6 * p.max(1.0));
                    hits += 1;
                }
                // Uniform-hemisphere estimate of the integral of eval.
                let z = u[2];
                let rr = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * PI * u[3];
                let (f, _) = s.eval(n, vec3(rr * phi.cos(), rr * phi.sin(), z), n);
                integral += (f * 2.0 * PI) as f64;
            }
            let integral = integral / count as f64;
            let kept = hits as f64 / count as f64;
            // The sampler keeps exactly the mass the density has above the horizon.
            assert!(
                (integral - kept).abs() < 0.03,
                "mu {mu} r {r}: integral {integral}, kept {kept}"
            );
        }
    }
}
