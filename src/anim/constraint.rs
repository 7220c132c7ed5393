//! Object constraints as Blender's `constraint.cc` solves them, in world space: Follow
//! Path, Track To and Damped Track. Anything else is an error naming the constraint,
//! never skipped: a skipped constraint would put the object somewhere else than Blender.

use super::error::AnimError;
use super::math::*;
use super::path::Path;
use crate::scene::{Constraint, Curve, Rna};

#[derive(Debug, Clone)]
pub enum Kind {
    FollowPath {
        target: String,
        use_follow: bool,
        use_radius: bool,
        fixed: bool,
        offset: f32,
        offset_factor: f32,
        forward: i32,
        up: i32,
    },
    TrackTo {
        target: String,
        track: i32,
        up: i32,
        target_z: bool,
    },
    DampedTrack {
        target: String,
        track: i32,
    },
}

/// A constraint ready to solve, with its influence.
#[derive(Debug, Clone)]
pub struct Parsed {
    pub kind: Kind,
    pub influence: f64,
}

impl Parsed {
    pub fn target(&self) -> &str {
        match &self.kind {
            Kind::FollowPath { target, .. }
            | Kind::TrackTo { target, .. }
            | Kind::DampedTrack { target, .. } => target,
        }
    }
}

fn s<'a>(p: &'a Rna, k: &str) -> Result<&'a str, AnimError> {
    p.get(k)
        .and_then(|v| v.as_str())
        .ok_or_else(|| AnimError::new(format!("properties.{k}"), "missing or not a string"))
}
fn f(p: &Rna, k: &str) -> Result<f32, AnimError> {
    p.get(k)
        .and_then(|v| v.as_f64())
        .map(|v| v as f32)
        .ok_or_else(|| AnimError::new(format!("properties.{k}"), "missing or not a number"))
}
fn b(p: &Rna, k: &str) -> Result<bool, AnimError> {
    p.get(k)
        .and_then(|v| v.as_bool())
        .ok_or_else(|| AnimError::new(format!("properties.{k}"), "missing or not a boolean"))
}

/// The target object's name, None when unset (Blender then leaves the owner alone).
fn target(p: &Rna) -> Result<Option<String>, AnimError> {
    match p.get("target") {
        None | Some(serde_json::Value::Null) => Ok(None),
        Some(v) => {
            let name = v
                .get("name")
                .and_then(|n| n.as_str())
                .ok_or_else(|| AnimError::new("properties.target", "not an ID reference"))?;
            if v.get("id_type")
                .and_then(|t| t.as_str())
                .is_some_and(|t| t != "OBJECT")
            {
                return Err(AnimError::new("properties.target", "is not an object"));
            }
            Ok(Some(name.to_string()))
        }
    }
}

fn track_axis(v: &str) -> Result<i32, AnimError> {
    Ok(match v {
        "TRACK_X" | "FORWARD_X" => 0,
        "TRACK_Y" | "FORWARD_Y" => 1,
        "TRACK_Z" | "FORWARD_Z" => 2,
        "TRACK_NEGATIVE_X" => 3,
        "TRACK_NEGATIVE_Y" => 4,
        "TRACK_NEGATIVE_Z" => 5,
        other => return Err(AnimError::new("", format!("unknown track axis {other:?}"))),
    })
}

fn up_axis(v: &str) -> Result<i32, AnimError> {
    Ok(match v {
        "UP_X" => 0,
        "UP_Y" => 1,
        "UP_Z" => 2,
        other => return Err(AnimError::new("", format!("unknown up axis {other:?}"))),
    })
}

