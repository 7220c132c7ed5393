//! Perlin noise and the Noise Texture node, as Blender's CPU implementation
//! (`blenlib/intern/noise.cc`, used by Geometry Nodes and by the texture nodes evaluated on
//! the CPU) computes it: Improved Perlin noise over the lookup3 hash, fractal variants
//! (fBM, multifractal, hybrid / ridged multifractal, hetero terrain), seeded offsets and
//! domain distortion.
//!
//! Precision follows the C++ exactly where it matters: `fade` and the bilinear blend are
//! evaluated in double (their literals are doubles), everything else in single precision.
//! Cycles' SVM kernel computes the same functions but `fade` in single precision (and with
//! SSE/AVX variants), so its values may differ from these in the last bit.
//!
//! Speed: the 2^N lattice corners of a point are hashed and their gradients taken in one
//! loop without dependencies between corners, which the compiler turns into AVX2
//! vector code (8 corners per instruction); the period wrap skips `fmod` for the
//! coordinates that do not need it; zero distortion is skipped where that gives the same
//! bits. tests/noise_speed.rs checks every result against the previous code.

use super::random::{hash_float_to_float1, hash_float_to_float2};
use super::white_noise::lookup3::{hash1, hash2, hash3_x8, hash4};

#[inline(always)]
fn fade(t: f32) -> f32 {
    ((t * t * t) as f64 * (t as f64 * (t as f64 * 6.0 - 15.0) + 10.0)) as f32
}

#[inline(always)]
fn negate_if(v: f32, cond: u32) -> f32 {
    if cond != 0 {
        -v
    } else {
        v
    }
}

#[inline(always)]
fn grad1(hash: u32, x: f32) -> f32 {
    let h = hash & 15;
    let g = (1 + (h & 7)) as f32;
    negate_if(g, h & 8) * x
}

#[inline(always)]
fn grad2(hash: u32, x: f32, y: f32) -> f32 {
    let h = hash & 7;
    let u = if h < 4 { x } else { y };
    let v = 2.0 * if h < 4 { y } else { x };
    negate_if(u, h & 1) + negate_if(v, h & 2)
}

/// The scalar gradient; AVX2 builds use `grad3_x8` instead.
#[cfg_attr(all(target_arch = "x86_64", target_feature = "avx2"), allow(dead_code))]
#[inline(always)]
fn grad3(hash: u32, x: f32, y: f32, z: f32) -> f32 {
    let h = hash & 15;
    let u = if h < 8 { x } else { y };
    let vt = if h == 12 || h == 14 { x } else { z };
    let v = if h < 4 { y } else { vt };
    negate_if(u, h & 1) + negate_if(v, h & 2)
}

/// `grad3` of 8 corners at once: written out for AVX2, like the corner hashes, because
/// the compiler unrolls the 8 corners and then moves each hash to a scalar register.
#[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
#[inline(always)]
fn grad3_x8(hash: [u32; 8], x: [f32; 8], y: [f32; 8], z: [f32; 8]) -> [f32; 8] {
    use std::arch::x86_64::*;
    // SAFETY: AVX2 is enabled for the whole build (the cfg above); loads and stores are
    // unaligned ones of whole 8-lane arrays.
    unsafe {
        let (x, y, z) = (
            _mm256_loadu_ps(x.as_ptr()),
            _mm256_loadu_ps(y.as_ptr()),
            _mm256_loadu_ps(z.as_ptr()),
        );
        let h = _mm256_and_si256(
            _mm256_loadu_si256(hash.as_ptr().cast()),
            _mm256_set1_epi32(15),
        );
        let is = |k: i32| _mm256_castsi256_ps(_mm256_cmpeq_epi32(h, _mm256_set1_epi32(k)));
        let below = |k: i32| _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(k), h));
        // blendv takes its second operand where the mask is set.
        let u = _mm256_blendv_ps(y, x, below(8));
        let vt = _mm256_blendv_ps(z, x, _mm256_or_ps(is(12), is(14)));
        let v = _mm256_blendv_ps(vt, y, below(4));
        // negate_if: flipping the sign bit is exactly negation.
        let sign = |bit: i32, shift: i32| {
            _mm256_castsi256_ps(_mm256_sllv_epi32(
                _mm256_and_si256(h, _mm256_set1_epi32(bit)),
                _mm256_set1_epi32(shift),
            ))
        };
        let g = _mm256_add_ps(_mm256_xor_ps(u, sign(1, 31)), _mm256_xor_ps(v, sign(2, 30)));
        let mut out = [0.0f32; 8];
        _mm256_storeu_ps(out.as_mut_ptr(), g);
        out
    }
}
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
#[inline(always)]
fn grad3_x8(hash: [u32; 8], x: [f32; 8], y: [f32; 8], z: [f32; 8]) -> [f32; 8] {
    std::array::from_fn(|i| grad3(hash[i], x[i], y[i], z[i]))
}

#[inline(always)]
fn grad4(hash: u32, x: f32, y: f32, z: f32, w: f32) -> f32 {
    let h = hash & 31;
    let u = if h < 24 { x } else { y };
    let v = if h < 16 { y } else { z };
    let s = if h < 8 { z } else { w };
    negate_if(u, h & 1) + negate_if(v, h & 2) + negate_if(s, h & 4)
}

#[inline(always)]
fn lerp(v0: f32, v1: f32, x: f32) -> f32 {
    (1.0 - x) * v0 + x * v1
}

