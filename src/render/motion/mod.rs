//! Motion blur as Cycles does it for the camera: the scene is synced at the shutter's
//! centre, the camera at three times across the shutter (Cycles' default of one motion
//! step each side), and every camera ray gets a time drawn through the inverse CDF of the
//! shutter curve, at which the camera transform is interpolated (rotation by slerp,
//! translation linearly).
//!
//! Objects use the same decomposition and interpolation (`object_motion` keeps moving
//! objects in object space and moves each ray into it at the ray's time).

pub mod object;

use crate::nodes::curves::{mapping_from_json, CurveKind, CurveTable};
use crate::render::math::*;
use crate::scene::settings::{MotionBlur, ShutterPosition};

/// Cycles' SHUTTER_TABLE_SIZE and the resolution Blender samples the curve at.
const TABLE: usize = 256;

/// The scene's motion blur settings, read from `scene.render`.
#[derive(Debug, Clone)]
pub struct Shutter {
    /// Shutter length in frames.
    pub length: f64,
    /// Offset of the shutter's centre from the frame (START: +length/2, END: -length/2).
    pub centre_delta: f64,
    /// Inverse CDF of the shutter curve: a uniform number to a time in [0, 1].
    table: Vec<f32>,
}

impl Shutter {
    /// None when motion blur is off (or the shutter is empty).
    pub fn from_settings(m: &MotionBlur) -> Result<Option<Shutter>, String> {
        let length = m.shutter;
        if !m.enabled || length.is_nan() || length <= 0.0 {
            return Ok(None);
        }
        let centre_delta = match m.position {
            ShutterPosition::Start => 0.5 * length,
            ShutterPosition::End => -0.5 * length,
            ShutterPosition::Center => 0.0,
        };
        let curve = match &m.shutter_curve {
            Some(v) => {
                let m = mapping_from_json(v)
                    .map_err(|e| format!("render.motion_blur_shutter_curve: {}", e.0))?;
                let t = CurveTable::new(&m, CurveKind::Float)
                    .map_err(|e| format!("render.motion_blur_shutter_curve: {}", e.0))?;
                // Blender hands Cycles the curve sampled at TABLE evenly spaced points.
                (0..TABLE)
                    .map(|i| t.eval1(1.0, i as f32 / (TABLE - 1) as f32))
                    .collect()
            }
            _ => vec![1.0; TABLE],
        };
        Ok(Some(Shutter {
            length,
            centre_delta,
            table: inverted_cdf(&curve),
        }))
    }

    /// The relative times (-1, 0, 1) of the camera's motion steps as frames.
    pub fn step_frames(&self, frame: f64) -> [f64; 3] {
        let c = frame + self.centre_delta;
        [c - 0.5 * self.length, c, c + 0.5 * self.length]
    }

    /// A ray time in [0, 1] from a uniform number (Cycles' lookup_table_read).
    #[inline]
    pub fn time(&self, u: f32) -> f32 {
        let n = self.table.len();
        let x = u.clamp(0.0, 1.0) * (n - 1) as f32;
        let i = (x as usize).min(n - 1);
        let j = (i + 1).min(n - 1);
        let t = x - i as f32;
        (1.0 - t) * self.table[i] + t * self.table[j]
    }
}

/// The shutter curve's value at x in [0, 1] from its sampled table (linear).
fn curve_at(curve: &[f32], x: f32) -> f32 {
    let n = curve.len();
    let x = x.clamp(0.0, 1.0) * (n - 1) as f32;
    let i = x as usize;
    if i + 1 < n {
        let f = x - i as f32;
        (1.0 - f) * curve[i] + f * curve[i + 1]
    } else {
        curve[n - 1]
    }
}

/// Cycles' util_cdf_inverted(TABLE, 0, 1, curve, symmetric = false): the CDF of |curve|
/// at TABLE - 1 points, inverted at TABLE cell centres.
fn inverted_cdf(curve: &[f32]) -> Vec<f32> {
    let res = TABLE - 1;
    let mut cdf = vec![0.0f32; res + 1];
    for i in 0..res {
        let x = i as f32 / (res - 1) as f32;
        cdf[i + 1] = cdf[i] + curve_at(curve, x).abs();
    }
    let fac = if cdf[res] == 0.0 { 0.0 } else { 1.0 / cdf[res] };
    for c in cdf.iter_mut() {
        *c *= fac;
    }
    cdf[res] = 1.0;
    let inv_res = 1.0 / TABLE as f32;
    (0..TABLE)
        .map(|i| {
            let x = (i as f32 + 0.5) * inv_res;
            // Last entry <= x (upper_bound - 1).
            let idx = cdf.partition_point(|&c| c <= x).saturating_sub(1);
            let (idx, t) = if idx < cdf.len() - 1 {
                (idx, (x - cdf[idx]) / (cdf[idx + 1] - cdf[idx]))
            } else {
                (TABLE, 0.0)
            };
            (idx as f32 + t) * inv_res
        })
        .collect()
}

