//! Denoising as Cycles does it by default: Intel Open Image Denoise's "RT" filter on the
//! HDR colour with albedo and normal guides. OIDN has no Debian package, so the library is
//! loaded at run time (the copy shipped with Blender or the bpy wheel, a pip wheel, or a
//! path the user gives) and called through its C API. Where none is installed,
//! `find_for_render` fetches a pinned copy into the user's cache folder (`provision`).
//!
//! Cycles (intern/cycles/integrator/denoiser_oidn.cpp, 4.5): CPU device with
//! `setAffinity` off; filter "RT" with `hdr` on, `srgb` off, `quality` from the scene
//! (High by default); with the Accurate prefilter (the default) each guide is first
//! denoised by its own RT filter and the main filter gets `cleanAux` on; with the None
//! prefilter `cleanAux` is on and guides are used as they are; with Fast it is off.
//!
//! The guides are Cycles' denoising passes ("Denoising Albedo", "Denoising Normal"): the
//! normal is in Cycles' camera space (x right, y up, z forward away from the camera, see
//! `cycles_denoise_normal`), (0, 0, 0) where the ray hits the background; the albedo there
//! is the background colour. Images are row-major, top row first, like the renderer's.

mod oidn;
pub mod provision;

use std::path::{Path, PathBuf};

pub use oidn::DenoiseError;

/// Which guides to give OIDN and how to prefilter them (scene.cycles.denoising_*).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prefilter {
    None,
    Fast,
    Accurate,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    Fast,
    Balanced,
    High,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DenoiseOptions {
    pub prefilter: Prefilter,
    pub quality: Quality,
    pub use_albedo: bool,
    pub use_normal: bool,
}

impl Default for DenoiseOptions {
    /// Cycles 4.5's defaults.
    fn default() -> Self {
        DenoiseOptions {
            prefilter: Prefilter::Accurate,
            quality: Quality::High,
            use_albedo: true,
            use_normal: true,
        }
    }
}

impl DenoiseOptions {
    /// From `scene.cycles` (denoising_prefilter, denoising_quality, denoising_input_passes).
    pub fn from_scene(scene: &crate::scene::Scene) -> DenoiseOptions {
        let c = &scene.file.scene.cycles;
        let s = |k: &str| c.get(k).and_then(|v| v.as_str()).unwrap_or("");
        let d = DenoiseOptions::default();
        DenoiseOptions {
            prefilter: match s("denoising_prefilter") {
                "NONE" => Prefilter::None,
                "FAST" => Prefilter::Fast,
                _ => d.prefilter,
            },
            quality: match s("denoising_quality") {
                "FAST" => Quality::Fast,
                "BALANCED" => Quality::Balanced,
                _ => d.quality,
            },
            use_albedo: s("denoising_input_passes") != "RGB",
            use_normal: !matches!(s("denoising_input_passes"), "RGB" | "RGB_ALBEDO"),
        }
    }
}

/// A world-space shading normal in the convention of Cycles' denoising normal pass:
/// Cycles' camera space, which is Blender's camera frame with z flipped to point forward.
/// `camera_matrix_world` is the camera object's world matrix (rows, translation in column 3).
pub fn cycles_denoise_normal(
    world_normal: [f32; 3],
    camera_matrix_world: &[[f64; 4]; 4],
) -> [f32; 3] {
    let m = camera_matrix_world;
    let axis = |c: usize| {
        let v = [m[0][c], m[1][c], m[2][c]];
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 0.0 {
            [v[0] / l, v[1] / l, v[2] / l]
        } else {
            v
        }
    };
    let n = world_normal.map(|v| v as f64);
    let dot = |a: [f64; 3]| (a[0] * n[0] + a[1] * n[1] + a[2] * n[2]) as f32;
    [dot(axis(0)), dot(axis(1)), -dot(axis(2))]
}

/// The loaded libOpenImageDenoise.
pub struct Denoiser {
    lib: oidn::Lib,
    path: PathBuf,
}

