//! Denoising against Cycles: fixtures/denoise/make_denoise_refs.py rendered a small scene
//! with Cycles (16 samples, adaptive sampling off) and Cycles' own OIDN denoising at its
//! defaults, storing the noisy image, the albedo and normal guides Cycles gave OIDN, and
//! the denoised result. We denoise the same noisy image with the same guides through
//! blendsynth's run-time-loaded OIDN and compare. The library comes from the bpy
//! installation (or $BLENDSYNTH_OIDN); without one the test skips, except in CI.

mod common;

use std::collections::HashMap;

use blendsynth::denoise::{DenoiseOptions, Denoiser};

struct Exr {
    width: usize,
    height: usize,
    channels: HashMap<String, Vec<f32>>,
}

fn read_exr(path: &std::path::Path) -> Exr {
    use exr::prelude::*;
    let img = read_all_flat_layers_from_file(path).unwrap();
    let mut channels = HashMap::new();
    let mut size = (0, 0);
    for layer in &img.layer_data {
        size = (layer.size.width(), layer.size.height());
        let prefix = layer
            .attributes
            .layer_name
            .as_ref()
            .map(|n| format!("{n}."))
            .unwrap_or_default();
        for ch in &layer.channel_data.list {
            let v: Vec<f32> = ch.sample_data.values_as_f32().collect();
            channels.insert(format!("{prefix}{}", ch.name), v);
        }
    }
    Exr {
        width: size.0,
        height: size.1,
        channels,
    }
}

impl Exr {
    fn get(&self, pass: &str, comps: &[&str]) -> Vec<Vec<f32>> {
        comps
            .iter()
            .map(|c| {
                let key = format!("ViewLayer.{pass}.{c}");
                self.channels
                    .get(&key)
                    .unwrap_or_else(|| {
                        panic!(
                            "{key} missing; have {:?}",
                            self.channels.keys().collect::<Vec<_>>()
                        )
                    })
                    .clone()
            })
            .collect()
    }
    fn rgba(&self, pass: &str) -> Vec<[f32; 4]> {
        let c = self.get(pass, &["R", "G", "B", "A"]);
        (0..self.width * self.height)
            .map(|i| [c[0][i], c[1][i], c[2][i], c[3][i]])
            .collect()
    }
    fn vec3(&self, pass: &str, comps: [&str; 3]) -> Vec<[f32; 3]> {
        let c = self.get(pass, &comps);
        (0..self.width * self.height)
            .map(|i| [c[0][i], c[1][i], c[2][i]])
            .collect()
    }
}

fn mean_abs(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let mut s = 0.0;
    for (p, q) in a.iter().zip(b) {
        for c in 0..3 {
            s += (p[c] as f64 - q[c] as f64).abs();
        }
    }
    s / (a.len() * 3) as f64
}

fn mean(a: &[[f32; 4]]) -> f64 {
    a.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / (a.len() * 3) as f64
}

