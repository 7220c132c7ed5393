//! Labels: COCO RLE against pycocotools' own encoding (fixtures/label/rle_reference.*),
//! camera intrinsics and pose against Blender's projection
//! (fixtures/label/camera_reference.*), masks, boxes and the drop rule.

mod common;

use blendsynth::label::{extract, rle, ClassMap, FrameIds, Instance, LabelSpec};
use blendsynth::scene::{Override, Scene};
use serde_json::Value;

fn load(p: &str) -> Value {
    serde_json::from_slice(&std::fs::read(common::repo().join(p)).unwrap()).unwrap()
}

#[test]
fn rle_matches_pycocotools() {
    let r = load("fixtures/label/rle_reference.json");
    let cases = r["cases"].as_array().unwrap();
    assert!(cases.len() >= 8);
    for c in cases {
        let name = c["name"].as_str().unwrap();
        let (h, w) = (
            c["height"].as_u64().unwrap() as u32,
            c["width"].as_u64().unwrap() as u32,
        );
        let rows: Vec<Vec<u8>> = c["rows"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_str().unwrap().bytes().collect())
            .collect();
        let mask = |p: usize| rows[p / w as usize][p % w as usize] == b'1';
        let counts = rle::counts(w, h, mask);
        assert_eq!(
            rle::to_string(&counts),
            c["counts"].as_str().unwrap(),
            "{name}: compressed RLE"
        );
        assert_eq!(
            rle::from_string(c["counts"].as_str().unwrap()).unwrap(),
            counts,
            "{name}: decode"
        );
        let (area, bbox) = rle::area_bbox(h, &counts);
        assert_eq!(area, c["area"].as_u64().unwrap(), "{name}: area");
        let want: Vec<u32> = c["bbox"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as u32)
            .collect();
        assert_eq!(bbox.to_vec(), want, "{name}: bbox");
    }
}

fn laparoscopy() -> Scene {
    Scene::load(&common::repo().join("assets/doi-23843904/laparoscopy")).unwrap()
}

#[test]
fn camera_projection_matches_blender() {
    let r = load("fixtures/label/camera_reference.json");
    let base = laparoscopy();
    let cam = r["camera"].as_str().unwrap();
    for c in r["cases"].as_array().unwrap() {
        let res: Vec<u32> = c["resolution"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as u32)
            .collect();
        let shift = c["shift"].as_array().unwrap();
        let sets = [
            format!(
                "cameras[\"{cam}\"].sensor_fit={}",
                c["sensor_fit"].as_str().unwrap()
            ),
            format!("cameras[\"{cam}\"].shift_x={}", shift[0]),
            format!("cameras[\"{cam}\"].shift_y={}", shift[1]),
            format!("cameras[\"{cam}\"].lens={}", c["lens"]),
        ];
        let ov: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = base.with_overrides(&ov).unwrap();
        let info =
            blendsynth::dataset::generate::scene_camera(&scene, 1.0, res[0], res[1]).unwrap();
        let m = info.matrix_world;
        for (p, want) in c["points"]
            .as_array()
            .unwrap()
            .iter()
            .zip(c["pixels"].as_array().unwrap())
        {
            let p: Vec<f64> = p
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            // World to camera: transpose of the rotation (the camera has no scale).
            let d: Vec<f64> = (0..3).map(|k| p[k] - m[k][3]).collect();
            let cam_p: Vec<f64> = (0..3)
                .map(|c| (0..3).map(|r| m[r][c] * d[r]).sum())
                .collect();
            let z = -cam_p[2];
            let (x, y) = (
                info.cx + info.fx * cam_p[0] / z,
                info.cy - info.fy * cam_p[1] / z,
            );
            let w: Vec<f64> = want
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert!(
                (x - w[0]).abs() < 1e-3 && (y - w[1]).abs() < 1e-3 && (z - w[2]).abs() < 1e-5,
                "{c}: got ({x}, {y}, {z}), Blender {w:?}"
            );
        }
    }
}

fn inst(name: &str) -> Instance {
    Instance {
        object: name.into(),
        instance_index: None,
        world_bounds: ([0.0; 3], [1.0; 3]),
        world_transform: [[0.0; 4]; 4],
    }
}

