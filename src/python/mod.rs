//! The `blendsynth._native` extension module: thin PyO3 wrappers over `crate::api`.
//! The Python package (`python/blendsynth/`) builds its typed API on these: values cross
//! as JSON text, pixel data as `bytearray`s that NumPy views without copying again.
//!
//! A render runs on its own thread while the calling thread waits with the GIL released;
//! every 100 ms it wakes (with the GIL) to report progress, run Python's signal handlers
//! (Ctrl-C) and cancel the render when either raises. The result wakes it at once.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict};

use crate::api::{self, ApiError, ErrorKind};
use crate::render::control::Control;
use crate::scene::{Override, Scene};

pyo3::create_exception!(
    blendsynth,
    BlendsynthError,
    PyException,
    "Base class of every blendsynth error."
);
pyo3::create_exception!(
    blendsynth,
    SceneError,
    BlendsynthError,
    "A scene folder, scene file, data path or value is wrong."
);
pyo3::create_exception!(
    blendsynth,
    UnsupportedError,
    BlendsynthError,
    "The scene uses something blendsynth does not evaluate (named in the message)."
);
pyo3::create_exception!(blendsynth, RenderError, BlendsynthError, "A render failed.");
pyo3::create_exception!(
    blendsynth,
    Cancelled,
    BlendsynthError,
    "A render was cancelled (CancelToken.cancel())."
);
pyo3::create_exception!(
    blendsynth,
    BlenderError,
    BlendsynthError,
    "Finding or running Blender for convert() failed."
);
pyo3::create_exception!(
    blendsynth,
    DatasetError,
    BlendsynthError,
    "A dataset spec, split, shard or output folder is wrong."
);

fn py_err(e: ApiError) -> PyErr {
    let m = e.message;
    match e.kind {
        ErrorKind::Scene => SceneError::new_err(m),
        ErrorKind::Unsupported => UnsupportedError::new_err(m),
        ErrorKind::Render => RenderError::new_err(m),
        ErrorKind::Cancelled => Cancelled::new_err(m),
        ErrorKind::Blender => BlenderError::new_err(m),
        ErrorKind::Dataset => DatasetError::new_err(m),
    }
}

/// Plain-old-data values copied into a `bytearray` (native byte order).
trait Pod: Copy {
    const SIZE: usize;
    fn put(&self, out: &mut [u8]);
}
macro_rules! pod {
    ($($t:ty),*) => {$(
        impl Pod for $t {
            const SIZE: usize = std::mem::size_of::<$t>();
            fn put(&self, out: &mut [u8]) {
                out.copy_from_slice(&self.to_ne_bytes());
            }
        }
    )*};
}
pod!(f32, u32, u16, u8);
impl<T: Pod, const N: usize> Pod for [T; N] {
    const SIZE: usize = T::SIZE * N;
    fn put(&self, out: &mut [u8]) {
        for (v, o) in self.iter().zip(out.chunks_exact_mut(T::SIZE)) {
            v.put(o);
        }
    }
}

fn bytes<'py, T: Pod>(py: Python<'py>, v: &[T]) -> PyResult<Bound<'py, PyByteArray>> {
    PyByteArray::new_with(py, v.len() * T::SIZE, |buf| {
        for (x, o) in v.iter().zip(buf.chunks_exact_mut(T::SIZE)) {
            x.put(o);
        }
        Ok(())
    })
}

/// A flag that stops renders from another thread: pass it as `cancel=` and call
/// `cancel()`.
#[pyclass(module = "blendsynth._native", frozen)]
struct CancelToken {
    flag: Arc<AtomicBool>,
}

#[pymethods]
impl CancelToken {
    #[new]
    fn new() -> Self {
        CancelToken {
            flag: Arc::new(AtomicBool::new(false)),
        }
    }
    /// Stops every render using this token (tiles not started are skipped).
    fn cancel(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }
    #[getter]
    fn cancelled(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }
    /// Clears the flag so the token can be used again.
    fn reset(&self) {
        self.flag.store(false, Ordering::Relaxed);
    }
}

