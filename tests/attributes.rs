//! Nodes that read mesh attributes and tangent space (Attribute, Color Attribute, a
//! named UV Map, Tangent in UV Map mode, Normal Map and Vector Displacement in tangent
//! space) against Cycles' EMIT bake of the same materials
//! (fixtures/bake/make_attr_refs.py): every texel, every channel.

mod common;
use common::*;


/// Cycles and blendsynth interpolate the same values with the same weights.
const TOL: f32 = 1e-5;

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
    check(&common::bake_cases_worst(&repo().join("fixtures/bake/attrs")));
}

/// Blender-side: bake the cases afresh with Cycles and compare against those bakes.
#[test]
fn fresh_cycles_attribute_bakes_match() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else { return };
    let t = tempfile::tempdir().unwrap();
    run_python(&py, &repo().join("fixtures/bake/make_attr_refs.py"), &["--out", t.path().to_str().unwrap()]);
    check(&common::bake_cases_worst(t.path()));
}
