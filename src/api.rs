//! The library's entry points as the command line uses them, for front ends other than
//! `main.rs` (the Python bindings in `src/python/`): each does what one CLI subcommand
//! does, with the same defaults and error messages, but returns data instead of writing
//! files or printing. Errors carry a kind so a front end can map them to its own types.
//!
//! `main.rs` could later share these (its `generate_options`, `make_renderer` and the
//! render/denoise sequence of `run_render` are mirrored here, not yet called from there).

use std::path::{Path, PathBuf};

use crate::dataset::{self, FrameRenderer, GenerateOptions, Summary};
use crate::render::{control::Control, RenderOptions, RenderOutput};
use crate::scene::{Override, Scene};

/// What went wrong, coarsely: the front end's exception type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// A scene folder, scene file, data path or value that is wrong.
    Scene,
    /// Something blendsynth cannot evaluate (a node, option or modifier): never a stand-in.
    Unsupported,
    Render,
    /// The render was stopped through its `Control`.
    Cancelled,
    /// Finding or running Blender for `convert`.
    Blender,
    /// A dataset spec, split, shard or output folder.
    Dataset,
}

#[derive(Debug, Clone)]
pub struct ApiError {
    pub kind: ErrorKind,
    /// The message the CLI prints after `error: `.
    pub message: String,
}

impl std::fmt::Display for ApiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
impl std::error::Error for ApiError {}

impl ApiError {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> ApiError {
        let message: String = message.into();
        // Errors are strings below this layer; "not supported" is how every evaluator
        // names what it does not evaluate (shader compiler, Geometry Nodes, colour, ...).
        let kind = if matches!(kind, ErrorKind::Render | ErrorKind::Scene)
            && (message.contains("not supported") || message.contains("unsupported"))
        {
            ErrorKind::Unsupported
        } else {
            kind
        };
        ApiError { kind, message }
    }
}

fn scene_err(e: impl std::fmt::Display) -> ApiError {
    ApiError::new(ErrorKind::Scene, e.to_string())
}

/// Loads and validates a scene folder (`Scene::load`).
pub fn load(dir: &Path) -> Result<Scene, ApiError> {
    Scene::load(dir).map_err(scene_err)
}

/// One `--set` override from a path and a JSON value.
pub fn parse_override(path: &str, value: serde_json::Value) -> Override {
    Override {
        path: path.strip_prefix("bpy.data.").unwrap_or(path).to_string(),
        value,
    }
}

/// One `--set PATH=VALUE` argument, parsed as the CLI parses it.
pub fn parse_override_arg(s: &str) -> Result<Override, ApiError> {
    Override::parse(s).map_err(scene_err)
}

/// `scene` with overrides applied and validated again (the CLI's `--set`).
pub fn apply(scene: &Scene, overrides: &[Override]) -> Result<Scene, ApiError> {
    scene.with_overrides(overrides).map_err(scene_err)
}

/// The value at a `--set` data path (what an override there would replace).
pub fn get(scene: &Scene, path: &str) -> Result<serde_json::Value, ApiError> {
    let path = path.strip_prefix("bpy.data.").unwrap_or(path);
    let mut root = serde_json::to_value(&scene.file).map_err(scene_err)?;
    crate::scene::overrides::get(&mut root, path)
        .map_err(|m| scene_err(format!("{}: at {path}: {m}", scene.json_path().display())))
}

/// The render subcommand's settings (`None`: the scene's own).
#[derive(Debug, Clone, Default)]
pub struct RenderRequest {
    pub frame: Option<f64>,
    pub samples: Option<u32>,
    pub threshold: Option<f32>,
    pub resolution: Option<(u32, u32)>,
    pub seed: Option<u32>,
    pub threads: Option<usize>,
    pub denoise: Option<bool>,
    pub oidn: Option<PathBuf>,
}

pub struct Rendered {
    /// Linear RGBA (what `render -o X.exr` writes), denoised when asked, and the passes.
    pub out: RenderOutput,
    pub denoised: bool,
    /// The CLI's notice when denoising was asked for and no library was found.
    pub notice: Option<String>,
}

