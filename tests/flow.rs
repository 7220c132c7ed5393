//! Optical flow and occlusion (issue 29) against Cycles' Vector and Object Index passes
//! of the fixtures in fixtures/ground_truth/flow/ (authored by make_flow_refs.py with
//! bpy 4.5.4 at 64x48, frame 2, motion blur off).
//!
//! Cycles' Vector pass (kernel/geom/primitive.h, primitive_motion_vector) holds, in its
//! raster space (y up), xy = raster(previous) - raster(now) and zw = raster(now) -
//! raster(next): with y down, backward flow is (X, -Y) and forward flow (-Z, W).

mod common;
use common::exr_channels;

use blendsynth::render::{film::flow::Motion, render_with_motion, RenderOptions, RenderOutput};
use blendsynth::scene::Scene;

fn fixture(p: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/ground_truth/flow")
        .join(p)
}

fn render(name: &str, w: usize, h: usize) -> (RenderOutput, Motion) {
    let scene = Scene::load(&fixture(&format!("{name}/scene"))).unwrap();
    let opts = RenderOptions {
        frame: Some(2.0),
        samples: Some(1),
        threshold: None,
        resolution: Some((w as u32, h as u32)),
        seed: Some(0),
        threads: Some(1),
        progress: false,
    };
    render_with_motion(&scene, &opts, &[], None, 1.0).unwrap()
}

/// Pixels whose 3x3 neighbourhood shows one instance (Cycles' samples jitter by 0.005
/// px, so a pixel on a silhouette may see another surface there).
fn interior(ids: &[u32], w: usize, h: usize) -> Vec<bool> {
    let mut out = vec![false; w * h];
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let id = ids[y * w + x];
            out[y * w + x] =
                id != 0 && (0..9).all(|k| ids[(y + k / 3 - 1) * w + x + k % 3 - 1] == id);
        }
    }
    out
}

struct Figures {
    pixels: usize,
    mean: f64,
    worst_1pct: f64,
    worst: f64,
}

fn figures(mut epe: Vec<f64>) -> Figures {
    epe.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let n = epe.len();
    let top = (n / 100).max(1);
    Figures {
        pixels: n,
        mean: epe.iter().sum::<f64>() / n as f64,
        worst_1pct: epe[n - top..].iter().sum::<f64>() / top as f64,
        worst: epe[n - 1],
    }
}

/// Compares forward and backward flow with Cycles' Vector pass; returns the per-direction
/// figures over the interior pixels with valid flow. `skip` names objects left out.
fn compare(name: &str, skip: &[&str]) -> (Figures, Figures) {
    let reference = fixture(&format!("{name}/passes.exr"));
    let (w, h, ch) = exr_channels(&reference);
    let v = |c: &str| &ch[&format!("ViewLayer.Vector.{c}")];
    let (vx, vy, vz, vw) = (v("X"), v("Y"), v("Z"), v("W"));
    let (out, motion) = render(name, w, h);
    let p = &out.passes;
    let inside = interior(&p.instance_id, w, h);
    let (mut fw, mut bw) = (Vec::new(), Vec::new());
    for i in 0..w * h {
        if p.instance_id[i] == 0 {
            assert!(
                motion.forward.flow[i][0].is_nan(),
                "{name}: background pixel {i}"
            );
            continue;
        }
        let object = &p.instances[p.instance_id[i] as usize - 1].object;
        if !inside[i] || skip.contains(&object.as_str()) {
            continue;
        }
        let (f, b) = (motion.forward.flow[i], motion.backward.flow[i]);
        assert!(
            f[0].is_finite() && b[0].is_finite(),
            "{name}: pixel ({}, {}) on {object}: flow {f:?} / {b:?} invalid",
            i % w,
            i / w
        );
        let cf = [-vz[i], vw[i]];
        let cb = [vx[i], -vy[i]];
        let d = |a: [f32; 2], c: [f32; 2]| {
            ((a[0] as f64 - c[0] as f64).powi(2) + (a[1] as f64 - c[1] as f64).powi(2)).sqrt()
        };
        fw.push(d(f, cf));
        bw.push(d(b, cb));
    }
    assert!(fw.len() > w * h / 40, "{name}: only {} pixels", fw.len());
    let (f, b) = (figures(fw), figures(bw));
    for (dir, x) in [("forward", &f), ("backward", &b)] {
        eprintln!(
            "{name} {dir}: {} pixels, mean end-point difference to Cycles' Vector pass {:.2e} px, worst 1% {:.2e} px, worst {:.2e} px",
            x.pixels, x.mean, x.worst_1pct, x.worst
        );
    }
    (f, b)
}

