//! Set Spline Type (`node_geo_curve_spline_type`, `geometry::convert_curves`). Converting
//! to Poly keeps the control points as they are (Blender's trivial conversion: a Bezier
//! curve loses its handles, a NURBS curve its weights and knots); Bezier handle and NURBS
//! attributes are dropped once no curve of that type is left. Conversions to Bezier,
//! NURBS and Catmull-Rom are refused by name.

use super::super::curves::{Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_NURBS, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::types::{DataType, Domain};

/// Removes the built-ins of curve types no curve has any more
/// (`remove_attributes_based_on_types`).
pub fn remove_attributes_based_on_types(c: &mut Curves) {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let any = |t: i8| types.iter().any(|v| *v as i8 == t);
    let mut drop: Vec<&str> = Vec::new();
    if !any(CURVE_TYPE_BEZIER) {
        drop.extend([
            "handle_left",
            "handle_right",
            "handle_type_left",
            "handle_type_right",
        ]);
    }
    if !any(CURVE_TYPE_NURBS) {
        drop.extend(["nurbs_weight", "nurbs_order", "knots_mode"]);
    }
    c.attributes
        .0
        .retain(|a| !a.id.name().is_some_and(|n| drop.contains(&n)));
}

pub fn set_spline_type(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let target = match ctx.prop_str("spline_type")? {
        "POLY" => CURVE_TYPE_POLY,
        other => {
            return Err(ctx.err(format!(
                "converting curves to {other} is not supported (only to POLY)"
            )))
        }
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    super::curve_write::edit_curves(
        ctx,
        "Curve",
        Domain::Curve,
        &[(&sel, DataType::Bool)],
        &mut |c, r| {
            let sel = r[0].as_bool();
            let mut types: Vec<i8> = c
                .ints("curve_type", Domain::Curve, 0)
                .iter()
                .map(|v| *v as i8)
                .collect();
            for i in 0..types.len() {
                if sel[i] {
                    types[i] = target;
                }
            }
            c.set_i8("curve_type", Domain::Curve, types);
            remove_attributes_based_on_types(c);
            Ok(())
        },
    )
}
