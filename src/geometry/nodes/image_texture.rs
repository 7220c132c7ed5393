//! Image Texture (`GeometryNodeImageTexture`) as a field: the image as Blender's float
//! buffer (bytes / 255 turned scene-linear per the image's colour space and associated
//! with alpha, float files as stored), sampled by X and Y of the vector with the shared
//! texel lookup (`nodes::image`, Geometry Nodes' flavour), then the image's alpha mode
//! applied to the sample.

use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;
use crate::geometry::types::unit_to_byte;
use crate::nodes::image::{srgb_to_linear, Extension, Interpolation, Pixels};
use crate::shader::images::{self, flip_rows, image_file, Encoding, ImageFile};

/// An image's pixels as Blender's `ImBuf` float buffer: linear, rows bottom to top.
struct FloatImage {
    width: i32,
    height: i32,
    pixels: Vec<[f32; 4]>,
}

/// The image as `BKE_image_acquire_ibuf` + `IMB_float_from_byte` leave it: alpha handled
/// at load (`imb_handle_alpha`: filled for "None", premultiplied bytes unassociated in
/// bytes, straight float files associated), bytes / 255 made scene-linear and, unless
/// the channels are packed, associated.
fn decode(f: &ImageFile) -> Result<FloatImage, String> {
    use image::DynamicImage as D;
    let img = images::decode(&f.path)?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let packed = f.is_data || f.alpha_mode == "CHANNEL_PACKED";
    let ignore = f.alpha_mode == "NONE" && !f.is_data;
    let premul = f.alpha_mode == "PREMUL" && !packed;
    let rows: Vec<[f32; 4]> = match &img {
        D::ImageRgb32F(_) | D::ImageRgba32F(_) => {
            if f.encoding == Encoding::Srgb {
                return Err(
                    "float images in the sRGB colour space are not supported in Geometry Nodes yet"
                        .into(),
                );
            }
            img.to_rgba32f()
                .pixels()
                .map(|p| {
                    let mut p = p.0;
                    if ignore {
                        p[3] = 1.0;
                    } else if !packed && !premul {
                        // Straight float files are associated at load.
                        for k in 0..3 {
                            p[k] *= p[3];
                        }
                    }
                    p
                })
                .collect()
        }
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => img
            .to_rgba8()
            .pixels()
            .map(|p| {
                let mut b = p.0;
                if ignore {
                    b[3] = 255;
                } else if premul {
                    // IMB_unpremultiply_rect, in bytes.
                    let inv = if b[3] != 0 { 1.0 / b[3] as f32 } else { 1.0 };
                    for k in 0..3 {
                        b[k] = unit_to_byte(b[k] as f32 * inv);
                    }
                }
                let mut p = b.map(|v| v as f32 * (1.0 / 255.0));
                if f.encoding == Encoding::Srgb {
                    for c in &mut p[..3] {
                        *c = srgb_to_linear(*c);
                    }
                }
                if !packed {
                    for k in 0..3 {
                        p[k] *= p[3];
                    }
                }
                p
            })
            .collect(),
        _ => {
            // 16-bit files load as float, colour-converted and associated at load;
            // only opaque or straight ones are handled here.
            if premul && img.color().has_alpha() {
                return Err("16-bit images with premultiplied alpha are not supported in Geometry Nodes yet".into());
            }
            img.to_rgba32f()
                .pixels()
                .map(|p| {
                    let mut p = p.0;
                    if ignore {
                        p[3] = 1.0;
                    }
                    if f.encoding == Encoding::Srgb {
                        for c in &mut p[..3] {
                            *c = srgb_to_linear(*c);
                        }
                    }
                    if !packed {
                        for k in 0..3 {
                            p[k] *= p[3];
                        }
                    }
                    p
                })
                .collect()
        }
    };
    Ok(FloatImage {
        width: w as i32,
        height: h as i32,
        pixels: flip_rows(&rows, w, h),
    })
}

pub fn image_texture(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let interp_name = ctx.prop_str("interpolation")?;
    let interpolation = Interpolation::from_blender(interp_name)
        .ok_or_else(|| ctx.err(format!("interpolation {interp_name:?} is not supported")))?;
    let ext_name = ctx.prop_str("extension")?;
    let extension = Extension::from_blender(ext_name)
        .ok_or_else(|| ctx.err(format!("extension {ext_name:?} is not supported")))?;
    let name = match ctx.input("Image")? {
        SocketValue::Image(n) => n,
        other => {
            return Err(ctx.err(format!(
                "input \"Image\" is a {}, expected an image",
                other.kind()
            )))
        }
    };
    let Some(name) = name else {
        // No image: Blender sets the outputs' defaults.
        return Ok(outputs([
            (
                "Color",
                SocketValue::Field(Field::Constant(super::super::types::Value::Color([0.0; 4]))),
            ),
            ("Alpha", SocketValue::float(0.0)),
        ]));
    };
    let file = image_file(ctx.session().scene, &name)
        .map_err(|e| ctx.err(e))?
        .ok_or_else(|| {
            ctx.err(format!(
                "image {name:?} has no file in the export (missing or generated)"
            ))
        })?;
    let alpha_mode = if file.is_data {
        "CHANNEL_PACKED".to_string()
    } else {
        file.alpha_mode.clone()
    };
    if !matches!(
        alpha_mode.as_str(),
        "STRAIGHT" | "PREMUL" | "CHANNEL_PACKED" | "NONE"
    ) {
        return Err(ctx.err(format!(
            "image {name:?}: alpha mode {alpha_mode:?} is not supported"
        )));
    }
    let img = Arc::new(decode(&file).map_err(|e| ctx.err(format!("image {name:?}: {e}")))?);
    let outs = Field::op(
        "Image Texture",
        vec![ctx.field("Vector", DataType::Vector)?],
        vec![DataType::Color, DataType::Float],
        move |n, x| {
            let v = x[0].as_vector();
            let px = Pixels {
                data: &img.pixels,
                width: img.width,
                height: img.height,
            };
            let (mut col, mut alpha) = (Vec::with_capacity(n), Vec::with_capacity(n));
            for p in v.iter() {
                let mut c = px.interp_geometry_nodes(p[0], p[1], interpolation, extension);
                match alpha_mode.as_str() {
                    // The field's colours are associated: straight images are multiplied.
                    "STRAIGHT" => {
                        for k in 0..3 {
                            c[k] *= c[3];
                        }
                    }
                    "NONE" => c[3] = 1.0,
                    _ => {}
                }
                col.push(c);
                alpha.push(c[3]);
            }
            Ok(vec![Array::Color(col), Array::Float(alpha)])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = outs.into_iter();
    Ok(outputs([
        ("Color", SocketValue::Field(it.next().unwrap())),
        ("Alpha", SocketValue::Field(it.next().unwrap())),
    ]))
}
