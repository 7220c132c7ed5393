//! Float OpenEXR encoding. One encoder for every EXR blendsynth writes (renders, passes,
//! bakes), written block by block in order: the `image` crate's encoder compresses blocks
//! in parallel and writes them as they finish, so the same pixels gave different file
//! bytes from run to run, and a dataset could not be compared byte for byte.

use ::exr::prelude::*;

/// RLE in 64-pixel tiles (the `exr` crate's fast lossless default), stored in
/// increasing order so the file layout does not depend on which block finished first.
const ENCODING: Encoding = Encoding {
    compression: Compression::RLE,
    blocks: Blocks::Tiles(Vec2(64, 64)),
    line_order: LineOrder::Increasing,
};

/// Linear float RGBA EXR bytes; `pixels` row by row from the top.
pub fn rgba_bytes(
    width: u32,
    height: u32,
    pixels: &[[f32; 4]],
) -> std::result::Result<Vec<u8>, String> {
    check(width, height, pixels.len())?;
    let w = width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = pixels[y * w + x];
        (p[0], p[1], p[2], p[3])
    });
    encode(&Image::from_encoded_channels(
        (w, height as usize),
        ENCODING,
        channels,
    ))
}

/// Linear float RGB EXR bytes; `pixels` row by row from the top.
pub fn rgb_bytes(
    width: u32,
    height: u32,
    pixels: &[[f32; 3]],
) -> std::result::Result<Vec<u8>, String> {
    check(width, height, pixels.len())?;
    let w = width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = pixels[y * w + x];
        (p[0], p[1], p[2])
    });
    encode(&Image::from_encoded_channels(
        (w, height as usize),
        ENCODING,
        channels,
    ))
}

/// One float32 channel named "Y" (read as grey by OpenEXR tools and OpenCV) as EXR bytes.
pub fn grey_bytes(width: u32, height: u32, data: &[f32]) -> std::result::Result<Vec<u8>, String> {
    check(width, height, data.len())?;
    let channel = AnyChannel::new("Y", FlatSamples::F32(data.to_vec()));
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        ENCODING,
        AnyChannels::sort(vec![channel].into()),
    );
    encode(&Image::from_layer(layer))
}

/// Float32 channels with the given names (sorted by name in the file, as EXR requires)
/// as EXR bytes; each channel row by row from the top.
pub fn channels_bytes(
    width: u32,
    height: u32,
    channels: &[(&str, Vec<f32>)],
) -> std::result::Result<Vec<u8>, String> {
    let mut list = Vec::new();
    for (name, data) in channels {
        check(width, height, data.len())?;
        list.push(AnyChannel::new(*name, FlatSamples::F32(data.clone())));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        LayerAttributes::default(),
        ENCODING,
        AnyChannels::sort(list.into()),
    );
    encode(&Image::from_layer(layer))
}

/// The image's bytes, its blocks compressed and written one after another.
fn encode<'i, L: ::exr::image::write::layers::WritableLayers<'i>>(
    image: &'i Image<L>,
) -> std::result::Result<Vec<u8>, String> {
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| format!("EXR encode: {e}"))?;
    Ok(out.into_inner())
}

fn check(width: u32, height: u32, n: usize) -> std::result::Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("cannot write an empty {width}x{height} image"));
    }
    if (width as usize) * (height as usize) != n {
        return Err(format!(
            "{width}x{height} image needs {} pixels, got {n}",
            width as u64 * height as u64
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_pixels_give_the_same_bytes_and_read_back_exactly() {
        let (w, h) = (300u32, 211u32);
        let px: Vec<[f32; 4]> = (0..w * h)
            .map(|i| {
                let f = i as f32;
                [f.sin() * 3.0, f * 1e-3, -f, (i % 7) as f32 / 7.0]
            })
            .collect();
        let a = rgba_bytes(w, h, &px).unwrap();
        for _ in 0..8 {
            assert_eq!(rgba_bytes(w, h, &px).unwrap(), a);
        }
        let img = image::load_from_memory_with_format(&a, image::ImageFormat::OpenExr)
            .unwrap()
            .into_rgba32f();
        assert_eq!((img.width(), img.height()), (w, h));
        for (i, p) in img.pixels().enumerate() {
            assert_eq!(p.0, px[i], "pixel {i}");
        }
        assert!(rgb_bytes(0, 3, &[]).is_err());
        assert!(rgba_bytes(2, 2, &px[..3]).is_err());
    }
}
