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

// ---- Provisioning: OIDN fetched into the cache folder when none is installed ----

/// A `blendsynth` run that sees no installed OIDN: no $BLENDSYNTH_OIDN, no bpy (no
/// BLENDSYNTH_BPY_PYTHON, VIRTUAL_ENV or BLENDSYNTH_BLENDER, the working directory
/// outside the repository and its .venv, a fresh HOME, no `blender` on PATH) and the
/// given cache folder.
fn isolated(root: &std::path::Path, cache: &std::path::Path) -> std::process::Command {
    let work = root.join("work");
    let home = root.join("home");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&home).unwrap();
    let path = std::env::var_os("PATH").unwrap_or_default();
    let path =
        std::env::join_paths(std::env::split_paths(&path).filter(|d| !d.join("blender").is_file()))
            .unwrap();
    let mut c = common::bin();
    c.current_dir(&work)
        .env_remove("BLENDSYNTH_OIDN")
        .env_remove("BLENDSYNTH_OIDN_DOWNLOAD")
        .env_remove("BLENDSYNTH_BPY_PYTHON")
        .env_remove("BLENDSYNTH_BLENDER")
        .env_remove("VIRTUAL_ENV")
        .env("HOME", &home)
        .env("XDG_CACHE_HOME", cache)
        .env("PATH", path);
    c
}

/// `blendsynth render` of a small fixture scene with denoising on, to `out`.
fn render_args(out: &std::path::Path) -> Vec<std::ffi::OsString> {
    let scene = common::repo().join("fixtures/render/scenes/diffuse_point");
    let mut a: Vec<std::ffi::OsString> = vec!["render".into(), scene.into()];
    for s in [
        "--samples",
        "4",
        "--resolution",
        "48x32",
        "--seed",
        "0",
        "--denoise",
        "on",
        "-o",
    ] {
        a.push(s.into());
    }
    a.push(out.into());
    a
}

/// Every channel's samples of an EXR as bits, channels in name order.
fn exr_bits(path: &std::path::Path) -> Vec<u32> {
    let e = read_exr(path);
    let mut names: Vec<&String> = e.channels.keys().collect();
    names.sort();
    names
        .iter()
        .flat_map(|n| e.channels[*n].iter().map(|v| v.to_bits()))
        .collect()
}

