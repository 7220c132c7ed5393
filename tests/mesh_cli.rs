//! `blendsynth mesh`: evaluated geometry written as glb / PLY / OBJ, one to one with
//! Blender's evaluated mesh (the exporter's reference, made by Blender), overrides by
//! data path, and clean errors.

mod common;

use common::{assert_clean_error, repo, run, stdout};

fn geonodes() -> String {
    repo()
        .join("fixtures/scenes/geonodes")
        .to_string_lossy()
        .into_owned()
}

#[test]
fn writes_blenders_evaluated_mesh_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let scene = blendsynth::scene::Scene::load(&repo().join("fixtures/scenes/geonodes")).unwrap();
    let reference = scene.load_evaluated(0).unwrap();
    assert_eq!(scene.file.evaluated[0].object, "Terrain");
    for ext in ["ply", "obj", "glb"] {
        let out = dir.path().join(format!("terrain.{ext}"));
        let o = run(
            &[
                "mesh",
                &geonodes(),
                "--object",
                "Terrain",
                "--frame",
                "1",
                "-o",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert!(o.status.success(), "{}", common::stderr(&o));
        assert!(
            stdout(&o).contains(&format!("{} vertices", reference.vertex_count())),
            "{}",
            stdout(&o)
        );
        let m = match ext {
            "glb" => blendsynth::scene::read_glb(&out).unwrap(),
            "obj" => blendsynth::scene::read_obj(&out).unwrap(),
            _ => {
                let bytes = std::fs::read(&out).unwrap();
                let head = String::from_utf8_lossy(&bytes[..300.min(bytes.len())]).into_owned();
                assert!(
                    head.contains(&format!("element vertex {}\n", reference.vertex_count())),
                    "{head}"
                );
                assert!(
                    head.contains(&format!("element face {}\n", reference.face_count())),
                    "{head}"
                );
                continue;
            }
        };
        assert_eq!(m.vertex_count(), reference.vertex_count(), "{ext}");
        assert_eq!(m.face_count(), reference.face_count(), "{ext}");
        if ext == "glb" {
            // Same vertices in the same order as Blender's.
            let err = m
                .positions
                .iter()
                .zip(&reference.positions)
                .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0f32, f32::max))
                .fold(0.0f32, f32::max);
            assert!(err < 1e-5, "max position error {err}");
        }
        // No temporary file is left next to the output.
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert!(names.iter().all(|n| !n.contains(".part.")), "{names:?}");
    }
}

#[test]
fn overrides_change_the_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.ply");
    let b = dir.path().join("b.ply");
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "Terrain",
            "-o",
            a.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    // A node input set by data path reaches the evaluator.
    let path = "bpy.data.node_groups[\"Terrain Builder\"].nodes[\"Grid\"].inputs[\"Vertices X\"].default_value=4";
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "Terrain",
            "--set",
            path,
            "-o",
            b.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn bad_input_is_a_clean_error_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.ply");
    let out_s = out.to_str().unwrap();
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "No Such Object",
            "-o",
            out_s,
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["No Such Object"]);
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "Terrain",
            "-o",
            dir.path().join("x.stl").to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["x.stl"]);
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "Terrain",
            "--set",
            "node_groups[\"nope\"].nodes[\"v\"].outputs[0].default_value=1",
            "-o",
            out_s,
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["nope"]);
    // An override that makes the tree unsupported (the Noise Texture has no 5D).
    let over = "node_groups[\"Terrain Builder\"].nodes[\"Noise Texture\"].noise_dimensions=\"5D\"";
    let o = run(
        &[
            "mesh",
            &geonodes(),
            "--object",
            "Terrain",
            "--set",
            over,
            "-o",
            out_s,
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["Noise Texture", "5D"]);
    let o = run(
        &[
            "mesh",
            "/nonexistent/scene",
            "--object",
            "Terrain",
            "-o",
            out_s,
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["/nonexistent/scene"]);
    assert!(!out.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no partial output"
    );
}
