//! Linear Gizmo (`node_geo_gizmo_linear`): a viewport handle for a value. Blender evaluates a gizmo
//! node only when a viewport asks to draw it (a side-effect node); in a render or
//! modifier evaluation its inputs are never requested and its Transform output is an
//! empty geometry (`LazyFunctionForGizmoNode`), which is what this gives.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::set::GeometrySet;
use super::super::value::SocketValue;

pub fn gizmo_linear(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(Outputs::from([(
        "Transform".to_string(),
        SocketValue::Geometry(GeometrySet::default()),
    )]))
}
