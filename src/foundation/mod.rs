//! The foundation every other layer builds on: small vector maths for the hot path,
//! Cycles' ray flags, and the BVH (used by the renderer and by Geometry Nodes' Raycast).
//! Nothing here knows Blender's data.

pub mod bvh;
pub mod bvh4;
pub mod math;
pub mod ray;
