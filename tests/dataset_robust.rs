//! Hostile and broken input to the dataset commands (issue 27, part B): frame counts
//! that would size an allocation, spec numbers that used to wrap or clamp, shard
//! records naming paths outside the dataset, a kill while the manifest is written, two
//! writers on one folder, a full disk at the last step, and more classes than an 8-bit
//! mask holds. Each test drives the CLI or the public API as a user would.

mod common;

use common::{assert_same_tree, tree};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use blendsynth::dataset::generate::{
    assign_splits, check_frames, parse_split, shard_frames, MAX_FRAMES,
};
use blendsynth::dataset::Spec;

fn repo_path(p: &str) -> String {
    common::repo().join(p).to_str().unwrap().to_string()
}

fn colon_spec_text() -> String {
    std::fs::read_to_string(common::repo().join("assets/doi-23843904/colonoscopy.toml")).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("blendsynth-robust-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `generate` of the built-in colon scene with the debugging bounds renderer (fast).
fn generate(out: &Path, frames: &str, extra: &[&str]) -> Command {
    generate_with_spec(
        out,
        &repo_path("assets/doi-23843904/colonoscopy.toml"),
        frames,
        extra,
    )
}

fn generate_with_spec(out: &Path, spec: &str, frames: &str, extra: &[&str]) -> Command {
    generate_cmd(out, spec, frames, "train=0.75,val=0.25", extra)
}

fn generate_cmd(out: &Path, spec: &str, frames: &str, split: &str, extra: &[&str]) -> Command {
    let mut c = common::bin();
    c.args([
        "generate",
        &repo_path("assets/doi-23843904/colonoscopy"),
        "--spec",
        spec,
        "--frames",
        frames,
        "--seed",
        "5",
        "--split",
        split,
        "--renderer",
        "bounds",
        "--jobs",
        "2",
        "-o",
        out.to_str().unwrap(),
    ])
    .args(extra);
    c
}

fn ok(o: Output) -> Output {
    assert!(
        o.status.success(),
        "{}{}",
        common::stdout(&o),
        common::stderr(&o)
    );
    o
}

// ---------------------------------------------------------------- frame counts

#[test]
fn huge_frame_counts_are_clear_errors_without_allocating() {
    let out = tmp("huge");
    for frames in ["1000000000000", "18446744073709551615", "1000000001"] {
        let t0 = std::time::Instant::now();
        let o = generate(&out, frames, &["--shard", "3/7"])
            .output()
            .unwrap();
        common::assert_clean_error(&o, 1, &["frames", "1000000000"]);
        assert!(t0.elapsed().as_secs() < 30, "{frames}: answered at once");
        assert!(!out.exists(), "{frames}: nothing written");
    }
    let o = generate(&out, "0", &[]).output().unwrap();
    common::assert_clean_error(&o, 1, &["frames"]);
}

#[test]
fn the_largest_dataset_is_handled_lazily() {
    // 10^9 frames, one shard of one frame: nothing is sized by the frame count (before,
    // every frame index and split was tabulated: 10 GB).
    let out = tmp("lazy");
    // One split, so no split boundary needs finding (that scans every index).
    let mut c = generate_cmd(
        &out,
        &repo_path("assets/doi-23843904/colonoscopy.toml"),
        "1000000000",
        "train=1",
        &["--shard", "999999998/999999999"],
    );
    let t0 = std::time::Instant::now();
    ok(c.output().unwrap());
    assert!(t0.elapsed().as_secs() < 60);
    let jsonl = std::fs::read_to_string(out.join("frames.jsonl")).unwrap();
    assert_eq!(jsonl.lines().count(), 1);
    assert!(jsonl.contains("\"index\":999999998"), "{jsonl}");
    std::fs::remove_dir_all(&out).unwrap();
}

// ---------------------------------------------------------------- splits

/// The table the split plan replaced (every index sorted by its hash), kept as the
/// oracle: existing datasets must keep their splits.
fn sorted_table(frames: u64, seed: u64, split: &[(String, f64)]) -> Vec<u16> {
    let n = frames as f64;
    let mut counts: Vec<u64> = split.iter().map(|(_, f)| (f * n).floor() as u64).collect();
    let mut rest: Vec<usize> = (0..split.len()).collect();
    rest.sort_by(|&a, &b| {
        let ra = split[a].1 * n - counts[a] as f64;
        let rb = split[b].1 * n - counts[b] as f64;
        rb.partial_cmp(&ra).unwrap().then(a.cmp(&b))
    });
    let mut left = frames - counts.iter().sum::<u64>();
    for &k in rest.iter().cycle() {
        if left == 0 {
            break;
        }
        counts[k] += 1;
        left -= 1;
    }
    let key = blendsynth::dataset::rng::key("#split");
    let mut order: Vec<u64> = (0..frames).collect();
    order.sort_by_key(|&i| (blendsynth::dataset::rng::bits(seed, i, key, 0), i));
    let mut out = vec![0u16; frames as usize];
    let mut pos = 0usize;
    for (k, c) in counts.iter().enumerate() {
        for &i in &order[pos..pos + *c as usize] {
            out[i as usize] = k as u16;
        }
        pos += *c as usize;
    }
    out
}

#[test]
fn split_plan_equals_the_sorted_table() {
    for (frames, seed, split) in [
        (1, 0, "train=1"),
        (1, 3, "train=0.5,val=0.5"),
        (2, 3, "a=0,b=1"),
        (7, 1, "a=1,b=0,c=0"),
        (10, 0, "a=0.34,b=0.33,c=0.33"),
        (24, 11, "train=0.75,val=0.25"),
        (1000, 5, "train=0.8,val=0.1,test=0.1"),
        (50_000, 3, "train=0.9,val=0.1"),
        (65_537, 9, "a=0.001,b=0.998,c=0.001"),
    ] {
        let split = parse_split(split).unwrap();
        assert_eq!(
            assign_splits(frames, seed, &split),
            sorted_table(frames, seed, &split),
            "{frames} frames, seed {seed}, {split:?}"
        );
    }
}

#[test]
fn frame_counts_are_bounded() {
    assert!(check_frames(0).is_err());
    assert!(check_frames(1).is_ok());
    assert!(check_frames(MAX_FRAMES).is_ok());
    assert!(check_frames(MAX_FRAMES + 1).unwrap_err().contains("frames"));
    assert!(check_frames(u64::MAX).is_err());
    assert_eq!(shard_frames(10, (3, 4)).collect::<Vec<_>>(), [3, 7]);
    assert_eq!(shard_frames(3, (5, 6)).count(), 0);
}

// ---------------------------------------------------------------- spec numbers

fn parse_err(extra: &str) -> String {
    match Spec::parse(extra) {
        Err(e) => e.to_string(),
        Ok(_) => "no error".into(),
    }
}

#[test]
fn spec_numbers_do_not_wrap_or_clamp() {
    let cases = [
        ("[render]\nsamples = 4294967297", "render.samples"),
        ("[render]\nsamples = 16777217", "render.samples"),
        ("[render]\nresolution = [4294967312, 16]", "render.resolution"),
        ("[render]\nresolution = [16, 65537]", "render.resolution"),
        ("[render]\nthreshold = inf", "render.threshold"),
        ("[render]\nthreshold = nan", "render.threshold"),
        ("[frames]\nstep = 9223372036854775807", "frames.step"),
        ("[frames]\nstart = -9223372036854775808", "frames.start"),
        ("[frames]\nmodulo = 9223372036854775807", "frames.modulo"),
        (
            "[[param]]\npath = 'materials[\"M\"].diffuse_color'\ndist = \"hsv\"\nh = [0, 1]\ns = [0, 1]\nv = [0, 1e308]",
            "v must be",
        ),
        (
            "[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"uniform\"\nmin = 0\nmax = 1e39",
            "max must be",
        ),
        (
            "[[param]]\npath = 'lights[\"Spot\"].energy'\ndist = \"normal\"\nmean = 0\nstd = inf",
            "std must be",
        ),
    ];
    for (text, want) in cases {
        let e = parse_err(text);
        assert!(e.contains(want), "{text:?}: {e}");
    }
    // Still valid: the limits themselves.
    let s = Spec::parse("[render]\nsamples = 16777216\nresolution = [65536, 1]\nthreshold = 1")
        .unwrap();
    assert_eq!(s.render.samples, Some(1 << 24));
    assert_eq!(s.render.resolution, Some((65536, 1)));
}

#[test]
fn a_schedule_leaving_blenders_frame_range_is_an_error() {
    // Without modulo, 2000 frames 1000 apart end beyond frame 1048574.
    let spec = tmp("schedule.toml");
    let text = colon_spec_text()
        .replace("step = 477", "step = 1000")
        .replace("modulo = 1000", "");
    std::fs::write(&spec, text).unwrap();
    let out = tmp("schedule");
    let o = generate_with_spec(&out, spec.to_str().unwrap(), "2000", &[])
        .output()
        .unwrap();
    common::assert_clean_error(&o, 1, &["frames.step", "1048574"]);
    let _ = std::fs::remove_dir_all(&out);
    std::fs::remove_file(&spec).unwrap();
}

// ---------------------------------------------------------------- merge

#[test]
fn merge_refuses_a_record_whose_split_leaves_the_shard() {
    let base = tmp("merge-escape");
    std::fs::create_dir_all(&base).unwrap();
    let shards: Vec<PathBuf> = (0..2).map(|i| base.join(format!("s{i}"))).collect();
    for (i, s) in shards.iter().enumerate() {
        ok(generate(s, "6", &["--shard", &format!("{i}/2")])
            .output()
            .unwrap());
    }
    // A tampered record: its split climbs out of the shard (read) and the output (write).
    let rec_path = shards[1].join("frames/000000001.json");
    let rec = std::fs::read_to_string(&rec_path).unwrap();
    let split = if rec.contains("\"split\":\"train\"") {
        "train"
    } else {
        "val"
    };
    let evil = "../../escaped";
    std::fs::write(
        &rec_path,
        rec.replace(
            &format!("\"split\":\"{split}\""),
            &format!("\"split\":\"{evil}\""),
        ),
    )
    .unwrap();
    // What the old merge read instead of the shard's image.
    for kind in ["images", "masks", "labels"] {
        let p = shards[1].join(kind).join(evil);
        std::fs::create_dir_all(&p).unwrap();
        let ext = if kind == "labels" { "txt" } else { "png" };
        std::fs::write(p.join(format!("000000001.{ext}")), b"secret").unwrap();
    }
    let out = base.join("deep/a/b/merged");
    let o = common::run(
        &[
            "merge",
            shards[0].to_str().unwrap(),
            shards[1].to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ],
        &[],
    );
    common::assert_clean_error(&o, 1, &["000000001.json", "split", "escaped"]);
    // Nothing was written outside the output folder.
    assert!(
        !base.join("deep/a/b/escaped").exists(),
        "merge wrote outside its output"
    );
    // The manifest's split names are checked too.
    let m = shards[0].join("manifest.json");
    let man = std::fs::read_to_string(&m).unwrap();
    for s in &shards {
        std::fs::write(s.join("manifest.json"), man.replace("\"val\"", "\"../v\"")).unwrap();
    }
    std::fs::write(&rec_path, &rec).unwrap();
    let out2 = base.join("merged2");
    let o = common::run(
        &[
            "merge",
            shards[0].to_str().unwrap(),
            shards[1].to_str().unwrap(),
            "-o",
            out2.to_str().unwrap(),
        ],
        &[],
    );
    common::assert_clean_error(&o, 1, &["manifest.json", "../v"]);
    std::fs::remove_dir_all(&base).unwrap();
}

// ---------------------------------------------------------------- kills, locks, full disk

#[test]
fn a_kill_while_the_manifest_is_written_is_resumable() {
    let clean = tmp("man-clean");
    ok(generate(&clean, "8", &[]).output().unwrap());
    // What a kill inside the manifest's write leaves: the folder and a torn temp file.
    let killed = tmp("man-killed");
    std::fs::create_dir_all(&killed).unwrap();
    std::fs::write(killed.join(".manifest.json.partial"), b"{\n  \"forma").unwrap();
    ok(generate(&killed, "8", &["--resume"]).output().unwrap());
    assert_same_tree(&clean, &killed);
    // And without --resume (a fresh run into the folder the kill left).
    std::fs::remove_dir_all(&killed).unwrap();
    std::fs::create_dir_all(&killed).unwrap();
    std::fs::write(killed.join(".manifest.json.partial"), b"").unwrap();
    ok(generate(&killed, "8", &[]).output().unwrap());
    assert_same_tree(&clean, &killed);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&killed).unwrap();
}

#[test]
fn a_second_writer_is_refused_while_the_first_runs() {
    let clean = tmp("lock-clean");
    ok(generate(&clean, "200", &[]).output().unwrap());
    let out = tmp("lock");
    let first_err = tmp("lock-first.err");
    let mut first = generate(&out, "200", &[])
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&first_err).unwrap())
        .spawn()
        .unwrap();
    let t0 = std::time::Instant::now();
    while !out.join("frames").is_dir() && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    // A requeued copy of the job starts beside it: refused, and it deletes nothing.
    let o = generate(&out, "200", &["--resume"]).output().unwrap();
    let running = first.try_wait().unwrap().is_none();
    if running {
        common::assert_clean_error(&o, 1, &["in use", "--resume"]);
    }
    assert!(
        first.wait().unwrap().success(),
        "the first run finishes: {}",
        std::fs::read_to_string(&first_err).unwrap()
    );
    std::fs::remove_file(&first_err).unwrap();
    assert!(
        running,
        "the first run ended before the second started; make it longer"
    );
    assert_same_tree(&clean, &out);
    // The lock goes with its process, however it ends: after a SIGKILL, resume works.
    std::fs::remove_dir_all(&out).unwrap();
    let mut victim = generate(&out, "200", &[])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    while !out.join("frames").is_dir() && t0.elapsed().as_secs() < 120 {
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    victim.kill().unwrap();
    victim.wait().unwrap();
    ok(generate(&out, "200", &["--resume"]).output().unwrap());
    assert_same_tree(&clean, &out);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn a_full_disk_at_the_last_step_says_how_to_resume() {
    let clean = tmp("full-clean");
    ok(generate(&clean, "40", &[]).output().unwrap());
    let jsonl = std::fs::metadata(clean.join("frames.jsonl")).unwrap().len();
    let largest_frame_file = tree(&clean)
        .iter()
        .filter(|(k, _)| !k.contains("annotations") && !k.ends_with("frames.jsonl"))
        .map(|(_, v)| v.len() as u64)
        .max()
        .unwrap();
    // A file size limit between the frames' files and frames.jsonl: writes beyond it
    // fail with EFBIG (SIGXFSZ ignored), as writes to a full disk fail with ENOSPC.
    // bash counts `ulimit -f` in 1024-byte blocks.
    let blocks = largest_frame_file / 1024 + 1;
    assert!(blocks * 1024 < jsonl, "{blocks} blocks, {jsonl} bytes");
    let full = tmp("full");
    let o = Command::new("bash")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {blocks}; exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_blendsynth"))
        .args(
            generate(&full, "40", &[])
                .get_args()
                .map(|a| a.to_os_string()),
        )
        .output()
        .unwrap();
    common::assert_clean_error(&o, 1, &["frames.jsonl", "--resume"]);
    let partials: Vec<String> = tree(&full)
        .into_keys()
        .filter(|k| k.ends_with(".partial"))
        .collect();
    assert!(partials.is_empty(), "half-written files left: {partials:?}");
    ok(generate(&full, "40", &["--resume"]).output().unwrap());
    assert_same_tree(&clean, &full);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&full).unwrap();
}

