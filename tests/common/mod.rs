//! Shared helpers for the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_blendsynth"))
}

/// Runs the CLI with a clean Blender environment plus `envs`.
pub fn run(args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = bin();
    c.args(args)
        .env_remove("BLENDSYNTH_BLENDER")
        .env_remove("BLENDSYNTH_BPY_PYTHON");
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().expect("run blendsynth")
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A failure must be one line on stderr starting with `error:` and no panic.
pub fn assert_clean_error(o: &Output, code: i32, must_contain: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "exit code; stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    assert!(lines[0].starts_with("error: "), "{err}");
    for m in must_contain {
        assert!(
            lines[0].contains(m),
            "error {:?} should mention {m:?}",
            lines[0]
        );
    }
}

pub fn in_ci() -> bool {
    std::env::var("CI").map(|v| v == "true").unwrap_or(false)
}

/// A Python interpreter with Blender's `bpy` module: $BLENDSYNTH_BPY_PYTHON, or the
/// repository's `.venv` that `.ci/run` creates.
pub fn bpy_python() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("BLENDSYNTH_BPY_PYTHON").filter(|p| !p.is_empty()) {
        return Some(PathBuf::from(p));
    }
    let venv = repo().join(".venv/bin/python");
    if venv.is_file() {
        let ok = Command::new(&venv)
            .args(["-c", "import bpy"])
            .output()
            .map(|o| o.status.success())
            .unwrap_or(false);
        if ok {
            return Some(venv);
        }
    }
    None
}

/// The published colon scene, read from `../shared/published` (never copied here).
pub fn published_colon() -> Option<PathBuf> {
    let p = repo().join("../shared/published/colon_nodes.blend");
    p.is_file().then_some(p)
}

/// Gets what a Blender-side test needs, or skips the test (returns None) on a user's
/// machine without it. In CI (CI=true) a missing requirement is a failure.
pub fn require<T>(what: &str, v: Option<T>) -> Option<T> {
    if v.is_none() {
        if in_ci() {
            panic!("{what} is required in CI (CI=true) but was not found");
        }
        eprintln!("SKIPPED: {what} not found (set BLENDSYNTH_BPY_PYTHON or run .ci/run)");
    }
    v
}

pub fn copy_dir(src: &Path, dst: &Path) {
    std::fs::create_dir_all(dst).unwrap();
    for e in std::fs::read_dir(src).unwrap() {
        let e = e.unwrap();
        let to = dst.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &to);
        } else {
            std::fs::copy(e.path(), &to).unwrap();
        }
    }
}

/// Runs a bpy script with the given python and returns stdout, panicking with stderr on failure.
pub fn run_python(python: &Path, script: &Path, args: &[&str]) -> String {
    let o = Command::new(python)
        .arg(script)
        .args(args)
        .output()
        .expect("run python");
    assert!(
        o.status.success(),
        "{} failed: {}\n{}",
        script.display(),
        stderr(&o),
        stdout(&o)
    );
    stdout(&o)
}

/// Counts from the export, in the layout `fixtures/blender_counts.py` prints from Blender.
pub fn export_counts(s: &blendsynth::scene::Scene) -> serde_json::Value {
    let mut trees = serde_json::Map::new();
    for (path, t) in s.node_trees() {
        let mut names: Vec<&str> = t.nodes.iter().map(|n| n.name.as_str()).collect();
        names.sort();
        let mut ids: Vec<&str> = t.nodes.iter().map(|n| n.bl_idname.as_str()).collect();
        ids.sort();
        trees.insert(
            path,
            serde_json::json!({
                "nodes": t.nodes.len(),
                "links": t.links.len(),
                "inputs": t.nodes.iter().map(|n| n.inputs.len()).sum::<usize>(),
                "outputs": t.nodes.iter().map(|n| n.outputs.len()).sum::<usize>(),
                "node_names": names,
                "bl_idnames": ids,
            }),
        );
    }
    let objects: serde_json::Map<String, serde_json::Value> = s
        .file
        .objects
        .iter()
        .map(|o| (o.name.clone(), serde_json::json!({"modifiers": o.modifiers.len(), "constraints": o.constraints.len()})))
        .collect();
    let mut anim = serde_json::Map::new();
    for a in &s.file.animation {
        anim.insert(
            a.id_path.clone(),
            serde_json::json!({"fcurves": a.fcurves.len(), "drivers": a.drivers.len(), "keyframes": a.fcurves.iter().map(|f| f.keyframes.len()).sum::<usize>()}),
        );
    }
    serde_json::json!({"node_trees": trees, "objects": objects, "animation": anim})
}

