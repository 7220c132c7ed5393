//! Per-instance masks and boxes from the instance pass.
//!
//! The drop rule: an instance is labelled when its object has a class and at least
//! `min_pixels` of its pixels are visible (id pass from the primary ray through each
//! pixel centre). Fully occluded or off-screen instances have no pixels and drop out;
//! tiny ones (fewer than `min_pixels`, default 16) are dropped too, so no box is made
//! from a few stray pixels. A box is the extent of the visible pixels (COCO
//! [x, y, w, h] in pixels), not of the projected geometry.

use super::{rle, ClassMap, FrameIds};

#[derive(Debug, Clone, PartialEq)]
pub struct InstanceLabel {
    /// Index into `FrameIds::instances`.
    pub instance: usize,
    /// Index into `ClassMap::names`.
    pub class: usize,
    /// Visible pixels.
    pub area: u64,
    /// [x, y, w, h] of the visible pixels.
    pub bbox: [u32; 4],
    /// COCO RLE counts (column-major), for classes with masks.
    pub rle: Option<Vec<u32>>,
    /// Smallest camera-space depth over the visible pixels, when depth was rendered.
    pub nearest_depth: Option<f32>,
}

/// Labels the instances of one frame, in instance order.
pub fn extract(
    ids: &FrameIds,
    classes: &ClassMap,
    min_pixels: u64,
) -> Result<Vec<InstanceLabel>, String> {
    ids.check()?;
    let n = ids.instances.len();
    let w = ids.width as usize;
    // Per instance: count, x0, y0, x1, y1, nearest depth.
    let mut stats = vec![(0u64, usize::MAX, usize::MAX, 0usize, 0usize, f32::INFINITY); n];
    for (p, &id) in ids.instance_id.iter().enumerate() {
        if id == 0 {
            continue;
        }
        let s = &mut stats[id as usize - 1];
        let (x, y) = (p % w, p / w);
        s.0 += 1;
        s.1 = s.1.min(x);
        s.2 = s.2.min(y);
        s.3 = s.3.max(x);
        s.4 = s.4.max(y);
        if let Some(d) = &ids.depth {
            s.5 = s.5.min(d[p]);
        }
    }
    let mut out = Vec::new();
    for (i, s) in stats.iter().enumerate() {
        let Some(class) = classes.class_of(&ids.instances[i].object) else {
            continue;
        };
        if s.0 == 0 || s.0 < min_pixels {
            continue;
        }
        let want = (i + 1) as u32;
        let rle = classes.masks[class]
            .then(|| rle::counts(ids.width, ids.height, |p| ids.instance_id[p] == want));
        out.push(InstanceLabel {
            instance: i,
            class,
            area: s.0,
            bbox: [
                s.1 as u32,
                s.2 as u32,
                (s.3 - s.1 + 1) as u32,
                (s.4 - s.2 + 1) as u32,
            ],
            rle,
            nearest_depth: ids.depth.as_ref().map(|_| s.5),
        });
    }
    Ok(out)
}

/// The semantic mask: per pixel 0 for background, else 1 + the class of the labelled
/// instance seen there (classes beyond 65534 do not fit and saturate; `generate`
/// refuses that many classes).
pub fn semantic(ids: &FrameIds, labels: &[InstanceLabel]) -> Vec<u16> {
    let mut class_of = vec![0u16; ids.instances.len() + 1];
    for l in labels {
        class_of[l.instance + 1] = u16::try_from(l.class + 1).unwrap_or(u16::MAX);
    }
    ids.instance_id
        .iter()
        .map(|&id| class_of[id as usize])
        .collect()
}