#[test]
fn denoised_like_cycles() {
    let exr = read_exr(&common::repo().join("fixtures/denoise/render.exr"));
    let (w, h) = (exr.width as u32, exr.height as u32);
    let noisy = exr.rgba("Noisy Image");
    let albedo = exr.vec3("Denoising Albedo", ["R", "G", "B"]);
    let normal = exr.vec3("Denoising Normal", ["X", "Y", "Z"]);
    let cycles = exr.rgba("Combined");

    let loaded = Denoiser::load(None).unwrap();
    let Some(den) = common::require(
        "libOpenImageDenoise (bpy wheel or $BLENDSYNTH_OIDN)",
        loaded,
    ) else {
        return;
    };
    println!("OIDN from {}", den.path().display());

    let mut ours = noisy.clone();
    den.denoise(w, h, &mut ours, &albedo, &normal).unwrap();

    let before = mean_abs(&noisy, &cycles);
    let after = mean_abs(&ours, &cycles);
    println!("image mean {:.5}; mean |noisy - cycles denoised| = {before:.6}; mean |ours - cycles denoised| = {after:.3e} ({:.5}% of the mean)", mean(&cycles), 100.0 * after / mean(&cycles));
    // Alpha is kept.
    assert!(ours.iter().zip(&noisy).all(|(a, b)| a[3] == b[3]));
    // Denoising must have done real work, and land on Cycles' result.
    // Same library, same guides, same settings and row order as Cycles: the result should be
    // Cycles' up to float noise, far below the noise that was removed.
    assert!(after < 1e-4 * mean(&cycles), "mean abs diff {after}");
    assert!(before > 100.0 * after, "before {before} after {after}");

    // Without the Accurate prefilter the result is measurably different (the option is honoured).
    let mut fast = noisy.clone();
    let opts = DenoiseOptions {
        prefilter: blendsynth::denoise::Prefilter::Fast,
        ..DenoiseOptions::default()
    };
    den.denoise_with(w, h, &mut fast, &albedo, &normal, &opts)
        .unwrap();
    let fast_diff = mean_abs(&fast, &cycles);
    println!("mean |ours(prefilter Fast) - cycles(Accurate)| = {fast_diff:.6}");
    assert!(fast_diff > 10.0 * after.max(1e-7));
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let Some(den) = common::require(
        "libOpenImageDenoise (bpy wheel or $BLENDSYNTH_OIDN)",
        Denoiser::load(None).unwrap(),
    ) else {
        return;
    };
    let mut c = vec![[0.5f32; 4]; 4];
    let e = den
        .denoise(2, 2, &mut c, &[[0.5; 3]; 3], &[[0.0, 0.0, 1.0]; 4])
        .unwrap_err()
        .to_string();
    assert!(e.contains("albedo"), "{e}");
    let e = den.denoise(0, 2, &mut c, &[], &[]).unwrap_err().to_string();
    assert!(e.contains("empty"), "{e}");
}

#[test]
fn explicit_missing_library_is_an_error() {
    let e = Denoiser::load(Some(std::path::Path::new(
        "/nonexistent/libOpenImageDenoise.so.2",
    )))
    .unwrap_err()
    .to_string();
    assert!(e.contains("/nonexistent/libOpenImageDenoise.so.2"), "{e}");
    let tmp = tempfile::tempdir().unwrap();
    let fake = tmp.path().join("libOpenImageDenoise.so.2");
    std::fs::write(&fake, b"not a library").unwrap();
    let e = Denoiser::load(Some(&fake)).unwrap_err().to_string();
    assert!(e.contains("cannot load"), "{e}");
}

/// The fixture camera (rotation X 1.1 rad) sees the floor (world +Z) with Cycles'
/// denoising normal (0, 0.891, -0.454); `cycles_denoise_normal` must produce what the
/// committed pass holds there.
#[test]
fn denoise_normal_convention_matches_cycles_pass() {
    let exr = read_exr(&common::repo().join("fixtures/denoise/render.exr"));
    let normal = exr.vec3("Denoising Normal", ["X", "Y", "Z"]);
    let floor = normal[(exr.height - 3) * exr.width + exr.width / 2];
    let (s, c) = (1.1f64.sin(), 1.1f64.cos());
    let cam = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, c, -s, -6.0],
        [0.0, s, c, 3.2],
        [0.0, 0.0, 0.0, 1.0],
    ];
    let ours = blendsynth::denoise::cycles_denoise_normal([0.0, 0.0, 1.0], &cam);
    for k in 0..3 {
        assert!(
            (ours[k] - floor[k]).abs() < 2e-3,
            "ours {ours:?} cycles {floor:?}"
        );
    }
    // Background pixels have a zero normal.
    assert_eq!(normal[2 * exr.width + 2], [0.0, 0.0, 0.0]);
}

