//! Blender's camera as Cycles builds it: sensor fit, shift, clipping (planar, along the
//! view axis), perspective and orthographic projection, thin-lens depth of field with
//! f-stop, focus distance or focus object, aperture blades and rotation; panoramic
//! cameras (`panorama`: equirectangular, fisheyes, mirror ball, cube face, cylindrical).

pub mod panorama;

use crate::anim::EvaluatedScene;
use crate::render::math::{vec3, Affine, Vec3, V3};
use crate::render::RenderError;
use crate::scene::settings::{CameraSettings, Output, Projection};
use crate::scene::Scene;

/// The scene's active camera object at `frame` (Blender's switch at timeline markers).
pub fn active_camera(scene: &Scene, frame: f64) -> Result<&str, RenderError> {
    scene
        .camera_at(frame)
        .map_err(RenderError)?
        .ok_or_else(|| RenderError("the scene has no active camera (scene.camera is empty)".into()))
}

#[derive(Debug, Clone)]
pub struct Camera {
    pub ortho: bool,
    /// Viewplane bounds (Cycles' `viewplane`), already shifted.
    left: f32,
    right: f32,
    bottom: f32,
    top: f32,
    /// tan(fov/2) for perspective; 1 for orthographic (the viewplane is in metres).
    tan_half: f32,
    pub clip_start: f32,
    pub clip_end: f32,
    /// Camera to world, scale removed; camera looks down -Z, +Y up.
    pub to_world: Affine,
    aperture: f32,
    focus: f32,
    blades: u32,
    rotation: f32,
    ratio: f32,
    pub width: u32,
    pub height: u32,
    /// Camera-to-world at the motion steps across the shutter, when motion blur is on.
    motion: Option<Vec<crate::render::motion::Decomposed>>,
    /// A panoramic camera's projection (viewplane [0, 1]^2 plus shift).
    pub panorama: Option<crate::render::camera::panorama::Panorama>,
}

impl Camera {
    /// The scene's active camera at the evaluated frame (timeline markers switch it).
    pub fn new(
        scene: &Scene,
        eval: &EvaluatedScene,
        width: u32,
        height: u32,
    ) -> Result<Camera, RenderError> {
        let name = active_camera(scene, eval.frame)?;
        Camera::of_object(scene, eval, name, width, height)
    }

