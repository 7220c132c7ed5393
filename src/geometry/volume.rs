//! The volume component: float fog grids as Blender's `Volume` holds them (OpenVDB
//! `FloatGrid`s), each a name, a background value, an index-to-object transform and the
//! values of its active voxels. blendsynth keeps each grid dense over the bounding box of
//! its active voxels (x fastest), an inactive voxel there holding the background, which
//! is what OpenVDB reads back from it.
//!
//! Blender 4.5's Geometry Nodes carry a volume component through Transform Geometry (the
//! grids' transforms, `transform_volume`), Join Geometry (one volume passes; two or more
//! are dropped, `join_component_type` joins no volumes) and Realize Instances (the first
//! volume found, its instance transform not applied): checked against Blender in
//! `tests/geometry.rs` (`gn_volume_nodes`).

use super::math::{mat4_mul, Mat4f};

/// OpenVDB's smallest determinant of a grid transform
/// (`BKE_volume_grid_determinant_valid`: 3 * `math::Tolerance<double>`).
pub const MIN_DETERMINANT: f64 = 3e-15;

/// Most voxels one grid may hold (dense over its active box): 2^26 floats, 256 MiB, so
/// a hostile resolution is an error naming the node, not an out-of-memory abort.
pub const MAX_VOXELS: u64 = 1 << 26;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Volume {
    pub grids: Vec<VolumeGrid>,
    /// Material slots (Set Material gives a volume its one material).
    pub materials: Vec<Option<String>>,
}

/// One float grid.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeGrid {
    pub name: String,
    /// Index space to object space, `m[col][row]` as `Mat4f` (column 3 the translation):
    /// voxel (i, j, k) is the point `m * (i, j, k, 1)`.
    pub transform: [[f64; 4]; 4],
    pub background: f32,
    /// Index of the stored box's first voxel.
    pub origin: [i32; 3],
    /// Voxels along each axis of the stored box (all 0 for a grid without active voxels).
    pub dims: [usize; 3],
    /// Values over the box, x fastest (`(k * ny + j) * nx + i`); inactive ones hold the
    /// background.
    pub values: Vec<f32>,
    pub active: Vec<bool>,
}

impl VolumeGrid {
    /// A grid from dense values at voxels `dims` starting at index 0 (x fastest), as
    /// OpenVDB's `copyFromDense` with tolerance 0 makes it: a voxel is active when its
    /// value differs from the background, and the stored box shrinks to the active ones.
    pub fn from_dense(
        name: &str,
        transform: [[f64; 4]; 4],
        background: f32,
        dims: [usize; 3],
        values: &[f32],
    ) -> VolumeGrid {
        // `isApproxEqual(v, background, 0)`: equal unless |v - background| > 0 (NaN is
        // "equal", so inactive).
        let active: Vec<bool> = values
            .iter()
            .map(|v| (v - background).abs() > 0.0)
            .collect();
        VolumeGrid::from_dense_active(name, transform, background, [0; 3], dims, values, &active)
    }

