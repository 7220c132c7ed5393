//! Image writers. Each writes to a temporary file beside the target and renames it into
//! place, so a reader never sees a half-written image.

use std::io::Write;
use std::path::Path;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ImageBuffer, ImageEncoder, Rgb, Rgba};

use super::ColorError;

fn werr(path: &Path, msg: impl std::fmt::Display) -> ColorError {
    ColorError::Write {
        path: path.to_path_buf(),
        message: msg.to_string(),
    }
}

fn check(path: &Path, width: u32, height: u32, n: usize) -> Result<(), ColorError> {
    if width == 0 || height == 0 {
        return Err(werr(
            path,
            format!("cannot write an empty {width}x{height} image"),
        ));
    }
    if (width as usize) * (height as usize) != n {
        return Err(werr(
            path,
            format!(
                "{width}x{height} image needs {} pixels, got {n}",
                width as u64 * height as u64
            ),
        ));
    }
    Ok(())
}

pub use crate::foundation::files::user_file_permissions;

/// Writes through `f` atomically (the one writer in `foundation::files`).
fn atomic(
    path: &Path,
    f: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<(), ColorError> {
    crate::foundation::files::write_atomic_with(path, f).map_err(|m| werr(path, m))
}

/// Display value to an n-bit code, rounding half up and clamping, as Blender does.
#[inline]
pub fn quantize(v: f32, max: f32) -> f32 {
    if !(v > 0.0) {
        0.0
    } else if v >= 1.0 {
        max
    } else {
        (v * max + 0.5).floor().min(max)
    }
}

/// PNG, 8 or 16 bits per channel. `pixels` are display-referred premultiplied RGBA (as
/// `to_display` leaves them); with `alpha` the colour is un-premultiplied, since PNG stores
/// straight alpha, and without it the colour is written as is (over black).
pub fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
    sixteen_bit: bool,
    alpha: bool,
) -> Result<(), ColorError> {
    check(path, width, height, pixels.len())?;
    let straight = |p: &[f32; 4]| -> [f32; 4] {
        if alpha && p[3] > 0.0 && p[3] != 1.0 {
            [p[0] / p[3], p[1] / p[3], p[2] / p[3], p[3]]
        } else {
            *p
        }
    };
    atomic(path, |w| {
        let enc = PngEncoder::new_with_quality(w, CompressionType::Default, FilterType::Adaptive);
        let max = if sixteen_bit { 65535.0 } else { 255.0 };
        match (sixteen_bit, alpha) {
            (true, true) => {
                let img: ImageBuffer<Rgba<u16>, Vec<u16>> =
                    ImageBuffer::from_fn(width, height, |x, y| {
                        let p = straight(&pixels[(y * width + x) as usize]);
                        Rgba(p.map(|v| quantize(v, max) as u16))
                    });
                img.write_with_encoder(enc).map_err(|e| e.to_string())
            }
            (true, false) => {
                let img: ImageBuffer<Rgb<u16>, Vec<u16>> =
                    ImageBuffer::from_fn(width, height, |x, y| {
                        let p = pixels[(y * width + x) as usize];
                        Rgb([p[0], p[1], p[2]].map(|v| quantize(v, max) as u16))
                    });
                img.write_with_encoder(enc).map_err(|e| e.to_string())
            }
            (false, true) => {
                let buf: Vec<u8> = pixels
                    .iter()
                    .flat_map(|p| straight(p).map(|v| quantize(v, max) as u8))
                    .collect();
                enc.write_image(&buf, width, height, image::ExtendedColorType::Rgba8)
                    .map_err(|e| e.to_string())
            }
            (false, false) => {
                let buf: Vec<u8> = pixels
                    .iter()
                    .flat_map(|p| [p[0], p[1], p[2]].map(|v| quantize(v, max) as u8))
                    .collect();
                enc.write_image(&buf, width, height, image::ExtendedColorType::Rgb8)
                    .map_err(|e| e.to_string())
            }
        }
    })
}

/// Linear float RGBA OpenEXR (the pixels as given, no colour management).
pub fn write_exr(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
) -> Result<(), ColorError> {
    check(path, width, height, pixels.len())?;
    let bytes =
        crate::foundation::exr::rgba_bytes(width, height, pixels).map_err(|m| werr(path, m))?;
    atomic(path, |w| w.write_all(&bytes).map_err(|e| e.to_string()))
}
