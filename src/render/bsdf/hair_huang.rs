//! Principled Hair BSDF, Huang model (Cycles' closure/bsdf_principled_hair_huang.h, after
//! Huang, Hullin and Hanika 2022, "A Microfacet-based Hair Scattering Model"): a fibre
//! of elliptical cross-section (Aspect Ratio) whose surface is a GGX microfacet
//! dielectric. Evaluation integrates over the offset `h` across the fibre by Simpson's
//! rule: R exactly, TT and TRT with one sampled microfacet normal per node (Cycles'
//! "combined Monte Carlo-Simpson" estimate), the TRRT+ rest as a geometric series with a
//! longitudinal lobe. Far from the camera (or on any ray but the camera's) the whole
//! fibre is integrated; a fibre wider than the pixel (the near field) integrates only
//! the part of it the pixel covers and samples from the hit's own `h`.
//!
//! As in Cycles, evaluation and sampling both state a pdf of 1 (the importance weight is
//! folded into the sampled value), so that MIS sees the same figure from either side.
//! The quadrature's and the sample's extra random numbers come from Cycles' LCG, seeded
//! here by a hash of the directions (evaluation) or of the sample's own numbers
//! (sampling): the estimate stays a pure function of its inputs.
//!
//! Local frame as Cycles': x the closure normal `n` (perpendicular to the tangent and to
//! the view on a circular fibre, the major axis otherwise), y the curve tangent, z =
//! n x tangent.

use std::f32::consts::PI;

use crate::render::bsdf::hair::Across;
use crate::render::bsdf::microfacet::ggx_vndf;
use crate::render::bsdf::tables::Tables;
use crate::render::math::{vec3, Vec3, V3};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Huang {
    /// Absorption coefficient per unit of fibre radius.
    pub sigma: Vec3,
    /// GGX alpha, clamped to [0.001, 1].
    pub roughness: f32,
    /// Cuticle tilt, radians, negated as Cycles' setup does.
    pub tilt: f32,
    pub eta: f32,
    /// Minor over major axis, at most 1 (Cycles swaps the axes above 1).
    pub b: f32,
    /// The hit's offset across the fibre, -1..1 (-v on a ribbon).
    pub h: f32,
    /// The R, TT and TRT multipliers, each at least 0.
    pub lobes: [f32; 3],
    /// The frame: `n` (Cycles' bsdf->N, local x) and the tangent (local y).
    pub n: V3,
    pub y: Vec3,
    /// The viewer's direction in the local frame (Cycles' extra->wi).
    pub wi: Vec3,
    /// The fibre's width seen from the viewer, in units of the major axis.
    pub radius: f32,
    /// Squared eccentricity, 1 - b^2.
    pub e2: f32,
    /// Half a pixel's width at the hit in units of the fibre's radius (1 off camera rays).
    pub pixel_coverage: f32,
}

/// What Cycles' bsdf_hair_huang_setup makes of a hit.
pub enum Setup {
    Closure(Huang),
    /// The hit lies outside the fibre's projected width (an elliptical fibre seen
    /// across its minor axis is narrower than its ribbon): Cycles replaces the closure
    /// with a transparent one of the same weight.
    Transparent,
}

/// Inputs of the closure as Cycles' svm_node_closure_bsdf passes them.
#[derive(Debug, Clone, Copy)]
pub struct Params {
    pub sigma: V3,
    pub roughness: f32,
    /// The Offset socket (radians), before Cycles negates it.
    pub offset: f32,
    pub ior: f32,
    pub aspect_ratio: f32,
    /// Reflection, Transmission, Secondary Reflection.
    pub lobes: [f32; 3],
}

impl Huang {
    /// Cycles' bsdf_hair_huang_setup on a ribbon hit. `dpdu` is the curve's tangent,
    /// `wi` the unit direction toward the viewer, `v` the hit's place across the ribbon,
    /// `major_axis` the curve's normal attribute (zero when it has none, as particle hair
    /// has none: Cycles then builds an arbitrary frame about the tangent),
    /// `pixel_coverage` Cycles' half-pixel width over the fibre's radius.
    pub fn setup(
        p: &Params,
        dpdu: V3,
        wi: V3,
        across: Across,
        major_axis: V3,
        pixel_coverage: f32,
    ) -> Option<Setup> {
        let (dpdu, wi, major_axis) = (Vec3::from(dpdu), Vec3::from(wi), Vec3::from(major_axis));
        let roughness = p.roughness.clamp(0.001, 1.0);
        let tilt = -p.offset;
        let y = safe_normalize(dpdu);
        let x = safe_normalize(dpdu.cross(wi));
        let h = match across {
            Across::Ribbon { v } => -v,
            Across::Tube { n } | Across::Surface { n, .. } => -x.dot(n.into()),
        };
        let mut b = p.aspect_ratio;
        let mut n = x;
        // Only a curve turns the frame to the ellipse's axis; on a mesh's faces Cycles keeps
        // the frame facing the ray but still takes the Aspect Ratio's eccentricity.
        if b != 1.0 && matches!(across, Across::Ribbon { .. } | Across::Tube { .. }) {
            n = safe_normalize(dpdu.cross(safe_normalize(major_axis.cross(dpdu))));
            if b > 1.0 {
                b = 1.0 / b;
                let minor = safe_normalize(dpdu.cross(n));
                n = safe_normalize(minor.cross(dpdu));
            }
        }
        let z;
        if n.is_zero() || !n.is_finite() {
            let (a, bb) = make_orthonormals(y);
            z = a;
            n = bb;
        } else {
            z = safe_normalize(n.cross(dpdu));
        }
        if y.is_zero() || !y.is_finite() {
            return None;
        }
        let li = vec3(wi.dot(n), wi.dot(y), wi.dot(z));
        let e2 = 1.0 - b * b;
        let radius = if e2 == 0.0 {
            1.0
        } else {
            (1.0 - e2 * li[0] * li[0] / (li[0] * li[0] + li[2] * li[2])).sqrt()
        };
        if !h.is_finite() || !radius.is_finite() {
            return None;
        }
        if h.abs() >= radius {
            return Some(Setup::Transparent);
        }
        Some(Setup::Closure(Huang {
            sigma: p.sigma.into(),
            roughness,
            tilt,
            eta: p.ior,
            b,
            h,
            lobes: p.lobes.map(|l| l.max(0.0)),
            n: n.into(),
            y,
            wi: li,
            radius,
            e2,
            pixel_coverage,
        }))
    }

