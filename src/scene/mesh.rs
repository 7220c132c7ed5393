//! Mesh data as Blender holds it (vertices, edges, faces as corner ranges, attributes
//! on every domain), read from the exporter's glb files or from a user's OBJ.
//!
//! Vertices stay one to one with Blender's: nothing is split at seams or sharp edges,
//! so counts and indices compare directly with Blender's.

use std::path::Path;

use gltf::json::accessor::{ComponentType, Type};
use serde::Deserialize;

use super::error::SceneError;
use super::limits::{mul_add, MAX_GLB_BYTES, MAX_MESH_ELEMENTS};

/// The attribute domains of a Blender mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Domain {
    Point,
    Edge,
    Face,
    Corner,
}

impl Domain {
    pub fn parse(s: &str) -> Option<Domain> {
        Some(match s {
            "POINT" => Domain::Point,
            "EDGE" => Domain::Edge,
            "FACE" => Domain::Face,
            "CORNER" => Domain::Corner,
            _ => return None,
        })
    }
    pub fn name(self) -> &'static str {
        match self {
            Domain::Point => "POINT",
            Domain::Edge => "EDGE",
            Domain::Face => "FACE",
            Domain::Corner => "CORNER",
        }
    }
}

/// Attribute values, typed as Blender's attribute data types.
#[derive(Debug, Clone, PartialEq)]
pub enum AttributeData {
    Float(Vec<f32>),
    Float2(Vec<[f32; 2]>),
    Float3(Vec<[f32; 3]>),
    /// FLOAT_COLOR and BYTE_COLOR, both as linear floats.
    Color(Vec<[f32; 4]>),
    /// Quaternions as (w, x, y, z).
    Quaternion(Vec<[f32; 4]>),
    /// Column-major 4x4 matrices.
    Float4x4(Vec<[f32; 16]>),
    Int(Vec<i32>),
    Int2(Vec<[i32; 2]>),
    Int8(Vec<i8>),
    Bool(Vec<bool>),
}

