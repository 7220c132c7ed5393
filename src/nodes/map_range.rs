//! Map Range node (float and vector), with Cycles semantics (`kernel/svm/map_range.h`).
//!
//! The float and vector variants differ in Cycles, and blendsynth keeps the differences:
//! the float one returns 0 for an empty "from" range and handles a reversed "from" range
//! in the smooth modes; the vector one divides safely (factor 0) and ignores "Clamp" for
//! the smooth modes. The float "Clamp" is the Clamp node (Range mode) Cycles appends.

use super::clamp::{clamp_node, ClampType};
use super::math::{clamp_c, safe_divide, V3};

blender_enum! {
    /// `ShaderNodeMapRange.interpolation_type`.
    pub enum MapRangeInterpolation {
        Linear = "LINEAR",
        Stepped = "STEPPED",
        SmoothStep = "SMOOTHSTEP",
        SmootherStep = "SMOOTHERSTEP",
    }
}

/// Cycles `smoothstep(edge0, edge1, x)` (edges assumed ordered).
#[inline]
pub fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    if x < edge0 {
        0.0
    } else if x >= edge1 {
        1.0
    } else {
        let t = (x - edge0) / (edge1 - edge0);
        (3.0 - 2.0 * t) * (t * t)
    }
}

/// Cycles `smootherstep(edge0, edge1, x)`.
#[inline]
pub fn smootherstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let x = clamp_c(safe_divide(x - edge0, edge1 - edge0), 0.0, 1.0);
    x * x * x * (x * (x * 6.0 - 15.0) + 10.0)
}

#[inline]
fn stepped(factor: f32, steps: f32) -> f32 {
    if steps > 0.0 {
        (factor * (steps + 1.0)).floor() / steps
    } else {
        0.0
    }
}

/// Map Range, float data type.
#[allow(clippy::too_many_arguments)]
pub fn map_range_float(
    interpolation: MapRangeInterpolation,
    clamp: bool,
    value: f32,
    from_min: f32,
    from_max: f32,
    to_min: f32,
    to_max: f32,
    steps: f32,
) -> f32 {
    use MapRangeInterpolation::*;
    let result = if from_max != from_min {
        let factor = match interpolation {
            Linear => (value - from_min) / (from_max - from_min),
            Stepped => stepped((value - from_min) / (from_max - from_min), steps),
            SmoothStep => {
                if from_min > from_max {
                    1.0 - smoothstep(from_max, from_min, value)
                } else {
                    smoothstep(from_min, from_max, value)
                }
            }
            SmootherStep => {
                if from_min > from_max {
                    1.0 - smootherstep(from_max, from_min, value)
                } else {
                    smootherstep(from_min, from_max, value)
                }
            }
        };
        to_min + factor * (to_max - to_min)
    } else {
        0.0
    };
    if clamp {
        clamp_node(ClampType::Range, result, to_min, to_max)
    } else {
        result
    }
}

/// Map Range, vector data type (each component independently).
#[allow(clippy::too_many_arguments)]
pub fn map_range_vector(
    interpolation: MapRangeInterpolation,
    clamp: bool,
    value: V3,
    from_min: V3,
    from_max: V3,
    to_min: V3,
    to_max: V3,
    steps: V3,
) -> V3 {
    use MapRangeInterpolation::*;
    // Cycles applies "Clamp" only to the linear and stepped modes here.
    let use_clamp = clamp && matches!(interpolation, Linear | Stepped);
    let mut out = [0.0; 3];
    for i in 0..3 {
        let f = safe_divide(value[i] - from_min[i], from_max[i] - from_min[i]);
        let factor = match interpolation {
            Linear => f,
            Stepped => stepped(f, steps[i]),
            SmoothStep => {
                let f = clamp_c(f, 0.0, 1.0);
                (3.0 - 2.0 * f) * (f * f)
            }
            SmootherStep => {
                let f = clamp_c(f, 0.0, 1.0);
                f * f * f * (f * (f * 6.0 - 15.0) + 10.0)
            }
        };
        let r = to_min[i] + factor * (to_max[i] - to_min[i]);
        out[i] = if use_clamp {
            if to_min[i] > to_max[i] {
                clamp_c(r, to_max[i], to_min[i])
            } else {
                clamp_c(r, to_min[i], to_max[i])
            }
        } else {
            r
        };
    }
    out
}
