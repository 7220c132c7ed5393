//! Shortest Edge Paths (`node_geo_input_shortest_edge_paths`): Dijkstra over the mesh
//! edges from every End Vertex at once, Edge Cost per edge (negative costs count as 0).
//! Next Vertex Index is the vertex one step closer to the nearest end (itself for ends and
//! unreachable vertices); Total Cost the summed cost to it (0 where unreachable).
//!
//! The result is Blender's bit for bit, ties included: the queue pops the lowest (cost,
//! vertex index) pair as `std::priority_queue<pair<float, int>, greater>` does, and each
//! vertex's edges are relaxed in edge index order (`build_vert_to_edge_map`), a neighbour
//! taking a new predecessor only on a strictly lower cost.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput};
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;

/// A queue entry ordered so the max-heap pops the lowest cost, then the lowest vertex.
#[derive(PartialEq)]
struct Entry(f32, i32);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // `std::greater<pair>`: compare (cost, index) lexicographically, reversed.
        o.0.partial_cmp(&self.0)
            .unwrap_or(Ordering::Equal)
            .then(o.1.cmp(&self.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Next vertex (-1 where none was found) and cost (`f32::MAX` where unreached).
fn shortest_paths(mesh: &Mesh, ends: &[bool], edge_cost: &[f32]) -> (Vec<i32>, Vec<f32>) {
    let n = mesh.vertex_count();
    let mut offsets = vec![0usize; n + 1];
    for e in &mesh.edges {
        offsets[e[0] as usize + 1] += 1;
        offsets[e[1] as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut vert_edges = vec![0usize; offsets[n]];
    for (i, e) in mesh.edges.iter().enumerate() {
        for v in [e[0] as usize, e[1] as usize] {
            vert_edges[fill[v]] = i;
            fill[v] += 1;
        }
    }
    let mut next = vec![-1i32; n];
    let mut cost = vec![f32::MAX; n];
    let mut visited = vec![false; n];
    let mut queue = BinaryHeap::new();
    for (v, _) in ends.iter().enumerate().filter(|(_, e)| **e) {
        cost[v] = 0.0;
        queue.push(Entry(0.0, v as i32));
    }
    while let Some(Entry(c, v)) = queue.pop() {
        let v = v as usize;
        if visited[v] {
            continue;
        }
        visited[v] = true;
        for &e in &vert_edges[offsets[v]..offsets[v + 1]] {
            let [a, b] = mesh.edges[e];
            let other = if a as usize == v { b } else { a } as usize;
            if visited[other] {
                continue;
            }
            let new_cost = c + edge_cost[e].max(0.0);
            if new_cost < cost[other] {
                cost[other] = new_cost;
                next[other] = v as i32;
                queue.push(Entry(new_cost, other as i32));
            }
        }
    }
    (next, cost)
}

#[derive(Debug)]
struct ShortestPaths {
    end: Field,
    cost: Field,
    /// Total Cost rather than Next Vertex Index.
    total: bool,
}

impl FieldInput for ShortestPaths {
    fn data_type(&self) -> DataType {
        if self.total {
            DataType::Float
        } else {
            DataType::Int
        }
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(mesh) = ctx.component else {
            return Ok(Array::zeros(
                self.data_type(),
                ctx.component.domain_size(domain),
            ));
        };
        let edge_cost = ctx.eval(&self.cost, Domain::Edge, DataType::Float)?;
        let ends = ctx.eval(&self.end, Domain::Point, DataType::Bool)?;
        let ends = ends.as_bool();
        let n = mesh.vertex_count();
        let out = if !ends.iter().any(|e| *e) {
            if self.total {
                Array::Float(vec![0.0; n])
            } else {
                Array::Int((0..n as i32).collect())
            }
        } else {
            let (next, cost) = shortest_paths(mesh, &ends, &edge_cost.as_float());
            if self.total {
                Array::Float(
                    cost.iter()
                        .map(|c| if *c == f32::MAX { 0.0 } else { *c })
                        .collect(),
                )
            } else {
                Array::Int(
                    next.iter()
                        .enumerate()
                        .map(|(i, v)| if *v == -1 { i as i32 } else { *v })
                        .collect(),
                )
            }
        };
        Ok(ctx.component.adapt(&out, Domain::Point, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Point)
    }
}

pub fn shortest_edge_paths(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let end = ctx.field("End Vertex", DataType::Bool)?;
    let cost = ctx.field("Edge Cost", DataType::Float)?;
    let mut out = Outputs::new();
    for (id, total) in [("Next Vertex Index", false), ("Total Cost", true)] {
        out.insert(
            id.into(),
            SocketValue::Field(Field::input(ShortestPaths {
                end: end.clone(),
                cost: cost.clone(),
                total,
            })),
        );
    }
    Ok(out)
}
