//! Geometry to Instance (`node_geo_geometry_to_instance.cc`): each geometry linked into the
//! multi-input, empty ones included, becomes one instance of it at the identity
//! transform, in link order.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::instances::{InstanceReference, Instances};
use super::super::math::MAT4_IDENTITY;
use super::super::set::GeometrySet;
use super::super::value::SocketValue;

pub fn geometry_to_instance(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut instances = Instances::default();
    for v in ctx.inputs_multi("Geometry")? {
        if let SocketValue::Geometry(g) = v {
            let h = instances.add_reference(InstanceReference::Geometry(g));
            instances.handles.push(h);
            instances.transforms.push(MAT4_IDENTITY);
        }
    }
    let set = GeometrySet {
        instances: Some(std::sync::Arc::new(instances)),
        ..GeometrySet::default()
    };
    Ok(outputs([("Instances", SocketValue::Geometry(set))]))
}
