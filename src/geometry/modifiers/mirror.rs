//! The Mirror modifier (`MOD_mirror.cc`, `BKE_mesh_mirror_apply_mirror_on_axis_for_modifier`):
//! for each enabled axis in X, Y, Z order the mesh is doubled, the copy mirrored (about the
//! object's origin, or the mirror object's), its faces flipped keeping their first corner,
//! its UV maps mirrored and offset; a copied vertex within the merge distance of its source
//! merges into it (both at their midpoint) with Blender's vertex merge (`weld::merge`).
//!
//! Bisect (and Bisect Flip) first cuts the mesh at the mirror plane and removes the
//! mirrored side, through BMesh as Blender does (`bisect_plane`). Clipping only constrains edit-mode
//! transforms and changes nothing here. Vertex groups are not exported, so their mirroring
//! has nothing to act on. Merging follows modifiers made since Blender 3.0 (copies merge
//! into their sources); an older modifier merges the other way round, which gives the same
//! geometry with vertices in another order.

use super::super::bisect_plane::bisect_and_keep_negative;
use super::super::math::{mat4_invert, mat4_mul, transform_point, MAT4_IDENTITY};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{Array, Domain};
use super::super::weld;
use super::{flag, flags3, float, id_name, Context, Props};

pub fn unsupported(_p: &Props) -> Option<String> {
    None
}

pub fn apply(p: &Props, ctx: &Context, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let axes = flags3(p, "use_axis");
    let merge = flag(p, "use_mirror_merge").then(|| float(p, "merge_threshold"));
    let merge = merge.transpose()?;
    let uv = UvMirror {
        u: flag(p, "use_mirror_u"),
        v: flag(p, "use_mirror_v"),
        udim: flag(p, "use_mirror_udim"),
        offset: [float(p, "mirror_offset_u")?, float(p, "mirror_offset_v")?],
        offset_copy: [float(p, "offset_u")?, float(p, "offset_v")?],
    };
    // Mirroring about another object: into its space, mirror, back.
    let space = match id_name(p, "mirror_object") {
        Some(name) => {
            let mw = (ctx.world)(&name)
                .ok_or_else(|| format!("mirror object {name:?} is not in the export"))?;
            let ow = (ctx.world)(ctx.object).unwrap_or(MAT4_IDENTITY);
            let tmp = mat4_mul(
                &mat4_invert(&mw)
                    .ok_or_else(|| format!("mirror object {name:?} has a singular transform"))?,
                &ow,
            );
            let itmp = mat4_invert(&tmp)
                .ok_or("the object's transform relative to the mirror object is singular")?;
            Some((tmp, itmp))
        }
        None => None,
    };
    let bisect = flags3(p, "use_bisect_axis");
    let flip = flags3(p, "use_bisect_flip_axis");
    let mut mesh = m.as_ref().clone();
    for axis in 0..3 {
        if !axes[axis] {
            continue;
        }
        let mut mtx = MAT4_IDENTITY;
        mtx[axis][axis] = -1.0;
        if let Some((tmp, itmp)) = &space {
            mtx = mat4_mul(&mat4_mul(itmp, &mtx), tmp);
        }
        if bisect[axis] {
            let (co, mut no) = match &space {
                Some((_, itmp)) => {
                    let mut no = [itmp[axis][0], itmp[axis][1], itmp[axis][2]];
                    // Non-uniform object scale (Blender's #87592 fix), scaled to its largest.
                    let ow = (ctx.world)(ctx.object).unwrap_or(MAT4_IDENTITY);
                    let s: Vec<f32> = (0..3)
                        .map(|k| ow[k][0] * ow[k][0] + ow[k][1] * ow[k][1] + ow[k][2] * ow[k][2])
                        .collect();
                    let max = s[0].max(s[1]).max(s[2]);
                    if max != 0.0 {
                        for k in 0..3 {
                            no[k] *= s[k] * (1.0 / max);
                        }
                    }
                    ([itmp[3][0], itmp[3][1], itmp[3][2]], no)
                }
                None => {
                    let mut no = [0.0f32; 3];
                    no[axis] = 1.0;
                    ([mtx[3][0], mtx[3][1], mtx[3][2]], no)
                }
            };
            // Keeps the side not mirrored onto, unless flipped.
            if !flip[axis] {
                no = [-no[0], -no[1], -no[2]];
            }
            let d = -(no[0] * co[0] + no[1] * co[1] + no[2] * co[2]);
            let eps = float(p, "bisect_threshold")?;
            mesh = bisect_and_keep_negative(&mesh, [no[0], no[1], no[2], d], eps)?;
        }
        mesh = mirror_axis(&mesh, &mtx, merge, &uv)?;
    }
    *g.mesh_mut().unwrap() = mesh;
    Ok(g)
}

