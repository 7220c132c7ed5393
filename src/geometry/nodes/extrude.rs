//! Extrude Mesh (`node_geo_extrude_mesh.cc`): vertices, edges, face regions and individual
//! faces, with Blender's element order (new elements appended after the old ones, in
//! selection order), side-face winding taken from the neighbouring face, and attribute
//! propagation (new elements copy or average their sources; booleans combine with "or").

use std::collections::HashMap;

use super::super::attribute::{AttrId, Attributes};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::interpolate::combine;
use super::super::math::V3;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

/// Values for new elements: the average of each group of old ones (booleans: any).
fn mix_groups(data: &Array, groups: &[Vec<usize>]) -> Array {
    let pairs: Vec<(u32, u32)> = groups
        .iter()
        .enumerate()
        .flat_map(|(o, g)| g.iter().map(move |&s| (o as u32, s as u32)))
        .collect();
    combine(data, groups.len(), &pairs, false)
}

/// Appends `extra` elements on `domain` to every attribute there.
fn append(attrs: &mut Attributes, domain: Domain, f: &dyn Fn(&Array) -> Array) {
    for a in attrs.0.iter_mut().filter(|a| a.domain == domain) {
        let extra = f(&a.data);
        a.data.extend(&extra);
    }
}

fn edge_to_faces(m: &Mesh) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); m.edge_count()];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            out[m.corner_edges[c] as usize].push(f);
        }
    }
    out
}

/// `fill_quad_consistent_direction`: the side quad's corners, wound like the face it
/// extends (when there is exactly one).
#[allow(clippy::too_many_arguments)]
fn quad(
    other: Option<(&[u32], &[u32])>,
    v_conn_1: u32,
    v_conn_2: u32,
    v_across_1: u32,
    v_across_2: u32,
    e_conn_face: u32,
    e_connect_1: u32,
    e_across: u32,
    e_connect_2: u32,
) -> ([u32; 4], [u32; 4]) {
    let mut start_with_connecting = true;
    if let Some((verts, edges)) = other {
        if let Some(i) = edges.iter().position(|&e| e == e_conn_face) {
            start_with_connecting = verts[i] == v_conn_1;
        }
    }
    if start_with_connecting {
        (
            [v_conn_1, v_across_1, v_across_2, v_conn_2],
            [e_connect_1, e_across, e_connect_2, e_conn_face],
        )
    } else {
        (
            [v_conn_1, v_conn_2, v_across_2, v_across_1],
            [e_conn_face, e_connect_2, e_across, e_connect_1],
        )
    }
}

