//! Replace Material (`node_geo_material_replace`): every material slot of every mesh
//! (nested instances included) that holds Old gets New. Slots compare as datablock
//! pointers, so an Old left empty replaces the empty slots. Blender also replaces Grease
//! Pencil materials, which blendsynth has no component for.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::set::GeometrySet;
use super::super::value::SocketValue;
use super::geometry_ops::{geo, modify_geometry_sets};

fn material(ctx: &NodeCtx, id: &str) -> Result<Option<String>, GeometryError> {
    match ctx.input(id)? {
        SocketValue::Material(m) => Ok(m),
        other => Err(ctx.err(format!(
            "input {id:?} is a {}, expected a material",
            other.kind()
        ))),
    }
}

pub fn replace_material(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let old = material(ctx, "Old")?;
    let new = material(ctx, "New")?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        // Write access copies a shared mesh, so only where a slot changes.
        if s.mesh.as_ref().is_some_and(|m| m.materials.contains(&old)) {
            for slot in s.mesh_mut().unwrap().materials.iter_mut() {
                if *slot == old {
                    slot.clone_from(&new);
                }
            }
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}
