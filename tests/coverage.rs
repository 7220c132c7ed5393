//! Issue 26: every object Cycles renders is rendered or refused by name, frozen geometry
//! is used only while nothing it reads changes, and `inspect` exit 0 means `render` and
//! `mesh` succeed.

mod common;
use common::*;

use blendsynth::render::{render, RenderOptions};
use blendsynth::scene::Scene;

fn small(frame: Option<f64>) -> RenderOptions {
    RenderOptions {
        frame,
        samples: Some(1),
        resolution: Some((16, 16)),
        threads: Some(1),
        ..Default::default()
    }
}

/// `inspect`'s verdict is the render's: on every committed fixture export, exit 0
/// (all_supported) implies the render succeeds.
#[test]
fn inspect_exit_0_implies_render_succeeds_on_every_fixture_scene() {
    let mut dirs = Vec::new();
    let mut stack = vec![repo().join("fixtures")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().is_some_and(|n| n == "scene.json") {
                dirs.push(d.clone());
            }
        }
    }
    dirs.sort();
    assert!(dirs.len() > 50, "fixture exports found: {}", dirs.len());
    let (mut passed, mut refused) = (0, 0);
    for d in &dirs {
        let Ok(scene) = Scene::load(d) else { continue };
        let report = blendsynth::inspect::report(&scene);
        if !report.all_supported {
            refused += 1;
            continue;
        }
        if scene.file.scene.camera.is_none() {
            // The report says so (render_error) only when it checks; no camera, no render.
            assert!(report.render_error.is_some(), "{}", d.display());
            continue;
        }
        let r = render(&scene, &small(None));
        assert!(
            r.is_ok(),
            "{}: inspect exit 0 but render failed: {}",
            d.display(),
            r.err().unwrap()
        );
        passed += 1;
    }
    eprintln!("{passed} fixture scenes pass inspect and render; {refused} refused by inspect");
    assert!(passed > 20);
}

