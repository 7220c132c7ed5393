//! The exchange format written by `blender_export/export_scene.py` and its loader.
//!
//! This is the only module that knows the JSON layout; everything downstream works on
//! the typed structures it returns.

mod active_camera;
pub mod datapath;
pub mod error;
pub mod file;
pub mod format;
pub mod hair;
pub mod limits;
pub mod mesh;
pub mod overrides;
pub mod settings;
mod validate;
pub mod volume_grid;

use std::path::{Component, Path, PathBuf};

pub use error::SceneError;
pub use format::*;
pub use mesh::{read_glb, read_obj, Attribute, AttributeData, Domain, MeshData};
pub use overrides::Override;

/// An exported scene: its folder and the parsed, validated `scene.json`.
#[derive(Debug, Clone)]
pub struct Scene {
    pub dir: PathBuf,
    pub file: SceneFile,
}

impl Scene {
    /// Reads and validates `DIR/scene.json` (meshes are read on demand).
    pub fn load(dir: &Path) -> Result<Scene, SceneError> {
        let json_path = dir.join("scene.json");
        if !dir.is_dir() {
            return Err(SceneError::new(
                dir,
                "",
                "not a folder (expected an export made by `blendsynth convert`)",
            ));
        }
        let bytes = file::read_regular(&json_path, limits::MAX_SCENE_JSON_BYTES)
            .map_err(|m| SceneError::new(&json_path, "", m))?;
        Scene::from_json(dir, &bytes)
    }

    /// Parses and validates scene.json bytes as if read from `DIR/scene.json`; nothing
    /// else is read (meshes load on demand). The fuzz target's entry point.
    pub fn from_json(dir: &Path, bytes: &[u8]) -> Result<Scene, SceneError> {
        let json_path = dir.join("scene.json");
        let file = parse_scene_json(bytes, &json_path)?;
        let scene = Scene {
            dir: dir.to_path_buf(),
            file,
        };
        validate::validate(&scene, &json_path)?;
        Ok(scene)
    }

    pub fn json_path(&self) -> PathBuf {
        self.dir.join("scene.json")
    }

    /// Resolves a path written in the scene file, refusing any that would leave the
    /// scene folder (absolute paths, `..`, or a symlink pointing outside).
    pub fn resolve(&self, rel: &str, location: &str) -> Result<PathBuf, SceneError> {
        resolve_inside(&self.dir, rel).map_err(|m| SceneError::new(&self.json_path(), location, m))
    }

    /// The export's copy of the file an Import node names by `path` (Blender's string,
    /// exactly): `Ok(Some(copy))`, `Ok(None)` when Blender found no file there (its node
    /// gives empty geometry), and an error for a path the export holds no copy of.
    pub fn import_file(&self, path: &str) -> Result<Option<PathBuf>, String> {
        let Some((i, f)) = self
            .file
            .import_files
            .iter()
            .enumerate()
            .find(|(_, f)| f.path == path)
        else {
            return Err(format!(
                "file {path:?} is not in the export (only files named by a string of the \
                 Geometry Nodes trees, `//`-relative or absolute, are copied; a path computed \
                 at evaluation or relative to the working folder is not)"
            ));
        };
        if f.outside {
            return Err(format!(
                "file {path:?} is outside the .blend's folder and was not exported (export \
                 with --allow-path naming its folder)"
            ));
        }
        match f.file.as_deref() {
            None if f.missing => Ok(None),
            None => Err(format!("file {path:?} was not exported")),
            Some(rel) => self
                .resolve(rel, &format!("import_files[{i}].file"))
                .map(Some)
                .map_err(|e| e.to_string()),
        }
    }

    pub fn object(&self, name: &str) -> Option<&Object> {
        self.file.objects.iter().find(|o| o.name == name)
    }
    pub fn material(&self, name: &str) -> Option<&Material> {
        self.file.materials.iter().find(|m| m.name == name)
    }
    pub fn collection(&self, name: &str) -> Option<&format::Collection> {
        self.file.collections.iter().find(|c| c.name == name)
    }
    pub fn node_group(&self, name: &str) -> Option<&NodeTree> {
        self.file.node_groups.iter().find(|g| g.name == name)
    }

    /// Every node of the node group `root` and of the groups nested in it (each group
    /// once, whatever the nesting), with the tree that holds it.
    pub fn group_nodes(&self, root: &str) -> Vec<(&NodeTree, &format::Node)> {
        let mut found = Vec::new();
        let mut seen: Vec<&str> = Vec::new();
        let mut todo = vec![root];
        while let Some(g) = todo.pop() {
            if seen.contains(&g) {
                continue;
            }
            seen.push(g);
            let Some(tree) = self.file.node_groups.iter().find(|t| t.name == g) else {
                continue;
            };
            for n in &tree.nodes {
                found.push((tree, n));
                todo.extend(n.node_tree.as_deref());
            }
        }
        found
    }
    pub fn mesh_ref(&self, name: &str) -> Option<&MeshRef> {
        self.file.meshes.iter().find(|m| m.name == name)
    }

