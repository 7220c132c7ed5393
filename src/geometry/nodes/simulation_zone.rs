//! The Simulation zone (`GeometryNodeSimulationInput` / `GeometryNodeSimulationOutput`),
//! as a user who plays the file from the simulation's start frame sees it, which is also
//! what a bake of it holds.
//!
//! Blender 4.5 (MOD_nodes.cc, `NodesModifierSimulationParams`) keeps each zone's state
//! from the frame before: at the zone's start frame, and whenever it has no state yet
//! within its frame range, the body runs once on the zone's inputs with a Delta Time of
//! 0; each later frame runs it once on the previous state with a Delta Time of the frames
//! since that state (at most one) over the scene's frame rate; past the range's end the
//! last state stays; before its start, and past its end with no state, the inputs pass
//! through without the body. A direct jump to a frame therefore depends on what was
//! evaluated before (a fresh file gives the start frame's result at every frame in the
//! range), so blendsynth plays the simulation from its start: `playback_frames` lists the
//! frames `geometry::evaluate_object` evaluates first, each session handing its states to
//! the next (`Session::simulation`).
//!
//! Between frames Blender stores the state as a bake holds it: each field item is
//! captured on the geometry item before it (on the item's domain) and read back as that
//! attribute, other values become single values, and anonymous attributes are removed
//! from the geometries. A zone with baked data (packed or on disk) reads the bake
//! instead: blendsynth does not read bakes, so such an object is Blender's evaluated mesh
//! where valid, else an error naming the zone (`unavailable_reason`).

use super::super::attribute::{AttrId, Attributes};
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs, SimulationState};
use super::super::field::{AttributeInput, Field};
use super::super::instances::InstanceReference;
use super::super::limits;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain, Value};
use super::super::value::SocketValue;
use super::super::zones::{item_ids, Zone};
use crate::scene::{BakeState, Modifier, Object, Scene};

/// The input node is only evaluated through its zone (see `repeat_zone::repeat_input`).
pub fn simulation_input(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Err(ctx.err("is read outside its Simulation zone"))
}

/// A zone's frame range and how its state is kept.
struct Settings {
    /// None: no range (Simulation Cache off: the state starts wherever there is none).
    range: Option<(f64, Option<f64>)>,
    /// Frames per second (`fps / fps_base`, in float as Blender keeps it).
    fps: f32,
}

/// The bake item of the Simulation Output node `node` in tree `tree` (by node name and
/// tree: a group holding a zone used twice shares its item's settings).
pub(super) fn bake_of<'m>(
    m: &'m Modifier,
    node: &str,
    tree: Option<&str>,
) -> Option<&'m BakeState> {
    let bakes = m.bake_states.as_deref()?;
    let named = |b: &&BakeState| b.node.as_deref() == Some(node);
    bakes
        .iter()
        .filter(named)
        .find(|b| tree.is_none() || b.node_tree.as_deref() == tree)
        .or_else(|| bakes.iter().find(named))
}

/// Blender's `get_node_bake_frame_range`: the item's own range, else the scene's
/// simulation range (its custom one, else its frame range); at least one frame.
fn frame_range(scene: &Scene, bake: Option<&BakeState>) -> Option<(i32, Option<i32>)> {
    let (s, e) = match bake {
        Some(b) if b.use_custom_simulation_frame_range => (b.frame_start, Some(b.frame_end)),
        _ => (
            scene.file.scene.simulation_frame_start?,
            scene.file.scene.simulation_frame_end,
        ),
    };
    Some((s, e.map(|e| e.max(s))))
}

