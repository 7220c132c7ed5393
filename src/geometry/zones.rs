//! Zones (Repeat, For Each Geometry Element): a zone's body is the nodes between its
//! input node and its output node that depend on the input node. The flat graph has no
//! back link, so the evaluator runs a zone by giving the input node its values for one
//! run (`Evaluator::preset`), evaluating the output node's inputs, and forgetting the
//! body's results before the next run. Nodes inside the zone that do not read the input
//! node are evaluated once, as their value is the same in every run.

use std::collections::HashMap;

use serde_json::Value as Json;

use super::error::GeometryError;
use super::eval::{NodeCtx, Outputs};
use super::field::Field;
use super::limits;
use super::set::GeometrySet;
use super::value::SocketValue;
use crate::nodes::graph::Source;

/// A zone found from its output node.
pub struct Zone {
    /// Flat index of the zone's input node.
    pub input: usize,
    /// The body: the input node and every node that depends on it, up to (not
    /// including) the output node.
    pub body: Vec<usize>,
}

impl Zone {
    /// The zone whose output node `ctx` is: its input node is the node of the same
    /// tree instance whose `paired_output` names it (flattening puts it first).
    pub fn of(ctx: &NodeCtx, input_type: &str) -> Result<Zone, GeometryError> {
        let graph = &ctx.ev.graph;
        let here = ctx.flat();
        let prefix = &here.path[..here.path.len() - here.node.name.len()];
        let input = (0..ctx.idx)
            .find(|&i| {
                let n = &graph.nodes[i];
                n.node.bl_idname == input_type
                    && n.path.strip_suffix(n.node.name.as_str()) == Some(prefix)
                    && n.node
                        .properties
                        .get("paired_output")
                        .and_then(Json::as_str)
                        == Some(here.node.name.as_str())
            })
            .ok_or_else(|| {
                ctx.err(format!(
                    "no {input_type} node is paired with this zone output (paired_output)"
                ))
            })?;
        // Flat order is dependency order, so one pass finds everything reading the input.
        let mut depends = vec![false; ctx.idx - input];
        depends[0] = true;
        for i in input + 1..ctx.idx {
            depends[i - input] = graph.nodes[i].inputs.iter().any(|inp| {
                inp.sources.iter().any(|s| match s {
                    Source::Link { node, .. } => *node >= input && depends[*node - input],
                    _ => false,
                })
            });
        }
        let body = (input..ctx.idx).filter(|&i| depends[i - input]).collect();
        Ok(Zone { input, body })
    }

    /// The input node's context (its own inputs: Iterations, the initial items, ...).
    pub fn input_ctx<'e, 'a>(&self, ctx: &NodeCtx<'e, 'a>) -> NodeCtx<'e, 'a> {
        NodeCtx {
            ev: ctx.ev,
            idx: self.input,
        }
    }

    /// Counts `runs` more body runs against `limits::MAX_ZONE_ITERATIONS`.
    pub fn spend(&self, ctx: &NodeCtx, runs: u64, what: &str) -> Result<(), GeometryError> {
        let total = ctx.ev.zone_iterations.get().saturating_add(runs);
        if total > limits::MAX_ZONE_ITERATIONS {
            return Err(ctx.err(format!(
                "{what} would run zone bodies {total} times in this evaluation, more than the \
                 limit of {} (docs/limits.md)",
                limits::MAX_ZONE_ITERATIONS
            )));
        }
        ctx.ev.zone_iterations.set(total);
        Ok(())
    }

    /// Runs the body once: the input node gives `values`, and the output node's inputs
    /// `ids` are evaluated.
    pub fn run(
        &self,
        ctx: &NodeCtx,
        values: Outputs,
        ids: &[String],
    ) -> Result<Vec<SocketValue>, GeometryError> {
        ctx.ev.forget(&self.body);
        ctx.ev.preset(self.input, values);
        let r = ids.iter().map(|id| ctx.input(id)).collect();
        ctx.ev.forget(&self.body);
        r
    }
}

/// The identifiers of a node's enabled sockets whose identifiers start with `prefix`
/// (a zone's items: `Item_3`, `Main_1`, ...), in socket order.
pub fn item_ids(sockets: &[crate::scene::Socket], prefix: &str) -> Vec<String> {
    sockets
        .iter()
        .filter(|s| s.enabled && s.kind != "CUSTOM" && s.identifier.starts_with(prefix))
        .map(|s| s.identifier.clone())
        .collect()
}

/// An error when a value a zone carries from one run to the next has grown past the
/// limits: geometry over `limits::MAX_ELEMENTS` in a domain, a field deeper than
/// `limits::MAX_FIELD_DEPTH`.
pub fn check_carried(ctx: &NodeCtx, id: &str, v: &SocketValue) -> Result<(), GeometryError> {
    match v {
        SocketValue::Geometry(g) => {
            let n = largest_domain(g) as u64;
            limits::check(Some(n), &format!("item {id:?}")).map_err(|e| ctx.err(e))
        }
        SocketValue::Field(f) => {
            let d = field_depth(f, &mut HashMap::new());
            if d > limits::MAX_FIELD_DEPTH {
                return Err(ctx.err(format!(
                    "item {id:?} is a field {d} operations deep, more than the limit of {} \
                     (docs/limits.md)",
                    limits::MAX_FIELD_DEPTH
                )));
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

fn largest_domain(g: &GeometrySet) -> usize {
    let mut n = 0;
    if let Some(m) = &g.mesh {
        n = n
            .max(m.vertex_count())
            .max(m.edge_count())
            .max(m.face_count())
            .max(m.corner_count());
    }
    if let Some(p) = &g.points {
        n = n.max(p.len());
    }
    if let Some(c) = &g.curves {
        n = n.max(c.point_count());
    }
    if let Some(i) = &g.instances {
        n = n.max(i.len());
    }
    n
}

/// Longest chain of operations in a field (shared operations counted once).
fn field_depth(f: &Field, memo: &mut HashMap<usize, usize>) -> usize {
    match f {
        Field::Constant(_) | Field::Input(_) => 0,
        Field::Op(op, _) => {
            let key = std::sync::Arc::as_ptr(op) as *const u8 as usize;
            if let Some(&d) = memo.get(&key) {
                return d;
            }
            let d = 1 + op
                .inputs
                .iter()
                .map(|i| field_depth(i, memo))
                .max()
                .unwrap_or(0);
            memo.insert(key, d);
            d
        }
    }
}
