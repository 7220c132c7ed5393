//! Compiling a material's flattened node graph into a `Program`: stack slots for every
//! value, constants laid out once, Blender's implicit conversions as explicit operations.
//! A node or option the program cannot run is an error naming it, never a stand-in.

use serde_json::Value;

use crate::nodes::color::{rgb_to_bw, LINEAR_REC709};
use crate::nodes::curves::{mapping_from_json, CurveKind, CurveTable};
use crate::nodes::graph::{active_output, flatten, flatten_with, FlatGraph, FlatNode, Source};
use crate::nodes::mix::MixBlend;
use crate::nodes::ramp::{band_from_json, RampTable};
use crate::scene::{Scene, Socket};

use super::bump::BumpPoint;
use super::bump_graph::{self, Schedule, Step};
use super::program::{AovWrite, BsdfNode, Closure, Kind, Op, Program, Slot};

/// Compiling the nodes that read mesh attributes and tangents.
mod attributes;
/// Compiling the input nodes that read the shading context.
mod inputs;
/// The shader node table and each node's compile step.
mod node_table;

pub use node_table::{find, support, ShaderNode, NODES};

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompileError(pub String);

impl std::fmt::Display for CompileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for CompileError {}

/// Compiles the Cycles surface of material `name`.
pub fn compile_material(scene: &Scene, name: &str) -> Result<Program, CompileError> {
    let mat = scene
        .material(name)
        .ok_or_else(|| CompileError(format!("no material {name:?}")))?;
    let tree = mat.node_tree.as_ref().ok_or_else(|| {
        CompileError(format!(
            "material {name:?} has no node tree (use_nodes off)"
        ))
    })?;
    // No output Cycles uses (a tree made for another engine): Cycles syncs no nodes and
    // the surface is empty, black and opaque (fixture `material_no_cycles_output`).
    let Some(out) = active_output(tree, "ShaderNodeOutputMaterial", "CYCLES") else {
        return Ok(empty_surface());
    };
    let aovs = aov_outputs(scene, tree);
    let (graph, _) = flatten_with(tree, &scene.file.node_groups, &out.name, &aovs)
        .map_err(|e| CompileError(format!("material {name:?}: {e}")))?;
    let mut c = Compiler::new(&graph);
    c.scene = Some(scene);
    (c.displace, c.true_displacement) = displacement_method(
        name,
        mat.properties
            .get("displacement_method")
            .and_then(Value::as_str),
    )?;
    c.material_pass_index = mat.pass_index as f32;
    c.run()
        .map_err(|e| CompileError(format!("material {name:?}: {}", e.0)))
}

/// The AOV Output nodes of `tree` Cycles runs: unmuted, naming a valid AOV of the view
/// layer (Cycles drops the others, and what only they read), in the tree itself or in
/// any unmuted group node's tree, at any depth, used or not (Cycles' sync adds every
/// node of every group and keeps AOV Outputs as outputs). Each is its path: the group
/// nodes down to it, then its name.
fn aov_outputs<'t>(scene: &'t Scene, tree: &'t crate::scene::NodeTree) -> Vec<Vec<&'t str>> {
    let mut out = Vec::new();
    collect_aovs(scene, tree, &mut Vec::new(), &mut out);
    out
}

fn collect_aovs<'t>(
    scene: &'t Scene,
    tree: &'t crate::scene::NodeTree,
    path: &mut Vec<&'t str>,
    out: &mut Vec<Vec<&'t str>>,
) {
    // Deeper nesting is a group containing itself, which flattening refuses by name.
    if path.len() > 64 {
        return;
    }
    for n in tree.nodes.iter().filter(|n| !n.mute) {
        if runs_aov(scene, n) {
            let mut p = path.clone();
            p.push(n.name.as_str());
            out.push(p);
        } else if let Some(g) = n.node_tree.as_deref().and_then(|g| scene.node_group(g)) {
            path.push(n.name.as_str());
            collect_aovs(scene, g, path, out);
            path.pop();
        }
    }
}

/// Whether `n` is an unmuted AOV Output naming a valid AOV of the view layer.
fn runs_aov(scene: &Scene, n: &crate::scene::Node) -> bool {
    !n.mute && n.bl_idname == "ShaderNodeOutputAOV" && aov_index(scene, n).is_some()
}

/// The view-layer AOV node `n` names, if valid: its index and whether it is a colour.
fn aov_index(scene: &Scene, n: &crate::scene::Node) -> Option<(u32, bool)> {
    let name = n.properties.get("aov_name").and_then(Value::as_str)?;
    let aovs = &scene.file.scene.view_layer.aovs;
    let i = aovs.iter().position(|a| a.is_valid && a.name == name)?;
    Some((i as u32, aovs[i].kind == "COLOR"))
}

/// The program of a material with no surface: no closure, no displacement.
fn empty_surface() -> Program {
    Program {
        ops: Vec::new(),
        initial: Vec::new(),
        ramps: Vec::new(),
        curves: Vec::new(),
        closures: Vec::new(),
        surface: None,
        bsdfs: Vec::new(),
        displaced_normal: None,
        attributes: Vec::new(),
        displacement: None,
        emission_estimate: [0.0; 3],
        surface_from_value: false,
        aovs: Vec::new(),
        reads_differentials: false,
        volume: None,
        volume_varying: false,
    }
}

/// How the Material Output's Displacement is compiled, after Cycles' displacement methods:
/// a bump of the shading normal (`Some(object_space)`; "Bump Only" in world space, "Both"
/// in object space, as Cycles' bump_from_displacement), and/or a value the renderer moves
/// the mesh's vertices by before tracing ("Displacement Only" and "Both").
fn displacement_method(
    material: &str,
    method: Option<&str>,
) -> Result<(Option<bool>, bool), CompileError> {
    match method.unwrap_or("BUMP") {
        "BUMP" => Ok((Some(false), false)),
        "BOTH" => Ok((Some(true), true)),
        "DISPLACEMENT" => Ok((None, true)),
        other => Err(CompileError(format!(
            "material {material:?}: displacement method {other:?} is not supported"
        ))),
    }
}

