//! `inspect` tells what blendsynth can evaluate: per node type and tree type, and per
//! material whether it compiles (with the reason when it does not).

mod common;
use common::*;

use serde_json::Value;

fn report(dir: &str) -> (Option<i32>, Value) {
    let o = run(
        &["inspect", "--json", repo().join(dir).to_str().unwrap()],
        &[],
    );
    (
        o.status.code(),
        serde_json::from_slice(&o.stdout).expect("JSON report"),
    )
}

fn row<'a>(r: &'a Value, kind: &str) -> &'a Value {
    r["coverage"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["bl_idname"] == kind)
        .unwrap_or_else(|| panic!("{kind} not in coverage"))
}

#[test]
fn shared_maths_counts_only_where_an_evaluator_runs_it() {
    // This file uses Math and Combine XYZ in a Geometry Nodes tree: they count because
    // the geometry evaluator runs them; its Principled material and world compile too,
    // so nothing is unsupported and the exit status is 0.
    let (code, r) = report("fixtures/scenes/geonodes");
    assert_eq!(code, Some(0));
    assert_eq!(row(&r, "ShaderNodeBsdfPrincipled")["support"], "supported");
    assert_eq!(row(&r, "ShaderNodeMath")["support"], "supported");
    assert_eq!(row(&r, "ShaderNodeCombineXYZ")["support"], "supported");
    // World surfaces compile since the world shader (render/light/world.rs, tests/world.rs).
    assert_eq!(row(&r, "ShaderNodeOutputWorld")["support"], "supported");
    // In a Geometry Nodes tree only what the geometry evaluator implements counts.
    use blendsynth::geometry::support_in;
    use blendsynth::nodes::Support;
    assert!(matches!(
        support_in("GeometryNodeTree", "GeometryNodeCurveToMesh"),
        Support::Supported
    ));
    assert!(matches!(
        support_in("GeometryNodeTree", "GeometryNodeSubdivisionSurface"),
        Support::Supported
    ));
    assert!(matches!(
        support_in("GeometryNodeTree", "GeometryNodeMergeByDistance"),
        Support::Supported
    ));
    assert!(matches!(
        support_in("GeometryNodeTree", "GeometryNodeMeshBoolean"),
        Support::Unsupported
    ));
    assert!(matches!(
        support_in("GeometryNodeTree", "ShaderNodeBsdfPrincipled"),
        Support::Unsupported
    ));
    let (_, r) = report("fixtures/bake/scenes/uv_math");
    assert_eq!(row(&r, "ShaderNodeMath")["support"], "supported");
}

#[test]
fn texture_and_colour_nodes_count_in_geometry_nodes_trees() {
    // The textures parity scene (tests/geometry.rs) uses them only in Geometry Nodes trees.
    let (code, r) = report("fixtures/geometry/scenes/textures");
    // Every node and the meshes evaluate; only `render` would refuse it, for want of a
    // camera (inspect's exit status is render's and mesh's).
    assert_eq!(code, Some(3), "{r}");
    assert_eq!(r["mesh_errors"], serde_json::json!([]), "{r}");
    assert!(
        r["render_error"]
            .as_str()
            .unwrap()
            .contains("no active camera"),
        "{r}"
    );
    for kind in [
        "ShaderNodeTexVoronoi",
        "ShaderNodeTexWhiteNoise",
        "ShaderNodeTexGradient",
        "ShaderNodeTexWave",
        "ShaderNodeTexMagic",
        "ShaderNodeTexChecker",
        "ShaderNodeTexBrick",
        "ShaderNodeValToRGB",
        "ShaderNodeRGBCurve",
        "ShaderNodeVectorCurve",
        "FunctionNodeSeparateColor",
        "FunctionNodeCombineColor",
        "ShaderNodeMix",
        "ShaderNodeMixRGB",
        "ShaderNodeVectorRotate",
        "FunctionNodeRotateVector",
        "FunctionNodeFloatToInt",
        "ShaderNodeBlackbody",
    ] {
        assert_eq!(row(&r, kind)["support"], "supported", "{kind}");
    }
    use blendsynth::geometry::support_in;
    use blendsynth::nodes::Support;
    // Gabor has no implementation on either side yet.
    assert!(matches!(
        support_in("GeometryNodeTree", "ShaderNodeTexGabor"),
        Support::Unsupported
    ));
}

#[test]
fn materials_report_whether_they_compile() {
    let (_, r) = report("fixtures/bake/scenes/structure");
    let m = &r["material_status"][0];
    assert_eq!(m["name"], "Structure");
    assert!(m["error"].is_null(), "{m}");
    // The zoo's last unsupported node (tangent-space Normal Map) is supported now: it
    // compiles; tests/bake.rs covers an unsupported node's error.
    let (_, r) = report("fixtures/scenes/material_zoo");
    let m = &r["material_status"][0];
    assert!(m["error"].is_null(), "{m}");
}

