//! A node tree flattened the way Blender evaluates it, shared by the shader compiler and
//! the Geometry Nodes evaluator: node groups inlined (recursively, each instance apart),
//! reroutes followed, frames dropped, muted nodes passing their inputs through, muted and
//! invalid links treated as absent, unavailable sockets ignored, and only what an output
//! node can reach kept. Nodes come out in dependency order (inputs first).

use std::collections::HashMap;

use serde_json::Value;

use crate::scene::{Link, Node, NodeTree, Socket};

/// Where an input's value comes from after flattening.
#[derive(Debug, Clone)]
pub enum Source<'a> {
    /// Output `output` of flat node `node`; `kind` is that output's socket type
    /// (VALUE, VECTOR, RGBA, ...), so the consumer can apply Blender's implicit conversion.
    Link {
        node: usize,
        output: usize,
        kind: &'a str,
    },
    /// A socket's own value: the unlinked input's default, or the default of a group
    /// socket that was left unlinked outside the group.
    Default(&'a Socket),
    /// An input of the outermost tree (a Geometry Nodes modifier input), by interface
    /// identifier.
    GroupInput(&'a str),
    /// An unlinked group input whose interface socket has a field as its Default Input
    /// (`InterfaceItem::default_input_field`: Index, Position, ...).
    DefaultInput(&'a str),
    /// Nothing: an unlinked reroute, or a muted node's output without a pass-through.
    /// Blender gives the socket type's zero value.
    Nothing,
}

#[derive(Debug, Clone)]
pub struct FlatInput<'a> {
    pub socket: &'a Socket,
    /// One source, or several for a multi-input socket (Join Geometry), in link order.
    pub sources: Vec<Source<'a>>,
}

#[derive(Debug, Clone)]
pub struct FlatNode<'a> {
    /// The node's path through the groups it was inlined from: `Group > Inner > Math`.
    pub path: String,
    pub node: &'a Node,
    /// Inputs in socket order; unavailable inputs (disabled by the node's mode) are left
    /// out, so look them up by identifier (`input`).
    pub inputs: Vec<FlatInput<'a>>,
}

impl<'a> FlatNode<'a> {
    pub fn input(&self, identifier: &str) -> Option<&FlatInput<'a>> {
        self.inputs
            .iter()
            .find(|i| i.socket.identifier == identifier)
    }
    pub fn property(&self, key: &str) -> Option<&'a Value> {
        self.node.properties.get(key)
    }
}

#[derive(Debug, Clone)]
pub struct FlatGraph<'a> {
    pub nodes: Vec<FlatNode<'a>>,
    /// The flat index of the output node the graph was built from.
    pub root: usize,
}

/// A graph that cannot be evaluated as Blender would: errors name the tree and node.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GraphError(pub String);

impl std::fmt::Display for GraphError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for GraphError {}

/// One inlined instance of a tree: the root tree, or a group node's group.
struct Instance<'a> {
    tree: &'a NodeTree,
    prefix: String,
    /// The instance this group node lives in, and the group node.
    parent: Option<(usize, &'a Node)>,
}

struct Builder<'a> {
    groups: &'a [NodeTree],
    instances: Vec<Instance<'a>>,
    children: HashMap<(usize, &'a str), usize>,
    done: HashMap<(usize, &'a str), usize>,
    in_progress: Vec<(usize, &'a str)>,
    nodes: Vec<FlatNode<'a>>,
}

/// Flattens `tree` from its output node `root` (e.g. the active Material Output).
/// `groups` are the file's node groups, which group nodes name.
pub fn flatten<'a>(
    tree: &'a NodeTree,
    groups: &'a [NodeTree],
    root: &str,
) -> Result<FlatGraph<'a>, GraphError> {
    flatten_with(tree, groups, root, &[]).map(|(g, _)| g)
}

/// `flatten`, also evaluating the nodes at the paths `extra` (outputs Cycles runs beside
/// the main one, such as AOV Outputs: the names of the group nodes down to the node,
/// then its own); returns their flat indices too.
pub fn flatten_with<'a>(
    tree: &'a NodeTree,
    groups: &'a [NodeTree],
    root: &str,
    extra: &[Vec<&str>],
) -> Result<(FlatGraph<'a>, Vec<usize>), GraphError> {
    let mut b = Builder {
        groups,
        instances: vec![Instance {
            tree,
            prefix: String::new(),
            parent: None,
        }],
        children: HashMap::new(),
        done: HashMap::new(),
        in_progress: Vec::new(),
        nodes: Vec::new(),
    };
    let node = find(tree, root)
        .ok_or_else(|| GraphError(format!("node tree {:?} has no node {root:?}", tree.name)))?;
    let root = b.node(0, node)?;
    let mut more = Vec::with_capacity(extra.len());
    for path in extra {
        let mut inst = 0;
        for (depth, name) in path.iter().enumerate() {
            let t = b.instances[inst].tree;
            let node = find(t, name).ok_or_else(|| {
                GraphError(format!("node tree {:?} has no node {name:?}", t.name))
            })?;
            if depth + 1 < path.len() {
                inst = b.group_instance(inst, node)?;
            } else {
                more.push(b.node(inst, node)?);
            }
        }
    }
    Ok((
        FlatGraph {
            nodes: b.nodes,
            root,
        },
        more,
    ))
}

