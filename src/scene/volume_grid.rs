//! Voxel grids as the exporter writes them, for smoke (gas fluid) domains and Volume
//! objects (OpenVDB): per domain or object, the record in scene.json (`SmokeDomain`,
//! `VolumeObject`) and one binary file per grid a material reads (blender_export/FORMAT.md,
//! "Smoke domains", "Volume objects"). Reading a grid checks its header against the file's
//! length before anything is allocated, so a hostile size is an error.

use serde::{Deserialize, Serialize};
use std::path::Path;

use super::{Scene, SceneError};

/// The first bytes of a grid file.
pub const MAGIC: &[u8; 8] = b"BSVGRID1";

/// Bytes before the voxel values: magic, channels and resolution (4 u32), the grid's box
/// in object space (6 f32).
pub const HEADER_BYTES: usize = 8 + 4 * 4 + 6 * 4;

/// Voxels (times channels) in one grid. A 1024^3 smoke simulation has 2^30 voxels and
/// would need 4 GiB per scalar grid; Blender's domains stay far below that.
pub const MAX_GRID_VALUES: usize = 1 << 30;

/// Resolution along one axis (Blender's domain resolution is at most 10000 with noise
/// upres; one axis of a plausible grid is far smaller).
pub const MAX_GRID_AXIS: u32 = 1 << 16;

/// One smoke domain at one exported frame (`convert --frames A..B` writes a record per
/// frame).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SmokeDomain {
    /// The domain object.
    pub object: String,
    /// Its Fluid modifier.
    pub modifier: String,
    /// The frame the grids are of.
    pub frame: f64,
    /// Whether the frame is within the cache's frame range (Cycles renders the domain
    /// empty outside it).
    pub in_cache_range: bool,
    /// Fluid > Cache > Clipping: values at or below it are empty space.
    #[serde(default)]
    pub clipping: f32,
    /// The grids the domain's materials read that Blender gave at the frame.
    #[serde(default)]
    pub grids: Vec<GridRef>,
    /// Grids the materials read that Blender did not give (not baked at the frame, ...),
    /// with the reason: Cycles renders them as absent.
    #[serde(default)]
    pub unread: Vec<(String, String)>,
}

/// One Volume object (OpenVDB grids) at one exported frame (`convert --frames A..B` writes
/// a record per frame for grids that change): its evaluated Volume's grids that its
/// materials read, each dense over its active voxels, and the Volume's render settings.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct VolumeObject {
    /// The object.
    pub object: String,
    /// Its Volume data.
    pub volume: String,
    /// The frame the grids are of.
    pub frame: f64,
    /// The grids are the same at every frame (one .vdb file, not a sequence, no modifier,
    /// no animation on the Volume), so this record holds at any frame. False in exports
    /// older than the field.
    #[serde(default)]
    pub every_frame: bool,
    /// The Volume's material slots.
    #[serde(default)]
    pub materials: Vec<Option<String>>,
    /// Volume > Render > Space: "OBJECT" (density and step size scale with the object)
    /// or "WORLD".
    pub space: String,
    /// Volume > Render > Step Size (0: from the voxel size).
    pub step_size: f32,
    /// Volume > Render > Clipping: values at or below it are empty space.
    pub clipping: f32,
    /// Volume > Render > Precision (Cycles' NanoVDB encoding: FULL, HALF, VARIABLE).
    #[serde(default)]
    pub precision: String,
    /// The velocity grid (Volume > Attributes > Velocity Grid) if the Volume has it.
    #[serde(default)]
    pub velocity_grid: Option<String>,
    /// Volume > Attributes > Velocity Scale.
    #[serde(default)]
    pub velocity_scale: f32,
    /// The grids the materials read that were written.
    #[serde(default)]
    pub grids: Vec<GridRef>,
    /// Grids the materials read that were not written, with the reason (a value type or
    /// transform not handled, ...): blendsynth refuses the object.
    #[serde(default)]
    pub unread: Vec<(String, String)>,
    /// Why no grid could be read at all (the OpenVDB module missing, ...): refused.
    #[serde(default)]
    pub error: Option<String>,
}

/// A grid file and the attribute name materials read it by.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GridRef {
    pub name: String,
    pub file: String,
}

