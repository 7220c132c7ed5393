//! Single-precision vector, rotation and matrix helpers with Blender's operation order
//! (`BLI_math_*`), so transformed positions match Blender's to the last bit or two.
//!
//! Matrices are `m[col][row]` as Blender's `float4x4` stores them (column 3 is the
//! translation), which is also the column-major order of FLOAT4X4 attributes.

pub use crate::foundation::math::{add, cross, dot, len as length, mul, scale, sub, V3};
pub type Mat4f = [[f32; 4]; 4];
pub type Mat3f = [[f32; 3]; 3];

pub const MAT4_IDENTITY: Mat4f = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Blender's C++ `math::normalize`: zero below a tiny squared length, else each component
/// divided by the length.
pub fn normalize(a: V3) -> V3 {
    let l2 = dot(a, a);
    if l2 > 1.0e-35 {
        let l = l2.sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    } else {
        [0.0; 3]
    }
}
/// Blender's `normalize_v3` (C): zero-length input gives zero.
pub fn normalize_v3(a: V3) -> (V3, f32) {
    let d = dot(a, a);
    if d > 1.0e-35 {
        let d = d.sqrt();
        (scale(a, 1.0 / d), d)
    } else {
        ([0.0; 3], 0.0)
    }
}

/// `axis_angle_normalized_to_mat3`: rotation by `angle` about the unit `axis`, with
/// Blender's operation order (Screw's steps, Fillet Curve's arcs).
pub fn axis_angle_normalized_to_mat3(axis: V3, angle: f32) -> Mat3f {
    axis_angle_normalized_to_mat3_ex(axis, angle.sin(), angle.cos())
}

/// `axis_angle_normalized_to_mat3_ex`: the rotation from the angle's sine and cosine.
pub fn axis_angle_normalized_to_mat3_ex(axis: V3, s: f32, c: f32) -> Mat3f {
    let ico = 1.0 - c;
    let nsi = scale(axis, s);
    let n00 = (axis[0] * axis[0]) * ico;
    let n01 = (axis[0] * axis[1]) * ico;
    let n11 = (axis[1] * axis[1]) * ico;
    let n02 = (axis[0] * axis[2]) * ico;
    let n12 = (axis[1] * axis[2]) * ico;
    let n22 = (axis[2] * axis[2]) * ico;
    [
        [n00 + c, n01 + nsi[2], n02 - nsi[1]],
        [n01 - nsi[2], n11 + c, n12 + nsi[0]],
        [n02 + nsi[1], n12 - nsi[0], n22 + c],
    ]
}

/// `ortho_v3_v3`: a vector perpendicular to `v`, built on its dominant axis.
pub fn ortho_v3(v: V3) -> V3 {
    let (x, y, z) = (v[0].abs(), v[1].abs(), v[2].abs());
    let axis = if x > y {
        if x > z {
            0
        } else {
            2
        }
    } else if y > z {
        1
    } else {
        2
    };
    match axis {
        0 => [-v[1] - v[2], v[0], v[0]],
        1 => [v[1], -v[0] - v[2], v[1]],
        _ => [v[2], v[2], -v[0] - v[1]],
    }
}

/// `rotation_between_vecs_to_mat3`: the rotation taking unit `v1` to unit `v2` (identity
/// when they agree, half a turn about a perpendicular when they are opposite).
pub fn rotation_between_vecs_to_mat3(v1: V3, v2: V3) -> Mat3f {
    let (axis, sin) = normalize_v3(cross(v1, v2));
    let cos = dot(v1, v2);
    if sin > f32::EPSILON {
        axis_angle_normalized_to_mat3_ex(axis, sin, cos)
    } else if cos > 0.0 {
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    } else {
        let (axis, _) = normalize_v3(ortho_v3(v1));
        axis_angle_normalized_to_mat3_ex(axis, 0.0, -1.0)
    }
}

/// `float3x3 * float3`: the columns scaled by the vector's components, summed in order.
pub fn mat3_mul_v3(m: &Mat3f, v: V3) -> V3 {
    let mut r = [0.0f32; 3];
    for i in 0..3 {
        r[i] = m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2];
    }
    r
}

pub fn mat4_mul(a: &Mat4f, b: &Mat4f) -> Mat4f {
    let mut r = [[0.0f32; 4]; 4];
    for j in 0..4 {
        for i in 0..4 {
            r[j][i] = a[0][i] * b[j][0] + a[1][i] * b[j][1] + a[2][i] * b[j][2] + a[3][i] * b[j][3];
        }
    }
    r
}