impl std::fmt::Debug for Denoiser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Denoiser")
            .field("path", &self.path)
            .finish()
    }
}

const LIB_NAMES: &[&str] = &[
    "libOpenImageDenoise.so.2",
    "libOpenImageDenoise.so",
    "libOpenImageDenoise.2.dylib",
    "libOpenImageDenoise.dylib",
    "OpenImageDenoise.dll",
];

/// The library file in `dir`, if any.
fn lib_in(dir: &Path) -> Option<PathBuf> {
    LIB_NAMES.iter().map(|n| dir.join(n)).find(|p| p.is_file())
}

/// Python environments to look in: the repository/work dir `.venv`, $VIRTUAL_ENV, and the
/// environment of $BLENDSYNTH_BPY_PYTHON (the bpy Python `convert` uses).
fn python_envs() -> Vec<PathBuf> {
    let mut envs = Vec::new();
    if let Some(p) = std::env::var_os("BLENDSYNTH_BPY_PYTHON").filter(|p| !p.is_empty()) {
        if let Some(env) = Path::new(&p).parent().and_then(|b| b.parent()) {
            envs.push(env.to_path_buf());
        }
    }
    if let Some(v) = std::env::var_os("VIRTUAL_ENV").filter(|p| !p.is_empty()) {
        envs.push(PathBuf::from(v));
    }
    if let Ok(cwd) = std::env::current_dir() {
        envs.push(cwd.join(".venv"));
    }
    if let Some(home) = std::env::var_os("HOME") {
        envs.push(PathBuf::from(home).join(".local"));
    }
    envs.push(PathBuf::from("/usr/local"));
    envs.push(PathBuf::from("/usr"));
    envs
}