/// A dense voxel grid: values at cell centres over an object-space box, x fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelGrid {
    pub name: String,
    pub channels: usize,
    pub resolution: [usize; 3],
    /// The box the cells tile, object space: cell (i, j, k) is centred at
    /// `min + (i + 0.5, j + 0.5, k + 0.5) * (max - min) / resolution`.
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// `channels` values per voxel, index `((k * ny + j) * nx + i) * channels + c`.
    pub values: Vec<f32>,
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Parses a grid file's bytes; the error names what is wrong.
pub fn parse_grid(name: &str, b: &[u8]) -> Result<VoxelGrid, String> {
    if b.len() < HEADER_BYTES || &b[..8] != MAGIC {
        return Err("is not a blendsynth voxel grid (bad header)".into());
    }
    let channels = u32_at(b, 8);
    if !matches!(channels, 1 | 3 | 4) {
        return Err(format!("has {channels} channels (1, 3 or 4 expected)"));
    }
    let res = [u32_at(b, 12), u32_at(b, 16), u32_at(b, 20)];
    if res.iter().any(|&r| r == 0 || r > MAX_GRID_AXIS) {
        return Err(format!(
            "has resolution {res:?} (each axis 1..={MAX_GRID_AXIS})"
        ));
    }
    let values = res
        .iter()
        .try_fold(channels as usize, |n, &r| n.checked_mul(r as usize))
        .filter(|&n| n <= MAX_GRID_VALUES)
        .ok_or_else(|| {
            format!(
                "has resolution {res:?} x {channels} channels, more than {MAX_GRID_VALUES} values"
            )
        })?;
    let expect = super::limits::mul_add(values, 4, HEADER_BYTES)
        .ok_or_else(|| "declares a size that overflows".to_string())?;
    if b.len() != expect {
        return Err(format!(
            "is {} bytes, but its header declares {expect} (resolution {res:?}, {channels} channels)",
            b.len()
        ));
    }
    let min = [0, 1, 2].map(|k| f32_at(b, 24 + 4 * k));
    let max = [0, 1, 2].map(|k| f32_at(b, 36 + 4 * k));
    if (0..3).any(|k| !(min[k].is_finite() && max[k].is_finite() && min[k] < max[k])) {
        return Err(format!("has an empty or non-finite box {min:?}..{max:?}"));
    }
    let mut out = Vec::with_capacity(values);
    for i in 0..values {
        let v = f32_at(b, HEADER_BYTES + 4 * i);
        if !v.is_finite() {
            return Err(format!("holds a non-finite value at index {i}"));
        }
        out.push(v);
    }
    Ok(VoxelGrid {
        name: name.to_string(),
        channels: channels as usize,
        resolution: res.map(|r| r as usize),
        min,
        max,
        values: out,
    })
}