fn ok(o: &std::process::Output) -> String {
    let err = common::stderr(o);
    assert!(o.status.success(), "exit {:?}: {err}", o.status);
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// From an empty cache folder with no OIDN installed, `render --denoise on` fetches the
/// pinned wheel (three processes at once: one downloads, the others wait for it) and
/// writes a denoised image; a second run loads it from the cache without a notice; the
/// same pyoidn wheel unpacked in full by Python's zipfile and given as $BLENDSYNTH_OIDN
/// gives the same image bit for bit. The fetched library then denoises Cycles' fixture
/// within the tolerance of `denoised_like_cycles`. Needs the Python package index:
/// skipped without it, except in CI.
#[test]
fn fetched_into_an_empty_cache_and_identical_to_the_same_library_named() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let outs: Vec<_> = (0..3)
        .map(|i| tmp.path().join(format!("first{i}.exr")))
        .collect();
    let t0 = std::time::Instant::now();
    let children: Vec<_> = outs
        .iter()
        .map(|o| {
            isolated(tmp.path(), &cache)
                .args(render_args(o))
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let results: Vec<_> = children
        .into_iter()
        .map(|c| c.wait_with_output().unwrap())
        .collect();
    let first_secs = t0.elapsed().as_secs_f64();
    let errs: Vec<String> = results.iter().map(ok).collect();
    if errs
        .iter()
        .any(|e| e.contains("cannot run `python3 -m pip"))
    {
        common::require::<()>("the Python package index (pip download pyoidn)", None);
        return;
    }
    let downloads = errs
        .iter()
        .filter(|e| e.contains("downloading it once"))
        .count();
    assert_eq!(downloads, 1, "one process downloads: {errs:#?}");
    for e in &errs {
        assert!(e.contains("Open Image Denoise ready in"), "{e}");
    }
    println!(
        "three concurrent first runs (one download + render): {first_secs:.1} s; notice: {}",
        errs.iter()
            .find(|e| e.contains("downloading"))
            .unwrap()
            .trim()
    );
    let lib = cache.join("blendsynth/oidn-2.5.1/lib");
    assert!(lib.join("libOpenImageDenoise.so.2").is_file());
    let leftovers: Vec<_> = std::fs::read_dir(cache.join("blendsynth"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(
        leftovers.is_empty(),
        "temporary folders left: {leftovers:?}"
    );
    let first = exr_bits(&outs[0]);
    for o in &outs[1..] {
        assert!(exr_bits(o) == first, "{} differs", o.display());
    }

    // Denoising really happened.
    let noisy = tmp.path().join("noisy.exr");
    let mut a = render_args(&noisy);
    let n = a.len();
    a[n - 3] = "off".into();
    ok(&isolated(tmp.path(), &cache).args(a).output().unwrap());
    assert!(
        exr_bits(&noisy) != first,
        "the denoised image equals the noisy one"
    );

    // Later runs: loaded from the cache, silently, same image.
    let again = tmp.path().join("again.exr");
    let e = ok(&isolated(tmp.path(), &cache)
        .args(render_args(&again))
        .output()
        .unwrap());
    assert!(!e.contains("notice"), "{e}");
    assert!(exr_bits(&again) == first);

    // The same library found through $BLENDSYNTH_OIDN: the whole wheel, fetched and
    // unpacked independently (Python's zipfile), as a user installing pyoidn would have it.
    let wheel_dir = tmp.path().join("wheel");
    let o = std::process::Command::new("python3")
        .args(["-m", "pip", "download", "--no-deps", "--only-binary=:all:"])
        .args([
            "--platform",
            "manylinux2014_x86_64",
            "--no-cache-dir",
            "--quiet",
        ])
        .arg("--dest")
        .arg(&wheel_dir)
        .arg("pyoidn==2.5.1.0")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", common::stderr(&o));
    let o = std::process::Command::new("python3")
        .args([
            "-c",
            "import sys, zipfile; zipfile.ZipFile(sys.argv[1]).extractall(sys.argv[2])",
        ])
        .arg(wheel_dir.join("pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl"))
        .arg(wheel_dir.join("x"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", common::stderr(&o));
    let named_lib = wheel_dir.join("x/pyoidn/oidn/lib");
    let named = tmp.path().join("named.exr");
    let cache2 = tmp.path().join("cache2");
    let e = ok(&isolated(tmp.path(), &cache2)
        .env("BLENDSYNTH_OIDN", &named_lib)
        .args(render_args(&named))
        .output()
        .unwrap());
    assert!(!e.contains("notice"), "{e}");
    assert!(
        !cache2.exists(),
        "provisioned although $BLENDSYNTH_OIDN was set"
    );
    assert!(
        exr_bits(&named) == first,
        "fetched and named libraries give different images"
    );

    // Against Cycles' own denoising (bpy's OIDN) on the committed fixture.
    let exr = read_exr(&common::repo().join("fixtures/denoise/render.exr"));
    let (w, h) = (exr.width as u32, exr.height as u32);
    let noisy = exr.rgba("Noisy Image");
    let albedo = exr.vec3("Denoising Albedo", ["R", "G", "B"]);
    let normal = exr.vec3("Denoising Normal", ["X", "Y", "Z"]);
    let cycles = exr.rgba("Combined");
    let den = Denoiser::load(Some(&lib)).unwrap().unwrap();
    let mut ours = noisy.clone();
    den.denoise(w, h, &mut ours, &albedo, &normal).unwrap();
    let max_abs = |a: &[[f32; 4]], b: &[[f32; 4]]| {
        a.iter()
            .zip(b)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
            .fold(0.0f32, f32::max)
    };
    let (d_mean, d_max) = (mean_abs(&ours, &cycles), max_abs(&ours, &cycles));
    println!(
        "fetched OIDN vs Cycles' denoised fixture: mean |diff| {d_mean:.3e} ({:.5}% of the image mean), max {d_max:.3e}; noisy vs Cycles {:.3e}",
        100.0 * d_mean / mean(&cycles),
        mean_abs(&noisy, &cycles)
    );
    assert!(d_mean < 1e-4 * mean(&cycles), "mean abs diff {d_mean}");
    if let Some(bpy) = Denoiser::load(None).ok().flatten() {
        let mut theirs = noisy.clone();
        bpy.denoise(w, h, &mut theirs, &albedo, &normal).unwrap();
        let same = ours
            .iter()
            .zip(&theirs)
            .all(|(p, q)| (0..4).all(|c| p[c].to_bits() == q[c].to_bits()));
        println!(
            "fetched OIDN vs {} through blendsynth: {}",
            bpy.path().display(),
            if same {
                "bit-identical".to_string()
            } else {
                format!("max |diff| {:.3e}", max_abs(&ours, &theirs))
            }
        );
        assert!(max_abs(&ours, &theirs) <= d_max.max(1e-6));
    }
}

/// With downloading turned off (the flag or the variable) and nothing installed, the run
/// succeeds with a notice that names the command installing OIDN, and the image is the
/// noisy one.
#[test]
fn download_turned_off_names_the_install_command() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let out = tmp.path().join("a.exr");
    let by_flag = ok(&isolated(tmp.path(), &cache)
        .args(render_args(&out))
        .arg("--no-oidn-download")
        .output()
        .unwrap());
    let out2 = tmp.path().join("b.exr");
    let by_env = ok(&isolated(tmp.path(), &cache)
        .env("BLENDSYNTH_OIDN_DOWNLOAD", "0")
        .args(render_args(&out2))
        .output()
        .unwrap());
    let noisy = tmp.path().join("noisy.exr");
    let mut a = render_args(&noisy);
    let n = a.len();
    a[n - 3] = "off".into();
    ok(&isolated(tmp.path(), &cache).args(a).output().unwrap());
    for e in [&by_flag, &by_env] {
        println!("{e}");
        assert!(e.contains("downloading it is turned off"), "{e}");
        let cmd = format!(
            "{} fetch-oidn",
            std::path::Path::new(env!("CARGO_BIN_EXE_blendsynth")).display()
        );
        assert!(e.contains(&cmd), "the notice should name `{cmd}`: {e}");
        assert!(!e.contains("downloading it once"), "{e}");
    }
    assert!(!cache.exists(), "the cache folder was written");
    assert!(exr_bits(&out) == exr_bits(&noisy));
    assert!(exr_bits(&out2) == exr_bits(&noisy));
}

/// A wheel that does not match the pinned sha256 (served here by pip itself from a
/// local folder, no network) is refused: a notice, the noisy image, exit 0, and nothing
/// left in the cache but the lock file.
#[test]
fn a_wheel_with_the_wrong_checksum_is_a_notice_not_a_failure() {
    let tmp = tempfile::tempdir().unwrap();
    let links = tmp.path().join("links");
    std::fs::create_dir_all(&links).unwrap();
    // A well-formed wheel (pip checks its metadata) under the pinned file name.
    {
        use std::io::Write;
        let f =
            std::fs::File::create(links.join("pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl"))
                .unwrap();
        let mut z = zip::ZipWriter::new(f);
        let o = zip::write::SimpleFileOptions::default();
        for (name, text) in [
            ("pyoidn/__init__.py", ""),
            (
                "pyoidn-2.5.1.0.dist-info/METADATA",
                "Metadata-Version: 2.1\nName: pyoidn\nVersion: 2.5.1.0\n",
            ),
            (
                "pyoidn-2.5.1.0.dist-info/WHEEL",
                "Wheel-Version: 1.0\nGenerator: test\nRoot-Is-Purelib: false\nTag: py3-none-manylinux2014_x86_64\n",
            ),
            ("pyoidn-2.5.1.0.dist-info/RECORD", ""),
        ] {
            z.start_file(name, o).unwrap();
            z.write_all(text.as_bytes()).unwrap();
        }
        z.finish().unwrap();
    }
    let cache = tmp.path().join("cache");
    let out = tmp.path().join("a.exr");
    let o = isolated(tmp.path(), &cache)
        .env("PIP_NO_INDEX", "1")
        .env("PIP_FIND_LINKS", &links)
        .args(render_args(&out))
        .output()
        .unwrap();
    let e = ok(&o);
    println!("{e}");
    if (e.contains("No module named pip") || e.contains("python3 is not on PATH"))
        && !common::in_ci()
    {
        eprintln!("SKIPPED: python3 -m pip not available");
        return;
    }
    assert!(e.contains("sha256 is") && e.contains("32ad13368f8d"), "{e}");
    assert!(
        e.contains("written noisy") && e.contains("fetch-oidn"),
        "{e}"
    );
    assert!(out.is_file());
    let left: Vec<_> = std::fs::read_dir(cache.join("blendsynth"))
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, vec!["oidn-2.5.1.lock".to_string()]);
}

/// `generate` (what `replicate` runs) on the built-in colonoscopy scene, its spec's
/// render settings shrunk: without denoising nothing is fetched; with denoising, from an
/// empty cache and no OIDN installed, the library is fetched once and the frame differs
/// from the noisy one. Needs the Python package index: skipped without it, except in CI.
#[test]
fn generate_fetches_only_when_a_frame_asks_for_denoising() {
    let tmp = tempfile::tempdir().unwrap();
    let cache = tmp.path().join("cache");
    let assets = common::repo().join("assets/doi-23843904");
    let spec = std::fs::read_to_string(assets.join("colonoscopy.toml")).unwrap();
    let (head, rest) = spec.split_once("[render]").unwrap();
    let rest = &rest[rest.find("\n[").unwrap()..];
    let run = |denoise: bool| {
        let spec_file = tmp.path().join(format!("spec-{denoise}.toml"));
        std::fs::write(
            &spec_file,
            format!("{head}[render]\nresolution = [40, 32]\nsamples = 4\nthreshold = 0.0\ndenoise = {denoise}\n{rest}"),
        )
        .unwrap();
        let out = tmp.path().join(format!("ds-{denoise}"));
        let o = isolated(tmp.path(), &cache)
            .arg("generate")
            .arg(assets.join("colonoscopy"))
            .arg("--spec")
            .arg(&spec_file)
            .args(["--frames", "1", "--seed", "0", "--jobs", "1", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        let err = ok(&o);
        // images/<split>/<frame>.png
        let frames: Vec<_> = std::fs::read_dir(out.join("images"))
            .unwrap()
            .flatten()
            .flat_map(|split| std::fs::read_dir(split.path()).unwrap().flatten())
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "png"))
            .collect();
        assert_eq!(frames.len(), 1, "{err}");
        (err, std::fs::read(&frames[0]).unwrap())
    };
    let (err, noisy) = run(false);
    assert!(!err.contains("Open Image Denoise"), "{err}");
    assert!(!cache.exists(), "fetched although no frame denoises");
    let (err, denoised) = run(true);
    if err.contains("cannot run `python3 -m pip") {
        common::require::<()>("the Python package index (pip download pyoidn)", None);
        return;
    }
    println!("{err}");
    assert_eq!(err.matches("downloading it once").count(), 1, "{err}");
    assert!(err.contains("Open Image Denoise ready in"), "{err}");
    assert!(cache
        .join("blendsynth/oidn-2.5.1/lib/libOpenImageDenoise.so.2")
        .is_file());
    assert!(denoised != noisy, "the denoised frame equals the noisy one");
}

/// A python3 without pip (Debian's default): the render still succeeds, noisy, and the
/// notice says to install pip.
#[test]
fn without_pip_the_notice_says_what_to_install() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().unwrap();
    let bin = tmp.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let py = bin.join("python3");
    std::fs::write(
        &py,
        "#!/bin/sh\necho '/usr/bin/python3: No module named pip' >&2\nexit 1\n",
    )
    .unwrap();
    std::fs::set_permissions(&py, std::fs::Permissions::from_mode(0o755)).unwrap();
    let mut c = isolated(tmp.path(), &tmp.path().join("cache"));
    let path = c
        .get_envs()
        .find(|(k, _)| *k == "PATH")
        .and_then(|(_, v)| v.map(|v| v.to_os_string()))
        .unwrap();
    let mut dirs = vec![bin.clone()];
    dirs.extend(std::env::split_paths(&path));
    c.env("PATH", std::env::join_paths(dirs).unwrap());
    let out = tmp.path().join("a.exr");
    let e = ok(&c.args(render_args(&out)).output().unwrap());
    assert!(
        e.contains("No module named pip") && e.contains("apt-get install python3-pip"),
        "{e}"
    );
    assert!(e.contains("written noisy"), "{e}");
    assert!(out.is_file());
}
