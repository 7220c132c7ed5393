//! Color Ramp (`ShaderNodeValToRGB`), and the lookup tables Cycles uses for ramps and
//! curves.
//!
//! Two stages, as in Blender + Cycles:
//! 1. [`ColorBand::evaluate`] is Blender's `BKE_colorband_evaluate` (interpolation
//!    between stops, HSV/HSL blending). Geometry Nodes evaluate the ramp this way.
//! 2. Cycles never sees the stops: Blender samples the band into a table of
//!    [`RAMP_TABLE_SIZE`] + 1 entries ([`RampTable`]), and the shader linearly
//!    interpolates the table ([`ramp_lookup`]). RGB/Float Curves use the same lookup.

use super::color::bli;
use super::math::saturate;

/// Blender's `MAXCOLORBAND`: a ramp holds at most 32 stops.
pub const MAX_STOPS: usize = 32;

/// Cycles' `RAMP_TABLE_SIZE`; the table holds one more entry (both ends included).
pub const RAMP_TABLE_SIZE: usize = 256;

blender_enum! {
    /// `ColorRamp.interpolation`.
    pub enum RampInterpolation {
        Ease = "EASE",
        Cardinal = "CARDINAL",
        Linear = "LINEAR",
        BSpline = "B_SPLINE",
        Constant = "CONSTANT",
    }
}

blender_enum! {
    /// `ColorRamp.color_mode`.
    pub enum RampColorMode {
        Rgb = "RGB",
        Hsv = "HSV",
        Hsl = "HSL",
    }
}

blender_enum! {
    /// `ColorRamp.hue_interpolation` (HSV/HSL modes).
    pub enum HueInterpolation {
        Near = "NEAR",
        Far = "FAR",
        Cw = "CW",
        Ccw = "CCW",
    }
}

/// One stop: position and straight RGBA.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampStop {
    pub position: f32,
    pub color: [f32; 4],
}

/// A colour band (Blender `ColorBand`): up to [`MAX_STOPS`] stops, in the order Blender
/// stores them (sorted by position; equal positions keep Blender's order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColorBand {
    stops: [RampStop; MAX_STOPS],
    len: usize,
    pub interpolation: RampInterpolation,
    pub color_mode: RampColorMode,
    pub hue_interpolation: HueInterpolation,
}

impl ColorBand {
    /// A band from its stops (1 to 32, in Blender's order). `None` if empty or too many.
    pub fn new(
        stops: &[RampStop],
        interpolation: RampInterpolation,
        color_mode: RampColorMode,
        hue_interpolation: HueInterpolation,
    ) -> Option<Self> {
        if stops.is_empty() || stops.len() > MAX_STOPS {
            return None;
        }
        let mut arr = [RampStop {
            position: 0.0,
            color: [0.0; 4],
        }; MAX_STOPS];
        arr[..stops.len()].copy_from_slice(stops);
        Some(ColorBand {
            stops: arr,
            len: stops.len(),
            interpolation,
            color_mode,
            hue_interpolation,
        })
    }

    pub fn stops(&self) -> &[RampStop] {
        &self.stops[..self.len]
    }