/// Per flat node, per output: where one copy of the graph keeps its values.
type CopyValues = Vec<Vec<Option<(Slot, Kind)>>>;

struct Compiler<'g, 'a> {
    g: &'g FlatGraph<'a>,
    initial: Vec<f32>,
    ops: Vec<Op>,
    ramps: Vec<RampTable>,
    curves: Vec<CurveTable>,
    closures: Vec<Closure>,
    /// Per flat node, per output index: where its value lives.
    values: Vec<Vec<Option<(Slot, Kind)>>>,
    /// Per flat node: the closure its (single) shader output makes.
    closure_of: Vec<Option<u32>>,
    /// The Emissions made of values linked into shader sockets (`closure_input`).
    value_emissions: Vec<u32>,
    surface: Option<u32>,
    volume: Option<u32>,
    bsdfs: Vec<BsdfNode>,
    /// The scene, for the images texture nodes name (None: no images available).
    scene: Option<&'a Scene>,
    /// Displacement compiled as a bump (object space when true); None: not at all.
    displace: Option<bool>,
    /// Displacement also compiled as a value to move vertices by (`Program::displacement`).
    true_displacement: bool,
    displacement: Option<super::program::TrueDisplacement>,
    /// Slots `constant` filled (unlinked or constant-folded values).
    constants: Vec<Slot>,
    /// Values of the graph copies not being compiled (see `bump_graph`), and which copy
    /// `values` holds now.
    copy_values: Vec<CopyValues>,
    copy: usize,
    displaced_normal: Option<Slot>,
    /// The material's pass index (Object Info > Material Index).
    material_pass_index: f32,
    /// Mesh attributes the program reads (`Program::attributes`).
    attributes: Vec<super::attributes::AttributeRequest>,
    /// Compiling a world's shader: no object, no camera-space view of the point.
    world: bool,
    /// The AOV Outputs compiled (`Program::aovs`).
    pub(super) aovs: Vec<AovWrite>,
}

fn kind_of(socket_type: &str) -> Option<Kind> {
    match socket_type {
        "VALUE" | "INT" | "BOOLEAN" => Some(Kind::Float),
        "VECTOR" => Some(Kind::Vector),
        "RGBA" => Some(Kind::Color),
        _ => None,
    }
}

fn prop<'n>(n: &FlatNode<'n>, key: &str) -> Result<&'n Value, CompileError> {
    n.property(key)
        .ok_or_else(|| CompileError(format!("node {:?} lacks property {key:?}", n.path)))
}
fn prop_str<'n>(n: &FlatNode<'n>, key: &str) -> Result<&'n str, CompileError> {
    prop(n, key)?.as_str().ok_or_else(|| {
        CompileError(format!(
            "node {:?}: property {key:?} is not a string",
            n.path
        ))
    })
}
fn prop_bool(n: &FlatNode, key: &str) -> Result<bool, CompileError> {
    prop(n, key)?.as_bool().ok_or_else(|| {
        CompileError(format!(
            "node {:?}: property {key:?} is not a boolean",
            n.path
        ))
    })
}
fn mode<T>(n: &FlatNode, key: &str, parse: fn(&str) -> Option<T>) -> Result<T, CompileError> {
    let v = prop_str(n, key)?;
    parse(v).ok_or_else(|| CompileError(format!("node {:?}: {key} {v:?} is not supported", n.path)))
}

/// A JSON default value as three floats (a scalar fills all three).
fn floats(v: &Value) -> [f32; 4] {
    match v {
        Value::Number(x) => {
            let f = x.as_f64().unwrap_or(0.0) as f32;
            [f, f, f, 1.0]
        }
        Value::Bool(b) => {
            let f = if *b { 1.0 } else { 0.0 };
            [f, f, f, 1.0]
        }
        Value::Array(a) => {
            let mut out = [0.0, 0.0, 0.0, 1.0];
            for (o, x) in out.iter_mut().zip(a) {
                *o = x.as_f64().unwrap_or(0.0) as f32;
            }
            out
        }
        _ => [0.0, 0.0, 0.0, 1.0],
    }
}

fn dimensions(n: &FlatNode, key: &str) -> Result<u8, CompileError> {
    match prop_str(n, key)? {
        "1D" => Ok(1),
        "2D" => Ok(2),
        "3D" => Ok(3),
        "4D" => Ok(4),
        other => Err(CompileError(format!(
            "node {:?}: {key} {other:?} is not supported",
            n.path
        ))),
    }
}

fn linked(n: &FlatNode, id: &str) -> bool {
    n.input(id)
        .is_some_and(|i| matches!(i.sources.first(), Some(Source::Link { .. })))
}

/// True when a texture node's `texture_mapping` leaves coordinates unchanged.
fn identity_mapping(m: &Value) -> bool {
    let v3 = |k: &str, want: f64| {
        m.get(k)
            .and_then(Value::as_array)
            .is_none_or(|a| a.iter().all(|x| x.as_f64() == Some(want)))
    };
    let b = |k: &str| m.get(k).and_then(Value::as_bool).unwrap_or(false);
    let s = |k: &str, want: &str| m.get(k).and_then(Value::as_str).is_none_or(|x| x == want);
    v3("translation", 0.0)
        && v3("rotation", 0.0)
        && v3("scale", 1.0)
        && !b("use_min")
        && !b("use_max")
        && s("mapping_x", "X")
        && s("mapping_y", "Y")
        && s("mapping_z", "Z")
}

