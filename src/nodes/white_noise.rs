//! White Noise Texture and the hashes of float tuples into float tuples that it and the
//! Voronoi texture share (Cycles' `util/hash.h`: `hash_floatN_to_floatM`).
//!
//! Speed: these run for every cell a Voronoi texture visits (125 per Smooth F1 point in
//! 3D), so they are forced inline: a loop over a block of cells then becomes one vector
//! loop (8 cells per AVX2 instruction). The lookup3 core is therefore written here as
//! `#[inline(always)]` functions of plain integers (noise.rs uses them too); it computes exactly what
//! `random::hash1..hash4` compute (tests/noise_speed.rs checks every output bit against
//! the previous code). Hashes that share their inputs share work: `hash_float4_to_float`
//! of (k, 1) and (k, 2) differ only after lookup3's `mix`, which runs once.

use super::math::V3;

/// Bob Jenkins' lookup3 (`final` and `mix`, the constants of Blender's `BLI_hash`); the
/// Perlin noise hashes its lattice corners with it too.
pub(crate) mod lookup3 {
    const SEED: u32 = 0xdeadbeef;

    #[inline(always)]
    pub fn init(words: u32) -> u32 {
        SEED.wrapping_add(words << 2).wrapping_add(13)
    }

    /// `mix(a, b, c)`.
    #[inline(always)]
    pub fn mix(mut a: u32, mut b: u32, mut c: u32) -> (u32, u32, u32) {
        a = a.wrapping_sub(c) ^ c.rotate_left(4);
        c = c.wrapping_add(b);
        b = b.wrapping_sub(a) ^ a.rotate_left(6);
        a = a.wrapping_add(c);
        c = c.wrapping_sub(b) ^ b.rotate_left(8);
        b = b.wrapping_add(a);
        a = a.wrapping_sub(c) ^ c.rotate_left(16);
        c = c.wrapping_add(b);
        b = b.wrapping_sub(a) ^ a.rotate_left(19);
        a = a.wrapping_add(c);
        c = c.wrapping_sub(b) ^ b.rotate_left(4);
        b = b.wrapping_add(a);
        (a, b, c)
    }

    /// `final(a, b, c)`, returning c (the hash).
    #[inline(always)]
    pub fn fin(mut a: u32, mut b: u32, mut c: u32) -> u32 {
        c = (c ^ b).wrapping_sub(b.rotate_left(14));
        a = (a ^ c).wrapping_sub(c.rotate_left(11));
        b = (b ^ a).wrapping_sub(a.rotate_left(25));
        c = (c ^ b).wrapping_sub(b.rotate_left(16));
        a = (a ^ c).wrapping_sub(c.rotate_left(4));
        b = (b ^ a).wrapping_sub(a.rotate_left(14));
        (c ^ b).wrapping_sub(b.rotate_left(24))
    }

    #[inline(always)]
    pub fn hash1(kx: u32) -> u32 {
        let a = init(1);
        fin(a.wrapping_add(kx), a, a)
    }
    #[inline(always)]
    pub fn hash2(kx: u32, ky: u32) -> u32 {
        let a = init(2);
        fin(a.wrapping_add(kx), a.wrapping_add(ky), a)
    }
    #[inline(always)]
    pub fn hash3(kx: u32, ky: u32, kz: u32) -> u32 {
        let a = init(3);
        fin(a.wrapping_add(kx), a.wrapping_add(ky), a.wrapping_add(kz))
    }
    /// The state of `hash4(kx, ky, kz, _)` before kw enters.
    #[inline(always)]
    pub fn hash4_head(kx: u32, ky: u32, kz: u32) -> (u32, u32, u32) {
        let i = init(4);
        mix(i.wrapping_add(kx), i.wrapping_add(ky), i.wrapping_add(kz))
    }
    #[inline(always)]
    pub fn hash4_tail((a, b, c): (u32, u32, u32), kw: u32) -> u32 {
        fin(a.wrapping_add(kw), b, c)
    }
    #[inline(always)]
    pub fn hash4(kx: u32, ky: u32, kz: u32, kw: u32) -> u32 {
        hash4_tail(hash4_head(kx, ky, kz), kw)
    }

