//! The Screw modifier (`MOD_screw.cc`): every edge of the mesh is swept about an axis (X,
//! Y, Z or an axis object's) through the angle in render steps, moving along the axis by
//! the screw offset (or the axis object's offset along it), repeated for the iterations.
//! A full turn without offset closes on the first ring. Element order is Blender's: the
//! input's vertices then one ring of copies per step, the input's edges (turned to run
//! along their faces, and with Calculate Order along each profile so faces face out),
//! the edges between rings, then per input edge its copies ring by ring; one quad per
//! input edge and step. Faces keep the data of the face their edge came from (else the
//! modifier's flat / smooth shading and material 0), corners their input corners' with
//! UVs moved along U per step (else UVs Blender makes: U along the turn, V the distance
//! from the axis plane, either stretched to 0..1). Merge joins the rings' vertices on the
//! axis into the first ring's, with Blender's vertex merge keeping the first ring's data
//! (`weld::merge_keeping_targets`).
//!
//! Edge attributes start at their defaults, as in Blender (it copies no edge data).

use super::super::math::{
    axis_angle_normalized_to_mat3, dot, mat3_to_mat4, mat4_invert, mat4_mul, normalize_v3,
    transform_point, Mat4f, V3,
};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::weld;
use super::{flag, float, id_name, int, text, Context, Props};

/// Every setting of the Screw modifier is evaluated; an unknown axis is named.
pub fn unsupported(p: &Props) -> Option<String> {
    match text(p, "axis") {
        Ok("X" | "Y" | "Z") => None,
        other => Some(format!("axis {:?}", other.ok())),
    }
}

/// Blender's own limit is memory; this keeps a bad override from exhausting it.
const MAX_ELEMENTS: u64 = 1 << 26;

const UNUSED: u32 = u32::MAX;
const INVALID: u32 = u32::MAX - 1;

fn valid(v: u32) -> bool {
    v < INVALID
}

pub fn apply(p: &Props, ctx: &Context, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    if m.vertex_count() == 0 {
        return Ok(g);
    }
    let axis = match text(p, "axis")? {
        "X" => 0,
        "Y" => 1,
        "Z" => 2,
        other => return Err(format!("axis {other:?} is not X, Y or Z")),
    };
    let steps = int(p, "render_steps")?;
    let iter = int(p, "iterations")?;
    if !(1..=10_000).contains(&steps) || !(1..=10_000).contains(&iter) {
        return Err(format!(
            "render_steps {steps} and iterations {iter} must be within 1..10000"
        ));
    }
    let s = Settings {
        axis,
        angle: float(p, "angle")?,
        screw_ofs: float(p, "screw_offset")?,
        iter: iter as u32,
        steps: steps as u32,
        merge: flag(p, "use_merge_vertices")
            .then(|| float(p, "merge_threshold"))
            .transpose()?,
        flip: flag(p, "use_normal_flip"),
        calc_order: flag(p, "use_normal_calculate"),
        smooth: flag(p, "use_smooth_shade"),
        stretch: [flag(p, "use_stretch_u"), flag(p, "use_stretch_v")],
        axis_object: None,
    };
    let s = Settings {
        axis_object: match id_name(p, "object") {
            Some(name) => {
                let ow = (ctx.world)(&name)
                    .ok_or_else(|| format!("axis object {name:?} is not in the export"))?;
                let inv = (ctx.world)(ctx.object)
                    .and_then(|w| mat4_invert(&w))
                    .ok_or("the object's transform is singular")?;
                Some((mat4_mul(&inv, &ow), flag(p, "use_object_screw_offset")))
            }
            None => None,
        },
        ..s
    };
    *g.mesh_mut().unwrap() = screw(&m, &s)?;
    Ok(g)
}

struct Settings {
    axis: usize,
    angle: f32,
    screw_ofs: f32,
    iter: u32,
    steps: u32,
    merge: Option<f32>,
    flip: bool,
    calc_order: bool,
    smooth: bool,
    /// Stretch U, Stretch V.
    stretch: [bool; 2],
    /// The axis object's transform relative to the object, and Object Screw.
    axis_object: Option<(Mat4f, bool)>,
}

