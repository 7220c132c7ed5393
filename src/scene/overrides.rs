//! Parameter overrides addressed by Blender data paths, as "Copy Full Data Path" gives
//! them (with or without `bpy.data.`):
//!
//! ```text
//! node_groups["Colon Geo Node"].nodes["Stalk Seed"].outputs[0].default_value=1234
//! materials["Fat.001"].node_tree.nodes["Noise Texture"].inputs["Scale"].default_value=7
//! materials["Fat.001"].node_tree.nodes["ColorRamp.001"].color_ramp.elements[1].color=[1,0,0,1]
//! objects["Colon"].modifiers["GeometryNodes"]["Socket_2"]=0.5
//! objects["Camera"].rotation_euler[2]=0.3      cameras["Camera"].dof.aperture_fstop=2
//! lights["Spot"].energy=90                     scenes["Scene"].render.motion_blur_shutter=0.3
//! ```
//!
//! Every exported property is addressable: a path walks the exchange format the way
//! Blender's RNA does, with settings the exporter keeps under `properties` reached as
//! plain attributes (`nodes["Math"].operation`), sockets found by identifier or name,
//! and `["key"]` on an object or modifier meaning its custom property or group input.
//! A value must keep the type of what it replaces; errors name the path.

use serde_json::Value;

use super::datapath::{parse, Token};
use super::{Scene, SceneError, SceneFile};

/// One `PATH=VALUE` override.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    pub path: String,
    pub value: Value,
}

impl Override {
    /// Parses `PATH=VALUE`. VALUE is JSON (`7`, `true`, `[1, 0, 0, 1]`, `"MULTIPLY"`), or
    /// a bare word taken as a string (`MULTIPLY`).
    pub fn parse(s: &str) -> Result<Override, String> {
        // The path may hold '=' inside quoted names, so split at the first '=' outside quotes.
        let mut quote = None;
        let mut split = None;
        for (i, c) in s.char_indices() {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, '=') => {
                    split = Some(i);
                    break;
                }
                _ => {}
            }
        }
        let Some(at) = split else {
            return Err(format!("override {s:?} is not PATH=VALUE"));
        };
        let path = s[..at].trim();
        let raw = s[at + 1..].trim();
        if raw.is_empty() {
            return Err(format!("override {path:?} has no value"));
        }
        let value = serde_json::from_str(raw).unwrap_or_else(|_| Value::String(raw.to_string()));
        Ok(Override {
            path: path.strip_prefix("bpy.data.").unwrap_or(path).to_string(),
            value,
        })
    }
}

impl Scene {
    /// A copy of the scene with the overrides applied (in order) and validated again.
    pub fn with_overrides(&self, overrides: &[Override]) -> Result<Scene, SceneError> {
        if overrides.is_empty() {
            return Ok(self.clone());
        }
        let json = self.json_path();
        let mut v = serde_json::to_value(&self.file)
            .map_err(|e| SceneError::new(&json, "", e.to_string()))?;
        for o in overrides {
            set(&mut v, &o.path, &o.value)
                .map_err(|m| SceneError::new(&json, format!("override {}", o.path), m))?;
        }
        let mut file: SceneFile = serde_path_to_error::deserialize(v).map_err(|e| {
            SceneError::new(
                &json,
                format!("after overrides, {}", e.path()),
                e.into_inner().to_string(),
            )
        })?;
        // Frozen geometry must know what changed since the export.
        file.overridden
            .extend(overrides.iter().map(|o| o.path.clone()));
        let scene = Scene {
            dir: self.dir.clone(),
            file,
        };
        super::validate::validate(&scene, &json)?;
        Ok(scene)
    }
}

/// The top-level collections of `bpy.data` the format holds, by their Blender names.
const COLLECTIONS: &[&str] = &[
    "objects",
    "meshes",
    "curves",
    "materials",
    "worlds",
    "node_groups",
    "cameras",
    "lights",
    "images",
];

/// Sets the value at a Blender data path inside the scene JSON.
pub fn set(root: &mut Value, path: &str, value: &Value) -> Result<(), String> {
    assign(walk(root, path)?, value)
}

/// The value at a Blender data path inside the scene JSON, found as `set` finds it; a
/// path to a structure rather than a value is an error, as it is for `set`.
pub fn get(root: &mut Value, path: &str) -> Result<Value, String> {
    let v = walk(root, path)?;
    if v.is_object() {
        return Err("points at a structure, not a value".into());
    }
    Ok(v.clone())
}