fn settings(ctx: &NodeCtx) -> Result<Settings, GeometryError> {
    let session = ctx.session();
    let scene = session.scene;
    let ev = ctx.ev;
    let flat = ctx.flat();
    // A top-level zone sits in the modifier's tree; a nested one in a group's.
    let tree = (!flat.path.contains(" > ")).then_some(ev.tree.name.as_str());
    let bake = bake_of(ev.modifier, &flat.node.name, tree);
    let (start, end) = frame_range(scene, bake).ok_or_else(|| {
        ctx.err(
            "the export does not say where simulations start (simulation_frame_start): \
             convert the .blend again with this version",
        )
    })?;
    let fps = scene.file.scene.fps / scene.file.scene.fps_base;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(ctx.err(format!(
            "the scene's frame rate {} / {} is not a positive number",
            scene.file.scene.fps, scene.file.scene.fps_base
        )));
    }
    if ev.modifier.bake_states.is_none() && session.frame != f64::from(start) {
        return Err(ctx.err(format!(
            "the export does not say whether this Simulation zone is baked or where it \
             ends, which frame {} needs: convert the .blend again with this version",
            session.frame
        )));
    }
    Ok(Settings {
        range: ev
            .object
            .use_simulation_cache
            .then(|| (f64::from(start), end.map(f64::from))),
        fps: fps as f32,
    })
}

pub fn simulation_output(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let zone = Zone::of(ctx, "GeometryNodeSimulationInput")?;
    let set = settings(ctx)?;
    let session = ctx.session();
    let frame = session.frame;
    let key = format!(
        "{}\u{1f}{}\u{1f}{}",
        ctx.ev.object.name,
        ctx.ev.modifier.name,
        ctx.flat().path
    );
    let ids = item_ids(&ctx.node().outputs, "Item_");
    let items = item_types(ctx, &ids, "state_items")?;
    // A state from a later frame means time moved back: Blender starts again.
    let prev = session
        .simulation
        .borrow()
        .get(&key)
        .filter(|p| p.frame <= frame)
        .cloned();
    // Blender compares frames with subframes by their whole frame first (`SubFrame`):
    // with a state, a subframe of the last frame still steps; without one it is past.
    let end = set.range.and_then(|(_, e)| e);
    let out = match prev {
        Some(p) if p.frame == frame || end.is_some_and(|e| frame.floor() > e) => p.items,
        Some(p) => {
            let delta = ((frame - p.frame) as f32).min(1.0) / set.fps;
            let items = step(ctx, &zone, &ids, &items, p.items, delta)?;
            store(ctx, &key, frame, &items);
            items
        }
        None => {
            let input = zone.input_ctx(ctx);
            let mut initial = Vec::with_capacity(ids.len());
            for (id, (kind, _)) in ids.iter().zip(&items) {
                initial.push(item_value(&input, id, kind)?);
            }
            let initial = to_state(initial, &items).map_err(|e| ctx.err(e))?;
            let outside = set
                .range
                .is_some_and(|(s, e)| frame < s || e.is_some_and(|e| frame > e));
            if outside {
                initial
            } else {
                let items = step(ctx, &zone, &ids, &items, initial, 0.0)?;
                store(ctx, &key, frame, &items);
                items
            }
        }
    };
    Ok(ids.into_iter().zip(out).collect())
}

fn store(ctx: &NodeCtx, key: &str, frame: f64, items: &[SocketValue]) {
    ctx.session().simulation.borrow_mut().insert(
        key.to_string(),
        SimulationState {
            frame,
            items: items.to_vec(),
        },
    );
}

/// Runs the body once on `state` with `delta` as Delta Time: the new state, or `state`
/// itself when Skip is on.
fn step(
    ctx: &NodeCtx,
    zone: &Zone,
    ids: &[String],
    items: &[(String, Domain)],
    state: Vec<SocketValue>,
    delta: f32,
) -> Result<Vec<SocketValue>, GeometryError> {
    zone.spend(ctx, 1, "the simulation step")?;
    let mut values: Outputs = ids.iter().cloned().zip(state.iter().cloned()).collect();
    values.insert("Delta Time".into(), SocketValue::float(delta));
    // Skip may be computed inside the zone, so it is evaluated with the body.
    let mut wanted = ids.to_vec();
    wanted.push("Skip".into());
    let mut stepped = zone.run(ctx, values, &wanted)?;
    let skip = match stepped.pop() {
        Some(SocketValue::Field(f)) => f.as_constant().map(|v| v.as_bool()).ok_or_else(|| {
            ctx.err("input \"Skip\" takes a single value but a field is connected")
        })?,
        _ => false,
    };
    if skip {
        return Ok(state);
    }
    let stepped = stepped
        .into_iter()
        .zip(items)
        .map(|(v, (kind, _))| convert_item(v, kind))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| ctx.err(e))?;
    to_state(stepped, items).map_err(|e| ctx.err(e))
}

