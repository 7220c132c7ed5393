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
    let o = convert_blend(&py, &blend, &export, &[]);
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
    // An override into a frozen object's modifiers is refused (its Cast modifier is not
    // evaluated by blendsynth); moving it is not.
    let o = run(
        &[
            "render",
            dir,
            "--samples",
            "1",
            "--resolution",
            "8x8",
            "--set",
            "objects[\"Still\"].modifiers[\"Mirror\"].use_axis=[true,true,false]",
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
    let o = convert_blend(&py, &blend, &export, &[]);
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
    let o = convert_blend(&py, &blend, &export, &[]);
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
    // The add-on's tree renders nothing: it refuses nothing.
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
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

/// Blender-side: data linked from a library under the names of the scene's own data
/// (`fixtures/coverage/make_linked_scene.py`, as in BlendLuxCore's full-export file)
/// converts with each linked ID named by Blender's `name_full` ("Cube [lib.blend]"), and
/// the local cube, the linked cube and the instanced library collection all render.
#[test]
fn linked_data_sharing_local_names_converts_and_renders() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let export = tmp.path().join("export");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_linked_scene.py"),
        &["--", tmp.path().to_str().unwrap()],
    );
    let blend = tmp.path().join("linked.blend");
    let o = convert_blend(&py, &blend, &export, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let scene = Scene::load(&export).unwrap();
    let names: Vec<&str> = scene.file.objects.iter().map(|o| o.name.as_str()).collect();
    for n in [
        "Cube",
        "Cube [lib.blend]",
        "Ball [lib.blend]",
        "Group instance",
    ] {
        assert!(names.contains(&n), "{n} in {names:?}");
    }
    let linked = scene.object("Cube [lib.blend]").unwrap();
    assert_eq!(linked.data.as_deref(), Some("Cube [lib.blend]"));
    assert_eq!(
        linked.material_slots[0].material.as_deref(),
        Some("Cube [lib.blend]")
    );
    let o = run(&["inspect", export.to_str().unwrap()], &[]);
    assert!(o.status.success(), "{}", stdout(&o));
    let opts = RenderOptions {
        resolution: Some((32, 32)),
        ..small(None)
    };
    let out = render(&scene, &opts).unwrap();
    let seen: std::collections::BTreeSet<&str> = out
        .passes
        .object_index
        .iter()
        .filter(|&&i| i > 0)
        .map(|&i| scene.file.objects[i as usize - 1].name.as_str())
        .collect();
    let want: std::collections::BTreeSet<&str> = ["Cube", "Cube [lib.blend]", "Group instance"]
        .into_iter()
        .collect();
    assert_eq!(seen, want);
}

/// Blender-side: `convert --frames 1..3` writes Blender's evaluated mesh of an object
/// with an animated shape key at every frame (`fixtures/coverage/make_frames_scene.py`);
/// `mesh` and `render` use the one at the frame (the key at 0.5 on frame 2 lifts the
/// vertex half way), and a frame outside the range is an error naming the animated path,
/// as every frame but the first is without `--frames`.
#[test]
fn convert_frames_exports_animated_frozen_meshes_per_frame() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let blend = tmp.path().join("frames.blend");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_frames_scene.py"),
        &["--", blend.to_str().unwrap()],
    );
    let convert = |extra: &[&str], out: &std::path::Path| {
        let o = convert_blend(&py, &blend, out, extra);
        assert!(o.status.success(), "{}", stderr(&o));
        Scene::load(out).unwrap()
    };
    let lifted = |scene: &Scene, frame: f64| -> Result<f32, String> {
        let set = blendsynth::geometry::evaluate_object(scene, "Sheet", frame, &[])
            .map_err(|e| e.to_string())?;
        let m = blendsynth::geometry::realize_to_mesh(&set).map_err(|e| e.to_string())?;
        Ok(m.positions[2][2])
    };
    let ranged = convert(&["--frames", "1..3"], &tmp.path().join("ranged"));
    let frames: Vec<f64> = ranged
        .file
        .evaluated
        .iter()
        .filter(|e| e.object == "Sheet")
        .map(|e| e.frame)
        .collect();
    assert_eq!(frames, [1.0, 2.0, 3.0]);
    for (frame, z) in [(1.0, 0.0), (2.0, 0.5), (3.0, 1.0)] {
        let got = lifted(&ranged, frame).unwrap();
        assert!((got - z).abs() < 1e-6, "frame {frame}: z {got}, want {z}");
        render(&ranged, &small(Some(frame))).unwrap();
    }
    let e = lifted(&ranged, 4.0).unwrap_err();
    assert!(e.contains("key_blocks") && e.contains("--frames"), "{e}");

    let single = convert(&[], &tmp.path().join("single"));
    assert!(lifted(&single, 1.0).is_ok());
    let e = render(&single, &small(Some(2.0))).unwrap_err().to_string();
    assert!(e.contains("\"Sheet\"") && e.contains("key_blocks"), "{e}");
    let o = run(
        &["inspect", single.dir.to_str().unwrap(), "--frame", "2"],
        &[],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stdout(&o));
}

