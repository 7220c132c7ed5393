//! YOLO labels (Ultralytics layout): `labels/SPLIT/NAME.txt` beside
//! `images/SPLIT/NAME.png`, one line per box, `class cx cy w h` normalised to [0, 1];
//! and `data.yaml` naming the splits and classes.

use super::record::Annotation;

pub fn label_text(annotations: &[Annotation], width: u32, height: u32) -> String {
    let (w, h) = (width as f64, height as f64);
    let mut s = String::new();
    for a in annotations {
        let [x, y, bw, bh] = a.bbox.map(|v| v as f64);
        s.push_str(&format!(
            "{} {:.6} {:.6} {:.6} {:.6}\n",
            a.category_id - 1,
            (x + bw / 2.0) / w,
            (y + bh / 2.0) / h,
            bw / w,
            bh / h
        ));
    }
    s
}

/// `data.yaml` for Ultralytics: split folders relative to the file's folder. No `path`
/// key: Ultralytics' `check_det_dataset` resolves a relative `path` (even `.`) against
/// the working directory, but without one it uses the YAML file's own folder.
pub fn data_yaml(splits: &[String], names: &[String]) -> String {
    let mut s = String::from(
        "# Ultralytics dataset written by blendsynth; paths are relative to this file's folder.\n",
    );
    for sp in splits {
        s.push_str(&format!("{sp}: images/{sp}\n"));
    }
    // Ultralytics requires `train` and `val`; a dataset made without one of them (one
    // split only) names its first split for it, so `check_det_dataset` accepts it.
    for need in ["train", "val"] {
        if let (false, Some(first)) = (splits.iter().any(|sp| sp == need), splits.first()) {
            s.push_str(&format!(
                "{need}: images/{first}  # no {need} split in this dataset\n"
            ));
        }
    }
    s.push_str(&format!("nc: {}\nnames:\n", names.len()));
    for (i, n) in names.iter().enumerate() {
        s.push_str(&format!("  {i}: {}\n", serde_json::to_string(n).unwrap()));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::data_yaml;

    #[test]
    fn a_single_split_also_serves_as_val() {
        let y = data_yaml(&["train".into()], &["polyp".into()]);
        assert!(
            y.contains("train: images/train\n") && y.contains("val: images/train "),
            "{y}"
        );
        let y = data_yaml(&["train".into(), "val".into()], &["polyp".into()]);
        assert_eq!(y.matches("val:").count(), 1, "{y}");
    }
}
