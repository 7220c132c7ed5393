//! Bump, Displacement ("Bump Only"), Vector Displacement and Normal Map parity:
//! `blendsynth bake` against Cycles' EMIT bake of materials whose Emission colour is the
//! perturbed normal (fixtures/bake/make_bump_refs.py). Every texel, every channel.

mod common;
use common::*;

use blendsynth::render::bake::{bake_emission, BakeOptions};
use blendsynth::scene::Scene;

/// The project bound for texture-driven values.
const TOL: f32 = 1e-4;

fn compare_in(root: &std::path::Path, case: &str) -> f32 {
    let dir = root.join(case);
    let scene = Scene::load(&dir).unwrap();
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("bake.json")).unwrap()).unwrap();
    let size = meta["size"].as_u64().unwrap() as u32;
    let reference: Vec<f32> = std::fs::read(dir.join("blender_emit.f32"))
        .unwrap()
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(reference.len(), (size * size * 4) as usize);
    let ours = bake_emission(
        &scene,
        &BakeOptions {
            object: meta["object"].as_str().unwrap().into(),
            uv: None,
            size,
        },
    )
    .unwrap_or_else(|e| panic!("{case}: {e}"));
    let mut worst = 0.0f32;
    let mut at = 0;
    for (i, p) in ours.pixels.iter().enumerate() {
        for c in 0..3 {
            let d = (p[c] - reference[i * 4 + c]).abs();
            if d > worst || d.is_nan() {
                worst = if d.is_nan() { f32::INFINITY } else { d };
                at = i;
            }
        }
        assert_eq!(
            p[3],
            reference[i * 4 + 3],
            "{case}: texel {i} coverage differs"
        );
    }
    let r = &reference[at * 4..at * 4 + 3];
    eprintln!("bump {case}: {size}x{size}, worst abs error {worst:.2e} at texel {at} (ours {:?}, Blender {r:?})", &ours.pixels[at][..3]);
    worst
}

fn compare(case: &str) -> f32 {
    compare_in(&repo().join("fixtures/bake/bump"), case)
}

#[test]
fn bump_of_a_noise_height_matches_cycles() {
    assert!(compare("bump_noise") <= TOL);
}

/// The benchmark material (benches/shading.rs): a 6-octave Noise height.
#[test]
fn bump_of_a_six_octave_noise_matches_cycles() {
    assert!(compare("noise6_bump") <= TOL);
}

#[test]
fn bump_of_texture_coordinate_maths_matches_cycles() {
    assert!(compare("bump_texcoord_math") <= TOL);
}

#[test]
fn inverted_bump_with_a_linked_normal_and_filter_width_matches_cycles() {
    assert!(compare("bump_invert_linked") <= TOL);
}

#[test]
fn world_displacement_bumps_the_shading_normal_as_cycles_does() {
    assert!(compare("displacement_world") <= TOL);
}

#[test]
fn object_displacement_bumps_the_shading_normal_as_cycles_does() {
    assert!(compare("displacement_object") <= TOL);
}

#[test]
fn vector_displacement_matches_cycles() {
    assert!(compare("vector_displacement") <= TOL);
}

#[test]
fn object_space_normal_map_matches_cycles() {
    assert!(compare("normal_map_object") <= TOL);
}

#[test]
fn blender_world_normal_map_matches_cycles() {
    assert!(compare("normal_map_blender_world") <= TOL);
}

fn read_exr(p: &std::path::Path) -> Vec<[f32; 3]> {
    let img = image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgba32f();
    img.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect()
}

fn rmse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|k| ((x[k] - y[k]) as f64).powi(2)).sum::<f64>())
        .sum();
    (s / (3 * a.len()) as f64).sqrt()
}

fn means(a: &[[f32; 3]]) -> [f64; 3] {
    std::array::from_fn(|k| a.iter().map(|p| p[k] as f64).sum::<f64>() / a.len() as f64)
}

/// A Noise-driven Bump on a sphere's BSDF normal and a displacement bump on the floor,
/// under an area light (fixtures/render/make_bump_render_ref.py): the render-parity
/// criteria of tests/render.rs, RMSE(ours, A) / RMSE(B, A) <= 1.15 and channel means
/// within 1% of Cycles'.
#[test]
fn bump_render_matches_cycles() {
    use blendsynth::render::{render, RenderOptions};
    let dir = repo().join("fixtures/render/bump_scenes/bump");
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("render.json")).unwrap()).unwrap();
    let samples = meta["samples"].as_u64().unwrap() as u32;
    let res = meta["resolution"].as_array().unwrap();
    let (w, h) = (
        res[0].as_u64().unwrap() as u32,
        res[1].as_u64().unwrap() as u32,
    );
    let (a, b) = (
        read_exr(&dir.join("cycles_a.exr")),
        read_exr(&dir.join("cycles_b.exr")),
    );
    let scene = Scene::load(&dir).unwrap();
    let out = render(
        &scene,
        &RenderOptions {
            samples: Some(samples),
            resolution: Some((w, h)),
            seed: Some(0),
            ..Default::default()
        },
    )
    .unwrap();
    let ours: Vec<[f32; 3]> = out.color.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let ratio = rmse(&ours, &a) / rmse(&b, &a).max(1e-12);
    let (mo, ma) = (means(&ours), means(&a));
    let worst_mean = (0..3)
        .map(|k| (mo[k] - ma[k]).abs() / ma[k].abs().max(1e-6))
        .fold(0.0, f64::max);
    eprintln!("bump render: ratio {ratio:.3}, worst channel mean error {:.2}% (ours {mo:.4?}, Cycles A {ma:.4?})", 100.0 * worst_mean);
    assert!(ratio <= 1.15, "ratio {ratio:.3}");
    assert!(worst_mean <= 0.01, "mean error {:.2}%", 100.0 * worst_mean);
}
