//! Datasets: the randomisation spec (parsing, validation errors naming the path,
//! draws), and `generate` (identical bytes across thread counts, shards + merge,
//! crash + resume, SIGKILL + resume through the CLI, and a real SLURM cluster in CI).

mod common;

use common::assert_same_tree;
use std::path::{Path, PathBuf};

use blendsynth::dataset::generate::{assign_splits, parse_split};
use blendsynth::dataset::spec::{hsv_to_rgb, RenderSettings};
use blendsynth::dataset::{generate, merge, FrameRenderer, GenerateOptions, RenderedFrame, Spec};
use blendsynth::label::{FrameIds, Instance};
use blendsynth::scene::Scene;

fn colon() -> Scene {
    Scene::load(&common::repo().join("assets/doi-23843904/colonoscopy")).unwrap()
}
fn colon_spec() -> Spec {
    Spec::load(&common::repo().join("assets/doi-23843904/colonoscopy.toml")).unwrap()
}

/// Test double (not a renderer): draws each mesh object as a square whose place
/// depends on its evaluated world position and the frame, and whose grey level
/// depends on the spot light's energy, so the output changes with every input that
/// matters and any nondeterminism shows up in the bytes.
struct SquaresRenderer;

impl FrameRenderer for SquaresRenderer {
    fn render(
        &self,
        scene: &Scene,
        frame: f64,
        seed: u32,
        _s: &RenderSettings,
        _threads: usize,
    ) -> Result<RenderedFrame, String> {
        let (w, h) = (64u32, 48u32);
        let ev = blendsynth::anim::evaluate_scene(scene, frame).map_err(|e| e.to_string())?;
        let energy = scene
            .file
            .lights
            .iter()
            .find(|l| l.name == "Spot")
            .and_then(|l| l.properties.get("energy"))
            .and_then(|v| v.as_f64())
            .unwrap_or(1.0);
        let grey = (energy / 2.0).min(1.0) as f32;
        let mut ids = vec![0u32; (w * h) as usize];
        let mut color = vec![[0.0, 0.0, (seed % 7) as f32 / 7.0, 1.0]; (w * h) as usize];
        let mut instances = Vec::new();
        for (k, o) in ev.data.objects.iter().enumerate() {
            if o.kind != "MESH" {
                continue;
            }
            let m = ev.world_matrices[k];
            instances.push(Instance {
                object: o.name.clone(),
                instance_index: None,
                world_bounds: (
                    [
                        m[0][3] as f32 - 0.01,
                        m[1][3] as f32 - 0.01,
                        m[2][3] as f32 - 0.01,
                    ],
                    [
                        m[0][3] as f32 + 0.01,
                        m[1][3] as f32 + 0.01,
                        m[2][3] as f32 + 0.01,
                    ],
                ),
                world_transform: m.map(|r| r.map(|v| v as f32)),
            });
            let id = instances.len() as u32;
            let size = (2.0 + 4.0 * o.scale[0]) as i64;
            let cx = ((m[0][3] * 1000.0 + frame * 7.0).rem_euclid(w as f64)) as i64;
            let cy = ((m[1][3] * 1000.0 + frame * 3.0).rem_euclid(h as f64)) as i64;
            for y in (cy - size).max(0)..(cy + size).min(h as i64) {
                for x in (cx - size).max(0)..(cx + size).min(w as i64) {
                    let p = (y * w as i64 + x) as usize;
                    ids[p] = id;
                    color[p] = [grey, (id as f32 / 10.0).min(1.0), 0.2, 1.0];
                }
            }
        }
        Ok(RenderedFrame {
            width: w,
            height: h,
            color,
            ids: FrameIds {
                width: w,
                height: h,
                instance_id: ids,
                depth: None,
                normal: None,
                instances,
                aov_channels: Vec::new(),
            },
        })
    }
}

fn opts(frames: u64) -> GenerateOptions {
    GenerateOptions {
        frames,
        seed: 11,
        split: parse_split("train=0.75,val=0.25").unwrap(),
        ..Default::default()
    }
}

