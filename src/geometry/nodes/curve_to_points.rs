//! Curve to Points (`node_geo_curve_to_points.cc`): curves resampled by count, length or
//! their evaluated points (`resample_indexed`), as a point cloud carrying the resampled
//! point attributes and the curves' own curve-domain attributes, with Tangent and Normal
//! (evaluated tangents and normals interpolated at each sample and normalized) and
//! Rotation (the frame from normal and tangent, `from_orthonormal_axes`).

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::math::{cross, mat3_to_quat_checked, normalize, V3};
use super::super::pointcloud::PointCloud;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::curve::{resample_indexed, ResampleMode};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

fn lerp_normalized(v: &[V3], a: &[usize], b: &[usize], f: &[f32]) -> Vec<V3> {
    (0..a.len())
        .map(|k| {
            let (p, q, t) = (v[a[k]], v[b[k]], f[k]);
            normalize([
                p[0] * (1.0 - t) + q[0] * t,
                p[1] * (1.0 - t) + q[1] * t,
                p[2] * (1.0 - t) + q[2] * t,
            ])
        })
        .collect()
}

/// Columns (normal, tangent x normal, tangent) as a rotation (`to_quaternion` of
/// `from_orthonormal_axes`; interpolated frames are not quite orthogonal, and Blender
/// keeps what that gives).
pub fn frame_rotation(normal: V3, tangent: V3) -> [f32; 4] {
    let y = cross(tangent, normal);
    // Mat3f is column-major like Blender's float3x3.
    mat3_to_quat_checked(&[normal, y, tangent])
}

pub fn curve_to_points(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let mode = ctx.prop_str("mode")?.to_string();
    let count = if mode == "COUNT" {
        ctx.field("Count", DataType::Int)?
    } else {
        Field::Constant(Value::Int(0))
    };
    let length = if mode == "LENGTH" {
        ctx.field("Length", DataType::Float)?
    } else {
        Field::Constant(Value::Float(0.0))
    };
    let rot_id = ctx
        .output_used("Rotation")
        .then(|| AttrId::anonymous("Rotation"));
    let tan_id = ctx
        .output_used("Tangent")
        .then(|| AttrId::anonymous("Tangent"));
    let nor_id = ctx
        .output_used("Normal")
        .then(|| AttrId::anonymous("Normal"));
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Curve,
            &[(&count, DataType::Int), (&length, DataType::Float)],
        )?;
        let m = match mode.as_str() {
            "COUNT" => ResampleMode::Count(r[0].as_int().into_owned()),
            "LENGTH" => {
                ResampleMode::Length(r[1].as_float().iter().map(|l| l.max(0.0001)).collect())
            }
            "EVALUATED" => ResampleMode::Evaluated,
            other => return Err(format!("mode {other} is not a Curve to Points mode")),
        };
        let (rc, samples, ev) = resample_indexed(&c, m)?;
        let mut pc = PointCloud {
            positions: rc.positions.clone(),
            materials: rc.materials.clone(),
            ..Default::default()
        };
        for a in rc.attributes.on(Domain::Point) {
            pc.attributes
                .set(a.id.clone(), Domain::Point, a.data.clone());
        }
        // Curve-domain attributes (not the built-in ones) move to the points.
        for a in c.attributes.on(Domain::Curve) {
            if a.id.name().is_some_and(|n| {
                matches!(
                    n,
                    "curve_type"
                        | "cyclic"
                        | "resolution"
                        | "normal_mode"
                        | "nurbs_order"
                        | "knots_mode"
                        | "material_index"
                )
            }) {
                continue;
            }
            pc.attributes.set(
                a.id.clone(),
                Domain::Point,
                ComponentRef::Curves(&rc).adapt(&a.data, Domain::Curve, Domain::Point),
            );
        }
        if tan_id.is_some() || nor_id.is_some() || rot_id.is_some() {
            let eval_pos = ev.positions(&c);
            let tangents = ev.tangents(&c, &eval_pos);
            let normals = ev.normals(&c, &tangents)?;
            let t = lerp_normalized(&tangents, &samples.a, &samples.b, &samples.factor);
            let n = lerp_normalized(&normals, &samples.a, &samples.b, &samples.factor);
            if let Some(id) = &rot_id {
                let rot = (0..t.len()).map(|k| frame_rotation(n[k], t[k])).collect();
                pc.attributes
                    .set(id.clone(), Domain::Point, Array::Quaternion(rot));
            }
            if let Some(id) = &tan_id {
                pc.attributes
                    .set(id.clone(), Domain::Point, Array::Vector(t));
            }
            if let Some(id) = &nor_id {
                pc.attributes
                    .set(id.clone(), Domain::Point, Array::Vector(n));
            }
        }
        s.curves = None;
        s.mesh = None;
        s.points = Some(Arc::new(pc));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    let mut o = outputs([("Points", geo(g))]);
    for (name, id, ty) in [
        ("Tangent", tan_id, DataType::Vector),
        ("Normal", nor_id, DataType::Vector),
        ("Rotation", rot_id, DataType::Quaternion),
    ] {
        if let Some(id) = id {
            o.insert(
                name.into(),
                SocketValue::Field(Field::input(AttributeInput { id, ty })),
            );
        }
    }
    Ok(o)
}
