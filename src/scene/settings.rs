//! Blender's settings as typed values: the render output, Cycles' integrator and film,
//! motion blur, cameras, lights, worlds and materials.
//!
//! The exporter writes each Blender struct as a map of its RNA property names. This file
//! is where those names are read, each with Blender's default (the DNA default, or the
//! default Cycles' add-on registers) in one place, so the renderer, the labels and the
//! dataset writer work on typed values and agree on them. A setting that is absent, or
//! of another JSON type, reads as its default, as the exporter's older versions left
//! some out; values are checked where they are used (the renderer's limits).

use serde_json::Value;

use super::format::{Camera, Light, Material, Object, Rna, SceneSettings, World};

fn num(m: &Rna, k: &str) -> Option<f64> {
    m.get(k).and_then(Value::as_f64)
}

fn flag(m: &Rna, k: &str) -> Option<bool> {
    m.get(k).and_then(Value::as_bool)
}

fn text<'a>(m: &'a Rna, k: &str) -> Option<&'a str> {
    m.get(k).and_then(Value::as_str)
}

/// An ID pointer: the exporter writes `{"id_type": ..., "name": ...}` (older exports, and
/// hand-written ones, a plain name).
fn id_name<'a>(m: &'a Rna, k: &str) -> Option<&'a str> {
    let v = m.get(k)?;
    v.as_str().or_else(|| v.get("name").and_then(Value::as_str))
}

fn group<'a>(m: &'a Rna, k: &str) -> Option<&'a Rna> {
    m.get(k).and_then(Value::as_object)
}

/// How Cycles renders hair curves (Render Properties > Curves, `scene.cycles_curves`).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveSettings {
    /// `RIBBONS` (Rounded Ribbons, the add-on's default) or `THICK` (3D Curves).
    pub shape: String,
    /// Ribbons: 2^subdivisions straight pieces per curve segment (default 2).
    pub subdivisions: u32,
}

impl CurveSettings {
    pub fn of(s: &SceneSettings) -> CurveSettings {
        let c = &s.cycles_curves;
        CurveSettings {
            shape: text(c, "shape").unwrap_or("RIBBONS").to_string(),
            subdivisions: num(c, "subdivisions").unwrap_or(2.0).clamp(0.0, 24.0) as u32,
        }
    }
}

/// The render output (`scene.render`): resolution and pixel aspect.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    pub resolution_x: f64,
    pub resolution_y: f64,
    pub resolution_percentage: f64,
    pub pixel_aspect_x: f64,
    pub pixel_aspect_y: f64,
}

impl Output {
    pub fn of(s: &SceneSettings) -> Output {
        let r = &s.render;
        Output {
            resolution_x: num(r, "resolution_x").unwrap_or(1920.0),
            resolution_y: num(r, "resolution_y").unwrap_or(1080.0),
            resolution_percentage: num(r, "resolution_percentage").unwrap_or(100.0),
            pixel_aspect_x: num(r, "pixel_aspect_x").unwrap_or(1.0),
            pixel_aspect_y: num(r, "pixel_aspect_y").unwrap_or(1.0),
        }
    }

    /// The image size Blender renders: resolution times its percentage, truncated as
    /// Blender's integer arithmetic does; a size below one pixel is Blender's "Image too
    /// small" error.
    pub fn size(&self) -> Result<(u32, u32), String> {
        for (k, v) in [
            ("resolution_percentage", self.resolution_percentage),
            ("resolution_x", self.resolution_x),
            ("resolution_y", self.resolution_y),
        ] {
            if !(v.is_finite() && v >= 1.0) {
                return Err(format!("scenes.render.{k} is {v}: must be at least 1"));
            }
        }
        let (rx, ry, pct) = (
            self.resolution_x,
            self.resolution_y,
            self.resolution_percentage,
        );
        let (w, h) = (rx * pct / 100.0, ry * pct / 100.0);
        if w < 1.0 || h < 1.0 {
            return Err(format!(
                "scenes.render resolution {rx}x{ry} at {pct}% is below one pixel (Blender: \"Image too small\")"
            ));
        }
        // Saturating: anything beyond u32 is then refused by the renderer's size check.
        Ok((w as u32, h as u32))
    }
}