/// `axis_angle_to_mat3_single` as a 4x4 (column-major, as `Mat4f`).
fn rotation_about(axis: usize, angle: f32) -> Mat4f {
    let (s, c) = (angle.sin(), angle.cos());
    let mut m = [[0.0f32; 4]; 4];
    m[3][3] = 1.0;
    match axis {
        0 => {
            m[0] = [1.0, 0.0, 0.0, 0.0];
            m[1] = [0.0, c, s, 0.0];
            m[2] = [0.0, -s, c, 0.0];
        }
        1 => {
            m[0] = [c, 0.0, -s, 0.0];
            m[1] = [0.0, 1.0, 0.0, 0.0];
            m[2] = [s, 0.0, c, 0.0];
        }
        _ => {
            m[0] = [c, s, 0.0, 0.0];
            m[1] = [-s, c, 0.0, 0.0];
            m[2] = [0.0, 0.0, 1.0, 0.0];
        }
    }
    m
}

/// One vertex of the profile graph (`ScrewVertConnect`).
#[derive(Clone, Copy)]
struct Connect {
    dist_sq: f32,
    co: V3,
    v: [u32; 2],
    e: [Option<usize>; 2],
    flag: u8,
}

/// `ScrewVertIter`: a walk along the profile from a vertex.
struct Walk {
    v: u32,
    other: u32,
    at: Option<usize>,
    e: Option<usize>,
}

impl Walk {
    fn new(vc: &[Connect], start: u32, dir: usize) -> Walk {
        if valid(start) {
            let c = &vc[start as usize];
            Walk {
                v: start,
                other: c.v[dir],
                at: Some(start as usize),
                e: c.e[1 - dir],
            }
        } else {
            Walk {
                v: start,
                other: UNUSED,
                at: None,
                e: None,
            }
        }
    }

    fn step(&mut self, vc: &[Connect]) {
        let c = &vc[self.at.expect("walk past its end")];
        if c.v[0] == self.other {
            self.other = self.v;
            self.v = c.v[1];
        } else if c.v[1] == self.other {
            self.other = self.v;
            self.v = c.v[0];
        }
        if valid(self.v) {
            let c = &vc[self.v as usize];
            self.at = Some(self.v as usize);
            self.e = c.e[(c.e[0] == self.e) as usize];
        } else {
            self.at = None;
            self.e = None;
        }
    }
}