impl<'g, 'a> Compiler<'g, 'a> {
    fn new(g: &'g FlatGraph<'a>) -> Self {
        Compiler {
            g,
            initial: Vec::new(),
            ops: Vec::new(),
            ramps: Vec::new(),
            curves: Vec::new(),
            closures: Vec::new(),
            values: vec![Vec::new(); g.nodes.len()],
            closure_of: vec![None; g.nodes.len()],
            value_emissions: Vec::new(),
            surface: None,
            volume: None,
            bsdfs: Vec::new(),
            scene: None,
            displace: None,
            true_displacement: false,
            displacement: None,
            constants: Vec::new(),
            copy_values: Vec::new(),
            copy: 0,
            displaced_normal: None,
            material_pass_index: 0.0,
            attributes: Vec::new(),
            world: false,
            aovs: Vec::new(),
        }
    }

    fn alloc(&mut self, kind: Kind) -> Slot {
        let s = self.initial.len() as Slot;
        self.initial
            .extend(std::iter::repeat_n(0.0, kind.width() as usize));
        s
    }

    fn constant(&mut self, kind: Kind, v: [f32; 3]) -> Slot {
        let s = self.alloc(kind);
        let w = kind.width() as usize;
        self.initial[s as usize..s as usize + w].copy_from_slice(&v[..w]);
        self.constants.push(s);
        s
    }

    /// Cycles' output_estimate_emission over the compiled closure tree: constant
    /// colours and strengths as they are, anything computed as one (it may emit).
    fn emission_estimate(&self, c: Option<u32>) -> [f32; 3] {
        let Some(c) = c else { return [0.0; 3] };
        let value = |slot: Slot, width: usize| -> [f32; 3] {
            if self.constants.contains(&slot) {
                let i = slot as usize;
                if width == 1 {
                    [self.initial[i]; 3]
                } else {
                    [self.initial[i], self.initial[i + 1], self.initial[i + 2]]
                }
            } else {
                [1.0; 3]
            }
        };
        let emitter = |color: Slot, strength: Slot| {
            let (c, s) = (value(color, 3), value(strength, 1));
            [c[0] * s[0], c[1] * s[1], c[2] * s[2]]
        };
        match self.closures[c as usize] {
            Closure::Emission { color, strength } => emitter(color, strength),
            Closure::Bsdf {
                emission: Some((color, strength)),
            } => emitter(color, strength),
            Closure::Bsdf { emission: None } => [0.0; 3],
            Closure::Add { a, b } => {
                let (x, y) = (self.emission_estimate(a), self.emission_estimate(b));
                [x[0] + y[0], x[1] + y[1], x[2] + y[2]]
            }
            Closure::Mix { fac, a, b } => {
                let (x, y) = (self.emission_estimate(a), self.emission_estimate(b));
                if self.constants.contains(&fac) {
                    let f = self.initial[fac as usize];
                    [
                        (1.0 - f) * x[0] + f * y[0],
                        (1.0 - f) * x[1] + f * y[1],
                        (1.0 - f) * x[2] + f * y[2],
                    ]
                } else {
                    [x[0] + y[0], x[1] + y[1], x[2] + y[2]]
                }
            }
        }
    }

    /// Whether closure `c`'s tree reads a value that is not a constant (a mix factor, an
    /// emission or a node input computed by ops).
    fn closure_varies(&self, c: u32) -> bool {
        let computed = |slot: Slot| !self.constants.contains(&slot);
        match self.closures[c as usize] {
            Closure::Emission { color, strength } => computed(color) || computed(strength),
            Closure::Bsdf { .. } => self
                .bsdfs
                .iter()
                .filter(|b| b.closure == c)
                .any(|b| b.inputs.iter().any(|(_, slot, _)| computed(*slot))),
            Closure::Mix { fac, a, b } => {
                computed(fac)
                    || a.is_some_and(|a| self.closure_varies(a))
                    || b.is_some_and(|b| self.closure_varies(b))
            }
            Closure::Add { a, b } => {
                a.is_some_and(|a| self.closure_varies(a))
                    || b.is_some_and(|b| self.closure_varies(b))
            }
        }
    }

    /// A socket's default converted to `want`, as Blender converts unlinked values.
    fn default_value(&mut self, sock: &Socket, want: Kind) -> Slot {
        let v = sock
            .default_value
            .as_ref()
            .map(floats)
            .unwrap_or([0.0, 0.0, 0.0, 1.0]);
        let rgb = [v[0], v[1], v[2]];
        let have = kind_of(&sock.kind).unwrap_or(Kind::Float);
        let value = match (have, want) {
            (Kind::Float, _) => [v[0]; 3],
            (Kind::Color, Kind::Float) => [rgb_to_bw(rgb, &LINEAR_REC709); 3],
            (Kind::Vector, Kind::Float) => [(v[0] + v[1] + v[2]) * (1.0 / 3.0); 3],
            _ => rgb,
        };
        self.constant(want, value)
    }

    /// The slot holding input `id` of node `n` as `want`.
    fn input(&mut self, n: &FlatNode<'a>, id: &str, want: Kind) -> Result<Slot, CompileError> {
        let Some(inp) = n.input(id) else {
            return Err(CompileError(format!(
                "node {:?} has no available input {id:?}",
                n.path
            )));
        };
        match inp.sources.first() {
            None | Some(Source::Nothing) => Ok(self.constant(want, [0.0; 3])),
            Some(Source::Default(sock)) => Ok(self.default_value(sock, want)),
            Some(Source::GroupInput(i)) => Err(CompileError(format!(
                "node {:?} reads group input {i:?}, which a material cannot provide",
                n.path
            ))),
            Some(Source::DefaultInput(k)) => Err(CompileError(format!(
                "node {:?} reads a group input whose Default Input is the {k} field, which a material cannot provide",
                n.path
            ))),
            Some(Source::Link { node, output, .. }) => {
                let (slot, have) = self.values[*node]
                    .get(*output)
                    .copied()
                    .flatten()
                    .ok_or_else(|| {
                        let from = &self.g.nodes[*node];
                        CompileError(format!(
                            "node {:?} output {:?} is not supported yet (used by {:?})",
                            from.path, from.node.outputs[*output].identifier, n.path
                        ))
                    })?;
                Ok(self.convert(slot, have, want))
            }
        }
    }