/// Cycles' sampling, light paths and film (`scene.cycles` and the film settings of
/// `scene.render`), with the defaults Cycles' add-on registers.
#[derive(Debug, Clone, PartialEq)]
pub struct Integrator {
    /// Render samples, as exported (checked by the renderer: a whole number in range).
    pub samples: f64,
    pub max_bounces: u32,
    pub diffuse_bounces: u32,
    pub glossy_bounces: u32,
    pub transmission_bounces: u32,
    pub transparent_max_bounces: u32,
    pub min_light_bounces: u32,
    pub min_transparent_bounces: u32,
    /// Per channel, as in the UI (0 is off).
    pub sample_clamp_direct: f64,
    pub sample_clamp_indirect: f64,
    /// Filter Glossy.
    pub blur_glossy: f64,
    /// Pixel filter width: Cycles' `filter_width`, else the render's `filter_size` (older
    /// files keep it there).
    pub filter_width: f64,
    pub film_transparent: bool,
    pub film_transparent_glass: bool,
    pub film_transparent_roughness: f64,
    pub use_light_tree: bool,
    pub use_adaptive_sampling: bool,
    pub adaptive_threshold: f64,
    pub adaptive_min_samples: f64,
    pub use_denoising: bool,
    /// The sampling pattern's seed.
    pub seed: f64,
    /// Light Paths > Max Bounces > Volume (0: single scattering).
    pub volume_bounces: u32,
    /// Volumes > Step Rate (render) and Max Steps: the ray marching of varying volumes.
    pub volume_step_rate: f64,
    pub volume_max_steps: u32,
}

impl Integrator {
    pub fn of(s: &SceneSettings) -> Integrator {
        let (cy, r) = (&s.cycles, &s.render);
        let count = |k: &str, d: f64| num(cy, k).unwrap_or(d) as u32;
        Integrator {
            samples: num(cy, "samples").unwrap_or(128.0),
            max_bounces: count("max_bounces", 12.0),
            diffuse_bounces: count("diffuse_bounces", 4.0),
            glossy_bounces: count("glossy_bounces", 4.0),
            transmission_bounces: count("transmission_bounces", 12.0),
            transparent_max_bounces: count("transparent_max_bounces", 8.0),
            min_light_bounces: count("min_light_bounces", 0.0),
            min_transparent_bounces: count("min_transparent_bounces", 0.0),
            sample_clamp_direct: num(cy, "sample_clamp_direct").unwrap_or(0.0),
            sample_clamp_indirect: num(cy, "sample_clamp_indirect").unwrap_or(10.0),
            blur_glossy: num(cy, "blur_glossy").unwrap_or(1.0),
            filter_width: num(cy, "filter_width")
                .or_else(|| num(r, "filter_size"))
                .unwrap_or(1.5),
            film_transparent: flag(r, "film_transparent").unwrap_or(false),
            film_transparent_glass: flag(cy, "film_transparent_glass").unwrap_or(false),
            film_transparent_roughness: num(cy, "film_transparent_roughness").unwrap_or(0.1),
            use_light_tree: flag(cy, "use_light_tree").unwrap_or(true),
            use_adaptive_sampling: flag(cy, "use_adaptive_sampling").unwrap_or(false),
            adaptive_threshold: num(cy, "adaptive_threshold").unwrap_or(0.01),
            adaptive_min_samples: num(cy, "adaptive_min_samples").unwrap_or(0.0),
            use_denoising: flag(cy, "use_denoising").unwrap_or(false),
            seed: num(cy, "seed").unwrap_or(0.0),
            volume_bounces: count("volume_bounces", 0.0),
            volume_step_rate: num(cy, "volume_step_rate").unwrap_or(1.0),
            volume_max_steps: count("volume_max_steps", 1024.0),
        }
    }
}

/// Where the shutter opens relative to the frame (`motion_blur_position`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShutterPosition {
    Start,
    Center,
    End,
}

/// Motion blur (`scene.render`).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionBlur {
    pub enabled: bool,
    /// Shutter length in frames.
    pub shutter: f64,
    pub position: ShutterPosition,
    /// The shutter curve's curve mapping as exported (read by the renderer's curve code).
    pub shutter_curve: Option<Value>,
}

