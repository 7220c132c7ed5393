//! Point Density texture as Cycles renders it (svm/voxel.h, svm_node_tex_voxel): Blender
//! computes the voxel grid at sync (RE_point_density_sample: voxel (x, y, z) holds the
//! density and colour at min + (max - min) * (x, y, z) / resolution), and Cycles reads it
//! as a 3D image with Clip extension and the node's interpolation (the CPU kernel's
//! interp_3d). It is evaluated in volumes only: in a surface Cycles' node feature mask
//! leaves it out, so both outputs are zero there.
//!
//! Object space maps the lookup point into the *shaded* object's texture space
//! (volume_normalized_position), not the points object's bounds; World space maps it
//! through the points object's inverse world matrix onto the grid's bounds.

use std::sync::Arc;

/// The node's interpolation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    Closest,
    Linear,
    Cubic,
}

impl Interpolation {
    pub fn from_blender(s: &str) -> Option<Interpolation> {
        Some(match s {
            "Closest" => Interpolation::Closest,
            "Linear" => Interpolation::Linear,
            "Cubic" => Interpolation::Cubic,
            _ => return None,
        })
    }
}

/// Where the lookup point is mapped from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Space {
    /// The shaded volume object's texture space (Generated coordinates).
    Object,
    /// World space through this affine map (rows) onto the grid's unit cube.
    World([[f32; 4]; 3]),
}

/// A resolution^3 grid of RGBA voxels, x fastest.
#[derive(Debug, Clone)]
pub struct VoxelGrid {
    pub resolution: usize,
    pub voxels: Arc<Vec<[f32; 4]>>,
}

/// Cycles' SET_CUBIC_SPLINE_WEIGHTS (uniform cubic B-spline), for 3D images and voxel
/// grids alike.
pub fn cubic_weights(t: f32) -> [f32; 4] {
    [
        (((-1.0 / 6.0) * t + 0.5) * t - 0.5) * t + (1.0 / 6.0),
        ((0.5 * t - 1.0) * t) * t + (2.0 / 3.0),
        ((-0.5 * t + 0.5) * t + 0.5) * t + (1.0 / 6.0),
        (1.0 / 6.0) * t * t * t,
    ]
}

/// Cycles' frac: the integer below `x` and the fraction above it.
fn frac(x: f32) -> (f32, i32) {
    // Cycles truncates and steps down for negatives (float_to_int, then -1 if x < 0).
    let i = (x as i32) - i32::from(x < 0.0);
    (x - i as f32, i)
}

impl VoxelGrid {
    /// The voxel at (x, y, z), zero outside (Clip).
    fn read(&self, x: i32, y: i32, z: i32) -> [f32; 4] {
        let n = self.resolution as i32;
        if x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n {
            return [0.0; 4];
        }
        let n = self.resolution;
        self.voxels[x as usize + n * (y as usize + n * z as usize)]
    }

    /// Cycles' kernel_tex_image_interp_3d at texture coordinates `co` (the unit cube is
    /// the grid), Clip extension.
    pub fn sample(&self, co: [f32; 3], interp: Interpolation) -> [f32; 4] {
        let n = self.resolution as i32;
        let size = self.resolution as f32;
        let mut r = [0.0f32; 4];
        let mut acc = |w: f32, v: [f32; 4]| {
            for k in 0..4 {
                r[k] += w * v[k];
            }
        };
        match interp {
            Interpolation::Closest => {
                let i = co.map(|c| frac(c * size).1);
                if i.iter().any(|&i| i < 0 || i >= n) {
                    return [0.0; 4];
                }
                return self.read(i[0], i[1], i[2]);
            }
            Interpolation::Linear => {
                let f = co.map(|c| frac(c * size - 0.5));
                if f.iter().any(|&(_, i)| i < -1 || i >= n) {
                    return [0.0; 4];
                }
                let ([tx, ty, tz], [ix, iy, iz]) = (f.map(|v| v.0), f.map(|v| v.1));
                // Cycles' trilinear_lookup, in its order of terms.
                for (dz, wz) in [(0, 1.0 - tz), (1, tz)] {
                    for (dy, wy) in [(0, 1.0 - ty), (1, ty)] {
                        for (dx, wx) in [(0, 1.0 - tx), (1, tx)] {
                            acc(wz * wy * wx, self.read(ix + dx, iy + dy, iz + dz));
                        }
                    }
                }
            }
            Interpolation::Cubic => {
                let f = co.map(|c| frac(c * size - 0.5));
                if f.iter().any(|&(_, i)| i < -2 || i > n) {
                    return [0.0; 4];
                }
                let ([tx, ty, tz], [ix, iy, iz]) = (f.map(|v| v.0), f.map(|v| v.1));
                let (u, v, w) = (cubic_weights(tx), cubic_weights(ty), cubic_weights(tz));
                for (c, wz) in w.iter().enumerate() {
                    for (b, wy) in v.iter().enumerate() {
                        for (a, wx) in u.iter().enumerate() {
                            let p =
                                self.read(ix + a as i32 - 1, iy + b as i32 - 1, iz + c as i32 - 1);
                            acc(wz * wy * wx, p);
                        }
                    }
                }
            }
        }
        r
    }
}

