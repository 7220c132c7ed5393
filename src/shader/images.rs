//! Images for Image and Environment Texture nodes, loaded as Cycles' image manager
//! loads them (`scene/image.cpp`, `scene/image_oiio.cpp`): 8-bit files stay bytes and
//! 16-bit files stay shorts (read as v/255 and v/65535), float files (EXR) stay floats;
//! grey and RGB become RGBA; straight alpha is associated in the stored type unless the
//! image is data, channel-packed or has alpha off; sRGB images keep their encoding and
//! are decoded per lookup after interpolation; a missing file is Cycles' magenta.
//!
//! An image is loaded once and shared (`Arc`) by every program that samples it with the
//! same settings; the cache holds weak references, so a finished scene frees them.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock, Weak};

use crate::nodes::image::{finish_lookup, Extension, Interpolation, Pixels, MISSING};
use crate::scene::Scene;

/// The stored texels, in the type the file had (Cycles' BYTE4 / USHORT4 / FLOAT4).
#[derive(Debug)]
pub enum Texels {
    Byte(Vec<[u8; 4]>),
    Short(Vec<[u16; 4]>),
    Float(Vec<[f32; 4]>),
}

/// How an image's colour values are stored relative to the scene's linear space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Encoding {
    /// Scene linear or data: used as read.
    Raw,
    /// sRGB-encoded: decoded to linear after interpolation (`COMPRESS_AS_SRGB`).
    Srgb,
}

/// One loaded image.
#[derive(Debug)]
pub struct TexImage {
    pub width: i32,
    pub height: i32,
    pub texels: Texels,
    pub encoding: Encoding,
    /// Single-channel images read with alpha 1 (Cycles stores them as one float).
    pub single_channel: bool,
    /// Whether colours are data (Non-Color): never (un)associated.
    pub is_data: bool,
    /// The Blender alpha mode: `STRAIGHT`, `PREMUL`, `CHANNEL_PACKED` or `NONE`.
    pub alpha_mode: String,
}

impl TexImage {
    /// The 1x1 magenta image Cycles substitutes for one it cannot load.
    pub fn missing() -> TexImage {
        TexImage {
            width: 1,
            height: 1,
            texels: Texels::Float(vec![MISSING]),
            encoding: Encoding::Raw,
            single_channel: false,
            is_data: false,
            alpha_mode: "STRAIGHT".into(),
        }
    }

    /// Whether an Alpha output in use divides colour by alpha after interpolation.
    pub fn unassociates(&self) -> bool {
        !(self.is_data || self.alpha_mode == "CHANNEL_PACKED" || self.alpha_mode == "NONE")
    }

    /// A lookup as `svm_image_texture` does it: interpolate, unassociate if asked,
    /// decode sRGB.
    pub fn lookup(
        &self,
        x: f32,
        y: f32,
        interpolation: Interpolation,
        extension: Extension,
        unassociate: bool,
    ) -> [f32; 4] {
        let (w, h) = (self.width, self.height);
        let mut r = match &self.texels {
            Texels::Byte(d) => Pixels {
                data: d,
                width: w,
                height: h,
            }
            .interp(x, y, interpolation, extension),
            Texels::Short(d) => Pixels {
                data: d,
                width: w,
                height: h,
            }
            .interp(x, y, interpolation, extension),
            Texels::Float(d) => Pixels {
                data: d,
                width: w,
                height: h,
            }
            .interp(x, y, interpolation, extension),
        };
        if self.single_channel {
            r = [r[0], r[0], r[0], 1.0];
        }
        finish_lookup(r, unassociate, self.encoding == Encoding::Srgb)
    }
}

/// How a colour-space name maps to Cycles' handling. `scene_linear`: the config's
/// scene-linear space (Blender 4.5: "Linear Rec.709").
pub fn encoding_of(colorspace: &str) -> Result<(Encoding, bool), String> {
    match colorspace {
        "Non-Color" | "Raw" | "Generic Data" => Ok((Encoding::Raw, true)),
        "Linear Rec.709" | "Linear" | "scene_linear" => Ok((Encoding::Raw, false)),
        "sRGB" => Ok((Encoding::Srgb, false)),
        other => Err(format!("colour space {other:?} needs an OpenColorIO conversion, which image textures do not support yet (sRGB, Non-Color and Linear Rec.709 are supported)")),
    }
}

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
struct Key {
    path: PathBuf,
    modified: Option<std::time::SystemTime>,
    len: u64,
    colorspace: String,
    alpha_mode: String,
}

fn cache() -> &'static Mutex<HashMap<Key, Weak<TexImage>>> {
    static CACHE: OnceLock<Mutex<HashMap<Key, Weak<TexImage>>>> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

/// The image datablock `name` of `scene`, loaded (or shared if already loaded).
/// A missing or unreadable file gives Cycles' magenta image and a warning; an
/// unsupported colour space is an error.
pub fn scene_image(scene: &Scene, name: &str) -> Result<Arc<TexImage>, String> {
    let Some(f) = image_file(scene, name)? else {
        warn_missing(name, "its file was not exported (missing or generated)");
        return Ok(Arc::new(TexImage::missing()));
    };
    Ok(load_shared(
        &f.path,
        name,
        &f.colorspace,
        &f.alpha_mode,
        f.encoding,
        f.is_data,
    ))
}