fn spec_err(extra: &str) -> String {
    let spec = Spec::parse(extra).map_err(|e| e.to_string());
    match spec {
        Err(e) => e,
        Ok(s) => s
            .validate(&colon())
            .map(|_| String::from("no error"))
            .unwrap_or_else(|e| e.to_string()),
    }
}

#[test]
fn spec_errors_name_the_path() {
    let cases = [
        ("[[param]]\npath = 'objects[\"Nope\"].location'\ndist = \"uniform\"\nmin = 0\nmax = 1\n", &["objects[\"Nope\"].location", "nothing named \"Nope\""][..]),
        ("[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"choice\"\nvalues = [\"a\"]\n", &["lights[\"Spot\"].energy", "single number"]),
        ("[[param]]\npath = 'cameras[\"Camera\"].dof.aperture_blades'\ndist = \"uniform\"\nmin = 1\nmax = 2\n", &["aperture_blades", "integer"]),
        ("[[param]]\npath = 'cameras[\"Camera\"].dof.aperture_blades'\ndist = \"uniform_int\"\nmin = 3\nmax = 20\n", &["aperture_blades", "[3, 20]", "[0, 16]"]),
        ("[[param]]\npath = 'lights[\"Spot\"].spot_blend'\ndist = \"normal\"\nmean = 0.5\nstd = 0.1\n", &["spot_blend", "clamp"]),
        ("[[param]]\npath = 'lights[\"Spot\"].spot_blend'\ndist = \"normal\"\nmean = 0.5\nstd = 0.1\nclamp = [0.2, 1.5]\n", &["spot_blend", "[0.2, 1.5]", "[0, 1]"]),
        ("[[param]]\npath = 'objects[\"Camera\"].location'\ndist = \"uniform\"\nmin = [0, 0]\nmax = [1, 1]\n", &["objects[\"Camera\"].location", "3 components"]),
        ("[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"uniform\"\nmin = 0\nmax = 1\n[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"uniform\"\nmin = 0\nmax = 1\n", &["energy", "twice"]),
        ("[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"gauss\"\n", &["energy", "unknown dist"]),
        ("[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"uniform\"\nmin = 2\nmax = 1\n", &["energy", "min 2 > max 1"]),
        ("[[param]]\npath = 'materials[\"Polyp\"].node_tree.nodes[\"Principled BSDF\"].inputs[\"Base Color\"]'\ndist = \"color\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]\n", &["Base Color", "structure"]),
        ("[frames]\nmodulo = 0\n", &["frames.modulo", "positive"]),
        ("[render]\nsampels = 3\n", &["render.sampels", "unknown key"]),
    ];
    for (toml, want) in cases {
        let e = spec_err(toml);
        for w in want {
            assert!(
                e.contains(w),
                "spec\n{toml}\nerror {e:?} should mention {w:?}"
            );
        }
    }
    // The built-in specs validate against their scenes.
    assert!(colon_spec().validate(&colon()).is_ok());
}

#[test]
fn draws_are_a_function_of_seed_frame_and_path() {
    let scene = colon();
    let spec = colon_spec();
    let json = serde_json::to_value(&scene.file).unwrap();
    let alone = spec.frame_values(&json, 1, 5, 1234).unwrap();
    let again = spec.frame_values(&json, 1, 5, 1234).unwrap();
    assert_eq!(alone, again);
    assert_ne!(
        alone.drawn,
        spec.frame_values(&json, 1, 6, 1234).unwrap().drawn,
        "seed changes values"
    );
    assert_ne!(
        alone.drawn,
        spec.frame_values(&json, 1, 5, 1235).unwrap().drawn,
        "frame changes values"
    );
    // Adding a parameter does not change the others' draws (streams keyed by path).
    let more = Spec::parse(&format!("{}\n[[param]]\npath = 'cameras[\"Camera\"].lens'\ndist = \"uniform\"\nmin = 20\nmax = 40\n", spec.source)).unwrap();
    let fv = more.frame_values(&json, 1, 5, 1234).unwrap();
    assert_eq!(&fv.drawn[..alone.drawn.len()], &alone.drawn[..]);
    // Offsets are added to the scene's value: the camera's base rotation is 0.
    let rot = alone
        .overrides
        .iter()
        .find(|o| o.path == "objects[\"Camera\"].rotation_euler")
        .unwrap();
    let drawn = &alone
        .drawn
        .iter()
        .find(|(p, _)| p == "objects[\"Camera\"].rotation_euler")
        .unwrap()
        .1;
    assert_eq!(&rot.value, drawn);
    // Frame schedule: the study's start 50, step 477, modulo.
    assert_eq!(alone.frame, (50 + 477 * 1234) % 1000);
}

