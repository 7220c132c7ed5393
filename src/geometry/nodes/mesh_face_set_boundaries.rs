//! Face Set Boundaries (`node_geo_mesh_face_set_boundaries`): true on the edges where two
//! faces of different Face Set values meet. Faces are walked in order and each edge
//! compares a face's value with the last face seen on it, as Blender does, so a mesh
//! boundary edge (one face) is not a face set boundary. Adapted from edges to the domain
//! asked for; false off meshes.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct FaceSetBoundaries {
    face_set: Field,
}

impl FieldInput for FaceSetBoundaries {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::Bool(vec![false; ctx.component.domain_size(domain)]));
        };
        let sets = FieldContext::new(ComponentRef::Mesh(m)).eval(
            &self.face_set,
            Domain::Face,
            DataType::Int,
        )?;
        let sets = sets.as_int();
        let ne = m.edge_count();
        let mut boundary = vec![false; ne];
        let mut last: Vec<Option<i32>> = vec![None; ne];
        for (f, &set) in sets.iter().enumerate() {
            for c in m.face(f) {
                let e = m.corner_edges[c] as usize;
                if last[e].is_some_and(|s| s != set) {
                    boundary[e] = true;
                }
                last[e] = Some(set);
            }
        }
        Ok(ctx
            .component
            .adapt(&Array::Bool(boundary), Domain::Edge, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Edge)
    }
}

pub fn face_set_boundaries(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let face_set = ctx.field("Face Set", DataType::Int)?;
    Ok(outputs([(
        "Boundary Edges",
        SocketValue::Field(Field::input(FaceSetBoundaries { face_set })),
    )]))
}
