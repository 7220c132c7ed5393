//! Where an object's geometry comes from, decided in one place for `render`, `mesh`,
//! `generate` and `inspect`: nothing (no geometry), its exported mesh, blendsynth's own
//! evaluation of its modifier stack, or Blender's evaluated mesh from the export
//! ("frozen", valid only while nothing it reads changes). Anything else is an error
//! naming the object and what it has, so no object is ever dropped without a word.

use crate::scene::{quote, Evaluated, Object, Scene};

use super::GeometryError;

/// Object types that hold no renderable geometry of their own.
pub const NO_GEOMETRY: &[&str] = &[
    "EMPTY",
    "LIGHT",
    "CAMERA",
    "SPEAKER",
    "LIGHT_PROBE",
    "ARMATURE",
    "LATTICE",
    // Cycles does not render Grease Pencil.
    "GPENCIL",
    "GREASEPENCIL",
];

/// Modifiers blendsynth evaluates outside `geometry::modifiers` (`eval::Session::
/// evaluate_stack`): Geometry Nodes and Subdivision Surface. With `modifiers::KINDS`,
/// these are the native ones.
const EVALUATED_ELSEWHERE: &[&str] = &["NODES", "SUBSURF"];

/// Every modifier type blendsynth evaluates itself (some only with some options).
pub fn native_modifiers() -> Vec<&'static str> {
    [EVALUATED_ELSEWHERE, super::modifiers::KINDS].concat()
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// No geometry: empties, lights, cameras, armatures, ...
    None,
    /// The exported mesh `meshes[i]` as it is.
    Mesh(usize),
    /// blendsynth evaluates the modifier stack (Geometry Nodes, Subdivision Surface) on
    /// the object's mesh or curve.
    Evaluate,
    /// Blender's evaluated mesh `evaluated[i]`, checked valid at the frame and overrides.
    Frozen(usize),
}

/// Whether blendsynth evaluates this modifier itself (one of `modifiers::KINDS` only
/// with the options its module evaluates).
fn native(m: &crate::scene::Modifier) -> bool {
    let kind = m.kind.as_str();
    EVALUATED_ELSEWHERE.contains(&kind)
        || (super::modifiers::KINDS.contains(&kind)
            && super::modifiers::unsupported(kind, &m.properties).is_none())
}

