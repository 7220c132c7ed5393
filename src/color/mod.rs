//! Film colour management as Blender 4.5 applies it to the final image: exposure, look,
//! view transform and display (read from the OpenColorIO config and LUT files that the
//! exporter copies into `DIR/colormanagement/`), then gamma; plus atomic PNG/EXR writers.
//!
//! Blender builds one OCIO processor per view (intern/opencolorio `createDisplayProcessor`):
//! scene linear -> exposure scale -> look (in the look's process space) -> the view's colour
//! space on the display -> `pow(x, 1/gamma)`. `pipeline` re-creates that chain from the
//! config without the OCIO library; alpha is divided out around it, as Blender does for
//! premultiplied float buffers.

pub mod config;
pub mod lut;
mod pipeline;
mod tone;
mod write;

use std::path::{Path, PathBuf};

pub use write::{quantize, user_file_permissions, write_exr, write_png};

use crate::scene::Scene;

#[derive(Debug, thiserror::Error)]
pub enum ColorError {
    #[error("{path}: {message}")]
    Config { path: PathBuf, message: String },
    #[error("{path}: {message}")]
    Lut { path: PathBuf, message: String },
    #[error("colour management: {0}")]
    Settings(String),
    #[error("{path}: {message}")]
    Write { path: PathBuf, message: String },
}

/// The scene's colour-management settings that shape the final image.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSettings {
    pub display_device: String,
    pub view_transform: String,
    /// "None" (or empty) for no look.
    pub look: String,
    pub exposure: f32,
    pub gamma: f32,
}

impl Default for ViewSettings {
    fn default() -> Self {
        ViewSettings {
            display_device: "sRGB".into(),
            view_transform: "Standard".into(),
            look: "None".into(),
            exposure: 0.0,
            gamma: 1.0,
        }
    }
}

impl ViewSettings {
    /// Reads `scene.view_settings` and `scene.display_settings`, or the output format's own
    /// (`render.image_settings.view_settings` / `display_settings`) when its colour
    /// management is "OVERRIDE", as Blender does when saving a render. Settings blendsynth
    /// does not reproduce (RGB curves, white balance) are reported as errors, not ignored.
    pub fn from_scene(scene: &Scene) -> Result<ViewSettings, ColorError> {
        let s = &scene.file.scene;
        let image = s.render.get("image_settings").and_then(|v| v.as_object());
        let overridden = image
            .and_then(|i| i.get("color_management"))
            .and_then(|v| v.as_str())
            == Some("OVERRIDE");
        let pick = |key: &str,
                    scene_value: &'_ serde_json::Map<String, serde_json::Value>|
         -> serde_json::Map<String, serde_json::Value> {
            match image.and_then(|i| i.get(key)).and_then(|v| v.as_object()) {
                Some(m) if overridden => m.clone(),
                _ => scene_value.clone(),
            }
        };
        let (vs, ds) = (
            pick("view_settings", &s.view_settings),
            pick("display_settings", &s.display_settings),
        );
        let prefix = if overridden {
            "scene.render.image_settings.view_settings"
        } else {
            "scene.view_settings"
        };
        let text = |m: &serde_json::Map<String, serde_json::Value>, k: &str, d: &str| {
            m.get(k).and_then(|v| v.as_str()).unwrap_or(d).to_string()
        };
        let num = |k: &str, d: f64| vs.get(k).and_then(|v| v.as_f64()).unwrap_or(d) as f32;
        let flag = |k: &str| vs.get(k).and_then(|v| v.as_bool()).unwrap_or(false);
        if flag("use_curve_mapping") {
            return Err(ColorError::Settings(format!("{prefix}.use_curve_mapping (RGB curves on the view) is not supported; turn it off in Blender")));
        }
        if flag("use_white_balance") {
            return Err(ColorError::Settings(format!(
                "{prefix}.use_white_balance is not supported; turn it off in Blender"
            )));
        }
        Ok(ViewSettings {
            display_device: text(&ds, "display_device", "sRGB"),
            view_transform: text(&vs, "view_transform", "Standard"),
            look: text(&vs, "look", "None"),
            exposure: num("exposure", 0.0),
            gamma: num("gamma", 1.0),
        })
    }

    fn has_look(&self) -> bool {
        !self.look.is_empty() && self.look != "None"
    }
}

/// A ready-to-apply display transform (LUTs loaded once; apply to any number of images).
#[derive(Debug, Clone)]
pub struct DisplayTransform {
    ops: Vec<pipeline::Op>,
}

