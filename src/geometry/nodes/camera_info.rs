//! Camera Info (`node_geo_camera_info`): a camera's projection matrix, focal length,
//! sensor and shift, clip range, focus distance and orthographic settings, from the
//! camera data at the frame (animated values included). The projection is
//! `BKE_camera_params_compute_viewplane` / `_compute_matrix` on the scene's resolution
//! (without its percentage) and pixel aspect, in single precision as Blender computes it. No object or a non-camera object gives the outputs' defaults (for
//! the latter Blender also shows "Object is not a camera").

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{Mat4f, MAT4_IDENTITY};
use super::super::types::Value;
use super::super::value::SocketValue;
use crate::scene::settings::{CameraSettings, Output, Projection, SensorFit};

const OUTPUTS: [&str; 9] = [
    "Projection Matrix",
    "Focal Length",
    "Sensor",
    "Shift",
    "Clip Start",
    "Clip End",
    "Focus Distance",
    "Is Orthographic",
    "Orthographic Scale",
];

/// `BKE_camera_sensor_fit`: Auto fits the longer side.
fn horizontal_fit(fit: SensorFit, x: f32, y: f32) -> bool {
    match fit {
        SensorFit::Auto => x >= y,
        SensorFit::Horizontal => true,
        SensorFit::Vertical => false,
    }
}

/// `BKE_camera_sensor_size`: the sensor side the fit uses (Auto: the width).
fn sensor_size(c: &CameraSettings) -> f32 {
    match c.sensor_fit {
        SensorFit::Vertical => c.sensor_height as f32,
        _ => c.sensor_width as f32,
    }
}

/// The window matrix Blender's camera parameters give (`winmat`).
fn projection(
    c: &CameraSettings,
    ortho: bool,
    winx: i32,
    winy: i32,
    xasp: f32,
    yasp: f32,
) -> Mat4f {
    let ycor = yasp / xasp;
    let (clip_start, clip_end) = (c.clip_start as f32, c.clip_end as f32);
    let mut pixsize = if ortho {
        c.ortho_scale as f32
    } else {
        sensor_size(c) * clip_start / c.lens as f32
    };
    let viewfac = if horizontal_fit(c.sensor_fit, xasp * winx as f32, yasp * winy as f32) {
        winx as f32
    } else {
        ycor * winy as f32
    };
    pixsize /= viewfac;
    // The camera's zoom factor is 1 (CAMERA_PARAM_ZOOM_INIT_CAMOB) and it has no offset.
    let dx = c.shift_x as f32 * viewfac;
    let dy = c.shift_y as f32 * viewfac;
    let xmin = (-0.5 * winx as f32 + dx) * pixsize;
    let xmax = (0.5 * winx as f32 + dx) * pixsize;
    let ymin = (-0.5 * ycor * winy as f32 + dy) * pixsize;
    let ymax = (0.5 * ycor * winy as f32 + dy) * pixsize;
    let (xd, yd, zd) = (xmax - xmin, ymax - ymin, clip_end - clip_start);
    let mut m = [[0.0f32; 4]; 4];
    if xd == 0.0 || yd == 0.0 || zd == 0.0 {
        // Blender leaves the matrix as initialised (zeros) in this case.
        return m;
    }
    if ortho {
        m = MAT4_IDENTITY;
        m[0][0] = 2.0 / xd;
        m[3][0] = -(xmax + xmin) / xd;
        m[1][1] = 2.0 / yd;
        m[3][1] = -(ymax + ymin) / yd;
        m[2][2] = -2.0 / zd;
        m[3][2] = -(clip_end + clip_start) / zd;
    } else {
        m[0][0] = clip_start * 2.0 / xd;
        m[1][1] = clip_start * 2.0 / yd;
        m[2][0] = (xmax + xmin) / xd;
        m[2][1] = (ymax + ymin) / yd;
        m[2][2] = -(clip_end + clip_start) / zd;
        m[2][3] = -1.0;
        m[3][2] = (-2.0 * clip_start * clip_end) / zd;
    }
    m
}