    /// Blender's `BKE_colorband_evaluate` at `pos`: straight RGBA.
    pub fn evaluate(&self, pos: f32) -> [f32; 4] {
        use RampInterpolation::*;
        let data = self.stops();
        let tot = data.len();
        // Outside RGB mode the band always blends linearly.
        let ipo = if self.color_mode == RampColorMode::Rgb {
            self.interpolation
        } else {
            Linear
        };
        let holds_ends = matches!(ipo, Linear | Ease | Constant);
        if tot == 1 || (pos <= data[0].position && holds_ends) {
            return data[0].color;
        }
        // `a`: first stop strictly right of `pos` (tot if none). `right`/`left` are the
        // stops around `pos`; past either end the end stop is repeated at position 1 / 0.
        let a = data.iter().position(|s| s.position > pos).unwrap_or(tot);
        let (right, left) = if a == tot {
            (
                RampStop {
                    position: 1.0,
                    ..data[tot - 1]
                },
                data[tot - 1],
            )
        } else if a == 0 {
            (
                data[0],
                RampStop {
                    position: 0.0,
                    ..data[0]
                },
            )
        } else {
            (data[a], data[a - 1])
        };
        if (a == tot && holds_ends) || ipo == Constant {
            return left.color;
        }
        let mut fac = if left.position != right.position {
            (pos - right.position) / (left.position - right.position)
        } else if a != tot {
            0.0
        } else {
            1.0
        };
        if matches!(ipo, BSpline | Cardinal) {
            // Four stops, right to left: next, right, left, previous.
            let next = if a + 1 >= tot { right } else { data[a + 1] };
            let prev = if a < 2 { left } else { data[a - 2] };
            fac = fac.clamp(0.0, 1.0);
            let w = curve_weights(fac, ipo == Cardinal);
            // BLI's CLAMP macro (NaN passes, like f32::clamp).
            return std::array::from_fn(|i| {
                let v = w[3] * prev.color[i]
                    + w[2] * left.color[i]
                    + w[1] * right.color[i]
                    + w[0] * next.color[i];
                v.clamp(0.0, 1.0)
            });
        }
        if ipo == Ease {
            let fac2 = fac * fac;
            fac = 3.0 * fac2 - 2.0 * fac2 * fac;
        }
        let mfac = 1.0 - fac;
        let alpha = mfac * right.color[3] + fac * left.color[3];
        let rgb3 = |c: [f32; 4]| [c[0], c[1], c[2]];
        match self.color_mode {
            RampColorMode::Rgb => {
                std::array::from_fn(|i| mfac * right.color[i] + fac * left.color[i])
            }
            RampColorMode::Hsv | RampColorMode::Hsl => {
                let hsv = self.color_mode == RampColorMode::Hsv;
                let to = if hsv {
                    bli::rgb_to_hsv
                } else {
                    bli::rgb_to_hsl
                };
                let c1 = to(rgb3(right.color));
                let c2 = to(rgb3(left.color));
                let mixed = [
                    hue_interp(self.hue_interpolation, mfac, fac, c1[0], c2[0]),
                    mfac * c1[1] + fac * c2[1],
                    mfac * c1[2] + fac * c2[2],
                ];
                let rgb = if hsv {
                    bli::hsv_to_rgb(mixed)
                } else {
                    bli::hsl_to_rgb(mixed)
                };
                [rgb[0], rgb[1], rgb[2], alpha]
            }
        }
    }
}

/// Blender's `key_curve_position_weights` for the cardinal (tension 0.71) and B-spline
/// bases (constants written as in Blender).
#[allow(clippy::excessive_precision)]
fn curve_weights(t: f32, cardinal: bool) -> [f32; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    if cardinal {
        let fc = 0.71f32;
        [
            -fc * t3 + 2.0 * fc * t2 - fc * t,
            (2.0 - fc) * t3 + (fc - 3.0) * t2 + 1.0,
            (fc - 2.0) * t3 + (3.0 - 2.0 * fc) * t2 + fc * t,
            fc * t3 - fc * t2,
        ]
    } else {
        [
            -0.16666666 * t3 + 0.5 * t2 - 0.5 * t + 0.16666666,
            0.5 * t3 - t2 + 0.66666666,
            -0.5 * t3 + 0.5 * t2 + 0.5 * t + 0.16666666,
            0.16666666 * t3,
        ]
    }
}

