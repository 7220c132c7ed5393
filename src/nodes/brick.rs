//! Brick Texture (Cycles `svm_brick`): rows of bricks with a per-brick tint from an
//! integer hash, mortar by the distance to the brick's edges, and every Nth row offset
//! and squashed.

use super::math::V3;

/// The node's non-socket settings (Blender's `offset`, `offset_frequency`, `squash`,
/// `squash_frequency` properties).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrickSettings {
    pub offset: f32,
    pub offset_frequency: i32,
    pub squash: f32,
    pub squash_frequency: i32,
}

/// Cycles' fast integer noise in [0, 1).
fn brick_noise(n: u32) -> f32 {
    let mut n = n.wrapping_add(1013) & 0x7fff_ffff;
    n ^= n >> 13;
    let nn = n
        .wrapping_mul(n.wrapping_mul(n).wrapping_mul(60493).wrapping_add(19990303))
        .wrapping_add(1376312589)
        & 0x7fff_ffff;
    0.5 * (nn as f32 / 1073741824.0)
}

fn smoothstep(f: f32) -> f32 {
    if f <= 0.0 {
        0.0
    } else if f >= 1.0 {
        1.0
    } else {
        let ff = f * f;
        3.0 * ff - 2.0 * ff * f
    }
}

/// (tint, mortar) at `p` (already scaled).
#[allow(clippy::too_many_arguments)]
pub fn brick(
    p: V3,
    mortar_size: f32,
    mortar_smooth: f32,
    bias: f32,
    mut brick_width: f32,
    row_height: f32,
    s: BrickSettings,
) -> (f32, f32) {
    let rownum = (p[1] / row_height).floor() as i32;
    let mut offset = 0.0;
    if s.offset_frequency != 0 && s.squash_frequency != 0 {
        if rownum.wrapping_rem(s.squash_frequency) == 0 {
            brick_width *= s.squash;
        }
        if rownum.wrapping_rem(s.offset_frequency) == 0 {
            offset = brick_width * s.offset;
        }
    }
    let bricknum = ((p[0] + offset) / brick_width).floor() as i32;
    let x = (p[0] + offset) - brick_width * bricknum as f32;
    let y = p[1] - row_height * rownum as f32;
    let hash = (rownum.wrapping_shl(16)).wrapping_add(bricknum & 0xFFFF) as u32;
    // saturatef: fminf(fmaxf(x, 0), 1).
    #[allow(clippy::manual_clamp)]
    let tint = (brick_noise(hash) + bias).max(0.0).min(1.0);
    let min_dist = x.min(y).min((brick_width - x).min(row_height - y));
    let mortar = if min_dist >= mortar_size {
        0.0
    } else if mortar_smooth == 0.0 {
        1.0
    } else {
        smoothstep((1.0 - min_dist / mortar_size) / mortar_smooth)
    };
    (tint, mortar)
}

/// (Color, Fac) of the Brick Texture node.
#[allow(clippy::too_many_arguments)]
pub fn brick_texture(
    vector: V3,
    color1: V3,
    color2: V3,
    mortar: V3,
    scale: f32,
    mortar_size: f32,
    mortar_smooth: f32,
    bias: f32,
    brick_width: f32,
    row_height: f32,
    s: BrickSettings,
) -> (V3, f32) {
    let p = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
    let (tint, f) = brick(
        p,
        mortar_size,
        mortar_smooth,
        bias,
        brick_width,
        row_height,
        s,
    );
    let mut c = color1;
    if f != 1.0 {
        let facm = 1.0 - tint;
        c = std::array::from_fn(|k| facm * color1[k] + tint * color2[k]);
    }
    (std::array::from_fn(|k| c[k] * (1.0 - f) + mortar[k] * f), f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_in_unit_range() {
        for n in [0u32, 1, 65535, 1 << 16, u32::MAX, 0x8000_0000] {
            let v = brick_noise(n);
            assert!((0.0..1.0).contains(&v), "{n}: {v}");
        }
    }
}
