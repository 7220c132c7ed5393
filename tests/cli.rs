//! The command line's contract: --help/--version, exit codes, one-line errors.

mod common;
use common::*;

#[test]
fn version_and_help() {
    let o = run(&["--version"], &[]);
    assert_eq!(o.status.code(), Some(0));
    assert!(stdout(&o).starts_with("blendsynth "), "{}", stdout(&o));
    // --version names the exchange format this build reads.
    let format = format!("(exchange format {})", blendsynth::scene::FORMAT_VERSION);
    assert!(stdout(&o).contains(&format), "{}", stdout(&o));
    for sub in [
        vec!["--help"],
        vec!["convert", "--help"],
        vec!["inspect", "--help"],
        vec!["help", "convert"],
    ] {
        let o = run(&sub, &[]);
        assert_eq!(o.status.code(), Some(0), "{sub:?}: {}", stderr(&o));
        assert!(stdout(&o).contains("Usage:"), "{sub:?}");
    }
}

#[test]
fn bad_usage_exits_2() {
    for args in [
        vec!["frobnicate"],
        vec!["convert"],
        vec!["inspect"],
        vec!["convert", "x.blend"],
        vec!["inspect", "d", "--bogus"],
    ] {
        let o = run(&args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn convert_missing_input() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("out");
    let o = run(
        &[
            "convert",
            "/nonexistent/scene.blend",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["input file not found", "/nonexistent/scene.blend"]);
    assert!(!out.exists());
}

#[test]
fn convert_rejects_non_blend() {
    let t = tempfile::tempdir().unwrap();
    let f = t.path().join("fake.blend");
    std::fs::write(&f, b"this is not blender data").unwrap();
    let o = run(
        &[
            "convert",
            f.to_str().unwrap(),
            "-o",
            t.path().join("o").to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["not a .blend file", "fake.blend"]);
}

/// Writes a file with a .blend header (enough to get past the header check).
fn fake_blend(dir: &std::path::Path) -> std::path::PathBuf {
    let f = dir.join("scene.blend");
    std::fs::write(&f, b"BLENDER-v404REND....").unwrap();
    f
}

#[test]
fn convert_without_blender_says_how_to_install() {
    let t = tempfile::tempdir().unwrap();
    let f = fake_blend(t.path());
    let out = t.path().join("out");
    let o = run(
        &["convert", f.to_str().unwrap(), "-o", out.to_str().unwrap()],
        &[("PATH", "/nonexistent")],
    );
    assert_clean_error(&o, 1, &["no Blender found", "--blender", "bpy==4.5.4"]);
    // Nothing half-written: neither the output nor a staging folder is left behind.
    assert!(!out.exists());
    let left: Vec<_> = std::fs::read_dir(t.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "left behind: {left:?}");
}

#[test]
fn convert_blender_path_must_exist() {
    let t = tempfile::tempdir().unwrap();
    let f = fake_blend(t.path());
    let o = run(
        &[
            "convert",
            f.to_str().unwrap(),
            "-o",
            t.path().join("o").to_str().unwrap(),
            "--blender",
            "/no/such/blender",
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["--blender /no/such/blender", "no such file"]);
}

#[test]
fn convert_unwritable_output_folder() {
    let t = tempfile::tempdir().unwrap();
    let f = fake_blend(t.path());
    // procfs refuses new folders even to root, so this fails the same way everywhere.
    let o = run(
        &[
            "convert",
            f.to_str().unwrap(),
            "-o",
            "/proc/blendsynth-test/out",
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["/proc/blendsynth-test"]);
    // An output path under a regular file.
    let o = run(
        &[
            "convert",
            f.to_str().unwrap(),
            "-o",
            f.join("out").to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["scene.blend/out"]);
}

#[test]
fn convert_refuses_to_overwrite_a_foreign_folder() {
    let t = tempfile::tempdir().unwrap();
    let f = fake_blend(t.path());
    let out = t.path().join("precious");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("thesis.tex"), b"...").unwrap();
    let o = run(
        &["convert", f.to_str().unwrap(), "-o", out.to_str().unwrap()],
        &[],
    );
    assert_clean_error(&o, 1, &["not a blendsynth export"]);
    assert!(out.join("thesis.tex").is_file());
}

#[test]
fn inspect_missing_folder() {
    let o = run(&["inspect", "/nonexistent/export"], &[]);
    assert_clean_error(&o, 1, &["/nonexistent/export"]);
}
