//! Separate/Combine XYZ and Separate/Combine Color (RGB, HSV, HSL), including the legacy
//! Separate/Combine RGB and HSV nodes, with Cycles semantics (`kernel/svm/sepcomb_*.h`).

use super::color::{hsl_to_rgb, hsv_to_rgb, rgb_to_hsl, rgb_to_hsv};
use super::math::V3;

blender_enum! {
    /// `mode` of Separate Color / Combine Color.
    pub enum ColorMode {
        Rgb = "RGB",
        Hsv = "HSV",
        Hsl = "HSL",
    }
}

/// Separate XYZ: the three components.
#[inline]
pub fn separate_xyz(v: V3) -> (f32, f32, f32) {
    (v[0], v[1], v[2])
}

/// Combine XYZ.
#[inline]
pub fn combine_xyz(x: f32, y: f32, z: f32) -> V3 {
    [x, y, z]
}

/// Separate Color: the colour's components in `mode` (H, S, V/L in [0, 1] for HSV/HSL).
/// Legacy Separate RGB is `Rgb`, Separate HSV is `Hsv`.
pub fn separate_color(mode: ColorMode, color: V3) -> V3 {
    match mode {
        ColorMode::Rgb => color,
        ColorMode::Hsv => rgb_to_hsv(color),
        ColorMode::Hsl => rgb_to_hsl(color),
    }
}

/// Combine Color: an RGB colour from components in `mode`. Legacy Combine RGB is `Rgb`,
/// Combine HSV is `Hsv`.
pub fn combine_color(mode: ColorMode, c: V3) -> V3 {
    match mode {
        ColorMode::Rgb => c,
        ColorMode::Hsv => hsv_to_rgb(c),
        ColorMode::Hsl => hsl_to_rgb(c),
    }
}
