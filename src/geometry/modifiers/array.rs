//! The Array modifier evaluated natively (`MOD_array.cc`): `count` copies of the mesh,
//! copy `c` moved by the `c`-th power of one offset matrix (constant and relative offsets,
//! then the offset object's transform relative to the object), Fixed Count or Fit Length,
//! UV offsets. Merge, caps and Fit Curve are not evaluated: `unsupported` names them and
//! the object stays frozen (Blender's evaluated mesh) while they are on.

use serde_json::Value as Json;

use super::super::math::{mat4_invert, mat4_mul, transform_point, Mat4f, MAT4_IDENTITY};
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::{flag, float, id_name as set_obj, vec3, Props};

/// The options of an Array modifier blendsynth does not evaluate, by name (None: all of
/// its settings are evaluated).
pub fn unsupported(p: &Props) -> Option<String> {
    let mut out = Vec::new();
    if flag(p, "use_merge_vertices") {
        out.push("Merge (use_merge_vertices)");
    }
    if set_obj(p, "start_cap").is_some() {
        out.push("Start Cap");
    }
    if set_obj(p, "end_cap").is_some() {
        out.push("End Cap");
    }
    if p.get("fit_type").and_then(Json::as_str) == Some("FIT_CURVE") {
        out.push("Fit Type Fit Curve");
    }
    (!out.is_empty()).then(|| out.join(", "))
}

/// Applies the modifier to the set's mesh. `world` gives objects' world matrices (the
/// object itself and the offset object).
pub fn apply(
    p: &Props,
    object: &str,
    world: &dyn Fn(&str) -> Option<Mat4f>,
    mut g: GeometrySet,
) -> Result<GeometrySet, String> {
    if let Some(why) = unsupported(p) {
        return Err(format!("Array options not evaluated: {why}"));
    }
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    if m.vertex_count() == 0 {
        return Ok(g);
    }
    let mut offset = MAT4_IDENTITY;
    if flag(p, "use_constant_offset") {
        let c = vec3(p, "constant_offset_displace")?;
        for k in 0..3 {
            offset[3][k] += c[k];
        }
    }
    if flag(p, "use_relative_offset") {
        let s = vec3(p, "relative_offset_displace")?;
        let mut lo = [f32::MAX; 3];
        let mut hi = [f32::MIN; 3];
        for v in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        for k in 0..3 {
            offset[3][k] += s[k] * (hi[k] - lo[k]);
        }
    }
    if flag(p, "use_object_offset") {
        if let Some(ob) = set_obj(p, "offset_object") {
            let inv = world(object)
                .and_then(|w| mat4_invert(&w))
                .unwrap_or(MAT4_IDENTITY);
            let ow =
                world(&ob).ok_or_else(|| format!("offset object {ob:?} is not in the export"))?;
            offset = mat4_mul(&mat4_mul(&offset, &inv), &ow);
        }
    }
    let mut count = p
        .get("count")
        .and_then(Json::as_i64)
        .ok_or("property \"count\" missing")?;
    if p.get("fit_type").and_then(Json::as_str) == Some("FIT_LENGTH") {
        let eps = 1e-6f32;
        let t = [offset[3][0], offset[3][1], offset[3][2]];
        let dist = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        count = if dist > eps {
            ((float(p, "fit_length")? + eps) / dist + 1.0) as i64
        } else {
            1
        };
    }
    // Blender's own cap on the generated vertices (about 67 million).
    if count.saturating_mul(m.vertex_count() as i64) > 1 << 26 {
        count = 1;
    }
    let count = count.max(1) as usize;
    let (nv, ne, nc, nf) = (
        m.vertex_count(),
        m.edge_count(),
        m.corner_count(),
        m.face_count(),
    );
    let mut out = m.as_ref().clone();
    out.custom_vert_normals = None;
    let mut current = MAT4_IDENTITY;
    for c in 1..count {
        current = mat4_mul(&current, &offset);
        out.positions
            .extend(m.positions.iter().map(|p| transform_point(&current, *p)));
        let (dv, de, dc) = ((c * nv) as u32, (c * ne) as u32, (c * nc) as u32);
        out.edges
            .extend(m.edges.iter().map(|[a, b]| [a + dv, b + dv]));
        out.face_offsets
            .extend(m.face_offsets[1..].iter().map(|o| o + dc));
        out.corner_verts
            .extend(m.corner_verts.iter().map(|v| v + dv));
        out.corner_edges
            .extend(m.corner_edges.iter().map(|e| e + de));
    }
    let sizes = |d: Domain| match d {
        Domain::Point => nv,
        Domain::Edge => ne,
        Domain::Corner => nc,
        Domain::Face => nf,
        _ => 0,
    };
    let uv = uv_offset(p, "offset_u", "offset_v");
    for a in out.attributes.0.iter_mut() {
        let n = sizes(a.domain);
        let idx: Vec<usize> = (1..count).flat_map(|_| 0..n).collect();
        let mut extra = a.data.gather(&idx);
        if a.domain == Domain::Corner && uv != [0.0, 0.0] {
            if let Array::Float2(v) = &mut extra {
                for (i, x) in v.iter_mut().enumerate() {
                    let c = (i / n.max(1) + 1) as f32;
                    x[0] += uv[0] * c;
                    x[1] += uv[1] * c;
                }
            }
        }
        a.data.extend(&extra);
    }
    *g.mesh_mut().unwrap() = out;
    Ok(g)
}

fn uv_offset(p: &Props, u: &str, v: &str) -> [f32; 2] {
    let f = |k: &str| p.get(k).and_then(Json::as_f64).unwrap_or(0.0) as f32;
    [f(u), f(v)]
}