    fn convert(&mut self, src: Slot, have: Kind, want: Kind) -> Slot {
        let op = match (have, want) {
            // Vectors and colours share a layout.
            (Kind::Vector | Kind::Color, Kind::Vector | Kind::Color) => return src,
            (Kind::Float, Kind::Float) => return src,
            (Kind::Vector, Kind::Float) => |src, dst| Op::VectorToFloat { src, dst },
            (Kind::Color, Kind::Float) => |src, dst| Op::ColorToFloat { src, dst },
            (Kind::Float, _) => |src, dst| Op::FloatToVector { src, dst },
        };
        let dst = self.alloc(want);
        self.ops.push(op(src, dst));
        dst
    }

    /// The closure feeding shader socket `id` of node `n`. A colour, vector or value there
    /// (linked, or a group socket's unlinked default) becomes an Emission, as Cycles'
    /// `ShaderGraph::connect` converts it: a value sets the Strength (Color white), anything
    /// else the Color (Strength 1).
    fn closure_input(&mut self, n: &FlatNode<'a>, id: &str) -> Result<Option<u32>, CompileError> {
        let value_kind = match n.input(id).and_then(|i| i.sources.first()) {
            Some(Source::Link { node, .. }) if self.closure_of[*node].is_some() => {
                return Ok(self.closure_of[*node]);
            }
            Some(Source::Link { kind, .. }) => kind_of(kind).ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: input {id:?} is linked to a {kind} output, which Cycles cannot make a shader of",
                    n.path
                ))
            })?,
            Some(Source::Default(sock)) => match kind_of(&sock.kind) {
                Some(k) if sock.default_value.is_some() => k,
                _ => return Ok(None),
            },
            _ => return Ok(None),
        };
        let (color, strength) = if value_kind == Kind::Float {
            (
                self.constant(Kind::Color, [1.0; 3]),
                self.input(n, id, Kind::Float)?,
            )
        } else {
            (
                self.input(n, id, Kind::Color)?,
                self.constant(Kind::Float, [1.0; 3]),
            )
        };
        self.closures.push(Closure::Emission { color, strength });
        let c = self.closures.len() as u32 - 1;
        self.value_emissions.push(c);
        Ok(Some(c))
    }

    fn outputs(&mut self, i: usize, n: &FlatNode, slots: &[(&str, Slot, Kind)]) {
        let mut v = vec![None; n.node.outputs.len()];
        for (id, slot, kind) in slots {
            if let Some(k) = n.node.outputs.iter().position(|o| o.identifier == *id) {
                v[k] = Some((*slot, *kind));
            }
        }
        self.values[i] = v;
    }

    fn run(mut self) -> Result<Program, CompileError> {
        let schedule =
            bump_graph::schedule(self.g, self.displace.is_some(), self.true_displacement)
                .map_err(CompileError)?;
        self.copy_values = vec![vec![Vec::new(); self.g.nodes.len()]; schedule.copies.len()];
        for step in &schedule.steps {
            let Some(i) = self.enter_step(&schedule, *step)? else {
                continue;
            };
            let n = &self.g.nodes[i];
            let node = node_table::find(&n.node.bl_idname).ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: {} is not supported yet",
                    n.path, n.node.bl_idname
                ))
            })?;
            (node.compile)(&mut self, i, &schedule)?;
        }
        self.switch_copy(&schedule, 0);
        let emission_estimate = self.emission_estimate(self.surface);
        let volume_varying = self.volume.is_some_and(|v| self.closure_varies(v));
        for b in &mut self.bsdfs {
            b.index_sockets();
        }
        let reads_differentials = self.ops.iter().any(|op| {
            matches!(
                op,
                Op::BumpPoint {
                    point: BumpPoint::Dx | BumpPoint::Dy,
                    ..
                }
            )
        });
        Ok(Program {
            ops: self.ops,
            initial: self.initial,
            ramps: self.ramps,
            curves: self.curves,
            closures: self.closures,
            surface: self.surface,
            volume: self.volume,
            volume_varying,
            bsdfs: self.bsdfs,
            displaced_normal: self.displaced_normal,
            attributes: self.attributes,
            displacement: self.displacement,
            emission_estimate,
            surface_from_value: self
                .surface
                .is_some_and(|s| self.value_emissions.contains(&s)),
            aovs: self.aovs,
            reads_differentials,
        })
    }

    /// Records a BSDF node's value inputs and enum properties for the renderer.
    fn record_bsdf(&mut self, i: usize) -> Result<(), CompileError> {
        let n = &self.g.nodes[i];
        let closure = self.closures.len() as u32 - 1;
        let mut inputs = Vec::new();
        for sock in n.node.inputs.iter().filter(|s| s.enabled) {
            let Some(kind) = kind_of(&sock.kind) else {
                continue;
            };
            if n.input(&sock.identifier).is_none() {
                continue;
            }
            let linked = n
                .input(&sock.identifier)
                .is_some_and(|inp| matches!(inp.sources.first(), Some(Source::Link { .. })));
            let slot = self.input(n, &sock.identifier, kind)?;
            inputs.push((sock.identifier.clone(), slot, linked));
        }
        let properties = n
            .node
            .properties
            .iter()
            .filter_map(|(k, v)| v.as_str().map(|s| (k.clone(), s.to_string())))
            .collect();
        let kind = crate::shader::program::BsdfKind::of(&n.node.bl_idname).ok_or_else(|| {
            CompileError(format!(
                "node {:?}: closure type {} has no shading in the renderer",
                n.path, n.node.bl_idname
            ))
        })?;
        self.bsdfs.push(BsdfNode {
            closure,
            bl_idname: n.node.bl_idname.clone(),
            kind,
            inputs,
            properties,
            by_socket: Vec::new(),
        });
        Ok(())
    }

    /// An input that may be unavailable for the node's mode (then a zero constant).
    fn opt_input(&mut self, n: &FlatNode<'a>, id: &str, want: Kind) -> Result<Slot, CompileError> {
        if n.input(id).is_some() {
            self.input(n, id, want)
        } else {
            Ok(self.constant(want, [0.0; 3]))
        }
    }

    fn inputs_n<const K: usize>(
        &mut self,
        n: &FlatNode<'a>,
        ids: [&str; K],
        want: Kind,
    ) -> Result<[Slot; K], CompileError> {
        let mut out = [0; K];
        for (o, id) in out.iter_mut().zip(ids) {
            *o = self.opt_input(n, id, want)?;
        }
        Ok(out)
    }

    /// A texture node's dimensions (if it has them), its Vector (Generated coordinates
    /// when unlinked, as Cycles does) and W. Only the identity texture mapping is
    /// supported: Cycles then adds no mapping step.
    fn texture_point(
        &mut self,
        n: &FlatNode<'a>,
        dims_key: Option<&str>,
    ) -> Result<(u8, Slot, Slot), CompileError> {
        let dims = match dims_key {
            Some(k) => dimensions(n, k)?,
            None => 3,
        };
        if let Some(m) = n.property("texture_mapping") {
            if !identity_mapping(m) {
                return Err(CompileError(format!(
                    "node {:?}: a non-identity texture_mapping is not supported yet",
                    n.path
                )));
            }
        }
        let vector = if dims == 1 {
            self.constant(Kind::Vector, [0.0; 3])
        } else if linked(n, "Vector") {
            self.input(n, "Vector", Kind::Vector)?
        } else {
            let d = self.alloc(Kind::Vector);
            self.ops.push(Op::TexCoord {
                generated: Some(d),
                normal: None,
                uv: None,
                object: None,
            });
            d
        };
        let w = if n.input("W").is_some() {
            self.input(n, "W", Kind::Float)?
        } else {
            self.constant(Kind::Float, [0.0; 3])
        };
        Ok((dims, vector, w))
    }

    fn inputs6(
        &mut self,
        n: &FlatNode<'a>,
        ids: [&str; 6],
        want: Kind,
    ) -> Result<[Slot; 6], CompileError> {
        let mut out = [0; 6];
        for (o, id) in out.iter_mut().zip(ids) {
            *o = self.opt_input(n, id, want)?;
        }
        Ok(out)
    }

    fn closure(&mut self, i: usize, c: Closure) {
        self.closures.push(c);
        self.closure_of[i] = Some(self.closures.len() as u32 - 1);
    }

    fn mix(&mut self, i: usize) -> Result<(), CompileError> {
        use Kind::{Color as C, Float as F, Vector as V};
        let n = &self.g.nodes[i];
        let clamp_factor = prop_bool(n, "clamp_factor")?;
        match prop_str(n, "data_type")? {
            "FLOAT" => {
                let (factor, a, b) = (
                    self.input(n, "Factor_Float", F)?,
                    self.input(n, "A_Float", F)?,
                    self.input(n, "B_Float", F)?,
                );
                let d = self.alloc(F);
                self.ops.push(Op::MixFloat {
                    clamp_factor,
                    factor,
                    a,
                    b,
                    dst: d,
                });
                self.outputs(i, n, &[("Result_Float", d, F)]);
            }
            "VECTOR" => {
                let (a, b) = (self.input(n, "A_Vector", V)?, self.input(n, "B_Vector", V)?);
                let d = self.alloc(V);
                if prop_str(n, "factor_mode")? == "NON_UNIFORM" {
                    let factor = self.input(n, "Factor_Vector", V)?;
                    self.ops.push(Op::MixVectorNonUniform {
                        clamp_factor,
                        factor,
                        a,
                        b,
                        dst: d,
                    });
                } else {
                    let factor = self.input(n, "Factor_Float", F)?;
                    self.ops.push(Op::MixVector {
                        clamp_factor,
                        factor,
                        a,
                        b,
                        dst: d,
                    });
                }
                self.outputs(i, n, &[("Result_Vector", d, V)]);
            }
            "RGBA" => {
                let blend = mode(n, "blend_type", MixBlend::from_blender)?;
                let clamp_result = prop_bool(n, "clamp_result")?;
                let (factor, a, b) = (
                    self.input(n, "Factor_Float", F)?,
                    self.input(n, "A_Color", C)?,
                    self.input(n, "B_Color", C)?,
                );
                let d = self.alloc(C);
                self.ops.push(Op::MixColor {
                    blend,
                    clamp_factor,
                    clamp_result,
                    factor,
                    a,
                    b,
                    dst: d,
                });
                self.outputs(i, n, &[("Result_Color", d, C)]);
            }
            other => {
                return Err(CompileError(format!(
                    "node {:?}: Mix data type {other:?} is not supported",
                    n.path
                )))
            }
        }
        Ok(())
    }

    /// The node's curve mapping, baked into the lookup table Cycles builds from it.
    fn curve_table(&mut self, n: &FlatNode, kind: CurveKind) -> Result<u32, CompileError> {
        let m = mapping_from_json(prop(n, "mapping")?)
            .map_err(|e| CompileError(format!("node {:?}: {}", n.path, e.0)))?;
        let t = CurveTable::new(&m, kind)
            .map_err(|e| CompileError(format!("node {:?}: {}", n.path, e.0)))?;
        self.curves.push(t);
        Ok(self.curves.len() as u32 - 1)
    }

    /// The node's colour band, sampled into a lookup table as Blender hands it to Cycles.
    fn ramp(&mut self, n: &FlatNode) -> Result<u32, CompileError> {
        let band = band_from_json(prop(n, "color_ramp")?)
            .map_err(|e| CompileError(format!("node {:?}: {e}", n.path)))?;
        self.ramps.push(RampTable::from_band(&band));
        Ok(self.ramps.len() as u32 - 1)
    }

    /// Makes copy `c` of the graph current: its values in `values`, and an op moving the
    /// shading point the following ops read.
    fn switch_copy(&mut self, schedule: &Schedule, c: usize) {
        if c == self.copy {
            return;
        }
        std::mem::swap(&mut self.values, &mut self.copy_values[self.copy]);
        std::mem::swap(&mut self.values, &mut self.copy_values[c]);
        let (old, new) = (schedule.copies[self.copy], schedule.copies[c]);
        if old.point != new.point || old.filter_width != new.filter_width {
            self.ops.push(Op::BumpPoint {
                point: new.point,
                width: new.filter_width,
            });
        }
        self.copy = c;
    }

    /// Prepares a schedule step; returns the node to compile, if it is one.
    fn enter_step(
        &mut self,
        schedule: &Schedule,
        step: Step,
    ) -> Result<Option<usize>, CompileError> {
        match step {
            Step::Node { node, copy } => {
                self.switch_copy(schedule, copy);
                Ok(Some(node))
            }
            Step::DisplacementBump => {
                let Some((c, x, y)) = schedule.displacement else {
                    return Ok(None);
                };
                self.switch_copy(schedule, 0);
                let root = self.g.root;
                let center = self.input_in_copy(c, root, "Displacement", Kind::Vector)?;
                let dx = self.input_in_copy(x, root, "Displacement", Kind::Vector)?;
                let dy = self.input_in_copy(y, root, "Displacement", Kind::Vector)?;
                let d = self.alloc(Kind::Vector);
                self.ops.push(Op::DisplacementBump {
                    object_space: self.displace == Some(true),
                    center,
                    dx,
                    dy,
                    dst: d,
                });
                self.displaced_normal = Some(d);
                if let Some(t) = &mut self.displacement {
                    t.bump_end = Some(self.ops.len());
                }
                Ok(None)
            }
            Step::DisplacementValue => {
                let Some(c) = schedule.displacement_value else {
                    return Ok(None);
                };
                self.switch_copy(schedule, 0);
                let value = self.input_in_copy(c, self.g.root, "Displacement", Kind::Vector)?;
                self.displacement = Some(super::program::TrueDisplacement {
                    center_end: self.ops.len(),
                    value,
                    bump_end: None,
                });
                Ok(None)
            }
        }
    }

    /// Input `id` of flat node `i` as copy `c` of the graph computed it.
    fn input_in_copy(
        &mut self,
        c: usize,
        i: usize,
        id: &str,
        want: Kind,
    ) -> Result<Slot, CompileError> {
        debug_assert_eq!(self.copy, 0);
        std::mem::swap(&mut self.values, &mut self.copy_values[c]);
        let n = &self.g.nodes[i];
        let r = self.input(n, id, want);
        std::mem::swap(&mut self.values, &mut self.copy_values[c]);
        r
    }
}

