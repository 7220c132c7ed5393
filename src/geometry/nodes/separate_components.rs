//! Separate Components (`node_geo_separate_components.cc`): each component of the
//! geometry on its own output. Grease Pencil, which blendsynth's geometry does not hold,
//! comes out empty.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::set::GeometrySet;
use super::super::value::SocketValue;

pub fn separate_components(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    let only = |s: GeometrySet| SocketValue::Geometry(s);
    Ok(outputs([
        (
            "Mesh",
            only(GeometrySet {
                mesh: g.mesh.clone(),
                ..GeometrySet::default()
            }),
        ),
        (
            "Curve",
            only(GeometrySet {
                curves: g.curves.clone(),
                ..GeometrySet::default()
            }),
        ),
        (
            "Point Cloud",
            only(GeometrySet {
                points: g.points.clone(),
                ..GeometrySet::default()
            }),
        ),
        (
            "Instances",
            only(GeometrySet {
                instances: g.instances.clone(),
                ..GeometrySet::default()
            }),
        ),
        (
            "Volume",
            only(GeometrySet {
                volume: g.volume.clone(),
                ..GeometrySet::default()
            }),
        ),
        ("Grease Pencil", only(GeometrySet::default())),
    ]))
}
