//! The Geometry Nodes evaluator: an object's modifier stack, each NODES modifier's tree
//! flattened (`nodes::graph::flatten`: groups inlined, reroutes and frames dropped, muted
//! nodes passed through) and evaluated on demand from its Group Output, each node once.
//!
//! Inputs are evaluated lazily, so a Switch only evaluates the branch it takes (an
//! unsupported node in the other branch is no error, as in Blender).

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};
use std::rc::Rc;

use serde_json::Value as Json;

use super::error::GeometryError;
use super::field::{AttributeInput, Field, IdInput, IndexInput, PositionInput};
use super::math::Mat4f;
use super::mesh::Mesh;
use super::set::GeometrySet;
use super::types::{DataType, Domain, Value};
use super::value::SocketValue;
use crate::nodes::graph::{
    active_output, default_input_field, flatten, FlatGraph, FlatNode, Source,
};
use crate::scene::{quote, Modifier, Node, NodeTree, Object, Scene};

/// A node's results, by output socket identifier.
pub type Outputs = HashMap<String, SocketValue>;

/// Everything shared while evaluating objects of one scene at one frame.
pub struct Session<'s> {
    pub scene: &'s Scene,
    pub frame: f64,
    /// World matrices at `frame`, in `scene.file.objects` order.
    pub world: Vec<Mat4f>,
    /// Per node group: each link's `multi_input_sort_id` (0 when the export has none).
    pub sort_ids: HashMap<String, Vec<i64>>,
    /// Camera data blocks at `frame` (animated), for Camera Info.
    pub cameras: Vec<crate::scene::Camera>,
    cache: RefCell<HashMap<String, GeometrySet>>,
    in_progress: RefCell<Vec<String>>,
    /// Simulation zone states, carried from the previous frame's session to this one
    /// (`nodes::simulation_zone`).
    pub(super) simulation: RefCell<SimulationStates>,
}

/// Why a mesh of `g` (or of its instances) has custom normals Blender would have moved
/// with a deformation (`Mesh::relative_normals_moved`).
fn moved_relative_normals(g: &GeometrySet, depth: u32) -> Option<String> {
    if let Some(why) = g.mesh.as_ref().and_then(|m| m.relative_normals_moved()) {
        return Some(why);
    }
    // Instance nesting is bounded where instances are made; the cap only guards this walk.
    if depth > 64 {
        return None;
    }
    g.instances.as_ref().and_then(|i| {
        i.references
            .iter()
            .filter_map(|r| r.geometry())
            .find_map(|r| moved_relative_normals(r, depth + 1))
    })
}

/// One Simulation zone's state after the frame it was last stepped at.
#[derive(Clone)]
pub struct SimulationState {
    pub frame: f64,
    pub items: Vec<SocketValue>,
}

/// Simulation states by zone (object, modifier and the zone's output node path).
pub type SimulationStates = HashMap<String, SimulationState>;

impl<'s> Session<'s> {
    pub fn new(
        scene: &'s Scene,
        frame: f64,
        world: Vec<Mat4f>,
        sort_ids: HashMap<String, Vec<i64>>,
        cameras: Vec<crate::scene::Camera>,
    ) -> Self {
        Session {
            scene,
            frame,
            world,
            sort_ids,
            cameras,
            cache: RefCell::new(HashMap::new()),
            in_progress: RefCell::new(Vec::new()),
            simulation: RefCell::new(HashMap::new()),
        }
    }

    /// This session continuing the simulation states of the previous frame's.
    pub fn with_simulation_states(self, states: SimulationStates) -> Self {
        *self.simulation.borrow_mut() = states;
        self
    }

    /// The simulation states after this session's evaluations.
    pub fn into_simulation_states(self) -> SimulationStates {
        self.simulation.into_inner()
    }

    pub fn world_matrix(&self, object: &str) -> Option<Mat4f> {
        let i = self
            .scene
            .file
            .objects
            .iter()
            .position(|o| o.name == object)?;
        self.world.get(i).copied()
    }

