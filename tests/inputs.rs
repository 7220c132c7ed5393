//! Input nodes that read the shading context (Fresnel, Layer Weight, Geometry, Object
//! Info, Camera Data, Texture Coordinate's Camera/Window/Reflection/Object-relative,
//! Light Path, Light Falloff, Normal, Tangent) against Cycles' EMIT bake of the same
//! materials (fixtures/bake/make_input_refs.py): every texel, every channel.

mod common;
use common::*;

use blendsynth::scene::Scene;

/// Cycles and blendsynth run the same float maths on the same inputs.
const TOL: f32 = 1e-5;

/// Radial tangents around X and Y: near where the radial vector vanishes (Generated
/// y = z = 0.5 for X) the tangent is normalise(cross(t, N)) of a short t, so a 1e-7
/// difference in Generated (Cycles stores it per vertex in float; blendsynth derives it
/// from the interpolated position) is magnified; measured worst 2.8e-5 there.
const TANGENT_TOL: f32 = 5e-5;

fn tolerance(case: &str) -> f32 {
    if case == "tangent_radial_x" || case == "tangent_radial_y" {
        TANGENT_TOL
    } else {
        TOL
    }
}

fn check(results: &[(String, f32)]) {
    let bad: Vec<_> = results
        .iter()
        .filter(|(c, w)| !(*w <= tolerance(c)))
        .collect();
    assert!(bad.is_empty(), "cases over their tolerance: {bad:?}");
    assert!(results.len() >= 26, "every case ran");
}

#[test]
fn input_nodes_match_cycles_emit_bakes() {
    check(&common::bake_cases_worst(
        &repo().join("fixtures/bake/inputs"),
    ));
}

/// Blender-side: bake the cases afresh with Cycles and compare against those bakes.
#[test]
fn fresh_cycles_input_bakes_match() {
    let Some(py) = require("a Python with bpy 4.5.4", bpy_python()) else {
        return;
    };
    let t = tempfile::tempdir().unwrap();
    run_python(
        &py,
        &repo().join("fixtures/bake/make_input_refs.py"),
        &["--out", t.path().to_str().unwrap()],
    );
    check(&common::bake_cases_worst(t.path()));
}

/// View-dependent outputs (Fresnel, Layer Weight, Camera Data, Light Path Ray Length,
/// Incoming, Window, Reflection): blendsynth's camera render of emission-only
/// materials against Cycles' at a 0.01 px pixel filter
/// (fixtures/render_inputs/make_view_refs.py). Per pixel, excluding silhouette pixels
/// (any 3x3 neighbour sees another object or the background): there the 0.005 px
/// filter jitter of either renderer can cross an edge. Also excluded: the few pixels
/// where Cycles itself sampled off the pixel centre, found from its own Window render
/// (which depends on nothing but the sample position; same camera, seed and samples in
/// every case): where that differs from the exact centre by more than 1e-4
/// (measured: 6 of 1280 pixels, up to 3.7e-3, i.e. 0.12 px; median 2.4e-5).
/// The bound asserted is 1e-3, not the 1e-4 aimed for: measured worst 2.2e-4 (Layer
/// Weight), 1.1e-4 (Window), 6.9e-4 (Reflection on the 32-segment sphere). What is
/// left is where Cycles sampled: blendsynth's own Window render is within 2e-5 of
/// every pixel centre, Cycles' is off by up to 1e-4 (0.004 px) on the pixels kept, and
/// 0.004 px times Reflection's gradient on the sphere (about 0.3 per pixel) is 1e-3.
const VIEW_TOL: f32 = 1e-3;

