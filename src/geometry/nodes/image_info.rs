//! Image Info (`node_geo_image_info`): an image's width, height, whether it has an alpha
//! channel, its frame count and frame rate, from the image file the export carries (as
//! Image Texture reads it). A still image has one frame at 0 fps whatever the Frame
//! input; no image, or one Blender cannot load (missing), gives the outputs' defaults.
//! Movies and sequences are refused with the image's name (as `image_file` refuses them),
//! and so are generated and packed-only images, whose pixels the export does not carry.

use image::ColorType;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::Value;
use super::super::value::SocketValue;
use crate::shader::images::image_file;

pub fn image_info(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let defaults = || -> Outputs {
        ctx.node()
            .outputs
            .iter()
            .map(|s| (s.identifier.clone(), SocketValue::zero(&s.kind)))
            .collect()
    };
    let name = match ctx.input("Image")? {
        SocketValue::Image(Some(n)) => n,
        SocketValue::Image(None) => return Ok(defaults()),
        other => {
            return Err(ctx.err(format!(
                "input \"Image\" is a {}, expected an image",
                other.kind()
            )))
        }
    };
    let scene = ctx.session().scene;
    if scene
        .file
        .images
        .iter()
        .any(|i| i.name == name && i.missing)
    {
        return Ok(defaults());
    }
    let file = image_file(scene, &name)
        .map_err(|e| ctx.err(e))?
        .ok_or_else(|| {
            ctx.err(format!(
                "image {name:?} has no file in the export (a generated image), so its size is unknown"
            ))
        })?;
    let img = crate::shader::images::decode(&file.path)
        .map_err(|e| ctx.err(format!("image {name:?}: {e}")))?;
    // ImBuf's planes are 32 for an image loaded with an alpha channel.
    let alpha = matches!(
        img.color(),
        ColorType::La8
            | ColorType::La16
            | ColorType::Rgba8
            | ColorType::Rgba16
            | ColorType::Rgba32F
    );
    let int = |v: u32| SocketValue::int(v.min(i32::MAX as u32) as i32);
    Ok(outputs([
        ("Width", int(img.width())),
        ("Height", int(img.height())),
        (
            "Has Alpha",
            SocketValue::Field(Field::Constant(Value::Bool(alpha))),
        ),
        ("Frame Count", SocketValue::int(1)),
        ("FPS", SocketValue::float(0.0)),
    ]))
}
