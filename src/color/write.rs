//! Image writers. Each writes to a temporary file beside the target and renames it into
//! place, so a reader never sees a half-written image.

use std::io::{BufWriter, Write};
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

/// For the temporary file an output is written to before it is renamed into place: an
/// image is a file the user asked for, so it gets the mode any program's new file gets
/// (0666 less the umask), not a temporary file's private 0600.
pub fn user_file_permissions() -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::Permissions::from_mode(0o666)
}

/// Writes through `f` into a temp file in the target's folder, then renames it over `path`.
fn atomic(
    path: &Path,
    f: impl FnOnce(&mut BufWriter<&mut std::fs::File>) -> Result<(), String>,
) -> Result<(), ColorError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".blendsynth-")
        .suffix(".tmp")
        .permissions(user_file_permissions())
        .tempfile_in(dir)
        .map_err(|e| {
            werr(
                path,
                format!("cannot create a temporary file in {}: {e}", dir.display()),
            )
        })?;
    {
        let mut w = BufWriter::new(tmp.as_file_mut());
        f(&mut w).map_err(|m| werr(path, m))?;
        w.flush().map_err(|e| werr(path, e))?;
    }
    tmp.persist(path).map_err(|e| werr(path, e.error))?;
    Ok(())
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
    let buf: Vec<f32> = pixels.iter().flatten().copied().collect();
    let img: ImageBuffer<Rgba<f32>, Vec<f32>> = ImageBuffer::from_raw(width, height, buf)
        .ok_or_else(|| werr(path, "pixel buffer size mismatch"))?;
    atomic(path, |w| {
        let enc = image::codecs::openexr::OpenExrEncoder::new(w);
        img.write_with_encoder(enc).map_err(|e| e.to_string())
    })
}
