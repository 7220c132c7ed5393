//! Perlin noise as Blender's `BLI_noise` (shared with Cycles): Jenkins lookup3 hashing of
//! the lattice coordinates, improved-Perlin gradients and fade, fractal sum. Used by the
//! Noise F-modifier (non-legacy mode), which needs the 2D variant only. Single precision
//! throughout, as in Blender.

fn rot(x: u32, k: u32) -> u32 {
    x.rotate_left(k)
}

fn final_mix(a: &mut u32, b: &mut u32, c: &mut u32) {
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

/// lookup3 `hashword` of two 32-bit keys.
pub fn hash2(kx: u32, ky: u32) -> u32 {
    let init = 0xdeadbeefu32.wrapping_add(2 << 2).wrapping_add(13);
    let (mut a, mut b, mut c) = (init, init, init);
    b = b.wrapping_add(ky);
    a = a.wrapping_add(kx);
    final_mix(&mut a, &mut b, &mut c);
    c
}

fn fade(t: f32) -> f32 {
    // Blender writes the constants as doubles, so this polynomial is evaluated in double.
    let t64 = t as f64;
    ((t * t * t) as f64 * (t64 * (t64 * 6.0 - 15.0) + 10.0)) as f32
}

fn negate_if(v: f32, cond: u32) -> f32 {
    if cond != 0 {
        -v
    } else {
        v
    }
}

fn grad2(hash: u32, x: f32, y: f32) -> f32 {
    let h = hash & 7;
    let u = if h < 4 { x } else { y };
    let v = 2.0 * if h < 4 { y } else { x };
    negate_if(u, h & 1) + negate_if(v, h & 2)
}

fn floor_frac(x: f32) -> (f32, i32) {
    let f = x.floor();
    (x - f, f as i32)
}

fn mix(a: f32, b: f32, t: f32) -> f32 {
    (1.0 - t) * a + t * b
}

fn perlin2(px: f32, py: f32) -> f32 {
    let (fx, x) = floor_frac(px);
    let (fy, y) = floor_frac(py);
    let u = fade(fx);
    let v = fade(fy);
    let (x0, x1, y0, y1) = (
        x as u32,
        x.wrapping_add(1) as u32,
        y as u32,
        y.wrapping_add(1) as u32,
    );
    let v0 = grad2(hash2(x0, y0), fx, fy);
    let v1 = grad2(hash2(x1, y0), fx - 1.0, fy);
    let v2 = grad2(hash2(x0, y1), fx, fy - 1.0);
    let v3 = grad2(hash2(x1, y1), fx - 1.0, fy - 1.0);
    // Bilinear mix; Blender writes `1.0 - x` with double literals, so parts are double.
    let x1c = (1.0 - u as f64) as f32;
    ((1.0 - v as f64) * (v0 * x1c + v1 * u) as f64 + (v * (v2 * x1c + v3 * u)) as f64) as f32
}

fn wrap_precision(p: f32) -> f32 {
    // Blender repeats the noise every 100000 and nudges huge coordinates off the lattice.
    let corr = if p.abs() >= 1_000_000.0 { 0.5 } else { 0.0 };
    (p % 100000.0) + corr
}

/// Signed 2D Perlin noise in about [-1, 1].
pub fn perlin_signed2(x: f32, y: f32) -> f32 {
    perlin2(wrap_precision(x), wrap_precision(y)) * 0.6616
}

/// Fractal Brownian motion of 2D Perlin noise (Blender's `perlin_fbm<float2>`).
pub fn perlin_fbm2(
    x: f32,
    y: f32,
    detail: f32,
    roughness: f32,
    lacunarity: f32,
    normalize: bool,
) -> f32 {
    let mut fscale = 1.0f32;
    let mut amp = 1.0f32;
    let mut maxamp = 0.0f32;
    let mut sum = 0.0f32;
    let octaves = detail as i32;
    for _ in 0..=octaves {
        let t = perlin_signed2(fscale * x, fscale * y);
        sum += t * amp;
        maxamp += amp;
        amp *= roughness;
        fscale *= lacunarity;
    }
    let rmd = detail - detail.floor();
    if rmd != 0.0 {
        let t = perlin_signed2(fscale * x, fscale * y);
        let sum2 = sum + t * amp;
        if normalize {
            mix(
                0.5 * sum / maxamp + 0.5,
                0.5 * sum2 / (maxamp + amp) + 0.5,
                rmd,
            )
        } else {
            mix(sum, sum2, rmd)
        }
    } else if normalize {
        0.5 * sum / maxamp + 0.5
    } else {
        sum
    }
}