    /// Camera object `cam_name` as it stands in `eval` (Cycles keeps the frame's camera
    /// object for every motion step, whatever the markers say at the step).
    pub fn of_object(
        scene: &Scene,
        eval: &EvaluatedScene,
        cam_name: &str,
        width: u32,
        height: u32,
    ) -> Result<Camera, RenderError> {
        let oi = eval
            .data
            .objects
            .iter()
            .position(|o| o.name == cam_name)
            .ok_or_else(|| {
                RenderError(format!("camera object {cam_name:?} is not in the export"))
            })?;
        let obj = &eval.data.objects[oi];
        let data = obj.data.as_deref().unwrap_or(cam_name);
        let cam = eval
            .data
            .cameras
            .iter()
            .find(|c| c.name == data)
            .ok_or_else(|| {
                RenderError(format!(
                    "camera object {cam_name:?}: camera data {data:?} is not in the export"
                ))
            })?;
        let p = CameraSettings::of(cam);
        let Some(projection) = p.projection else {
            return Err(RenderError(format!(
                "camera {data:?}: camera type {:?} is not supported",
                p.kind
            )));
        };
        let ortho = projection == Projection::Orthographic;
        let out = Output::of(&scene.file.scene);
        let (pax, pay) = (out.pixel_aspect_x as f32, out.pixel_aspect_y as f32);
        let xratio = width as f32 * pax;
        let yratio = height as f32 * pay;
        let panorama = if projection == Projection::Panoramic {
            Some(
                crate::render::camera::panorama::Panorama::from_camera(&p, xratio, yratio)
                    .map_err(|e| RenderError(format!("camera {data:?}: {e}")))?,
            )
        } else {
            None
        };
        let (horizontal, sensor) = p.fit(xratio as f64, yratio as f64);
        let sensor = sensor as f32;
        let (mut aspect, mut xaspect, mut yaspect) = if horizontal {
            (xratio / yratio, xratio / yratio, 1.0)
        } else {
            (yratio / xratio, 1.0, yratio / xratio)
        };
        let ortho_scale = p.ortho_scale as f32;
        if ortho {
            xaspect = xaspect * ortho_scale / (aspect * 2.0);
            yaspect = yaspect * ortho_scale / (aspect * 2.0);
            aspect = ortho_scale / 2.0;
        }
        let (sx, sy) = (p.shift_x as f32, p.shift_y as f32);
        let dx = 2.0 * aspect * sx;
        let dy = 2.0 * aspect * sy;
        let lens = p.lens as f32;
        let tan_half = if ortho {
            1.0
        } else {
            (0.5 * sensor) / lens / aspect
        };
        // Camera transform without scale (Cycles clears it).
        let to_world = without_scale(&Affine::from_rows(&eval.world_matrices[oi]));
        let (mut aperture, mut focus, mut blades, mut rotation, mut ratio) =
            (0.0f32, 10.0f32, 0u32, 0.0f32, 1.0f32);
        if let Some(d) = p.dof.as_ref().filter(|d| d.use_dof) {
            let fstop = d.aperture_fstop as f32;
            // Cycles: lens in mm to a radius in metres; orthographic uses 1/(2 f-stop).
            aperture = if fstop <= 0.0 {
                0.0
            } else if ortho {
                1.0 / (2.0 * fstop)
            } else {
                (lens * 1e-3) / (2.0 * fstop)
            };
            // Blender's unit scale applies to the lens; scene scale is 1 in our fixtures.
            blades = d.aperture_blades as u32;
            rotation = d.aperture_rotation as f32;
            ratio = d.aperture_ratio as f32;
            focus = d.focus_distance as f32;
            if let Some(fo) = d.focus_object.as_deref() {
                if !d.focus_subtarget.is_empty() {
                    return Err(RenderError(format!(
                        "camera {data:?}: depth of field focusing on bone {:?} of {fo:?} is not supported (an object's origin is)",
                        d.focus_subtarget
                    )));
                }
                if let Some(fi) = eval.data.objects.iter().position(|o| o.name == fo) {
                    // Distance along the view axis to the focus object's origin.
                    let t = eval.world_matrices[fi];
                    let pos = vec3(t[0][3] as f32, t[1][3] as f32, t[2][3] as f32);
                    let view = -to_world.column_vec3(2).normalize();
                    focus = (pos - to_world.column_vec3(3)).dot(view).abs();
                }
            }
            focus = focus.max(1e-5);
        }
        let clip_start = p.clip_start as f32;
        let clip_end = p.clip_end as f32;
        // A panoramic camera's viewplane is [0, 1]^2, moved by the shift as it is.
        let (left, right, bottom, top) = if panorama.is_some() {
            (sx, 1.0 + sx, sy, 1.0 + sy)
        } else {
            (-xaspect + dx, xaspect + dx, -yaspect + dy, yaspect + dy)
        };
        Ok(Camera {
            ortho,
            left,
            right,
            bottom,
            top,
            tan_half,
            clip_start,
            clip_end,
            to_world,
            aperture,
            focus,
            blades,
            rotation,
            ratio,
            width,
            height,
            motion: None,
            panorama,
        })
    }

    /// Gives the camera its transforms at the shutter's motion steps (scale removed as
    /// for the centre transform); rays then take a time.
    pub fn set_motion(&mut self, steps: &[Affine]) {
        let unscaled: Vec<Affine> = steps.iter().map(without_scale).collect();
        self.motion = Some(crate::render::motion::decompose(&unscaled));
    }

    pub fn has_motion(&self) -> bool {
        self.motion.is_some()
    }

    /// `ray` at shutter time `time` in [0, 1] (ignored without motion blur).
    pub fn ray_at(&self, x: f32, y: f32, lens: [f32; 2], time: f32) -> (V3, V3, f32, f32) {
        match &self.motion {
            Some(steps) => {
                self.ray_with(&crate::render::motion::interpolate(steps, time), x, y, lens)
            }
            None => self.ray(x, y, lens),
        }
    }

    /// A camera ray through raster position (x right, y down from the top-left corner,
    /// in pixels): origin, unit direction, tmin, tmax. `lens` is a 2D sample.
    pub fn ray(&self, x: f32, y: f32, lens: [f32; 2]) -> (V3, V3, f32, f32) {
        self.ray_with(&self.to_world, x, y, lens)
    }

    fn ray_with(&self, to_world: &Affine, x: f32, y: f32, lens: [f32; 2]) -> (V3, V3, f32, f32) {
        let (o, d, tmin, tmax) = self.ray_vec3(to_world, x, y, lens);
        (o.into(), d.into(), tmin, tmax)
    }

