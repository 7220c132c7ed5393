//! The scene as Geometry Nodes sees it at a frame: node-group F-curves (socket values,
//! node settings) and modifier-input F-curves evaluated and written in, then the caller's
//! overrides on top (Blender data paths, as `Scene::with_overrides` takes them), and the
//! link order of multi-input sockets, which the typed scene structures do not keep.

use std::collections::HashMap;

use serde_json::Value;

use super::error::GeometryError;
use crate::anim::{evaluate_fcurve_as, ValueKind};
use crate::scene::datapath::{parse, Token};
use crate::scene::overrides::set;
use crate::scene::{Scene, SceneFile};

/// Reads the value at a Blender data path (the same walk `overrides::set` does).
fn get<'a>(root: &'a Value, path: &str) -> Option<&'a Value> {
    let tokens = parse(path).ok()?;
    let mut it = tokens.iter();
    let mut cur = match it.next()? {
        Token::Prop(c) => root.get(c.as_str())?,
        _ => return None,
    };
    for t in it {
        cur = match t {
            Token::Prop(p) => cur
                .get(p.as_str())
                .or_else(|| cur.get("properties").and_then(|x| x.get(p.as_str())))?,
            Token::Key(k) => match cur {
                Value::Array(items) => items
                    .iter()
                    .find(|x| x.get("identifier").and_then(Value::as_str) == Some(k.as_str()))
                    .or_else(|| {
                        items
                            .iter()
                            .find(|x| x.get("name").and_then(Value::as_str) == Some(k.as_str()))
                    })?,
                Value::Object(m) => m
                    .get("inputs")
                    .and_then(|i| i.get(k.as_str()))
                    .or_else(|| m.get("custom_properties").and_then(|i| i.get(k.as_str())))?,
                _ => return None,
            },
            Token::Index(i) => cur.get(*i)?,
        };
    }
    Some(cur)
}

/// F-curves that change Geometry Nodes inputs: on node groups, and on objects'
/// modifier inputs (`modifiers["GeometryNodes"]["Socket_2"]`).
fn animated_paths(file: &SceneFile) -> Result<Vec<(String, &crate::scene::FCurve)>, GeometryError> {
    let mut out = Vec::new();
    for ad in &file.animation {
        let node_group = ad.id_type == "NODETREE" && ad.id_path.starts_with("node_groups[");
        for fc in &ad.fcurves {
            if node_group || (ad.id_type == "OBJECT" && fc.data_path.starts_with("modifiers[")) {
                out.push((format!("{}.{}", ad.id_path, fc.data_path), fc));
            }
        }
        if node_group {
            if let Some(d) = ad.drivers.iter().find(|d| !d.mute) {
                return Err(GeometryError::new(format!(
                    "{}: driver on {} is not supported",
                    ad.id_path, d.data_path
                )));
            }
        }
    }
    Ok(out)
}

/// A copy of `scene` with animation at `frame` and then `overrides` written in.
pub fn scene_at(
    scene: &Scene,
    frame: f64,
    overrides: &[(String, Value)],
) -> Result<Scene, GeometryError> {
    let anim = animated_paths(&scene.file)?;
    if anim.is_empty() && overrides.is_empty() {
        return Ok(scene.clone());
    }
    let mut root =
        serde_json::to_value(&scene.file).map_err(|e| GeometryError::new(e.to_string()))?;
    for (path, fc) in anim {
        if fc.mute || fc.keyframes.is_empty() && fc.modifiers.is_empty() {
            continue;
        }
        let target = get(&root, &path).ok_or_else(|| {
            GeometryError::new(format!("animated property {path} is not in the export"))
        })?;
        let (full, current) = match target {
            Value::Array(a) => (
                format!("{path}[{}]", fc.array_index),
                a.get(fc.array_index).cloned().unwrap_or(Value::Null),
            ),
            v => (path.clone(), v.clone()),
        };
        let kind = ValueKind::of_json(&current).unwrap_or_default();
        let v = evaluate_fcurve_as(fc, frame, kind)?;
        let json = if current.is_boolean() {
            Value::Bool(v != 0.0)
        } else if current.is_i64() || current.is_u64() {
            Value::from(v as i64)
        } else {
            Value::from(v)
        };
        set(&mut root, &full, &json)
            .map_err(|m| GeometryError::new(format!("animating {full}: {m}")))?;
    }
    for (path, value) in overrides {
        let path = path.strip_prefix("bpy.data.").unwrap_or(path);
        set(&mut root, path, value)
            .map_err(|m| GeometryError::new(format!("override {path}: {m}")))?;
    }
    let mut file: SceneFile = serde_json::from_value(root)
        .map_err(|e| GeometryError::new(format!("after overrides: {e}")))?;
    file.overridden.extend(
        overrides
            .iter()
            .map(|(p, _)| p.strip_prefix("bpy.data.").unwrap_or(p).to_string()),
    );
    Ok(Scene {
        dir: scene.dir.clone(),
        file,
    })
}

/// Per node group, each link's `multi_input_sort_id` (0 when the export lacks it).
pub fn link_sort_ids(scene: &Scene) -> Result<HashMap<String, Vec<i64>>, GeometryError> {
    Ok(scene
        .file
        .node_groups
        .iter()
        .map(|g| {
            (
                g.name.clone(),
                g.links.iter().map(|l| l.multi_input_sort_id).collect(),
            )
        })
        .collect())
}