/// Each item's socket type and attribute domain (the node's `items` property, e.g.
/// `state_items`, in order).
pub(super) fn item_types(
    ctx: &NodeCtx,
    ids: &[String],
    items: &str,
) -> Result<Vec<(String, Domain)>, GeometryError> {
    let props = ctx
        .prop(items)
        .and_then(|v| v.as_array())
        .ok_or_else(|| ctx.err(format!("the export has no {items}")))?;
    if props.len() != ids.len() {
        return Err(ctx.err(format!(
            "{} {items} but {} item sockets",
            props.len(),
            ids.len()
        )));
    }
    ids.iter()
        .zip(props)
        .map(|(id, p)| {
            let kind = ctx
                .node()
                .outputs
                .iter()
                .find(|s| &s.identifier == id)
                .map(|s| s.kind.clone())
                .unwrap_or_default();
            let domain = p
                .get("attribute_domain")
                .and_then(|d| d.as_str())
                .and_then(Domain::parse)
                .unwrap_or(Domain::Point);
            Ok((kind, domain))
        })
        .collect()
}

/// The value of input `id` of the zone's input node, as the item's type.
fn item_value(ctx: &NodeCtx, id: &str, kind: &str) -> Result<SocketValue, GeometryError> {
    let v = ctx.input(id)?;
    convert_item(v, kind).map_err(|e| ctx.err(e))
}

pub(super) fn convert_item(v: SocketValue, kind: &str) -> Result<SocketValue, String> {
    Ok(match (v, DataType::from_socket(kind)) {
        (SocketValue::Field(f), Some(ty)) => SocketValue::Field(f.convert(ty)),
        (v, _) => v,
    })
}

/// The items as Blender's simulation state holds them (`move_socket_values_to_bake_items`
/// and back): a field item captured on the last geometry item before it and read back
/// as that attribute (an attribute of no geometry, read as zeros, when there is none);
/// anonymous attributes of the geometries removed, nested instances included.
pub(super) fn to_state(
    mut values: Vec<SocketValue>,
    items: &[(String, Domain)],
) -> Result<Vec<SocketValue>, String> {
    let all = Field::Constant(Value::Bool(true));
    let mut keep: Vec<Vec<AttrId>> = vec![Vec::new(); values.len()];
    let mut last_geometry = None;
    for i in 0..values.len() {
        if matches!(values[i], SocketValue::Geometry(_)) {
            last_geometry = Some(i);
            continue;
        }
        let SocketValue::Field(f) = &values[i] else {
            continue;
        };
        if !f.depends_on_context() {
            continue;
        }
        let ty = f.data_type();
        let id = AttrId::anonymous("Simulation state");
        if let Some(g) = last_geometry {
            let f = f.clone();
            if let SocketValue::Geometry(set) = &mut values[g] {
                super::attribute::store(set, &id, items[i].1, &f, &all, Some(ty))?;
            }
            keep[g].push(id.clone());
        }
        values[i] = SocketValue::Field(Field::input(AttributeInput { id, ty }));
    }
    for (v, keep) in values.iter_mut().zip(&keep) {
        if let SocketValue::Geometry(g) = v {
            remove_anonymous(g, keep);
        }
    }
    Ok(values)
}