    /// The object's original geometry (its data, before modifiers).
    pub fn original_geometry(&self, o: &Object) -> Result<GeometrySet, GeometryError> {
        let here = format!("objects[{}]", quote(&o.name));
        match o.kind.as_str() {
            "MESH" => {
                let index = super::source::mesh_index(self.scene, o)?;
                let md = self.scene.load_mesh(index)?;
                Ok(GeometrySet::from_mesh(Mesh::from_scene(
                    &md,
                    &self.scene.file.meshes[index].materials,
                )))
            }
            "CURVE" => {
                let data = o.data.as_deref().ok_or_else(|| {
                    GeometryError::new(format!("{here}: curve object without curve data"))
                })?;
                let cu = self
                    .scene
                    .file
                    .curves
                    .iter()
                    .find(|c| c.name == data)
                    .ok_or_else(|| {
                        GeometryError::new(format!("{here}: curve {data:?} is not in the export"))
                    })?;
                let curves = super::legacy_curve::to_curves(cu).map_err(|e| e.within(&here))?;
                Ok(GeometrySet {
                    curves: Some(std::sync::Arc::new(curves)),
                    ..Default::default()
                })
            }
            "EMPTY" | "CAMERA" | "LIGHT" | "LIGHT_PROBE" | "SPEAKER" => Ok(GeometrySet::default()),
            other => Err(GeometryError::new(format!(
                "{here}: {other} objects cannot be evaluated as geometry yet"
            ))),
        }
    }

    /// The object's evaluated geometry: original data through its modifier stack.
    pub fn evaluate_object(&self, name: &str) -> Result<GeometrySet, GeometryError> {
        if let Some(g) = self.cache.borrow().get(name) {
            return Ok(g.clone());
        }
        if self.in_progress.borrow().iter().any(|n| n == name) {
            return Err(GeometryError::new(format!(
                "objects[{}]: depends on its own geometry (dependency cycle)",
                quote(name)
            )));
        }
        let o = self
            .scene
            .object(name)
            .ok_or_else(|| GeometryError::new(format!("no object named {name:?} in the export")))?;
        self.in_progress.borrow_mut().push(name.to_string());
        let result = self.evaluate_stack(o);
        self.in_progress.borrow_mut().pop();
        let g = result?;
        if let Some(why) = moved_relative_normals(&g, 0) {
            return Err(GeometryError::new(format!(
                "objects[{}]: {why}",
                quote(name)
            )));
        }
        self.cache.borrow_mut().insert(name.to_string(), g.clone());
        Ok(g)
    }

    fn evaluate_stack(&self, o: &Object) -> Result<GeometrySet, GeometryError> {
        // A bare curve path without modifiers (no bevel, extrude or fill: nothing to
        // render) gives Object Info its curves; a curve Blender meshes stays frozen.
        if o.kind == "CURVE"
            && !o.modifiers.iter().any(|m| m.show_render)
            && !super::source::curve_has_surface(self.scene, o)
        {
            return self.original_geometry(o);
        }
        match super::source::object_source(self.scene, o, self.frame, &[])? {
            super::source::Source::None => return Ok(GeometrySet::default()),
            super::source::Source::Frozen(i) => {
                let e = &self.scene.file.evaluated[i];
                let md = self.scene.load_evaluated(i)?;
                return Ok(GeometrySet::from_mesh(Mesh::from_scene(&md, &e.materials)));
            }
            super::source::Source::Mesh(_) | super::source::Source::Evaluate => {}
        }
        let mut g = self.original_geometry(o)?;
        for m in &o.modifiers {
            if !m.show_render {
                continue;
            }
            let here = format!("objects[{}].modifiers[{}]", quote(&o.name), quote(&m.name));
            if m.kind == "SUBSURF" {
                g = super::nodes::subdivision_surface::subsurf_modifier(&m.properties, g)
                    .map_err(|e| GeometryError::new(format!("{here}: {e}")))?;
                continue;
            }
            if super::modifiers::KINDS.contains(&m.kind.as_str()) {
                let world = |n: &str| self.world_matrix(n);
                let ctx = super::modifiers::Context {
                    object: &o.name,
                    world: &world,
                };
                g = super::modifiers::apply(&m.kind, &m.properties, &ctx, g)
                    .map_err(|e| GeometryError::new(format!("{here}: {e}")))?;
                continue;
            }
            if m.kind != "NODES" {
                return Err(GeometryError::new(format!("{here}: {} modifiers are not supported (only Geometry Nodes, Subdivision Surface and {})", m.kind, super::modifiers::KINDS.join(", "))));
            }
            g = self
                .evaluate_modifier(o, m, g)
                .map_err(|e| e.within(&here))?;
        }
        Ok(g)
    }