impl AttributeData {
    pub fn len(&self) -> usize {
        match self {
            AttributeData::Float(v) => v.len(),
            AttributeData::Float2(v) => v.len(),
            AttributeData::Float3(v) => v.len(),
            AttributeData::Color(v) | AttributeData::Quaternion(v) => v.len(),
            AttributeData::Float4x4(v) => v.len(),
            AttributeData::Int(v) => v.len(),
            AttributeData::Int2(v) => v.len(),
            AttributeData::Int8(v) => v.len(),
            AttributeData::Bool(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// No values of Blender data type `data_type` (None: a type the format does not hold).
    pub fn empty(data_type: &str) -> Option<AttributeData> {
        use AttributeData as A;
        Some(match data_type {
            "FLOAT" => A::Float(vec![]),
            "FLOAT2" => A::Float2(vec![]),
            "FLOAT_VECTOR" => A::Float3(vec![]),
            "FLOAT_COLOR" | "BYTE_COLOR" => A::Color(vec![]),
            "QUATERNION" => A::Quaternion(vec![]),
            "FLOAT4X4" => A::Float4x4(vec![]),
            "INT" => A::Int(vec![]),
            "INT32_2D" => A::Int2(vec![]),
            "INT8" => A::Int8(vec![]),
            "BOOLEAN" => A::Bool(vec![]),
            _ => return None,
        })
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub name: String,
    pub domain: Domain,
    /// Blender's data type name (FLOAT, FLOAT2, FLOAT_VECTOR, INT, BOOLEAN, ...).
    pub data_type: String,
    pub data: AttributeData,
}

/// A mesh with Blender's topology: faces are ranges of corners (`face_offsets`), each
/// corner names a vertex and an edge.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    pub name: String,
    pub positions: Vec<[f32; 3]>,
    pub edges: Vec<[u32; 2]>,
    /// `face_count + 1` entries; face `f` owns corners `face_offsets[f]..face_offsets[f+1]`.
    pub face_offsets: Vec<u32>,
    pub corner_verts: Vec<u32>,
    pub corner_edges: Vec<u32>,
    /// Blender's corner normals (split normals), one per corner; empty without faces.
    pub corner_normals: Vec<[f32; 3]>,
    /// Triangulation as corner indices (Blender's `loop_triangles`).
    pub triangles: Vec<[u32; 3]>,
    /// The face each triangle belongs to.
    pub triangle_faces: Vec<u32>,
    pub attributes: Vec<Attribute>,
}

impl MeshData {
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    pub fn face_count(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }
    pub fn corner_count(&self) -> usize {
        self.corner_verts.len()
    }
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.name == name)
    }
    pub fn domain_size(&self, d: Domain) -> usize {
        match d {
            Domain::Point => self.vertex_count(),
            Domain::Edge => self.edges.len(),
            Domain::Face => self.face_count(),
            Domain::Corner => self.corner_count(),
        }
    }

    /// Checks every index is in range and every attribute has its domain's size, so
    /// downstream code can index without bounds failures.
    pub fn validate(&self, file: &Path) -> Result<(), SceneError> {
        let err = |loc: &str, msg: String| Err(SceneError::new(file, loc, msg));
        let nv = self.vertex_count() as u64;
        let nc = self.corner_count() as u64;
        if let Some(i) = self
            .positions
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return err(
                "vertex_positions",
                format!("vertex {i} has a non-finite coordinate"),
            );
        }
        if let Some(i) = self
            .edges
            .iter()
            .position(|e| e[0] as u64 >= nv || e[1] as u64 >= nv)
        {
            return err(
                "edge_verts",
                format!("edge {i} names a vertex >= vertex count {nv}"),
            );
        }
        if self.face_offsets.first().copied().unwrap_or(0) != 0 {
            return err("face_offsets", "must start at 0".into());
        }
        if self.face_offsets.windows(2).any(|w| w[1] <= w[0]) {
            return err(
                "face_offsets",
                "faces must have at least one corner (offsets increasing)".into(),
            );
        }
        if !self.face_offsets.is_empty() && *self.face_offsets.last().unwrap() as u64 != nc {
            return err(
                "face_offsets",
                format!("last offset must equal corner count {nc}"),
            );
        }
        if let Some(i) = self.corner_verts.iter().position(|&v| v as u64 >= nv) {
            return err(
                "corner_verts",
                format!("corner {i} names a vertex >= vertex count {nv}"),
            );
        }
        if !self.corner_edges.is_empty() {
            if self.corner_edges.len() as u64 != nc {
                return err(
                    "corner_edges",
                    format!("has {} entries, expected {nc}", self.corner_edges.len()),
                );
            }
            let ne = self.edges.len() as u64;
            if let Some(i) = self.corner_edges.iter().position(|&e| e as u64 >= ne) {
                return err(
                    "corner_edges",
                    format!("corner {i} names an edge >= edge count {ne}"),
                );
            }
        }
        if !self.corner_normals.is_empty() && self.corner_normals.len() as u64 != nc {
            return err(
                "corner_normals",
                format!("has {} entries, expected {nc}", self.corner_normals.len()),
            );
        }
        // Blender's normals are unit vectors; a NaN would shade the whole face black.
        if let Some(i) = self
            .corner_normals
            .iter()
            .position(|n| n.iter().any(|c| !c.is_finite()))
        {
            return err(
                "corner_normals",
                format!("mesh {:?}: corner {i} has a non-finite normal", self.name),
            );
        }
        if let Some(i) = self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&c| c as u64 >= nc))
        {
            return err(
                "triangle_corners",
                format!("triangle {i} names a corner >= corner count {nc}"),
            );
        }
        if self.triangle_faces.len() != self.triangles.len() {
            return err("triangle_faces", "must have one entry per triangle".into());
        }
        let nf = self.face_count() as u64;
        if let Some(i) = self.triangle_faces.iter().position(|&f| f as u64 >= nf) {
            return err(
                "triangle_faces",
                format!("triangle {i} names a face >= face count {nf}"),
            );
        }
        for a in &self.attributes {
            // UV maps (2D vectors) feed texture lookups and tangents: NaN there is
            // corrupt data, not a value Blender's UV editor can make.
            if let (Domain::Corner, AttributeData::Float2(v)) = (a.domain, &a.data) {
                if let Some(i) = v.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                    return err(
                        &format!("attributes[\"{}\"]", a.name),
                        format!("mesh {:?}: value {i} is not finite", self.name),
                    );
                }
            }
            let want = self.domain_size(a.domain);
            if a.data.len() != want {
                return err(
                    &format!("attributes[\"{}\"]", a.name),
                    format!(
                        "has {} values but the {} domain has {want}",
                        a.data.len(),
                        a.domain.name()
                    ),
                );
            }
        }
        Ok(())
    }
}

