//! Small vector, quaternion and matrix helpers.
//!
//! Two precisions on purpose: `f64` row-major 4x4 matrices for composing transforms, and
//! `f32` vectors/quaternions for the curve path, where Blender accumulates lengths in
//! single precision and the result depends on doing the same operations in the same order.
//!
//! Matrices are `m[row][col]` (as `mathutils.Matrix` and the exchange format index them);
//! Blender's C code stores the transpose (`mat[col][row]`), so its `mat[3]` (translation)
//! is our column 3 and its `mat[i]` (axis i) is our column i.

pub type Mat4 = [[f64; 4]; 4];
pub type Mat3 = [[f64; 3]; 3];
pub use crate::foundation::math::{vec3, Vec3};
pub type Quat = [f32; 4];

pub const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

pub fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut r = [[0.0; 4]; 4];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

pub fn mat3_to_mat4(m: &Mat3) -> Mat4 {
    let mut r = IDENTITY;
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = m[i][j];
        }
    }
    r
}

pub fn mat4_to_mat3(m: &Mat4) -> Mat3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = m[i][j];
        }
    }
    r
}

pub fn mul3(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

pub fn transpose3(m: &Mat3) -> Mat3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = m[j][i];
        }
    }
    r
}

pub fn det3(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

pub fn inverse3(m: &Mat3) -> Option<Mat3> {
    let d = det3(m);
    if d == 0.0 || !d.is_finite() {
        return None;
    }
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            // Cofactor of (j, i) for the adjugate.
            let (a, b) = ((j + 1) % 3, (j + 2) % 3);
            let (c, e) = ((i + 1) % 3, (i + 2) % 3);
            r[i][j] = (m[a][c] * m[b][e] - m[a][e] * m[b][c]) / d;
        }
    }
    Some(r)
}

/// General 4x4 inverse (Gauss-Jordan with partial pivoting); None when singular.
pub fn inverse(m: &Mat4) -> Option<Mat4> {
    let mut a = *m;
    let mut r = IDENTITY;
    for c in 0..4 {
        let p = (c..4).max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))?;
        if a[p][c] == 0.0 {
            return None;
        }
        a.swap(c, p);
        r.swap(c, p);
        let inv = 1.0 / a[c][c];
        for j in 0..4 {
            a[c][j] *= inv;
            r[c][j] *= inv;
        }
        for i in 0..4 {
            if i != c {
                let f = a[i][c];
                if f != 0.0 {
                    for j in 0..4 {
                        a[i][j] -= f * a[c][j];
                        r[i][j] -= f * r[c][j];
                    }
                }
            }
        }
    }
    Some(r)
}

/// Length of column `i` of the upper 3x3: Blender's `mat4_to_size` (axis lengths).
pub fn axis_len(m: &Mat4, i: usize) -> f64 {
    (m[0][i] * m[0][i] + m[1][i] * m[1][i] + m[2][i] * m[2][i]).sqrt()
}

pub fn scale_axis(m: &mut Mat4, i: usize, f: f64) {
    for row in m.iter_mut().take(3) {
        row[i] *= f;
    }
}

pub fn translation(m: &Mat4) -> [f64; 3] {
    [m[0][3], m[1][3], m[2][3]]
}

pub fn set_translation(m: &mut Mat4, t: [f64; 3]) {
    for i in 0..3 {
        m[i][3] = t[i];
    }
}

pub fn column(m: &Mat4, i: usize) -> [f64; 3] {
    [m[0][i], m[1][i], m[2][i]]
}

// ---- f64 vectors -------------------------------------------------------------------------