    fn evaluate_modifier(
        &self,
        o: &Object,
        m: &Modifier,
        input: GeometrySet,
    ) -> Result<GeometrySet, GeometryError> {
        let Some(group) = m.node_group.as_deref() else {
            return Ok(input);
        };
        let tree = self.scene.node_group(group).ok_or_else(|| {
            GeometryError::new(format!("node group {group:?} is not in the export"))
        })?;
        let out_node = active_output(tree, "NodeGroupOutput", "").ok_or_else(|| {
            GeometryError::new(format!(
                "node tree {:?} has no Group Output node",
                tree.name
            ))
        })?;
        let graph = flatten(tree, &self.scene.file.node_groups, &out_node.name)
            .map_err(|e| GeometryError::new(e.0))?;
        let mut inputs: HashMap<String, SocketValue> = HashMap::new();
        let mut geometry_given = false;
        for item in tree
            .interface
            .iter()
            .filter(|i| i.item_type == "SOCKET" && i.in_out.as_deref() == Some("INPUT"))
        {
            let Some(id) = item.identifier.as_deref() else {
                continue;
            };
            let kind = SocketValue::interface_kind(item.socket_type.as_deref().unwrap_or(""));
            let v = if kind == "GEOMETRY" {
                // Only the first geometry input receives the object's geometry.
                let v = if geometry_given {
                    GeometrySet::default()
                } else {
                    input.clone()
                };
                geometry_given = true;
                SocketValue::Geometry(v)
            } else if m
                .inputs
                .get(&format!("{id}_use_attribute"))
                .is_some_and(|u| u.as_bool() == Some(true) || u.as_i64() == Some(1))
            {
                let name = m
                    .inputs
                    .get(&format!("{id}_attribute_name"))
                    .and_then(Json::as_str)
                    .unwrap_or_default();
                let ty = DataType::from_socket(kind).unwrap_or(DataType::Float);
                SocketValue::Field(Field::input(AttributeInput {
                    id: super::attribute::AttrId::named(name),
                    ty,
                }))
            } else if let Some(v) = m.inputs.get(id) {
                SocketValue::from_json(kind, v)
                    .map_err(|e| GeometryError::new(format!("input {:?}: {e}", item.name)))?
            } else if let Some(v) = &item.default_value {
                SocketValue::from_json(kind, v)
                    .map_err(|e| GeometryError::new(format!("input {:?}: {e}", item.name)))?
            } else {
                SocketValue::zero(kind)
            };
            inputs.insert(id.to_string(), v);
        }
        let ev = Evaluator {
            session: self,
            tree,
            graph,
            group_inputs: inputs,
            object: o,
            modifier: m,
            memo: RefCell::new(HashMap::new()),
            busy: RefCell::new(HashSet::new()),
            zone_iterations: std::cell::Cell::new(0),
        };
        let root = &ev.graph.nodes[ev.graph.root];
        let ctx = NodeCtx {
            ev: &ev,
            idx: ev.graph.root,
        };
        let mut result = None;
        let mut outputs: Vec<(String, SocketValue)> = Vec::new();
        for inp in &root.inputs {
            if inp.socket.kind == "CUSTOM" {
                continue;
            }
            let v = ctx.input(&inp.socket.identifier)?;
            if inp.socket.kind == "GEOMETRY" {
                if result.is_none() {
                    if let SocketValue::Geometry(g) = v {
                        result = Some(g);
                    }
                }
            } else {
                outputs.push((inp.socket.identifier.clone(), v));
            }
        }
        let mut g = result.unwrap_or_default();
        // Field outputs become named attributes when the modifier names one.
        for (id, v) in outputs {
            let name = m
                .inputs
                .get(&format!("{id}_attribute_name"))
                .and_then(Json::as_str)
                .unwrap_or_default();
            if name.is_empty() {
                continue;
            }
            let SocketValue::Field(f) = v else { continue };
            let item = tree
                .interface
                .iter()
                .find(|i| i.identifier.as_deref() == Some(&id));
            let domain = item
                .and_then(|i| i.properties.get("attribute_domain"))
                .and_then(Json::as_str)
                .and_then(Domain::parse)
                .unwrap_or(Domain::Point);
            super::nodes::attribute::store(
                &mut g,
                &super::attribute::AttrId::named(name),
                domain,
                &f,
                &Field::Constant(Value::Bool(true)),
                None,
            )
            .map_err(|e| GeometryError::new(format!("output attribute {name:?}: {e}")))?;
        }
        Ok(g)
    }
}

