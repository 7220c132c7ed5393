//! Distribute Points on Faces, Random and Poisson Disk, with Blender's random sequences
//! (`node_geo_distribute_points_on_faces.cc`): per loop triangle a generator seeded with
//! `hash(triangle, seed * 5383843)` decides the count (probabilistic rounding of area x
//! density) and draws barycentric coordinates; Poisson Disk over-samples at the maximum
//! density, removes points closer than the minimum distance in point order, thins by the
//! density factor with a hash of the barycentric coordinates, and compacts the arrays by
//! Blender's swap-remove (which reorders points).

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::math::{normalize, V3};
use super::super::mesh::Mesh;
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};
use crate::nodes::random::{hash2, hash3, hash_float_to_float3, Rng};

/// Blender's loop triangles: triangles as they are, quads split (0,1,2) (0,2,3), n-gons
/// by Blender's ear clipping (`polyfill`).
pub fn corner_tris(m: &Mesh) -> Result<(Vec<[u32; 3]>, Vec<u32>), String> {
    let mut tris = Vec::new();
    let mut faces = Vec::new();
    for f in 0..m.face_count() {
        let r = m.face(f);
        let s = r.start as u32;
        match r.len() {
            3 => {
                tris.push([s, s + 1, s + 2]);
                faces.push(f as u32);
            }
            4 => {
                tris.push([s, s + 1, s + 2]);
                tris.push([s, s + 2, s + 3]);
                faces.push(f as u32);
                faces.push(f as u32);
            }
            n => {
                let normal = m.face_normal(f);
                let co = super::super::polyfill::project(
                    normal,
                    r.clone().map(|c| m.positions[m.corner_verts[c] as usize]),
                );
                for t in super::super::polyfill::polyfill(&co) {
                    tris.push([s + t[0], s + t[1], s + t[2]]);
                    faces.push(f as u32);
                }
                let _ = n;
            }
        }
    }
    Ok((tris, faces))
}

