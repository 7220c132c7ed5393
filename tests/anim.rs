//! Scene evaluation at a frame against Blender's own values.
//!
//! - The fixture scenes in `fixtures/anim/scenes/` (made by `fixtures/anim/make_anim_refs.py`)
//!   carry `blender_ref.json`: every F-curve's value and every object's `matrix_world` at
//!   many frames, as Blender 4.5 computed them. We must agree within 1e-5 (F-curve values
//!   relative for large values).
//! - The published colon scene is exported and evaluated by Blender at test time (never
//!   copied here); its camera must match at frames 50, 527 and 11595.

mod common;
use common::*;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use blendsynth::anim::{
    evaluate_fcurve_as, evaluate_scene_with, evaluate_transforms, EvalOptions, Mat4, ValueKind,
};
use blendsynth::scene::{quote, Scene};
use serde::Deserialize;

const TOL: f64 = 1e-5;

#[derive(Deserialize)]
struct RefCurve {
    id_path: String,
    data_path: String,
    array_index: usize,
    values: Vec<f64>,
}

#[derive(Deserialize)]
struct Reference {
    frames: Vec<f64>,
    fcurves: Vec<RefCurve>,
    matrices: HashMap<String, Vec<Mat4>>,
    /// Animated curve and camera settings as Blender's depsgraph evaluated them.
    #[serde(default)]
    datablocks: Vec<RefCurve>,
}

fn scenes_dir() -> PathBuf {
    repo().join("fixtures/anim/scenes")
}

fn fixture_names() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir())
        .expect("fixtures/anim/scenes exists")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().join("blender_ref.json").is_file())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn load(name: &str) -> (Scene, Reference) {
    let dir = scenes_dir().join(name);
    let scene = Scene::load(&dir).unwrap_or_else(|e| panic!("{name}: {e}"));
    let text = std::fs::read_to_string(dir.join("blender_ref.json")).unwrap();
    (scene, serde_json::from_str(&text).unwrap())
}

/// Worst error and where it happened.
#[derive(Default)]
struct Worst {
    err: f64,
    at: String,
}

impl Worst {
    fn add(&mut self, err: f64, at: impl FnOnce() -> String) {
        if err > self.err || err.is_nan() {
            self.err = if err.is_nan() { f64::INFINITY } else { err };
            self.at = at();
        }
    }
}

/// F-curve error: absolute, relative above magnitude 1.
fn value_err(ours: f64, blender: f64) -> f64 {
    (ours - blender).abs() / blender.abs().max(1.0)
}

/// Matrix error: absolute, relative above magnitude 1 (Blender computes in single
/// precision, so a translation of 150 is only known to about 1e-5 absolute).
fn mat_abs_err(a: &Mat4, b: &Mat4) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..4 {
        for j in 0..4 {
            e = e.max((a[i][j] - b[i][j]).abs());
        }
    }
    e
}

fn mat_err(a: &Mat4, b: &Mat4) -> f64 {
    let mut e: f64 = 0.0;
    for i in 0..4 {
        for j in 0..4 {
            e = e.max((a[i][j] - b[i][j]).abs() / b[i][j].abs().max(1.0));
        }
    }
    e
}

fn fcurve_worst(scene: &Scene, r: &Reference, name: &str) -> Worst {
    let mut worst = Worst::default();
    for rc in &r.fcurves {
        let ad = scene
            .file
            .animation
            .iter()
            .find(|a| a.id_path == rc.id_path)
            .unwrap_or_else(|| panic!("{name}: no animation for {}", rc.id_path));
        let fc = ad
            .fcurves
            .iter()
            .find(|f| f.data_path == rc.data_path && f.array_index == rc.array_index)
            .unwrap_or_else(|| {
                panic!(
                    "{name}: {} has no F-curve {}[{}]",
                    rc.id_path, rc.data_path, rc.array_index
                )
            });
        // Integer and boolean custom properties are rounded / stepped by Blender.
        let kind = scene
            .file
            .objects
            .iter()
            .find(|o| rc.id_path == format!("objects[{}]", quote(&o.name)))
            .and_then(|o| {
                rc.data_path
                    .strip_prefix("[\"")?
                    .strip_suffix("\"]")
                    .and_then(|k| o.custom_properties.get(k))
            })
            .and_then(ValueKind::of_json)
            .unwrap_or_default();
        for (f, want) in r.frames.iter().zip(&rc.values) {
            let got = evaluate_fcurve_as(fc, *f, kind).unwrap_or_else(|e| panic!("{name}: {e}"));
            worst.add(value_err(got, *want), || {
                format!(
                    "{name} {} {}[{}] frame {f}: ours {got} Blender {want}",
                    rc.id_path, rc.data_path, rc.array_index
                )
            });
        }
    }
    worst
}