/// The `extras.blendsynth` block of an exporter glb.
#[derive(Deserialize)]
struct GlbExtras {
    version: u32,
    #[serde(default)]
    name: String,
    vertex_count: usize,
    edge_count: usize,
    face_count: usize,
    corner_count: usize,
    #[serde(default)]
    triangle_count: usize,
    vertex_positions: Option<usize>,
    edge_verts: Option<usize>,
    face_offsets: Option<usize>,
    corner_verts: Option<usize>,
    corner_edges: Option<usize>,
    corner_normals: Option<usize>,
    triangle_corners: Option<usize>,
    triangle_faces: Option<usize>,
    #[serde(default)]
    attributes: Vec<GlbAttribute>,
}

#[derive(Deserialize)]
struct GlbAttribute {
    name: String,
    domain: String,
    data_type: String,
    accessor: usize,
}

/// Reads an exporter glb (layout in `blender_export/FORMAT.md`).
pub fn read_glb(path: &Path) -> Result<MeshData, SceneError> {
    let bytes =
        super::file::read_regular(path, MAX_GLB_BYTES).map_err(|m| SceneError::new(path, "", m))?;
    parse_glb(&bytes, path)
}

/// The 12-byte GLB header of the glTF 2.0 specification: magic `glTF`, version, total
/// length. The gltf crate subtracts the header's size from the length unchecked (an
/// overflow panic where overflow checks are on: found by `cargo fuzz run glb`), so the
/// length is checked here first.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    if bytes.len() < 12 || &bytes[..4] != b"glTF" {
        return Err("no glTF header".into());
    }
    let length = word(8) as usize;
    if length < 12 || length > bytes.len() {
        return Err(format!(
            "the header's length {length} is outside 12..={}, the file's size",
            bytes.len()
        ));
    }
    Ok(())
}

/// The accessor references of every mesh primitive are in range. The `gltf` crate's
/// validation indexes the POSITION accessor before checking it exists (a panic on a
/// corrupt file, found by tests/fuzz_mutations.rs), so this runs first.
fn check_primitive_accessors(bytes: &[u8]) -> Result<(), String> {
    // A file this cannot read is left to the full reader, for its error message.
    let Ok(glb) = gltf::Glb::from_slice(bytes) else {
        return Ok(());
    };
    let Ok(root) = gltf::json::deserialize::from_slice::<gltf::json::Root>(&glb.json) else {
        return Ok(());
    };
    let n = root.accessors.len();
    for (mi, m) in root.meshes.iter().enumerate() {
        for (pi, p) in m.primitives.iter().enumerate() {
            let targets = p.targets.iter().flatten().flat_map(|t| {
                [&t.positions, &t.normals, &t.tangents]
                    .into_iter()
                    .flatten()
                    .map(|i| i.value())
            });
            let used = p
                .attributes
                .values()
                .map(|i| i.value())
                .chain(p.indices.iter().map(|i| i.value()))
                .chain(targets);
            for i in used {
                if i >= n {
                    return Err(format!(
                        "meshes[{mi}].primitives[{pi}] uses accessor {i}, but the file has {n}"
                    ));
                }
            }
        }
    }
    Ok(())
}

