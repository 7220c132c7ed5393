//! Camera intrinsics and pose of a frame, from the scene camera as Blender defines it
//! (lens and sensor in mm, sensor fit, shift in units of the fitted image side).

use serde::{Deserialize, Serialize};

use crate::scene::Rna;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraInfo {
    pub name: String,
    pub lens_mm: f64,
    pub sensor_width_mm: f64,
    pub sensor_height_mm: f64,
    pub sensor_fit: String,
    /// Blender's camera type: "PERSP", "ORTHO", or "PANO:" and the panorama type (for
    /// example "PANO:FISHEYE_EQUISOLID"). Records written before it read as "PERSP".
    #[serde(default = "persp")]
    pub projection: String,
    pub width: u32,
    pub height: u32,
    /// Intrinsics in pixels (x right, y down, origin at the top-left corner of the
    /// top-left pixel): fx, fy, cx, cy. Pinhole for "PERSP"; for "ORTHO" fx and fy are
    /// pixels per scene unit (u = cx + fx * x_camera); 0 for panoramas, which have none.
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    pub clip_start: f64,
    pub clip_end: f64,
    pub aperture_fstop: Option<f64>,
    pub focus_distance: Option<f64>,
    /// Blender's camera-to-world matrix (camera looks down its -Z, +Y up), m[row][col].
    pub matrix_world: [[f64; 4]; 4],
    /// Camera position in world space.
    pub location: [f64; 3],
}

fn persp() -> String {
    "PERSP".into()
}

fn f(p: &Rna, k: &str, default: f64) -> f64 {
    p.get(k).and_then(|v| v.as_f64()).unwrap_or(default)
}

pub fn camera_info(
    name: &str,
    props: &Rna,
    matrix_world: [[f64; 4]; 4],
    width: u32,
    height: u32,
) -> CameraInfo {
    let lens = f(props, "lens", 50.0);
    let sw = f(props, "sensor_width", 36.0);
    let sh = f(props, "sensor_height", 24.0);
    let fit = props
        .get("sensor_fit")
        .and_then(|v| v.as_str())
        .unwrap_or("AUTO")
        .to_string();
    let (w, h) = (width as f64, height as f64);
    // Which image side the sensor spans, and the sensor size along it (Blender's
    // BKE_camera_sensor_fit / sensor_size).
    let (side, sensor) = match fit.as_str() {
        "HORIZONTAL" => (w, sw),
        "VERTICAL" => (h, sh),
        _ => (w.max(h), sw),
    };
    let kind = props
        .get("type")
        .and_then(|v| v.as_str())
        .unwrap_or("PERSP");
    let (projection, focal) = match kind {
        "ORTHO" => ("ORTHO".to_string(), side / f(props, "ortho_scale", 6.0)),
        "PANO" => (
            format!(
                "PANO:{}",
                props
                    .get("panorama_type")
                    .and_then(|v| v.as_str())
                    .unwrap_or("FISHEYE_EQUISOLID")
            ),
            0.0,
        ),
        other => (other.to_string(), lens / sensor * side),
    };
    let dof = props.get("dof");
    let d = |k: &str| dof.and_then(|x| x.get(k)).and_then(|v| v.as_f64());
    CameraInfo {
        name: name.to_string(),
        lens_mm: lens,
        sensor_width_mm: sw,
        sensor_height_mm: sh,
        sensor_fit: fit,
        projection,
        width,
        height,
        fx: focal,
        fy: focal,
        cx: w / 2.0 - f(props, "shift_x", 0.0) * side,
        cy: h / 2.0 + f(props, "shift_y", 0.0) * side,
        clip_start: f(props, "clip_start", 0.1),
        clip_end: f(props, "clip_end", 1000.0),
        aperture_fstop: d("aperture_fstop"),
        focus_distance: d("focus_distance"),
        matrix_world,
        location: [matrix_world[0][3], matrix_world[1][3], matrix_world[2][3]],
    }
}
