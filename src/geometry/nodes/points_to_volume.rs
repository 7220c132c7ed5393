//! Points to Volume (`node_geo_points_to_volume.cc` -> `geometry::fog_volume_grid_add_from_points`
//! -> OpenVDB `tools::ParticlesToLevelSet::rasterizeSpheres` and `tools::sdfToFogVolume`):
//! a `density` fog grid of spheres around the points.
//!
//! Blender gathers the positions of the mesh's vertices, the point cloud's points and the
//! curves' control points (in that order), with Radius evaluated on each. The voxel size
//! is Voxel Size, or the positions' bounding box diagonal plus twice the largest radius
//! over Voxel Amount (no volume at an Amount of 1 or less); a size OpenVDB cannot hold, or
//! no points, leaves the geometry as it is. Positions go to index space as
//! `p / size - 0.5` and radii as `r / size` (single precision); the grid's transform is a
//! plain scale by the size.
//!
//! OpenVDB rasterizes each sphere (`makeSphere`, in voxel units, half-width 1): a voxel
//! within the radius minus one becomes an inactive inside voxel (-1) that no later sphere
//! changes; one within the radius plus one otherwise keeps the smallest `|c - P| - R`. The
//! fog divides each negative value by the most negative one (-1 as soon as any voxel is
//! inside a sphere's core, which then reads 1), and Density multiplies every active value.

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, FieldContext};
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::super::volume::{Volume, VolumeGrid, MAX_VOXELS, MIN_DETERMINANT};
use super::geometry_ops::modify_geometry_sets;

pub fn points_to_volume(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mode = ctx.prop_str("resolution_mode")?;
    if mode != "VOXEL_AMOUNT" && mode != "VOXEL_SIZE" {
        return Err(ctx.err(format!(
            "Resolution {mode:?} is not a Points to Volume mode"
        )));
    }
    let density = ctx.float("Density")?;
    // Only the mode's socket is available.
    let (size, amount) = if mode == "VOXEL_SIZE" {
        (ctx.float("Voxel Size")?, 0.0)
    } else {
        (0.0, ctx.float("Voxel Amount")?)
    };
    let radius = ctx.field("Radius", DataType::Float)?;
    let mut g = ctx.geometry("Points")?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let mut positions: Vec<[f32; 3]> = Vec::new();
        let mut radii: Vec<f32> = Vec::new();
        let comps: [(Option<ComponentRef>, &[[f32; 3]]); 3] = [
            (
                s.mesh.as_deref().map(ComponentRef::Mesh),
                s.mesh.as_deref().map_or(&[], |m| &m.positions),
            ),
            (
                s.points.as_deref().map(ComponentRef::Points),
                s.points.as_deref().map_or(&[], |p| &p.positions),
            ),
            (
                s.curves.as_deref().map(ComponentRef::Curves),
                s.curves.as_deref().map_or(&[], |c| &c.positions),
            ),
        ];
        for (comp, pos) in comps {
            let Some(comp) = comp else { continue };
            if pos.is_empty() {
                continue;
            }
            let r = FieldContext::new(comp).eval(&radius, Domain::Point, DataType::Float)?;
            positions.extend_from_slice(pos);
            radii.extend_from_slice(&r.as_float());
        }
        if positions.is_empty() {
            return Ok(());
        }
        let voxel_size = if mode == "VOXEL_SIZE" {
            size
        } else {
            let max_radius = radii.iter().cloned().fold(f32::MIN, f32::max);
            voxel_size_from_amount(amount, &positions, max_radius)
        };
        // `BKE_volume_voxel_size_valid`.
        let det = voxel_size * voxel_size * voxel_size;
        if !((det as f64).abs() >= MIN_DETERMINANT) {
            return Ok(());
        }
        if voxel_size < 0.0 {
            return Err(format!(
                "a negative voxel size ({voxel_size}) mirrors OpenVDB's grid; not evaluated"
            ));
        }
        let grid = fog_grid(&positions, &radii, voxel_size, density)?;
        *s = GeometrySet {
            volume: Some(Arc::new(Volume {
                grids: vec![grid],
                materials: Vec::new(),
            })),
            ..Default::default()
        };
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Volume", SocketValue::Geometry(g))]))
}

