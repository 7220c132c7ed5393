//! Gabor Texture (Cycles `svm_node_tex_gabor`, kernel/svm/gabor.h): sparse Gabor
//! convolution noise after Tricard et al., eight impulses per unit cell, each a
//! Hann-windowed Gaussian times a sinusoid, summed over the 3x3 (2D) or 3x3x3 (3D)
//! neighbouring cells; Value is the phasor's imaginary part, Phase its angle, Intensity
//! its length, normalised by six standard deviations as Cycles does.

use std::f32::consts::PI;

use super::math::V3;
use super::random::{hash_float_to_float3, hash_float_to_float4};

const IMPULSES: i32 = 8;

blender_enum! {
    pub enum GaborType {
        TwoD = "2D",
        ThreeD = "3D",
    }
}

/// The node's outputs: (Value, Phase, Intensity).
pub fn gabor_texture(
    kind: GaborType,
    vector: V3,
    scale: f32,
    frequency: f32,
    anisotropy: f32,
    orientation_2d: f32,
    orientation_3d: V3,
) -> [f32; 3] {
    let p = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
    let isotropy = 1.0 - anisotropy.clamp(0.0, 1.0);
    let frequency = frequency.max(0.001);
    let (phasor, sd) = match kind {
        GaborType::TwoD => (
            noise_2d([p[0], p[1]], frequency, isotropy, orientation_2d),
            (IMPULSES as f32 * 0.5 * 0.25).sqrt(),
        ),
        GaborType::ThreeD => (
            noise_3d(p, frequency, isotropy, normalize(orientation_3d)),
            (IMPULSES as f32 * 0.5 * (1.0 / (4.0 * std::f32::consts::SQRT_2))).sqrt(),
        ),
    };
    let norm = 6.0 * sd;
    let value = (phasor[1] / norm) * 0.5 + 0.5;
    let phase = (phasor[1].atan2(phasor[0]) + PI) / (2.0 * PI);
    let intensity = (phasor[0] * phasor[0] + phasor[1] * phasor[1]).sqrt() / norm;
    [value, phase, intensity]
}

fn normalize(v: V3) -> V3 {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l != 0.0 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        v
    }
}

fn polar(r: f32, angle: f32) -> [f32; 2] {
    [r * angle.cos(), r * angle.sin()]
}

/// The windowed Gaussian envelope at squared distance `d2` from the kernel's centre.
fn envelope(d2: f32) -> f32 {
    let hann = 0.5 + 0.5 * (PI * d2).cos();
    let gauss = (-PI * d2).exp();
    gauss * hann
}

fn noise_2d(c: [f32; 2], frequency: f32, isotropy: f32, orientation: f32) -> [f32; 2] {
    let cell = [c[0].floor(), c[1].floor()];
    let local = [c[0] - cell[0], c[1] - cell[1]];
    let mut sum = [0.0f32; 2];
    for j in -1..=1 {
        for i in -1..=1 {
            let off = [i as f32, j as f32];
            let n = cell_2d(
                [cell[0] + off[0], cell[1] + off[1]],
                [local[0] - off[0], local[1] - off[1]],
                frequency,
                isotropy,
                orientation,
            );
            sum = [sum[0] + n[0], sum[1] + n[1]];
        }
    }
    sum
}

fn cell_2d(
    cell: [f32; 2],
    p: [f32; 2],
    frequency: f32,
    isotropy: f32,
    base_orientation: f32,
) -> [f32; 2] {
    let mut noise = [0.0f32; 2];
    for i in 0..IMPULSES {
        let seed = |k: i32| [cell[0], cell[1], (i * 3 + k) as f32];
        let random_orientation = (hash_float_to_float3(seed(0)) - 0.5) * PI;
        let orientation = base_orientation + random_orientation * isotropy;
        let s = seed(1);
        let center = [
            hash_float_to_float3(s),
            hash_float_to_float3([s[2], s[0], s[1]]),
        ];
        let q = [p[0] - center[0], p[1] - center[1]];
        let d2 = q[0] * q[0] + q[1] * q[1];
        if d2 >= 1.0 {
            continue;
        }
        let weight = if hash_float_to_float3(seed(2)) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let f = polar(frequency, orientation);
        let angle = 2.0 * PI * (q[0] * f[0] + q[1] * f[1]);
        let k = polar(envelope(d2), angle);
        noise = [noise[0] + weight * k[0], noise[1] + weight * k[1]];
    }
    noise
}

/// Cycles' spherical_to_direction.
fn spherical_to_direction(theta: f32, phi: f32) -> V3 {
    let s = theta.sin();
    [s * phi.cos(), s * phi.sin(), theta.cos()]
}

fn orientation_3d(o: V3, isotropy: f32, seed: [f32; 4]) -> V3 {
    if isotropy == 0.0 {
        return o;
    }
    let mut inclination = o[2].acos();
    let sign = if o[1] < 0.0 { -1.0 } else { 1.0 };
    let mut azimuth = sign * (o[0] / (o[0] * o[0] + o[1] * o[1]).sqrt()).acos();
    let r = [
        hash_float_to_float4(seed) * PI,
        hash_float_to_float4([seed[2], seed[0], seed[3], seed[1]]) * PI,
    ];
    inclination += r[0] * isotropy;
    azimuth += r[1] * isotropy;
    spherical_to_direction(inclination, azimuth)
}

fn noise_3d(c: V3, frequency: f32, isotropy: f32, orientation: V3) -> [f32; 2] {
    let cell = c.map(f32::floor);
    let local = [c[0] - cell[0], c[1] - cell[1], c[2] - cell[2]];
    let mut sum = [0.0f32; 2];
    for k in -1..=1 {
        for j in -1..=1 {
            for i in -1..=1 {
                let off = [i as f32, j as f32, k as f32];
                let n = cell_3d(
                    [cell[0] + off[0], cell[1] + off[1], cell[2] + off[2]],
                    [local[0] - off[0], local[1] - off[1], local[2] - off[2]],
                    frequency,
                    isotropy,
                    orientation,
                );
                sum = [sum[0] + n[0], sum[1] + n[1]];
            }
        }
    }
    sum
}

fn cell_3d(cell: V3, p: V3, frequency: f32, isotropy: f32, base: V3) -> [f32; 2] {
    let mut noise = [0.0f32; 2];
    for i in 0..IMPULSES {
        let seed = |k: i32| [cell[0], cell[1], cell[2], (i * 3 + k) as f32];
        let orientation = orientation_3d(base, isotropy, seed(0));
        let s = seed(1);
        // Cycles' hash_float4_to_float3.
        let center = [
            hash_float_to_float4(s),
            hash_float_to_float4([s[2], s[0], s[3], s[1]]),
            hash_float_to_float4([s[3], s[2], s[1], s[0]]),
        ];
        let q = [p[0] - center[0], p[1] - center[1], p[2] - center[2]];
        let d2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
        if d2 >= 1.0 {
            continue;
        }
        let weight = if hash_float_to_float4(seed(2)) < 0.5 {
            -1.0
        } else {
            1.0
        };
        let f = orientation.map(|x| frequency * x);
        let angle = 2.0 * PI * (q[0] * f[0] + q[1] * f[1] + q[2] * f[2]);
        let k = polar(envelope(d2), angle);
        noise = [noise[0] + weight * k[0], noise[1] + weight * k[1]];
    }
    noise
}
