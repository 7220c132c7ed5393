//! Clamp node, with Cycles semantics (`kernel/svm/clamp.h`).

use super::math::clamp_c;

blender_enum! {
    /// `ShaderNodeClamp.clamp_type`.
    pub enum ClampType {
        /// Clamp to [Min, Max]; when Min > Max the result is Max.
        MinMax = "MINMAX",
        /// Clamp to the range between Min and Max, whichever order they come in.
        Range = "RANGE",
    }
}

/// The Clamp node. NaN becomes the lower bound, as in Cycles' `min(max(x, lo), hi)`.
#[inline]
pub fn clamp_node(clamp_type: ClampType, value: f32, min: f32, max: f32) -> f32 {
    if clamp_type == ClampType::Range && min > max {
        clamp_c(value, max, min)
    } else {
        clamp_c(value, min, max)
    }
}