/// Parses a constraint; None when Blender would skip it (muted, disabled, zero influence,
/// no target).
pub fn parse(c: &Constraint) -> Result<Option<Parsed>, AnimError> {
    let p = &c.properties;
    let disabled = p.get("is_valid").and_then(|v| v.as_bool()) == Some(false);
    if c.mute || disabled || c.influence == 0.0 {
        return Ok(None);
    }
    for space in ["owner_space", "target_space"] {
        if let Some(sp) = p.get(space).and_then(|v| v.as_str()) {
            if sp != "WORLD" {
                return Err(AnimError::new(
                    format!("properties.{space}"),
                    format!("{sp:?} space is not supported (only WORLD)"),
                ));
            }
        }
    }
    let kind = match c.kind.as_str() {
        "FOLLOW_PATH" => {
            let Some(t) = target(p)? else { return Ok(None) };
            Kind::FollowPath {
                target: t,
                use_follow: b(p, "use_curve_follow")?,
                use_radius: b(p, "use_curve_radius")?,
                fixed: b(p, "use_fixed_location")?,
                offset: f(p, "offset")?,
                offset_factor: f(p, "offset_factor")?,
                forward: track_axis(s(p, "forward_axis")?)
                    .map_err(|e| e.within("properties.forward_axis"))?,
                up: up_axis(s(p, "up_axis")?).map_err(|e| e.within("properties.up_axis"))?,
            }
        }
        "TRACK_TO" | "DAMPED_TRACK" => {
            let Some(t) = target(p)? else { return Ok(None) };
            if p.get("subtarget")
                .and_then(|v| v.as_str())
                .is_some_and(|v| !v.is_empty())
            {
                return Err(AnimError::new(
                    "properties.subtarget",
                    "bone or vertex group sub-targets are not supported",
                ));
            }
            let track =
                track_axis(s(p, "track_axis")?).map_err(|e| e.within("properties.track_axis"))?;
            if c.kind == "TRACK_TO" {
                Kind::TrackTo {
                    target: t,
                    track,
                    up: up_axis(s(p, "up_axis")?).map_err(|e| e.within("properties.up_axis"))?,
                    target_z: b(p, "use_target_z")?,
                }
            } else {
                Kind::DampedTrack { target: t, track }
            }
        }
        other => {
            return Err(AnimError::new(
                "type",
                format!("constraint type {other:?} is not supported"),
            ))
        }
    };
    Ok(Some(Parsed {
        kind,
        influence: c.influence,
    }))
}

/// The Follow Path target matrix: the curve object's world matrix times the point (and,
/// with follow, the orientation; with radius, the scale) on its path.
pub fn follow_path_target(
    kind: &Kind,
    curve: &Curve,
    curve_world: &Mat4,
    path: Option<&Path>,
) -> Mat4 {
    let Kind::FollowPath {
        use_follow,
        use_radius,
        fixed,
        offset,
        offset_factor,
        forward,
        up,
        ..
    } = *kind
    else {
        return IDENTITY;
    };
    let Some(path) = path else { return IDENTITY };
    let ctime = if fixed {
        offset_factor
    } else {
        let eval_time = curve
            .properties
            .get("eval_time")
            .and_then(|v| v.as_f64())
            .unwrap_or(0.0) as f32;
        // path_duration is a short in Blender: an integer divisor.
        let pathlen = curve
            .properties
            .get("path_duration")
            .and_then(|v| v.as_f64())
            .unwrap_or(100.0) as i32 as f32;
        let mut t = (eval_time - offset) / pathlen;
        let first_cyclic = curve.splines.first().is_some_and(|s| s.use_cyclic_u);
        let clamp = curve
            .properties
            .get("use_path_clamp")
            .and_then(|v| v.as_bool())
            .unwrap_or(false);
        if !first_cyclic && clamp {
            t = t.clamp(0.0, 1.0);
        }
        t
    };
    let sample = path.sample(ctime);
    let mut tot = IDENTITY;
    if use_follow {
        let q = quat_apply_track(sample.quat, forward, up);
        tot = mat3_to_mat4(&quat_to_mat3_64([
            q[0] as f64,
            q[1] as f64,
            q[2] as f64,
            q[3] as f64,
        ]));
        // Blender's quat_to_mat4 rounds to float.
        for row in tot.iter_mut().take(3) {
            for v in row.iter_mut().take(3) {
                *v = *v as f32 as f64;
            }
        }
    }
    if use_radius {
        let r = sample.radius as f64;
        for row in tot.iter_mut().take(3) {
            for v in row.iter_mut().take(3) {
                *v *= r;
            }
        }
    }
    set_translation(
        &mut tot,
        [
            sample.pos[0] as f64,
            sample.pos[1] as f64,
            sample.pos[2] as f64,
        ],
    );
    mul(curve_world, &tot)
}

/// Blender's `followpath_evaluate`: applies the target matrix, then restores the owner's
/// scale unless the curve radius is meant to scale it.
pub fn follow_path(kind: &Kind, owner: &Mat4, target: &Mat4) -> Mat4 {
    let use_radius = matches!(
        kind,
        Kind::FollowPath {
            use_radius: true,
            ..
        }
    );
    let size = [axis_len(owner, 0), axis_len(owner, 1), axis_len(owner, 2)];
    let mut m = mul(target, owner);
    if !use_radius {
        for (i, s) in size.iter().enumerate() {
            let obsize = axis_len(&m, i);
            if obsize != 0.0 {
                scale_axis(&mut m, i, s / obsize);
            }
        }
    }
    m
}

fn basis_cross(n: i32, m: i32) -> f64 {
    match n - m {
        1 | -2 => 1.0,
        -1 | 2 => -1.0,
        _ => 0.0,
    }
}

