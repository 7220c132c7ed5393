//! Cross-reference checks on a parsed scene file: every name that points somewhere must
//! land, and every file path must stay inside the scene folder. Errors name the JSON path.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::{resolve_inside, NodeTree, Scene, SceneError};

pub(super) fn validate(scene: &Scene, json: &Path) -> Result<(), SceneError> {
    let f = &scene.file;
    let err = |loc: String, msg: String| Err(SceneError::new(json, loc, msg));

    let objects = unique(json, "objects", f.objects.iter().map(|o| o.name.as_str()))?;
    let meshes = unique(json, "meshes", f.meshes.iter().map(|m| m.name.as_str()))?;
    let curves = unique(json, "curves", f.curves.iter().map(|c| c.name.as_str()))?;
    let materials = unique(
        json,
        "materials",
        f.materials.iter().map(|m| m.name.as_str()),
    )?;
    let worlds = unique(json, "worlds", f.worlds.iter().map(|w| w.name.as_str()))?;
    let groups = unique(
        json,
        "node_groups",
        f.node_groups.iter().map(|g| g.name.as_str()),
    )?;
    let cameras = unique(json, "cameras", f.cameras.iter().map(|c| c.name.as_str()))?;
    let lights = unique(json, "lights", f.lights.iter().map(|l| l.name.as_str()))?;
    unique(json, "images", f.images.iter().map(|i| i.name.as_str()))?;

    if let Some(cam) = &f.scene.camera {
        if !objects.contains(cam.as_str()) {
            return err(
                "scene.camera".into(),
                format!("names object {cam:?}, which is not in objects"),
            );
        }
    }
    for (i, m) in f.scene.camera_markers.iter().enumerate() {
        if !objects.contains(m.camera.as_str()) {
            return err(
                format!("scene.camera_markers[{i}].camera"),
                format!("names object {:?}, which is not in objects", m.camera),
            );
        }
    }
    if let Some(w) = &f.scene.world {
        if !worlds.contains(w.as_str()) {
            return err(
                "scene.world".into(),
                format!("names world {w:?}, which is not in worlds"),
            );
        }
    }

    for (i, o) in f.objects.iter().enumerate() {
        let at = |field: &str| format!("objects[{i}] ({:?}).{field}", o.name);
        if let Some(d) = &o.data {
            let (list, set) = match o.kind.as_str() {
                "MESH" => ("meshes", Some(&meshes)),
                "CURVE" => ("curves", Some(&curves)),
                "CAMERA" => ("cameras", Some(&cameras)),
                "LIGHT" => ("lights", Some(&lights)),
                _ => ("", None),
            };
            if let Some(set) = set {
                if !set.contains(d.as_str()) {
                    return err(
                        at("data"),
                        format!("names {list} entry {d:?}, which does not exist"),
                    );
                }
            }
        }
        if let Some(p) = &o.parent {
            if !objects.contains(p.as_str()) {
                return err(
                    at("parent"),
                    format!("names object {p:?}, which does not exist"),
                );
            }
        }
        for (s, slot) in o.material_slots.iter().enumerate() {
            if let Some(m) = &slot.material {
                if !materials.contains(m.as_str()) {
                    return err(
                        at(&format!("material_slots[{s}].material")),
                        format!("names material {m:?}, which does not exist"),
                    );
                }
            }
        }
        for (k, m) in o.modifiers.iter().enumerate() {
            if let Some(g) = &m.node_group {
                if !groups.contains(g.as_str()) {
                    return err(
                        at(&format!("modifiers[{k}].node_group")),
                        format!("names node group {g:?}, which does not exist"),
                    );
                }
            }
        }
        check_matrix(json, &at("matrix_world"), &o.matrix_world)?;
    }

    for (i, m) in f.meshes.iter().enumerate() {
        resolve_inside(&scene.dir, &m.file)
            .map_err(|e| SceneError::new(json, format!("meshes[{i}].file"), e))?;
        for (s, mat) in m.materials.iter().enumerate() {
            if let Some(mat) = mat {
                if !materials.contains(mat.as_str()) {
                    return err(
                        format!("meshes[{i}].materials[{s}]"),
                        format!("names material {mat:?}, which does not exist"),
                    );
                }
            }
        }
    }
    for (i, e) in f.evaluated.iter().enumerate() {
        resolve_inside(&scene.dir, &e.file)
            .map_err(|m| SceneError::new(json, format!("evaluated[{i}].file"), m))?;
        if !objects.contains(e.object.as_str()) {
            return err(
                format!("evaluated[{i}].object"),
                format!("names object {:?}, which does not exist", e.object),
            );
        }
    }
    let grid_owners = f
        .smoke_domains
        .iter()
        .map(|d| ("smoke_domains", &d.object, &d.grids))
        .chain(
            f.volume_objects
                .iter()
                .map(|v| ("volume_objects", &v.object, &v.grids)),
        );
    let mut counts: HashMap<&str, usize> = HashMap::new();
    for (list, object, grids) in grid_owners {
        let i = counts.entry(list).or_default();
        if !objects.contains(object.as_str()) {
            return err(
                format!("{list}[{i}].object"),
                format!("names object {object:?}, which does not exist"),
            );
        }
        for (g, grid) in grids.iter().enumerate() {
            resolve_inside(&scene.dir, &grid.file)
                .map_err(|m| SceneError::new(json, format!("{list}[{i}].grids[{g}].file"), m))?;
        }
        *i += 1;
    }
    for (i, im) in f.images.iter().enumerate() {
        if let Some(p) = &im.file {
            resolve_inside(&scene.dir, p)
                .map_err(|m| SceneError::new(json, format!("images[{i}].file"), m))?;
        }
    }
    // The colour-management folder is a folder; the config in it is a regular file.
    if let Some(p) = &f.color_management.dir {
        let joined = super::confine(&scene.dir, p)
            .map_err(|m| SceneError::new(json, "color_management.dir", m))?;
        if joined.exists() && !joined.is_dir() {
            return err(
                "color_management.dir".into(),
                format!("path {p:?} is not a folder"),
            );
        }
    }
    if let Some(p) = &f.color_management.config {
        resolve_inside(&scene.dir, p)
            .map_err(|m| SceneError::new(json, "color_management.config", m))?;
    }

    for (i, m) in f.materials.iter().enumerate() {
        if let Some(t) = &m.node_tree {
            check_tree(json, &format!("materials[{i}].node_tree"), t, &groups)?;
        }
    }
    for (i, w) in f.worlds.iter().enumerate() {
        if let Some(t) = &w.node_tree {
            check_tree(json, &format!("worlds[{i}].node_tree"), t, &groups)?;
        }
    }
    for (i, g) in f.node_groups.iter().enumerate() {
        check_tree(json, &format!("node_groups[{i}]"), g, &groups)?;
    }
    Ok(())
}

