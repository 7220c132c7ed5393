//! `blendsynth preview`: a contact sheet of a dataset's first frames, each with its
//! semantic mask tinted over the image and its boxes outlined in the class colour, for
//! a person to check a dataset at a glance.

use std::path::Path;

use super::layout::{self, write_atomic};
use crate::label::record::FrameRecord;

const PALETTE: [[u8; 3]; 6] = [
    [255, 60, 60],
    [60, 220, 60],
    [60, 120, 255],
    [255, 200, 0],
    [255, 0, 255],
    [0, 230, 230],
];
const THUMB: u32 = 256;
const GAP: u32 = 4;

fn records(dir: &Path, count: usize) -> Result<Vec<FrameRecord>, String> {
    let jsonl = dir.join("frames.jsonl");
    let text = std::fs::read_to_string(&jsonl)
        .map_err(|e| format!("{}: {e} (not a finished dataset?)", jsonl.display()))?;
    text.lines()
        .take(count)
        .enumerate()
        .map(|(n, l)| {
            serde_json::from_str(l).map_err(|e| format!("{} line {}: {e}", jsonl.display(), n + 1))
        })
        .collect()
}

/// Writes the sheet; returns how many frames it shows.
pub fn contact_sheet(dir: &Path, output: &Path, count: usize) -> Result<usize, String> {
    let recs = records(dir, count.max(1))?;
    if recs.is_empty() {
        return Err(format!("{}: no frames", dir.display()));
    }
    let cols = (recs.len() as f64).sqrt().ceil() as u32;
    let rows = (recs.len() as u32).div_ceil(cols);
    let (sw, sh) = (cols * (THUMB + GAP) + GAP, rows * (THUMB + GAP) + GAP);
    let mut sheet = vec![40u8; (sw * sh * 3) as usize];
    for (n, r) in recs.iter().enumerate() {
        // The record's fields name files: only the layout's own paths are read.
        layout::check_split_name(&r.split)?;
        if r.image != layout::image_rel(&r.split, r.index) {
            return Err(format!(
                "{}: frame {}: image {:?} is not {:?}",
                dir.join("frames.jsonl").display(),
                r.index,
                r.image,
                layout::image_rel(&r.split, r.index)
            ));
        }
        let img_path = layout::image_path(dir, &r.split, r.index);
        let img = image::open(&img_path)
            .map_err(|e| format!("{}: {e}", img_path.display()))?
            .to_rgb8();
        if (img.width(), img.height()) != (r.width, r.height) {
            return Err(format!(
                "{}: {}x{}, but the frame is {}x{}",
                img_path.display(),
                img.width(),
                img.height(),
                r.width,
                r.height
            ));
        }
        let mask_path = layout::mask_path(dir, &r.split, r.index);
        // Masks are 8-bit, or 16-bit with more than 254 classes: read the values as
        // they are (a conversion would rescale them).
        let mask =
            match image::open(&mask_path).map_err(|e| format!("{}: {e}", mask_path.display()))? {
                image::DynamicImage::ImageLuma16(m) => m,
                other => {
                    let m = other.to_luma8();
                    image::ImageBuffer::from_fn(m.width(), m.height(), |x, y| {
                        image::Luma([m.get_pixel(x, y).0[0] as u16])
                    })
                }
            };
        if (mask.width(), mask.height()) != (r.width, r.height) {
            return Err(format!(
                "{}: {}x{}, but the frame is {}x{}",
                mask_path.display(),
                mask.width(),
                mask.height(),
                r.width,
                r.height
            ));
        }
        let scale = THUMB as f64 / r.width.max(r.height) as f64;
        let (tw, th) = (
            ((r.width as f64) * scale) as u32,
            ((r.height as f64) * scale) as u32,
        );
        let (ox, oy) = (
            GAP + (n as u32 % cols) * (THUMB + GAP),
            GAP + (n as u32 / cols) * (THUMB + GAP),
        );
        let mut put = |x: u32, y: u32, c: [u8; 3]| {
            if x < tw && y < th {
                let p = (((oy + y) * sw + ox + x) * 3) as usize;
                sheet[p..p + 3].copy_from_slice(&c);
            }
        };
        for y in 0..th {
            for x in 0..tw {
                let (sx, sy) = (
                    ((x as f64 + 0.5) / scale) as u32,
                    ((y as f64 + 0.5) / scale) as u32,
                );
                let (sx, sy) = (sx.min(r.width - 1), sy.min(r.height - 1));
                let mut c = img.get_pixel(sx, sy).0;
                let m = mask.get_pixel(sx, sy).0[0];
                if m > 0 {
                    let t = PALETTE[(m as usize - 1) % PALETTE.len()];
                    c = [0, 1, 2].map(|k| ((c[k] as u16 * 3 + t[k] as u16 * 2) / 5) as u8);
                }
                put(x, y, c);
            }
        }
        for a in &r.annotations {
            let t = PALETTE[(a.category_id as usize - 1) % PALETTE.len()];
            let [bx, by, bw, bh] = a.bbox;
            let x0 = (bx as f64 * scale) as u32;
            let y0 = (by as f64 * scale) as u32;
            let x1 = (((bx + bw) as f64 * scale) as u32)
                .saturating_sub(1)
                .max(x0);
            let y1 = (((by + bh) as f64 * scale) as u32)
                .saturating_sub(1)
                .max(y0);
            for x in x0..=x1 {
                put(x, y0, t);
                put(x, y1, t);
            }
            for y in y0..=y1 {
                put(x0, y, t);
                put(x1, y, t);
            }
        }
    }
    write_atomic(output, &layout::png_bytes(sw, sh, 3, &sheet)?)?;
    Ok(recs.len())
}
