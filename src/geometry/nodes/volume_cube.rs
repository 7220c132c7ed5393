//! Volume Cube (`node_geo_volume_cube.cc`): a `density` fog grid of Resolution X x Y x Z
//! voxels whose Density field is evaluated at points spread evenly from Min to Max (the
//! first and last voxel at the bounds), in Blender's Grid3DFieldContext, where only
//! Position is given. OpenVDB's `copyFromDense` (tolerance 0) keeps the voxels that differ
//! from Background active; the grid's index-to-object transform is
//! `(ijk - 0.5) * (Max - Min) / (Resolution - 1) + Min`, so a voxel's value was evaluated
//! half a voxel from its centre, as in Blender.

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::FieldContext;
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::super::volume::{Volume, VolumeGrid, MAX_VOXELS, MIN_DETERMINANT};

/// Blender's `map` in float: x from [0, n - 1] to [lo, hi], in its operation order.
fn map(x: usize, n: usize, lo: f32, hi: f32) -> f32 {
    (x as f32 - 0.0) * (hi - lo) / ((n - 1) as f32 - 0.0) + lo
}

pub fn volume_cube(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let min = ctx.vector("Min")?;
    let max = ctx.vector("Max")?;
    let res = [
        ctx.int("Resolution X")?,
        ctx.int("Resolution Y")?,
        ctx.int("Resolution Z")?,
    ];
    let empty = || {
        Ok(outputs([(
            "Volume",
            SocketValue::Geometry(GeometrySet::default()),
        )]))
    };
    // Blender's node errors ("Resolution must be greater than 1", "Bounding box volume
    // must be greater than 0", "Volume scale is lower than permitted by OpenVDB") leave
    // the output empty.
    if res.iter().any(|&r| r < 2) || (0..3).any(|k| min[k] == max[k]) {
        return empty();
    }
    let n = res.map(|r| r as usize);
    let scale: [f64; 3] = [0, 1, 2].map(|k| (max[k] - min[k]) as f64 / (res[k] - 1) as f64);
    if (scale[0] * scale[1] * scale[2]).abs() < MIN_DETERMINANT {
        return empty();
    }
    let total = super::super::limits::product(&n.map(|r| r as u64)).filter(|t| *t <= MAX_VOXELS);
    let Some(total) = total else {
        return Err(ctx.err(format!(
            "Resolution {} x {} x {} makes more than {MAX_VOXELS} voxels, the limit of one grid",
            res[0], res[1], res[2]
        )));
    };
    let density = ctx.field("Density", DataType::Float)?;
    let background = ctx.float("Background")?;
    // Blender's dense buffer is z fastest (LayoutZYX), which is also the field's index
    // order.
    let mut positions = Vec::with_capacity(total as usize);
    for x in 0..n[0] {
        let px = map(x, n[0], min[0], max[0]);
        for y in 0..n[1] {
            let py = map(y, n[1], min[1], max[1]);
            for z in 0..n[2] {
                positions.push([px, py, map(z, n[2], min[2], max[2])]);
            }
        }
    }
    let points = PointCloud {
        positions,
        ..Default::default()
    };
    let fc = FieldContext::position_only(&points);
    let zyx = fc
        .eval(&density, Domain::Point, DataType::Float)
        .map_err(|e| ctx.err(e))?;
    let zyx = zyx.as_float();
    // To x fastest.
    let mut xyz = vec![0.0f32; zyx.len()];
    for x in 0..n[0] {
        for y in 0..n[1] {
            for z in 0..n[2] {
                xyz[(z * n[1] + y) * n[0] + x] = zyx[(x * n[1] + y) * n[2] + z];
            }
        }
    }
    // preTranslate(-0.5), postScale(scale), postTranslate(Min): index ijk lands at
    // (ijk - 0.5) * scale + Min.
    let mut t = [[0.0f64; 4]; 4];
    for k in 0..3 {
        t[k][k] = scale[k];
        t[3][k] = -0.5 * scale[k] + min[k] as f64;
    }
    t[3][3] = 1.0;
    let grid = VolumeGrid::from_dense("density", t, background, n, &xyz);
    Ok(outputs([(
        "Volume",
        SocketValue::Geometry(GeometrySet {
            volume: Some(Arc::new(Volume {
                grids: vec![grid],
                materials: Vec::new(),
            })),
            ..Default::default()
        }),
    )]))
}
