//! Active Camera (`node_geo_input_active_camera`): the scene's camera object. Blender
//! switches it at timeline markers bound to cameras; blendsynth does not follow that
//! switch, so a scene with such markers is refused by name rather than given the
//! exported frame's camera at every frame.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::value::SocketValue;

pub fn active_camera(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let s = &ctx.session().scene.file.scene;
    if let Some(why) = s.camera_switching() {
        return Err(ctx.err(why));
    }
    Ok(Outputs::from([(
        "Active Camera".to_string(),
        SocketValue::Object(s.camera.clone()),
    )]))
}
