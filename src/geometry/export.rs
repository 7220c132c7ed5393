//! Writing a realized mesh: PLY (binary), OBJ, and glb in the exporter's layout (so
//! `scene::read_glb` reads it back). Vertices stay one to one with Blender's: UVs are
//! per corner (OBJ `vt` per corner, glb corner attributes), nothing is split.

use std::path::Path;

use super::error::GeometryError;
use super::mesh::Mesh;
use super::types::{Array, Domain};

/// The first named FLOAT2 corner attribute (the UV map).
fn uv_map(m: &Mesh) -> Option<(&str, &Vec<[f32; 2]>)> {
    m.attributes
        .iter()
        .find_map(|a| match (&a.data, a.domain, a.id.name()) {
            (Array::Float2(v), Domain::Corner, Some(n)) => Some((n, v)),
            _ => None,
        })
}

fn material_indices(m: &Mesh) -> Vec<i32> {
    m.attributes
        .named("material_index")
        .map(|a| a.data.as_int().into_owned())
        .unwrap_or_else(|| vec![0; m.face_count()])
}

/// Binary little-endian PLY: vertices (x, y, z), faces (vertex indices and
/// `material_index`), loose edges as an `edge` element.
pub fn ply_bytes(m: &Mesh) -> Result<Vec<u8>, GeometryError> {
    let mut used = vec![false; m.edge_count()];
    for &e in &m.corner_edges {
        if let Some(u) = used.get_mut(e as usize) {
            *u = true;
        }
    }
    let loose: Vec<[u32; 2]> = m
        .edges
        .iter()
        .zip(&used)
        .filter(|(_, u)| !**u)
        .map(|(e, _)| *e)
        .collect();
    let mut out = Vec::new();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment blendsynth: Blender vertex order\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nproperty int material_index\nelement edge {}\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        m.vertex_count(),
        m.face_count(),
        loose.len()
    );
    out.extend_from_slice(header.as_bytes());
    for p in &m.positions {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    let mi = material_indices(m);
    for f in 0..m.face_count() {
        let r = m.face(f);
        if r.len() > 255 {
            return Err(GeometryError::new(format!(
                "face {f} has {} corners, more than PLY's uchar count holds",
                r.len()
            )));
        }
        out.push(r.len() as u8);
        for c in r {
            out.extend_from_slice(&(m.corner_verts[c] as i32).to_le_bytes());
        }
        out.extend_from_slice(&mi[f].to_le_bytes());
    }
    for e in &loose {
        out.extend_from_slice(&(e[0] as i32).to_le_bytes());
        out.extend_from_slice(&(e[1] as i32).to_le_bytes());
    }
    Ok(out)
}

/// OBJ: `v` per vertex in Blender's order, `vt` per face corner when there is a UV map,
/// `usemtl` where the material changes, `l` for loose edges.
pub fn obj_bytes(m: &Mesh) -> Vec<u8> {
    let mut s = String::new();
    s.push_str("# blendsynth: Blender vertex order, one vt per face corner\n");
    for p in &m.positions {
        s.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
    }
    let uv = uv_map(m);
    if let Some((_, uv)) = uv {
        for t in uv {
            s.push_str(&format!("vt {} {}\n", t[0], t[1]));
        }
    }
    let mi = material_indices(m);
    let mut current: Option<i32> = None;
    for f in 0..m.face_count() {
        if !m.materials.is_empty() && current != Some(mi[f]) {
            current = Some(mi[f]);
            let name = m
                .materials
                .get(mi[f].max(0) as usize)
                .cloned()
                .flatten()
                .unwrap_or_else(|| "None".into());
            s.push_str(&format!("usemtl {name}\n"));
        }
        s.push('f');
        for c in m.face(f) {
            if uv.is_some() {
                s.push_str(&format!(" {}/{}", m.corner_verts[c] + 1, c + 1));
            } else {
                s.push_str(&format!(" {}", m.corner_verts[c] + 1));
            }
        }
        s.push('\n');
    }
    let mut used = vec![false; m.edge_count()];
    for &e in &m.corner_edges {
        if let Some(u) = used.get_mut(e as usize) {
            *u = true;
        }
    }
    for (e, u) in m.edges.iter().zip(&used) {
        if !u {
            s.push_str(&format!("l {} {}\n", e[0] + 1, e[1] + 1));
        }
    }
    s.into_bytes()
}

struct GlbBuilder {
    bin: Vec<u8>,
    views: Vec<serde_json::Value>,
    accessors: Vec<serde_json::Value>,
}

