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
        let prefix = layer.attributes.layer_name.as_ref().map(|n| format!("{n}.")).unwrap_or_default();
        for ch in &layer.channel_data.list {
            let v: Vec<f32> = ch.sample_data.values_as_f32().collect();
            channels.insert(format!("{prefix}{}", ch.name), v);
        }
    }
    Exr { width: size.0, height: size.1, channels }
}

impl Exr {
    fn get(&self, pass: &str, comps: &[&str]) -> Vec<Vec<f32>> {
        comps
            .iter()
            .map(|c| {
                let key = format!("ViewLayer.{pass}.{c}");
                self.channels.get(&key).unwrap_or_else(|| panic!("{key} missing; have {:?}", self.channels.keys().collect::<Vec<_>>())).clone()
            })
            .collect()
    }
    fn rgba(&self, pass: &str) -> Vec<[f32; 4]> {
        let c = self.get(pass, &["R", "G", "B", "A"]);
        (0..self.width * self.height).map(|i| [c[0][i], c[1][i], c[2][i], c[3][i]]).collect()
    }
    fn vec3(&self, pass: &str, comps: [&str; 3]) -> Vec<[f32; 3]> {
        let c = self.get(pass, &comps);
        (0..self.width * self.height).map(|i| [c[0][i], c[1][i], c[2][i]]).collect()
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
    let Some(den) = common::require("libOpenImageDenoise (bpy wheel or $BLENDSYNTH_OIDN)", loaded) else { return };
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
    let opts = DenoiseOptions { prefilter: blendsynth::denoise::Prefilter::Fast, ..DenoiseOptions::default() };
    den.denoise_with(w, h, &mut fast, &albedo, &normal, &opts).unwrap();
    let fast_diff = mean_abs(&fast, &cycles);
    println!("mean |ours(prefilter Fast) - cycles(Accurate)| = {fast_diff:.6}");
    assert!(fast_diff > 10.0 * after.max(1e-7));
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let Some(den) = common::require("libOpenImageDenoise (bpy wheel or $BLENDSYNTH_OIDN)", Denoiser::load(None).unwrap()) else { return };
    let mut c = vec![[0.5f32; 4]; 4];
    let e = den.denoise(2, 2, &mut c, &[[0.5; 3]; 3], &[[0.0, 0.0, 1.0]; 4]).unwrap_err().to_string();
    assert!(e.contains("albedo"), "{e}");
    let e = den.denoise(0, 2, &mut c, &[], &[]).unwrap_err().to_string();
    assert!(e.contains("empty"), "{e}");
}

#[test]
fn explicit_missing_library_is_an_error() {
    let e = Denoiser::load(Some(std::path::Path::new("/nonexistent/libOpenImageDenoise.so.2"))).unwrap_err().to_string();
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
    let cam = [[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, -6.0], [0.0, s, c, 3.2], [0.0, 0.0, 0.0, 1.0]];
    let ours = blendsynth::denoise::cycles_denoise_normal([0.0, 0.0, 1.0], &cam);
    for k in 0..3 {
        assert!((ours[k] - floor[k]).abs() < 2e-3, "ours {ours:?} cycles {floor:?}");
    }
    // Background pixels have a zero normal.
    assert_eq!(normal[2 * exr.width + 2], [0.0, 0.0, 0.0]);
}
