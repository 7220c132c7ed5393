//! `blendsynth generate`: renders a dataset's frames in parallel and labels them.
//!
//! Frame `i` depends only on (scene, spec, seed, i): its scene frame, parameter values
//! and render seed come from the spec's counter-based draws, its split from a
//! seed-keyed permutation of all frame indices. So a frame rendered alone, by another
//! shard, on another thread count or after a resume is the same bytes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use serde_json::{json, Value};

use super::finalize;
use super::layout::{self, write_atomic};
use super::renderer::FrameRenderer;
use super::rng;
use super::spec::Spec;
use crate::label::camera::{camera_info, CameraInfo};
use crate::label::record::{annotations, Bounds, FrameRecord};
use crate::label::{extract, instances::semantic, yolo, ClassMap};
use crate::scene::Scene;

/// See `GenerateOptions::after_write`.
pub type WriteHook = fn(u64, &Path) -> Result<(), String>;

#[derive(Debug, Clone)]
pub struct GenerateOptions {
    pub frames: u64,
    pub seed: u64,
    /// (split name, fraction); fractions sum to 1.
    pub split: Vec<(String, f64)>,
    /// (index, count), 0-based: this run renders frames with `i % count == index`.
    pub shard: (u64, u64),
    pub resume: bool,
    /// Frames rendered at once (each with `threads_per_frame` threads).
    pub jobs: usize,
    pub threads_per_frame: usize,
    pub progress: bool,
    /// Test hook: called after each file of a frame is written, with the frame index
    /// and the file; an error stops the run there (a crash mid-frame).
    pub after_write: Option<WriteHook>,
}

impl Default for GenerateOptions {
    fn default() -> Self {
        GenerateOptions {
            frames: 1,
            seed: 0,
            split: vec![("train".into(), 1.0)],
            shard: (0, 1),
            resume: false,
            jobs: 1,
            threads_per_frame: 1,
            progress: false,
            after_write: None,
        }
    }
}

/// Parses `train=0.9,val=0.1`.
pub fn parse_split(s: &str) -> Result<Vec<(String, f64)>, String> {
    let mut out = Vec::new();
    for part in s.split(',') {
        let (name, frac) = part
            .split_once('=')
            .ok_or_else(|| format!("split {part:?} is not NAME=FRACTION"))?;
        let name = name.trim();
        layout::check_split_name(name)?;
        let f: f64 = frac
            .trim()
            .parse()
            .map_err(|_| format!("split {name}: {frac:?} is not a number"))?;
        if !(0.0..=1.0).contains(&f) {
            return Err(format!("split {name}: {f} is not within [0, 1]"));
        }
        if out.iter().any(|(n, _)| n == name) {
            return Err(format!("split {name} appears twice"));
        }
        out.push((name.to_string(), f));
    }
    let sum: f64 = out.iter().map(|(_, f)| f).sum();
    if (sum - 1.0).abs() > 1e-9 {
        return Err(format!("split fractions sum to {sum}, not 1"));
    }
    Ok(out)
}

/// Parses `I/N` (0-based I).
pub fn parse_shard(s: &str) -> Result<(u64, u64), String> {
    let (i, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard {s:?} is not I/N"))?;
    let (i, n): (u64, u64) = (
        i.trim().parse().map_err(|_| format!("shard index {i:?}"))?,
        n.trim().parse().map_err(|_| format!("shard count {n:?}"))?,
    );
    if n == 0 || i >= n {
        return Err(format!("shard {i}/{n}: need 0 <= I < N (I is 0-based)"));
    }
    Ok((i, n))
}

/// The most frames a dataset can have: frame files are named by a 9-digit index, and
/// the dataset-wide files (COCO, frames.jsonl) hold every frame's record.
pub const MAX_FRAMES: u64 = 1_000_000_000;

/// Checks a dataset's frame count (`--frames`, a manifest's `frames`).
pub fn check_frames(frames: u64) -> Result<(), String> {
    if frames == 0 || frames > MAX_FRAMES {
        return Err(format!(
            "frames: {frames} is not within [1, {MAX_FRAMES}] (frame files are named by a 9-digit index)"
        ));
    }
    Ok(())
}

/// The split of every frame, without a table of frames: exact counts per split (largest
/// remainder); frames ordered by a seed-keyed hash so each split is a random subset,
/// identical on every shard. Split `k` holds the frames whose hash ranks in
/// [cut k-1, cut k); the hash is a bijection of the index (a chain of bijective mixes),
/// so ranks have no ties and each cut is one hash value, found by radix selection in
/// constant memory.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitPlan {
    seed: u64,
    /// The hash at each split boundary (None: past the last frame).
    cuts: Vec<Option<u64>>,
}

