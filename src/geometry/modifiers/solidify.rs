//! The Solidify modifier in Simple mode (`MOD_solidify_extrude.cc`): the mesh and a copy
//! with reversed faces (the shell), moved apart along vertex normals by the thickness
//! split by the offset, each vertex by the plain distance or, with Even Thickness, by the
//! angle-weighted inverse cosine of its faces; Fill Rim joins the two along boundary
//! edges with quads (Only Rim drops the copy's faces). Flip swaps which layer moves by
//! which part. Element order is Blender's: originals, copies, rim edges, rim faces.
//!
//! The rim's creases (inner, outer, rim edges) go to `crease_edge` as in Blender, for a
//! Subdivision Surface after it. Not evaluated (named by `unsupported`): Complex mode,
//! High Quality Normals, thickness clamping, convex bevel weights, material offsets and
//! vertex groups.

use super::super::attribute::AttrId;
use super::super::math::{dot, normalize_v3, sub, V3};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::{flag, float, text, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let mut out: Vec<String> = Vec::new();
    match text(p, "solidify_mode") {
        Ok("EXTRUDE") => {}
        Ok("NON_MANIFOLD") => out.push("Mode Complex (solidify_mode)".into()),
        other => out.push(format!("solidify_mode {:?}", other.ok())),
    }
    for (k, name) in [
        ("use_quality_normals", "High Quality Normals"),
        ("use_thickness_angle_clamp", "Angle Clamp"),
    ] {
        if flag(p, k) {
            out.push(format!("{name} ({k})"));
        }
    }
    for (k, name) in [
        ("thickness_clamp", "Clamp"),
        ("bevel_convex", "Bevel Convex"),
    ] {
        if p.get(k).and_then(|v| v.as_f64()).unwrap_or(0.0) != 0.0 {
            out.push(format!("{name} ({k})"));
        }
    }
    for (k, name) in [
        ("material_offset", "Material Offset"),
        ("material_offset_rim", "Rim Material Offset"),
    ] {
        if p.get(k).and_then(|v| v.as_i64()).unwrap_or(0) != 0 {
            out.push(format!("{name} ({k})"));
        }
    }
    for k in ["vertex_group", "shell_vertex_group", "rim_vertex_group"] {
        let g = text(p, k).unwrap_or("");
        if !g.is_empty() {
            out.push(format!("{k} {g:?} (vertex groups are not exported)"));
        }
    }
    (!out.is_empty()).then(|| out.join(", "))
}

const UNUSED: u32 = u32::MAX;
const PAIR: u32 = u32::MAX - 1;

fn saturate_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

/// `angle_normalized_v3v3`.
fn angle_normalized(a: V3, b: V3) -> f32 {
    let len = |d: V3| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    if dot(a, b) >= 0.0 {
        2.0 * saturate_asin(len(sub(a, b)) / 2.0)
    } else {
        let nb = [-b[0], -b[1], -b[2]];
        std::f32::consts::PI - 2.0 * saturate_asin(len(sub(a, nb)) / 2.0)
    }
}

/// `shell_v3v3_normalized_to_dist`.
fn shell_dist(a: V3, b: V3) -> f32 {
    let c = dot(a, b).abs();
    if c < 1e-8 {
        1.0
    } else {
        1.0 / c
    }
}

/// Whether the modifier fills a rim (Fill Rim, or Only Rim): a Subdivision Surface after
/// such a rim is not evaluated natively (see `source::frozen_reason`).
pub fn fills_rim(p: &Props) -> bool {
    flag(p, "use_rim")
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let offset = float(p, "thickness")?;
    let offset_fac = float(p, "offset")?;
    let opts = Opts {
        ofs_orig: -(((-offset_fac + 1.0) * 0.5) * offset),
        ofs_new: 0.0,
        flip: flag(p, "use_flip_normals"),
        even: flag(p, "use_even_offset"),
        rim: flag(p, "use_rim"),
        shell: !(flag(p, "use_rim") && flag(p, "use_rim_only")),
        crease: [
            float(p, "edge_crease_inner").unwrap_or(0.0),
            float(p, "edge_crease_outer").unwrap_or(0.0),
            float(p, "edge_crease_rim").unwrap_or(0.0),
        ],
    };
    let opts = Opts {
        ofs_new: offset + opts.ofs_orig,
        ..opts
    };
    *g.mesh_mut().unwrap() = solidify(&m, &opts);
    Ok(g)
}

struct Opts {
    ofs_orig: f32,
    ofs_new: f32,
    flip: bool,
    even: bool,
    rim: bool,
    shell: bool,
    /// Inner, outer and rim edge creases.
    crease: [f32; 3],
}