#[test]
fn distributions_respect_their_ranges() {
    let spec = Spec::parse(
        "[[param]]\npath = 'a'\ndist = \"uniform_int\"\nmin = -2\nmax = 2\n\
         [[param]]\npath = 'b'\ndist = \"normal\"\nmean = 3\nstd = 2\n\
         [[param]]\npath = 'c'\ndist = \"log_uniform\"\nmin = 0.01\nmax = 100\n\
         [[param]]\npath = 'd'\ndist = \"choice\"\nvalues = [\"X\", \"Y\"]\nweights = [3, 1]\n\
         [[param]]\npath = 'e'\ndist = \"hsv\"\nh = [0, 1]\ns = [0, 0.6]\nv = [1, 1]\n",
    )
    .unwrap();
    let n = 4000u64;
    let draw = |k: usize, i: u64| {
        blendsynth::dataset::spec::sample(
            &spec.params[k].dist,
            9,
            i,
            blendsynth::dataset::rng::key(&spec.params[k].path),
        )
    };
    let ints: Vec<i64> = (0..n).map(|i| draw(0, i).as_i64().unwrap()).collect();
    assert_eq!(
        (*ints.iter().min().unwrap(), *ints.iter().max().unwrap()),
        (-2, 2)
    );
    let xs: Vec<f64> = (0..n).map(|i| draw(1, i).as_f64().unwrap()).collect();
    let mean = xs.iter().sum::<f64>() / n as f64;
    let sd = (xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    assert!(
        (mean - 3.0).abs() < 0.1 && (sd - 2.0).abs() < 0.1,
        "normal mean {mean} sd {sd}"
    );
    let logs: Vec<f64> = (0..n)
        .map(|i| draw(2, i).as_f64().unwrap().log10())
        .collect();
    assert!(logs.iter().all(|l| (-2.0..2.0).contains(l)));
    let below_one = logs.iter().filter(|l| **l < 0.0).count() as f64 / n as f64;
    assert!(
        (below_one - 0.5).abs() < 0.04,
        "log-uniform: half below 1, got {below_one}"
    );
    let xs = (0..n).filter(|&i| draw(3, i) == "X").count() as f64 / n as f64;
    assert!((xs - 0.75).abs() < 0.03, "weighted choice {xs}");
    for i in 0..200 {
        let c: Vec<f64> = draw(4, i)
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(
            c.iter().all(|x| (0.4 - 1e-12..=1.0).contains(x))
                && c.iter().cloned().fold(0.0, f64::max) == 1.0,
            "{c:?}"
        );
    }
    // hsv_to_rgb is Python's colorsys.hsv_to_rgb (values printed by Python 3).
    let py = [
        ((0.0, 0.5, 1.0), [1.0, 0.5, 0.5]),
        ((0.3, 0.6, 1.0), [0.5200000000000001, 1.0, 0.4]),
        ((0.55, 0.25, 0.8), [0.6000000000000001, 0.74, 0.8]),
        ((0.99, 1.0, 0.5), [0.5, 0.0, 0.03000000000000025]),
        ((0.5, 0.0, 0.7), [0.7, 0.7, 0.7]),
    ];
    for ((h, s, v), want) in py {
        let got = hsv_to_rgb(h, s, v);
        assert!(
            (0..3).all(|k| (got[k] - want[k]).abs() < 1e-12),
            "hsv {h} {s} {v}: {got:?} vs {want:?}"
        );
    }
}

#[test]
fn splits_have_exact_counts_and_are_seeded() {
    let s = assign_splits(50_000, 3, &parse_split("train=0.9,val=0.1").unwrap());
    assert_eq!(s.iter().filter(|&&k| k == 0).count(), 45_000);
    assert_eq!(s.iter().filter(|&&k| k == 1).count(), 5_000);
    assert_ne!(
        s,
        assign_splits(50_000, 4, &parse_split("train=0.9,val=0.1").unwrap())
    );
    let s = assign_splits(10, 0, &parse_split("a=0.34,b=0.33,c=0.33").unwrap());
    assert_eq!(
        [0, 1, 2].map(|k| s.iter().filter(|&&x| x == k).count()),
        [4, 3, 3]
    );
    assert!(parse_split("train=0.9,val=0.2")
        .unwrap_err()
        .contains("sum"));
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "blendsynth-dataset-test-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn same_bytes_across_threads_shards_and_merge() {
    let (scene, spec) = (colon(), colon_spec());
    let one = tmp("one");
    generate(&scene, &spec, &SquaresRenderer, &one, &opts(24)).unwrap();
    let recs = std::fs::read_to_string(one.join("frames.jsonl")).unwrap();
    assert_eq!(recs.lines().count(), 24);
    assert!(
        recs.contains("\"class\":\"polyp\""),
        "some polyps are labelled"
    );
    let coco: serde_json::Value =
        serde_json::from_slice(&std::fs::read(one.join("annotations/instances_val.json")).unwrap())
            .unwrap();
    assert_eq!(coco["images"].as_array().unwrap().len(), 6);

    let threaded = tmp("threaded");
    generate(
        &scene,
        &spec,
        &SquaresRenderer,
        &threaded,
        &GenerateOptions {
            jobs: 3,
            ..opts(24)
        },
    )
    .unwrap();
    assert_same_tree(&one, &threaded);

    let shards: Vec<PathBuf> = (0..3).map(|i| tmp(&format!("shard{i}"))).collect();
    for (i, d) in shards.iter().enumerate() {
        generate(
            &scene,
            &spec,
            &SquaresRenderer,
            d,
            &GenerateOptions {
                shard: (i as u64, 3),
                jobs: 2,
                ..opts(24)
            },
        )
        .unwrap();
    }
    let merged = tmp("merged");
    assert_eq!(merge(&shards, &merged).unwrap(), 24);
    assert_same_tree(&one, &merged);

    // One frame regenerated alone (shard 17 of 24 is frame 17) is the same bytes.
    let alone = tmp("alone");
    generate(
        &scene,
        &spec,
        &SquaresRenderer,
        &alone,
        &GenerateOptions {
            shard: (17, 24),
            ..opts(24)
        },
    )
    .unwrap();
    let split = if one.join("images/train/000000017.png").exists() {
        "train"
    } else {
        "val"
    };
    for f in [
        format!("images/{split}/000000017.png"),
        format!("masks/{split}/000000017.png"),
        format!("labels/{split}/000000017.txt"),
        "frames/000000017.json".to_string(),
    ] {
        assert_eq!(
            std::fs::read(alone.join(&f)).unwrap(),
            std::fs::read(one.join(&f)).unwrap(),
            "{f}"
        );
    }
    assert_eq!(std::fs::read_dir(alone.join("frames")).unwrap().count(), 1);
    std::fs::remove_dir_all(&alone).unwrap();

    // Missing shards are an error naming the frames.
    let partial = tmp("partial");
    assert!(merge(&shards[..2], &partial)
        .unwrap_err()
        .contains("in none of the shards"));
    for d in [&one, &threaded, &merged].into_iter().chain(&shards) {
        std::fs::remove_dir_all(d).unwrap();
    }
}

fn crash_on_frame_5(i: u64, p: &Path) -> Result<(), String> {
    if i == 5 && p.extension().is_some_and(|e| e == "png") {
        return Err("injected crash".into());
    }
    Ok(())
}

#[test]
fn crash_mid_frame_then_resume_equals_uninterrupted() {
    let (scene, spec) = (colon(), colon_spec());
    let clean = tmp("clean");
    generate(&scene, &spec, &SquaresRenderer, &clean, &opts(12)).unwrap();
    let crashed = tmp("crashed");
    let e = generate(
        &scene,
        &spec,
        &SquaresRenderer,
        &crashed,
        &GenerateOptions {
            after_write: Some(crash_on_frame_5),
            ..opts(12)
        },
    )
    .unwrap_err();
    assert!(e.contains("frame 5") && e.contains("--resume"), "{e}");
    assert!(
        !crashed.join("frames/000000005.json").exists(),
        "frame 5 is unfinished"
    );
    // Leave a torn temp file as a kill during a write would.
    std::fs::write(crashed.join("frames/.000000005.json.partial"), b"{\"ind").unwrap();
    // Without --resume the folder is refused; with other settings too.
    assert!(
        generate(&scene, &spec, &SquaresRenderer, &crashed, &opts(12))
            .unwrap_err()
            .contains("--resume")
    );
    assert!(generate(
        &scene,
        &spec,
        &SquaresRenderer,
        &crashed,
        &GenerateOptions {
            resume: true,
            seed: 12,
            ..opts(12)
        }
    )
    .unwrap_err()
    .contains("other settings"));
    let s = generate(
        &scene,
        &spec,
        &SquaresRenderer,
        &crashed,
        &GenerateOptions {
            resume: true,
            ..opts(12)
        },
    )
    .unwrap();
    assert!(s.skipped >= 5 && s.rendered + s.skipped == 12, "{s:?}");
    assert_same_tree(&clean, &crashed);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&crashed).unwrap();
}

