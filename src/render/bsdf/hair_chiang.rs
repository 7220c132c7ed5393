//! Principled Hair BSDF, Chiang model (Cycles' closure/bsdf_principled_hair_chiang.h,
//! after Chiang et al. 2016 and pbrt-v3): the R, TT and TRT bounces inside a circular
//! fibre, each a longitudinal lobe (Bessel form, variance from Roughness, R narrowed by
//! Coat, tilted by the cuticle angle) times an azimuthal trimmed logistic about its
//! exit direction, plus the residual TRRT+ as a uniform azimuth. The frame is Cycles':
//! X the curve tangent (dP/du), Y across it facing away from the viewer's side (the
//! closure's normal), Z = X x Y; `h` (the hit's offset across the fibre) is -v on a
//! ribbon. Colour comes from an absorption coefficient, given or derived from melanin or
//! a colour (`sigma_from_*`). Sampled by picking a bounce by its grey energy, so sampling
//! and evaluation give the same pdf.

use std::f32::consts::PI;

use crate::render::bsdf::hair::Across;
use crate::render::math::{vec3, Vec3, V3};

/// Rec.709 luminance, Cycles' spectrum_to_gray in a linear Rec.709 scene.
const GRAY: Vec3 = vec3(0.2126, 0.7152, 0.0722);

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Chiang {
    /// Absorption coefficient per unit of fibre radius.
    pub sigma: Vec3,
    /// Longitudinal variance (mapped from Roughness).
    pub v: f32,
    /// Azimuthal logistic scale (mapped from Radial Roughness).
    pub s: f32,
    /// Cuticle tilt, radians, negated as Cycles' setup does.
    pub alpha: f32,
    pub eta: f32,
    /// The R lobe's variance (Roughness narrowed by Coat).
    pub m0_roughness: f32,
    /// Offset across the fibre, -1..1.
    pub h: f32,
    /// Unit curve tangent (Cycles' normalised dP/du).
    pub x: Vec3,
}