/// Evaluates one flattened tree.
pub struct Evaluator<'a> {
    pub session: &'a Session<'a>,
    pub tree: &'a NodeTree,
    pub graph: FlatGraph<'a>,
    pub group_inputs: HashMap<String, SocketValue>,
    /// The object whose modifier this is (Self Object, relative transforms).
    pub object: &'a Object,
    /// The modifier whose tree this is (its bakes, the simulation state's key).
    pub modifier: &'a Modifier,
    memo: RefCell<HashMap<usize, Rc<Outputs>>>,
    busy: RefCell<HashSet<usize>>,
    /// Zone body runs so far, all zones together (`zones`: bounded by a limit).
    pub(super) zone_iterations: std::cell::Cell<u64>,
}

impl<'a> Evaluator<'a> {
    fn node_outputs(&self, idx: usize) -> Result<Rc<Outputs>, GeometryError> {
        if let Some(o) = self.memo.borrow().get(&idx) {
            return Ok(o.clone());
        }
        if !self.busy.borrow_mut().insert(idx) {
            return Err(GeometryError::new("cycle in the node graph"));
        }
        let ctx = NodeCtx { ev: self, idx };
        let r = super::nodes::evaluate(&ctx);
        self.busy.borrow_mut().remove(&idx);
        let out = Rc::new(r?);
        self.memo.borrow_mut().insert(idx, out.clone());
        Ok(out)
    }

    /// Drops the results of `nodes`, so they are evaluated afresh (a zone's body, once
    /// per iteration).
    pub(super) fn forget(&self, nodes: &[usize]) {
        let mut memo = self.memo.borrow_mut();
        for n in nodes {
            memo.remove(n);
        }
    }

    /// Gives node `idx` these results without evaluating it (a zone input node's
    /// values for one iteration).
    pub(super) fn preset(&self, idx: usize, outputs: Outputs) {
        self.memo.borrow_mut().insert(idx, Rc::new(outputs));
    }

    /// The node tree whose node list holds `node` (to find its links).
    fn tree_of(&self, node: &Node) -> Option<&'a NodeTree> {
        self.session
            .scene
            .file
            .node_groups
            .iter()
            .find(|t| t.nodes.iter().any(|n| std::ptr::eq(n, node)))
    }
}

/// What a node implementation sees: its inputs (evaluated on demand) and settings.
pub struct NodeCtx<'e, 'a> {
    pub ev: &'e Evaluator<'a>,
    pub idx: usize,
}

/// Node inputs that, unlinked, are a field rather than their socket value
/// (`implicit_field` in Blender's node declarations).
fn implicit_field(bl_idname: &str, identifier: &str) -> Option<Field> {
    match (bl_idname, identifier) {
        ("GeometryNodeSetPosition", "Position")
        | ("GeometryNodeSampleNearest", "Sample Position")
        | ("GeometryNodeSampleNearestSurface", "Sample Position")
        | ("GeometryNodeProximity", "Source Position")
        | ("GeometryNodeRaycast", "Source Position")
        | ("GeometryNodeMeshToPoints", "Position")
        | ("GeometryNodeIndexOfNearest", "Position") => Some(Field::input(PositionInput)),
        // Texture nodes in Geometry Nodes read the position when their vector is unlinked.
        (
            "ShaderNodeTexNoise"
            | "ShaderNodeTexVoronoi"
            | "ShaderNodeTexWave"
            | "ShaderNodeTexGradient"
            | "ShaderNodeTexMagic"
            | "ShaderNodeTexChecker"
            | "ShaderNodeTexBrick"
            | "ShaderNodeTexWhiteNoise"
            | "ShaderNodeTexMusgrave"
            | "GeometryNodeImageTexture",
            "Vector",
        ) => Some(Field::input(PositionInput)),
        ("FunctionNodeRandomValue", "ID") | ("GeometryNodeInstanceOnPoints", "Instance Index") => {
            Some(Field::input(IdInput))
        }
        ("GeometryNodeExtrudeMesh", "Offset") => Some(Field::input(super::field::NormalInput)),
        ("GeometryNodeSetInstanceTransform", "Transform") => {
            Some(super::nodes::points::instance_transform_field())
        }
        ("GeometryNodeSampleIndex", "Index") | ("GeometryNodeFieldAtIndex", "Index") => {
            Some(Field::input(IndexInput))
        }
        ("GeometryNodeCurveOfPoint" | "GeometryNodeOffsetPointInCurve", "Point Index")
        | ("GeometryNodePointsOfCurve", "Curve Index") => Some(Field::input(IndexInput)),
        _ => None,
    }
}

