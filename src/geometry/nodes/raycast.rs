//! Raycast (`node_geo_raycast.cc`): rays from Source Position along the normalized Ray
//! Direction onto the target's mesh (realized data only, as Blender's `only_realized_data`:
//! instances are ignored), tested against its corner triangles with the renderer's BVH and
//! watertight test, as Blender's `BLI_bvhtree_ray_cast` does (hits from distance 0 up to,
//! not including, Ray Length; either side of a triangle). A hit gives the position along
//! the ray, the hit triangle's normal (`normal_tri_v3`, not the face's) and the distance;
//! a miss gives zeros and Ray Length as the distance. The Attribute is sampled on the hit
//! triangle (`mesh_sample`), by barycentric or nearest-corner weights of the hit position.
//!
//! Rays through an edge shared by two triangles hit either; Blender keeps the one its BVH
//! reaches first, so which one is not reproduced (the fixtures avoid such rays).

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::{normalize, V3};
use super::super::mesh_sample::{cleared, corner_values, sample, Triangles};
use super::super::nearest::normal_tri;
use super::super::types::{Array, DataType, Value};
use super::super::value::SocketValue;
use crate::foundation::bvh::{Accel, Bvh};

/// The data types the node's `data_type` menu offers in Blender 4.5.
pub fn sample_data_type(ctx: &NodeCtx) -> Result<DataType, GeometryError> {
    let d = ctx.prop_str("data_type")?;
    match d {
        "FLOAT" | "INT" | "FLOAT_VECTOR" | "FLOAT_COLOR" | "BOOLEAN" | "QUATERNION"
        | "FLOAT4X4" => Ok(DataType::parse(d).unwrap()),
        other => Err(ctx.err(format!("data type {other} is not supported"))),
    }
}

pub fn raycast(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let target = ctx.geometry("Target Geometry")?;
    let ty = sample_data_type(ctx)?;
    let nearest = match ctx.prop_str("mapping")? {
        "INTERPOLATED" => false,
        "NEAREST" => true,
        other => return Err(ctx.err(format!("mapping {other} is not supported"))),
    };
    let want_attribute = ctx.output_used("Attribute");
    let attribute = ctx.field("Attribute", ty)?;
    // No mesh, or one without faces (Blender warns about the latter): default outputs.
    let Some(mesh) = target.mesh.clone().filter(|m| m.face_count() > 0) else {
        let c = |v: Value| SocketValue::Field(Field::Constant(v));
        return Ok(outputs([
            ("Is Hit", c(Value::Bool(false))),
            ("Hit Position", c(Value::Vector([0.0; 3]))),
            ("Hit Normal", c(Value::Vector([0.0; 3]))),
            ("Hit Distance", c(Value::Float(0.0))),
            ("Attribute", c(Value::zero(ty))),
        ]));
    };
    let tris = Triangles::new(&mesh).map_err(|e| ctx.err(e))?;
    let values = if want_attribute {
        Some(corner_values(&mesh, &attribute, ty).map_err(|e| ctx.err(format!("Attribute: {e}")))?)
    } else {
        None
    };
    let bvh = Bvh::build(&tris.positions);
    let shared = Arc::new((tris, bvh, values));
    let src = ctx.field("Source Position", DataType::Vector)?;
    let dir = ctx.field("Ray Direction", DataType::Vector)?;
    let len = ctx.field("Ray Length", DataType::Float)?;
    let fields = Field::op(
        "Raycast",
        vec![src, dir, len],
        vec![
            DataType::Bool,
            DataType::Vector,
            DataType::Vector,
            DataType::Float,
            ty,
        ],
        move |n, a| {
            let (tris, bvh, values) = &*shared;
            let (src, dir, len) = (a[0].as_vector(), a[1].as_vector(), a[2].as_float());
            let mut is_hit = vec![false; n];
            let mut pos = vec![[0.0f32; 3]; n];
            let mut nor = vec![[0.0f32; 3]; n];
            let mut dist = vec![0.0f32; n];
            let mut attr = Array::filled(cleared(ty), if values.is_some() { n } else { 0 });
            for i in 0..n {
                let d = normalize(dir[i]);
                // Blender accepts hits at distance 0 (also -0), so the lower bound sits just below.
                match bvh.intersect(src[i], d, -f32::MIN_POSITIVE, len[i]) {
                    Some(h) => {
                        let t = h.prim as usize;
                        let p: V3 = std::array::from_fn(|k| src[i][k] + d[k] * h.t);
                        is_hit[i] = true;
                        pos[i] = p;
                        let [v0, v1, v2] = tris.positions[t];
                        nor[i] = normal_tri(v0, v1, v2);
                        dist[i] = h.t;
                        if let Some(v) = values {
                            let w = if nearest {
                                tris.nearest_weights(t, p)
                            } else {
                                tris.bary_weights(t, p)
                            };
                            attr.set(i, sample(v, tris, t, w));
                        }
                    }
                    None => dist[i] = len[i],
                }
            }
            if values.is_none() {
                attr = Array::filled(cleared(ty), n);
            }
            Ok(vec![
                Array::Bool(is_hit),
                Array::Vector(pos),
                Array::Vector(nor),
                Array::Float(dist),
                attr,
            ])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter().map(SocketValue::Field);
    let mut next = || it.next().unwrap();
    Ok(outputs([
        ("Is Hit", next()),
        ("Hit Position", next()),
        ("Hit Normal", next()),
        ("Hit Distance", next()),
        ("Attribute", next()),
    ]))
}
