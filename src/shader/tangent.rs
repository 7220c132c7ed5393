//! Tangent space as Cycles builds it: MikkTSpace tangents per corner of the mesh's
//! triangles (Cycles runs MikkTSpace on its triangles, not on Blender's faces), and the
//! nodes that use them: Normal Map and Vector Displacement in tangent space, Tangent in
//! UV Map mode.

use crate::foundation::math::{Vec3, V3};
use crate::scene::{AttributeData, MeshData};
use rayon::prelude::*;

use super::point::ShadingPoint;

struct MikkMesh<'a> {
    mesh: &'a MeshData,
    uvs: &'a [[f32; 2]],
    flat: Vec<bool>,
    vertex_normals: Vec<V3>,
    out: Vec<[f32; 4]>,
}

impl MikkMesh<'_> {
    fn corner(&self, face: usize, vert: usize) -> usize {
        self.mesh.triangles[face][vert] as usize
    }
    fn pos(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.mesh.corner_verts[self.corner(face, vert)] as usize]
    }
}

impl mikktspace::Geometry for MikkMesh<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.triangles.len()
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.pos(face, vert)
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        // Cycles: the vertex normal on a smooth face, the triangle's normal on a flat one.
        if self.flat[self.mesh.triangle_faces[face] as usize] {
            let p = [0, 1, 2].map(|k| Vec3::from(self.pos(face, k)));
            normalize_div((p[1] - p[0]).cross(p[2] - p[0])).into()
        } else {
            self.vertex_normals[self.mesh.corner_verts[self.corner(face, vert)] as usize]
        }
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.uvs[self.corner(face, vert)]
    }
    fn set_tangent_encoded(&mut self, t: [f32; 4], face: usize, vert: usize) {
        self.out[3 * face + vert] = t;
    }
}

/// MikkTSpace tangents (x, y, z, bitangent sign) for UV map `uvs`, per corner of each
/// triangle (index 3 * triangle + k), object space.
pub fn mikk_tangents(mesh: &MeshData, uvs: &[[f32; 2]]) -> Vec<[f32; 4]> {
    // MikkTSpace's vertex welding and area terms overflow for coordinates near f32's
    // range (its cell index then runs past its table: a panic). Its output directions
    // do not depend on a uniform scale, so such a mesh runs scaled down by a power of
    // two. Ordinary meshes are left alone, so their tangents keep every bit.
    // A NaN or infinite position or UV (Geometry Nodes can make them) sends
    // MikkTSpace's welding into an endless loop. Such triangles are never hit by a ray,
    // so their tangents do not matter: the non-finite values go in as 0.
    let finite_uvs;
    let uvs = if uvs.iter().flatten().all(|c| c.is_finite()) {
        uvs
    } else {
        finite_uvs = uvs
            .iter()
            .map(|u| u.map(finite_or_zero))
            .collect::<Vec<_>>();
        &finite_uvs[..]
    };
    let finite;
    let mesh = if mesh.positions.iter().flatten().all(|c| c.is_finite()) {
        mesh
    } else {
        finite = MeshData {
            positions: mesh
                .positions
                .iter()
                .map(|p| p.map(finite_or_zero))
                .collect(),
            ..mesh.clone()
        };
        &finite
    };
    let scaled;
    let mesh = match scale_down(&mesh.positions) {
        Some(positions) => {
            scaled = MeshData {
                positions,
                ..mesh.clone()
            };
            &scaled
        }
        None => mesh,
    };
    let flat = match mesh.attribute("sharp_face").map(|a| &a.data) {
        Some(AttributeData::Bool(v)) => v.clone(),
        _ => vec![false; mesh.face_count()],
    };
    let mut m = MikkMesh {
        mesh,
        uvs,
        flat,
        vertex_normals: vertex_normals(mesh),
        out: vec![[0.0; 4]; mesh.triangles.len() * 3],
    };
    mikktspace::generate_tangents(&mut m);
    m.out
}

fn finite_or_zero(c: f32) -> f32 {
    if c.is_finite() {
        c
    } else {
        0.0
    }
}

/// Largest coordinate MikkTSpace gets as is: squared it stays far inside f32's range.
const MIKK_MAX_COORD: f32 = (1u64 << 40) as f32;

/// The positions scaled by a power of two (exact in floating point) to a largest
/// coordinate near 1, when they are beyond MIKK_MAX_COORD; None otherwise.
fn scale_down(positions: &[[f32; 3]]) -> Option<Vec<[f32; 3]>> {
    let max = positions
        .iter()
        .flatten()
        .map(|c| c.abs())
        .filter(|c| c.is_finite())
        .fold(0.0f32, f32::max);
    if max <= MIKK_MAX_COORD {
        return None;
    }
    let k = 2f64.powi(-(max as f64).log2().floor() as i32);
    Some(
        positions
            .iter()
            .map(|p| p.map(|c| (c as f64 * k) as f32))
            .collect(),
    )
}