/// The slot a data path names.
fn walk<'a>(root: &'a mut Value, path: &str) -> Result<&'a mut Value, String> {
    let tokens = parse(path)?;
    let mut it = tokens.iter();
    let mut cur: &mut Value = match it.next() {
        Some(Token::Prop(c)) if c == "scenes" => {
            let Some(Token::Key(name)) = it.next() else {
                return Err("expected scenes[\"NAME\"]".into());
            };
            let scene = &mut root["scene"];
            if scene["name"].as_str() != Some(name.as_str()) {
                return Err(format!(
                    "no scene named {name:?} (the export holds {:?})",
                    scene["name"]
                ));
            }
            scene
        }
        Some(Token::Prop(c)) if COLLECTIONS.contains(&c.as_str()) => root
            .get_mut(c.as_str())
            .ok_or_else(|| format!("the export has no {c}"))?,
        Some(t) => {
            return Err(format!(
                "{t:?} is not a bpy.data collection this format holds ({})",
                COLLECTIONS.join(", ")
            ))
        }
        None => return Err("empty path".into()),
    };
    let mut walked = String::new();
    for t in it {
        cur = step(cur, t).map_err(|m| {
            if walked.is_empty() {
                m
            } else {
                format!("{m} (after {walked})")
            }
        })?;
        walked.push_str(&match t {
            Token::Prop(p) => format!(".{p}"),
            Token::Key(k) => format!("[{k:?}]"),
            Token::Index(i) => format!("[{i}]"),
        });
    }
    Ok(cur)
}

/// One step of the walk: an attribute, a named member of a collection, or an index.
fn step<'a>(v: &'a mut Value, t: &Token) -> Result<&'a mut Value, String> {
    match t {
        Token::Prop(p) => {
            let Value::Object(map) = v else {
                return Err(format!("cannot take .{p} of a {}", kind(v)));
            };
            if map.contains_key(p.as_str()) {
                return Ok(map.get_mut(p.as_str()).unwrap());
            }
            // Settings the exporter dumped from RNA live under `properties`.
            if let Some(Value::Object(props)) = map.get_mut("properties") {
                if let Some(x) = props.get_mut(p.as_str()) {
                    return Ok(x);
                }
            }
            Err(format!("no property {p:?}"))
        }
        Token::Key(k) => match v {
            Value::Array(items) => {
                // Sockets are looked up by identifier first, then by name, as Blender does.
                let pos = items
                    .iter()
                    .position(|x| x.get("identifier").and_then(Value::as_str) == Some(k.as_str()))
                    .or_else(|| {
                        items
                            .iter()
                            .position(|x| x.get("name").and_then(Value::as_str) == Some(k.as_str()))
                    });
                match pos {
                    Some(i) => Ok(&mut items[i]),
                    None => Err(format!("nothing named {k:?} here")),
                }
            }
            Value::Object(map) => {
                // `modifier["Socket_2"]` is a group input; `object["prop"]` a custom property.
                let holder = ["inputs", "custom_properties"]
                    .into_iter()
                    .find(|h| map.get(*h).and_then(|m| m.get(k.as_str())).is_some())
                    .ok_or_else(|| format!("no input or custom property {k:?}"))?;
                Ok(&mut map[holder][k.as_str()])
            }
            _ => Err(format!("cannot look up [{k:?}] in a {}", kind(v))),
        },
        Token::Index(i) => match v {
            Value::Array(items) => {
                let n = items.len();
                items
                    .get_mut(*i)
                    .ok_or_else(|| format!("index {i} out of range (length {n})"))
            }
            _ => Err(format!("cannot index a {}", kind(v))),
        },
    }
}

/// Replaces `slot` with `value`, keeping the type of what was there.
fn assign(slot: &mut Value, value: &Value) -> Result<(), String> {
    match (&*slot, value) {
        (Value::Number(old), Value::Number(new)) => {
            let new_f = new.as_f64().ok_or("not a number")?;
            if !new_f.is_finite() {
                return Err("value must be finite".into());
            }
            if (old.is_i64() || old.is_u64()) && !(new.is_i64() || new.is_u64()) {
                if new_f.fract() != 0.0 {
                    return Err(format!("expects an integer, got {new}"));
                }
                *slot = Value::from(new_f as i64);
                return Ok(());
            }
            // A float stays a float, whatever way the number was written.
            *slot = if old.is_f64() {
                Value::from(new_f)
            } else {
                value.clone()
            };
            Ok(())
        }
        (Value::Bool(_), Value::Bool(_)) | (Value::String(_), Value::String(_)) => {
            *slot = value.clone();
            Ok(())
        }
        // Booleans written as 0/1, as Blender accepts them.
        (Value::Bool(_), Value::Number(n)) if n.as_i64().is_some_and(|i| i == 0 || i == 1) => {
            *slot = Value::Bool(n.as_i64() == Some(1));
            Ok(())
        }
        (Value::Array(old), Value::Array(new)) => {
            if old.len() != new.len() {
                return Err(format!("expects {} values, got {}", old.len(), new.len()));
            }
            let mut out = old.clone();
            for (o, n) in out.iter_mut().zip(new) {
                assign(o, n)?;
            }
            *slot = Value::Array(out);
            Ok(())
        }
        // A scalar to a vector or colour fills every component, as Blender's
        // implicit float-to-vector conversion does.
        (Value::Array(old), Value::Number(_)) if old.iter().all(Value::is_number) => {
            let mut out = old.clone();
            for o in out.iter_mut() {
                assign(o, value)?;
            }
            *slot = Value::Array(out);
            Ok(())
        }
        (Value::Object(_), _) => Err(format!("points at a structure, not a value (got {value})")),
        (old, new) => Err(format!("expects a {}, got {new}", kind(old))),
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "list",
        Value::Object(_) => "structure",
    }
}
