//! Finding a Blender and running the exporter in it (`blendsynth convert`).
//!
//! Blender is only a converter here: it reads the .blend and writes the exchange
//! format; blendsynth never needs it to render. A .blend can carry Python, so Blender
//! always runs with auto-run scripts disabled, and the exporter opens the file itself
//! with `use_scripts=False`. A .blend can also name any file on the machine as an
//! image: the exporter copies only regular files under the .blend's folder or a folder
//! the user allowed (`allow_paths`), and lists every file it copies.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{anyhow, bail, Context, Result};

use crate::scene::Scene;

/// The exporter, embedded so an installed binary needs no source tree.
pub const EXPORT_SCRIPT: &str = include_str!("../../blender_export/export_scene.py");

/// How to run Blender's Python.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Runner {
    /// A `blender` executable, run headless.
    Blender(PathBuf),
    /// A Python interpreter that can `import bpy` (the `bpy` wheel from PyPI).
    BpyPython(PathBuf),
}

impl Runner {
    pub fn path(&self) -> &Path {
        match self {
            Runner::Blender(p) | Runner::BpyPython(p) => p,
        }
    }

    /// A command that runs `script` with `args` inside Blender, auto-run disabled.
    pub fn command(&self, script: &Path, args: &[&std::ffi::OsStr]) -> Command {
        let mut cmd;
        match self {
            Runner::Blender(b) => {
                cmd = Command::new(b);
                cmd.args([
                    "-b",
                    "--factory-startup",
                    "--disable-autoexec",
                    "--python-exit-code",
                    "1",
                    "--python",
                ]);
                cmd.arg(script).arg("--");
            }
            Runner::BpyPython(py) => {
                cmd = Command::new(py);
                cmd.arg(script);
            }
        }
        cmd.args(args);
        cmd
    }
}

pub const INSTALL_HINT: &str = "install Blender 4.2 LTS or newer and pass --blender PATH (or set BLENDSYNTH_BLENDER, or put `blender` on PATH), \
or install the bpy module (`python3.11 -m venv venv && venv/bin/pip install bpy==4.5.4`) and set BLENDSYNTH_BPY_PYTHON=venv/bin/python";

/// Finds Blender: `--blender PATH`, then `BLENDSYNTH_BLENDER`, then
/// `BLENDSYNTH_BPY_PYTHON`, then `blender` on PATH.
pub fn locate(explicit: Option<&Path>) -> Result<Runner> {
    let classify = |p: PathBuf| {
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().to_lowercase())
            .unwrap_or_default();
        if name.starts_with("python") {
            Runner::BpyPython(p)
        } else {
            Runner::Blender(p)
        }
    };
    if let Some(p) = explicit {
        if !p.is_file() {
            bail!("--blender {}: no such file", p.display());
        }
        return Ok(classify(p.to_path_buf()));
    }
    if let Some(p) = std::env::var_os("BLENDSYNTH_BLENDER").filter(|v| !v.is_empty()) {
        let p = PathBuf::from(p);
        if !p.is_file() {
            bail!("BLENDSYNTH_BLENDER={}: no such file", p.display());
        }
        return Ok(Runner::Blender(p));
    }
    if let Some(p) = std::env::var_os("BLENDSYNTH_BPY_PYTHON").filter(|v| !v.is_empty()) {
        let p = PathBuf::from(p);
        if !p.is_file() {
            bail!("BLENDSYNTH_BPY_PYTHON={}: no such file", p.display());
        }
        return Ok(Runner::BpyPython(p));
    }
    if let Some(p) = find_on_path("blender") {
        return Ok(Runner::Blender(p));
    }
    Err(anyhow!("no Blender found: {INSTALL_HINT}"))
}

fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(name))
        .find(|p| p.is_file())
}

/// Options of `blendsynth convert`.
#[derive(Debug, Clone, Default)]
pub struct ConvertOptions {
    pub blender: Option<PathBuf>,
    /// Frame to evaluate the reference meshes at (default: the file's current frame).
    pub frame: Option<i32>,
    /// `--frames A..B`: evaluate at frame A and also write the evaluated meshes of
    /// objects whose evaluation is animated at every frame A+1..B (excludes `frame`).
    pub frames: Option<(i32, i32)>,
    /// Skip writing evaluated reference meshes.
    pub no_evaluated: bool,
    /// Folders outside the .blend's own whose files (images) may be copied into the
    /// export (`--allow-path`). Files elsewhere are an error: a .blend can name any
    /// file on the machine, and an export is meant to be shared.
    pub allow_paths: Vec<PathBuf>,
}

/// A file `convert` copied into the export.
#[derive(Debug, Clone, PartialEq, Eq, serde::Deserialize)]
pub struct CopiedFile {
    /// The image (Blender name) that named it.
    pub image: String,
    /// Where it was read (symlinks resolved).
    pub from: PathBuf,
    /// Where it went, relative to the export folder.
    pub to: String,
}

/// Exports `input` into `out` with Blender, then loads and validates the result
/// (scene.json and every mesh). The export is written to a staging folder and moved
/// into place only when it is complete and valid, so `out` is never half-written.
pub fn convert(input: &Path, out: &Path, opts: &ConvertOptions) -> Result<Scene> {
    Ok(convert_listing(input, out, opts)?.0)
}

