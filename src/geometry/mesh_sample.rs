//! Sampling a mesh at points on its corner triangles as Blender's `mesh_surface_sample`
//! does for Raycast and Sample Nearest Surface: the value field is evaluated on the
//! corner domain (other domains reach it by Blender's domain interpolation), and the three
//! corner values of a triangle are mixed with weights (`attribute_math::mix3`) that are
//! either barycentric (`interp_weights_tri_v3`) or one-hot on the nearest corner.
//! Triangle -1 (nothing hit, no group) gives the type's cleared value: all zeros, also for
//! rotations and matrices (`T{}`).

use super::field::{ComponentRef, Field, FieldContext};
use super::math::{euler_to_quat, from_loc_rot_scale, mat3_to_euler, normalize, V3};
use super::mesh::Mesh;
use super::nearest::{dist_sq, interp_weights_tri};
use super::types::{Array, DataType, Domain, Value};

/// A mesh's corner triangles with what sampling needs of them.
pub struct Triangles {
    /// Corner indices of each triangle.
    pub corners: Vec<[u32; 3]>,
    /// The face of each triangle.
    pub faces: Vec<u32>,
    /// Vertex positions of each triangle's corners.
    pub positions: Vec<[V3; 3]>,
}

impl Triangles {
    pub fn new(m: &Mesh) -> Result<Triangles, String> {
        let (corners, faces) = super::nodes::distribute::corner_tris(m)?;
        let positions = corners
            .iter()
            .map(|t| t.map(|c| m.positions[m.corner_verts[c as usize] as usize]))
            .collect();
        Ok(Triangles {
            corners,
            faces,
            positions,
        })
    }

    /// Barycentric weights of `p` in triangle `t` (Interpolated).
    pub fn bary_weights(&self, t: usize, p: V3) -> V3 {
        let [a, b, c] = self.positions[t];
        interp_weights_tri(a, b, c, p)
    }

    /// All weight on the corner nearest to `p` (Nearest; `MIN3_PAIR`, so the later corner
    /// wins a tie).
    pub fn nearest_weights(&self, t: usize, p: V3) -> V3 {
        let [a, b, c] = self.positions[t];
        let (d0, d1, d2) = (dist_sq(p, a), dist_sq(p, b), dist_sq(p, c));
        if d0 < d1 {
            if d0 < d2 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            }
        } else if d1 < d2 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        }
    }
}

/// The value field evaluated on the mesh's corners, as `ty`.
pub fn corner_values(m: &Mesh, field: &Field, ty: DataType) -> Result<Array, String> {
    FieldContext::new(ComponentRef::Mesh(m)).eval(field, Domain::Corner, ty)
}

/// `T{}`: what a sample without a triangle gives.
pub fn cleared(ty: DataType) -> Value {
    match ty {
        DataType::Quaternion => Value::Quaternion([0.0; 4]),
        DataType::Matrix => Value::Matrix([[0.0; 4]; 4]),
        t => Value::zero(t),
    }
}

/// `mix3` of triangle `t`'s corner values with weights `w`.
pub fn sample(values: &Array, tris: &Triangles, t: usize, w: V3) -> Value {
    let [c0, c1, c2] = tris.corners[t].map(|c| c as usize);
    mix3(w, values.get(c0), values.get(c1), values.get(c2))
}

/// `attribute_math::mix3`: weighted sums in single precision (integers rounded half away
/// from zero, booleans true from 0.5), rotations mixed as exponential maps, matrices as
/// location, rotation and scale separately.
pub fn mix3(w: V3, a: Value, b: Value, c: Value) -> Value {
    let f = |x: f32, y: f32, z: f32| w[0] * x + w[1] * y + w[2] * z;
    match (a, b, c) {
        (Value::Float(x), Value::Float(y), Value::Float(z)) => Value::Float(f(x, y, z)),
        (Value::Int(x), Value::Int(y), Value::Int(z)) => {
            Value::Int(f(x as f32, y as f32, z as f32).round() as i32)
        }
        (Value::Bool(x), Value::Bool(y), Value::Bool(z)) => {
            Value::Bool(f(x as u8 as f32, y as u8 as f32, z as u8 as f32) >= 0.5)
        }
        (Value::Vector(x), Value::Vector(y), Value::Vector(z)) => {
            Value::Vector(mix3_v3(w, x, y, z))
        }
        (Value::Color(x), Value::Color(y), Value::Color(z)) => {
            Value::Color(std::array::from_fn(|k| f(x[k], y[k], z[k])))
        }
        (Value::Quaternion(x), Value::Quaternion(y), Value::Quaternion(z)) => {
            Value::Quaternion(mix3_quat(w, x, y, z))
        }
        (Value::Matrix(x), Value::Matrix(y), Value::Matrix(z)) => {
            Value::Matrix(mix3_matrix(w, &x, &y, &z))
        }
        // Fields reaching here are of socket types; anything else keeps the first value.
        (a, _, _) => a,
    }
}