pub fn dot64(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub fn sub64(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
/// Normalizes in place, returning the old length (0 and a zero vector when degenerate),
/// as Blender's `normalize_v3` does.
pub fn normalize64(v: &mut [f64; 3]) -> f64 {
    let d = dot64(*v, *v);
    if d > 1.0e-35 {
        let l = d.sqrt();
        for x in v.iter_mut() {
            *x /= l;
        }
        l
    } else {
        *v = [0.0; 3];
        0.0
    }
}

/// Rotation matrix of a (not necessarily unit) quaternion `[w, x, y, z]`, already
/// normalized by the caller. Matches Blender's `quat_to_mat3` (computed in double there).
pub fn quat_to_mat3_64(q: [f64; 4]) -> Mat3 {
    let s = std::f64::consts::SQRT_2;
    let (q0, q1, q2, q3) = (s * q[0], s * q[1], s * q[2], s * q[3]);
    let (qda, qdb, qdc) = (q0 * q1, q0 * q2, q0 * q3);
    let (qaa, qab, qac) = (q1 * q1, q1 * q2, q1 * q3);
    let (qbb, qbc, qcc) = (q2 * q2, q2 * q3, q3 * q3);
    // Blender's C arrays are column-major; row i here is its [*][i].
    [
        [1.0 - qbb - qcc, -qdc + qab, qdb + qac],
        [qdc + qab, 1.0 - qaa - qcc, -qda + qbc],
        [-qdb + qac, qda + qbc, 1.0 - qaa - qbb],
    ]
}

pub fn normalize_quat64(q: [f64; 4]) -> [f64; 4] {
    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if l != 0.0 {
        [q[0] / l, q[1] / l, q[2] / l, q[3] / l]
    } else {
        // Blender's normalize_qt turns a zero quaternion into (0, 1, 0, 0).
        [0.0, 1.0, 0.0, 0.0]
    }
}

/// Spherical interpolation as Blender's `interp_qt_qtqt` (shortest arc, lerp when close).
pub fn slerp64(a: [f64; 4], b: [f64; 4], t: f64) -> [f64; 4] {
    let mut cosom = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    let mut qa = a;
    if cosom < 0.0 {
        cosom = -cosom;
        qa = [-a[0], -a[1], -a[2], -a[3]];
    }
    let (w0, w1) = if cosom.abs() < 1.0 - 1e-4 {
        let omega = cosom.acos();
        let sinom = omega.sin();
        (((1.0 - t) * omega).sin() / sinom, (t * omega).sin() / sinom)
    } else {
        (1.0 - t, t)
    };
    [
        w0 * qa[0] + w1 * b[0],
        w0 * qa[1] + w1 * b[1],
        w0 * qa[2] + w1 * b[2],
        w0 * qa[3] + w1 * b[3],
    ]
}

/// Quaternion of a rotation matrix (orthonormal, positive determinant).
pub fn mat3_to_quat64(m: &Mat3) -> [f64; 4] {
    // Shepperd's method on the row-major matrix; sign fixed so w >= 0.
    let tr = m[0][0] + m[1][1] + m[2][2];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (m[2][1] - m[1][2]) / s,
            (m[0][2] - m[2][0]) / s,
            (m[1][0] - m[0][1]) / s,
        ]
    } else if m[0][0] > m[1][1] && m[0][0] > m[2][2] {
        let s = (1.0 + m[0][0] - m[1][1] - m[2][2]).sqrt() * 2.0;
        [
            (m[2][1] - m[1][2]) / s,
            0.25 * s,
            (m[0][1] + m[1][0]) / s,
            (m[0][2] + m[2][0]) / s,
        ]
    } else if m[1][1] > m[2][2] {
        let s = (1.0 + m[1][1] - m[0][0] - m[2][2]).sqrt() * 2.0;
        [
            (m[0][2] - m[2][0]) / s,
            (m[0][1] + m[1][0]) / s,
            0.25 * s,
            (m[1][2] + m[2][1]) / s,
        ]
    } else {
        let s = (1.0 + m[2][2] - m[0][0] - m[1][1]).sqrt() * 2.0;
        [
            (m[1][0] - m[0][1]) / s,
            (m[0][2] + m[2][0]) / s,
            (m[1][2] + m[2][1]) / s,
            0.25 * s,
        ]
    };
    let q = if q[0] < 0.0 {
        [-q[0], -q[1], -q[2], -q[3]]
    } else {
        q
    };
    normalize_quat64(q)
}

/// Polar decomposition `A = U P` (U orthogonal, P symmetric), by Newton iteration
/// `U <- (U + U^-T) / 2`, which converges to the orthogonal factor for invertible A.
pub fn polar_decompose(a: &Mat3) -> (Mat3, Mat3) {
    let mut u = *a;
    if inverse3(a).is_none() {
        // Singular: fall back to Gram-Schmidt-free identity rotation; P = A.
        return ([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], *a);
    }
    for _ in 0..100 {
        // The iterates stay invertible in exact arithmetic; stop if rounding says otherwise.
        let Some(inv) = inverse3(&u) else { break };
        let inv_t = transpose3(&inv);
        let mut next = [[0.0; 3]; 3];
        let mut delta: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                next[i][j] = 0.5 * (u[i][j] + inv_t[i][j]);
                delta = delta.max((next[i][j] - u[i][j]).abs());
            }
        }
        u = next;
        if delta < 1e-15 {
            break;
        }
    }
    let p = mul3(&transpose3(&u), a);
    (u, p)
}