/// An exported scene with its overrides and frame (see the Python `Scene`).
#[pyclass(name = "Scene", module = "blendsynth._native")]
struct PyScene {
    base: Arc<Scene>,
    overrides: Vec<Override>,
    /// `base` with the overrides applied (what `render` sees, as with `--set`).
    effective: Arc<Scene>,
    frame: Option<f64>,
}

impl PyScene {
    fn new(scene: Scene) -> PyScene {
        let base = Arc::new(scene);
        PyScene {
            effective: base.clone(),
            base,
            overrides: Vec::new(),
            frame: None,
        }
    }

    fn push(&mut self, o: Override) -> PyResult<()> {
        let mut all = self.overrides.clone();
        all.push(o);
        let scene = api::apply(&self.base, &all).map_err(py_err)?;
        self.overrides = all;
        self.effective = Arc::new(scene);
        Ok(())
    }
}

fn parse_json(s: &str) -> PyResult<serde_json::Value> {
    serde_json::from_str(s).map_err(|e| PyValueError::new_err(format!("value: {e}")))
}

#[pymethods]
impl PyScene {
    #[staticmethod]
    fn load(py: Python<'_>, dir: PathBuf) -> PyResult<Self> {
        let scene = py.detach(|| api::load(&dir)).map_err(py_err)?;
        Ok(PyScene::new(scene))
    }

    #[getter]
    fn dir(&self) -> PathBuf {
        self.base.dir.clone()
    }

    /// Overrides the value at a data path (`value_json`: JSON text).
    fn set(&mut self, path: &str, value_json: &str) -> PyResult<()> {
        let o = api::parse_override(path, parse_json(value_json)?);
        self.push(o)
    }

    /// One `--set PATH=VALUE` argument, parsed as the CLI does.
    fn set_arg(&mut self, arg: &str) -> PyResult<()> {
        let o = api::parse_override_arg(arg).map_err(py_err)?;
        self.push(o)
    }

    /// The value at a data path, as JSON text.
    fn get(&self, path: &str) -> PyResult<String> {
        let v = api::get(&self.effective, path).map_err(py_err)?;
        Ok(v.to_string())
    }

    /// The overrides set so far, as (path, JSON text).
    fn overrides(&self) -> Vec<(String, String)> {
        self.overrides
            .iter()
            .map(|o| (o.path.clone(), o.value.to_string()))
            .collect()
    }

    /// Drops every override.
    fn reset(&mut self) {
        self.overrides.clear();
        self.effective = self.base.clone();
    }

    #[getter]
    fn get_frame(&self) -> f64 {
        self.frame
            .unwrap_or(self.base.file.scene.frame_current as f64)
    }

    #[setter]
    fn set_frame(&mut self, frame: Option<f64>) -> PyResult<()> {
        if let Some(f) = frame {
            if !f.is_finite() {
                return Err(PyValueError::new_err(format!("frame {f} is not finite")));
            }
        }
        self.frame = frame;
        Ok(())
    }

    /// Object names, in the scene file's order.
    fn objects(&self) -> Vec<String> {
        self.effective
            .file
            .objects
            .iter()
            .map(|o| o.name.clone())
            .collect()
    }

    /// `blendsynth inspect --json` as JSON text.
    fn inspect(&self, py: Python<'_>) -> PyResult<String> {
        let scene = self.effective.clone();
        let (json, _) = py.detach(|| api::inspect_json(&scene)).map_err(py_err)?;
        Ok(json)
    }

