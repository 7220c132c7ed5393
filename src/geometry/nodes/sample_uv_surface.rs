//! Sample UV Surface (`node_geo_sample_uv_surface.cc`, Blender's `ReverseUVSampler`):
//! finds the corner triangle whose UV Map triangle holds each Sample UV and samples the
//! Value there with the UV-space barycentric weights (`mesh_sample`; Blender mixes point
//! and face values on their own domain, the same values as their copies on the corners).
//!
//! The lookup is Blender's: UV space is cut into `max(3, trunc(3 sqrt(triangles)))` cells
//! per unit (cell = UV x resolution, truncated toward zero); a sample tests only the
//! triangles whose corner cells' bounding range holds its cell. A
//! triangle closer than the best so far (distance = how far the furthest barycentric
//! weight lies outside [0, 1]) becomes the best; a sample inside two triangles by more than
//! 1e-5 (both of UV area above 1e-5) is "multiple": not valid. A best distance below 1e-5
//! (inside, or just outside an edge) is valid, with the weights clamped to [0, 1];
//! anything else (outside every UV triangle, degenerate UV triangles skipped) is not valid
//! and gives the type's cleared value.
//!
//! Ties (a sample on an edge shared by two triangles) go to the first triangle in Blender's
//! iteration order (see `sample`).
//!
//! Blender compares the area of the current triangle with itself where it means the best
//! one (`best_tri = corner_tris_[tri_i]`); that is kept, so overlaps are judged by the later
//! triangle's area only.

use std::collections::HashMap;
use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::mesh_sample::{cleared, corner_values, sample, Triangles};
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use super::raycast::sample_data_type;

type V2 = [f32; 2];

/// The triangles of one grid row with their cell column ranges, in triangle order.
struct Row {
    tris: Vec<(u32, i32, i32)>,
}

/// `ReverseUVSampler`: the UV triangles and their grid.
pub struct ReverseUvSampler {
    uv_tris: Vec<[V2; 3]>,
    resolution: i32,
    rows: HashMap<i32, Row>,
}

/// How a UV sample resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UvSample {
    /// Outside every UV triangle (or only in degenerate ones).
    None,
    /// Inside two UV triangles.
    Multiple,
    /// Triangle and clamped barycentric weights.
    Ok(u32, [f32; 3]),
}

fn cell(uv: V2, resolution: i32) -> (i32, i32) {
    // C++'s float to int conversion truncates toward zero (`int2{uv * resolution}`).
    let r = resolution as f32;
    ((uv[0] * r) as i32, (uv[1] * r) as i32)
}

/// `barycentric_coords_v2`: None for a degenerate triangle.
fn barycentric(a: V2, b: V2, c: V2, p: V2) -> Option<[f32; 3]> {
    let det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
    if det.abs() > f32::EPSILON {
        let w0 = ((b[1] - c[1]) * (p[0] - c[0]) + (c[0] - b[0]) * (p[1] - c[1])) / det;
        let w1 = ((c[1] - a[1]) * (p[0] - c[0]) + (a[0] - c[0]) * (p[1] - c[1])) / det;
        Some([w0, w1, 1.0 - w0 - w1])
    } else {
        None
    }
}

/// `area_tri_v2`.
fn area(a: V2, b: V2, c: V2) -> f32 {
    (0.5 * ((a[0] - b[0]) * (b[1] - c[1]) + (a[1] - b[1]) * (c[0] - b[0]))).abs()
}

impl ReverseUvSampler {
    pub fn new(uv_tris: Vec<[V2; 3]>) -> ReverseUvSampler {
        // `std::max<int>(3, sqrt(n) * 3)`: the float product truncated.
        let resolution = 3.max(((uv_tris.len() as f64).sqrt() as f32 * 3.0) as i32);
        let mut rows: HashMap<i32, Row> = HashMap::new();
        for (t, uv) in uv_tris.iter().enumerate() {
            let cells = uv.map(|p| cell(p, resolution));
            let (x0, x1) = (
                cells.iter().map(|c| c.0).min().unwrap(),
                cells.iter().map(|c| c.0).max().unwrap(),
            );
            let (y0, y1) = (
                cells.iter().map(|c| c.1).min().unwrap(),
                cells.iter().map(|c| c.1).max().unwrap(),
            );
            for y in y0..=y1 {
                rows.entry(y)
                    .or_insert_with(|| Row { tris: Vec::new() })
                    .tris
                    .push((t as u32, x0, x1));
            }
        }
        ReverseUvSampler {
            uv_tris,
            resolution,
            rows,
        }
    }