// ---------------------------------------------------------------- masks

#[test]
fn masks_are_16_bit_beyond_254_classes() {
    // 299 classes before the polyps': the polyp class id in the mask is 300.
    let mut extra = String::new();
    for k in 0..299 {
        extra.push_str(&format!(
            "[[labels.class]]\nname = \"c{k}\"\nobjects = [\"NoSuchObject{k}\"]\n"
        ));
    }
    let text = colon_spec_text().replace(
        "[[labels.class]]\nname = \"polyp\"",
        &format!("{extra}[[labels.class]]\nname = \"polyp\""),
    );
    assert!(text.contains("c298"));
    let spec = tmp("classes.toml");
    std::fs::write(&spec, text).unwrap();
    let out = tmp("classes");
    ok(generate_with_spec(&out, spec.to_str().unwrap(), "16", &[])
        .output()
        .unwrap());
    let mut seen = std::collections::BTreeSet::new();
    for split in ["train", "val"] {
        for e in std::fs::read_dir(out.join("masks").join(split)).unwrap() {
            let img = image::open(e.unwrap().path()).unwrap();
            let image::DynamicImage::ImageLuma16(m) = img else {
                panic!("masks of a dataset with 300 classes are 16-bit")
            };
            seen.extend(m.pixels().map(|p| p.0[0]));
        }
    }
    assert!(seen.contains(&300), "polyps are class 300: {seen:?}");
    assert!(seen.iter().all(|&v| v == 0 || v == 300), "{seen:?}");
    let coco = std::fs::read_to_string(out.join("annotations/instances_train.json")).unwrap()
        + &std::fs::read_to_string(out.join("annotations/instances_val.json")).unwrap();
    assert!(coco.contains("\"category_id\":300"));
    let preview = out.join("preview.png");
    ok(common::run(
        &[
            "preview",
            out.to_str().unwrap(),
            "-o",
            preview.to_str().unwrap(),
        ],
        &[],
    ));
    std::fs::remove_dir_all(&out).unwrap();
    std::fs::remove_file(&spec).unwrap();
}