/// Calculate Order: turns the edges of each profile so the faces swept from them face
/// away from the axis (Blender's walk from the vertex farthest from the axis).
fn order_edges(
    m: &Mesh,
    edges: &mut [[u32; 2]],
    axis: usize,
    to_axis: Option<&Mat4f>,
    negative: bool,
) {
    let nv = m.vertex_count();
    let (o1, o2) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let mut vc: Vec<Connect> = m
        .positions
        .iter()
        .map(|&p| {
            let co = to_axis.map_or(p, |t| transform_point(t, p));
            Connect {
                dist_sq: co[o1] * co[o1] + co[o2] * co[o2],
                co,
                v: [UNUSED; 2],
                e: [None; 2],
                flag: 0,
            }
        })
        .collect();
    for (i, e) in edges.iter().enumerate() {
        for (a, b) in [(e[0], e[1]), (e[1], e[0])] {
            let c = &mut vc[a as usize];
            if c.v[0] == UNUSED {
                c.v[0] = b;
                c.e[0] = Some(i);
            } else if c.v[1] == UNUSED {
                c.v[1] = b;
                c.e[1] = Some(i);
            } else {
                // A vertex of three edges: not part of a profile.
                c.v = [INVALID; 2];
            }
        }
    }
    for i in 0..nv {
        if vc[i].flag != 0 {
            continue;
        }
        let mut linked = 0;
        let mut best = UNUSED;
        let mut closed = 0;
        let mut fl = -1.0f32;
        for j in 0..2 {
            let mut w = Walk::new(&vc, i as u32, j);
            if j == 1 {
                w.step(&vc);
            }
            while let Some(at) = w.at {
                if vc[at].flag != 0 {
                    closed = 1;
                    break;
                }
                vc[at].flag = 1;
                linked += 1;
                if fl <= vc[at].dist_sq {
                    fl = vc[at].dist_sq;
                    best = w.v;
                }
                w.step(&vc);
            }
        }
        if linked <= 1 {
            continue;
        }
        let b = vc[best as usize];
        let mut flip = false;
        if valid(b.v[0]) && valid(b.v[1]) {
            let (f1, f2) = (vc[b.v[0] as usize].co, vc[b.v[1] as usize].co);
            let (v1, v2, vb) = (f1[axis], f2[axis], b.co[axis]);
            flip = if v1 < vb && vb < v2 {
                false
            } else if v1 > vb && vb > v2 {
                true
            } else {
                let t1 = normalize_v3([f1[0] - b.co[0], f1[1] - b.co[1], f1[2] - b.co[2]]).0;
                let t2 = normalize_v3([f2[0] - b.co[0], f2[1] - b.co[1], f2[2] - b.co[2]]).0;
                t1[axis] < t2[axis]
            };
        } else if valid(b.v[0]) {
            flip = vc[b.v[0] as usize].co[axis] < b.co[axis];
        }
        if negative {
            flip = !flip;
        }
        for j in closed..2 {
            let mut w = Walk::new(&vc, best, j);
            vc[best as usize].flag = 1;
            if j == 1 && valid(b.v[0]) && valid(b.v[1]) {
                flip = !flip;
            }
            while let Some(at) = w.at {
                if vc[at].flag == 2 {
                    break;
                }
                vc[at].flag = 2;
                if let Some(e) = w.e {
                    let ed = &mut edges[e];
                    if (w.v == ed[0] && !flip) || (w.v == ed[1] && w.v != ed[0] && flip) {
                        ed.swap(0, 1);
                    }
                }
                w.step(&vc);
            }
        }
    }
}

/// `dist_signed_squared_to_plane_v3` through the origin.
fn dist_signed_squared(p: V3, n: V3) -> f32 {
    let len_sq = dot(n, n);
    let side = dot(n, p);
    let fac = side / len_sq;
    (len_sq * (fac * fac)).copysign(side)
}

/// `dist_signed_to_plane_v3` through the origin.
fn dist_signed(p: V3, n: V3) -> f32 {
    let len_sq = dot(n, n);
    let side = dot(n, p);
    let fac = side / len_sq;
    len_sq.sqrt() * fac
}

fn sqrt_signed(f: f32) -> f32 {
    if f >= 0.0 {
        f.sqrt()
    } else {
        -(-f).sqrt()
    }
}