fn unique<'a>(
    json: &Path,
    list: &str,
    names: impl Iterator<Item = &'a str>,
) -> Result<HashSet<&'a str>, SceneError> {
    let mut set = HashSet::new();
    for (i, n) in names.enumerate() {
        if !set.insert(n) {
            return Err(SceneError::new(
                json,
                format!("{list}[{i}].name"),
                format!("{n:?} appears twice"),
            ));
        }
    }
    Ok(set)
}

fn check_matrix(json: &Path, loc: &str, m: &[[f64; 4]; 4]) -> Result<(), SceneError> {
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(SceneError::new(json, loc, "has a non-finite entry"));
    }
    Ok(())
}

/// Node names are unique, links land on existing sockets, group nodes name existing
/// groups, socket indices match their positions.
fn check_tree(
    json: &Path,
    at: &str,
    t: &NodeTree,
    groups: &HashSet<&str>,
) -> Result<(), SceneError> {
    let err = |loc: String, msg: String| Err(SceneError::new(json, loc, msg));
    let mut nodes: HashMap<&str, usize> = HashMap::new();
    for (i, n) in t.nodes.iter().enumerate() {
        if nodes.insert(n.name.as_str(), i).is_some() {
            return err(
                format!("{at}.nodes[{i}].name"),
                format!("node {:?} appears twice", n.name),
            );
        }
    }
    for (i, n) in t.nodes.iter().enumerate() {
        let nat = format!("{at}.nodes[{i}] ({:?})", n.name);
        if let Some(p) = &n.parent {
            if !nodes.contains_key(p.as_str()) {
                return err(
                    format!("{nat}.parent"),
                    format!("names node {p:?}, which is not in this tree"),
                );
            }
        }
        if let Some(g) = &n.node_tree {
            if !groups.contains(g.as_str()) {
                return err(
                    format!("{nat}.node_tree"),
                    format!("names node group {g:?}, which does not exist"),
                );
            }
        }
        for (side, sockets) in [("inputs", &n.inputs), ("outputs", &n.outputs)] {
            let mut ids = HashSet::new();
            for (k, s) in sockets.iter().enumerate() {
                if s.index != k {
                    return err(
                        format!("{nat}.{side}[{k}].index"),
                        format!("is {} but the socket is at position {k}", s.index),
                    );
                }
                if !ids.insert(s.identifier.as_str()) {
                    return err(
                        format!("{nat}.{side}[{k}].identifier"),
                        format!("{:?} appears twice", s.identifier),
                    );
                }
                if let Some(m) = socket_value_error(&s.kind, s.default_value.as_ref()) {
                    return err(format!("{nat}.{side}[{k}] ({:?}).default_value", s.name), m);
                }
            }
        }
    }
    for (i, l) in t.links.iter().enumerate() {
        let lat = format!("{at}.links[{i}]");
        let Some(&from) = nodes.get(l.from_node.as_str()) else {
            return err(
                format!("{lat}.from_node"),
                format!(
                    "names node {:?}, which is not in this tree (dangling link)",
                    l.from_node
                ),
            );
        };
        let Some(&to) = nodes.get(l.to_node.as_str()) else {
            return err(
                format!("{lat}.to_node"),
                format!(
                    "names node {:?}, which is not in this tree (dangling link)",
                    l.to_node
                ),
            );
        };
        if !t.nodes[from]
            .outputs
            .iter()
            .any(|s| s.identifier == l.from_socket)
        {
            return err(
                format!("{lat}.from_socket"),
                format!(
                    "node {:?} has no output {:?} (dangling link)",
                    l.from_node, l.from_socket
                ),
            );
        }
        if !t.nodes[to]
            .inputs
            .iter()
            .any(|s| s.identifier == l.to_socket)
        {
            return err(
                format!("{lat}.to_socket"),
                format!(
                    "node {:?} has no input {:?} (dangling link)",
                    l.to_node, l.to_socket
                ),
            );
        }
    }
    Ok(())
}

