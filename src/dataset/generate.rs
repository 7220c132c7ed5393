//! `blendsynth generate`: renders a dataset's frames in parallel and labels them.
//!
//! Frame `i` depends only on (scene, spec, seed, i): its scene frame, parameter values
//! and render seed come from the spec's counter-based draws, its split from a
//! seed-keyed permutation of all frame indices. So a frame rendered alone, by another
//! shard, on another thread count or after a resume is the same bytes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
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
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            return Err(format!(
                "split name {name:?} must be letters, digits, '_' or '-'"
            ));
        }
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

/// The split of every frame: exact counts (largest remainder), frames ordered by a
/// seed-keyed hash so each split is a random subset, identical on every shard.
pub fn assign_splits(frames: u64, seed: u64, split: &[(String, f64)]) -> Vec<u16> {
    let n = frames as f64;
    let mut counts: Vec<u64> = split.iter().map(|(_, f)| (f * n).floor() as u64).collect();
    let mut rest: Vec<usize> = (0..split.len()).collect();
    rest.sort_by(|&a, &b| {
        let ra = split[a].1 * n - counts[a] as f64;
        let rb = split[b].1 * n - counts[b] as f64;
        rb.partial_cmp(&ra).unwrap().then(a.cmp(&b))
    });
    let mut left = frames - counts.iter().sum::<u64>();
    for &k in rest.iter().cycle() {
        if left == 0 {
            break;
        }
        counts[k] += 1;
        left -= 1;
    }
    let key = rng::key("#split");
    let mut order: Vec<u64> = (0..frames).collect();
    order.sort_by_key(|&i| (rng::bits(seed, i, key, 0), i));
    let mut out = vec![0u16; frames as usize];
    let mut pos = 0usize;
    for (k, c) in counts.iter().enumerate() {
        for &i in &order[pos..pos + *c as usize] {
            out[i as usize] = k as u16;
        }
        pos += *c as usize;
    }
    out
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

/// Renders the frames of this shard that are not finished, then writes the COCO, YOLO
/// and JSONL files over the finished frames.
pub fn generate(
    scene: &Scene,
    spec: &Spec,
    renderer: &dyn FrameRenderer,
    out: &Path,
    opts: &GenerateOptions,
) -> Result<Summary, String> {
    let start = Instant::now();
    for w in spec.validate(scene).map_err(|e| e.to_string())? {
        eprintln!("warning: {w}");
    }
    let classes = ClassMap::new(&spec.labels, scene);
    let man = manifest(scene, spec, opts, &classes);
    let man_path = out.join("manifest.json");
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
        if out.exists()
            && std::fs::read_dir(out)
                .map(|mut d| d.next().is_some())
                .unwrap_or(false)
        {
            return Err(format!(
                "{} exists and is not a blendsynth dataset; choose an empty or new folder",
                out.display()
            ));
        }
        write_atomic(
            &man_path,
            format!("{}\n", serde_json::to_string_pretty(&man).unwrap()).as_bytes(),
        )?;
    }
    let splits = assign_splits(opts.frames, opts.seed, &opts.split);
    let mine: Vec<u64> = (0..opts.frames)
        .filter(|i| i % opts.shard.1 == opts.shard.0)
        .collect();
    let todo: Vec<u64> = mine
        .iter()
        .copied()
        .filter(|&i| !layout::record_path(out, i).exists())
        .collect();
    let skipped = (mine.len() - todo.len()) as u64;

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
        let b = indicatif::ProgressBar::new(todo.len() as u64);
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
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let first_error: Mutex<Option<(u64, String)>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..opts.jobs.max(1).min(todo.len().max(1)) {
            s.spawn(|| loop {
                if stop.load(Ordering::Relaxed) {
                    return;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&i) = todo.get(k) else { return };
                match ctx.frame(i) {
                    Ok(()) => bar.inc(1),
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
        }
    });
    bar.finish_and_clear();
    if let Some((i, e)) = first_error.into_inner().unwrap() {
        return Err(format!(
            "frame {i}: {e} (finished frames are kept; rerun with --resume)"
        ));
    }
    let names: Vec<String> = opts.split.iter().map(|(n, _)| n.clone()).collect();
    finalize::finalize(out, &mine, &names, &classes.names)?;
    Ok(Summary {
        rendered: todo.len() as u64,
        skipped,
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
    splits: &'a [u16],
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

    fn frame(&self, i: u64) -> Result<(), String> {
        let opts = self.opts;
        let split = &opts.split[self.splits[i as usize] as usize].0;
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
        let r = self.renderer.render(
            &scene,
            fv.frame as f64,
            fv.render_seed,
            &self.spec.render,
            opts.threads_per_frame,
        )?;
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
            &layout::png_bytes(r.width, r.height, 1, &semantic(&r.ids, &labels))?,
        )?;
        hook(&mask)?;
        let labels_spec = &self.spec.labels;
        if labels_spec.depth {
            let d = r
                .ids
                .depth
                .as_ref()
                .ok_or("the spec asks for depth but the renderer gave none")?;
            let mm: Vec<u16> = d
                .iter()
                .map(|&z| crate::label::passes::depth_mm(z, labels_spec.mm_per_unit))
                .collect();
            let p = layout::depth_path(self.out, split, i);
            write_atomic(&p, &layout::png16_bytes(r.width, r.height, &mm)?)?;
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
        let txt = layout::label_path(self.out, split, i);
        write_atomic(&txt, yolo::label_text(&anns, r.width, r.height).as_bytes())?;
        hook(&txt)?;
        let record = FrameRecord {
            index: i,
            split: split.clone(),
            image: format!("images/{split}/{}.png", layout::frame_name(i)),
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
        };
        let rec = layout::record_path(self.out, i);
        write_atomic(
            &rec,
            format!("{}\n", serde_json::to_string(&record).unwrap()).as_bytes(),
        )?;
        hook(&rec)
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
    let name = scene
        .file
        .scene
        .camera
        .as_deref()
        .ok_or("the scene has no camera")?;
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
    Ok(camera_info(
        name,
        &cam.properties,
        ev.world_matrices[idx],
        width,
        height,
    ))
}