#[test]
fn boxes_masks_and_drop_rule() {
    let scene = laparoscopy();
    let spec = LabelSpec::from_toml(&toml::from_str::<toml::Value>("min_pixels = 4\n[[class]]\nname = \"liver\"\n[[class]]\nname = \"gallbladder\"\nmask = false\n").unwrap()).unwrap();
    let classes = ClassMap::new(&spec, &scene);
    assert_eq!(classes.names, vec!["liver", "gallbladder"]);
    // 8x6 frame: the liver (id 1) partly hidden by the gallbladder (id 2); a bowel loop
    // (no class, id 3); a second liver instance with 3 pixels (dropped: < 4); a fully
    // hidden gallbladder instance (id 5: no pixels).
    #[rustfmt::skip]
    let ids = vec![
        0, 1, 1, 1, 1, 0, 0, 3,
        0, 1, 2, 2, 1, 1, 0, 3,
        0, 1, 2, 2, 1, 1, 0, 0,
        0, 0, 1, 1, 1, 0, 0, 0,
        4, 4, 0, 0, 0, 0, 0, 0,
        4, 0, 0, 0, 0, 0, 0, 0u32,
    ];
    let frame = FrameIds {
        width: 8,
        height: 6,
        instance_id: ids,
        depth: None,
        normal: None,
        instances: vec![
            inst("Liver"),
            inst("Gallbladder"),
            inst("Bowel.000"),
            inst("Liver"),
            inst("Gallbladder"),
        ],
        aov_channels: Vec::new(),
    };
    let labels = extract(&frame, &classes, 4).unwrap();
    assert_eq!(labels.len(), 2, "{labels:?}");
    assert_eq!(
        (
            labels[0].instance,
            labels[0].class,
            labels[0].area,
            labels[0].bbox
        ),
        (0, 0, 13, [1, 0, 5, 4])
    );
    assert_eq!(
        (
            labels[1].instance,
            labels[1].class,
            labels[1].area,
            labels[1].bbox
        ),
        (1, 1, 4, [2, 1, 2, 2])
    );
    assert!(labels[1].rle.is_none(), "gallbladder has mask = false");
    let counts = labels[0].rle.as_ref().unwrap();
    assert_eq!(rle::area_bbox(6, counts), (13, [1, 0, 5, 4]));
    let sem = blendsynth::label::instances::semantic(&frame, &labels);
    assert_eq!(&sem[8..16], &[0, 1, 2, 2, 1, 1, 0, 0]);
    assert_eq!(
        sem[32], 0,
        "the dropped instance is not in the semantic mask"
    );
    // Bad input is an error, not a panic.
    let mut bad = frame.clone();
    bad.instance_id[0] = 9;
    assert!(extract(&bad, &classes, 4)
        .unwrap_err()
        .contains("instance id 9"));
}

#[test]
fn classes_from_custom_property_and_patterns() {
    let scene = Scene::load(&common::repo().join("assets/doi-23843904/colonoscopy")).unwrap();
    let spec = LabelSpec::from_toml(
        &toml::from_str::<toml::Value>("[[class]]\nname = \"wall\"\nobjects = [\"Col*\"]\n")
            .unwrap(),
    )
    .unwrap();
    let c = ClassMap::new(&spec, &scene);
    assert_eq!(
        c.names,
        vec!["wall", "polyp"],
        "spec classes first, then property classes"
    );
    assert_eq!(c.class_of("Colon"), Some(0));
    assert_eq!(c.class_of("Polyp.stalked.001"), Some(1));
    assert_eq!(c.class_of("Camera"), None);
}

#[test]
fn yolo_lines_are_normalised_centres() {
    use blendsynth::label::record::Annotation;
    let a = Annotation {
        object: "P".into(),
        instance_index: None,
        class: "polyp".into(),
        category_id: 2,
        bbox: [10, 20, 30, 40],
        area: 1,
        rle: None,
        size: [0.0; 3],
        size_mm: [0.0; 3],
        largest_mm: 0.0,
        distance: 0.0,
        distance_mm: 0.0,
        nearest_depth: None,
    };
    assert_eq!(
        blendsynth::label::yolo::label_text(&[a], 100, 200),
        "1 0.250000 0.200000 0.300000 0.200000\n"
    );
}