/// Where an image datablock's file is and how its values are to be read.
pub struct ImageFile {
    pub path: PathBuf,
    pub colorspace: String,
    pub alpha_mode: String,
    pub encoding: Encoding,
    pub is_data: bool,
}

/// The file of image `name` (None when it was not exported: missing or generated); an
/// unsupported colour space or source is an error naming the image.
pub fn image_file(scene: &Scene, name: &str) -> Result<Option<ImageFile>, String> {
    let im = scene
        .file
        .images
        .iter()
        .find(|i| i.name == name)
        .ok_or_else(|| format!("no image {name:?} in the scene"))?;
    let colorspace = im.colorspace.clone().unwrap_or_else(|| "sRGB".into());
    let alpha_mode = im.alpha_mode.clone().unwrap_or_else(|| "STRAIGHT".into());
    let (encoding, is_data) =
        encoding_of(&colorspace).map_err(|e| format!("image {name:?}: {e}"))?;
    let Some(rel) = im.file.as_deref().filter(|_| !im.missing) else {
        return Ok(None);
    };
    if matches!(im.source.as_deref(), Some("SEQUENCE" | "MOVIE" | "TILED")) {
        return Err(format!(
            "image {name:?}: source {} (sequences, movies, UDIM tiles) is not supported yet",
            im.source.as_deref().unwrap_or("")
        ));
    }
    let path = scene
        .resolve(rel, &format!("images[{name:?}].file"))
        .map_err(|e| e.to_string())?;
    Ok(Some(ImageFile {
        path,
        colorspace,
        alpha_mode,
        encoding,
        is_data,
    }))
}

fn warn_missing(name: &str, why: &str) {
    eprintln!("warning: image {name:?}: {why}; rendering it magenta as Cycles does");
}

fn load_shared(
    path: &Path,
    name: &str,
    colorspace: &str,
    alpha_mode: &str,
    encoding: Encoding,
    is_data: bool,
) -> Arc<TexImage> {
    let meta = std::fs::metadata(path).ok();
    let key = Key {
        path: path.to_path_buf(),
        modified: meta.as_ref().and_then(|m| m.modified().ok()),
        len: meta.as_ref().map_or(0, |m| m.len()),
        colorspace: colorspace.into(),
        alpha_mode: alpha_mode.into(),
    };
    let mut c = cache().lock().unwrap_or_else(|e| e.into_inner());
    if let Some(img) = c.get(&key).and_then(Weak::upgrade) {
        return img;
    }
    let img = Arc::new(match load(path, encoding, is_data, alpha_mode) {
        Ok(i) => i,
        Err(e) => {
            warn_missing(name, &e);
            TexImage::missing()
        }
    });
    c.retain(|_, w| w.strong_count() > 0);
    c.insert(key, Arc::downgrade(&img));
    img
}

/// Reads and decodes an image file, whatever its format; errors name the file.
pub fn decode(path: &Path) -> Result<image::DynamicImage, String> {
    let reader = image::ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let tiff = reader.format() == Some(image::ImageFormat::Tiff);
    match reader.decode() {
        Ok(img) => Ok(img),
        // The image crate reads TIFF's 8- and 16-bit and float RGB(A) only; Blender (OIIO)
        // also reads grey and grey-alpha floats and 32-bit integers, as floats.
        Err(e) if tiff => decode_tiff_as_float(path)
            .map_err(|t| format!("cannot decode {}: {e} ({t})", path.display())),
        Err(e) => Err(format!("cannot decode {}: {e}", path.display())),
    }
}

