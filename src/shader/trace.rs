//! The ray queries a shader may make at its shading point (Cycles' `__SHADER_RAYTRACE__`
//! nodes: Ambient Occlusion and Bevel). The renderer implements `Trace` over its scene; the
//! shader layer sees only this narrow interface, so it imports nothing from `render`.

use crate::nodes::math::V3;

use super::point::ShadingPoint;

/// Ray queries at one shading point. Where Cycles cannot trace (displacement, shadow and
/// light-emission shading, the world, bakes without a scene) the caller passes
/// `NoTrace`, which answers as Cycles' kernel does there.
pub trait Trace {
    /// Cycles' svm_ao: the fraction of `samples` cosine-distributed rays about `n` (unit)
    /// from `sp.position` that reach `max_dist` unblocked, by any object's opaque-shadow
    /// visibility or, with `only_local`, by the shaded object alone.
    fn ambient_occlusion(
        &self,
        sp: &ShadingPoint,
        n: V3,
        max_dist: f32,
        samples: u32,
        only_local: bool,
    ) -> f32;

    /// Cycles' svm_bevel: the shaded object's normals within `radius`, blended by the
    /// cubic falloff over `samples` probes (the shading normal where there is nothing).
    fn bevel(&self, sp: &ShadingPoint, radius: f32, samples: u32) -> V3;
}

/// No ray tracing: Ambient Occlusion is 1 and Bevel the shading normal, as Cycles'
/// kernels answer without the ray-tracing node feature or a BVH.
pub struct NoTrace;

impl Trace for NoTrace {
    fn ambient_occlusion(&self, _: &ShadingPoint, _: V3, _: f32, _: u32, _: bool) -> f32 {
        1.0
    }

    fn bevel(&self, sp: &ShadingPoint, _: f32, _: u32) -> V3 {
        sp.normal
    }
}
