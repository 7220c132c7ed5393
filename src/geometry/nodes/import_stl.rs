//! Import STL (`node_geo_import_stl.cc`, reading with `io/stl`): the file's triangles as
//! a mesh, as Blender 4.5 reads them for the node (no facet normals, no axis change):
//! binary when the size is exactly 84 + 50 x the header's triangle count, else ASCII;
//! vertices merged where their coordinates are bitwise the same, in first-use order;
//! triangles with a repeated vertex dropped, and repeats of a triangle (same three
//! vertices in the same order) dropped; edges as `mesh_calc_edges`; every face flat.
//! A file shorter than a binary header gives empty geometry (Blender's read error).

use std::collections::HashMap;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::import_file::{is_space, parse_float, read_path, skip_space, skip_word};

const BINARY_HEADER: usize = 80;
const BINARY_STRIDE: usize = 50;

pub fn import_stl(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let set = match read_path(ctx)? {
        None => GeometrySet::default(),
        Some((path, bytes)) => match read_stl(&bytes) {
            Some(mesh) => GeometrySet::from_mesh(mesh),
            None => {
                eprintln!(
                    "warning: {}",
                    ctx.err(format!("STL file {path:?} is shorter than an STL header: empty geometry, as Blender gives"))
                );
                GeometrySet::default()
            }
        },
    };
    Ok(outputs([("Mesh", SocketValue::Geometry(set))]))
}

/// The mesh Blender's STL importer makes of `bytes`; None where it fails to read.
pub fn read_stl(bytes: &[u8]) -> Option<Mesh> {
    if bytes.len() < BINARY_HEADER + 4 {
        return None;
    }
    let count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as u64;
    let binary = bytes.len() as u64 == (BINARY_HEADER as u64 + 4) + BINARY_STRIDE as u64 * count;
    let mut b = Builder::default();
    if binary {
        let f = |t: &[u8], k: usize| f32::from_le_bytes(t[k * 4..k * 4 + 4].try_into().unwrap());
        for t in bytes[84..].chunks_exact(BINARY_STRIDE) {
            // 3 floats of facet normal, then the three vertices.
            let v = |i: usize| [f(t, 3 + 3 * i), f(t, 4 + 3 * i), f(t, 5 + 3 * i)];
            b.add([v(0), v(1), v(2)]);
        }
    } else {
        read_ascii(bytes, &mut b);
    }
    Some(b.into_mesh())
}

/// `read_stl_ascii`: the header line skipped, then tokens; "vertex" reads three floats
/// and up to two more "vertex" rows (a missing one keeps the previous triangle's), and
/// every other token is skipped.
fn read_ascii(bytes: &[u8], b: &mut Builder) {
    let mut p = bytes
        .iter()
        .position(|&c| c == b'\n')
        .unwrap_or(bytes.len());
    let skip_ws = |p: &mut usize| *p = skip_space(bytes, *p);
    let token = |p: &mut usize, tok: &[u8]| -> bool {
        skip_ws(p);
        let rest = &bytes[*p..];
        if rest.len() < tok.len() + 1 || &rest[..tok.len()] != tok || !is_space(rest[tok.len()]) {
            return false;
        }
        *p += tok.len() + 1;
        true
    };
    let float3 = |p: &mut usize, out: &mut [f32; 3]| {
        for o in out.iter_mut() {
            skip_ws(p);
            let (v, n) = parse_float(&bytes[*p..], 0.0);
            *o = v;
            *p += n;
        }
    };
    let mut tri = [[0.0f32; 3]; 3];
    let mut normal = [0.0f32; 3];
    while p < bytes.len() {
        if token(&mut p, b"vertex") {
            float3(&mut p, &mut tri[0]);
            if token(&mut p, b"vertex") {
                float3(&mut p, &mut tri[1]);
            }
            if token(&mut p, b"vertex") {
                float3(&mut p, &mut tri[2]);
            }
            b.add(tri);
        } else if token(&mut p, b"facet") {
            // "normal" and the facet normal, which the node does not use.
            p = skip_word(bytes, p);
            skip_ws(&mut p);
            float3(&mut p, &mut normal);
        } else {
            p = skip_word(bytes, p);
            skip_ws(&mut p);
        }
    }
}

/// `STLMeshHelper`: unique vertices and triangles in first-use order.
#[derive(Default)]
struct Builder {
    positions: Vec<[f32; 3]>,
    vertex_of: HashMap<[u32; 3], u32>,
    tris: Vec<[u32; 3]>,
    seen_tris: HashMap<[u32; 3], ()>,
}

impl Builder {
    fn vertex(&mut self, p: [f32; 3]) -> u32 {
        let key = p.map(f32::to_bits);
        let next = self.positions.len() as u32;
        *self.vertex_of.entry(key).or_insert_with(|| {
            self.positions.push(p);
            next
        })
    }
    fn add(&mut self, t: [[f32; 3]; 3]) {
        let ids = [self.vertex(t[0]), self.vertex(t[1]), self.vertex(t[2])];
        if ids[0] == ids[1] || ids[0] == ids[2] || ids[1] == ids[2] {
            return;
        }
        if self.seen_tris.insert(ids, ()).is_none() {
            self.tris.push(ids);
        }
    }
    fn into_mesh(self) -> Mesh {
        let n = self.tris.len();
        let mut m = Mesh::new();
        m.positions = self.positions;
        m.face_offsets = (0..=n as u32).map(|f| f * 3).collect();
        m.corner_verts = self.tris.into_iter().flatten().collect();
        m.calc_edges(false);
        // The importer marks every face flat (`mesh_smooth_set(false)`).
        m.attributes.set(
            AttrId::Named("sharp_face".into()),
            Domain::Face,
            Array::Bool(vec![true; n]),
        );
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_merge_vertices_and_drop_bad_triangles() {
        let ascii = b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0 0 0\nvertex 1 1 0\nendloop\nendfacet\nendsolid x\n";
        let m = read_stl(ascii).unwrap();
        assert_eq!(
            (m.vertex_count(), m.face_count(), m.edge_count()),
            (3, 1, 3)
        );
        let mut bin = vec![0u8; 80];
        bin.extend(1u32.to_le_bytes());
        for x in [0.0f32, 0., 1., 0., 0., 0., 2., 0., 0., 0., 2., 0.] {
            bin.extend(x.to_le_bytes());
        }
        bin.extend([0, 0]);
        let m = read_stl(&bin).unwrap();
        assert_eq!(
            m.positions,
            vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]
        );
        assert!(read_stl(b"solid").is_none());
    }
}
