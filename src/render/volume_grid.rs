//! Voxel grids inside a volume as Cycles 4.5 samples them (kernel image_3d NanoVDB
//! lookups, geom/volume.h): a smoke domain's grids over its texture-space box, or a Volume
//! object's OpenVDB grids each over its own box of active voxels, read by
//! Attribute nodes and Principled Volume's Density/Color/Temperature attributes at each
//! ray-marching step, with trilinear or tricubic B-spline interpolation in voxel index
//! space (a voxel spans [i, i + 1], its value at i + 0.5; outside the grid every value is
//! 0), and the ray-marching step the grids ask for.

use crate::scene::volume_grid::VoxelGrid;
use crate::shader::attributes::{AttributeRequest, MAX_ATTRIBUTES};
use crate::shader::point::ShadingPoint;

use super::math::*;

/// The grids of one smoke domain or Volume object, in its object space.
#[derive(Debug, Clone)]
pub struct DomainGrids {
    pub grids: Vec<VoxelGrid>,
    /// The box the grids tile together (a smoke domain's texture space; the union of a
    /// Volume object's grid boxes).
    pub min: V3,
    pub max: V3,
    /// The ray-marching step before step rates (Cycles' Object::compute_volume_step_size).
    pub step: GridStep,
    /// Cycles' object_volume_density: every volume closure's weight (extinction,
    /// scattering, emission) is multiplied by it. 1 but for a Volume object in Object
    /// space, where it undoes the object's scale.
    pub density_scale: f32,
}

/// Where the ray-marching step of grids comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GridStep {
    /// From the voxel size (smoke domains; a Volume's Step Size 0).
    Voxel,
    /// A Volume's Step Size in object space (Volume > Render > Space Object).
    Object(f32),
    /// A Volume's Step Size in world space.
    World(f32),
}

/// Per attribute request of a program: the grid it reads, if the domain has one of
/// that name.
pub type GridBinding = [Option<u8>; MAX_ATTRIBUTES];

impl DomainGrids {
    /// The grids with Cycles' clipping applied (copyFromDense with the domain's clipping
    /// as tolerance: values within it of 0 are empty space); None when no voxel is left,
    /// where Cycles builds no volume mesh and the domain renders nothing.
    pub fn new(mut grids: Vec<VoxelGrid>, clipping: f32) -> Option<DomainGrids> {
        let first = grids.first()?;
        let (mut min, mut max) = (first.min, first.max);
        for g in &grids {
            min = vmin(min, g.min);
            max = vmax(max, g.max);
        }
        let mut any = false;
        for g in &mut grids {
            for voxel in g.values.chunks_mut(g.channels) {
                if voxel.iter().all(|v| v.abs() <= clipping) {
                    voxel.fill(0.0);
                } else {
                    any = true;
                }
            }
        }
        any.then_some(DomainGrids {
            grids,
            min,
            max,
            step: GridStep::Voxel,
            density_scale: 1.0,
        })
    }

    /// Cycles' Object::compute_volume_step_size for grids before the step rates: the
    /// Volume's Step Size (in object space through `to_world`, the smallest component
    /// of a step along each axis), or from the voxels.
    pub fn step(&self, to_world: &Affine) -> f32 {
        match self.step {
            GridStep::Voxel => self.voxel_step(to_world),
            GridStep::World(s) => s,
            GridStep::Object(s) => {
                let w = to_world.vector([s; 3]);
                w[0].abs().min(w[1].abs()).min(w[2].abs())
            }
        }
    }

    /// Binds a program's attribute requests to grids by name.
    pub fn bind(&self, requests: &[AttributeRequest]) -> GridBinding {
        let mut b = [None; MAX_ATTRIBUTES];
        for (k, r) in requests.iter().enumerate().take(MAX_ATTRIBUTES) {
            if let AttributeRequest::Named(n) = r {
                b[k] = self
                    .grids
                    .iter()
                    .position(|g| &g.name == n)
                    .map(|i| i as u8);
            }
        }
        b
    }