/// Compiles the Cycles surface of world `name`: Background closures as emission, and
/// texture coordinates read from the ray direction (`world_point`).
pub fn compile_world(scene: &Scene, name: &str) -> Result<Program, CompileError> {
    let world = scene
        .file
        .worlds
        .iter()
        .find(|w| w.name == name)
        .ok_or_else(|| CompileError(format!("no world {name:?}")))?;
    let tree = world
        .node_tree
        .as_ref()
        .ok_or_else(|| CompileError(format!("world {name:?} has no node tree")))?;
    let out = active_output(tree, "ShaderNodeOutputWorld", "CYCLES")
        .ok_or_else(|| CompileError(format!("world {name:?} has no World Output")))?;
    let aovs = aov_outputs(scene, tree);
    let (graph, _) = flatten_with(tree, &scene.file.node_groups, &out.name, &aovs)
        .map_err(|e| CompileError(format!("world {name:?}: {e}")))?;
    let mut c = Compiler::new(&graph);
    c.scene = Some(scene);
    c.world = true;
    c.run()
        .map_err(|e| CompileError(format!("world {name:?}: {}", e.0)))
}

/// Node types a light's tree may use: what reads only the light sample's position, normal,
/// incoming direction and distance (the shading point Cycles sets up for a light), or
/// nothing at all. Others read context blendsynth does not model at a light (UV, path
/// state, attributes) and are refused by name.
const LIGHT_NODES: &[&str] = &[
    "ShaderNodeOutputLight",
    "ShaderNodeEmission",
    "ShaderNodeAddShader",
    "ShaderNodeMixShader",
    "ShaderNodeValue",
    "ShaderNodeRGB",
    "ShaderNodeTexCoord",
    "ShaderNodeNewGeometry",
    "ShaderNodeLightFalloff",
    "ShaderNodeFresnel",
    "ShaderNodeLayerWeight",
    "ShaderNodeTexIES",
    "ShaderNodeTexNoise",
    "ShaderNodeTexVoronoi",
    "ShaderNodeTexWave",
    "ShaderNodeTexGradient",
    "ShaderNodeTexMagic",
    "ShaderNodeTexWhiteNoise",
    "ShaderNodeTexChecker",
    "ShaderNodeTexGabor",
    "ShaderNodeTexBrick",
    "ShaderNodeTexImage",
    "ShaderNodeMix",
    "ShaderNodeMixRGB",
    "ShaderNodeInvert",
    "ShaderNodeGamma",
    "ShaderNodeBrightContrast",
    "ShaderNodeHueSaturation",
    "ShaderNodeRGBCurve",
    "ShaderNodeMapping",
    "ShaderNodeVectorRotate",
    "ShaderNodeVectorCurve",
    "ShaderNodeMath",
    "ShaderNodeVectorMath",
    "ShaderNodeMapRange",
    "ShaderNodeClamp",
    "ShaderNodeValToRGB",
    "ShaderNodeFloatCurve",
    "ShaderNodeRGBToBW",
    "ShaderNodeSeparateXYZ",
    "ShaderNodeCombineXYZ",
    "ShaderNodeSeparateColor",
    "ShaderNodeCombineColor",
    "ShaderNodeSeparateRGB",
    "ShaderNodeCombineRGB",
    "ShaderNodeSeparateHSV",
    "ShaderNodeCombineHSV",
    "ShaderNodeBlackbody",
    "ShaderNodeWavelength",
];

