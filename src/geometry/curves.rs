//! The curves component: points grouped into curves by offsets, with Blender's built-in
//! curve attributes kept as ordinary attributes under their Blender names (`curve_type`,
//! `cyclic`, `resolution`, `handle_left`, `handle_right`, `radius`, `tilt`,
//! `nurbs_weight`, `nurbs_order`, ...) on the POINT or CURVE domain.
//!
//! No curve node is evaluated yet; the type exists so geometry sets can carry curves
//! through joins, transforms and instancing without losing them.

use super::attribute::Attributes;
use super::math::V3;
use super::types::Domain;

/// Blender's `CurveType` values as stored in the `curve_type` attribute.
pub const CURVE_TYPE_CATMULL_ROM: i8 = 0;
pub const CURVE_TYPE_POLY: i8 = 1;
pub const CURVE_TYPE_BEZIER: i8 = 2;
pub const CURVE_TYPE_NURBS: i8 = 3;

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curves {
    pub positions: Vec<V3>,
    /// `curve_count + 1` entries, starting at 0.
    pub curve_offsets: Vec<u32>,
    pub attributes: Attributes,
    pub materials: Vec<Option<String>>,
}

impl Curves {
    pub fn point_count(&self) -> usize {
        self.positions.len()
    }
    pub fn curve_count(&self) -> usize {
        self.curve_offsets.len().saturating_sub(1)
    }
    pub fn domain_size(&self, d: Domain) -> usize {
        match d {
            Domain::Point => self.point_count(),
            Domain::Curve => self.curve_count(),
            _ => 0,
        }
    }
    pub fn points(&self, c: usize) -> std::ops::Range<usize> {
        self.curve_offsets[c] as usize..self.curve_offsets[c + 1] as usize
    }
}