/// Cycles' world-space texture transform (blender/shader.cpp): translate(-loc) *
/// scale(size) * inverse(object world matrix), with loc and size from
/// density_texture_space_invert of the grid's bounds; so a point at `min` in the points
/// object's space maps to 0 and one at `max` to 1. None when an axis of the bounds is
/// empty or the matrix is singular (Blender's grid is then all zero anyway).
pub fn world_space(
    object_matrix: &[[f32; 4]; 4],
    min: [f32; 3],
    max: [f32; 3],
) -> Option<[[f32; 4]; 3]> {
    let m = &object_matrix;
    let inv = crate::foundation::math::Affine {
        m: [m[0], m[1], m[2]],
    }
    .inverse()?
    .m;
    let mut out = [[0.0f32; 4]; 3];
    for k in 0..3 {
        let d = max[k] - min[k];
        if !(d > 0.0) {
            return None;
        }
        // Cycles: size' = 0.5 / half-size, loc' = centre * size' - 0.5.
        let size = 0.5 / (d * 0.5);
        let loc = (min[k] + max[k]) * 0.5 * size - 0.5;
        for j in 0..4 {
            out[k][j] = inv[k][j] * size;
        }
        out[k][3] -= loc;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(n: usize) -> VoxelGrid {
        let voxels = (0..n * n * n)
            .map(|i| {
                let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
                [x as f32, y as f32, z as f32, 1.0]
            })
            .collect();
        VoxelGrid {
            resolution: n,
            voxels: Arc::new(voxels),
        }
    }

    #[test]
    fn linear_is_exact_at_voxel_centres_and_between_them() {
        let g = ramp(4);
        // Voxel (1, 2, 3)'s centre is at ((1.5, 2.5, 3.5) / 4).
        let c = g.sample([1.5 / 4.0, 2.5 / 4.0, 3.5 / 4.0], Interpolation::Linear);
        assert_eq!(c, [1.0, 2.0, 3.0, 1.0]);
        let m = g.sample([2.0 / 4.0, 2.5 / 4.0, 1.5 / 4.0], Interpolation::Linear);
        assert!((m[0] - 1.5).abs() < 1e-6 && (m[1] - 2.0).abs() < 1e-6);
        // Half a voxel past the edge the border voxel is mixed with Clip's zero.
        let e = g.sample([0.0, 0.5, 0.5], Interpolation::Linear);
        assert!((e[3] - 0.5).abs() < 1e-6);
        assert_eq!(g.sample([1.2, 0.5, 0.5], Interpolation::Linear), [0.0; 4]);
    }

    #[test]
    fn closest_and_cubic_follow_cycles() {
        let g = ramp(4);
        assert_eq!(
            g.sample([0.30, 0.99, 0.01], Interpolation::Closest),
            [1.0, 3.0, 0.0, 1.0]
        );
        assert_eq!(
            g.sample([-0.01, 0.5, 0.5], Interpolation::Closest),
            [0.0; 4]
        );
        // The B-spline reproduces a linear ramp away from the border.
        let c = g.sample([2.0 / 4.0, 2.0 / 4.0, 2.0 / 4.0], Interpolation::Cubic);
        assert!((c[0] - 1.5).abs() < 1e-5, "{c:?}");
        // And its weights sum to one.
        let w = cubic_weights(0.3);
        assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn world_space_maps_the_bounds_onto_the_unit_cube() {
        let m = [
            [2.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, -1.0],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let t = world_space(&m, [-1.0; 3], [1.0; 3]).unwrap();
        let ap = |p: [f32; 3]| {
            [0, 1, 2].map(|k| t[k][0] * p[0] + t[k][1] * p[1] + t[k][2] * p[2] + t[k][3])
        };
        // World (-1, -1, -2) is object (-1, -1, -1): the grid's min corner.
        let a = ap([-1.0, -1.0, -2.0]);
        assert!(a.iter().all(|v| v.abs() < 1e-6), "{a:?}");
        let b = ap([3.0, 1.0, 0.0]);
        assert!(b.iter().all(|v| (v - 1.0).abs() < 1e-6), "{b:?}");
        assert!(world_space(&m, [0.0; 3], [0.0, 1.0, 1.0]).is_none());
    }
}
