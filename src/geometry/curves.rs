//! The curves component: points grouped into curves by offsets, with Blender's built-in
//! curve attributes kept as ordinary attributes under their Blender names (`curve_type`,
//! `cyclic`, `resolution`, `handle_left`, `handle_right`, `radius`, `tilt`,
//! `nurbs_weight`, `nurbs_order`, ...) on the POINT or CURVE domain.
//!
//! The typed accessors below read a built-in with Blender's default where it is absent
//! and write it back under its built-in type, so the curve nodes agree on both.

use super::attribute::{AttrId, Attributes};
use super::math::{transform_normals, Mat4f, V3};
use super::types::{Array, Domain};

/// Blender's `CurveType` values as stored in the `curve_type` attribute.
pub const CURVE_TYPE_CATMULL_ROM: i8 = 0;
pub const CURVE_TYPE_POLY: i8 = 1;
pub const CURVE_TYPE_BEZIER: i8 = 2;
pub const CURVE_TYPE_NURBS: i8 = 3;

/// Blender's `HandleType` values as stored in `handle_type_left` / `handle_type_right`.
pub const HANDLE_FREE: i8 = 0;
pub const HANDLE_AUTO: i8 = 1;
pub const HANDLE_VECTOR: i8 = 2;
pub const HANDLE_ALIGN: i8 = 3;

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

impl Curves {
    /// An integer built-in (`curve_type`, `resolution`, handle types, ...) on `domain`, or
    /// `default` everywhere when absent.
    pub fn ints(&self, name: &str, domain: Domain, default: i32) -> Vec<i32> {
        match self.attributes.named(name) {
            Some(a) if a.domain == domain => a.data.as_int().into_owned(),
            _ => vec![default; self.domain_size(domain)],
        }
    }
    /// A float point built-in (`radius`, `tilt`, `nurbs_weight`), `default` when absent.
    pub fn point_floats(&self, name: &str, default: f32) -> Vec<f32> {
        match self.attributes.named(name) {
            Some(a) if a.domain == Domain::Point => a.data.as_float().into_owned(),
            _ => vec![default; self.point_count()],
        }
    }
    /// A vector point built-in (`handle_left`, `handle_right`), or `None` when absent.
    pub fn point_vectors(&self, name: &str) -> Option<Vec<V3>> {
        match self.attributes.named(name) {
            Some(a) if a.domain == Domain::Point => Some(a.data.as_vector().into_owned()),
            _ => None,
        }
    }
    pub fn cyclic(&self) -> Vec<bool> {
        match self.attributes.named("cyclic") {
            Some(a) if a.domain == Domain::Curve => a.data.as_bool().into_owned(),
            _ => vec![false; self.curve_count()],
        }
    }
    /// Writes an 8-bit built-in (`curve_type`, `normal_mode`, handle types).
    pub fn set_i8(&mut self, name: &str, domain: Domain, v: Vec<i8>) {
        self.attributes
            .set(AttrId::named(name), domain, Array::Int8(v));
    }
    /// Sets an 8-bit built-in to `value` on the selected elements, keeping the others'
    /// (their stored value, or `default` where it is absent).
    pub fn set_i8_selected(
        &mut self,
        name: &str,
        domain: Domain,
        default: i32,
        sel: &[bool],
        value: i8,
    ) {
        let mut v: Vec<i8> = self
            .ints(name, domain, default)
            .iter()
            .map(|v| *v as i8)
            .collect();
        for (x, s) in v.iter_mut().zip(sel) {
            if *s {
                *x = value;
            }
        }
        self.set_i8(name, domain, v);
    }
    /// The curve of every point.
    pub fn point_to_curve(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.point_count());
        for c in 0..self.curve_count() {
            out.extend(self.points(c).map(|_| c));
        }
        out
    }
}

impl Curves {
    /// Moves the `custom_normal` point attribute (Free normals) as positions move by `m`,
    /// as `transform_custom_normal_attribute`: by the inverse transpose of the 3x3 part,
    /// normalized.
    pub fn transform_custom_normals(&mut self, m: &Mat4f) {
        let Some(a) = self.attributes.get_mut(&AttrId::named("custom_normal")) else {
            return;
        };
        if let Array::Vector(v) = &mut a.data {
            transform_normals(m, v);
        }
    }
}