fn remove_anonymous(g: &mut GeometrySet, keep: &[AttrId]) {
    let drop = |a: &Attributes| {
        a.iter()
            .any(|x| x.id.is_anonymous() && !keep.contains(&x.id))
    };
    let clean = |a: &mut Attributes| {
        let gone: Vec<AttrId> = a
            .iter()
            .filter(|x| x.id.is_anonymous() && !keep.contains(&x.id))
            .map(|x| x.id.clone())
            .collect();
        for id in gone {
            a.remove(&id);
        }
    };
    // Write access copies shared data, so only where something goes.
    if g.mesh.as_ref().is_some_and(|m| drop(&m.attributes)) {
        clean(&mut g.mesh_mut().unwrap().attributes);
    }
    if g.points.as_ref().is_some_and(|p| drop(&p.attributes)) {
        clean(&mut g.points_mut().unwrap().attributes);
    }
    if g.curves.as_ref().is_some_and(|c| drop(&c.attributes)) {
        clean(&mut g.curves_mut().unwrap().attributes);
    }
    if let Some(inst) = g.instances.as_ref() {
        let nested = inst.references.iter().any(|r| match r {
            InstanceReference::Geometry(s) | InstanceReference::Object(_, s) => has_anonymous(s),
            InstanceReference::None => false,
        });
        if nested || drop(&inst.attributes) {
            let inst = g.instances_mut().unwrap();
            clean(&mut inst.attributes);
            for r in inst.references.iter_mut() {
                if let InstanceReference::Geometry(s) | InstanceReference::Object(_, s) = r {
                    remove_anonymous(s, &[]);
                }
            }
        }
    }
}

fn has_anonymous(g: &GeometrySet) -> bool {
    let any = |a: &Attributes| a.iter().any(|x| x.id.is_anonymous());
    g.mesh.as_ref().is_some_and(|m| any(&m.attributes))
        || g.points.as_ref().is_some_and(|p| any(&p.attributes))
        || g.curves.as_ref().is_some_and(|c| any(&c.attributes))
        || g.instances.as_ref().is_some_and(|i| {
            any(&i.attributes)
                || i.references.iter().any(|r| match r {
                    InstanceReference::Geometry(s) | InstanceReference::Object(_, s) => {
                        has_anonymous(s)
                    }
                    InstanceReference::None => false,
                })
        })
}

/// The Simulation Output nodes of `o`'s render-enabled Geometry Nodes modifiers, nested
/// groups included: (modifier, node name, tree name).
fn zones_of<'s>(scene: &'s Scene, o: &'s Object) -> Vec<(&'s Modifier, &'s str, &'s str)> {
    let mut found = Vec::new();
    for m in o
        .modifiers
        .iter()
        .filter(|m| m.show_render && m.kind == "NODES")
    {
        for (tree, n) in m
            .node_group
            .as_deref()
            .map_or_else(Vec::new, |g| scene.group_nodes(g))
        {
            if n.bl_idname == "GeometryNodeSimulationOutput" {
                found.push((m, n.name.as_str(), tree.name.as_str()));
            }
        }
    }
    found
}

/// Why node `node` of tree `tree` (a Simulation zone or a Bake node, `what`) in modifier
/// `m`, whose export records bake states, cannot be evaluated: it holds baked data Blender
/// reads instead of `instead`, or the exporter could not tell whether it does.
pub(super) fn baked_verdict(
    m: &Modifier,
    node: &str,
    tree: &str,
    what: &str,
    instead: &str,
) -> Option<String> {
    let bake = bake_of(m, node, Some(tree))?;
    match bake.baked {
        Some(false) => None,
        Some(true) => {
            let place = match bake.target.as_deref() {
                Some("DISK") => "on disk",
                _ => "packed in the .blend",
            };
            Some(format!(
                "{what} {node:?} (modifier {:?}) holds baked data ({place}) that Blender reads \
                 instead of {instead}; blendsynth does not read bakes",
                m.name
            ))
        }
        None => Some(format!(
            "{what} {node:?} (modifier {:?}): the exporter could not tell whether it holds \
             baked data",
            m.name
        )),
    }
}

