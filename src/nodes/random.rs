//! Blender's hash-based random values: Bob Jenkins' lookup3 hash as `BLI_noise.hh`
//! (`noise::hash`, `hash_to_float`, `hash_float_to_float`, ...) defines it, used by the
//! Random Value node, by noise textures' seeds and by point distribution; and
//! `RandomNumberGenerator` (`BLI_rand.hh`, a 48-bit linear congruential generator), used
//! by Distribute Points on Faces.

#[inline]
fn rot(x: u32, k: u32) -> u32 {
    x.rotate_left(k)
}

#[inline]
fn mix(a: &mut u32, b: &mut u32, c: &mut u32) {
    *a = a.wrapping_sub(*c);
    *a ^= rot(*c, 4);
    *c = c.wrapping_add(*b);
    *b = b.wrapping_sub(*a);
    *b ^= rot(*a, 6);
    *a = a.wrapping_add(*c);
    *c = c.wrapping_sub(*b);
    *c ^= rot(*b, 8);
    *b = b.wrapping_add(*a);
    *a = a.wrapping_sub(*c);
    *a ^= rot(*c, 16);
    *c = c.wrapping_add(*b);
    *b = b.wrapping_sub(*a);
    *b ^= rot(*a, 19);
    *a = a.wrapping_add(*c);
    *c = c.wrapping_sub(*b);
    *c ^= rot(*b, 4);
    *b = b.wrapping_add(*a);
}

#[inline]
fn finalize(a: &mut u32, b: &mut u32, c: &mut u32) {
    *c ^= *b;
    *c = c.wrapping_sub(rot(*b, 14));
    *a ^= *c;
    *a = a.wrapping_sub(rot(*c, 11));
    *b ^= *a;
    *b = b.wrapping_sub(rot(*a, 25));
    *c ^= *b;
    *c = c.wrapping_sub(rot(*b, 16));
    *a ^= *c;
    *a = a.wrapping_sub(rot(*c, 4));
    *b ^= *a;
    *b = b.wrapping_sub(rot(*a, 14));
    *c ^= *b;
    *c = c.wrapping_sub(rot(*b, 24));
}

const SEED: u32 = 0xdeadbeef;

pub fn hash1(kx: u32) -> u32 {
    let mut a = SEED.wrapping_add(1 << 2).wrapping_add(13);
    let (mut b, mut c) = (a, a);
    a = a.wrapping_add(kx);
    finalize(&mut a, &mut b, &mut c);
    c
}

pub fn hash2(kx: u32, ky: u32) -> u32 {
    let mut a = SEED.wrapping_add(2 << 2).wrapping_add(13);
    let (mut b, mut c) = (a, a);
    b = b.wrapping_add(ky);
    a = a.wrapping_add(kx);
    finalize(&mut a, &mut b, &mut c);
    c
}

pub fn hash3(kx: u32, ky: u32, kz: u32) -> u32 {
    let mut a = SEED.wrapping_add(3 << 2).wrapping_add(13);
    let (mut b, mut c) = (a, a);
    c = c.wrapping_add(kz);
    b = b.wrapping_add(ky);
    a = a.wrapping_add(kx);
    finalize(&mut a, &mut b, &mut c);
    c
}

pub fn hash4(kx: u32, ky: u32, kz: u32, kw: u32) -> u32 {
    let mut a = SEED.wrapping_add(4 << 2).wrapping_add(13);
    let (mut b, mut c) = (a, a);
    a = a.wrapping_add(kx);
    b = b.wrapping_add(ky);
    c = c.wrapping_add(kz);
    mix(&mut a, &mut b, &mut c);
    a = a.wrapping_add(kw);
    finalize(&mut a, &mut b, &mut c);
    c
}

/// `uint_to_float_01`: `float(k) / float(0xFFFFFFFF)` in single precision.
#[inline]
pub fn uint_to_float_01(k: u32) -> f32 {
    k as f32 / u32::MAX as f32
}

pub fn hash_to_float1(kx: u32) -> f32 {
    uint_to_float_01(hash1(kx))
}
pub fn hash_to_float2(kx: u32, ky: u32) -> f32 {
    uint_to_float_01(hash2(kx, ky))
}
pub fn hash_to_float3(kx: u32, ky: u32, kz: u32) -> f32 {
    uint_to_float_01(hash3(kx, ky, kz))
}
pub fn hash_to_float4(kx: u32, ky: u32, kz: u32, kw: u32) -> f32 {
    uint_to_float_01(hash4(kx, ky, kz, kw))
}

