//! White Noise Texture and the hashes of float tuples into float tuples that it and the
//! Voronoi texture share (Cycles' `util/hash.h`: `hash_floatN_to_floatM`).

use super::math::Vec3;
use super::random::{hash_float_to_float1 as h1, hash_float_to_float2 as h2, hash_float_to_float3 as h3, hash_float_to_float4 as h4};

pub fn hash_f1_to_f3(k: f32) -> Vec3 {
    [h1(k), h2([k, 1.0]), h2([k, 2.0])]
}
pub fn hash_f2_to_f2(k: [f32; 2]) -> [f32; 2] {
    [h2(k), h3([k[0], k[1], 1.0])]
}
pub fn hash_f2_to_f3(k: [f32; 2]) -> Vec3 {
    [h2(k), h3([k[0], k[1], 1.0]), h3([k[0], k[1], 2.0])]
}
pub fn hash_f3_to_f3(k: Vec3) -> Vec3 {
    [h3(k), h4([k[0], k[1], k[2], 1.0]), h4([k[0], k[1], k[2], 2.0])]
}
pub fn hash_f4_to_f4(k: [f32; 4]) -> [f32; 4] {
    [h4(k), h4([k[3], k[0], k[1], k[2]]), h4([k[2], k[3], k[0], k[1]]), h4([k[1], k[2], k[3], k[0]])]
}
pub fn hash_f4_to_f3(k: [f32; 4]) -> Vec3 {
    [h4(k), h4([k[2], k[0], k[3], k[1]]), h4([k[3], k[2], k[1], k[0]])]
}

/// The White Noise Texture node: (Value, Color) for `dimensions` 1-4 (`vector` for 2-4,
/// `w` for 1 and 4).
pub fn white_noise(dimensions: u8, vector: Vec3, w: f32) -> (f32, Vec3) {
    let [x, y, z] = vector;
    match dimensions {
        1 => (h1(w), hash_f1_to_f3(w)),
        2 => (h2([x, y]), hash_f2_to_f3([x, y])),
        4 => (h4([x, y, z, w]), hash_f4_to_f3([x, y, z, w])),
        _ => (h3(vector), hash_f3_to_f3(vector)),
    }
}