#[inline]
fn bi_mix(v0: f32, v1: f32, v2: f32, v3: f32, x: f32, y: f32) -> f32 {
    let x1 = (1.0 - x as f64) as f32;
    ((1.0 - y as f64) * (v0 * x1 + v1 * x) as f64 + (y * (v2 * x1 + v3 * x)) as f64) as f32
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn tri_mix(v: [f32; 8], x: f32, y: f32, z: f32) -> f32 {
    let x1 = (1.0 - x as f64) as f32;
    let y1 = (1.0 - y as f64) as f32;
    let z1 = (1.0 - z as f64) as f32;
    z1 * (y1 * (v[0] * x1 + v[1] * x) + y * (v[2] * x1 + v[3] * x))
        + z * (y1 * (v[4] * x1 + v[5] * x) + y * (v[6] * x1 + v[7] * x))
}

#[inline(always)]
fn floor_fraction(x: f32) -> (i32, f32) {
    let f = x.floor();
    (f as i32, x - f)
}

fn perlin_noise1(p: f32) -> f32 {
    let (x, fx) = floor_fraction(p);
    let u = fade(fx);
    lerp(
        grad1(hash1(x as u32), fx),
        grad1(hash1(x.wrapping_add(1) as u32), fx - 1.0),
        u,
    )
}

fn perlin_noise2(p: [f32; 2]) -> f32 {
    let (x, fx) = floor_fraction(p[0]);
    let (y, fy) = floor_fraction(p[1]);
    let (u, v) = (fade(fx), fade(fy));
    let h = |dx: i32, dy: i32| hash2(x.wrapping_add(dx) as u32, y.wrapping_add(dy) as u32);
    bi_mix(
        grad2(h(0, 0), fx, fy),
        grad2(h(1, 0), fx - 1.0, fy),
        grad2(h(0, 1), fx, fy - 1.0),
        grad2(h(1, 1), fx - 1.0, fy - 1.0),
        u,
        v,
    )
}

/// The gradients at the 8 corners of the lattice cell of `p` (corner index bit 0: x + 1,
/// bit 1: y + 1, bit 2: z + 1) and the position in the cell.
#[inline(always)]
fn corners3(p: [f32; 3]) -> ([f32; 8], [f32; 3]) {
    let (x, fx) = floor_fraction(p[0]);
    let (y, fy) = floor_fraction(p[1]);
    let (z, fz) = floor_fraction(p[2]);
    let d = |i: usize, bit: usize| (i >> bit & 1) as i32;
    let h = hash3_x8(
        std::array::from_fn(|i| x.wrapping_add(d(i, 0)) as u32),
        std::array::from_fn(|i| y.wrapping_add(d(i, 1)) as u32),
        std::array::from_fn(|i| z.wrapping_add(d(i, 2)) as u32),
    );
    let at = |f: f32, bit: usize| std::array::from_fn(|i| f - d(i, bit) as f32);
    (grad3_x8(h, at(fx, 0), at(fy, 1), at(fz, 2)), [fx, fy, fz])
}

/// The gradients at the 16 corners of the 4D lattice cell of `p` (index bits 0-3: x, y,
/// z, w + 1) and the position in the cell.
#[inline(always)]
fn corners4(p: [f32; 4]) -> ([f32; 16], [f32; 4]) {
    let (x, fx) = floor_fraction(p[0]);
    let (y, fy) = floor_fraction(p[1]);
    let (z, fz) = floor_fraction(p[2]);
    let (w, fw) = floor_fraction(p[3]);
    let mut g = [0.0f32; 16];
    for (i, g) in g.iter_mut().enumerate() {
        let [dx, dy, dz, dw] = [i & 1, i >> 1 & 1, i >> 2 & 1, i >> 3 & 1].map(|d| d as i32);
        let h = hash4(
            x.wrapping_add(dx) as u32,
            y.wrapping_add(dy) as u32,
            z.wrapping_add(dz) as u32,
            w.wrapping_add(dw) as u32,
        );
        *g = grad4(
            h,
            fx - dx as f32,
            fy - dy as f32,
            fz - dz as f32,
            fw - dw as f32,
        );
    }
    (g, [fx, fy, fz, fw])
}

#[inline(always)]
fn half(g: &[f32; 16], from: usize) -> [f32; 8] {
    std::array::from_fn(|i| g[from + i])
}

#[inline(always)]
fn perlin_noise3(p: [f32; 3]) -> f32 {
    let (g, [fx, fy, fz]) = corners3(p);
    tri_mix(g, fade(fx), fade(fy), fade(fz))
}

#[inline(always)]
fn perlin_noise4(p: [f32; 4]) -> f32 {
    let (g, [fx, fy, fz, fw]) = corners4(p);
    let (u, v, t, s) = (fade(fx), fade(fy), fade(fz), fade(fw));
    let a = tri_mix(half(&g, 0), u, v, t);
    let b = tri_mix(half(&g, 8), u, v, t);
    lerp(a, b, s)
}

/// A point of 1 to 4 dimensions, so the fractal functions are written once.
pub trait NoisePoint: Copy {
    fn perlin_signed(self) -> f32;
    fn scaled(self, s: f32) -> Self;
    fn plus(self, o: Self) -> Self;
    /// `random_floatN_offset(seed)`.
    fn offset(seed: f32) -> Self;
    /// `perlin_distortion(p, strength)`.
    fn distortion(self, strength: f32) -> Self;
    /// `p + distortion(p, strength)`.
    fn distorted(self, strength: f32) -> Self {
        self.plus(self.distortion(strength))
    }
    /// Whether every component satisfies `f`.
    fn all(self, f: impl Fn(f32) -> bool) -> bool;
    /// Whether `a * b + c` is one fused operation, as in Cycles' FMA-built CPU kernels
    /// (GCC contracts them); Blender's own CPU code is built without FMA.
    const FUSED: bool = false;
    /// `perlin_signed` of each point of `ps` into `out` (as long as `ps`). Points whose
    /// flavour has a lane-parallel kernel override it (the same bits); the rest loop.
    fn perlin_signed_batch(ps: &[Self], out: &mut [f32]) {
        for (o, p) in out.iter_mut().zip(ps) {
            *o = p.perlin_signed();
        }
    }
    /// `perlin_signed` of `self.scaled(s)` for each scale `s` of `scales` into `out`:
    /// fBm's octaves. Flavours with a lane-parallel kernel override it (the same bits).
    fn perlin_signed_scaled(self, scales: &[f32], out: &mut [f32]) {
        const MAX: usize = 17;
        let mut pts = [self; MAX];
        for (q, &s) in pts.iter_mut().zip(scales) {
            *q = self.scaled(s);
        }
        Self::perlin_signed_batch(&pts[..scales.len()], out);
    }
}

#[inline]
fn madd<P: NoisePoint>(a: f32, b: f32, c: f32) -> f32 {
    if P::FUSED {
        a.mul_add(b, c)
    } else {
        a * b + c
    }
}

/// Linear blend: Cycles' `a + t * (b - a)` (fused) or Blender's `interpf`.
#[inline]
fn blend<P: NoisePoint>(a: f32, b: f32, t: f32) -> f32 {
    if P::FUSED {
        t.mul_add(b - a, a)
    } else {
        lerp(a, b, t)
    }
}

#[inline(always)]
fn correction(v: f32) -> f32 {
    0.5 * (v.abs() >= 1_000_000.0) as u8 as f32
}

/// `v % 100000`, calling `fmod` only where it changes `v` (it returns any |v| < 100000,
/// signed zeros included, unchanged).
#[inline(always)]
fn wrap(v: f32) -> f32 {
    if v.abs() < 100000.0 {
        v
    } else {
        fmod_period(v)
    }
}

/// `v % 100000` for |v| >= 100000, out of line (LLVM treats `%` as free of side effects
/// and would otherwise compute it on both branches of `wrap`). Below 2^24 it is computed
/// exactly in f64 instead of by the libm loop: the quotient's truncation is exact there
/// (a float at least 1e5 in size is a multiple of 1e5 or at least 2^-7 away from one), so
/// are the product and the difference, and the remainder fits an f32; fmod gives a zero
/// the sign of v.
#[inline(never)]
fn fmod_period(v: f32) -> f32 {
    if v.abs() < 16_777_216.0 {
        let x = v as f64;
        let r = x - (x / 100000.0).trunc() * 100000.0;
        if r == 0.0 {
            0.0f32.copysign(v)
        } else {
            r as f32
        }
    } else {
        v % 100000.0
    }
}

/// `p.distorted(strength)`, skipping the noise where it cannot change p: with strength
/// 0, p + noise * 0 is p when p is finite (then so is its noise) and not -0 (-0 + +0 is
/// +0).
#[inline(always)]
fn distorted<P: NoisePoint>(p: P, strength: f32) -> P {
    if strength == 0.0 && p.all(|x| x.is_finite() && x.to_bits() != (-0.0f32).to_bits()) {
        p
    } else {
        p.distorted(strength)
    }
}

impl NoisePoint for f32 {
    #[inline]
    fn perlin_signed(self) -> f32 {
        let p = wrap(self) + correction(self);
        perlin_noise1(p) * 0.25
    }
    fn scaled(self, s: f32) -> Self {
        s * self
    }
    fn plus(self, o: Self) -> Self {
        self + o
    }
    fn offset(seed: f32) -> Self {
        100.0 + hash_float_to_float1(seed) * 100.0
    }
    fn distortion(self, strength: f32) -> Self {
        (self + Self::offset(0.0)).perlin_signed() * strength
    }
    fn all(self, f: impl Fn(f32) -> bool) -> bool {
        f(self)
    }
}

fn offset_component(seed: f32, k: f32) -> f32 {
    100.0 + hash_float_to_float2([seed, k]) * 100.0
}

impl NoisePoint for [f32; 2] {
    fn all(self, f: impl Fn(f32) -> bool) -> bool {
        self.iter().all(|&x| f(x))
    }
    #[inline]
    fn perlin_signed(self) -> f32 {
        let p = [
            wrap(self[0]) + correction(self[0]),
            wrap(self[1]) + correction(self[1]),
        ];
        perlin_noise2(p) * 0.6616
    }
    fn scaled(self, s: f32) -> Self {
        [s * self[0], s * self[1]]
    }
    fn plus(self, o: Self) -> Self {
        [self[0] + o[0], self[1] + o[1]]
    }
    fn offset(seed: f32) -> Self {
        [offset_component(seed, 0.0), offset_component(seed, 1.0)]
    }
    fn distortion(self, strength: f32) -> Self {
        [
            self.plus(Self::offset(0.0)).perlin_signed() * strength,
            self.plus(Self::offset(1.0)).perlin_signed() * strength,
        ]
    }
}

impl NoisePoint for [f32; 3] {
    fn all(self, f: impl Fn(f32) -> bool) -> bool {
        self.iter().all(|&x| f(x))
    }
    #[inline]
    fn perlin_signed(self) -> f32 {
        let p = self.map(|v| wrap(v) + correction(v));
        perlin_noise3(p) * 0.9820
    }
    fn scaled(self, s: f32) -> Self {
        [s * self[0], s * self[1], s * self[2]]
    }
    fn plus(self, o: Self) -> Self {
        [self[0] + o[0], self[1] + o[1], self[2] + o[2]]
    }
    fn offset(seed: f32) -> Self {
        [
            offset_component(seed, 0.0),
            offset_component(seed, 1.0),
            offset_component(seed, 2.0),
        ]
    }
    fn distortion(self, strength: f32) -> Self {
        [
            self.plus(Self::offset(0.0)).perlin_signed() * strength,
            self.plus(Self::offset(1.0)).perlin_signed() * strength,
            self.plus(Self::offset(2.0)).perlin_signed() * strength,
        ]
    }
}

impl NoisePoint for [f32; 4] {
    fn all(self, f: impl Fn(f32) -> bool) -> bool {
        self.iter().all(|&x| f(x))
    }
    #[inline]
    fn perlin_signed(self) -> f32 {
        let p = self.map(|v| wrap(v) + correction(v));
        perlin_noise4(p) * 0.8344
    }
    fn scaled(self, s: f32) -> Self {
        [s * self[0], s * self[1], s * self[2], s * self[3]]
    }
    fn plus(self, o: Self) -> Self {
        [
            self[0] + o[0],
            self[1] + o[1],
            self[2] + o[2],
            self[3] + o[3],
        ]
    }
    fn offset(seed: f32) -> Self {
        [
            offset_component(seed, 0.0),
            offset_component(seed, 1.0),
            offset_component(seed, 2.0),
            offset_component(seed, 3.0),
        ]
    }
    fn distortion(self, strength: f32) -> Self {
        [
            self.plus(Self::offset(0.0)).perlin_signed() * strength,
            self.plus(Self::offset(1.0)).perlin_signed() * strength,
            self.plus(Self::offset(2.0)).perlin_signed() * strength,
            self.plus(Self::offset(3.0)).perlin_signed() * strength,
        ]
    }
}

/// Perlin noise in [0, 1].
pub fn perlin<P: NoisePoint>(p: P) -> f32 {
    p.perlin_signed() / 2.0 + 0.5
}

pub fn fbm<P: NoisePoint>(
    p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    normalize: bool,
) -> f32 {
    // The octaves' noise values do not depend on each other, only their sum does: up to
    // MAX_BATCH of them are evaluated first, as one batch (lanes of the Cycles kernel),
    // then summed in the loop's order, so the result is the same bits.
    const MAX_BATCH: usize = 17;
    let whole = detail as i32;
    let rmd = detail - detail.floor();
    let count = if whole < 0 { 0 } else { whole as usize + 1 } + (rmd != 0.0) as usize;
    if count <= MAX_BATCH {
        let mut scales = [0.0f32; MAX_BATCH];
        let mut fscale = 1.0f32;
        for s in scales.iter_mut().take(count) {
            *s = fscale;
            fscale *= lacunarity;
        }
        let mut t = [0.0f32; MAX_BATCH];
        p.perlin_signed_scaled(&scales[..count], &mut t[..count]);
        return fbm_sum::<P>(&t[..count], detail, roughness, normalize);
    }
    let mut fscale = 1.0f32;
    let mut amp = 1.0f32;
    let mut maxamp = 0.0f32;
    let mut sum = 0.0f32;
    for _ in 0..=(detail as i32) {
        let t = p.scaled(fscale).perlin_signed();
        sum = madd::<P>(t, amp, sum);
        maxamp += amp;
        amp *= roughness;
        fscale *= lacunarity;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        let t = p.scaled(fscale).perlin_signed();
        let sum2 = madd::<P>(t, amp, sum);
        return if normalize {
            blend::<P>(
                0.5 * sum / maxamp + 0.5,
                0.5 * sum2 / (maxamp + amp) + 0.5,
                rmd,
            )
        } else {
            blend::<P>(sum, sum2, rmd)
        };
    }
    if normalize {
        0.5 * sum / maxamp + 0.5
    } else {
        sum
    }
}

/// `fbm`'s sum over the octaves' noise values `t` (the whole octaves, then the fraction's
/// one when `detail` has a fraction), in `fbm`'s order of operations.
#[inline(always)]
fn fbm_sum<P: NoisePoint>(t: &[f32], detail: f32, roughness: f32, normalize: bool) -> f32 {
    let mut amp = 1.0f32;
    let mut maxamp = 0.0f32;
    let mut sum = 0.0f32;
    let rmd = detail - detail.floor();
    let whole = t.len() - (rmd != 0.0) as usize;
    for &t in &t[..whole] {
        sum = madd::<P>(t, amp, sum);
        maxamp += amp;
        amp *= roughness;
    }
    if rmd != 0.0 {
        let sum2 = madd::<P>(t[whole], amp, sum);
        return if normalize {
            blend::<P>(
                0.5 * sum / maxamp + 0.5,
                0.5 * sum2 / (maxamp + amp) + 0.5,
                rmd,
            )
        } else {
            blend::<P>(sum, sum2, rmd)
        };
    }
    if normalize {
        0.5 * sum / maxamp + 0.5
    } else {
        sum
    }
}

pub fn multi_fractal<P: NoisePoint>(mut p: P, detail: f32, roughness: f32, lacunarity: f32) -> f32 {
    let mut value = 1.0f32;
    let mut pwr = 1.0f32;
    for _ in 0..=(detail as i32) {
        value *= madd::<P>(pwr, p.perlin_signed(), 1.0);
        pwr *= roughness;
        p = p.scaled(lacunarity);
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        value *= madd::<P>(rmd * pwr, p.perlin_signed(), 1.0);
    }
    value
}

pub fn hetero_terrain<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
) -> f32 {
    let mut pwr = roughness;
    let mut value = offset + p.perlin_signed();
    p = p.scaled(lacunarity);
    for _ in 1..=(detail as i32) {
        value = madd::<P>((p.perlin_signed() + offset) * pwr, value, value);
        pwr *= roughness;
        p = p.scaled(lacunarity);
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        let increment = (p.perlin_signed() + offset) * pwr * value;
        value = madd::<P>(rmd, increment, value);
    }
    value
}