fn split_hash(seed: u64, i: u64) -> u64 {
    rng::bits(seed, i, rng::key("#split"), 0)
}

/// The value of rank `rank` (0-based) among `split_hash(seed, i)` for i in 0..frames:
/// four passes, each fixing 16 more bits of the answer.
fn select_hash(frames: u64, seed: u64, mut rank: u64) -> u64 {
    let mut prefix = 0u64;
    let mut hist = vec![0u64; 1 << 16];
    for level in 0..4 {
        let shift = 48 - 16 * level;
        let high = if level == 0 { 0 } else { !0u64 << (shift + 16) };
        hist.iter_mut().for_each(|h| *h = 0);
        for i in 0..frames {
            let x = split_hash(seed, i);
            if x & high == prefix {
                hist[((x >> shift) & 0xffff) as usize] += 1;
            }
        }
        let mut digit = 0;
        for (d, &c) in hist.iter().enumerate() {
            if rank < c {
                digit = d as u64;
                break;
            }
            rank -= c;
        }
        prefix |= digit << shift;
    }
    prefix
}

impl SplitPlan {
    pub fn new(frames: u64, seed: u64, split: &[(String, f64)]) -> SplitPlan {
        let n = frames as f64;
        let mut counts: Vec<u64> = split.iter().map(|(_, f)| (f * n).floor() as u64).collect();
        let mut rest: Vec<usize> = (0..split.len()).collect();
        rest.sort_by(|&a, &b| {
            let ra = split[a].1 * n - counts[a] as f64;
            let rb = split[b].1 * n - counts[b] as f64;
            rb.total_cmp(&ra).then(a.cmp(&b))
        });
        let mut left = frames.saturating_sub(counts.iter().sum::<u64>());
        for &k in rest.iter().cycle() {
            if left == 0 {
                break;
            }
            counts[k] += 1;
            left -= 1;
        }
        let mut pos = 0u64;
        let cuts = counts[..counts.len().saturating_sub(1)]
            .iter()
            .map(|c| {
                pos += c;
                (pos < frames).then(|| select_hash(frames, seed, pos))
            })
            .collect();
        SplitPlan { seed, cuts }
    }

    /// The split (index into the split list) of frame `i`.
    pub fn split_of(&self, i: u64) -> u16 {
        let h = split_hash(self.seed, i);
        self.cuts
            .iter()
            .filter(|c| c.is_some_and(|c| h >= c))
            .count() as u16
    }
}

/// The split of every frame as a table (for tests and small datasets; `generate` asks a
/// `SplitPlan` frame by frame).
pub fn assign_splits(frames: u64, seed: u64, split: &[(String, f64)]) -> Vec<u16> {
    let plan = SplitPlan::new(frames, seed, split);
    (0..frames).map(|i| plan.split_of(i)).collect()
}

/// The manifest: everything that determines the frames. Resume and merge require equal
/// manifests (apart from the shard).
pub fn manifest(scene: &Scene, spec: &Spec, opts: &GenerateOptions, classes: &ClassMap) -> Value {
    let scene_bytes = std::fs::read(scene.json_path()).unwrap_or_default();
    let scene_hash = format!("{:016x}", rng::key(&String::from_utf8_lossy(&scene_bytes)));
    json!({
        "format": "blendsynth-dataset",
        "version": 1,
        "scene": {"source_file": scene.file.source_file, "scene_json_fnv1a": scene_hash},
        "spec": spec.source,
        "seed": opts.seed,
        "frames": opts.frames,
        "split": opts.split.iter().map(|(n, f)| json!([n, f])).collect::<Vec<_>>(),
        "classes": classes.names,
        "shard": if opts.shard.1 > 1 { json!(format!("{}/{}", opts.shard.0, opts.shard.1)) } else { Value::Null },
    })
}

