//! Microfacet distributions and the dielectric interface as Cycles 4.x defines them
//! (kernel/closure/bsdf_microfacet.h): GGX and Beckmann normal distributions, Smith
//! masking-shadowing in the non-separable form, visible-normal sampling, and the glass
//! and refraction closures (rough or sharp), which pick reflection or refraction in
//! proportion to the tinted Fresnel reflectance and transmittance.
//!
//! Directions: `v` points toward the viewer (Cycles' `wi`), `l` is the scattered or light
//! direction (Cycles' `wo`). `eval` returns BSDF times |cos| as Cycles' closures do.

use crate::render::math::*;
use std::f32::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distribution {
    Ggx,
    Beckmann,
}

/// Below this alpha_x * alpha_y a closure is singular (Cycles' BSDF_ROUGHNESS_SQ_THRESH).
pub const ROUGHNESS_SQ_THRESH: f32 = 2e-10;

/// Normal distribution D for squared alpha `a2`.
#[inline]
pub fn d(dist: Distribution, a2: f32, cos_nh: f32) -> f32 {
    let c2 = (cos_nh * cos_nh).min(1.0);
    let s2 = 1.0 - c2;
    match dist {
        Distribution::Beckmann => 1.0 / ((s2 / (c2 * a2)).exp() * PI * a2 * c2 * c2),
        Distribution::Ggx => a2 / (PI * (s2 + a2 * c2) * (s2 + a2 * c2)),
    }
}

/// Smith Lambda from alpha^2 tan^2(theta).
#[inline]
fn lambda_from(dist: Distribution, a2t2: f32) -> f32 {
    match dist {
        Distribution::Ggx => 0.5 * ((1.0 + a2t2).sqrt() - 1.0),
        Distribution::Beckmann => {
            // Walter et al.'s rational approximation, exact enough above a = 1.6.
            if a2t2 < 0.39 {
                return 0.0;
            }
            let a = 1.0 / a2t2.sqrt();
            ((0.396 * a - 1.259) * a + 1.0) / ((2.181 * a + 3.535) * a)
        }
    }
}

#[inline]
pub fn lambda(dist: Distribution, a2: f32, cos_n: f32) -> f32 {
    lambda_from(dist, a2 * (1.0 / (cos_n * cos_n) - 1.0).max(0.0))
}

/// Error function (Abramowitz and Stegun 7.1.26, |error| < 1.5e-7).
pub fn erf(x: f32) -> f32 {
    let s = x.signum();
    let x = x.abs();
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let y = 1.0
        - (((((1.061_405_4 * t - 1.453_152_1) * t) + 1.421_413_7) * t - 0.284_496_74) * t
            + 0.254_829_6)
            * t
            * (-x * x).exp();
    s * y
}

/// Inverse error function (Giles' single-precision approximation).
pub fn erfinv(x: f32) -> f32 {
    let x = x.clamp(-0.999_999, 0.999_999);
    let mut w = -((1.0 - x) * (1.0 + x)).ln();
    let p;
    if w < 5.0 {
        w -= 2.5;
        let mut q = 2.810_226_4e-8;
        q = 3.432_739_4e-7 + q * w;
        q = -3.523_387_6e-6 + q * w;
        q = -4.391_506_5e-6 + q * w;
        q = 0.000_218_580_87 + q * w;
        q = -0.001_253_725 + q * w;
        q = -0.004_177_681_6 + q * w;
        q = 0.246_640_73 + q * w;
        p = 1.501_409_4 + q * w;
    } else {
        w = w.sqrt() - 3.0;
        let mut q = -0.000_200_214_26;
        q = 0.000_100_950_56 + q * w;
        q = 0.001_349_343_2 + q * w;
        q = -0.003_673_428_4 + q * w;
        q = 0.005_739_507_7 + q * w;
        q = -0.007_622_461 + q * w;
        q = 0.009_438_870_5 + q * w;
        q = 1.001_674_1 + q * w;
        p = 2.832_976_8 + q * w;
    }
    p * x
}

/// Visible normal of GGX (Heitz 2018), local frame with N = +z.
pub fn sample_ggx_vndf(v: V3, ax: f32, ay: f32, u: [f32; 2]) -> V3 {
    ggx_vndf(v.into(), ax, ay, u).into()
}