/// Animated datablock settings (curve `eval_time`, camera `lens`, ...) written into the
/// evaluated copy.
fn datablock_worst(scene: &Scene, r: &Reference, name: &str) -> Worst {
    let mut worst = Worst::default();
    let opts = EvalOptions { for_render: false };
    for (fi, f) in r.frames.iter().enumerate() {
        let ev = evaluate_scene_with(scene, *f, opts)
            .unwrap_or_else(|e| panic!("{name} frame {f}: {e}"));
        for d in &r.datablocks {
            let props = if let Some(c) = ev
                .data
                .curves
                .iter()
                .find(|c| d.id_path == format!("curves[{}]", quote(&c.name)))
            {
                &c.properties
            } else if let Some(c) = ev
                .data
                .cameras
                .iter()
                .find(|c| d.id_path == format!("cameras[{}]", quote(&c.name)))
            {
                &c.properties
            } else {
                panic!("{name}: no datablock {}", d.id_path)
            };
            let v = &props[&d.data_path];
            let got = if v.is_array() {
                v[d.array_index].as_f64()
            } else {
                v.as_f64()
            }
            .unwrap();
            let want = d.values[fi];
            worst.add(value_err(got, want), || {
                format!(
                    "{name} {}.{}[{}] frame {f}: ours {got} Blender {want}",
                    d.id_path, d.data_path, d.array_index
                )
            });
        }
    }
    worst
}

fn matrix_worst(scene: &Scene, r: &Reference, name: &str) -> Worst {
    let mut worst = Worst::default();
    let mut abs: f64 = 0.0;
    // The references come from the viewport depsgraph (frame_set), so use its resolution.
    let opts = EvalOptions { for_render: false };
    for (fi, f) in r.frames.iter().enumerate() {
        let ev = evaluate_scene_with(scene, *f, opts)
            .unwrap_or_else(|e| panic!("{name} frame {f}: {e}"));
        for (o, m) in scene.file.objects.iter().zip(&ev.world_matrices) {
            let want = &r
                .matrices
                .get(&o.name)
                .unwrap_or_else(|| panic!("{name}: no reference for {}", o.name))[fi];
            worst.add(mat_err(m, want), || {
                format!(
                    "{name} {} frame {f}:\n ours    {m:?}\n Blender {want:?}",
                    o.name
                )
            });
            abs = abs.max(mat_abs_err(m, want));
        }
    }
    eprintln!("matrices {name:14} worst absolute {abs:.3e}");
    worst
}

#[test]
fn fixture_fcurves_match_blender() {
    let names = fixture_names();
    assert!(
        !names.is_empty(),
        "no fixture scenes in {}",
        scenes_dir().display()
    );
    let mut total = Worst::default();
    for name in &names {
        let (scene, r) = load(name);
        let w = fcurve_worst(&scene, &r, name);
        eprintln!(
            "fcurves  {name:14} worst {:.3e}  ({} curves x {} frames)",
            w.err,
            r.fcurves.len(),
            r.frames.len()
        );
        if w.err > total.err {
            total = w;
        }
        let w = datablock_worst(&scene, &r, name);
        eprintln!(
            "settings {name:14} worst {:.3e}  ({} animated settings)",
            w.err,
            r.datablocks.len()
        );
        if w.err > total.err {
            total = w;
        }
    }
    eprintln!("fcurves  worst overall {:.3e} at {}", total.err, total.at);
    assert!(
        total.err <= TOL,
        "F-curve value differs from Blender by {:.3e} at {}",
        total.err,
        total.at
    );
}

#[test]
fn fixture_matrices_match_blender() {
    let mut total = Worst::default();
    for name in &fixture_names() {
        let (scene, r) = load(name);
        let w = matrix_worst(&scene, &r, name);
        eprintln!(
            "matrices {name:14} worst {:.3e}  ({} objects x {} frames)",
            w.err,
            r.matrices.len(),
            r.frames.len()
        );
        if w.err > total.err {
            total = w;
        }
    }
    eprintln!("matrices worst overall {:.3e} at {}", total.err, total.at);
    assert!(
        total.err <= TOL,
        "world matrix differs from Blender by {:.3e} at {}",
        total.err,
        total.at
    );
}

