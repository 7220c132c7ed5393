//! Field Variance (`node_geo_field_variance`): the population variance and standard
//! deviation of a float or vector field over a domain, per Group ID (vectors per
//! component). Ungrouped, Blender 4.5 sums the squared deviations with `std::reduce` and a
//! lambda that squares only its second argument; GCC's `std::reduce` also applies it to
//! pairs of raw values (blocks of four), so the result is not the textbook variance (0.8
//! for 0..4, not 2). That is what Blender outputs, so it is what this outputs; grouped
//! values take Blender's other, sequential path, which is the textbook one.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::field_statistics::{group_sums, reduce, statistics_node, Groups};

fn variance(v: &[f32], groups: Option<&Groups>) -> Vec<f32> {
    match groups {
        None => {
            let n = v.len() as f32;
            let mean = reduce(v, 0.0, |a, b| a + b) / n;
            let squared = reduce(v, 0.0, |acc, x| {
                let d = mean - x;
                acc + d * d
            });
            vec![squared / n]
        }
        Some(g) => {
            let (sum, count) = group_sums(v, g);
            let mut dev = vec![0.0f32; g.count];
            for (x, &k) in v.iter().zip(&g.of) {
                let d = sum[k] / count[k] as f32 - *x;
                dev[k] += d * d;
            }
            dev.iter().zip(&count).map(|(d, c)| d / *c as f32).collect()
        }
    }
}

fn standard_deviation(v: &[f32], groups: Option<&Groups>) -> Vec<f32> {
    variance(v, groups).into_iter().map(f32::sqrt).collect()
}

pub fn field_variance(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    statistics_node(
        ctx,
        "Field Variance",
        &["FLOAT", "FLOAT_VECTOR"],
        &[
            ("Standard Deviation", standard_deviation, None),
            ("Variance", variance, None),
        ],
    )
}