pub fn hybrid_multi_fractal<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
    gain: f32,
) -> f32 {
    let mut pwr = 1.0f32;
    let mut value = 0.0f32;
    let mut weight = 1.0f32;
    let mut i = 0;
    while weight > 0.001 && i <= detail as i32 {
        if weight > 1.0 {
            weight = 1.0;
        }
        let signal = (p.perlin_signed() + offset) * pwr;
        pwr *= roughness;
        value = madd::<P>(weight, signal, value);
        weight *= gain * signal;
        p = p.scaled(lacunarity);
        i += 1;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 && weight > 0.001 {
        if weight > 1.0 {
            weight = 1.0;
        }
        let signal = (p.perlin_signed() + offset) * pwr;
        value = madd::<P>(rmd * weight, signal, value);
    }
    value
}

pub fn ridged_multi_fractal<P: NoisePoint>(
    mut p: P,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    offset: f32,
    gain: f32,
) -> f32 {
    let mut pwr = roughness;
    let mut signal = offset - p.perlin_signed().abs();
    signal *= signal;
    let mut value = signal;
    for _ in 1..=(detail as i32) {
        p = p.scaled(lacunarity);
        let weight = (signal * gain).clamp(0.0, 1.0);
        signal = offset - p.perlin_signed().abs();
        signal *= signal;
        signal *= weight;
        value = madd::<P>(signal, pwr, value);
        pwr *= roughness;
    }
    value
}

/// The Noise Texture's `noise_type`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseType {
    MultiFractal,
    Fbm,
    HybridMultiFractal,
    RidgedMultiFractal,
    HeteroTerrain,
}