/// The comparison is not vacuous: a scene changed slightly is caught.
#[test]
fn a_perturbed_scene_is_caught() {
    let (mut scene, r) = load("follow_path");
    let cu = scene
        .file
        .curves
        .iter_mut()
        .find(|c| c.name == "PathBezData")
        .unwrap();
    cu.splines[0].bezier_points[2].co[2] += 0.001;
    assert!(matrix_worst(&scene, &r, "follow_path").err > TOL);
    let (mut scene, r) = load("interpolation");
    let fc = &mut scene.file.animation[0].fcurves[0];
    fc.keyframes[1].co[1] += 0.001;
    assert!(fcurve_worst(&scene, &r, "interpolation").err > TOL);
}

#[test]
fn unsupported_constraints_are_errors_naming_them() {
    let (mut scene, _) = load("track");
    let o = scene
        .file
        .objects
        .iter_mut()
        .find(|o| o.name == "TrackHalf")
        .unwrap();
    o.constraints[0].kind = "CHILD_OF".into();
    let e = evaluate_transforms(&scene, 1.0).unwrap_err().to_string();
    assert!(
        e.contains("TrackHalf") && e.contains("Track To") && e.contains("CHILD_OF"),
        "{e}"
    );
    // A muted one is simply not evaluated, as in Blender.
    let o = scene
        .file
        .objects
        .iter_mut()
        .find(|o| o.name == "TrackHalf")
        .unwrap();
    o.constraints[0].mute = true;
    evaluate_transforms(&scene, 1.0).unwrap();
}

#[test]
fn unsupported_fmodifier_is_an_error_naming_the_curve() {
    let (mut scene, _) = load("modifiers");
    let ad = &mut scene.file.animation[0];
    let fc = ad
        .fcurves
        .iter_mut()
        .find(|f| f.data_path == "[\"noise\"]")
        .unwrap();
    fc.modifiers[0]
        .properties
        .insert("use_legacy_noise".into(), true.into());
    let e = evaluate_transforms(&scene, 1.0).unwrap_err().to_string();
    assert!(e.contains("[\"noise\"]") && e.contains("legacy"), "{e}");
}

#[test]
fn parent_cycles_are_errors() {
    let (mut scene, _) = load("transforms");
    let a = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == "ChainA")
        .unwrap();
    scene.file.objects[a].parent = Some("ChainC".into());
    let e = evaluate_transforms(&scene, 1.0).unwrap_err().to_string();
    assert!(e.contains("cycle"), "{e}");
}

fn json_line(out: &str) -> serde_json::Value {
    let line = out
        .lines()
        .find_map(|l| l.strip_prefix("BLENDSYNTH_JSON "))
        .unwrap_or_else(|| panic!("no BLENDSYNTH_JSON line in:\n{out}"));
    serde_json::from_str(line).unwrap()
}

/// Blender-side: the published colon scene's camera rides a Follow Path constraint on a
/// curve whose `eval_time` comes from a key-less Generator F-curve.
#[test]
fn colon_camera_matches_blender() {
    let Some(python) = require("a Python with bpy", bpy_python()) else {
        return;
    };
    let Some(blend) = require("../shared/published/colon_nodes.blend", published_colon()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("colon");
    run_python(
        &python,
        &repo().join("blender_export/export_scene.py"),
        &["--in", path_str(&blend), "--out", path_str(&out)],
    );
    let frames = [50.0, 527.0, 11595.0];
    let args: Vec<String> = std::iter::once(path_str(&blend).to_string())
        .chain(frames.iter().map(|f| f.to_string()))
        .collect();
    let args: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    let reference = json_line(&run_python(
        &python,
        &repo().join("fixtures/anim/colon_camera.py"),
        &args,
    ));
    let scene = Scene::load(&out).unwrap_or_else(|e| panic!("{e}"));
    let camera = scene
        .file
        .scene
        .camera
        .clone()
        .expect("the scene has a camera");
    assert_eq!(reference["camera"].as_str(), Some(camera.as_str()));
    let ci = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == camera)
        .unwrap();
    for (k, f) in frames.iter().enumerate() {
        let ours = evaluate_transforms(&scene, *f).unwrap_or_else(|e| panic!("frame {f}: {e}"))[ci];
        let want: Mat4 = serde_json::from_value(reference["matrices"][k].clone()).unwrap();
        let err = mat_abs_err(&ours, &want);
        eprintln!("colon camera frame {f}: max abs error {err:.3e}");
        assert!(
            err <= TOL,
            "camera at frame {f} differs by {err:.3e}:\n ours    {ours:?}\n Blender {want:?}"
        );
    }
}

fn path_str(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}
