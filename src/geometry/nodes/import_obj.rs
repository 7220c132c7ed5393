//! Import OBJ (`node_geo_import_obj.cc`, reading with `io/wavefront_obj`): one instance
//! (identity transform) per object of the file that has vertices, each a mesh as Blender
//! 4.5 builds it: the object's used vertices in file order, faces in file order (faces
//! with fewer than three corners dropped by swapping the last face into their place, as
//! `fixup_invalid_faces` does), `l` edges then the faces' edges (`mesh_calc_edges`), the
//! "UVMap" corner attribute when the file has any `vt` (zero where a corner has none),
//! `material_index` in order of first `usemtl` per object (no material is created), and
//! flat faces where the smoothing group is off. `o` starts an object; `g` does not. A
//! file with no face or edge at all is one mesh of all its vertices. No axis conversion.
//!
//! Refused by name (Blender does something blendsynth does not reproduce): vertex
//! normals (`vn`: custom normals, which split fans at sharp edges), vertex colours
//! (`v` with RGB, `#MRGB`), curves and surfaces (`cstype`, `curv`, `surf`, ...),
//! polylines of more than two vertices, and faces that repeat a vertex (Blender
//! re-triangulates them).

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::instances::{InstanceReference, Instances};
use super::super::math::MAT4_IDENTITY;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::import_file::{is_space, parse_float, parse_int, read_path, skip_space};

pub fn import_obj(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut set = GeometrySet::default();
    if let Some((path, bytes)) = read_path(ctx)? {
        let meshes = read_obj(&bytes).map_err(|e| ctx.err(format!("OBJ file {path:?}: {e}")))?;
        if !meshes.is_empty() {
            let mut instances = Instances::default();
            for m in meshes {
                let h =
                    instances.add_reference(InstanceReference::Geometry(GeometrySet::from_mesh(m)));
                instances.handles.push(h);
                instances.transforms.push(MAT4_IDENTITY);
            }
            set = GeometrySet::from_instances(instances);
        }
    }
    Ok(outputs([("Instances", SocketValue::Geometry(set))]))
}

#[derive(Clone, Copy)]
struct Corner {
    vert: usize,
    uv: Option<usize>,
}

struct Face {
    start: usize,
    count: usize,
    smooth: bool,
    material: i32,
}

#[derive(Default)]
struct Geometry {
    corners: Vec<Corner>,
    faces: Vec<Face>,
    edges: Vec<[usize; 2]>,
    used: std::collections::BTreeSet<usize>,
    materials: Vec<String>,
}

fn keyword<'a>(line: &'a [u8], k: &[u8]) -> Option<&'a [u8]> {
    (line.len() > k.len() && &line[..k.len()] == k && is_space(line[k.len()]))
        .then(|| &line[k.len() + 1..])
}