fn cli_generate(out: &Path, extra: &[&str]) -> std::process::Command {
    cli_generate_n(out, "300", "3", extra)
}

fn cli_generate_n(out: &Path, frames: &str, seed: &str, extra: &[&str]) -> std::process::Command {
    let repo = common::repo();
    let mut c = common::bin();
    c.args([
        "generate",
        repo.join("assets/doi-23843904/colonoscopy")
            .to_str()
            .unwrap(),
        "--spec",
        repo.join("assets/doi-23843904/colonoscopy.toml")
            .to_str()
            .unwrap(),
    ])
    .args([
        "--frames",
        frames,
        "--seed",
        seed,
        "--split",
        "train=0.9,val=0.1",
        "--renderer",
        "bounds",
        "-o",
        out.to_str().unwrap(),
    ])
    .args(extra);
    c
}

#[test]
fn sigkill_then_resume_through_the_cli_equals_uninterrupted() {
    let clean = tmp("cli-clean");
    let o = cli_generate(&clean, &["--jobs", "2"]).output().unwrap();
    assert!(o.status.success(), "{}", common::stderr(&o));
    let killed = tmp("cli-killed");
    let mut child = cli_generate(&killed, &["--jobs", "2"])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    let done = |d: &Path| {
        std::fs::read_dir(d.join("frames"))
            .map(|r| r.count())
            .unwrap_or(0)
    };
    while done(&killed) < 20 && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let finished = done(&killed);
    assert!(
        finished < 300,
        "the run was killed before the end ({finished} frames done)"
    );
    let o = cli_generate(&killed, &["--jobs", "1", "--resume"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert_same_tree(&clean, &killed);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&killed).unwrap();
}

#[test]
fn replicate_and_preview_through_the_cli() {
    let out = tmp("replica");
    let o = common::run(
        &[
            "replicate",
            "--dataset",
            "doi-23843904",
            "--frames",
            "8",
            "--renderer",
            "bounds",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    assert!(common::stdout(&o).contains("dataset written to"));
    for part in ["colonoscopy", "laparoscopy"] {
        let d = out.join(part);
        let yaml = std::fs::read_to_string(d.join("data.yaml")).unwrap();
        assert!(
            yaml.contains("train: images/train") && yaml.contains("val: images/val"),
            "{yaml}"
        );
        let train: serde_json::Value = serde_json::from_slice(
            &std::fs::read(d.join("annotations/instances_train.json")).unwrap(),
        )
        .unwrap();
        let val: serde_json::Value = serde_json::from_slice(
            &std::fs::read(d.join("annotations/instances_val.json")).unwrap(),
        )
        .unwrap();
        // 8 frames at 0.9/0.1: 7 + 1 (largest remainder).
        assert_eq!(
            (
                train["images"].as_array().unwrap().len(),
                val["images"].as_array().unwrap().len()
            ),
            (7, 1)
        );
        let sheet = out.join(format!("{part}.png"));
        let o = common::run(
            &[
                "preview",
                d.to_str().unwrap(),
                "-o",
                sheet.to_str().unwrap(),
            ],
            &[],
        );
        assert!(o.status.success(), "{}", common::stderr(&o));
        assert_eq!(
            image::image_dimensions(&sheet).unwrap(),
            (3 * 260 + 4, 3 * 260 + 4)
        );
    }
    // Laparoscopy: livers carry masks (RLE), and boxes come with them.
    let lap: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out.join("laparoscopy/annotations/instances_train.json")).unwrap(),
    )
    .unwrap();
    assert!(lap["annotations"]
        .as_array()
        .unwrap()
        .iter()
        .any(|a| a["segmentation"]["counts"].is_string()));
    let o = common::run(
        &[
            "replicate",
            "--dataset",
            "doi-0",
            "-o",
            out.join("x").to_str().unwrap(),
        ],
        &[],
    );
    common::assert_clean_error(&o, 1, &["doi-0"]);
    std::fs::remove_dir_all(&out).unwrap();
}

/// SLURM is up when `sinfo` reports a usable node. In CI (`.ci/run` starts a
/// single-node cluster) a missing cluster is a failure; elsewhere the test skips.
fn slurm_up() -> bool {
    std::process::Command::new("sinfo")
        .args(["-h", "-o", "%T"])
        .output()
        .map(|o| {
            o.status.success()
                && String::from_utf8_lossy(&o.stdout)
                    .lines()
                    .any(|l| ["idle", "mix", "alloc"].iter().any(|s| l.starts_with(s)))
        })
        .unwrap_or(false)
}

#[test]
fn slurm_job_array_and_merge_equal_a_single_run() {
    if common::require(
        "a running SLURM cluster (deploy/slurm/single-node.sh)",
        slurm_up().then_some(()),
    )
    .is_none()
    {
        return;
    }
    let repo = common::repo();
    let out = tmp("slurm");
    std::fs::create_dir_all(&out).unwrap();
    let bin = PathBuf::from(env!("CARGO_BIN_EXE_blendsynth"));
    let o = std::process::Command::new("bash")
        .arg(repo.join("deploy/slurm/submit.sh"))
        .arg("--wait")
        .env("SCENE", repo.join("assets/doi-23843904/colonoscopy"))
        .env("SPEC", repo.join("assets/doi-23843904/colonoscopy.toml"))
        .env("FRAMES", "40")
        .env("SHARDS", "4")
        .env("SEED", "5")
        .env("OUT", &out)
        .env("RENDERER", "bounds")
        .env("BLENDSYNTH", &bin)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "sbatch: {}{}",
        common::stdout(&o),
        common::stderr(&o)
    );
    let single = tmp("slurm-single");
    let o = cli_generate_n(&single, "40", "5", &[]).output().unwrap();
    assert!(o.status.success(), "{}", common::stderr(&o));
    for i in 0..4 {
        assert!(
            out.join(format!("shard-{i}/manifest.json")).exists(),
            "array task {i} ran"
        );
    }
    assert_same_tree(&single, &out.join("dataset"));
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_dir_all(&single).unwrap();
}