/// The output node Blender renders with: among nodes of type `bl_idname` whose
/// `target` (if any) is ALL or `target`, the one marked active, else the first.
pub fn active_output<'a>(tree: &'a NodeTree, bl_idname: &str, target: &str) -> Option<&'a Node> {
    let candidates: Vec<&Node> = tree
        .nodes
        .iter()
        .filter(|n| n.bl_idname == bl_idname)
        .filter(
            |n| match n.properties.get("target").and_then(Value::as_str) {
                Some(t) => t == "ALL" || t == target,
                None => true,
            },
        )
        .collect();
    candidates
        .iter()
        .find(|n| {
            n.properties
                .get("is_active_output")
                .and_then(Value::as_bool)
                == Some(true)
        })
        .or(candidates.first())
        .copied()
}

fn find<'a>(tree: &'a NodeTree, name: &str) -> Option<&'a Node> {
    tree.nodes.iter().find(|n| n.name == name)
}

fn is_group_node(n: &Node) -> bool {
    n.node_tree.is_some() && n.bl_idname.ends_with("NodeGroup")
}

impl<'a> Builder<'a> {
    fn path(&self, inst: usize, node: &Node) -> String {
        format!("{}{}", self.instances[inst].prefix, node.name)
    }

    fn err(&self, inst: usize, node: &Node, msg: impl std::fmt::Display) -> GraphError {
        let root = &self.instances[0].tree.name;
        GraphError(format!(
            "node tree {root:?}, node {:?}: {msg}",
            self.path(inst, node)
        ))
    }

    /// Adds an evaluated node (its inputs first) and returns its flat index.
    fn node(&mut self, inst: usize, node: &'a Node) -> Result<usize, GraphError> {
        let key = (inst, node.name.as_str());
        if let Some(&i) = self.done.get(&key) {
            return Ok(i);
        }
        if self.in_progress.contains(&key) {
            return Err(self.err(inst, node, "is part of a cycle of links"));
        }
        self.in_progress.push(key);
        // A zone's output node needs its input node (Repeat's Iterations, For Each's
        // Geometry) even when nothing in the zone reads the input node's outputs; it
        // comes first, so a zone's nodes lie between its input and output in flat order.
        let tree = self.instances[inst].tree;
        if let Some(input) = tree.nodes.iter().find(|n| {
            n.properties.get("paired_output").and_then(Value::as_str) == Some(node.name.as_str())
        }) {
            self.node(inst, input)?;
        }
        let mut inputs = Vec::with_capacity(node.inputs.len());
        for s in node.inputs.iter().filter(|s| s.enabled) {
            let sources = self.input(inst, node, s)?;
            inputs.push(FlatInput { socket: s, sources });
        }
        self.in_progress.pop();
        let path = self.path(inst, node);
        self.nodes.push(FlatNode { path, node, inputs });
        let i = self.nodes.len() - 1;
        self.done.insert(key, i);
        Ok(i)
    }