#[test]
fn a_kill_at_every_write_then_resume_equals_an_uninterrupted_run() {
    // Every point at which a kill can leave the folder different: after each atomic
    // write's rename, and with each write's temporary file complete but not renamed
    // (BLENDSYNTH_KILL_AT_WRITE, foundation/files.rs). That includes the final step
    // (frames.jsonl, COCO, data.yaml), which a kill timed from outside rarely hits.
    use std::os::unix::process::ExitStatusExt;
    let clean = tmp("every-clean");
    ok(generate(&clean, "4", &[]).output().unwrap());
    let files = tree(&clean).len() as u64;
    let killed = tmp("every-killed");
    let mut kills = 0;
    for when in ["", ":before-rename"] {
        for n in 1.. {
            let _ = std::fs::remove_dir_all(&killed);
            let o = generate(&killed, "4", &[])
                .env("BLENDSYNTH_KILL_AT_WRITE", format!("{n}{when}"))
                .output()
                .unwrap();
            if o.status.success() {
                // Past the run's last write: every file is written once.
                assert_eq!(n, files + 1, "{n}{when}: the run wrote {files} files");
                break;
            }
            assert_eq!(
                o.status.signal(),
                Some(9),
                "{n}{when}: {}",
                common::stderr(&o)
            );
            kills += 1;
            let partials = tree(&killed)
                .into_keys()
                .filter(|k| k.ends_with(".partial"))
                .count();
            // The other worker (--jobs 2) may be inside a write of its own.
            assert!(partials >= usize::from(!when.is_empty()), "{n}{when}");
            ok(generate(&killed, "4", &["--resume"]).output().unwrap());
            assert_same_tree(&clean, &killed);
        }
    }
    assert_eq!(kills, 2 * files);
    std::fs::remove_dir_all(&clean).unwrap();
    std::fs::remove_dir_all(&killed).unwrap();
}

#[test]
fn kills_at_random_moments_then_resume_equal_an_uninterrupted_run() {
    // The quick version of fixtures/dataset/kill_resume.sh (the report runs 100 kills).
    let o = Command::new("bash")
        .arg(common::repo().join("fixtures/dataset/kill_resume.sh"))
        .env("BLENDSYNTH_BIN", env!("CARGO_BIN_EXE_blendsynth"))
        .env("KILLS", "5")
        .env("FRAMES", "8")
        .output()
        .unwrap();
    let text = common::stdout(&o);
    assert!(o.status.success(), "{text}{}", common::stderr(&o));
    assert!(text.contains("every result byte-identical"), "{text}");
}
