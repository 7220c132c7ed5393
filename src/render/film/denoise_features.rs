//! The denoiser's guide passes as Cycles writes them (kernel/film/denoising_passes.h):
//! per sample, along the path, not from one ray through the pixel centre, so they carry
//! the bumped closure normals, depth of field and motion blur the image has. OIDN keeps
//! detail the guides show and smooths what they do not, so guides without the bump
//! flatten a bumped surface.
//!
//! At the first surface where at least a quarter of the closures' sample weight is
//! non-specular (roughness squared above 0.075²), the sample writes the closures' normal
//! (average weighted by sample weight) and their non-specular albedo, both times the
//! specular albedo of the surfaces passed before; until then each mostly-specular surface
//! only multiplies that throughput. Emission and background met on the way add to the
//! albedo. A path that never writes leaves zero.

use crate::render::bsdf::{LobeKind, LobeSet};
use crate::render::math::{Vec3, V3};

/// One sample's guide values and the state of their path.
#[derive(Debug, Clone, Copy)]
pub struct Features {
    /// Still looking for the surface that writes the guides (PATH_RAY_DENOISING_FEATURES).
    pub active: bool,
    /// Specular albedo of the surfaces passed so far.
    pub throughput: V3,
    pub normal: V3,
    pub albedo: V3,
}

impl Default for Features {
    fn default() -> Self {
        Features {
            active: true,
            throughput: [1.0; 3],
            normal: [0.0; 3],
            albedo: [0.0; 3],
        }
    }
}

/// Cycles' bsdf_get_specular_roughness_squared: singular closures 0, microfacets
/// alpha_x * alpha_y, everything else (diffuse-like, BSSRDF) 1.
fn roughness_squared(k: &LobeKind) -> f32 {
    match k {
        // Cycles: singular closures (CLOSURE_IS_BSDF_SINGULAR).
        LobeKind::Transparent | LobeKind::RayPortal(_) => 0.0,
        LobeKind::Glossy { alpha, .. } => alpha * alpha,
        LobeKind::Glass(g) => g.alpha * g.alpha,
        LobeKind::Reflection(r) => r.alpha * r.alpha,
        LobeKind::GlossyAniso { lobe, .. } => lobe.alpha_x * lobe.alpha_y,
        _ => 1.0,
    }
}

impl Features {
    /// Light reaching the sample before the guides are written (emission, background,
    /// a lamp seen directly): Cycles adds it to the albedo guide.
    #[inline]
    pub fn add_emission(&mut self, contribution: V3) {
        let contribution = Vec3::from(contribution);
        if self.active && contribution.is_finite() {
            let throughput = Vec3::from(self.throughput);
            self.albedo = (Vec3::from(self.albedo) + throughput * contribution).into();
        }
    }

    /// A surface with these closures (after Filter Glossy) on the sample's path.
    pub fn surface(&mut self, lobes: &LobeSet) {
        if !self.active {
            return;
        }
        let (mut n, mut diffuse, mut specular) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        let (mut sum, mut sum_nonspecular) = (0.0f32, 0.0f32);
        for l in &lobes.lobes[..lobes.len] {
            let weight = Vec3::from(l.weight);
            n += Vec3::from(l.n) * l.sample_weight;
            sum += l.sample_weight;
            // Cycles' bsdf_albedo: a BSSRDF's weight (its sample weight counts every
            // channel); otherwise the weight scaled by the albedo estimate that the
            // sample weight was scaled by.
            let wsum = weight[0].abs() + weight[1].abs() + weight[2].abs();
            let albedo = match l.kind {
                LobeKind::Subsurface(_) => weight,
                _ if wsum > 0.0 => weight * (l.sample_weight / wsum).min(1.0),
                _ => Vec3::ZERO,
            };
            if roughness_squared(&l.kind) > 0.075 * 0.075 {
                diffuse += albedo;
                sum_nonspecular += l.sample_weight;
            } else {
                specular += albedo;
            }
        }
        let throughput = Vec3::from(self.throughput);
        if sum == 0.0 || sum_nonspecular * 4.0 > sum {
            if sum != 0.0 {
                n *= 1.0 / sum;
            }
            if n.is_finite() {
                self.normal = n.into();
            }
            let a = throughput * diffuse;
            if a.is_finite() {
                self.albedo = (Vec3::from(self.albedo) + a).into();
            }
            self.active = false;
        } else {
            self.throughput = (throughput * specular).into();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::bsdf::Fresnel;

    #[test]
    fn mostly_specular_surfaces_pass_the_guides_on() {
        let mut lobes = LobeSet::default();
        let mirror = LobeKind::Glossy {
            alpha: 0.0,
            fresnel: Fresnel::Constant,
            energy: 1.0,
        };
        lobes.push(mirror, [0.9, 0.8, 0.7], [0.0, 0.0, 1.0]);
        lobes.push(LobeKind::Diffuse, [0.1, 0.1, 0.1], [0.0, 1.0, 0.0]);
        let mut f = Features::default();
        f.surface(&lobes);
        // 0.3 of 2.7 is non-specular: below a quarter, so the path goes on.
        assert!(f.active);
        assert_eq!(f.throughput, [0.9, 0.8, 0.7]);
        let mut diffuse = LobeSet::default();
        diffuse.push(LobeKind::Diffuse, [0.5, 0.25, 0.5], [1.0, 0.0, 0.0]);
        f.surface(&diffuse);
        assert!(!f.active);
        assert_eq!(f.normal, [1.0, 0.0, 0.0]);
        assert!((f.albedo[0] - 0.45).abs() < 1e-6 && (f.albedo[1] - 0.2).abs() < 1e-6);
    }

    #[test]
    fn the_normal_is_the_sample_weighted_average_of_the_closures() {
        let mut lobes = LobeSet::default();
        lobes.push(LobeKind::Diffuse, [0.3; 3], [0.0, 0.0, 1.0]);
        lobes.push(LobeKind::Diffuse, [0.1; 3], [1.0, 0.0, 0.0]);
        let mut f = Features::default();
        f.surface(&lobes);
        assert!(!f.active);
        assert!((f.normal[2] - 0.75).abs() < 1e-6 && (f.normal[0] - 0.25).abs() < 1e-6);
        assert!((f.albedo[0] - 0.4).abs() < 1e-6);
    }
}