pub(crate) fn ggx_vndf(v: Vec3, ax: f32, ay: f32, u: [f32; 2]) -> Vec3 {
    let vh = vec3(ax * v[0], ay * v[1], v[2]).normalize();
    let lensq = vh[0] * vh[0] + vh[1] * vh[1];
    let (t1, t2) = if lensq > 1e-7 {
        let t1 = vec3(-vh[1], vh[0], 0.0) * (1.0 / lensq.sqrt());
        (t1, vh.cross(t1))
    } else {
        (Vec3::X, Vec3::Y)
    };
    let t = crate::render::camera::concentric_disk(u);
    let (tx, mut ty) = (t[0], t[1]);
    let s = 0.5 * (1.0 + vh[2]);
    ty = (1.0 - tx * tx).max(0.0).sqrt() * (1.0 - s) + ty * s;
    let nh = t1 * tx + t2 * ty + vh * (1.0 - tx * tx - ty * ty).max(0.0).sqrt();
    vec3(ax * nh[0], ay * nh[1], nh[2].max(0.0)).normalize()
}

/// Visible normal of Beckmann (Heitz and d'Eon 2014 with Jakob's improved slope
/// inversion), local frame with N = +z.
pub fn sample_beckmann_vndf(v: Vec3, ax: f32, ay: f32, u: [f32; 2]) -> Vec3 {
    let vs = vec3(ax * v[0], ay * v[1], v[2]).normalize();
    let (mut sx, mut sy);
    let (mut cos_phi, mut sin_phi) = (1.0f32, 0.0f32);
    if vs[2] >= 0.99999 {
        let r = (-(u[0].max(1e-12)).ln()).sqrt();
        let phi = 2.0 * PI * u[1];
        sx = r * phi.cos();
        sy = r * phi.sin();
    } else {
        let cos_t = vs[2];
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let tan_t = sin_t / cos_t;
        let cot_t = 1.0 / tan_t;
        let erf_a = erf(cot_t);
        let exp_a2 = (-cot_t * cot_t).exp();
        const SQRT_PI_INV: f32 = 0.564_189_6;
        cos_phi = vs[0] / sin_t;
        sin_phi = vs[1] / sin_t;
        let k = tan_t * SQRT_PI_INV;
        let y_approx = u[0] * (1.0 + erf_a + k * (1.0 - erf_a * erf_a));
        let y_exact = u[0] * (1.0 + erf_a + k * exp_a2);
        let b = if k > 0.0 {
            (0.5 - (k * (k - y_approx + 1.0) + 0.25).max(0.0).sqrt()) / k
        } else {
            y_approx - 1.0
        };
        let mut inv_erf = erfinv(b);
        let (mut begin_x, mut begin_y) = (-1.0f32, -y_exact);
        let mut end_x = erf_a;
        let mut cur_x = b;
        let mut cur_y = 1.0 + b + k * (-inv_erf * inv_erf).exp() - y_exact;
        let mut iter = 0;
        // Newton steps, falling back to bisection outside the bracket.
        while cur_y.abs() > 1e-6 && iter < 3 {
            iter += 1;
            if begin_y.signum() == cur_y.signum() {
                begin_x = cur_x;
                begin_y = cur_y;
            } else {
                end_x = cur_x;
            }
            let newton = cur_x - cur_y / (1.0 - inv_erf * tan_t);
            cur_x = if newton >= begin_x && newton <= end_x {
                newton
            } else {
                0.5 * (begin_x + end_x)
            };
            inv_erf = erfinv(cur_x);
            cur_y = 1.0 + cur_x + k * (-inv_erf * inv_erf).exp() - y_exact;
        }
        sx = inv_erf;
        sy = erfinv(2.0 * u[1] - 1.0);
    }
    let tmp = cos_phi * sx - sin_phi * sy;
    sy = sin_phi * sx + cos_phi * sy;
    sx = tmp;
    vec3(-ax * sx, -ay * sy, 1.0).normalize()
}

pub fn sample_vndf(dist: Distribution, v: Vec3, ax: f32, ay: f32, u: [f32; 2]) -> Vec3 {
    match dist {
        Distribution::Ggx => ggx_vndf(v, ax, ay, u),
        Distribution::Beckmann => sample_beckmann_vndf(v, ax, ay, u),
    }
}