impl<'e, 'a> NodeCtx<'e, 'a> {
    pub fn flat(&self) -> &'e FlatNode<'a> {
        &self.ev.graph.nodes[self.idx]
    }
    pub fn node(&self) -> &'a Node {
        self.ev.graph.nodes[self.idx].node
    }
    pub fn session(&self) -> &'e Session<'a> {
        self.ev.session
    }
    /// An error naming the tree and node.
    pub fn err(&self, msg: impl std::fmt::Display) -> GeometryError {
        GeometryError::new(format!(
            "node tree {:?}, node {:?} ({}): {msg}",
            self.ev.tree.name,
            self.flat().path,
            self.node().bl_idname
        ))
    }

    pub fn prop(&self, key: &str) -> Option<&'a Json> {
        self.node().properties.get(key)
    }
    pub fn prop_str(&self, key: &str) -> Result<&'a str, GeometryError> {
        self.prop(key)
            .and_then(Json::as_str)
            .ok_or_else(|| self.err(format!("property {key:?} missing")))
    }
    pub fn prop_bool(&self, key: &str) -> Result<bool, GeometryError> {
        self.prop(key)
            .and_then(|v| v.as_bool().or_else(|| v.as_i64().map(|i| i != 0)))
            .ok_or_else(|| self.err(format!("property {key:?} missing")))
    }

    /// Whether input `id` is available in the node's current mode.
    pub fn has_input(&self, id: &str) -> bool {
        self.flat().input(id).is_some()
    }
    /// Whether output `id` is linked to anything.
    pub fn output_used(&self, id: &str) -> bool {
        self.node()
            .outputs
            .iter()
            .any(|s| s.identifier == id && s.is_linked)
    }

    fn source_value(
        &self,
        src: &Source<'a>,
        consumer_kind: &str,
    ) -> Result<SocketValue, GeometryError> {
        let v = match src {
            Source::Link { node, output, .. } => {
                let outs = self.ev.node_outputs(*node)?;
                let from = &self.ev.graph.nodes[*node];
                let id = &from.node.outputs[*output].identifier;
                match outs.get(id) {
                    Some(v) => v.clone(),
                    None => {
                        return Err(GeometryError::new(format!(
                            "node tree {:?}, node {:?}: output {id:?} is not evaluated",
                            self.ev.tree.name, from.path
                        )))
                    }
                }
            }
            Source::Default(s) => {
                let Some(dv) = &s.default_value else {
                    return Ok(SocketValue::zero(&s.kind));
                };
                SocketValue::from_json(&s.kind, dv).map_err(|e| self.err(e))?
            }
            // A modifier input whose Default Input is a field is not set on the modifier:
            // Blender evaluates the field.
            Source::GroupInput(id) => match default_input_field(self.ev.tree, id) {
                Some(kind) => self.default_input(kind)?,
                None => self
                    .ev
                    .group_inputs
                    .get(*id)
                    .cloned()
                    .unwrap_or_else(|| SocketValue::zero(consumer_kind)),
            },
            Source::DefaultInput(kind) => self.default_input(kind)?,
            Source::Nothing => SocketValue::zero(consumer_kind),
        };
        Ok(coerce(v, consumer_kind))
    }

    /// The field a group input's Default Input names (`NodeDefaultInputType`).
    fn default_input(&self, kind: &str) -> Result<SocketValue, GeometryError> {
        let f = match kind {
            "INDEX" => Field::input(IndexInput),
            "ID_OR_INDEX" => Field::input(IdInput),
            "NORMAL" => Field::input(super::field::NormalInput),
            "POSITION" => Field::input(PositionInput),
            "INSTANCE_TRANSFORM" => super::nodes::points::instance_transform_field(),
            "HANDLE_LEFT" => super::nodes::curve_read::handle_positions_field(true),
            "HANDLE_RIGHT" => super::nodes::curve_read::handle_positions_field(false),
            other => {
                return Err(self.err(format!(
                    "a group input's Default Input {other:?} is not supported"
                )))
            }
        };
        Ok(SocketValue::Field(f))
    }

    fn flat_input(
        &self,
        id: &str,
    ) -> Result<&'e crate::nodes::graph::FlatInput<'a>, GeometryError> {
        self.flat()
            .input(id)
            .ok_or_else(|| self.err(format!("input {id:?} is not available")))
    }

    /// The value of input `id` (the first link of a multi-input).
    pub fn input(&self, id: &str) -> Result<SocketValue, GeometryError> {
        let inp = self.flat_input(id)?;
        let unlinked = inp
            .sources
            .iter()
            .all(|s| matches!(s, Source::Default(_) | Source::Nothing));
        if unlinked {
            if let Some(f) = implicit_field(&self.node().bl_idname, id) {
                return Ok(SocketValue::Field(f));
            }
        }
        match inp.sources.first() {
            Some(s) => self.source_value(s, &inp.socket.kind),
            None => Ok(SocketValue::zero(&inp.socket.kind)),
        }
    }

    /// All values linked into multi-input `id`, in Blender's order (descending
    /// `multi_input_sort_id`: top to bottom in the editor).
    pub fn inputs_multi(&self, id: &str) -> Result<Vec<SocketValue>, GeometryError> {
        let inp = self.flat_input(id)?;
        let node = self.node();
        let mut order: Vec<usize> = (0..inp.sources.len()).collect();
        if inp.sources.len() > 1 {
            if let Some(tree) = self.ev.tree_of(node) {
                let ids = self.ev.session.sort_ids.get(&tree.name);
                let keys: Vec<i64> = tree
                    .links
                    .iter()
                    .enumerate()
                    .filter(|(_, l)| {
                        l.to_node == node.name && l.to_socket == id && !l.is_muted && l.is_valid
                    })
                    .map(|(i, _)| ids.and_then(|v| v.get(i)).copied().unwrap_or(0))
                    .collect();
                if keys.len() == inp.sources.len() {
                    order.sort_by_key(|&k| std::cmp::Reverse(keys[k]));
                }
            }
        }
        let mut out = Vec::new();
        for k in order {
            let s = &inp.sources[k];
            if matches!(s, Source::Default(_) | Source::Nothing) && inp.socket.kind == "GEOMETRY" {
                continue;
            }
            out.push(self.source_value(s, &inp.socket.kind)?);
        }
        Ok(out)
    }

    pub fn field(&self, id: &str, ty: DataType) -> Result<Field, GeometryError> {
        match self.input(id)? {
            SocketValue::Field(f) => Ok(f.convert(ty)),
            other => Err(self.err(format!(
                "input {id:?} is a {}, expected a value or field",
                other.kind()
            ))),
        }
    }
    /// A single value: an input fed by a field that depends on geometry is an error.
    pub fn single(&self, id: &str, ty: DataType) -> Result<Value, GeometryError> {
        match self.field(id, ty)? {
            Field::Constant(v) => Ok(v),
            _ => Err(self.err(format!(
                "input {id:?} takes a single value but a field is connected"
            ))),
        }
    }
    pub fn float(&self, id: &str) -> Result<f32, GeometryError> {
        Ok(self.single(id, DataType::Float)?.as_float())
    }
    pub fn int(&self, id: &str) -> Result<i32, GeometryError> {
        Ok(self.single(id, DataType::Int)?.as_int())
    }
    pub fn bool(&self, id: &str) -> Result<bool, GeometryError> {
        Ok(self.single(id, DataType::Bool)?.as_bool())
    }
    pub fn vector(&self, id: &str) -> Result<[f32; 3], GeometryError> {
        Ok(self.single(id, DataType::Vector)?.as_vector())
    }
    pub fn geometry(&self, id: &str) -> Result<GeometrySet, GeometryError> {
        match self.input(id)? {
            SocketValue::Geometry(g) => Ok(g),
            SocketValue::None => Ok(GeometrySet::default()),
            other => Err(self.err(format!(
                "input {id:?} is a {}, expected geometry",
                other.kind()
            ))),
        }
    }
    pub fn string(&self, id: &str) -> Result<String, GeometryError> {
        match self.input(id)? {
            SocketValue::String(s) | SocketValue::Menu(s) => Ok(s),
            other => Err(self.err(format!(
                "input {id:?} is a {}, expected a string",
                other.kind()
            ))),
        }
    }
}

/// Converts a value to what a socket of type `kind` takes (Blender's implicit
/// conversions between field types; anything else unchanged).
fn coerce(v: SocketValue, kind: &str) -> SocketValue {
    match (v, DataType::from_socket(kind)) {
        (SocketValue::Field(f), Some(t)) => {
            if Value::can_convert(f.data_type(), t) {
                SocketValue::Field(f.convert(t))
            } else {
                SocketValue::Field(Field::Constant(Value::zero(t)))
            }
        }
        (v, _) => v,
    }
}

/// Builds an `Outputs` map.
pub fn outputs<const N: usize>(items: [(&str, SocketValue); N]) -> Outputs {
    items.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
}
