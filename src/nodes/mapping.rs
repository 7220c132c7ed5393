//! Mapping node (Cycles `svm_mapping`): point, texture, vector and normal mappings with
//! an XYZ Euler rotation.

use crate::foundation::math::dot;

use super::math::V3;

blender_enum! {
    pub enum MappingType {
        Point = "POINT",
        Texture = "TEXTURE",
        Vector = "VECTOR",
        Normal = "NORMAL",
    }
}

/// Rows of Cycles' `euler_to_transform` (rotation part).
pub(crate) fn euler_rows(e: V3) -> [V3; 3] {
    let (cx, cy, cz) = (e[0].cos(), e[1].cos(), e[2].cos());
    let (sx, sy, sz) = (e[0].sin(), e[1].sin(), e[2].sin());
    [
        [cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz],
        [cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz],
        [-sy, cy * sx, cy * cx],
    ]
}

pub(crate) fn rotate(r: &[V3; 3], a: V3) -> V3 {
    [dot(a, r[0]), dot(a, r[1]), dot(a, r[2])]
}

pub(crate) fn rotate_transposed(r: &[V3; 3], a: V3) -> V3 {
    let col = |i: usize| [r[0][i], r[1][i], r[2][i]];
    [dot(a, col(0)), dot(a, col(1)), dot(a, col(2))]
}

fn safe_div(a: V3, b: V3) -> V3 {
    std::array::from_fn(|i| if b[i] != 0.0 { a[i] / b[i] } else { 0.0 })
}

pub fn mapping(kind: MappingType, vector: V3, location: V3, rotation: V3, scale: V3) -> V3 {
    let r = euler_rows(rotation);
    let mul = |a: V3, b: V3| -> V3 { std::array::from_fn(|i| a[i] * b[i]) };
    match kind {
        MappingType::Point => {
            let v = rotate(&r, mul(vector, scale));
            [v[0] + location[0], v[1] + location[1], v[2] + location[2]]
        }
        MappingType::Texture => {
            let d = [
                vector[0] - location[0],
                vector[1] - location[1],
                vector[2] - location[2],
            ];
            safe_div(rotate_transposed(&r, d), scale)
        }
        MappingType::Vector => rotate(&r, mul(vector, scale)),
        MappingType::Normal => {
            let v = rotate(&r, safe_div(vector, scale));
            let len = dot(v, v).sqrt();
            if len != 0.0 {
                let k = 1.0 / len;
                v.map(|x| x * k)
            } else {
                v
            }
        }
    }
}