/// An affine transform split for interpolation as Cycles' DecomposedTransform: unit
/// quaternion (x, y, z, w), translation, and the upper-triangular scale/shear matrix S
/// (the transform is R S plus translation) as s00, s01, s02, s11, s12, s22.
#[derive(Debug, Clone, Copy)]
pub struct Decomposed {
    q: [f32; 4],
    t: V3,
    s: [f32; 6],
}

/// Rotation part of an affine transform (scale already removed) as a quaternion.
fn quat_from(m: &Affine) -> [f32; 4] {
    let r = |i: usize, j: usize| m.m[i][j] as f64;
    let trace = r(0, 0) + r(1, 1) + r(2, 2);
    let q = if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        [
            (r(2, 1) - r(1, 2)) / s,
            (r(0, 2) - r(2, 0)) / s,
            (r(1, 0) - r(0, 1)) / s,
            0.25 * s,
        ]
    } else if r(0, 0) > r(1, 1) && r(0, 0) > r(2, 2) {
        let s = (1.0 + r(0, 0) - r(1, 1) - r(2, 2)).sqrt() * 2.0;
        [
            0.25 * s,
            (r(0, 1) + r(1, 0)) / s,
            (r(0, 2) + r(2, 0)) / s,
            (r(2, 1) - r(1, 2)) / s,
        ]
    } else if r(1, 1) > r(2, 2) {
        let s = (1.0 + r(1, 1) - r(0, 0) - r(2, 2)).sqrt() * 2.0;
        [
            (r(0, 1) + r(1, 0)) / s,
            0.25 * s,
            (r(1, 2) + r(2, 1)) / s,
            (r(0, 2) - r(2, 0)) / s,
        ]
    } else {
        let s = (1.0 + r(2, 2) - r(0, 0) - r(1, 1)).sqrt() * 2.0;
        [
            (r(0, 2) + r(2, 0)) / s,
            (r(1, 2) + r(2, 1)) / s,
            0.25 * s,
            (r(1, 0) - r(0, 1)) / s,
        ]
    };
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    [
        (q[0] / n) as f32,
        (q[1] / n) as f32,
        (q[2] / n) as f32,
        (q[3] / n) as f32,
    ]
}

/// Cycles' transform_decompose: scale and shear by Gram-Schmidt on the columns, a
/// negative determinant folded into the scale, the orthonormal rest as a quaternion.
fn decompose_one(m: &Affine) -> Decomposed {
    let div = |v: Vec3, d: f32| {
        if d != 0.0 {
            v * (1.0 / d)
        } else {
            Vec3::ZERO
        }
    };
    let (mut cx, mut cy, mut cz) = (m.column_vec3(0), m.column_vec3(1), m.column_vec3(2));
    let sx = cx.length();
    cx = div(cx, sx);
    let shz = cx.dot(cy);
    cy -= cx * shz;
    let sy = cy.length();
    cy = div(cy, sy);
    let shy = cx.dot(cz);
    cz -= cx * shy;
    let shx = cy.dot(cz);
    cz -= cy * shx;
    let sz = cz.length();
    cz = div(cz, sz);
    let mut r = Affine {
        m: std::array::from_fn(|i| [cx[i], cy[i], cz[i], 0.0]),
    };
    let mut sc = [sx, sy, sz];
    if cx.cross(cy).dot(cz) < 0.0 {
        sc = sc.map(|v| -v);
        for row in r.m.iter_mut() {
            for v in row.iter_mut().take(3) {
                *v = -*v;
            }
        }
    }
    Decomposed {
        q: quat_from(&r),
        t: m.column(3),
        s: [sc[0], shz, shy, sc[1], shx, sc[2]],
    }
}

/// Decomposes the motion steps, flipping quaternions onto one hemisphere so slerp takes
/// the short way (as Cycles' transform_motion_decompose does), and giving a step whose
/// scale is zero its neighbour's rotation.
pub fn decompose(steps: &[Affine]) -> Vec<Decomposed> {
    let mut out: Vec<Decomposed> = Vec::with_capacity(steps.len());
    for m in steps {
        let mut d = decompose_one(m);
        if let Some(prev) = out.last() {
            let c =
                d.q[0] * prev.q[0] + d.q[1] * prev.q[1] + d.q[2] * prev.q[2] + d.q[3] * prev.q[3];
            if c < 0.0 {
                d.q = d.q.map(|c| -c);
            }
        }
        out.push(d);
    }
    for i in 0..out.len() {
        if out[i].s[0] == 0.0 && out[i].s[3] == 0.0 && out[i].s[5] == 0.0 {
            if i > 0 {
                out[i].q = out[i - 1].q;
            } else if i + 1 < out.len() {
                out[i].q = out[i + 1].q;
            }
        }
    }
    out
}

fn quat_interpolate(a: [f32; 4], b: [f32; 4], t: f32) -> [f32; 4] {
    let cos = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    let norm = |q: [f32; 4]| {
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        q.map(|c| c / n)
    };
    if cos > 0.9995 {
        return norm(std::array::from_fn(|i| (1.0 - t) * a[i] + t * b[i]));
    }
    let theta = cos.clamp(-1.0, 1.0).acos();
    let perp = norm(std::array::from_fn(|i| b[i] - a[i] * cos));
    let tp = theta * t;
    std::array::from_fn(|i| a[i] * tp.cos() + perp[i] * tp.sin())
}

