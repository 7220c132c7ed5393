//! The Triangulate node (`node_geo_triangulate`, `geometry::mesh_triangulate`): unlike the
//! modifier it does not go through BMesh. The selected n-gons' triangles come first (face
//! by face, ear clipping then optional beauty rotation), then two per selected quad (fixed
//! corner orders per diagonal), duplicates of an earlier triangle dropped, then every
//! other face (unselected, or an original triangle no new one duplicates) in its order.
//! Old edges keep their indices; new ones are appended as `mesh_calc_edges` adds them.

use std::collections::HashMap;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::mesh::Mesh;
use super::super::modifiers::triangulate::{carry_attributes, quad_flip};
use super::super::polyfill::{polyfill, project};
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::super::{beautify, set::GeometrySet};
use super::geometry_ops::{eval_fields, modify_geometry_sets};

/// The diagonal a quad is split along, as face-local corner triples.
fn quad_tris(m: &Mesh, f: usize, mode: &str) -> [[usize; 3]; 2] {
    let s = m.face(f).start;
    let p = |k: usize| m.positions[m.corner_verts[s + k] as usize];
    let d2 = |a: [f32; 3], b: [f32; 3]| {
        (a[0] - b[0]) * (a[0] - b[0])
            + (a[1] - b[1]) * (a[1] - b[1])
            + (a[2] - b[2]) * (a[2] - b[2])
    };
    let edge_0_2 = match mode {
        "FIXED" => true,
        "FIXED_ALTERNATE" => false,
        "SHORTEST_DIAGONAL" => d2(p(0), p(2)) < d2(p(1), p(3)),
        "LONGEST_DIAGONAL" => d2(p(0), p(2)) > d2(p(1), p(3)),
        _ => {
            let flip = quad_flip(p(1), p(2), p(3), p(0));
            if flip & 1 != 0 {
                true
            } else if flip & 2 != 0 {
                false
            } else {
                beautify::rotate_beauty_3d(p(1), p(2), p(3), p(0), false) > 0.0
            }
        }
    };
    if edge_0_2 {
        [[2, 0, 1], [0, 2, 3]]
    } else {
        [[1, 3, 0], [3, 1, 2]]
    }
}

fn ordered(t: [u32; 3]) -> [u32; 3] {
    let mut t = t;
    t.sort_unstable();
    t
}

fn triangulate(m: &Mesh, selected: &[bool], quad_mode: &str, ngon_beauty: bool) -> Option<Mesh> {
    let sel = |f: usize| selected[f] && m.face_size(f) > 3;
    let ngons: Vec<usize> = (0..m.face_count())
        .filter(|&f| sel(f) && m.face_size(f) > 4)
        .collect();
    let quads: Vec<usize> = (0..m.face_count())
        .filter(|&f| sel(f) && m.face_size(f) == 4)
        .collect();
    if ngons.is_empty() && quads.is_empty() {
        return None;
    }
    // New triangles as (source face, global corners).
    let mut tris: Vec<(usize, [usize; 3])> = Vec::new();
    for &f in &ngons {
        let r = m.face(f);
        let co = project(
            m.face_normal(f),
            r.clone().map(|c| m.positions[m.corner_verts[c] as usize]),
        );
        let mut local = polyfill(&co);
        if ngon_beauty {
            local = beautify::beautify(&co, &local);
        }
        for t in local {
            tris.push((f, t.map(|k| r.start + k as usize)));
        }
    }
    for &f in &quads {
        let s = m.face(f).start;
        for t in quad_tris(m, f, quad_mode) {
            tris.push((f, t.map(|k| s + k)));
        }
    }
    let verts = |t: &[usize; 3]| t.map(|c| m.corner_verts[c]);
    let mut seen: HashMap<[u32; 3], ()> = HashMap::new();
    tris.retain(|(_, t)| seen.insert(ordered(verts(t)), ()).is_none());
    // Faces kept as they were: unselected ones, and triangles no new triangle repeats.
    let kept: Vec<usize> = (0..m.face_count())
        .filter(|&f| {
            if sel(f) {
                return false;
            }
            if m.face_size(f) == 3 {
                let r = m.face(f);
                let t = [
                    m.corner_verts[r.start],
                    m.corner_verts[r.start + 1],
                    m.corner_verts[r.start + 2],
                ];
                return !seen.contains_key(&ordered(t));
            }
            true
        })
        .collect();
    let mut out = Mesh::new();
    out.positions = m.positions.clone();
    out.edges = m.edges.clone();
    out.materials = m.materials.clone();
    out.face_offsets = vec![0];
    let mut face_src = Vec::with_capacity(tris.len() + kept.len());
    let mut corner_src = Vec::new();
    for (f, t) in &tris {
        face_src.push(*f);
        corner_src.extend_from_slice(t);
        out.face_offsets.push(corner_src.len() as u32);
    }
    for &f in &kept {
        face_src.push(f);
        corner_src.extend(m.face(f));
        out.face_offsets.push(corner_src.len() as u32);
    }
    out.corner_verts = corner_src.iter().map(|&c| m.corner_verts[c]).collect();
    // New edges in triangle order: a quad's diagonal as its first triangle's first two
    // corners give it, an n-gon's inner edges low vertex first (as Blender 4.5 orders and
    // orients them, fixture `topology/tri_*`).
    let mut edge_of: HashMap<(u32, u32), u32> = HashMap::new();
    for (i, e) in m.edges.iter().enumerate() {
        edge_of
            .entry((e[0].min(e[1]), e[0].max(e[1])))
            .or_insert(i as u32);
    }
    for (f, t) in &tris {
        let v = verts(t);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            if a == b || edge_of.contains_key(&key) {
                continue;
            }
            edge_of.insert(key, out.edges.len() as u32);
            out.edges.push(if m.face_size(*f) == 4 {
                [a, b]
            } else {
                [key.0, key.1]
            });
        }
    }
    out.corner_edges = (0..out.face_count())
        .flat_map(|f| {
            let r = out.face(f);
            let cv = &out.corner_verts;
            let edge_of = &edge_of;
            r.clone().map(move |c| {
                let next = if c + 1 == r.end { r.start } else { c + 1 };
                let (a, b) = (cv[c], cv[next]);
                edge_of.get(&(a.min(b), a.max(b))).copied().unwrap_or(0)
            })
        })
        .collect();
    let new_edges = out.edges.len() - m.edges.len();
    carry_attributes(m, &mut out, new_edges, &face_src, &corner_src);
    Some(out)
}

pub fn triangulate_node(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let quad = ctx.prop_str("quad_method")?.to_string();
    let ngon = ctx.prop_str("ngon_method")?;
    if !matches!(
        quad.as_str(),
        "BEAUTY" | "FIXED" | "FIXED_ALTERNATE" | "SHORTEST_DIAGONAL" | "LONGEST_DIAGONAL"
    ) || !matches!(ngon, "BEAUTY" | "CLIP")
    {
        return Err(ctx.err(format!(
            "quad method {quad} / n-gon method {ngon} is not supported"
        )));
    }
    let ngon_beauty = ngon == "BEAUTY";
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            Domain::Face,
            &[(&sel, DataType::Bool)],
        )?;
        if let Some(out) = triangulate(&m, &r[0].as_bool(), &quad, ngon_beauty) {
            *s.mesh_mut().unwrap() = out;
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}
