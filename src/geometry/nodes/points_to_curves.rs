//! Points to Curves (`node_geo_points_to_curves`): each point cloud becomes poly curves,
//! one per distinct Curve Group ID in order of first appearance, each holding its points
//! in index order or, with a Weight field, by ascending weight (equal weights by index).
//! Point attributes go along; every other component is dropped, as in Blender.

use std::cmp::Ordering;
use std::collections::HashMap;
use std::sync::Arc;

use super::super::attribute::{AttrId, Attributes};
use super::super::curves::{Curves, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

/// Sorts one group's point indices by weight, ties by index (Blender's `grouped_sort`).
fn sort_by_weight(group: &mut [usize], w: &[f32]) {
    group.sort_by(|&a, &b| {
        if w[a] == w[b] {
            a.cmp(&b)
        } else if w[a] < w[b] {
            Ordering::Less
        } else {
            Ordering::Greater
        }
    });
}

fn curves_from_points(p: &PointCloud, group: &Field, weight: &Field) -> Result<Curves, String> {
    let n = p.len();
    let r = eval_fields(
        ComponentRef::Points(p),
        Domain::Point,
        &[(group, DataType::Int), (weight, DataType::Float)],
    )?;
    let (ids, w) = (r[0].as_int(), r[1].as_float());
    // Group index per point, groups numbered by first appearance.
    let mut index_of: HashMap<i32, usize> = HashMap::new();
    let curve_of: Vec<usize> = if matches!(group, Field::Constant(_)) {
        vec![0; n]
    } else {
        ids.iter()
            .map(|id| {
                let next = index_of.len();
                *index_of.entry(*id).or_insert(next)
            })
            .collect()
    };
    let curves = curve_of.iter().max().map_or(0, |m| m + 1);
    let mut offsets = vec![0u32; curves + 1];
    for &c in &curve_of {
        offsets[c + 1] += 1;
    }
    for c in 0..curves {
        offsets[c + 1] += offsets[c];
    }
    let mut fill = offsets.clone();
    let mut order = vec![0usize; n];
    for (i, &c) in curve_of.iter().enumerate() {
        order[fill[c] as usize] = i;
        fill[c] += 1;
    }
    if !matches!(weight, Field::Constant(_)) {
        for c in 0..curves {
            sort_by_weight(&mut order[offsets[c] as usize..offsets[c + 1] as usize], &w);
        }
    }
    let mut attributes = Attributes::default();
    for a in p.attributes.iter() {
        attributes.set(a.id.clone(), Domain::Point, a.data.gather(&order));
    }
    attributes.set(
        AttrId::named("curve_type"),
        Domain::Curve,
        Array::Int8(vec![CURVE_TYPE_POLY; curves]),
    );
    Ok(Curves {
        positions: order.iter().map(|&i| p.positions[i]).collect(),
        curve_offsets: offsets,
        attributes,
        materials: p.materials.clone(),
    })
}

pub fn points_to_curves(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Points")?;
    let group = ctx.field("Curve Group ID", DataType::Int)?;
    let weight = ctx.field("Weight", DataType::Float)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let points = s.points.take();
        s.mesh = None;
        s.curves = None;
        if let Some(p) = points.filter(|p| !p.is_empty()) {
            s.curves = Some(Arc::new(curves_from_points(&p, &group, &weight)?));
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curves", SocketValue::Geometry(g))]))
}
