//! Camera intrinsics and pose of a frame, from the scene camera as Blender and Cycles
//! define it (lens and sensor in mm, sensor fit, shift in units of the fitted image side,
//! non-square pixels), in Blender's convention and in OpenCV's, plus the model of a
//! panoramic camera. See docs/ground-truth.md for the conventions.

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
    /// The render's pixel aspect (x, y): a pixel is x wide and y tall.
    #[serde(default = "square")]
    pub pixel_aspect: [f64; 2],
    /// Intrinsics in pixels (x right, y down, origin at the top-left corner of the
    /// top-left pixel, so the centre of pixel (i, j) is (i + 0.5, j + 0.5)): fx, fy, cx,
    /// cy. Pinhole for "PERSP"; for "ORTHO" fx and fy are pixels per scene unit
    /// (u = cx + fx * X); for the fisheyes see `panorama`; 0 for other panoramas.
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// The same as a 3x3 matrix K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], row-major,
    /// applied to OpenCV camera coordinates: (u, v, 1) ~ K (X/Z, Y/Z, 1) for "PERSP",
    /// (u, v, 1) = K (X, Y, 1) for "ORTHO". All zeros for panoramas.
    #[serde(default)]
    pub k: [[f64; 3]; 3],
    pub clip_start: f64,
    pub clip_end: f64,
    pub aperture_fstop: Option<f64>,
    pub focus_distance: Option<f64>,
    /// Blender's camera-to-world matrix (camera looks down its -Z, +Y up, +X right),
    /// m[row][col], as Blender stores it (object scale included).
    pub matrix_world: [[f64; 4]; 4],
    /// OpenCV's world-to-camera matrix [R | t] (camera x right, y down, z forward; no
    /// scale: Blender and Cycles ignore the camera object's scale), m[row][col], last
    /// row (0, 0, 0, 1): X_cam = R X_world + t.
    #[serde(default)]
    pub world_to_camera_opencv: [[f64; 4]; 4],
    /// Camera position in world space.
    pub location: [f64; 3],
    /// A panoramic camera's projection, as Cycles evaluates it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub panorama: Option<PanoramaInfo>,
}

/// A panoramic camera's model and parameters. Pixel (x, y) relates to the ray's angle
/// theta from the view axis (OpenCV +Z) and its direction around it as written per
/// model in docs/ground-truth.md; `fx`, `fy`, `cx`, `cy` of the frame's CameraInfo are
/// the fisheyes' pixel scales and centre.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PanoramaInfo {
    /// Blender's panorama type (FISHEYE_EQUIDISTANT, FISHEYE_EQUISOLID,
    /// FISHEYE_LENS_POLYNOMIAL, EQUIRECTANGULAR, EQUIANGULAR_CUBEMAP_FACE, MIRRORBALL,
    /// CENTRAL_CYLINDRICAL).
    pub model: String,
    /// Field of view of the fisheyes, radians: rays beyond fov/2 from the axis see nothing.
    pub fov: f64,
    /// Fisheye lens in mm (equisolid).
    pub fisheye_lens_mm: f64,
    /// The sensor size Cycles spans the image with (mm; sensor fit and aspect applied).
    pub sensor_mm: [f64; 2],
    /// Polynomial fisheye: theta = -(k0 + k1 r + k2 r^2 + k3 r^3 + k4 r^4), r in mm.
    pub polynomial: [f64; 5],
    /// Equirectangular longitude and latitude ranges (min, max), radians.
    pub longitude: [f64; 2],
    pub latitude: [f64; 2],
    /// Central cylindrical: u range (radians), v range and radius.
    pub cylindrical_u: [f64; 2],
    pub cylindrical_v: [f64; 2],
    pub cylindrical_radius: f64,
}

fn persp() -> String {
    "PERSP".into()
}

fn square() -> [f64; 2] {
    [1.0, 1.0]
}

