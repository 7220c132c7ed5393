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

/// Element `i` of an instance attribute as RGBA, as Blender's implicit conversion to a
/// colour does (a number n is (n, n, n, 1); 2D and 3D vectors get z 0 and alpha 1), for
/// Instancer Attribute nodes. None for matrices and out-of-range indices.
pub fn instance_rgba(data: &crate::geometry::types::Array, i: usize) -> Option<[f32; 4]> {
    use crate::geometry::types::Array;
    let num = |x: f32| [x, x, x, 1.0];
    Some(match data {
        Array::Float(v) => num(*v.get(i)?),
        Array::Int(v) => num(*v.get(i)? as f32),
        Array::Int8(v) => num(*v.get(i)? as f32),
        Array::Bool(v) => num(if *v.get(i)? { 1.0 } else { 0.0 }),
        Array::Float2(v) => {
            let p = v.get(i)?;
            [p[0], p[1], 0.0, 1.0]
        }
        Array::Int2(v) => {
            let p = v.get(i)?;
            [p[0] as f32, p[1] as f32, 0.0, 1.0]
        }
        Array::Vector(v) => {
            let p = v.get(i)?;
            [p[0], p[1], p[2], 1.0]
        }
        Array::Color(v) | Array::ByteColor(v) | Array::Quaternion(v) => *v.get(i)?,
        Array::Matrix(_) => return None,
    })
}