/// Why blendsynth cannot evaluate `o`'s Simulation zones at `frame`: a zone whose baked
/// data Blender reads instead of simulating, or, at any frame but the start, an older
/// export that does not say whether a zone is baked. None when every zone plays natively.
pub fn unavailable_reason(scene: &Scene, o: &Object, frame: f64) -> Option<String> {
    for (m, node, tree) in zones_of(scene, o) {
        let Some(_) = m.bake_states else {
            let start = scene.file.scene.simulation_frame_start;
            if start.is_some_and(|s| f64::from(s) == frame) {
                continue;
            }
            return Some(format!(
                "Simulation zone {node:?} at frame {frame}: the export does not say whether \
                 it is baked (convert the .blend again with this version)"
            ));
        };
        if let Some(why) = baked_verdict(m, node, tree, "Simulation zone", "simulating") {
            return Some(why);
        }
    }
    None
}

/// Whether `o`'s geometry may depend on a Simulation zone: its own Geometry Nodes hold
/// one, or read other objects' geometry (Object Info, Collection Info), which may.
fn may_simulate(scene: &Scene, o: &Object) -> bool {
    let reads_objects = o
        .modifiers
        .iter()
        .filter(|m| m.show_render && m.kind == "NODES")
        .filter_map(|m| m.node_group.as_deref())
        .any(|g| {
            scene.group_nodes(g).iter().any(|(_, n)| {
                matches!(
                    n.bl_idname.as_str(),
                    "GeometryNodeObjectInfo" | "GeometryNodeCollectionInfo"
                )
            })
        });
    reads_objects || !zones_of(scene, o).is_empty()
}

/// The frames `geometry::evaluate_object` evaluates `object` at, in order, before `frame`
/// so that every Simulation zone of the scene has played up to it: each whole frame from
/// the earliest zone start to the frame before `frame` (up to the latest zone end, past
/// which states stay). Empty when the scene has no Simulation zone or the object's
/// geometry cannot depend on one.
pub fn playback_frames(scene: &Scene, object: &str, frame: f64) -> Result<Vec<f64>, GeometryError> {
    if !scene.object(object).is_some_and(|o| may_simulate(scene, o)) {
        return Ok(Vec::new());
    }
    let mut first: Option<i32> = None;
    let mut last: Option<i32> = None;
    let mut unbounded = false;
    for o in &scene.file.objects {
        for (m, node, tree) in zones_of(scene, o) {
            let Some((s, e)) = frame_range(scene, bake_of(m, node, Some(tree))) else {
                continue;
            };
            // Without the cache a zone starts at the first frame evaluated: playback
            // starts at the scene's first frame.
            let s = if o.use_simulation_cache {
                s
            } else {
                scene.file.scene.frame_start
            };
            first = Some(first.map_or(s, |f| f.min(s)));
            match e {
                Some(e) if o.use_simulation_cache => last = Some(last.map_or(e, |l| l.max(e))),
                _ => unbounded = true,
            }
        }
    }
    let Some(first) = first else {
        return Ok(Vec::new());
    };
    // The whole frames before `frame`.
    let before = frame.ceil() - 1.0;
    let upto = match last {
        Some(l) if !unbounded => before.min(f64::from(l)),
        _ => before,
    };
    let first = f64::from(first);
    if upto < first {
        return Ok(Vec::new());
    }
    let count = upto - first + 1.0;
    if count > limits::MAX_SIMULATION_FRAMES as f64 {
        return Err(GeometryError::new(format!(
            "frame {frame} is {count} frames after the simulation start {first}: playing \
             the Simulation zones up to it is more than the limit of {} frames \
             (docs/limits.md)",
            limits::MAX_SIMULATION_FRAMES
        )));
    }
    Ok((0..count as u64).map(|k| first + k as f64).collect())
}