fn f(p: &Rna, k: &str, default: f64) -> f64 {
    p.get(k).and_then(|v| v.as_f64()).unwrap_or(default)
}

/// OpenCV's world-to-camera [R | t] from Blender's camera-to-world matrix: the rotation
/// with scale removed (each axis normalised), camera axes x = Blender +X, y = Blender
/// -Y, z = Blender -Z.
pub fn opencv_world_to_camera(m: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let axis = |c: usize| {
        let v = [m[0][c], m[1][c], m[2][c]];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if n > 0.0 {
            v.map(|x| x / n)
        } else {
            v
        }
    };
    let (x, y, z) = (axis(0), axis(1), axis(2));
    // Rows of R are the OpenCV camera axes in world space.
    let rows = [x, y.map(|v| -v), z.map(|v| -v)];
    let pos = [m[0][3], m[1][3], m[2][3]];
    let mut out = [[0.0; 4]; 4];
    for r in 0..3 {
        out[r][..3].copy_from_slice(&rows[r]);
        out[r][3] = -(0..3).map(|k| rows[r][k] * pos[k]).sum::<f64>();
    }
    out[3][3] = 1.0;
    out
}

/// The frame's camera. `pixel_aspect` is the render's (pixel_aspect_x, pixel_aspect_y).
pub fn camera_info(
    name: &str,
    props: &Rna,
    matrix_world: [[f64; 4]; 4],
    width: u32,
    height: u32,
    pixel_aspect: [f64; 2],
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
    let (xratio, yratio) = (w * pixel_aspect[0], h * pixel_aspect[1]);
    // Which side the sensor spans, and its size along it (Cycles' blender_camera_sync:
    // AUTO fits the longer side of the image with pixel aspect, using sensor_width).
    let (horizontal, sensor) = match fit.as_str() {
        "HORIZONTAL" => (true, sw),
        "VERTICAL" => (false, sh),
        _ => (xratio > yratio, sw),
    };
    let kind = props
        .get("type")
        .and_then(|v| v.as_str())
        .unwrap_or("PERSP");
    let (sx, sy) = (f(props, "shift_x", 0.0), f(props, "shift_y", 0.0));
    // Cycles' viewplane: [left, right] x [bottom, top] spans the image; a pixel's ray
    // is (vx tan, vy tan, -1) in Blender camera space (perspective) or starts at
    // (vx, vy, 0) (orthographic).
    let (mut aspect, mut xaspect, mut yaspect) = if horizontal {
        (xratio / yratio, xratio / yratio, 1.0)
    } else {
        (yratio / xratio, 1.0, yratio / xratio)
    };
    let ortho = kind == "ORTHO";
    if ortho {
        let scale = f(props, "ortho_scale", 6.0);
        xaspect *= scale / (aspect * 2.0);
        yaspect *= scale / (aspect * 2.0);
        aspect = scale / 2.0;
    }
    let (dx, dy) = (2.0 * aspect * sx, 2.0 * aspect * sy);
    let (left, right) = (-xaspect + dx, xaspect + dx);
    let (bottom, top) = (-yaspect + dy, yaspect + dy);
    let tan_half = if ortho {
        1.0
    } else {
        0.5 * sensor / lens / aspect
    };
    let mut fx = w / ((right - left) * tan_half);
    let mut fy = h / ((top - bottom) * tan_half);
    let mut cx = -left * w / (right - left);
    let mut cy = top * h / (top - bottom);
    let mut panorama = None;
    let projection = match kind {
        "PANO" => {
            let model = props
                .get("panorama_type")
                .and_then(|v| v.as_str())
                .unwrap_or("FISHEYE_EQUISOLID")
                .to_string();
            let fov = f(props, "fisheye_fov", std::f64::consts::PI);
            let fisheye_lens = f(props, "fisheye_lens", 10.5);
            let sensor_mm = if horizontal {
                [sensor, sensor * yratio / xratio]
            } else {
                [sensor * xratio / yratio, sensor]
            };
            // The panoramic viewplane is [0, 1]^2 moved by the shift.
            cx = w * (0.5 - sx);
            cy = h * (0.5 + sy);
            (fx, fy) = match model.as_str() {
                // theta = sqrt(((x - cx) / fx)^2 + ((y - cy) / fy)^2)
                "FISHEYE_EQUIDISTANT" => (w / fov, h / fov),
                // 2 sin(theta / 2) = sqrt(((x - cx) / fx)^2 + ((y - cy) / fy)^2)
                "FISHEYE_EQUISOLID" => (
                    fisheye_lens * w / sensor_mm[0],
                    fisheye_lens * h / sensor_mm[1],
                ),
                // Pixels per mm on the sensor; r = sqrt(((x-cx)/fx)^2 + ((y-cy)/fy)^2).
                "FISHEYE_LENS_POLYNOMIAL" => (w / sensor_mm[0], h / sensor_mm[1]),
                _ => (0.0, 0.0),
            };
            let p = |k: &str| f(props, k, 0.0);
            panorama = Some(PanoramaInfo {
                fov,
                fisheye_lens_mm: fisheye_lens,
                sensor_mm,
                polynomial: [
                    p("fisheye_polynomial_k0"),
                    p("fisheye_polynomial_k1"),
                    p("fisheye_polynomial_k2"),
                    p("fisheye_polynomial_k3"),
                    p("fisheye_polynomial_k4"),
                ],
                longitude: [
                    f(props, "longitude_min", -std::f64::consts::PI),
                    f(props, "longitude_max", std::f64::consts::PI),
                ],
                latitude: [
                    f(props, "latitude_min", -std::f64::consts::FRAC_PI_2),
                    f(props, "latitude_max", std::f64::consts::FRAC_PI_2),
                ],
                cylindrical_u: [
                    f(
                        props,
                        "central_cylindrical_range_u_min",
                        -std::f64::consts::PI,
                    ),
                    f(
                        props,
                        "central_cylindrical_range_u_max",
                        std::f64::consts::PI,
                    ),
                ],
                cylindrical_v: [
                    f(props, "central_cylindrical_range_v_min", -1.0),
                    f(props, "central_cylindrical_range_v_max", 1.0),
                ],
                cylindrical_radius: f(props, "central_cylindrical_radius", 1.0),
                model: model.clone(),
            });
            format!("PANO:{model}")
        }
        other => other.to_string(),
    };
    let k = if panorama.is_some() {
        [[0.0; 3]; 3]
    } else {
        [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]
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
        pixel_aspect,
        fx,
        fy,
        cx,
        cy,
        k,
        clip_start: f(props, "clip_start", 0.1),
        clip_end: f(props, "clip_end", 1000.0),
        aperture_fstop: d("aperture_fstop"),
        focus_distance: d("focus_distance"),
        matrix_world,
        world_to_camera_opencv: opencv_world_to_camera(&matrix_world),
        location: [matrix_world[0][3], matrix_world[1][3], matrix_world[2][3]],
        panorama,
    }
}

impl CameraInfo {
    /// Projects a world point to pixels (x right, y down) with K and the OpenCV pose;
    /// also returns the point's OpenCV depth Z. None for panoramas.
    pub fn project(&self, p: [f64; 3]) -> Option<([f64; 2], f64)> {
        if self.panorama.is_some() {
            return None;
        }
        let m = &self.world_to_camera_opencv;
        let c: [f64; 3] =
            std::array::from_fn(|r| (0..3).map(|k| m[r][k] * p[k]).sum::<f64>() + m[r][3]);
        let (x, y) = if self.projection == "ORTHO" {
            (c[0], c[1])
        } else {
            (c[0] / c[2], c[1] / c[2])
        };
        let k = &self.k;
        Some(([k[0][0] * x + k[0][2], k[1][1] * y + k[1][2]], c[2]))
    }
}
