//! Edge Paths to Selection (`node_geo_edge_paths_to_selection`): the edges on the paths
//! that Next Vertex Index links walk from each start vertex (as Shortest Edge Paths
//! gives them). Every start is selected first and a walk stops at a selected vertex, at
//! a vertex pointing to itself or at an index out of range; an edge is selected when
//! both its vertices are and one is the other's next vertex.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

#[derive(Debug)]
struct PathsToSelection {
    start: Field,
    next: Field,
}

impl FieldInput for PathsToSelection {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(mesh) = ctx.component else {
            return Ok(Array::Bool(vec![false; ctx.component.domain_size(domain)]));
        };
        let next = ctx.eval(&self.next, Domain::Point, DataType::Int)?;
        let next = next.as_int();
        let start = ctx.eval(&self.start, Domain::Point, DataType::Bool)?;
        let start = start.as_bool();
        let n = mesh.vertex_count();
        let mut selected = start.to_vec();
        let valid = |v: i32| v >= 0 && (v as usize) < n;
        for s in (0..n).filter(|&i| start[i]) {
            let mut at = s;
            while next[at] != at as i32 && valid(next[at]) && !selected[next[at] as usize] {
                at = next[at] as usize;
                selected[at] = true;
            }
        }
        let edges: Vec<bool> = mesh
            .edges
            .iter()
            .map(|&[a, b]| {
                selected[a as usize]
                    && selected[b as usize]
                    && (a as i32 == next[b as usize] || b as i32 == next[a as usize])
            })
            .collect();
        Ok(ctx
            .component
            .adapt(&Array::Bool(edges), Domain::Edge, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Edge)
    }
}

pub fn edge_paths_to_selection(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let start = ctx.field("Start Vertices", DataType::Bool)?;
    let next = ctx.field("Next Vertex Index", DataType::Int)?;
    let mut out = Outputs::new();
    out.insert(
        "Selection".into(),
        SocketValue::Field(Field::input(PathsToSelection { start, next })),
    );
    Ok(out)
}
