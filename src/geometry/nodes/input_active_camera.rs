//! Active Camera (`node_geo_input_active_camera`): the scene's camera object at the
//! evaluated frame, switched at timeline markers bound to cameras as Blender's render
//! pipeline switches it before it evaluates the frame (`Scene::camera_at`).

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::value::SocketValue;

pub fn active_camera(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let session = ctx.session();
    let camera = session
        .scene
        .camera_at(session.frame)
        .map_err(|e| ctx.err(e))?;
    Ok(Outputs::from([(
        "Active Camera".to_string(),
        SocketValue::Object(camera.map(str::to_string)),
    )]))
}
