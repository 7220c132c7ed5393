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
    while j.len() % 4 != 0 {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while b.len() % 4 != 0 {
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
