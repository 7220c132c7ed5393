//! Node-graph evaluation shared by shader graphs and Geometry Nodes.
//!
//! Each node family gets its own file here, named as Blender names it (math, noise,
//! voronoi, ramp, ...). Until a family is implemented and proven against Blender's
//! numbers, `support` reports it as unsupported: `blendsynth inspect` must never
//! claim a node that would be evaluated as something else.

pub mod graph;

/// How blendsynth handles a node type (by its `bl_idname`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    /// Evaluated with Blender's semantics and covered by the conformance suite.
    Supported,
    /// Graph structure, resolved when a tree is compiled (frames, reroutes, group
    /// sockets, group nodes); nothing to evaluate.
    Structural,
    /// Not implemented yet: a scene using it cannot be evaluated faithfully.
    Unsupported,
}

/// Node types that only shape the graph: frames and reroutes are dropped, group nodes
/// are inlined, group input/output nodes become the group's boundary.
const STRUCTURAL: &[&str] = &[
    "NodeFrame",
    "NodeReroute",
    "NodeGroupInput",
    "NodeGroupOutput",
    "ShaderNodeGroup",
    "GeometryNodeGroup",
];

/// Evaluated node types, added family by family as each passes the Blender
/// conformance suite.
const SUPPORTED: &[&str] = &[];

pub fn support(bl_idname: &str) -> Support {
    if STRUCTURAL.contains(&bl_idname) {
        Support::Structural
    } else if SUPPORTED.contains(&bl_idname) {
        Support::Supported
    } else {
        Support::Unsupported
    }
}
