//! Split Edges (`geometry::split_edges`, Blender 4.5): each vertex of a selected edge gets
//! one vertex per group of its faces still joined by unselected edges (the last group keeps
//! the original vertex, new ones are appended in vertex order), and each selected edge one
//! edge per distinct pair of its faces' new corner vertices (the first reuses the edge).
//! New elements copy the attributes of the element they split from.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

/// For each of `n` keys, the items whose key it is, in item order.
fn group_by(n: usize, keys: impl Iterator<Item = usize>) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); n];
    for (i, k) in keys.enumerate() {
        out[k].push(i);
    }
    out
}

fn ordered(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

pub fn split_edges(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        if m.edge_count() == 0 {
            return Ok(());
        }
        let sel = eval_fields(
            ComponentRef::Mesh(&m),
            Domain::Edge,
            &[(&sel, DataType::Bool)],
        )?;
        let sel = sel[0].as_bool().into_owned();
        if !sel.iter().any(|&b| b) {
            return Ok(());
        }
        // A new Arc: `mesh_mut` would first deep-copy the shared input.
        s.mesh = Some(std::sync::Arc::new(split(&m, &sel)));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", SocketValue::Geometry(g))]))
}

/// The corner of `face` on the same edge as `corner` that uses `vert` (`corner` or the
/// next one, depending on the faces' winding).
fn corner_at_vert(m: &Mesh, face: usize, corner: usize, vert: u32) -> usize {
    if m.corner_verts[corner] == vert {
        corner
    } else {
        m.next_corner(face, corner)
    }
}

// Long because it follows Blender 4.5's geometry::split_edges step by step (corner groups
// per vertex, new vertices, deduplicated edges, attributes), which tests compare exactly.
fn split(m: &Mesh, split_edge: &[bool]) -> Mesh {
    let nv = m.vertex_count();
    let ne = m.edge_count();
    let corner_face = m.corner_faces();
    let vert_corners = group_by(nv, m.corner_verts.iter().map(|&v| v as usize));
    let edge_corners = group_by(ne, m.corner_edges.iter().map(|&e| e as usize));
    let loose: Vec<bool> = edge_corners.iter().map(|c| c.is_empty()).collect();
    let any_loose = loose.iter().any(|&l| l);
    let mut vert_edges = vec![Vec::new(); nv];
    for (e, [a, b]) in m.edges.iter().enumerate() {
        vert_edges[*a as usize].push(e);
        if b != a {
            vert_edges[*b as usize].push(e);
        }
    }
    let mut affected = vec![false; nv];
    for (e, [a, b]) in m.edges.iter().enumerate() {
        if split_edge[e] {
            affected[*a as usize] = true;
            affected[*b as usize] = true;
        }
    }
    let affected: Vec<usize> = (0..nv).filter(|&v| affected[v]).collect();

    // Groups of corners around each affected vertex, joined across unselected edges.
    let groups: Vec<Vec<Vec<usize>>> = affected
        .iter()
        .map(|&v| {
            let connected = &vert_corners[v];
            let mut used = vec![false; connected.len()];
            let mut out = Vec::new();
            for &start in connected {
                let mut group = Vec::new();
                let mut stack = vec![start];
                while let Some(c) = stack.pop() {
                    let i = connected.iter().position(|&x| x == c).unwrap();
                    if used[i] {
                        continue;
                    }
                    used[i] = true;
                    group.push(c);
                    let f = corner_face[c] as usize;
                    let prev = m.prev_corner(f, c);
                    for e in [m.corner_edges[c], m.corner_edges[prev]] {
                        if split_edge[e as usize] {
                            continue;
                        }
                        for &oc in &edge_corners[e as usize] {
                            let of = corner_face[oc] as usize;
                            if of == f {
                                continue;
                            }
                            stack.push(corner_at_vert(m, of, oc, v as u32));
                        }
                    }
                }
                if !group.is_empty() {
                    out.push(group);
                }
            }
            out
        })
        .collect();

    // New vertices per affected vertex (the original is reused once).
    let mut counts: Vec<i64> = groups.iter().map(|g| g.len() as i64 - 1).collect();
    if any_loose {
        for (k, &v) in affected.iter().enumerate() {
            let sel = vert_edges[v]
                .iter()
                .filter(|&&e| loose[e] && split_edge[e])
                .count();
            let unsel = vert_edges[v]
                .iter()
                .filter(|&&e| loose[e] && !split_edge[e])
                .count();
            counts[k] += sel as i64;
            if groups[k].is_empty() && unsel > 0 {
                counts[k] += 1;
            }
        }
    }
    let mut vert_offsets = vec![0usize; affected.len() + 1];
    for k in 0..affected.len() {
        vert_offsets[k + 1] = vert_offsets[k] + counts[k].max(0) as usize;
    }
    let mut out = m.clone();
    out.custom_vert_normals = None;
    for (k, gs) in groups.iter().enumerate() {
        for (gi, group) in gs.iter().enumerate().take(gs.len().saturating_sub(1)) {
            let nvx = (nv + vert_offsets[k] + gi) as u32;
            for &c in group {
                out.corner_verts[c] = nvx;
            }
        }
    }
    let edge_of_corner = |out: &Mesh, c: usize| -> [u32; 2] {
        let f = corner_face[c] as usize;
        ordered(out.corner_verts[c], out.corner_verts[m.next_corner(f, c)])
    };

    // Selected edges: one edge per distinct corner-vertex pair, the first in place.
    let mut new_edges: Vec<[u32; 2]> = Vec::new();
    let mut new_edge_source: Vec<usize> = Vec::new();
    for e in (0..ne).filter(|&e| split_edge[e]) {
        let corners = &edge_corners[e];
        if corners.is_empty() {
            continue;
        }
        let start = new_edges.len();
        let mut dedup: Vec<[u32; 2]> = Vec::new();
        for &c in corners {
            let pair = edge_of_corner(&out, c);
            let index = match dedup.iter().position(|p| *p == pair) {
                Some(i) => i,
                None => {
                    dedup.push(pair);
                    dedup.len() - 1
                }
            };
            if index > 0 {
                out.corner_edges[c] = (ne + start + index - 1) as u32;
            }
        }
        out.edges[e] = dedup[0];
        for p in &dedup[1..] {
            new_edges.push(*p);
            new_edge_source.push(e);
        }
    }
    // Unselected edges follow their first corner's (possibly new) vertices.
    for e in (0..ne).filter(|&e| !split_edge[e]) {
        if let Some(&c) = edge_corners[e].first() {
            out.edges[e] = edge_of_corner(&out, c);
        }
    }
    if any_loose {
        let swap = |edge: &mut [u32; 2], old: u32, new: u32| {
            if edge[0] == old {
                edge[0] = new;
            } else if edge[1] == old {
                edge[1] = new;
            }
        };
        for (k, &v) in affected.iter().enumerate() {
            let total = vert_offsets[k + 1] - vert_offsets[k];
            let mut i = groups[k].len().saturating_sub(1);
            if i == total {
                continue;
            }
            let sel: Vec<usize> = vert_edges[v]
                .iter()
                .copied()
                .filter(|&e| loose[e] && split_edge[e])
                .collect();
            let unsel: Vec<usize> = vert_edges[v]
                .iter()
                .copied()
                .filter(|&e| loose[e] && !split_edge[e])
                .collect();
            let mut done = false;
            for e in sel {
                let nvx = (nv + vert_offsets[k] + i) as u32;
                swap(&mut out.edges[e], v as u32, nvx);
                i += 1;
                if i == total {
                    done = true;
                    break;
                }
            }
            if !done {
                let nvx = (nv + vert_offsets[k] + i) as u32;
                for e in unsel {
                    swap(&mut out.edges[e], v as u32, nvx);
                }
            }
        }
    }
    // New edges and vertices copy their sources' attributes.
    out.edges.extend_from_slice(&new_edges);
    let mut vert_source = Vec::with_capacity(vert_offsets[affected.len()]);
    for (k, &v) in affected.iter().enumerate() {
        vert_source.extend(std::iter::repeat_n(
            v,
            vert_offsets[k + 1] - vert_offsets[k],
        ));
    }
    for &v in &vert_source {
        out.positions.push(m.positions[v]);
    }
    for a in out.attributes.0.iter_mut() {
        let source = match a.domain {
            Domain::Point => &vert_source,
            Domain::Edge => &new_edge_source,
            _ => continue,
        };
        let extra: Array = a.data.gather(source);
        a.data.extend(&extra);
    }
    out
}