// Long because it follows Blender's function step by step.
fn solidify(m: &Mesh, o: &Opts) -> Mesh {
    let (nv, ne, nf, nc) = (
        m.vertex_count(),
        m.edge_count(),
        m.face_count(),
        m.corner_count(),
    );
    // Boundary edges (one face user) make the rim: the face using each, flipped when it
    // runs against the edge, and where in the face it is.
    let mut edge_users = vec![UNUSED; ne];
    let mut edge_order = vec![0usize; ne];
    let mut rim_edges: Vec<usize> = Vec::new();
    let mut rim_verts: Vec<usize> = Vec::new();
    let mut old_vert = vec![UNUSED; nv];
    if o.rim {
        for f in 0..nf {
            let r = m.face(f);
            let mut prev = r.end - 1;
            for (j, c) in r.clone().enumerate() {
                let v = m.corner_verts[c];
                let pv = m.corner_verts[prev];
                let e = m.corner_edges[prev] as usize;
                if edge_users[e] == UNUSED {
                    let ed = m.edges[e];
                    edge_users[e] = if (pv > v) == (ed[0] < ed[1]) {
                        f as u32
                    } else {
                        (f + nf) as u32
                    };
                    edge_order[e] = j;
                } else {
                    edge_users[e] = PAIR;
                }
                prev = c;
            }
        }
        let mut tag = vec![false; nv];
        for e in 0..ne {
            if edge_users[e] != UNUSED && edge_users[e] != PAIR {
                tag[m.edges[e][0] as usize] = true;
                tag[m.edges[e][1] as usize] = true;
                rim_edges.push(e);
            }
        }
        for v in 0..nv {
            if tag[v] {
                old_vert[v] = rim_verts.len() as u32;
                rim_verts.push(v);
            }
        }
    }
    let new_polys = rim_edges.len();
    let (new_verts, new_edges) = if o.shell {
        (0, 0)
    } else {
        (rim_verts.len(), new_polys)
    };

    let mut out = Mesh::new();
    out.materials = m.materials.clone();
    // Vertices (and their attributes): originals, then the copies.
    let vert_src: Vec<usize> = if o.shell {
        (0..nv).chain(0..nv).collect()
    } else {
        (0..nv).chain(rim_verts.iter().copied()).collect()
    };
    out.positions = vert_src.iter().map(|&v| m.positions[v]).collect();
    // Edges: originals, copies, rim edges.
    let mut edge_src: Vec<usize> = (0..ne).collect();
    out.edges = m.edges.clone();
    if o.shell {
        edge_src.extend(0..ne);
        out.edges
            .extend(m.edges.iter().map(|[a, b]| [a + nv as u32, b + nv as u32]));
    } else {
        for &e in &rim_edges {
            edge_src.push(e);
            let [a, b] = m.edges[e];
            out.edges.push([
                old_vert[a as usize] + nv as u32,
                old_vert[b as usize] + nv as u32,
            ]);
        }
    }
    // Faces and corners: originals, reversed copies.
    let mut face_src: Vec<usize> = (0..nf).collect();
    let mut corner_src: Vec<usize> = (0..nc).collect();
    out.face_offsets = m.face_offsets.clone();
    out.corner_verts = m.corner_verts.clone();
    out.corner_edges = m.corner_edges.clone();
    if o.shell {
        for f in 0..nf {
            let r = m.face(f);
            let mut order: Vec<usize> = r.clone().collect();
            order[1..].reverse();
            face_src.push(f);
            for &c in &order {
                corner_src.push(c);
                out.corner_verts.push(m.corner_verts[c] + nv as u32);
            }
            for c in r.clone().rev() {
                out.corner_edges.push(m.corner_edges[c] + ne as u32);
            }
            out.face_offsets.push(out.corner_verts.len() as u32);
        }
    }

    // Offsets along the vertex normals.
    let vert_normals = m.vertex_normals();
    let layer = |test: bool| -> (usize, bool) {
        // (first vertex of the layer, whether it holds every vertex)
        if ((o.ofs_new >= o.ofs_orig) == o.flip) == test {
            (0, true)
        } else {
            (nv, o.shell)
        }
    };
    let mut apply_layer = |test: bool, amount: &dyn Fn(usize) -> Option<f32>| {
        let (start, aligned) = layer(test);
        let count = if aligned { nv } else { new_verts };
        for k in 0..count {
            let i = if aligned { k } else { rim_verts[k] };
            if let Some(d) = amount(i) {
                let n = vert_normals[i];
                let pos = &mut out.positions[start + k];
                for a in 0..3 {
                    pos[a] += n[a] * d;
                }
            }
        }
    };
    if !o.even {
        if o.ofs_new != 0.0 {
            apply_layer(false, &|_| Some(o.ofs_new));
        }
        if o.ofs_orig != 0.0 {
            apply_layer(true, &|_| Some(o.ofs_orig));
        }
    } else {
        let face_normals = m.face_normals();
        let mut angles = vec![0.0f32; nv];
        let mut accum = vec![0.0f32; nv];
        for f in 0..nf {
            let r = m.face(f);
            let fv: Vec<usize> = r.clone().map(|c| m.corner_verts[c] as usize).collect();
            let n = fv.len();
            let mut cur = n - 1;
            let mut prev_dir = normalize_v3(sub(m.positions[fv[cur - 1]], m.positions[fv[cur]])).0;
            for next in 0..n {
                let next_dir = normalize_v3(sub(m.positions[fv[cur]], m.positions[fv[next]])).0;
                let angle = angle_normalized(prev_dir, next_dir).max(f32::EPSILON);
                let v = fv[cur];
                accum[v] += angle;
                angles[v] += shell_dist(vert_normals[v], face_normals[f]) * angle;
                prev_dir = next_dir;
                cur = next;
            }
        }
        for (ofs, test) in [(o.ofs_new, false), (o.ofs_orig, true)] {
            if ofs != 0.0 {
                apply_layer(test, &|i| {
                    (accum[i] != 0.0).then(|| ofs * (angles[i] / accum[i]))
                });
            }
        }
    }

    // Rim: an edge per rim vertex, a quad per boundary edge.
    if o.rim {
        let edge_base = ne * if o.shell { 2 } else { 1 } + new_edges;
        for (r, &v) in rim_verts.iter().enumerate() {
            edge_src.push(usize::MAX);
            let other = if o.shell { v } else { r };
            out.edges.push([v as u32, (other + nv) as u32]);
        }
        for (i, &e) in rim_edges.iter().enumerate() {
            let (pidx, flip) = if edge_users[e] as usize >= nf {
                (edge_users[e] as usize - nf, true)
            } else {
                (edge_users[e] as usize, false)
            };
            let [a, b] = m.edges[e];
            let (a, b) = (a as usize, b as usize);
            let size = m.face_size(pidx);
            let start = m.face_offsets[pidx] as usize;
            let k1 = start + (edge_order[e] + size - 1) % size;
            let k2 = start + edge_order[e];
            face_src.push(pidx);
            corner_src.extend([k2, k1, k1, k2]);
            let copy = |v: usize| if o.shell { v } else { old_vert[v] as usize } + nv;
            let rim_edge = |v: usize| (edge_base + old_vert[v] as usize) as u32;
            let copy_edge = (if o.shell { e } else { i } + ne) as u32;
            let (x, y) = if flip { (b, a) } else { (a, b) };
            out.corner_verts
                .extend([x as u32, y as u32, copy(y) as u32, copy(x) as u32]);
            out.corner_edges
                .extend([e as u32, rim_edge(y), copy_edge, rim_edge(x)]);
            out.face_offsets.push(out.corner_verts.len() as u32);
        }
    }

    for a in m.attributes.iter() {
        let data = match a.domain {
            Domain::Point => a.data.gather(&vert_src),
            Domain::Edge if ne == 0 => a.data.clone(),
            Domain::Edge => {
                let known: Vec<usize> = edge_src.iter().map(|&e| e.min(ne - 1)).collect();
                let mut d = a.data.gather(&known);
                // Rim edges (per rim vertex) start at their defaults.
                let mut z = a.data.empty_like();
                z.extend_default(1);
                for (k, &e) in edge_src.iter().enumerate() {
                    if e == usize::MAX {
                        d.set(k, z.get(0));
                    }
                }
                d
            }
            Domain::Face => a.data.gather(&face_src),
            Domain::Corner => a.data.gather(&corner_src),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    if o.rim && o.crease.iter().any(|&c| c != 0.0) {
        let id = AttrId::named("crease_edge");
        let mut crease = match out.attributes.get(&id) {
            Some(a) if a.domain == Domain::Edge => a.data.as_float().into_owned(),
            _ => vec![0.0; out.edges.len()],
        };
        let [inner, outer, rim] = o.crease;
        let edge_base = ne * if o.shell { 2 } else { 1 } + new_edges;
        if rim != 0.0 {
            for c in &mut crease[edge_base..edge_base + rim_verts.len()] {
                *c = rim;
            }
        }
        for (i, &e) in rim_edges.iter().enumerate() {
            // Added without wrapping: capped at 1, not clamped below.
            if outer != 0.0 {
                crease[e] = (crease[e] + outer).min(1.0);
            }
            if inner != 0.0 {
                let k = ne + if o.shell { e } else { i };
                crease[k] = (crease[k] + inner).min(1.0);
            }
        }
        out.attributes.set(id, Domain::Edge, Array::Float(crease));
    }
    out
}
