//! Hostile and broken input (issue 27, part A): crafted glb numbers, huge sizes, FIFOs,
//! paths leaving the scene, silent clamps. Each case must end in a clear error naming
//! what was wrong: never a panic, abort, hang or stray output.

mod common;
use common::*;

use blendsynth::scene::mesh::parse_glb;
use blendsynth::scene::Scene;
use serde_json::Value;
use std::path::{Path, PathBuf};

const FIXTURE: &str = "fixtures/scenes/material_zoo";
const GLB: &str = "fixtures/scenes/material_zoo/meshes/0000_Plane.glb";

/// A glb split into its JSON chunk (parsed) and BIN chunk.
fn split_glb(bytes: &[u8]) -> (Value, Vec<u8>) {
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    let json_len = u32_at(12);
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    (json, bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec())
}

fn join_glb(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut j = serde_json::to_vec(json).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// The fixture glb with `edit` applied to its JSON, parsed: must be an error (no panic).
fn glb_err(edit: impl FnOnce(&mut Value)) -> String {
    let (mut json, bin) = split_glb(&std::fs::read(repo().join(GLB)).unwrap());
    edit(&mut json);
    let bytes = join_glb(&json, &bin);
    let path = Path::new("crafted.glb");
    match std::panic::catch_unwind(|| parse_glb(&bytes, path)) {
        Err(_) => panic!("parse_glb panicked"),
        Ok(Ok(_)) => panic!("crafted glb was accepted"),
        Ok(Err(e)) => {
            let s = e.to_string();
            assert!(s.contains("crafted.glb"), "error must name the file: {s}");
            s
        }
    }
}

/// The accessor of `extras.blendsynth.<what>`.
fn accessor<'a>(json: &'a mut Value, what: &str) -> &'a mut Value {
    let i = json["extras"]["blendsynth"][what].as_u64().unwrap() as usize;
    &mut json["accessors"][i]
}

#[test]
fn glb_roundtrip_of_the_test_helpers_is_faithful() {
    let bytes = std::fs::read(repo().join(GLB)).unwrap();
    let (json, bin) = split_glb(&bytes);
    let a = parse_glb(&bytes, Path::new("a.glb")).unwrap();
    let b = parse_glb(&join_glb(&json, &bin), Path::new("b.glb")).unwrap();
    assert_eq!(a, b);
}

