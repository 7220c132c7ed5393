//! Reverse Curve (`node_geo_curve_reverse`, `CurvesGeometry::reverse_curves`): the
//! selected curves' points in reverse order, every point attribute with them; Bezier
//! handles also swap sides so the shape stays the same.

use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::types::{DataType, Domain};

fn reverse_curves(c: &mut Curves, sel: &[bool]) {
    // Per point: the point it takes its values from.
    let mut src: Vec<usize> = (0..c.point_count()).collect();
    for (i, _) in sel.iter().enumerate().filter(|(_, s)| **s) {
        let r = c.points(i);
        for (k, p) in r.clone().enumerate() {
            src[p] = r.end - 1 - k;
        }
    }
    c.positions = src.iter().map(|&s| c.positions[s]).collect();
    let swap = |n: &str| match n {
        "handle_left" => Some("handle_right"),
        "handle_right" => Some("handle_left"),
        "handle_type_left" => Some("handle_type_right"),
        "handle_type_right" => Some("handle_type_left"),
        _ => None,
    };
    let before = c.attributes.clone();
    let reversed_points: Vec<usize> = (0..c.curve_count())
        .filter(|&i| sel[i])
        .flat_map(|i| c.points(i))
        .collect();
    for a in c.attributes.0.iter_mut() {
        if a.domain != Domain::Point {
            continue;
        }
        // Unselected curves keep their own side's values; reversed ones take the other
        // side's, in reverse order.
        let other =
            a.id.name()
                .and_then(swap)
                .and_then(|o| before.named(o))
                .filter(|o| o.domain == Domain::Point);
        let mut data = a.data.gather(&src);
        if let Some(o) = other {
            let from_other = o.data.gather(&src);
            data.scatter(&reversed_points, &from_other.gather(&reversed_points));
        }
        a.data = data;
    }
}

pub fn reverse_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let sel = ctx.field("Selection", DataType::Bool)?;
    super::curve_write::edit_curves(
        ctx,
        "Curve",
        Domain::Curve,
        &[(&sel, DataType::Bool)],
        &mut |c, r| {
            reverse_curves(c, &r[0].as_bool());
            Ok(())
        },
    )
}