/// R S plus translation (Cycles' transform_compose).
fn compose(q: [f32; 4], t: V3, s: &[f32; 6]) -> Affine {
    let [x, y, z, w] = q;
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let sm = [[s[0], s[1], s[2]], [0.0, s[3], s[4]], [0.0, 0.0, s[5]]];
    Affine {
        m: std::array::from_fn(|i| {
            [0, 1, 2, 3].map(|j| {
                if j == 3 {
                    t[i]
                } else {
                    r[i][0] * sm[0][j] + r[i][1] * sm[1][j] + r[i][2] * sm[2][j]
                }
            })
        }),
    }
}

/// The transform at `time` in [0, 1] across the motion steps.
pub fn interpolate(steps: &[Decomposed], time: f32) -> Affine {
    let max = steps.len() - 1;
    let x = time.clamp(0.0, 1.0) * max as f32;
    let i = (x as usize).min(max - 1);
    let t = x - i as f32;
    let (a, b) = (&steps[i], &steps[i + 1]);
    let lerp = |x: f32, y: f32| (1.0 - t) * x + t * y;
    compose(
        quat_interpolate(a.q, b.q, t),
        std::array::from_fn(|k| lerp(a.t[k], b.t[k])),
        &std::array::from_fn(|k| lerp(a.s[k], b.s[k])),
    )
}

impl Decomposed {
    pub fn translation(&self) -> V3 {
        self.t
    }

    /// An upper bound of |R S p| for every p within `r` of `c`: how far the object's
    /// points reach from its origin at this step. S is interpolated linearly, so between
    /// two steps the reach stays below the larger of theirs.
    pub fn reach(&self, c: V3, r: f32) -> f32 {
        let s = &self.s;
        let sc = vec3(
            s[0] * c[0] + s[1] * c[1] + s[2] * c[2],
            s[3] * c[1] + s[4] * c[2],
            s[5] * c[2],
        );
        let frobenius = s.iter().map(|v| v * v).sum::<f32>().sqrt();
        sc.length() + r * frobenius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_curve_table_is_the_identity() {
        let table = inverted_cdf(&vec![1.0; TABLE]);
        for (i, v) in table.iter().enumerate() {
            let x = (i as f32 + 0.5) / TABLE as f32;
            assert!((v - x).abs() < 2.0 / TABLE as f32, "{i}: {v} vs {x}");
        }
    }

    #[test]
    fn interpolation_hits_the_steps_and_the_half_angle() {
        let rz = |a: f32| Affine {
            m: [
                [a.cos(), -a.sin(), 0.0, a],
                [a.sin(), a.cos(), 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
        };
        let steps = decompose(&[rz(0.0), rz(0.4), rz(0.8)]);
        for (time, a) in [(0.0, 0.0f32), (0.25, 0.2), (0.5, 0.4), (1.0, 0.8)] {
            let m = interpolate(&steps, time);
            let want = rz(a);
            for r in 0..3 {
                for c in 0..4 {
                    assert!(
                        (m.m[r][c] - want.m[r][c]).abs() < 1e-5,
                        "time {time}: {:?} vs {:?}",
                        m.m,
                        want.m
                    );
                }
            }
        }
    }

    #[test]
    fn scale_and_shear_survive_decomposition() {
        // Rotated, non-uniformly scaled and sheared transforms recompose exactly, and so
        // do mirrored ones without shear. (Cycles folds a mirror into the scale only, not
        // the shear, so a mirrored sheared transform does not survive there either.)
        let (c, s) = (0.6f32.cos(), 0.6f32.sin());
        let rot = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
        for sm in [
            [[2.0, 0.3, -0.2], [0.0, 0.5, 0.1], [0.0, 0.0, 1.5]],
            [[2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, -1.5]],
        ] {
            let m = Affine {
                m: std::array::from_fn(|i| {
                    [0, 1, 2, 3].map(|j| {
                        if j == 3 {
                            [1.0, -2.0, 3.0][i]
                        } else {
                            (0..3).map(|k| rot[i][k] * sm[k][j]).sum()
                        }
                    })
                }),
            };
            let steps = decompose(&[m, m]);
            let back = interpolate(&steps, 0.3);
            for r in 0..3 {
                for c in 0..4 {
                    assert!(
                        (back.m[r][c] - m.m[r][c]).abs() < 1e-5,
                        "{:?} vs {:?}",
                        back.m,
                        m.m
                    );
                }
            }
        }
    }

    #[test]
    fn scale_interpolates_linearly() {
        // Cycles interpolates the scale matrix linearly between steps.
        let sx = |k: f32| Affine {
            m: [
                [k, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
        };
        let steps = decompose(&[sx(1.0), sx(2.0), sx(4.0)]);
        for (time, want) in [(0.25, 1.5f32), (0.5, 2.0), (0.75, 3.0)] {
            assert!((interpolate(&steps, time).m[0][0] - want).abs() < 1e-6);
        }
    }
}
