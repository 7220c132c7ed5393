//! Merge by Distance (`node_geo_merge_by_distance.cc`): meshes weld their selected
//! vertices ("All" by proximity, "Connected" along short edges; `weld`), point clouds
//! merge selected points within the distance (`point_merge_by_distance`).

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::pointcloud::PointCloud;
use super::super::types::{DataType, Domain};
use super::super::weld;
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

pub fn merge_by_distance(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let distance = ctx.float("Distance")?;
    // Blender 4.5 has a Mode menu socket; older files a `mode` property.
    let mode = if ctx.has_input("Mode") {
        ctx.string("Mode")?
    } else {
        ctx.prop_str("mode").unwrap_or("ALL").to_string()
    };
    if mode != "ALL" && mode != "CONNECTED" {
        return Err(ctx.err(format!("mode {mode:?} is not a Merge by Distance mode")));
    }
    modify_geometry_sets(&mut g, &mut |s| {
        if let Some(p) = s.points.clone() {
            let r = eval_fields(
                ComponentRef::Points(&p),
                Domain::Point,
                &[(&sel, DataType::Bool)],
            )?;
            if let Some(np) = merge_points(&p, &r[0].as_bool(), distance) {
                s.points = Some(Arc::new(np));
            }
        }
        if let Some(m) = s.mesh.clone() {
            let r = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Point,
                &[(&sel, DataType::Bool)],
            )?;
            let selection = r[0].as_bool();
            let (dest, killed) = if mode == "ALL" {
                weld::duplicates_all(&m.positions, &selection, distance)
            } else {
                weld::duplicates_connected(&m, &selection, distance)
            };
            if killed > 0 {
                s.mesh = Some(Arc::new(weld::merge(&m, &dest)?));
            }
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}

/// `geometry::point_merge_by_distance`: clusters found in the k-d tree's node order; the
/// merged point keeps the target's place in the order and the cluster's averaged
/// attributes (`id`: see below).
fn merge_points(p: &PointCloud, selection: &[bool], distance: f32) -> Option<PointCloud> {
    let (dest, killed) = weld::duplicates_tree_order(&p.positions, selection, distance);
    if killed == 0 {
        return None;
    }
    let n = p.len();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    let mut group_of = vec![usize::MAX; n];
    for i in 0..n {
        if dest[i] < 0 || dest[i] == i as i32 {
            group_of[i] = groups.len();
            groups.push(vec![i as u32]);
        }
    }
    for i in 0..n {
        if dest[i] >= 0 && dest[i] != i as i32 {
            groups[group_of[dest[i] as usize]].push(i as u32);
        }
    }
    for g in groups.iter_mut() {
        g.sort_unstable();
    }
    let mut out = PointCloud {
        materials: p.materials.clone(),
        ..Default::default()
    };
    out.positions = weld::mix_groups(
        &super::super::types::Array::Vector(p.positions.clone()),
        &groups,
    )
    .as_vector()
    .into_owned();
    for a in p.attributes.iter() {
        let data = if a.id.name() == Some("id") {
            // Blender reads the id at each group's offset into its merge map (the running
            // count of merged sources), not at the group's first source index; match it.
            let offsets: Vec<usize> = groups
                .iter()
                .scan(0, |acc, g| {
                    let o = *acc;
                    *acc += g.len();
                    Some(o)
                })
                .collect();
            a.data.gather(&offsets)
        } else {
            weld::mix_groups(&a.data, &groups)
        };
        out.attributes.set(a.id.clone(), Domain::Point, data);
    }
    Some(out)
}
