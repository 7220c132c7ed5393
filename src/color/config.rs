//! The subset of an OpenColorIO v2 config (config.ocio) that Blender's colour management
//! uses: roles, displays and their views, colour spaces with their reference transforms,
//! and looks. Parsed with a YAML reader; transforms stay symbolic here and are turned into
//! pixel operations by `pipeline`.

use crate::scene::limits::MAX_COLOR_FILE_BYTES;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde_yaml::Value;

use super::ColorError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dir {
    Forward,
    Inverse,
}

impl Dir {
    pub fn combine(self, other: Dir) -> Dir {
        if self == other {
            Dir::Forward
        } else {
            Dir::Inverse
        }
    }
}

/// One OCIO transform as written in the config.
#[derive(Debug, Clone)]
pub enum Transform {
    Group(Vec<Transform>, Dir),
    ColorSpace {
        src: String,
        dst: String,
        dir: Dir,
    },
    Matrix {
        m: [f64; 16],
        offset: [f64; 4],
        dir: Dir,
    },
    Allocation {
        lg2: bool,
        vars: Vec<f64>,
        dir: Dir,
    },
    File {
        src: String,
        tetrahedral: bool,
        dir: Dir,
    },
    Exponent {
        value: [f64; 4],
        dir: Dir,
    },
    ExponentWithLinear {
        gamma: [f64; 4],
        offset: [f64; 4],
        dir: Dir,
    },
    Range {
        min_in: Option<f64>,
        max_in: Option<f64>,
        min_out: Option<f64>,
        max_out: Option<f64>,
        dir: Dir,
    },
    Cdl {
        slope: [f64; 3],
        offset: [f64; 3],
        power: [f64; 3],
        sat: f64,
        dir: Dir,
    },
    GradingPrimaryLog {
        contrast: [f64; 3],
        saturation: f64,
        pivot: f64,
        brightness: [f64; 3],
        gamma: [f64; 3],
        dir: Dir,
    },
    GradingTone(Box<GradingTone>),
    Unsupported(String),
}

/// GradingToneTransform values: each zone is (rgb, master, start/width params).
#[derive(Debug, Clone)]
pub struct GradingTone {
    pub log: bool,
    pub blacks: [f64; 6],
    pub shadows: [f64; 6],
    pub midtones: [f64; 6],
    pub highlights: [f64; 6],
    pub whites: [f64; 6],
    pub s_contrast: f64,
    pub dir: Dir,
}

#[derive(Debug, Clone)]
pub struct ColorSpace {
    pub name: String,
    pub aliases: Vec<String>,
    pub is_data: bool,
    pub to_ref: Option<Transform>,
    pub from_ref: Option<Transform>,
}

#[derive(Debug, Clone)]
pub struct Look {
    pub name: String,
    pub process_space: String,
    pub transform: Option<Transform>,
    pub inverse_transform: Option<Transform>,
}

#[derive(Debug, Clone)]
pub struct Config {
    pub path: PathBuf,
    pub search_dirs: Vec<PathBuf>,
    pub roles: HashMap<String, String>,
    /// display name -> (view name -> colour space name)
    pub displays: Vec<(String, Vec<(String, String)>)>,
    pub spaces: Vec<ColorSpace>,
    pub looks: Vec<Look>,
}

/// `rel` joined to `dir` when it stays inside (the scene's path policy); `file`: it must
/// also be a regular file when it exists (a LUT), rather than a search folder.
fn inside(dir: &Path, rel: &str, file: bool) -> Result<PathBuf, String> {
    let r = if file {
        crate::scene::resolve_inside(dir, rel)
    } else {
        crate::scene::confine(dir, rel)
    };
    r.map_err(|m| m.replace("scene folder", "config's folder"))
}

fn err(path: &Path, msg: impl std::fmt::Display) -> ColorError {
    ColorError::Config {
        path: path.to_path_buf(),
        message: msg.to_string(),
    }
}

/// (tag name without `!<` `>`, inner value)
fn untag(v: &Value) -> (Option<String>, &Value) {
    match v {
        Value::Tagged(t) => {
            let s = t.tag.to_string();
            let s = s
                .trim_start_matches('!')
                .trim_start_matches('<')
                .trim_end_matches('>')
                .to_string();
            (Some(s), &t.value)
        }
        _ => (None, v),
    }
}

fn get<'a>(v: &'a Value, key: &str) -> Option<&'a Value> {
    v.as_mapping().and_then(|m| m.get(key))
}

