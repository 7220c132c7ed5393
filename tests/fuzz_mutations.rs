//! The fuzz targets' entry points (fuzz/fuzz_targets) on deterministic mutations of their
//! committed seeds, in every `cargo test`: cargo-fuzz needs an instrumented build that is
//! too slow for CI (`.ci/fuzz.sh` runs it for real), but the same inputs a first fuzzing
//! pass tries — flipped bits, bytes set to boundary values, truncations, deleted and
//! repeated spans, numbers replaced by huge, negative and non-finite ones — catch a
//! panic, an abort-free overflow or an unchecked allocation just as well. The stream is
//! fixed (a seeded xorshift), so CI cannot pass or fail by the draw.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use blendsynth::scene::{Override, Scene};

mod common;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        // xorshift64*
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
}

const NUMBERS: [&str; 10] = [
    "-1",
    "0",
    "4294967296",
    "18446744073709551616",
    "1e308",
    "-1e308",
    "1e-320",
    "NaN",
    "2147483647",
    "99999999999",
];

/// One mutation of `seed`.
fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    let n = b.len();
    match rng.below(7) {
        0 if n > 0 => {
            let i = rng.below(n);
            b[i] ^= 1 << rng.below(8);
        }
        1 if n > 0 => {
            let i = rng.below(n);
            b[i] = [0u8, 0xff, 0x7f, 0x80, b'9', b'-', b'"', b'{', b'[', b'\\'][rng.below(10)];
        }
        2 => b.truncate(rng.below(n + 1)),
        3 if n > 0 => {
            let i = rng.below(n);
            let len = rng.below((n - i).min(64) + 1);
            b.drain(i..i + len);
        }
        4 if n > 0 => {
            let i = rng.below(n);
            let len = rng.below((n - i).min(64) + 1);
            let span: Vec<u8> = b[i..i + len].to_vec();
            let at = rng.below(n + 1);
            b.splice(at..at, span);
        }
        5 => {
            // A run of digits becomes a boundary number.
            let digits: Vec<usize> = (0..n).filter(|&i| b[i].is_ascii_digit()).collect();
            if !digits.is_empty() {
                let start = digits[rng.below(digits.len())];
                let mut end = start;
                while end < n && (b[end].is_ascii_digit() || b[end] == b'.') {
                    end += 1;
                }
                let with = NUMBERS[rng.below(NUMBERS.len())].as_bytes().to_vec();
                b.splice(start..end, with);
            }
        }
        _ if n >= 4 => {
            // A little-endian u32 (glb lengths, counts and offsets) set to a boundary.
            let i = rng.below(n - 3);
            let v: u32 = [0, 1, 0x7fff_ffff, 0xffff_ffff, 0x1000_0000, 4][rng.below(6)];
            b[i..i + 4].copy_from_slice(&v.to_le_bytes());
        }
        _ => b.push(rng.next() as u8),
    }
    b
}

fn seeds(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let dir = common::repo().join("fuzz/seeds").join(target);
    let mut out: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no seeds in {}", dir.display());
    out
}

/// Runs `f` on every seed and `per_seed` mutations of each; a panic fails the test and
/// names the seed and mutation (rerun that one input with the printed index).
fn exercise(target: &str, per_seed: usize, f: impl Fn(&[u8])) {
    static LAST: std::sync::Mutex<String> = std::sync::Mutex::new(String::new());
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|info| {
        *LAST.lock().unwrap_or_else(|e| e.into_inner()) = info.to_string();
    }));
    let mut failures = Vec::new();
    for (path, seed) in seeds(target) {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ seed.len() as u64);
        for k in 0..=per_seed {
            let input = if k == 0 {
                seed.clone()
            } else {
                mutate(&seed, &mut rng)
            };
            if catch_unwind(AssertUnwindSafe(|| f(&input))).is_err() {
                let why = LAST.lock().unwrap_or_else(|e| e.into_inner()).clone();
                failures.push(format!("{} mutation {k}: {why}", path.display()));
            }
        }
    }
    std::panic::set_hook(hook);
    assert!(failures.is_empty(), "{target}: panics on {failures:?}");
}

#[test]
fn scene_json_never_panics() {
    exercise("scene_json", 400, |data| {
        let _ = Scene::from_json(Path::new("/nonexistent-fuzz-scene"), data);
    });
}

#[test]
fn glb_never_panics() {
    exercise("glb", 3000, |data| {
        let _ = blendsynth::scene::mesh::parse_glb(data, Path::new("fuzz.glb"));
    });
}

#[test]
fn spec_never_panics() {
    exercise("spec", 3000, |data| {
        if let Ok(text) = std::str::from_utf8(data) {
            let _ = blendsynth::dataset::spec::Spec::parse(text);
        }
    });
}

#[test]
fn set_value_never_panics() {
    let json = std::fs::read(common::repo().join("fixtures/scenes/geonodes/scene.json")).unwrap();
    let scene = Scene::from_json(Path::new("/nonexistent-fuzz-scene"), &json).unwrap();
    exercise("set_value", 3000, |data| {
        if let Ok(text) = std::str::from_utf8(data) {
            if let Ok(o) = Override::parse(text) {
                let _ = scene.with_overrides(&[o]);
            }
        }
    });
}