/// Blender's `vectomat`: columns with the track axis along `vec` and the up axis as close
/// to `target_up` (or world Z) as possible.
fn vectomat(vec: [f64; 3], target_up: [f64; 3], axis: i32, upflag: i32, target_z: bool) -> Mat3 {
    let mut n = vec;
    if normalize64(&mut n) == 0.0 {
        n = [0.0, 0.0, 1.0];
    }
    let axis = if axis > 2 {
        axis - 3
    } else {
        n = [-n[0], -n[1], -n[2]];
        axis
    };
    let u = if target_z { target_up } else { [0.0, 0.0, 1.0] };
    let k = dot64(u, n) / dot64(n, n);
    let mut proj = sub64(u, [n[0] * k, n[1] * k, n[2] * k]);
    if normalize64(&mut proj) == 0.0 {
        proj = [0.0, 1.0, 0.0];
    }
    let mut right = cross64(proj, n);
    normalize64(&mut right);
    let mut m = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if axis != upflag {
        let right_index = (3 - axis - upflag) as usize;
        let neg = basis_cross(axis, upflag);
        for r in 0..3 {
            m[r][right_index] = neg * right[r];
            m[r][upflag as usize] = proj[r];
            m[r][axis as usize] = n[r];
        }
    }
    m
}

/// Replaces the 3x3 part of `m` with `a * m3x3`, keeping the translation.
fn premul_rotation(a: &Mat3, m: &Mat4) -> Mat4 {
    let r = mul3(a, &mat4_to_mat3(m));
    let mut out = mat3_to_mat4(&r);
    set_translation(&mut out, translation(m));
    out
}

pub fn track_to(kind: &Kind, owner: &Mat4, target: &Mat4) -> Mat4 {
    let Kind::TrackTo {
        track,
        up,
        target_z,
        ..
    } = *kind
    else {
        return *owner;
    };
    let size = [axis_len(owner, 0), axis_len(owner, 1), axis_len(owner, 2)];
    // Clear the rotation, keep the (world) scale.
    let mut m = *owner;
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] = if r == c { size[r] } else { 0.0 };
        }
    }
    let vec = sub64(translation(&m), translation(target));
    let tot = vectomat(vec, column(target, 2), track, up, target_z);
    premul_rotation(&tot, &m)
}

const TRACK_DIRS: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [-1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, -1.0],
];

fn mul3v(m: &Mat4, v: [f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

fn axis_angle_normalized_to_mat3(axis: [f64; 3], angle: f64) -> Mat3 {
    let (s, c) = angle.sin_cos();
    let ico = 1.0 - c;
    let nsi = [axis[0] * s, axis[1] * s, axis[2] * s];
    let n00 = axis[0] * axis[0] * ico;
    let n01 = axis[0] * axis[1] * ico;
    let n11 = axis[1] * axis[1] * ico;
    let n02 = axis[0] * axis[2] * ico;
    let n12 = axis[1] * axis[2] * ico;
    let n22 = axis[2] * axis[2] * ico;
    [
        [n00 + c, n01 - nsi[2], n02 + nsi[1]],
        [n01 + nsi[2], n11 + c, n12 - nsi[0]],
        [n02 - nsi[1], n12 + nsi[0], n22 + c],
    ]
}

/// Blender's `damptrack_do_transform`: the smallest rotation that points the track axis at
/// the target.
pub fn damped_track(kind: &Kind, owner: &Mat4, target: &Mat4) -> Mat4 {
    let Kind::DampedTrack { track, .. } = *kind else {
        return *owner;
    };
    let track = track as usize;
    let mut tarvec = sub64(translation(target), translation(owner));
    if normalize64(&mut tarvec) == 0.0 {
        return *owner;
    }
    let mut obvec = mul3v(owner, TRACK_DIRS[track]);
    if normalize64(&mut obvec) == 0.0 {
        obvec = TRACK_DIRS[track];
    }
    let mut raxis = cross64(obvec, tarvec);
    let mut rangle = dot64(obvec, tarvec).clamp(-1.0, 1.0).acos();
    let norm = normalize64(&mut raxis);
    let pi = std::f64::consts::PI;
    if norm < f32::EPSILON as f64 {
        // Opposite vectors: rotate half a turn about another local axis.
        if rangle.abs() < pi - 0.01 {
            return *owner;
        }
        rangle = pi;
        let tmp = mul3v(owner, TRACK_DIRS[(track + 1) % 6]);
        raxis = cross64(obvec, tmp);
        if normalize64(&mut raxis) == 0.0 {
            return *owner;
        }
    } else if norm < 0.1 {
        // asin is more precise than acos near 0 and pi.
        rangle = if rangle > std::f64::consts::FRAC_PI_2 {
            pi - norm.asin()
        } else {
            norm.asin()
        };
    }
    let rmat = axis_angle_normalized_to_mat3(raxis, rangle);
    premul_rotation(&rmat, owner)
}