fn f64_of(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse().ok(),
        _ => None,
    }
}

fn f64s(v: Option<&Value>) -> Vec<f64> {
    match v {
        Some(Value::Sequence(s)) => s.iter().filter_map(f64_of).collect(),
        Some(x) => f64_of(x).into_iter().collect(),
        None => vec![],
    }
}

fn string(v: Option<&Value>) -> Option<String> {
    match v? {
        Value::String(s) => Some(s.clone()),
        Value::Number(n) => Some(n.to_string()),
        Value::Bool(b) => Some(b.to_string()),
        _ => None,
    }
}

fn dir_of(v: &Value) -> Dir {
    match string(get(v, "direction")).as_deref() {
        Some("inverse") => Dir::Inverse,
        _ => Dir::Forward,
    }
}

fn rgbm(v: Option<&Value>, default: f64) -> [f64; 4] {
    let mut out = [default; 4];
    if let Some(v) = v {
        let rgb = f64s(get(v, "rgb"));
        for (i, x) in rgb.iter().take(3).enumerate() {
            out[i] = *x;
        }
        if let Some(m) = get(v, "master").and_then(f64_of) {
            out[3] = m;
        }
    }
    out
}

fn parse_transform(v: &Value) -> Transform {
    let (tag, inner) = untag(v);
    let tag = tag.unwrap_or_default();
    let dir = dir_of(inner);
    match tag.as_str() {
        "GroupTransform" => {
            let children = match get(inner, "children") {
                Some(Value::Sequence(s)) => s.iter().map(parse_transform).collect(),
                _ => vec![],
            };
            Transform::Group(children, dir)
        }
        "ColorSpaceTransform" => Transform::ColorSpace {
            src: string(get(inner, "src")).unwrap_or_default(),
            dst: string(get(inner, "dst")).unwrap_or_default(),
            dir,
        },
        "MatrixTransform" => {
            let mut m = [
                1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
            ];
            let mv = f64s(get(inner, "matrix"));
            if mv.len() == 16 {
                m.copy_from_slice(&mv);
            }
            let mut offset = [0.0; 4];
            let ov = f64s(get(inner, "offset"));
            for (i, x) in ov.iter().take(4).enumerate() {
                offset[i] = *x;
            }
            Transform::Matrix { m, offset, dir }
        }
        "AllocationTransform" => Transform::Allocation {
            lg2: string(get(inner, "allocation")).as_deref() == Some("lg2"),
            vars: f64s(get(inner, "vars")),
            dir,
        },
        "FileTransform" => Transform::File {
            src: string(get(inner, "src")).unwrap_or_default(),
            tetrahedral: string(get(inner, "interpolation")).as_deref() == Some("tetrahedral"),
            dir,
        },
        "ExponentTransform" => {
            let v = f64s(get(inner, "value"));
            let value = match v.len() {
                1 => [v[0], v[0], v[0], 1.0],
                4 => [v[0], v[1], v[2], v[3]],
                _ => [1.0; 4],
            };
            Transform::Exponent { value, dir }
        }
        "ExponentWithLinearTransform" => {
            let g = f64s(get(inner, "gamma"));
            let o = f64s(get(inner, "offset"));
            let four = |v: Vec<f64>, d: f64| match v.len() {
                1 => [v[0], v[0], v[0], d],
                4 => [v[0], v[1], v[2], v[3]],
                _ => [d; 4],
            };
            Transform::ExponentWithLinear {
                gamma: four(g, 1.0),
                offset: four(o, 0.0),
                dir,
            }
        }
        "RangeTransform" => Transform::Range {
            min_in: get(inner, "min_in_value").and_then(f64_of),
            max_in: get(inner, "max_in_value").and_then(f64_of),
            min_out: get(inner, "min_out_value").and_then(f64_of),
            max_out: get(inner, "max_out_value").and_then(f64_of),
            dir,
        },
        "CDLTransform" => {
            let three = |v: Vec<f64>, d: f64| {
                if v.len() == 3 {
                    [v[0], v[1], v[2]]
                } else {
                    [d; 3]
                }
            };
            Transform::Cdl {
                slope: three(f64s(get(inner, "slope")), 1.0),
                offset: three(f64s(get(inner, "offset")), 0.0),
                power: three(f64s(get(inner, "power")), 1.0),
                sat: get(inner, "sat").and_then(f64_of).unwrap_or(1.0),
                dir,
            }
        }
        "GradingPrimaryTransform" => {
            let style = string(get(inner, "style")).unwrap_or_else(|| "log".into());
            if style != "log" {
                return Transform::Unsupported(format!("GradingPrimaryTransform style {style}"));
            }
            let c = rgbm(get(inner, "contrast"), 1.0);
            let b = rgbm(get(inner, "brightness"), 0.0);
            let g = rgbm(get(inner, "gamma"), 1.0);
            let pivot = get(inner, "pivot")
                .and_then(|p| get(p, "contrast"))
                .and_then(f64_of)
                .unwrap_or(0.0);
            if get(inner, "clamp").is_some()
                || get(inner, "pivot")
                    .and_then(|p| get(p, "black").or(get(p, "white")))
                    .is_some()
            {
                return Transform::Unsupported(
                    "GradingPrimaryTransform with clamp or black/white pivots".into(),
                );
            }
            Transform::GradingPrimaryLog {
                contrast: [c[0] * c[3], c[1] * c[3], c[2] * c[3]],
                brightness: [b[0] + b[3], b[1] + b[3], b[2] + b[3]],
                gamma: [g[0] * g[3], g[1] * g[3], g[2] * g[3]],
                saturation: get(inner, "saturation").and_then(f64_of).unwrap_or(1.0),
                pivot,
                dir,
            }
        }
        "GradingToneTransform" => {
            let style = string(get(inner, "style")).unwrap_or_else(|| "log".into());
            // Each zone: rgb (3), master, then the zone's two placement parameters with
            // OCIO's defaults for the log style.
            let zone = |key: &str, d: [f64; 2], names: [&str; 2]| -> [f64; 6] {
                let z = get(inner, key);
                let m = rgbm(z, 1.0);
                let p0 = z
                    .and_then(|z| get(z, names[0]))
                    .and_then(f64_of)
                    .unwrap_or(d[0]);
                let p1 = z
                    .and_then(|z| get(z, names[1]))
                    .and_then(f64_of)
                    .unwrap_or(d[1]);
                [m[0], m[1], m[2], m[3], p0, p1]
            };
            Transform::GradingTone(Box::new(GradingTone {
                log: style == "log",
                blacks: zone("blacks", [0.4, 0.4], ["start", "width"]),
                shadows: zone("shadows", [0.5, 0.0], ["start", "pivot"]),
                midtones: zone("midtones", [0.4, 0.6], ["center", "width"]),
                highlights: zone("highlights", [0.3, 1.0], ["start", "pivot"]),
                whites: zone("whites", [0.4, 0.5], ["start", "width"]),
                s_contrast: get(inner, "s_contrast").and_then(f64_of).unwrap_or(1.0),
                dir,
            }))
        }
        other => Transform::Unsupported(other.to_string()),
    }
}

