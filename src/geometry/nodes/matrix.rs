//! Transform (4x4 matrix) function nodes (`function/nodes/node_fn_*`): Combine / Separate
//! Transform, Transform Point / Direction, Project Point, Invert, Multiply and Transpose
//! Matrices, Matrix Determinant, Combine / Separate Matrix. Matrices are column-major as
//! Blender's `float4x4`.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{
    euler_to_quat, from_loc_rot_scale, mat3_to_euler, mat4_invert, mat4_mul, transform_direction,
    transform_point, Mat3f, Mat4f,
};
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;

fn field_out(name: &str, f: Field) -> Outputs {
    outputs([(name, SocketValue::Field(f))])
}

pub fn combine_transform(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = Field::op1(
        "Combine Transform",
        vec![
            ctx.field("Translation", DataType::Vector)?,
            ctx.field("Rotation", DataType::Quaternion)?,
            ctx.field("Scale", DataType::Vector)?,
        ],
        DataType::Matrix,
        |n, x| {
            let (t, r, s) = (x[0].as_vector(), x[1].as_quat(), x[2].as_vector());
            Ok(Array::Matrix(
                (0..n)
                    .map(|i| from_loc_rot_scale(t[i], r[i], s[i]))
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(field_out("Transform", f))
}

/// The 3x3 part with its columns normalized, and their lengths (`normalize_and_get_size`).
fn normalize_and_get_size(m: &Mat4f) -> (Mat3f, [f32; 3]) {
    let mut r = [[0.0f32; 3]; 3];
    let mut s = [0.0f32; 3];
    for c in 0..3 {
        let v = [m[c][0], m[c][1], m[c][2]];
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        s[c] = len;
        if len > 0.0 {
            let inv = 1.0 / len;
            r[c] = v.map(|x| x * inv);
        }
    }
    (r, s)
}

pub fn separate_transform(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx.field("Transform", DataType::Matrix)?;
    let fs = Field::op(
        "Separate Transform",
        vec![m],
        vec![DataType::Vector, DataType::Quaternion, DataType::Vector],
        |_, x| {
            let m = x[0].as_matrix();
            let mut t = Vec::with_capacity(m.len());
            let mut r = Vec::with_capacity(m.len());
            let mut s = Vec::with_capacity(m.len());
            for m in m.iter() {
                t.push([m[3][0], m[3][1], m[3][2]]);
                let (n, size) = normalize_and_get_size(m);
                // `normalized_to_quaternion_safe`: through Euler angles, which any
                // (sheared, negative) matrix has.
                r.push(euler_to_quat(mat3_to_euler(&n)));
                s.push(size);
            }
            Ok(vec![
                Array::Vector(t),
                Array::Quaternion(r),
                Array::Vector(s),
            ])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fs.into_iter();
    Ok(outputs([
        ("Translation", SocketValue::Field(it.next().unwrap())),
        ("Rotation", SocketValue::Field(it.next().unwrap())),
        ("Scale", SocketValue::Field(it.next().unwrap())),
    ]))
}

fn vector_by_matrix(
    ctx: &NodeCtx,
    label: &'static str,
    input: &str,
    f: fn(&Mat4f, [f32; 3]) -> [f32; 3],
) -> Result<Field, GeometryError> {
    Field::op1(
        label,
        vec![
            ctx.field(input, DataType::Vector)?,
            ctx.field("Transform", DataType::Matrix)?,
        ],
        DataType::Vector,
        move |n, x| {
            let (v, m) = (x[0].as_vector(), x[1].as_matrix());
            Ok(Array::Vector((0..n).map(|i| f(&m[i], v[i])).collect()))
        },
    )
    .map_err(|e| ctx.err(e))
}

pub fn transform_point_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = vector_by_matrix(ctx, "Transform Point", "Vector", transform_point)?;
    Ok(field_out("Vector", f))
}

pub fn transform_direction_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = vector_by_matrix(ctx, "Transform Direction", "Direction", transform_direction)?;
    Ok(field_out("Direction", f))
}

/// `math::project_point`: the homogeneous product divided by its w.
fn project_point(m: &Mat4f, p: [f32; 3]) -> [f32; 3] {
    let mut r = [0.0f32; 4];
    for (i, ri) in r.iter_mut().enumerate() {
        *ri = m[0][i] * p[0] + m[1][i] * p[1] + m[2][i] * p[2] + m[3][i];
    }
    [r[0] / r[3], r[1] / r[3], r[2] / r[3]]
}

pub fn project_point_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = vector_by_matrix(ctx, "Project Point", "Vector", project_point)?;
    Ok(field_out("Vector", f))
}

fn matrix_map(
    ctx: &NodeCtx,
    label: &'static str,
    f: fn(&Mat4f) -> Mat4f,
) -> Result<Outputs, GeometryError> {
    let m = ctx.field("Matrix", DataType::Matrix)?;
    let out = Field::op1(label, vec![m], DataType::Matrix, move |_, x| {
        Ok(Array::Matrix(x[0].as_matrix().iter().map(f).collect()))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(field_out("Matrix", out))
}

/// Invert Matrix: the inverse, or zero and Invertible false for a singular matrix.
pub fn invert_matrix(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx.field("Matrix", DataType::Matrix)?;
    let fs = Field::op(
        "Invert Matrix",
        vec![m],
        vec![DataType::Matrix, DataType::Bool],
        |_, x| {
            let (mut out, mut ok) = (Vec::new(), Vec::new());
            for m in x[0].as_matrix().iter() {
                let inv = mat4_invert(m);
                ok.push(inv.is_some());
                out.push(inv.unwrap_or([[0.0; 4]; 4]));
            }
            Ok(vec![Array::Matrix(out), Array::Bool(ok)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fs.into_iter();
    Ok(outputs([
        ("Matrix", SocketValue::Field(it.next().unwrap())),
        ("Invertible", SocketValue::Field(it.next().unwrap())),
    ]))
}

pub fn transpose_matrix(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    matrix_map(ctx, "Transpose Matrix", |m| {
        let mut t = [[0.0f32; 4]; 4];
        for c in 0..4 {
            for r in 0..4 {
                t[c][r] = m[r][c];
            }
        }
        t
    })
}

pub fn multiply_matrices(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = Field::op1(
        "Multiply Matrices",
        vec![
            ctx.field("Matrix", DataType::Matrix)?,
            ctx.field("Matrix_001", DataType::Matrix)?,
        ],
        DataType::Matrix,
        |n, x| {
            let (a, b) = (x[0].as_matrix(), x[1].as_matrix());
            Ok(Array::Matrix(
                (0..n).map(|i| mat4_mul(&a[i], &b[i])).collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(field_out("Matrix", f))
}

/// The 4x4 determinant (cofactor expansion in double).
fn determinant(m: &Mat4f) -> f32 {
    let a = |c: usize, r: usize| m[c][r] as f64;
    let det3 = |c0: usize, c1: usize, c2: usize, r0: usize, r1: usize, r2: usize| {
        a(c0, r0) * (a(c1, r1) * a(c2, r2) - a(c2, r1) * a(c1, r2))
            - a(c1, r0) * (a(c0, r1) * a(c2, r2) - a(c2, r1) * a(c0, r2))
            + a(c2, r0) * (a(c0, r1) * a(c1, r2) - a(c1, r1) * a(c0, r2))
    };
    let d = a(0, 0) * det3(1, 2, 3, 1, 2, 3) - a(1, 0) * det3(0, 2, 3, 1, 2, 3)
        + a(2, 0) * det3(0, 1, 3, 1, 2, 3)
        - a(3, 0) * det3(0, 1, 2, 1, 2, 3);
    d as f32
}

pub fn matrix_determinant(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx.field("Matrix", DataType::Matrix)?;
    let f = Field::op1("Matrix Determinant", vec![m], DataType::Float, |_, x| {
        Ok(Array::Float(
            x[0].as_matrix().iter().map(determinant).collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(field_out("Determinant", f))
}

fn element_name(c: usize, r: usize) -> String {
    format!("Column {} Row {}", c + 1, r + 1)
}

pub fn combine_matrix(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut inputs = Vec::with_capacity(16);
    for c in 0..4 {
        for r in 0..4 {
            inputs.push(ctx.field(&element_name(c, r), DataType::Float)?);
        }
    }
    let f = Field::op1("Combine Matrix", inputs, DataType::Matrix, |n, x| {
        let xs: Vec<_> = x.iter().map(|a| a.as_float()).collect();
        Ok(Array::Matrix(
            (0..n)
                .map(|i| {
                    let mut m = [[0.0f32; 4]; 4];
                    for c in 0..4 {
                        for r in 0..4 {
                            m[c][r] = xs[c * 4 + r][i];
                        }
                    }
                    m
                })
                .collect(),
        ))
    })
    .map_err(|e| ctx.err(e))?;
    Ok(field_out("Matrix", f))
}

pub fn separate_matrix(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let m = ctx.field("Matrix", DataType::Matrix)?;
    let fs = Field::op(
        "Separate Matrix",
        vec![m],
        vec![DataType::Float; 16],
        |_, x| {
            let m = x[0].as_matrix();
            Ok((0..16)
                .map(|k| Array::Float(m.iter().map(|m| m[k / 4][k % 4]).collect()))
                .collect())
        },
    )
    .map_err(|e| ctx.err(e))?;
    Ok(fs
        .into_iter()
        .enumerate()
        .map(|(k, f)| (element_name(k / 4, k % 4), SocketValue::Field(f)))
        .collect())
}
