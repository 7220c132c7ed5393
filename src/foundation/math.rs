//! Small f32 vector maths for the hot path: the `Vec3` value type with operators, and
//! the older free functions on plain `[f32; 3]` arrays (`V3`) that the modules not yet
//! converted still call. Both compute the same expressions in the same order, so a
//! module moves from one to the other without changing a bit of its results.

use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

pub type V3 = [f32; 3];

/// A 3-component f32 vector or colour (Cycles' `float3`).
///
/// Named fields rather than an array inside: code reads `v.x` as Cycles' does, and
/// `Index` still serves the loops over channels. `repr(C)` keeps the layout of a
/// `[f32; 3]`, so the conversions to and from stored arrays cost nothing.
///
/// Every operator is component-wise with no fused multiply-add and no reassociation:
/// `a + b * f` is `madd(a, b, f)`, `v * (1.0 / l)` is `scale(v, 1.0 / l)` and `v / l`
/// divides each component, as the expression reads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Vec3 {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// Shorthand for `Vec3::new`.
#[inline(always)]
pub const fn vec3(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3 { x, y, z }
}

impl Vec3 {
    pub const ZERO: Vec3 = vec3(0.0, 0.0, 0.0);
    pub const ONE: Vec3 = vec3(1.0, 1.0, 1.0);
    pub const X: Vec3 = vec3(1.0, 0.0, 0.0);
    pub const Y: Vec3 = vec3(0.0, 1.0, 0.0);
    pub const Z: Vec3 = vec3(0.0, 0.0, 1.0);