/// Serialises a grid in the exporter's format (tests and tools write fixtures with it).
pub fn grid_bytes(g: &VoxelGrid) -> Vec<u8> {
    let mut b = Vec::with_capacity(HEADER_BYTES + 4 * g.values.len());
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&(g.channels as u32).to_le_bytes());
    for r in g.resolution {
        b.extend_from_slice(&(r as u32).to_le_bytes());
    }
    for v in g.min.iter().chain(g.max.iter()).chain(g.values.iter()) {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

impl Scene {
    /// Whether the export has a smoke domain record of object `name` (at any frame).
    pub fn is_smoke_domain(&self, name: &str) -> bool {
        self.file.smoke_domains.iter().any(|d| d.object == name)
    }

    /// The smoke domain record of object `name` at `frame`, else its first record (whose
    /// frame the caller's error then names); none when the export has no record of it.
    pub fn smoke_domain(&self, name: &str, frame: f64) -> Option<(usize, &SmokeDomain)> {
        record_at(
            &self.file.smoke_domains,
            |d| d.object == name,
            |d| d.frame == frame,
        )
    }

    /// The Volume object record of object `name` at `frame` (or one valid at every
    /// frame), else its first record (whose frame the caller's error then names); none
    /// when the export has no record of it.
    pub fn volume_object(&self, name: &str, frame: f64) -> Option<(usize, &VolumeObject)> {
        record_at(
            &self.file.volume_objects,
            |v| v.object == name,
            |v| v.frame == frame || v.every_frame,
        )
    }

    /// The frames the export holds grids of for object `name` (smoke or Volume), sorted.
    pub fn grid_frames(&self, name: &str) -> Vec<f64> {
        let f = &self.file;
        let mut frames: Vec<f64> = (f.smoke_domains.iter().filter(|d| d.object == name))
            .map(|d| d.frame)
            .chain((f.volume_objects.iter().filter(|v| v.object == name)).map(|v| v.frame))
            .collect();
        frames.sort_by(f64::total_cmp);
        frames.dedup();
        frames
    }

    /// Reads every grid of smoke domain `index`.
    pub fn load_smoke_grids(&self, index: usize) -> Result<Vec<VoxelGrid>, SceneError> {
        let d = &self.file.smoke_domains[index];
        self.load_grids(&d.grids, &format!("smoke_domains[{index}]"))
    }

    /// Reads every grid of Volume object record `index`.
    pub fn load_volume_grids(&self, index: usize) -> Result<Vec<VoxelGrid>, SceneError> {
        let v = &self.file.volume_objects[index];
        self.load_grids(&v.grids, &format!("volume_objects[{index}]"))
    }

    fn load_grids(&self, refs: &[GridRef], owner: &str) -> Result<Vec<VoxelGrid>, SceneError> {
        let mut out = Vec::with_capacity(refs.len());
        for (g, r) in refs.iter().enumerate() {
            let location = format!("{owner}.grids[{g}].file");
            let path = self.resolve(&r.file, &location)?;
            out.push(read_grid(&r.name, &path)?);
        }
        Ok(out)
    }
}

/// Reads one grid file.
pub fn read_grid(name: &str, path: &Path) -> Result<VoxelGrid, SceneError> {
    let limit = (HEADER_BYTES + 4 * MAX_GRID_VALUES) as u64;
    let bytes = super::file::read_regular(path, limit).map_err(|m| SceneError::new(path, "", m))?;
    parse_grid(name, &bytes).map_err(|m| SceneError::new(path, "", format!("grid {name:?} {m}")))
}

/// Of the records that are `mine`, the first one valid `at` the frame, else the first
/// (whose frame the caller's error then names); none when there is no record.
fn record_at<T>(
    records: &[T],
    mine: impl Fn(&T) -> bool,
    at: impl Fn(&T) -> bool,
) -> Option<(usize, &T)> {
    let mut of = records.iter().enumerate().filter(|(_, r)| mine(r));
    let first = of.next()?;
    Some(
        std::iter::once(first)
            .chain(of)
            .find(|(_, r)| at(r))
            .unwrap_or(first),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> VoxelGrid {
        VoxelGrid {
            name: "density".into(),
            channels: 1,
            resolution: [2, 3, 1],
            min: [-1.0; 3],
            max: [1.0; 3],
            values: vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0],
        }
    }

    #[test]
    fn round_trips_and_refuses_hostile_headers() {
        let b = grid_bytes(&grid());
        assert_eq!(parse_grid("density", &b).unwrap(), grid());
        // A header declaring more voxels than the file holds: an error, no allocation.
        let mut big = b.clone();
        big[12..16].copy_from_slice(&60000u32.to_le_bytes());
        big[16..20].copy_from_slice(&60000u32.to_le_bytes());
        let e = parse_grid("density", &big).unwrap_err();
        assert!(e.contains("more than"), "{e}");
        let mut short = b.clone();
        short.pop();
        assert!(parse_grid("density", &short).unwrap_err().contains("bytes"));
        let mut zero = b.clone();
        zero[12..16].copy_from_slice(&0u32.to_le_bytes());
        assert!(parse_grid("density", &zero)
            .unwrap_err()
            .contains("resolution"));
        let mut nan = b.clone();
        let at = HEADER_BYTES + 4;
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(parse_grid("density", &nan)
            .unwrap_err()
            .contains("non-finite"));
        let mut flat = b;
        flat[36..40].copy_from_slice(&(-1.0f32).to_le_bytes());
        assert!(parse_grid("density", &flat).unwrap_err().contains("box"));
    }
}
