//! Shader AOV passes as Cycles writes them (kernel/svm/aov.h, film/aov_passes.h): one pass
//! per valid AOV of the view layer, a Value AOV one channel, a Color AOV four (its colour
//! and 1, so its alpha is the share of samples that wrote it). A sample writes where its
//! path is still "primary" (Cycles' PATH_RAY_TRANSPARENT_BACKGROUND: the camera ray and
//! transparent bounces after it) until a surface opaque enough for the data passes
//! (alpha at least the view layer's Alpha Threshold, or no transparency) sets
//! PATH_RAY_SINGLE_PASS_DONE; behind a more transparent surface the next one adds its
//! value to the same sample. The pass is the sum over the pixel's samples divided by its
//! sample count, never denoised.

use crate::scene::format::ViewLayer;

/// One AOV pass: Blender's name for it, whether it is a colour, and where its channels
/// start in a sample's AOV values.
#[derive(Debug, Clone, PartialEq)]
pub struct AovPass {
    pub name: String,
    pub color: bool,
    pub offset: usize,
}

impl AovPass {
    pub fn channels(&self) -> usize {
        if self.color {
            4
        } else {
            1
        }
    }
}

/// Where every view-layer AOV lives in a sample's values (`stride` floats).
#[derive(Debug, Clone, Default)]
pub struct Layout {
    /// The passes written, in the view layer's order.
    pub passes: Vec<AovPass>,
    /// Per exported AOV (index as `AovWrite::aov`): its pass, None when invalid.
    of_aov: Vec<Option<usize>>,
    pub stride: usize,
    /// Cycles' pass_alpha_threshold.
    pub alpha_threshold: f32,
}

impl Layout {
    pub fn of(layer: &ViewLayer) -> Layout {
        let mut l = Layout {
            alpha_threshold: layer.pass_alpha_threshold as f32,
            ..Layout::default()
        };
        for a in &layer.aovs {
            if !a.is_valid {
                l.of_aov.push(None);
                continue;
            }
            let p = AovPass {
                name: a.name.clone(),
                color: a.kind == "COLOR",
                offset: l.stride,
            };
            l.stride += p.channels();
            l.of_aov.push(Some(l.passes.len()));
            l.passes.push(p);
        }
        l
    }

    /// The pass AOV `aov` (an `AovWrite::aov`) writes, if any.
    pub fn pass(&self, aov: u32) -> Option<&AovPass> {
        let i = (*self.of_aov.get(aov as usize)?)?;
        self.passes.get(i)
    }

    /// Whether a surface of transparency `transparent` (its transparent closures' weight)
    /// ends the AOV writes of its sample, as it sets Cycles' PATH_RAY_SINGLE_PASS_DONE.
    pub fn ends_primary(&self, transparent: [f32; 3]) -> bool {
        let t = transparent.map(|x| (1.0 - x).clamp(0.0, 1.0));
        transparent == [0.0; 3]
            || self.alpha_threshold == 0.0
            || (t[0] + t[1] + t[2]) / 3.0 >= self.alpha_threshold
    }
}

/// One AOV pass of a render: `channels` floats per pixel (1 for a Value AOV, RGBA for a
/// Color AOV), top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct AovImage {
    pub name: String,
    pub color: bool,
    pub data: Vec<f32>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::format::Aov;

    #[test]
    fn invalid_aovs_get_no_pass_and_colours_take_four_channels() {
        let aov = |name: &str, kind: &str, is_valid| Aov {
            name: name.into(),
            kind: kind.into(),
            is_valid,
        };
        let layer = ViewLayer {
            name: "ViewLayer".into(),
            pass_alpha_threshold: 0.5,
            aovs: vec![
                aov("c", "COLOR", true),
                aov("bad", "VALUE", false),
                aov("v", "VALUE", true),
            ],
        };
        let l = Layout::of(&layer);
        assert_eq!(l.stride, 5);
        assert_eq!(l.pass(0).map(|p| p.offset), Some(0));
        assert!(l.pass(1).is_none());
        assert_eq!(l.pass(2).map(|p| (p.offset, p.color)), Some((4, false)));
        assert!(l.pass(3).is_none());
        // Opaque ends; alpha 0.3 (transparency 0.7) lets the next surface write too.
        assert!(l.ends_primary([0.0; 3]));
        assert!(!l.ends_primary([0.7; 3]));
        assert!(l.ends_primary([0.5; 3]));
    }
}