/// Normal Map, tangent space (Cycles' svm_node_normal_map): `tangent` is the interpolated
/// (x, y, z, sign), `normal` the interpolated object-space normal (see
/// `AttributeRequest::MapNormal`); None when the mesh has no such UV map, then the
/// unperturbed normal.
pub fn normal_map_tangent(
    sp: &ShadingPoint,
    tangent: Option<[f32; 4]>,
    normal: V3,
    color: V3,
    strength: f32,
) -> V3 {
    let Some(t4) = tangent else { return sp.normal };
    let (normal, color) = (Vec3::from(normal), Vec3::from(color));
    let mut c = (color - Vec3::splat(0.5)) * 2.0;
    // Tangent space scales the map's x and y by strength instead of blending normals.
    c.x *= strength;
    c.y *= strength;
    c.z = 1.0 + (c.z - 1.0) * strength.clamp(0.0, 1.0);
    let t = vec3_of(t4);
    let b = normal.cross(t) * t4[3];
    let local = safe_normalize_mul(t * c.x + b * c.y + normal * c.z);
    let mut n = sp.transform.normal(local.into());
    if sp.backfacing {
        n = (Vec3::from(n) * -1.0).into();
    }
    if n == [0.0; 3] {
        n = sp.normal;
    }
    n
}

/// Vector Displacement, tangent space (Cycles' svm_node_vector_displacement): x along the
/// tangent, y along the normal, z along the bitangent, then to world space. Without the
/// UV map Cycles uses dPdu, which a bake does not have: None is then zero.
pub fn vector_displacement_tangent(
    sp: &ShadingPoint,
    tangent: Option<[f32; 4]>,
    vector: V3,
    midlevel: f32,
    scale: f32,
) -> V3 {
    let Some(t4) = tangent else { return [0.0; 3] };
    let d = (Vec3::from(vector) - Vec3::splat(midlevel)) * scale;
    let normal = Vec3::from(sp.transform.inverse_normal(sp.normal));
    let t = vec3_of(t4);
    let b = safe_normalize_mul(normal.cross(t)) * t4[3];
    let local = t * d.x + normal * d.y + b * d.z;
    sp.transform.dir(local.into())
}

/// Tangent node, UV Map mode: the interpolated tangent to world space, made orthogonal to
/// the shading normal; zero without the UV map.
pub fn tangent_uv(sp: &ShadingPoint, tangent: Option<[f32; 4]>) -> V3 {
    let Some(t4) = tangent else { return [0.0; 3] };
    let t = Vec3::from(sp.transform.normal([t4[0], t4[1], t4[2]]));
    let n = Vec3::from(sp.normal);
    n.cross(normalize_div(t.cross(n))).into()
}

/// The xyz of a MikkTSpace tangent (its w is the bitangent sign).
fn vec3_of(t4: [f32; 4]) -> Vec3 {
    Vec3::new(t4[0], t4[1], t4[2])
}

/// Cycles' `normalize`: each component divided by the length (NaN for a zero vector),
/// as `nodes::math::normalize3`.
fn normalize_div(v: Vec3) -> Vec3 {
    v / v.length()
}

/// Cycles' `safe_normalize` by the reciprocal length, a zero vector left as it is
/// (`nodes::math::safe_normalize3`; a NaN length gives NaN, unlike `Vec3::normalize`).
fn safe_normalize_mul(v: Vec3) -> Vec3 {
    let t = v.length();
    if t != 0.0 {
        v * (1.0 / t)
    } else {
        v
    }
}

