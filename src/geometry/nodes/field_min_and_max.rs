//! Field Min & Max (`node_geo_field_min_and_max`): the lowest and highest value of a
//! float, integer or vector field over a domain, per Group ID (vectors per component).
//! Blender folds `math::min` / `math::max` from the type's largest / lowest value, so a
//! NaN never replaces the running result.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::field_statistics::{statistics_node, Groups};

fn fold<T: Copy>(v: &[T], groups: Option<&Groups>, init: T, pick: fn(T, T) -> T) -> Vec<T> {
    match groups {
        None => vec![v.iter().fold(init, |r, x| pick(r, *x))],
        Some(g) => {
            let mut r = vec![init; g.count];
            for (x, &k) in v.iter().zip(&g.of) {
                r[k] = pick(r[k], *x);
            }
            r
        }
    }
}

// std::min(r, x) is `x < r ? x : r`, std::max(r, x) is `r < x ? x : r`.
fn lower<T: PartialOrd>(r: T, x: T) -> T {
    if x < r {
        x
    } else {
        r
    }
}
fn higher<T: PartialOrd>(r: T, x: T) -> T {
    if r < x {
        x
    } else {
        r
    }
}

fn min_f(v: &[f32], g: Option<&Groups>) -> Vec<f32> {
    fold(v, g, f32::MAX, lower)
}
fn max_f(v: &[f32], g: Option<&Groups>) -> Vec<f32> {
    fold(v, g, f32::MIN, higher)
}
fn min_i(v: &[i32], g: Option<&Groups>) -> Vec<i32> {
    fold(v, g, i32::MAX, lower)
}
fn max_i(v: &[i32], g: Option<&Groups>) -> Vec<i32> {
    fold(v, g, i32::MIN, higher)
}

pub fn field_min_and_max(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    statistics_node(
        ctx,
        "Field Min & Max",
        &["FLOAT", "INT", "FLOAT_VECTOR"],
        &[("Min", min_f, Some(min_i)), ("Max", max_f, Some(max_i))],
    )
}
