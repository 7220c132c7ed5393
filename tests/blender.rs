//! Blender-side tests: real Blender (the bpy module) converts .blend files and the
//! result must hold everything Blender reports. Skipped with a notice on a machine
//! without bpy; a failure in CI (CI=true).

mod common;
use common::*;

use blendsynth::scene::Scene;
use serde_json::Value;
use std::path::Path;

fn blender_counts(py: &Path, blend: &Path) -> Value {
    let out = run_python(
        py,
        &repo().join("fixtures/blender_counts.py"),
        &[blend.to_str().unwrap()],
    );
    // Blender prints its own lines first; the JSON is the last line.
    serde_json::from_str(out.lines().last().unwrap_or(""))
        .expect("blender_counts.py prints JSON on its last line")
}

/// One .blend of fixtures/make_fixtures.py, written under `dir`.
fn make_fixture(py: &Path, dir: &Path, name: &str) -> std::path::PathBuf {
    let blends = dir.join("blend");
    run_python(
        py,
        &repo().join("fixtures/make_fixtures.py"),
        &["--out", blends.to_str().unwrap(), "--only", name],
    );
    blends.join(format!("{name}.blend"))
}

fn convert(py: &Path, blend: &Path, out: &Path) {
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())],
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "convert {} failed: {}",
        blend.display(),
        stderr(&o)
    );
}

/// The same through `--blender PATH` naming the bpy Python.
fn convert_with_flag(py: &Path, blend: &Path, out: &Path) {
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--blender",
            py.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "convert {} failed: {}",
        blend.display(),
        stderr(&o)
    );
}

#[test]
fn published_colon_scene_round_trips() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let Some(blend) = require("../shared/published/colon_nodes.blend", published_colon()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("colon-export");
    convert(&py, &blend, &out);
    let scene = Scene::load(&out).unwrap();

    // Nothing lost: node, link and socket counts equal what Blender reports.
    let ours = export_counts(&scene);
    let theirs = blender_counts(&py, &blend);
    assert_eq!(ours, theirs, "export counts differ from Blender's");

    let o = run(&["inspect", out.to_str().unwrap()], &[]);
    assert!(
        matches!(o.status.code(), Some(0) | Some(3)),
        "{}",
        stderr(&o)
    );
    let text = stdout(&o);
    for tree in [
        "node_groups[\"Colon Geo Node\"]",
        "materials[\"Fat.001\"].node_tree",
    ] {
        let (_, t) = scene
            .node_trees()
            .into_iter()
            .find(|(p, _)| p == tree)
            .unwrap_or_else(|| panic!("{tree} missing"));
        assert!(text.contains(tree), "inspect does not list {tree}");
        for n in &t.nodes {
            assert!(
                text.contains(&format!("  {:<32} {}", n.name, n.bl_idname)),
                "inspect does not list node {:?} of {tree}",
                n.name
            );
        }
    }
    assert!(
        text.contains("constraint FOLLOW_PATH \"Follow Path\" target BezierCurve.001"),
        "{text}"
    );
    assert!(
        text.contains("use_curve_follow=true") && text.contains("use_curve_radius=true"),
        "{text}"
    );
    assert!(
        text.contains(".eval_time[0]") && text.contains("GENERATOR"),
        "animated eval_time missing:\n{text}"
    );

    // Filmic needs the running Blender's colour-management files next to the export.
    let config = scene
        .file
        .color_management
        .config
        .as_deref()
        .expect("colour-management config for Filmic");
    assert!(scene
        .resolve(config, "color_management.config")
        .unwrap()
        .is_file());

    // The evaluated reference mesh is there, with its instances realised.
    let colon = scene
        .file
        .evaluated
        .iter()
        .position(|e| e.object == "Colon")
        .expect("evaluated Colon");
    let m = scene.load_evaluated(colon).unwrap();
    assert!(
        m.triangles.len() > 100_000,
        "evaluated colon has only {} triangles",
        m.triangles.len()
    );
}

#[test]
fn fixtures_round_trip_and_committed_exports_are_current() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let blends = t.path().join("blend");
    run_python(
        &py,
        &repo().join("fixtures/make_fixtures.py"),
        &["--out", blends.to_str().unwrap()],
    );
    for name in ["material_zoo", "geonodes", "animated_camera"] {
        let blend = blends.join(format!("{name}.blend"));
        let out = t.path().join(name);
        if name == "geonodes" {
            convert_with_flag(&py, &blend, &out);
        } else {
            convert(&py, &blend, &out);
        }
        let fresh = Scene::load(&out).unwrap();
        assert_eq!(
            export_counts(&fresh),
            blender_counts(&py, &blend),
            "{name}: export differs from Blender"
        );
        // The committed export (what `cargo test` uses without Blender) is not stale.
        let committed = Scene::load(&repo().join("fixtures/scenes").join(name)).unwrap();
        assert_eq!(
            export_counts(&committed),
            export_counts(&fresh),
            "{name}: committed export is stale; run fixtures/regenerate.sh"
        );
    }
}

#[test]
fn autorun_script_in_a_blend_never_runs() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let blend = make_fixture(&py, t.path(), "autorun");
    let marker = t.path().join("AUTORUN_RAN");

    // Control: with auto-run allowed, Blender does run the file's script.
    let control = std::process::Command::new(&py)
        .args([
            "-c",
            "import bpy,sys; bpy.ops.wm.open_mainfile(filepath=sys.argv[1], use_scripts=True)",
            blend.to_str().unwrap(),
        ])
        .env("BLENDSYNTH_AUTORUN_MARKER", &marker)
        .output()
        .unwrap();
    assert!(control.status.success(), "{}", stderr(&control));
    assert!(
        marker.exists(),
        "control failed: the fixture's registered script did not run even with auto-run enabled"
    );
    std::fs::remove_file(&marker).unwrap();

    // blendsynth convert: the script must not run.
    let out = t.path().join("export");
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &[
            ("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap()),
            ("BLENDSYNTH_AUTORUN_MARKER", marker.to_str().unwrap()),
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        !marker.exists(),
        "the .blend's auto-run script ran during convert"
    );
}

/// An object Blender's viewport depsgraph does not evaluate (its collection disabled in
/// viewports) converts and renders: the export once stopped on it with "Expected an
/// evaluated object".
#[test]
fn objects_of_viewport_disabled_collections_convert() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let blend = make_fixture(&py, t.path(), "viewport_disabled");
    let out = t.path().join("export");
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let scene = Scene::load(&out).unwrap();
    assert!(
        scene.object("Label").is_some(),
        "the text object is exported"
    );
}

/// The committed copy of Cycles' albedo tables (tests/closures.rs compares ours with it)
/// is what this Blender's library holds.
#[test]
fn committed_cycles_albedo_tables_are_current() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("tables.json");
    run_python(
        &py,
        &repo().join("fixtures/render/cycles_albedo_tables.py"),
        &["--out", out.to_str().unwrap()],
    );
    let fresh: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let committed: Value = serde_json::from_str(
        &std::fs::read_to_string(repo().join("fixtures/render/cycles_albedo_tables.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(fresh, committed, "fixtures/render/cycles_albedo_tables.json is stale; run fixtures/render/cycles_albedo_tables.py");
}