impl GlbBuilder {
    /// Adds an accessor (None for zero elements, as the exporter omits them).
    fn add(
        &mut self,
        bytes: &[u8],
        count: usize,
        ty: &str,
        comp: u32,
        target: Option<u32>,
    ) -> Option<usize> {
        if count == 0 {
            return None;
        }
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        let mut view =
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = t.into();
        }
        self.views.push(view);
        let mut acc = serde_json::json!({"bufferView": self.views.len() - 1, "componentType": comp, "count": count, "type": ty});
        if ty == "VEC3" && comp == 5126 && target == Some(34962) {
            // POSITION needs bounds.
            let f: Vec<f32> = bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                .collect();
            let mut mn = [f32::INFINITY; 3];
            let mut mx = [f32::NEG_INFINITY; 3];
            for p in f.chunks_exact(3) {
                for k in 0..3 {
                    mn[k] = mn[k].min(p[k]);
                    mx[k] = mx[k].max(p[k]);
                }
            }
            acc["min"] = serde_json::json!(mn);
            acc["max"] = serde_json::json!(mx);
        }
        self.accessors.push(acc);
        Some(self.accessors.len() - 1)
    }
}

// Little-endian bytes by extend per value: a flat_map collect into bytes ran one byte
// at a time and was most of `blendsynth mesh` on the published colon (650k vertices).
fn le_bytes(values: usize, v: impl Iterator<Item = [u8; 4]>) -> Vec<u8> {
    let mut out = Vec::with_capacity(values * 4);
    for b in v {
        out.extend_from_slice(&b);
    }
    out
}
fn f32s<const K: usize>(v: &[[f32; K]]) -> Vec<u8> {
    le_bytes(v.len() * K, v.iter().flatten().map(|c| c.to_le_bytes()))
}
fn u32s(v: impl Iterator<Item = u32>) -> Vec<u8> {
    le_bytes(v.size_hint().0, v.map(u32::to_le_bytes))
}

/// glb in the exporter's layout (FORMAT.md, "The mesh glb"): the exact mesh in
/// `extras.blendsynth` plus a corner-split triangle primitive for viewers.
// Long because it writes the glb's JSON and binary chunks in one pass, in the exporter's layout.
pub fn glb_bytes(m: &Mesh, name: &str) -> Result<Vec<u8>, GeometryError> {
    let md = m.to_scene(name);
    let mut b = GlbBuilder {
        bin: Vec::new(),
        views: Vec::new(),
        accessors: Vec::new(),
    };
    let mut ex = serde_json::json!({
        "version": 1, "name": name, "vertex_count": m.vertex_count(), "edge_count": m.edge_count(),
        "face_count": m.face_count(), "corner_count": m.corner_count(), "triangle_count": md.triangles.len(),
    });
    let put = |ex: &mut serde_json::Value, key: &str, idx: Option<usize>| {
        if let Some(i) = idx {
            ex[key] = i.into();
        }
    };
    put(
        &mut ex,
        "vertex_positions",
        b.add(&f32s(&m.positions), m.vertex_count(), "VEC3", 5126, None),
    );
    let ev: Vec<[u32; 2]> = m.edges.clone();
    put(
        &mut ex,
        "edge_verts",
        b.add(
            &u32s(ev.iter().flat_map(|e| e.iter().copied())),
            m.edge_count(),
            "VEC2",
            5125,
            None,
        ),
    );
    if m.face_count() > 0 {
        put(
            &mut ex,
            "face_offsets",
            b.add(
                &u32s(m.face_offsets.iter().copied()),
                m.face_offsets.len(),
                "SCALAR",
                5125,
                None,
            ),
        );
    }
    put(
        &mut ex,
        "corner_verts",
        b.add(
            &u32s(m.corner_verts.iter().copied()),
            m.corner_count(),
            "SCALAR",
            5125,
            None,
        ),
    );
    put(
        &mut ex,
        "corner_edges",
        b.add(
            &u32s(m.corner_edges.iter().copied()),
            m.corner_count(),
            "SCALAR",
            5125,
            None,
        ),
    );
    let normals = if m.face_count() > 0 {
        md.corner_normals.clone()
    } else {
        Vec::new()
    };
    let normals_idx = b.add(&f32s(&normals), normals.len(), "VEC3", 5126, None);
    put(&mut ex, "corner_normals", normals_idx);
    let tri_idx = b.add(
        &u32s(md.triangles.iter().flat_map(|t| t.iter().copied())),
        md.triangles.len() * 3,
        "SCALAR",
        5125,
        None,
    );
    put(&mut ex, "triangle_corners", tri_idx);
    put(
        &mut ex,
        "triangle_faces",
        b.add(
            &u32s(md.triangle_faces.iter().copied()),
            md.triangle_faces.len(),
            "SCALAR",
            5125,
            None,
        ),
    );
    let mut attrs = Vec::new();
    let mut uvs: Vec<Vec<[f32; 2]>> = Vec::new();
    for a in &md.attributes {
        use crate::scene::AttributeData as D;
        let n = a.data.len();
        let (bytes, ty, comp) = match &a.data {
            D::Float(v) => (
                le_bytes(v.len(), v.iter().map(|c| c.to_le_bytes())),
                "SCALAR",
                5126,
            ),
            D::Float2(v) => {
                if a.domain == crate::scene::Domain::Corner {
                    uvs.push(v.clone());
                }
                (f32s(v), "VEC2", 5126)
            }
            D::Float3(v) => (f32s(v), "VEC3", 5126),
            D::Color(v) | D::Quaternion(v) => (f32s(v), "VEC4", 5126),
            D::Float4x4(v) => (f32s(v), "MAT4", 5126),
            D::Int(v) => (
                le_bytes(v.len(), v.iter().map(|c| c.to_le_bytes())),
                "SCALAR",
                5125,
            ),
            D::Int2(v) => (
                le_bytes(v.len() * 2, v.iter().flatten().map(|c| c.to_le_bytes())),
                "VEC2",
                5125,
            ),
            D::Int8(v) => (v.iter().map(|c| *c as u8).collect(), "SCALAR", 5120),
            D::Bool(v) => (v.iter().map(|c| *c as u8).collect(), "SCALAR", 5121),
        };
        if let Some(i) = b.add(&bytes, n, ty, comp, None) {
            attrs.push(serde_json::json!({"name": a.name, "domain": a.domain.name(), "data_type": a.data_type, "accessor": i}));
        }
    }
    ex["attributes"] = attrs.into();
    let mut meshes = Vec::new();
    if let Some(ti) = tri_idx {
        let split: Vec<[f32; 3]> = m
            .corner_verts
            .iter()
            .map(|&v| m.positions[v as usize])
            .collect();
        let pos = b
            .add(&f32s(&split), split.len(), "VEC3", 5126, Some(34962))
            .unwrap();
        let mut attributes = serde_json::json!({"POSITION": pos});
        if let Some(n) = normals_idx {
            attributes["NORMAL"] = n.into();
        }
        for (i, uv) in uvs.iter().enumerate() {
            let flipped: Vec<[f32; 2]> = uv.iter().map(|t| [t[0], 1.0 - t[1]]).collect();
            if let Some(k) = b.add(&f32s(&flipped), flipped.len(), "VEC2", 5126, None) {
                attributes[format!("TEXCOORD_{i}")] = k.into();
            }
        }
        meshes.push(serde_json::json!({"name": name, "primitives": [{"attributes": attributes, "indices": ti, "mode": 4}]}));
    }
    while !b.bin.len().is_multiple_of(4) {
        b.bin.push(0);
    }
    let mut doc = serde_json::json!({
        "asset": {"version": "2.0", "generator": "blendsynth"},
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
        "extras": {"blendsynth": ex},
    });
    if !meshes.is_empty() {
        doc["meshes"] = meshes.into();
        doc["nodes"] = serde_json::json!([{"mesh": 0, "name": name}]);
        doc["scenes"] = serde_json::json!([{"nodes": [0]}]);
        doc["scene"] = 0.into();
    }
    let mut json = serde_json::to_vec(&doc).map_err(|e| GeometryError::new(e.to_string()))?;
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + b.bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(b.bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b.bin);
    Ok(out)
}