#[test]
fn view_dependent_inputs_match_cycles_renders() {
    use blendsynth::render::{render, RenderOptions};
    let root = repo().join("fixtures/render_inputs");
    let mut failures = Vec::new();
    let probe: Vec<f32> = std::fs::read(root.join("window/cycles.f32"))
        .unwrap()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    for case in ["facing", "camera", "incoming", "window", "reflection"] {
        let dir = root.join(case);
        let meta: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("view.json")).unwrap()).unwrap();
        let (w, h) = (
            meta["width"].as_u64().unwrap() as usize,
            meta["height"].as_u64().unwrap() as usize,
        );
        let reference: Vec<f32> = std::fs::read(dir.join("cycles.f32"))
            .unwrap()
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let scene = Scene::load(&dir).unwrap();
        let opts = RenderOptions {
            samples: Some(meta["samples"].as_u64().unwrap() as u32),
            resolution: Some((w as u32, h as u32)),
            seed: Some(0),
            threads: Some(1),
            ..Default::default()
        };
        let out = render(&scene, &opts).unwrap_or_else(|e| panic!("{case}: {e}"));
        let ids = &out.passes.object_index;
        let (mut worst, mut at, mut compared) = (0.0f32, (0, 0, 0), 0);
        for y in 0..h {
            for x in 0..w {
                let id = ids[y * w + x];
                let edge = id == 0
                    || (-1..=1).any(|dy: i64| {
                        (-1..=1).any(|dx: i64| {
                            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                            nx >= 0
                                && ny >= 0
                                && (nx as usize) < w
                                && (ny as usize) < h
                                && ids[ny as usize * w + nx as usize] != id
                        })
                    });
                let centre = [
                    (x as f32 + 0.5) / w as f32,
                    1.0 - (y as f32 + 0.5) / h as f32,
                ];
                let off_centre =
                    (0..2).any(|k| (probe[(y * w + x) * 4 + k] - centre[k]).abs() > 1e-4);
                if edge || off_centre {
                    continue;
                }
                compared += 1;
                for c in 0..3 {
                    let d = (out.color[y * w + x][c] - reference[(y * w + x) * 4 + c]).abs();
                    if !(d <= worst) {
                        worst = if d.is_nan() { f32::INFINITY } else { d };
                        at = (x, y, c);
                    }
                }
            }
        }
        let (x, y, c) = at;
        eprintln!("render {case:12} {w}x{h}: {compared} interior pixels, worst abs error {worst:.2e} at ({x},{y}) channel {c}: ours {} Cycles {}", out.color[y * w + x][c], reference[(y * w + x) * 4 + c]);
        assert!(compared > w * h / 2, "{case}: most pixels are compared");
        if !(worst <= VIEW_TOL) {
            failures.push((case, worst));
        }
    }
    assert!(failures.is_empty(), "over {VIEW_TOL:e}: {failures:?}");
}

/// Light Path in a path tracer: the emitter is red to camera rays, green to the rest,
/// blue by Ray Depth, with Light Falloff on its strength; the floor sees it only
/// through light samples and diffuse bounces (fixtures/render_inputs/make_light_path_ref.py).
/// As tests/render.rs: RMSE against Cycles A over Cycles B's RMSE against A.
#[test]
fn light_path_render_matches_cycles() {
    use blendsynth::render::{render, RenderOptions};
    let dir = repo().join("fixtures/render_inputs/light_path");
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("view.json")).unwrap()).unwrap();
    let (w, h) = (
        meta["width"].as_u64().unwrap() as u32,
        meta["height"].as_u64().unwrap() as u32,
    );
    let load = |f: &str| -> Vec<f32> {
        std::fs::read(dir.join(f))
            .unwrap()
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let (a, b) = (load("cycles_a.f32"), load("cycles_b.f32"));
    let scene = Scene::load(&dir).unwrap();
    let opts = RenderOptions {
        samples: Some(meta["samples"].as_u64().unwrap() as u32),
        resolution: Some((w, h)),
        seed: Some(0),
        ..Default::default()
    };
    let out = render(&scene, &opts).unwrap();
    let ours: Vec<f32> = out
        .color
        .iter()
        .flat_map(|p| [p[0], p[1], p[2], p[3]])
        .collect();
    let rmse = |x: &[f32], y: &[f32]| -> f64 {
        let s: f64 = x
            .chunks(4)
            .zip(y.chunks(4))
            .map(|(p, q)| {
                (0..3)
                    .map(|k| (p[k] as f64 - q[k] as f64).powi(2))
                    .sum::<f64>()
            })
            .sum();
        (s / (x.len() / 4 * 3) as f64).sqrt()
    };
    let mean =
        |x: &[f32], k: usize| x.chunks(4).map(|p| p[k] as f64).sum::<f64>() / (x.len() / 4) as f64;
    let ratio = rmse(&ours, &a) / rmse(&b, &a).max(1e-12);
    let means: Vec<(f64, f64)> = (0..3).map(|k| (mean(&ours, k), mean(&a, k))).collect();
    eprintln!("light_path render {w}x{h}: RMSE ratio {ratio:.3}; means ours/Cycles {means:?}");
    for (k, (o, c)) in means.iter().enumerate() {
        assert!(
            (o - c).abs() <= 0.01 * c.abs().max(1e-3),
            "channel {k}: mean {o} vs Cycles {c}"
        );
    }
    assert!(ratio <= 1.15, "RMSE ratio {ratio}");
}
