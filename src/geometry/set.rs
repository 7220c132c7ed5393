//! A geometry set: at most one component of each type, as Blender's `GeometrySet`.
//! Components are shared (`Arc`) and copied on write, so passing geometry along links is
//! cheap.

use std::sync::Arc;

use super::curves::Curves;
use super::instances::Instances;
use super::mesh::Mesh;
use super::pointcloud::PointCloud;
use super::volume::Volume;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct GeometrySet {
    pub mesh: Option<Arc<Mesh>>,
    pub curves: Option<Arc<Curves>>,
    pub points: Option<Arc<PointCloud>>,
    pub instances: Option<Arc<Instances>>,
    /// Fog grids (`volume`): not an attribute component, so not in `component_types`.
    pub volume: Option<Arc<Volume>>,
}

/// Component types in Blender's order (`GeometryComponent::Type`), which is the order
/// realizing and exporting walk them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ComponentType {
    Mesh,
    PointCloud,
    Instances,
    Curves,
}

impl GeometrySet {
    pub fn from_mesh(m: Mesh) -> GeometrySet {
        GeometrySet {
            mesh: Some(Arc::new(m)),
            ..Default::default()
        }
    }
    pub fn from_points(p: PointCloud) -> GeometrySet {
        GeometrySet {
            points: Some(Arc::new(p)),
            ..Default::default()
        }
    }
    pub fn from_instances(i: Instances) -> GeometrySet {
        GeometrySet {
            instances: Some(Arc::new(i)),
            ..Default::default()
        }
    }
    pub fn is_empty(&self) -> bool {
        self.mesh.is_none()
            && self.curves.is_none()
            && self.points.is_none()
            && self.instances.is_none()
            && self.volume.is_none()
    }
    pub fn mesh_mut(&mut self) -> Option<&mut Mesh> {
        self.mesh.as_mut().map(Arc::make_mut)
    }
    pub fn points_mut(&mut self) -> Option<&mut PointCloud> {
        self.points.as_mut().map(Arc::make_mut)
    }
    pub fn curves_mut(&mut self) -> Option<&mut Curves> {
        self.curves.as_mut().map(Arc::make_mut)
    }
    pub fn instances_mut(&mut self) -> Option<&mut Instances> {
        self.instances.as_mut().map(Arc::make_mut)
    }
    pub fn volume_mut(&mut self) -> Option<&mut Volume> {
        self.volume.as_mut().map(Arc::make_mut)
    }
    /// Present attribute components, in Blender's order (a volume has no attributes).
    pub fn component_types(&self) -> Vec<ComponentType> {
        let mut out = Vec::new();
        if self.mesh.is_some() {
            out.push(ComponentType::Mesh);
        }
        if self.points.is_some() {
            out.push(ComponentType::PointCloud);
        }
        if self.instances.is_some() {
            out.push(ComponentType::Instances);
        }
        if self.curves.is_some() {
            out.push(ComponentType::Curves);
        }
        out
    }
    /// Drops empty components (Blender's nodes leave no empty mesh behind in most cases).
    pub fn remove_empty(&mut self) {
        if self.mesh.as_ref().is_some_and(|m| m.vertex_count() == 0) {
            self.mesh = None;
        }
        if self.points.as_ref().is_some_and(|p| p.is_empty()) {
            self.points = None;
        }
        if self.curves.as_ref().is_some_and(|c| c.point_count() == 0) {
            self.curves = None;
        }
        if self.instances.as_ref().is_some_and(|i| i.is_empty()) {
            self.instances = None;
        }
        if self.volume.as_ref().is_some_and(|v| v.is_empty()) {
            self.volume = None;
        }
    }
}