/// Cycles' bsdf_principled_hair_albedo_roughness_scale.
fn albedo_roughness_scale(x: f32) -> f32 {
    (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969
}

/// The absorption giving roughly `color` as the hair's multiple-scattering albedo
/// (Cycles' bsdf_principled_hair_sigma_from_reflectance).
pub fn sigma_from_reflectance(color: V3, radial_roughness: f32) -> V3 {
    let k = albedo_roughness_scale(radial_roughness);
    color.map(|c| {
        let s = c.ln() / k;
        s * s
    })
}

/// Absorption of eumelanin and pheomelanin concentrations (Cycles'
/// bsdf_principled_hair_sigma_from_concentration).
pub fn sigma_from_concentration(eumelanin: f32, pheomelanin: f32) -> V3 {
    let eu = [0.506, 0.841, 1.653];
    let pheo = [0.343, 0.733, 1.924];
    [0, 1, 2].map(|i| eumelanin * eu[i] + pheomelanin * pheo[i])
}

/// Cycles' sigma for Melanin Concentration: melanin randomised by Random Color, mapped
/// from 0..1 to a concentration, split by Melanin Redness, plus the Tint's absorption.
pub fn sigma_from_melanin(
    melanin: f32,
    redness: f32,
    tint: V3,
    random: f32,
    random_color: f32,
    radial_roughness: f32,
) -> V3 {
    let factor = 1.0 + 2.0 * (random - 0.5) * random_color.clamp(0.0, 1.0);
    let m = -(1.0 - melanin * factor).max(0.0001).ln();
    let s = Vec3::from(sigma_from_concentration(m * (1.0 - redness), m * redness));
    (s + sigma_from_reflectance(tint, radial_roughness).into()).into()
}

fn sqr(x: f32) -> f32 {
    x * x
}
fn cos_from_sin(s: f32) -> f32 {
    (1.0 - s * s).max(0.0).sqrt()
}
fn safe_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

fn delta_phi(p: i32, gamma_o: f32, gamma_t: f32) -> f32 {
    2.0 * p as f32 * gamma_t - 2.0 * gamma_o + p as f32 * PI
}

/// The angle in [-pi, pi].
fn wrap_angle(a: f32) -> f32 {
    (a + PI) - 2.0 * PI * ((a + PI) / (2.0 * PI)).floor() - PI
}

fn logistic(x: f32, s: f32) -> f32 {
    let v = (-x.abs() / s).exp();
    v / (s * sqr(1.0 + v))
}

fn logistic_cdf(x: f32, s: f32) -> f32 {
    let arg = -x / s;
    if arg > 88.0 {
        return 0.0;
    }
    1.0 / (1.0 + arg.exp())
}

/// The modified Bessel function I0 by its series (Cycles' bessel_I0, to the same
/// number of terms).
fn bessel_i0(x: f32) -> f32 {
    let x = x * x;
    let mut val = 1.0 + 0.25 * x;
    let mut pow_x_2i = x * x;
    let mut i_fac_2: u64 = 1;
    let mut pow_4_i: i64 = 16;
    for i in 2..10u64 {
        i_fac_2 *= i * i;
        let newval = val + pow_x_2i / (pow_4_i as f32 * i_fac_2 as f32);
        if val == newval {
            return val;
        }
        val = newval;
        pow_x_2i *= x;
        pow_4_i *= 4;
    }
    val
}

fn log_bessel_i0(x: f32) -> f32 {
    if x > 12.0 {
        return x + 0.5 * (1.0 / (8.0 * x) - (2.0 * PI).ln() - x.ln());
    }
    bessel_i0(x).ln()
}

fn trimmed_logistic(x: f32, s: f32) -> f32 {
    let scaling = 1.0 - 2.0 * logistic_cdf(-PI, s);
    let v = logistic(x, s);
    if scaling != 0.0 {
        v / scaling
    } else {
        0.0
    }
}

fn sample_trimmed_logistic(u: f32, s: f32) -> f32 {
    let cdf_minuspi = logistic_cdf(-PI, s);
    let x = -s * (1.0 / (u * (1.0 - 2.0 * cdf_minuspi) + cdf_minuspi) - 1.0).ln();
    x.clamp(-PI, PI)
}

fn azimuthal(phi: f32, p: i32, s: f32, gamma_o: f32, gamma_t: f32) -> f32 {
    trimmed_logistic(wrap_angle(phi - delta_phi(p, gamma_o, gamma_t)), s)
}

/// Cycles' longitudinal_scattering (the Huang model's TRRT+ lobe uses it too).
// Cycles writes ln 2 as 0.6931, kept for the same figures.
#[allow(clippy::approx_constant)]
pub fn longitudinal_scattering(sin_i: f32, cos_i: f32, sin_o: f32, cos_o: f32, v: f32) -> f32 {
    let inv_v = 1.0 / v;
    let cos_arg = cos_i * cos_o * inv_v;
    let sin_arg = sin_i * sin_o * inv_v;
    if v <= 0.1 {
        let i0 = log_bessel_i0(cos_arg);
        return (i0 - sin_arg - inv_v + 0.6931 + (0.5 * inv_v).ln()).exp();
    }
    ((-sin_arg).exp() * bessel_i0(cos_arg)) / (inv_v.sinh() * 2.0 * v)
}

fn fresnel_dielectric_cos(cosi: f32, eta: f32) -> f32 {
    crate::render::bsdf::fresnel_dielectric(cosi, eta)
}

/// The viewer's frame quantities shared by evaluation and sampling.
struct Frame {
    y: Vec3,
    z: Vec3,
    sin_theta_o: f32,
    cos_theta_o: f32,
    phi_o: f32,
    gamma_o: f32,
    gamma_t: f32,
    ap: [Vec3; 4],
    ap_energy: [f32; 4],
    angles: [f32; 6],
}

impl Chiang {
    /// Cycles' bsdf_hair_chiang_setup: roughnesses clamped and mapped to the logistic's
    /// variance and scale; `coat` narrows the R lobe. `wo` is the unit direction toward
    /// the viewer, `dpdu` the curve tangent, `v` the hit's place across the ribbon.
    /// Returns the closure and its normal (Cycles' Y, the closure's N).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        sigma: V3,
        roughness: f32,
        radial_roughness: f32,
        coat: f32,
        alpha: f32,
        eta: f32,
        dpdu: V3,
        wo: V3,
        across: Across,
    ) -> Option<(Chiang, V3)> {
        let r = roughness.clamp(0.001, 1.0);
        let s = radial_roughness.clamp(0.001, 1.0);
        let m0 = ((1.0 - coat.clamp(0.0, 1.0)) * r).clamp(0.001, 1.0);
        let map_v = |x: f32| sqr(0.726 * x + 0.812 * sqr(x) + 3.700 * x.powi(20));
        let s = (0.265 * s + 1.194 * sqr(s) + 5.372 * s.powi(22)) * (PI / 8.0).sqrt();
        let x = safe_normalize(dpdu.into())?;
        let y = safe_normalize(x.cross(wo.into()))?;
        // The sine of the angle between the true normal and Z, seen along the tangent.
        let h = match across {
            Across::Ribbon { v } => -v,
            Across::Tube { n: ng } | Across::Surface { ng, .. } => {
                Vec3::from(ng).cross(x).dot(x.cross(y).normalize())
            }
        };
        Some((
            Chiang {
                sigma: sigma.into(),
                v: map_v(r),
                s,
                alpha: -alpha,
                eta,
                m0_roughness: map_v(m0),
                h,
                x,
            },
            y.into(),
        ))
    }

    fn frame(&self, y: Vec3, wo: Vec3) -> Frame {
        let z = self.x.cross(y).normalize();
        let o = [wo.dot(self.x), wo.dot(y), wo.dot(z)];
        let sin_theta_o = o[0];
        let cos_theta_o = cos_from_sin(sin_theta_o);
        let phi_o = o[2].atan2(o[1]);
        let sin_theta_t = sin_theta_o / self.eta;
        let cos_theta_t = cos_from_sin(sin_theta_t);
        let sin_gamma_o = self.h;
        let cos_gamma_o = cos_from_sin(sin_gamma_o);
        let gamma_o = safe_asin(sin_gamma_o);
        let sin_gamma_t = sin_gamma_o * cos_theta_o / (sqr(self.eta) - sqr(sin_theta_o)).sqrt();
        let cos_gamma_t = cos_from_sin(sin_gamma_t);
        let gamma_t = safe_asin(sin_gamma_t);
        let t = self
            .sigma
            .map(|s| (-s * (2.0 * cos_gamma_t / cos_theta_t)).exp());
        let f = fresnel_dielectric_cos(cos_theta_o * cos_gamma_o, self.eta);
        let (ap, ap_energy) = attenuation(f, t);
        Frame {
            y,
            z,
            sin_theta_o,
            cos_theta_o,
            phi_o,
            gamma_o,
            gamma_t,
            ap,
            ap_energy,
            angles: alpha_angles(sin_theta_o, cos_theta_o, self.alpha),
        }
    }

    /// (F, pdf) of the four bounces toward sin(theta_i), phi (relative to the viewer).
    fn lobes(&self, fr: &Frame, sin_theta_i: f32, phi: f32) -> (Vec3, f32) {
        let cos_theta_i = cos_from_sin(sin_theta_i);
        let mut f = Vec3::ZERO;
        let mut energy = 0.0;
        for i in 0..3 {
            let v = match i {
                0 => self.m0_roughness,
                1 => 0.25 * self.v,
                _ => 4.0 * self.v,
            };
            let mp = longitudinal_scattering(
                sin_theta_i,
                cos_theta_i,
                fr.angles[2 * i],
                fr.angles[2 * i + 1],
                v,
            );
            let np = azimuthal(phi, i as i32, self.s, fr.gamma_o, fr.gamma_t);
            f += fr.ap[i] * (mp * np);
            energy += fr.ap_energy[i] * mp * np;
        }
        let mp = longitudinal_scattering(
            sin_theta_i,
            cos_theta_i,
            fr.sin_theta_o,
            fr.cos_theta_o,
            4.0 * self.v,
        );
        let np = 1.0 / (2.0 * PI);
        f += fr.ap[3] * (mp * np);
        energy += fr.ap_energy[3] * mp * np;
        (f, energy)
    }

    /// (BSDF times cosine, pdf) toward `wi` for a viewer along `wo`; `y` is the
    /// closure's normal.
    pub fn eval(&self, y: Vec3, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        let fr = self.frame(y, wo);
        let sin_theta_i = wi.dot(self.x);
        let phi_i = wi.dot(fr.z).atan2(wi.dot(fr.y));
        let (f, pdf) = self.lobes(&fr, sin_theta_i, phi_i - fr.phi_o);
        if f.is_finite() && pdf.is_finite() {
            (f, pdf)
        } else {
            (Vec3::ZERO, 0.0)
        }
    }

    /// Cycles' bsdf_hair_chiang_sample: (direction, F, pdf, transmits). The bounce is
    /// picked by `u[2]`.
    pub fn sample(&self, y: Vec3, wo: Vec3, u: [f32; 3]) -> Option<(Vec3, Vec3, f32, bool)> {
        let fr = self.frame(y, wo);
        let mut uz = u[2];
        let mut p = 0;
        while p < 3 {
            if uz < fr.ap_energy[p] {
                break;
            }
            uz -= fr.ap_energy[p];
            p += 1;
        }
        uz /= fr.ap_energy[p];
        // Cycles samples the R bounce with the Roughness variance, not the coated one.
        let v = match p {
            0 => self.v,
            1 => 0.25 * self.v,
            _ => 4.0 * self.v,
        };
        let (sin_o, cos_o) = if p < 3 {
            (fr.angles[2 * p], fr.angles[2 * p + 1])
        } else {
            (fr.sin_theta_o, fr.cos_theta_o)
        };
        let uz = uz.max(1e-5);
        let fac = 1.0 + v * (uz + (1.0 - uz) * (-2.0 / v).exp()).ln();
        let sin_theta_i = -fac * sin_o + cos_from_sin(fac) * (2.0 * PI * u[1]).cos() * cos_o;
        let phi = if p < 3 {
            delta_phi(p as i32, fr.gamma_o, fr.gamma_t) + sample_trimmed_logistic(u[0], self.s)
        } else {
            2.0 * PI * u[0]
        };
        let phi_i = fr.phi_o + phi;
        let (f, pdf) = self.lobes(&fr, sin_theta_i, phi);
        let c = cos_from_sin(sin_theta_i);
        let wi = fr.y * (c * phi_i.cos()) + fr.z * (c * phi_i.sin()) + self.x * sin_theta_i;
        if !(pdf > 0.0) || !pdf.is_finite() || !f.is_finite() {
            return None;
        }
        Some((wi, f, pdf, p != 0))
    }

    /// Cycles' bsdf_hair_chiang_blur (Filter Glossy).
    pub fn blur(&mut self, roughness: f32) {
        self.v = self.v.max(roughness);
        self.s = self.s.max(roughness);
        self.m0_roughness = self.m0_roughness.max(roughness);
    }
}