/// `convert`, also returning every file it copied into the export.
pub fn convert_listing(
    input: &Path,
    out: &Path,
    opts: &ConvertOptions,
) -> Result<(Scene, Vec<CopiedFile>)> {
    check_blend_file(input)?;
    let allowed = opts
        .allow_paths
        .iter()
        .map(|p| {
            std::fs::canonicalize(p)
                .ok()
                .filter(|c| c.is_dir())
                .ok_or_else(|| anyhow!("--allow-path {}: not a folder", p.display()))
        })
        .collect::<Result<Vec<_>>>()?;
    check_output_dir(out)?;

    let parent = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).with_context(|| {
        format!(
            "cannot create output folder {} (its parent {} cannot be created)",
            out.display(),
            parent.display()
        )
    })?;
    let stem = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "export".into());
    let staging = tempfile::Builder::new()
        .prefix(&format!(".{stem}.partial-"))
        .tempdir_in(parent)
        .with_context(|| format!("cannot write output folder {}", out.display()))?;

    let runner = locate(opts.blender.as_deref())?;
    let script_dir =
        tempfile::tempdir().context("cannot create a temporary folder for the exporter script")?;
    let script = script_dir.path().join("export_scene.py");
    std::fs::write(&script, EXPORT_SCRIPT).context("cannot write the exporter script")?;

    let input_abs = std::fs::canonicalize(input)
        .with_context(|| format!("cannot resolve {}", input.display()))?;
    let frame_s = opts.frame.map(|f| f.to_string());
    let frames_s = opts.frames.map(|(a, b)| format!("{a}..{b}"));
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "--in".as_ref(),
        input_abs.as_os_str(),
        "--out".as_ref(),
        staging.path().as_os_str(),
    ];
    if let Some(f) = &frame_s {
        args.push("--frame".as_ref());
        args.push(f.as_ref());
    }
    if let Some(f) = &frames_s {
        args.push("--frames".as_ref());
        args.push(f.as_ref());
    }
    if opts.no_evaluated {
        args.push("--no-evaluated".as_ref());
    }
    for a in &allowed {
        args.push("--allow-path".as_ref());
        args.push(a.as_os_str());
    }
    let copied_list = script_dir.path().join("copied.json");
    args.push("--copied-list".as_ref());
    args.push(copied_list.as_os_str());
    let output = runner
        .command(&script, &args)
        .stdin(Stdio::null())
        .output()
        .with_context(|| format!("cannot start Blender at {}", runner.path().display()))?;
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let stdout = String::from_utf8_lossy(&output.stdout);
        bail!(
            "Blender ({}) failed to export {} ({}): {}",
            runner.path().display(),
            input.display(),
            output.status,
            last_error_line(&stderr, &stdout)
        );
    }

    let copied: Vec<CopiedFile> = std::fs::read(&copied_list)
        .ok()
        .and_then(|b| serde_json::from_slice(&b).ok())
        .ok_or_else(|| anyhow!("the exporter did not list the files it copied"))?;

    // Validate everything before the export replaces anything.
    let staged = Scene::load(staging.path()).context("the exporter wrote an invalid scene")?;
    for i in 0..staged.file.meshes.len() {
        staged.load_mesh(i)?;
    }
    for i in 0..staged.file.evaluated.len() {
        staged.load_evaluated(i)?;
    }
    let staging_path = staging.keep();
    if out.exists() {
        std::fs::remove_dir_all(out)
            .with_context(|| format!("cannot replace {}", out.display()))?;
    }
    std::fs::rename(&staging_path, out)
        .with_context(|| format!("cannot move the export into {}", out.display()))?;
    Ok((Scene::load(out)?, copied))
}

/// The input must exist and look like a .blend (plain, gzip or zstd compressed).
fn check_blend_file(input: &Path) -> Result<()> {
    use std::io::Read;
    let mut f = std::fs::File::open(input).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => anyhow!("input file not found: {}", input.display()),
        _ => anyhow!("cannot open {}: {e}", input.display()),
    })?;
    if input.is_dir() {
        bail!("{} is a folder, expected a .blend file", input.display());
    }
    let mut head = [0u8; 7];
    let n = f.read(&mut head).unwrap_or(0);
    let ok = &head[..n] == b"BLENDER"
        || head[..n].starts_with(&[0x28, 0xB5, 0x2F, 0xFD])
        || head[..n].starts_with(&[0x1F, 0x8B]);
    if !ok {
        bail!(
            "{} is not a .blend file (no BLENDER header)",
            input.display()
        );
    }
    Ok(())
}

/// Refuses to overwrite a folder that is not an earlier export.
fn check_output_dir(out: &Path) -> Result<()> {
    if out.is_file() {
        bail!("output {} is a file; give a folder", out.display());
    }
    if out.is_dir() {
        let empty = std::fs::read_dir(out)
            .map(|mut d| d.next().is_none())
            .unwrap_or(false);
        if !empty && !out.join("scene.json").is_file() {
            bail!("output folder {} exists and is not a blendsynth export; choose another or remove it", out.display());
        }
    }
    Ok(())
}

/// One line out of Blender's output that says what went wrong.
fn last_error_line(stderr: &str, stdout: &str) -> String {
    let lines: Vec<&str> = stderr
        .lines()
        .chain(stdout.lines())
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines
        .iter()
        .rev()
        .find(|l| l.contains("rror") || l.starts_with("blendsynth-export:"))
        .or(lines.last())
        .map(|l| l.to_string())
        .unwrap_or_else(|| "no output".into())
}
