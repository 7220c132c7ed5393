//! The dataset-wide files, written from the finished frames alone (so a dataset made
//! by one process, by shards then `merge`, or by a resumed run is byte-identical):
//! `frames.jsonl`, `annotations/instances_SPLIT.json` (COCO), `data.yaml` (YOLO), and per
//! sequence `sequences/S/trajectory.txt` (TUM) and COLMAP's text model.

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::layout::{self, write_atomic};
use crate::label::coco;
use crate::label::record::FrameRecord;
use crate::label::trajectory;
use crate::label::yolo;

fn read_record(out: &Path, i: u64) -> Result<FrameRecord, String> {
    let p = layout::record_path(out, i);
    let bytes = std::fs::read(&p).map_err(|e| format!("{}: {e}", p.display()))?;
    serde_json::from_slice(&bytes).map_err(|e| format!("{}: {e}", p.display()))
}

/// Writes the dataset-wide files over frames `indices` (all must be finished).
pub fn finalize(
    out: &Path,
    indices: &[u64],
    splits: &[String],
    class_names: &[String],
) -> Result<(), String> {
    let records = indices
        .iter()
        .map(|&i| read_record(out, i))
        .collect::<Result<Vec<_>, _>>()?;
    let mut jsonl = String::new();
    for r in &records {
        jsonl.push_str(&serde_json::to_string(r).unwrap());
        jsonl.push('\n');
    }
    write_atomic(&out.join("frames.jsonl"), jsonl.as_bytes())?;
    for s in splits {
        let c = coco::instances(&records, s, class_names, "blendsynth generate");
        write_atomic(
            &out.join("annotations").join(format!("instances_{s}.json")),
            serde_json::to_string(&c).unwrap().as_bytes(),
        )?;
    }
    write_atomic(
        &out.join("data.yaml"),
        yolo::data_yaml(splits, class_names).as_bytes(),
    )?;
    write_sequences(out, &records)
}

/// Each sequence's trajectory (TUM) and COLMAP model, from its records in frame order.
fn write_sequences(out: &Path, records: &[FrameRecord]) -> Result<(), String> {
    let mut by_sequence: std::collections::BTreeMap<u64, Vec<&FrameRecord>> =
        std::collections::BTreeMap::new();
    for r in records {
        if let Some(s) = r.sequence {
            by_sequence.entry(s).or_default().push(r);
        }
    }
    for (s, mut recs) in by_sequence {
        recs.sort_by_key(|r| r.sequence_frame);
        let dir = layout::sequence_dir(out, s);
        write_atomic(
            &dir.join("trajectory.txt"),
            trajectory::tum(&recs).as_bytes(),
        )?;
        if let Some(files) = trajectory::colmap(&recs) {
            for (name, text) in ["cameras.txt", "images.txt", "points3D.txt"]
                .iter()
                .zip(files)
            {
                write_atomic(&dir.join(name), text.as_bytes())?;
            }
        }
    }
    Ok(())
}

/// A shard's record of frame `i`, checked before any of its fields becomes a path: it
/// is frame `i`, its split is one of the dataset's, and its image is where the layout
/// puts it.
fn checked_record(dir: &Path, i: u64, splits: &[String]) -> Result<FrameRecord, String> {
    let rec = read_record(dir, i)?;
    let p = layout::record_path(dir, i);
    if rec.index != i {
        return Err(format!("{}: index is {}, not {i}", p.display(), rec.index));
    }
    if !splits.contains(&rec.split) {
        return Err(format!(
            "{}: split {:?} is not one of the dataset's ({})",
            p.display(),
            rec.split,
            splits.join(", ")
        ));
    }
    if rec.image != layout::image_rel(&rec.split, i) {
        return Err(format!(
            "{}: image {:?} is not {:?}",
            p.display(),
            rec.image,
            layout::image_rel(&rec.split, i)
        ));
    }
    Ok(rec)
}