    /// Reads one mesh datablock's glb and checks it against the counts in scene.json.
    pub fn load_mesh(&self, index: usize) -> Result<MeshData, SceneError> {
        let r = &self.file.meshes[index];
        let path = self.resolve(&r.file, &format!("meshes[{index}].file"))?;
        let m = read_glb(&path)?;
        let counts = [
            ("vertex_count", r.vertex_count, m.vertex_count()),
            ("edge_count", r.edge_count, m.edges.len()),
            ("face_count", r.face_count, m.face_count()),
            ("corner_count", r.corner_count, m.corner_count()),
        ];
        for (what, declared, found) in counts {
            if declared != found {
                return Err(SceneError::new(
                    &self.json_path(),
                    format!("meshes[{index}].{what}"),
                    format!("says {declared} but {} holds {found}", path.display()),
                ));
            }
        }
        // glTF has no empty accessors, so an attribute of a domain without elements (a UV
        // map of an edge-only mesh, which the Screw modifier fills) is only listed here.
        let mut m = m;
        for a in &r.attributes {
            let Some(domain) = Domain::parse(&a.domain) else {
                continue;
            };
            if a.name != "position" && m.attribute(&a.name).is_none() && m.domain_size(domain) == 0
            {
                if let Some(data) = AttributeData::empty(&a.data_type) {
                    m.attributes.push(Attribute {
                        name: a.name.clone(),
                        domain,
                        data_type: a.data_type.clone(),
                        data,
                    });
                }
            }
        }
        Ok(m)
    }

    /// Reads a Point Density node's grid: resolution^3 RGBA voxels, x fastest. `location`
    /// names the node for errors.
    pub fn load_point_density(
        &self,
        grid: &format::PointDensityGrid,
        location: &str,
    ) -> Result<Vec<[f32; 4]>, SceneError> {
        let err = |m: String| SceneError::new(&self.json_path(), location, m);
        let res = grid.resolution;
        if res == 0 || res > limits::MAX_POINT_DENSITY_RESOLUTION {
            return Err(err(format!(
                "point_density.resolution {res} is outside 1..={}",
                limits::MAX_POINT_DENSITY_RESOLUTION
            )));
        }
        let voxels = (res as usize).pow(3);
        let path = self.resolve(&grid.file, &format!("{location}.point_density.file"))?;
        let bytes = file::read_regular(&path, (voxels * 16) as u64)
            .map_err(|m| err(format!("{}: {m}", path.display())))?;
        if bytes.len() != voxels * 16 {
            return Err(err(format!(
                "{} holds {} bytes, not {res}^3 RGBA float32 voxels ({})",
                path.display(),
                bytes.len(),
                voxels * 16
            )));
        }
        Ok(bytes
            .chunks_exact(16)
            .map(|c| {
                let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
                [f(0), f(4), f(8), f(12)]
            })
            .collect())
    }

    /// Reads an evaluated (reference) mesh written by the exporter.
    pub fn load_evaluated(&self, index: usize) -> Result<MeshData, SceneError> {
        let e = &self.file.evaluated[index];
        read_glb(&self.resolve(&e.file, &format!("evaluated[{index}].file"))?)
    }

    /// All node trees in the file, with a Blender data path prefix for each:
    /// `node_groups["X"]`, `materials["X"].node_tree`, `worlds["X"].node_tree`.
    pub fn node_trees(&self) -> Vec<(String, &NodeTree)> {
        let mut out = Vec::new();
        for m in &self.file.materials {
            if let Some(t) = &m.node_tree {
                out.push((format!("materials[{}].node_tree", quote(&m.name)), t));
            }
        }
        for w in &self.file.worlds {
            if let Some(t) = &w.node_tree {
                out.push((format!("worlds[{}].node_tree", quote(&w.name)), t));
            }
        }
        for g in &self.file.node_groups {
            out.push((format!("node_groups[{}]", quote(&g.name)), g));
        }
        out
    }
}

/// Quotes a name as Blender data paths do: `"Fat.001"`, with `"` and `\` escaped.
pub fn quote(name: &str) -> String {
    format!("\"{}\"", name.replace('\\', "\\\\").replace('"', "\\\""))
}

