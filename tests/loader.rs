//! Bad input to the loader: each case is a committed fixture export with one thing
//! broken, and must give a clear error naming the file and where in it.

mod common;
use common::*;

use blendsynth::scene::{read_obj, Scene};
use serde_json::Value;
use std::path::{Path, PathBuf};

const FIXTURE: &str = "fixtures/scenes/material_zoo";

/// A private copy of the fixture export, with `edit` applied to its scene.json.
fn broken(edit: impl FnOnce(&mut Value)) -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("scene");
    copy_dir(&repo().join(FIXTURE), &dir);
    let p = dir.join("scene.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    edit(&mut v);
    std::fs::write(&p, serde_json::to_vec_pretty(&v).unwrap()).unwrap();
    (t, dir)
}

fn load_err(dir: &Path) -> String {
    match Scene::load(dir) {
        Ok(_) => panic!("{} should have been rejected", dir.display()),
        Err(e) => {
            let s = e.to_string();
            assert!(
                s.contains("scene.json") || s.contains(".glb"),
                "error must name the file: {s}"
            );
            s
        }
    }
}

fn first_tree_with_links(v: &mut Value) -> &mut Value {
    v["materials"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find_map(|m| {
            let t = &mut m["node_tree"];
            (t.is_object() && !t["links"].as_array().unwrap().is_empty()).then_some(t)
        })
        .expect("fixture has a material with links")
}

#[test]
fn fixture_loads_and_inspects() {
    let s = Scene::load(&repo().join(FIXTURE)).unwrap();
    assert!(!s.file.objects.is_empty());
    for i in 0..s.file.meshes.len() {
        s.load_mesh(i).unwrap();
    }
    let o = run(&["inspect", repo().join(FIXTURE).to_str().unwrap()], &[]);
    // Nodes are not all supported yet, so inspect says so with status 3.
    assert!(
        matches!(o.status.code(), Some(0) | Some(3)),
        "{}",
        stderr(&o)
    );
    assert!(stdout(&o).contains("Node coverage"));
    let o = run(
        &["inspect", "--json", repo().join(FIXTURE).to_str().unwrap()],
        &[],
    );
    let v: Value = serde_json::from_slice(&o.stdout).expect("inspect --json is JSON");
    assert!(v["coverage"].as_array().unwrap().len() >= 20);
}

#[test]
fn unknown_fields_are_tolerated() {
    let (_t, dir) = broken(|v| {
        v["a_future_field"] = Value::from(42);
        v["objects"][0]["another_future_field"] = serde_json::json!({"x": [1, 2]});
        first_tree_with_links(v)["nodes"][0]["future"] = Value::from("yes");
    });
    Scene::load(&dir).expect("unknown fields must be ignored");
}

#[test]
fn missing_required_field() {
    let (_t, dir) = broken(|v| {
        v["objects"][0]
            .as_object_mut()
            .unwrap()
            .remove("matrix_world");
    });
    let e = load_err(&dir);
    assert!(
        e.contains("objects[0]") && e.contains("matrix_world"),
        "{e}"
    );
}

#[test]
fn wrong_type() {
    let (_t, dir) = broken(|v| v["objects"][0]["location"] = Value::from("north"));
    let e = load_err(&dir);
    assert!(e.contains("objects[0].location"), "{e}");
    let (_t, dir) = broken(|v| v["scene"]["frame_start"] = Value::from(1.5));
    let e = load_err(&dir);
    assert!(e.contains("scene.frame_start"), "{e}");
}

#[test]
fn not_a_scene_or_newer_version() {
    let (_t, dir) = broken(|v| v["format"] = Value::from("something-else"));
    assert!(load_err(&dir).contains("format"));
    let (_t, dir) = broken(|v| v["version"] = Value::from(99));
    let e = load_err(&dir);
    assert!(e.contains("version") && e.contains("99"), "{e}");
}

/// Replaces the first number after `"frame_current":` with `word`.
fn with_token(word: &str) -> (tempfile::TempDir, PathBuf) {
    let (t, dir) = broken(|_| {});
    let p = dir.join("scene.json");
    let text = std::fs::read_to_string(&p).unwrap();
    let key = "\"frame_current\": ";
    let at = text.find(key).unwrap() + key.len();
    let end = at + text[at..].find([',', '\n']).unwrap();
    std::fs::write(&p, format!("{}{}{}", &text[..at], word, &text[end..])).unwrap();
    (t, dir)
}

#[test]
fn non_finite_numbers() {
    for word in ["NaN", "Infinity", "-Infinity"] {
        let (_t, dir) = with_token(word);
        let e = load_err(&dir);
        assert!(
            e.contains("non-finite") && e.contains("line "),
            "{word}: {e}"
        );
    }
    let (_t, dir) = with_token("1e999");
    let e = load_err(&dir);
    assert!(e.contains("line ") && e.contains("out of range"), "{e}");
}

#[test]
fn dangling_links() {
    let (_t, dir) =
        broken(|v| first_tree_with_links(v)["links"][0]["from_node"] = Value::from("No Such Node"));
    let e = load_err(&dir);
    assert!(
        e.contains(".links[0].from_node") && e.contains("No Such Node") && e.contains("dangling"),
        "{e}"
    );
    let (_t, dir) =
        broken(|v| first_tree_with_links(v)["links"][0]["to_socket"] = Value::from("NoSocket"));
    let e = load_err(&dir);
    assert!(
        e.contains(".links[0].to_socket") && e.contains("NoSocket"),
        "{e}"
    );
    let (_t, dir) = broken(|v| v["objects"][0]["parent"] = Value::from("Ghost"));
    assert!(load_err(&dir).contains("objects[0]"));
}

#[test]
fn mesh_paths_stay_inside_the_scene_folder() {
    for (path, why) in [
        ("../../etc/passwd", "leaves the scene folder"),
        ("/etc/passwd", "absolute"),
        ("meshes\\a.glb", "separators"),
    ] {
        let (_t, dir) = broken(|v| v["meshes"][0]["file"] = Value::from(path));
        let e = load_err(&dir);
        assert!(
            e.contains("meshes[0].file") && e.contains(why),
            "{path}: {e}"
        );
    }
    // A symlink inside the folder that points outside it.
    let (t, dir) = broken(|v| v["meshes"][0]["file"] = Value::from("meshes/escape.glb"));
    let outside = t.path().join("outside.glb");
    std::fs::write(&outside, b"x").unwrap();
    std::os::unix::fs::symlink(&outside, dir.join("meshes/escape.glb")).unwrap();
    let e = load_err(&dir);
    assert!(e.contains("outside the scene folder"), "{e}");
}

/// The exporter writes the colour-management config into a folder of its own (Filmic,
/// AgX, ...): that folder passes the regular-file rule meant for the files a scene reads.
#[test]
fn colour_management_folder_is_a_folder() {
    let (_t, dir) = broken(|v| {
        v["color_management"] = serde_json::json!({"dir": "colormanagement"});
    });
    std::fs::create_dir(dir.join("colormanagement")).unwrap();
    Scene::load(&dir).unwrap_or_else(|e| panic!("{e}"));
    let (_t, dir) = broken(|v| {
        v["color_management"] = serde_json::json!({"dir": "scene.json"});
    });
    let e = load_err(&dir);
    assert!(
        e.contains("color_management.dir") && e.contains("not a folder"),
        "{e}"
    );
}

#[test]
fn truncated_files() {
    let (_t, dir) = broken(|_| {});
    let p = dir.join("scene.json");
    let bytes = std::fs::read(&p).unwrap();
    std::fs::write(&p, &bytes[..bytes.len() / 2]).unwrap();
    let e = load_err(&dir);
    assert!(e.contains("truncated"), "{e}");

    let (_t, dir) = broken(|_| {});
    let s = Scene::load(&dir).unwrap();
    let glb = dir.join(&s.file.meshes[0].file);
    let bytes = std::fs::read(&glb).unwrap();
    std::fs::write(&glb, &bytes[..bytes.len() * 2 / 3]).unwrap();
    let e = s.load_mesh(0).unwrap_err().to_string();
    assert!(e.contains(".glb"), "{e}");
    // Through the CLI: exit 1, one line, no panic.
    let o = run(&["inspect", dir.to_str().unwrap()], &[]);
    assert_clean_error(&o, 1, &[".glb"]);
}

#[test]
fn mesh_counts_must_match_scene_json() {
    let (_t, dir) = broken(|v| {
        let n = v["meshes"][0]["vertex_count"].as_u64().unwrap();
        v["meshes"][0]["vertex_count"] = Value::from(n + 1);
    });
    let s = Scene::load(&dir).unwrap();
    let e = s.load_mesh(0).unwrap_err().to_string();
    assert!(e.contains("meshes[0].vertex_count"), "{e}");
}

#[test]
fn cli_reports_bad_scene_in_one_line() {
    let (_t, dir) =
        broken(|v| first_tree_with_links(v)["links"][0]["to_node"] = Value::from("Nowhere"));
    let o = run(&["inspect", dir.to_str().unwrap()], &[]);
    assert_clean_error(&o, 1, &["scene.json", "to_node", "Nowhere"]);
}

#[test]
fn obj_keeps_vertices_one_to_one() {
    let t = tempfile::tempdir().unwrap();
    let p = t.path().join("m.obj");
    // A quad and a triangle sharing an edge, with per-corner UVs that differ across it.
    std::fs::write(
        &p,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0.5 0\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\nvt 0.9 0.9\n\
         f 1/1 2/2 3/3 4/4\nf 2/5 5/6 3/5\n",
    )
    .unwrap();
    let m = read_obj(&p).unwrap();
    assert_eq!(m.vertex_count(), 5);
    assert_eq!(m.face_count(), 2);
    assert_eq!(m.corner_count(), 7);
    assert_eq!(m.edges.len(), 6);
    assert_eq!(m.corner_verts, vec![0, 1, 2, 3, 1, 4, 2]);
    assert_eq!(m.triangles.len(), 3);
    match &m.attribute("UVMap").unwrap().data {
        blendsynth::scene::AttributeData::Float2(uv) => assert_eq!(uv[4], [0.5, 0.5]),
        d => panic!("{d:?}"),
    }
}

#[test]
fn inspect_exits_0_when_every_node_is_supported() {
    // The animated camera scene without its world has no shader nodes at all.
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("scene");
    copy_dir(&repo().join("fixtures/scenes/animated_camera"), &dir);
    let p = dir.join("scene.json");
    let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    v["worlds"] = Value::Array(vec![]);
    v["scene"]["world"] = Value::Null;
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let o = run(&["inspect", dir.to_str().unwrap()], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The unmodified scene's world (Background, World Output) is evaluated too.
    let o = run(
        &[
            "inspect",
            repo()
                .join("fixtures/scenes/animated_camera")
                .to_str()
                .unwrap(),
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // A world node blendsynth does not evaluate (Script: OSL) is named in the table; it
    // refuses nothing while nothing reads it (as in `render`), and makes inspect exit 3,
    // named, once it feeds the world's output.
    let mut v: Value = serde_json::from_slice(
        &std::fs::read(repo().join("fixtures/scenes/animated_camera/scene.json")).unwrap(),
    )
    .unwrap();
    let tree = &mut v["worlds"][0]["node_tree"];
    let nodes = tree["nodes"].as_array_mut().expect("world nodes");
    let first = nodes[0]["name"].as_str().unwrap().to_string();
    let mut script = nodes[0].clone();
    script["name"] = Value::from("Script");
    script["bl_idname"] = Value::from("ShaderNodeScript");
    nodes.push(script);
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let o = run(&["inspect", dir.to_str().unwrap()], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).contains("ShaderNodeScript"));
    for l in v["worlds"][0]["node_tree"]["links"].as_array_mut().unwrap() {
        if l["from_node"] == first.as_str() {
            l["from_node"] = Value::from("Script");
        }
    }
    std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
    let o = run(&["inspect", dir.to_str().unwrap()], &[]);
    assert_eq!(o.status.code(), Some(3), "{}", stdout(&o));
    assert!(stdout(&o).contains("render NOT YET") && stdout(&o).contains("Script"));
}