fn area_tri(a: V3, b: V3, c: V3) -> f32 {
    let n1 = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let n2 = [b[0] - c[0], b[1] - c[1], b[2] - c[2]];
    let n = [
        n1[1] * n2[2] - n1[2] * n2[1],
        n1[2] * n2[0] - n1[0] * n2[2],
        n1[0] * n2[1] - n1[1] * n2[0],
    ];
    (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() * 0.5
}

struct Samples {
    positions: Vec<V3>,
    bary: Vec<V3>,
    tri: Vec<usize>,
}

fn sample_surface(
    m: &Mesh,
    tris: &[[u32; 3]],
    base_density: f32,
    factors: Option<&[f32]>,
    seed: i32,
) -> Samples {
    let mut s = Samples {
        positions: Vec::new(),
        bary: Vec::new(),
        tri: Vec::new(),
    };
    for (ti, t) in tris.iter().enumerate() {
        let p = |c: u32| m.positions[m.corner_verts[c as usize] as usize];
        let (p0, p1, p2) = (p(t[0]), p(t[1]), p(t[2]));
        let factor = match factors {
            Some(f) => {
                (f[t[0] as usize].max(0.0) + f[t[1] as usize].max(0.0) + f[t[2] as usize].max(0.0))
                    / 3.0
            }
            None => 1.0,
        };
        let area = area_tri(p0, p1, p2);
        let mut rng = Rng::new(hash2(ti as u32, seed as u32));
        let x = area * base_density * factor;
        let round_up = (x - x.floor()) > rng.get_float();
        let count = x as i32 + round_up as i32;
        for _ in 0..count {
            let b = rng.get_barycentric_coordinates();
            let mut q = [0.0f32; 3];
            for k in 0..3 {
                q[k] = p0[k] * b[0] + p1[k] * b[1] + p2[k] * b[2];
            }
            s.positions.push(q);
            s.bary.push(b);
            s.tri.push(ti);
        }
    }
    s
}

/// Marks points closer than `dist` to an earlier kept point (Blender's KD-tree range
/// search visits every point within the radius, eliminated or not).
fn eliminate_close(positions: &[V3], dist: f32, mask: &mut [bool]) {
    if dist <= 0.0 {
        return;
    }
    let r2 = dist * dist;
    // A uniform grid with cells of the search radius.
    let cell = |p: &V3| {
        [
            (p[0] / dist).floor() as i64,
            (p[1] / dist).floor() as i64,
            (p[2] / dist).floor() as i64,
        ]
    };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::new();
    for (i, p) in positions.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(i);
    }
    for i in 0..positions.len() {
        if mask[i] {
            continue;
        }
        let c = cell(&positions[i]);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        for &j in list {
                            if j == i {
                                continue;
                            }
                            let (a, b) = (positions[i], positions[j]);
                            let d = (a[0] - b[0]) * (a[0] - b[0])
                                + (a[1] - b[1]) * (a[1] - b[1])
                                + (a[2] - b[2]) * (a[2] - b[2]);
                            if d <= r2 {
                                mask[j] = true;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Blender's `vec_to_quat` (C version, `quat_to_mat3` in double).
fn vec_to_quat(vec: V3, axis: i32, upflag: i32) -> [f32; 4] {
    let eps = 1e-4f32;
    let len = (vec[0] * vec[0] + vec[1] * vec[1] + vec[2] * vec[2]).sqrt();
    if len == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let (tvec, axis) = if axis > 2 {
        (vec, axis - 3)
    } else {
        ([-vec[0], -vec[1], -vec[2]], axis)
    };
    let (mut nor, co);
    match axis {
        0 => {
            nor = [0.0, -tvec[2], tvec[1]];
            if tvec[1].abs() + tvec[2].abs() < eps {
                nor[1] = 1.0;
            }
            co = tvec[0];
        }
        1 => {
            nor = [tvec[2], 0.0, -tvec[0]];
            if tvec[0].abs() + tvec[2].abs() < eps {
                nor[2] = 1.0;
            }
            co = tvec[1];
        }
        _ => {
            nor = [-tvec[1], tvec[0], 0.0];
            if tvec[0].abs() + tvec[1].abs() < eps {
                nor[0] = 1.0;
            }
            co = tvec[2];
        }
    }
    let co = co / len;
    let (nor, _) = super::super::math::normalize_v3(nor);
    let angle = if co <= -1.0 {
        std::f32::consts::PI
    } else if co >= 1.0 {
        0.0
    } else {
        co.acos()
    };
    let phi = 0.5 * angle;
    let (si, c) = (phi.sin(), phi.cos());
    let mut q = [c, nor[0] * si, nor[1] * si, nor[2] * si];
    if axis != upflag {
        // Third column of quat_to_mat3 (double precision in Blender's C code).
        let (q0, q1, q2, q3) = (
            std::f64::consts::SQRT_2 * q[0] as f64,
            std::f64::consts::SQRT_2 * q[1] as f64,
            std::f64::consts::SQRT_2 * q[2] as f64,
            std::f64::consts::SQRT_2 * q[3] as f64,
        );
        let fp = [
            (q0 * q2 + q1 * q3) as f32,
            (-q0 * q1 + q2 * q3) as f32,
            (1.0 - q1 * q1 - q2 * q2) as f32,
        ];
        let angle = match (axis, upflag) {
            (0, 1) => 0.5 * fp[2].atan2(fp[1]),
            (0, _) => -0.5 * fp[1].atan2(fp[2]),
            (1, 0) => -0.5 * fp[2].atan2(fp[0]),
            (1, _) => 0.5 * fp[0].atan2(fp[2]),
            (_, 0) => 0.5 * (-fp[1]).atan2(-fp[0]),
            _ => -0.5 * (-fp[0]).atan2(-fp[1]),
        };
        let co = angle.cos();
        let si = angle.sin() / len;
        let q2 = [co, tvec[0] * si, tvec[1] * si, tvec[2] * si];
        q = qmul(q2, q);
    }
    q
}

fn qmul(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] + a[2] * b[0] + a[3] * b[1] - a[1] * b[3],
        a[0] * b[3] + a[3] * b[0] + a[1] * b[2] - a[2] * b[1],
    ]
}

/// Built-in mesh attributes that do not become point cloud attributes.
fn mesh_builtin(name: &str) -> bool {
    matches!(
        name,
        "position" | "material_index" | "sharp_face" | "sharp_edge"
    ) || name.starts_with('.')
}

fn mix3(a: &Array, idx: [usize; 3], w: V3) -> Value {
    let t = a.data_type();
    match a {
        Array::Bool(v) => Value::Bool(
            (v[idx[0]] as u8 as f32 * w[0]
                + v[idx[1]] as u8 as f32 * w[1]
                + v[idx[2]] as u8 as f32 * w[2])
                >= 0.5,
        ),
        Array::Int(v) => Value::Int(
            (v[idx[0]] as f32 * w[0] + v[idx[1]] as f32 * w[1] + v[idx[2]] as f32 * w[2]).round()
                as i32,
        ),
        _ => {
            let lanes = match a {
                Array::Float(_) => 1,
                Array::Float2(_) => 2,
                Array::Vector(_) => 3,
                _ => 4,
            };
            let get = |k: usize| -> [f32; 4] {
                match a.get(idx[k]) {
                    Value::Float(x) => [x, 0.0, 0.0, 0.0],
                    Value::Float2(x) => [x[0], x[1], 0.0, 0.0],
                    Value::Vector(x) => [x[0], x[1], x[2], 0.0],
                    Value::Color(x) | Value::ByteColor(x) | Value::Quaternion(x) => x,
                    other => other.as_color(),
                }
            };
            let (a0, a1, a2) = (get(0), get(1), get(2));
            let mut r = [0.0f32; 4];
            for k in 0..lanes {
                r[k] = a0[k] * w[0] + a1[k] * w[1] + a2[k] * w[2];
            }
            match t {
                DataType::Float => Value::Float(r[0]),
                DataType::Float2 => Value::Float2([r[0], r[1]]),
                DataType::Vector => Value::Vector([r[0], r[1], r[2]]),
                DataType::ByteColor => Value::ByteColor(r),
                DataType::Quaternion => Value::Quaternion(r),
                _ => Value::Color(r).convert(t),
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn distribute_mesh(
    ctx: &NodeCtx,
    m: &Mesh,
    method: &str,
    sel: &Field,
    seed: i32,
    want_normal: Option<&AttrId>,
    want_rot: Option<&AttrId>,
    legacy: bool,
) -> Result<Option<PointCloud>, String> {
    let (tris, tri_faces) = corner_tris(m)?;
    let comp = ComponentRef::Mesh(m);
    let density_factors = |f: &Field| -> Result<Vec<f32>, String> {
        let r = eval_fields(
            comp,
            Domain::Corner,
            &[(sel, DataType::Bool), (f, DataType::Float)],
        )?;
        let (s, d) = (r[0].as_bool(), r[1].as_float());
        Ok((0..d.len())
            .map(|i| if s[i] { d[i] } else { 0.0 })
            .collect())
    };
    let s = if method == "RANDOM" {
        let density = ctx
            .field("Density", DataType::Float)
            .map_err(|e| e.message)?;
        let f = density_factors(&density)?;
        sample_surface(m, &tris, 1.0, Some(&f), seed)
    } else {
        let dmin = ctx.float("Distance Min").map_err(|e| e.message)?;
        let dmax = ctx.float("Density Max").map_err(|e| e.message)?;
        let factor = ctx
            .field("Density Factor", DataType::Float)
            .map_err(|e| e.message)?;
        let mut s = sample_surface(m, &tris, dmax, None, seed);
        let mut mask = vec![false; s.positions.len()];
        eliminate_close(&s.positions, dmin, &mut mask);
        let f = density_factors(&factor)?;
        for i in 0..s.positions.len() {
            if mask[i] {
                continue;
            }
            let t = tris[s.tri[i]];
            let b = s.bary[i];
            let p = f[t[0] as usize].max(0.0) * b[0]
                + f[t[1] as usize].max(0.0) * b[1]
                + f[t[2] as usize].max(0.0) * b[2];
            if hash_float_to_float3(b) > p {
                mask[i] = true;
            }
        }
        // Blender's `remove_and_reorder`, from the back.
        for i in (0..s.positions.len()).rev() {
            if mask[i] {
                s.positions.swap_remove(i);
                s.bary.swap_remove(i);
                s.tri.swap_remove(i);
            }
        }
        s
    };
    if s.positions.is_empty() {
        return Ok(None);
    }
    let n = s.positions.len();
    let mut pc = PointCloud {
        positions: s.positions.clone(),
        ..Default::default()
    };
    pc.attributes.set(
        AttrId::named("radius"),
        Domain::Point,
        Array::Float(vec![0.05; n]),
    );
    // Mesh attributes, sampled at the points.
    for a in m.attributes.iter() {
        if a.id.name().is_some_and(mesh_builtin) || a.domain == Domain::Edge {
            continue;
        }
        let mut out = Array::zeros(a.data_type(), n);
        for i in 0..n {
            let t = tris[s.tri[i]];
            let v = match a.domain {
                Domain::Point => mix3(
                    &a.data,
                    [
                        m.corner_verts[t[0] as usize] as usize,
                        m.corner_verts[t[1] as usize] as usize,
                        m.corner_verts[t[2] as usize] as usize,
                    ],
                    s.bary[i],
                ),
                Domain::Corner => mix3(
                    &a.data,
                    [t[0] as usize, t[1] as usize, t[2] as usize],
                    s.bary[i],
                ),
                _ => a.data.get(tri_faces[s.tri[i]] as usize),
            };
            out.set(i, v);
        }
        pc.attributes.set(a.id.clone(), Domain::Point, out);
    }
    let ids: Vec<i32> = (0..n)
        .map(|i| {
            let b = s.bary[i];
            hash2(
                hash3(b[0].to_bits(), b[1].to_bits(), b[2].to_bits()),
                s.tri[i] as u32,
            ) as i32
        })
        .collect();
    pc.attributes
        .set(AttrId::named("id"), Domain::Point, Array::Int(ids));
    if want_normal.is_some() || want_rot.is_some() {
        let normals = if legacy {
            legacy_normals(m, &tris, &s)
        } else {
            sample_normals(m, &tris, &tri_faces, &s)
        };
        if let Some(id) = want_normal {
            pc.attributes
                .set(id.clone(), Domain::Point, Array::Vector(normals.clone()));
        }
        if let Some(id) = want_rot {
            let rot = normals
                .iter()
                .map(|n| super::super::math::normalize_quat(vec_to_quat(*n, 5, 1)))
                .collect();
            pc.attributes
                .set(id.clone(), Domain::Point, Array::Quaternion(rot));
        }
    }
    Ok(Some(pc))
}

/// "Legacy Normal" (files from before 4.0): the normal of the triangle each point lies on
/// (`normal_tri_v3`), whatever the shading.
fn legacy_normals(m: &Mesh, tris: &[[u32; 3]], s: &Samples) -> Vec<V3> {
    s.tri
        .iter()
        .map(|&t| {
            let c = tris[t];
            let p = |k: usize| m.positions[m.corner_verts[c[k] as usize] as usize];
            let (a, b, d) = (p(0), p(1), p(2));
            let n1 = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            let n2 = [b[0] - d[0], b[1] - d[1], b[2] - d[2]];
            normalize([
                n1[1] * n2[2] - n1[2] * n2[1],
                n1[2] * n2[0] - n1[0] * n2[2],
                n1[0] * n2[1] - n1[1] * n2[0],
            ])
        })
        .collect()
}

/// The surface normal at each point, by the mesh's normal domain (face normals on flat
/// faces, interpolated vertex or corner normals on smooth ones).
fn sample_normals(m: &Mesh, tris: &[[u32; 3]], tri_faces: &[u32], s: &Samples) -> Vec<V3> {
    let sharp = m.sharp_faces();
    let has_sharp_edges = m
        .attributes
        .named("sharp_edge")
        .is_some_and(|a| a.data.as_bool().iter().any(|x| *x));
    let all_flat = !sharp.is_empty() && sharp.iter().all(|x| *x);
    let none_flat = !sharp.iter().any(|x| *x) && !has_sharp_edges;
    let interp = |vals: [V3; 3], b: V3| -> V3 {
        let mut r = [0.0f32; 3];
        for k in 0..3 {
            r[k] = vals[0][k] * b[0] + vals[1][k] * b[1] + vals[2][k] * b[2];
        }
        normalize(r)
    };
    if all_flat {
        let fnorm = m.face_normals();
        s.tri
            .iter()
            .map(|&t| fnorm[tri_faces[t] as usize])
            .collect()
    } else if none_flat {
        let vn = m.vertex_normals();
        s.tri
            .iter()
            .zip(&s.bary)
            .map(|(&t, b)| {
                let c = tris[t];
                interp(
                    [
                        vn[m.corner_verts[c[0] as usize] as usize],
                        vn[m.corner_verts[c[1] as usize] as usize],
                        vn[m.corner_verts[c[2] as usize] as usize],
                    ],
                    *b,
                )
            })
            .collect()
    } else {
        let cn = m.corner_normals();
        s.tri
            .iter()
            .zip(&s.bary)
            .map(|(&t, b)| {
                let c = tris[t];
                interp(
                    [cn[c[0] as usize], cn[c[1] as usize], cn[c[2] as usize]],
                    *b,
                )
            })
            .collect()
    }
}

pub fn distribute_points_on_faces(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let method = ctx.prop_str("distribute_method")?.to_string();
    if !matches!(method.as_str(), "RANDOM" | "POISSON") {
        return Err(ctx.err(format!("method {method} is not supported")));
    }
    let legacy = ctx.prop_bool("use_legacy_normal").unwrap_or(false);
    let seed = ctx.int("Seed")?.wrapping_mul(5383843);
    let sel = ctx.field("Selection", DataType::Bool)?;
    let rot_id = ctx
        .output_used("Rotation")
        .then(|| AttrId::anonymous("Rotation"));
    let normal_id = ctx
        .output_used("Normal")
        .then(|| AttrId::anonymous("Normal"));
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        if let Some(m) = s.mesh.clone() {
            let pc = distribute_mesh(
                ctx,
                &m,
                &method,
                &sel,
                seed,
                normal_id.as_ref(),
                rot_id.as_ref(),
                legacy,
            )?;
            s.points = pc.map(Arc::new);
        } else {
            s.points = None;
        }
        s.mesh = None;
        s.curves = None;
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    let mut o = outputs([("Points", SocketValue::Geometry(g))]);
    if let Some(id) = normal_id {
        o.insert(
            "Normal".into(),
            SocketValue::Field(Field::input(AttributeInput {
                id,
                ty: DataType::Vector,
            })),
        );
    }
    if let Some(id) = rot_id {
        o.insert(
            "Rotation".into(),
            SocketValue::Field(Field::input(AttributeInput {
                id,
                ty: DataType::Quaternion,
            })),
        );
    }
    Ok(o)
}