/// Parses scene.json bytes, turning serde errors into ones that name the JSON path
/// (for wrong types and missing fields) or the line and column (for syntax).
pub fn parse_scene_json(bytes: &[u8], path: &Path) -> Result<SceneFile, SceneError> {
    // Check the tag first so a random JSON file gets a clear message, not a field error.
    let head: serde_json::Result<serde_json::Value> = serde_json::from_slice(bytes);
    let value = match head {
        Ok(v) => v,
        Err(e) => return Err(json_syntax_error(&e, bytes, path)),
    };
    match value.get("format").and_then(|f| f.as_str()) {
        Some(FORMAT_TAG) => {}
        Some(other) => {
            return Err(SceneError::new(
                path,
                "format",
                format!("is {other:?}, expected {FORMAT_TAG:?}"),
            ))
        }
        None => {
            return Err(SceneError::new(
                path,
                "format",
                format!("missing: not a blendsynth scene (expected \"format\": {FORMAT_TAG:?})"),
            ))
        }
    }
    match value.get("version").and_then(|v| v.as_u64()) {
        Some(v) if v as u32 <= FORMAT_VERSION && v >= 1 => {}
        Some(v) => {
            return Err(SceneError::new(path, "version", format!("format version {v} is not readable by this build (reads 1..={FORMAT_VERSION}); update blendsynth")))
        }
        None => return Err(SceneError::new(path, "version", "missing or not an integer")),
    }
    serde_path_to_error::deserialize(value).map_err(|e| {
        let loc = e.path().to_string();
        SceneError::new(
            path,
            if loc == "." { String::new() } else { loc },
            e.into_inner().to_string(),
        )
    })
}

fn json_syntax_error(e: &serde_json::Error, bytes: &[u8], path: &Path) -> SceneError {
    let loc = format!("line {} column {}", e.line(), e.column());
    let msg = if e.is_eof() {
        format!("file ends early (truncated?): {e}")
    } else {
        // JSON has no NaN or infinity; Python writes them as bare words unless told not to.
        let offset = line_col_offset(bytes, e.line(), e.column());
        let rest = &bytes[offset.min(bytes.len())..];
        let rest = rest
            .get(
                rest.iter()
                    .position(|b| !b.is_ascii_whitespace())
                    .unwrap_or(0)..,
            )
            .unwrap_or(&[]);
        let word = |w: &[u8]| {
            rest.starts_with(w) || (rest.first() == Some(&b'-') && rest[1..].starts_with(w))
        };
        if word(b"NaN") || word(b"Infinity") || word(b"inf") {
            format!("non-finite number (NaN or infinity) is not allowed: {e}")
        } else {
            e.to_string()
        }
    };
    SceneError::new(path, loc, msg)
}

fn line_col_offset(bytes: &[u8], line: usize, col: usize) -> usize {
    let mut l = 1;
    let mut start = 0;
    for (i, b) in bytes.iter().enumerate() {
        if l == line {
            break;
        }
        if *b == b'\n' {
            l += 1;
            start = i + 1;
        }
    }
    // serde_json reports the column of the last byte it read.
    start + col.saturating_sub(1)
}

/// Joins `rel` to `dir` if it stays inside `dir` and, when it exists, is a regular file
/// (every path a scene names is a file to read: a FIFO would block the reader forever);
/// the error says why not.
pub fn resolve_inside(dir: &Path, rel: &str) -> Result<PathBuf, String> {
    let joined = confine(dir, rel)?;
    if joined.exists() {
        file::check_regular(&joined).map_err(|m| format!("path {rel:?} {m}"))?;
    }
    Ok(joined)
}

/// Joins `rel` to `dir` if it stays inside `dir` (no absolute path, no `..`, no symlink
/// out), whatever it names (a search folder too).
pub fn confine(dir: &Path, rel: &str) -> Result<PathBuf, String> {
    if rel.is_empty() {
        return Err("empty path".into());
    }
    if rel.contains('\\') || rel.contains('\0') {
        return Err(format!("path {rel:?} must use '/' separators"));
    }
    let p = Path::new(rel);
    for c in p.components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            Component::ParentDir => {
                return Err(format!("path {rel:?} leaves the scene folder ('..')"))
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(format!(
                    "path {rel:?} is absolute; paths must be relative to the scene folder"
                ))
            }
        }
    }
    let joined = dir.join(p);
    // A symlink inside the folder could still point outside it.
    if let (Ok(real), Ok(real_dir)) = (joined.canonicalize(), dir.canonicalize()) {
        if !real.starts_with(&real_dir) {
            return Err(format!(
                "path {rel:?} resolves outside the scene folder (symlink?)"
            ));
        }
    }
    Ok(joined)
}