/// Blender's `interp_m4_m4m4`: rotation slerped (polar decomposition), scale/shear and
/// translation interpolated linearly. Used to blend a constraint by its influence.
pub fn interp_mat4(a: &Mat4, b: &Mat4, t: f64) -> Mat4 {
    let (mut ua, mut pa) = polar_decompose(&mat4_to_mat3(a));
    let (mut ub, mut pb) = polar_decompose(&mat4_to_mat3(b));
    // Quaternions cannot represent an axis flip: move the flip into P (as Blender does).
    for (u, p) in [(&mut ua, &mut pa), (&mut ub, &mut pb)] {
        if det3(u) < 0.0 {
            for i in 0..3 {
                for j in 0..3 {
                    u[i][j] = -u[i][j];
                    p[i][j] = -p[i][j];
                }
            }
        }
    }
    let q = slerp64(mat3_to_quat64(&ua), mat3_to_quat64(&ub), t);
    let u = quat_to_mat3_64(normalize_quat64(q));
    let mut p = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            p[i][j] = pa[i][j] + (pb[i][j] - pa[i][j]) * t;
        }
    }
    let mut r = mat3_to_mat4(&mul3(&u, &p));
    for i in 0..3 {
        r[i][3] = a[i][3] + (b[i][3] - a[i][3]) * t;
    }
    r
}

// ---- f32 vectors and quaternions (curve path) -------------------------------------------

pub fn len_between(a: Vec3, b: Vec3) -> f32 {
    (a - b).length()
}
/// Blender's `normalize_v3`: multiplies by the reciprocal length, zeroes tiny vectors.
pub fn normalize(v: &mut Vec3) -> f32 {
    let d = v.dot(*v);
    if d > 1.0e-35 {
        let l = d.sqrt();
        *v *= 1.0 / l;
        l
    } else {
        *v = Vec3::ZERO;
        0.0
    }
}

pub fn normalized(mut v: Vec3) -> Vec3 {
    normalize(&mut v);
    v
}

fn safe_asin(f: f32) -> f32 {
    if f <= -1.0 {
        -std::f32::consts::FRAC_PI_2
    } else if f >= 1.0 {
        std::f32::consts::FRAC_PI_2
    } else {
        f.asin()
    }
}

pub fn safe_acos(f: f32) -> f32 {
    if f <= -1.0 {
        std::f32::consts::PI
    } else if f >= 1.0 {
        0.0
    } else {
        f.acos()
    }
}

/// Angle between unit vectors, via asin of the half chord (Blender's more precise form).
pub fn angle_normalized(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) >= 0.0 {
        2.0 * safe_asin(len_between(a, b) / 2.0)
    } else {
        std::f32::consts::PI - 2.0 * safe_asin(len_between(a, -b) / 2.0)
    }
}

/// Unit bisector direction at `b` of the polyline a-b-c.
pub fn bisect(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let mut d12 = b - a;
    let mut d23 = c - b;
    normalize(&mut d12);
    normalize(&mut d23);
    normalized(d12 + d23)
}

pub const QUAT_IDENTITY: Quat = [1.0, 0.0, 0.0, 0.0];

pub fn qmul(a: Quat, b: Quat) -> Quat {
    let t0 = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    let t1 = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    let t2 = a[0] * b[2] + a[2] * b[0] + a[3] * b[1] - a[1] * b[3];
    let t3 = a[0] * b[3] + a[3] * b[0] + a[1] * b[2] - a[2] * b[1];
    [t0, t1, t2, t3]
}

