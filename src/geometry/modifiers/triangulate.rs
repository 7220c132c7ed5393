//! The Triangulate modifier (`MOD_triangulate.cc`, `BM_mesh_triangulate` and
//! `BM_face_triangulate`): every face with at least `min_vertices` corners becomes
//! triangles. Quads split by the quad method (Beauty, Fixed, Fixed Alternate, Shortest or
//! Longest Diagonal), n-gons by Blender's ear clipping (`polyfill`), then, for Beauty,
//! its edge rotation (`beautify`).
//!
//! Element order follows BMesh: each face keeps its place holding its last triangle; the
//! other triangles are appended after all faces, face by face (the memory pool reuses the
//! slot of each face's discarded last triangle for the next face's first one); new edges
//! are appended as the triangles create them. Keep Normals writes custom normals, which
//! blendsynth does not represent: `unsupported` names it.

use std::collections::HashMap;

use super::super::beautify::{beautify, rotate_beauty_3d};
use super::super::mesh::Mesh;
use super::super::polyfill::{polyfill, project};
use super::super::set::GeometrySet;
use super::super::types::Domain;
use super::{flag, int, text, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let mut out = Vec::new();
    if flag(p, "keep_custom_normals") {
        out.push("Keep Normals (keep_custom_normals)".to_string());
    }
    for (k, allowed) in [
        (
            "quad_method",
            &[
                "BEAUTY",
                "FIXED",
                "FIXED_ALTERNATE",
                "SHORTEST_DIAGONAL",
                "LONGEST_DIAGONAL",
            ][..],
        ),
        ("ngon_method", &["BEAUTY", "CLIP"][..]),
    ] {
        match p.get(k).and_then(|v| v.as_str()) {
            Some(m) if allowed.contains(&m) => {}
            other => out.push(format!("{k} {other:?}")),
        }
    }
    (!out.is_empty()).then(|| out.join(", "))
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let quad = text(p, "quad_method")?;
    let ngon_beauty = text(p, "ngon_method")? == "BEAUTY";
    let min_vertices = int(p, "min_vertices")?.max(4) as usize;
    *g.mesh_mut().unwrap() = triangulate(&m, quad, ngon_beauty, min_vertices);
    Ok(g)
}

/// The corners (face-local indices) of each triangle of face `f`, in creation order.
fn face_tris(m: &Mesh, f: usize, quad: &str, ngon_beauty: bool) -> Vec<[usize; 3]> {
    let r = m.face(f);
    let n = r.len();
    let pos = |k: usize| m.positions[m.corner_verts[r.start + k] as usize];
    if n == 4 {
        let split_02 = match quad {
            "FIXED" => true,
            "FIXED_ALTERNATE" => false,
            _ => {
                // v1..v4 are corners 1, 2, 3, 0; "split 24" joins corners 0 and 2.
                let (v1, v2, v3, v4) = (pos(1), pos(2), pos(3), pos(0));
                let d = |a: [f32; 3], b: [f32; 3]| {
                    (a[0] - b[0]) * (a[0] - b[0])
                        + (a[1] - b[1]) * (a[1] - b[1])
                        + (a[2] - b[2]) * (a[2] - b[2])
                };
                match quad {
                    "SHORTEST_DIAGONAL" => d(v1, v3) - d(v4, v2) > 0.0,
                    "LONGEST_DIAGONAL" => d(v1, v3) - d(v4, v2) < 0.0,
                    _ => {
                        let flip = quad_flip(v1, v2, v3, v4);
                        if flip & 1 != 0 {
                            true
                        } else if flip & 2 != 0 {
                            false
                        } else {
                            let same13 = m.corner_verts[r.start + 1] == m.corner_verts[r.start + 3];
                            !same13 && rotate_beauty_3d(v1, v2, v3, v4, false) > 0.0
                        }
                    }
                }
            }
        };
        let l = if split_02 { [0, 1, 2, 3] } else { [1, 2, 3, 0] };
        return vec![[l[0], l[1], l[2]], [l[0], l[2], l[3]]];
    }
    let co = project(m.face_normal(f), (0..n).map(pos));
    let mut tris = polyfill(&co);
    if ngon_beauty {
        tris = beautify(&co, &tris);
    }
    tris.iter()
        .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
        .collect()
}

