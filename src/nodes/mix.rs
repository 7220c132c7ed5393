//! Mix (`ShaderNodeMix`: float, vector, colour) and the legacy MixRGB node, with Cycles
//! semantics (`kernel/svm/mix.h`, `kernel/svm/color_util.h`).

use super::color::{hsv_to_rgb, rgb_to_hsv};
use super::math::{interp3, max_c, min_c, saturate, saturate3, V3};

blender_enum! {
    /// `blend_type` of the Mix (colour) and MixRGB nodes.
    pub enum MixBlend {
        Mix = "MIX",
        Darken = "DARKEN",
        Multiply = "MULTIPLY",
        Burn = "BURN",
        Lighten = "LIGHTEN",
        Screen = "SCREEN",
        Dodge = "DODGE",
        Add = "ADD",
        Overlay = "OVERLAY",
        SoftLight = "SOFT_LIGHT",
        LinearLight = "LINEAR_LIGHT",
        Difference = "DIFFERENCE",
        Exclusion = "EXCLUSION",
        Subtract = "SUBTRACT",
        Divide = "DIVIDE",
        Hue = "HUE",
        Saturation = "SATURATION",
        Color = "COLOR",
        Value = "VALUE",
    }
}

blender_enum! {
    /// `ShaderNodeMix.data_type` (Rotation exists only in Geometry Nodes).
    pub enum MixDataType {
        Float = "FLOAT",
        Vector = "VECTOR",
        Rgba = "RGBA",
        Rotation = "ROTATION",
    }
}

blender_enum! {
    /// `ShaderNodeMix.factor_mode` (vector data type).
    pub enum MixFactorMode {
        Uniform = "UNIFORM",
        NonUniform = "NON_UNIFORM",
    }
}

fn per_channel(c1: V3, c2: V3, f: impl Fn(f32, f32) -> f32) -> V3 {
    [f(c1[0], c2[0]), f(c1[1], c2[1]), f(c1[2], c2[2])]
}