/// `math::transform_point`: the 3x3 part times `p`, plus the translation.
#[inline]
pub fn transform_point(m: &Mat4f, p: V3) -> V3 {
    let mut r = [0.0; 3];
    for i in 0..3 {
        r[i] = m[0][i] * p[0] + m[1][i] * p[1] + m[2][i] * p[2] + m[3][i];
    }
    r
}
#[inline]
pub fn transform_direction(m: &Mat4f, p: V3) -> V3 {
    let mut r = [0.0; 3];
    for i in 0..3 {
        r[i] = m[0][i] * p[0] + m[1][i] * p[1] + m[2][i] * p[2];
    }
    r
}

pub fn translation(t: V3) -> Mat4f {
    let mut m = MAT4_IDENTITY;
    m[3][0] = t[0];
    m[3][1] = t[1];
    m[3][2] = t[2];
    m
}

/// Blender's `to_quaternion(EulerXYZ)` (`eul_to_quat`), in single precision.
pub fn euler_to_quat(e: V3) -> [f32; 4] {
    let (ti, tj, th) = (e[0] * 0.5, e[1] * 0.5, e[2] * 0.5);
    let (ci, cj, ch) = (ti.cos(), tj.cos(), th.cos());
    let (si, sj, sh) = (ti.sin(), tj.sin(), th.sin());
    let (cc, cs, sc, ss) = (ci * ch, ci * sh, si * ch, si * sh);
    [
        cj * cc + sj * ss,
        cj * sc - sj * cs,
        cj * ss + sj * cc,
        cj * cs - sj * sc,
    ]
}

/// `from_rotation<float3x3>(EulerXYZ)` (`eul_to_mat3`), `m[col][row]`.
pub fn euler_to_mat3(e: V3) -> Mat3f {
    let (ci, cj, ch) = (e[0].cos(), e[1].cos(), e[2].cos());
    let (si, sj, sh) = (e[0].sin(), e[1].sin(), e[2].sin());
    let (cc, cs, sc, ss) = (ci * ch, ci * sh, si * ch, si * sh);
    [
        [cj * ch, cj * sh, -sj],
        [sj * sc - cs, sj * ss + cc, cj * si],
        [sj * cc + ss, sj * cs - sc, cj * ci],
    ]
}

/// `from_rotation<float3x3>(Quaternion)` (`quat_to_mat3`): the products are formed from
/// `sqrt(2) * q` (a double constant, rounded to float), the diagonal in double.
pub fn quat_to_mat3(q: [f32; 4]) -> Mat3f {
    let s2 = std::f64::consts::SQRT_2;
    let q0 = (s2 * q[0] as f64) as f32;
    let q1 = (s2 * q[1] as f64) as f32;
    let q2 = (s2 * q[2] as f64) as f32;
    let q3 = (s2 * q[3] as f64) as f32;
    let qda = q0 * q1;
    let qdb = q0 * q2;
    let qdc = q0 * q3;
    let qaa = q1 * q1;
    let qab = q1 * q2;
    let qac = q1 * q3;
    let qbb = q2 * q2;
    let qbc = q2 * q3;
    let qcc = q3 * q3;
    let d = |a: f32, b: f32| (1.0f64 - a as f64 - b as f64) as f32;
    [
        [d(qbb, qcc), qdc + qab, -qdb + qac],
        [-qdc + qab, d(qaa, qcc), qda + qbc],
        [qdb + qac, -qda + qbc, d(qaa, qbb)],
    ]
}

pub fn quat_to_mat4(q: [f32; 4]) -> Mat4f {
    mat3_to_mat4(&quat_to_mat3(q))
}

pub fn mat3_to_mat4(m: &Mat3f) -> Mat4f {
    let mut r = MAT4_IDENTITY;
    for c in 0..3 {
        for i in 0..3 {
            r[c][i] = m[c][i];
        }
    }
    r
}

/// `to_euler(float3x3)` for a normalized matrix: of Blender's two solutions the one with
/// the smaller sum of absolute angles.
pub fn mat3_to_euler(m: &Mat3f) -> V3 {
    let cy = m[0][0].hypot(m[0][1]);
    let (e1, e2);
    if cy > 16.0 * f32::EPSILON {
        e1 = [
            m[1][2].atan2(m[2][2]),
            (-m[0][2]).atan2(cy),
            m[0][1].atan2(m[0][0]),
        ];
        e2 = [
            (-m[1][2]).atan2(-m[2][2]),
            (-m[0][2]).atan2(-cy),
            (-m[0][1]).atan2(-m[0][0]),
        ];
    } else {
        e1 = [(-m[2][1]).atan2(m[1][1]), (-m[0][2]).atan2(cy), 0.0];
        e2 = e1;
    }
    let s = |e: V3| e[0].abs() + e[1].abs() + e[2].abs();
    if s(e1) > s(e2) {
        e2
    } else {
        e1
    }
}

