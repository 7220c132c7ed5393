//! The order a material with bumps is compiled in: like Cycles' refine_bump_nodes and
//! bump_from_displacement, the subgraph feeding a Bump node's Height (or the Material
//! Output's Displacement) is compiled again as a dx and a dy copy whose coordinate nodes
//! read the shading point moved by the ray differentials. The displacement's copies run
//! first, so every later node (and every closure) sees the bumped normal.

use crate::nodes::graph::{FlatGraph, Source};

use super::bump::{BumpPoint, DEFAULT_FILTER_WIDTH};

/// A copy of (part of) the graph: copy 0 is the graph itself.
#[derive(Debug, Clone, Copy)]
pub struct GraphCopy {
    pub point: BumpPoint,
    pub filter_width: f32,
}

#[derive(Debug, Clone, Copy)]
pub enum Step {
    /// Compile flat node `node` into copy `copy`.
    Node { node: usize, copy: usize },
    /// The displacement's three copies are compiled: bump the shading normal.
    DisplacementBump,
    /// The displacement's centre copy is compiled: its value moves the vertices.
    DisplacementValue,
}

#[derive(Debug, Clone)]
pub struct Schedule {
    pub copies: Vec<GraphCopy>,
    pub steps: Vec<Step>,
    /// Per flat node: for a Bump node with a linked Height, its (dx, dy) copies.
    pub bump_copies: Vec<Option<(usize, usize)>>,
    /// The displacement's (centre, dx, dy) copies, when it is bumped.
    pub displacement: Option<(usize, usize, usize)>,
    /// The copy whose Displacement is the value vertices move by (true displacement).
    pub displacement_value: Option<usize>,
}

fn linked_node(g: &FlatGraph, node: usize, input: &str) -> Option<usize> {
    match g.nodes[node].input(input)?.sources.first() {
        Some(Source::Link { node, .. }) => Some(*node),
        _ => None,
    }
}

/// Every node `start` depends on, itself included, as a mask over the flat nodes.
fn dependencies(g: &FlatGraph, start: usize) -> Vec<bool> {
    let mut mark = vec![false; g.nodes.len()];
    let mut todo = vec![start];
    while let Some(i) = todo.pop() {
        if std::mem::replace(&mut mark[i], true) {
            continue;
        }
        for inp in &g.nodes[i].inputs {
            for s in &inp.sources {
                if let Source::Link { node, .. } = s {
                    todo.push(*node);
                }
            }
        }
    }
    mark
}

fn is_bump(g: &FlatGraph, i: usize) -> bool {
    g.nodes[i].node.bl_idname == "ShaderNodeBump" && linked_node(g, i, "Height").is_some()
}

/// A Bump node's Filter Width: Cycles takes it as a constant of the compiled program.
pub fn filter_width(g: &FlatGraph, i: usize) -> Result<f32, String> {
    let n = &g.nodes[i];
    match n.input("Filter Width").and_then(|inp| inp.sources.first()) {
        None => Ok(DEFAULT_FILTER_WIDTH),
        Some(Source::Default(sock)) => Ok(sock
            .default_value
            .as_ref()
            .and_then(|v| v.as_f64())
            .map_or(DEFAULT_FILTER_WIDTH, |v| v as f32)),
        Some(Source::Nothing) => Ok(0.0),
        Some(_) => Err(format!(
            "node {:?}: a linked Filter Width is not supported (Cycles reads it as a constant)",
            n.path
        )),
    }
}

fn add_copies(
    g: &FlatGraph,
    s: &mut Schedule,
    deps: &[bool],
    points: &[BumpPoint],
    width: f32,
) -> Result<Vec<usize>, String> {
    if let Some(i) = (0..g.nodes.len()).find(|&i| deps[i] && is_bump(g, i)) {
        return Err(format!(
            "node {:?}: a Bump inside another bump's height is not supported yet",
            g.nodes[i].path
        ));
    }
    let mut out = Vec::new();
    for &point in points {
        let copy = s.copies.len();
        s.copies.push(GraphCopy {
            point,
            filter_width: width,
        });
        s.steps.extend(
            (0..g.nodes.len())
                .filter(|&i| deps[i])
                .map(|node| Step::Node { node, copy }),
        );
        out.push(copy);
    }
    Ok(out)
}

/// The compile order. `bump`: the Material Output's Displacement is bumped; `value`: it
/// is also a value of its own (true displacement). The centre copy's ops come first, so
/// the renderer can run them alone at a vertex.
pub fn schedule(g: &FlatGraph, bump: bool, value: bool) -> Result<Schedule, String> {
    let mut s = Schedule {
        copies: vec![GraphCopy {
            point: BumpPoint::Center,
            filter_width: 0.0,
        }],
        steps: Vec::new(),
        bump_copies: vec![None; g.nodes.len()],
        displacement: None,
        displacement_value: None,
    };
    if bump || value {
        if let Some(d) = linked_node(g, g.root, "Displacement") {
            let deps = dependencies(g, d);
            let c = add_copies(g, &mut s, &deps, &[BumpPoint::Center], DEFAULT_FILTER_WIDTH)?[0];
            if value {
                s.displacement_value = Some(c);
                s.steps.push(Step::DisplacementValue);
            }
            if bump {
                let xy = add_copies(
                    g,
                    &mut s,
                    &deps,
                    &[BumpPoint::Dx, BumpPoint::Dy],
                    DEFAULT_FILTER_WIDTH,
                )?;
                s.displacement = Some((c, xy[0], xy[1]));
                s.steps.push(Step::DisplacementBump);
            }
        }
    }
    for i in 0..g.nodes.len() {
        if is_bump(g, i) {
            let deps = dependencies(g, linked_node(g, i, "Height").unwrap_or(i));
            let width = filter_width(g, i)?;
            let c = add_copies(g, &mut s, &deps, &[BumpPoint::Dx, BumpPoint::Dy], width)?;
            s.bump_copies[i] = Some((c[0], c[1]));
        }
        s.steps.push(Step::Node { node: i, copy: 0 });
    }
    Ok(s)
}
