//! Material Index and Set Material Index (`node_geo_input_material_index.cc`,
//! `node_geo_set_material_index.cc`): the `material_index` attribute read as a field (0
//! where it is missing), and written on the selected faces of meshes, the value clamped
//! to Blender's slot range by the attribute's validator (0 to MAXMAT); the other faces keep
//! theirs. Other components are left as they are.

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// Blender's `MAXMAT`: the material index validator clamps to 0..=MAXMAT.
const MAXMAT: i32 = 32767;

pub fn material_index(_ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let f = Field::input(AttributeInput {
        id: AttrId::named("material_index"),
        ty: DataType::Int,
    });
    Ok(outputs([("Material Index", SocketValue::Field(f))]))
}

pub fn set_material_index(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let index = ctx.field("Material Index", DataType::Int)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let n = m.face_count();
        if n == 0 {
            return Ok(());
        }
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            Domain::Face,
            &[(&sel, DataType::Bool), (&index, DataType::Int)],
        )?;
        let (sel, index) = (r[0].as_bool(), r[1].as_int());
        let mut values = match m.attributes.named("material_index") {
            Some(a) if a.domain == Domain::Face => a.data.as_int().into_owned(),
            _ => vec![0; n],
        };
        for f in 0..n {
            if sel[f] {
                values[f] = index[f].clamp(0, MAXMAT);
            }
        }
        // Our reference would make `mesh_mut` deep-copy the mesh.
        drop(m);
        s.mesh_mut().unwrap().attributes.set(
            AttrId::named("material_index"),
            Domain::Face,
            Array::Int(values),
        );
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}
