//! Edges to Face Groups (`node_geo_edges_to_face_groups`): faces joined across every edge
//! that is not a Boundary Edge, each group numbered in order of its first face
//! (`AtomicDisjointSet::calc_reduced_ids`, as Mesh Island numbers vertices). Adapted from
//! faces to the domain asked for; 0 off meshes.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct FaceGroups {
    boundary: Field,
}

fn find(parent: &mut [usize], mut x: usize) -> usize {
    while parent[x] != x {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    x
}

impl FieldInput for FaceGroups {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::Int(vec![0; ctx.component.domain_size(domain)]));
        };
        let b = FieldContext::new(ComponentRef::Mesh(m)).eval(
            &self.boundary,
            Domain::Edge,
            DataType::Bool,
        )?;
        let b = b.as_bool();
        let nf = m.face_count();
        let mut parent: Vec<usize> = (0..nf).collect();
        // The first face seen on each edge; later faces on a non-boundary edge join it.
        let mut first = vec![usize::MAX; m.edge_count()];
        for f in 0..nf {
            for c in m.face(f) {
                let e = m.corner_edges[c] as usize;
                if b[e] {
                    continue;
                }
                if first[e] == usize::MAX {
                    first[e] = f;
                    continue;
                }
                let (x, y) = (find(&mut parent, first[e]), find(&mut parent, f));
                if x != y {
                    parent[x.max(y)] = x.min(y);
                }
            }
        }
        let mut id_of_root = vec![-1i32; nf];
        let mut next = 0;
        let ids: Vec<i32> = (0..nf)
            .map(|f| {
                let r = find(&mut parent, f);
                if id_of_root[r] < 0 {
                    id_of_root[r] = next;
                    next += 1;
                }
                id_of_root[r]
            })
            .collect();
        Ok(ctx.component.adapt(&Array::Int(ids), Domain::Face, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Face)
    }
}

pub fn edges_to_face_groups(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let boundary = ctx.field("Boundary Edges", DataType::Bool)?;
    Ok(outputs([(
        "Face Group ID",
        SocketValue::Field(Field::input(FaceGroups { boundary })),
    )]))
}
