//! Camera intrinsics and pose of a frame, from the scene camera as Blender and Cycles
//! define it (lens and sensor in mm, sensor fit, shift in units of the fitted image side,
//! non-square pixels), in Blender's convention and in OpenCV's, plus the model of a
//! panoramic camera. See docs/ground-truth.md for the conventions.

use serde::{Deserialize, Serialize};

use crate::scene::settings::{CameraSettings, Panoramic, Projection};

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
    cam: &CameraSettings,
    matrix_world: [[f64; 4]; 4],
    width: u32,
    height: u32,
    pixel_aspect: [f64; 2],
) -> CameraInfo {
    let (w, h) = (width as f64, height as f64);
    let (xratio, yratio) = (w * pixel_aspect[0], h * pixel_aspect[1]);
    // Which side the sensor spans, and its size along it (Cycles' blender_camera_sync:
    // AUTO fits the longer side of the image with pixel aspect, using sensor_width).
    let (horizontal, sensor) = cam.fit(xratio, yratio);
    let (sx, sy) = (cam.shift_x, cam.shift_y);
    // Cycles' viewplane: [left, right] x [bottom, top] spans the image; a pixel's ray
    // is (vx tan, vy tan, -1) in Blender camera space (perspective) or starts at
    // (vx, vy, 0) (orthographic).
    let (mut aspect, mut xaspect, mut yaspect) = if horizontal {
        (xratio / yratio, xratio / yratio, 1.0)
    } else {
        (yratio / xratio, 1.0, yratio / xratio)
    };
    let ortho = cam.projection == Some(Projection::Orthographic);
    if ortho {
        let scale = cam.ortho_scale;
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
        0.5 * sensor / cam.lens / aspect
    };
    let mut fx = w / ((right - left) * tan_half);
    let mut fy = h / ((top - bottom) * tan_half);
    let mut cx = -left * w / (right - left);
    let mut cy = top * h / (top - bottom);
    let mut panorama = None;
    let projection = if cam.projection == Some(Projection::Panoramic) {
        let sensor_mm = if horizontal {
            [sensor, sensor * yratio / xratio]
        } else {
            [sensor * xratio / yratio, sensor]
        };
        // The panoramic viewplane is [0, 1]^2 moved by the shift.
        cx = w * (0.5 - sx);
        cy = h * (0.5 + sy);
        let info = panorama_info(&cam.panorama, sensor_mm);
        (fx, fy) = info.focal_pixels(w, h);
        let projection = format!("PANO:{}", info.model);
        panorama = Some(info);
        projection
    } else {
        cam.kind.clone()
    };
    let k = if panorama.is_some() {
        [[0.0; 3]; 3]
    } else {
        [[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]]
    };
    CameraInfo {
        name: name.to_string(),
        lens_mm: cam.lens,
        sensor_width_mm: cam.sensor_width,
        sensor_height_mm: cam.sensor_height,
        sensor_fit: cam.sensor_fit_name().to_string(),
        projection,
        width,
        height,
        pixel_aspect,
        fx,
        fy,
        cx,
        cy,
        k,
        clip_start: cam.clip_start,
        clip_end: cam.clip_end,
        aperture_fstop: cam.dof.as_ref().map(|d| d.aperture_fstop),
        focus_distance: cam.dof.as_ref().map(|d| d.focus_distance),
        matrix_world,
        world_to_camera_opencv: opencv_world_to_camera(&matrix_world),
        location: [matrix_world[0][3], matrix_world[1][3], matrix_world[2][3]],
        panorama,
    }
}

/// A panoramic camera's model and parameters as the records state them.
fn panorama_info(p: &Panoramic, sensor_mm: [f64; 2]) -> PanoramaInfo {
    PanoramaInfo {
        fov: p.fisheye_fov,
        fisheye_lens_mm: p.fisheye_lens,
        sensor_mm,
        polynomial: p.fisheye_polynomial,
        longitude: p.longitude,
        latitude: p.latitude,
        cylindrical_u: p.central_cylindrical_range_u,
        cylindrical_v: p.central_cylindrical_range_v,
        cylindrical_radius: p.central_cylindrical_radius,
        model: p.panorama_type.clone(),
    }
}

impl PanoramaInfo {
    /// Focal lengths in pixels of the fisheye models (0 for the others).
    fn focal_pixels(&self, w: f64, h: f64) -> (f64, f64) {
        match self.model.as_str() {
            // theta = sqrt(((x - cx) / fx)^2 + ((y - cy) / fy)^2)
            "FISHEYE_EQUIDISTANT" => (w / self.fov, h / self.fov),
            // 2 sin(theta / 2) = sqrt(((x - cx) / fx)^2 + ((y - cy) / fy)^2)
            "FISHEYE_EQUISOLID" => (
                self.fisheye_lens_mm * w / self.sensor_mm[0],
                self.fisheye_lens_mm * h / self.sensor_mm[1],
            ),
            // Pixels per mm on the sensor; r = sqrt(((x-cx)/fx)^2 + ((y-cy)/fy)^2).
            "FISHEYE_LENS_POLYNOMIAL" => (w / self.sensor_mm[0], h / self.sensor_mm[1]),
            _ => (0.0, 0.0),
        }
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