    fn z(&self) -> Vec3 {
        Vec3::from(self.n).cross(self.y)
    }

    fn local_of(&self, w: Vec3) -> Vec3 {
        vec3(w.dot(self.n.into()), w.dot(self.y), w.dot(self.z()))
    }

    fn global_of(&self, w: Vec3) -> Vec3 {
        Vec3::from(self.n) * w.x + self.y * w.y + self.z() * w.z
    }

    fn circular(&self) -> bool {
        self.b == 1.0
    }

    fn nearfield(&self) -> bool {
        self.radius > self.pixel_coverage
    }

    /// Cycles' bsdf_hair_huang_blur (Filter Glossy).
    pub fn blur(&mut self, roughness: f32) {
        self.roughness = self.roughness.max(roughness);
    }

    /// (BSDF times cosine, pdf) toward `wo` (global, away from the hit): Cycles'
    /// bsdf_hair_huang_eval, whose pdf is always 1.
    pub fn eval(&self, wo: Vec3, tables: &Tables) -> (Vec3, f32) {
        let o = self.local_of(wo);
        let seed = hash_dirs(self.wi, o, self.h);
        let f = self.eval_local(o, seed, tables);
        if f.is_finite() && f.x >= 0.0 && f.y >= 0.0 && f.z >= 0.0 {
            (f, 1.0)
        } else {
            (Vec3::ZERO, 1.0)
        }
    }

    fn eval_local(&self, o: Vec3, seed: u32, tables: &Tables) -> Vec3 {
        let i = self.wi;
        let tan_tilt = self.tilt.tan();
        if tan_tilt * tan_theta(o) < -1.0 {
            return Vec3::ZERO;
        }
        // The azimuths whose mesonormal the viewer sees.
        let half_span = (-tan_tilt * tan_theta(i)).max(0.0).acos();
        if half_span.is_nan() {
            return Vec3::ZERO;
        }
        let r = self.radius;
        let b = self.b;
        let phi_i = if self.circular() { 0.0 } else { dir_phi(i) };
        let mut h = (
            phi_to_h(phi_i + half_span, b, i),
            phi_to_h(phi_i - half_span, b, i),
        );
        let mut dh = 2.0;
        if self.nearfield() {
            // Only the part of the fibre the pixel covers.
            let half = self.pixel_coverage;
            let nf = intersect((-r, r), (self.h - half, self.h + half));
            dh = (nf.1 - nf.0) / r;
            h = intersect(h, nf);
        }
        h = (h.0 / r, h.1 / r);
        h = intersect(h, (-0.999, 0.999));
        if h.0 >= h.1 {
            return Vec3::ZERO;
        }
        let projected_area = cos_theta(i) * dh;
        let mut rng = seed;
        let f = Vec3::splat(self.eval_r(i, o, h, tables))
            + self.eval_residual(i, o, h, &mut rng, tables);
        f * (1.0 / projected_area)
    }

    fn energy_scale(&self, tables: &Tables, mu: f32, eta: f32) -> f32 {
        1.0 / tables.glass_e(mu, self.roughness.sqrt(), eta)
    }

    /// The R lobe by Simpson's rule over `h` (Cycles' bsdf_hair_huang_eval_r).
    fn eval_r(&self, wi: Vec3, wo: Vec3, hr: (f32, f32), tables: &Tables) -> f32 {
        if self.lobes[0] <= 0.0 {
            return 0.0;
        }
        let b = self.b;
        let wh = (wi + wo).normalize();
        let a2 = self.roughness * self.roughness;
        let sc_i = sincos_phi(wi);
        let h_range = hr.1 - hr.0;
        let (intervals, res) = simpson_grid(h_range, self.roughness * 0.7);
        let mut integral = 0.0;
        for k in 0..=intervals {
            let h = hr.0 + k as f32 * res;
            let gamma_m = h_to_gamma(h, b, wi);
            let wm = sphg_dir(self.tilt, gamma_m, b);
            if visible2(wi, wo, vec3(wm.x, 0.0, wm.z), wh) {
                let weight = simpson_weight(k, intervals) * d_gamma_d_h(sc_i, gamma_m, b);
                let cos_mi = wm.dot(wi);
                let g = ggx_g2(a2, cos_mi, wm.dot(wo));
                integral += weight
                    * ggx_d(a2, wm.dot(wh))
                    * g
                    * arc_length(self.e2, gamma_m)
                    * self.energy_scale(tables, cos_mi, self.eta);
            }
        }
        integral *= 2.0 / 3.0 * res;
        let f = crate::render::bsdf::fresnel_dielectric(wi.dot(wh), self.eta);
        self.lobes[0] * 0.25 * f * integral
    }

