//! The `blendsynth` command line: parses arguments and calls the library.
//!
//! Exit codes: 0 success, 1 failure (one line naming what was wrong), 2 bad usage,
//! 3 `inspect` found node types blendsynth does not support yet.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};

use blendsynth::shader::bake::{bake_emission, write_exr, BakeOptions};
use blendsynth::{blender, inspect, scene::Override, scene::Scene};

#[derive(Parser)]
#[command(name = "blendsynth", version, about = "Render Blender scenes without Blender, to make labelled synthetic training datasets")]
struct Cli {
    #[command(subcommand)]
    command: Command,
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
        #[arg(long, allow_negative_numbers = true)]
        frame: Option<i32>,
        /// Do not write evaluated reference meshes.
        #[arg(long)]
        no_evaluated: bool,
    },
    /// Evaluate an object's material over its UV map as Cycles' EMIT bake does (surface
    /// emission at each texel), writing a float EXR.
    Bake(BakeArgs),
    /// Render an exported scene with the path tracer to a linear float EXR.
    Render(RenderArgs),
    /// Describe an exported scene and list which node types blendsynth supports.
    /// Exits with status 3 when the scene uses unsupported node types.
    Inspect {
        /// A folder written by `blendsynth convert`.
        dir: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
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
    /// Adaptive sampling noise threshold (accepted; adaptive sampling is not implemented yet).
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
    /// Folder for label passes (depth, ids, normal, uv, albedo) as float EXRs.
    #[arg(long)]
    passes: Option<PathBuf>,
    /// Output image (linear float EXR).
    #[arg(short, long)]
    output: PathBuf,
}

fn parse_resolution(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s.split_once(['x', 'X']).ok_or_else(|| format!("{s:?}: expected WxH, e.g. 640x480"))?;
    let w = a.trim().parse::<u32>().map_err(|e| format!("{s:?}: width: {e}"))?;
    let h = b.trim().parse::<u32>().map_err(|e| format!("{s:?}: height: {e}"))?;
    Ok((w, h))
}

fn run_render(a: RenderArgs) -> Result<()> {
    use blendsynth::render;
    let overrides = a.set.iter().map(|s| Override::parse(s)).collect::<Result<Vec<_>, _>>().map_err(anyhow::Error::msg)?;
    let scene = Scene::load(&a.dir)?.with_overrides(&overrides)?;
    let opts = render::RenderOptions { frame: a.frame, samples: a.samples, threshold: a.threshold, resolution: a.resolution, seed: a.seed, threads: a.threads, progress: true };
    let out = render::render(&scene, &opts).map_err(|e| anyhow::anyhow!("render {}: {e}", a.dir.display()))?;
    render::write_exr(&a.output, out.width, out.height, &out.color).map_err(anyhow::Error::msg)?;
    if let Some(dir) = &a.passes {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let p = &out.passes;
        let grey = |v: &[f32]| v.iter().map(|&x| [x, x, x, 1.0]).collect::<Vec<_>>();
        let ids = |v: &[u32]| v.iter().map(|&x| [x as f32, x as f32, x as f32, 1.0]).collect::<Vec<_>>();
        let rgb = |v: &[[f32; 3]]| v.iter().map(|x| [x[0], x[1], x[2], 1.0]).collect::<Vec<_>>();
        let depth: Vec<f32> = p.depth.iter().map(|&d| if d.is_finite() { d } else { 1e10 }).collect();
        let files: [(&str, Vec<[f32; 4]>); 7] = [
            ("depth.exr", grey(&depth)),
            ("object_index.exr", ids(&p.object_index)),
            ("instance_id.exr", ids(&p.instance_id)),
            ("material_index.exr", ids(&p.material_index)),
            ("normal.exr", rgb(&p.normal)),
            ("albedo.exr", rgb(&p.albedo)),
            ("uv.exr", p.uv.iter().map(|u| [u[0], u[1], 0.0, 1.0]).collect()),
        ];
        for (name, px) in files {
            render::write_exr(&dir.join(name), out.width, out.height, &px).map_err(anyhow::Error::msg)?;
        }
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

fn run(cli: Cli) -> Result<Outcome> {
    match cli.command {
        Command::Convert { input, output, blender, frame, no_evaluated } => {
            let opts = blender::ConvertOptions { blender, frame, no_evaluated };
            let scene = blender::convert(&input, &output, &opts)?;
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
            let overrides = a.set.iter().map(|s| Override::parse(s)).collect::<Result<Vec<_>, _>>().map_err(anyhow::Error::msg)?;
            let scene = Scene::load(&a.dir)?.with_overrides(&overrides)?;
            let opts = BakeOptions { object: a.object.clone(), uv: a.uv, size: a.size };
            let start = std::time::Instant::now();
            let baked = bake_emission(&scene, &opts).map_err(|e| anyhow::anyhow!("bake {:?}: {e}", a.object))?;
            write_exr(&baked, &a.output).map_err(anyhow::Error::msg)?;
            println!("baked {} ({}x{}) -> {} in {:.2} s", a.object, a.size, a.size, a.output.display(), start.elapsed().as_secs_f64());
            Ok(Outcome::Done)
        }
        Command::Render(a) => {
            run_render(a)?;
            Ok(Outcome::Done)
        }
        Command::Inspect { dir, json } => {
            let scene = Scene::load(&dir)?;
            for i in 0..scene.file.meshes.len() {
                scene.load_mesh(i)?;
            }
            let report = inspect::report(&scene);
            if json {
                println!("{}", serde_json::to_string_pretty(&report).context("cannot serialise the report")?);
            } else {
                print!("{}", report.to_text());
            }
            Ok(if report.all_supported { Outcome::Done } else { Outcome::Unsupported })
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
