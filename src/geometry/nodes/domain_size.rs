//! Domain Size (`node_geo_attribute_domain_size.cc`): the element counts of one component
//! of the geometry, zero for a component the geometry lacks. Only the top level counts:
//! instanced geometry is not looked into, as in Blender.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::value::SocketValue;

pub fn domain_size(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    let n = |c: usize| SocketValue::int(i32::try_from(c).unwrap_or(i32::MAX));
    let component = ctx.prop_str("component")?;
    Ok(match component {
        "MESH" => {
            let m = g.mesh.as_deref();
            outputs([
                ("Point Count", n(m.map_or(0, |m| m.positions.len()))),
                ("Edge Count", n(m.map_or(0, |m| m.edges.len()))),
                ("Face Count", n(m.map_or(0, |m| m.face_count()))),
                (
                    "Face Corner Count",
                    n(m.map_or(0, |m| m.corner_verts.len())),
                ),
            ])
        }
        "POINTCLOUD" => outputs([("Point Count", n(g.points.as_deref().map_or(0, |p| p.len())))]),
        "CURVE" => {
            let c = g.curves.as_deref();
            outputs([
                ("Point Count", n(c.map_or(0, |c| c.point_count()))),
                ("Spline Count", n(c.map_or(0, |c| c.curve_count()))),
            ])
        }
        "INSTANCES" => outputs([(
            "Instance Count",
            n(g.instances.as_deref().map_or(0, |i| i.len())),
        )]),
        // Blendsynth's geometry holds no Grease Pencil (Cycles does not render it), so the
        // layer count is Blender's for a geometry without one (Molecular Nodes' Cartoon
        // asks it of its protein's curves).
        "GREASEPENCIL" => outputs([("Layer Count", n(0))]),
        other => return Err(ctx.err(format!("component {other} is not supported"))),
    })
}
