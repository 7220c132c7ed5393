//! The point cloud component: positions and POINT attributes (`radius` among them).

use super::attribute::Attributes;
use super::math::V3;
use super::types::Domain;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    pub positions: Vec<V3>,
    pub attributes: Attributes,
    pub materials: Vec<Option<String>>,
}

impl PointCloud {
    pub fn len(&self) -> usize {
        self.positions.len()
    }
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }
    pub fn domain_size(&self, d: Domain) -> usize {
        match d {
            Domain::Point => self.len(),
            _ => 0,
        }
    }
}
