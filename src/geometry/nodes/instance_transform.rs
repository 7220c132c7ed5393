//! Translate, Rotate and Scale Instances: change the selected instances' transforms in
//! world space or in each instance's own space (`node_geo_{translate,rotate,scale}_instances`);
//! Set Instance Transform replaces them (`node_geo_set_instance_transform`).

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::math::{
    mat3_to_mat4, mat4_mul, normalize, quat_to_mat3, transform_point, translation, Mat3f, Mat4f, V3,
};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

/// Evaluates `fields` on the instances and applies `f(transform, values, i)` to each selected one.
fn modify(
    ctx: &NodeCtx,
    fields: &[(&str, DataType)],
    f: &dyn Fn(&mut Mat4f, &[Array], usize),
) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Instances")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let fs: Vec<(Field, DataType)> = fields
        .iter()
        .map(|(id, t)| Ok((ctx.field(id, *t)?, *t)))
        .collect::<Result<_, GeometryError>>()?;
    if let Some(inst) = g.instances.clone() {
        let fctx = super::super::field::FieldContext::new(ComponentRef::Instances(&inst));
        let sel = fctx
            .eval(&sel, Domain::Instance, DataType::Bool)
            .map_err(|e| ctx.err(e))?;
        let vals: Vec<Array> = fs
            .iter()
            .map(|(f, t)| fctx.eval(f, Domain::Instance, *t))
            .collect::<Result<_, String>>()
            .map_err(|e| ctx.err(e))?;
        let sel = sel.as_bool();
        let im = g.instances_mut().unwrap();
        for i in 0..im.transforms.len() {
            if sel[i] {
                f(&mut im.transforms[i], &vals, i);
            }
        }
    }
    Ok(outputs([("Instances", SocketValue::Geometry(g))]))
}

/// Set Instance Transform: the selected instances take Transform (unlinked: their own).
pub fn set_instance_transform(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    modify(ctx, &[("Transform", DataType::Matrix)], &|m, v, i| {
        *m = v[0].as_matrix()[i];
    })
}

pub fn translate_instances(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    modify(
        ctx,
        &[
            ("Translation", DataType::Vector),
            ("Local Space", DataType::Bool),
        ],
        &|m, v, i| {
            let t = v[0].as_vector()[i];
            if v[1].as_bool()[i] {
                *m = mat4_mul(m, &translation(t));
            } else {
                for k in 0..3 {
                    m[3][k] += t[k];
                }
            }
        },
    )
}

/// `m * diag(s)`: scales the axes (`rescale_m4`).
fn scale_axes(m: &Mat4f, s: V3) -> Mat4f {
    let mut r = *m;
    for c in 0..3 {
        for k in 0..4 {
            r[c][k] *= s[c];
        }
    }
    r
}

pub fn scale_instances(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    modify(
        ctx,
        &[
            ("Scale", DataType::Vector),
            ("Center", DataType::Vector),
            ("Local Space", DataType::Bool),
        ],
        &|m, v, i| {
            let (s, p) = (v[0].as_vector()[i], v[1].as_vector()[i]);
            let neg = [-p[0], -p[1], -p[2]];
            if v[2].as_bool()[i] {
                *m = mat4_mul(
                    &scale_axes(&mat4_mul(m, &translation(p)), s),
                    &translation(neg),
                );
            } else {
                let around = mat4_mul(&scale_axes(&translation(p), s), &translation(neg));
                *m = mat4_mul(&around, m);
            }
        },
    )
}

/// Rotation by `angle` about unit `axis` (`axis_angle_to_mat3`), `m[col][row]`.
pub fn axis_angle_mat3(axis: V3, angle: f32) -> Mat3f {
    let a = normalize(axis);
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let [x, y, z] = a;
    [
        [t * x * x + c, t * x * y + s * z, t * x * z - s * y],
        [t * x * y - s * z, t * y * y + c, t * y * z + s * x],
        [t * x * z + s * y, t * y * z - s * x, t * z * z + c],
    ]
}

pub fn mat3_mul(a: &Mat3f, b: &Mat3f) -> Mat3f {
    let mut r = [[0.0f32; 3]; 3];
    for j in 0..3 {
        for i in 0..3 {
            r[j][i] = a[0][i] * b[j][0] + a[1][i] * b[j][1] + a[2][i] * b[j][2];
        }
    }
    r
}

pub fn rotate_instances(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    modify(
        ctx,
        &[
            ("Rotation", DataType::Quaternion),
            ("Pivot Point", DataType::Vector),
            ("Local Space", DataType::Bool),
        ],
        &|m, v, i| {
            let (q, p) = (v[0].as_quat()[i], v[1].as_vector()[i]);
            let (rot, pivot) = if v[2].as_bool()[i] {
                // The rotation expressed about the instance's own (normalized) axes.
                let axes: Mat3f = [0, 1, 2].map(|c| normalize([m[c][0], m[c][1], m[c][2]]));
                let mut inv = [[0.0f32; 3]; 3];
                for a in 0..3 {
                    for b in 0..3 {
                        inv[a][b] = axes[b][a];
                    }
                }
                (
                    mat3_mul(&mat3_mul(&axes, &quat_to_mat3(q)), &inv),
                    transform_point(m, p),
                )
            } else {
                (quat_to_mat3(q), p)
            };
            for k in 0..3 {
                m[3][k] -= pivot[k];
            }
            *m = mat4_mul(&mat3_to_mat4(&rot), m);
            for k in 0..3 {
                m[3][k] += pivot[k];
            }
        },
    )
}
