//! What a shader knows about the surface point it shades.

use crate::nodes::math::Vec3;

/// A shading point, in the spaces Cycles' texture-coordinate nodes read.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ShadingPoint {
    /// World-space position and shading normal.
    pub position: Vec3,
    pub normal: Vec3,
    /// Object-space position (Texture Coordinate > Object) and normal (> Normal).
    pub object_position: Vec3,
    pub object_normal: Vec3,
    /// Position in the mesh's texture space, 0..1 over its bounds (> Generated).
    pub generated: Vec3,
    /// The active render UV map, with w = 0 (> UV).
    pub uv: Vec3,
}