/// `is_quad_flip_v3`: bit 0 when the (1-3) diagonal gives flipped triangles, bit 1 (2-4).
/// Carries `m`'s attributes onto its triangulation `out`, as both Triangulate the modifier
/// and the node do: points unchanged, the `new_edges` added edges default, each face and
/// corner from its source (`face_src`, `corner_src`).
pub(crate) fn carry_attributes(
    m: &Mesh,
    out: &mut Mesh,
    new_edges: usize,
    face_src: &[usize],
    corner_src: &[usize],
) {
    for a in m.attributes.iter() {
        let data = match a.domain {
            Domain::Point => a.data.clone(),
            Domain::Edge => {
                let mut d = a.data.clone();
                d.extend_default(new_edges);
                d
            }
            Domain::Face => a.data.gather(face_src),
            Domain::Corner => a.data.gather(corner_src),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
}

pub(crate) fn quad_flip(v1: [f32; 3], v2: [f32; 3], v3: [f32; 3], v4: [f32; 3]) -> u32 {
    use super::super::math::{cross, dot, sub};
    let (d12, d23, d34, d41) = (sub(v1, v2), sub(v2, v3), sub(v3, v4), sub(v4, v1));
    let mut r = 0;
    if dot(cross(d12, d23), cross(d34, d41)) < 0.0 {
        r |= 1;
    }
    if dot(cross(d23, d34), cross(d41, d12)) < 0.0 {
        r |= 2;
    }
    r
}

fn triangulate(m: &Mesh, quad: &str, ngon_beauty: bool, min_vertices: usize) -> Mesh {
    let nf = m.face_count();
    let mut edge_of: HashMap<(u32, u32), u32> = HashMap::with_capacity(m.edge_count() * 2);
    for (i, e) in m.edges.iter().enumerate() {
        edge_of
            .entry((e[0].min(e[1]), e[0].max(e[1])))
            .or_insert(i as u32);
    }
    let mut edges = m.edges.clone();
    // Output faces as (source face, source corners, untouched).
    let mut slots: Vec<(usize, Vec<usize>, bool)> = Vec::with_capacity(nf);
    let mut extra: Vec<(usize, Vec<usize>, bool)> = Vec::new();
    for f in 0..nf {
        let r = m.face(f);
        if r.len() < min_vertices || r.len() <= 3 {
            slots.push((f, r.collect(), true));
            continue;
        }
        let tris = face_tris(m, f, quad, ngon_beauty);
        let last = tris.len() - 1;
        for (i, t) in tris.iter().enumerate() {
            let corners: Vec<usize> = t.iter().map(|&k| r.start + k).collect();
            // Edges (v[i-1], v[i]) for i = 0, 1, 2, made where missing.
            for k in 0..3 {
                let a = m.corner_verts[corners[(k + 2) % 3]];
                let b = m.corner_verts[corners[k]];
                let next = edges.len() as u32;
                edge_of.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    edges.push([a, b]);
                    next
                });
            }
            if i == last {
                slots.push((f, corners, false));
            } else {
                extra.push((f, corners, false));
            }
        }
    }
    let mut out = Mesh::new();
    out.materials = m.materials.clone();
    out.positions = m.positions.clone();
    let new_edges = edges.len() - m.edge_count();
    out.edges = edges;
    let mut face_src = Vec::with_capacity(slots.len() + extra.len());
    let mut corner_src = Vec::new();
    for (f, corners, untouched) in slots.into_iter().chain(extra) {
        face_src.push(f);
        let k = corners.len();
        for (j, &c) in corners.iter().enumerate() {
            let a = m.corner_verts[c];
            let b = m.corner_verts[corners[(j + 1) % k]];
            out.corner_verts.push(a);
            out.corner_edges.push(if untouched {
                m.corner_edges[c]
            } else {
                edge_of[&(a.min(b), a.max(b))]
            });
            corner_src.push(c);
        }
        out.face_offsets.push(out.corner_verts.len() as u32);
    }
    carry_attributes(m, &mut out, new_edges, &face_src, &corner_src);
    out
}