/// Fresnel reflectance of a dielectric with relative IOR `eta` and, when light
/// refracts, the cosine of the refracted direction with the half vector (negative).
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32) {
    let c = cos_i.abs();
    let sin_t2 = (1.0 - c * c) / (eta * eta);
    if sin_t2 >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    (0.5 * (rs * rs + rp * rp), -cos_t)
}

/// A dielectric interface (Glass, Refraction, Principled transmission).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    pub dist: Distribution,
    pub alpha: f32,
    /// Relative IOR across the surface as hit (inverted on back faces).
    pub eta: f32,
    /// Refraction BSDF: no reflected lobe.
    pub refract_only: bool,
    /// Tints of the reflected and the transmitted light (besides the closure weight).
    pub tint_r: V3,
    pub tint_t: V3,
    /// Multiple-scattering energy compensation (1 / single-scattering albedo).
    pub energy: f32,
    /// Principled transmission's thin film: its reflectance replaces the bare Fresnel
    /// (refraction takes the rest; the refracted direction is Snell's either way).
    pub film: Option<crate::render::bsdf::thin_film::ThinFilm>,
}

/// Result of sampling a dielectric: direction, eval / pdf (without the closure weight)
/// and pdf (infinite when singular).
pub struct DielectricSample {
    pub l: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub singular: bool,
    pub transmit: bool,
}

impl Dielectric {
    pub fn singular(&self) -> bool {
        self.alpha * self.alpha <= ROUGHNESS_SQ_THRESH
    }

    fn fresnel(&self, cos_hv: f32) -> (Vec3, Vec3, f32) {
        let (f, cos_ht) = fresnel_dielectric(cos_hv, self.eta);
        if f >= 1.0 {
            // Total internal reflection.
            let r = if self.refract_only {
                Vec3::ZERO
            } else {
                self.tint_r.into()
            };
            return (r, Vec3::ZERO, cos_ht);
        }
        if self.refract_only {
            // Cycles' Refraction BSDF has no Fresnel factor.
            return (Vec3::ZERO, self.tint_t.into(), cos_ht);
        }
        if let Some(film) = &self.film {
            let r = Vec3::from(film.eval(cos_hv));
            return (
                Vec3::from(self.tint_r) * r,
                Vec3::from(self.tint_t) * r.map(|x| 1.0 - x),
                cos_ht,
            );
        }
        let (tint_r, tint_t) = (Vec3::from(self.tint_r), Vec3::from(self.tint_t));
        (tint_r * f, tint_t * (1.0 - f), cos_ht)
    }

