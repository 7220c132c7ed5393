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
    let bad: Vec<_> = results
        .iter()
        .filter(|(c, w)| !(*w <= tolerance(c)))
        .collect();
    assert!(bad.is_empty(), "cases over their tolerance: {bad:?}");
    assert!(results.len() >= 38, "every case ran");
}

#[test]
fn attribute_nodes_match_cycles_emit_bakes() {
    check(&common::bake_cases_worst(
        &repo().join("fixtures/bake/attrs"),
    ));
}

/// Blender-side: bake the cases afresh with Cycles and compare against those bakes.
#[test]
fn fresh_cycles_attribute_bakes_match() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    run_python(
        &py,
        &repo().join("fixtures/bake/make_attr_refs.py"),
        &["--out", t.path().to_str().unwrap()],
    );
    check(&common::bake_cases_worst(t.path()));
}

/// Pointiness and Random Per Island (Geometry node and Attribute by name) on a mesh of
/// three bent islands, one vertex welded across two of them
/// (fixtures/bake/make_attr_island_refs.py).
#[test]
fn derived_attributes_match_cycles_emit_bakes() {
    let results = common::bake_cases_worst(&repo().join("fixtures/bake/attr_islands"));
    assert!(results.len() >= 7, "every case ran");
    check_derived(&results);
}

fn check_derived(results: &[(String, f32)]) {
    let bad: Vec<_> = results
        .iter()
        .filter(|(c, w)| !(*w <= tolerance(c)))
        .collect();
    assert!(bad.is_empty(), "cases over their tolerance: {bad:?}");
}

/// Blender-side: the derived-attribute cases baked afresh by Cycles.
#[test]
fn fresh_cycles_derived_attribute_bakes_match() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    run_python(
        &py,
        &repo().join("fixtures/bake/make_attr_island_refs.py"),
        &["--out", t.path().to_str().unwrap()],
    );
    check_derived(&common::bake_cases_worst(t.path()));
}

/// What shaders still cannot read is a clear error when a mesh is bound (bake and render
/// alike): quaternion and matrix attributes.
#[test]
fn quaternion_and_matrix_attributes_are_refused() {
    use blendsynth::scene::{Attribute, AttributeData, Domain, MeshData};
    use blendsynth::shader::attributes::{AttributeRequest, BoundAttributes};
    for (name, data) in [
        (
            "rot",
            AttributeData::Quaternion(vec![[1.0, 0.0, 0.0, 0.0]; 3]),
        ),
        ("xf", AttributeData::Float4x4(vec![[0.0; 16]; 3])),
    ] {
        let mesh = MeshData {
            positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            attributes: vec![Attribute {
                name: name.into(),
                domain: Domain::Point,
                data_type: "X".into(),
                data,
            }],
            ..Default::default()
        };
        let e = BoundAttributes::bind(&mesh, &[AttributeRequest::Named(name.into())], None, None)
            .unwrap_err();
        assert!(
            e.contains(name) && e.contains("quaternion and matrix"),
            "{e}"
        );
    }
}