    fn ray_vec3(
        &self,
        to_world: &Affine,
        x: f32,
        y: f32,
        lens: [f32; 2],
    ) -> (Vec3, Vec3, f32, f32) {
        let vx = self.left + (self.right - self.left) * (x / self.width as f32);
        let vy = self.top - (self.top - self.bottom) * (y / self.height as f32);
        if let Some(pano) = &self.panorama {
            return self.panorama_ray(pano, to_world, vx, vy, lens);
        }
        // Camera space, looking down -Z.
        let (mut p, mut d) = if self.ortho {
            (vec3(vx, vy, 0.0), vec3(0.0, 0.0, -1.0))
        } else {
            (
                Vec3::ZERO,
                vec3(vx * self.tan_half, vy * self.tan_half, -1.0).normalize(),
            )
        };
        let tmin;
        let tmax;
        if self.aperture > 0.0 {
            let mut uv = self.sample_aperture(lens);
            uv[0] *= self.aperture;
            uv[1] *= self.aperture;
            // Point on the plane of focus, then the ray from the lens point through it.
            let ft = self.focus / -d[2];
            let focus_p = p + d * ft;
            let lp = vec3(p[0] + uv[0], p[1] + uv[1], p[2]);
            d = (focus_p - lp).normalize();
            p = lp;
        }
        // Clipping planes are planar, along the view axis.
        let zinv = 1.0 / (-d[2]).max(1e-8);
        if self.ortho {
            tmin = self.clip_start;
            tmax = self.clip_end;
        } else {
            p += d * (self.clip_start * zinv);
            tmin = 0.0;
            tmax = (self.clip_end - self.clip_start) * zinv;
        }
        let wo = to_world.point_vec3(p);
        let wd = to_world.vector_vec3(d).normalize();
        (wo, wd, tmin, tmax)
    }

    /// Cycles' camera_sample_panorama: the direction from the projection, a thin lens
    /// across it, the near clip along the ray. Outside the lens: a zero direction and
    /// tmax 0 (the sample sees nothing).
    fn panorama_ray(
        &self,
        pano: &crate::render::camera::panorama::Panorama,
        to_world: &Affine,
        u: f32,
        v: f32,
        lens: [f32; 2],
    ) -> (Vec3, Vec3, f32, f32) {
        let mut d = Vec3::from(pano.direction(u, v));
        if d == Vec3::ZERO {
            return (to_world.column_vec3(3), Vec3::ZERO, 0.0, 0.0);
        }
        let mut p = Vec3::ZERO;
        if self.aperture > 0.0 {
            let mut uv = self.sample_aperture(lens);
            uv[0] *= self.aperture;
            uv[1] *= self.aperture;
            let df = d.normalize();
            let pf = df * self.focus;
            let mut a = Vec3::X - df * df[0];
            if a.dot(a) < 1e-12 {
                a = Vec3::Y;
            }
            let a = a.normalize();
            let b = df.cross(a).normalize();
            p = a * uv[0] + b * uv[1];
            d = (pf - p).normalize();
        }
        let wo = to_world.point_vec3(pano.to_blender_camera(p.into()).into());
        let wd = to_world
            .vector_vec3(pano.to_blender_camera(d.into()).into())
            .normalize();
        (
            wo + wd * self.clip_start,
            wd,
            0.0,
            self.clip_end - self.clip_start,
        )
    }

    /// Compact ray differentials (Cycles' ray.dP, ray.dD) of the ray through (x, y): the
    /// mean change of its origin and direction one pixel right and one pixel down.
    pub fn ray_differentials(&self, x: f32, y: f32, lens: [f32; 2]) -> (f32, f32) {
        let (o, d, ..) = self.ray_vec3(&self.to_world, x, y, lens);
        let (ox, dx, ..) = self.ray_vec3(&self.to_world, x + 1.0, y, lens);
        let (oy, dy, ..) = self.ray_vec3(&self.to_world, x, y + 1.0, lens);
        (
            0.5 * ((ox - o).length() + (oy - o).length()),
            0.5 * ((dx - d).length() + (dy - d).length()),
        )
    }

    fn sample_aperture(&self, u: [f32; 2]) -> [f32; 2] {
        let mut p = if self.blades < 3 {
            concentric_disk(u)
        } else {
            regular_polygon(self.blades, self.rotation, u)
        };
        // Anamorphic ratio stretches the bokeh as Cycles does.
        p[0] *= self.ratio.sqrt().max(1e-6);
        p[1] /= self.ratio.sqrt().max(1e-6);
        p
    }