/// Smoke domains are listed with the grids they render from, or why they render nothing
/// (as Cycles renders them then): an unbaked cache, a material that reads no grid.
#[test]
fn smoke_domains_say_what_they_render_from() {
    let (_, r) = report("fixtures/render/scenes/smoke_unbaked");
    let d = r["smoke_domains"].as_array().unwrap();
    let a = d.iter().find(|x| x["object"] == "DomainA").unwrap();
    assert!(a["empty"].as_str().unwrap().contains("clipping"), "{a}");
    let b = d.iter().find(|x| x["object"] == "DomainB").unwrap();
    assert!(b["empty"].as_str().unwrap().contains("read no grid"), "{b}");
    assert_eq!(r["render_error"], Value::Null);
    let (_, r) = report("fixtures/render/scenes/smoke_grid_gradient");
    let g = &r["smoke_domains"][0];
    assert_eq!(g["empty"], Value::Null, "{g}");
    assert_eq!(
        g["grids"],
        serde_json::json!(["color", "density", "temperature"])
    );
}

#[test]
fn an_object_rendered_from_blenders_mesh_instead_is_listed_as_frozen() {
    // Blendsynth evaluates this Geometry Nodes object, but its material reads an Instancer
    // attribute of instances it realises, so `render` draws Blender's evaluated mesh of it
    // (render/build.rs, geometry::source::frozen_instead): inspect must say so.
    let (code, r) = report("fixtures/render/scenes/nested_instancer_native");
    assert_eq!(code, Some(0), "{r}");
    let frozen = r["frozen"].as_array().unwrap();
    let z = frozen
        .iter()
        .find(|z| {
            z["reason"]
                .as_str()
                .unwrap()
                .contains("Instancer attributes")
        })
        .unwrap_or_else(|| panic!("no object frozen for its Instancer attributes: {r}"));
    assert!(z["reads"].as_array().is_some_and(|a| !a.is_empty()), "{z}");
}

/// Volume objects (OpenVDB) are listed with the grids they render from, `inspect` exits 0
/// on them; a Volume object blendsynth cannot read is refused by name, by `inspect` and
/// `render` alike: an export without its grids, the OpenVDB module missing, a grid type
/// not handled, and motion blur by its velocity grid.
#[test]
fn volume_objects_render_from_their_grids_or_are_refused_by_name() {
    let (code, r) = report("fixtures/render/scenes/volume_vdb_fog");
    assert_eq!(code, Some(0), "{r}");
    assert_eq!(r["render_error"], Value::Null);
    let v = &r["volume_objects"][0];
    assert_eq!(v["object"], "FogBall");
    assert_eq!(v["grids"], serde_json::json!(["color", "density"]));
    assert_eq!(v["empty"], Value::Null, "{v}");
    let src = repo().join("fixtures/render/scenes/volume_vdb_fog");
    let edited = |edit: &dyn Fn(&mut Value), must: &[&str]| {
        let t = tempfile::tempdir().unwrap();
        copy_dir(&src, t.path());
        let json = t.path().join("scene.json");
        let mut j: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        edit(&mut j);
        std::fs::write(&json, serde_json::to_vec(&j).unwrap()).unwrap();
        let o = run(&["inspect", "--json", t.path().to_str().unwrap()], &[]);
        assert_ne!(o.status.code(), Some(0));
        let r: Value = serde_json::from_slice(&o.stdout).unwrap();
        let e = r["render_error"].as_str().unwrap_or_default().to_string();
        for m in must.iter().chain(&["\"FogBall\"", "Volume object"]) {
            assert!(e.contains(m), "{m:?} not in {e:?}");
        }
        let out = t.path().join("out.exr");
        let o = run(
            &[
                "render",
                t.path().to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert_clean_error(&o, 1, must);
    };
    edited(
        &|j| j["volume_objects"] = serde_json::json!([]),
        &["does not carry"],
    );
    edited(
        &|j| {
            j["volume_objects"][0]["error"] = "Blender's OpenVDB Python module was not found".into()
        },
        &["OpenVDB Python module"],
    );
    edited(
        &|j| {
            j["volume_objects"][0]["unread"] =
                serde_json::json!([["mask", "OpenVDB value type bool is not handled"]])
        },
        &["\"mask\"", "bool"],
    );
    edited(
        &|j| {
            j["volume_objects"][0]["velocity_grid"] = "velocity".into();
            j["scene"]["render"]["use_motion_blur"] = true.into();
        },
        &["velocity", "motion blur"],
    );
}
