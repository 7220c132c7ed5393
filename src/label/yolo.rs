//! YOLO labels (Ultralytics layout): `labels/SPLIT/NAME.txt` beside
//! `images/SPLIT/NAME.png`, one line per box, `class cx cy w h` normalised to [0, 1];
//! and `data.yaml` naming the splits and classes.

use super::record::Annotation;

pub fn label_text(annotations: &[Annotation], width: u32, height: u32) -> String {
    let (w, h) = (width as f64, height as f64);
    let mut s = String::new();
    for a in annotations {
        let [x, y, bw, bh] = a.bbox.map(|v| v as f64);
        s.push_str(&format!("{} {:.6} {:.6} {:.6} {:.6}\n", a.category_id - 1, (x + bw / 2.0) / w, (y + bh / 2.0) / h, bw / w, bh / h));
    }
    s
}

/// `data.yaml` for Ultralytics: split folders relative to the file's folder. No `path`
/// key: Ultralytics' `check_det_dataset` resolves a relative `path` (even `.`) against
/// the working directory, but without one it uses the YAML file's own folder.
pub fn data_yaml(splits: &[String], names: &[String]) -> String {
    let mut s = String::from("# Ultralytics dataset written by blendsynth; paths are relative to this file's folder.\n");
    for sp in splits {
        s.push_str(&format!("{sp}: images/{sp}\n"));
    }
    s.push_str(&format!("nc: {}\nnames:\n", names.len()));
    for (i, n) in names.iter().enumerate() {
        s.push_str(&format!("  {i}: {}\n", serde_json::to_string(n).unwrap()));
    }
    s
}