/// The meshes Blender's OBJ importer makes of `bytes`, one per object with vertices.
pub fn read_obj(bytes: &[u8]) -> Result<Vec<Mesh>, String> {
    // Line continuations (a backslash before the newline) join lines.
    let mut text = bytes.to_vec();
    for i in 0..text.len().saturating_sub(1) {
        if text[i] == b'\\' && text[i + 1] == b'\n' {
            text[i] = b' ';
            text[i + 1] = b' ';
        } else if text[i] == b'\\' && text[i + 1] == b'\r' && text.get(i + 2) == Some(&b'\n') {
            text[i] = b' ';
            text[i + 1] = b' ';
            text[i + 2] = b' ';
        }
    }
    let mut verts: Vec<[f32; 3]> = Vec::new();
    let mut uvs: Vec<[f32; 2]> = Vec::new();
    let mut geoms: Vec<Geometry> = vec![Geometry::default()];
    let mut smooth = false;
    let mut material: i32 = -1;
    for (ln, raw) in text.split(|&b| b == b'\n').enumerate() {
        let line = &raw[skip_space(raw, 0)..];
        let at = |what: &str| format!("line {}: {what}", ln + 1);
        if line.is_empty() || line[0] == b'#' && keyword(line, b"#MRGB").is_none() {
            continue;
        }
        let floats = |rest: &[u8], n: usize, fallback: f32| -> (Vec<f32>, usize) {
            let mut p = 0;
            let mut out = Vec::with_capacity(n);
            for _ in 0..n {
                p = skip_space(rest, p);
                let (v, k) = parse_float(&rest[p..], fallback);
                out.push(v);
                p += k;
            }
            (out, p)
        };
        if let Some(rest) = keyword(line, b"v") {
            let (v, p) = floats(rest, 3, 0.0);
            verts.push([v[0], v[1], v[2]]);
            if skip_space(rest, p) < rest.len() {
                let (c, _) = floats(&rest[p..], 3, -1.0);
                if c.iter().all(|&x| x >= 0.0) {
                    return Err(at("vertex colours are not supported yet"));
                }
            }
        } else if keyword(line, b"vn").is_some() {
            return Err(at(
                "vertex normals (vn) are not supported yet (Blender sets them as custom normals)",
            ));
        } else if let Some(rest) = keyword(line, b"vt") {
            let (v, _) = floats(rest, 2, 0.0);
            uvs.push([v[0], v[1]]);
        } else if let Some(rest) = keyword(line, b"f") {
            add_face(
                geoms.last_mut().unwrap(),
                rest,
                verts.len(),
                uvs.len(),
                smooth,
                material,
            )
            .map_err(|e| at(&e))?;
        } else if let Some(rest) = keyword(line, b"l") {
            let g = geoms.last_mut().unwrap();
            let mut p = 0;
            let mut ids = Vec::new();
            loop {
                p = skip_space(rest, p);
                if p >= rest.len() {
                    break;
                }
                let (v, k) = parse_int(&rest[p..], -1);
                if k == 0 {
                    break;
                }
                ids.push(v);
                p += k;
            }
            if ids.len() > 2 {
                return Err(at(
                    "polylines of more than two vertices are not supported yet",
                ));
            }
            let fix = |v: i32| -> Result<usize, String> {
                let i = if v < 0 {
                    verts.len() as i64 + v as i64
                } else {
                    v as i64 - 1
                };
                if i < 0 || i as usize >= verts.len() {
                    return Err(at(&format!("edge vertex index {v} out of range")));
                }
                Ok(i as usize)
            };
            let a = fix(*ids.first().unwrap_or(&-1))?;
            let b = fix(*ids.get(1).unwrap_or(&-1))?;
            g.edges.push([a, b]);
            g.used.insert(a);
            g.used.insert(b);
        } else if keyword(line, b"o").is_some() {
            smooth = false;
            material = -1;
            let g = geoms.last().unwrap();
            if !g.faces.is_empty() || !g.edges.is_empty() {
                geoms.push(Geometry::default());
            }
        } else if keyword(line, b"g").is_some() {
            // Groups only name vertex groups, which the node does not import.
        } else if let Some(rest) = keyword(line, b"s") {
            let r = &rest[skip_space(rest, 0)..];
            let r = std::str::from_utf8(r).unwrap_or("");
            smooth = if r == "0" || r.starts_with("off") || r.starts_with("null") {
                false
            } else {
                parse_int(r.as_bytes(), 0).0 != 0
            };
        } else if let Some(rest) = keyword(line, b"usemtl") {
            let name = String::from_utf8_lossy(rest).trim().to_string();
            let g = geoms.last_mut().unwrap();
            material = match g.materials.iter().position(|m| *m == name) {
                Some(i) => i as i32,
                None => {
                    g.materials.push(name);
                    g.materials.len() as i32 - 1
                }
            };
        } else if keyword(line, b"mtllib").is_some() {
        } else if keyword(line, b"#MRGB").is_some() {
            return Err(at("vertex colours (#MRGB) are not supported yet"));
        } else if [
            "cstype", "deg", "curv", "parm", "surf", "curv2", "bmat", "step",
        ]
        .iter()
        .any(|k| keyword(line, k.as_bytes()).is_some())
        {
            return Err(at("curves and surfaces are not supported yet"));
        }
        // Anything else Blender ignores (with a message).
    }
    // No face or edge anywhere: the last object takes every vertex.
    if !verts.is_empty() && geoms.iter().all(|g| g.used.is_empty()) {
        geoms.last_mut().unwrap().used = (0..verts.len()).collect();
    }
    Ok(geoms
        .into_iter()
        .filter(|g| !g.used.is_empty())
        .map(|g| to_mesh(g, &verts, &uvs))
        .collect())
}