struct UvMirror {
    u: bool,
    v: bool,
    udim: bool,
    /// `mirror_offset_u/v`: added to mirrored coordinates.
    offset: [f32; 2],
    /// `offset_u/v`: added to every UV of the copy.
    offset_copy: [f32; 2],
}

impl UvMirror {
    fn active(&self) -> bool {
        self.u || self.v || self.offset_copy != [0.0, 0.0]
    }
    fn map(&self, mut uv: [f32; 2]) -> [f32; 2] {
        for (k, on) in [self.u, self.v].into_iter().enumerate() {
            if on {
                let x = uv[k];
                uv[k] = if self.udim {
                    // Flip about the centre of the UDIM tile (C's fmodf keeps the sign).
                    x.ceil() - x % 1.0 + self.offset[k]
                } else {
                    1.0 - x + self.offset[k]
                };
            }
        }
        [uv[0] + self.offset_copy[0], uv[1] + self.offset_copy[1]]
    }
}

/// One axis: the mesh, then its mirrored copy with flipped faces, then the merge.
fn mirror_axis(
    m: &Mesh,
    mtx: &super::super::math::Mat4f,
    merge: Option<f32>,
    uv: &UvMirror,
) -> Result<Mesh, String> {
    let (nv, ne, nc, nf) = (
        m.vertex_count(),
        m.edge_count(),
        m.corner_count(),
        m.face_count(),
    );
    let mut out = m.clone();
    out.custom_vert_normals = None;
    out.positions
        .extend(m.positions.iter().map(|p| transform_point(mtx, *p)));
    out.edges
        .extend(m.edges.iter().map(|[a, b]| [a + nv as u32, b + nv as u32]));
    out.face_offsets
        .extend(m.face_offsets[1..].iter().map(|o| o + nc as u32));
    // The copy's corners: each face keeps its first corner and reverses the rest, and
    // each corner's edge (to the next corner) is the old edges in reverse.
    let mut order: Vec<usize> = (0..nc).collect();
    let mut corner_edges = m.corner_edges.clone();
    for f in 0..nf {
        let r = m.face(f);
        order[r.start + 1..r.end].reverse();
        corner_edges[r.clone()].reverse();
    }
    out.corner_verts
        .extend(order.iter().map(|&c| m.corner_verts[c] + nv as u32));
    out.corner_edges
        .extend(corner_edges.iter().map(|e| e + ne as u32));
    for a in out.attributes.0.iter_mut() {
        let mut copy = match a.domain {
            Domain::Corner => a.data.gather(&order),
            Domain::Point | Domain::Edge | Domain::Face => a.data.clone(),
            _ => continue,
        };
        let is_uv_map = a.domain == Domain::Corner
            && a.id.name().is_some_and(|n| !n.starts_with('.'))
            && matches!(copy, Array::Float2(_));
        if is_uv_map && uv.active() {
            if let Array::Float2(v) = &mut copy {
                for x in v.iter_mut() {
                    *x = uv.map(*x);
                }
            }
        }
        a.data.extend(&copy);
    }
    let Some(tolerance) = merge else {
        return Ok(out);
    };
    // Copies within the distance of their source merge into it, both at the midpoint.
    let tol_sq = tolerance * tolerance;
    let mut dest = vec![-1i32; 2 * nv];
    let mut merged = 0;
    for i in 0..nv {
        let (a, b) = (out.positions[i], out.positions[nv + i]);
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < tol_sq {
            let mid = [
                (a[0] + b[0]) * 0.5,
                (a[1] + b[1]) * 0.5,
                (a[2] + b[2]) * 0.5,
            ];
            out.positions[i] = mid;
            out.positions[nv + i] = mid;
            dest[i] = i as i32;
            dest[nv + i] = i as i32;
            merged += 1;
        }
    }
    if merged == 0 {
        return Ok(out);
    }
    weld::merge(&out, &dest)
}
