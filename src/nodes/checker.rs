//! Checker Texture (Cycles `svm_checker`).

use super::math::V3;

/// Fac at `p` (already multiplied by the node's Scale): 1 picks Color1, 0 Color2.
pub fn checker(p: V3) -> f32 {
    // The nudge avoids flicker on integer (unit) coordinates, as Cycles does.
    let cell = |v: f32| (((v + 0.000001) * 0.999999).floor() as i32).unsigned_abs() % 2;
    let (xi, yi, zi) = (cell(p[0]), cell(p[1]), cell(p[2]));
    if ((xi == yi) as u32) == zi {
        1.0
    } else {
        0.0
    }
}

/// (Color, Fac) of the Checker Texture node.
pub fn checker_texture(vector: V3, color1: V3, color2: V3, scale: f32) -> (V3, f32) {
    let f = checker([vector[0] * scale, vector[1] * scale, vector[2] * scale]);
    (if f == 1.0 { color1 } else { color2 }, f)
}