    /// Where world point `w` lands on the image (the inverse of `ray`'s raster to
    /// viewplane mapping; Cycles' worldtoraster, or for a panorama its direction from the
    /// eye through direction_to_panorama): pixels, x right, y down from the top-left
    /// corner, in f64. None behind a perspective camera's eye plane and outside a
    /// panorama's lens.
    pub fn raster_of(&self, w: V3) -> Option<[f64; 2]> {
        let m = &self.to_world.m;
        if let Some(pano) = &self.panorama {
            let d = Vec3::from(w) - self.to_world.column_vec3(3);
            // Camera space: the transpose of the (scale-free) rotation.
            let c = |i: usize| m[0][i] * d[0] + m[1][i] * d[1] + m[2][i] * d[2];
            let [u, v] = pano.uv_of(pano.from_blender_camera([c(0), c(1), c(2)]))?;
            return Some(self.raster_of_viewplane(u as f64, v as f64));
        }
        let d = [
            w[0] as f64 - m[0][3] as f64,
            w[1] as f64 - m[1][3] as f64,
            w[2] as f64 - m[2][3] as f64,
        ];
        // Camera space: the transpose of the (scale-free) rotation.
        let c = |i: usize| m[0][i] as f64 * d[0] + m[1][i] as f64 * d[1] + m[2][i] as f64 * d[2];
        let (x, y, z) = (c(0), c(1), c(2));
        let (vx, vy) = if self.ortho {
            (x, y)
        } else {
            if !(z < 0.0) {
                return None;
            }
            let k = 1.0 / (-z * self.tan_half as f64);
            (x * k, y * k)
        };
        Some(self.raster_of_viewplane(vx, vy))
    }

    /// Raster position (pixels, y down) of viewplane point (vx, vy): `ray`'s mapping inverted.
    fn raster_of_viewplane(&self, vx: f64, vy: f64) -> [f64; 2] {
        let (l, r, b, t) = (
            self.left as f64,
            self.right as f64,
            self.bottom as f64,
            self.top as f64,
        );
        [
            (vx - l) / (r - l) * self.width as f64,
            (t - vy) / (t - b) * self.height as f64,
        ]
    }

    /// The camera-space Z distance of a world point (for the depth pass).
    pub fn depth(&self, w: V3) -> f32 {
        // Cycles' camera_z_depth: a panorama has no view axis, so its depth is the distance.
        if self.panorama.is_some() {
            return (Vec3::from(w) - self.to_world.column_vec3(3)).length();
        }
        let view = -self.to_world.column_vec3(2);
        (Vec3::from(w) - self.to_world.column_vec3(3)).dot(view)
    }

    /// Distance of world point `w` from the camera along its ray: from the eye for a
    /// perspective camera, from the view plane (the depth) for an orthographic one.
    pub fn distance(&self, w: V3) -> f32 {
        if self.ortho {
            self.depth(w)
        } else {
            (Vec3::from(w) - self.to_world.column_vec3(3)).length()
        }
    }
}

/// The transform with its axes normalised (Cycles clears camera scale).
fn without_scale(m: &Affine) -> Affine {
    let mut o = *m;
    for c in 0..3 {
        let l = m.column_vec3(c).length();
        if l > 0.0 {
            for r in 0..3 {
                o.m[r][c] /= l;
            }
        }
    }
    o
}

pub fn concentric_disk(u: [f32; 2]) -> [f32; 2] {
    let a = 2.0 * u[0] - 1.0;
    let b = 2.0 * u[1] - 1.0;
    if a == 0.0 && b == 0.0 {
        return [0.0, 0.0];
    }
    let (r, phi) = if a * a > b * b {
        (a, std::f32::consts::FRAC_PI_4 * (b / a))
    } else {
        (
            b,
            std::f32::consts::FRAC_PI_2 - std::f32::consts::FRAC_PI_4 * (a / b),
        )
    };
    [r * phi.cos(), r * phi.sin()]
}

/// Uniform point in a regular polygon inscribed in the unit circle.
fn regular_polygon(blades: u32, rotation: f32, u: [f32; 2]) -> [f32; 2] {
    let n = blades as f32;
    let k = ((u[0] * n) as u32).min(blades - 1);
    let u0 = u[0] * n - k as f32;
    let step = 2.0 * std::f32::consts::PI / n;
    let a0 = rotation + k as f32 * step;
    let a1 = a0 + step;
    let (p1, p2) = ([a0.cos(), a0.sin()], [a1.cos(), a1.sin()]);
    // Uniform in the triangle (centre, p1, p2).
    let s = u0.sqrt();
    let (b1, b2) = (s * (1.0 - u[1]), s * u[1]);
    [p1[0] * b1 + p2[0] * b2, p1[1] * b1 + p2[1] * b2]
}

impl Camera {
    /// The camera as the shader's texture-coordinate nodes see it (Cycles' world to
    /// camera and world to NDC transforms).
    pub fn view(&self) -> crate::shader::view::View {
        crate::shader::view::View::new(
            &self.to_world.m,
            self.ortho,
            self.tan_half,
            [self.left, self.right, self.bottom, self.top],
        )
    }
}