/// Mean below 0.01 px (the target) and every pixel within `worst` px.
fn check(name: &str, skip: &[&str], worst: f64) {
    let (f, b) = compare(name, skip);
    for x in [&f, &b] {
        assert!(
            x.mean < 0.01,
            "{name}: mean end-point difference {}",
            x.mean
        );
        assert!(
            x.worst < worst,
            "{name}: worst end-point difference {}",
            x.worst
        );
    }
}

/// Median |second difference along x| of a flow's x component over pixels whose row
/// neighbours show the same instance (a rigid body's flow is smooth across its faces).
fn roughness(flow: &[f32], ids: &[u32], id: u32, w: usize) -> f64 {
    let mut d: Vec<f64> = (1..flow.len() - 1)
        .filter(|&i| i % w != 0 && i % w != w - 1 && (i - 1..=i + 1).all(|k| ids[k] == id))
        .map(|i| (flow[i + 1] as f64 - 2.0 * flow[i] as f64 + flow[i - 1] as f64).abs())
        .collect();
    d.sort_by(|a, b| a.partial_cmp(b).unwrap());
    d[d.len() / 2]
}

#[test]
fn camera_motion_flow_matches_cycles_vector_pass() {
    check("camera", &[], 0.05);
}

/// The box turns and scales between frames. There Cycles' Vector pass is rough: its
/// flow changes by up to 0.1 px from one pixel to the next more than a rigid body's
/// smooth flow can (median |second difference| 7x ours, asserted below), while every
/// sample sits 0.0005 px from the pixel centre (ground_truth.rs). So the worst pixels
/// (up to 0.11 px) are that roughness; the mean stays below 0.01 px. Not explained.
#[test]
fn object_motion_flow_matches_cycles_vector_pass() {
    check("object", &[], 0.15);
    let (r_ours, r_cycles) = box_roughness("object");
    assert!(r_cycles > 3.0 * r_ours, "{r_ours} {r_cycles}");
}

/// The median |second difference along x| of the box's forward flow x in scene `name`:
/// (ours, Cycles' Vector pass).
fn box_roughness(name: &str) -> (f64, f64) {
    let (w, h, ch) = exr_channels(&fixture(&format!("{name}/passes.exr")));
    let (out, motion) = render(name, w, h);
    let p = &out.passes;
    let boxed = p.instances.iter().position(|i| i.object == "Box").unwrap() as u32 + 1;
    let ours: Vec<f32> = motion.forward.flow.iter().map(|f| f[0]).collect();
    let cycles: Vec<f32> = ch["ViewLayer.Vector.Z"].iter().map(|z| -z).collect();
    let (r_ours, r_cycles) = (
        roughness(&ours, &p.instance_id, boxed, w),
        roughness(&cycles, &p.instance_id, boxed, w),
    );
    eprintln!(
        "{name}: box, median |second difference| of flow x: ours {r_ours:.4} px, Cycles' {r_cycles:.4} px"
    );
    (r_ours, r_cycles)
}

/// Panoramic cameras: Cycles' Vector pass maps through direction_to_panorama, times the
/// image size; a moving, turning camera and a moving ball (make_flow_refs.py). The flow
/// is large here (up to 6 px at 64x48) and Cycles' pass is rough again: on the box its
/// median |second difference| is 2.3 to 4.3 times ours (more than twice, asserted below), as in the object
/// scene, so the worst pixels (up to 0.09 px) are that roughness; the mean stays below
/// 0.01 px.
fn check_panoramic(name: &str) {
    check(name, &[], 0.1);
    let (r_ours, r_cycles) = box_roughness(name);
    assert!(r_cycles > 2.0 * r_ours, "{r_ours} {r_cycles}");
}