/// `blendsynth render`: the same render and denoising, without writing files.
pub fn render(
    scene: &Scene,
    req: &RenderRequest,
    control: Option<&Control>,
) -> Result<Rendered, ApiError> {
    let render_err = |e: crate::render::RenderError| {
        if e.is_cancelled() {
            ApiError::new(ErrorKind::Cancelled, e.0)
        } else {
            ApiError::new(
                ErrorKind::Render,
                format!("render {}: {e}", scene.dir.display()),
            )
        }
    };
    let opts = RenderOptions {
        frame: req.frame,
        samples: req.samples,
        threshold: req.threshold,
        resolution: req.resolution,
        seed: req.seed,
        threads: req.threads,
        progress: false,
    };
    // Find the denoiser before spending the render time, as the CLI does.
    let want = req
        .denoise
        .unwrap_or_else(|| crate::denoise::scene_wants_denoising(scene));
    let denoiser = if want {
        crate::denoise::Denoiser::load(req.oidn.as_deref())
            .map_err(|e| ApiError::new(ErrorKind::Render, e.to_string()))?
    } else {
        None
    };
    let notice = (want && denoiser.is_none()).then(|| {
        "no Open Image Denoise library found (oidn=, $BLENDSYNTH_OIDN, a bpy/Blender install or the pyoidn wheel); the image is noisy".to_string()
    });
    let mut out =
        crate::render::render_controlled(scene, &opts, &[], control).map_err(render_err)?;
    let denoised = denoiser.is_some();
    if let Some(d) = &denoiser {
        let frame = req.frame.unwrap_or(scene.file.scene.frame_current as f64);
        crate::denoise::denoise_render(d, scene, frame, &mut out)
            .map_err(|e| ApiError::new(ErrorKind::Render, format!("denoising: {e}")))?;
    }
    Ok(Rendered {
        out,
        denoised,
        notice,
    })
}

/// The display image `render -o X.png` writes: the scene's colour management, its output
/// format's bit depth and alpha (straight), as 8- or 16-bit codes, row-major.
pub struct Display {
    pub channels: usize,
    pub sixteen_bit: bool,
    pub codes: Vec<u16>,
}

pub fn display(scene: &Scene, linear: &[[f32; 4]]) -> Result<Display, ApiError> {
    let mut px = linear.to_vec();
    crate::color::to_display(scene, &mut px).map_err(scene_err)?;
    let f = crate::color::OutputFormat::from_scene(scene);
    let max = if f.sixteen_bit { 65535.0 } else { 255.0 };
    let channels = if f.alpha { 4 } else { 3 };
    let mut codes = Vec::with_capacity(px.len() * channels);
    for p in &px {
        // PNG stores straight alpha (as `color::write_png`).
        let p = if f.alpha && p[3] > 0.0 && p[3] != 1.0 {
            [p[0] / p[3], p[1] / p[3], p[2] / p[3], p[3]]
        } else {
            *p
        };
        codes.extend(
            p[..channels]
                .iter()
                .map(|&v| crate::color::quantize(v, max) as u16),
        );
    }
    Ok(Display {
        channels,
        sixteen_bit: f.sixteen_bit,
        codes,
    })
}

/// The class map `render --passes --classes SPEC` uses (a spec's [labels], or objects'
/// `class` custom property without one), and its mm per scene unit.
pub fn class_map(
    scene: &Scene,
    spec: Option<&Path>,
) -> Result<(crate::label::ClassMap, f64), ApiError> {
    let labels = match spec {
        Some(f) => {
            dataset::spec::Spec::load(f)
                .map_err(|e| ApiError::new(ErrorKind::Dataset, e.to_string()))?
                .labels
        }
        None => crate::label::LabelSpec::default(),
    };
    Ok((
        crate::label::ClassMap::new(&labels, scene),
        labels.mm_per_unit,
    ))
}

/// The semantic pass (0 background, else class index + 1) of a render.
pub fn semantic(out: &RenderOutput, classes: &crate::label::ClassMap) -> Vec<u32> {
    let p = &out.passes;
    let objects: Vec<String> = p.instances.iter().map(|i| i.object.clone()).collect();
    let images = crate::label::passes::PassImages {
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
        aovs: Vec::new(),
        view_layer: "",
    };
    crate::label::passes::semantic(&images, classes)
}

/// `blendsynth mesh`: the object's evaluated geometry at `frame` (default: the scene's
/// current frame) with the overrides, instances realised.
pub fn mesh(
    scene: &Scene,
    object: &str,
    frame: Option<f64>,
    overrides: &[Override],
) -> Result<crate::geometry::Mesh, ApiError> {
    let ov: Vec<(String, serde_json::Value)> = overrides
        .iter()
        .map(|o| (o.path.clone(), o.value.clone()))
        .collect();
    let frame = frame.unwrap_or(scene.file.scene.frame_current as f64);
    let err = |e: crate::geometry::GeometryError| {
        let m = format!("mesh {object:?}: {e}");
        let kind = if scene.object(object).is_none() {
            ErrorKind::Scene
        } else {
            ErrorKind::Render
        };
        ApiError::new(kind, m)
    };
    let set = crate::geometry::evaluate_object(scene, object, frame, &ov).map_err(err)?;
    crate::geometry::realize_to_mesh(&set).map_err(err)
}