/// Blender's vertex normals (what Cycles' smooth triangles and MikkTSpace read): each
/// face's normal weighted by its corner angle at the vertex, summed and normalised.
pub fn vertex_normals(mesh: &MeshData) -> Vec<V3> {
    // Without sharp faces, sharp edges or custom normals Blender's corner normals are its
    // vertex normals: take them as Blender rounded them.
    let any = |name: &str| matches!(mesh.attribute(name).map(|a| &a.data), Some(AttributeData::Bool(v)) if v.iter().any(|&b| b));
    if !any("sharp_face")
        && !any("sharp_edge")
        && mesh.attribute("custom_normal").is_none()
        && mesh.corner_normals.len() == mesh.corner_count()
    {
        let mut out = vec![[0.0f32; 3]; mesh.vertex_count()];
        for (c, &v) in mesh.corner_verts.iter().enumerate() {
            out[v as usize] = mesh.corner_normals[c];
        }
        return out;
    }
    let pos = |c: usize| Vec3::from(mesh.positions[mesh.corner_verts[c] as usize]);
    let face_normal = |a: usize, n: usize| match n {
        3 => normalize_div((pos(a) - pos(a + 1)).cross(pos(a + 1) - pos(a + 2))),
        4 => normalize_div((pos(a) - pos(a + 2)).cross(pos(a + 1) - pos(a + 3))),
        _ => {
            // Newell's method.
            let mut s = Vec3::ZERO;
            for k in 0..n {
                let (p, q) = (pos(a + k), pos(a + (k + 1) % n));
                s.x += (p.y - q.y) * (p.z + q.z);
                s.y += (p.z - q.z) * (p.x + q.x);
                s.z += (p.x - q.x) * (p.y + q.y);
            }
            normalize_div(s)
        }
    };
    // Each corner's weighted face normal on rayon's threads (the arc cosines were a serial
    // part of the published colon's set-up), then summed per vertex in corner order, the
    // order of the one-thread loop, so the same bits.
    let first = mesh.face_offsets.first().map_or(0, |&o| o as usize);
    let end = mesh.face_offsets.last().map_or(0, |&o| o as usize);
    let weighted: Vec<Option<Vec3>> = (first..end.max(first))
        .into_par_iter()
        .map(|c| {
            let f = mesh.face_offsets.partition_point(|&o| o as usize <= c) - 1;
            let (a, b) = (
                mesh.face_offsets[f] as usize,
                mesh.face_offsets[f + 1] as usize,
            );
            let n = b - a;
            if n < 3 {
                return None;
            }
            let k = c - a;
            let prev = a + (k + n - 1) % n;
            let next = a + (k + 1) % n;
            let d1 = safe_normalize_mul(pos(prev) - pos(c));
            let d2 = safe_normalize_mul(pos(next) - pos(c));
            let angle = d1.dot(d2).clamp(-1.0, 1.0).acos();
            Some(face_normal(a, n) * angle)
        })
        .collect();
    let mut acc = vec![Vec3::ZERO; mesh.vertex_count()];
    for (c, w) in (first..).zip(&weighted) {
        if let Some(w) = w {
            let v = mesh.corner_verts[c] as usize;
            acc[v] += *w;
        }
    }
    acc.into_iter()
        .map(|a| safe_normalize_mul(a).into())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit plane (one quad, two triangles) with a UV map, positions scaled by `s`.
    fn plane(s: f32) -> (MeshData, Vec<[f32; 2]>) {
        let p = [
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ];
        let m = MeshData {
            name: "Plane".into(),
            positions: p.iter().map(|v: &[f32; 3]| v.map(|c| c * s)).collect(),
            edges: vec![[0, 1], [1, 2], [2, 3], [3, 0]],
            face_offsets: vec![0, 4],
            corner_verts: vec![0, 1, 2, 3],
            corner_edges: vec![0, 1, 2, 3],
            corner_normals: vec![[0.0, 0.0, 1.0]; 4],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            triangle_faces: vec![0, 0],
            attributes: vec![],
        };
        (m, vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    }

    #[test]
    fn huge_positions_give_the_same_tangents_as_small_ones() {
        let (m, uv) = plane(1.0);
        let small = mikk_tangents(&m, &uv);
        for s in [3e38f32, 1e30, 1e20, f32::MAX] {
            let (m, uv) = plane(s);
            let big = std::panic::catch_unwind(|| mikk_tangents(&m, &uv))
                .unwrap_or_else(|_| panic!("mikk_tangents panicked at scale {s}"));
            for (a, b) in small.iter().zip(&big) {
                for k in 0..4 {
                    assert!((a[k] - b[k]).abs() < 1e-6, "scale {s}: {a:?} vs {b:?}");
                }
            }
        }
    }

    #[test]
    fn non_finite_positions_do_not_panic() {
        for bad in [f32::NAN, f32::INFINITY] {
            let (mut m, uv) = plane(1.0);
            m.positions[2][0] = bad;
            let t = std::panic::catch_unwind(|| mikk_tangents(&m, &uv));
            assert!(t.is_ok(), "mikk_tangents panicked with a {bad} coordinate");
            let (m, mut uv) = plane(1.0);
            uv[1][0] = bad;
            let t = std::panic::catch_unwind(|| mikk_tangents(&m, &uv));
            assert!(t.is_ok(), "mikk_tangents panicked with a {bad} UV");
        }
    }
}