    /// (BSDF * |cos|, pdf) toward `l`; `ng` faces the viewer.
    pub fn eval(&self, n: Vec3, v: Vec3, l: Vec3, ng: Vec3) -> (Vec3, f32) {
        let cos_nv = n.dot(v);
        let cos_nl = n.dot(l);
        let is_t = cos_nl < 0.0;
        if cos_nv <= 0.0
            || self.singular()
            || (ng.dot(l) < 0.0) != is_t
            || (!is_t && self.refract_only)
        {
            return (Vec3::ZERO, 0.0);
        }
        let hu = if is_t { -(l * self.eta + v) } else { v + l };
        let hl = hu.length();
        if !(hl > 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let h = hu * (1.0 / hl);
        let cos_hv = h.dot(v);
        let (r, t, _) = self.fresnel(cos_hv);
        let sum = r.average() + t.average();
        if !(sum > 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let a2 = self.alpha * self.alpha;
        let dd = d(self.dist, a2, n.dot(h));
        let lv = lambda(self.dist, a2, cos_nv);
        let ll = lambda(self.dist, a2, cos_nl);
        let common = dd / cos_nv
            * if is_t {
                (self.eta / hl) * (self.eta / hl) * (cos_hv * h.dot(l)).abs()
            } else {
                0.25
            };
        let p_r = r.average() / sum;
        let lobe = if is_t { 1.0 - p_r } else { p_r };
        let pdf = common * lobe / (1.0 + lv);
        let f = (if is_t { t } else { r }) * (common / (1.0 + lv + ll) * self.energy);
        (f, pdf)
    }

    /// Samples reflection or refraction with `u[2]`, a microfacet normal with `u[0..2]`.
    pub fn sample(&self, n: Vec3, v: Vec3, ng: Vec3, u: [f32; 3]) -> Option<DielectricSample> {
        let cos_nv = n.dot(v);
        if cos_nv <= 0.0 {
            return None;
        }
        let mut singular = self.singular();
        let (tx, ty) = n.basis();
        let lv_local = vec3(v.dot(tx), v.dot(ty), cos_nv);
        let h = if singular {
            n
        } else {
            let hl = sample_vndf(self.dist, lv_local, self.alpha, self.alpha, [u[0], u[1]]);
            tx * hl[0] + ty * hl[1] + n * hl[2]
        };
        let cos_hv = h.dot(v);
        let (r, t, cos_ht) = self.fresnel(cos_hv);
        let sum = r.average() + t.average();
        if !(sum > 0.0) {
            return None;
        }
        let p_r = r.average() / sum;
        let refract = u[2] >= p_r;
        let l = if refract {
            // Snell: tangential part scaled by 1/eta, normal part from cos_ht.
            v * (-1.0 / self.eta) + h * (cos_hv / self.eta + cos_ht)
        } else {
            h * (2.0 * cos_hv) - v
        };
        let l = l.normalize();
        if (ng.dot(l) < 0.0) != refract || (n.dot(l) < 0.0) != refract {
            return None;
        }
        let (mut e, mut pdf) = if refract { (t, 1.0 - p_r) } else { (r, p_r) };
        if refract && (self.eta - 1.0).abs() < 1e-4 {
            singular = true;
        }
        if singular {
            return Some(DielectricSample {
                l,
                weight: e * (self.energy / pdf),
                pdf: f32::INFINITY,
                singular: true,
                transmit: refract,
            });
        }
        let a2 = self.alpha * self.alpha;
        let cos_nl = n.dot(l);
        let dd = d(self.dist, a2, n.dot(h));
        let lv = lambda(self.dist, a2, cos_nv);
        let ll = lambda(self.dist, a2, cos_nl);
        let cos_hl = h.dot(l);
        let common = dd / cos_nv
            * if refract {
                (cos_hv * cos_hl).abs() / (cos_hl + cos_hv / self.eta).powi(2)
            } else {
                0.25
            };
        pdf *= common / (1.0 + lv);
        e *= common / (1.0 + lv + ll) * self.energy;
        if !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        Some(DielectricSample {
            l,
            weight: e * (1.0 / pdf),
            pdf,
            singular: false,
            transmit: refract,
        })
    }
}

/// Mean of the glass BSDF's single-scattering throughput seen from `mu`, by VNDF
/// samples (the tables Cycles calls ggx_glass_E and ggx_glass_inv_E): reflection and
/// refraction each weighted by its Fresnel share, each with G2/G1. A refracted sample
/// counts whichever side of the surface it leaves on (only reflections are checked), as
/// Cycles' tables evidently do: with the check, the entries for light leaving glass
/// (eta < 1) read up to 0.7 below Cycles' near grazing, where most of it refracts back
/// upward; without it, they match within the noise of the samples (tests/closures.rs).
pub fn glass_albedo(mu: f32, alpha: f32, eta: f32, samples: &[[f32; 2]]) -> f32 {
    let mu = mu.max(1e-4);
    let v = vec3((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let a2 = alpha * alpha;
    if a2 <= ROUGHNESS_SQ_THRESH {
        // A mirror interface: its reflection and refraction (each chosen by its own
        // Fresnel share) both leave on their side, unmasked.
        return 1.0;
    }
    let lv = lambda(Distribution::Ggx, a2, mu);
    let mut sum = 0.0f64;
    for u in samples {
        let h = ggx_vndf(v, alpha, alpha, *u);
        let cos_hv = h.dot(v);
        let (f, cos_ht) = fresnel_dielectric(cos_hv, eta);
        let r = h * (2.0 * cos_hv) - v;
        if r[2] > 0.0 {
            let ll = lambda(Distribution::Ggx, a2, r[2]);
            sum += (f * (1.0 + lv) / (1.0 + lv + ll)) as f64;
        }
        if f < 1.0 {
            if (eta - 1.0).abs() < 1e-4 {
                // Refraction through an interface of IOR 1 is a straight pass (Cycles makes
                // it singular), with no masking.
                sum += (1.0 - f) as f64;
            } else {
                let t = (v * (-1.0 / eta) + h * (cos_hv / eta + cos_ht)).normalize();
                let ll = lambda(Distribution::Ggx, a2, t[2]);
                sum += ((1.0 - f) * (1.0 + lv) / (1.0 + lv + ll)) as f64;
            }
        }
    }
    (sum / samples.len().max(1) as f64) as f32
}

/// The Glass or Refraction closure as Cycles' SVM sets it up: alpha = roughness^2, IOR
/// inverted on back faces, Multiscatter GGX glass scaled by 1 / E from the glass albedo
/// table. `mu` is cos(N, view). Tints are one: the colour is the closure weight.
pub fn glass_closure(
    tables: &crate::render::bsdf::tables::Tables,
    distribution: Option<&str>,
    refract_only: bool,
    roughness: f32,
    ior: f32,
    backfacing: bool,
    mu: f32,
) -> Dielectric {
    let r = roughness.clamp(0.0, 1.0);
    let ior = ior.max(1e-5);
    let eta = if backfacing { 1.0 / ior } else { ior };
    let dist = if distribution == Some("BECKMANN") {
        Distribution::Beckmann
    } else {
        Distribution::Ggx
    };
    let mut g = Dielectric {
        dist,
        alpha: r * r,
        eta,
        refract_only,
        tint_r: [1.0; 3],
        tint_t: [1.0; 3],
        energy: 1.0,
        film: None,
    };
    if !refract_only && distribution == Some("MULTI_GGX") && !g.singular() {
        g.energy = 1.0 / tables.glass_e(mu.clamp(0.0, 1.0), r, eta).max(1e-3);
    }
    g
}

/// Microfacet reflection for the Beckmann distribution (isotropic GGX keeps
/// `LobeKind::Glossy`): the Glossy BSDF's (Fresnel constant: the colour is the closure
/// weight) and the Metallic BSDF's (F82 tint or physical conductor).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reflection {
    pub dist: Distribution,
    pub alpha: f32,
    pub fresnel: crate::render::bsdf::Fresnel,
}

impl Reflection {
    pub fn singular(&self) -> bool {
        self.alpha * self.alpha <= ROUGHNESS_SQ_THRESH
    }

    /// (BSDF * cos, pdf) toward `l`.
    pub fn eval(&self, n: Vec3, v: Vec3, l: Vec3, ng: Vec3) -> (f32, f32) {
        let cos_nv = n.dot(v);
        let cos_nl = n.dot(l);
        if cos_nv <= 0.0 || cos_nl <= 0.0 || ng.dot(l) <= 0.0 || self.singular() {
            return (0.0, 0.0);
        }
        let h = (v + l).normalize();
        let a2 = self.alpha * self.alpha;
        let dd = d(self.dist, a2, n.dot(h));
        let lv = lambda(self.dist, a2, cos_nv);
        let ll = lambda(self.dist, a2, cos_nl);
        let common = dd / cos_nv * 0.25;
        (common / (1.0 + lv + ll), common / (1.0 + lv))
    }

    /// A reflected direction from a visible normal (or the mirror direction), and whether
    /// it is singular.
    pub fn sample(&self, n: Vec3, v: Vec3, ng: Vec3, u: [f32; 2]) -> Option<(Vec3, bool)> {
        let cos_nv = n.dot(v);
        if cos_nv <= 0.0 {
            return None;
        }
        let h = if self.singular() {
            n
        } else {
            let (tx, ty) = n.basis();
            let hl = sample_vndf(
                self.dist,
                vec3(v.dot(tx), v.dot(ty), cos_nv),
                self.alpha,
                self.alpha,
                u,
            );
            tx * hl[0] + ty * hl[1] + n * hl[2]
        };
        let l = h * (2.0 * h.dot(v)) - v;
        if ng.dot(l) <= 0.0 || n.dot(l) <= 0.0 {
            return None;
        }
        Some((l, self.singular()))
    }
}