    pub fn sample(&self, q: V2) -> UvSample {
        const EDGE_EPSILON: f32 = 0.00001;
        const AREA_EPSILON: f32 = 0.00001;
        let (cx, cy) = cell(q, self.resolution);
        let Some(row) = self.rows.get(&cy) else {
            return UvSample::None;
        };
        let mut best_dist = f32::MAX;
        let mut best = (0u32, [0.0f32; 3]);
        // Blender gathers a row's triangles in a `ChunkedList` of 8-element segments that
        // iterates the newest segment first (one thread below 256 triangles; above that
        // Blender's order depends on its threads' timing).
        let chunks = row.tris.chunks(8).rev();
        for &(t, x0, x1) in chunks.flatten() {
            if cx < x0 || cx > x1 {
                continue;
            }
            let [a, b, c] = self.uv_tris[t as usize];
            let Some(w) = barycentric(a, b, c, q) else {
                continue;
            };
            let dist = w
                .iter()
                .map(|&x| (-x).max(x - 1.0))
                .fold(f32::MIN, f32::max);
            if dist <= 0.0 && best_dist <= 0.0 && dist.max(best_dist) < -EDGE_EPSILON {
                // Blender tests the current triangle's area twice (for the best one and
                // itself), so only the current one counts.
                if area(a, b, c) > AREA_EPSILON {
                    return UvSample::Multiple;
                }
            }
            if dist < best_dist {
                best_dist = dist;
                best = (t, w);
            }
        }
        if best_dist < EDGE_EPSILON {
            UvSample::Ok(best.0, best.1.map(|x| x.clamp(0.0, 1.0)))
        } else {
            UvSample::None
        }
    }
}

pub fn sample_uv_surface(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Mesh")?;
    let ty = sample_data_type(ctx)?;
    let value = ctx.field("Value", ty)?;
    let defaults = || {
        Ok(outputs([
            ("Value", SocketValue::Field(Field::Constant(cleared(ty)))),
            (
                "Is Valid",
                SocketValue::Field(Field::Constant(Value::Bool(false))),
            ),
        ]))
    };
    let Some(mesh) = g.mesh.clone() else {
        return defaults();
    };
    // Blender's "The source mesh must have faces" error: default outputs.
    if mesh.face_count() == 0 && mesh.vertex_count() != 0 {
        return defaults();
    }
    let tris = Triangles::new(&mesh).map_err(|e| ctx.err(e))?;
    let uv_map = ctx.field("Source UV Map", DataType::Vector)?;
    let uvs = corner_values(&mesh, &uv_map, DataType::Vector)
        .map_err(|e| ctx.err(format!("UV Map: {e}")))?;
    let uvs = uvs.as_vector();
    let uv_tris = tris
        .corners
        .iter()
        .map(|t| t.map(|c| [uvs[c as usize][0], uvs[c as usize][1]]))
        .collect();
    let sampler = ReverseUvSampler::new(uv_tris);
    let values = corner_values(&mesh, &value, ty).map_err(|e| ctx.err(format!("Value: {e}")))?;
    let shared = Arc::new((sampler, tris, values));
    let sample_uv = ctx.field("Sample UV", DataType::Vector)?;
    let fields = Field::op(
        "Sample UV Surface",
        vec![sample_uv],
        vec![ty, DataType::Bool],
        move |n, a| {
            let (sampler, tris, values) = &*shared;
            let q = a[0].as_vector();
            let mut out = Array::filled(cleared(ty), n);
            let mut valid = vec![false; n];
            for i in 0..n {
                if let UvSample::Ok(t, w) = sampler.sample([q[i][0], q[i][1]]) {
                    valid[i] = true;
                    out.set(i, sample(values, tris, t as usize, w));
                }
            }
            Ok(vec![out, Array::Bool(valid)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter().map(SocketValue::Field);
    Ok(outputs([
        ("Value", it.next().unwrap()),
        ("Is Valid", it.next().unwrap()),
    ]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_edge_outside_and_overlap() {
        // Two triangles sharing the diagonal of the unit square, a third overlapping the first.
        let s = ReverseUvSampler::new(vec![
            [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
            [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        ]);
        assert!(matches!(s.sample([0.7, 0.2]), UvSample::Ok(0, _)));
        assert!(matches!(s.sample([0.2, 0.7]), UvSample::Ok(1, _)));
        // On the shared edge: the first triangle (the later is not strictly closer).
        assert!(matches!(s.sample([0.5, 0.5]), UvSample::Ok(0, _)));
        assert_eq!(s.sample([1.5, 0.5]), UvSample::None);
        let s = ReverseUvSampler::new(vec![
            [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
            [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]],
        ]);
        assert_eq!(s.sample([0.7, 0.2]), UvSample::Multiple);
    }
}