/// `blendsynth inspect --json`, as a JSON string, and whether every node type is supported.
pub fn inspect_json(scene: &Scene) -> Result<(String, bool), ApiError> {
    for i in 0..scene.file.meshes.len() {
        scene.load_mesh(i).map_err(scene_err)?;
    }
    let report = crate::inspect::report(scene);
    let json = serde_json::to_string(&report).map_err(scene_err)?;
    Ok((json, report.all_supported))
}

/// `blendsynth convert`: the loaded result and the export's warnings.
pub fn convert(
    input: &Path,
    out: &Path,
    blender: Option<PathBuf>,
    frame: Option<i32>,
    no_evaluated: bool,
    allow_paths: Vec<PathBuf>,
) -> Result<Scene, ApiError> {
    let opts = crate::blender::ConvertOptions {
        blender,
        frame,
        frames: None,
        no_evaluated,
        allow_paths,
    };
    crate::blender::convert(input, out, &opts)
        .map_err(|e| ApiError::new(ErrorKind::Blender, format!("{e:#}").replace('\n', " ")))
}

/// The options `generate` and `replicate` share (the CLI's RunArgs).
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    pub seed: u64,
    /// "I/N".
    pub shard: Option<String>,
    pub resume: bool,
    pub jobs: Option<usize>,
    /// "path" (default) or "bounds" (the debugging stand-in).
    pub renderer: Option<String>,
    pub progress: bool,
}

fn dataset_err(e: impl std::fmt::Display) -> ApiError {
    ApiError::new(ErrorKind::Dataset, e.to_string())
}

fn generate_options(
    run: &RunOptions,
    frames: u64,
    split: Vec<(String, f64)>,
) -> Result<GenerateOptions, ApiError> {
    if frames == 0 {
        return Err(dataset_err("--frames must be at least 1"));
    }
    let cores = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    Ok(GenerateOptions {
        frames,
        seed: run.seed,
        split,
        shard: run
            .shard
            .as_deref()
            .map(dataset::generate::parse_shard)
            .transpose()
            .map_err(dataset_err)?
            .unwrap_or((0, 1)),
        resume: run.resume,
        jobs: run.jobs.unwrap_or(cores).max(1),
        threads_per_frame: 1,
        progress: run.progress,
        after_write: None,
    })
}

fn make_renderer(run: &RunOptions, scene: &Scene) -> Result<Box<dyn FrameRenderer>, ApiError> {
    match run.renderer.as_deref().unwrap_or("path") {
        "path" => dataset::renderer::path_tracer(scene).map_err(dataset_err),
        "bounds" => Ok(Box::new(
            dataset::bounds::BoundsRenderer::new(scene).map_err(dataset_err)?,
        )),
        other => Err(dataset_err(format!(
            "renderer {other:?}: expected \"path\" or \"bounds\""
        ))),
    }
}

/// `blendsynth generate`.
pub fn generate(
    dir: &Path,
    spec: &Path,
    frames: u64,
    out: &Path,
    split: &str,
    run: &RunOptions,
) -> Result<Summary, ApiError> {
    let scene = load(dir)?;
    let spec = dataset::Spec::load(spec).map_err(dataset_err)?;
    let split = dataset::generate::parse_split(split).map_err(dataset_err)?;
    let opts = generate_options(run, frames, split)?;
    let renderer = make_renderer(run, &scene)?;
    dataset::generate(&scene, &spec, renderer.as_ref(), out, &opts).map_err(dataset_err)
}

/// `blendsynth replicate`: one summary per part.
pub fn replicate(
    name: &str,
    part: &str,
    frames: u64,
    assets: Option<&Path>,
    out: &Path,
    run: &RunOptions,
) -> Result<Vec<Summary>, ApiError> {
    use dataset::replicate::{self, Part};
    if name != replicate::DATASET {
        return Err(dataset_err(format!(
            "unknown dataset {name:?} (known: {})",
            replicate::DATASET
        )));
    }
    let part = <Part as clap::ValueEnum>::from_str(part, true).map_err(|_| {
        dataset_err(format!(
            "part {part:?}: expected colonoscopy, laparoscopy or all"
        ))
    })?;
    let parts = part.parts();
    let mut summaries = Vec::new();
    for p in &parts {
        let (scene, spec) = replicate::scene_and_spec(*p, assets).map_err(dataset_err)?;
        let dest = if parts.len() > 1 {
            out.join(p.name())
        } else {
            out.to_path_buf()
        };
        let opts = generate_options(run, frames, replicate::split())?;
        let renderer = make_renderer(run, &scene)?;
        summaries.push(
            dataset::generate(&scene, &spec, renderer.as_ref(), &dest, &opts)
                .map_err(dataset_err)?,
        );
    }
    Ok(summaries)
}