fn value(v: Value) -> SocketValue {
    SocketValue::Field(Field::Constant(v))
}

pub fn camera_info(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let defaults = || -> Outputs {
        ctx.node()
            .outputs
            .iter()
            .map(|s| {
                let v = if s.kind == "MATRIX" {
                    value(Value::Matrix(MAT4_IDENTITY))
                } else {
                    SocketValue::zero(&s.kind)
                };
                (s.identifier.clone(), v)
            })
            .collect()
    };
    let SocketValue::Object(obj) = ctx.input("Camera")? else {
        return Err(ctx.err("Camera input is not an object"));
    };
    let Some(name) = obj else {
        return Ok(defaults());
    };
    let session = ctx.session();
    let object = session
        .scene
        .object(&name)
        .ok_or_else(|| ctx.err(format!("object {name:?} is not in the export")))?;
    if object.kind != "CAMERA" {
        return Ok(defaults());
    }
    let data = object.data.as_deref().unwrap_or(&name);
    let cam = session
        .cameras
        .iter()
        .find(|c| c.name == data)
        .ok_or_else(|| ctx.err(format!("camera data {data:?} is not in the export")))?;
    let c = CameraSettings::of(cam);
    let ortho = c.projection == Some(Projection::Orthographic);
    let out = Output::of(&session.scene.file.scene);
    let (xasp, yasp) = (out.pixel_aspect_x as f32, out.pixel_aspect_y as f32);
    let winmat = projection(
        &c,
        ortho,
        out.resolution_x as i32,
        out.resolution_y as i32,
        xasp,
        yasp,
    );
    // Blender 4.5 outputs the camera's own sensor size and shift (not fitted to the
    // render's aspect, as later versions do).
    let sensor = [c.sensor_width as f32, c.sensor_height as f32, 0.0];
    let shift = [c.shift_x as f32, c.shift_y as f32, 0.0];
    let focus = focus_distance(ctx, &name, &c)?;
    let values = [
        Value::Matrix(winmat),
        Value::Float(c.lens as f32),
        Value::Vector(sensor),
        Value::Vector(shift),
        Value::Float(c.clip_start as f32),
        Value::Float(c.clip_end as f32),
        Value::Float(focus),
        Value::Bool(ortho),
        Value::Float(c.ortho_scale as f32),
    ];
    Ok(OUTPUTS
        .iter()
        .zip(values)
        .map(|(k, v)| (k.to_string(), value(v)))
        .collect())
}

/// `BKE_camera_object_dof_distance`: the focus object's distance along the camera's
/// view axis when one is set (whether or not depth of field is on), else the distance.
fn focus_distance(ctx: &NodeCtx, camera: &str, c: &CameraSettings) -> Result<f32, GeometryError> {
    let Some(dof) = &c.dof else {
        return Ok(10.0);
    };
    let Some(target) = &dof.focus_object else {
        return Ok(dof.focus_distance as f32);
    };
    if !dof.focus_subtarget.is_empty() {
        return Err(ctx.err(format!(
            "camera {camera:?} focuses on bone {:?} of {target:?}: focus on a bone is not supported",
            dof.focus_subtarget
        )));
    }
    let session = ctx.session();
    let world = |n: &str| {
        session
            .world_matrix(n)
            .ok_or_else(|| ctx.err(format!("object {n:?} is not in the export")))
    };
    let (cm, tm) = (world(camera)?, world(target)?);
    let z = cm[2];
    let d2 = z[0] * z[0] + z[1] * z[1] + z[2] * z[2];
    let len = d2.sqrt();
    // normalize_v3_v3: a multiply by the reciprocal length.
    let view = if d2 > 1e-35 {
        let r = 1.0 / len;
        [z[0] * r, z[1] * r, z[2] * r]
    } else {
        [0.0; 3]
    };
    let d = [
        cm[3][0] - tm[3][0],
        cm[3][1] - tm[3][1],
        cm[3][2] - tm[3][2],
    ];
    Ok((view[0] * d[0] + view[1] * d[1] + view[2] * d[2]).abs())
}