    /// Eight `hash3` at once, for the 8 lattice corners of 3D Perlin noise. The compiler
    /// unrolls an 8-corner loop before it would vectorise it and keeps the scalar
    /// hashes, so the AVX2 version is written out (AVX2 has no vector rotate: two shifts
    /// and an or).
    #[cfg(all(target_arch = "x86_64", target_feature = "avx2"))]
    #[inline(always)]
    pub fn hash3_x8(kx: [u32; 8], ky: [u32; 8], kz: [u32; 8]) -> [u32; 8] {
        use std::arch::x86_64::*;
        macro_rules! rot {
            ($x:expr, $k:literal) => {
                _mm256_or_si256(
                    _mm256_slli_epi32::<$k>($x),
                    _mm256_srli_epi32::<{ 32 - $k }>($x),
                )
            };
        }
        // SAFETY: AVX2 is enabled for the whole build (the cfg above); loads and stores
        // are unaligned ones of whole [u32; 8] arrays.
        unsafe {
            let load = |k: [u32; 8]| _mm256_loadu_si256(k.as_ptr().cast());
            let i = _mm256_set1_epi32(init(3) as i32);
            let mut a = _mm256_add_epi32(i, load(kx));
            let mut b = _mm256_add_epi32(i, load(ky));
            let mut c = _mm256_add_epi32(i, load(kz));
            c = _mm256_sub_epi32(_mm256_xor_si256(c, b), rot!(b, 14));
            a = _mm256_sub_epi32(_mm256_xor_si256(a, c), rot!(c, 11));
            b = _mm256_sub_epi32(_mm256_xor_si256(b, a), rot!(a, 25));
            c = _mm256_sub_epi32(_mm256_xor_si256(c, b), rot!(b, 16));
            a = _mm256_sub_epi32(_mm256_xor_si256(a, c), rot!(c, 4));
            b = _mm256_sub_epi32(_mm256_xor_si256(b, a), rot!(a, 14));
            c = _mm256_sub_epi32(_mm256_xor_si256(c, b), rot!(b, 24));
            let mut out = [0u32; 8];
            _mm256_storeu_si256(out.as_mut_ptr().cast(), c);
            out
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "avx2")))]
    #[inline(always)]
    pub fn hash3_x8(kx: [u32; 8], ky: [u32; 8], kz: [u32; 8]) -> [u32; 8] {
        std::array::from_fn(|i| hash3(kx[i], ky[i], kz[i]))
    }
}

/// `uint_to_float_01`: `float(k) / float(0xFFFFFFFF)`; the divisor rounds to 2^32, so the
/// product with 2^-32 is the same bits and vectorises.
#[inline(always)]
fn unit(k: u32) -> f32 {
    k as f32 * (1.0 / 4294967296.0)
}

#[inline(always)]
fn bits<const N: usize>(k: [f32; N]) -> [u32; N] {
    k.map(f32::to_bits)
}

/// `hash_float_to_float`.
#[inline(always)]
pub fn hash_f1_to_f1(k: f32) -> f32 {
    unit(lookup3::hash1(k.to_bits()))
}
/// `hash_float2_to_float`.
#[inline(always)]
pub fn hash_f2_to_f1(k: [f32; 2]) -> f32 {
    unit(lookup3::hash2(k[0].to_bits(), k[1].to_bits()))
}
/// `hash_float3_to_float`.
#[inline(always)]
pub fn hash_f3_to_f1(k: V3) -> f32 {
    let [x, y, z] = bits(k);
    unit(lookup3::hash3(x, y, z))
}
/// `hash_float4_to_float`.
#[inline(always)]
pub fn hash_f4_to_f1(k: [f32; 4]) -> f32 {
    let [x, y, z, w] = bits(k);
    unit(lookup3::hash4(x, y, z, w))
}

#[inline(always)]
pub fn hash_f1_to_f3(k: f32) -> V3 {
    let x = k.to_bits();
    [
        unit(lookup3::hash1(x)),
        unit(lookup3::hash2(x, 1.0f32.to_bits())),
        unit(lookup3::hash2(x, 2.0f32.to_bits())),
    ]
}
#[inline(always)]
pub fn hash_f2_to_f2(k: [f32; 2]) -> [f32; 2] {
    let [x, y] = bits(k);
    [
        unit(lookup3::hash2(x, y)),
        unit(lookup3::hash3(x, y, 1.0f32.to_bits())),
    ]
}
#[inline(always)]
pub fn hash_f2_to_f3(k: [f32; 2]) -> V3 {
    let [x, y] = bits(k);
    [
        unit(lookup3::hash2(x, y)),
        unit(lookup3::hash3(x, y, 1.0f32.to_bits())),
        unit(lookup3::hash3(x, y, 2.0f32.to_bits())),
    ]
}
#[inline(always)]
pub fn hash_f3_to_f3(k: V3) -> V3 {
    let [x, y, z] = bits(k);
    let head = lookup3::hash4_head(x, y, z);
    [
        unit(lookup3::hash3(x, y, z)),
        unit(lookup3::hash4_tail(head, 1.0f32.to_bits())),
        unit(lookup3::hash4_tail(head, 2.0f32.to_bits())),
    ]
}
#[inline(always)]
pub fn hash_f4_to_f4(k: [f32; 4]) -> [f32; 4] {
    let [x, y, z, w] = bits(k);
    let h = lookup3::hash4;
    [
        unit(h(x, y, z, w)),
        unit(h(w, x, y, z)),
        unit(h(z, w, x, y)),
        unit(h(y, z, w, x)),
    ]
}
#[inline(always)]
pub fn hash_f4_to_f3(k: [f32; 4]) -> V3 {
    let [x, y, z, w] = bits(k);
    let h = lookup3::hash4;
    [
        unit(h(x, y, z, w)),
        unit(h(z, x, w, y)),
        unit(h(w, z, y, x)),
    ]
}

/// The White Noise Texture node: (Value, Color) for `dimensions` 1-4 (`vector` for 2-4,
/// `w` for 1 and 4).
pub fn white_noise(dimensions: u8, vector: V3, w: f32) -> (f32, V3) {
    let [x, y, z] = vector;
    match dimensions {
        1 => (hash_f1_to_f1(w), hash_f1_to_f3(w)),
        2 => (hash_f2_to_f1([x, y]), hash_f2_to_f3([x, y])),
        4 => (hash_f4_to_f1([x, y, z, w]), hash_f4_to_f3([x, y, z, w])),
        _ => (hash_f3_to_f1(vector), hash_f3_to_f3(vector)),
    }
}