    /// TT, TRT and the TRRT+ rest (Cycles' bsdf_hair_huang_eval_residual). Long because
    /// it follows Cycles' function step for step (the quadrature over h with its
    /// per-node microfacet samples), which keeps it checkable against the kernel.
    fn eval_residual(
        &self,
        wi: Vec3,
        wo: Vec3,
        hr: (f32, f32),
        rng: &mut u32,
        tables: &Tables,
    ) -> Vec3 {
        let [_, tt_mul, trt_mul] = self.lobes;
        if tt_mul <= 0.0 && trt_mul <= 0.0 {
            return Vec3::ZERO;
        }
        let b = self.b;
        let mu_a = self.sigma;
        let eta = self.eta;
        let inv_eta = 1.0 / eta;
        let a2 = self.roughness * self.roughness;
        let sc_i = sincos_phi(wi);
        let h_range = hr.1 - hr.0;
        let (intervals, res) = simpson_grid(h_range, self.roughness * 0.8);
        let mut s_tt = Vec3::ZERO;
        let mut s_trt = Vec3::ZERO;
        let mut s_trrt = Vec3::ZERO;
        for k in 0..=intervals {
            let h = hr.0 + k as f32 * res;
            let gamma_mi = h_to_gamma(h, b, wi);
            let wmi = sphg_dir(self.tilt, gamma_mi, b);
            let wmi_ = sphg_dir(0.0, gamma_mi, b);
            let u1 = [lcg_float(rng), lcg_float(rng)];
            let wh1 = sample_wh(self.roughness, wi, wmi, u1);
            let cos_hi1 = wi.dot(wh1);
            if !(cos_hi1 > 0.0) {
                continue;
            }
            let cos_mi1 = wi.dot(wmi);
            let (f1, cos_theta_t1) = fresnel(cos_hi1, eta);
            let t1 = 1.0 - f1;
            let scale1 = self.energy_scale(tables, cos_mi1, eta);
            // Refraction into the fibre.
            let wt = refract_angle(wi, wh1, cos_theta_t1, inv_eta);
            let phi_t = dir_phi(wt);
            let gamma_mt = 2.0 * to_phi(phi_t, b) - gamma_mi;
            let wmt = sphg_dir(-self.tilt, gamma_mt, b);
            let wmt_ = sphg_dir(0.0, gamma_mt, b);
            let cos_mo1 = (-wt).dot(wmi);
            let cos_mi2 = (-wt).dot(wmt);
            let g1o = ggx_go(a2, cos_mi1, cos_mo1);
            if !visible2(wi, -wt, wmi, wh1) || !visible2(wi, -wt, wmi_, wh1) {
                continue;
            }
            let weight = simpson_weight(k, intervals) * d_gamma_d_h(sc_i, gamma_mi, b);
            let path = if self.circular() {
                2.0 * (gamma_mi - phi_t).cos()
            } else {
                -len2(sub2(to_point(gamma_mi, b), to_point(gamma_mt + PI, b)))
            };
            let a_t = mu_a.map(|m| (m / cos_theta(wt) * path).exp());
            let scale2 = self.energy_scale(tables, cos_mi2, inv_eta);

            if tt_mul > 0.0 && wo.dot(wt) >= inv_eta - 1e-5 {
                let wh2 = -wt + wo * inv_eta;
                let rcp_norm = 1.0 / wh2.length();
                let wh2 = wh2 * rcp_norm;
                let cos_mh2 = wmt.dot(wh2);
                if cos_mh2 >= 0.0 {
                    let cos_hi2 = (-wt).dot(wh2);
                    let cos_ho2 = (-wo).dot(wh2);
                    let cos_mo2 = (-wo).dot(wmt);
                    let t2 = (1.0 - fresnel_cos(cos_hi2, inv_eta)) * scale2;
                    let d2 = ggx_d(a2, cos_mh2);
                    let g2 = ggx_g2(a2, cos_mi2, cos_mo2);
                    let s = weight * t1 * scale1 * t2 * d2 * g1o * g2 / cos_mo1
                        * cos_mi1
                        * cos_hi2
                        * cos_ho2
                        * rcp_norm
                        * rcp_norm;
                    let result = a_t * s;
                    if result.is_finite() {
                        s_tt += result * (tt_mul * arc_length(self.e2, gamma_mt));
                    }
                }
            }

            if trt_mul > 0.0 {
                let u2 = [lcg_float(rng), lcg_float(rng)];
                let wh2 = sample_wh(self.roughness, -wt, wmt, u2);
                let cos_hi2 = (-wt).dot(wh2);
                if !(cos_hi2 > 0.0) {
                    continue;
                }
                let r2 = fresnel_cos(cos_hi2, inv_eta);
                let wtr = -reflect(wt, wh2);
                let trrt = trrt_series(t1, r2, a_t);
                if (-wtr).dot(wo) < inv_eta - 1e-5 {
                    // Total internal reflection.
                    s_trrt += trrt * weight;
                    continue;
                }
                if !visible2(-wt, -wtr, wmt, wh2) || !visible2(-wt, -wtr, wmt_, wh2) {
                    continue;
                }
                let phi_tr = dir_phi(wtr);
                let gamma_mtr = gamma_mi - 2.0 * (to_phi(phi_t, b) - to_phi(phi_tr, b)) + PI;
                let wmtr = sphg_dir(-self.tilt, gamma_mtr, b);
                let wmtr_ = sphg_dir(0.0, gamma_mtr, b);
                let wh3 = wtr + wo * inv_eta;
                let rcp_norm3 = 1.0 / wh3.length();
                let wh3 = wh3 * rcp_norm3;
                let cos_mh3 = wmtr.dot(wh3);
                if cos_mh3 < 0.0
                    || !visible2(wtr, -wo, wmtr, wh3)
                    || !visible2(wtr, -wo, wmtr_, wh3)
                {
                    s_trrt += trrt * weight;
                    continue;
                }
                let cos_hi3 = wh3.dot(wtr);
                let cos_ho3 = wh3.dot(-wo);
                let cos_mi3 = wmtr.dot(wtr);
                let t3 = (1.0 - fresnel_cos(cos_hi3, inv_eta))
                    * self.energy_scale(tables, cos_mi3, inv_eta);
                let d3 = ggx_d(a2, cos_mh3);
                let path_tr = if self.circular() {
                    2.0 * (phi_tr - gamma_mt).cos().abs()
                } else {
                    len2(sub2(to_point(gamma_mtr, b), to_point(gamma_mt, b)))
                };
                let a_tr = mu_a.map(|m| (m / cos_theta(wtr) * -path_tr).exp());
                let cos_mo2 = wmt.dot(-wtr);
                let g2o = ggx_go(a2, cos_mi2, cos_mo2);
                let g3 = ggx_g2(a2, cos_mi3, wmtr.dot(-wo));
                let s = weight * t1 * scale1 * r2 * scale2 * t3 * d3 * g1o * g2o * g3
                    / (cos_mo1 * cos_mo2)
                    * cos_mi1
                    * cos_mi2
                    * cos_hi3
                    * cos_ho3
                    * rcp_norm3
                    * rcp_norm3;
                let result = a_t * a_tr * s;
                if result.is_finite() {
                    s_trt += result * (trt_mul * arc_length(self.e2, gamma_mtr));
                }
                s_trrt += trrt * weight;
            }
        }
        // TRRT+ with Chiang et al.'s longitudinal lobe and a uniform azimuth.
        let m = crate::render::bsdf::hair_chiang::longitudinal_scattering(
            sin_theta(wi),
            cos_theta(wi),
            sin_theta(wo),
            cos_theta(wo),
            4.0 * self.roughness,
        );
        let n = 1.0 / (2.0 * PI);
        let simpson = 2.0 / 3.0 * res;
        ((s_tt + s_trt) * (inv_eta * inv_eta) + s_trrt * (m * n * (2.0 / PI))) * simpson
    }