/// Blender's `colorband_hue_interp`: hue blend going the chosen way round the circle.
fn hue_interp(mode: HueInterpolation, mfac: f32, fac: f32, h1: f32, h2: f32) -> f32 {
    let hue_mod = |h: f32| if h < 1.0 { h } else { h - 1.0 };
    let h1 = hue_mod(h1);
    let h2 = hue_mod(h2);
    // 0: direct, 1: h1 + 1, 2: h2 + 1.
    let way = match mode {
        HueInterpolation::Near => {
            if h1 < h2 && (h2 - h1) > 0.5 {
                1
            } else if h1 > h2 && (h2 - h1) < -0.5 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Far => {
            if h1 == h2 || (h1 < h2 && (h2 - h1) < 0.5) {
                1
            } else if h1 > h2 && (h2 - h1) > -0.5 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Ccw => {
            if h1 > h2 {
                2
            } else {
                0
            }
        }
        HueInterpolation::Cw => {
            if h1 < h2 {
                1
            } else {
                0
            }
        }
    };
    match way {
        1 => hue_mod(mfac * (h1 + 1.0) + fac * h2),
        2 => hue_mod(mfac * h1 + fac * (h2 + 1.0)),
        _ => mfac * h1 + fac * h2,
    }
}

/// Reads a `ColorRamp` as the exporter writes it (`elements[].position/color`,
/// `interpolation`, `color_mode`, `hue_interpolation`); the error says what is wrong.
pub fn band_from_json(r: &serde_json::Value) -> Result<ColorBand, String> {
    use serde_json::Value;
    let elements = r
        .get("elements")
        .and_then(Value::as_array)
        .ok_or("color_ramp has no elements")?;
    let mut stops = Vec::with_capacity(elements.len());
    for e in elements {
        let position = e
            .get("position")
            .and_then(Value::as_f64)
            .ok_or("color_ramp element without position")? as f32;
        let c = e
            .get("color")
            .and_then(Value::as_array)
            .ok_or("color_ramp element without color")?;
        let mut color = [0.0, 0.0, 0.0, 1.0];
        for (o, x) in color.iter_mut().zip(c) {
            *o = x
                .as_f64()
                .ok_or("color_ramp element color is not numbers")? as f32;
        }
        stops.push(RampStop { position, color });
    }
    let s = |k: &str| r.get(k).and_then(Value::as_str).unwrap_or("");
    let interp = RampInterpolation::from_blender(s("interpolation")).ok_or_else(|| {
        format!(
            "color_ramp interpolation {:?} is not supported",
            s("interpolation")
        )
    })?;
    let cm = RampColorMode::from_blender(s("color_mode")).ok_or_else(|| {
        format!(
            "color_ramp color mode {:?} is not supported",
            s("color_mode")
        )
    })?;
    let hue = HueInterpolation::from_blender(s("hue_interpolation")).ok_or_else(|| {
        format!(
            "color_ramp hue interpolation {:?} is not supported",
            s("hue_interpolation")
        )
    })?;
    ColorBand::new(&stops, interp, cm, hue)
        .ok_or_else(|| "color_ramp needs 1 to 32 elements".to_string())
}

/// The band sampled at `i / RAMP_TABLE_SIZE` for i in 0..=RAMP_TABLE_SIZE, as Blender
/// hands it to Cycles.
#[derive(Debug, Clone, PartialEq)]
pub struct RampTable {
    pub entries: [[f32; 4]; RAMP_TABLE_SIZE + 1],
    /// False for constant interpolation: the lookup then takes the entry at or below.
    pub interpolate: bool,
}

impl RampTable {
    pub fn from_band(band: &ColorBand) -> Self {
        let mut entries = [[0.0; 4]; RAMP_TABLE_SIZE + 1];
        for (i, e) in entries.iter_mut().enumerate() {
            *e = band.evaluate(i as f32 / RAMP_TABLE_SIZE as f32);
        }
        RampTable {
            entries,
            interpolate: band.interpolation != RampInterpolation::Constant,
        }
    }

    /// The Color Ramp node in Cycles: (colour RGB, alpha) at `fac`.
    pub fn color_ramp(&self, fac: f32) -> ([f32; 3], f32) {
        let c = ramp_lookup(&self.entries, fac, self.interpolate, false);
        ([c[0], c[1], c[2]], c[3])
    }
}

/// Cycles `rgb_ramp_lookup` over a table spanning [0, 1]: linear interpolation between
/// neighbouring entries (or the entry at or below, without `interpolate`); outside
/// [0, 1] either clamps or, with `extrapolate` (curves), continues the end slope.
pub fn ramp_lookup(table: &[[f32; 4]], f: f32, interpolate: bool, extrapolate: bool) -> [f32; 4] {
    let n = table.len();
    let last = (n - 1) as f32;
    let lerp4 = |a: [f32; 4], b: [f32; 4], t: f32| {
        [
            (1.0 - t) * a[0] + t * b[0],
            (1.0 - t) * a[1] + t * b[1],
            (1.0 - t) * a[2] + t * b[2],
            (1.0 - t) * a[3] + t * b[3],
        ]
    };
    // Not `!(0.0..=1.0).contains(&f)`: NaN must not extrapolate.
    #[allow(clippy::manual_range_contains)]
    if (f < 0.0 || f > 1.0) && extrapolate && n >= 2 {
        let (t0, t1, d) = if f < 0.0 {
            (table[0], table[1], -f)
        } else {
            (table[n - 1], table[n - 2], f - 1.0)
        };
        let mut out = [0.0; 4];
        for i in 0..4 {
            out[i] = t0[i] + (t0[i] - t1[i]) * d * last;
        }
        return out;
    }
    let f = saturate(f) * last;
    // Truncating conversion; NaN converts to 0 in Rust (Cycles clamps the index too).
    let i = (f as i32).clamp(0, n as i32 - 1) as usize;
    let t = f - i as f32;
    let a = table[i];
    if interpolate && t > 0.0 {
        lerp4(a, table[i + 1], t)
    } else {
        a
    }
}