/// Blender-side: a scene of curves, text, modifiers Blender evaluates, Use Nodes off and
/// a curve with Geometry Nodes (`fixtures/coverage/make_coverage_scene.py`).
#[test]
fn objects_blendsynth_does_not_build_render_frozen_or_are_refused_by_name() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let blend = tmp.path().join("coverage.blend");
    let export = tmp.path().join("export");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_coverage_scene.py"),
        &["--", blend.to_str().unwrap()],
    );
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            export.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let dir = export.to_str().unwrap();

    // inspect: exit 0, the frozen objects listed with what they read.
    let o = run(&["inspect", "--json", dir], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let mut frozen: Vec<&str> = r["frozen"]
        .as_array()
        .unwrap()
        .iter()
        .map(|z| z["object"].as_str().unwrap())
        .collect();
    frozen.sort();
    assert_eq!(frozen, ["Bars", "Label", "Still", "Tube"]);

    // mesh of a bare path: Blender's wire mesh of its evaluated points (Object.to_mesh).
    let scene = Scene::load(&export).unwrap();
    let i = scene
        .file
        .evaluated
        .iter()
        .position(|e| e.object == "Path")
        .expect("the export's mesh of Path");
    let theirs = scene.load_evaluated(i).unwrap();
    let ours = blendsynth::geometry::evaluate_object(&scene, "Path", 1.0, &[])
        .and_then(|g| blendsynth::geometry::realize_to_mesh(&g))
        .unwrap();
    assert_eq!(ours.positions.len(), theirs.positions.len());
    assert_eq!(ours.edges.len(), theirs.edges.len(), "wire edges");
    assert_eq!(ours.face_count(), 0);
    for (a, b) in ours.positions.iter().zip(&theirs.positions) {
        for k in 0..3 {
            assert!(
                (a[k] - b[k]).abs() < 1e-5,
                "Path vertex {a:?} vs Blender {b:?}"
            );
        }
    }

    // render: every object is in the image, the Use Nodes off cube in its diffuse colour.
    let scene = Scene::load(&export).unwrap();
    let mut opts = small(None);
    opts.resolution = Some((64, 64));
    opts.samples = Some(8);
    let out = render(&scene, &opts).unwrap();
    let index = |name: &str| {
        scene
            .file
            .objects
            .iter()
            .position(|o| o.name == name)
            .unwrap() as u32
            + 1
    };
    for name in ["Tube", "Label", "Bars", "Still", "Plain", "Ribbon"] {
        let n = out
            .passes
            .object_index
            .iter()
            .filter(|&&i| i == index(name))
            .count();
        assert!(n > 0, "{name} is not in the object index pass");
    }
    let plain: Vec<&[f32; 4]> = out
        .color
        .iter()
        .zip(&out.passes.object_index)
        .filter(|(_, &i)| i == index("Plain"))
        .map(|(c, _)| c)
        .collect();
    let mean = |k: usize| plain.iter().map(|c| c[k]).sum::<f32>() / plain.len() as f32;
    assert!(
        mean(0) > 2.0 * mean(2),
        "Use Nodes off: diffuse_color (0.9, 0.8, 0.1) expected, got {} {} {}",
        mean(0),
        mean(1),
        mean(2)
    );

    // Another frame: "Bars" reads its animated Array count, so it is refused by name.
    let o = run(
        &[
            "render",
            dir,
            "--frame",
            "5",
            "--samples",
            "1",
            "-o",
            tmp.path().join("f5.exr").to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["\"Bars\"", "modifiers[\"Array\"].count"]);
    let o = run(&["inspect", dir, "--frame", "5"], &[]);
    assert_eq!(o.status.code(), Some(3));
    assert!(
        stdout(&o).contains("render NOT YET: object \"Bars\""),
        "{}",
        stdout(&o)
    );
    // An override into a frozen object's modifiers is refused; moving it is not.
    let o = run(
        &[
            "render",
            dir,
            "--samples",
            "1",
            "--resolution",
            "8x8",
            "--set",
            "objects[\"Still\"].modifiers[\"Mirror\"].use_axis=[false,true,false]",
            "-o",
            tmp.path().join("s.exr").to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["\"Still\"", "override"]);
    let o = run(
        &[
            "render",
            dir,
            "--samples",
            "1",
            "--resolution",
            "8x8",
            "--set",
            "objects[\"Still\"].location=[0,0,1]",
            "-o",
            tmp.path().join("m.exr").to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));

    // mesh: a frozen object is Blender's evaluated mesh.
    let ply = tmp.path().join("tube.ply");
    let o = run(
        &["mesh", dir, "--object", "Tube", "-o", ply.to_str().unwrap()],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let e = scene
        .file
        .evaluated
        .iter()
        .find(|e| e.object == "Tube")
        .unwrap();
    assert!(
        stdout(&o).contains(&format!("{} vertices", e.vertex_count.unwrap())),
        "{}",
        stdout(&o)
    );
}

/// Blender-side: objects parented to bones (`fixtures/coverage/make_bone_scene.py`) sit
/// where Blender puts them at the exported frame and, while the armature's pose is not
/// animated, at other frames too; with an animated pose another frame is refused by name.
#[test]
fn bone_parents_follow_blender_while_the_pose_is_known() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let blend = tmp.path().join("bone.blend");
    let want = tmp.path().join("bone.json");
    let export = tmp.path().join("export");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_bone_scene.py"),
        &["--", blend.to_str().unwrap(), want.to_str().unwrap()],
    );
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            export.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let want: serde_json::Value = serde_json::from_slice(&std::fs::read(&want).unwrap()).unwrap();
    let scene = Scene::load(&export).unwrap();
    // Without the posed armature's child, every frame evaluates.
    let mut unposed = scene.clone();
    unposed.file.objects.retain(|o| o.name != "Prop");
    let check = |frame: f64, name: &str| {
        let s = if frame == 1.0 { &scene } else { &unposed };
        let i = s.file.objects.iter().position(|o| o.name == name).unwrap();
        let m = blendsynth::anim::evaluate_transforms(s, frame).unwrap()[i];
        let w = &want[format!("{frame}")][name];
        for r in 0..4 {
            for c in 0..4 {
                let b = w[r][c].as_f64().unwrap();
                assert!(
                    (m[r][c] - b).abs() < 1e-4,
                    "{name} at frame {frame}: [{r}][{c}] {} vs Blender {b}",
                    m[r][c]
                );
            }
        }
    };
    check(1.0, "Hand");
    check(7.0, "Hand");
    check(1.0, "Prop");
    let e = blendsynth::anim::evaluate_transforms(&scene, 7.0)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("Prop") && e.contains("Dancer") && e.contains("pose"),
        "{e}"
    );
}