#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    pub rendered: u64,
    pub skipped: u64,
    pub seconds: f64,
    pub out: PathBuf,
    pub complete: bool,
}

/// The frame indices of shard `(index, count)` of a dataset of `frames` frames, lazily.
pub fn shard_frames(frames: u64, shard: (u64, u64)) -> impl Iterator<Item = u64> + Clone {
    (shard.0..frames).step_by(shard.1.clamp(1, usize::MAX as u64) as usize)
}

/// The frames of shard `(index, count)` when frames come in sequences of `length`: whole
/// sequences, sequence `s` in shard `s % count` (with `length` 1, `shard_frames`).
pub fn shard_sequence_frames(
    frames: u64,
    length: u64,
    shard: (u64, u64),
) -> impl Iterator<Item = u64> + Clone {
    let length = length.max(1);
    let n = shard.1.max(1);
    (0..frames).filter(move |i| (i / length) % n == shard.0)
}

/// Every frame of every sequence is a Blender frame: the schedule's starts are checked by
/// `FrameSchedule::check`; here the ends of the first, last and (wrapping) largest start.
fn check_sequence_frames(spec: &Spec, current: i64, sequences: u64) -> Result<(), String> {
    let Some(q) = &spec.sequence else {
        return Ok(());
    };
    let mut starts = vec![
        spec.frames.frame(current, 0),
        spec.frames.frame(current, sequences - 1),
    ];
    if let Some(m) = spec.frames.modulo {
        starts.extend([0, m - 1]);
    }
    for s in starts {
        let end = s as i128 + q.step as i128 * (q.length as i128 - 1);
        if !(super::spec::MIN_FRAME as i128..=super::spec::MAX_FRAME as i128).contains(&end) {
            return Err(format!("spec: sequence: a sequence starting at scene frame {s} would end at {end}, outside Blender's frame range"));
        }
    }
    Ok(())
}

/// The dataset folder is empty apart from `.partial` leftovers of a run killed before
/// its manifest was in place (a run killed while writing the manifest).
fn only_partials(out: &Path) -> bool {
    let Ok(entries) = std::fs::read_dir(out) else {
        return false;
    };
    entries.into_iter().all(|e| {
        e.is_ok_and(|e| {
            e.file_type().is_ok_and(|t| t.is_file())
                && e.file_name().to_string_lossy().ends_with(".partial")
        })
    })
}