fn add_face(
    g: &mut Geometry,
    rest: &[u8],
    nv: usize,
    nuv: usize,
    smooth: bool,
    material: i32,
) -> Result<(), String> {
    let start = g.corners.len();
    let mut p = skip_space(rest, 0);
    let mut valid = true;
    let mut corners = Vec::new();
    while p < rest.len() && valid {
        let (v, k) = parse_int(&rest[p..], i32::MAX);
        p += k;
        valid &= v != i32::MAX;
        let mut uv = None;
        if p < rest.len() && rest[p] == b'/' {
            p += 1;
            if p < rest.len() && rest[p] != b'/' {
                let (t, k) = parse_int(&rest[p..], i32::MAX);
                p += k;
                if t != i32::MAX {
                    uv = Some(t);
                }
            }
            if p < rest.len() && rest[p] == b'/' {
                p += 1;
                let (_, k) = parse_int(&rest[p..], i32::MAX);
                p += k;
            }
        }
        let vi = if v < 0 {
            nv as i64 + v as i64
        } else {
            v as i64 - 1
        };
        if vi < 0 || vi as usize >= nv {
            valid = false;
        }
        let uvi = uv.map(|t| {
            if t < 0 {
                nuv as i64 + t as i64
            } else {
                t as i64 - 1
            }
        });
        if uvi.is_some_and(|t| t < 0 || t as usize >= nuv) {
            valid = false;
        }
        if valid {
            g.used.insert(vi as usize);
        }
        corners.push(Corner {
            vert: vi.max(0) as usize,
            uv: uvi.map(|t| t.max(0) as usize),
        });
        p = skip_space(rest, p);
    }
    if !valid {
        return Ok(()); // Blender ignores the face (vertices already tracked stay).
    }
    let mut seen = std::collections::HashSet::new();
    if corners.len() >= 3 && !corners.iter().all(|c| seen.insert(c.vert)) {
        return Err(
            "a face repeats a vertex (Blender splits it into valid faces), not supported yet"
                .into(),
        );
    }
    g.faces.push(Face {
        start,
        count: corners.len(),
        smooth,
        material,
    });
    g.corners.extend(corners);
    Ok(())
}

fn to_mesh(mut g: Geometry, verts: &[[f32; 3]], uvs: &[[f32; 2]]) -> Mesh {
    // `fixup_invalid_faces`: a face of fewer than three corners is replaced by the last
    // face, which is then not looked at again.
    let mut i = 0;
    while i < g.faces.len() {
        if g.faces[i].count < 3 {
            g.faces.swap_remove(i);
        }
        i += 1;
    }
    let local: std::collections::HashMap<usize, u32> = g
        .used
        .iter()
        .enumerate()
        .map(|(l, &v)| (v, l as u32))
        .collect();
    let mut m = Mesh::new();
    m.positions = g.used.iter().map(|&v| verts[v]).collect();
    let mut uv_data = Vec::new();
    let mut sharp = Vec::with_capacity(g.faces.len());
    let mut mat = Vec::with_capacity(g.faces.len());
    for f in &g.faces {
        for c in &g.corners[f.start..f.start + f.count] {
            m.corner_verts.push(*local.get(&c.vert).unwrap_or(&0));
            uv_data.push(c.uv.map_or([0.0; 2], |t| uvs[t]));
        }
        m.face_offsets.push(m.corner_verts.len() as u32);
        sharp.push(!f.smooth);
        mat.push(f.material.max(0));
    }
    m.edges = g
        .edges
        .iter()
        .map(|e| [local[&e[0]], local[&e[1]]])
        .collect();
    m.calc_edges(true);
    m.materials = vec![None; g.materials.len()];
    let nf = m.face_count();
    m.attributes.set(
        AttrId::Named("material_index".into()),
        Domain::Face,
        Array::Int(mat),
    );
    m.attributes.set(
        AttrId::Named("sharp_face".into()),
        Domain::Face,
        Array::Bool(sharp),
    );
    debug_assert_eq!(nf, m.face_count());
    if !uvs.is_empty() {
        m.attributes.set(
            AttrId::Named("UVMap".into()),
            Domain::Corner,
            Array::Float2(uv_data),
        );
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_keep_their_used_vertices_in_file_order() {
        let obj =
            b"v 9 9 9\no A\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 2 3 4\no B\nv 2 0 0\nf 3 -1 4\nf 2 3\n";
        let ms = read_obj(obj).unwrap();
        assert_eq!(ms.len(), 2);
        assert_eq!(
            ms[0].positions,
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
        );
        // B uses vertices 2..5 (the dropped two-corner face's too), in file order.
        assert_eq!(ms[1].positions.len(), 4);
        assert_eq!(ms[1].corner_verts, vec![1, 3, 2]);
        assert!(read_obj(b"v 0 0 0\nvn 0 0 1\n").is_err());
    }
}