impl MotionBlur {
    pub fn of(s: &SceneSettings) -> Result<MotionBlur, String> {
        let r = &s.render;
        let enabled = flag(r, "use_motion_blur") == Some(true);
        // Only a shutter that opens is held to a known position.
        let position = match text(r, "motion_blur_position")
            .filter(|_| enabled)
            .unwrap_or("CENTER")
        {
            "START" => ShutterPosition::Start,
            "END" => ShutterPosition::End,
            "CENTER" => ShutterPosition::Center,
            other => {
                return Err(format!(
                    "render.motion_blur_position {other:?} is not START, CENTER or END"
                ))
            }
        };
        Ok(MotionBlur {
            enabled,
            shutter: num(r, "motion_blur_shutter").unwrap_or(0.5),
            position,
            shutter_curve: r
                .get("motion_blur_shutter_curve")
                .filter(|v| !v.is_null())
                .cloned(),
        })
    }
}

/// Which image side the camera's sensor spans (`sensor_fit`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorFit {
    Auto,
    Horizontal,
    Vertical,
}

/// A camera's projection (`type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Projection {
    Perspective,
    Orthographic,
    Panoramic,
}

/// Depth of field (`camera.dof`).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthOfField {
    pub use_dof: bool,
    pub aperture_fstop: f64,
    pub aperture_blades: f64,
    pub aperture_rotation: f64,
    pub aperture_ratio: f64,
    pub focus_distance: f64,
    pub focus_object: Option<String>,
    /// The focus object's bone to focus on (empty: its origin).
    pub focus_subtarget: String,
}

/// A camera's data block (after animation), with Blender's DNA defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraSettings {
    /// Blender's `type` as exported ("PERSP", "ORTHO", "PANO", or what a newer Blender
    /// writes); `projection` is None for a type blendsynth does not know.
    pub kind: String,
    pub projection: Option<Projection>,
    pub lens: f64,
    pub sensor_width: f64,
    pub sensor_height: f64,
    pub sensor_fit: SensorFit,
    pub ortho_scale: f64,
    pub shift_x: f64,
    pub shift_y: f64,
    pub clip_start: f64,
    pub clip_end: f64,
    /// As exported (None for an export without it); on when `use_dof`.
    pub dof: Option<DepthOfField>,
    /// The exported settings of a panoramic camera, by RNA name (see `Panoramic`).
    pub panorama: Panoramic,
}

/// A panoramic camera's settings (Cycles' panorama types, Blender 4.x names).
#[derive(Debug, Clone, PartialEq)]
pub struct Panoramic {
    pub panorama_type: String,
    pub fisheye_fov: f64,
    pub fisheye_lens: f64,
    pub fisheye_polynomial: [f64; 5],
    pub longitude: [f64; 2],
    pub latitude: [f64; 2],
    pub central_cylindrical_radius: f64,
    pub central_cylindrical_range_u: [f64; 2],
    pub central_cylindrical_range_v: [f64; 2],
}