#[test]
fn optional_depth_output_agrees_with_the_records() {
    let scene = Scene::load(&common::repo().join("assets/doi-23843904/laparoscopy")).unwrap();
    let base = std::fs::read_to_string(common::repo().join("assets/doi-23843904/laparoscopy.toml"))
        .unwrap();
    let spec = Spec::parse(&base.replace("[labels]\n", "[labels]\ndepth = true\n")).unwrap();
    assert!(spec.labels.depth);
    let renderer = blendsynth::dataset::bounds::BoundsRenderer::new(&scene).unwrap();
    let out = tmp("depth");
    generate(
        &scene,
        &spec,
        &renderer,
        &out,
        &GenerateOptions {
            frames: 3,
            ..Default::default()
        },
    )
    .unwrap();
    let mut checked = 0;
    for line in std::fs::read_to_string(out.join("frames.jsonl"))
        .unwrap()
        .lines()
    {
        let r: blendsynth::label::record::FrameRecord = serde_json::from_str(line).unwrap();
        let img = image::open(out.join(format!("depth/train/{:09}.png", r.index))).unwrap();
        let d = img.as_luma16().expect("16-bit depth").clone();
        for a in &r.annotations {
            let [x, y, w, h] = a.bbox;
            let mut nearest = u16::MAX;
            for yy in y..y + h {
                for xx in x..x + w {
                    let v = d.get_pixel(xx, yy).0[0];
                    if v > 0 {
                        nearest = nearest.min(v);
                    }
                }
            }
            let want = (a.nearest_depth.unwrap() * 1000.0).round() as u16;
            assert!(
                nearest <= want && want > 0,
                "frame {} {}: depth image {nearest} mm, record {want} mm",
                r.index,
                a.object
            );
            checked += 1;
        }
    }
    assert!(checked > 0);
    // Normals need a renderer that makes them.
    let spec = Spec::parse(&base.replace("[labels]\n", "[labels]\nnormals = true\n")).unwrap();
    let e = generate(
        &scene,
        &spec,
        &renderer,
        &tmp("normals"),
        &GenerateOptions {
            frames: 1,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.contains("normals"), "{e}");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn polyp_sizes_are_the_authored_sizes_times_the_drawn_scale() {
    // make_scenes.py: Polyp.sessile.000 is a sphere of radius 6 mm flattened to 0.55 in
    // its own z; Polyp.stalked.001 a stalk and head of size 5 mm, 5 * (1.5 + 0.6) tall.
    let authored = [
        ("Polyp.sessile.000", [12.0, 12.0, 6.6]),
        ("Polyp.stalked.001", [6.0, 6.0, 10.5]),
    ];
    let out = tmp("sizes");
    generate(&colon(), &colon_spec(), &SquaresRenderer, &out, &opts(40)).unwrap();
    let mut checked = 0;
    for line in std::fs::read_to_string(out.join("frames.jsonl"))
        .unwrap()
        .lines()
    {
        let r: blendsynth::label::record::FrameRecord = serde_json::from_str(line).unwrap();
        for a in &r.annotations {
            let Some((_, dims)) = authored.iter().find(|(n, _)| *n == a.object) else {
                continue;
            };
            let scale = r.values[&format!("objects[\"{}\"].scale", a.object)]
                .as_f64()
                .unwrap();
            for k in 0..3 {
                assert!(
                    (a.size_mm[k] - dims[k] * scale).abs() < 1e-3,
                    "{} frame {}: {:?} vs {dims:?} x {scale}",
                    a.object,
                    r.index,
                    a.size_mm
                );
            }
            assert!((a.largest_mm - dims.iter().cloned().fold(0.0, f64::max) * scale).abs() < 1e-3);
            checked += 1;
        }
    }
    assert!(checked >= 2, "polyps seen: {checked}");
    std::fs::remove_dir_all(&out).unwrap();
}

/// Blender-side: the spec reproducing the authors' script validates against the
/// published colon scene freshly converted, and `replicate --assets` runs on it.
#[test]
fn published_colon_spec_validates_and_replicate_assets_runs() {
    let Some(py) = common::require("a Python with bpy 4.5.4", common::bpy_python()) else {
        return;
    };
    let Some(blend) = common::require(
        "../shared/published/colon_nodes.blend",
        common::published_colon(),
    ) else {
        return;
    };
    let dir = tmp("published");
    let o = common::run(
        &[
            "convert",
            blend.to_str().unwrap(),
            "-o",
            dir.join("scene").to_str().unwrap(),
            "--no-evaluated",
            "--blender",
            py.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    let scene = Scene::load(&dir.join("scene")).unwrap();
    let spec = Spec::load(&common::repo().join("assets/doi-23843904/colon_nodes.toml")).unwrap();
    assert_eq!(spec.params.len(), 21);
    spec.validate(&scene).unwrap();
    let out = dir.join("out");
    let o = common::run(
        &[
            "replicate",
            "--dataset",
            "doi-23843904",
            "--part",
            "colonoscopy",
            "--assets",
            dir.join("scene").to_str().unwrap(),
            "--frames",
            "3",
            "--renderer",
            "bounds",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    let frames: Vec<i64> = std::fs::read_to_string(out.join("frames.jsonl"))
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<serde_json::Value>(l).unwrap()["frame"]
                .as_i64()
                .unwrap()
        })
        .collect();
    assert_eq!(
        frames,
        vec![50, 527, 1004],
        "the authors' schedule: 50, then +477 modulo 18000"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The COCO files load in pycocotools and every RLE decodes to the recorded area and
/// box (fixtures/label/check_coco.py). Needs the repository's Python with pycocotools
/// (`.ci/run` installs it); skipped without it, a failure in CI.
#[test]
fn coco_files_load_in_pycocotools() {
    let py = common::bpy_python().filter(|p| {
        std::process::Command::new(p)
            .args(["-c", "import pycocotools"])
            .output()
            .is_ok_and(|o| o.status.success())
    });
    let Some(py) = common::require("a Python with pycocotools", py) else {
        return;
    };
    let out = tmp("pycoco");
    let o = common::run(
        &[
            "replicate",
            "--dataset",
            "doi-23843904",
            "--frames",
            "10",
            "--renderer",
            "bounds",
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    assert!(o.status.success(), "{}", common::stderr(&o));
    for part in ["colonoscopy", "laparoscopy"] {
        let o = std::process::Command::new(&py)
            .arg(common::repo().join("fixtures/label/check_coco.py"))
            .arg(out.join(part))
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}{}",
            common::stdout(&o),
            common::stderr(&o)
        );
        assert_eq!(
            common::stdout(&o)
                .lines()
                .filter(|l| l.contains("images"))
                .count(),
            2,
            "{}",
            common::stdout(&o)
        );
    }
    std::fs::remove_dir_all(&out).unwrap();
}

/// The production renderer behind `generate`/`replicate`: the path tracer renders a
/// built-in frame (small and few samples, to stay quick) whose instance pass sees the
/// colon wall, and whose image is finite and not flat.
#[test]
fn path_tracer_renders_a_labelled_builtin_frame() {
    use blendsynth::dataset::{renderer::path_tracer, replicate, spec::RenderSettings};
    let (scene, _spec) = replicate::scene_and_spec(replicate::Part::Colonoscopy, None).unwrap();
    let r = path_tracer(&scene).unwrap();
    let settings = RenderSettings {
        resolution: Some((64, 64)),
        samples: Some(8),
        threshold: Some(0.0),
        denoise: Some(false),
    };
    let f = r
        .render(
            &scene,
            scene.file.scene.frame_current as f64,
            0,
            &settings,
            2,
        )
        .unwrap();
    assert_eq!((f.width, f.height, f.color.len()), (64, 64, 64 * 64));
    // Display-referred but not clamped (Standard passes values above 1; the PNG writer clamps).
    assert!(f.color.iter().all(|p| p.iter().all(|c| c.is_finite())));
    let mean = f.color.iter().map(|p| p[0] as f64).sum::<f64>() / f.color.len() as f64;
    let var = f
        .color
        .iter()
        .map(|p| (p[0] as f64 - mean).powi(2))
        .sum::<f64>()
        / f.color.len() as f64;
    assert!(
        mean > 0.02 && var > 1e-5,
        "image is flat: mean {mean}, variance {var}"
    );
    let seen: std::collections::BTreeSet<&str> = f
        .ids
        .instance_id
        .iter()
        .filter(|&&i| i > 0)
        .map(|&i| f.ids.instances[i as usize - 1].object.as_str())
        .collect();
    assert!(
        seen.iter().any(|o| o.starts_with("Colon")),
        "no colon wall in the instance pass: {seen:?}"
    );
}
