//! The `blendsynth` command line: parses arguments and calls the library.
//!
//! Exit codes: 0 success, 1 failure (one line naming what was wrong), 2 bad usage,
//! 3 `inspect` found something `render` or `mesh` would refuse.

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use blendsynth::render::bake::{bake_emission, write_exr, BakeOptions};
use blendsynth::{blender, inspect, scene::Override, scene::Scene};

/// The crate version and the exchange format it reads (`tests/cli.rs` keeps the number
/// equal to `scene::FORMAT_VERSION`).
const VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), " (exchange format 1)");

#[derive(Parser)]
#[command(
    name = "blendsynth",
    version = VERSION,
    about = "Render Blender scenes without Blender, to make labelled synthetic training datasets"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Never download Open Image Denoise when none is installed (offline clusters); the
    /// same as BLENDSYNTH_OIDN_DOWNLOAD=0.
    #[arg(long, global = true)]
    no_oidn_download: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Export a .blend file with Blender into a blendsynth scene folder, then validate it.
    Convert {
        /// The .blend file to convert.
        input: PathBuf,
        /// Output folder (created; an earlier export there is replaced).
        #[arg(short, long)]
        output: PathBuf,
        /// Blender executable, or a Python interpreter with the bpy module.
        /// Default: $BLENDSYNTH_BLENDER, then $BLENDSYNTH_BPY_PYTHON, then `blender` on PATH.
        #[arg(long)]
        blender: Option<PathBuf>,
        /// Frame at which to write the evaluated reference meshes (default: the file's current frame).
        #[arg(long, allow_negative_numbers = true, conflicts_with = "frames")]
        frame: Option<i32>,
        /// Evaluate at frame A, and also write Blender's evaluated meshes of objects whose
        /// evaluation is animated (shape keys, armatures, simulations, ...) at every frame
        /// A+1..B, so `render --frame F` and `generate` work on them for F in A..B.
        #[arg(long, value_name = "A..B", value_parser = parse_frame_range, allow_hyphen_values = true)]
        frames: Option<(i32, i32)>,
        /// Do not write evaluated reference meshes.
        #[arg(long)]
        no_evaluated: bool,
        /// Also copy image files from this folder (repeatable). By default only files
        /// under the .blend's own folder are copied; others are an error.
        #[arg(long = "allow-path", value_name = "DIR")]
        allow_path: Vec<PathBuf>,
    },
    /// Evaluate an object's material over its UV map as Cycles' EMIT bake does (surface
    /// emission at each texel), writing a float EXR.
    Bake(BakeArgs),
    /// Render an exported scene with the path tracer to a linear float EXR.
    Render(RenderArgs),
    /// Describe an exported scene, list which node types blendsynth supports, and run
    /// every check `render` and `mesh` make at the frame. Exits with status 3 when
    /// something would be refused (exit 0: `render` and `mesh` succeed).
    Inspect {
        /// A folder written by `blendsynth convert`.
        dir: PathBuf,
        /// Frame to check at (default: the scene's current frame).
        #[arg(long, allow_negative_numbers = true)]
        frame: Option<f64>,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Render a labelled dataset: frames with parameters drawn from a randomisation
    /// spec, in parallel, resumable, optionally one shard of many.
    Generate(GenerateArgs),
    /// Join shard folders made by `generate --shard` into one dataset.
    Merge {
        /// Shard folders (all shards of one dataset).
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Output folder (new or empty).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Draw a contact sheet of a dataset's frames with masks and boxes.
    Preview {
        /// A dataset folder written by `generate`, `merge` or `replicate`.
        dir: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
        /// How many frames (the first ones, in frame order).
        #[arg(long, default_value_t = 16)]
        count: usize,
    },
    /// Regenerate a published dataset with built-in scenes and specs.
    Replicate(ReplicateArgs),
    /// Evaluate an object's geometry (modifiers, Geometry Nodes) at a frame and write it
    /// as a mesh: instances realised, Blender's vertices kept one to one.
    Mesh(MeshArgs),
    /// Download Open Image Denoise (the pinned pyoidn wheel, through python3 -m pip) into
    /// the cache folder, or DIR, unless it is there; print the library folder.
    FetchOidn {
        /// Folder to provision into instead of $XDG_CACHE_HOME/blendsynth (e.g. shared
        /// storage); give the printed folder to the jobs as BLENDSYNTH_OIDN.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum RendererKind {
    /// The path tracer (the real images).
    Path,
    /// Debugging stand-in: each mesh object's projected bounding box as a flat
    /// rectangle; checks a spec and the label pipeline in seconds. Not a render.
    Bounds,
}

#[derive(clap::Args)]
struct RunArgs {
    /// Dataset seed: with the spec, fixes every frame's values.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// This run's slice, I/N with 0 <= I < N: frames with index % N == I.
    #[arg(long)]
    shard: Option<String>,
    /// Finish a killed or partial run in OUT (same settings): finished frames are kept,
    /// partial ones redone.
    #[arg(long)]
    resume: bool,
    /// Frames rendered at once (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Which renderer makes the images and label passes.
    #[arg(long, value_enum, default_value = "path")]
    renderer: RendererKind,
}

#[derive(clap::Args)]
struct GenerateArgs {
    /// A scene folder written by `blendsynth convert`.
    dir: PathBuf,
    /// The randomisation spec (TOML; see README, "Randomisation spec").
    #[arg(long)]
    spec: PathBuf,
    /// Number of frames in the dataset.
    #[arg(long)]
    frames: u64,
    /// Output dataset folder.
    #[arg(short, long)]
    output: PathBuf,
    /// Split fractions, NAME=FRACTION,... summing to 1 (exact counts per split).
    #[arg(long, default_value = "train=1")]
    split: String,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Args)]
struct ReplicateArgs {
    /// The dataset to regenerate (doi-23843904: Dowrick et al., procedural colonoscopy
    /// and laparoscopy, UCL 2023).
    #[arg(long)]
    dataset: String,
    /// Which part (all: both, into OUT/colonoscopy and OUT/laparoscopy).
    #[arg(long, value_enum, default_value = "all")]
    part: blendsynth::dataset::replicate::Part,
    /// Frames per part (the study: 50000, split 45000/5000).
    #[arg(long, default_value_t = 50000)]
    frames: u64,
    /// Folder of a converted scene to use instead of the built-in one (a single part).
    #[arg(long)]
    assets: Option<PathBuf>,
    /// Output folder.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    run: RunArgs,
}

/// The path tracer as a dataset renderer. The render branch wires this at merge (see
/// `dataset::renderer::path_tracer`).
fn make_renderer(
    kind: RendererKind,
    scene: &Scene,
) -> Result<Box<dyn blendsynth::dataset::FrameRenderer>> {
    match kind {
        RendererKind::Path => {
            blendsynth::dataset::renderer::path_tracer(scene).map_err(anyhow::Error::msg)
        }
        RendererKind::Bounds => Ok(Box::new(
            blendsynth::dataset::bounds::BoundsRenderer::new(scene).map_err(anyhow::Error::msg)?,
        )),
    }
}

fn generate_options(
    run: &RunArgs,
    frames: u64,
    split: Vec<(String, f64)>,
) -> Result<blendsynth::dataset::GenerateOptions> {
    use blendsynth::dataset::generate::parse_shard;
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    blendsynth::dataset::generate::check_frames(frames).map_err(|e| anyhow::anyhow!("--{e}"))?;
    // Each job is a thread rendering a frame; more than this is a typo, not a machine.
    const MAX_JOBS: usize = 1024;
    if let Some(j) = run.jobs.filter(|j| !(1..=MAX_JOBS).contains(j)) {
        anyhow::bail!("--jobs {j}: must be within [1, {MAX_JOBS}]");
    }
    Ok(blendsynth::dataset::GenerateOptions {
        frames,
        seed: run.seed,
        split,
        shard: run
            .shard
            .as_deref()
            .map(parse_shard)
            .transpose()
            .map_err(anyhow::Error::msg)?
            .unwrap_or((0, 1)),
        resume: run.resume,
        jobs: run.jobs.unwrap_or(cores),
        threads_per_frame: 1,
        progress: true,
        after_write: None,
    })
}

fn print_summary(s: &blendsynth::dataset::Summary) {
    println!(
        "dataset {}: {} frames rendered, {} already done, {:.1} s ({:.1} frames/hour)",
        s.out.display(),
        s.rendered,
        s.skipped,
        s.seconds,
        if s.seconds > 0.0 {
            s.rendered as f64 * 3600.0 / s.seconds
        } else {
            0.0
        }
    );
}

#[derive(clap::Args)]
struct MeshArgs {
    /// A folder written by `blendsynth convert`.
    dir: PathBuf,
    /// The object to evaluate.
    #[arg(long)]
    object: String,
    /// Scene frame (default: the file's current frame).
    #[arg(long, allow_negative_numbers = true)]
    frame: Option<f64>,
    /// Parameter override by Blender data path, PATH=VALUE (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Output mesh: .glb (attributes kept), .ply or .obj.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args)]
struct BakeArgs {
    /// A folder written by `blendsynth convert`.
    dir: PathBuf,
    /// The mesh object whose material to bake.
    #[arg(long)]
    object: String,
    /// UV map to bake over (default: the mesh's active render UV map).
    #[arg(long)]
    uv: Option<String>,
    /// Image width and height in texels.
    #[arg(long)]
    size: u32,
    /// Parameter override by Blender data path, PATH=VALUE (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Output image (a float EXR).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// A folder written by `blendsynth convert`.
    dir: PathBuf,
    /// Frame to render (default: the scene's current frame).
    #[arg(long, allow_negative_numbers = true)]
    frame: Option<f64>,
    /// Samples per pixel (default: the scene's Cycles samples).
    #[arg(long)]
    samples: Option<u32>,
    /// Adaptive sampling noise threshold: T > 0 turns Cycles' adaptive sampling on with T,
    /// 0 turns it off (default: the scene's setting).
    #[arg(long)]
    threshold: Option<f32>,
    /// Image size WxH (default: the scene's resolution times its percentage).
    #[arg(long, value_parser = parse_resolution)]
    resolution: Option<(u32, u32)>,
    /// Sampling seed (default: the scene's Cycles seed).
    #[arg(long)]
    seed: Option<u32>,
    /// Worker threads (default: all cores; the image is identical either way).
    #[arg(long)]
    threads: Option<usize>,
    /// Parameter override by Blender data path, PATH=VALUE (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Folder for label passes from the pixel-centre ray: depth (Z) and distance,
    /// object/instance/material ids, semantic class, normal, albedo, UV, and classes.json.
    #[arg(long)]
    passes: Option<PathBuf>,
    /// File format of the passes: exr (float) or png (16-bit ids, depth in mm).
    #[arg(long, value_enum, default_value = "exr")]
    pass_format: PassFormatArg,
    /// Class mapping for the semantic pass: a dataset spec (TOML); its [labels] section
    /// ([[labels.class]] name + objects patterns, class_property, mm_per_unit) is used.
    /// Without it, objects' custom property `class` names their class.
    #[arg(long)]
    classes: Option<PathBuf>,
    /// Denoise with Open Image Denoise as Cycles does (default: the scene's setting).
    #[arg(long, value_enum)]
    denoise: Option<OnOff>,
    /// libOpenImageDenoise to use (file or folder; default: $BLENDSYNTH_OIDN, the bpy or
    /// Blender installation, or the pyoidn wheel).
    #[arg(long)]
    oidn: Option<PathBuf>,
    /// Output image: .png through the scene's colour management (view transform, look,
    /// exposure, gamma; its bit depth and alpha), or .exr linear float RGBA.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum PassFormatArg {
    Exr,
    Png,
}

#[derive(Clone, Copy, PartialEq, clap::ValueEnum)]
enum OnOff {
    On,
    Off,
}

/// `--set PATH=VALUE` arguments, as `bake`, `mesh` and `render` take them.
fn parse_overrides(set: &[String]) -> Result<Vec<Override>> {
    set.iter()
        .map(|s| Override::parse(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(anyhow::Error::msg)
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: expected WxH, e.g. 640x480"))?;
    let w = a
        .trim()
        .parse::<u32>()
        .map_err(|e| format!("{s:?}: width: {e}"))?;
    let h = b
        .trim()
        .parse::<u32>()
        .map_err(|e| format!("{s:?}: height: {e}"))?;
    Ok((w, h))
}

/// The folder a file will be written in ("." for a bare file name).
fn output_dir(file: &std::path::Path) -> &std::path::Path {
    match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    }
}

/// Errors unless `dir` is a folder this process can create files in (checked by creating
/// an anonymous temporary file there).
fn writable_dir(dir: &std::path::Path, what: &str) -> Result<()> {
    if !dir.is_dir() {
        anyhow::bail!("{what} {} does not exist or is not a folder", dir.display());
    }
    tempfile::tempfile_in(dir)
        .map(drop)
        .with_context(|| format!("{what} {} is not writable", dir.display()))
}

fn run_render(a: RenderArgs) -> Result<()> {
    use blendsynth::render;
    let overrides = parse_overrides(&a.set)?;
    let scene = Scene::load(&a.dir)?.with_overrides(&overrides)?;
    let opts = render::RenderOptions {
        frame: a.frame,
        samples: a.samples,
        threshold: a.threshold,
        resolution: a.resolution,
        seed: a.seed,
        threads: a.threads,
        progress: true,
    };
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    if ext != "png" && ext != "exr" {
        anyhow::bail!(
            "{}: the output must be a .png or .exr file",
            a.output.display()
        );
    }
    // Every output location is checked before spending the render time, so a bad folder
    // fails now rather than after the image is written.
    writable_dir(output_dir(&a.output), "output folder")?;
    if let Some(dir) = &a.passes {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--passes {}: cannot create the folder", dir.display()))?;
        writable_dir(dir, "--passes folder")?;
    }
    // Find the denoiser before spending the render time.
    let want_denoise = a.denoise.map_or_else(
        || blendsynth::denoise::scene_wants_denoising(&scene),
        |d| d == OnOff::On,
    );
    let denoiser = if want_denoise {
        blendsynth::denoise::find_for_render(a.oidn.as_deref())?
    } else {
        None
    };
    let mut out = render::render(&scene, &opts)
        .map_err(|e| anyhow::anyhow!("render {}: {e}", a.dir.display()))?;
    if let Some(d) = &denoiser {
        let frame = a.frame.unwrap_or(scene.file.scene.frame_current as f64);
        blendsynth::denoise::denoise_render(d, &scene, frame, &mut out)
            .map_err(|e| anyhow::anyhow!("denoising: {e}"))?;
    }
    blendsynth::color::write_render(&scene, &a.output, out.width, out.height, &out.color)?;
    if let Some(dir) = &a.passes {
        use blendsynth::label::passes::{write_passes, PassFormat, PassImages};
        // A dataset spec file (its [labels] section), read as `generate` reads it.
        let labels = match &a.classes {
            Some(f) => blendsynth::dataset::spec::Spec::load(f)?.labels,
            None => blendsynth::label::LabelSpec::default(),
        };
        let classes = blendsynth::label::ClassMap::new(&labels, &scene);
        let p = &out.passes;
        let objects: Vec<String> = p.instances.iter().map(|i| i.object.clone()).collect();
        let images = PassImages {
            width: out.width,
            height: out.height,
            depth: &p.depth,
            distance: &p.distance,
            object_index: &p.object_index,
            instance_id: &p.instance_id,
            material_index: &p.material_index,
            normal: &p.normal,
            albedo: &p.albedo,
            uv: &p.uv,
            instance_objects: &objects,
            aovs: p
                .aovs
                .iter()
                .map(blendsynth::label::passes::AovPlane::of)
                .collect(),
            view_layer: &scene.file.scene.view_layer.name,
        };
        let format = if a.pass_format == PassFormatArg::Png {
            PassFormat::Png
        } else {
            PassFormat::Exr
        };
        write_passes(dir, &images, &classes, format, labels.mm_per_unit)
            .map_err(anyhow::Error::msg)?;
    }
    let s = &out.stats;
    println!(
        "rendered {} ({}x{}, {} samples, {} triangles) -> {} in {:.2} s ({:.2} s setup), {:.2} M rays/s",
        a.dir.display(),
        out.width,
        out.height,
        s.samples,
        s.triangles,
        a.output.display(),
        s.wall_seconds,
        s.build_seconds,
        s.rays as f64 / (s.wall_seconds - s.build_seconds).max(1e-9) / 1e6
    );
    Ok(())
}

enum Outcome {
    Done,
    Unsupported,
}

/// `A..B` for `convert --frames`: inclusive, A <= B, at most 10000 frames (the exporter's
/// limit).
fn parse_frame_range(s: &str) -> Result<(i32, i32), String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("{s:?} is not a frame range A..B"))?;
    let p = |x: &str| {
        x.trim()
            .parse::<i32>()
            .map_err(|_| format!("{s:?}: {x:?} is not a whole frame number"))
    };
    let (a, b) = (p(a)?, p(b)?);
    if b < a || (b as i64 - a as i64) >= 10000 {
        return Err(format!("{s:?}: need A <= B and at most 10000 frames"));
    }
    Ok((a, b))
}

// Long because one arm per subcommand; each only maps arguments to library calls.
fn run(cli: Cli) -> Result<Outcome> {
    match cli.command {
        Command::Convert {
            input,
            output,
            blender,
            frame,
            frames,
            no_evaluated,
            allow_path,
        } => {
            let opts = blender::ConvertOptions {
                blender,
                frame,
                frames,
                no_evaluated,
                allow_paths: allow_path,
            };
            let (scene, copied) = blender::convert_listing(&input, &output, &opts)?;
            for c in &copied {
                println!(
                    "copied {} -> {} (image {:?})",
                    c.from.display(),
                    output.join(&c.to).display(),
                    c.image
                );
            }
            let f = &scene.file;
            println!(
                "converted {} -> {}: {} objects, {} meshes, {} materials, {} node groups, {} animated ID(s) (Blender {})",
                input.display(),
                output.display(),
                f.objects.len(),
                f.meshes.len(),
                f.materials.len(),
                f.node_groups.len(),
                f.animation.len(),
                f.blender_version
            );
            for w in &f.warnings {
                eprintln!("warning: {w}");
            }
            Ok(Outcome::Done)
        }
        Command::Bake(a) => {
            // The image is size x size texels: the render's size limits apply.
            blendsynth::render::limits::check_film(a.size, a.size, "--size")
                .map_err(|e| anyhow::anyhow!("bake: {e}"))?;
            let overrides = parse_overrides(&a.set)?;
            let scene = Scene::load(&a.dir)?.with_overrides(&overrides)?;
            let opts = BakeOptions {
                object: a.object.clone(),
                uv: a.uv,
                size: a.size,
            };
            let start = std::time::Instant::now();
            let baked = bake_emission(&scene, &opts)
                .map_err(|e| anyhow::anyhow!("bake {:?}: {e}", a.object))?;
            write_exr(&baked, &a.output).map_err(anyhow::Error::msg)?;
            println!(
                "baked {} ({}x{}) -> {} in {:.2} s",
                a.object,
                a.size,
                a.size,
                a.output.display(),
                start.elapsed().as_secs_f64()
            );
            Ok(Outcome::Done)
        }
        Command::Render(a) => {
            run_render(a)?;
            Ok(Outcome::Done)
        }
        Command::Inspect { dir, frame, json } => {
            let scene = Scene::load(&dir)?;
            for i in 0..scene.file.meshes.len() {
                scene.load_mesh(i)?;
            }
            let report = inspect::report_at(&scene, frame);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).context("cannot serialise the report")?
                );
            } else {
                print!("{}", report.to_text());
            }
            Ok(if report.all_supported {
                Outcome::Done
            } else {
                Outcome::Unsupported
            })
        }
        Command::Generate(a) => {
            use blendsynth::dataset::{generate, generate::parse_split, Spec};
            let scene = Scene::load(&a.dir)?;
            let spec = Spec::load(&a.spec)?;
            let opts = generate_options(
                &a.run,
                a.frames,
                parse_split(&a.split).map_err(anyhow::Error::msg)?,
            )?;
            let renderer = make_renderer(a.run.renderer, &scene)?;
            let s = generate(&scene, &spec, renderer.as_ref(), &a.output, &opts)
                .map_err(anyhow::Error::msg)?;
            print_summary(&s);
            Ok(Outcome::Done)
        }
        Command::Merge { shards, output } => {
            let n = blendsynth::dataset::merge(&shards, &output).map_err(anyhow::Error::msg)?;
            println!(
                "merged {} shard(s) into {}: {n} frames",
                shards.len(),
                output.display()
            );
            Ok(Outcome::Done)
        }
        Command::Preview { dir, output, count } => {
            let n = blendsynth::dataset::preview::contact_sheet(&dir, &output, count)
                .map_err(anyhow::Error::msg)?;
            println!("preview of {n} frame(s) -> {}", output.display());
            Ok(Outcome::Done)
        }
        Command::Replicate(a) => {
            use blendsynth::dataset::replicate;
            if a.dataset != replicate::DATASET {
                anyhow::bail!(
                    "unknown dataset {:?} (known: {})",
                    a.dataset,
                    replicate::DATASET
                );
            }
            for part in a.part.parts() {
                let (scene, spec) = replicate::scene_and_spec(part, a.assets.as_deref())
                    .map_err(anyhow::Error::msg)?;
                let out = if a.part.parts().len() > 1 {
                    a.output.join(part.name())
                } else {
                    a.output.clone()
                };
                let opts = generate_options(&a.run, a.frames, replicate::split())?;
                let renderer = make_renderer(a.run.renderer, &scene)?;
                let s =
                    blendsynth::dataset::generate(&scene, &spec, renderer.as_ref(), &out, &opts)
                        .map_err(anyhow::Error::msg)?;
                print_summary(&s);
            }
            println!("dataset written to {}", a.output.display());
            Ok(Outcome::Done)
        }
        Command::Mesh(a) => {
            let overrides = parse_overrides(&a.set)?;
            let overrides: Vec<(String, serde_json::Value)> =
                overrides.into_iter().map(|o| (o.path, o.value)).collect();
            let scene = Scene::load(&a.dir)?;
            // Objects without geometry would evaluate to an empty mesh: say so instead, as
            // Blender's to_mesh does ("Object does not have geometry data"; a Volume's
            // voxels are not a mesh).
            if let Some(o) = scene.object(&a.object) {
                if matches!(
                    o.kind.as_str(),
                    "EMPTY" | "CAMERA" | "LIGHT" | "LIGHT_PROBE" | "SPEAKER" | "VOLUME"
                ) {
                    anyhow::bail!(
                        "mesh {:?}: not a geometry object (it is a {} object)",
                        a.object,
                        o.kind
                    );
                }
            }
            let frame = a.frame.unwrap_or(scene.file.scene.frame_current as f64);
            let start = std::time::Instant::now();
            let set = blendsynth::geometry::evaluate_object(&scene, &a.object, frame, &overrides)
                .map_err(|e| anyhow::anyhow!("mesh {:?}: {e}", a.object))?;
            let mesh = blendsynth::geometry::realize_to_mesh(&set)
                .map_err(|e| anyhow::anyhow!("mesh {:?}: {e}", a.object))?;
            let seconds = start.elapsed().as_secs_f64();
            blendsynth::geometry::write_mesh(&a.output, &mesh, &a.object)?;
            println!(
                "{} at frame {frame}: {} vertices, {} edges, {} faces -> {} (evaluated in {seconds:.3} s)",
                a.object,
                mesh.vertex_count(),
                mesh.edge_count(),
                mesh.face_count(),
                a.output.display()
            );
            Ok(Outcome::Done)
        }
        Command::FetchOidn { dir } => {
            let lib = blendsynth::denoise::fetch(dir.as_deref())?;
            println!("{}", lib.display());
            Ok(Outcome::Done)
        }
    }
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are not errors; clap knows which is which.
            let _ = e.print();
            return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
        }
    };
    if cli.no_oidn_download {
        // Before any thread starts; child processes inherit it.
        std::env::set_var(blendsynth::denoise::provision::DOWNLOAD_ENV, "0");
    }
    match run(cli) {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Unsupported) => ExitCode::from(3),
        Err(e) => {
            let msg = format!("{e:#}").replace('\n', " ");
            eprintln!("error: {msg}");
            ExitCode::from(1)
        }
    }
}