#[test]
fn glb_header_length_below_the_header_is_named() {
    // cargo fuzz (glb target) found this: the gltf crate subtracts 12 from the header's
    // length unchecked, a panic where overflow checks are on.
    let mut bytes = std::fs::read(repo().join(GLB)).unwrap();
    for length in [0u32, 4, 11] {
        bytes[8..12].copy_from_slice(&length.to_le_bytes());
        let e = parse_glb(&bytes, Path::new("a.glb"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("header's length {length} ")), "{e}");
    }
    let too_long = bytes.len() as u32 + 1;
    bytes[8..12].copy_from_slice(&too_long.to_le_bytes());
    let e = parse_glb(&bytes, Path::new("a.glb"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("header's length"), "{e}");
}

#[test]
fn glb_accessor_count_2_pow_62_is_an_error() {
    let e = glb_err(|j| accessor(j, "vertex_positions")["count"] = Value::from(1u64 << 62));
    assert!(e.contains("vertex_positions"), "{e}");
}

#[test]
fn glb_buffer_view_offset_near_2_pow_64_is_an_error() {
    let e = glb_err(|j| {
        let v = accessor(j, "vertex_positions")["bufferView"]
            .as_u64()
            .unwrap() as usize;
        j["bufferViews"][v]["byteOffset"] = Value::from(u64::MAX - 7);
    });
    assert!(e.contains("vertex_positions"), "{e}");
}

#[test]
fn glb_count_2_pow_60_plus_1_with_stride_16_is_an_error() {
    let e = glb_err(|j| {
        let a = accessor(j, "vertex_positions");
        a["count"] = Value::from((1u64 << 60) + 1);
        let v = a["bufferView"].as_u64().unwrap() as usize;
        a["byteOffset"] = Value::from(0);
        j["bufferViews"][v]["byteStride"] = Value::from(16);
    });
    assert!(e.contains("vertex_positions"), "{e}");
}

#[test]
fn glb_attribute_accessor_with_huge_count_is_an_error() {
    glb_err(|j| {
        let i = j["extras"]["blendsynth"]["attributes"][0]["accessor"]
            .as_u64()
            .unwrap() as usize;
        j["accessors"][i]["count"] = Value::from(u64::MAX);
    });
}

#[test]
fn glb_declared_counts_beyond_the_limit_are_errors() {
    for what in [
        "vertex_count",
        "face_count",
        "corner_count",
        "triangle_count",
    ] {
        let e = glb_err(|j| j["extras"]["blendsynth"][what] = Value::from(u64::MAX / 2));
        assert!(e.contains(what), "{e}");
    }
}

/// A private copy of the fixture export, with `edit` applied to its mesh's glb JSON.
fn scene_with_glb(edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> (tempfile::TempDir, PathBuf) {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("scene");
    copy_dir(&repo().join(FIXTURE), &dir);
    let p = dir.join("meshes/0000_Plane.glb");
    let (mut json, mut bin) = split_glb(&std::fs::read(&p).unwrap());
    edit(&mut json, &mut bin);
    std::fs::write(&p, join_glb(&json, &bin)).unwrap();
    (t, dir)
}

#[test]
fn crafted_glb_through_every_scene_command_is_a_clean_error() {
    let (_t, dir) =
        scene_with_glb(|j, _| accessor(j, "vertex_positions")["count"] = Value::from(1u64 << 62));
    let d = dir.to_str().unwrap();
    for args in [
        vec!["inspect", d],
        vec!["render", d, "-o", "/nonexistent-dir/x.png"],
        vec![
            "mesh",
            d,
            "--object",
            "Plane",
            "-o",
            "/nonexistent-dir/x.glb",
        ],
    ] {
        let o = run(&args, &[]);
        let err = stderr(&o);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_ne!(o.status.code(), Some(0), "{args:?}: {err}");
        assert_ne!(o.status.code(), Some(101), "{args:?}: {err}");
    }
}

/// Float data of a corner accessor set to NaN in the BIN chunk.
fn nan_in(j: &Value, bin: &mut [u8], acc: usize) {
    let a = &j["accessors"][acc];
    let v = &j["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let off = v["byteOffset"].as_u64().unwrap_or(0) + a["byteOffset"].as_u64().unwrap_or(0);
    let off = off as usize;
    bin[off..off + 4].copy_from_slice(&f32::NAN.to_le_bytes());
}

#[test]
fn nan_normals_are_an_error_naming_the_field() {
    let (json, mut bin) = split_glb(&std::fs::read(repo().join(GLB)).unwrap());
    let acc = json["extras"]["blendsynth"]["corner_normals"]
        .as_u64()
        .unwrap() as usize;
    nan_in(&json, &mut bin, acc);
    let e = parse_glb(&join_glb(&json, &bin), Path::new("n.glb")).unwrap_err();
    let e = e.to_string();
    assert!(e.contains("corner_normals") && e.contains("Plane"), "{e}");
}

#[test]
fn nan_uvs_are_an_error_naming_the_attribute() {
    let (json, mut bin) = split_glb(&std::fs::read(repo().join(GLB)).unwrap());
    let uv = json["extras"]["blendsynth"]["attributes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["data_type"] == "FLOAT2" && a["domain"] == "CORNER")
        .expect("the fixture plane has a UV map")
        .clone();
    nan_in(&json, &mut bin, uv["accessor"].as_u64().unwrap() as usize);
    let e = parse_glb(&join_glb(&json, &bin), Path::new("uv.glb")).unwrap_err();
    let e = e.to_string();
    assert!(e.contains(uv["name"].as_str().unwrap()), "{e}");
    assert!(e.contains("not finite"), "{e}");
}

#[test]
fn a_mesh_file_that_is_a_fifo_is_an_error_not_a_hang() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("scene");
    copy_dir(&repo().join(FIXTURE), &dir);
    let glb = dir.join("meshes/0000_Plane.glb");
    std::fs::remove_file(&glb).unwrap();
    let st = std::process::Command::new("mkfifo")
        .arg(&glb)
        .status()
        .unwrap();
    assert!(st.success());
    let e = Scene::load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("not a regular file") && e.contains("0000_Plane.glb"),
        "{e}"
    );
    // The CLI too, with a timeout standing in for "does not hang".
    let mut child = bin()
        .args(["inspect", dir.to_str().unwrap()])
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    loop {
        if let Some(st) = child.try_wait().unwrap() {
            assert!(!st.success());
            break;
        }
        if start.elapsed().as_secs() > 20 {
            child.kill().unwrap();
            panic!("inspect hangs on a FIFO mesh file");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

#[test]
fn scene_json_that_is_a_fifo_is_an_error() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path().join("scene");
    std::fs::create_dir(&dir).unwrap();
    let st = std::process::Command::new("mkfifo")
        .arg(dir.join("scene.json"))
        .status()
        .unwrap();
    assert!(st.success());
    let e = Scene::load(&dir).unwrap_err().to_string();
    assert!(e.contains("not a regular file"), "{e}");
}

// --- Colour management: nothing read outside the config's folder, nothing echoed -------

fn write_config(dir: &Path, body: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let p = dir.join("config.ocio");
    std::fs::write(&p, body).unwrap();
    p
}

const MINIMAL_CONFIG: &str = "ocio_profile_version: 2\nroles:\n  default: Linear\ncolorspaces:\n  - !<ColorSpace>\n    name: Linear\n";

#[test]
fn color_config_search_path_outside_its_folder_is_an_error() {
    use blendsynth::color::config::Config;
    let t = tempfile::tempdir().unwrap();
    let ok = write_config(
        &t.path().join("a"),
        &format!("search_path: luts\n{MINIMAL_CONFIG}"),
    );
    Config::load(&ok).unwrap();
    for sp in ["/etc", "../..", "luts:../../..", "luts/../../x"] {
        let p = write_config(
            &t.path().join("b"),
            &format!("search_path: \"{sp}\"\n{MINIMAL_CONFIG}"),
        );
        let e = Config::load(&p)
            .err()
            .unwrap_or_else(|| panic!("{sp} accepted"));
        let e = e.to_string();
        assert!(e.contains("search_path"), "{sp}: {e}");
    }
}

#[test]
fn lut_paths_outside_the_config_folder_are_errors() {
    use blendsynth::color::config::Config;
    let t = tempfile::tempdir().unwrap();
    let p = write_config(
        &t.path().join("c"),
        &format!("search_path: luts\n{MINIMAL_CONFIG}"),
    );
    std::fs::write(t.path().join("outside.spi1d"), "Version 1\n").unwrap();
    let cfg = Config::load(&p).unwrap();
    for name in ["/etc/passwd", "../outside.spi1d", "../../outside.spi1d"] {
        assert!(cfg.find_file(name).is_err(), "{name} was looked up");
    }
    std::fs::create_dir_all(t.path().join("c/luts")).unwrap();
    std::fs::write(t.path().join("c/luts/in.spi1d"), "Version 1\n").unwrap();
    assert!(cfg.find_file("in.spi1d").unwrap().is_some());
}

#[test]
fn color_errors_never_echo_file_content() {
    use blendsynth::color::config::Config;
    let t = tempfile::tempdir().unwrap();
    let p = write_config(t.path(), "SECRET-KEY-MATERIAL: [unclosed\n  - SECRET2 {\n");
    let e = Config::load(&p).unwrap_err().to_string();
    assert!(!e.contains("SECRET"), "{e}");
    let lut = t.path().join("x.spi1d");
    std::fs::write(&lut, "SECRETWORD here\n").unwrap();
    let e = blendsynth::color::lut::load(&lut).unwrap_err().to_string();
    assert!(!e.contains("SECRET"), "{e}");
    std::fs::write(&lut, "Version 1\nLength 2\n{\n SECRETNUMBER\n}\n").unwrap();
    let e = blendsynth::color::lut::load(&lut).unwrap_err().to_string();
    assert!(!e.contains("SECRET"), "{e}");
    let cube = t.path().join("x.cube");
    std::fs::write(&cube, "LUT_3D_SIZE 4000000\n").unwrap();
    let e = blendsynth::color::lut::load(&cube).unwrap_err().to_string();
    assert!(e.contains("limit"), "{e}");
}

// --- Command-line values and scene settings: errors naming them, checked up front ----

const RENDER_SCENE: &str = "fixtures/render/scenes/diffuse_point";

fn render_scene() -> String {
    repo().join(RENDER_SCENE).to_string_lossy().into_owned()
}

/// `render` with `extra` arguments into a fresh folder; must fail cleanly mentioning
/// every string in `must`, and write nothing.
fn render_fails(extra: &[&str], must: &[&str]) {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("x.png");
    let scene = render_scene();
    let mut args = vec!["render", &scene, "-o", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    let o = run(&args, &[]);
    assert_clean_error(&o, 1, must);
    assert!(!out.exists(), "{extra:?} wrote an image");
}

#[test]
fn render_resolution_16384_squared_is_an_error_before_allocating() {
    render_fails(&["--resolution", "16384x16384"], &["16384x16384", "limit"]);
}

#[test]
fn render_threads_beyond_the_cap_and_zero_are_errors() {
    render_fails(
        &["--threads", "100000", "--resolution", "8x8"],
        &["--threads"],
    );
    render_fails(&["--threads", "0", "--resolution", "8x8"], &["--threads"]);
}

#[test]
fn render_threshold_nan_and_inf_are_errors() {
    for t in ["NaN", "inf", "-inf", "-1"] {
        let arg = format!("--threshold={t}");
        render_fails(&[&arg, "--resolution", "8x8"], &["--threshold"]);
    }
}

#[test]
fn scene_resolution_zero_percent_and_zero_samples_are_errors_naming_the_setting() {
    let cases = [
        ("scenes[\"Scene\"].render.resolution_x=0", "resolution_x"),
        (
            "scenes[\"Scene\"].render.resolution_percentage=0",
            "resolution_percentage",
        ),
        ("scenes[\"Scene\"].cycles.samples=0", "samples"),
        ("scenes[\"Scene\"].cycles.samples=-3", "samples"),
    ];
    for (set, name) in cases {
        render_fails(&["--set", set], &[name]);
    }
    // --samples 0 names the option.
    render_fails(&["--samples", "0", "--resolution", "8x8"], &["--samples"]);
}

#[test]
fn mesh_of_an_object_without_geometry_is_an_error() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("cam.glb");
    let dir = repo().join("fixtures/scenes/geonodes");
    let o = run(
        &[
            "mesh",
            dir.to_str().unwrap(),
            "--object",
            "Camera",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["Camera", "not a geometry object"]);
    assert!(!out.exists());
}

#[test]
fn huge_grid_and_subdivide_level_through_set_are_errors_naming_the_node() {
    let dir = repo().join("fixtures/scenes/geonodes");
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("t.glb");
    let node = |n: &str, i: &str, v: &str| {
        format!("node_groups[\"Terrain Builder\"].nodes[\"{n}\"].inputs[\"{i}\"].default_value={v}")
    };
    let cases = [
        (
            vec![
                node("Grid", "Vertices X", "100000"),
                node("Grid", "Vertices Y", "100000"),
            ],
            "Grid",
        ),
        (
            vec![node("Subdivide Mesh", "Level", "30")],
            "Subdivide Mesh",
        ),
    ];
    for (sets, name) in cases {
        let mut args = vec![
            "mesh",
            dir.to_str().unwrap(),
            "--object",
            "Terrain",
            "-o",
            out.to_str().unwrap(),
        ];
        for s in &sets {
            args.push("--set");
            args.push(s);
        }
        let o = run(&args, &[]);
        assert_clean_error(&o, 1, &[name, "limit"]);
        assert!(!out.exists());
    }
}

#[test]
fn render_passes_to_an_unwritable_folder_fails_before_rendering() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("x.png");
    // A regular file where the passes folder should go: nothing can be created in it.
    let blocker = t.path().join("blocker");
    std::fs::write(&blocker, b"").unwrap();
    let passes = blocker.join("passes");
    let o = run(
        &[
            "render",
            &render_scene(),
            "--resolution",
            "8x8",
            "--samples",
            "1",
            "--passes",
            passes.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert_clean_error(&o, 1, &["--passes"]);
    assert!(
        !out.exists(),
        "the image was written before the passes failed"
    );
}

#[test]
fn png_output_has_normal_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("x.png");
    let o = run(
        &[
            "render",
            &render_scene(),
            "--resolution",
            "8x8",
            "--samples",
            "1",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let umask = std::process::Command::new("sh")
        .args(["-c", "umask"])
        .output()
        .unwrap();
    let umask = u32::from_str_radix(String::from_utf8_lossy(&umask.stdout).trim(), 8).unwrap();
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o666 & !umask, "mode {mode:o}, umask {umask:o}");
}

// --- Strict types for socket values ----------------------------------------------------

#[test]
fn a_float_socket_holding_a_string_or_null_is_an_error_naming_the_field() {
    for bad in [Value::from("0.5"), Value::Null] {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("scene");
        copy_dir(&repo().join(FIXTURE), &dir);
        let p = dir.join("scene.json");
        let mut v: Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
        let mut hit = None;
        'outer: for (mi, m) in v["materials"]
            .as_array_mut()
            .unwrap()
            .iter_mut()
            .enumerate()
        {
            let Some(nodes) = m["node_tree"]["nodes"].as_array_mut() else {
                continue;
            };
            for (ni, n) in nodes.iter_mut().enumerate() {
                for (si, s) in n["inputs"].as_array_mut().unwrap().iter_mut().enumerate() {
                    if s["type"] == "VALUE" {
                        s["default_value"] = bad.clone();
                        hit = Some(format!(
                            "materials[{mi}].node_tree.nodes[{ni}] ({:?}).inputs[{si}]",
                            n["name"].as_str().unwrap()
                        ));
                        break 'outer;
                    }
                }
            }
        }
        let hit = hit.expect("the fixture has a float socket");
        std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
        let e = Scene::load(&dir).unwrap_err().to_string();
        assert!(
            e.contains(&hit) && e.contains("default_value"),
            "{hit}: {e}"
        );
        assert!(e.contains("must be a number"), "{e}");
    }
}

#[test]
fn bake_size_beyond_the_limits_is_an_error_before_allocating() {
    let t = tempfile::tempdir().unwrap();
    let out = t.path().join("b.exr");
    for size in ["100000", "0", "16384"] {
        let o = run(
            &[
                "bake",
                &render_scene(),
                "--object",
                "Cube",
                "--size",
                size,
                "-o",
                out.to_str().unwrap(),
            ],
            &[],
        );
        assert_clean_error(&o, 1, &["--size"]);
        assert!(!out.exists());
    }
}

/// A smoke domain's grid file that lies about its size, or a grid path leaving the
/// scene folder: a one-line error naming the file, before anything is allocated from it.
#[test]
fn hostile_smoke_grids_are_clean_errors() {
    let src = repo().join("fixtures/render/scenes/smoke_grid_gradient");
    let render = |dir: &Path| {
        let out = dir.join("out.exr");
        run(
            &[
                "render",
                dir.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--samples",
                "1",
                "--resolution",
                "8x8",
            ],
            &[],
        )
    };
    // A header declaring a huge resolution over a small file.
    let t = tempfile::tempdir().unwrap();
    copy_dir(&src, t.path());
    let grid = t.path().join("volumes/0001_Domain_density.grid");
    let mut b = std::fs::read(&grid).unwrap();
    for at in [12, 16, 20] {
        b[at..at + 4].copy_from_slice(&60000u32.to_le_bytes());
    }
    std::fs::write(&grid, &b).unwrap();
    let o = render(t.path());
    assert_clean_error(&o, 1, &["Domain", "0001_Domain_density.grid", "density"]);
    // A file cut short.
    let t = tempfile::tempdir().unwrap();
    copy_dir(&src, t.path());
    let grid = t.path().join("volumes/0001_Domain_color.grid");
    let b = std::fs::read(&grid).unwrap();
    std::fs::write(&grid, &b[..b.len() - 3]).unwrap();
    assert_clean_error(&render(t.path()), 1, &["0001_Domain_color.grid", "bytes"]);
    // A grid path out of the scene folder.
    let t = tempfile::tempdir().unwrap();
    copy_dir(&src, t.path());
    let json = t.path().join("scene.json");
    let mut j: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    j["smoke_domains"][0]["grids"][0]["file"] = "../../etc/passwd".into();
    std::fs::write(&json, serde_json::to_vec(&j).unwrap()).unwrap();
    assert_clean_error(
        &render(t.path()),
        1,
        &["smoke_domains[0].grids[0].file", ".."],
    );
}