    /// Cycles' bsdf_hair_huang_sample: (direction, value, pdf 1). Cycles labels every
    /// sample a glossy reflection, through the fibre or not. Long because it follows
    /// Cycles' function step for step (R, TT, TRT and TRRT+ chosen by their energies).
    pub fn sample(&self, u: [f32; 3], tables: &Tables) -> Option<(Vec3, Vec3, f32)> {
        let mut rng = hash_u(u);
        let roughness = self.roughness;
        let sample_lobe = u[0];
        let sample_h = u[1];
        let u_h1 = [u[2], lcg_float(&mut rng)];
        let u_h2 = [lcg_float(&mut rng), lcg_float(&mut rng)];
        let u_h3 = [lcg_float(&mut rng), lcg_float(&mut rng)];
        let wi = self.wi;
        let b = self.b;
        // The far field samples h: the hit's own is no better than any across the fibre.
        let h_div_r = if self.nearfield() {
            self.h / self.radius
        } else {
            sample_h * 2.0 - 1.0
        };
        let gamma_mi = h_to_gamma(h_div_r, b, wi);
        let wmi_ = sphg_dir(0.0, gamma_mi, b);
        let (st, ct) = self.tilt.sin_cos();
        let wmi = vec3(wmi_.x * ct, st, wmi_.z * ct);
        let cos_mi1 = wmi.dot(wi);
        if cos_mi1 < 0.0 || wmi_.dot(wi) < 0.0 {
            return None;
        }
        let a2 = roughness * roughness;
        let wh1 = sample_wh(roughness, wi, wmi, u_h1);
        let wr = -reflect(wi, wh1);
        if !visible1(wi, wmi_, wh1) {
            return None;
        }
        let (r1, cos_theta_t1) = fresnel(wi.dot(wh1), self.eta);
        let scale1 = self.energy_scale(tables, cos_mi1, self.eta);
        let r = self.lobes[0]
            * r1
            * scale1
            * if visible1(wr, wmi_, wh1) { 1.0 } else { 0.0 }
            * ggx_go(a2, cos_mi1, wmi.dot(wr));

        let inv_eta = 1.0 / self.eta;
        let wt = refract_angle(wi, wh1, cos_theta_t1, inv_eta);
        let phi_t = dir_phi(wt);
        let gamma_mt = 2.0 * to_phi(phi_t, b) - gamma_mi;
        let wmt = sphg_dir(-self.tilt, gamma_mt, b);
        let wmt_ = sphg_dir(0.0, gamma_mt, b);
        let wh2 = sample_wh(roughness, -wt, wmt, u_h2);
        let wtr = -reflect(wt, wh2);

        let mut wtt = Vec3::ZERO;
        let mut wtrt = Vec3::ZERO;
        let mut wtrrt = Vec3::ZERO;
        let mut tt = Vec3::ZERO;
        let mut trt = Vec3::ZERO;
        let mut trrt = Vec3::ZERO;
        let cos_mi2 = (-wt).dot(wmt);
        if cos_mi2 > 0.0 && visible1(-wt, wmi_, wh1) && visible1(-wt, wmt_, wh2) {
            let mu_a = self.sigma;
            let path = if self.circular() {
                2.0 * (phi_t - gamma_mi).cos()
            } else {
                -len2(sub2(to_point(gamma_mi, b), to_point(gamma_mt + PI, b)))
            };
            let a_t = mu_a.map(|m| (m / cos_theta(wt) * path).exp());
            let (r2, cos_theta_t2) = fresnel((-wt).dot(wh2), inv_eta);
            let t1 = (1.0 - r1) * scale1 * ggx_go(a2, cos_mi1, wmi.dot(-wt));
            let t2 = 1.0 - r2;
            let scale2 = self.energy_scale(tables, cos_mi2, inv_eta);
            wtt = refract_angle(-wt, wh2, cos_theta_t2, self.eta);
            if wmt.dot(-wtt) > 0.0 && t2 > 0.0 && visible1(-wtt, wmt_, wh2) {
                tt = a_t * (self.lobes[1] * t1 * t2 * scale2 * ggx_go(a2, cos_mi2, wmt.dot(-wtt)));
            }
            let phi_tr = dir_phi(wtr);
            let gamma_mtr = gamma_mi - 2.0 * (to_phi(phi_t, b) - to_phi(phi_tr, b)) + PI;
            let wmtr = sphg_dir(-self.tilt, gamma_mtr, b);
            let wh3 = sample_wh(roughness, wtr, wmtr, u_h3);
            let (r3, cos_theta_t3) = fresnel(wtr.dot(wh3), inv_eta);
            wtrt = refract_angle(wtr, wh3, cos_theta_t3, self.eta);
            let cos_mi3 = wmtr.dot(wtr);
            if cos_mi3 > 0.0 {
                let path_tr = if self.circular() {
                    2.0 * (phi_tr - gamma_mt).cos().abs()
                } else {
                    len2(sub2(to_point(gamma_mt, b), to_point(gamma_mtr, b)))
                };
                let a_tr = mu_a.map(|m| (m / cos_theta(wtr) * -path_tr).exp());
                let tr = a_t
                    * a_tr
                    * (t1
                        * r2
                        * scale2
                        * self.energy_scale(tables, cos_mi3, inv_eta)
                        * ggx_go(a2, cos_mi2, wmt.dot(-wtr)));
                let t3 = 1.0 - r3;
                if t3 > 0.0
                    && visible1(wtr, wmtr_flat(wmtr), wh3)
                    && visible1(-wtrt, wmtr_flat(wmtr), wh3)
                {
                    trt = tr * (self.lobes[2] * t3 * ggx_go(a2, cos_mi3, wmtr.dot(-wtrt)));
                }
                // TRRT+: Chiang et al.'s longitudinal lobe about the viewer, any azimuth.
                let rand_theta = lcg_float(&mut rng).max(1e-5);
                let fac = 1.0
                    + 4.0
                        * roughness
                        * (rand_theta + (1.0 - rand_theta) * (-0.5 / roughness).exp()).ln();
                let sin_theta_o = -fac * sin_theta(wi)
                    + cos_from_sin(fac) * (2.0 * PI * lcg_float(&mut rng)).cos() * cos_theta(wi);
                let cos_theta_o = cos_from_sin(sin_theta_o);
                let phi_o = 2.0 * PI * lcg_float(&mut rng);
                let (sin_phi_o, cos_phi_o) = phi_o.sin_cos();
                wtrrt = vec3(
                    sin_phi_o * cos_theta_o,
                    sin_theta_o,
                    cos_phi_o * cos_theta_o,
                );
                // The series A T + A^2 R T + ..., attenuations from the bounces before.
                let a_avg = (a_t * a_tr).map(|x| x.sqrt());
                let t_avg = (0.5 * (t2 + t3)).max(1e-5);
                let a_res = a_avg.map(|a| a * t_avg / (1.0 - a * (1.0 - t_avg)));
                trrt = tr
                    * a_res
                    * Vec3::splat(r3)
                    * ggx_go(a2, cos_mi3, wmtr.dot(-reflect(wtr, wh3)));
            }
        }
        let tt_e = tt.average();
        let trt_e = trt.average();
        let trrt_e = trrt.average();
        let total = r + tt_e + trt_e + trrt_e;
        if !(total > 0.0) || !total.is_finite() {
            return None;
        }
        let x = sample_lobe * total;
        let (local, value) = if x < r {
            (wr, Vec3::splat(total))
        } else if x < r + tt_e {
            (wtt, tt * (total / tt_e))
        } else if x < r + tt_e + trt_e {
            (wtrt, trt * (total / trt_e))
        } else {
            (wtrrt, trrt * (total / trrt_e))
        };
        if !value.is_finite() || !local.is_finite() {
            return None;
        }
        Some((self.global_of(local), value, 1.0))
    }
}