/// Rotates `r` by unit quaternion `q` (Blender's `mul_qt_v3`, same operation order).
pub fn qrotate(q: Quat, r: Vec3) -> Vec3 {
    let t0 = -q[1] * r[0] - q[2] * r[1] - q[3] * r[2];
    let t1 = q[0] * r[0] + q[2] * r[2] - q[3] * r[1];
    let t2 = q[0] * r[1] + q[3] * r[0] - q[1] * r[2];
    let r2 = q[0] * r[2] + q[1] * r[1] - q[2] * r[0];
    let (r0, r1) = (t1, t2);
    let o1 = t0 * -q[1] + r0 * q[0] - r1 * q[3] + r2 * q[2];
    let o2 = t0 * -q[2] + r1 * q[0] - r2 * q[1] + r0 * q[3];
    let o3 = t0 * -q[3] + r2 * q[0] - r0 * q[2] + r1 * q[1];
    vec3(o1, o2, o3)
}

pub fn qnormalize(q: &mut Quat) -> f32 {
    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if l != 0.0 {
        let f = 1.0 / l;
        for x in q.iter_mut() {
            *x *= f;
        }
    } else {
        *q = [0.0, 1.0, 0.0, 0.0];
    }
    l
}

pub fn axis_angle_normalized_to_quat(axis: Vec3, angle: f32) -> Quat {
    let phi = 0.5 * angle;
    let (si, co) = (phi.sin(), phi.cos());
    [co, axis[0] * si, axis[1] * si, axis[2] * si]
}

pub fn axis_angle_to_quat(axis: Vec3, angle: f32) -> Quat {
    let mut n = axis;
    if normalize(&mut n) != 0.0 {
        axis_angle_normalized_to_quat(n, angle)
    } else {
        QUAT_IDENTITY
    }
}

/// Blender's `interp_qt_qtqt` in single precision.
pub fn qslerp(a: Quat, b: Quat, t: f32) -> Quat {
    let mut cosom = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    let mut qa = a;
    if cosom < 0.0 {
        cosom = -cosom;
        qa = [-a[0], -a[1], -a[2], -a[3]];
    }
    let (w0, w1) = if cosom.abs() < 1.0 - 1e-4 {
        let omega = cosom.acos();
        let sinom = omega.sin();
        (((1.0 - t) * omega).sin() / sinom, (t * omega).sin() / sinom)
    } else {
        (1.0 - t, t)
    };
    [
        w0 * qa[0] + w1 * b[0],
        w0 * qa[1] + w1 * b[1],
        w0 * qa[2] + w1 * b[2],
        w0 * qa[3] + w1 * b[3],
    ]
}

/// Blender's `quat_to_mat3` (double internally), as a row-major f32 3x3.
pub fn quat_to_mat3(q: Quat) -> [[f32; 3]; 3] {
    let m = quat_to_mat3_64([q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64]);
    let mut r = [[0.0f32; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = m[i][j] as f32;
        }
    }
    r
}

/// Blender's `vec_to_quat`: the rotation that points `axis` (0..5 = X,Y,Z,-X,-Y,-Z) along
/// `vec`, with `upflag` (0..2) kept as close to up as possible.
pub fn vec_to_quat(vec: Vec3, axis: i32, upflag: i32) -> Quat {
    let eps = 1e-4f32;
    let l = vec.length();
    if l == 0.0 {
        return QUAT_IDENTITY;
    }
    let (tvec, axis) = if axis > 2 {
        (vec, axis - 3)
    } else {
        (-vec, axis)
    };
    let mut nor;
    let mut co;
    if axis == 0 {
        nor = vec3(0.0, -tvec[2], tvec[1]);
        if tvec[1].abs() + tvec[2].abs() < eps {
            nor[1] = 1.0;
        }
        co = tvec[0];
    } else if axis == 1 {
        nor = vec3(tvec[2], 0.0, -tvec[0]);
        if tvec[0].abs() + tvec[2].abs() < eps {
            nor[2] = 1.0;
        }
        co = tvec[1];
    } else {
        nor = vec3(-tvec[1], tvec[0], 0.0);
        if tvec[0].abs() + tvec[1].abs() < eps {
            nor[0] = 1.0;
        }
        co = tvec[2];
    }
    co /= l;
    normalize(&mut nor);
    let mut q = axis_angle_normalized_to_quat(nor, safe_acos(co));
    if axis != upflag {
        // Blender reads mat[2] (its third column-major axis = our column 2).
        let m = quat_to_mat3(q);
        let fp = [m[0][2], m[1][2], m[2][2]];
        let angle = if axis == 0 {
            if upflag == 1 {
                0.5 * fp[2].atan2(fp[1])
            } else {
                -0.5 * fp[1].atan2(fp[2])
            }
        } else if axis == 1 {
            if upflag == 0 {
                -0.5 * fp[2].atan2(fp[0])
            } else {
                0.5 * fp[0].atan2(fp[2])
            }
        } else if upflag == 0 {
            0.5 * (-fp[1]).atan2(-fp[0])
        } else {
            -0.5 * (-fp[0]).atan2(-fp[1])
        };
        let co2 = angle.cos();
        let si = angle.sin() / l;
        let q2 = [co2, tvec[0] * si, tvec[1] * si, tvec[2] * si];
        q = qmul(q2, q);
    }
    q
}