    /// Cycles' Object::compute_volume_step_size for voxel grids: the smallest component
    /// of one voxel's diagonal in world space, over the grids.
    pub fn voxel_step(&self, to_world: &Affine) -> f32 {
        self.grids
            .iter()
            .map(|g| {
                let d = [0, 1, 2].map(|k| (g.max[k] - g.min[k]) / g.resolution[k] as f32);
                let w = to_world.vector(d);
                w[0].abs().min(w[1].abs()).min(w[2].abs())
            })
            .filter(|s| *s > 0.0)
            .fold(f32::INFINITY, f32::min)
    }

    /// Writes the bound grids' values at object-space point `local` into `sp` as
    /// Cycles' volume attribute lookups give them (x, y, z, alpha 1; the Fac the mean of
    /// x, y, z); requests without a grid are missing.
    pub fn fill(&self, bind: &GridBinding, local: V3, cubic: bool, sp: &mut ShadingPoint) {
        sp.attr_missing = !0;
        for (k, b) in bind.iter().enumerate() {
            let Some(gi) = b else { continue };
            let g = &self.grids[*gi as usize];
            let v = sample(g, index_coords(g, local), cubic);
            sp.attrs[k] = v;
            sp.attr_fac[k] = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
            sp.attr_missing &= !(1 << k);
        }
    }
}

/// Voxel index coordinates of object-space point `p` in grid `g` (0 at its box's minimum).
fn index_coords(g: &VoxelGrid, p: V3) -> V3 {
    [0, 1, 2].map(|k| (p[k] - g.min[k]) / (g.max[k] - g.min[k]) * g.resolution[k] as f32)
}

/// Cycles' object_volume_density for a Volume in Object space: 1 over the length of the
/// object's transform applied to the unit diagonal.
pub fn object_space_density(to_world: &Affine) -> f32 {
    let d = 1.0 / 3f32.sqrt();
    let l = to_world.vector_vec3(Vec3::splat(d)).length();
    if l > 0.0 && l.is_finite() {
        1.0 / l
    } else {
        1.0
    }
}

/// The voxel (i, j, k) of `g` as (x, y, z, 1): a 4-channel (RGBA) grid keeps its RGB, as
/// Cycles 4.5 converts such grids to three channels for NanoVDB; 0 outside the grid.
fn voxel(g: &VoxelGrid, i: i64, j: i64, k: i64) -> [f32; 4] {
    let [nx, ny, nz] = g.resolution.map(|r| r as i64);
    if i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz {
        return [0.0, 0.0, 0.0, 1.0];
    }
    let at = (((k * ny + j) * nx + i) as usize) * g.channels;
    match g.channels {
        1 => {
            let v = g.values[at];
            [v, v, v, 1.0]
        }
        _ => [g.values[at], g.values[at + 1], g.values[at + 2], 1.0],
    }
}

