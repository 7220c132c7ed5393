//! What a shader knows about the surface point it shades.

use crate::nodes::math::Vec3;

use super::bump::ObjectTransform;

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
    /// Geometric (flat triangle) normal in world space, facing the incoming ray as Cycles'
    /// sd->Ng does; zero when unknown (then bumps use the shading normal's frame).
    pub ng: Vec3,
    /// Ray differentials of the position (world units per pixel), expanded from Cycles'
    /// compact form around `ng`: the Bump node's dx/dy offsets. Zero: no bump.
    pub dp_dx: Vec3,
    pub dp_dy: Vec3,
    /// Changes of Generated and UV along `dp_dx` / `dp_dy` (the attribute differentials
    /// of Cycles' bump variants of the coordinate nodes).
    pub generated_dx: Vec3,
    pub generated_dy: Vec3,
    pub uv_dx: Vec3,
    pub uv_dy: Vec3,
    /// The object's transform (object-space bump, displacement and normal maps).
    pub transform: ObjectTransform,
    /// The ray hit the back of the surface (normals already flipped toward it).
    pub backfacing: bool,
}