/// Hashes of floats hash their bit patterns.
pub fn hash_float_to_float1(k: f32) -> f32 {
    uint_to_float_01(hash1(k.to_bits()))
}
pub fn hash_float_to_float2(k: [f32; 2]) -> f32 {
    uint_to_float_01(hash2(k[0].to_bits(), k[1].to_bits()))
}
pub fn hash_float_to_float3(k: [f32; 3]) -> f32 {
    uint_to_float_01(hash3(k[0].to_bits(), k[1].to_bits(), k[2].to_bits()))
}
pub fn hash_float_to_float4(k: [f32; 4]) -> f32 {
    uint_to_float_01(hash4(
        k[0].to_bits(),
        k[1].to_bits(),
        k[2].to_bits(),
        k[3].to_bits(),
    ))
}

// --- Random Value node ------------------------------------------------------------------

/// Random Value, Float: `hash_to_float(seed, id)` scaled into [min, max].
pub fn random_float(min: f32, max: f32, id: i32, seed: i32) -> f32 {
    let v = hash_to_float2(seed as u32, id as u32);
    v * (max - min) + min
}

/// Random Value, Vector: one hash per component.
pub fn random_vector(min: [f32; 3], max: [f32; 3], id: i32, seed: i32) -> [f32; 3] {
    let x = hash_to_float3(seed as u32, id as u32, 0);
    let y = hash_to_float3(seed as u32, id as u32, 1);
    let z = hash_to_float3(seed as u32, id as u32, 2);
    [
        x * (max[0] - min[0]) + min[0],
        y * (max[1] - min[1]) + min[1],
        z * (max[2] - min[2]) + min[2],
    ]
}

/// Random Value, Integer: note the swapped hash arguments and `max + 1` (so both ends
/// are as likely as the values between), floored in single precision.
pub fn random_int(min: i32, max: i32, id: i32, seed: i32) -> i32 {
    let v = hash_to_float2(id as u32, seed as u32);
    let range = max.wrapping_add(1).wrapping_sub(min) as f32;
    (v * range + min as f32).floor() as i32
}

/// Random Value, Boolean.
pub fn random_bool(probability: f32, id: i32, seed: i32) -> bool {
    hash_to_float2(id as u32, seed as u32) <= probability
}

// --- RandomNumberGenerator --------------------------------------------------------------

/// `blender::RandomNumberGenerator`: drand48's generator.
#[derive(Debug, Clone)]
pub struct Rng {
    x: u64,
}

const MULTIPLIER: u64 = 0x5DEECE66D;
const ADDEND: u64 = 0xB;
const MASK: u64 = 0x0000_FFFF_FFFF_FFFF;

impl Rng {
    pub fn new(seed: u32) -> Rng {
        let mut r = Rng { x: 0 };
        r.seed(seed);
        r
    }
    pub fn seed(&mut self, seed: u32) {
        self.x = ((seed as u64) << 16) | 0x330E;
    }
    fn step(&mut self) {
        self.x = (MULTIPLIER.wrapping_mul(self.x).wrapping_add(ADDEND)) & MASK;
    }
    pub fn get_uint32(&mut self) -> u32 {
        self.step();
        (self.x >> 17) as u32
    }
    pub fn get_int32(&mut self) -> i32 {
        self.step();
        (self.x >> 17) as i32
    }
    /// A double in [0, 1).
    pub fn get_double(&mut self) -> f64 {
        self.get_int32() as f64 / 0x8000_0000u32 as f64
    }
    /// A float in [0, 1).
    pub fn get_float(&mut self) -> f32 {
        self.get_double() as f32
    }
    /// Uniform barycentric weights (`get_barycentric_coordinates`).
    pub fn get_barycentric_coordinates(&mut self) -> [f32; 3] {
        let mut rand1 = self.get_float();
        let mut rand2 = self.get_float();
        if rand1 + rand2 > 1.0 {
            rand1 = 1.0 - rand1;
            rand2 = 1.0 - rand2;
        }
        [rand1, rand2, 1.0 - rand1 - rand2]
    }
    /// Advances the generator `n` steps.
    pub fn skip(&mut self, n: u64) {
        for _ in 0..n {
            self.step();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rng_is_drand48() {
        // drand48 with srand48(0): the first values are well known.
        let mut r = Rng::new(0);
        let a = r.get_double();
        assert!((a - 0.170828036106).abs() < 1e-9, "{a}");
    }
}
