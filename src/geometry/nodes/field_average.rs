//! Field Average (`node_geo_field_average`): the mean and median of a float or vector
//! field over a domain, per Group ID. The ungrouped mean is summed as Blender's
//! `std::reduce` sums (blocks of four); grouped sums run in element order. Vectors per
//! component; an even count's median is the midpoint of the two middle values.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::field_statistics::{group_sums, reduce, statistics_node, Groups};

fn mean(v: &[f32], groups: Option<&Groups>) -> Vec<f32> {
    match groups {
        None => vec![reduce(v, 0.0, |a, b| a + b) / v.len() as f32],
        Some(g) => {
            let (sum, count) = group_sums(v, g);
            sum.iter().zip(&count).map(|(s, c)| s / *c as f32).collect()
        }
    }
}

fn median_of(mut x: Vec<f32>) -> f32 {
    x.sort_by(f32::total_cmp);
    let h = x.len() / 2;
    if x.len().is_multiple_of(2) {
        (x[h - 1] + x[h]) * 0.5
    } else {
        x[h]
    }
}

fn median(v: &[f32], groups: Option<&Groups>) -> Vec<f32> {
    match groups {
        None => vec![median_of(v.to_vec())],
        Some(g) => {
            let mut members: Vec<Vec<f32>> = vec![Vec::new(); g.count];
            for (x, &k) in v.iter().zip(&g.of) {
                members[k].push(*x);
            }
            members.into_iter().map(median_of).collect()
        }
    }
}

pub fn field_average(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    statistics_node(
        ctx,
        "Field Average",
        &["FLOAT", "FLOAT_VECTOR"],
        &[("Mean", mean, None), ("Median", median, None)],
    )
}