pub fn parse_glb(bytes: &[u8], path: &Path) -> Result<MeshData, SceneError> {
    let corrupt = |e: String| {
        SceneError::new(
            path,
            "",
            format!("not a valid glb (truncated or corrupt?): {e}"),
        )
    };
    check_glb_header(bytes).map_err(corrupt)?;
    check_primitive_accessors(bytes).map_err(corrupt)?;
    // A backstop for other such holes in the reader: an error, never a panic.
    let gltf = std::panic::catch_unwind(|| gltf::Gltf::from_slice(bytes))
        .map_err(|_| corrupt("the glTF reader failed on it".into()))?
        .map_err(|e| corrupt(e.to_string()))?;
    let blob: &[u8] = gltf.blob.as_deref().unwrap_or(&[]);
    let root = gltf.document.as_json();
    let extras_raw = root.extras.as_ref().ok_or_else(|| {
        SceneError::new(
            path,
            "extras",
            "no blendsynth extras: not written by blendsynth's exporter",
        )
    })?;
    #[derive(Deserialize)]
    struct Wrap {
        blendsynth: GlbExtras,
    }
    let ex: GlbExtras = serde_json::from_str::<Wrap>(extras_raw.get())
        .map_err(|e| SceneError::new(path, "extras.blendsynth", e.to_string()))?
        .blendsynth;
    if ex.version != 1 {
        return Err(SceneError::new(
            path,
            "extras.blendsynth.version",
            format!("unsupported mesh layout version {}", ex.version),
        ));
    }
    let counts = [
        ("vertex_count", ex.vertex_count),
        ("edge_count", ex.edge_count),
        ("face_count", ex.face_count),
        ("corner_count", ex.corner_count),
        ("triangle_count", ex.triangle_count),
    ];
    for (what, n) in counts {
        if n > MAX_MESH_ELEMENTS {
            return Err(SceneError::new(
                path,
                format!("extras.blendsynth.{what}"),
                format!("{n} is more than the limit of {MAX_MESH_ELEMENTS} elements"),
            ));
        }
    }
    let reader = AccessorReader { root, blob, path };
    let mut m = MeshData {
        name: ex.name.clone(),
        ..Default::default()
    };
    m.positions = reader.vec3(ex.vertex_positions, "vertex_positions", ex.vertex_count)?;
    m.edges = reader.uvec2(ex.edge_verts, "edge_verts", ex.edge_count)?;
    m.face_offsets = reader.u32s(
        ex.face_offsets,
        "face_offsets",
        if ex.face_count > 0 {
            ex.face_count + 1
        } else {
            0
        },
    )?;
    if ex.face_count == 0 {
        // An empty offsets array and `[0]` both mean "no faces".
        m.face_offsets = vec![0];
    }
    m.corner_verts = reader.u32s(ex.corner_verts, "corner_verts", ex.corner_count)?;
    m.corner_edges = reader.u32s(
        ex.corner_edges,
        "corner_edges",
        if ex.edge_count > 0 {
            ex.corner_count
        } else {
            0
        },
    )?;
    m.corner_normals = reader.vec3(
        ex.corner_normals,
        "corner_normals",
        if ex.face_count > 0 {
            ex.corner_count
        } else {
            0
        },
    )?;
    let tri = reader.u32s(
        ex.triangle_corners,
        "triangle_corners",
        // Cannot overflow: the count is at most MAX_MESH_ELEMENTS (checked above).
        ex.triangle_count * 3,
    )?;
    m.triangles = tri.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    m.triangle_faces = reader.u32s(ex.triangle_faces, "triangle_faces", ex.triangle_count)?;
    for (i, a) in ex.attributes.iter().enumerate() {
        let loc = format!("extras.blendsynth.attributes[{i}] (\"{}\")", a.name);
        let domain = Domain::parse(&a.domain)
            .ok_or_else(|| SceneError::new(path, &loc, format!("unknown domain {:?}", a.domain)))?;
        let data = reader.attribute(a.accessor, &a.data_type, &loc)?;
        m.attributes.push(Attribute {
            name: a.name.clone(),
            domain,
            data_type: a.data_type.clone(),
            data,
        });
    }
    m.validate(path)?;
    Ok(m)
}

