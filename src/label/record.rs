//! The per-frame record: one JSON object per frame with everything needed to use or
//! regenerate it (written as `frames/NNNNNNNNN.json`, merged into `frames.jsonl`).

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::camera::CameraInfo;
use super::{FrameIds, InstanceLabel};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Annotation {
    pub object: String,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub instance_index: Option<u32>,
    pub class: String,
    /// COCO category id (class index + 1).
    pub category_id: u32,
    /// [x, y, w, h] of the visible pixels.
    pub bbox: [u32; 4],
    /// Visible pixels.
    pub area: u64,
    /// pycocotools compressed RLE (column-major), for classes with masks.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub rle: Option<String>,
    /// The instance's true 3D size in scene units and millimetres: its mesh's bounds
    /// along the object's own axes, times the object's world scale (for Geometry
    /// Nodes instances, whose mesh the scene does not hold, the world-space bounds).
    pub size: [f64; 3],
    pub size_mm: [f64; 3],
    /// The largest of the three, in millimetres (a polyp's size as reported clinically).
    pub largest_mm: f64,
    /// Distance from the camera to the centre of the instance's bounds.
    pub distance: f64,
    pub distance_mm: f64,
    /// Nearest visible depth (camera-space Z), when depth was rendered.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub nearest_depth: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameRecord {
    /// Dataset frame index (0-based); COCO image id is index + 1.
    pub index: u64,
    pub split: String,
    /// Image path relative to the dataset folder.
    pub image: String,
    pub width: u32,
    pub height: u32,
    /// Scene frame rendered.
    pub frame: i64,
    /// Dataset seed, and the render seed derived from it for this frame.
    pub seed: u64,
    pub render_seed: u32,
    /// Every randomised parameter: value applied, and the drawn value (differs for offsets).
    pub values: serde_json::Map<String, Value>,
    pub drawn: serde_json::Map<String, Value>,
    pub camera: CameraInfo,
    pub annotations: Vec<Annotation>,
    /// With `[sequence]`: the sequence (0-based), the frame's place in it, and its time
    /// in seconds (scene frame / the scene's frame rate).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub sequence: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub sequence_frame: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub time: Option<f64>,
}

/// Axis-aligned bounds (min, max).
pub type Bounds = ([f64; 3], [f64; 3]);

/// Annotations of one frame from its labels. `local_bounds` gives an object's mesh
/// bounds in its own space (None when unknown).
pub fn annotations(
    ids: &FrameIds,
    labels: &[InstanceLabel],
    class_names: &[String],
    camera: &CameraInfo,
    mm_per_unit: f64,
    local_bounds: &dyn Fn(&str) -> Option<Bounds>,
) -> Vec<Annotation> {
    labels
        .iter()
        .map(|l| {
            let inst = &ids.instances[l.instance];
            let (lo, hi) = inst.world_bounds;
            let m = &inst.world_transform;
            let axis_len =
                |c: usize| ((0..3).map(|r| (m[r][c] as f64).powi(2)).sum::<f64>()).sqrt();
            let size = match (inst.instance_index, local_bounds(&inst.object)) {
                (None, Some((llo, lhi))) => [0, 1, 2].map(|k| (lhi[k] - llo[k]) * axis_len(k)),
                _ => [0, 1, 2].map(|k| (hi[k] - lo[k]) as f64),
            };
            let centre = [0, 1, 2].map(|k| (hi[k] as f64 + lo[k] as f64) / 2.0);
            let distance = (0..3)
                .map(|k| (centre[k] - camera.location[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            Annotation {
                object: inst.object.clone(),
                instance_index: inst.instance_index,
                class: class_names[l.class].clone(),
                category_id: l.class as u32 + 1,
                bbox: l.bbox,
                area: l.area,
                rle: l.rle.as_deref().map(super::rle::to_string),
                size,
                size_mm: size.map(|s| s * mm_per_unit),
                largest_mm: size.iter().cloned().fold(0.0, f64::max) * mm_per_unit,
                distance,
                distance_mm: distance * mm_per_unit,
                nearest_depth: l.nearest_depth.map(|d| d as f64),
            }
        })
        .collect()
}