pub fn quat_to_euler(q: [f32; 4]) -> V3 {
    mat3_to_euler(&quat_to_mat3(q))
}

/// `mat3_normalized_to_quat_fast` followed by a normalize.
pub fn mat3_normalized_to_quat(m: &Mat3f) -> [f32; 4] {
    normalize_quat(mat3_to_quat_raw(m))
}

/// `math::to_quaternion(float3x3)` (`normalized_to_quat_with_checks`): no column
/// normalization, a negative matrix negated, and the result normalized only when its
/// squared length is off by 0.0006 or more (so a slightly sheared frame keeps its scale).
pub fn mat3_to_quat_checked(m: &Mat3f) -> [f32; 4] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
    if !det.is_finite() {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let m = if det < 0.0 {
        m.map(|c| c.map(|x| -x))
    } else {
        *m
    };
    let q = mat3_to_quat_raw(&m);
    let len_sq = q[1] * q[1] + q[2] * q[2] + q[3] * q[3] + q[0] * q[0];
    if (len_sq - 1.0).abs() >= 0.0002 * 3.0 {
        let inv = (1.0 / (len_sq as f64).sqrt()) as f32;
        return q.map(|x| x * inv);
    }
    q
}

/// Mike Day's matrix to quaternion (w, x, y, z), unnormalized.
fn mat3_to_quat_raw(m: &Mat3f) -> [f32; 4] {
    let mut q = [0.0f32; 4];
    if m[2][2] < 0.0 {
        if m[0][0] > m[1][1] {
            let trace = 1.0 + m[0][0] - m[1][1] - m[2][2];
            let mut s = 2.0 * trace.sqrt();
            if m[1][2] < m[2][1] {
                s = -s;
            }
            q[1] = 0.25 * s;
            s = 1.0 / s;
            q[0] = (m[1][2] - m[2][1]) * s;
            q[2] = (m[0][1] + m[1][0]) * s;
            q[3] = (m[2][0] + m[0][2]) * s;
            if trace == 1.0 && q[0] == 0.0 && q[2] == 0.0 && q[3] == 0.0 {
                q[1] = 1.0;
            }
        } else {
            let trace = 1.0 - m[0][0] + m[1][1] - m[2][2];
            let mut s = 2.0 * trace.sqrt();
            if m[2][0] < m[0][2] {
                s = -s;
            }
            q[2] = 0.25 * s;
            s = 1.0 / s;
            q[0] = (m[2][0] - m[0][2]) * s;
            q[1] = (m[0][1] + m[1][0]) * s;
            q[3] = (m[1][2] + m[2][1]) * s;
            if trace == 1.0 && q[0] == 0.0 && q[1] == 0.0 && q[3] == 0.0 {
                q[2] = 1.0;
            }
        }
    } else if m[0][0] < -m[1][1] {
        let trace = 1.0 - m[0][0] - m[1][1] + m[2][2];
        let mut s = 2.0 * trace.sqrt();
        if m[0][1] < m[1][0] {
            s = -s;
        }
        q[3] = 0.25 * s;
        s = 1.0 / s;
        q[0] = (m[0][1] - m[1][0]) * s;
        q[1] = (m[2][0] + m[0][2]) * s;
        q[2] = (m[1][2] + m[2][1]) * s;
        if trace == 1.0 && q[0] == 0.0 && q[1] == 0.0 && q[2] == 0.0 {
            q[3] = 1.0;
        }
    } else {
        let trace = 1.0 + m[0][0] + m[1][1] + m[2][2];
        let mut s = 2.0 * trace.sqrt();
        q[0] = 0.25 * s;
        s = 1.0 / s;
        q[1] = (m[1][2] - m[2][1]) * s;
        q[2] = (m[2][0] - m[0][2]) * s;
        q[3] = (m[0][1] - m[1][0]) * s;
        if trace == 1.0 && q[1] == 0.0 && q[2] == 0.0 && q[3] == 0.0 {
            q[0] = 1.0;
        }
    }
    q
}

pub fn normalize_quat(q: [f32; 4]) -> [f32; 4] {
    let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if len != 0.0 {
        let f = 1.0 / len;
        [q[0] * f, q[1] * f, q[2] * f, q[3] * f]
    } else {
        [0.0, 1.0, 0.0, 0.0]
    }
}