/// Renders the frames of this shard that are not finished, then writes the COCO, YOLO
/// and JSONL files over the finished frames. Holds an exclusive lock on `out` while
/// it runs (see `layout::lock`), so a second writer is refused instead of deleting
/// this run's in-flight files.
// Long because the frame loop keeps resume, shards and progress in one place, so the order of writes (the record last) stays visible.
pub fn generate(
    scene: &Scene,
    spec: &Spec,
    renderer: &dyn FrameRenderer,
    out: &Path,
    opts: &GenerateOptions,
) -> Result<Summary, String> {
    let start = Instant::now();
    check_frames(opts.frames)?;
    if opts.shard.1 == 0 || opts.shard.0 >= opts.shard.1 {
        return Err(format!(
            "shard {}/{}: need 0 <= I < N",
            opts.shard.0, opts.shard.1
        ));
    }
    for w in spec.validate(scene).map_err(|e| e.to_string())? {
        eprintln!("warning: {w}");
    }
    // Refused up front, not at the first frame after the output folder is made.
    if spec.labels.motion() {
        if let Some(m) = crate::render::flow_refusal(scene) {
            return Err(m);
        }
    }
    let current = scene.file.scene.frame_current as i64;
    // Splits and shards hold whole sequences: the unit is a sequence, or a frame.
    let (units, length) = match &spec.sequence {
        Some(q) => {
            let n = q.sequences(opts.frames).map_err(|e| e.to_string())?;
            spec.frames.check(current, n).map_err(|e| e.to_string())?;
            check_sequence_frames(spec, current, n)?;
            (n, q.length)
        }
        None => {
            spec.frames
                .check(current, opts.frames)
                .map_err(|e| e.to_string())?;
            (opts.frames, 1)
        }
    };
    let classes = ClassMap::new(&spec.labels, scene);
    if classes.names.len() > layout::MAX_CLASSES {
        return Err(format!(
            "spec: labels: {} classes; masks hold at most {}",
            classes.names.len(),
            layout::MAX_CLASSES
        ));
    }
    let man = manifest(scene, spec, opts, &classes);
    let man_path = out.join("manifest.json");
    std::fs::create_dir_all(out).map_err(|e| format!("{}: cannot create: {e}", out.display()))?;
    let _lock = layout::lock(out)?;
    if man_path.exists() {
        let old: Value = serde_json::from_slice(
            &std::fs::read(&man_path).map_err(|e| format!("{}: {e}", man_path.display()))?,
        )
        .map_err(|e| format!("{}: {e}", man_path.display()))?;
        if !opts.resume {
            return Err(format!(
                "{} already holds a dataset; pass --resume to finish it, or choose another folder",
                out.display()
            ));
        }
        if old != man {
            return Err(format!("{}: made with other settings (scene, spec, seed, frames, split or shard); --resume needs the same ones", man_path.display()));
        }
        layout::remove_partials(out).map_err(|e| format!("{}: {e}", out.display()))?;
    } else {
        if !only_partials(out) {
            return Err(format!(
                "{} exists and is not a blendsynth dataset; choose an empty or new folder",
                out.display()
            ));
        }
        layout::remove_partials(out).map_err(|e| format!("{}: {e}", out.display()))?;
        write_atomic(
            &man_path,
            format!("{}\n", serde_json::to_string_pretty(&man).unwrap()).as_bytes(),
        )
        .map_err(|e| format!("{e} (nothing rendered yet; rerun with --resume)"))?;
    }
    let splits = SplitPlan::new(units, opts.seed, &opts.split);
    let mine = shard_sequence_frames(opts.frames, length, opts.shard);
    let mine_count = mine.clone().count() as u64;

    let scene_json = serde_json::to_value(&scene.file).map_err(|e| e.to_string())?;
    let ctx = FrameContext {
        scene,
        scene_json: &scene_json,
        spec,
        renderer,
        classes: &classes,
        out,
        opts,
        splits: &splits,
        bounds: Mutex::new(std::collections::HashMap::new()),
    };

    let bar = if opts.progress {
        let b = indicatif::ProgressBar::new(mine_count);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} frames {pos}/{len} [{elapsed_precise} < {eta_precise}] {per_sec} {msg}",
            )
            .unwrap(),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };
    // Workers take this shard's frames in order from a shared iterator and skip the
    // finished ones, so no list of frames is built.
    let queue = Mutex::new(mine.clone());
    let rendered = AtomicU64::new(0);
    let skipped = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    let first_error: Mutex<Option<(u64, String)>> = Mutex::new(None);
    let workers = (opts.jobs.max(1) as u64).min(mine_count.max(1)) as usize;
    let mut spawned = 0;
    let mut spawn_error = None;
    std::thread::scope(|s| {
        for _ in 0..workers {
            // A thread the system refuses ends the spawning (fewer workers), not a panic.
            let worker = std::thread::Builder::new().spawn_scoped(s, || loop {
                if stop.load(Ordering::Relaxed) {
                    return;
                }
                let Some(i) = queue.lock().unwrap().next() else {
                    return;
                };
                if layout::record_path(out, i).exists() {
                    skipped.fetch_add(1, Ordering::Relaxed);
                    bar.inc(1);
                    continue;
                }
                match ctx.frame(i) {
                    Ok(()) => {
                        rendered.fetch_add(1, Ordering::Relaxed);
                        bar.inc(1)
                    }
                    Err(e) => {
                        stop.store(true, Ordering::Relaxed);
                        let mut g = first_error.lock().unwrap();
                        if g.as_ref().is_none_or(|(j, _)| i < *j) {
                            *g = Some((i, e));
                        }
                        return;
                    }
                }
            });
            match worker {
                Ok(_) => spawned += 1,
                Err(e) => {
                    spawn_error = Some(e);
                    break;
                }
            }
        }
    });
    bar.finish_and_clear();
    if spawned == 0 {
        if let Some(e) = spawn_error {
            return Err(format!("cannot start a worker thread: {e}"));
        }
    }
    if let Some((i, e)) = first_error.into_inner().unwrap() {
        return Err(format!(
            "frame {i}: {e} (finished frames are kept; rerun with --resume)"
        ));
    }
    let names: Vec<String> = opts.split.iter().map(|(n, _)| n.clone()).collect();
    let indices: Vec<u64> = mine.collect();
    finalize::finalize(out, &indices, &names, &classes.names).map_err(|e| {
        format!("writing the dataset files: {e} (every frame is finished and kept; rerun with --resume)")
    })?;
    Ok(Summary {
        rendered: rendered.into_inner(),
        skipped: skipped.into_inner(),
        seconds: start.elapsed().as_secs_f64(),
        out: out.to_path_buf(),
        complete: true,
    })
}

