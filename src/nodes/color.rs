//! Colour conversions and the colour-adjustment nodes: Invert, Gamma, Bright/Contrast,
//! Hue/Saturation/Value, RGB to BW.
//!
//! Two families of RGB <-> HSV/HSL conversions exist and give different numbers:
//! Cycles' kernel ones (`util/color.h`, used by shader nodes at render time) are the
//! top-level functions here; Blender's own (`BLI_math_color`, used by Geometry Nodes and
//! by the Color Ramp's HSV/HSL blending, which Blender evaluates before Cycles sees it)
//! are in [`bli`].

use super::math::{clamp_c, dot3, fract, max_c, min_c, saturate, V3};

/// Constants Cycles derives from the OpenColorIO config for the scene-linear space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneLinear {
    /// Luminance weights (RGB to BW, colour-to-float conversion).
    pub rgb_to_y: V3,
    /// CIE XYZ (D65) to scene-linear RGB, by rows (Wavelength).
    pub xyz_to_rgb: [V3; 3],
}

/// Blender's default config (scene linear = Linear Rec.709), as Blender 4.5 computes the
/// matrices from its OCIO config (recorded by the conformance generator through
/// `mathutils.Color.from_scene_linear_to_xyz_d65` / `from_xyz_d65_to_scene_linear`).
/// They differ from the textbook Rec.709 values in the 5th-6th digit.
pub const LINEAR_REC709: SceneLinear = SceneLinear {
    rgb_to_y: [0.212_674_05, 0.715_151_55, 0.072_175_41],
    xyz_to_rgb: [
        [3.240_437_7, -1.537_132, -0.498_529_5],
        [-0.969_267_5, 1.876_013_4, 0.041_555_703],
        [0.055_643_23, -0.204_025_49, 1.057_225_2],
    ],
};

/// Multiplies a row-major 3x3 matrix by a vector (each row a dot product, as Cycles).
#[inline]
pub fn mat3_mul(m: &[V3; 3], v: V3) -> V3 {
    [dot3(m[0], v), dot3(m[1], v), dot3(m[2], v)]
}

// --- Cycles kernel conversions ----------------------------------------------------------

/// Cycles `rgb_to_hsv`.
pub fn rgb_to_hsv(rgb: V3) -> V3 {
    let [r, g, b] = rgb;
    let cmax = r.max(g.max(b));
    let cmin = min_c(r, min_c(g, b));
    let cdelta = cmax - cmin;
    let v = cmax;
    let s = if cmax != 0.0 { cdelta / cmax } else { 0.0 };
    let mut h = 0.0;
    if s != 0.0 {
        let c = [
            (cmax - r) / cdelta,
            (cmax - g) / cdelta,
            (cmax - b) / cdelta,
        ];
        h = if r == cmax {
            c[2] - c[1]
        } else if g == cmax {
            2.0 + c[0] - c[2]
        } else {
            4.0 + c[1] - c[0]
        };
        h /= 6.0;
        if h < 0.0 {
            h += 1.0;
        }
    }
    [h, s, v]
}

/// Cycles `hsv_to_rgb`.
pub fn hsv_to_rgb(hsv: V3) -> V3 {
    let [mut h, s, v] = hsv;
    if s == 0.0 {
        return [v, v, v];
    }
    if h == 1.0 {
        h = 0.0;
    }
    h *= 6.0;
    let i = h.floor();
    let f = h - i;
    let p = v * (1.0 - s);
    let q = v * (1.0 - (s * f));
    let t = v * (1.0 - (s * (1.0 - f)));
    if i == 0.0 {
        [v, t, p]
    } else if i == 1.0 {
        [q, v, p]
    } else if i == 2.0 {
        [p, v, t]
    } else if i == 3.0 {
        [p, q, v]
    } else if i == 4.0 {
        [t, p, v]
    } else {
        [v, p, q]
    }
}

/// Cycles `rgb_to_hsl` (same arithmetic as Blender's).
pub fn rgb_to_hsl(rgb: V3) -> V3 {
    let [r, g, b] = rgb;
    let cmax = r.max(g.max(b));
    let cmin = min_c(r, min_c(g, b));
    let l = min_c(1.0, (cmax + cmin) / 2.0);
    let (mut h, s);
    if cmax == cmin {
        h = 0.0;
        s = 0.0;
    } else {
        let d = cmax - cmin;
        s = if l > 0.5 {
            d / (2.0 - cmax - cmin)
        } else {
            d / (cmax + cmin)
        };
        h = if cmax == r {
            (g - b) / d + if g < b { 6.0 } else { 0.0 }
        } else if cmax == g {
            (b - r) / d + 2.0
        } else {
            (r - g) / d + 4.0
        };
    }
    h /= 6.0;
    [h, s, l]
}

