//! The Wireframe modifier (`MOD_wireframe.cc`, `BM_mesh_wireframe`): every face corner
//! gets a vertex inset towards the face's inside, every vertex used by a face two copies
//! offset along its normal, and each face edge becomes two quads (and two more along
//! boundary edges, from a vertex inset along the boundary, with Boundary on); with Replace
//! the original mesh goes.
//!
//! Element order follows BMesh: the offset pairs vertex by vertex, then the corner (and
//! boundary) vertices face by face, then the quads face by face and edge by edge, their
//! edges made as each quad needs them; the original elements before all of them, or
//! gone. Relative thickness and vertex groups are not evaluated (`unsupported`).

use std::collections::HashMap;

use super::super::attribute::AttrId;
use super::super::math::{add, cross, dot, length, scale, sub, V3};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::{flag, float, int, text, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let mut out = Vec::new();
    if flag(p, "use_relative_offset") {
        out.push("Offset Relative (use_relative_offset)".to_string());
    }
    let group = text(p, "vertex_group").unwrap_or("");
    if !group.is_empty() {
        out.push(format!(
            "Vertex Group {group:?} (vertex groups are not exported)"
        ));
    }
    (!out.is_empty()).then(|| out.join(", "))
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let o = Options {
        offset: float(p, "thickness")?,
        offset_fac: float(p, "offset")?,
        replace: flag(p, "use_replace"),
        boundary: flag(p, "use_boundary"),
        even: flag(p, "use_even_offset"),
        crease: flag(p, "use_crease")
            .then(|| float(p, "crease_weight"))
            .transpose()?,
        mat_offset: int(p, "material_offset")? as i32,
    };
    *g.mesh_mut().unwrap() = wireframe(&m, &o);
    Ok(g)
}

struct Options {
    offset: f32,
    offset_fac: f32,
    replace: bool,
    boundary: bool,
    even: bool,
    crease: Option<f32>,
    mat_offset: i32,
}

/// `normalize_v3` (zero stays zero).
fn norm(v: V3) -> V3 {
    let d = dot(v, v);
    if d > 1e-35 {
        scale(v, 1.0 / d.sqrt())
    } else {
        [0.0; 3]
    }
}

/// `angle_normalized_v3v3`.
fn angle_normalized(a: V3, b: V3) -> f32 {
    if dot(a, b) >= 0.0 {
        2.0 * (length(sub(b, a)) / 2.0).clamp(-1.0, 1.0).asin()
    } else {
        std::f32::consts::PI - 2.0 * (length(add(a, b)) / 2.0).clamp(-1.0, 1.0).asin()
    }
}

/// `shell_angle_to_dist`.
fn shell(angle: f32) -> f32 {
    if angle < 1.0e-8 {
        1.0
    } else {
        (1.0 / angle.cos()).abs()
    }
}

