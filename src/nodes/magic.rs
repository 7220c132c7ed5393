//! Magic Texture (Cycles `svm_magic`).

use super::math::V3;

/// (Color, Fac) of the Magic Texture node; `depth` is its Turbulence Depth.
pub fn magic(p: V3, scale: f32, depth: i32, distortion: f32) -> (V3, f32) {
    // Wrapping into one period first keeps large inputs from losing precision.
    let tau = 2.0 * std::f32::consts::PI;
    let (px, py, pz) = (p[0] % tau, p[1] % tau, p[2] % tau);
    let d = distortion;
    let mut x = ((px + py + pz) * 5.0 * scale).sin();
    let mut y = ((-px + py - pz) * 5.0 * scale).cos();
    let mut z = -((-px - py + pz) * 5.0 * scale).cos();
    let n = depth;
    if n > 0 {
        x *= d;
        y *= d;
        z *= d;
        y = -(x - y + z).cos() * d;
        if n > 1 {
            x = (x - y - z).cos() * d;
            if n > 2 {
                z = (-x - y - z).sin() * d;
                if n > 3 {
                    x = -(-x + y - z).cos() * d;
                    if n > 4 {
                        y = -(-x + y + z).sin() * d;
                        if n > 5 {
                            y = -(-x + y + z).cos() * d;
                            if n > 6 {
                                x = (x + y + z).cos() * d;
                                if n > 7 {
                                    z = (x + y - z).sin() * d;
                                    if n > 8 {
                                        x = -(-x - y + z).cos() * d;
                                        if n > 9 {
                                            y = -(x - y + z).sin() * d;
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    if d != 0.0 {
        let d2 = d * 2.0;
        x /= d2;
        y /= d2;
        z /= d2;
    }
    let c = [0.5 - x, 0.5 - y, 0.5 - z];
    (c, (c[0] + c[1] + c[2]) * (1.0 / 3.0))
}