#[test]
fn fisheye_equidistant_flow_matches_cycles_vector_pass() {
    check_panoramic("fisheye_equidistant");
}

#[test]
fn fisheye_equisolid_flow_matches_cycles_vector_pass() {
    check_panoramic("fisheye_equisolid");
}

#[test]
fn equirectangular_flow_matches_cycles_vector_pass() {
    check_panoramic("equirectangular");
}

#[test]
fn geometry_nodes_deformation_flow_matches_cycles_vector_pass() {
    check("deform", &["Growing"], 0.05);
}

/// The "Growing" grid changes its vertex count every frame: its flow is invalid in both
/// directions (NaN) and never called occluded; the deforming grid's is valid.
#[test]
fn flow_is_invalid_where_topology_changes() {
    let (out, motion) = render("deform", 64, 48);
    let p = &out.passes;
    let (mut growing, mut wave) = (0, 0);
    for i in 0..p.instance_id.len() {
        if p.instance_id[i] == 0 {
            continue;
        }
        let object = &p.instances[p.instance_id[i] as usize - 1].object;
        let valid = [&motion.forward, &motion.backward].map(|d| d.flow[i][0].is_finite());
        match object.as_str() {
            "Growing" => {
                growing += 1;
                assert_eq!(valid, [false, false], "pixel {i}");
                assert!(!motion.forward.occluded[i] && !motion.backward.occluded[i]);
            }
            "Wave" => {
                wave += 1;
                assert_eq!(valid, [true, true], "pixel {i}");
            }
            _ => {}
        }
    }
    assert!(growing > 4 && wave > 100, "growing {growing}, wave {wave}");
}

/// A box passes in front of a wall seen by a still camera: a wall pixel is occluded
/// forward exactly where Blender's Object Index pass shows the box at frame 3 (the wall
/// and camera stand still, so its flow is zero), backward where it shows it at frame 1.
/// Pixels on an Object Index boundary at either frame are left out (Cycles' samples
/// jitter by 0.005 px).
#[test]
fn occlusion_matches_blenders_object_index_at_the_other_frames() {
    let (w, h, now) = exr_channels(&fixture("occlusion/passes.exr"));
    let index = |f: u32| {
        let (_, _, ch) = exr_channels(&fixture(&format!("occlusion/index_{f}.exr")));
        ch["ViewLayer.IndexOB.X"].clone()
    };
    let ids_of = |v: &[f32]| v.iter().map(|&x| x.round() as u32).collect::<Vec<u32>>();
    let now = ids_of(&now["ViewLayer.IndexOB.X"]);
    let (prev, next) = (ids_of(&index(1)), ids_of(&index(3)));
    let (out, motion) = render("occlusion", w, h);
    let p = &out.passes;
    let clear = |ids: &[u32], i: usize| {
        let (x, y) = (i % w, i / w);
        x > 0
            && y > 0
            && x + 1 < w
            && y + 1 < h
            && (0..9).all(|k| ids[(y + k / 3 - 1) * w + x + k % 3 - 1] == ids[i])
    };
    let mut counts = [[0usize; 2]; 2];
    for i in 0..w * h {
        // Wall pixels for both renderers (a silhouette pixel may differ).
        if p.instance_id[i] == 0
            || now[i] != 1
            || p.instances[p.instance_id[i] as usize - 1].object != "Wall"
        {
            continue;
        }
        for (d, (field, other)) in [(&motion.forward, &next), (&motion.backward, &prev)]
            .into_iter()
            .enumerate()
        {
            assert_eq!(field.flow[i], [0.0, 0.0], "wall pixel {i}: flow");
            if !clear(&now, i) || !clear(other, i) {
                continue;
            }
            let expected = other[i] == 2;
            assert_eq!(
                field.occluded[i],
                expected,
                "wall pixel ({}, {}), {}",
                i % w,
                i / w,
                ["forward", "backward"][d]
            );
            counts[d][expected as usize] += 1;
        }
    }
    eprintln!(
        "wall pixels [visible, occluded]: forward {:?}, backward {:?}",
        counts[0], counts[1]
    );
    for c in counts {
        assert!(c[0] > 100 && c[1] > 20, "{counts:?}");
    }
    // The box is in front of everything: its pixels are occluded only where it leaves
    // the image or turns a face away from the camera (self-occlusion).
    let (fw, bw) = (&motion.forward, &motion.backward);
    let box_px: Vec<usize> = (0..w * h)
        .filter(|&i| now[i] == 2 && p.instance_id[i] != 0)
        .collect();
    let visible = box_px
        .iter()
        .filter(|&&i| !fw.occluded[i] && !bw.occluded[i])
        .count();
    assert!(
        visible * 10 > box_px.len() * 8,
        "{visible} of {}",
        box_px.len()
    );
    // The box turns here too (see object_motion_flow_matches_cycles_vector_pass).
    check("occlusion", &[], 0.5);
}

