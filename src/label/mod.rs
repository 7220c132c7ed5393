//! Labels from the instance pass: per-instance masks and boxes, semantic masks, COCO
//! and YOLO records, camera intrinsics and pose, per-instance 3D measurements.
//!
//! Input is plain data (`FrameIds`) mirroring the renderer's `Passes` (CONTRACT.md), so
//! labelling needs no renderer: `FrameIds::from` the render output is all the wiring.
//!
//! One idea per file: `classes` (which object is which class), `instances` (masks,
//! boxes, the drop rule), `rle` (COCO's compressed RLE), `camera` (intrinsics, pose),
//! `coco` and `yolo` (file formats), `record` (the per-frame JSON), `passes` (a render's
//! label passes as image files), `trajectory` (a sequence's poses as TUM and COLMAP text).

pub mod camera;
pub mod classes;
pub mod coco;
pub mod instances;
pub mod passes;
pub mod record;
pub mod rle;
pub mod trajectory;
pub mod yolo;

pub use classes::{ClassMap, ClassSpec, FloatFormat, LabelSpec, MeshGlb};
pub use instances::{extract, InstanceLabel};

/// One rendered instance, as the renderer's `InstanceInfo` describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// Blender object name.
    pub object: String,
    /// Index within a Geometry Nodes instance set, if any.
    pub instance_index: Option<u32>,
    /// World-space axis-aligned bounds (min, max).
    pub world_bounds: ([f32; 3], [f32; 3]),
    pub world_transform: [[f32; 4]; 4],
}

/// The label passes of one frame: what labelling needs from a render.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameIds {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first: 0 = background, else 1 + index into `instances`.
    pub instance_id: Vec<u32>,
    /// Camera-space Z distance per pixel (infinity for background), when rendered.
    pub depth: Option<Vec<f32>>,
    /// World-space shading normal of the first hit, when rendered.
    pub normal: Option<Vec<[f32; 3]>>,
    pub instances: Vec<Instance>,
    /// The view layer's shader AOV passes as float channels named as Blender's
    /// multilayer EXR names them (`passes::aov_channels`); empty without AOVs.
    pub aov_channels: Vec<(String, Vec<f32>)>,
}

impl FrameIds {
    /// Checks buffer sizes and that every id names an instance.
    pub fn check(&self) -> Result<(), String> {
        let n = self.width as usize * self.height as usize;
        if self.instance_id.len() != n {
            return Err(format!(
                "instance_id has {} pixels, expected {}x{} = {n}",
                self.instance_id.len(),
                self.width,
                self.height
            ));
        }
        if let Some(d) = &self.depth {
            if d.len() != n {
                return Err(format!("depth has {} pixels, expected {n}", d.len()));
            }
        }
        if let Some(d) = &self.normal {
            if d.len() != n {
                return Err(format!("normal has {} pixels, expected {n}", d.len()));
            }
        }
        if let Some(bad) = self
            .instance_id
            .iter()
            .find(|&&id| id as usize > self.instances.len())
        {
            return Err(format!(
                "instance id {bad} but only {} instances",
                self.instances.len()
            ));
        }
        Ok(())
    }
}
