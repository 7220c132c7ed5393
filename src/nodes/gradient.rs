//! Gradient Texture (Cycles `svm_gradient`; Geometry Nodes' multi-function is the same
//! without the final clamp).

use super::math::V3;

blender_enum! {
    pub enum GradientType {
        Linear = "LINEAR",
        Quadratic = "QUADRATIC",
        Easing = "EASING",
        Diagonal = "DIAGONAL",
        Spherical = "SPHERICAL",
        QuadraticSphere = "QUADRATIC_SPHERE",
        Radial = "RADIAL",
    }
}

/// Fac (the Color output is Fac in all three channels), clamped to [0, 1] as Cycles does.
pub fn gradient(kind: GradientType, p: V3) -> f32 {
    gradient_unclamped(kind, p).clamp(0.0, 1.0)
}

/// Fac before Cycles' clamp: what Geometry Nodes output (Linear, Quadratic and Diagonal
/// leave [0, 1] there).
pub fn gradient_unclamped(kind: GradientType, p: V3) -> f32 {
    let [x, y, z] = p;
    match kind {
        GradientType::Linear => x,
        GradientType::Quadratic => {
            let r = x.max(0.0);
            r * r
        }
        GradientType::Easing => {
            // fminf(fmaxf(x, 0), 1): NaN becomes 0, unlike clamp.
            #[allow(clippy::manual_clamp)]
            let r = x.max(0.0).min(1.0);
            let t = r * r;
            3.0 * t - 2.0 * t * r
        }
        GradientType::Diagonal => (x + y) * 0.5,
        GradientType::Radial => y.atan2(x) / (2.0 * std::f32::consts::PI) + 0.5,
        GradientType::Spherical | GradientType::QuadraticSphere => {
            // The bias makes a unit-length vector give exactly zero.
            let r = (0.999999 - (x * x + y * y + z * z).sqrt()).max(0.0);
            if kind == GradientType::Spherical {
                r
            } else {
                r * r
            }
        }
    }
}