fn safe_normalize(v: Vec3) -> Option<Vec3> {
    let l = v.dot(v).sqrt();
    (l > 0.0 && l.is_finite()).then(|| v * (1.0 / l))
}

/// Cycles' hair_attenuation: the colour of each bounce for Fresnel `f` and one pass's
/// transmittance `t`, and their grey energies normalised to sum to one.
fn attenuation(f: f32, t: Vec3) -> ([Vec3; 4], [f32; 4]) {
    let gray = |c: Vec3| c.dot(GRAY);
    let mut ap = [Vec3::ZERO; 4];
    let mut e = [0.0; 4];
    ap[0] = Vec3::splat(f);
    e[0] = f;
    let mut col = t * sqr(1.0 - f);
    ap[1] = col;
    e[1] = gray(col);
    col *= t * f;
    ap[2] = col;
    e[2] = gray(col);
    let tf = t * f;
    col *= tf.map(|x| {
        let d = 1.0 - x;
        if d != 0.0 {
            x / d
        } else {
            0.0
        }
    });
    ap[3] = col;
    e[3] = gray(col);
    let total: f32 = e.iter().sum();
    let fac = if total != 0.0 { 1.0 / total } else { 0.0 };
    (ap, e.map(|x| x * fac))
}

/// Cycles' hair_alpha_angles: the viewer's elevation (sin, cos) tilted by the cuticle
/// for R (2 alpha), TT (-alpha) and TRT (-4 alpha).
fn alpha_angles(sin_o: f32, cos_o: f32, alpha: f32) -> [f32; 6] {
    let s1 = alpha.sin();
    let c1 = cos_from_sin(s1);
    let s2 = 2.0 * s1 * c1;
    let c2 = sqr(c1) - sqr(s1);
    let s4 = 2.0 * s2 * c2;
    let c4 = sqr(c2) - sqr(s2);
    [
        sin_o * c2 - cos_o * s2,
        (cos_o * c2 + sin_o * s2).abs(),
        sin_o * c1 + cos_o * s1,
        (cos_o * c1 - sin_o * s1).abs(),
        sin_o * c4 + cos_o * s4,
        (cos_o * c4 - sin_o * s4).abs(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closure(coat: f32, h: f32) -> (Chiang, Vec3, Vec3) {
        let wo = vec3(0.3, 1.0, 0.5).normalize();
        let sigma = sigma_from_melanin(0.6, 0.3, [1.0; 3], 0.0, 0.0, 0.3);
        let (c, y) = Chiang::new(
            sigma,
            0.3,
            0.3,
            coat,
            2f32.to_radians(),
            1.55,
            [0.0, 0.0, 1.0],
            wo.into(),
            Across::Ribbon { v: h },
        )
        .unwrap();
        (c, y.into(), wo)
    }

    fn sphere_dir(i: usize, j: usize, n: usize) -> (Vec3, f32) {
        let z = -1.0 + (i as f32 + 0.5) / n as f32 * 2.0;
        let phi = (j as f32 + 0.5) / (2 * n) as f32 * 2.0 * PI;
        let r = (1.0 - z * z).sqrt();
        (
            vec3(r * phi.cos(), r * phi.sin(), z),
            4.0 * PI / (2 * n * n) as f32,
        )
    }

    /// Sampling returns evaluation's value and pdf for the direction it picks.
    #[test]
    fn sample_matches_eval() {
        for (coat, h) in [(0.0, 0.3), (0.5, -0.7), (0.0, 0.0)] {
            let (c, y, wo) = closure(coat, h);
            let mut n = 0;
            for i in 0..8 {
                for j in 0..8 {
                    for k in 0..8 {
                        let u = [
                            (i as f32 + 0.5) / 8.0,
                            (j as f32 + 0.5) / 8.0,
                            (k as f32 + 0.5) / 8.0,
                        ];
                        let Some((wi, f, pdf, _)) = c.sample(y, wo, u) else {
                            continue;
                        };
                        let (fe, pe) = c.eval(y, wo, wi);
                        assert!((pe - pdf).abs() <= 1e-3 * pdf.max(1.0), "{u:?} {pe} {pdf}");
                        for ch in 0..3 {
                            assert!((fe[ch] - f[ch]).abs() <= 1e-3 * f[ch].max(1.0));
                        }
                        n += 1;
                    }
                }
            }
            assert!(n > 400, "{n}");
        }
    }

    /// The pdf integrates to one over the sphere, and the energy (BSDF times cosine)
    /// to at most one: a white fibre without absorption loses nothing but what the
    /// trimmed lobes leave out.
    #[test]
    fn pdf_normalised_and_energy_bounded() {
        let (c, y, wo) = closure(0.0, 0.4);
        let mut white = c;
        white.sigma = Vec3::ZERO;
        let n = 400;
        let (mut pdf_sum, mut f_sum, mut white_sum) = (0.0f64, [0.0f64; 3], 0.0f64);
        for i in 0..n {
            for j in 0..2 * n {
                let (wi, dw) = sphere_dir(i, j, n);
                let (f, p) = c.eval(y, wo, wi);
                pdf_sum += (p * dw) as f64;
                for ch in 0..3 {
                    f_sum[ch] += (f[ch] * dw) as f64;
                }
                white_sum += (white.eval(y, wo, wi).0[1] * dw) as f64;
            }
        }
        assert!((pdf_sum - 1.0).abs() < 0.02, "{pdf_sum}");
        assert!(f_sum.iter().all(|&f| f > 0.0 && f < 1.0), "{f_sum:?}");
        assert!(white_sum > 0.9 && white_sum < 1.02, "{white_sum}");
    }

    #[test]
    fn melanin_sigma_as_cycles() {
        // Melanin 0.8, redness 1 (pheomelanin only), white tint: -ln(0.2) x pheomelanin.
        let s = sigma_from_melanin(0.8, 1.0, [1.0; 3], 0.0, 0.0, 0.3);
        let m = -(0.2f32).ln();
        for (k, c) in [0.343, 0.733, 1.924].iter().enumerate() {
            assert!((s[k] - m * c).abs() < 1e-5);
        }
    }
}
