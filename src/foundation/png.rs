//! PNG encoding for label images (ids, masks, depth in 16 bits, previews). Colour-managed
//! renders are written by `color::write`, which quantises as Blender does first.

use image::ImageEncoder;

/// 8-bit PNG bytes with 1 (grey), 3 (RGB) or 4 (RGBA) channels.
pub fn png_bytes(width: u32, height: u32, channels: u8, data: &[u8]) -> Result<Vec<u8>, String> {
    let kind = match channels {
        1 => image::ExtendedColorType::L8,
        3 => image::ExtendedColorType::Rgb8,
        4 => image::ExtendedColorType::Rgba8,
        _ => return Err(format!("{channels} channels")),
    };
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(data, width, height, kind)
        .map_err(|e| format!("PNG encode: {e}"))?;
    Ok(out)
}

/// 16-bit grey PNG bytes.
pub fn png16_bytes(width: u32, height: u32, data: &[u16]) -> Result<Vec<u8>, String> {
    // The encoder takes native-endian samples (it writes PNG big-endian itself).
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_ne_bytes()).collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&bytes, width, height, image::ExtendedColorType::L16)
        .map_err(|e| format!("PNG encode: {e}"))?;
    Ok(out)
}