/// Rotation part of a matrix with its columns normalized, as a quaternion.
pub fn mat4_to_quat_normalized(m: &Mat4f) -> [f32; 4] {
    let mut r = [[0.0f32; 3]; 3];
    for c in 0..3 {
        let n = normalize([m[c][0], m[c][1], m[c][2]]);
        r[c] = n;
    }
    mat3_normalized_to_quat(&r)
}

/// `math::from_loc_rot_scale<float4x4>(location, rotation, scale)`.
pub fn from_loc_rot_scale(loc: V3, rot: [f32; 4], s: V3) -> Mat4f {
    let r = quat_to_mat3(rot);
    let mut m = MAT4_IDENTITY;
    for c in 0..3 {
        for i in 0..3 {
            m[c][i] = r[c][i] * s[c];
        }
    }
    m[3] = [loc[0], loc[1], loc[2], 1.0];
    m
}

/// `from_loc_rot_scale` with an Euler rotation (Transform Geometry's rotation input).
pub fn from_loc_euler_scale(loc: V3, rot: V3, s: V3) -> Mat4f {
    let r = euler_to_mat3(rot);
    let mut m = MAT4_IDENTITY;
    for c in 0..3 {
        for i in 0..3 {
            m[c][i] = r[c][i] * s[c];
        }
    }
    m[3] = [loc[0], loc[1], loc[2], 1.0];
    m
}

/// General 4x4 inverse (cofactors, f64 internally); None when singular.
pub fn mat4_invert(m: &Mat4f) -> Option<Mat4f> {
    // Work on rows of the transposed layout: a[r][c] = m[c][r].
    let mut a = [[0.0f64; 4]; 4];
    for c in 0..4 {
        for r in 0..4 {
            a[r][c] = m[c][r] as f64;
        }
    }
    let mut inv = [[0.0f64; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for col in 0..4 {
        let mut piv = col;
        for r in col + 1..4 {
            if a[r][col].abs() > a[piv][col].abs() {
                piv = r;
            }
        }
        if a[piv][col] == 0.0 {
            return None;
        }
        a.swap(col, piv);
        inv.swap(col, piv);
        let d = a[col][col];
        for k in 0..4 {
            a[col][k] /= d;
            inv[col][k] /= d;
        }
        for r in 0..4 {
            if r != col {
                let f = a[r][col];
                for k in 0..4 {
                    a[r][k] -= f * a[col][k];
                    inv[r][k] -= f * inv[col][k];
                }
            }
        }
    }
    let mut out = [[0.0f32; 4]; 4];
    for c in 0..4 {
        for r in 0..4 {
            out[c][r] = inv[r][c] as f32;
        }
    }
    Some(out)
}

/// From the exchange format's row-major f64 matrix (`m[row][col]`).
pub fn from_rows_f64(m: &[[f64; 4]; 4]) -> Mat4f {
    let mut out = [[0.0f32; 4]; 4];
    for c in 0..4 {
        for r in 0..4 {
            out[c][r] = m[r][c] as f32;
        }
    }
    out
}

/// Flattens to the column-major 16 floats FLOAT4X4 attributes and glTF use.
pub fn flatten(m: &Mat4f) -> [f32; 16] {
    let mut out = [0.0; 16];
    for c in 0..4 {
        for r in 0..4 {
            out[c * 4 + r] = m[c][r];
        }
    }
    out
}

/// Turns free normals (a `custom_normal` attribute) as positions move by `m`, as Blender's
/// `transform_custom_normal_attribute`: by the inverse transpose of the 3x3 part,
/// normalized.
pub fn transform_normals(m: &Mat4f, normals: &mut [V3]) {
    let nm = normal_matrix(m);
    for n in normals.iter_mut() {
        *n = normalize(mat3_mul_v3(&nm, *n));
    }
}

/// The transpose of the inverse of the 3x3 part, to move normals.
pub fn normal_matrix(m: &Mat4f) -> Mat3f {
    let a = [
        [m[0][0], m[0][1], m[0][2]],
        [m[1][0], m[1][1], m[1][2]],
        [m[2][0], m[2][1], m[2][2]],
    ];
    let inv = mat4_invert(&mat3_to_mat4(&a)).unwrap_or(MAT4_IDENTITY);
    // transpose of inverse
    let mut r = [[0.0f32; 3]; 3];
    for c in 0..3 {
        for i in 0..3 {
            r[c][i] = inv[i][c];
        }
    }
    r
}