/// The outputs of the coordinate nodes a light sample gives (Generated falls back to the
/// object-space position, as Cycles does for geometry without the attribute).
const LIGHT_COORDINATES: &[(&str, &[&str])] = &[
    ("ShaderNodeTexCoord", &["Generated", "Normal", "Object"]),
    (
        "ShaderNodeNewGeometry",
        &["Position", "Normal", "True Normal", "Incoming"],
    ),
];

/// Compiles the node tree of light `light` (its evaluated datablock), whose active Light
/// Output's Surface Cycles evaluates at every light sample; None when it has no Light
/// Output for Cycles (the light is then black).
pub fn compile_light(
    scene: &Scene,
    light: &crate::scene::format::Light,
) -> Result<Option<Program>, CompileError> {
    let name = &light.name;
    let Some(tree) = light.node_tree.as_ref() else {
        return Ok(None);
    };
    let Some(out) = active_output(tree, "ShaderNodeOutputLight", "CYCLES") else {
        return Ok(None);
    };
    let graph = flatten(tree, &scene.file.node_groups, &out.name)
        .map_err(|e| CompileError(format!("light {name:?}: {e}")))?;
    let mut c = Compiler::new(&graph);
    c.scene = Some(scene);
    for (i, n) in graph.nodes.iter().enumerate() {
        let id = n.node.bl_idname.as_str();
        if !LIGHT_NODES.contains(&id) && !crate::nodes::STRUCTURAL.contains(&id) {
            return Err(CompileError(format!(
                "light {name:?}: node {:?} ({id}) in a light's node tree is not supported yet",
                n.path
            )));
        }
        for (node, allowed) in LIGHT_COORDINATES {
            if id != *node {
                continue;
            }
            if let Some(o) = n.node.outputs.iter().find(|o| {
                !allowed.contains(&o.identifier.as_str()) && c.output_used(i, &o.identifier)
            }) {
                return Err(CompileError(format!(
                    "light {name:?}: output {:?} of node {:?} is not supported in a light's node tree yet",
                    o.identifier, n.path
                )));
            }
        }
    }
    c.run()
        .map(Some)
        .map_err(|e| CompileError(format!("light {name:?}: {}", e.0)))
}

