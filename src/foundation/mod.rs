//! The foundation every other layer builds on: small vector maths for the hot path,
//! Cycles' ray flags, the one box tree and the triangle BVH on it (used by the renderer
//! and by Geometry Nodes), EXR encoding and the one atomic file writer.
//! Nothing here knows Blender's data.

pub mod box_tree;
pub mod bvh;
pub mod bvh4;
pub mod embree;
pub mod exr;
pub mod files;
pub mod math;
pub mod png;
pub mod ray;