    #[inline(always)]
    pub const fn new(x: f32, y: f32, z: f32) -> Vec3 {
        Vec3 { x, y, z }
    }
    /// All three components `v`.
    #[inline(always)]
    pub const fn splat(v: f32) -> Vec3 {
        Vec3 { x: v, y: v, z: v }
    }
    #[inline(always)]
    pub const fn to_array(self) -> [f32; 3] {
        [self.x, self.y, self.z]
    }
    /// `f` on each component.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Vec3 {
        vec3(f(self.x), f(self.y), f(self.z))
    }
    /// `f` on each pair of components.
    #[inline(always)]
    pub fn zip(self, o: Vec3, f: impl Fn(f32, f32) -> f32) -> Vec3 {
        vec3(f(self.x, o.x), f(self.y, o.y), f(self.z, o.z))
    }
    /// `x * o.x + y * o.y + z * o.z`, summed left to right.
    #[inline(always)]
    pub fn dot(self, o: Vec3) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub fn cross(self, o: Vec3) -> Vec3 {
        vec3(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline(always)]
    pub fn length_squared(self) -> f32 {
        self.dot(self)
    }
    #[inline(always)]
    pub fn length(self) -> f32 {
        self.dot(self).sqrt()
    }
    /// Unit vector by multiplying with the reciprocal length; a zero (or NaN) length
    /// leaves the vector as it is (the free `normalize`).
    #[inline(always)]
    pub fn normalize(self) -> Vec3 {
        let l = self.length();
        if l > 0.0 {
            self * (1.0 / l)
        } else {
            self
        }
    }
    /// Cycles' `average`: the mean of the three channels.
    #[inline(always)]
    pub fn average(self) -> f32 {
        (self.x + self.y + self.z) / 3.0
    }
    /// The largest component (`f32::max`, so a NaN loses).
    #[inline(always)]
    pub fn max_element(self) -> f32 {
        self.x.max(self.y).max(self.z)
    }
    /// The smallest component (`f32::min`, so a NaN loses).
    #[inline(always)]
    pub fn min_element(self) -> f32 {
        self.x.min(self.y).min(self.z)
    }
    /// Component-wise `f32::min`.
    #[inline(always)]
    pub fn min(self, o: Vec3) -> Vec3 {
        vec3(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    /// Component-wise `f32::max`.
    #[inline(always)]
    pub fn max(self, o: Vec3) -> Vec3 {
        vec3(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    #[inline(always)]
    pub fn abs(self) -> Vec3 {
        self.map(f32::abs)
    }
    /// Every component finite (no NaN or infinity).
    #[inline(always)]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    /// Every component equal to zero (either sign).
    #[inline(always)]
    pub fn is_zero(self) -> bool {
        self.x == 0.0 && self.y == 0.0 && self.z == 0.0
    }
    /// An orthonormal basis around the unit vector `self` (Duff et al. 2017), for local
    /// shading frames (the free `basis`).
    #[inline]
    pub fn basis(self) -> (Vec3, Vec3) {
        let n = self;
        let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
        let a = -1.0 / (s + n.z);
        let b = n.x * n.y * a;
        (
            vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
            vec3(b, s + n.y * n.y * a, -n.y),
        )
    }
    /// `v` written in the frame `(t, b, self)`: `(v.t, v.b, v.self)`.
    #[inline(always)]
    pub fn to_frame(self, t: Vec3, b: Vec3, v: Vec3) -> Vec3 {
        vec3(v.dot(t), v.dot(b), v.dot(self))
    }
}

impl From<[f32; 3]> for Vec3 {
    #[inline(always)]
    fn from(a: [f32; 3]) -> Vec3 {
        vec3(a[0], a[1], a[2])
    }
}
impl From<Vec3> for [f32; 3] {
    #[inline(always)]
    fn from(v: Vec3) -> [f32; 3] {
        [v.x, v.y, v.z]
    }
}

impl Index<usize> for Vec3 {
    type Output = f32;
    #[inline(always)]
    fn index(&self, i: usize) -> &f32 {
        match i {
            0 => &self.x,
            1 => &self.y,
            2 => &self.z,
            _ => panic!("Vec3 index {i} out of range"),
        }
    }
}
impl IndexMut<usize> for Vec3 {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        match i {
            0 => &mut self.x,
            1 => &mut self.y,
            2 => &mut self.z,
            _ => panic!("Vec3 index {i} out of range"),
        }
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn add(self, o: Vec3) -> Vec3 {
        vec3(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn sub(self, o: Vec3) -> Vec3 {
        vec3(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
/// Component-wise product (colours times colours).
impl Mul for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn mul(self, o: Vec3) -> Vec3 {
        vec3(self.x * o.x, self.y * o.y, self.z * o.z)
    }
}
impl Mul<f32> for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn mul(self, f: f32) -> Vec3 {
        vec3(self.x * f, self.y * f, self.z * f)
    }
}
/// `f * v` is `v * f` (the vector's component first, as `scale` multiplies).
impl Mul<Vec3> for f32 {
    type Output = Vec3;
    #[inline(always)]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}
/// Component-wise quotient.
impl Div for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn div(self, o: Vec3) -> Vec3 {
        vec3(self.x / o.x, self.y / o.y, self.z / o.z)
    }
}
/// Each component divided by `f` (a true division, not a multiply by `1 / f`).
impl Div<f32> for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn div(self, f: f32) -> Vec3 {
        vec3(self.x / f, self.y / f, self.z / f)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn neg(self) -> Vec3 {
        vec3(-self.x, -self.y, -self.z)
    }
}
impl AddAssign for Vec3 {
    #[inline(always)]
    fn add_assign(&mut self, o: Vec3) {
        *self = *self + o;
    }
}
impl SubAssign for Vec3 {
    #[inline(always)]
    fn sub_assign(&mut self, o: Vec3) {
        *self = *self - o;
    }
}
impl MulAssign for Vec3 {
    #[inline(always)]
    fn mul_assign(&mut self, o: Vec3) {
        *self = *self * o;
    }
}
impl MulAssign<f32> for Vec3 {
    #[inline(always)]
    fn mul_assign(&mut self, f: f32) {
        *self = *self * f;
    }
}
impl DivAssign<f32> for Vec3 {
    #[inline(always)]
    fn div_assign(&mut self, f: f32) {
        *self = *self / f;
    }
}
impl std::iter::Sum for Vec3 {
    /// Summed in order from zero, as a loop of `+=` does.
    fn sum<I: Iterator<Item = Vec3>>(it: I) -> Vec3 {
        it.fold(Vec3::ZERO, |a, b| a + b)
    }
}

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
    /// `point` on a `Vec3` (the array forms stay for the modules not yet converted).
    #[inline]
    pub fn point_vec3(&self, p: Vec3) -> Vec3 {
        self.point(p.into()).into()
    }
    /// `vector` on a `Vec3`.
    #[inline]
    pub fn vector_vec3(&self, v: Vec3) -> Vec3 {
        self.vector(v.into()).into()
    }
    /// `column` as a `Vec3`.
    #[inline]
    pub fn column_vec3(&self, i: usize) -> Vec3 {
        self.column(i).into()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Values of every magnitude and sign, zeros of both signs, infinities and NaN, from
    /// a fixed generator (the same cases on every run).
    fn values() -> Vec<f32> {
        let mut v = vec![0.0, -0.0, 1.0, -1.0, 0.5, 3.0, 1e-30, -1e30];
        v.extend([
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MIN_POSITIVE,
        ]);
        let mut s = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..600 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Mostly moderate exponents, some extreme ones.
            let m = (s >> 40) as u32 & 0x007f_ffff;
            let e = if s & 7 == 0 {
                (s >> 8) as u32 & 0xfe
            } else {
                110 + (s >> 8) as u32 % 40
            };
            v.push(f32::from_bits(((s >> 63) as u32) << 31 | e << 23 | m));
        }
        v
    }

    fn vectors() -> Vec<V3> {
        let v = values();
        (0..v.len())
            .map(|i| [v[i], v[(i * 7 + 3) % v.len()], v[(i * 13 + 5) % v.len()]])
            .collect()
    }

    fn bits(a: V3) -> [u32; 3] {
        a.map(f32::to_bits)
    }
    fn same(a: Vec3, b: V3) {
        assert_eq!(bits(a.into()), bits(b), "{a:?} vs {b:?}");
    }
    fn same_f(a: f32, b: f32) {
        assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
    }

    /// Each operator and method gives the bits the free function gave.
    #[test]
    fn operators_match_the_free_functions_bit_for_bit() {
        let vs = vectors();
        let fs = values();
        for (i, &a) in vs.iter().enumerate() {
            let b = vs[(i * 5 + 1) % vs.len()];
            let f = fs[(i * 11 + 2) % fs.len()];
            let (va, vb) = (Vec3::from(a), Vec3::from(b));
            same(va + vb, add(a, b));
            same(va - vb, sub(a, b));
            same(va * vb, mul(a, b));
            same(va * f, scale(a, f));
            same(f * va, scale(a, f));
            same(va + vb * f, madd(a, b, f));
            same(-va, neg(a));
            same(va.cross(vb), cross(a, b));
            same(va.normalize(), normalize(a));
            same(va.min(vb), vmin(a, b));
            same(va.max(vb), vmax(a, b));
            same(va / f, [a[0] / f, a[1] / f, a[2] / f]);
            same(va / vb, [a[0] / b[0], a[1] / b[1], a[2] / b[2]]);
            same_f(va.dot(vb), dot(a, b));
            same_f(va.length(), len(a));
            same_f(va.average(), average(a));
            same_f(va.max_element(), max3(a));
            assert_eq!(va.is_finite(), finite(a));
            assert_eq!(va.is_zero(), is_zero(a));
            let (t, bb) = va.basis();
            let (t0, b0) = basis(a);
            same(t, t0);
            same(bb, b0);
            let mut c = va;
            c += vb;
            same(c, add(a, b));
            c -= vb;
            same(c, sub(add(a, b), b));
            c *= f;
            same(c, scale(sub(add(a, b), b), f));
            c *= vb;
            same(c, mul(scale(sub(add(a, b), b), f), b));
            let mut d = va;
            d /= f;
            same(d, (va / f).into());
        }
    }

    /// `*` by a scalar is not `/` by its reciprocal, and `normalize` keeps the reciprocal
    /// multiply of the free function (the two differ in the last bit for some lengths).
    #[test]
    fn division_and_reciprocal_stay_distinct() {
        let v = vec3(1.0, 2.0, 2.0);
        let l = 3.0f32;
        assert_eq!(v / l, vec3(1.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0));
        let differs = values()
            .into_iter()
            .filter(|x| x.is_normal() && x.abs() > 1e-20 && x.abs() < 1e20)
            .any(|x| (Vec3::splat(0.7) / x).x != (Vec3::splat(0.7) * (1.0 / x)).x);
        assert!(differs, "some divisor tells x / l from x * (1 / l)");
    }

    #[test]
    fn conversions_index_and_constants() {
        let a = [1.5f32, -2.0, 0.25];
        let v = Vec3::from(a);
        assert_eq!((v.x, v.y, v.z), (1.5, -2.0, 0.25));
        assert_eq!((v[0], v[1], v[2]), (1.5, -2.0, 0.25));
        let back: [f32; 3] = v.into();
        assert_eq!(back, a);
        let mut w = v;
        w[1] = 7.0;
        assert_eq!(w, vec3(1.5, 7.0, 0.25));
        assert_eq!(Vec3::default(), Vec3::ZERO);
        assert_eq!(Vec3::splat(1.0), Vec3::ONE);
        assert_eq!(Vec3::X.cross(Vec3::Y), Vec3::Z);
        assert_eq!(v.map(|c| c * 2.0), vec3(3.0, -4.0, 0.5));
        assert_eq!(v.abs().min_element(), 0.25);
        let s: Vec3 = [v, w].into_iter().sum();
        assert_eq!(s, v + w);
        assert_eq!(std::mem::size_of::<Vec3>(), 12);
    }

    #[test]
    #[should_panic(expected = "out of range")]
    fn index_out_of_range_panics() {
        let _ = Vec3::ZERO[3];
    }
}