/// Blender's `quat_apply_track`: re-orients a path quaternion so `axis` (0..5) is forward
/// and `upflag` (0..2) is up.
pub fn quat_apply_track(quat: Quat, axis: i32, upflag: i32) -> Quat {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let track: [Quat; 6] = [
        [s, 0.0, -s, 0.0],
        [0.5, 0.5, 0.5, 0.5],
        [s, 0.0, 0.0, s],
        [s, 0.0, s, 0.0],
        [0.5, -0.5, -0.5, 0.5],
        [0.0, s, s, 0.0],
    ];
    let mut q = qmul(quat, track[axis as usize]);
    let axis = if axis > 2 { axis - 3 } else { axis };
    if upflag != (2 - axis) >> 1 {
        let mut r = [s, 0.0, 0.0, 0.0];
        r[(axis + 1) as usize] = if axis == 1 { s } else { -s };
        q = qmul(q, r);
    }
    q
}

fn normal_tri(a: Vec3, b: Vec3, c: Vec3) -> (Vec3, f32) {
    let mut n = (a - b).cross(b - c);
    let l = normalize(&mut n);
    (n, l)
}

fn invert3_f32(m: [[f32; 3]; 3]) -> [[f32; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let mut r = [[0.0f32; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) = ((j + 1) % 3, (j + 2) % 3);
            let (c, e) = ((i + 1) % 3, (i + 2) % 3);
            r[i][j] = m[a][c] * m[b][e] - m[a][e] * m[b][c];
        }
    }
    if det != 0.0 {
        let inv = 1.0 / det;
        for row in r.iter_mut() {
            for v in row.iter_mut() {
                *v *= inv;
            }
        }
    }
    r
}

/// Blender's `tri_to_quat`: the rotation taking the XY plane to the triangle's plane with
/// X along a->b.
pub fn tri_to_quat(a: Vec3, b: Vec3, c: Vec3) -> Quat {
    let (vec, _) = normal_tri(a, b, c);
    let mut n = vec3(vec[1], -vec[0], 0.0);
    normalize(&mut n);
    if n[0] == 0.0 && n[1] == 0.0 {
        n[0] = 1.0;
    }
    let angle = -0.5 * safe_acos(vec[2]);
    let (co, si) = (angle.cos(), angle.sin());
    let q1 = [co, n[0] * si, n[1] * si, 0.0];
    let imat = invert3_f32(quat_to_mat3(q1));
    let d = b - a;
    let mut v = vec3(
        imat[0][0] * d[0] + imat[0][1] * d[1] + imat[0][2] * d[2],
        imat[1][0] * d[0] + imat[1][1] * d[1] + imat[1][2] * d[2],
        0.0,
    );
    normalize(&mut v);
    let angle = 0.5 * v[1].atan2(v[0]);
    let q2 = [angle.cos(), 0.0, 0.0, angle.sin()];
    qmul(q1, q2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_roundtrip() {
        let m = [
            [2.0, 0.5, 0.0, 1.0],
            [0.0, 1.0, 0.3, -2.0],
            [0.1, 0.0, 3.0, 0.5],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let p = mul(&m, &inverse(&m).unwrap());
        for i in 0..4 {
            for j in 0..4 {
                assert!((p[i][j] - IDENTITY[i][j]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn polar_of_rotation_times_scale() {
        let r = quat_to_mat3_64(normalize_quat64([0.9, 0.1, -0.3, 0.2]));
        let s = [[2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 1.5]];
        let (u, p) = polar_decompose(&mul3(&r, &s));
        for i in 0..3 {
            for j in 0..3 {
                assert!((u[i][j] - r[i][j]).abs() < 1e-12);
                assert!((p[i][j] - s[i][j]).abs() < 1e-12);
            }
        }
    }
}