struct AccessorReader<'a> {
    root: &'a gltf::json::Root,
    blob: &'a [u8],
    path: &'a Path,
}

impl AccessorReader<'_> {
    /// Returns the accessor's elements packed tightly, after checking its type and
    /// that every byte lies inside the BIN chunk.
    fn bytes(
        &self,
        index: usize,
        ty: Type,
        comp: ComponentType,
        what: &str,
    ) -> Result<(usize, Vec<u8>), SceneError> {
        let err = |m: String| SceneError::new(self.path, format!("accessor {what} (#{index})"), m);
        let acc = self
            .root
            .accessors
            .get(index)
            .ok_or_else(|| err("does not exist".into()))?;
        use gltf::json::validation::Checked;
        let acc_ty = match acc.type_ {
            Checked::Valid(t) => Some(t),
            Checked::Invalid => None,
        };
        let acc_comp = match acc.component_type {
            Checked::Valid(c) => Some(c.0),
            Checked::Invalid => None,
        };
        if acc_ty != Some(ty) || acc_comp != Some(comp) {
            return Err(err(format!(
                "has type {:?}/{:?}, expected {ty:?}/{comp:?}",
                acc_ty, acc_comp
            )));
        }
        let count = usize::try_from(acc.count.0)
            .ok()
            .filter(|&n| n <= MAX_MESH_ELEMENTS)
            .ok_or_else(|| {
                err(format!(
                    "count {} is more than the limit of {MAX_MESH_ELEMENTS} elements",
                    acc.count.0
                ))
            })?;
        let elem = ty.multiplicity() * comp.size();
        let view_index = acc
            .buffer_view
            .ok_or_else(|| err("has no buffer view".into()))?
            .value();
        let view = self
            .root
            .buffer_views
            .get(view_index)
            .ok_or_else(|| err("buffer view missing".into()))?;
        if view.buffer.value() != 0 {
            return Err(err("data must be in the glb's BIN chunk".into()));
        }
        let stride = view.byte_stride.map(|s| s.0).unwrap_or(elem);
        if stride < elem {
            return Err(err(format!(
                "byte stride {stride} is less than its element size {elem}"
            )));
        }
        // Offsets and lengths are input numbers: every sum and product is checked, so a
        // crafted file gets this error rather than a wrapped bounds check. With the end
        // inside the blob, the copy below is at most the blob's size.
        let size = |v: u64| usize::try_from(v).ok();
        let view_off = size(view.byte_offset.map(|o| o.0).unwrap_or(0));
        let acc_off = size(acc.byte_offset.map(|o| o.0).unwrap_or(0));
        let view_len = size(view.byte_length.0);
        let ends = (|| {
            let start = view_off?.checked_add(acc_off?)?;
            let view_end = view_off?.checked_add(view_len?)?;
            let need_end = match count {
                0 => start,
                n => mul_add(stride, n - 1, start)?.checked_add(elem)?,
            };
            Some((start, view_end, need_end))
        })();
        let inside = |&(_, view_end, need_end): &(usize, usize, usize)| {
            need_end <= view_end && view_end <= self.blob.len()
        };
        let Some((start, _, _)) = ends.filter(inside) else {
            return Err(err(format!(
                "reads past the end of its data ({} bytes; truncated or corrupt file?)",
                self.blob.len()
            )));
        };
        let mut out = Vec::with_capacity(count * elem);
        for i in 0..count {
            out.extend_from_slice(&self.blob[start + i * stride..start + i * stride + elem]);
        }
        Ok((count, out))
    }

    fn checked(
        &self,
        index: Option<usize>,
        ty: Type,
        comp: ComponentType,
        what: &str,
        expect: usize,
    ) -> Result<Vec<u8>, SceneError> {
        let Some(index) = index else {
            if expect == 0 {
                return Ok(Vec::new());
            }
            return Err(SceneError::new(
                self.path,
                format!("extras.blendsynth.{what}"),
                format!("missing, expected {expect} elements"),
            ));
        };
        let (count, bytes) = self.bytes(index, ty, comp, what)?;
        if count != expect {
            return Err(SceneError::new(
                self.path,
                format!("accessor {what} (#{index})"),
                format!("has {count} elements, expected {expect}"),
            ));
        }
        Ok(bytes)
    }

    fn vec3(
        &self,
        index: Option<usize>,
        what: &str,
        n: usize,
    ) -> Result<Vec<[f32; 3]>, SceneError> {
        let b = self.checked(index, Type::Vec3, ComponentType::F32, what, n)?;
        Ok(floats(&b)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect())
    }
    fn uvec2(
        &self,
        index: Option<usize>,
        what: &str,
        n: usize,
    ) -> Result<Vec<[u32; 2]>, SceneError> {
        let b = self.checked(index, Type::Vec2, ComponentType::U32, what, n)?;
        Ok(u32s(&b).chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }
    fn u32s(&self, index: Option<usize>, what: &str, n: usize) -> Result<Vec<u32>, SceneError> {
        Ok(u32s(&self.checked(
            index,
            Type::Scalar,
            ComponentType::U32,
            what,
            n,
        )?))
    }

    fn attribute(
        &self,
        index: usize,
        data_type: &str,
        loc: &str,
    ) -> Result<AttributeData, SceneError> {
        use AttributeData as A;
        let get = |ty, comp| self.bytes(index, ty, comp, loc).map(|(_, b)| b);
        Ok(match data_type {
            "FLOAT" => A::Float(floats(&get(Type::Scalar, ComponentType::F32)?)),
            "FLOAT2" => A::Float2(
                floats(&get(Type::Vec2, ComponentType::F32)?)
                    .chunks_exact(2)
                    .map(|c| [c[0], c[1]])
                    .collect(),
            ),
            "FLOAT_VECTOR" => A::Float3(
                floats(&get(Type::Vec3, ComponentType::F32)?)
                    .chunks_exact(3)
                    .map(|c| [c[0], c[1], c[2]])
                    .collect(),
            ),
            "FLOAT_COLOR" | "BYTE_COLOR" => {
                A::Color(vec4s(&floats(&get(Type::Vec4, ComponentType::F32)?)))
            }
            "QUATERNION" => A::Quaternion(vec4s(&floats(&get(Type::Vec4, ComponentType::F32)?))),
            "FLOAT4X4" => A::Float4x4(
                floats(&get(Type::Mat4, ComponentType::F32)?)
                    .chunks_exact(16)
                    .map(|c| c.try_into().unwrap())
                    .collect(),
            ),
            "INT" => A::Int(
                u32s(&get(Type::Scalar, ComponentType::U32)?)
                    .into_iter()
                    .map(|v| v as i32)
                    .collect(),
            ),
            "INT32_2D" => A::Int2(
                u32s(&get(Type::Vec2, ComponentType::U32)?)
                    .chunks_exact(2)
                    .map(|c| [c[0] as i32, c[1] as i32])
                    .collect(),
            ),
            "INT8" => A::Int8(
                get(Type::Scalar, ComponentType::I8)?
                    .into_iter()
                    .map(|v| v as i8)
                    .collect(),
            ),
            "BOOLEAN" => A::Bool(
                get(Type::Scalar, ComponentType::U8)?
                    .into_iter()
                    .map(|v| v != 0)
                    .collect(),
            ),
            other => {
                return Err(SceneError::new(
                    self.path,
                    loc,
                    format!("unknown attribute data type {other:?}"),
                ))
            }
        })
    }
}