/// The guides themselves: Cycles' "Denoising Normal" and "Denoising Albedo" of the colon
/// material in small (sharp glossy over a bumped Burley subsurface Principled; scene
/// sss_burley_bump, fixtures/denoise/make_guide_refs.py, 16 samples) against ours from
/// the same export and sample count. Both are averages of 16 noisy samples, so they differ
/// by sampling noise; a guide without the bump (the shading normal through the pixel
/// centre, what blendsynth gave OIDN before) is far further off, and flattens the
/// relief in denoised images.
#[test]
fn denoising_guides_follow_cycles() {
    use blendsynth::render::{render, RenderOptions};
    let exr = read_exr(&common::repo().join("fixtures/denoise/guides_sss_burley_bump.exr"));
    let scene = blendsynth::scene::Scene::load(
        &common::repo().join("fixtures/render/scenes/sss_burley_bump"),
    )
    .unwrap();
    let opts = RenderOptions {
        samples: Some(16),
        resolution: Some((exr.width as u32, exr.height as u32)),
        seed: Some(0),
        threshold: Some(0.0),
        ..Default::default()
    };
    let out = render(&scene, &opts).unwrap();
    let cam_name = scene.file.scene.camera.clone().unwrap();
    let ci = scene
        .file
        .objects
        .iter()
        .position(|o| o.name == cam_name)
        .unwrap();
    let cam = blendsynth::anim::evaluate_transforms(&scene, scene.file.scene.frame_current as f64)
        .unwrap()[ci];
    let to_cam = |n: &[f32; 3]| blendsynth::denoise::cycles_denoise_normal(*n, &cam);
    let cycles_n = exr.vec3("Denoising Normal", ["X", "Y", "Z"]);
    let cycles_a = exr.vec3("Denoising Albedo", ["R", "G", "B"]);
    let mad = |a: &[[f32; 3]], b: &[[f32; 3]]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| (0..3).map(|c| (p[c] - q[c]).abs() as f64).sum::<f64>())
            .sum::<f64>()
            / (3 * a.len()) as f64
    };
    let ours_n: Vec<[f32; 3]> = out.passes.denoise_normal.iter().map(to_cam).collect();
    let old_n: Vec<[f32; 3]> = out
        .passes
        .normal
        .iter()
        .zip(&out.passes.instance_id)
        .map(|(n, &id)| if id == 0 { [0.0; 3] } else { to_cam(n) })
        .collect();
    let (d_new, d_old) = (mad(&ours_n, &cycles_n), mad(&old_n, &cycles_n));
    let mean3 = |a: &[[f32; 3]]| {
        (0..3)
            .map(|c| a.iter().map(|p| p[c] as f64).sum::<f64>() / a.len() as f64)
            .collect::<Vec<_>>()
    };
    let (ma, mc) = (mean3(&out.passes.albedo), mean3(&cycles_a));
    let d_alb = mad(&out.passes.albedo, &cycles_a);
    // The noise floor: our own guides with another seed.
    let other = render(
        &scene,
        &RenderOptions {
            seed: Some(1),
            ..opts
        },
    )
    .unwrap();
    let other_n: Vec<[f32; 3]> = other.passes.denoise_normal.iter().map(to_cam).collect();
    let d_floor = mad(&ours_n, &other_n);
    println!("normal guide: mean |ours - Cycles| {d_new:.4} (ours with another seed {d_floor:.4}), with the unbumped centre-ray normal {d_old:.4}; means ours {:.4?} Cycles {:.4?}; albedo guide: mean |ours - Cycles| {d_alb:.4}, means ours {ma:.4?} Cycles {mc:.4?}", mean3(&ours_n), mean3(&cycles_n));
    assert!(
        d_new < 0.5 * d_old,
        "normal guide {d_new} not much closer to Cycles' than the unbumped one ({d_old})"
    );
    assert!(
        d_new < 1.25 * d_floor,
        "normal guide off by {d_new}, more than sampling noise ({d_floor})"
    );
    for c in 0..3 {
        assert!(
            (ma[c] / mc[c] - 1.0).abs() < 0.03,
            "albedo guide channel {c}: ours {} Cycles {}",
            ma[c],
            mc[c]
        );
    }
    assert!(d_alb < 0.03, "albedo guide off by {d_alb}");
}