/// Cycles' make_float3(wmtr.x, 0, wmtr.z): the mesonormal's visibility ignores its tilt.
fn wmtr_flat(w: Vec3) -> Vec3 {
    vec3(w.x, 0.0, w.z)
}

/// Cycles' bsdf_hair_huang_eval_trrt: TRRT and beyond as a geometric series, with the
/// attenuations of the bounces before.
fn trrt_series(t: f32, r: f32, a: Vec3) -> Vec3 {
    let t_avg = (1.0 - r).max(1e-5);
    a.map(|a| {
        let trrt_avg = t * r * r * t_avg * a * a * a;
        trrt_avg / (1.0 - a * (1.0 - t_avg))
    })
}

/// An even number of Simpson intervals of at most `res` over `range`, and their width.
fn simpson_grid(range: f32, res: f32) -> (usize, f32) {
    let intervals = 2 * (range / res * 0.5).ceil() as usize;
    let intervals = intervals.max(2);
    (intervals, range / intervals as f32)
}

fn simpson_weight(k: usize, intervals: usize) -> f32 {
    if k == 0 || k == intervals {
        0.5
    } else {
        (k % 2 + 1) as f32
    }
}

fn safe_normalize(v: Vec3) -> Vec3 {
    let l = v.length();
    if l > 0.0 {
        v * (1.0 / l)
    } else {
        Vec3::ZERO
    }
}