// Long because it follows Blender's function step by step.
fn screw(m: &Mesh, s: &Settings) -> Result<Mesh, String> {
    let (tv, te, nf) = (m.vertex_count(), m.edge_count(), m.face_count());
    let mut axis_vec = [0.0f32; 3];
    axis_vec[s.axis] = 1.0;
    let mut angle = s.angle;
    let mut screw_ofs = s.screw_ofs;
    let tx = s.axis_object.as_ref().map(|(t, _)| *t);
    if let Some((t, object_offset)) = &s.axis_object {
        // The rotation part only.
        let a = axis_vec;
        axis_vec = normalize_v3([
            t[0][0] * a[0] + t[1][0] * a[1] + t[2][0] * a[2],
            t[0][1] * a[0] + t[1][1] * a[1] + t[2][1] * a[2],
            t[0][2] * a[0] + t[1][2] * a[1] + t[2][2] * a[2],
        ])
        .0;
        if *object_offset {
            let o = [t[3][0], t[3][1], t[3][2]];
            screw_ofs = if dot(o, o).sqrt() != 0.0 {
                dot(axis_vec, o) / dot(axis_vec, axis_vec)
            } else {
                0.0
            };
        }
    }
    let iter = s.iter;
    angle *= iter as f32;
    screw_ofs *= iter as f32;
    let mut uv_u_scale = 1.0 / s.steps as f32;
    let mut step_tot = (s.steps + 1) * iter - (iter - 1);
    let two_pi = std::f32::consts::PI * 2.0;
    let close = screw_ofs.abs() <= f32::EPSILON * 100.0
        && (angle.abs() - two_pi).abs() <= f32::EPSILON * 100.0
        && step_tot > 3;
    if close {
        step_tot -= 1;
        screw_ofs = 0.0;
    } else {
        step_tot = step_tot.max(2);
    }
    let step_tot = step_tot as usize;
    if ((tv + te) as u64) * (step_tot as u64) > MAX_ELEMENTS {
        return Err(format!(
            "{tv} vertices and {te} edges in {step_tot} rings are over blendsynth's limit"
        ));
    }
    if !s.stretch[0] {
        uv_u_scale = (uv_u_scale / iter as f32) * (angle / two_pi);
    }
    let merge = s.merge.filter(|_| screw_ofs == 0.0);

    // The input's edges, each turned to run along (the last of) its faces.
    let mut edges = m.edges.clone();
    let mut edge_face = vec![None; te];
    let mut vert_corner = vec![None; tv];
    for f in 0..nf {
        for c in m.face(f) {
            let v = m.corner_verts[c];
            let e = m.corner_edges[c] as usize;
            edge_face[e] = Some(f);
            vert_corner[v as usize] = Some(c);
            if edges[e][0] != v {
                edges[e].swap(0, 1);
            }
        }
    }
    if s.calc_order && te != 0 {
        order_edges(m, &mut edges, s.axis, tx.as_ref(), angle < 0.0);
    }

    let mut out = Mesh::new();
    out.materials = m.materials.clone();
    out.positions = Vec::with_capacity(tv * step_tot);
    out.positions.extend_from_slice(&m.positions);
    out.edges = edges.clone();
    for step in 1..step_tot {
        let step_angle = (angle / (step_tot - (!close) as usize) as f32) * step as f32;
        let mut mat = if tx.is_some() {
            mat3_to_mat4(&axis_angle_normalized_to_mat3(axis_vec, step_angle))
        } else {
            rotation_about(s.axis, step_angle)
        };
        if screw_ofs != 0.0 {
            let k = screw_ofs * (step as f32 / (step_tot - 1) as f32);
            for a in 0..3 {
                mat[3][a] += axis_vec[a] * k;
            }
        }
        let stride = tv * step;
        for j in 0..tv {
            let p = m.positions[j];
            let q = match &tx {
                Some(t) => {
                    let o = [t[3][0], t[3][1], t[3][2]];
                    let r = transform_point(&mat, [p[0] - o[0], p[1] - o[1], p[2] - o[2]]);
                    [r[0] + o[0], r[1] + o[1], r[2] + o[2]]
                }
                None => transform_point(&mat, p),
            };
            out.positions.push(q);
            out.edges
                .push([(stride + j) as u32, j as u32 + (stride - tv) as u32]);
        }
    }
    if close {
        let stride = (step_tot - 1) * tv;
        for i in 0..tv {
            out.edges.push([i as u32, (stride + i) as u32]);
        }
    }

    let edge_offset = te + tv * (step_tot - if close { 0 } else { 1 });
    let quad_ord: [usize; 4] = if s.flip { [3, 2, 1, 0] } else { [0, 1, 2, 3] };
    let quad_ord_ofs: [usize; 4] = if s.flip { [2, 1, 0, 3] } else { [0, 1, 2, 3] };
    let step_last = step_tot - if close { 1 } else { 2 };
    let faces_n = te * (step_last + 1);
    // Per new face its source face, per new corner its source corner (None: defaults).
    let mut face_src: Vec<Option<usize>> = Vec::with_capacity(faces_n);
    let mut face_mat: Vec<i32> = Vec::with_capacity(faces_n);
    let mut corner_src: Vec<Option<usize>> = Vec::with_capacity(faces_n * 4);
    // UVs: added to the source's (true) or set (false), per corner.
    let mut corner_uv: Vec<([f32; 2], bool)> = Vec::with_capacity(faces_n * 4);
    let has_uv = m.attributes.iter().any(is_uv_map);
    let mut uv_v_min = f32::MAX;
    let mut uv_v_max = -f32::MAX;
    if has_uv && s.stretch[1] {
        for &p in &m.positions {
            let v = dist_signed_squared(p, axis_vec);
            uv_v_min = uv_v_min.min(v);
            uv_v_max = uv_v_max.max(v);
        }
        uv_v_min = sqrt_signed(uv_v_min);
        uv_v_max = sqrt_signed(uv_v_max);
    }
    let range = uv_v_max - uv_v_min;
    let range_inv = if range != 0.0 { 1.0 / range } else { 0.0 };
    let material = m
        .attributes
        .named("material_index")
        .filter(|a| a.domain == Domain::Face)
        .map(|a| a.data.as_int().into_owned());
    out.face_offsets = Vec::with_capacity(faces_n + 1);
    out.face_offsets.push(0);
    for i in 0..te {
        let face = edge_face[i];
        let corners = [
            vert_corner[edges[i][0] as usize],
            vert_corner[edges[i][1] as usize],
        ];
        let has_corners = corners[0].is_some();
        if has_corners && corners[1].is_none() {
            return Err(format!(
                "edge {i} runs from a face's vertex to a loose one (Blender reads past its data)"
            ));
        }
        let mat_nr = match (face, &material) {
            (Some(f), Some(mi)) => mi[f],
            _ => 0,
        };
        let (mut va, mut vb) = (0.0, 0.0);
        if !has_corners && has_uv {
            va = dist_signed(m.positions[edges[i][0] as usize], axis_vec);
            vb = dist_signed(m.positions[edges[i][1] as usize], axis_vec);
            if s.stretch[1] {
                va = (va - uv_v_min) * range_inv;
                vb = (vb - uv_v_min) * range_inv;
            }
        }
        let first = edges[i];
        let (mut i1, mut i2) = (first[0] as usize, first[1] as usize);
        for step in 0..=step_last {
            face_src.push(face);
            face_mat.push(mat_nr);
            let ua = step as f32 * uv_u_scale;
            let ub = (step + 1) as f32 * uv_u_scale;
            let base = corner_src.len();
            let mut verts = [0u32; 4];
            let mut cedges = [0u32; 4];
            let mut uvs = [([0.0f32; 2], has_corners); 4];
            if has_corners {
                let (c0, c1) = (corners[0], corners[1]);
                corner_src.extend([c0, c1, c1, c0]);
                uvs[quad_ord[0]].0[0] = ua;
                uvs[quad_ord[1]].0[0] = ua;
                uvs[quad_ord[2]].0[0] = ub;
                uvs[quad_ord[3]].0[0] = ub;
            } else {
                corner_src.extend([None; 4]);
                uvs[quad_ord[0]].0 = [ua, va];
                uvs[quad_ord[1]].0 = [ua, vb];
                uvs[quad_ord[2]].0 = [ub, vb];
                uvs[quad_ord[3]].0 = [ub, va];
            }
            corner_uv.extend(uvs);
            let ring = |step: usize| (edge_offset + step + i * (step_tot - 1)) as u32;
            if !(close && step == step_last) {
                verts[quad_ord[0]] = i1 as u32;
                verts[quad_ord[1]] = i2 as u32;
                verts[quad_ord[2]] = (i2 + tv) as u32;
                verts[quad_ord[3]] = (i1 + tv) as u32;
                cedges[quad_ord_ofs[0]] = if step == 0 { i as u32 } else { ring(step) - 1 };
                cedges[quad_ord_ofs[1]] = (te + i2) as u32;
                cedges[quad_ord_ofs[2]] = ring(step);
                cedges[quad_ord_ofs[3]] = (te + i1) as u32;
                if step != 0 {
                    out.edges.push([i1 as u32, i2 as u32]);
                }
                i1 += tv;
                i2 += tv;
            } else {
                verts[quad_ord[0]] = i1 as u32;
                verts[quad_ord[1]] = i2 as u32;
                verts[quad_ord[2]] = first[1];
                verts[quad_ord[3]] = first[0];
                cedges[quad_ord_ofs[0]] = ring(step) - 1;
                cedges[quad_ord_ofs[1]] = (te + i2) as u32;
                cedges[quad_ord_ofs[2]] = i as u32;
                cedges[quad_ord_ofs[3]] = (te + i1) as u32;
            }
            out.corner_verts.extend(verts);
            out.corner_edges.extend(cedges);
            out.face_offsets.push((base + 4) as u32);
        }
        out.edges.push([i1 as u32, i2 as u32]);
    }

    // Attributes: every ring copies the input's vertex data; edges start at defaults.
    let vert_src: Vec<usize> = (0..step_tot).flat_map(|_| 0..tv).collect();
    for a in m.attributes.iter() {
        let data = match a.domain {
            Domain::Point => a.data.gather(&vert_src),
            Domain::Edge => default_array(&a.data, out.edges.len()),
            Domain::Face => gather_or_default(&a.data, &face_src),
            Domain::Corner => {
                let mut d = gather_or_default(&a.data, &corner_src);
                if is_uv_map(a) {
                    if let Array::Float2(v) = &mut d {
                        for (x, (uv, add)) in v.iter_mut().zip(&corner_uv) {
                            if *add {
                                x[0] += uv[0];
                            } else {
                                *x = *uv;
                            }
                        }
                    }
                }
                d
            }
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    // Faces without a source face take the modifier's shading and material 0.
    let sharp = super::super::attribute::AttrId::named("sharp_face");
    let mut sharp_face = match out.attributes.get(&sharp) {
        Some(a) if a.domain == Domain::Face => a.data.as_bool().into_owned(),
        _ => vec![false; face_src.len()],
    };
    for (k, f) in face_src.iter().enumerate() {
        if f.is_none() {
            sharp_face[k] = !s.smooth;
        }
    }
    out.attributes
        .set(sharp, Domain::Face, Array::Bool(sharp_face));
    if face_mat.iter().any(|&x| x != 0) || material.is_some() {
        out.attributes.set(
            super::super::attribute::AttrId::named("material_index"),
            Domain::Face,
            Array::Int(face_mat),
        );
    }

    if let Some(threshold) = merge {
        return merge_on_axis(out, tv, step_tot, axis_vec, tx.as_ref(), threshold);
    }
    Ok(out)
}

fn is_uv_map(a: &super::super::attribute::Attribute) -> bool {
    a.domain == Domain::Corner
        && a.id.name().is_some_and(|n| !n.starts_with('.'))
        && matches!(a.data, Array::Float2(_))
}

fn default_array(like: &Array, n: usize) -> Array {
    let mut d = like.empty_like();
    d.extend_default(n);
    d
}

/// `src` gathered, defaults where None.
fn gather_or_default(data: &Array, src: &[Option<usize>]) -> Array {
    let mut d = default_array(data, src.len());
    let (at, from): (Vec<usize>, Vec<usize>) = src
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.map(|s| (k, s)))
        .unzip();
    if !at.is_empty() {
        d.scatter(&at, &data.gather(&from));
    }
    d
}

/// `mesh_remove_doubles_on_axis`: first-ring vertices within `threshold` of the axis move
/// onto it and take the other rings' copies of themselves.
fn merge_on_axis(
    mut out: Mesh,
    tv: usize,
    step_tot: usize,
    axis_vec: V3,
    tx: Option<&Mat4f>,
    threshold: f32,
) -> Result<Mesh, String> {
    let th_sq = threshold * threshold;
    let origin = tx.map_or([0.0; 3], |t| [t[3][0], t[3][1], t[3][2]]);
    let mut dest = vec![-1i32; tv * step_tot];
    let mut any = false;
    for i in 0..tv {
        let p = out.positions[i];
        let rel = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        let d = dot(rel, axis_vec);
        let mut on = [axis_vec[0] * d, axis_vec[1] * d, axis_vec[2] * d];
        if tx.is_some() {
            on = [on[0] + origin[0], on[1] + origin[1], on[2] + origin[2]];
        }
        let diff = [on[0] - p[0], on[1] - p[1], on[2] - p[2]];
        if dot(diff, diff) <= th_sq {
            out.positions[i] = on;
            any = true;
            dest[i] = i as i32;
            for step in 1..step_tot {
                dest[step * tv + i] = i as i32;
            }
        }
    }
    if !any {
        return Ok(out);
    }
    weld::merge_keeping_targets(&out, &dest)
}
