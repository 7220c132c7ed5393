//! COCO instances files, one per split, from the per-frame records: image ids are the
//! frame index + 1, annotation ids count up over frames in index order, so the file is
//! the same however the frames were produced (one process, shards, resumed runs).

use serde_json::{json, Value};

use super::record::FrameRecord;

/// The COCO JSON of the frames of one split. `records` are all frames of the dataset in
/// index order, so annotation ids are unique across splits too.
pub fn instances(
    records: &[FrameRecord],
    split: &str,
    names: &[String],
    description: &str,
) -> Value {
    let categories: Vec<Value> = names
        .iter()
        .enumerate()
        .map(|(i, n)| json!({"id": i + 1, "name": n, "supercategory": "tissue"}))
        .collect();
    let mut images = Vec::with_capacity(records.len());
    let mut annotations = Vec::new();
    let mut next_id = 1u64;
    for r in records {
        if r.split != split {
            next_id += r.annotations.len() as u64;
            continue;
        }
        let file = r.image.rsplit('/').next().unwrap_or(&r.image);
        images.push(json!({"id": r.index + 1, "file_name": file, "width": r.width, "height": r.height, "frame": r.frame}));
        for a in &r.annotations {
            let mut ann = json!({
                "id": next_id,
                "image_id": r.index + 1,
                "category_id": a.category_id,
                "bbox": a.bbox,
                "area": a.area,
                "iscrowd": 0,
            });
            if let Some(c) = &a.rle {
                ann["segmentation"] = json!({"size": [r.height, r.width], "counts": c});
            } else {
                // No mask for this class: its box as a polygon, which COCO tools accept.
                let [x, y, w, h] = a.bbox.map(|v| v as f64);
                ann["segmentation"] = json!([[x, y, x + w, y, x + w, y + h, x, y + h]]);
            }
            annotations.push(ann);
            next_id += 1;
        }
    }
    json!({
        "info": {"description": description, "version": "1.0"},
        "licenses": [],
        "images": images,
        "annotations": annotations,
        "categories": categories,
    })
}