/// `compute_voxel_size_from_amount`.
fn voxel_size_from_amount(amount: f32, positions: &[[f32; 3]], max_radius: f32) -> f32 {
    if amount <= 1.0 {
        return 0.0;
    }
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for p in positions {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let d: [f32; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
    let diagonal = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    (diagonal + 2.0 * max_radius) / amount
}

/// The fog grid of the spheres, as OpenVDB rasterizes and converts them.
fn fog_grid(
    positions: &[[f32; 3]],
    radii: &[f32],
    voxel_size: f32,
    density: f32,
) -> Result<VolumeGrid, String> {
    let inv = 1.0f32 / voxel_size;
    // (P, R) in voxel units, particles OpenVDB ignores (R < 0) dropped.
    let spheres: Vec<([f64; 3], f64)> = positions
        .iter()
        .zip(radii)
        .map(|(p, r)| (p.map(|c| (c * inv - 0.5) as f64), (r * inv) as f64))
        .filter(|(_, r)| *r >= 0.0 && *r <= f32::MAX as f64)
        .collect();
    let w = 1.0f64;
    let bounds = |(p, r): &([f64; 3], f64)| -> ([i64; 3], [i64; 3]) {
        let max = r + w;
        (
            p.map(|c| (c - max).floor() as i64),
            p.map(|c| (c + max).ceil() as i64),
        )
    };
    let (mut lo, mut hi) = ([i64::MAX; 3], [i64::MIN; 3]);
    for s in &spheres {
        if s.0.iter().any(|c| !c.is_finite()) || !s.1.is_finite() {
            return Err("a point's position or radius is not finite".into());
        }
        let (a, b) = bounds(s);
        for k in 0..3 {
            lo[k] = lo[k].min(a[k]);
            hi[k] = hi[k].max(b[k]);
        }
    }
    let transform = {
        let mut t = [[0.0f64; 4]; 4];
        for (k, col) in t.iter_mut().enumerate().take(3) {
            col[k] = voxel_size as f64;
        }
        t[3][3] = 1.0;
        t
    };
    if spheres.is_empty() {
        return Ok(VolumeGrid::from_dense_active(
            "density",
            transform,
            0.0,
            [0; 3],
            [0; 3],
            &[],
            &[],
        ));
    }
    let mut total: u64 = 1;
    let mut n = [0usize; 3];
    for k in 0..3 {
        let len = (hi[k] - lo[k] + 1) as u64;
        n[k] = len as usize;
        total = total.saturating_mul(len);
    }
    if total > MAX_VOXELS || lo.iter().chain(&hi).any(|c| c.abs() > i32::MAX as i64 / 2) {
        return Err(format!(
            "the spheres span {total} voxels at this voxel size, more than the limit of one grid ({MAX_VOXELS})"
        ));
    }
    let len = total as usize;
    // The grid's background is 1 (`FloatGrid::create(1.0f)`).
    let mut value = vec![1.0f32; len];
    let mut active = vec![false; len];
    let at = |c: [i64; 3]| -> usize {
        (((c[2] - lo[2]) as usize * n[1]) + (c[1] - lo[1]) as usize) * n[0]
            + (c[0] - lo[0]) as usize
    };
    for s in &spheres {
        let (p, r) = *s;
        let max = r + w;
        let max2 = max * max;
        let min2 = (r - w).max(0.0).powi(2);
        let (a, b) = bounds(s);
        for x in a[0]..=b[0] {
            let x2 = (x as f64 - p[0]).powi(2);
            for y in a[1]..=b[1] {
                let x2y2 = x2 + (y as f64 - p[1]).powi(2);
                for z in a[2]..=b[2] {
                    let d2 = x2y2 + (z as f64 - p[2]).powi(2);
                    let i = at([x, y, z]);
                    // Outside this sphere's band, or in another sphere's core.
                    if d2 >= max2 || (!active[i] && value[i] < 0.0) {
                        continue;
                    }
                    if d2 <= min2 {
                        value[i] = -1.0;
                        active[i] = false;
                        continue;
                    }
                    let d = (d2.sqrt() - r) as f32;
                    if d < value[i] {
                        value[i] = d;
                        active[i] = true;
                    }
                }
            }
        }
    }
    // `sdfToFogVolume`: no negative tile (no flood fill ran), so the cutoff is the
    // smallest voxel value.
    let cutoff = value.iter().cloned().fold(f32::MAX, f32::min);
    let weight = 1.0f32 / cutoff;
    let mut on = vec![false; len];
    for i in 0..len {
        let v = if value[i] > 0.0 {
            0.0
        } else {
            value[i] * weight
        };
        if v > 0.0 {
            value[i] = v * density;
            on[i] = true;
        } else {
            value[i] = 0.0;
        }
    }
    let origin = lo.map(|c| c as i32);
    Ok(VolumeGrid::from_dense_active(
        "density", transform, 0.0, origin, n, &value, &on,
    ))
}