impl CameraSettings {
    pub fn of(c: &Camera) -> CameraSettings {
        let p = &c.properties;
        let kind = text(p, "type").unwrap_or("PERSP").to_string();
        let projection = match kind.as_str() {
            "PERSP" => Some(Projection::Perspective),
            "ORTHO" => Some(Projection::Orthographic),
            "PANO" => Some(Projection::Panoramic),
            _ => None,
        };
        let sensor_fit = match text(p, "sensor_fit").unwrap_or("AUTO") {
            "HORIZONTAL" => SensorFit::Horizontal,
            "VERTICAL" => SensorFit::Vertical,
            _ => SensorFit::Auto,
        };
        let dof = group(p, "dof").map(|d| DepthOfField {
            use_dof: flag(d, "use_dof").unwrap_or(false),
            aperture_fstop: num(d, "aperture_fstop").unwrap_or(2.8),
            aperture_blades: num(d, "aperture_blades").unwrap_or(0.0),
            aperture_rotation: num(d, "aperture_rotation").unwrap_or(0.0),
            aperture_ratio: num(d, "aperture_ratio").unwrap_or(1.0),
            focus_distance: num(d, "focus_distance").unwrap_or(10.0),
            focus_object: id_name(d, "focus_object").map(str::to_string),
            focus_subtarget: text(d, "focus_subtarget").unwrap_or("").to_string(),
        });
        let n = |k: &str, d: f64| num(p, k).unwrap_or(d);
        use std::f64::consts::{FRAC_PI_2, PI};
        CameraSettings {
            kind,
            projection,
            lens: n("lens", 50.0),
            sensor_width: n("sensor_width", 36.0),
            sensor_height: n("sensor_height", 24.0),
            sensor_fit,
            ortho_scale: n("ortho_scale", 6.0),
            shift_x: n("shift_x", 0.0),
            shift_y: n("shift_y", 0.0),
            clip_start: n("clip_start", 0.1),
            clip_end: n("clip_end", 1000.0),
            dof,
            panorama: Panoramic {
                panorama_type: text(p, "panorama_type")
                    .unwrap_or("FISHEYE_EQUISOLID")
                    .to_string(),
                fisheye_fov: n("fisheye_fov", PI),
                fisheye_lens: n("fisheye_lens", 10.5),
                fisheye_polynomial: [
                    n("fisheye_polynomial_k0", 0.0),
                    n("fisheye_polynomial_k1", 0.0),
                    n("fisheye_polynomial_k2", 0.0),
                    n("fisheye_polynomial_k3", 0.0),
                    n("fisheye_polynomial_k4", 0.0),
                ],
                longitude: [n("longitude_min", -PI), n("longitude_max", PI)],
                latitude: [n("latitude_min", -FRAC_PI_2), n("latitude_max", FRAC_PI_2)],
                central_cylindrical_radius: n("central_cylindrical_radius", 1.0),
                central_cylindrical_range_u: [
                    n("central_cylindrical_range_u_min", -PI),
                    n("central_cylindrical_range_u_max", PI),
                ],
                central_cylindrical_range_v: [
                    n("central_cylindrical_range_v_min", -1.0),
                    n("central_cylindrical_range_v_max", 1.0),
                ],
            },
        }
    }

    /// The sensor fit's name as Blender spells it.
    pub fn sensor_fit_name(&self) -> &'static str {
        match self.sensor_fit {
            SensorFit::Auto => "AUTO",
            SensorFit::Horizontal => "HORIZONTAL",
            SensorFit::Vertical => "VERTICAL",
        }
    }

    /// Blender's sensor fit for an image of (xratio, yratio) (pixel aspect included):
    /// whether the sensor spans the width, and the sensor size along that side in mm.
    pub fn fit(&self, xratio: f64, yratio: f64) -> (bool, f64) {
        match self.sensor_fit {
            SensorFit::Horizontal => (true, self.sensor_width),
            SensorFit::Vertical => (false, self.sensor_height),
            SensorFit::Auto => (xratio > yratio, self.sensor_width),
        }
    }
}

/// A light's area shape (`shape`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AreaShape {
    Square,
    Rectangle,
    Disk,
    Ellipse,
}

/// A light's data block (after animation), with Blender's DNA defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSettings {
    pub color: Option<[f64; 3]>,
    pub energy: f64,
    pub exposure: f64,
    pub use_temperature: bool,
    /// The blackbody colour Blender computed for the temperature (working space).
    pub temperature_color: Option<[f64; 3]>,
    pub use_nodes: bool,
    pub cast_shadow: bool,
    /// Point and spot radius.
    pub shadow_soft_size: f64,
    pub use_soft_falloff: bool,
    pub spot_size: f64,
    pub spot_blend: f64,
    pub size: f64,
    pub size_y: f64,
    pub shape: AreaShape,
    pub spread: f64,
    /// Sun angular diameter.
    pub angle: f64,
    pub normalize: bool,
    pub is_portal: bool,
    pub use_multiple_importance_sampling: bool,
    pub max_bounces: u32,
}

/// An RGB triple from an exported colour array (a missing channel reads 1, as a light's
/// colour always has been read).
pub fn rgb(v: Option<&Value>) -> Option<[f64; 3]> {
    v.and_then(Value::as_array)
        .map(|a| [0, 1, 2].map(|i| a.get(i).and_then(Value::as_f64).unwrap_or(1.0)))
}

/// An RGB triple only when the export has at least three numbers.
fn rgb_strict(v: Option<&Value>) -> Option<[f64; 3]> {
    match v {
        Some(Value::Array(c)) if c.len() >= 3 && c.iter().all(Value::is_number) => {
            Some([c[0].as_f64()?, c[1].as_f64()?, c[2].as_f64()?])
        }
        _ => None,
    }
}

