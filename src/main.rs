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
    /// Describe an exported scene and list which node types blendsynth supports.
    /// Exits with status 3 when the scene uses unsupported node types.
    Inspect {
        /// A folder written by `blendsynth convert`.
        dir: PathBuf,
        /// Print the report as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Evaluate an object's geometry (modifiers, Geometry Nodes) at a frame and write it
    /// as a mesh: instances realised, Blender's vertices kept one to one.
    Mesh(MeshArgs),
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
        Command::Mesh(a) => {
            let overrides = a.set.iter().map(|s| Override::parse(s)).collect::<Result<Vec<_>, _>>().map_err(anyhow::Error::msg)?;
            let overrides: Vec<(String, serde_json::Value)> = overrides.into_iter().map(|o| (o.path, o.value)).collect();
            let scene = Scene::load(&a.dir)?;
            let frame = a.frame.unwrap_or(scene.file.scene.frame_current as f64);
            let start = std::time::Instant::now();
            let set = blendsynth::geometry::evaluate_object(&scene, &a.object, frame, &overrides).map_err(|e| anyhow::anyhow!("mesh {:?}: {e}", a.object))?;
            let mesh = blendsynth::geometry::realize_to_mesh(&set).map_err(|e| anyhow::anyhow!("mesh {:?}: {e}", a.object))?;
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