/// A world shading point for direction `d` (unit, world space), as Cycles sets up the
/// background: position, Generated and Object coordinates are the direction, the
/// normal faces back along the ray, no UV.
/// The shading point of the world seen along direction `d`, by a ray in `path` (Light Path
/// reads it: Cycles evaluates the background with the ray's flags plus Emission).
pub fn world_point(
    d: crate::nodes::math::V3,
    path: super::point::PathState,
) -> super::point::ShadingPoint {
    let n = [-d[0], -d[1], -d[2]];
    super::point::ShadingPoint {
        path,
        position: d,
        normal: n,
        object_position: d,
        object_normal: n,
        generated: d,
        ..Default::default()
    }
}

impl<'g, 'a> Compiler<'g, 'a> {
    fn prop_f32(n: &FlatNode, key: &str) -> Result<f32, CompileError> {
        prop(n, key)?.as_f64().map(|v| v as f32).ok_or_else(|| {
            CompileError(format!(
                "node {:?}: property {key:?} is not a number",
                n.path
            ))
        })
    }

    /// Whether output `id` of flat node `i` feeds anything in the graph.
    fn output_used(&self, i: usize, id: &str) -> bool {
        let Some(k) = self.g.nodes[i]
            .node
            .outputs
            .iter()
            .position(|o| o.identifier == id)
        else {
            return false;
        };
        self.g.nodes.iter().any(|m| m.inputs.iter().any(|inp| inp.sources.iter().any(|s| matches!(s, Source::Link { node, output, .. } if *node == i && *output == k))))
    }