/// Cycles `hsl_to_rgb` (same arithmetic as Blender's).
pub fn hsl_to_rgb(hsl: V3) -> V3 {
    let [h, s, l] = hsl;
    let nr = clamp_c((h * 6.0 - 3.0).abs() - 1.0, 0.0, 1.0);
    let ng = clamp_c(2.0 - (h * 6.0 - 2.0).abs(), 0.0, 1.0);
    let nb = clamp_c(2.0 - (h * 6.0 - 4.0).abs(), 0.0, 1.0);
    let chroma = (1.0 - (2.0 * l - 1.0).abs()) * s;
    [
        (nr - 0.5) * chroma + l,
        (ng - 0.5) * chroma + l,
        (nb - 0.5) * chroma + l,
    ]
}

/// Blender's own conversions (`BLI_math_color`), used where Blender, not Cycles, does
/// the arithmetic (Color Ramp HSV/HSL blending, Geometry Nodes).
pub mod bli {
    use super::super::math::{clamp_c, min_c, V3};

    /// `rgb_to_hsv`: branch-free variant with 1e-20 guards (hue in [0, 1]).
    pub fn rgb_to_hsv(rgb: V3) -> V3 {
        let [mut r, mut g, mut b] = rgb;
        let mut k = 0.0f32;
        if g < b {
            std::mem::swap(&mut g, &mut b);
            k = -1.0;
        }
        let mut min_gb = b;
        if r < g {
            std::mem::swap(&mut r, &mut g);
            k = -2.0 / 6.0 - k;
            min_gb = min_c(g, b);
        }
        let chroma = r - min_gb;
        let h = (k + (g - b) / (6.0 * chroma + 1e-20)).abs();
        let s = chroma / (r + 1e-20);
        [h, s, r]
    }

    /// `hsv_to_rgb`: piecewise-linear hue ramps.
    pub fn hsv_to_rgb(hsv: V3) -> V3 {
        let [h, s, v] = hsv;
        let nr = clamp_c((h * 6.0 - 3.0).abs() - 1.0, 0.0, 1.0);
        let ng = clamp_c(2.0 - (h * 6.0 - 2.0).abs(), 0.0, 1.0);
        let nb = clamp_c(2.0 - (h * 6.0 - 4.0).abs(), 0.0, 1.0);
        [
            ((nr - 1.0) * s + 1.0) * v,
            ((ng - 1.0) * s + 1.0) * v,
            ((nb - 1.0) * s + 1.0) * v,
        ]
    }

    pub fn rgb_to_hsl(rgb: V3) -> V3 {
        super::rgb_to_hsl(rgb)
    }

    pub fn hsl_to_rgb(hsl: V3) -> V3 {
        super::hsl_to_rgb(hsl)
    }
}

// --- Nodes ------------------------------------------------------------------------------

/// Invert Color: `fac * (1 - c) + (1 - fac) * c` per channel.
pub fn invert(fac: f32, color: V3) -> V3 {
    let f = |c: f32| fac * (1.0 - c) + (1.0 - fac) * c;
    [f(color[0]), f(color[1]), f(color[2])]
}

/// Gamma: `c^gamma` for positive channels (others unchanged); gamma 0 gives white.
pub fn gamma(color: V3, gamma: f32) -> V3 {
    if gamma == 0.0 {
        return [1.0; 3];
    }
    let f = |c: f32| if c > 0.0 { c.powf(gamma) } else { c };
    [f(color[0]), f(color[1]), f(color[2])]
}

/// Brightness/Contrast: `max((1 + contrast) * c + bright - contrast / 2, 0)`.
pub fn bright_contrast(color: V3, bright: f32, contrast: f32) -> V3 {
    let a = 1.0 + contrast;
    let b = bright - contrast * 0.5;
    let f = |c: f32| max_c(a * c + b, 0.0);
    [f(color[0]), f(color[1]), f(color[2])]
}

/// Hue/Saturation/Value: shifts hue (0.5 = no change), scales saturation (clamped to
/// [0, 1]) and value, blends with the input by `fac`, and clamps negatives to 0.
pub fn hue_saturation(hue: f32, saturation: f32, value: f32, fac: f32, color: V3) -> V3 {
    let mut hsv = rgb_to_hsv(color);
    hsv[0] = fract(hsv[0] + hue + 0.5);
    hsv[1] = saturate(hsv[1] * saturation);
    hsv[2] *= value;
    let rgb = hsv_to_rgb(hsv);
    let f = |i: usize| max_c(fac * rgb[i] + (1.0 - fac) * color[i], 0.0);
    [f(0), f(1), f(2)]
}

/// RGB to BW: luminance with the scene-linear space's weights.
pub fn rgb_to_bw(color: V3, space: &SceneLinear) -> f32 {
    dot3(color, space.rgb_to_y)
}
