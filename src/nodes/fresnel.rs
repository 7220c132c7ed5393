//! Fresnel and Layer Weight (Cycles' svm/fresnel.h): dielectric reflectance of the
//! incoming direction against a normal, and the facing ratio.

use crate::foundation::math::dot;

use super::math::V3;

/// Unpolarised dielectric Fresnel reflectance for cos(theta_i) and relative IOR `eta`
/// (Cycles' `fresnel_dielectric_cos`): 1 under total internal reflection.
pub fn fresnel_dielectric_cos(cosi: f32, eta: f32) -> f32 {
    let c = cosi.abs();
    let g = eta * eta - 1.0 + c * c;
    if g > 0.0 {
        let g = g.sqrt();
        let a = (g - c) / (g + c);
        let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
        0.5 * a * a * (1.0 + b * b)
    } else {
        1.0
    }
}

/// Fresnel node: `incoming` is the unit direction toward the viewer, `normal` the node's
/// Normal input (the shading normal when unlinked).
pub fn fresnel(ior: f32, incoming: V3, normal: V3, backfacing: bool) -> f32 {
    let eta = ior.max(1e-5);
    let eta = if backfacing { 1.0 / eta } else { eta };
    fresnel_dielectric_cos(dot(incoming, normal), eta)
}

/// Layer Weight node: (Fresnel, Facing).
pub fn layer_weight(blend: f32, incoming: V3, normal: V3, backfacing: bool) -> (f32, f32) {
    let cosi = dot(incoming, normal);
    let eta = (1.0 - blend).max(1e-5);
    let eta = if backfacing { eta } else { 1.0 / eta };
    let fresnel = fresnel_dielectric_cos(cosi, eta);
    let mut f = cosi.abs();
    if blend != 0.5 {
        let b = blend.clamp(0.0, 1.0 - 1e-5);
        let b = if b < 0.5 { 2.0 * b } else { 0.5 / (1.0 - b) };
        f = f.powf(b);
    }
    (fresnel, 1.0 - f)
}