/// Writes `m` as binary PLY (`ply_bytes`), atomically.
pub fn write_ply(path: &Path, m: &Mesh) -> Result<(), GeometryError> {
    write_atomic(path, &ply_bytes(m).map_err(|e| in_file(path, e))?)
}

/// Writes `m` as OBJ (`obj_bytes`), atomically.
pub fn write_obj(path: &Path, m: &Mesh) -> Result<(), GeometryError> {
    write_atomic(path, &obj_bytes(m))
}

/// Writes `m` as glTF binary (`glb_bytes`), atomically.
pub fn write_glb(path: &Path, m: &Mesh, name: &str) -> Result<(), GeometryError> {
    write_atomic(path, &glb_bytes(m, name).map_err(|e| in_file(path, e))?)
}

fn in_file(path: &Path, e: GeometryError) -> GeometryError {
    GeometryError::new(format!("{}: {e}", path.display()))
}

/// The one atomic writer (a temporary file beside `path`, synced, renamed over it), so a
/// failure never leaves a half-written output.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), GeometryError> {
    crate::foundation::files::write_atomic(path, bytes).map_err(GeometryError::new)
}

/// Writes `m` in the format `path`'s extension names (`glb`, `ply` or `obj`), atomically.
pub fn write_mesh(path: &Path, m: &Mesh, name: &str) -> Result<(), GeometryError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let bytes = match ext.as_str() {
        "glb" => glb_bytes(m, name).map_err(|e| in_file(path, e))?,
        "ply" => ply_bytes(m).map_err(|e| in_file(path, e))?,
        "obj" => obj_bytes(m),
        _ => {
            return Err(GeometryError::new(format!(
                "{}: unknown mesh format (use .glb, .ply or .obj)",
                path.display()
            )))
        }
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(GeometryError::new(format!(
            "{}: folder {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    write_atomic(path, &bytes)
}