    /// `blendsynth mesh`: positions (N x 3 f32), face offsets (F + 1 u32) and corner
    /// vertices (u32), as bytearrays.
    #[pyo3(signature = (object, frame=None))]
    fn mesh<'py>(
        &self,
        py: Python<'py>,
        object: &str,
        frame: Option<f64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (scene, overrides) = (self.base.clone(), self.overrides.clone());
        let frame = frame.or(self.frame);
        let m = py
            .detach(|| api::mesh(&scene, object, frame, &overrides))
            .map_err(py_err)?;
        let d = PyDict::new(py);
        d.set_item("positions", bytes(py, &m.positions)?)?;
        d.set_item("face_offsets", bytes(py, &m.face_offsets)?)?;
        d.set_item("corner_verts", bytes(py, &m.corner_verts)?)?;
        d.set_item("vertex_count", m.vertex_count())?;
        d.set_item("face_count", m.face_count())?;
        Ok(d)
    }

    /// `blendsynth render` without files: returns {pass: (bytearray, shape, dtype)} plus
    /// metadata. See the Python `Scene.render` for the arguments.
    #[pyo3(signature = (passes, samples=None, seed=None, resolution=None, threshold=None,
        denoise=None, threads=None, oidn=None, classes=None, frame=None, cancel=None,
        progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        passes: Vec<String>,
        samples: Option<u32>,
        seed: Option<u32>,
        resolution: Option<(u32, u32)>,
        threshold: Option<f32>,
        denoise: Option<bool>,
        threads: Option<usize>,
        oidn: Option<PathBuf>,
        classes: Option<PathBuf>,
        frame: Option<f64>,
        cancel: Option<PyRef<'py, CancelToken>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        const KNOWN: &[&str] = &[
            "image",
            "display",
            "depth",
            "distance",
            "normal",
            "albedo",
            "uv",
            "object_index",
            "instance_id",
            "material_index",
            "semantic",
            "sample_count",
            "aovs",
        ];
        if let Some(p) = passes.iter().find(|p| !KNOWN.contains(&p.as_str())) {
            return Err(PyValueError::new_err(format!(
                "unknown pass {p:?} (known: {})",
                KNOWN.join(", ")
            )));
        }
        if threads == Some(0) {
            return Err(PyValueError::new_err("threads must be at least 1"));
        }
        let scene = self.effective.clone();
        let classes = if passes.iter().any(|p| p == "semantic") {
            Some(api::class_map(&scene, classes.as_deref()).map_err(py_err)?)
        } else {
            None
        };
        let req = api::RenderRequest {
            frame: frame.or(self.frame),
            samples,
            threshold,
            resolution,
            seed,
            threads,
            denoise,
            oidn,
        };
        let control = Arc::new(match &cancel {
            Some(t) => Control::with_flag(t.flag.clone()),
            None => Control::new(),
        });
        drop(cancel);
        let r = run_render(py, scene.clone(), req, control, progress)?;
        let out = &r.out;
        let (w, h) = (out.width as usize, out.height as usize);
        let d = PyDict::new(py);
        let p = &out.passes;
        for name in &passes {
            let item = match name.as_str() {
                "image" => (bytes(py, &out.color)?, vec![h, w, 4], "float32"),
                "display" => {
                    let disp = api::display(&scene, &out.color).map_err(py_err)?;
                    if disp.sixteen_bit {
                        (bytes(py, &disp.codes)?, vec![h, w, disp.channels], "uint16")
                    } else {
                        let b: Vec<u8> = disp.codes.iter().map(|&c| c as u8).collect();
                        (bytes(py, &b)?, vec![h, w, disp.channels], "uint8")
                    }
                }
                "depth" => (bytes(py, &p.depth)?, vec![h, w], "float32"),
                "distance" => (bytes(py, &p.distance)?, vec![h, w], "float32"),
                "normal" => (bytes(py, &p.normal)?, vec![h, w, 3], "float32"),
                "albedo" => (bytes(py, &p.albedo)?, vec![h, w, 3], "float32"),
                "uv" => (bytes(py, &p.uv)?, vec![h, w, 2], "float32"),
                "object_index" => (bytes(py, &p.object_index)?, vec![h, w], "uint32"),
                "instance_id" => (bytes(py, &p.instance_id)?, vec![h, w], "uint32"),
                "material_index" => (bytes(py, &p.material_index)?, vec![h, w], "uint32"),
                "sample_count" => (bytes(py, &p.sample_count)?, vec![h, w], "uint32"),
                "semantic" => {
                    let (map, _) = classes.as_ref().expect("made above for semantic");
                    (bytes(py, &api::semantic(out, map))?, vec![h, w], "uint32")
                }
                "aovs" => {
                    // The view layer's AOV passes by name: (H, W) for a Value AOV,
                    // (H, W, 4) for a Color AOV, as aovs.exr holds them.
                    let aovs = PyDict::new(py);
                    for a in &p.aovs {
                        let shape = if a.color { vec![h, w, 4] } else { vec![h, w] };
                        aovs.set_item(&a.name, (bytes(py, &a.data)?, shape, "float32"))?;
                    }
                    d.set_item(name, aovs)?;
                    continue;
                }
                _ => unreachable!("checked against KNOWN"),
            };
            d.set_item(name, item)?;
        }
        let meta = PyDict::new(py);
        meta.set_item("width", out.width)?;
        meta.set_item("height", out.height)?;
        meta.set_item("samples", out.stats.samples)?;
        meta.set_item("samples_taken", out.stats.samples_taken)?;
        meta.set_item("seconds", out.stats.wall_seconds)?;
        meta.set_item("setup_seconds", out.stats.build_seconds)?;
        meta.set_item("triangles", out.stats.triangles)?;
        meta.set_item("denoised", r.denoised)?;
        meta.set_item("notice", r.notice.clone())?;
        let objects: Vec<&str> = p.instances.iter().map(|i| i.object.as_str()).collect();
        meta.set_item("instance_objects", objects)?;
        if let Some((map, mm)) = &classes {
            meta.set_item("class_names", map.names.clone())?;
            meta.set_item("mm_per_unit", *mm)?;
        }
        d.set_item("_meta", meta)?;
        Ok(d)
    }
}

