//! Thin-film iridescence of the Principled BSDF (4.2+ "Thin Film Thickness" and "Thin
//! Film IOR"), as Cycles 4.5 computes it (`fresnel_iridescence` in bsdf_util.h): Belcour
//! and Barla 2017's Airy reflectance of a film between the outside and the substrate,
//! summed to the third path-order difference, integrated against their Gaussian fit of
//! the CIE XYZ curves in Fourier space, then taken to linear Rec.709. Cycles 4.5 applies
//! it to the Principled dielectric specular layer and its transmission (glass), not to
//! the metallic layer.

use crate::render::bsdf::f0_from_ior;
use crate::render::math::{Vec3, V3};
use std::f32::consts::PI;

/// Cycles' THINFILM_THICKNESS_CUTOFF: thinner films (nm) are no film at all.
pub const CUTOFF: f32 = 0.1;

/// Below this thickness (nm) the wave-optics model no longer holds; Cycles blends the
/// film's IOR toward the outside's so the film fades out smoothly.
const FADE: f32 = 30.0;

/// A film on a dielectric substrate, with the outside's IOR one (relative IORs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThinFilm {
    /// Film thickness in nanometres (above `CUTOFF`).
    pub thickness: f32,
    /// Film IOR relative to the outside.
    pub ior: f32,
    /// Substrate IOR relative to the outside.
    pub eta: f32,
    /// Per channel f0 / F0(eta): the Principled Specular Tint and IOR Level scale the
    /// film's reflectance toward this, more the nearer it is to the substrate's F0.
    pub f0_scale: V3,
}

impl ThinFilm {
    /// Reflectance at incidence cosine `cos_i`, with the f0 scaling Cycles applies in
    /// `generalized_schlick_fresnel` (the Principled layers are generalized Schlick).
    pub fn eval(&self, cos_i: f32) -> V3 {
        let mut f = reflectance(self.ior, self.eta, cos_i, self.thickness);
        let f0 = f0_from_ior(self.eta);
        // Film colours can fall below F0, so Cycles does not remap F0..1 as without film:
        // it scales by f0 / F0, fully at F and not at all at total reflection.
        if f0 > 1e-5 && f != [1.0; 3] {
            for (c, scale) in f.iter_mut().zip(self.f0_scale) {
                let s = ((1.0 - *c) / (1.0 - f0)).clamp(0.0, 1.0);
                *c *= 1.0 + (scale - 1.0) * s;
            }
        }
        f
    }
}

/// Fresnel of one interface split by polarization: (R_s, R_p), the cosine of the
/// refracted direction (negative, on the far side) and whether each reflected
/// amplitude is negative (a phase shift of pi). None on total internal reflection.
fn polarized(cos_i: f32, eta: f32) -> Option<([f32; 2], f32, [bool; 2])> {
    let eta_cos_t_sq = eta * eta - (1.0 - cos_i * cos_i);
    if eta_cos_t_sq <= 0.0 {
        return None;
    }
    let ci = cos_i.abs();
    let ct = -eta_cos_t_sq.max(0.0).sqrt() / eta;
    let rs = (ci + eta * ct) / (ci - eta * ct);
    let rp = (ct + eta * ci) / (eta * ci - ct);
    Some(([rs * rs, rp * rp], ct, [rs < 0.0, rp < 0.0]))
}

/// Belcour and Barla's Fourier-space XYZ sensitivity at optical path difference `opd`
/// (nm) with no phase shift. Cycles' version takes a shift, but here every shift is a
/// multiple of pi (dielectric interfaces), which only flips the sign (see `airy`).
fn sensitivity(opd: f32) -> Vec3 {
    const VAL: V3 = [5.4856e-13, 4.4201e-13, 5.2481e-13];
    const POS: V3 = [1.6810e+06, 1.7953e+06, 2.2084e+06];
    const VAR: V3 = [4.3278e+09, 9.3046e+09, 6.6121e+09];
    let phase = 2.0 * PI * opd * 1e-9;
    let mut xyz = [0.0; 3];
    for k in 0..3 {
        xyz[k] = VAL[k]
            * (2.0 * PI * VAR[k]).sqrt()
            * (POS[k] * phase).cos()
            * (-phase * phase * VAR[k]).exp();
    }
    // The fit's second lobe of X.
    xyz[0] += 1.64408e-8 * (2.2399e+06 * phase).cos() * (-4.5282e+09 * phase * phase).exp();
    Vec3::from(xyz) * (1.0 / 1.0685e-7)
}

/// Airy summation (the paper's equation 10) for one polarization, in XYZ: the film's
/// first reflection plus the interfering internal paths, to path-order difference 3.
/// `flip` says the phase shift is an odd multiple of pi (each order m adds m of it).
fn airy(r12: f32, r23: f32, sens: &[Vec3; 3], flip: bool) -> Vec3 {
    if r23 == 1.0 {
        return Vec3::ONE;
    }
    let t121 = 1.0 - r12;
    let r123 = r12 * r23;
    let rs = t121 * t121 * r23 / (1.0 - r123);
    let mut out = Vec3::splat(r12 + rs);
    let mut cm = rs - t121;
    for (m, s) in sens.iter().enumerate() {
        cm *= r123.sqrt();
        let sign = if flip && m % 2 == 0 { -1.0 } else { 1.0 };
        out += *s * (2.0 * cm * sign);
    }
    out
}

