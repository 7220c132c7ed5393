//! Rotation function nodes: Axis Angle to Rotation, Rotate Rotation, Align Rotation to
//! Vector, Align Euler to Vector, Rotate Euler and Axes to Rotation
//! (`function/nodes/node_fn_*`).

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{
    cross, euler_to_mat3, mat3_normalized_to_quat, mat3_to_euler, mat3_to_quat_checked, normalize,
    quat_to_mat3, Mat3f, V3,
};
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;
use super::instance_transform::{axis_angle_mat3, mat3_mul};

/// Hamilton product `a * b` (w, x, y, z): `b` applied first.
pub fn quat_mul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] + a[2] * b[0] + a[3] * b[1] - a[1] * b[3],
        a[0] * b[3] + a[3] * b[0] + a[1] * b[2] - a[2] * b[1],
    ]
}

/// A vector orthogonal to non-zero `v` (`get_orthogonal_of_non_zero_vector`).
fn orthogonal(v: V3) -> V3 {
    if v[0] != -v[1] {
        [-v[1], v[0], 0.0]
    } else if v[0] != -v[2] {
        [-v[2], 0.0, v[0]]
    } else {
        [0.0, -v[2], v[1]]
    }
}

fn axis_index(ctx: &NodeCtx, prop: &str) -> Result<usize, GeometryError> {
    match ctx.prop_str(prop)? {
        "X" => Ok(0),
        "Y" => Ok(1),
        "Z" => Ok(2),
        other => Err(ctx.err(format!("{prop} {other:?} is not an axis"))),
    }
}