impl NoiseType {
    pub fn from_blender(s: &str) -> Option<NoiseType> {
        Some(match s {
            "MULTIFRACTAL" => NoiseType::MultiFractal,
            "FBM" => NoiseType::Fbm,
            "HYBRID_MULTIFRACTAL" => NoiseType::HybridMultiFractal,
            "RIDGED_MULTIFRACTAL" => NoiseType::RidgedMultiFractal,
            "HETERO_TERRAIN" => NoiseType::HeteroTerrain,
            _ => return None,
        })
    }
}

/// Noise settings after the node's clamping.
#[derive(Debug, Clone, Copy)]
pub struct NoiseParams {
    pub kind: NoiseType,
    pub normalize: bool,
    pub detail: f32,
    pub roughness: f32,
    pub lacunarity: f32,
    pub offset: f32,
    pub gain: f32,
    pub distortion: f32,
}

fn select<P: NoisePoint>(p: P, n: &NoiseParams) -> f32 {
    match n.kind {
        NoiseType::MultiFractal => multi_fractal(p, n.detail, n.roughness, n.lacunarity),
        NoiseType::Fbm => fbm(p, n.detail, n.roughness, n.lacunarity, n.normalize),
        NoiseType::HybridMultiFractal => {
            hybrid_multi_fractal(p, n.detail, n.roughness, n.lacunarity, n.offset, n.gain)
        }
        NoiseType::RidgedMultiFractal => {
            ridged_multi_fractal(p, n.detail, n.roughness, n.lacunarity, n.offset, n.gain)
        }
        NoiseType::HeteroTerrain => {
            hetero_terrain(p, n.detail, n.roughness, n.lacunarity, n.offset)
        }
    }
}