/// A TIFF the image crate refuses, as RGBA floats: integers normalised to 0..1 (signed ones
/// to -1..1), grey spread to RGB, alpha 1 where there is none.
fn decode_tiff_as_float(path: &Path) -> Result<image::DynamicImage, String> {
    use tiff::decoder::{Decoder, DecodingResult as R};
    let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
    let mut d = Decoder::new(std::io::BufReader::new(file)).map_err(|e| e.to_string())?;
    let (w, h) = d.dimensions().map_err(|e| e.to_string())?;
    let channels = match d.colortype().map_err(|e| e.to_string())? {
        tiff::ColorType::Gray(_) => 1,
        tiff::ColorType::GrayA(_) => 2,
        tiff::ColorType::RGB(_) => 3,
        tiff::ColorType::RGBA(_) => 4,
        // Grey with an extra sample (the tiff crate's name for grey + alpha it does not
        // recognise), read as OIIO reads it: grey and alpha.
        tiff::ColorType::Multiband { num_samples: 2, .. } => 2,
        other => return Err(format!("TIFF colour type {other:?} is not read")),
    };
    let v: Vec<f32> = match d.read_image().map_err(|e| e.to_string())? {
        R::U8(v) => v.iter().map(|&x| x as f32 / u8::MAX as f32).collect(),
        R::U16(v) => v.iter().map(|&x| x as f32 / u16::MAX as f32).collect(),
        R::U32(v) => v
            .iter()
            .map(|&x| (x as f64 / u32::MAX as f64) as f32)
            .collect(),
        R::U64(v) => v
            .iter()
            .map(|&x| (x as f64 / u64::MAX as f64) as f32)
            .collect(),
        R::I8(v) => v.iter().map(|&x| x as f32 / i8::MAX as f32).collect(),
        R::I16(v) => v.iter().map(|&x| x as f32 / i16::MAX as f32).collect(),
        R::I32(v) => v
            .iter()
            .map(|&x| (x as f64 / i32::MAX as f64) as f32)
            .collect(),
        R::I64(v) => v
            .iter()
            .map(|&x| (x as f64 / i64::MAX as f64) as f32)
            .collect(),
        R::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
        R::F32(v) => v,
        R::F64(v) => v.iter().map(|&x| x as f32).collect(),
    };
    let n = w as usize * h as usize;
    if v.len() < n * channels {
        return Err(format!("{} samples for {w}x{h}x{channels}", v.len()));
    }
    let mut rgba = Vec::with_capacity(n * 4);
    for p in v.chunks_exact(channels).take(n) {
        rgba.extend_from_slice(&match *p {
            [g] => [g, g, g, 1.0],
            [g, a] => [g, g, g, a],
            [r, g, b] => [r, g, b, 1.0],
            [r, g, b, a] => [r, g, b, a],
            _ => unreachable!("1 to 4 channels"),
        });
    }
    image::Rgba32FImage::from_raw(w, h, rgba)
        .map(image::DynamicImage::ImageRgba32F)
        .ok_or_else(|| "buffer size".to_string())
}

/// `w` x `h` pixels reordered from the file's top-row-first to Blender's and Cycles'
/// bottom-row-first.
pub fn flip_rows<T: Copy>(px: &[T], w: usize, h: usize) -> Vec<T> {
    let mut out = Vec::with_capacity(px.len());
    for y in (0..h).rev() {
        out.extend_from_slice(&px[y * w..(y + 1) * w]);
    }
    out
}

/// Decodes `path` into Cycles' storage for an image with these settings.
pub fn load(
    path: &Path,
    encoding: Encoding,
    is_data: bool,
    alpha_mode: &str,
) -> Result<TexImage, String> {
    use image::DynamicImage as D;
    let img = decode(path)?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return Err(format!("{} is empty", path.display()));
    }
    let channels = img.color().channel_count();
    let has_alpha = img.color().has_alpha();
    // Straight alpha is associated at load for colour images (OIIO reports PNG, TGA, ...
    // as unassociated; EXR is already associated). Non-Color, channel-packed and
    // alpha-off images keep their channels.
    let associate = !(is_data || alpha_mode == "CHANNEL_PACKED" || alpha_mode == "NONE");
    let is_exr = matches!(img, D::ImageRgb32F(_) | D::ImageRgba32F(_));
    let ignore_alpha = alpha_mode == "NONE";
    let texels = match img {
        D::ImageLuma8(_) | D::ImageLumaA8(_) | D::ImageRgb8(_) | D::ImageRgba8(_) => {
            let mut px: Vec<[u8; 4]> = img.to_rgba8().pixels().map(|p| p.0).collect();
            for p in &mut px {
                if ignore_alpha {
                    p[3] = 255;
                } else if associate && has_alpha {
                    let a = p[3] as u32;
                    for c in &mut p[..3] {
                        *c = ((*c as u32 * a) / 255) as u8;
                    }
                }
            }
            Texels::Byte(flip_rows(&px, w, h))
        }
        D::ImageLuma16(_) | D::ImageLumaA16(_) | D::ImageRgb16(_) | D::ImageRgba16(_) => {
            let mut px: Vec<[u16; 4]> = img.to_rgba16().pixels().map(|p| p.0).collect();
            for p in &mut px {
                if ignore_alpha {
                    p[3] = 65535;
                } else if associate && has_alpha {
                    let a = p[3] as u32;
                    for c in &mut p[..3] {
                        *c = ((*c as u32 * a) / 65535) as u16;
                    }
                }
            }
            Texels::Short(flip_rows(&px, w, h))
        }
        _ => {
            let mut px: Vec<[f32; 4]> = img.to_rgba32f().pixels().map(|p| p.0).collect();
            for p in &mut px {
                if ignore_alpha {
                    p[3] = 1.0;
                } else if associate && has_alpha && !is_exr {
                    let a = p[3];
                    for c in &mut p[..3] {
                        *c *= a;
                    }
                }
                // Cycles zeroes a float texel with any non-finite channel.
                if p.iter().any(|x| !x.is_finite()) {
                    *p = [0.0; 4];
                }
            }
            Texels::Float(flip_rows(&px, w, h))
        }
    };
    Ok(TexImage {
        width: w as i32,
        height: h as i32,
        texels,
        encoding,
        single_channel: channels == 1,
        is_data,
        alpha_mode: alpha_mode.into(),
    })
}