impl LightSettings {
    pub fn of(l: &Light) -> LightSettings {
        let p = &l.properties;
        let cy = group(p, "cycles");
        let n = |k: &str, d: f64| num(p, k).unwrap_or(d);
        use std::f64::consts::{FRAC_PI_4, PI};
        LightSettings {
            color: rgb(p.get("color")),
            energy: n("energy", 10.0),
            exposure: n("exposure", 0.0),
            use_temperature: flag(p, "use_temperature").unwrap_or(false),
            temperature_color: rgb(p.get("temperature_color")),
            use_nodes: flag(p, "use_nodes").unwrap_or(false),
            // Blender 4.x keeps Cast Shadow as `use_shadow` (Cycles syncs it from there);
            // older files had it under `cycles.cast_shadow`.
            cast_shadow: p
                .get("use_shadow")
                .or_else(|| cy.and_then(|c| c.get("cast_shadow")))
                .and_then(Value::as_bool)
                .unwrap_or(true),
            shadow_soft_size: n("shadow_soft_size", 0.25),
            use_soft_falloff: flag(p, "use_soft_falloff").unwrap_or(true),
            spot_size: n("spot_size", FRAC_PI_4),
            spot_blend: n("spot_blend", 0.15),
            size: n("size", 1.0),
            size_y: n("size_y", 1.0),
            shape: match text(p, "shape").unwrap_or("SQUARE") {
                "RECTANGLE" => AreaShape::Rectangle,
                "DISK" => AreaShape::Disk,
                "ELLIPSE" => AreaShape::Ellipse,
                _ => AreaShape::Square,
            },
            spread: n("spread", PI),
            angle: n("angle", 0.00918),
            normalize: flag(p, "normalize").unwrap_or(true),
            is_portal: cy.and_then(|c| flag(c, "is_portal")).unwrap_or(false),
            use_multiple_importance_sampling: cy
                .and_then(|c| flag(c, "use_multiple_importance_sampling"))
                .unwrap_or(true),
            max_bounces: cy
                .and_then(|c| c.get("max_bounces"))
                .and_then(Value::as_u64)
                .unwrap_or(1024)
                .min(u32::MAX as u64) as u32,
        }
    }
}

/// A world's Cycles settings.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldSettings {
    /// Settings > Surface > Sampling is not "None": Cycles light-samples the world.
    pub sampled: bool,
    /// Ray visibility (Cycles' world `visibility`): camera, diffuse, glossy,
    /// transmission, volume scatter; true where absent.
    pub visible_to: [bool; 5],
    /// Settings > Volume > Homogeneous: the world volume is evaluated once per segment.
    pub homogeneous_volume: bool,
    /// Settings > Volume > Sampling (Blender's default for a world is Equiangular).
    pub volume_sampling: VolumeSampling,
    /// Settings > Volume > Step Size: the ray-marching step of a varying world volume.
    pub volume_step_size: f64,
}

impl WorldSettings {
    pub fn of(w: &World) -> WorldSettings {
        let p = &w.properties;
        let vis = group(p, "cycles_visibility");
        let see = |k: &str| vis.and_then(|v| flag(v, k)) != Some(false);
        let cy = group(p, "cycles");
        WorldSettings {
            sampled: cy.and_then(|c| text(c, "sampling_method")) != Some("NONE"),
            homogeneous_volume: cy
                .and_then(|c| flag(c, "homogeneous_volume"))
                .unwrap_or(false),
            volume_sampling: match cy.and_then(|c| text(c, "volume_sampling")) {
                Some("DISTANCE") => VolumeSampling::Distance,
                Some("MULTIPLE_IMPORTANCE") => VolumeSampling::MultipleImportance,
                _ => VolumeSampling::Equiangular,
            },
            volume_step_size: cy.and_then(|c| num(c, "volume_step_size")).unwrap_or(1.0),
            visible_to: [
                see("camera"),
                see("diffuse"),
                see("glossy"),
                see("transmission"),
                see("scatter"),
            ],
        }
    }
}