/// site-packages folders of a Python environment (lib/python3.*/site-packages, dist-packages).
fn site_packages(env: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for lib in ["lib", "lib64"] {
        if let Ok(rd) = std::fs::read_dir(env.join(lib)) {
            let mut dirs: Vec<PathBuf> = rd
                .flatten()
                .map(|e| e.path())
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("python3"))
                })
                .collect();
            dirs.sort();
            for d in dirs {
                for sp in ["site-packages", "dist-packages"] {
                    let p = d.join(sp);
                    if p.is_dir() {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
}

/// Every place searched, in order (for the "not found" notice and for `load`).
pub fn candidate_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    for env in python_envs() {
        for sp in site_packages(&env) {
            // bpy wheel: bpy/lib; OIDN Python wheels keep the library in their package dir
            // or a lib folder inside it.
            dirs.push(sp.join("bpy/lib"));
            for pkg in ["oidn", "pyoidn"] {
                dirs.push(sp.join(pkg));
                dirs.push(sp.join(pkg).join("lib"));
                dirs.push(sp.join(pkg).join("libs"));
            }
            dirs.push(sp.join("pyoidn/oidn/lib"));
            dirs.push(sp.join("pyoidn.libs"));
        }
    }
    // A Blender installation: <blender dir>/lib next to the executable found on PATH or
    // named by $BLENDSYNTH_BLENDER.
    let mut blenders = Vec::new();
    if let Some(b) = std::env::var_os("BLENDSYNTH_BLENDER").filter(|p| !p.is_empty()) {
        blenders.push(PathBuf::from(b));
    }
    if let Some(path) = std::env::var_os("PATH") {
        for d in std::env::split_paths(&path) {
            let b = d.join("blender");
            if b.is_file() {
                blenders.push(b);
            }
        }
    }
    for b in blenders {
        let b = std::fs::canonicalize(&b).unwrap_or(b);
        if let Some(d) = b.parent() {
            dirs.push(d.join("lib"));
        }
    }
    dirs
}

impl Denoiser {
    /// Finds libOpenImageDenoise: `explicit` (the library file or its folder),
    /// $BLENDSYNTH_OIDN, the bpy/Blender installation, a pip OIDN wheel. Ok(None) when
    /// none is found (the caller prints a notice and keeps the noisy image); an error when
    /// a library is named or found but cannot be used.
    pub fn load(explicit: Option<&Path>) -> Result<Option<Denoiser>, DenoiseError> {
        let named = explicit.map(Path::to_path_buf).or_else(|| {
            std::env::var_os("BLENDSYNTH_OIDN")
                .filter(|p| !p.is_empty())
                .map(PathBuf::from)
        });
        if let Some(p) = named {
            let file = if p.is_dir() {
                lib_in(&p).ok_or_else(|| DenoiseError::NotFound(p.clone()))?
            } else {
                p.clone()
            };
            if !file.is_file() {
                return Err(DenoiseError::NotFound(file));
            }
            return Self::open(&file).map(Some);
        }
        for d in candidate_dirs() {
            if let Some(file) = lib_in(&d) {
                return Self::open(&file).map(Some);
            }
        }
        Ok(None)
    }

    fn open(file: &Path) -> Result<Denoiser, DenoiseError> {
        Ok(Denoiser {
            lib: oidn::Lib::open(file)?,
            path: file.to_path_buf(),
        })
    }

    /// The library file in use.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Cycles' default: RT filter, hdr, albedo + normal guides (prefiltered as Cycles does).
    pub fn denoise(
        &self,
        width: u32,
        height: u32,
        color: &mut [[f32; 4]],
        albedo: &[[f32; 3]],
        normal: &[[f32; 3]],
    ) -> Result<(), DenoiseError> {
        self.denoise_with(
            width,
            height,
            color,
            albedo,
            normal,
            &DenoiseOptions::default(),
        )
    }

    /// As `denoise`, with the scene's prefilter / quality / guide choice. Alpha is kept.
    pub fn denoise_with(
        &self,
        width: u32,
        height: u32,
        color: &mut [[f32; 4]],
        albedo: &[[f32; 3]],
        normal: &[[f32; 3]],
        opts: &DenoiseOptions,
    ) -> Result<(), DenoiseError> {
        let n = width as usize * height as usize;
        if width == 0 || height == 0 {
            return Err(DenoiseError::Input(format!("empty {width}x{height} image")));
        }
        if color.len() != n {
            return Err(DenoiseError::Input(format!(
                "colour has {} pixels, {width}x{height} needs {n}",
                color.len()
            )));
        }
        if opts.use_albedo && albedo.len() != n {
            return Err(DenoiseError::Input(format!(
                "albedo guide has {} pixels, {width}x{height} needs {n}",
                albedo.len()
            )));
        }
        if opts.use_normal && normal.len() != n {
            return Err(DenoiseError::Input(format!(
                "normal guide has {} pixels, {width}x{height} needs {n}",
                normal.len()
            )));
        }
        // OIDN reads and writes packed float3 buffers; non-finite input would spread, so
        // it is zeroed first (Cycles' passes are finite by construction). Rows go bottom-up,
        // as in Cycles' render buffers: the network is not exactly symmetric under a vertical
        // flip, and matching Cycles' result bit for bit needs its row order.
        let finite = |v: f32| if v.is_finite() { v } else { 0.0 };
        let w = width as usize;
        let bottom_up = |i: usize| (height as usize - 1 - i / w) * w + i % w;
        let mut rgb: Vec<[f32; 3]> = (0..n)
            .map(|i| color[bottom_up(i)])
            .map(|p| [finite(p[0]), finite(p[1]), finite(p[2])])
            .collect();
        let mut alb: Vec<[f32; 3]> = if opts.use_albedo {
            (0..n).map(|i| albedo[bottom_up(i)].map(finite)).collect()
        } else {
            Vec::new()
        };
        let mut nrm: Vec<[f32; 3]> = if opts.use_normal {
            (0..n).map(|i| normal[bottom_up(i)].map(finite)).collect()
        } else {
            Vec::new()
        };
        let mut out = vec![[0.0f32; 3]; n];
        let quality = match opts.quality {
            Quality::Fast => oidn::QUALITY_FAST,
            Quality::Balanced => oidn::QUALITY_BALANCED,
            Quality::High => oidn::QUALITY_HIGH,
        };
        let dev = self.lib.device()?;
        if opts.prefilter == Prefilter::Accurate {
            for (guide, name) in [(&mut alb, "albedo"), (&mut nrm, "normal")] {
                if guide.is_empty() {
                    continue;
                }
                let mut filtered = vec![[0.0f32; 3]; n];
                let f = dev.filter("RT")?;
                f.image(name, guide.as_mut_ptr().cast(), width, height)?;
                f.image("output", filtered.as_mut_ptr().cast(), width, height)?;
                f.set_int("quality", quality);
                f.run()?;
                *guide = filtered;
            }
        }
        let f = dev.filter("RT")?;
        f.image("color", rgb.as_mut_ptr().cast(), width, height)?;
        if !alb.is_empty() {
            f.image("albedo", alb.as_mut_ptr().cast(), width, height)?;
        }
        if !nrm.is_empty() {
            if alb.is_empty() {
                return Err(DenoiseError::Input(
                    "OIDN needs the albedo guide when the normal guide is given".into(),
                ));
            }
            f.image("normal", nrm.as_mut_ptr().cast(), width, height)?;
        }
        f.image("output", out.as_mut_ptr().cast(), width, height)?;
        f.set_bool("hdr", true);
        f.set_bool("srgb", false);
        f.set_int("quality", quality);
        if matches!(opts.prefilter, Prefilter::None | Prefilter::Accurate)
            && (!alb.is_empty() || !nrm.is_empty())
        {
            f.set_bool("cleanAux", true);
        }
        f.run()?;
        for (i, o) in out.iter().enumerate() {
            let p = &mut color[bottom_up(i)];
            p[0] = o[0];
            p[1] = o[1];
            p[2] = o[2];
        }
        Ok(())
    }
}

/// Denoises a finished render in place as Cycles does after its last sample: the
/// renderer's world-space guide normals are first turned into Cycles' camera-space
/// convention (background stays zero) using the scene camera at `frame`.
pub fn denoise_render(
    denoiser: &Denoiser,
    scene: &crate::scene::Scene,
    frame: f64,
    out: &mut crate::render::RenderOutput,
) -> Result<(), DenoiseError> {
    let cam_name = scene
        .camera_at(frame)
        .map_err(DenoiseError::Input)?
        .ok_or_else(|| DenoiseError::Input("the scene has no camera".into()))?;
    let idx = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == cam_name)
        .ok_or_else(|| DenoiseError::Input(format!("camera object {cam_name:?} not found")))?;
    let mats = crate::anim::evaluate_transforms(scene, frame)
        .map_err(|e| DenoiseError::Input(format!("camera at frame {frame}: {e}")))?;
    let cam = mats[idx];
    let p = &out.passes;
    // The guide is already zero where every sample saw the background.
    let normal: Vec<[f32; 3]> = p
        .denoise_normal
        .iter()
        .map(|n| cycles_denoise_normal(*n, &cam))
        .collect();
    denoiser.denoise_with(
        out.width,
        out.height,
        &mut out.color,
        &p.albedo,
        &normal,
        &DenoiseOptions::from_scene(scene),
    )
}