/// Cycles' make_orthonormals: two unit vectors perpendicular to `n` and each other.
fn make_orthonormals(n: Vec3) -> (Vec3, Vec3) {
    let a = if n.x != n.y || n.x != n.z {
        vec3(n.z - n.y, n.x - n.z, n.y - n.x)
    } else {
        vec3(n.z - n.y, n.x + n.z, -n.y - n.x)
    };
    let a = a.normalize();
    (a, n.cross(a))
}

fn sqr(x: f32) -> f32 {
    x * x
}

fn cos_from_sin(s: f32) -> f32 {
    (1.0 - s * s).max(0.0).sqrt()
}

fn sin_theta(w: Vec3) -> f32 {
    w.y
}

fn cos_theta(w: Vec3) -> f32 {
    (sqr(w.x) + sqr(w.z)).max(0.0).sqrt()
}

fn tan_theta(w: Vec3) -> f32 {
    sin_theta(w) / cos_theta(w)
}

fn sincos_phi(w: Vec3) -> [f32; 2] {
    let c = cos_theta(w);
    [w.x / c, w.z / c]
}

/// The azimuth, 0 toward local z (the viewer's on a circular fibre).
fn dir_phi(w: Vec3) -> f32 {
    w.x.atan2(w.z)
}

fn to_phi(gamma: f32, b: f32) -> f32 {
    if b == 1.0 {
        return gamma;
    }
    let (s, c) = gamma.sin_cos();
    (b * s).atan2(c)
}

/// The offset across the fibre of the ray toward the ellipse point at azimuth `phi`.
fn phi_to_h(phi: f32, b: f32, wi: Vec3) -> f32 {
    if b == 1.0 {
        return -phi.sin();
    }
    let gamma = {
        let (s, c) = phi.sin_cos();
        s.atan2(b * c)
    };
    let (sg, cg) = gamma.sin_cos();
    let sc = sincos_phi(wi);
    -sc[1] * sg + b * sc[0] * cg
}

fn h_to_gamma(h_div_r: f32, b: f32, wi: Vec3) -> f32 {
    if b == 1.0 {
        -h_div_r.asin()
    } else {
        wi.z.atan2(-b * wi.x) - (-h_div_r).acos()
    }
}

/// |d gamma / d h|, the change of variable of the quadrature.
fn d_gamma_d_h(sc_i: [f32; 2], gamma: f32, b: f32) -> f32 {
    let d = if b == 1.0 {
        gamma.cos()
    } else {
        let (s, c) = gamma.sin_cos();
        sc_i[1] * c + b * sc_i[0] * s
    };
    if d != 0.0 {
        1.0 / d
    } else {
        0.0
    }
}

fn to_point(gamma: f32, b: f32) -> [f32; 2] {
    let (s, c) = gamma.sin_cos();
    [s, b * c]
}

