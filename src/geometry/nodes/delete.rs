//! Delete Geometry and Separate Geometry (`geometry/intern/separate_geometry.cc`,
//! `mesh_copy_selection.cc`): the kept elements stay in their order, and what depends on a
//! removed element goes too. For meshes, "All" derives the kept vertices, edges and faces
//! from the selection's domain; "Edges and Faces" keeps every vertex; "Only Faces" keeps
//! vertices and edges.

use std::sync::Arc;

use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    All,
    EdgeFace,
    OnlyFace,
}

fn indices(keep: &[bool]) -> Vec<usize> {
    (0..keep.len()).filter(|&i| keep[i]).collect()
}

/// The mesh restricted to `keep` (a selection on `domain`).
pub fn mesh_keep(m: &Mesh, domain: Domain, keep: &[bool], mode: Mode) -> Mesh {
    let (nv, ne, nf) = (m.vertex_count(), m.edge_count(), m.face_count());
    let (vk, ek, fk): (Vec<bool>, Vec<bool>, Vec<bool>) = match domain {
        Domain::Point => {
            let ek: Vec<bool> = m
                .edges
                .iter()
                .map(|e| keep[e[0] as usize] && keep[e[1] as usize])
                .collect();
            let fk: Vec<bool> = (0..nf)
                .map(|f| m.face(f).all(|c| keep[m.corner_verts[c] as usize]))
                .collect();
            (keep.to_vec(), ek, fk)
        }
        Domain::Edge => {
            let fk: Vec<bool> = (0..nf)
                .map(|f| m.face(f).all(|c| keep[m.corner_edges[c] as usize]))
                .collect();
            let mut vk = vec![false; nv];
            for (e, ev) in m.edges.iter().enumerate() {
                if keep[e] {
                    vk[ev[0] as usize] = true;
                    vk[ev[1] as usize] = true;
                }
            }
            (vk, keep.to_vec(), fk)
        }
        _ => {
            let mut vk = vec![false; nv];
            let mut ek = vec![false; ne];
            for f in 0..nf {
                if keep[f] {
                    for c in m.face(f) {
                        vk[m.corner_verts[c] as usize] = true;
                        ek[m.corner_edges[c] as usize] = true;
                    }
                }
            }
            (vk, ek, keep.to_vec())
        }
    };
    let (vk, ek) = match mode {
        Mode::All => (vk, ek),
        Mode::EdgeFace => (vec![true; nv], ek),
        Mode::OnlyFace => (vec![true; nv], vec![true; ne]),
    };
    let vi = indices(&vk);
    let ei = indices(&ek);
    let fi = indices(&fk);
    let mut vmap = vec![u32::MAX; nv];
    for (n, &v) in vi.iter().enumerate() {
        vmap[v] = n as u32;
    }
    let mut emap = vec![u32::MAX; ne];
    for (n, &e) in ei.iter().enumerate() {
        emap[e] = n as u32;
    }
    let mut out = Mesh::new();
    out.positions = vi.iter().map(|&v| m.positions[v]).collect();
    out.edges = ei
        .iter()
        .map(|&e| [vmap[m.edges[e][0] as usize], vmap[m.edges[e][1] as usize]])
        .collect();
    let mut corners = Vec::new();
    for &f in &fi {
        for c in m.face(f) {
            corners.push(c);
            out.corner_verts.push(vmap[m.corner_verts[c] as usize]);
            out.corner_edges.push(emap[m.corner_edges[c] as usize]);
        }
        out.face_offsets.push(out.corner_verts.len() as u32);
    }
    out.materials = m.materials.clone();
    for a in m.attributes.iter() {
        let idx = match a.domain {
            Domain::Point => &vi,
            Domain::Edge => &ei,
            Domain::Face => &fi,
            Domain::Corner => &corners,
            _ => continue,
        };
        out.attributes
            .set(a.id.clone(), a.domain, a.data.gather(idx));
    }
    out
}

/// The curves' selected points (`curves_copy_point_selection`: a curve keeps the points
/// selected on it, in order, and goes when none is) or selected curves
/// (`curves_copy_curve_selection`), with their attributes.
fn curves_keep(c: &Curves, domain: Domain, keep: &[bool]) -> Curves {
    let mut points = Vec::new();
    let mut curves = Vec::new();
    let mut offsets = vec![0u32];
    for i in 0..c.curve_count() {
        let before = points.len();
        for p in c.points(i) {
            let on = if domain == Domain::Point {
                keep[p]
            } else {
                keep[i]
            };
            if on {
                points.push(p);
            }
        }
        if points.len() > before {
            curves.push(i);
            offsets.push(points.len() as u32);
        }
    }
    let mut out = c.clone();
    out.positions = points.iter().map(|&p| c.positions[p]).collect();
    out.curve_offsets = offsets;
    out.attributes.gather_domain(Domain::Point, &points);
    out.attributes.gather_domain(Domain::Curve, &curves);
    out
}

