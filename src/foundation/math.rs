//! Small f32 vector helpers for the hot path (plain arrays, no allocation).

pub type V3 = [f32; 3];

#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline(always)]
pub fn mul(a: V3, b: V3) -> V3 {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}
#[inline(always)]
pub fn scale(a: V3, f: f32) -> V3 {
    [a[0] * f, a[1] * f, a[2] * f]
}
/// Cycles' `average`: the mean of the three channels.
#[inline(always)]
pub fn average(a: V3) -> f32 {
    (a[0] + a[1] + a[2]) / 3.0
}
#[inline(always)]
pub fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline(always)]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline(always)]
pub fn len(a: V3) -> f32 {
    dot(a, a).sqrt()
}
#[inline(always)]
pub fn normalize(a: V3) -> V3 {
    let l = len(a);
    if l > 0.0 {
        scale(a, 1.0 / l)
    } else {
        a
    }
}
#[inline(always)]
pub fn neg(a: V3) -> V3 {
    [-a[0], -a[1], -a[2]]
}
#[inline(always)]
pub fn madd(a: V3, b: V3, f: f32) -> V3 {
    [a[0] + b[0] * f, a[1] + b[1] * f, a[2] + b[2] * f]
}
/// Cycles' `Transform`: a 3x4 row-major affine matrix (the last column translates).
pub type Transform = [[f32; 4]; 3];

/// Cycles' `transform_point`.
#[inline(always)]
pub fn transform_point(m: &Transform, p: V3) -> V3 {
    std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
}
/// Cycles' `transform_direction`: the 3x3 part only.
#[inline(always)]
pub fn transform_direction(m: &Transform, d: V3) -> V3 {
    std::array::from_fn(|r| m[r][0] * d[0] + m[r][1] * d[1] + m[r][2] * d[2])
}
/// Cycles' `transform_direction_transposed`: by the transpose of the 3x3 part (normals
/// go through the transposed inverse).
#[inline(always)]
pub fn transform_direction_transposed(m: &Transform, d: V3) -> V3 {
    std::array::from_fn(|c| m[0][c] * d[0] + m[1][c] * d[1] + m[2][c] * d[2])
}
/// A ray origin just off a surface at `p` (true normal `ng`), on the side `dir` leaves
/// toward, so the ray does not hit the surface it starts on.
#[inline]
pub fn offset_origin(p: V3, ng: V3, dir: V3) -> V3 {
    let eps = 1e-5 * (1.0 + max3(p.map(f32::abs)));
    if dot(dir, ng) >= 0.0 {
        madd(p, ng, eps)
    } else {
        madd(p, ng, -eps)
    }
}
#[inline(always)]
pub fn max3(a: V3) -> f32 {
    a[0].max(a[1]).max(a[2])
}
/// Every component finite (no NaN or infinity).
#[inline(always)]
pub fn finite(v: V3) -> bool {
    v.iter().all(|x| x.is_finite())
}

#[inline(always)]
pub fn is_zero(a: V3) -> bool {
    a[0] == 0.0 && a[1] == 0.0 && a[2] == 0.0
}
#[inline(always)]
pub fn vmin(a: V3, b: V3) -> V3 {
    [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])]
}
#[inline(always)]
pub fn vmax(a: V3, b: V3) -> V3 {
    [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])]
}

/// An orthonormal basis around `n` (Duff et al. 2017), for local shading frames.
#[inline]
pub fn basis(n: V3) -> (V3, V3) {
    let s = if n[2] >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    (
        [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
        [b, s + n[1] * n[1] * a, -n[1]],
    )
}

/// Row-major affine transform (3x4, f32), as the exchange format's matrices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    pub m: [[f32; 4]; 3],
}

impl Affine {
    pub fn from_rows(m: &[[f64; 4]; 4]) -> Affine {
        let mut o = [[0.0f32; 4]; 3];
        for r in 0..3 {
            for c in 0..4 {
                o[r][c] = m[r][c] as f32;
            }
        }
        Affine { m: o }
    }
    #[inline]
    pub fn point(&self, p: V3) -> V3 {
        let m = &self.m;
        [
            m[0][0] * p[0] + m[0][1] * p[1] + m[0][2] * p[2] + m[0][3],
            m[1][0] * p[0] + m[1][1] * p[1] + m[1][2] * p[2] + m[1][3],
            m[2][0] * p[0] + m[2][1] * p[1] + m[2][2] * p[2] + m[2][3],
        ]
    }
    #[inline]
    pub fn vector(&self, v: V3) -> V3 {
        let m = &self.m;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }
    pub fn column(&self, i: usize) -> V3 {
        [self.m[0][i], self.m[1][i], self.m[2][i]]
    }
    /// Inverse (None when singular), computed in f64.
    pub fn inverse(&self) -> Option<Affine> {
        let a = |r: usize, c: usize| self.m[r][c] as f64;
        let det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
            - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
            + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
        if det.abs() < 1e-30 || !det.is_finite() {
            return None;
        }
        let d = 1.0 / det;
        let mut i = [[0.0f64; 4]; 4];
        i[0][0] = (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) * d;
        i[0][1] = (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) * d;
        i[0][2] = (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) * d;
        i[1][0] = (a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2)) * d;
        i[1][1] = (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) * d;
        i[1][2] = (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) * d;
        i[2][0] = (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0)) * d;
        i[2][1] = (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) * d;
        i[2][2] = (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) * d;
        let t = [a(0, 3), a(1, 3), a(2, 3)];
        for r in 0..3 {
            i[r][3] = -(i[r][0] * t[0] + i[r][1] * t[1] + i[r][2] * t[2]);
        }
        i[3][3] = 1.0;
        Some(Affine::from_rows(&i))
    }
    /// Transforms a normal by the inverse transpose.
    #[inline]
    pub fn normal_by_inverse(inv: &Affine, n: V3) -> V3 {
        let m = &inv.m;
        [
            m[0][0] * n[0] + m[1][0] * n[1] + m[2][0] * n[2],
            m[0][1] * n[0] + m[1][1] * n[1] + m[2][1] * n[2],
            m[0][2] * n[0] + m[1][2] * n[1] + m[2][2] * n[2],
        ]
    }
    pub fn to_rows(&self) -> [[f32; 4]; 4] {
        [self.m[0], self.m[1], self.m[2], [0.0, 0.0, 0.0, 1.0]]
    }
}
