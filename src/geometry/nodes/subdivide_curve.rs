//! Subdivide Curve (`node_geo_curve_subdivide`): every curve, Cuts per point (the
//! segment that starts there), by `geometry::subdivide_curves`.

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::subdivide_curves::subdivide_curves;
use super::super::types::{DataType, Domain};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

pub fn subdivide_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let cuts = ctx.field("Cuts", DataType::Int)?;
    // A single Cuts below 1 leaves the curves as they are (handle types included).
    if cuts.as_constant().is_some_and(|v| v.as_int() < 1) {
        return Ok(outputs([("Curve", geo(g))]));
    }
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        if c.point_count() == 0 {
            return Ok(());
        }
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Point,
            &[(&cuts, DataType::Int)],
        )?;
        s.curves = Some(Arc::new(subdivide_curves(&c, &r[0].as_int())?));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}