// Long because it follows BM_mesh_wireframe step by step: the element order Blender's
// mesh has comes from the order of those steps.
fn wireframe(m: &Mesh, o: &Options) -> Mesh {
    let ofs_orig = -(((-o.offset_fac + 1.0) * 0.5) * o.offset);
    let ofs_new = o.offset + ofs_orig;
    let ofs_mid = (ofs_orig + ofs_new) / 2.0;
    let inset = o.offset / 2.0;
    let nv = m.vertex_count();
    let fno = m.face_normals();
    let vno = m.vertex_normals();
    let co = &m.positions;
    let mut face_count = vec![0u32; m.edge_count()];
    let mut used = vec![false; nv];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            face_count[m.corner_edges[c] as usize] += 1;
            used[m.corner_verts[c] as usize] = true;
        }
    }
    let is_boundary = |e: usize| face_count[e] == 1;
    // Each boundary edge's corner, and each vertex's boundary edges in disk (edge) order.
    let mut edge_corner = vec![(0usize, 0usize); m.edge_count()];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            edge_corner[m.corner_edges[c] as usize] = (f, c);
        }
    }
    let mut vert_boundary: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (e, [a, b]) in m.edges.iter().enumerate() {
        if is_boundary(e) {
            vert_boundary[*a as usize].push(e);
            vert_boundary[*b as usize].push(e);
        }
    }
    // New vertices: position and the input vertex they copy.
    let mut pos: Vec<V3> = Vec::new();
    let mut vsrc: Vec<usize> = Vec::new();
    let base = if o.replace { 0 } else { nv };
    let new_vert = |p: V3, src: usize, pos: &mut Vec<V3>, vsrc: &mut Vec<usize>| {
        pos.push(p);
        vsrc.push(src);
        (base + pos.len() - 1) as u32
    };
    let mut neg = vec![u32::MAX; nv];
    let mut posv = vec![u32::MAX; nv];
    for v in 0..nv {
        if !used[v] {
            continue;
        }
        let t = add(co[v], scale(vno[v], ofs_mid));
        neg[v] = new_vert(
            add(t, scale(vno[v], ofs_orig - ofs_mid)),
            v,
            &mut pos,
            &mut vsrc,
        );
        posv[v] = new_vert(
            add(t, scale(vno[v], ofs_new - ofs_mid)),
            v,
            &mut pos,
            &mut vsrc,
        );
    }
    let mut corner_vert = vec![u32::MAX; m.corner_count()];
    let mut bound = vec![u32::MAX; nv];
    for f in 0..m.face_count() {
        let r = m.face(f);
        for c in r.clone() {
            let v = m.corner_verts[c] as usize;
            let prev = m.corner_verts[m.prev_corner(f, c)] as usize;
            let next_c = m.next_corner(f, c);
            let next = m.corner_verts[next_c] as usize;
            // `BM_loop_calc_face_tangent`.
            let vp = norm(sub(co[prev], co[v]));
            let vn = norm(sub(co[v], co[next]));
            let dir = add(vp, vn);
            let same = (0..3).all(|k| (vp[k] - vn[k]).abs() <= f32::EPSILON * 10.0);
            let tangent = if !same {
                let mut nor = cross(vp, vn);
                if dot(nor, fno[f]) < 0.0 {
                    nor = scale(nor, -1.0);
                }
                norm(cross(dir, nor))
            } else {
                norm(cross(dir, fno[f]))
            };
            let mut fac_shell = 1.0;
            if o.even {
                // `BM_loop_calc_face_angle`.
                let a = norm(sub(co[v], co[prev]));
                let b = norm(sub(co[v], co[next]));
                fac_shell *= shell((std::f32::consts::PI - angle_normalized(a, b)) * 0.5);
            }
            let mut t = add(co[v], scale(tangent, inset * fac_shell));
            if o.offset != 0.0 {
                t = add(t, scale(vno[v], ofs_mid));
            }
            corner_vert[c] = new_vert(t, v, &mut pos, &mut vsrc);
            if o.boundary && is_boundary(m.corner_edges[c] as usize) {
                for vb in [v, next] {
                    if bound[vb] != u32::MAX {
                        continue;
                    }
                    let (no, no_face, others) =
                        boundary_tangent(m, vb, &fno, &vert_boundary[vb], &edge_corner);
                    let mut fac_shell = 1.0;
                    if o.even {
                        if let Some((va, vc)) = others {
                            fac_shell *= shell(
                                (std::f32::consts::PI
                                    - angle_on_axis(co[va], co[vb], co[vc], no_face))
                                    * 0.5,
                            );
                        }
                    }
                    let mut t = add(co[vb], scale(no, inset * fac_shell));
                    if o.offset != 0.0 {
                        t = add(t, scale(vno[vb], ofs_mid));
                    }
                    bound[vb] = new_vert(t, vb, &mut pos, &mut vsrc);
                }
            }
        }
    }
    // Faces: four corners, the input face and the input corner each corner copies.
    let mut faces: Vec<([u32; 4], usize, [usize; 4])> = Vec::new();
    for f in 0..m.face_count() {
        for c in m.face(f) {
            let cn = m.next_corner(f, c);
            let (v1, v2) = (m.corner_verts[c] as usize, m.corner_verts[cn] as usize);
            let (l1, l2) = (corner_vert[c], corner_vert[cn]);
            faces.push(([l1, l2, neg[v2], neg[v1]], f, [c, cn, cn, c]));
            faces.push(([l2, l1, posv[v1], posv[v2]], f, [cn, c, c, cn]));
            if o.boundary && is_boundary(m.corner_edges[c] as usize) {
                let (b1, b2) = (bound[v1], bound[v2]);
                faces.push(([b2, b1, neg[v1], neg[v2]], f, [cn, c, c, cn]));
                faces.push(([b1, b2, posv[v2], posv[v1]], f, [c, cn, cn, c]));
            }
        }
    }
    let mut out = if o.replace {
        let mut e = Mesh::new();
        e.materials = m.materials.clone();
        e
    } else {
        m.clone()
    };
    let (nv0, ne0, nc0, nf0) = (
        out.vertex_count(),
        out.edge_count(),
        out.corner_count(),
        out.face_count(),
    );
    out.positions.extend(pos);
    let mut edge_of: HashMap<(u32, u32), u32> = HashMap::new();
    let mut new_edges = Vec::new();
    for (q, _, _) in &faces {
        let mut ids = [0u32; 4];
        for k in 0..4 {
            let prev = (k + 3) % 4;
            let (a, b) = (q[prev], q[k]);
            let key = (a.min(b), a.max(b));
            ids[prev] = *edge_of.entry(key).or_insert_with(|| {
                new_edges.push([a, b]);
                (ne0 + new_edges.len() - 1) as u32
            });
        }
        out.corner_verts.extend(q);
        out.corner_edges.extend(ids);
        out.face_offsets.push(out.corner_verts.len() as u32);
    }
    out.edges.extend(new_edges);
    let ne = out.edge_count();
    // Attributes: originals kept (or not), new elements copied from their sources.
    let mat_max = (m.materials.len() as i32 - 1).max(0);
    let mut attrs = Vec::new();
    for a in m.attributes.iter() {
        let (keep, add): (usize, Array) = match a.domain {
            Domain::Point => (nv0, a.data.gather(&vsrc)),
            Domain::Edge => {
                let mut d = a.data.empty_like();
                d.extend_default(ne - ne0);
                (ne0, d)
            }
            Domain::Face => {
                let idx: Vec<usize> = faces.iter().map(|x| x.1).collect();
                let mut d = a.data.gather(&idx);
                if a.id.name() == Some("material_index") && o.mat_offset != 0 {
                    if let Array::Int(v) = &mut d {
                        for x in v.iter_mut() {
                            *x = (*x + o.mat_offset).clamp(0, mat_max);
                        }
                    }
                }
                (nf0, d)
            }
            Domain::Corner => {
                let idx: Vec<usize> = faces.iter().flat_map(|x| x.2).collect();
                (nc0, a.data.gather(&idx))
            }
            _ => continue,
        };
        let mut data = if keep > 0 {
            a.data.clone()
        } else {
            a.data.empty_like()
        };
        data.extend(&add);
        attrs.push((a.id.clone(), a.domain, data));
    }
    out.attributes = Default::default();
    for (id, d, data) in attrs {
        out.attributes.set(id, d, data);
    }
    if o.mat_offset != 0 && out.attributes.named("material_index").is_none() {
        let mut v = vec![0i32; nf0];
        v.extend(std::iter::repeat_n(
            o.mat_offset.clamp(0, mat_max),
            faces.len(),
        ));
        out.attributes
            .set(AttrId::named("material_index"), Domain::Face, Array::Int(v));
    }
    if let Some(w) = o.crease {
        let id = AttrId::named("crease_edge");
        let mut v = match out.attributes.named("crease_edge") {
            Some(a) => a.data.as_float().into_owned(),
            None => vec![0.0; ne],
        };
        let mut set = |a: u32, b: u32| {
            if let Some(&e) = edge_of.get(&(a.min(b), a.max(b))) {
                v[e as usize] = w;
            }
        };
        for f in 0..m.face_count() {
            for c in m.face(f) {
                let cn = m.next_corner(f, c);
                let (v1, v2) = (m.corner_verts[c] as usize, m.corner_verts[cn] as usize);
                if o.boundary && is_boundary(m.corner_edges[c] as usize) {
                    set(posv[v1], bound[v1]);
                    set(posv[v2], bound[v2]);
                    set(neg[v1], bound[v1]);
                    set(neg[v2], bound[v2]);
                }
                set(posv[v1], corner_vert[c]);
                set(posv[v2], corner_vert[cn]);
                set(neg[v1], corner_vert[c]);
                set(neg[v2], corner_vert[cn]);
            }
        }
        out.attributes.set(id, Domain::Edge, Array::Float(v));
    }
    out.custom_vert_normals = None;
    out
}