fn push_quads(m: &mut Mesh, quads: &[([u32; 4], [u32; 4])]) {
    for (v, e) in quads {
        m.corner_verts.extend_from_slice(v);
        m.corner_edges.extend_from_slice(e);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
}

/// Offsets per vertex: the single value, or the average over `groups` of element offsets.
fn vertex_offsets(offsets: &[V3], single: Option<V3>, nv: usize, pairs: &[(u32, u32)]) -> Vec<V3> {
    match single {
        Some(o) => vec![o; nv],
        None => combine(&Array::Vector(offsets.to_vec()), nv, pairs, false)
            .as_vector()
            .into_owned(),
    }
}

struct Outs {
    top: Option<(Domain, Vec<bool>)>,
    side: Option<(Domain, Vec<bool>)>,
}

fn extrude_vertices(m: &mut Mesh, sel: &[bool], offsets: &[V3]) -> Outs {
    let (nv, ne) = (m.vertex_count(), m.edge_count());
    let picked: Vec<usize> = (0..nv).filter(|&i| sel[i]).collect();
    if picked.is_empty() {
        return Outs {
            top: None,
            side: None,
        };
    }
    let mut v2e: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (e, ev) in m.edges.iter().enumerate() {
        v2e[ev[0] as usize].push(e);
        v2e[ev[1] as usize].push(e);
    }
    let groups: Vec<Vec<usize>> = picked.iter().map(|&v| v2e[v].clone()).collect();
    append(&mut m.attributes, Domain::Point, &|a| a.gather(&picked));
    append(&mut m.attributes, Domain::Edge, &|a| mix_groups(a, &groups));
    for (k, &v) in picked.iter().enumerate() {
        m.edges.push([v as u32, (nv + k) as u32]);
        let p = m.positions[v];
        let o = offsets[v];
        m.positions.push([p[0] + o[0], p[1] + o[1], p[2] + o[2]]);
    }
    let mut top = vec![false; m.vertex_count()];
    top[nv..].iter_mut().for_each(|x| *x = true);
    let mut side = vec![false; m.edge_count()];
    side[ne..].iter_mut().for_each(|x| *x = true);
    Outs {
        top: Some((Domain::Point, top)),
        side: Some((Domain::Edge, side)),
    }
}

fn extrude_edges(m: &mut Mesh, sel: &[bool], offsets: &[V3], single: Option<V3>) -> Outs {
    let (nv, ne, nf, nc) = (
        m.vertex_count(),
        m.edge_count(),
        m.face_count(),
        m.corner_count(),
    );
    let edges: Vec<usize> = (0..ne).filter(|&e| sel[e]).collect();
    if edges.is_empty() {
        return Outs {
            top: None,
            side: None,
        };
    }
    let mut pairs = Vec::new();
    let mut used = vec![false; nv];
    for &e in &edges {
        let ev = m.edges[e];
        pairs.push((ev[0], e as u32));
        pairs.push((ev[1], e as u32));
        used[ev[0] as usize] = true;
        used[ev[1] as usize] = true;
    }
    let vert_offsets = vertex_offsets(offsets, single, nv, &pairs);
    let new_verts: Vec<usize> = (0..nv).filter(|&v| used[v]).collect();
    let mut vert_to_new = vec![usize::MAX; nv];
    for (k, &v) in new_verts.iter().enumerate() {
        vert_to_new[v] = k;
    }
    let e2f = edge_to_faces(m);
    let connect_start = ne;
    let dup_start = ne + new_verts.len();
    let orig = m.clone();
    // Edges: connecting, then duplicates.
    let mut vert_sel_edges: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for &e in &edges {
        let ev = m.edges[e];
        vert_sel_edges[ev[0] as usize].push(e);
        vert_sel_edges[ev[1] as usize].push(e);
    }
    for (k, &v) in new_verts.iter().enumerate() {
        m.edges.push([v as u32, (nv + k) as u32]);
    }
    let mut dups = Vec::new();
    for &e in &edges {
        let ev = orig.edges[e];
        let d = [
            (nv + vert_to_new[ev[0] as usize]) as u32,
            (nv + vert_to_new[ev[1] as usize]) as u32,
        ];
        dups.push(d);
        m.edges.push(d);
    }
    let mut quads = Vec::new();
    for (i, &e) in edges.iter().enumerate() {
        let ev = orig.edges[e];
        let d = dups[i];
        let other = if e2f[e].len() == 1 {
            let r = orig.face(e2f[e][0]);
            Some((&orig.corner_verts[r.clone()], &orig.corner_edges[r]))
        } else {
            None
        };
        quads.push(quad(
            other,
            ev[0],
            ev[1],
            d[0],
            d[1],
            e as u32,
            (connect_start + (d[0] as usize - nv)) as u32,
            (dup_start + i) as u32,
            (connect_start + (d[1] as usize - nv)) as u32,
        ));
    }
    push_quads(m, &quads);
    // Attributes.
    append(&mut m.attributes, Domain::Point, &|a| a.gather(&new_verts));
    let connect_groups: Vec<Vec<usize>> = new_verts
        .iter()
        .map(|&v| vert_sel_edges[v].clone())
        .collect();
    append(&mut m.attributes, Domain::Edge, &|a| {
        let mut x = mix_groups(a, &connect_groups);
        x.extend(&a.gather(&edges));
        x
    });
    let face_groups: Vec<Vec<usize>> = edges.iter().map(|&e| e2f[e].clone()).collect();
    append(&mut m.attributes, Domain::Face, &|a| {
        mix_groups(a, &face_groups)
    });
    append(&mut m.attributes, Domain::Corner, &|a| {
        let mut out = Array::zeros(a.data_type(), edges.len() * 4);
        for (i, &e) in edges.iter().enumerate() {
            if e2f[e].is_empty() {
                continue;
            }
            let ev = orig.edges[e];
            let (mut g1, mut g2) = (Vec::new(), Vec::new());
            for &f in &e2f[e] {
                for c in orig.face(f) {
                    if orig.corner_verts[c] == ev[0] {
                        g1.push(c);
                    }
                    if orig.corner_verts[c] == ev[1] {
                        g2.push(c);
                    }
                }
            }
            let two = mix_groups(a, &[g1, g2]);
            let d = dups[i];
            for k in 0..4 {
                let v = quads[i].0[k];
                if v == d[0] || v == ev[0] {
                    out.set(4 * i + k, two.get(0));
                } else if v == d[1] || v == ev[1] {
                    out.set(4 * i + k, two.get(1));
                }
            }
        }
        out
    });
    for &v in &new_verts {
        let p = orig.positions[v];
        let o = vert_offsets[v];
        m.positions.push([p[0] + o[0], p[1] + o[1], p[2] + o[2]]);
    }
    let _ = (nf, nc);
    let mut top = vec![false; m.edge_count()];
    top[dup_start..].iter_mut().for_each(|x| *x = true);
    let mut side = vec![false; m.face_count()];
    side[nf..].iter_mut().for_each(|x| *x = true);
    Outs {
        top: Some((Domain::Edge, top)),
        side: Some((Domain::Face, side)),
    }
}

// Long because it follows Blender's face-region extrusion step by step.
fn extrude_face_regions(m: &mut Mesh, sel: &[bool], offsets: &[V3], single: Option<V3>) -> Outs {
    let (nv, ne, nf) = (m.vertex_count(), m.edge_count(), m.face_count());
    if !sel.iter().any(|x| *x) {
        return Outs {
            top: None,
            side: None,
        };
    }
    let orig = m.clone();
    let mut pairs = Vec::new();
    let mut all_selected_verts = vec![false; nv];
    for f in 0..nf {
        if sel[f] {
            for c in orig.face(f) {
                pairs.push((orig.corner_verts[c], f as u32));
                all_selected_verts[orig.corner_verts[c] as usize] = true;
            }
        }
    }
    let vert_offsets = vertex_offsets(offsets, single, nv, &pairs);
    let e2f = edge_to_faces(&orig);
    let mut new_inner: Vec<usize> = Vec::new();
    let mut inner: Vec<usize> = Vec::new();
    let mut boundary: Vec<usize> = Vec::new();
    let mut boundary_face: Vec<usize> = Vec::new();
    for e in 0..ne {
        let (mut selected, mut deselected, mut last) = (0, 0, 0);
        for &f in &e2f[e] {
            if sel[f] {
                selected += 1;
                last = f;
            } else {
                deselected += 1;
            }
        }
        if selected == 1 {
            boundary.push(e);
            boundary_face.push(last);
        } else if selected > 1 {
            if deselected > 0 {
                new_inner.push(e);
            } else {
                inner.push(e);
            }
        }
    }
    // Insertion-ordered set of duplicated vertices.
    let mut new_verts: Vec<usize> = Vec::new();
    let mut index_of: HashMap<usize, usize> = HashMap::new();
    let mut add = |v: usize, new_verts: &mut Vec<usize>| {
        if let std::collections::hash_map::Entry::Vacant(slot) = index_of.entry(v) {
            slot.insert(new_verts.len());
            new_verts.push(v);
        }
    };
    for &e in &boundary {
        add(orig.edges[e][0] as usize, &mut new_verts);
        add(orig.edges[e][1] as usize, &mut new_verts);
    }
    let extruded = new_verts.len();
    for &e in &new_inner {
        add(orig.edges[e][0] as usize, &mut new_verts);
        add(orig.edges[e][1] as usize, &mut new_verts);
    }
    let idx = |v: u32| -> Option<usize> { new_verts.iter().position(|&x| x == v as usize) };
    let connect_start = ne;
    let boundary_start = ne + extruded;
    let inner_start = boundary_start + boundary.len();
    for i in 0..extruded {
        m.edges.push([new_verts[i] as u32, (nv + i) as u32]);
    }
    let mut boundary_edges = Vec::new();
    for &e in &boundary {
        let ev = orig.edges[e];
        let d = [
            (nv + idx(ev[0]).unwrap()) as u32,
            (nv + idx(ev[1]).unwrap()) as u32,
        ];
        boundary_edges.push(d);
        m.edges.push(d);
    }
    for &e in &new_inner {
        let ev = orig.edges[e];
        m.edges.push([
            (nv + idx(ev[0]).unwrap()) as u32,
            (nv + idx(ev[1]).unwrap()) as u32,
        ]);
    }
    for &e in &inner {
        for k in 0..2 {
            if let Some(i) = idx(m.edges[e][k]) {
                m.edges[e][k] = (nv + i) as u32;
            }
        }
    }
    for f in 0..nf {
        if !sel[f] {
            continue;
        }
        for c in orig.face(f) {
            if let Some(i) = idx(m.corner_verts[c]) {
                m.corner_verts[c] = (nv + i) as u32;
            }
            let ce = m.corner_edges[c] as usize;
            if let Some(i) = boundary.iter().position(|&b| b == ce) {
                m.corner_edges[c] = (boundary_start + i) as u32;
                continue;
            }
            if let Some(i) = new_inner.iter().position(|&b| b == ce) {
                m.corner_edges[c] = (inner_start + i) as u32;
            }
        }
    }
    let mut quads = Vec::new();
    for (i, &e) in boundary.iter().enumerate() {
        let d = boundary_edges[i];
        let r = m.face(boundary_face[i]);
        let ex1 = d[0] as usize - nv;
        let ex2 = d[1] as usize - nv;
        quads.push(quad(
            Some((&m.corner_verts[r.clone()], &m.corner_edges[r])),
            d[0],
            d[1],
            new_verts[ex1] as u32,
            new_verts[ex2] as u32,
            (boundary_start + i) as u32,
            (connect_start + ex1) as u32,
            e as u32,
            (connect_start + ex2) as u32,
        ));
    }
    let edited = m.clone();
    push_quads(m, &quads);
    // Attributes.
    append(&mut m.attributes, Domain::Point, &|a| a.gather(&new_verts));
    append(&mut m.attributes, Domain::Face, &|a| {
        a.gather(&boundary_face)
    });
    let mut v2b: Vec<Vec<usize>> = vec![Vec::new(); nv + new_verts.len()];
    for i in 0..boundary.len() {
        // Blender maps over the boundary edges of the mesh being edited.
        let ev = edited.edges[boundary[i]];
        v2b[ev[0] as usize].push(boundary[i]);
        v2b[ev[1] as usize].push(boundary[i]);
    }
    let connect_groups: Vec<Vec<usize>> = new_verts.iter().map(|&v| v2b[v].clone()).collect();
    append(&mut m.attributes, Domain::Edge, &|a| {
        let mut x = mix_groups(a, &connect_groups);
        x.extend(&a.gather(&boundary));
        x.extend(&a.gather(&new_inner));
        x
    });
    let mut orig_corners = vec![0usize; boundary.len() * 4];
    for i in 0..boundary.len() {
        let d = boundary_edges[i];
        let (o1, o2) = (
            new_verts[d[0] as usize - nv] as u32,
            new_verts[d[1] as usize - nv] as u32,
        );
        let (mut c1, mut c2) = (0, 0);
        for c in edited.face(boundary_face[i]) {
            if edited.corner_verts[c] == d[0] {
                c1 = c;
            }
            if edited.corner_verts[c] == d[1] {
                c2 = c;
            }
        }
        for k in 0..4 {
            let v = quads[i].0[k];
            if v == d[0] || v == o1 {
                orig_corners[4 * i + k] = c1;
            } else if v == d[1] || v == o2 {
                orig_corners[4 * i + k] = c2;
            }
        }
    }
    append(&mut m.attributes, Domain::Corner, &|a| {
        a.gather(&orig_corners)
    });
    for &v in &new_verts {
        m.positions.push(orig.positions[v]);
    }
    for v in 0..nv {
        if !all_selected_verts[v] {
            continue;
        }
        let o = vert_offsets[v];
        let t = match idx(v as u32) {
            Some(i) => nv + i,
            None => v,
        };
        let p = m.positions[t];
        m.positions[t] = [p[0] + o[0], p[1] + o[1], p[2] + o[2]];
    }
    let mut top = sel.to_vec();
    top.resize(m.face_count(), false);
    let mut side = vec![false; m.face_count()];
    side[nf..].iter_mut().for_each(|x| *x = true);
    Outs {
        top: Some((Domain::Face, top)),
        side: Some((Domain::Face, side)),
    }
}

fn extrude_individual_faces(m: &mut Mesh, sel: &[bool], offsets: &[V3]) -> Outs {
    let (nv, ne, nf, nc) = (
        m.vertex_count(),
        m.edge_count(),
        m.face_count(),
        m.corner_count(),
    );
    let faces: Vec<usize> = (0..nf).filter(|&f| sel[f]).collect();
    if faces.is_empty() {
        return Outs {
            top: None,
            side: None,
        };
    }
    let total: usize = faces.iter().map(|&f| m.face_size(f)).sum();
    let orig = m.clone();
    let mut new_vert_src = vec![0usize; total];
    let mut dup_edge_src = vec![0usize; total];
    let mut connect = vec![[0u32; 2]; total];
    let mut dup = vec![[0u32; 2]; total];
    let mut side_v = vec![[0u32; 4]; total];
    let mut side_e = vec![[0u32; 4]; total];
    let mut side_face_src = vec![0usize; total];
    let mut orig_corners = vec![0usize; total * 4];
    let mut start = 0;
    for &f in &faces {
        let r = orig.face(f);
        let n = r.len();
        for i in 0..n {
            let c = r.start + i;
            new_vert_src[start + i] = orig.corner_verts[c] as usize;
            dup_edge_src[start + i] = orig.corner_edges[c] as usize;
            m.corner_verts[c] = (nv + start + i) as u32;
            m.corner_edges[c] = (ne + total + start + i) as u32;
        }
        for i in 0..n {
            let nx = if i == n - 1 { 0 } else { i + 1 };
            let (ie, ien) = (start + i, start + nx);
            let new_vert = (nv + ie) as u32;
            let new_next = (nv + ien) as u32;
            dup[ie] = [new_vert, new_next];
            side_v[ie] = [
                new_next,
                new_vert,
                new_vert_src[ie] as u32,
                new_vert_src[ien] as u32,
            ];
            side_e[ie] = [
                (ne + total + ie) as u32,
                (ne + ie) as u32,
                dup_edge_src[ie] as u32,
                (ne + ien) as u32,
            ];
            connect[ie] = [new_vert_src[ie] as u32, new_vert];
            side_face_src[ie] = f;
            let c = r.start + i;
            let cn = r.start + nx;
            orig_corners[ie * 4..ie * 4 + 4].copy_from_slice(&[cn, c, c, cn]);
        }
        start += n;
    }
    m.edges.extend_from_slice(&connect);
    m.edges.extend_from_slice(&dup);
    let quads: Vec<([u32; 4], [u32; 4])> =
        side_v.iter().zip(&side_e).map(|(v, e)| (*v, *e)).collect();
    push_quads(m, &quads);
    append(&mut m.attributes, Domain::Point, &|a| {
        a.gather(&new_vert_src)
    });
    // Connecting edges mix the face's two edges at the vertex.
    let mut neighbors = vec![Vec::new(); total];
    let mut s = 0;
    for &f in &faces {
        let n = orig.face_size(f);
        for i in 0..n {
            let p = if i == 0 { n - 1 } else { i - 1 };
            neighbors[s + i] = vec![dup_edge_src[s + i], dup_edge_src[s + p]];
        }
        s += n;
    }
    append(&mut m.attributes, Domain::Edge, &|a| {
        let mut x = mix_groups(a, &neighbors);
        x.extend(&a.gather(&dup_edge_src));
        x
    });
    append(&mut m.attributes, Domain::Face, &|a| {
        a.gather(&side_face_src)
    });
    append(&mut m.attributes, Domain::Corner, &|a| {
        a.gather(&orig_corners)
    });
    let mut s = 0;
    for &f in &faces {
        let n = orig.face_size(f);
        for i in 0..n {
            let p = orig.positions[new_vert_src[s + i]];
            let o = offsets[f];
            m.positions.push([p[0] + o[0], p[1] + o[1], p[2] + o[2]]);
        }
        s += n;
    }
    let _ = nc;
    let mut top = sel.to_vec();
    top.resize(m.face_count(), false);
    let mut side = vec![false; m.face_count()];
    side[nf..].iter_mut().for_each(|x| *x = true);
    Outs {
        top: Some((Domain::Face, top)),
        side: Some((Domain::Face, side)),
    }
}

pub fn extrude_mesh(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let mode = ctx.prop_str("mode")?.to_string();
    let sel = ctx.field("Selection", DataType::Bool)?;
    let offset = ctx.field("Offset", DataType::Vector)?;
    let scale = ctx.field("Offset Scale", DataType::Float)?;
    let individual = if ctx.has_input("Individual") {
        ctx.bool("Individual")?
    } else {
        false
    };
    // Offset x scale as one field, so constants stay constants.
    let off = Field::op1(
        "Offset x Scale",
        vec![offset, scale],
        DataType::Vector,
        |n, x| {
            let (o, s) = (x[0].as_vector(), x[1].as_float());
            Ok(Array::Vector(
                (0..n)
                    .map(|i| [o[i][0] * s[i], o[i][1] * s[i], o[i][2] * s[i]])
                    .collect(),
            ))
        },
    )
    .map_err(|e| ctx.err(e))?;
    let single = off.as_constant().map(|v| v.as_vector());
    let top_id = ctx.output_used("Top").then(|| AttrId::anonymous("Top"));
    let side_id = ctx.output_used("Side").then(|| AttrId::anonymous("Side"));
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let domain = match mode.as_str() {
            "VERTICES" => Domain::Point,
            "EDGES" => Domain::Edge,
            "FACES" => Domain::Face,
            other => return Err(format!("mode {other} is not supported")),
        };
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            domain,
            &[(&sel, DataType::Bool), (&off, DataType::Vector)],
        )?;
        let (sv, ov) = (r[0].as_bool().into_owned(), r[1].as_vector().into_owned());
        // Our reference would make `mesh_mut` deep-copy the mesh.
        drop(m);
        let mm = s.mesh_mut().unwrap();
        let outs = match domain {
            Domain::Point => extrude_vertices(mm, &sv, &ov),
            Domain::Edge => extrude_edges(mm, &sv, &ov, single),
            _ if individual => extrude_individual_faces(mm, &sv, &ov),
            _ => extrude_face_regions(mm, &sv, &ov, single),
        };
        mm.custom_vert_normals = None;
        for (id, v) in [(&top_id, outs.top), (&side_id, outs.side)] {
            if let (Some(id), Some((d, vals))) = (id, v) {
                mm.attributes.set(id.clone(), d, Array::Bool(vals));
            }
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    let mut o = outputs([("Mesh", SocketValue::Geometry(g))]);
    for (name, id) in [("Top", top_id), ("Side", side_id)] {
        if let Some(id) = id {
            o.insert(
                name.into(),
                SocketValue::Field(Field::input(AttributeInput {
                    id,
                    ty: DataType::Bool,
                })),
            );
        }
    }
    Ok(o)
}