/// Renders on a worker thread; the caller waits without the GIL and wakes every 100 ms
/// for progress and signals (a KeyboardInterrupt, or an exception from the callback,
/// cancels the render, waits for it to stop, and is raised).
fn run_render(
    py: Python<'_>,
    scene: Arc<Scene>,
    req: api::RenderRequest,
    control: Arc<Control>,
    progress: Option<Py<PyAny>>,
) -> PyResult<api::Rendered> {
    let (tx, mut rx) = mpsc::channel();
    let c = control.clone();
    std::thread::Builder::new()
        .name("blendsynth-render".into())
        .spawn(move || {
            let _ = tx.send(api::render(&scene, &req, Some(&c)));
        })
        .map_err(|e| RenderError::new_err(format!("cannot start the render thread: {e}")))?;
    let mut last = None;
    loop {
        let (got, back) = py.detach(move || (rx.recv_timeout(Duration::from_millis(100)), rx));
        rx = back;
        let interrupt = |e: PyErr, rx: mpsc::Receiver<_>| -> PyErr {
            control.cancel();
            let _ = py.detach(move || rx.recv());
            e
        };
        match got {
            Ok(r) => {
                let r = r.map_err(py_err)?;
                if let Some(cb) = &progress {
                    let (_, total) = control.progress();
                    cb.call1(py, (total, total))?;
                }
                return Ok(r);
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(RenderError::new_err(
                    "the render thread stopped unexpectedly",
                ));
            }
        }
        if let Err(e) = py.check_signals() {
            return Err(interrupt(e, rx));
        }
        if let Some(cb) = &progress {
            let p = control.progress();
            if last != Some(p) {
                last = Some(p);
                if let Err(e) = cb.call1(py, p) {
                    return Err(interrupt(e, rx));
                }
            }
        }
    }
}

/// `blendsynth convert`; returns the loaded scene.
#[pyfunction]
#[pyo3(signature = (blend, out_dir, blender=None, frame=None, evaluated=true, allow_paths=Vec::new()))]
fn convert(
    py: Python<'_>,
    blend: PathBuf,
    out_dir: PathBuf,
    blender: Option<PathBuf>,
    frame: Option<i32>,
    evaluated: bool,
    allow_paths: Vec<PathBuf>,
) -> PyResult<PyScene> {
    let scene = py
        .detach(|| api::convert(&blend, &out_dir, blender, frame, !evaluated, allow_paths))
        .map_err(py_err)?;
    Ok(PyScene::new(scene))
}