/// The Middlebury file: header, then (u, v) pairs, 1e10 for unknown flow.
#[test]
fn flo_file_layout() {
    let b = blendsynth::render::film::flow::flo_bytes(2, 1, &[[1.5, -2.0], [f32::NAN, f32::NAN]]);
    assert_eq!(&b[..4], b"PIEH");
    assert_eq!(u32::from_le_bytes(b[4..8].try_into().unwrap()), 2);
    assert_eq!(u32::from_le_bytes(b[8..12].try_into().unwrap()), 1);
    let f = |k: usize| f32::from_le_bytes(b[12 + 4 * k..16 + 4 * k].try_into().unwrap());
    assert_eq!([f(0), f(1), f(2), f(3)], [1.5, -2.0, 1e10, 1e10]);
    assert_eq!(b.len(), 12 + 16);
}

/// A dataset of the occlusion fixture: two sequences of two frames (scene frames 2, 3
/// each) with flow (EXR and .flo), occlusion and the scene mesh per sequence; the files
/// hold what `render_with_motion` gives, the glb holds the geometry the renderer traced,
/// and two shards merged give the same bytes as one run.
#[test]
fn dataset_writes_flow_occlusion_and_scene_mesh() {
    use blendsynth::dataset::{generate, merge, renderer::path_tracer, GenerateOptions, Spec};
    let spec = Spec::parse(
        "[render]\nresolution = [64, 48]\nsamples = 1\ndenoise = false\n\
         [frames]\nstart = 2\nstep = 0\n\
         [sequence]\nlength = 2\nstep = 1\n\
         [labels]\nflow = true\nflow_flo = true\nocclusion = true\nmesh_glb = \"sequence\"\n",
    )
    .unwrap();
    let scene = Scene::load(&fixture("occlusion/scene")).unwrap();
    let r = path_tracer(&scene).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let run = |out: &std::path::Path, shard: (u64, u64)| {
        let opts = GenerateOptions {
            frames: 4,
            shard,
            ..GenerateOptions::default()
        };
        generate(&scene, &spec, r.as_ref(), out, &opts).unwrap();
    };
    let one = tmp.path().join("one");
    run(&one, (0, 1));
    let (_, motion) = render("occlusion", 64, 48);
    let name = |k: &str, ext: &str| one.join(format!("{k}/train/000000000.{ext}"));
    let (w, h, fw) = exr_channels(&name("flow_fw", "exr"));
    assert_eq!((w, h), (64, 48));
    let (_, _, bw) = exr_channels(&name("flow_bw", "exr"));
    let flo = std::fs::read(name("flow_fw", "flo")).unwrap();
    assert_eq!(flo.len(), 12 + 64 * 48 * 8);
    let mask = image::open(name("occlusion_fw", "png"))
        .unwrap()
        .into_luma8();
    let same = |a: f32, b: f32| a == b || (a.is_nan() && b.is_nan());
    for i in 0..w * h {
        assert!(same(fw["R"][i], motion.forward.flow[i][0]), "pixel {i}");
        assert!(same(fw["G"][i], motion.forward.flow[i][1]), "pixel {i}");
        assert!(same(bw["R"][i], motion.backward.flow[i][0]), "pixel {i}");
        let u = f32::from_le_bytes(flo[12 + 8 * i..16 + 8 * i].try_into().unwrap());
        let want = motion.forward.flow[i][0];
        assert_eq!(u, if want.is_nan() { 1e10 } else { want });
        assert_eq!(mask.as_raw()[i] == 255, motion.forward.occluded[i]);
    }
    // The scene mesh of each sequence's first frame only.
    assert!(name("meshes", "glb").exists());
    assert!(!one.join("meshes/train/000000001.glb").exists());
    assert!(one.join("meshes/train/000000002.glb").exists());
    check_scene_mesh(&name("meshes", "glb"));
    // Two shards merged: the same bytes.
    let (a, b, merged) = (
        tmp.path().join("a"),
        tmp.path().join("b"),
        tmp.path().join("m"),
    );
    run(&a, (0, 2));
    run(&b, (1, 2));
    merge(&[a, b], &merged).unwrap();
    for f in [
        "flow_fw/train/000000001.exr",
        "flow_bw/train/000000003.flo",
        "occlusion_bw/train/000000002.png",
        "meshes/train/000000002.glb",
    ] {
        assert_eq!(
            std::fs::read(one.join(f)).unwrap(),
            std::fs::read(merged.join(f)).unwrap(),
            "{f}"
        );
    }
}