fn floats(b: &[u8]) -> Vec<f32> {
    b.chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
fn u32s(b: &[u8]) -> Vec<u32> {
    b.chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}
fn vec4s(f: &[f32]) -> Vec<[f32; 4]> {
    f.chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// Reads a user's OBJ as Blender's OBJ importer would lay it out: one vertex per `v`
/// line, faces keep their corner order, UVs and normals become corner data.
pub fn read_obj(path: &Path) -> Result<MeshData, SceneError> {
    let opts = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) = tobj::load_obj(path, &opts)
        .map_err(|e| SceneError::new(path, "", format!("cannot read OBJ: {e}")))?;
    let mut m = MeshData {
        name: path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        ..Default::default()
    };
    m.face_offsets.push(0);
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut material_index: Vec<i32> = Vec::new();
    let mut any_uv = false;
    let mut all_normals = true;
    for model in &models {
        let mesh = &model.mesh;
        let base = m.positions.len() as u32;
        m.positions
            .extend(mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        let has_uv = !mesh.texcoord_indices.is_empty();
        let has_n = !mesh.normal_indices.is_empty();
        any_uv |= has_uv;
        all_normals &= has_n;
        let mut corner = 0usize;
        for &n in &arities {
            for k in 0..n as usize {
                let c = corner + k;
                m.corner_verts.push(base + mesh.indices[c]);
                let uv = if has_uv {
                    let t = mesh.texcoord_indices[c] as usize;
                    [mesh.texcoords[2 * t], mesh.texcoords[2 * t + 1]]
                } else {
                    [0.0, 0.0]
                };
                uvs.push(uv);
                if has_n {
                    let t = mesh.normal_indices[c] as usize;
                    m.corner_normals.push([
                        mesh.normals[3 * t],
                        mesh.normals[3 * t + 1],
                        mesh.normals[3 * t + 2],
                    ]);
                }
            }
            corner += n as usize;
            m.face_offsets.push(m.corner_verts.len() as u32);
            material_index.push(mesh.material_id.unwrap_or(0) as i32);
        }
    }
    if !all_normals {
        m.corner_normals.clear();
    }
    build_edges(&mut m);
    fan_triangulate(&mut m);
    if any_uv {
        m.attributes.push(Attribute {
            name: "UVMap".into(),
            domain: Domain::Corner,
            data_type: "FLOAT2".into(),
            data: AttributeData::Float2(uvs),
        });
    }
    m.attributes.push(Attribute {
        name: "material_index".into(),
        domain: Domain::Face,
        data_type: "INT".into(),
        data: AttributeData::Int(material_index),
    });
    m.validate(path)?;
    Ok(m)
}

/// Derives unique edges from face corners (in first-seen order, as Blender's importer
/// builds them) and fills `corner_edges`.
fn build_edges(m: &mut MeshData) {
    let mut map = std::collections::HashMap::new();
    m.corner_edges = vec![0; m.corner_verts.len()];
    for f in 0..m.face_count() {
        let (s, e) = (m.face_offsets[f] as usize, m.face_offsets[f + 1] as usize);
        for c in s..e {
            let a = m.corner_verts[c];
            let b = m.corner_verts[if c + 1 == e { s } else { c + 1 }];
            let key = (a.min(b), a.max(b));
            let next = m.edges.len() as u32;
            let id = *map.entry(key).or_insert_with(|| {
                m.edges.push([key.0, key.1]);
                next
            });
            m.corner_edges[c] = id;
        }
    }
}

fn fan_triangulate(m: &mut MeshData) {
    for f in 0..m.face_count() {
        let (s, e) = (m.face_offsets[f], m.face_offsets[f + 1]);
        for c in s + 1..e.saturating_sub(1) {
            m.triangles.push([s, c, c + 1]);
            m.triangle_faces.push(f as u32);
        }
    }
}
