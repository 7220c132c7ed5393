//! A light's node tree that varies, evaluated at each light sample as Cycles'
//! `light_sample_shader_eval` does for a non-constant light shader: the emission of the
//! Light Output's Surface at the sampled point, seen from the point it lights.

use std::cell::RefCell;

use crate::render::math::Vec3;
use crate::shader::bump::ObjectTransform;
use crate::shader::point::{ObjectInfo, ShadingPoint};
use crate::shader::program::Program;

#[derive(Debug)]
pub struct LightShader {
    program: Program,
    /// The light object (Object Info values, its world-to-object transform).
    object: ObjectInfo,
    /// Its transforms both ways, for object-space coordinates as Cycles reads them at a
    /// light.
    transform: ObjectTransform,
}

thread_local! {
    // One stack per thread, reused: a light sample allocates nothing.
    static STACK: RefCell<Vec<f32>> = const { RefCell::new(Vec::new()) };
}

impl LightShader {
    pub fn new(program: Program, object: ObjectInfo, to_world: [[f32; 4]; 3]) -> LightShader {
        LightShader {
            program,
            object,
            transform: ObjectTransform {
                to_world,
                to_object: object.world_to_object,
            },
        }
    }

    /// Cycles' emission estimate of the tree (its light tree weight).
    pub fn estimate(&self) -> Vec3 {
        self.program.emission_estimate.into()
    }

    /// The emission of the tree for the light point `p` with normal `ng` (Cycles' ls->P,
    /// ls->Ng), lighting along `incoming` (from the light toward the lit point, -ls->D)
    /// at distance `t`.
    pub fn emission(&self, p: Vec3, ng: Vec3, incoming: Vec3, t: f32) -> Vec3 {
        let (p, ng, incoming) = (p.into(), ng.into(), incoming.into());
        let object_position = self.transform.inverse_point(p);
        let sp = ShadingPoint {
            position: p,
            normal: ng,
            ng,
            true_normal: ng,
            incoming,
            ray_length: t,
            object_position,
            object_normal: self.transform.inverse_normal(ng),
            // No Generated attribute at a light: Cycles falls back to object space.
            generated: object_position,
            object: self.object,
            transform: self.transform,
            ..Default::default()
        };
        STACK.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            s.extend_from_slice(&self.program.initial);
            self.program.run(&sp, &mut s);
            self.program.surface_emission(&s).into()
        })
    }
}