/// Why an object needs Blender's evaluated mesh, or None when blendsynth builds it.
pub fn frozen_reason(scene: &Scene, o: &Object) -> Option<String> {
    let mods: Vec<_> = o.modifiers.iter().filter(|m| m.show_render).collect();
    match o.kind.as_str() {
        "EMPTY"
            if o.instance_type.as_deref() == Some("COLLECTION")
                && o.instance_collection.is_some() =>
        {
            Some(format!(
                "instances collection {:?}",
                o.instance_collection.as_deref().unwrap_or("")
            ))
        }
        "MESH" => {
            let mut why = Vec::new();
            let other: Vec<String> = mods
                .iter()
                .filter(|m| !native(m))
                .map(|m| {
                    match super::modifiers::KINDS
                        .contains(&m.kind.as_str())
                        .then(|| super::modifiers::unsupported(&m.kind, &m.properties))
                        .flatten()
                    {
                        Some(why) => format!("{} {:?} ({why})", m.kind, m.name),
                        None => format!("{} {:?}", m.kind, m.name),
                    }
                })
                .collect();
            if !other.is_empty() {
                why.push(format!("modifier(s) {}", other.join(", ")));
            }
            // blendsynth's Catmull-Clark does not yet give Blender's mesh on a Solidify
            // rim (the rim's degenerate UV quads, its creases on meshes with loose
            // parts): such a stack keeps Blender's mesh.
            let rim = mods.iter().position(|m| {
                m.kind == "SOLIDIFY" && super::modifiers::solidify::fills_rim(&m.properties)
            });
            if let Some(sub) = rim.and_then(|r| mods[r..].iter().find(|m| m.kind == "SUBSURF")) {
                why.push(format!(
                    "SUBSURF {:?} after the rim of SOLIDIFY {:?} (not evaluated natively yet)",
                    sub.name,
                    mods[rim.unwrap_or(0)].name
                ));
            }
            let shape_keys = o
                .data
                .as_deref()
                .and_then(|d| scene.file.meshes.iter().find(|m| m.name == d))
                .is_some_and(|m| m.shape_keys);
            if shape_keys {
                why.push("shape keys".into());
            }
            if matches!(o.instance_type.as_deref(), Some("VERTS" | "FACES")) {
                why.push(format!(
                    "instancing by {}",
                    o.instance_type.as_deref().unwrap_or("").to_lowercase()
                ));
            }
            (!why.is_empty()).then(|| why.join(", "))
        }
        "CURVE" => {
            if !mods.is_empty() && mods.iter().all(|m| m.kind == "NODES") {
                None
            } else if mods.iter().any(|m| m.kind != "NODES") {
                Some(format!(
                    "curve object with modifier(s) {}",
                    mods.iter()
                        .map(|m| format!("{} {:?}", m.kind, m.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            } else if curve_has_surface(scene, o) {
                Some("curve object meshed as Blender meshes it (bevel, extrude, fill)".into())
            } else {
                // A bare path (no bevel, extrude or 2D fill): Blender makes no faces of it
                // and Cycles renders nothing (object_source gives None).
                None
            }
        }
        // Cycles renders a Curves object's evaluated curves as hair (the export's
        // strands) and any mesh its Geometry Nodes make; blendsynth evaluates neither.
        "CURVES" => Some("Curves object".into()),
        // Cycles renders a point cloud object's points as spheres (the export's points).
        "POINTCLOUD" => Some("point cloud object".into()),
        "SURFACE" => Some("NURBS surface object".into()),
        "FONT" => Some("text object".into()),
        "META" => Some("metaball object".into()),
        _ => None,
    }
}

/// Whether Blender makes faces of a curve object without modifiers: a bevel (depth, or
/// an object in Object mode), an extrusion, or a 2D curve whose closed splines are filled.
pub fn curve_has_surface(scene: &Scene, o: &Object) -> bool {
    let Some(c) = o
        .data
        .as_deref()
        .and_then(|d| scene.file.curves.iter().find(|c| c.name == d))
    else {
        return false;
    };
    let p = &c.properties;
    let num = |k: &str| p.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0);
    let text = |k: &str| p.get(k).and_then(|v| v.as_str()).unwrap_or("");
    let bevel_object = text("bevel_mode") == "OBJECT" && !text("bevel_object").is_empty();
    let filled_2d = text("dimensions") == "2D"
        && text("fill_mode") != "NONE"
        && c.splines.iter().any(|s| s.use_cyclic_u);
    num("bevel_depth") > 0.0 || num("extrude") > 0.0 || bevel_object || filled_2d
}

/// The source of object `o`'s geometry at `frame`, with `overrides` (data paths) applied
/// beside the scene's own. Errors name the object and what blendsynth cannot do with it.
pub fn object_source(
    scene: &Scene,
    o: &Object,
    frame: f64,
    overrides: &[String],
) -> Result<Source, GeometryError> {
    let here = format!("object {:?}", o.name);
    if let Some(reason) = frozen_reason(scene, o) {
        return frozen(scene, o, frame, overrides, &reason).map(Source::Frozen);
    }
    if NO_GEOMETRY.contains(&o.kind.as_str()) {
        return Ok(Source::None);
    }
    let has_mods = o.modifiers.iter().any(|m| m.show_render);
    // A Geometry Nodes stack with a node blendsynth does not evaluate (the Auto Smooth
    // modifier 4.1 adds to old files, ...): Blender's evaluated mesh, while valid.
    if matches!(o.kind.as_str(), "MESH" | "CURVE") {
        let reason = unsupported_gn_node(scene, o)
            .map(|node| format!("Geometry Nodes node {node} that blendsynth does not evaluate"))
            .or_else(|| simulation_after_start(scene, o, frame));
        if let Some(reason) = reason {
            let has_frozen = scene
                .file
                .evaluated
                .iter()
                .any(|e| e.object == o.name && e.reads.is_some());
            if has_frozen {
                return frozen(scene, o, frame, overrides, &reason).map(Source::Frozen);
            }
        }
    }
    match o.kind.as_str() {
        "MESH" => {
            let mi = mesh_index(scene, o)?;
            Ok(if has_mods {
                Source::Evaluate
            } else {
                Source::Mesh(mi)
            })
        }
        "CURVE" if !has_mods => Ok(Source::None),
        "CURVE" => Ok(Source::Evaluate),
        // Voxel grids, no mesh: `render` draws them (render/build.rs push_volume_object),
        // and Blender's `Object.to_mesh` of one is empty.
        "VOLUME" => Ok(Source::None),
        other => Err(GeometryError::new(format!(
            "{here}: {other} objects are not supported by the renderer"
        ))),
    }
}

/// The first node (`"name" (bl_idname)`) of the object's render-enabled Geometry Nodes
/// modifiers, nested groups included, that the evaluator does not implement.
pub fn unsupported_gn_node(scene: &Scene, o: &Object) -> Option<String> {
    fn walk(scene: &Scene, group: &str, seen: &mut Vec<String>) -> Option<String> {
        if seen.iter().any(|g| g == group) {
            return None;
        }
        seen.push(group.to_string());
        let tree = scene.node_group(group)?;
        for n in &tree.nodes {
            if let Some(g) = n.node_tree.as_deref() {
                if let Some(x) = walk(scene, g, seen) {
                    return Some(x);
                }
            }
            if super::support_in("GeometryNodeTree", &n.bl_idname)
                == crate::nodes::Support::Unsupported
            {
                return Some(format!("{:?} ({})", n.name, n.bl_idname));
            }
        }
        None
    }
    let mut seen = Vec::new();
    o.modifiers
        .iter()
        .filter(|m| m.show_render && m.kind == "NODES")
        .filter_map(|m| m.node_group.as_deref())
        .find_map(|g| walk(scene, g, &mut seen))
}

/// Why `o` is frozen at `frame` when its Geometry Nodes hold a Simulation zone blendsynth
/// cannot play: one with baked data (Blender reads the bake instead of simulating), or
/// an older export that does not say whether it is baked, at any frame but the start;
/// or a Bake node with baked data (or an export that cannot tell), at any frame.
/// Only Blender's evaluated mesh (the export's, or `convert --frames`) has it then.
pub fn simulation_after_start(scene: &Scene, o: &Object, frame: f64) -> Option<String> {
    super::nodes::simulation_zone::unavailable_reason(scene, o, frame)
        .or_else(|| super::nodes::bake::baked_reason(scene, o))
}

/// Blender's evaluated mesh of `o` in place of blendsynth's own evaluation, for `reason`,
/// when the export has one that is valid at the frame and overrides; None otherwise.
pub fn frozen_instead(
    scene: &Scene,
    o: &Object,
    frame: f64,
    overrides: &[String],
    reason: &str,
) -> Option<usize> {
    let has_frozen = scene
        .file
        .evaluated
        .iter()
        .any(|e| e.object == o.name && e.reads.is_some());
    has_frozen
        .then(|| frozen(scene, o, frame, overrides, reason).ok())
        .flatten()
}

/// The export's evaluated mesh of `o`, when it may stand for the object at `frame` with
/// the scene's overrides: nothing it reads is animated (or the frame is the exported
/// one) and no override changed what it reads.
fn frozen(
    scene: &Scene,
    o: &Object,
    frame: f64,
    overrides: &[String],
    reason: &str,
) -> Result<usize, GeometryError> {
    let here = format!("object {:?} ({reason})", o.name);
    // `convert --frames A..B` writes one entry per frame for objects whose evaluation is
    // animated: the one at the frame, else the first (valid at any frame when nothing it
    // reads is animated).
    let entries = || {
        scene
            .file
            .evaluated
            .iter()
            .enumerate()
            .filter(|(_, e)| e.object == o.name && e.reads.is_some())
    };
    let Some((i, e)) = entries()
        .find(|(_, e)| (e.frame - frame).abs() <= 1e-6)
        .or_else(|| entries().next())
    else {
        return Err(GeometryError::new(format!(
            "{here}: blendsynth does not evaluate this and the export has no frozen mesh of it (convert the .blend again with this version)"
        )));
    };
    let all: Vec<String> = scene
        .file
        .overridden
        .iter()
        .chain(overrides)
        .cloned()
        .collect();
    check_frozen(&o.name, e, frame, &all)
        .map_err(|m| GeometryError::new(format!("{here}: {m}")))?;
    if e.volume_grids > 0 {
        // The frozen mesh carries no grids: rendering it would drop the volume.
        return Err(GeometryError::new(format!(
            "{here}: Blender's evaluated geometry holds a volume ({} grid{}), which blendsynth does not evaluate from this node tree and the frozen mesh does not carry",
            e.volume_grids,
            if e.volume_grids == 1 { "" } else { "s" }
        )));
    }
    Ok(i)
}

/// Whether frozen geometry `e` is still what Blender would evaluate: at its own frame
/// or with nothing it reads animated, and with no override under what it reads.
pub fn check_frozen(
    object: &str,
    e: &Evaluated,
    frame: f64,
    overridden: &[String],
) -> Result<(), String> {
    if let Some(u) = e.unsupported.first() {
        return Err(format!(
            "{u} is not in Blender's evaluated mesh and not supported by the renderer"
        ));
    }
    let reads = e.reads.as_deref().unwrap_or(&[]);
    if (frame - e.frame).abs() > 1e-6 {
        if let Some(p) = e.animated.first() {
            return Err(format!(
                "its geometry is frozen (Blender's evaluated mesh at frame {}) and reads animated {p}; frame {frame} would need Blender to evaluate it again (convert with --frame {frame}, or --frames A..B over the frames to render)",
                e.frame
            ));
        }
    }
    for p in overridden {
        let p = normalise(p);
        if let Some(r) = reads.iter().find(|r| under(&p, &normalise(r))) {
            return Err(format!(
                "its geometry is frozen (Blender's evaluated mesh of {}) and override {p} changes {r}, which blendsynth cannot evaluate",
                quote(object)
            ));
        }
    }
    Ok(())
}

/// Single-quoted keys written as the exporter writes them (double quotes).
fn normalise(p: &str) -> String {
    p.strip_prefix("bpy.data.")
        .unwrap_or(p)
        .replace("['", "[\"")
        .replace("']", "\"]")
}

/// Whether data path `p` is `prefix` or inside it.
fn under(p: &str, prefix: &str) -> bool {
    p == prefix
        || (p.starts_with(prefix) && matches!(p.as_bytes().get(prefix.len()), Some(b'.' | b'[')))
        // An override of the whole container also changes what is inside it.
        || (prefix.starts_with(p) && matches!(prefix.as_bytes().get(p.len()), Some(b'.' | b'[')))
}

/// The index in the export's meshes of a mesh object's data.
pub(super) fn mesh_index(scene: &Scene, o: &Object) -> Result<usize, GeometryError> {
    let here = format!("objects[{}]", quote(&o.name));
    let data = o
        .data
        .as_deref()
        .ok_or_else(|| GeometryError::new(format!("{here}: mesh object without mesh data")))?;
    scene
        .file
        .meshes
        .iter()
        .position(|m| m.name == data)
        .ok_or_else(|| GeometryError::new(format!("{here}: mesh {data:?} is not in the export")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(animated: &[&str]) -> Evaluated {
        serde_json::from_value(serde_json::json!({
            "object": "Cube", "frame": 1.0, "file": "evaluated/0000_Cube.glb",
            "reads": ["objects[\"Cube\"].modifiers", "meshes[\"Cube\"]", "shape_keys[\"Key\"]"],
            "animated": animated,
        }))
        .unwrap()
    }

    #[test]
    fn frozen_mesh_is_valid_only_while_its_inputs_are_unchanged() {
        let still = entry(&[]);
        assert!(check_frozen("Cube", &still, 7.0, &[]).is_ok());
        let moving = entry(&["shape_keys[\"Key\"].key_blocks[\"A\"].value"]);
        assert!(check_frozen("Cube", &moving, 1.0, &[]).is_ok());
        let e = check_frozen("Cube", &moving, 2.0, &[]).unwrap_err();
        assert!(
            e.contains("key_blocks[\"A\"].value") && e.contains("frame 1"),
            "{e}"
        );
        // Moving the object is fine; changing its modifiers or data is not.
        let ok = [
            "objects[\"Cube\"].location".to_string(),
            "objects[\"Cube.001\"].modifiers[\"A\"].count".into(),
        ];
        assert!(check_frozen("Cube", &still, 1.0, &ok).is_ok());
        for bad in [
            "objects['Cube'].modifiers['Array'].count",
            "bpy.data.meshes[\"Cube\"].vertices[0].co",
            "objects[\"Cube\"].modifiers",
        ] {
            let e = check_frozen("Cube", &still, 1.0, &[bad.to_string()]).unwrap_err();
            assert!(e.contains("override"), "{e}");
        }
    }
}
