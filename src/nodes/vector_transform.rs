//! Vector Transform node (Cycles `svm_node_vector_transform`): a point, direction or
//! normal between world, object and camera space. As in Cycles, normals go through the
//! transposed inverse and are normalised; object space is skipped where there is no
//! object (a world shader), and converting a space to itself changes nothing (a normal
//! is then not normalised either).

use crate::foundation::math::{
    transform_direction, transform_direction_transposed, transform_point,
};

use super::math::V3;

blender_enum! {
    pub enum VectorTransformType {
        Point = "POINT",
        Vector = "VECTOR",
        Normal = "NORMAL",
    }
}

blender_enum! {
    pub enum TransformSpace {
        World = "WORLD",
        Object = "OBJECT",
        Camera = "CAMERA",
    }
}

/// An affine transform and its inverse, as rows of 3x4 matrices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    pub forward: [[f32; 4]; 3],
    pub inverse: [[f32; 4]; 3],
}

impl Default for Affine {
    fn default() -> Self {
        const IDENTITY: [[f32; 4]; 3] = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        Affine {
            forward: IDENTITY,
            inverse: IDENTITY,
        }
    }
}

fn normalize(v: V3) -> V3 {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if l > 0.0 {
        [v[0] / l, v[1] / l, v[2] / l]
    } else {
        v
    }
}

/// `v` through `t` (`inverse` false) or its inverse, as a point, direction or normal.
fn apply(kind: VectorTransformType, t: &Affine, inverse: bool, v: V3) -> V3 {
    let (m, other) = if inverse {
        (&t.inverse, &t.forward)
    } else {
        (&t.forward, &t.inverse)
    };
    match kind {
        VectorTransformType::Point => transform_point(m, v),
        VectorTransformType::Vector => transform_direction(m, v),
        VectorTransformType::Normal => normalize(transform_direction_transposed(other, v)),
    }
}

/// The node's output. `object` is the shaded object's object-to-world transform (None:
/// no object), `camera` Cycles' camera-to-world (camera space: x right, y up, z forward).
pub fn vector_transform(
    kind: VectorTransformType,
    from: TransformSpace,
    to: TransformSpace,
    v: V3,
    object: Option<&Affine>,
    camera: &Affine,
) -> V3 {
    use TransformSpace::{Camera, Object, World};
    let mut v = v;
    match (from, to) {
        (World, Camera) => v = apply(kind, camera, true, v),
        (World, Object) => {
            if let Some(o) = object {
                v = apply(kind, o, true, v);
            }
        }
        (Camera, World) => v = apply(kind, camera, false, v),
        (Camera, Object) => {
            // Cycles goes through world space even without an object.
            v = apply(kind, camera, false, v);
            if let Some(o) = object {
                v = apply(kind, o, true, v);
            }
        }
        (Object, World) => {
            if let Some(o) = object {
                v = apply(kind, o, false, v);
            }
        }
        (Object, Camera) => {
            if let Some(o) = object {
                v = apply(kind, o, false, v);
            }
            v = apply(kind, camera, true, v);
        }
        (World, World) | (Object, Object) | (Camera, Camera) => {}
    }
    v
}