fn read_manifest(dir: &Path) -> Result<Value, String> {
    let p = dir.join("manifest.json");
    let b = std::fs::read(&p)
        .map_err(|e| format!("{}: {e} (not a blendsynth dataset?)", p.display()))?;
    serde_json::from_slice(&b).map_err(|e| format!("{}: {e}", p.display()))
}

/// Joins shard folders into `out`: the manifests must agree (apart from the shard) and
/// together hold every frame. The result equals a single run of all frames.
pub fn merge(shards: &[PathBuf], out: &Path) -> Result<u64, String> {
    if shards.is_empty() {
        return Err("merge needs at least one dataset folder".into());
    }
    let mut manifest = read_manifest(&shards[0])?;
    manifest["shard"] = Value::Null;
    for s in &shards[1..] {
        let mut m = read_manifest(s)?;
        m["shard"] = Value::Null;
        if m != manifest {
            return Err(format!(
                "{} was made with other settings than {} (scene, spec, seed, frames or split)",
                s.display(),
                shards[0].display()
            ));
        }
    }
    if out.join("manifest.json").exists()
        || out.exists()
            && std::fs::read_dir(out)
                .map(|mut d| d.next().is_some())
                .unwrap_or(false)
    {
        return Err(format!(
            "{} is not empty; merge writes into a new folder",
            out.display()
        ));
    }
    let man_path = shards[0].join("manifest.json");
    let frames = manifest["frames"]
        .as_u64()
        .ok_or_else(|| format!("{}: no frame count", man_path.display()))?;
    super::generate::check_frames(frames).map_err(|e| format!("{}: {e}", man_path.display()))?;
    let splits: Vec<String> = manifest["split"]
        .as_array()
        .ok_or_else(|| format!("{}: no split", man_path.display()))?
        .iter()
        .map(|s| {
            let name = s[0]
                .as_str()
                .ok_or_else(|| format!("{}: split {s} has no name", man_path.display()))?;
            layout::check_split_name(name).map_err(|e| format!("{}: {e}", man_path.display()))?;
            Ok(name.to_string())
        })
        .collect::<Result<_, String>>()?;
    let classes: Vec<String> = manifest["classes"]
        .as_array()
        .ok_or("manifest has no classes")?
        .iter()
        .filter_map(|s| s.as_str().map(String::from))
        .collect();
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let _lock = layout::lock(out)?;
    let mut missing = Vec::new();
    for i in 0..frames {
        let Some(src) = shards.iter().find(|s| layout::record_path(s, i).exists()) else {
            missing.push(i);
            continue;
        };
        let rec = checked_record(src, i, &splits)?;
        let mut files = vec![
            (
                layout::image_path(src, &rec.split, i),
                layout::image_path(out, &rec.split, i),
            ),
            (
                layout::mask_path(src, &rec.split, i),
                layout::mask_path(out, &rec.split, i),
            ),
            (
                layout::label_path(src, &rec.split, i),
                layout::label_path(out, &rec.split, i),
            ),
        ];
        // Depth, normals and the other optional files, where the shard has them.
        files.extend(
            layout::optional_frame_files(src, &rec.split, i)
                .into_iter()
                .zip(layout::optional_frame_files(out, &rec.split, i))
                .filter(|(a, _)| a.exists()),
        );
        // The record last: its presence marks the frame finished.
        files.push((layout::record_path(src, i), layout::record_path(out, i)));
        for (a, b) in files {
            let bytes = std::fs::read(&a).map_err(|e| format!("{}: {e}", a.display()))?;
            write_atomic(&b, &bytes)?;
        }
    }
    if !missing.is_empty() {
        let _ = std::fs::remove_dir_all(out);
        let shown: Vec<String> = missing.iter().take(10).map(|i| i.to_string()).collect();
        return Err(format!("{} of {frames} frames are in none of the shards (first: {}); finish them with generate --resume", missing.len(), shown.join(", ")));
    }
    write_atomic(
        &out.join("manifest.json"),
        format!("{}\n", serde_json::to_string_pretty(&manifest).unwrap()).as_bytes(),
    )?;
    let all: Vec<u64> = (0..frames).collect();
    finalize(out, &all, &splits, &classes)?;
    Ok(frames)
}