struct FrameContext<'a> {
    scene: &'a Scene,
    scene_json: &'a Value,
    spec: &'a Spec,
    renderer: &'a dyn FrameRenderer,
    classes: &'a ClassMap,
    out: &'a Path,
    opts: &'a GenerateOptions,
    splits: &'a SplitPlan,
    /// Mesh bounds in object space, by object name (meshes do not change per frame).
    bounds: Mutex<std::collections::HashMap<String, Option<Bounds>>>,
}

impl FrameContext<'_> {
    fn local_bounds(&self, object: &str) -> Option<Bounds> {
        if let Some(b) = self.bounds.lock().unwrap().get(object) {
            return *b;
        }
        let b = (|| {
            let o = self.scene.object(object)?;
            let mesh = o.data.as_deref().filter(|_| o.kind == "MESH")?;
            let idx = self.scene.file.meshes.iter().position(|m| m.name == mesh)?;
            super::bounds::positions_bounds(&self.scene.load_mesh(idx).ok()?.positions)
        })();
        self.bounds.lock().unwrap().insert(object.to_string(), b);
        b
    }

    // Long because one frame's files are written in the order resume relies on (image,
    // passes, depth, labels, then the record that marks the frame done).
    fn frame(&self, i: u64) -> Result<(), String> {
        let opts = self.opts;
        let length = self.spec.sequence.as_ref().map_or(1, |q| q.length);
        let split = &opts.split[self.splits.split_of(i / length) as usize].0;
        let fv = self
            .spec
            .frame_values(
                self.scene_json,
                self.scene.file.scene.frame_current as i64,
                opts.seed,
                i,
            )
            .map_err(|e| e.to_string())?;
        let scene = self
            .scene
            .with_overrides(&fv.overrides)
            .map_err(|e| e.to_string())?;
        let (r, motion) = if self.spec.labels.motion() {
            // Flow goes to the neighbouring frames of the sequence's step (1 without one).
            let step = self.spec.sequence.as_ref().map_or(1, |q| q.step);
            let (r, m) = self.renderer.render_with_motion(
                &scene,
                fv.frame as f64,
                fv.render_seed,
                &self.spec.render,
                opts.threads_per_frame,
                step as f64,
            )?;
            (r, Some(m))
        } else {
            let r = self.renderer.render(
                &scene,
                fv.frame as f64,
                fv.render_seed,
                &self.spec.render,
                opts.threads_per_frame,
            )?;
            (r, None)
        };
        if r.color.len() != (r.width * r.height) as usize
            || r.ids.width != r.width
            || r.ids.height != r.height
        {
            return Err(format!(
                "renderer returned {}x{} with {} pixels and {}x{} ids",
                r.width,
                r.height,
                r.color.len(),
                r.ids.width,
                r.ids.height
            ));
        }
        let labels = extract(&r.ids, self.classes, self.spec.labels.min_pixels)?;
        let camera = scene_camera(&scene, fv.frame as f64, r.width, r.height)?;
        let anns = annotations(
            &r.ids,
            &labels,
            &self.classes.names,
            &camera,
            self.spec.labels.mm_per_unit,
            &|o| self.local_bounds(o),
        );

        let hook = |p: &Path| opts.after_write.map_or(Ok(()), |h| h(i, p));
        let img = layout::image_path(self.out, split, i);
        write_atomic(
            &img,
            &layout::png_bytes(r.width, r.height, 3, &layout::to_rgb8(&r.color))?,
        )?;
        hook(&img)?;
        let mask = layout::mask_path(self.out, split, i);
        write_atomic(
            &mask,
            &layout::mask_png_bytes(
                r.width,
                r.height,
                self.classes.names.len(),
                &semantic(&r.ids, &labels),
            )?,
        )?;
        hook(&mask)?;
        let labels_spec = &self.spec.labels;
        if labels_spec.depth {
            let d = r
                .ids
                .depth
                .as_ref()
                .ok_or("the spec asks for depth but the renderer gave none")?;
            let q: Vec<u16> = d
                .iter()
                .map(|&z| {
                    crate::label::passes::depth_png16(
                        z,
                        labels_spec.mm_per_unit,
                        labels_spec.depth_png_max_mm,
                    )
                })
                .collect();
            let p = layout::depth_path(self.out, split, i);
            write_atomic(&p, &layout::png16_bytes(r.width, r.height, &q)?)?;
            hook(&p)?;
        }
        if let Some(format) = labels_spec.depth_float {
            let d = r
                .ids
                .depth
                .as_ref()
                .ok_or("the spec asks for depth but the renderer gave none")?;
            let unit = if labels_spec.depth_float_mm {
                labels_spec.mm_per_unit
            } else {
                1.0
            };
            // 0 marks "no surface", as in the PNG.
            let v: Vec<f32> = d
                .iter()
                .map(|&z| {
                    if z.is_finite() {
                        (z as f64 * unit) as f32
                    } else {
                        0.0
                    }
                })
                .collect();
            let p = layout::depth_float_path(self.out, split, i, format.extension());
            let bytes = match format {
                crate::label::FloatFormat::Exr => layout::exr_grey_bytes(r.width, r.height, &v)?,
                crate::label::FloatFormat::Npy => layout::npy_f32_bytes(r.width, r.height, &v)?,
            };
            write_atomic(&p, &bytes)?;
            hook(&p)?;
        }
        if labels_spec.normals {
            let n = r
                .ids
                .normal
                .as_ref()
                .ok_or("the spec asks for normals but the renderer gave none")?;
            let p = layout::normal_path(self.out, split, i);
            write_atomic(&p, &layout::exr_rgb_bytes(r.width, r.height, n)?)?;
            hook(&p)?;
        }
        if labels_spec.normals_camera {
            let n = r
                .ids
                .normal
                .as_ref()
                .ok_or("the spec asks for normals but the renderer gave none")?;
            let cam = crate::label::passes::normals_to_camera(n, &camera.world_to_camera_opencv);
            let p = layout::normal_camera_path(self.out, split, i);
            write_atomic(&p, &layout::exr_rgb_bytes(r.width, r.height, &cam)?)?;
            hook(&p)?;
        }
        if labels_spec.aovs {
            if r.ids.aov_channels.is_empty() {
                return Err("the spec asks for aovs but the scene's view layer has no shader AOVs (or the renderer gave none)".into());
            }
            let list: Vec<(&str, Vec<f32>)> = r
                .ids
                .aov_channels
                .iter()
                .map(|(n, v)| (n.as_str(), v.clone()))
                .collect();
            let p = layout::aov_path(self.out, split, i);
            write_atomic(
                &p,
                &crate::foundation::exr::channels_bytes(r.width, r.height, &list)?,
            )?;
            hook(&p)?;
        }
        if let Some(m) = &motion {
            self.write_motion(m, &r, split, i, &hook)?;
        }
        if let Some(when) = labels_spec.mesh_glb {
            let first = self
                .spec
                .sequence
                .as_ref()
                .is_none_or(|q| i.is_multiple_of(q.length));
            if when == crate::label::MeshGlb::Frame || first {
                let p = layout::motion_path(self.out, "meshes", split, i, "glb");
                self.write_scene_mesh(&scene, fv.frame as f64, &p)?;
                hook(&p)?;
            }
        }
        let txt = layout::label_path(self.out, split, i);
        write_atomic(&txt, yolo::label_text(&anns, r.width, r.height).as_bytes())?;
        hook(&txt)?;
        let record = FrameRecord {
            index: i,
            split: split.clone(),
            image: layout::image_rel(split, i),
            width: r.width,
            height: r.height,
            frame: fv.frame,
            seed: opts.seed,
            render_seed: fv.render_seed,
            values: fv
                .overrides
                .iter()
                .map(|o| (o.path.clone(), o.value.clone()))
                .collect(),
            drawn: fv.drawn.iter().cloned().collect(),
            camera,
            annotations: anns,
            sequence: self.spec.sequence.as_ref().map(|q| i / q.length),
            sequence_frame: self.spec.sequence.as_ref().map(|q| i % q.length),
            time: self.spec.sequence.as_ref().map(|_| {
                let s = &self.scene.file.scene;
                fv.frame as f64 * s.fps_base / s.fps
            }),
        };
        let rec = layout::record_path(self.out, i);
        write_atomic(
            &rec,
            format!("{}\n", serde_json::to_string(&record).unwrap()).as_bytes(),
        )?;
        hook(&rec)
    }
}