/// `perlin_fractal_distorted`: the Fac output.
pub fn fractal_distorted<P: NoisePoint>(p: P, n: &NoiseParams) -> f32 {
    let p = distorted(p, n.distortion);
    select(p, n)
}

/// `perlin_float3_fractal_distorted`: the Color output (its first channel is Fac). The
/// seeds of the two extra channels depend on the dimension, as in Blender.
pub fn fractal_distorted_color<P: NoisePoint>(p: P, n: &NoiseParams, seeds: [f32; 2]) -> [f32; 3] {
    let p = distorted(p, n.distortion);
    [
        select(p, n),
        select(p.plus(P::offset(seeds[0])), n),
        select(p.plus(P::offset(seeds[1])), n),
    ]
}

/// The Noise Texture node on one point: `dimensions` 1-4 (`vector` used for 2-4, `w` for
/// 1 and 4). Returns (Fac, Color).
#[allow(clippy::too_many_arguments)]
pub fn noise_texture(
    dimensions: u8,
    vector: [f32; 3],
    w: f32,
    scale: f32,
    params: NoiseParams,
    want_color: bool,
) -> (f32, [f32; 4]) {
    let mut n = params;
    n.detail = n.detail.clamp(0.0, 15.0);
    n.roughness = n.roughness.max(0.0);
    let v = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
    let ws = w * scale;
    let c = if want_color {
        match dimensions {
            1 => fractal_distorted_color(ws, &n, [1.0, 2.0]),
            2 => fractal_distorted_color([v[0], v[1]], &n, [2.0, 3.0]),
            4 => fractal_distorted_color([v[0], v[1], v[2], ws], &n, [4.0, 5.0]),
            _ => fractal_distorted_color(v, &n, [3.0, 4.0]),
        }
    } else {
        let f = match dimensions {
            1 => fractal_distorted(ws, &n),
            2 => fractal_distorted([v[0], v[1]], &n),
            4 => fractal_distorted([v[0], v[1], v[2], ws], &n),
            _ => fractal_distorted(v, &n),
        };
        [f, 0.0, 0.0]
    };
    (c[0], [c[0], c[1], c[2], 1.0])
}

