//! Geometric ground truth against Blender-made references (fixtures/ground_truth/,
//! authored by make_refs.py): camera intrinsics and OpenCV pose against Blender's own
//! projection, depth against Cycles' Z pass.

mod common;

use blendsynth::scene::{Override, Scene};
use serde_json::Value;

fn fixture(p: &str) -> std::path::PathBuf {
    common::repo().join("fixtures/ground_truth").join(p)
}

fn scene() -> Scene {
    Scene::load(&fixture("scene")).unwrap()
}

fn nums(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn k_and_opencv_pose_reproject_blenders_pixels() {
    let r: Value =
        serde_json::from_slice(&std::fs::read(fixture("projection.json")).unwrap()).unwrap();
    let base = scene();
    let cam = r["camera"].as_str().unwrap();
    let frame = r["frame"].as_f64().unwrap();
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 10);
    let mut worst = 0.0f64;
    for c in cases {
        let res = nums(&c["resolution"]);
        let aspect = nums(&c["pixel_aspect"]);
        let shift = nums(&c["shift"]);
        let kind = c["type"].as_str().unwrap();
        let mut sets = vec![
            format!("scenes[\"Scene\"].render.pixel_aspect_x={}", aspect[0]),
            format!("scenes[\"Scene\"].render.pixel_aspect_y={}", aspect[1]),
            format!(
                "cameras[\"{cam}\"].sensor_fit={}",
                c["sensor_fit"].as_str().unwrap()
            ),
            format!("cameras[\"{cam}\"].shift_x={}", shift[0]),
            format!("cameras[\"{cam}\"].shift_y={}", shift[1]),
            format!("cameras[\"{cam}\"].type={kind}"),
        ];
        if kind == "ORTHO" {
            sets.push(format!(
                "cameras[\"{cam}\"].ortho_scale={}",
                c["ortho_scale"]
            ));
        } else {
            sets.push(format!("cameras[\"{cam}\"].lens={}", c["lens"]));
        }
        let ov: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = base.with_overrides(&ov).unwrap();
        let info = blendsynth::dataset::generate::scene_camera(
            &scene,
            frame,
            res[0] as u32,
            res[1] as u32,
        )
        .unwrap();
        // K is the matrix form of fx, fy, cx, cy.
        assert_eq!(info.k[0], [info.fx, 0.0, info.cx]);
        assert_eq!(info.k[1], [0.0, info.fy, info.cy]);
        for (p, want) in c["points"]
            .as_array()
            .unwrap()
            .iter()
            .zip(c["pixels"].as_array().unwrap())
        {
            let p = nums(p);
            let w = nums(want);
            let (px, z) = info.project([p[0], p[1], p[2]]).unwrap();
            let err = (px[0] - w[0]).abs().max((px[1] - w[1]).abs());
            worst = worst.max(err);
            assert!(
                err < 1e-3 && (kind == "ORTHO" || (z - w[2]).abs() < 1e-5 * w[2].abs().max(1.0)),
                "{c}: point {p:?} at ({}, {}) depth {z}, Blender {w:?}",
                px[0],
                px[1]
            );
        }
    }
    eprintln!("worst reprojection difference {worst:.2e} px");
}