/// Blends `c2` over `c1` with factor `t` (not clamped here). Cycles `svm_mix`.
pub fn blend(mode: MixBlend, t: f32, c1: V3, c2: V3) -> V3 {
    use MixBlend::*;
    let tm = 1.0 - t;
    match mode {
        Mix => interp3(c1, c2, t),
        Add => interp3(c1, per_channel(c1, c2, |a, b| a + b), t),
        Multiply => interp3(c1, per_channel(c1, c2, |a, b| a * b), t),
        Subtract => interp3(c1, per_channel(c1, c2, |a, b| a - b), t),
        Screen => per_channel(c1, c2, |a, b| 1.0 - (tm + t * (1.0 - b)) * (1.0 - a)),
        Overlay => per_channel(c1, c2, |a, b| {
            if a < 0.5 {
                a * (tm + 2.0 * t * b)
            } else {
                1.0 - (tm + 2.0 * t * (1.0 - b)) * (1.0 - a)
            }
        }),
        Divide => per_channel(c1, c2, |a, b| if b != 0.0 { tm * a + t * a / b } else { a }),
        Difference => interp3(c1, per_channel(c1, c2, |a, b| (a - b).abs()), t),
        Exclusion => {
            let e = per_channel(c1, c2, |a, b| a + b - 2.0 * a * b);
            interp3(c1, e, t).map(|x| max_c(x, 0.0))
        }
        Darken => interp3(c1, per_channel(c1, c2, min_c), t),
        Lighten => interp3(c1, per_channel(c1, c2, max_c), t),
        // Dodge and Burn branch on `1 - t * b` / `tm + t * b`; Cycles' kernels evaluate
        // these as one fused multiply-add (seen in the references: t = 1.25, b = 0.2 gives
        // a tiny positive, not 0), so they are fused here too.
        Dodge => per_channel(c1, c2, |a, b| {
            if a == 0.0 {
                return a;
            }
            let tmp = (-t).mul_add(b, 1.0);
            if tmp <= 0.0 {
                1.0
            } else {
                let q = a / tmp;
                if q > 1.0 {
                    1.0
                } else {
                    q
                }
            }
        }),
        Burn => per_channel(c1, c2, |a, b| {
            let tmp = t.mul_add(b, tm);
            if tmp <= 0.0 {
                return 0.0;
            }
            // Cycles' `< 0 ? 0 : > 1 ? 1 : q`; f32::clamp also passes NaN through.
            (1.0 - (1.0 - a) / tmp).clamp(0.0, 1.0)
        }),
        Hue => {
            let hsv2 = rgb_to_hsv(c2);
            if hsv2[1] != 0.0 {
                let mut hsv = rgb_to_hsv(c1);
                hsv[0] = hsv2[0];
                interp3(c1, hsv_to_rgb(hsv), t)
            } else {
                c1
            }
        }
        Saturation => {
            let mut hsv = rgb_to_hsv(c1);
            if hsv[1] != 0.0 {
                let hsv2 = rgb_to_hsv(c2);
                hsv[1] = tm * hsv[1] + t * hsv2[1];
                hsv_to_rgb(hsv)
            } else {
                c1
            }
        }
        Value => {
            let mut hsv = rgb_to_hsv(c1);
            let hsv2 = rgb_to_hsv(c2);
            hsv[2] = tm * hsv[2] + t * hsv2[2];
            hsv_to_rgb(hsv)
        }
        Color => {
            let hsv2 = rgb_to_hsv(c2);
            if hsv2[1] != 0.0 {
                let mut hsv = rgb_to_hsv(c1);
                hsv[0] = hsv2[0];
                hsv[1] = hsv2[1];
                interp3(c1, hsv_to_rgb(hsv), t)
            } else {
                c1
            }
        }
        SoftLight => per_channel(c1, c2, |a, b| {
            let scr = 1.0 - (1.0 - b) * (1.0 - a);
            tm * a + t * ((1.0 - a) * b * a + a * scr)
        }),
        LinearLight => per_channel(c1, c2, |a, b| a + t * (2.0 * b + -1.0)),
    }
}

/// Mix node, colour data type.
pub fn mix_color(
    mode: MixBlend,
    clamp_factor: bool,
    clamp_result: bool,
    factor: f32,
    a: V3,
    b: V3,
) -> V3 {
    let t = if clamp_factor {
        saturate(factor)
    } else {
        factor
    };
    let r = blend(mode, t, a, b);
    if clamp_result {
        saturate3(r)
    } else {
        r
    }
}

/// Mix node, float data type: `a * (1 - t) + b * t`.
pub fn mix_float(clamp_factor: bool, factor: f32, a: f32, b: f32) -> f32 {
    let t = if clamp_factor {
        saturate(factor)
    } else {
        factor
    };
    a * (1.0 - t) + b * t
}

/// Mix node, vector data type with a uniform (float) factor.
pub fn mix_vector(clamp_factor: bool, factor: f32, a: V3, b: V3) -> V3 {
    let t = if clamp_factor {
        saturate(factor)
    } else {
        factor
    };
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

/// Mix node, vector data type with a per-component factor.
pub fn mix_vector_non_uniform(clamp_factor: bool, factor: V3, a: V3, b: V3) -> V3 {
    let t = if clamp_factor {
        saturate3(factor)
    } else {
        factor
    };
    [
        a[0] * (1.0 - t[0]) + b[0] * t[0],
        a[1] * (1.0 - t[1]) + b[1] * t[1],
        a[2] * (1.0 - t[2]) + b[2] * t[2],
    ]
}

/// Legacy MixRGB node: the factor is always clamped to [0, 1]; "Clamp" clamps the result.
/// Its `use_alpha` option is never read by Cycles (colours carry no alpha there).
pub fn mix_rgb(mode: MixBlend, use_clamp: bool, fac: f32, color1: V3, color2: V3) -> V3 {
    mix_color(mode, true, use_clamp, fac, color1, color2)
}