// --- Cycles' kernel flavour -------------------------------------------------------------
//
// Cycles (`kernel/svm/noise.h`) computes the same Perlin noise with its own arithmetic:
// `fade` in single precision, linear blends as `a + t * (b - a)`, and, in its SSE/AVX
// CPU kernels, the blends in a fixed axis order (2D and 3D: x, then y, then z; 4D: w
// first, then x, y, z). At fine scales times many octaves the coordinates are large and
// these rounding differences grow past 1e-4, so shaders use this flavour; Geometry
// Nodes keep Blender's CPU version above.

#[inline(always)]
fn cy_mix(a: f32, b: f32, t: f32) -> f32 {
    t.mul_add(b - a, a)
}

#[inline(always)]
fn cy_fade(t: f32) -> f32 {
    let a = t.mul_add(6.0, -15.0);
    let b = t.mul_add(a, 10.0);
    (t * t) * (t * b)
}

fn cy_perlin1(p: f32) -> f32 {
    let (x, fx) = floor_fraction(p);
    let u = t_fade1(fx);
    cy_mix(
        grad1(hash1(x as u32), fx),
        grad1(hash1(x.wrapping_add(1) as u32), fx - 1.0),
        u,
    )
}

/// The scalar 1D kernel's fade: `t * t * t * (t * (t * 6 - 15) + 10)`.
#[inline(always)]
fn t_fade1(t: f32) -> f32 {
    t * t * t * t.mul_add(t.mul_add(6.0, -15.0), 10.0)
}

fn cy_perlin2(p: [f32; 2]) -> f32 {
    let (x, fx) = floor_fraction(p[0]);
    let (y, fy) = floor_fraction(p[1]);
    let (u, v) = (cy_fade(fx), cy_fade(fy));
    let h = |dx: i32, dy: i32| hash2(x.wrapping_add(dx) as u32, y.wrapping_add(dy) as u32);
    let g0 = cy_mix(grad2(h(0, 0), fx, fy), grad2(h(1, 0), fx - 1.0, fy), u);
    let g1 = cy_mix(
        grad2(h(0, 1), fx, fy - 1.0),
        grad2(h(1, 1), fx - 1.0, fy - 1.0),
        u,
    );
    cy_mix(g0, g1, v)
}

/// Gradients at the 8 corners (index bit 0: x, bit 1: y, bit 2: z) blended x, y, z.
#[inline(always)]
fn cy_tri(g: [f32; 8], u: f32, v: f32, w: f32) -> f32 {
    let x00 = cy_mix(g[0], g[1], u);
    let x10 = cy_mix(g[2], g[3], u);
    let x01 = cy_mix(g[4], g[5], u);
    let x11 = cy_mix(g[6], g[7], u);
    cy_mix(cy_mix(x00, x10, v), cy_mix(x01, x11, v), w)
}

#[inline(always)]
fn cy_perlin3(p: [f32; 3]) -> f32 {
    let (g, [fx, fy, fz]) = corners3(p);
    cy_tri(g, cy_fade(fx), cy_fade(fy), cy_fade(fz))
}

/// `cy_perlin3(cycles_fmod(p))` of 8 points at once, a point per lane: each lane does
/// the scalar kernel's operations in its order (floor, the corner hashes and gradients,
/// FMA fades and blends), so the same bits. `None` when a coordinate is not finite or not
/// below the wrap period (`cycles_fmod` would change it): the caller goes scalar.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
))]
#[inline]
fn cy_perlin3_x8(p: &[[f32; 3]; 8]) -> Option<[f32; 8]> {
    cy_perlin3_soa(&std::array::from_fn(|a| std::array::from_fn(|l| p[l][a])))
}