    fn brick(&mut self, i: usize) -> Result<(), CompileError> {
        use crate::nodes::brick::BrickSettings;
        let n = &self.g.nodes[i];
        let (_, vector, _) = self.texture_point(n, None)?;
        let int = |key: &str| -> Result<i32, CompileError> {
            prop(n, key)?.as_i64().map(|v| v as i32).ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: property {key:?} is not an integer",
                    n.path
                ))
            })
        };
        let settings = BrickSettings {
            offset: Self::prop_f32(n, "offset")?,
            offset_frequency: int("offset_frequency")?,
            squash: Self::prop_f32(n, "squash")?,
            squash_frequency: int("squash_frequency")?,
        };
        let [c1, c2, m] = self.inputs_n(n, ["Color1", "Color2", "Mortar"], Kind::Color)?;
        let [scale, size, smooth, bias, width, height] = self.inputs_n(
            n,
            [
                "Scale",
                "Mortar Size",
                "Mortar Smooth",
                "Bias",
                "Brick Width",
                "Row Height",
            ],
            Kind::Float,
        )?;
        let (fac, color) = (self.alloc(Kind::Float), self.alloc(Kind::Color));
        self.ops.push(Op::TexBrick {
            settings,
            vector,
            args: [c1, c2, m, scale, size, smooth, bias, width, height],
            fac,
            color,
        });
        self.outputs(
            i,
            n,
            &[("Fac", fac, Kind::Float), ("Color", color, Kind::Color)],
        );
        Ok(())
    }

    /// The image an Image/Environment Texture node names (Cycles' magenta if none).
    fn node_image(
        &self,
        n: &FlatNode,
    ) -> Result<std::sync::Arc<super::images::TexImage>, CompileError> {
        let name = n
            .property("image")
            .and_then(|v| v.get("name"))
            .and_then(Value::as_str);
        match (name, self.scene) {
            (Some(name), Some(scene)) => super::images::scene_image(scene, name)
                .map_err(|e| CompileError(format!("node {:?}: {e}", n.path))),
            (Some(_), None) => Err(CompileError(format!(
                "node {:?}: images need the scene",
                n.path
            ))),
            (None, _) => Ok(std::sync::Arc::new(super::images::TexImage::missing())),
        }
    }

    fn image_texture(&mut self, i: usize) -> Result<(), CompileError> {
        use crate::nodes::image::{Extension, Interpolation, Projection};
        let n = &self.g.nodes[i];
        let interpolation = mode(n, "interpolation", Interpolation::from_blender)?;
        let extension = mode(n, "extension", Extension::from_blender)?;
        let projection = mode(n, "projection", Projection::from_blender)?;
        let blend = Self::prop_f32(n, "projection_blend")?;
        if let Some(m) = n.property("texture_mapping") {
            if !identity_mapping(m) {
                return Err(CompileError(format!(
                    "node {:?}: a non-identity texture_mapping is not supported yet",
                    n.path
                )));
            }
        }
        let image = self.node_image(n)?;
        // An unlinked Vector is the UV map (Cycles' LINK_TEXTURE_UV).
        let vector = if linked(n, "Vector") {
            self.input(n, "Vector", Kind::Vector)?
        } else {
            let d = self.alloc(Kind::Vector);
            self.ops.push(Op::UvMap { dst: d });
            d
        };
        let unassociate = self.output_used(i, "Alpha") && image.unassociates();
        let (color, alpha) = (self.alloc(Kind::Color), self.alloc(Kind::Float));
        self.ops.push(Op::TexImage {
            image,
            projection,
            blend,
            interpolation,
            extension,
            unassociate,
            vector,
            color,
            alpha,
        });
        self.outputs(
            i,
            n,
            &[("Color", color, Kind::Color), ("Alpha", alpha, Kind::Float)],
        );
        Ok(())
    }

    /// Sky Texture: the model precomputed once here, as Cycles' `SkyTextureNode::compile`.
    /// Its Vector is Generated when unlinked (with Nishita's sun disc Blender makes the
    /// socket unavailable, so it always is then).
    fn sky_texture(&mut self, i: usize) -> Result<(), CompileError> {
        use crate::nodes::sky::{Sky, SkySettings, SkyType};
        let n = &self.g.nodes[i];
        let (_, vector, _) = self.texture_point(n, None)?;
        let f = |key: &str| Self::prop_f32(n, key);
        let sun = prop(n, "sun_direction")?
            .as_array()
            .filter(|a| a.len() == 3)
            .and_then(|a| {
                a.iter()
                    .map(|x| x.as_f64().map(|v| v as f32))
                    .collect::<Option<Vec<f32>>>()
            })
            .ok_or_else(|| {
                CompileError(format!(
                    "node {:?}: sun_direction is not a 3-vector",
                    n.path
                ))
            })?;
        // Blender's sync normalises the sun direction.
        let l = (sun[0] * sun[0] + sun[1] * sun[1] + sun[2] * sun[2]).sqrt();
        let settings = SkySettings {
            sky_type: mode(n, "sky_type", SkyType::from_blender)?,
            sun_direction: [sun[0] / l, sun[1] / l, sun[2] / l],
            turbidity: f("turbidity")?,
            ground_albedo: f("ground_albedo")?,
            sun_disc: prop_bool(n, "sun_disc")?,
            sun_size: f("sun_size")?,
            sun_intensity: f("sun_intensity")?,
            sun_elevation: f("sun_elevation")?,
            sun_rotation: f("sun_rotation")?,
            altitude: f("altitude")?,
            air_density: f("air_density")?,
            dust_density: f("dust_density")?,
            ozone_density: f("ozone_density")?,
        };
        let sky =
            Sky::new(&settings).map_err(|e| CompileError(format!("node {:?}: {e}", n.path)))?;
        let color = self.alloc(Kind::Color);
        self.ops.push(Op::TexSky {
            sky: std::sync::Arc::new(sky),
            vector,
            color,
            generated: !linked(n, "Vector"),
        });
        self.outputs(i, n, &[("Color", color, Kind::Color)]);
        Ok(())
    }

    fn environment_texture(&mut self, i: usize) -> Result<(), CompileError> {
        use crate::nodes::image::{EnvProjection, Interpolation};
        let n = &self.g.nodes[i];
        let interpolation = mode(n, "interpolation", Interpolation::from_blender)?;
        let projection = mode(n, "projection", EnvProjection::from_blender)?;
        if let Some(m) = n.property("texture_mapping") {
            if !identity_mapping(m) {
                return Err(CompileError(format!(
                    "node {:?}: a non-identity texture_mapping is not supported yet",
                    n.path
                )));
            }
        }
        let image = self.node_image(n)?;
        // An unlinked Vector is the position: for a world, the ray direction.
        let vector = if linked(n, "Vector") {
            self.input(n, "Vector", Kind::Vector)?
        } else {
            let d = self.alloc(Kind::Vector);
            self.ops.push(Op::Position { dst: d });
            d
        };
        let unassociate = self.output_used(i, "Alpha") && image.unassociates();
        let (color, alpha) = (self.alloc(Kind::Color), self.alloc(Kind::Float));
        self.ops.push(Op::TexEnvironment {
            image,
            projection,
            interpolation,
            unassociate,
            vector,
            color,
            alpha,
        });
        self.outputs(
            i,
            n,
            &[("Color", color, Kind::Color), ("Alpha", alpha, Kind::Float)],
        );
        Ok(())
    }
}