/// The glb read back (the exporter's reader) holds the renderer's geometry: each pixel's
/// primary hit, placed by its barycentrics on the glb's triangle of that instance, has
/// the depth the renderer's depth pass gives it.
fn check_scene_mesh(path: &std::path::Path) {
    let m = blendsynth::scene::mesh::read_glb(path).unwrap();
    let ids = m
        .attributes
        .iter()
        .find(|a| a.name == "instance_id")
        .expect("instance_id face attribute");
    let blendsynth::scene::AttributeData::Int(ids) = &ids.data else {
        panic!("instance_id is not an int attribute")
    };
    // Faces are the renderer's triangles, instance after instance, in mesh order.
    let first: std::collections::HashMap<i32, usize> = ids
        .iter()
        .enumerate()
        .rev()
        .map(|(f, &id)| (id, f))
        .collect();
    let (out, _) = render("occlusion", 64, 48);
    let scene = Scene::load(&fixture("occlusion/scene")).unwrap();
    let eval = blendsynth::anim::evaluate_scene(&scene, 2.0).unwrap();
    let cam = blendsynth::render::camera::Camera::new(&scene, &eval, 64, 48).unwrap();
    let mut worst = 0.0f64;
    let mut n = 0;
    for (i, hit) in out.passes.hits.iter().enumerate() {
        let Some(hit) = hit else { continue };
        let face = first[&(hit.inst as i32 + 1)] + hit.tri as usize;
        let c = &m.face_offsets;
        let v: Vec<[f32; 3]> = (c[face]..c[face + 1])
            .map(|k| m.positions[m.corner_verts[k as usize] as usize])
            .collect();
        assert_eq!(v.len(), 3);
        let w0 = 1.0 - hit.u - hit.v;
        let p: [f32; 3] = std::array::from_fn(|k| v[0][k] * w0 + v[1][k] * hit.u + v[2][k] * hit.v);
        let z = out.passes.depth[i] as f64;
        worst = worst.max((cam.depth(p) as f64 - z).abs() / z);
        n += 1;
    }
    assert!(n > 1000 && worst < 1e-6, "{n} pixels, worst {worst:.2e}");
    eprintln!(
        "scene glb: {n} pixel hits on its triangles, worst relative depth difference {worst:.1e}"
    );
}