/// Grid `g` at voxel index coordinates `x` (Cycles' kernel_tex_image_interp_nanovdb:
/// trilinear, or tricubic B-spline, around x - 0.5).
pub fn sample(g: &VoxelGrid, x: V3, cubic: bool) -> [f32; 4] {
    let f = x.map(|c| c - 0.5);
    let base = f.map(|c| c.floor());
    let t = [0, 1, 2].map(|k| f[k] - base[k]);
    let b = base.map(|c| c as i64);
    let mut out = [0.0f32; 3];
    if cubic {
        let w = t.map(crate::nodes::point_density::cubic_weights);
        for (dz, wz) in w[2].iter().enumerate() {
            for (dy, wy) in w[1].iter().enumerate() {
                for (dx, wx) in w[0].iter().enumerate() {
                    let v = voxel(
                        g,
                        b[0] + dx as i64 - 1,
                        b[1] + dy as i64 - 1,
                        b[2] + dz as i64 - 1,
                    );
                    let wt = wx * wy * wz;
                    for c in 0..3 {
                        out[c] += wt * v[c];
                    }
                }
            }
        }
    } else {
        for dz in 0..2 {
            let wz = if dz == 0 { 1.0 - t[2] } else { t[2] };
            for dy in 0..2 {
                let wy = if dy == 0 { 1.0 - t[1] } else { t[1] };
                for dx in 0..2 {
                    let wx = if dx == 0 { 1.0 - t[0] } else { t[0] };
                    let v = voxel(g, b[0] + dx, b[1] + dy, b[2] + dz);
                    let wt = wx * wy * wz;
                    for c in 0..3 {
                        out[c] += wt * v[c];
                    }
                }
            }
        }
    }
    [out[0], out[1], out[2], 1.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2x2x2 grid with values 0..8 (x fastest).
    fn grid() -> VoxelGrid {
        VoxelGrid {
            name: "density".into(),
            channels: 1,
            resolution: [2, 2, 2],
            min: [0.0; 3],
            max: [2.0; 3],
            values: (0..8).map(|v| v as f32).collect(),
        }
    }

    #[test]
    fn trilinear_at_centres_between_them_and_outside() {
        let g = grid();
        // Voxel centres give the voxel's value.
        assert_eq!(sample(&g, [0.5, 0.5, 0.5], false)[0], 0.0);
        assert_eq!(sample(&g, [1.5, 0.5, 0.5], false)[0], 1.0);
        assert_eq!(sample(&g, [0.5, 1.5, 0.5], false)[0], 2.0);
        assert_eq!(sample(&g, [1.5, 1.5, 1.5], false)[0], 7.0);
        // Halfway between all eight centres: their mean, 3.5.
        assert!((sample(&g, [1.0, 1.0, 1.0], false)[0] - 3.5).abs() < 1e-6);
        // A quarter of the way from voxel 0 to voxel 1 along x: 0.25.
        assert!((sample(&g, [0.75, 0.5, 0.5], false)[0] - 0.25).abs() < 1e-6);
        // At the box's face, half a voxel from the last centre: half its value (the
        // outside is 0), and nothing a voxel beyond.
        assert!((sample(&g, [2.0, 1.5, 1.5], false)[0] - 3.5).abs() < 1e-6);
        assert_eq!(sample(&g, [3.5, 1.5, 1.5], false)[0], 0.0);
        assert_eq!(sample(&g, [-0.5, 0.5, 0.5], false)[0], 0.0);
    }

    #[test]
    fn cubic_is_cycles_b_spline() {
        // A single voxel of 1 in a 3x3x3 grid: the B-spline at its centre is
        // (2/3)^3, a voxel away along x (1/6)(2/3)^2, and it sums to 1 over the
        // centres of a constant grid's interior.
        let mut g = VoxelGrid {
            name: "density".into(),
            channels: 1,
            resolution: [3, 3, 3],
            min: [0.0; 3],
            max: [3.0; 3],
            values: vec![0.0; 27],
        };
        g.values[13] = 1.0;
        let c = sample(&g, [1.5, 1.5, 1.5], true)[0];
        assert!((c - (2.0f32 / 3.0).powi(3)).abs() < 1e-6, "{c}");
        let n = sample(&g, [2.5, 1.5, 1.5], true)[0];
        assert!(
            (n - (1.0 / 6.0) * (2.0f32 / 3.0).powi(2)).abs() < 1e-6,
            "{n}"
        );
        g.values = vec![2.0; 27];
        let mid = sample(&g, [1.5, 1.5, 1.5], true)[0];
        assert!((mid - 2.0).abs() < 1e-5, "{mid}");
        // Linear at the same point reads the voxel.
        assert_eq!(sample(&g, [1.5, 1.5, 1.5], false)[0], 2.0);
    }

    #[test]
    fn colour_grids_keep_rgb_and_points_map_through_the_box() {
        let g = VoxelGrid {
            name: "color".into(),
            channels: 4,
            resolution: [1, 1, 1],
            min: [-1.0; 3],
            max: [1.0; 3],
            values: vec![0.2, 0.4, 0.6, 0.5],
        };
        let d = DomainGrids::new(vec![g], 1e-6).unwrap();
        let bind = d.bind(&[
            AttributeRequest::Named("density".into()),
            AttributeRequest::Named("color".into()),
        ]);
        assert_eq!(bind[0], None);
        assert_eq!(bind[1], Some(0));
        let mut sp = ShadingPoint::default();
        // The box centre is the voxel's centre.
        d.fill(&bind, [0.0; 3], false, &mut sp);
        assert_eq!(sp.attrs[1], [0.2, 0.4, 0.6, 1.0]);
        assert!((sp.attr_fac[1] - 0.4).abs() < 1e-6);
        assert_eq!(sp.attr_missing & 0b11, 0b01);
        // World step: the smallest component of a voxel's diagonal (2 here, scaled by 0.5
        // along y).
        let to_world = Affine {
            m: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.5, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
        };
        assert_eq!(d.voxel_step(&to_world), 1.0);
    }

    #[test]
    fn clipping_empties_small_values_and_an_empty_domain_is_none() {
        let mut g = grid();
        g.values = vec![1e-7; 8];
        assert!(DomainGrids::new(vec![g.clone()], 1e-6).is_none());
        g.values[3] = 0.5;
        let d = DomainGrids::new(vec![g], 1e-6).unwrap();
        assert_eq!(d.grids[0].values[0], 0.0);
        assert_eq!(d.grids[0].values[3], 0.5);
    }

    #[test]
    fn volume_object_grids_keep_their_own_boxes_steps_and_density_scale() {
        // Two grids over different boxes (a Volume object's grids each cover their own
        // active voxels): each is sampled through its own box, the union is marched.
        let mut a = grid();
        a.values = vec![1.0; 8];
        let mut b = a.clone();
        b.name = "color".into();
        b.min = [10.0; 3];
        b.max = [12.0; 3];
        b.values = vec![2.0; 8];
        let d = DomainGrids::new(vec![a, b], 1e-3).unwrap();
        assert_eq!((d.min, d.max), ([0.0; 3], [12.0; 3]));
        let bind = d.bind(&[
            AttributeRequest::Named("density".into()),
            AttributeRequest::Named("color".into()),
        ]);
        let mut sp = ShadingPoint::default();
        d.fill(&bind, [11.0; 3], false, &mut sp);
        assert_eq!(sp.attrs[0][0], 0.0);
        assert_eq!(sp.attrs[1][0], 2.0);
        d.fill(&bind, [1.0; 3], false, &mut sp);
        assert_eq!((sp.attrs[0][0], sp.attrs[1][0]), (1.0, 0.0));
        // A Step Size in object space goes through the transform (smallest axis); in
        // world space it is as given.
        let to_world = Affine {
            m: [
                [2.0, 0.0, 0.0, 0.0],
                [0.0, 0.5, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
        };
        let mut d = d;
        d.step = GridStep::Object(0.2);
        assert_eq!(d.step(&to_world), 0.1);
        d.step = GridStep::World(0.2);
        assert_eq!(d.step(&to_world), 0.2);
        // Object space's density: 1 / |M (1, 1, 1) / sqrt 3|; a uniform scale of 2 halves it.
        let two = Affine {
            m: [
                [2.0, 0.0, 0.0, 1.0],
                [0.0, 2.0, 0.0, 0.0],
                [0.0, 0.0, 2.0, 0.0],
            ],
        };
        assert!((object_space_density(&two) - 0.5).abs() < 1e-6);
        let expect = 1.0 / ((4.0f32 + 0.25 + 1.0) / 3.0).sqrt();
        assert!((object_space_density(&to_world) - expect).abs() < 1e-6);
    }
}