impl DisplayTransform {
    /// Builds the transform for `settings` from the OCIO config at `config` (the export's
    /// `colormanagement/config.ocio`). Without a config only what needs no LUT is possible:
    /// Standard and Raw on the sRGB display.
    pub fn new(
        settings: &ViewSettings,
        config: Option<&Path>,
    ) -> Result<DisplayTransform, ColorError> {
        let exposure_scale = if settings.exposure == 0.0 {
            1.0
        } else {
            2f32.powf(settings.exposure)
        };
        let mut ops = Vec::new();
        match config {
            Some(path) => {
                let cfg = config::Config::load(path)?;
                let mut b = pipeline::Builder::new(&cfg);
                if exposure_scale != 1.0 {
                    let s = exposure_scale as f64;
                    b.push_matrix([[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]], [0.0; 3]);
                }
                let mut space = "scene_linear".to_string();
                if settings.has_look() {
                    space = b.look(&space, &settings.look)?;
                }
                let view_space = cfg
                    .view_space(&settings.display_device, &settings.view_transform)
                    .ok_or_else(|| {
                        let views: Vec<String> = cfg
                            .displays
                            .iter()
                            .map(|(d, v)| {
                                format!(
                                    "{d}: {}",
                                    v.iter()
                                        .map(|(n, _)| n.as_str())
                                        .collect::<Vec<_>>()
                                        .join(", ")
                                )
                            })
                            .collect();
                        ColorError::Config {
                            path: path.to_path_buf(),
                            message: format!(
                                "no view {:?} on display {:?} (the config has {})",
                                settings.view_transform,
                                settings.display_device,
                                views.join("; ")
                            ),
                        }
                    })?;
                let view_space = view_space.to_string();
                b.convert(&space, &view_space)?;
                ops.extend(b.finish());
            }
            None => {
                if exposure_scale != 1.0 {
                    ops.push(pipeline::Op::Affine {
                        scale: [exposure_scale; 3],
                        offset: [0.0; 3],
                    });
                }
                if settings.display_device != "sRGB"
                    || settings.has_look()
                    || !matches!(settings.view_transform.as_str(), "Standard" | "Raw")
                {
                    return Err(ColorError::Settings(format!(
                        "view {:?} / look {:?} on display {:?} needs Blender's OCIO config and LUTs, which this export lacks (re-export with `blendsynth convert`, which copies them to colormanagement/)",
                        settings.view_transform, settings.look, settings.display_device
                    )));
                }
                if settings.view_transform == "Standard" {
                    // The sRGB colour space of Blender's config: the piecewise sRGB curve.
                    ops.push(pipeline::Op::MonCurve {
                        gamma: [2.4; 3],
                        offset: [0.055; 3],
                        encode: true,
                    });
                }
            }
        }
        if settings.gamma != 1.0 {
            let e = 1.0 / settings.gamma.max(f32::EPSILON);
            ops.push(pipeline::Op::Pow([e; 3]));
        }
        Ok(DisplayTransform { ops })
    }

    /// The scene's transform (its settings, its export's config).
    pub fn from_scene(scene: &Scene) -> Result<DisplayTransform, ColorError> {
        let settings = ViewSettings::from_scene(scene)?;
        let config = match &scene.file.color_management.config {
            Some(rel) => Some(
                scene
                    .resolve(rel, "color_management.config")
                    .map_err(|e| ColorError::Settings(e.to_string()))?,
            ),
            None => None,
        };
        DisplayTransform::new(&settings, config.as_deref())
    }

    /// Linear scene-referred premultiplied RGBA in, display-referred premultiplied RGBA out
    /// (alpha unchanged). Colour is divided by alpha around the transform for partly
    /// transparent pixels, as Blender does; non-finite results become 0.
    pub fn apply(&self, pixels: &mut [[f32; 4]]) {
        for px in pixels.iter_mut() {
            let a = px[3];
            let predivide = a != 1.0 && a != 0.0;
            let mut rgb = [px[0], px[1], px[2]];
            if predivide {
                for v in rgb.iter_mut() {
                    *v /= a;
                }
            }
            for op in &self.ops {
                op.apply(&mut rgb);
            }
            if predivide {
                for v in rgb.iter_mut() {
                    *v *= a;
                }
            }
            for (d, v) in px.iter_mut().zip(rgb) {
                *d = if v.is_finite() { v } else { 0.0 };
            }
        }
    }
}

/// Exposure, view transform (Standard, Filmic, AgX, ... with look), gamma and display
/// encoding as the scene's colour management says, in place. Input linear scene-referred
/// (Linear Rec.709), output display-referred values (0..1 for the usual views).
pub fn to_display(scene: &Scene, pixels: &mut [[f32; 4]]) -> Result<(), ColorError> {
    DisplayTransform::from_scene(scene)?.apply(pixels);
    Ok(())
}

/// How the scene's output format (`render.image_settings`) stores the final image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputFormat {
    /// 16 bits per channel (PNG `color_depth` "16"); else 8.
    pub sixteen_bit: bool,
    /// An alpha channel (`color_mode` "RGBA").
    pub alpha: bool,
}

impl OutputFormat {
    pub fn from_scene(scene: &Scene) -> OutputFormat {
        let ims = scene
            .file
            .scene
            .render
            .get("image_settings")
            .and_then(|v| v.as_object());
        let get = |k: &str| {
            ims.and_then(|m| m.get(k))
                .and_then(|v| v.as_str())
                .unwrap_or("")
        };
        OutputFormat {
            sixteen_bit: get("color_depth") == "16",
            alpha: get("color_mode") == "RGBA",
        }
    }
}

/// Writes a rendered frame as Blender would save it, choosing by `path`'s extension:
/// `.exr` gets the linear scene-referred pixels as float RGBA (Blender applies no view
/// transform to float formats); `.png` gets the scene's colour management and its
/// output format's bit depth and alpha. `linear` is left untouched.
pub fn write_render(
    scene: &Scene,
    path: &Path,
    width: u32,
    height: u32,
    linear: &[[f32; 4]],
) -> Result<(), ColorError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "exr" => write_exr(path, width, height, linear),
        "png" => {
            let mut px = linear.to_vec();
            to_display(scene, &mut px)?;
            let f = OutputFormat::from_scene(scene);
            write_png(path, width, height, &px, f.sixteen_bit, f.alpha)
        }
        _ => Err(ColorError::Write {
            path: path.to_path_buf(),
            message: format!("unsupported output type .{ext} (use .png or .exr)"),
        }),
    }
}