/// `bm_vert_boundary_tangent`: the direction to inset a boundary vertex along (and the
/// face normal it lies in, and its two boundary neighbours when it has two).
fn boundary_tangent(
    m: &Mesh,
    v: usize,
    fno: &[V3],
    edges: &[usize],
    edge_corner: &[(usize, usize)],
) -> (V3, V3, Option<(usize, usize)>) {
    let co = &m.positions;
    let corner_of = |e: usize| edge_corner[e];
    let other = |e: usize| {
        let [a, b] = m.edges[e];
        if a as usize == v {
            b as usize
        } else {
            a as usize
        }
    };
    // `BM_edge_calc_face_tangent`: the edge in its loop's direction, across the face.
    let edge_tangent = |f: usize, c: usize| {
        let a = co[m.corner_verts[c] as usize];
        let b = co[m.corner_verts[m.next_corner(f, c)] as usize];
        norm(cross(sub(a, b), fno[f]))
    };
    let (no_face, no_edge, check, others) = if edges.len() >= 2 {
        let (fa, ca) = corner_of(edges[0]);
        let (fb, cb) = corner_of(edges[1]);
        let no_face = norm(add(fno[fa], fno[fb]));
        let (va, vb) = (other(edges[0]), other(edges[1]));
        let ta = norm(sub(co[v], co[va]));
        let tb = norm(sub(co[vb], co[v]));
        let check = add(edge_tangent(fa, ca), edge_tangent(fb, cb));
        (no_face, add(ta, tb), check, Some((va, vb)))
    } else {
        let (fa, ca) = corner_of(edges[0]);
        let va = other(edges[0]);
        (fno[fa], sub(co[v], co[va]), edge_tangent(fa, ca), None)
    };
    let mut no = norm(cross(no_edge, no_face));
    if dot(no, check) > 0.0 {
        no = scale(no, -1.0);
    }
    (no, no_face, others)
}

/// `angle_on_axis_v3v3v3_v3`: the angle at `b` between `a` and `c` seen along `axis`.
fn angle_on_axis(a: V3, b: V3, c: V3, axis: V3) -> f32 {
    let project = |p: V3| {
        let mul = dot(p, axis) / dot(axis, axis);
        sub(p, scale(axis, mul))
    };
    let p1 = project(sub(a, b));
    let p2 = project(sub(c, b));
    angle_normalized(norm(p1), norm(p2))
}