/// Axes to Rotation (`node_fn_axes_to_rotation`): the primary axis exactly along
/// Primary, the secondary as close to Secondary as it can be, the third completing a
/// rotation; a zero input is replaced by an orthogonal of the other, both zero give the
/// identity. Equal axes give the node no function: the identity everywhere.
pub fn axes_to_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let (pa, sa) = (
        axis_index(ctx, "primary_axis")?,
        axis_index(ctx, "secondary_axis")?,
    );
    if pa == sa {
        let id = Field::Constant(super::super::types::Value::Quaternion([1.0, 0.0, 0.0, 0.0]));
        return Ok(outputs([("Rotation", SocketValue::Field(id))]));
    }
    let ta = 3 - pa - sa;
    // The third axis is flipped where needed for a determinant of 1.
    let third = if (sa + 1) % 3 == pa { -1.0 } else { 1.0 };
    let p = ctx.field("Primary Axis", DataType::Vector)?;
    let s = ctx.field("Secondary Axis", DataType::Vector)?;
    let is_zero = |v: V3| v == [0.0; 3];
    let f = Field::op1(
        "Axes to Rotation",
        vec![p, s],
        DataType::Quaternion,
        move |_, x| {
            let (ps, ss) = (x[0].as_vector(), x[1].as_vector());
            Ok(Array::Quaternion(
                ps.iter()
                    .zip(ss.iter())
                    .map(|(p, s)| {
                        let mut p = normalize(*p);
                        let mut s = *s;
                        let t;
                        match (!is_zero(p), !is_zero(s)) {
                            (true, true) => {
                                let mut c = cross(p, s);
                                if is_zero(c) {
                                    c = orthogonal(p);
                                }
                                t = normalize(c);
                                s = cross(t, p);
                            }
                            (true, false) => {
                                s = normalize(orthogonal(p));
                                t = cross(p, s);
                            }
                            (false, true) => {
                                s = normalize(s);
                                p = normalize(orthogonal(s));
                                t = cross(p, s);
                            }
                            (false, false) => return [1.0, 0.0, 0.0, 0.0],
                        }
                        let mut m: Mat3f = [[0.0; 3]; 3];
                        m[pa] = p;
                        m[sa] = s;
                        m[ta] = t.map(|x| x * third);
                        mat3_to_quat_checked(&m)
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

pub fn axis_angle_to_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let axis = ctx.field("Axis", DataType::Vector)?;
    let angle = ctx.field("Angle", DataType::Float)?;
    let f = Field::op1(
        "Axis Angle to Rotation",
        vec![axis, angle],
        DataType::Quaternion,
        |_, x| {
            let (ax, an) = (x[0].as_vector(), x[1].as_float());
            Ok(Array::Quaternion(
                ax.iter()
                    .zip(an.iter())
                    .map(|(a, t)| {
                        let n = normalize(*a);
                        let (s, c) = (t * 0.5).sin_cos();
                        [c, n[0] * s, n[1] * s, n[2] * s]
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

pub fn rotate_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let local = ctx.prop("rotation_space").and_then(|v| v.as_str()) == Some("LOCAL");
    let r = ctx.field("Rotation", DataType::Quaternion)?;
    let by = ctx.field("Rotate By", DataType::Quaternion)?;
    let f = Field::op1(
        "Rotate Rotation",
        vec![r, by],
        DataType::Quaternion,
        move |_, x| {
            let (r, by) = (x[0].as_quat(), x[1].as_quat());
            Ok(Array::Quaternion(
                r.iter()
                    .zip(by.iter())
                    .map(|(r, b)| {
                        if local {
                            quat_mul(*r, *b)
                        } else {
                            quat_mul(*b, *r)
                        }
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

fn axis_vector(name: &str) -> Option<V3> {
    match name {
        "X" => Some([1.0, 0.0, 0.0]),
        "Y" => Some([0.0, 1.0, 0.0]),
        "Z" => Some([0.0, 0.0, 1.0]),
        _ => None,
    }
}

fn mat3_vec(m: &Mat3f, v: V3) -> V3 {
    [0, 1, 2].map(|i| m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2])
}

/// `angle_normalized_v3v3`: the angle between unit vectors, accurate near 0 and pi.
pub(crate) fn angle_normalized(a: V3, b: V3) -> f32 {
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let len = |v: V3| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if d >= 0.0 {
        2.0 * (len([a[0] - b[0], a[1] - b[1], a[2] - b[2]]) / 2.0).asin()
    } else {
        std::f32::consts::PI - 2.0 * (len([a[0] + b[0], a[1] + b[1], a[2] + b[2]]) / 2.0).asin()
    }
}

fn cross_f64(a: V3, b: V3) -> V3 {
    let (a, b) = (a.map(|x| x as f64), b.map(|x| x as f64));
    [
        (a[1] * b[2] - a[2] * b[1]) as f32,
        (a[2] * b[0] - a[0] * b[2]) as f32,
        (a[0] * b[1] - a[1] * b[0]) as f32,
    ]
}

fn is_zero(v: V3) -> bool {
    v == [0.0; 3]
}

/// `project_plane_normalized_v3_v3v3`: `v` minus its part along unit `n`.
fn project_plane(v: V3, n: V3) -> V3 {
    let d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    [v[0] - n[0] * d, v[1] - n[1] * d, v[2] - n[2] * d]
}

/// `angle_signed_on_axis_v3v3_v3`: the angle from `v2` to `v1` about `axis`, in [0, 2 pi).
fn angle_signed_on_axis(v1: V3, v2: V3, axis: V3) -> f32 {
    let (p1, p2) = (project_plane(v1, axis), project_plane(v2, axis));
    let angle = angle_normalized(normalize(p1), normalize(p2));
    let t = cross_f64(p2, p1);
    if t[0] * axis[0] + t[1] * axis[1] + t[2] * axis[2] < 0.0 {
        std::f32::consts::PI * 2.0 - angle
    } else {
        angle
    }
}

/// The new rotation matrix aligning `main` of `old` to `vector` by `factor`
/// (`align_rotations_auto_pivot` / `align_rotations_fixed_pivot`); None keeps `old`.
fn align(old: &Mat3f, vector: V3, factor: f32, main: V3, pivot: Option<V3>) -> Option<Mat3f> {
    if is_zero(vector) {
        return None;
    }
    let old_axis = mat3_vec(old, main);
    let rot = match pivot {
        None => {
            let new_axis = normalize(vector);
            let mut axis = cross_f64(old_axis, new_axis);
            if is_zero(axis) {
                axis = cross_f64(old_axis, [1.0, 0.0, 0.0]);
                if is_zero(axis) {
                    axis = cross_f64(old_axis, [0.0, 1.0, 0.0]);
                }
            }
            axis_angle_mat3(axis, factor * angle_normalized(old_axis, new_axis))
        }
        Some(p) => {
            if p == main {
                return None;
            }
            let pivot_axis = mat3_vec(old, p);
            let mut full = angle_signed_on_axis(vector, old_axis, pivot_axis);
            if full > std::f32::consts::PI {
                full -= 2.0 * std::f32::consts::PI;
            }
            axis_angle_mat3(pivot_axis, factor * full)
        }
    };
    Some(mat3_mul(&rot, old))
}

fn align_settings(ctx: &NodeCtx) -> Result<(V3, Option<V3>), GeometryError> {
    let main = axis_vector(ctx.prop_str("axis")?).ok_or_else(|| ctx.err("unknown axis"))?;
    let pivot = match ctx.prop_str("pivot_axis")? {
        "AUTO" => None,
        other => Some(axis_vector(other).ok_or_else(|| ctx.err("unknown pivot axis"))?),
    };
    Ok((main, pivot))
}

pub fn align_euler_to_vector(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let (main, pivot) = align_settings(ctx)?;
    let ins = vec![
        ctx.field("Rotation", DataType::Vector)?,
        ctx.field("Factor", DataType::Float)?,
        ctx.field("Vector", DataType::Vector)?,
    ];
    let f = Field::op1(
        "Align Euler to Vector",
        ins,
        DataType::Vector,
        move |_, x| {
            let (r, fac, v) = (x[0].as_vector(), x[1].as_float(), x[2].as_vector());
            Ok(Array::Vector(
                (0..r.len())
                    .map(|i| {
                        align(&euler_to_mat3(r[i]), v[i], fac[i], main, pivot)
                            .map_or(r[i], |m| mat3_to_euler(&m))
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

pub fn align_rotation_to_vector(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let (main, pivot) = align_settings(ctx)?;
    let ins = vec![
        ctx.field("Rotation", DataType::Quaternion)?,
        ctx.field("Factor", DataType::Float)?,
        ctx.field("Vector", DataType::Vector)?,
    ];
    let f = Field::op1(
        "Align Rotation to Vector",
        ins,
        DataType::Quaternion,
        move |_, x| {
            let (r, fac, v) = (x[0].as_quat(), x[1].as_float(), x[2].as_vector());
            Ok(Array::Quaternion(
                (0..r.len())
                    .map(|i| {
                        align(&quat_to_mat3(r[i]), v[i], fac[i], main, pivot)
                            .map_or(r[i], |m| mat3_normalized_to_quat(&m))
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

/// Rotate Euler (`node_fn_rotate_euler.cc`, deprecated but in old files): the Euler
/// Rotation turned by an Euler or an axis and angle, in object space (the turn applied
/// after) or local space (before), back to Euler angles.
pub fn rotate_euler(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let axis_angle = ctx.prop("rotation_type").and_then(|v| v.as_str()) == Some("AXIS_ANGLE");
    let local = ctx.prop("space").and_then(|v| v.as_str()) == Some("LOCAL");
    let mut inputs = vec![ctx.field("Rotation", DataType::Vector)?];
    if axis_angle {
        inputs.push(ctx.field("Axis", DataType::Vector)?);
        inputs.push(ctx.field("Angle", DataType::Float)?);
    } else {
        inputs.push(ctx.field("Rotate By", DataType::Vector)?);
    }
    let f = Field::op1("Rotate Euler", inputs, DataType::Vector, move |n, x| {
        let input = x[0].as_vector();
        let by = x[1].as_vector();
        let angle = if axis_angle {
            x[2].as_float().to_vec()
        } else {
            vec![0.0; n]
        };
        Ok(Array::Vector(
            (0..n)
                .map(|i| {
                    let m = euler_to_mat3(input[i]);
                    let r = if axis_angle {
                        // `axis_angle_to_mat3`: a zero axis is no rotation.
                        let a = by[i];
                        if a[0] * a[0] + a[1] * a[1] + a[2] * a[2] == 0.0 {
                            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
                        } else {
                            axis_angle_mat3(a, angle[i])
                        }
                    } else {
                        euler_to_mat3(by[i])
                    };
                    let res = if local {
                        mat3_mul(&m, &r)
                    } else {
                        mat3_mul(&r, &m)
                    };
                    mat3_to_euler(&normalized(&res))
                })
                .collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

/// Each column scaled to unit length (`mat3_to_eul` normalizes before converting).
fn normalized(m: &Mat3f) -> Mat3f {
    [normalize(m[0]), normalize(m[1]), normalize(m[2])]
}

/// Invert Rotation: the conjugate (`invert_normalized`).
pub fn invert_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx.field("Rotation", DataType::Quaternion)?;
    let f = Field::op1("Invert Rotation", vec![r], DataType::Quaternion, |_, x| {
        Ok(Array::Quaternion(
            x[0].as_quat()
                .iter()
                .map(|q| [q[0], -q[1], -q[2], -q[3]])
                .collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

/// Quaternion to Rotation: the components, normalized.
pub fn quaternion_to_rotation(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let inputs = ["W", "X", "Y", "Z"]
        .iter()
        .map(|k| ctx.field(k, DataType::Float))
        .collect::<Result<Vec<_>, _>>()?;
    let f = Field::op1(
        "Quaternion to Rotation",
        inputs,
        DataType::Quaternion,
        |n, x| {
            let c: Vec<_> = x.iter().map(|a| a.as_float()).collect();
            Ok(Array::Quaternion(
                (0..n)
                    .map(|i| {
                        let q = [c[0][i], c[1][i], c[2][i], c[3][i]];
                        let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
                        let inv = if len != 0.0 { 1.0 / len } else { 0.0 };
                        q.map(|v| v * inv)
                    })
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Rotation", SocketValue::Field(f))]))
}

pub fn rotation_to_quaternion(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx.field("Rotation", DataType::Quaternion)?;
    let fs = Field::op(
        "Rotation to Quaternion",
        vec![r],
        vec![DataType::Float; 4],
        |_, x| {
            let q = x[0].as_quat();
            Ok((0..4)
                .map(|k| Array::Float(q.iter().map(|q| q[k]).collect()))
                .collect())
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(["W", "X", "Y", "Z"]
        .iter()
        .zip(fs)
        .map(|(k, f)| (k.to_string(), SocketValue::Field(f)))
        .collect())
}

/// `math::to_axis_angle(Quaternion)`: the vector part over sin(angle / 2), the angle
/// 2 atan2(sin, cos) of the halves; below a sine of 0.0005 the identity, +Y and 0 (as
/// Blender 4.5 gives it, fixture `rotation_matrix`).
fn to_axis_angle(q: [f32; 4]) -> (V3, f32) {
    let axis = [q[1], q[2], q[3]];
    let sin_half = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if sin_half < 0.0005 {
        return ([0.0, 1.0, 0.0], 0.0);
    }
    let axis = axis.map(|v| v / sin_half);
    (axis, sin_half.atan2(q[0]) * 2.0)
}

pub fn rotation_to_axis_angle(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let r = ctx.field("Rotation", DataType::Quaternion)?;
    let fs = Field::op(
        "Rotation to Axis Angle",
        vec![r],
        vec![DataType::Vector, DataType::Float],
        |_, x| {
            let (axes, angles): (Vec<V3>, Vec<f32>) =
                x[0].as_quat().iter().map(|q| to_axis_angle(*q)).unzip();
            Ok(vec![Array::Vector(axes), Array::Float(angles)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fs.into_iter();
    Ok(outputs([
        ("Axis", SocketValue::Field(it.next().unwrap())),
        ("Angle", SocketValue::Field(it.next().unwrap())),
    ]))
}