/// Linear Rec.709 from XYZ with the Rec.709 (D65) white folded in per column: the fit is
/// of the raw CIE curves (illuminant E), and Cycles adapts to the working white by
/// scaling XYZ by its white point before the usual matrix. Rows sum to one, so a flat
/// reflectance stays grey.
const XYZ_TO_REC709_WHITE: [V3; 3] = [
    [3.079_954_5, -1.537_138_5, -0.542_815_9],
    [-0.921_258_2, 1.876_010_8, 0.045_247_4],
    [0.052_887_4, -0.204_025_9, 1.151_138_5],
];

/// The film's reflectance (linear Rec.709, each channel in 0..1) for light arriving at
/// cosine `cos_i` from a medium of IOR one onto a film of IOR `film_ior` over a substrate
/// of IOR `eta`, the film `thickness` nm thick (Cycles' `fresnel_iridescence`).
pub fn reflectance(film_ior: f32, eta: f32, cos_i: f32, thickness: f32) -> V3 {
    let mut eta2 = film_ior;
    if thickness < FADE {
        let t = (thickness / FADE).clamp(0.0, 1.0);
        eta2 = 1.0 + (eta2 - 1.0) * t * t * (3.0 - 2.0 * t);
    }
    let Some((r12, cos2, neg12)) = polarized(cos_i, eta2) else {
        return [1.0; 3];
    };
    if r12 == [1.0; 2] {
        return [1.0; 3];
    }
    let Some((r23, _, neg23)) = polarized(-cos2, eta / eta2) else {
        return [1.0; 3];
    };
    if r23 == [1.0; 2] {
        return [1.0; 3];
    }
    let opd = -2.0 * eta2 * thickness * cos2;
    let sens = [
        sensitivity(opd),
        sensitivity(2.0 * opd),
        sensitivity(3.0 * opd),
    ];
    // Phase pi - phi12 + phi23: an odd multiple of pi unless exactly one interface flips.
    let flip = |p: usize| neg12[p] == neg23[p];
    let rs = airy(r12[0], r23[0], &sens, flip(0));
    let rp = airy(r12[1], r23[1], &sens, flip(1));
    let xyz = (rs + rp) * 0.5;
    XYZ_TO_REC709_WHITE.map(|row| Vec3::from(row).dot(xyz).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fresnel(cos_i: f32, eta: f32) -> f32 {
        crate::render::bsdf::fresnel_dielectric(cos_i, eta)
    }

    #[test]
    fn vanishing_film_is_the_bare_interface() {
        // A film of no thickness (faded to the outside's IOR) or one with the substrate's
        // own IOR is optically absent: the plain dielectric Fresnel in every channel.
        for &cos_i in &[1.0f32, 0.8, 0.5, 0.2] {
            for &eta in &[1.33f32, 1.5, 2.0] {
                let bare = fresnel(cos_i, eta);
                for f in [
                    reflectance(1.4, eta, cos_i, 1e-3),
                    reflectance(eta, eta, cos_i, 500.0),
                ] {
                    for c in f {
                        assert!(
                            (c - bare).abs() < 2e-3,
                            "cos {cos_i} eta {eta}: {f:?} vs {bare}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn thick_film_averages_to_incoherent_sum() {
        // Far beyond the coherence length the interference averages out: the reflectance
        // is the incoherent sum of the two interfaces' multiple reflections, grey.
        let (r12, r23) = (f0_from_ior(1.33), f0_from_ior(1.5 / 1.33));
        let incoherent = r12 + (1.0 - r12) * (1.0 - r12) * r23 / (1.0 - r12 * r23);
        for c in reflectance(1.33, 1.5, 1.0, 20_000.0) {
            assert!((c - incoherent).abs() < 2e-3, "{c} vs {incoherent}");
        }
    }

    #[test]
    fn interference_colours_and_bounds() {
        // A visible-range film on glass colours the reflection and stays within 0..1,
        // with total internal reflection inside the film giving one.
        let f = reflectance(1.33, 1.5, 1.0, 400.0);
        assert!(f.iter().all(|c| (0.0..=1.0).contains(c)));
        assert!(
            f.iter().cloned().fold(0.0, f32::max) - f.iter().cloned().fold(1.0, f32::min) > 0.01,
            "{f:?}"
        );
        assert_eq!(reflectance(1.2, 1.0 / 1.5, 0.1, 400.0), [1.0; 3]);
    }

    #[test]
    fn matches_cycles_head_on() {
        // Blender 4.5.4 Cycles, a smooth black Principled (IOR 1.5) seen head-on under a
        // white world: each pixel is the film's reflectance at normal incidence.
        let cases = [
            (300.0, 1.33, 1.5, [0.022044, 0.006795, 0.026982]),
            (500.0, 1.33, 1.5, [0.037087, 0.008976, 0.036142]),
            (15.0, 1.33, 1.5, [0.039087, 0.038547, 0.037827]),
            (500.0, 1.5, 1.33, [0.080149, 0.036745, 0.049041]),
        ];
        for (thickness, film, eta, cycles) in cases {
            let f = reflectance(film, eta, 1.0, thickness);
            for k in 0..3 {
                assert!(
                    (f[k] - cycles[k]).abs() < 2e-5,
                    "{thickness} nm: {f:?} vs {cycles:?}"
                );
            }
        }
    }

    #[test]
    fn f0_scale_one_changes_nothing() {
        let tf = ThinFilm {
            thickness: 400.0,
            ior: 1.33,
            eta: 1.5,
            f0_scale: [1.0; 3],
        };
        assert_eq!(tf.eval(0.7), reflectance(1.33, 1.5, 0.7, 400.0));
    }
}
