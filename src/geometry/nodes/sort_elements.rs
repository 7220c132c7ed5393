//! Sort Elements (`node_geo_sort_elements`, `geometry::reorder_*`): the selected elements
//! of a domain move among the selected slots, ordered by group ID (ascending) and within a
//! group by Sort Weight (ties and constant weights keep index order); unselected elements
//! stay where they are. Meshes (points, edges, faces), point clouds and instances are
//! reordered; curves are refused by name.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::modify_geometry_sets;

/// New element `i` is old element `order[i]`; None when nothing moves.
fn sorted_indices(
    comp: ComponentRef,
    domain: Domain,
    sel: &Field,
    group: &Field,
    weight: &Field,
) -> Result<Option<Vec<usize>>, String> {
    let n = comp.domain_size(domain);
    let (group_single, weight_single) = (
        matches!(group, Field::Constant(_)),
        matches!(weight, Field::Constant(_)),
    );
    if n == 0 || (group_single && weight_single) {
        return Ok(None);
    }
    let ctx = FieldContext::new(comp);
    let s = ctx.eval(sel, domain, DataType::Bool)?;
    let g = ctx.eval(group, domain, DataType::Int)?;
    let w = ctx.eval(weight, domain, DataType::Float)?;
    let (s, g, w) = (s.as_bool(), g.as_int(), w.as_float());
    let mask: Vec<usize> = (0..n).filter(|&i| s[i]).collect();
    if mask.is_empty() {
        return Ok(None);
    }
    let mut gathered = mask.clone();
    let by_weight = |a: &usize, b: &usize| {
        if w[*a] == w[*b] {
            a.cmp(b)
        } else {
            w[*a]
                .partial_cmp(&w[*b])
                .unwrap_or(std::cmp::Ordering::Equal)
        }
    };
    if group_single {
        gathered.sort_by(by_weight);
    } else {
        // Stable by group ID: equal IDs keep mask order, then weights within each group.
        gathered.sort_by_key(|&i| g[i]);
        if !weight_single {
            let mut start = 0;
            while start < gathered.len() {
                let id = g[gathered[start]];
                let end = start
                    + gathered[start..]
                        .iter()
                        .take_while(|&&i| g[i] == id)
                        .count();
                gathered[start..end].sort_by(by_weight);
                start = end;
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    for (k, &slot) in mask.iter().enumerate() {
        order[slot] = gathered[k];
    }
    Ok((order.iter().enumerate().any(|(i, &o)| i != o)).then_some(order))
}

fn inverse(order: &[usize]) -> Vec<u32> {
    let mut inv = vec![0u32; order.len()];
    for (new, &old) in order.iter().enumerate() {
        inv[old] = new as u32;
    }
    inv
}

fn reorder_mesh(m: &Mesh, domain: Domain, order: &[usize]) -> Mesh {
    let mut out = m.clone();
    match domain {
        Domain::Point => {
            let inv = inverse(order);
            out.positions = order.iter().map(|&i| m.positions[i]).collect();
            out.custom_vert_normals = m
                .custom_vert_normals
                .as_ref()
                .map(|n| order.iter().map(|&i| n[i]).collect());
            out.edges = m
                .edges
                .iter()
                .map(|e| [inv[e[0] as usize], inv[e[1] as usize]])
                .collect();
            out.corner_verts = m.corner_verts.iter().map(|&v| inv[v as usize]).collect();
        }
        Domain::Edge => {
            let inv = inverse(order);
            out.edges = order.iter().map(|&i| m.edges[i]).collect();
            out.corner_edges = m.corner_edges.iter().map(|&e| inv[e as usize]).collect();
        }
        _ => {
            let mut corners = Vec::with_capacity(m.corner_count());
            out.face_offsets = vec![0];
            for &f in order {
                corners.extend(m.face(f));
                out.face_offsets.push(corners.len() as u32);
            }
            out.corner_verts = corners.iter().map(|&c| m.corner_verts[c]).collect();
            out.corner_edges = corners.iter().map(|&c| m.corner_edges[c]).collect();
            for a in out.attributes.0.iter_mut() {
                if a.domain == Domain::Corner {
                    a.data = a.data.gather(&corners);
                }
            }
        }
    }
    for a in out.attributes.0.iter_mut() {
        if a.domain == domain {
            a.data = a.data.gather(order);
        }
    }
    out
}

pub fn sort_elements(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let d = ctx.prop_str("domain")?;
    let domain = Domain::parse(d).ok_or_else(|| ctx.err(format!("unknown domain {d}")))?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let group = ctx.field("Group ID", DataType::Int)?;
    let weight = ctx.field("Sort Weight", DataType::Float)?;
    if domain == Domain::Instance {
        if let Some(inst) = g.instances.clone() {
            let order = sorted_indices(
                ComponentRef::Instances(&inst),
                domain,
                &sel,
                &group,
                &weight,
            )
            .map_err(|e| ctx.err(e))?;
            if let Some(order) = order {
                let im = g.instances_mut().unwrap();
                im.handles = order.iter().map(|&i| inst.handles[i]).collect();
                im.transforms = order.iter().map(|&i| inst.transforms[i]).collect();
                for a in im.attributes.0.iter_mut() {
                    a.data = a.data.gather(&order);
                }
            }
        }
        return Ok(outputs([("Geometry", SocketValue::Geometry(g))]));
    }
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        if s.curves.as_ref().is_some_and(|c| c.point_count() > 0)
            && matches!(domain, Domain::Point | Domain::Curve)
        {
            return Err("sorting curves is not supported by blendsynth".into());
        }
        if let Some(m) = s.mesh.clone() {
            if matches!(domain, Domain::Point | Domain::Edge | Domain::Face) {
                if let Some(order) =
                    sorted_indices(ComponentRef::Mesh(&m), domain, &sel, &group, &weight)?
                {
                    *s.mesh_mut().unwrap() = reorder_mesh(&m, domain, &order);
                }
            }
        }
        if let Some(p) = s.points.clone() {
            if domain == Domain::Point {
                if let Some(order) =
                    sorted_indices(ComponentRef::Points(&p), domain, &sel, &group, &weight)?
                {
                    let pp = s.points_mut().unwrap();
                    pp.positions = order.iter().map(|&i| p.positions[i]).collect();
                    for a in pp.attributes.0.iter_mut() {
                        a.data = a.data.gather(&order);
                    }
                }
            }
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", SocketValue::Geometry(g))]))
}
