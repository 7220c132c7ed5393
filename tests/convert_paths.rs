//! `convert`'s path policy (issue 27): a .blend may name any file on the machine as an
//! image (an absolute path, `//../..`, a symlink inside its folder), and an export is
//! meant to be shared, so only files under the .blend's folder are copied unless the
//! user allows another folder (`--allow-path DIR`); every copied file is listed, and
//! errors name the image, the path and the flag, never the file's content. Needs
//! Blender (the bpy module): skipped without it, a failure in CI.

mod common;

use common::*;

const SECRET: &str = "OPENSSH PRIVATE KEY";

/// A temporary folder with the blends `make_blends.py` authors (see its docstring).
fn authored_blends(py: &std::path::Path) -> tempfile::TempDir {
    let t = tempfile::tempdir().unwrap();
    run_python(
        py,
        &repo().join("fixtures/convert_paths/make_blends.py"),
        &[t.path().to_str().unwrap()],
    );
    t
}

#[test]
fn convert_copies_only_files_inside_the_blends_folder_unless_allowed() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = authored_blends(&py);
    let root = t.path();
    let secret_dir = root.join("secret");
    let proj = root.join("proj");

    for (blend, image, named) in [
        ("absolute", "key_abs", secret_dir.join("id_rsa")),
        ("relative", "key_rel", "//../secret/id_rsa".into()),
        ("symlink", "key_link", "//textures/link.png".into()),
    ] {
        let out = root.join(format!("out-{blend}"));
        let o = convert_blend(&py, &proj.join(format!("{blend}.blend")), &out, &[]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{blend}: {err}");
        for want in [
            format!("images[\"{image}\"]"),
            named.display().to_string(),
            format!("--allow-path {}", secret_dir.display()),
        ] {
            assert!(err.contains(&want), "{blend}: {want:?} not in {err}");
        }
        assert!(!err.contains(SECRET), "the error shows the file: {err}");
        assert!(!out.exists(), "{blend}: no export written");
        let leftovers: Vec<_> = std::fs::read_dir(root)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains(".partial"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }

    // Inside the folder: copied and listed; a missing file stays missing (magenta).
    let out = root.join("out-inside");
    let o = convert_blend(&py, &proj.join("inside.blend"), &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let listed: Vec<String> = stdout(&o)
        .lines()
        .filter(|l| l.starts_with("copied "))
        .map(String::from)
        .collect();
    assert_eq!(listed.len(), 1, "{listed:?}");
    assert!(
        listed[0].contains("textures/in.png") && listed[0].contains("\"in\""),
        "{listed:?}"
    );
    let scene = blendsynth::scene::Scene::load(&out).unwrap();
    let gone = scene.file.images.iter().find(|i| i.name == "gone").unwrap();
    assert!(gone.missing && gone.file.is_none());

    // Allowed: every file copied and listed, one line each.
    let out = root.join("out-all");
    let o = convert_blend(
        &py,
        &proj.join("all.blend"),
        &out,
        &["--allow-path", secret_dir.to_str().unwrap()],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = stdout(&o);
    let listed: Vec<&str> = text.lines().filter(|l| l.starts_with("copied ")).collect();
    assert_eq!(listed.len(), 4, "{text}");
    for image in ["in", "key_abs", "key_rel", "key_link"] {
        assert!(
            listed
                .iter()
                .any(|l| l.ends_with(&format!("(image \"{image}\")"))),
            "{image} not listed: {text}"
        );
    }
    let copied = std::fs::read_dir(out.join("images")).unwrap().count();
    assert_eq!(copied, 4);

    // An --allow-path that is not a folder is an error before Blender runs.
    let o = convert_blend(
        &py,
        &proj.join("all.blend"),
        &root.join("out-bad"),
        &["--allow-path", root.join("nope").to_str().unwrap()],
    );
    assert_clean_error(&o, 1, &["--allow-path", "nope"]);
}

/// An IES Texture's External file goes by the same policy as images: outside the .blend's
/// folder an error naming the node and flag; inside, its bytes travel in the export; a
/// missing one is the "\n" Cycles falls back to (every lookup 100).
#[test]
fn ies_files_follow_the_path_policy() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = authored_blends(&py);
    let root = t.path();
    let proj = root.join("proj");
    let out = root.join("out-ies-outside");
    let o = convert_blend(&py, &proj.join("ies_outside.blend"), &out, &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    for want in ["IES file", "//../secret/id_rsa", "--allow-path"] {
        assert!(err.contains(want), "{want:?} not in {err}");
    }
    assert!(!err.contains(SECRET), "the error shows the file: {err}");
    assert!(!out.exists());

    let out = root.join("out-ies-inside");
    let o = convert_blend(&py, &proj.join("ies_inside.blend"), &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let scene = blendsynth::scene::Scene::load(&out).unwrap();
    let tree = scene.file.lights[0].node_tree.as_ref().unwrap();
    let ies = |name: &str| {
        tree.nodes
            .iter()
            .find(|n| n.name == name)
            .and_then(|n| n.ies.clone())
            .unwrap()
    };
    let inside = ies("//lamp.ies");
    assert!(
        inside.starts_with("IESNA:LM-63-2002\nTILT=NONE"),
        "{inside:?}"
    );
    assert_eq!(ies("//nope.ies"), "\n");
}