/// `cy_perlin3_x8` of points given as one 8-lane array per axis (`p[axis][lane]`), which
/// fBm's octaves are built as directly.
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
))]
#[inline]
fn cy_perlin3_soa(p: &[[f32; 8]; 3]) -> Option<[f32; 8]> {
    use std::arch::x86_64::*;
    // SAFETY: AVX2 and FMA are enabled for the whole build (the cfg above); loads and
    // stores are unaligned ones of whole 8-lane arrays.
    unsafe {
        let abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff));
        let period = _mm256_set1_ps(100000.0);
        let mut inside = 0xff;
        let mut cell = [[0i32; 8]; 3];
        let mut frac = [_mm256_setzero_ps(); 3];
        for a in 0..3 {
            let v = _mm256_loadu_ps(p[a].as_ptr());
            // |v| < 1e5 (false for NaN): `wrap` leaves v alone and `correction` adds +0.
            inside &=
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_and_ps(v, abs), period));
            let v = _mm256_add_ps(v, _mm256_setzero_ps());
            let f = _mm256_floor_ps(v);
            _mm256_storeu_si256(cell[a].as_mut_ptr().cast(), _mm256_cvttps_epi32(f));
            frac[a] = _mm256_sub_ps(v, f);
        }
        if inside != 0xff {
            return None;
        }
        let arr = |v: __m256| {
            let mut o = [0.0f32; 8];
            _mm256_storeu_ps(o.as_mut_ptr(), v);
            o
        };
        // Corner c (bit 0: x + 1, bit 1: y + 1, bit 2: z + 1), all 8 points.
        let mut g = [_mm256_setzero_ps(); 8];
        for (c, g) in g.iter_mut().enumerate() {
            let d = [c & 1, c >> 1 & 1, c >> 2 & 1];
            let k = |a: usize| cell[a].map(|x| x.wrapping_add(d[a] as i32) as u32);
            let h = hash3_x8(k(0), k(1), k(2));
            let at = |a: usize| arr(_mm256_sub_ps(frac[a], _mm256_set1_ps(d[a] as f32)));
            *g = _mm256_loadu_ps(grad3_x8(h, at(0), at(1), at(2)).as_ptr());
        }
        let fade = |t: __m256| {
            let a = _mm256_fmadd_ps(t, _mm256_set1_ps(6.0), _mm256_set1_ps(-15.0));
            let b = _mm256_fmadd_ps(t, a, _mm256_set1_ps(10.0));
            _mm256_mul_ps(_mm256_mul_ps(t, t), _mm256_mul_ps(t, b))
        };
        let mix = |a: __m256, b: __m256, t: __m256| _mm256_fmadd_ps(t, _mm256_sub_ps(b, a), a);
        let (u, v, w) = (fade(frac[0]), fade(frac[1]), fade(frac[2]));
        let x00 = mix(g[0], g[1], u);
        let x10 = mix(g[2], g[3], u);
        let x01 = mix(g[4], g[5], u);
        let x11 = mix(g[6], g[7], u);
        Some(arr(mix(mix(x00, x10, v), mix(x01, x11, v), w)))
    }
}
#[cfg(not(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
)))]
#[inline]
fn cy_perlin3_x8(_: &[[f32; 3]; 8]) -> Option<[f32; 8]> {
    None
}
#[cfg(not(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    target_feature = "fma"
)))]
#[inline]
fn cy_perlin3_soa(_: &[[f32; 8]; 3]) -> Option<[f32; 8]> {
    None
}

#[inline(always)]
fn cy_perlin4(p: [f32; 4]) -> f32 {
    let (g, [fx, fy, fz, fw]) = corners4(p);
    let s = cy_fade(fw);
    // w first (Cycles' SSE order), then x, y, z.
    let g: [f32; 8] = std::array::from_fn(|i| cy_mix(g[i], g[i + 8], s));
    cy_tri(g, cy_fade(fx), cy_fade(fy), cy_fade(fz))
}

/// A point evaluated with Cycles' kernel arithmetic (see above).
#[derive(Debug, Clone, Copy)]
pub struct Cycles<P>(pub P);

macro_rules! cycles_point {
    ($t:ty, $perlin:ident, $scale:expr) => {
        cycles_point!($t, $perlin, $scale, {});
    };
    ($t:ty, $perlin:ident, $scale:expr, { $($batch:item)* }) => {
        impl NoisePoint for Cycles<$t> {
            $($batch)*
            fn all(self, f: impl Fn(f32) -> bool) -> bool {
                self.0.all_c(f)
            }
            #[inline]
            fn perlin_signed(self) -> f32 {
                // Repeats every 100000 with Blender's half-cell shift beyond 1e6.
                let p = cycles_fmod(self.0);
                $perlin(p) * $scale
            }
            fn scaled(self, s: f32) -> Self {
                Cycles(self.0.scaled(s))
            }
            fn plus(self, o: Self) -> Self {
                Cycles(self.0.plus(o.0))
            }
            fn offset(seed: f32) -> Self {
                Cycles(<$t>::offset(seed))
            }
            fn distortion(self, strength: f32) -> Self {
                let mut out = self.0;
                let n = std::mem::size_of::<$t>() / 4;
                for i in 0..n {
                    let o = Cycles(<$t>::offset(i as f32));
                    set(&mut out, i, self.plus(o).perlin_signed() * strength);
                }
                Cycles(out)
            }
            fn distorted(self, strength: f32) -> Self {
                if std::mem::size_of::<$t>() == 4 {
                    // The scalar kernel contracts `p += snoise(..) * distortion`.
                    let mut out = self.0;
                    let d = self.plus(Cycles(<$t>::offset(0.0))).perlin_signed();
                    set(&mut out, 0, d.mul_add(strength, get(self.0)));
                    Cycles(out)
                } else {
                    self.plus(self.distortion(strength))
                }
            }
            const FUSED: bool = true;
        }
    };
}