/// EMIT-bake parity fixtures (cases.json + CASE.f32 written by a fixtures/bake script):
/// blendsynth's bake of every case against Cycles', the worst absolute error by case name.
pub fn bake_cases_worst(dir: &Path) -> Vec<(String, f32)> {
    let scene = blendsynth::scene::Scene::load(dir).unwrap();
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cases.json")).unwrap()).unwrap();
    let size = meta["size"].as_u64().unwrap() as u32;
    let mut out = Vec::new();
    for (case, object) in meta["cases"].as_object().unwrap() {
        let reference: Vec<f32> = std::fs::read(dir.join(format!("{case}.f32")))
            .unwrap()
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(reference.len(), (size * size * 4) as usize);
        let ours = blendsynth::render::bake::bake_emission(
            &scene,
            &blendsynth::render::bake::BakeOptions {
                object: object.as_str().unwrap().into(),
                uv: None,
                size,
            },
        )
        .unwrap_or_else(|e| panic!("{case}: {e}"));
        let (mut worst, mut at) = (0.0f32, (0, 0));
        for (i, p) in ours.pixels.iter().enumerate() {
            assert_eq!(
                p[3],
                reference[i * 4 + 3],
                "{case}: texel {i} coverage differs"
            );
            for c in 0..3 {
                let d = (p[c] - reference[i * 4 + c]).abs();
                if !(d <= worst) {
                    worst = if d.is_nan() { f32::INFINITY } else { d };
                    at = (i, c);
                }
            }
        }
        let (i, c) = at;
        eprintln!("{case:24} {size}x{size}: worst abs error {worst:.2e} (texel {i} channel {c}: ours {} Cycles {})", ours.pixels[i][c], reference[i * 4 + c]);
        out.push((case.clone(), worst));
    }
    out
}

/// Every file under `dir`, relative path -> bytes.
pub fn tree(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, d: &Path, out: &mut std::collections::BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.insert(
                    p.strip_prefix(root).unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    let mut out = std::collections::BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

pub fn assert_same_tree(a: &Path, b: &Path) {
    let (ta, tb) = (tree(a), tree(b));
    assert_eq!(
        ta.keys().collect::<Vec<_>>(),
        tb.keys().collect::<Vec<_>>(),
        "file lists of {} and {}",
        a.display(),
        b.display()
    );
    for (k, v) in &ta {
        assert!(
            v == &tb[k],
            "{k} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// The named channels of a multilayer EXR (`layer.channel`, top row first) and its size.
pub fn exr_channels(
    path: &std::path::Path,
) -> (usize, usize, std::collections::HashMap<String, Vec<f32>>) {
    use exr::prelude::*;
    let img = read_all_flat_layers_from_file(path).unwrap();
    let mut channels = std::collections::HashMap::new();
    let mut size = (0, 0);
    for layer in &img.layer_data {
        size = (layer.size.width(), layer.size.height());
        let prefix = layer
            .attributes
            .layer_name
            .as_ref()
            .map(|n| format!("{n}."))
            .unwrap_or_default();
        for ch in &layer.channel_data.list {
            channels.insert(
                format!("{prefix}{}", ch.name),
                ch.sample_data.values_as_f32().collect(),
            );
        }
    }
    (size.0, size.1, channels)
}

/// `blendsynth convert BLEND -o OUT EXTRA...` with the given bpy Python.
pub fn convert_blend(py: &Path, blend: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "convert",
        blend.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args, &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())])
}