fn sub2(a: [f32; 2], b: [f32; 2]) -> [f32; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn len2(a: [f32; 2]) -> f32 {
    (a[0] * a[0] + a[1] * a[1]).sqrt()
}

/// The direction at elevation `theta` whose azimuth is the ellipse normal's at `gamma`.
fn sphg_dir(theta: f32, gamma: f32, b: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sg, cg) = gamma.sin_cos();
    let (sp, cp) = if b == 1.0 || cg.abs() < 1e-6 {
        (sg, cg)
    } else {
        let tan_phi = b * sg / cg;
        let cp = cg.signum() / (tan_phi * tan_phi + 1.0).sqrt();
        (cp * tan_phi, cp)
    };
    vec3(sp * ct, st, cp * ct)
}

fn arc_length(e2: f32, gamma: f32) -> f32 {
    if e2 == 0.0 {
        1.0
    } else {
        (1.0 - e2 * sqr(gamma.sin())).sqrt()
    }
}

fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    // Cycles' reflect(incident, unit_normal): incident - 2 n (n . incident).
    w - n * (2.0 * n.dot(w))
}

fn refract_angle(incident: Vec3, normal: Vec3, cos_theta_t: f32, inv_eta: f32) -> Vec3 {
    normal * (inv_eta * normal.dot(incident) + cos_theta_t) - incident * inv_eta
}

/// Cycles' fresnel_dielectric with the refracted cosine (negative; 0 on total internal
/// reflection, where Cycles leaves it unset and never uses it).
fn fresnel(cos_i: f32, eta: f32) -> (f32, f32) {
    let e = sqr(eta) - (1.0 - sqr(cos_i));
    if e <= 0.0 {
        return (1.0, 0.0);
    }
    let ci = cos_i.abs();
    let ct = -e.max(0.0).sqrt() / eta;
    let rs = (ci + eta * ct) / (ci - eta * ct);
    let rp = (ct + eta * ci) / (eta * ci - ct);
    (0.5 * (rs * rs + rp * rp), ct)
}

fn fresnel_cos(cos_i: f32, eta: f32) -> f32 {
    crate::render::bsdf::fresnel_dielectric(cos_i, eta)
}

fn ggx_lambda(a2: f32, cos_n: f32) -> f32 {
    crate::render::bsdf::microfacet::lambda(
        crate::render::bsdf::microfacet::Distribution::Ggx,
        a2,
        cos_n,
    )
}

fn ggx_d(a2: f32, cos_nh: f32) -> f32 {
    crate::render::bsdf::microfacet::d(
        crate::render::bsdf::microfacet::Distribution::Ggx,
        a2,
        cos_nh,
    )
}

fn ggx_g2(a2: f32, cos_i: f32, cos_o: f32) -> f32 {
    1.0 / (1.0 + ggx_lambda(a2, cos_i) + ggx_lambda(a2, cos_o))
}

/// Shadowing-masking over masking toward the viewer (Cycles' bsdf_Go).
fn ggx_go(a2: f32, cos_i: f32, cos_o: f32) -> f32 {
    let li = ggx_lambda(a2, cos_i);
    let lo = ggx_lambda(a2, cos_o);
    (1.0 + li) / (1.0 + li + lo)
}

fn visible1(v: Vec3, m: Vec3, h: Vec3) -> bool {
    v.dot(h) > 0.0 && v.dot(m) > 0.0
}

fn visible2(wi: Vec3, wo: Vec3, m: Vec3, h: Vec3) -> bool {
    visible1(wi, m, h) && visible1(wo, m, h)
}

/// A visible microfacet normal about the (tilted) mesonormal `wm` (Cycles' sample_wh).
fn sample_wh(roughness: f32, wi: Vec3, wm: Vec3, u: [f32; 2]) -> Vec3 {
    let (s, t) = make_orthonormals(wm);
    let local = vec3(wi.dot(s), wi.dot(t), wi.dot(wm));
    let h = ggx_vndf(local, roughness, roughness, u);
    s * h.x + t * h.y + wm * h.z
}

fn intersect(a: (f32, f32), b: (f32, f32)) -> (f32, f32) {
    (a.0.max(b.0), a.1.min(b.1))
}

/// Cycles' lcg_step_float.
fn lcg_float(rng: &mut u32) -> f32 {
    *rng = rng.wrapping_mul(1103515245).wrapping_add(12345);
    *rng as f32 * (1.0 / 0xFFFF_FFFFu32 as f32)
}

fn hash_dirs(a: Vec3, b: Vec3, h: f32) -> u32 {
    use crate::nodes::random::hash4;
    let k = hash4(a.x.to_bits(), a.y.to_bits(), a.z.to_bits(), h.to_bits());
    hash4(k, b.x.to_bits(), b.y.to_bits(), b.z.to_bits())
}

