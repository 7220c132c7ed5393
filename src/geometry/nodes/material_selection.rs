//! Material Selection (`node_geo_material_selection.cc`): true on the faces of a mesh
//! (the curves of a Curves geometry) whose material index names a slot holding the
//! material, adapted from that domain to the one asked for; false when no slot holds it,
//! and on points and instances.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct MaterialSelection {
    material: Option<String>,
}

impl FieldInput for MaterialSelection {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let (slots, attributes, own) = match ctx.component {
            ComponentRef::Mesh(m) => (&m.materials, &m.attributes, Domain::Face),
            ComponentRef::Curves(c) => (&c.materials, &c.attributes, Domain::Curve),
            _ => return Ok(Array::Bool(vec![false; ctx.component.domain_size(domain)])),
        };
        let n = ctx.component.domain_size(own);
        let holding: Vec<i32> = (0..slots.len())
            .filter(|&i| slots[i] == self.material)
            .map(|i| i as i32)
            .collect();
        let selected = match attributes.named("material_index") {
            _ if holding.is_empty() => vec![false; n],
            Some(a) => a
                .data
                .as_int()
                .iter()
                .map(|i| holding.contains(i))
                .collect(),
            None => vec![holding.contains(&0); n],
        };
        Ok(ctx.component.adapt(&Array::Bool(selected), own, domain))
    }
    fn preferred_domain(&self, ctx: &FieldContext) -> Option<Domain> {
        match ctx.component {
            ComponentRef::Curves(_) => Some(Domain::Curve),
            _ => Some(Domain::Face),
        }
    }
}

pub fn material_selection(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let material = match ctx.input("Material")? {
        SocketValue::Material(m) => m,
        _ => None,
    };
    Ok(outputs([(
        "Selection",
        SocketValue::Field(Field::input(MaterialSelection { material })),
    )]))
}
