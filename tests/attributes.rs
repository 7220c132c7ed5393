//! Nodes that read mesh attributes and tangent space (Attribute, Color Attribute, a
//! named UV Map, Tangent in UV Map mode, Normal Map and Vector Displacement in tangent
//! space) against Cycles' EMIT bake of the same materials
//! (fixtures/bake/make_attr_refs.py): every texel, every channel.

mod common;
use common::*;

use std::path::Path;

use blendsynth::scene::Scene;
use blendsynth::shader::bake::{bake_emission, BakeOptions};

/// Cycles and blendsynth interpolate the same values with the same weights.
const TOL: f32 = 1e-5;

/// Worst absolute error of every case of the export in `dir`, by case name.
fn compare_all(dir: &Path) -> Vec<(String, f32)> {
    let scene = Scene::load(dir).unwrap();
    let meta: serde_json::Value = serde_json::from_slice(&std::fs::read(dir.join("cases.json")).unwrap()).unwrap();
    let size = meta["size"].as_u64().unwrap() as u32;
    let mut out = Vec::new();
    for (case, object) in meta["cases"].as_object().unwrap() {
        let reference: Vec<f32> = std::fs::read(dir.join(format!("{case}.f32"))).unwrap().chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
        assert_eq!(reference.len(), (size * size * 4) as usize);
        let ours = bake_emission(&scene, &BakeOptions { object: object.as_str().unwrap().into(), uv: None, size }).unwrap_or_else(|e| panic!("{case}: {e}"));
        let (mut worst, mut at) = (0.0f32, (0, 0));
        for (i, p) in ours.pixels.iter().enumerate() {
            assert_eq!(p[3], reference[i * 4 + 3], "{case}: texel {i} coverage differs");
            for c in 0..3 {
                let d = (p[c] - reference[i * 4 + c]).abs();
                if !(d <= worst) {
                    worst = if d.is_nan() { f32::INFINITY } else { d };
                    at = (i, c);
                }
            }
        }
        let (i, c) = at;
        eprintln!("{case:28} {size}x{size}: worst abs error {worst:.2e} (texel {i} channel {c}: ours {} Cycles {})", ours.pixels[i][c], reference[i * 4 + c]);
        out.push((case.clone(), worst));
    }
    out
}

fn tolerance(_case: &str) -> f32 {
    TOL
}

fn check(results: &[(String, f32)]) {
    let bad: Vec<_> = results.iter().filter(|(c, w)| !(*w <= tolerance(c))).collect();
    assert!(bad.is_empty(), "cases over their tolerance: {bad:?}");
    assert!(results.len() >= 38, "every case ran");
}

#[test]
fn attribute_nodes_match_cycles_emit_bakes() {
    check(&compare_all(&repo().join("fixtures/bake/attrs")));
}

/// Blender-side: bake the cases afresh with Cycles and compare against those bakes.
#[test]
fn fresh_cycles_attribute_bakes_match() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else { return };
    let t = tempfile::tempdir().unwrap();
    run_python(&py, &repo().join("fixtures/bake/make_attr_refs.py"), &["--out", t.path().to_str().unwrap()]);
    check(&compare_all(t.path()));
}