fn hash_u(u: [f32; 3]) -> u32 {
    crate::nodes::random::hash3(u[0].to_bits(), u[1].to_bits(), u[2].to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn closure(sigma: V3, aspect: f32, v: f32, coverage: f32) -> Huang {
        let p = Params {
            sigma,
            roughness: 0.3,
            offset: 2f32.to_radians(),
            ior: 1.55,
            aspect_ratio: aspect,
            lobes: [1.0; 3],
        };
        let wo = vec3(0.3, 1.0, 0.5).normalize();
        match Huang::setup(
            &p,
            [0.0, 0.0, 1.0],
            wo.into(),
            Across::Ribbon { v },
            [0.0; 3],
            coverage,
        ) {
            Some(Setup::Closure(c)) => c,
            _ => panic!("no closure"),
        }
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

    /// The integral of the evaluation over the sphere (the albedo eval implies).
    fn eval_albedo(c: &Huang, tables: &Tables) -> V3 {
        let n = 64;
        let mut sum = [0.0f64; 3];
        for i in 0..n {
            for j in 0..2 * n {
                let (wi, dw) = sphere_dir(i, j, n);
                let (f, pdf) = c.eval(wi, tables);
                assert_eq!(pdf, 1.0);
                for k in 0..3 {
                    sum[k] += (f[k] * dw) as f64;
                }
            }
        }
        sum.map(|s| s as f32)
    }

    /// The mean sampled value (the albedo sampling implies; its pdf is Cycles' 1).
    fn sample_albedo(c: &Huang, tables: &Tables) -> V3 {
        let n = 24;
        let mut sum = [0.0f64; 3];
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let u = [
                        (i as f32 + 0.5) / n as f32,
                        (j as f32 + 0.5) / n as f32,
                        (k as f32 + 0.5) / n as f32,
                    ];
                    if let Some((wi, f, pdf)) = c.sample(u, tables) {
                        assert_eq!(pdf, 1.0);
                        assert!((wi.length() - 1.0).abs() < 1e-3, "{wi:?}");
                        for ch in 0..3 {
                            sum[ch] += f[ch] as f64;
                        }
                    }
                }
            }
        }
        sum.map(|s| (s / (n * n * n) as f64) as f32)
    }

    /// Sampling and evaluation state the same pdf (Cycles' 1, checked in both helpers)
    /// and, for an absorbing fibre, imply the same albedo: the sampled value's mean is the
    /// evaluation's integral over the sphere within 8% (Cycles estimates TRRT+ one way
    /// when evaluating, another when sampling), both below one, red above green above
    /// blue. A white fibre's samples keep to at most one; its evaluation does not
    /// (Cycles' TRRT+ series, T over a trapped ray's every bounce, counts up to T again
    /// where the inner Fresnel is total), so only the sampled side is bounded there.
    #[test]
    fn sample_and_eval_agree_and_conserve_energy() {
        let tables = Tables::shared();
        tables.warm_glass();
        // Far field circular, far field elliptical, near field (the pixel covers a fifth).
        for (aspect, v, coverage) in [(1.0, 0.3, 1.0), (0.6, -0.2, 1.0), (1.0, 0.5, 0.2)] {
            let brown = closure([0.4, 0.8, 1.6], aspect, v, coverage);
            let e = eval_albedo(&brown, tables);
            let s = sample_albedo(&brown, tables);
            for ch in 0..3 {
                assert!(e[ch] > 0.03 && e[ch] < 1.0, "{aspect} {v}: eval {e:?}");
                assert!(s[ch] > 0.03 && s[ch] < 1.0, "{aspect} {v}: sample {s:?}");
                assert!(
                    (e[ch] - s[ch]).abs() < 0.08 * s[ch],
                    "{aspect} {v}: {e:?} {s:?}"
                );
            }
            assert!(e[0] > e[1] && e[1] > e[2], "{e:?}");
            let white = sample_albedo(&closure([0.0; 3], aspect, v, coverage), tables);
            assert!(white.iter().all(|&w| w > 0.9 && w < 1.03), "{white:?}");
        }
    }

    /// Cycles' setup: an ellipse's projected width is below one across its minor axis, a
    /// hit beyond it is transparent; Aspect Ratio above 1 swaps the axes.
    #[test]
    fn ellipse_setup_as_cycles() {
        let p = Params {
            sigma: [0.0; 3],
            roughness: 0.3,
            offset: 0.0,
            ior: 1.55,
            aspect_ratio: 0.5,
            lobes: [1.0; 3],
        };
        // Tangent z: the arbitrary frame's x is (1,1,1) x z normalised's cross.
        let wi = [1.0, 0.0, 0.0];
        let Some(Setup::Closure(c)) = Huang::setup(
            &p,
            [0.0, 0.0, 1.0],
            wi,
            Across::Ribbon { v: 0.1 },
            [0.0; 3],
            1.0,
        ) else {
            panic!()
        };
        let li = c.wi;
        let expect = (1.0 - 0.75 * li[0] * li[0] / (li[0] * li[0] + li[2] * li[2])).sqrt();
        assert!((c.radius - expect).abs() < 1e-6 && c.radius < 1.0);
        let beyond = -(c.radius + 0.01);
        assert!(matches!(
            Huang::setup(
                &p,
                [0.0, 0.0, 1.0],
                wi,
                Across::Ribbon { v: -beyond },
                [0.0; 3],
                1.0
            ),
            Some(Setup::Transparent)
        ));
        let wide = Params {
            aspect_ratio: 2.0,
            ..p
        };
        let Some(Setup::Closure(w)) = Huang::setup(
            &wide,
            [0.0, 0.0, 1.0],
            wi,
            Across::Ribbon { v: 0.1 },
            [0.0; 3],
            1.0,
        ) else {
            panic!()
        };
        assert_eq!(w.b, 0.5);
    }
}