/// Whether the scene asks for denoising of the final render (`cycles.use_denoising`).
pub fn scene_wants_denoising(scene: &crate::scene::Scene) -> bool {
    crate::scene::settings::Integrator::of(&scene.file.scene).use_denoising
}

/// How the install command is spelled in notices: this executable when it is the
/// blendsynth CLI, else `blendsynth`.
fn cli_name() -> String {
    std::env::current_exe()
        .ok()
        .filter(|p| p.file_stem().is_some_and(|s| s == "blendsynth"))
        .map(|p| p.display().to_string())
        .unwrap_or_else(|| "blendsynth".into())
}

/// The command that installs OIDN where blendsynth finds it (where no wheel is pinned
/// for the platform, what to set instead).
pub fn install_command() -> String {
    if provision::PINNED.is_some() {
        format!("{} fetch-oidn", cli_name())
    } else {
        "set BLENDSYNTH_OIDN to an Open Image Denoise 2.x library (no pyoidn wheel is pinned for this platform)".into()
    }
}

/// The denoiser for `render`, `generate` and `replicate`: `Denoiser::load`'s search
/// (`explicit`, $BLENDSYNTH_OIDN, bpy/Blender, pip wheels), then the copy provisioned in
/// the cache folder, then, unless $BLENDSYNTH_OIDN_DOWNLOAD turns it off, provisioning it
/// now. Notices go to stderr; not finding or not fetching the library is a notice and
/// Ok(None) (images are then written noisy), while a library that is named or installed
/// but unusable stays an error.
pub fn find_for_render(explicit: Option<&Path>) -> Result<Option<Denoiser>, DenoiseError> {
    if let Some(d) = Denoiser::load(explicit)? {
        return Ok(Some(d));
    }
    let noisy = "images that ask for denoising are written noisy";
    let root = match provision::cache_root() {
        Ok(r) => r,
        Err(e) => {
            eprintln!(
                "notice: no Open Image Denoise library found, and {e}; {noisy}. To install it: {}",
                install_command()
            );
            return Ok(None);
        }
    };
    if let Some(dir) = provision::existing(&root) {
        return match lib_in(&dir).map(|f| Denoiser::open(&f)) {
            Some(Ok(d)) => Ok(Some(d)),
            Some(Err(e)) => {
                eprintln!(
                    "notice: {e}; {noisy}. Delete {} to download it again",
                    dir.parent().unwrap_or(&dir).display()
                );
                Ok(None)
            }
            None => Ok(None),
        };
    }
    if !provision::enabled() {
        eprintln!(
            "notice: no Open Image Denoise library found ($BLENDSYNTH_OIDN, a bpy/Blender install, a pyoidn wheel, {}) and downloading it is turned off (--no-oidn-download or {}=0); {noisy}. To install it: {}",
            provision::lib_dir(&root).unwrap_or_else(|_| root.clone()).display(),
            provision::DOWNLOAD_ENV,
            install_command()
        );
        return Ok(None);
    }
    let t0 = std::time::Instant::now();
    let fetched = provision::provision(&root, &|m| eprintln!("{m}"))
        .map_err(DenoiseError::from)
        .and_then(|dir| {
            let f = lib_in(&dir).ok_or_else(|| DenoiseError::NotFound(dir.clone()))?;
            Denoiser::open(&f)
        });
    match fetched {
        Ok(d) => {
            eprintln!(
                "notice: Open Image Denoise ready in {} ({:.1} s); later runs load it from there",
                d.path().parent().unwrap_or(d.path()).display(),
                t0.elapsed().as_secs_f64()
            );
            Ok(Some(d))
        }
        Err(e) => {
            eprintln!("notice: {e}; {noisy}. To install it by hand: {} (on a machine with network; then set BLENDSYNTH_OIDN to the folder it prints if the cache folder is not shared)", install_command());
            Ok(None)
        }
    }
}

/// `blendsynth fetch-oidn`: provisions OIDN under `root` (default: the cache folder)
/// whatever $BLENDSYNTH_OIDN_DOWNLOAD says, checks that the library loads, and returns
/// its folder.
pub fn fetch(root: Option<&Path>) -> Result<PathBuf, DenoiseError> {
    let root = match root {
        Some(r) => std::path::absolute(r)
            .map_err(|e| DenoiseError::Input(format!("{}: {e}", r.display())))?,
        None => provision::cache_root()?,
    };
    let dir = provision::provision(&root, &|m| eprintln!("{m}"))?;
    let f = lib_in(&dir).ok_or_else(|| DenoiseError::NotFound(dir.clone()))?;
    Denoiser::open(&f)?;
    Ok(dir)
}