/// Blender-side: a file saved with an add-on's node classes, converted without them
/// (`fixtures/coverage/make_addon_nodes_scene.py`): the add-on's tree and nodes export
/// (their value-less sockets as CUSTOM), `inspect` names them, and the material, whose
/// Cycles output does not use the add-on node, renders as Cycles renders it.
#[test]
fn files_with_add_on_nodes_convert_and_name_them() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let blend = tmp.path().join("addon.blend");
    let export = tmp.path().join("export");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_addon_nodes_scene.py"),
        &["--", blend.to_str().unwrap()],
    );
    let o = run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            export.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_BPY_PYTHON", py.to_str().unwrap())],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let scene = Scene::load(&export).unwrap();
    let tree = scene
        .file
        .node_groups
        .iter()
        .find(|g| g.name == "Add-on material")
        .expect("the add-on's node tree is exported");
    assert_eq!(tree.bl_idname, "NodeTreeUndefined");
    for n in &tree.nodes {
        assert_eq!(n.bl_idname, "NodeUndefined");
        for s in n.inputs.iter().chain(&n.outputs) {
            assert_eq!(s.kind, "CUSTOM", "{} {}", n.name, s.name);
            assert!(s.default_value.is_none());
        }
    }
    let o = run(&["inspect", export.to_str().unwrap()], &[]);
    assert!(stdout(&o).contains("NodeUndefined"), "{}", stdout(&o));
    assert!(stdout(&o).contains("render: ok"), "{}", stdout(&o));
    render(&scene, &small(None)).unwrap();
}

/// A constraint blendsynth does not evaluate, on a camera that is not the scene's, moves
/// nothing that renders: the frame renders (issue 26). On the scene camera it is an
/// error naming the camera and the constraint.
#[test]
fn constraints_on_other_cameras_do_not_block_the_render() {
    use serde_json::Value;
    let src = repo().join("fixtures/scenes/animated_camera");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scene");
    copy_dir(&src, &dir);
    let p = dir.join("scene.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let objects = v["objects"].as_array_mut().unwrap();
    let camera = objects.iter().position(|o| o["name"] == "Camera").unwrap();
    let limit = serde_json::json!({"name": "Limit Distance", "type": "LIMIT_DISTANCE",
        "mute": false, "influence": 1.0, "owner_space": "WORLD", "target_space": "WORLD",
        "properties": {}});
    let mut other = objects[camera].clone();
    other["name"] = Value::from("Spare");
    other["constraints"] = Value::Array(vec![limit.clone()]);
    objects.push(other);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    render(&scene, &small(None)).expect("a spare camera's constraint blocks nothing");
    assert!(blendsynth::inspect::report(&scene).render_error.is_none());

    v["objects"][camera]["constraints"] = Value::Array(vec![limit]);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    let e = render(&scene, &small(None)).unwrap_err().to_string();
    assert!(
        e.contains("\"Camera\"") && e.contains("LIMIT_DISTANCE"),
        "{e}"
    );
}