trait Comps: Copy {
    fn map_c(self, f: impl Fn(f32) -> f32) -> Self;
    fn all_c(self, f: impl Fn(f32) -> bool) -> bool;
    fn set_c(&mut self, i: usize, v: f32);
    fn first_c(self) -> f32;
}
impl Comps for f32 {
    #[inline(always)]
    fn map_c(self, f: impl Fn(f32) -> f32) -> Self {
        f(self)
    }
    #[inline(always)]
    fn all_c(self, f: impl Fn(f32) -> bool) -> bool {
        f(self)
    }
    fn set_c(&mut self, _: usize, v: f32) {
        *self = v;
    }
    fn first_c(self) -> f32 {
        self
    }
}
impl<const N: usize> Comps for [f32; N] {
    #[inline(always)]
    fn map_c(self, f: impl Fn(f32) -> f32) -> Self {
        self.map(f)
    }
    #[inline(always)]
    fn all_c(self, f: impl Fn(f32) -> bool) -> bool {
        self.iter().all(|&x| f(x))
    }
    fn set_c(&mut self, i: usize, v: f32) {
        self[i] = v;
    }
    fn first_c(self) -> f32 {
        self[0]
    }
}
#[inline(always)]
fn cycles_fmod<T: Comps>(p: T) -> T {
    p.map_c(|x| wrap(x) + correction(x))
}
fn get<T: Comps>(p: T) -> f32 {
    p.first_c()
}
fn set<T: Comps>(p: &mut T, i: usize, v: f32) {
    p.set_c(i, v)
}

cycles_point!(f32, cy_perlin1, 0.25);
cycles_point!([f32; 2], cy_perlin2, 0.6616);
cycles_point!([f32; 3], cy_perlin3, 0.9820, {
    fn perlin_signed_batch(ps: &[Self], out: &mut [f32]) {
        for (ps, out) in ps.chunks(8).zip(out.chunks_mut(8)) {
            let mut lanes = [[0.0f32; 3]; 8];
            for (l, p) in lanes.iter_mut().zip(ps) {
                *l = p.0;
            }
            match cy_perlin3_x8(&lanes) {
                Some(v) => {
                    for (o, v) in out.iter_mut().zip(v) {
                        *o = v * 0.9820;
                    }
                }
                None => {
                    for (o, p) in out.iter_mut().zip(ps) {
                        *o = p.perlin_signed();
                    }
                }
            }
        }
    }
    fn perlin_signed_scaled(self, scales: &[f32], out: &mut [f32]) {
        // The octaves' points go straight into per-axis lanes (`scaled` is one product
        // per component, so the same bits); copying whole points into lanes and
        // gathering them again stalled on store forwarding. Unused lanes hold 0.
        for (scales, out) in scales.chunks(8).zip(out.chunks_mut(8)) {
            let mut s8 = [0.0f32; 8];
            s8[..scales.len()].copy_from_slice(scales);
            let lanes: [[f32; 8]; 3] = std::array::from_fn(|a| s8.map(|s| s * self.0[a]));
            match cy_perlin3_soa(&lanes) {
                Some(v) => {
                    for (o, v) in out.iter_mut().zip(v) {
                        *o = v * 0.9820;
                    }
                }
                None => {
                    for (o, &s) in out.iter_mut().zip(scales) {
                        *o = self.scaled(s).perlin_signed();
                    }
                }
            }
        }
    }
});
cycles_point!([f32; 4], cy_perlin4, 0.8344);

/// The Noise Texture node as Cycles' shader kernel evaluates it: (Fac, Color).
#[allow(clippy::too_many_arguments)]
pub fn noise_texture_cycles(
    dimensions: u8,
    vector: [f32; 3],
    w: f32,
    scale: f32,
    params: NoiseParams,
) -> (f32, [f32; 3]) {
    let mut n = params;
    n.detail = n.detail.clamp(0.0, 15.0);
    n.roughness = n.roughness.max(0.0);
    let v = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
    let ws = w * scale;
    let c = match dimensions {
        1 => fractal_distorted_color(Cycles(ws), &n, [1.0, 2.0]),
        2 => fractal_distorted_color(Cycles([v[0], v[1]]), &n, [2.0, 3.0]),
        4 => fractal_distorted_color(Cycles([v[0], v[1], v[2], ws]), &n, [4.0, 5.0]),
        _ => fractal_distorted_color(Cycles(v), &n, [3.0, 4.0]),
    };
    (c[0], c)
}

/// `noise_texture_cycles` when only Fac is read: the same bits as its Fac, without the
/// Color output's two extra fractals (Cycles skips them too when Color is unlinked).
pub fn noise_texture_cycles_fac(
    dimensions: u8,
    vector: [f32; 3],
    w: f32,
    scale: f32,
    params: NoiseParams,
) -> f32 {
    let mut n = params;
    n.detail = n.detail.clamp(0.0, 15.0);
    n.roughness = n.roughness.max(0.0);
    let v = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
    let ws = w * scale;
    match dimensions {
        1 => fractal_distorted(Cycles(ws), &n),
        2 => fractal_distorted(Cycles([v[0], v[1]]), &n),
        4 => fractal_distorted(Cycles([v[0], v[1], v[2], ws]), &n),
        _ => fractal_distorted(Cycles(v), &n),
    }
}