    /// The sources feeding input socket `s` of `node`.
    fn input(
        &mut self,
        inst: usize,
        node: &'a Node,
        s: &'a Socket,
    ) -> Result<Vec<Source<'a>>, GraphError> {
        let tree = self.instances[inst].tree;
        let links: Vec<_> = links_into(tree, node, s).collect();
        if links.is_empty() {
            return Ok(vec![if s.default_value.is_some() {
                Source::Default(s)
            } else {
                Source::Nothing
            }]);
        }
        let mut out = Vec::with_capacity(links.len());
        for l in links {
            let from = find(tree, &l.from_node).ok_or_else(|| {
                self.err(
                    inst,
                    node,
                    format!("links from missing node {:?}", l.from_node),
                )
            })?;
            out.push(self.output(inst, from, &l.from_socket)?);
        }
        Ok(out)
    }

    /// What output `identifier` of `node` provides, seeing through structure.
    fn output(
        &mut self,
        inst: usize,
        node: &'a Node,
        identifier: &str,
    ) -> Result<Source<'a>, GraphError> {
        let index = node
            .outputs
            .iter()
            .position(|o| o.identifier == identifier)
            .ok_or_else(|| self.err(inst, node, format!("has no output {identifier:?}")))?;
        if node.bl_idname == "NodeReroute" {
            return self.single(inst, node, &node.inputs[0]);
        }
        if node.bl_idname == "NodeGroupInput" {
            return match self.instances[inst].parent {
                None => Ok(Source::GroupInput(&node.outputs[index].identifier)),
                Some((outer, group_node)) => {
                    let s = group_node
                        .inputs
                        .iter()
                        .find(|s| s.identifier == identifier)
                        .ok_or_else(|| {
                            self.err(
                                outer,
                                group_node,
                                format!("has no input {identifier:?} for its group's interface"),
                            )
                        })?;
                    let outer_tree = self.instances[outer].tree;
                    if links_into(outer_tree, group_node, s).next().is_none() {
                        if let Some(f) = default_input_field(self.instances[inst].tree, identifier)
                        {
                            return Ok(Source::DefaultInput(f));
                        }
                    }
                    self.single(outer, group_node, s)
                }
            };
        }
        if node.mute {
            return match pass_through(node, index) {
                Some(s) => self.single(inst, node, s),
                None => Ok(Source::Nothing),
            };
        }
        if is_group_node(node) {
            let child = self.group_instance(inst, node)?;
            let tree = self.instances[child].tree;
            let out = active_output(tree, "NodeGroupOutput", "").ok_or_else(|| {
                self.err(
                    inst,
                    node,
                    format!("group {:?} has no Group Output node", tree.name),
                )
            })?;
            let s = out
                .inputs
                .iter()
                .find(|s| s.identifier == identifier)
                .ok_or_else(|| {
                    self.err(
                        inst,
                        node,
                        format!("group {:?} has no output {identifier:?}", tree.name),
                    )
                })?;
            return self.single(child, out, s);
        }
        let i = self.node(inst, node)?;
        Ok(Source::Link {
            node: i,
            output: index,
            kind: &node.outputs[index].kind,
        })
    }

    /// The (first) source of an input that is passed through (reroute, group boundary,
    /// muted node).
    fn single(
        &mut self,
        inst: usize,
        node: &'a Node,
        s: &'a Socket,
    ) -> Result<Source<'a>, GraphError> {
        Ok(self
            .input(inst, node, s)?
            .into_iter()
            .next()
            .unwrap_or(Source::Nothing))
    }

    fn group_instance(&mut self, inst: usize, node: &'a Node) -> Result<usize, GraphError> {
        let key = (inst, node.name.as_str());
        if let Some(&c) = self.children.get(&key) {
            return Ok(c);
        }
        let name = node.node_tree.as_deref().unwrap_or_default();
        let tree =
            self.groups.iter().find(|g| g.name == name).ok_or_else(|| {
                self.err(inst, node, format!("names missing node group {name:?}"))
            })?;
        // A group that (indirectly) contains itself cannot be inlined.
        let mut up = Some(inst);
        while let Some(i) = up {
            if std::ptr::eq(self.instances[i].tree, tree) {
                return Err(self.err(inst, node, format!("group {name:?} contains itself")));
            }
            up = self.instances[i].parent.map(|(p, _)| p);
        }
        let prefix = format!("{}{} > ", self.instances[inst].prefix, node.name);
        self.instances.push(Instance {
            tree,
            prefix,
            parent: Some((inst, node)),
        });
        let c = self.instances.len() - 1;
        self.children.insert(key, c);
        Ok(c)
    }
}

/// The input a muted node passes to output `index`: Blender's own choice as the exporter
/// recorded it (`internal_links`), or, for exports without it, the first available input
/// of the same socket type, which is Blender's rule for the common nodes.
fn pass_through(node: &Node, index: usize) -> Option<&Socket> {
    let out = &node.outputs[index];
    if !node.internal_links.is_empty() {
        let link = node
            .internal_links
            .iter()
            .find(|l| l.to == out.identifier)?;
        return node.inputs.iter().find(|s| s.identifier == link.from);
    }
    node.inputs.iter().find(|s| s.enabled && s.kind == out.kind)
}

/// The live links into input socket `s` of `node`: not muted, valid, and not from a node
/// Cycles ignores (Cycles' sync drops those).
fn links_into<'t>(
    tree: &'t NodeTree,
    node: &'t Node,
    s: &'t Socket,
) -> impl Iterator<Item = &'t Link> {
    tree.links
        .iter()
        .filter(move |l| {
            l.to_node == node.name && l.to_socket == s.identifier && !l.is_muted && l.is_valid
        })
        .filter(move |l| {
            find(tree, &l.from_node)
                .is_none_or(|n| !super::IGNORED_BY_CYCLES.contains(&n.bl_idname.as_str()))
        })
}

/// The field an unlinked input `identifier` of group `tree` reads, if its Default Input is
/// one.
pub fn default_input_field<'a>(tree: &'a NodeTree, identifier: &str) -> Option<&'a str> {
    tree.interface
        .iter()
        .find(|it| {
            it.identifier.as_deref() == Some(identifier) && it.in_out.as_deref() == Some("INPUT")
        })
        .and_then(|it| it.default_input_field())
}