fn summary<'py>(py: Python<'py>, s: &crate::dataset::Summary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("out", s.out.clone())?;
    d.set_item("rendered", s.rendered)?;
    d.set_item("skipped", s.skipped)?;
    d.set_item("seconds", s.seconds)?;
    d.set_item("complete", s.complete)?;
    Ok(d)
}

/// `blendsynth generate`.
#[pyfunction]
#[pyo3(signature = (dir, spec, frames, out, split, seed, shard, resume, jobs, renderer, progress))]
#[allow(clippy::too_many_arguments)]
fn generate<'py>(
    py: Python<'py>,
    dir: PathBuf,
    spec: PathBuf,
    frames: u64,
    out: PathBuf,
    split: String,
    seed: u64,
    shard: Option<String>,
    resume: bool,
    jobs: Option<usize>,
    renderer: String,
    progress: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let run = api::RunOptions {
        seed,
        shard,
        resume,
        jobs,
        renderer: Some(renderer),
        progress,
    };
    let s = py
        .detach(|| api::generate(&dir, &spec, frames, &out, &split, &run))
        .map_err(py_err)?;
    summary(py, &s)
}

/// `blendsynth replicate`.
#[pyfunction]
#[pyo3(signature = (dataset, out, part, frames, assets, seed, shard, resume, jobs, renderer, progress))]
#[allow(clippy::too_many_arguments)]
fn replicate<'py>(
    py: Python<'py>,
    dataset: String,
    out: PathBuf,
    part: String,
    frames: u64,
    assets: Option<PathBuf>,
    seed: u64,
    shard: Option<String>,
    resume: bool,
    jobs: Option<usize>,
    renderer: String,
    progress: bool,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let run = api::RunOptions {
        seed,
        shard,
        resume,
        jobs,
        renderer: Some(renderer),
        progress,
    };
    let all = py
        .detach(|| api::replicate(&dataset, &part, frames, assets.as_deref(), &out, &run))
        .map_err(py_err)?;
    all.iter().map(|s| summary(py, s)).collect()
}

/// Reads a PNG/JPEG/EXR as (bytearray, shape, dtype): 8-bit images as uint8 (grey, RGB or
/// RGBA as stored), 16-bit as uint16, float as float32, so the dataset reader needs only
/// NumPy.
#[pyfunction]
fn read_image<'py>(
    py: Python<'py>,
    path: PathBuf,
) -> PyResult<(Bound<'py, PyByteArray>, Vec<usize>, &'static str)> {
    use image::DynamicImage as D;
    let img = py
        .detach(|| image::open(&path))
        .map_err(|e| pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display())))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    Ok(match img {
        D::ImageLuma8(b) => (bytes(py, b.as_raw())?, vec![h, w], "uint8"),
        D::ImageRgb8(b) => (bytes(py, b.as_raw())?, vec![h, w, 3], "uint8"),
        D::ImageRgba8(b) => (bytes(py, b.as_raw())?, vec![h, w, 4], "uint8"),
        D::ImageLuma16(b) => (bytes(py, b.as_raw())?, vec![h, w], "uint16"),
        D::ImageRgb16(b) => (bytes(py, b.as_raw())?, vec![h, w, 3], "uint16"),
        D::ImageRgba16(b) => (bytes(py, b.as_raw())?, vec![h, w, 4], "uint16"),
        D::ImageRgb32F(b) => (bytes(py, b.as_raw())?, vec![h, w, 3], "float32"),
        other => {
            let b = other.to_rgba32f();
            (bytes(py, b.as_raw())?, vec![h, w, 4], "float32")
        }
    })
}

#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyScene>()?;
    m.add_class::<CancelToken>()?;
    m.add_function(wrap_pyfunction!(convert, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(replicate, m)?)?;
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add("BlendsynthError", py.get_type::<BlendsynthError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("UnsupportedError", py.get_type::<UnsupportedError>())?;
    m.add("RenderError", py.get_type::<RenderError>())?;
    m.add("Cancelled", py.get_type::<Cancelled>())?;
    m.add("BlenderError", py.get_type::<BlenderError>())?;
    m.add("DatasetError", py.get_type::<DatasetError>())?;
    Ok(())
}
