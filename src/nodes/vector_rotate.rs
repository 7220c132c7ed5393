//! Vector Rotate node (Cycles `svm_node_vector_rotate`): about an axis (given or X/Y/Z)
//! by an angle, or by an XYZ Euler rotation, around a centre; optionally inverted.

use super::mapping::{euler_rows, rotate, rotate_transposed};
use super::math::V3;

blender_enum! {
    pub enum VectorRotateType {
        AxisAngle = "AXIS_ANGLE",
        XAxis = "X_AXIS",
        YAxis = "Y_AXIS",
        ZAxis = "Z_AXIS",
        EulerXyz = "EULER_XYZ",
    }
}

/// Rodrigues' rotation in the term order of Cycles' `rotate_around_axis`.
fn rotate_around_axis(p: V3, a: V3, angle: f32) -> V3 {
    let (c, s) = (angle.cos(), angle.sin());
    let t = 1.0 - c;
    [
        ((c + t * a[0] * a[0]) * p[0])
            + ((t * a[0] * a[1] - a[2] * s) * p[1])
            + ((t * a[0] * a[2] + a[1] * s) * p[2]),
        ((t * a[0] * a[1] + a[2] * s) * p[0])
            + ((c + t * a[1] * a[1]) * p[1])
            + ((t * a[1] * a[2] - a[0] * s) * p[2]),
        ((t * a[0] * a[2] - a[1] * s) * p[0])
            + ((t * a[1] * a[2] + a[0] * s) * p[1])
            + ((c + t * a[2] * a[2]) * p[2]),
    ]
}

pub fn vector_rotate(
    kind: VectorRotateType,
    invert: bool,
    vector: V3,
    center: V3,
    axis: V3,
    angle: f32,
    rotation: V3,
) -> V3 {
    let d = [
        vector[0] - center[0],
        vector[1] - center[1],
        vector[2] - center[2],
    ];
    let add_c = |v: V3| [v[0] + center[0], v[1] + center[1], v[2] + center[2]];
    if kind == VectorRotateType::EulerXyz {
        let r = euler_rows(rotation);
        return add_c(if invert {
            rotate_transposed(&r, d)
        } else {
            rotate(&r, d)
        });
    }
    let (axis, len) = match kind {
        VectorRotateType::XAxis => ([1.0, 0.0, 0.0], 1.0),
        VectorRotateType::YAxis => ([0.0, 1.0, 0.0], 1.0),
        VectorRotateType::ZAxis => ([0.0, 0.0, 1.0], 1.0),
        _ => (
            axis,
            (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt(),
        ),
    };
    let angle = if invert { -angle } else { angle };
    if len != 0.0 {
        add_c(rotate_around_axis(d, axis.map(|x| x / len), angle))
    } else {
        vector
    }
}