/// `inspect`'s verdict is the render's, both ways (issue 26): a material with an add-on
/// node that nothing renders is listed (the node as unsupported, the material as not
/// compiling) and refuses nothing, so inspect exits 0 and the frame renders; once an
/// object that renders uses it, inspect refuses it with the render's own words.
#[test]
fn inspect_refuses_exactly_what_render_refuses() {
    use serde_json::{json, Value};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scene");
    copy_dir(&repo().join("fixtures/scenes/animated_camera"), &dir);
    let p = dir.join("scene.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let node = json!({"name": "Lux Matte", "bl_idname": "NodeUndefined",
        "inputs": [], "outputs": [{"index": 0, "identifier": "Material", "name": "Material",
        "type": "CUSTOM", "bl_idname": "NodeSocketUndefined"}]});
    // Linked into a Cycles output: a tree with no Cycles output at all is Cycles' empty
    // surface, which renders (fixture material_no_cycles_output).
    let output = json!({"name": "Material Output", "bl_idname": "ShaderNodeOutputMaterial",
        "properties": {"is_active_output": true, "target": "ALL"},
        "inputs": [{"index": 0, "identifier": "Surface", "name": "Surface", "type": "SHADER",
                    "bl_idname": "NodeSocketShader", "is_linked": true, "enabled": true}],
        "outputs": []});
    let link = json!({"from_node": "Lux Matte", "from_socket": "Material", "from_index": 0,
        "to_node": "Material Output", "to_socket": "Surface", "to_index": 0,
        "is_muted": false, "is_valid": true});
    v["materials"] = json!([{"name": "Add-on", "use_nodes": true,
        "node_tree": {"name": "Shader Nodetree", "bl_idname": "ShaderNodeTree",
                      "nodes": [node, output], "links": [link]}}]);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    let report = blendsynth::inspect::report(&scene);
    assert!(report
        .coverage
        .iter()
        .any(|r| r.bl_idname == "NodeUndefined"
            && r.support == blendsynth::nodes::Support::Unsupported));
    assert!(report.material_status[0].error.is_some());
    assert!(report.all_supported, "{}", report.to_text());
    render(&scene, &small(None)).expect("an unused material refuses nothing");

    let subject = v["objects"]
        .as_array()
        .unwrap()
        .iter()
        .position(|o| o["name"] == "Subject")
        .unwrap();
    v["objects"][subject]["material_slots"] = json!([{"material": "Add-on", "link": "OBJECT"}]);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    let e = render(&scene, &small(None)).unwrap_err().to_string();
    let report = blendsynth::inspect::report(&scene);
    assert!(!report.all_supported);
    assert_eq!(report.render_error.as_deref(), Some(e.as_str()));
}

/// A BSDF wired to a light's output emits nothing in Cycles (the shader's emission
/// estimate is zero, so the light is left out): the frame renders as without the light,
/// where it was refused (godot-blender-exporter's cycles_lights file).
#[test]
fn a_light_whose_tree_ends_in_a_bsdf_is_left_out() {
    use serde_json::{json, Value};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("scene");
    copy_dir(&repo().join("fixtures/scenes/animated_camera"), &dir);
    let p = dir.join("scene.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    let key = v["lights"]
        .as_array()
        .unwrap()
        .iter()
        .position(|l| l["name"] == "Key")
        .unwrap();
    let sock = |i: usize, id: &str, kind: &str| {
        json!({"index": i, "identifier": id,
        "name": id, "type": kind, "bl_idname": "NodeSocketShader"})
    };
    v["lights"][key]["properties"]["use_nodes"] = json!(true);
    v["lights"][key]["node_tree"] = json!({"name": "Shader Nodetree",
        "bl_idname": "ShaderNodeTree",
        "nodes": [
            {"name": "Diffuse BSDF", "bl_idname": "ShaderNodeBsdfDiffuse",
             "inputs": [], "outputs": [sock(0, "BSDF", "SHADER")]},
            {"name": "Light Output", "bl_idname": "ShaderNodeOutputLight",
             "properties": {"is_active_output": true, "target": "ALL"},
             "inputs": [sock(0, "Surface", "SHADER")], "outputs": []}],
        "links": [{"from_node": "Diffuse BSDF", "from_socket": "BSDF", "from_index": 0,
                   "to_node": "Light Output", "to_socket": "Surface", "to_index": 0}]});
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    let with_bsdf = render(&scene, &small(None)).expect("a BSDF light renders black");
    v["lights"][key]["node_tree"] = Value::Null;
    v["lights"][key]["properties"]["energy"] = json!(0.0);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let scene = Scene::load(&dir).unwrap();
    let dark = render(&scene, &small(None)).unwrap();
    assert_eq!(with_bsdf.color, dark.color);
}

/// Blender-side: frozen meshes are Blender's evaluation with the render settings Cycles
/// uses, not the viewport's (`fixtures/coverage/make_render_levels_scene.py`: Subdivision
/// Surface at level 0 in the viewport, 2 in renders, under a Triangulate modifier): the
/// cube at level 2 has 98 vertices and 96 quads, 192 triangles. The exported modifier
/// keeps the file's viewport level.
#[test]
fn frozen_meshes_use_render_levels() {
    let Some(py) = require("bpy", bpy_python()) else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let blend = tmp.path().join("levels.blend");
    let export = tmp.path().join("export");
    run_python(
        &py,
        &repo().join("fixtures/coverage/make_render_levels_scene.py"),
        &["--", blend.to_str().unwrap()],
    );
    let o = convert_blend(&py, &blend, &export, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let scene = Scene::load(&export).unwrap();
    let set = blendsynth::geometry::evaluate_object(&scene, "Cube", 1.0, &[]).unwrap();
    let m = blendsynth::geometry::realize_to_mesh(&set).unwrap();
    assert_eq!((m.vertex_count(), m.face_count()), (98, 192));
    let sub = &scene.object("Cube").unwrap().modifiers[0];
    assert_eq!(
        sub.properties.get("levels").and_then(|v| v.as_i64()),
        Some(0)
    );
}