fn mix3_v3(w: V3, x: V3, y: V3, z: V3) -> V3 {
    std::array::from_fn(|k| w[0] * x[k] + w[1] * y[k] + w[2] * z[k])
}

/// `Quaternion::expmap()`: axis times angle, from the half angle's arc cosine (a tiny
/// sine counts as 1, a zero axis points along Y).
pub fn quat_to_expmap(q: [f32; 4]) -> V3 {
    let half = q[0].acos();
    let mut s = half.sin();
    let angle = half * 2.0;
    if s.abs() < 0.0005 {
        s = 1.0;
    }
    let mut axis = [q[1] / s, q[2] / s, q[3] / s];
    if axis == [0.0; 3] {
        axis[1] = 1.0;
    }
    [axis[0] * angle, axis[1] * angle, axis[2] * angle]
}

/// `Quaternion::expmap(v)`: rotation by |v| (wrapped to [-pi, pi]) about v; identity for 0.
pub fn expmap_to_quat(v: V3) -> [f32; 4] {
    let len_sq = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if !(len_sq > 1.0e-35) {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let len = len_sq.sqrt();
    let axis = [v[0] / len, v[1] / len, v[2] / len];
    let pi = std::f32::consts::PI;
    let two_pi = 2.0 * pi;
    let a = len + pi;
    let angle = (a - two_pi * (a / two_pi).floor()) - pi;
    let half = angle / 2.0;
    let (s, c) = (half.sin(), half.cos());
    [c, axis[0] * s, axis[1] * s, axis[2] * s]
}

fn mix3_quat(w: V3, a: [f32; 4], b: [f32; 4], c: [f32; 4]) -> [f32; 4] {
    expmap_to_quat(mix3_v3(
        w,
        quat_to_expmap(a),
        quat_to_expmap(b),
        quat_to_expmap(c),
    ))
}

fn column(m: &super::math::Mat4f, k: usize) -> V3 {
    [m[k][0], m[k][1], m[k][2]]
}

/// `normalized_to_quaternion_safe(normalize(float3x3(m)))`: through Euler angles, which
/// tolerate shear.
fn matrix_rotation(m: &super::math::Mat4f) -> [f32; 4] {
    let r = [
        normalize(column(m, 0)),
        normalize(column(m, 1)),
        normalize(column(m, 2)),
    ];
    euler_to_quat(mat3_to_euler(&r))
}

fn matrix_scale(m: &super::math::Mat4f) -> V3 {
    std::array::from_fn(|k| {
        let c = column(m, k);
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
    })
}

fn mix3_matrix(
    w: V3,
    a: &super::math::Mat4f,
    b: &super::math::Mat4f,
    c: &super::math::Mat4f,
) -> super::math::Mat4f {
    let loc = mix3_v3(w, column(a, 3), column(b, 3), column(c, 3));
    let rot = mix3_quat(
        w,
        matrix_rotation(a),
        matrix_rotation(b),
        matrix_rotation(c),
    );
    let scale = mix3_v3(w, matrix_scale(a), matrix_scale(b), matrix_scale(c));
    from_loc_rot_scale(loc, rot, scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expmap_round_trips_and_identity_mixes_to_identity() {
        let q = euler_to_quat([0.3, -0.2, 0.9]);
        let r = expmap_to_quat(quat_to_expmap(q));
        for k in 0..4 {
            assert!((q[k] - r[k]).abs() < 1e-6, "{q:?} {r:?}");
        }
        let id = [1.0, 0.0, 0.0, 0.0];
        assert_eq!(mix3_quat([0.2, 0.3, 0.5], id, id, id), id);
    }

    #[test]
    fn integers_round_and_booleans_threshold() {
        let w = [0.25, 0.25, 0.5];
        assert_eq!(
            mix3(w, Value::Int(1), Value::Int(2), Value::Int(4)),
            Value::Int(3)
        );
        assert_eq!(
            mix3(w, Value::Bool(true), Value::Bool(true), Value::Bool(false)),
            Value::Bool(true)
        );
        assert_eq!(
            mix3(w, Value::Bool(true), Value::Bool(false), Value::Bool(false)),
            Value::Bool(false)
        );
    }
}
