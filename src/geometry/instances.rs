//! The instances component: references to geometry (or objects), each instance a
//! reference handle plus a 4x4 transform, with INSTANCE-domain attributes.

use super::attribute::Attributes;
use super::math::Mat4f;
use super::set::GeometrySet;
use super::types::Domain;

#[derive(Debug, Clone, PartialEq)]
pub enum InstanceReference {
    /// A geometry set (Instance on Points with a geometry input).
    Geometry(GeometrySet),
    /// An object, already evaluated (Object Info "As Instance"): name for messages.
    Object(String, GeometrySet),
    /// An empty reference.
    None,
}

impl InstanceReference {
    pub fn geometry(&self) -> Option<&GeometrySet> {
        match self {
            InstanceReference::Geometry(g) | InstanceReference::Object(_, g) => Some(g),
            InstanceReference::None => None,
        }
    }
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Instances {
    pub references: Vec<InstanceReference>,
    /// Per instance: index into `references`.
    pub handles: Vec<u32>,
    pub transforms: Vec<Mat4f>,
    pub attributes: Attributes,
}

impl Instances {
    pub fn len(&self) -> usize {
        self.transforms.len()
    }
    pub fn is_empty(&self) -> bool {
        self.transforms.is_empty()
    }
    pub fn domain_size(&self, d: Domain) -> usize {
        match d {
            Domain::Instance => self.len(),
            _ => 0,
        }
    }
    /// Adds a reference and returns its handle.
    pub fn add_reference(&mut self, r: InstanceReference) -> u32 {
        self.references.push(r);
        (self.references.len() - 1) as u32
    }
}