/// Strict types for a socket's value: a float socket holds a number, not a string or
/// null (which downstream code would otherwise read as 0). Types without a value
/// (geometry, shader, ...) and those this build does not know are not checked.
fn socket_value_error(kind: &str, v: Option<&serde_json::Value>) -> Option<String> {
    use serde_json::Value;
    let numbers = |v: &Value, lens: &[usize]| match v {
        Value::Array(a) => lens.contains(&a.len()) && a.iter().all(Value::is_number),
        _ => false,
    };
    let ok = |v: &Value| match kind {
        "VALUE" => v.is_number(),
        "INT" => v.as_i64().is_some_and(|i| i32::try_from(i).is_ok()),
        "BOOLEAN" => v.is_boolean(),
        "VECTOR" => numbers(v, &[2, 3, 4]),
        "RGBA" => numbers(v, &[4]),
        "ROTATION" => numbers(v, &[3]),
        "STRING" => v.is_string(),
        _ => true,
    };
    let expected = match kind {
        "VALUE" => "a number",
        "INT" => "a 32-bit integer",
        "BOOLEAN" => "true or false",
        "VECTOR" => "a list of 2 to 4 numbers",
        "RGBA" => "a list of 4 numbers",
        "ROTATION" => "a list of 3 numbers (Euler angles)",
        "STRING" => "a string",
        _ => return None,
    };
    match v {
        Some(v) if ok(v) => None,
        Some(v) => Some(format!(
            "a {kind} socket's value must be {expected}, not {}",
            json_kind(v)
        )),
        None => Some(format!(
            "a {kind} socket's value must be {expected}, not null or missing"
        )),
    }
}

fn json_kind(v: &serde_json::Value) -> &'static str {
    use serde_json::Value;
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "an object",
    }
}