/// A material's Cycles settings.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialSettings {
    /// Emission sampling ("AUTO", "NONE", "FRONT", "BACK", "FRONT_BACK").
    pub emission_sampling: String,
    pub use_bump_map_correction: bool,
    /// Viewport Display colour, which Cycles renders when Use Nodes is off.
    pub diffuse_color: Option<[f64; 3]>,
    /// Volume > Homogeneous: the volume is evaluated once per ray segment even when it
    /// varies.
    pub homogeneous_volume: bool,
    /// Volume > Sampling.
    pub volume_sampling: VolumeSampling,
    /// Volume > Step Rate: scales the object's ray-marching step.
    pub volume_step_rate: f64,
    /// Volume > Interpolation is Cubic (else Linear): how voxel grids are sampled.
    pub volume_cubic: bool,
}

impl MaterialSettings {
    pub fn of(m: &Material) -> MaterialSettings {
        let p = &m.properties;
        let cy = group(p, "cycles");
        MaterialSettings {
            emission_sampling: cy
                .and_then(|c| text(c, "emission_sampling"))
                .unwrap_or("AUTO")
                .to_string(),
            use_bump_map_correction: cy
                .and_then(|c| flag(c, "use_bump_map_correction"))
                .unwrap_or(true),
            diffuse_color: rgb_strict(p.get("diffuse_color")),
            homogeneous_volume: cy
                .and_then(|c| flag(c, "homogeneous_volume"))
                .unwrap_or(false),
            volume_sampling: match cy.and_then(|c| text(c, "volume_sampling")) {
                Some("DISTANCE") => VolumeSampling::Distance,
                Some("EQUIANGULAR") => VolumeSampling::Equiangular,
                _ => VolumeSampling::MultipleImportance,
            },
            volume_step_rate: cy.and_then(|c| num(c, "volume_step_rate")).unwrap_or(1.0),
            volume_cubic: cy.and_then(|c| text(c, "volume_interpolation")) == Some("CUBIC"),
        }
    }
}

/// A material's Volume > Sampling: how a scatter point for direct light is chosen along
/// a ray inside the volume (Blender's default is Multiple Importance).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VolumeSampling {
    Distance,
    Equiangular,
    MultipleImportance,
}

/// An object's Cycles settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSettings {
    /// Deformation motion blur (Object > Motion Blur > Deformation).
    pub use_deform_motion: bool,
}

impl ObjectSettings {
    pub fn of(o: &Object) -> ObjectSettings {
        ObjectSettings {
            use_deform_motion: o.cycles.as_ref().and_then(|c| flag(c, "use_deform_motion"))
                != Some(false),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(render: Value, cycles: Value) -> SceneSettings {
        serde_json::from_value(serde_json::json!({
            "name": "S", "frame_start": 1, "frame_end": 1, "frame_current": 1,
            "fps": 24.0, "render": render, "cycles": cycles,
        }))
        .unwrap()
    }

    #[test]
    fn output_size_truncates_as_blender_and_refuses_below_a_pixel() {
        let s = scene(
            serde_json::json!({"resolution_x": 1001, "resolution_y": 333, "resolution_percentage": 50}),
            serde_json::json!({}),
        );
        assert_eq!(Output::of(&s).size(), Ok((500, 166)));
        let s = scene(
            serde_json::json!({"resolution_x": 1, "resolution_y": 1, "resolution_percentage": 50}),
            serde_json::json!({}),
        );
        assert!(Output::of(&s)
            .size()
            .unwrap_err()
            .contains("Image too small"));
        let s = scene(
            serde_json::json!({"resolution_x": 0}),
            serde_json::json!({}),
        );
        assert!(Output::of(&s)
            .size()
            .unwrap_err()
            .contains("resolution_x is 0"));
    }

    #[test]
    fn absent_settings_read_as_cycles_defaults() {
        let s = scene(serde_json::json!({}), serde_json::json!({}));
        let i = Integrator::of(&s);
        assert_eq!(
            (i.samples, i.max_bounces, i.diffuse_bounces),
            (128.0, 12, 4)
        );
        assert_eq!((i.sample_clamp_indirect, i.filter_width), (10.0, 1.5));
        assert!(i.use_light_tree && !i.film_transparent && !i.use_denoising);
        assert_eq!(Output::of(&s).size(), Ok((1920, 1080)));
        let s = scene(
            serde_json::json!({"filter_size": 2.0}),
            serde_json::json!({}),
        );
        assert_eq!(Integrator::of(&s).filter_width, 2.0);
    }
}
