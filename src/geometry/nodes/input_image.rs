//! Image (`node_geo_input_image`): the node's image, for Image Info and Image Texture.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::input::id_input;

pub fn input_image(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    id_input(ctx, "image", "IMAGE", "Image")
}