    /// A grid from values and active flags over the box of `dims` voxels at index
    /// `origin` (x fastest), the stored box shrunk to the active voxels; inactive ones
    /// read the background.
    pub fn from_dense_active(
        name: &str,
        transform: [[f64; 4]; 4],
        background: f32,
        origin: [i32; 3],
        dims: [usize; 3],
        values: &[f32],
        active: &[bool],
    ) -> VolumeGrid {
        let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
        for (n, _) in active.iter().enumerate().filter(|(_, a)| **a) {
            let ijk = [
                n % dims[0],
                (n / dims[0]) % dims[1],
                n / (dims[0] * dims[1]),
            ];
            for a in 0..3 {
                lo[a] = lo[a].min(ijk[a]);
                hi[a] = hi[a].max(ijk[a]);
            }
        }
        let mut g = VolumeGrid {
            name: name.to_string(),
            transform,
            background,
            origin: [0; 3],
            dims: [0; 3],
            values: Vec::new(),
            active: Vec::new(),
        };
        if lo[0] == usize::MAX {
            return g;
        }
        let d = [0, 1, 2].map(|a| hi[a] - lo[a] + 1);
        g.origin = [0, 1, 2].map(|a| origin[a] + lo[a] as i32);
        g.dims = d;
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    let n = (k * dims[1] + j) * dims[0] + i;
                    g.values
                        .push(if active[n] { values[n] } else { background });
                    g.active.push(active[n]);
                }
            }
        }
        g
    }

    pub fn active_voxel_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }

    /// The index box of the active voxels (inclusive), None when there is none.
    pub fn active_bounds(&self) -> Option<([i32; 3], [i32; 3])> {
        let [nx, ny, _] = self.dims;
        let (mut lo, mut hi) = ([i32::MAX; 3], [i32::MIN; 3]);
        for (n, _) in self.active.iter().enumerate().filter(|(_, a)| **a) {
            let ijk = [n % nx, (n / nx) % ny, n / (nx * ny)];
            for a in 0..3 {
                let c = self.origin[a] + ijk[a] as i32;
                lo[a] = lo[a].min(c);
                hi[a] = hi[a].max(c);
            }
        }
        (lo[0] <= hi[0]).then_some((lo, hi))
    }

    /// The value at voxel index `ijk` (the background off the stored box).
    pub fn value(&self, ijk: [i32; 3]) -> f32 {
        let mut at = 0usize;
        let mut stride = 1usize;
        for a in 0..3 {
            let c = ijk[a] - self.origin[a];
            if c < 0 || c as usize >= self.dims[a] {
                return self.background;
            }
            at += c as usize * stride;
            stride *= self.dims[a];
        }
        self.values[at]
    }

    /// Drops every voxel (OpenVDB's `clear` of the tree); the background stays.
    pub fn clear(&mut self) {
        self.origin = [0; 3];
        self.dims = [0; 3];
        self.values.clear();
        self.active.clear();
    }

    /// Blender's `transform_volume` for one grid: the transform becomes `m` times it in
    /// single precision (`float4x4`); a result OpenVDB cannot hold (determinant below
    /// `MIN_DETERMINANT`) empties the grid and keeps its axes' directions at unit length
    /// (identity axes for a zero determinant).
    pub fn apply_transform(&mut self, m: &Mat4f) {
        let cur: Mat4f = self.transform.map(|c| c.map(|x| x as f32));
        let mut t = mat4_mul(m, &cur);
        let det = det3(&t);
        if (det as f64).abs() < MIN_DETERMINANT {
            self.clear();
            if det == 0.0 {
                for (c, col) in t.iter_mut().take(3).enumerate() {
                    *col = [0.0; 4];
                    col[c] = 1.0;
                }
            } else {
                for col in t.iter_mut().take(3) {
                    let l = (col[0] * col[0] + col[1] * col[1] + col[2] * col[2]).sqrt();
                    for x in col.iter_mut().take(3) {
                        *x /= l;
                    }
                }
            }
        }
        self.transform = t.map(|c| c.map(|x| x as f64));
    }

    /// The transform as object-space origin of voxel (0, 0, 0) and voxel size per axis,
    /// None when it rotates, shears or mirrors (Cycles' dense boxes are axis-aligned here).
    pub fn axis_aligned(&self) -> Option<([f64; 3], [f64; 3])> {
        let t = &self.transform;
        let size = [t[0][0], t[1][1], t[2][2]];
        let biggest = size.iter().fold(0.0f64, |m, s| m.max(s.abs()));
        let off = (0..3).any(|c| (0..3).any(|r| r != c && t[c][r].abs() > 1e-6 * biggest));
        let projective = (0..3).any(|c| t[c][3] != 0.0) || t[3][3] != 1.0;
        if off || projective || size.iter().any(|s| *s <= 0.0) {
            return None;
        }
        Some(([t[3][0], t[3][1], t[3][2]], size))
    }
}

/// Determinant of the upper 3x3 of a `m[col][row]` matrix.
fn det3(m: &Mat4f) -> f32 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

impl Volume {
    pub fn is_empty(&self) -> bool {
        self.grids.is_empty()
    }
    pub fn apply_transform(&mut self, m: &Mat4f) {
        for g in &mut self.grids {
            g.apply_transform(m);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: [[f64; 4]; 4] = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ];

    #[test]
    fn copy_from_dense_activates_values_off_the_background_and_shrinks_the_box() {
        // 3x2x1, background 1: only the voxels at (1, 0, 0) and (2, 1, 0) differ.
        let v = [1.0, 5.0, 1.0, 1.0, 1.0, 0.0];
        let g = VolumeGrid::from_dense("density", ID, 1.0, [3, 2, 1], &v);
        assert_eq!(g.active_voxel_count(), 2);
        assert_eq!(g.origin, [1, 0, 0]);
        assert_eq!(g.dims, [2, 2, 1]);
        assert_eq!(g.values, vec![5.0, 1.0, 1.0, 0.0]);
        assert_eq!(g.active_bounds(), Some(([1, 0, 0], [2, 1, 0])));
        assert_eq!(g.value([2, 1, 0]), 0.0);
        assert_eq!(g.value([0, 0, 0]), 1.0);
        assert_eq!(g.value([9, 9, 9]), 1.0);
        let empty = VolumeGrid::from_dense("density", ID, 1.0, [3, 2, 1], &[1.0; 6]);
        assert_eq!(
            (empty.active_voxel_count(), empty.active_bounds()),
            (0, None)
        );
    }

    #[test]
    fn transforms_compose_and_a_degenerate_one_empties_the_grid() {
        let mut g = VolumeGrid::from_dense("density", ID, 0.0, [1, 1, 1], &[2.0]);
        let mut m = super::super::math::MAT4_IDENTITY;
        m[0][0] = 2.0;
        m[3] = [1.0, 2.0, 3.0, 1.0];
        g.apply_transform(&m);
        assert_eq!(g.axis_aligned(), Some(([1.0, 2.0, 3.0], [2.0, 1.0, 1.0])));
        m[1][1] = 0.0;
        g.apply_transform(&m);
        assert_eq!(g.active_voxel_count(), 0);
        assert_eq!(g.transform[1], [0.0, 1.0, 0.0, 0.0]);
    }
}
