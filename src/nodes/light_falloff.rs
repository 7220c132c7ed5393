//! Light Falloff (Cycles' svm/light_path.h): a strength divided back by the ray length
//! to undo or soften the inverse-square falloff.

/// (Quadratic, Linear, Constant) for `strength`, `smooth` and the ray length.
pub fn light_falloff(strength: f32, smooth: f32, ray_length: f32) -> [f32; 3] {
    let mut out = [
        strength,
        strength * ray_length,
        strength * ray_length * ray_length,
    ];
    if smooth > 0.0 {
        let squared = ray_length * ray_length;
        // Distant lamps set the ray length to f32::MAX; the square then overflows.
        if squared.is_finite() {
            for o in &mut out {
                *o *= squared / (smooth + squared);
            }
        }
    }
    out
}
