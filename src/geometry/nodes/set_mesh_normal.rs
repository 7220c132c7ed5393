//! Set Mesh Normal (`node_geo_set_mesh_normal.cc`, Blender 4.5).
//!
//! Sharpness: stores Edge Sharpness as `sharp_edge` and Face Sharpness as `sharp_face`
//! (both fields evaluated before either is written; an all-false one removes its
//! attribute), and with Remove Custom drops `custom_normal`.
//! Free: captures Custom Normal on the chosen domain (point, face or corner) as the
//! `custom_normal` float vector attribute, which then is the mesh's normals as Blender
//! reads them (unnormalized; `Mesh::free_custom_normals`): the renderer's corner normals
//! and the Normal input.
//! Tangent Space (Blender's corner fan spaces, quantized to 16-bit angles) is an error
//! naming the node.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

pub fn set_mesh_normal(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    match ctx.prop_str("mode")? {
        "SHARPNESS" => {
            let remove_custom = ctx.bool("Remove Custom")?;
            let sharp_edge = ctx.field("Edge Sharpness", DataType::Bool)?;
            let sharp_face = ctx.field("Face Sharpness", DataType::Bool)?;
            modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
                let Some(m) = s.mesh.clone() else {
                    return Ok(());
                };
                let e = eval_fields(
                    ComponentRef::Mesh(&m),
                    Domain::Edge,
                    &[(&sharp_edge, DataType::Bool)],
                )?;
                let f = eval_fields(
                    ComponentRef::Mesh(&m),
                    Domain::Face,
                    &[(&sharp_face, DataType::Bool)],
                )?;
                drop(m);
                let mm = s.mesh_mut().unwrap();
                for (name, domain, values) in [
                    ("sharp_edge", Domain::Edge, &e[0]),
                    ("sharp_face", Domain::Face, &f[0]),
                ] {
                    // All false: no attribute, as Blender stores it.
                    let id = AttrId::named(name);
                    mm.attributes.remove(&id);
                    if values.as_bool().iter().any(|b| *b) {
                        mm.attributes
                            .set(id, domain, Array::Bool(values.as_bool().into_owned()));
                    }
                }
                if remove_custom {
                    mm.attributes.remove(&AttrId::named("custom_normal"));
                }
                Ok(())
            })
            .map_err(|e| ctx.err(e))?;
        }
        "FREE" => {
            let d = ctx.prop_str("domain")?;
            let domain = match Domain::parse(d) {
                Some(x @ (Domain::Point | Domain::Face | Domain::Corner)) => x,
                _ => return Err(ctx.err(format!("domain {d} is not supported"))),
            };
            let normal = ctx.field("Custom Normal", DataType::Vector)?;
            modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
                let Some(m) = s.mesh.clone() else {
                    return Ok(());
                };
                let r = eval_fields(
                    ComponentRef::Mesh(&m),
                    domain,
                    &[(&normal, DataType::Vector)],
                )?;
                drop(m);
                let mm = s.mesh_mut().unwrap();
                let id = AttrId::named("custom_normal");
                // Capturing replaces an attribute of another domain or type.
                mm.attributes.remove(&id);
                mm.attributes.set(id, domain, r[0].clone());
                // Free normals stay put: no longer Import PLY's relative ones.
                mm.attributes
                    .remove(&AttrId::named(super::super::mesh::RELATIVE_NORMALS_REST));
                Ok(())
            })
            .map_err(|e| ctx.err(e))?;
        }
        "TANGENT_SPACE" => {
            return Err(ctx.err(
                "Tangent Space custom normals (Blender's corner fan spaces) are not supported",
            ))
        }
        other => return Err(ctx.err(format!("mode {other} is not supported"))),
    }
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}