/// Keeps the selected (or, `invert`, the unselected) elements of every component.
fn separate(
    s: &mut GeometrySet,
    domain: Domain,
    mode: Mode,
    sel: &Field,
    invert: bool,
) -> Result<(), String> {
    let pick =
        |v: std::borrow::Cow<'_, [bool]>| -> Vec<bool> { v.iter().map(|x| *x != invert).collect() };
    if let Some(m) = s.mesh.clone() {
        if matches!(
            domain,
            Domain::Point | Domain::Edge | Domain::Face | Domain::Corner
        ) {
            let d = if domain == Domain::Corner {
                return Err("the corner domain cannot be deleted".into());
            } else {
                domain
            };
            let r = eval_fields(ComponentRef::Mesh(&m), d, &[(sel, DataType::Bool)])?;
            s.mesh = Some(Arc::new(mesh_keep(&m, d, &pick(r[0].as_bool()), mode)));
        }
    }
    if let Some(p) = s.points.clone() {
        if domain == Domain::Point {
            let r = eval_fields(
                ComponentRef::Points(&p),
                Domain::Point,
                &[(sel, DataType::Bool)],
            )?;
            let idx = indices(&pick(r[0].as_bool()));
            let mut q = (*p).clone();
            q.positions = idx.iter().map(|&i| p.positions[i]).collect();
            q.attributes.gather_domain(Domain::Point, &idx);
            s.points = Some(Arc::new(q));
        }
    }
    if let Some(c) = s.curves.clone() {
        if matches!(domain, Domain::Point | Domain::Curve) {
            let r = eval_fields(ComponentRef::Curves(&c), domain, &[(sel, DataType::Bool)])?;
            let keep = pick(r[0].as_bool());
            if keep.iter().any(|k| !k) {
                let kept = curves_keep(&c, domain, &keep);
                // Blender removes the component when no point is left.
                s.curves = (kept.point_count() > 0).then(|| Arc::new(kept));
            }
        }
    }
    if let Some(i) = s.instances.clone() {
        if domain == Domain::Instance {
            let r = eval_fields(
                ComponentRef::Instances(&i),
                Domain::Instance,
                &[(sel, DataType::Bool)],
            )?;
            let idx = indices(&pick(r[0].as_bool()));
            let mut q = (*i).clone();
            q.transforms = idx.iter().map(|&k| i.transforms[k]).collect();
            q.handles = idx.iter().map(|&k| i.handles[k]).collect();
            q.attributes.gather_domain(Domain::Instance, &idx);
            s.instances = Some(Arc::new(q));
        }
    }
    Ok(())
}

fn domain_and_mode(ctx: &NodeCtx) -> Result<(Domain, Mode), GeometryError> {
    let d = ctx.prop_str("domain")?;
    let domain = Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))?;
    let mode = match ctx.prop("mode").and_then(|v| v.as_str()).unwrap_or("ALL") {
        "ALL" => Mode::All,
        "EDGE_FACE" => Mode::EdgeFace,
        "ONLY_FACE" => Mode::OnlyFace,
        m => return Err(ctx.err(format!("mode {m} is not supported"))),
    };
    Ok((domain, mode))
}

fn run(
    g: &mut GeometrySet,
    domain: Domain,
    mode: Mode,
    sel: &Field,
    invert: bool,
) -> Result<(), String> {
    if domain == Domain::Instance {
        separate(g, domain, mode, sel, invert)
    } else {
        modify_geometry_sets(g, &mut |s: &mut GeometrySet| {
            separate(s, domain, mode, sel, invert)
        })
    }
}

pub fn delete_geometry(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let (domain, mode) = domain_and_mode(ctx)?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    run(&mut g, domain, mode, &sel, true).map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", SocketValue::Geometry(g))]))
}

pub fn separate_geometry(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    let (domain, _) = domain_and_mode(ctx)?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let mut a = g.clone();
    let mut b = g;
    if ctx.output_used("Selection") {
        run(&mut a, domain, Mode::All, &sel, false).map_err(|e| ctx.err(e))?;
    }
    if ctx.output_used("Inverted") {
        run(&mut b, domain, Mode::All, &sel, true).map_err(|e| ctx.err(e))?;
    }
    Ok(outputs([
        ("Selection", SocketValue::Geometry(a)),
        ("Inverted", SocketValue::Geometry(b)),
    ]))
}