fn verbatim_tags_to_local(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find("!<") {
        out.push_str(&rest[..i]);
        let after = &rest[i + 2..];
        match after.find('>') {
            Some(j)
                if after[..j]
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_') =>
            {
                out.push('!');
                out.push_str(&after[..j]);
                rest = &after[j + 1..];
            }
            _ => {
                out.push_str("!<");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

impl Config {
    pub fn load(path: &Path) -> Result<Config, ColorError> {
        let bytes = crate::scene::file::read_regular(path, MAX_COLOR_FILE_BYTES)
            .map_err(|m| err(path, m))?;
        let text =
            String::from_utf8(bytes).map_err(|_| err(path, "not a text file (not UTF-8)"))?;
        // serde_yaml drops verbatim tags (`!<ColorSpace>`); the local form (`!ColorSpace`) is kept.
        let text = verbatim_tags_to_local(&text);
        // serde_yaml's messages can quote the document ("invalid type: string ..."):
        // only the location is reported, so a wrong file's content is never echoed.
        let doc: Value = serde_yaml::from_str(&text).map_err(|e| {
            let at = e
                .location()
                .map(|l| format!(" (at line {} column {})", l.line(), l.column()))
                .unwrap_or_default();
            err(path, format!("not a readable OCIO config{at}"))
        })?;
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        // The search path stays inside the config's folder (which the scene's path
        // policy already confines): an absolute or `..` entry is an error.
        let search_dirs = string(get(&doc, "search_path"))
            .unwrap_or_default()
            .split(':')
            .filter(|s| !s.is_empty())
            .map(|s| inside(&base, s, false).map_err(|m| err(path, format!("search_path: {m}"))))
            .chain(std::iter::once(Ok(base.clone())))
            .collect::<Result<_, _>>()?;
        let mut roles = HashMap::new();
        if let Some(Value::Mapping(m)) = get(&doc, "roles") {
            for (k, v) in m {
                if let (Some(k), Some(v)) = (string(Some(k)), string(Some(v))) {
                    roles.insert(k, v);
                }
            }
        }
        let mut displays = Vec::new();
        if let Some(Value::Mapping(m)) = get(&doc, "displays") {
            for (k, v) in m {
                let name = string(Some(k)).unwrap_or_default();
                let mut views = Vec::new();
                if let Value::Sequence(s) = v {
                    for view in s {
                        let (_, inner) = untag(view);
                        if let (Some(n), Some(cs)) =
                            (string(get(inner, "name")), string(get(inner, "colorspace")))
                        {
                            views.push((n, cs));
                        }
                    }
                }
                displays.push((name, views));
            }
        }
        let mut spaces = Vec::new();
        if let Some(Value::Sequence(s)) = get(&doc, "colorspaces") {
            for cs in s {
                let (_, inner) = untag(cs);
                let aliases = match get(inner, "aliases") {
                    Some(Value::Sequence(a)) => a.iter().filter_map(|x| string(Some(x))).collect(),
                    _ => vec![],
                };
                let tr =
                    |keys: &[&str]| keys.iter().find_map(|k| get(inner, k)).map(parse_transform);
                spaces.push(ColorSpace {
                    name: string(get(inner, "name"))
                        .ok_or_else(|| err(path, "a colour space has no name"))?,
                    aliases,
                    is_data: matches!(get(inner, "isdata"), Some(Value::Bool(true))),
                    to_ref: tr(&["to_scene_reference", "to_reference"]),
                    from_ref: tr(&["from_scene_reference", "from_reference"]),
                });
            }
        }
        if get(&doc, "display_colorspaces").is_some() {
            return Err(err(
                path,
                "display-referred colour spaces (display_colorspaces) are not supported",
            ));
        }
        let mut looks = Vec::new();
        if let Some(Value::Sequence(s)) = get(&doc, "looks") {
            for l in s {
                let (_, inner) = untag(l);
                looks.push(Look {
                    name: string(get(inner, "name")).unwrap_or_default(),
                    process_space: string(get(inner, "process_space")).unwrap_or_default(),
                    transform: get(inner, "transform").map(parse_transform),
                    inverse_transform: get(inner, "inverse_transform").map(parse_transform),
                });
            }
        }
        Ok(Config {
            path: path.to_path_buf(),
            search_dirs,
            roles,
            displays,
            spaces,
            looks,
        })
    }

    /// A colour space by name, alias or role (names compare case-insensitively, as OCIO does).
    pub fn space(&self, name: &str) -> Option<&ColorSpace> {
        let find = |n: &str| {
            self.spaces.iter().find(|c| {
                c.name.eq_ignore_ascii_case(n)
                    || c.aliases.iter().any(|a| a.eq_ignore_ascii_case(n))
            })
        };
        find(name).or_else(|| {
            self.roles
                .iter()
                .find(|(k, _)| k.eq_ignore_ascii_case(name))
                .and_then(|(_, v)| find(v))
        })
    }

    pub fn view_space(&self, display: &str, view: &str) -> Option<&str> {
        let (_, views) = self.displays.iter().find(|(d, _)| d == display)?;
        views
            .iter()
            .find(|(v, _)| v == view)
            .map(|(_, cs)| cs.as_str())
    }

    pub fn look(&self, name: &str) -> Option<&Look> {
        self.looks.iter().find(|l| l.name == name)
    }

    /// A LUT file named by a transform, looked up in the search path. The name must stay
    /// inside the config's folder (no absolute path, no `..`, no symlink out).
    pub fn find_file(&self, name: &str) -> Result<Option<PathBuf>, ColorError> {
        let base = self.path.parent().unwrap_or(Path::new("."));
        for d in &self.search_dirs {
            let rel = d.strip_prefix(base).unwrap_or(Path::new(""));
            let rel = rel.join(name);
            let rel = rel.to_string_lossy();
            let p = inside(base, &rel, true)
                .map_err(|m| err(&self.path, format!("LUT file {name:?}: {m}")))?;
            if p.is_file() {
                return Ok(Some(p));
            }
        }
        Ok(None)
    }
}