impl FrameContext<'_> {
    /// The evaluated scene at `frame` as a world-space glb at `path` (written beside it
    /// as a `.partial` file, then renamed into place).
    fn write_scene_mesh(&self, scene: &Scene, frame: f64, path: &Path) -> Result<(), String> {
        let opts = crate::render::RenderOptions {
            frame: Some(frame),
            resolution: Some(super::renderer::resolution(scene, &self.spec.render)?),
            ..Default::default()
        };
        let mesh = crate::render::evaluated_scene_mesh(scene, &opts, &[])
            .map_err(|e| format!("the scene mesh: {e}"))?;
        let glb = crate::geometry::export::glb_bytes(&mesh, "scene").map_err(|e| e.to_string())?;
        write_atomic(path, &glb)
    }

    /// A frame's optical flow (EXR, and .flo on request) and occlusion masks, as the
    /// spec's `[labels]` ask.
    fn write_motion(
        &self,
        m: &crate::render::film::flow::Motion,
        r: &super::renderer::RenderedFrame,
        split: &str,
        i: u64,
        hook: &dyn Fn(&Path) -> Result<(), String>,
    ) -> Result<(), String> {
        let l = &self.spec.labels;
        let (w, h) = (r.width, r.height);
        for (dir, f) in [("fw", &m.forward), ("bw", &m.backward)] {
            if f.flow.len() != (w * h) as usize {
                return Err(format!(
                    "the renderer's flow has {} pixels, not {w}x{h}",
                    f.flow.len()
                ));
            }
            if l.flow {
                let x = f.flow.iter().map(|v| v[0]).collect();
                let y = f.flow.iter().map(|v| v[1]).collect();
                let p = layout::motion_path(self.out, &format!("flow_{dir}"), split, i, "exr");
                write_atomic(
                    &p,
                    &layout::exr_channels_bytes(w, h, &[("R", x), ("G", y)])?,
                )?;
                hook(&p)?;
                if l.flow_flo {
                    let p = layout::motion_path(self.out, &format!("flow_{dir}"), split, i, "flo");
                    write_atomic(&p, &crate::render::film::flow::flo_bytes(w, h, &f.flow))?;
                    hook(&p)?;
                }
            }
            if l.occlusion {
                let mask: Vec<u8> = f
                    .occluded
                    .iter()
                    .map(|&o| if o { 255 } else { 0 })
                    .collect();
                let p = layout::motion_path(self.out, &format!("occlusion_{dir}"), split, i, "png");
                write_atomic(&p, &layout::png_bytes(w, h, 1, &mask)?)?;
                hook(&p)?;
            }
        }
        Ok(())
    }
}

/// The scene camera's intrinsics and pose at `frame` (animation and constraints
/// evaluated; overrides already in `scene`).
pub fn scene_camera(
    scene: &Scene,
    frame: f64,
    width: u32,
    height: u32,
) -> Result<CameraInfo, String> {
    let name = scene.camera_at(frame)?.ok_or("the scene has no camera")?;
    let idx = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == name)
        .ok_or_else(|| format!("scene camera {name:?} is not an object"))?;
    let ev = crate::anim::evaluate_scene(scene, frame).map_err(|e| e.to_string())?;
    let obj = &ev.data.objects[idx];
    let data = obj.data.as_deref().unwrap_or(name);
    let cam = ev
        .data
        .cameras
        .iter()
        .find(|c| c.name == data)
        .ok_or_else(|| format!("camera data {data:?} of {name:?} not found"))?;
    let out = crate::scene::settings::Output::of(&scene.file.scene);
    Ok(camera_info(
        name,
        &crate::scene::settings::CameraSettings::of(cam),
        ev.world_matrices[idx],
        width,
        height,
        [out.pixel_aspect_x, out.pixel_aspect_y],
    ))
}
