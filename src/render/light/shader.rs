//! A light's node tree that varies, evaluated at each light sample as Cycles'
//! `light_sample_shader_eval` does for a non-constant light shader: the emission of the
//! Light Output's Surface at the sampled point, seen from the point it lights.

use std::cell::RefCell;

use crate::render::math::*;
use crate::shader::point::{ObjectInfo, ShadingPoint};
use crate::shader::program::Program;

#[derive(Debug)]
pub struct LightShader {
    program: Program,
    /// The light object (location, world-to-object transform, for object-space
    /// coordinates as Cycles reads them at a light).
    object: ObjectInfo,
    /// The object-to-world rows, whose transpose takes normals to object space.
    to_world: [[f32; 4]; 3],
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
            to_world,
        }
    }

    /// Cycles' emission estimate of the tree (its light tree weight).
    pub fn estimate(&self) -> V3 {
        self.program.emission_estimate
    }

    /// The emission of the tree for the light point `p` with normal `ng` (Cycles' ls->P,
    /// ls->Ng), lighting along `incoming` (from the light toward the lit point, -ls->D)
    /// at distance `t`.
    pub fn emission(&self, p: V3, ng: V3, incoming: V3, t: f32) -> V3 {
        let m = &self.object.world_to_object;
        let object_position = [0, 1, 2].map(|r| dot([m[r][0], m[r][1], m[r][2]], p) + m[r][3]);
        // Cycles' object_inverse_normal_transform: the transpose of the object's matrix.
        let w = &self.to_world;
        let on = [0, 1, 2].map(|c| w[0][c] * ng[0] + w[1][c] * ng[1] + w[2][c] * ng[2]);
        let sp = ShadingPoint {
            position: p,
            normal: ng,
            ng,
            true_normal: ng,
            incoming,
            ray_length: t,
            object_position,
            object_normal: normalize(on),
            // No Generated attribute at a light: Cycles falls back to object space.
            generated: object_position,
            object: self.object,
            ..Default::default()
        };
        STACK.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            s.extend_from_slice(&self.program.initial);
            self.program.run(&sp, &mut s);
            self.program.surface_emission(&s)
        })
    }
}
