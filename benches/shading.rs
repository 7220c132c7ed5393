//! Shading-point throughput of compiled materials, single-threaded (points per second
//! per core). `cargo bench --bench shading [CASE...]` (all cases when none is named).
//!
//! Materials: the bake-parity fixtures (fixtures/bake/scenes). `textures` is Mapping, a
//! 6-octave fBm Noise, Smooth-F1 Voronoi (2 octaves), Wave, Magic, Gradient and Checker.
//! With `BLENDSYNTH_COLON_EXPORT=DIR` (a `blendsynth convert` of
//! ../shared/published/colon_nodes.blend, which is never copied into the repository)
//! it also measures the published tissue material "Fat.001".
//! `noise6_bump` (fixtures/bake/bump) is a 6-octave fBm Noise into a Bump node: the
//! height subgraph runs three times (centre, dx, dy) per point.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use blendsynth::scene::Scene;
use blendsynth::shader::{compile_material, ShadingPoint};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bake/scenes");
    let bump_root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/bake/bump");
    let mut cases: Vec<(String, std::path::PathBuf, Option<&str>)> =
        ["uv_math", "structure", "closures", "textures"]
            .iter()
            .map(|c| (c.to_string(), root.join(c), None))
            .collect();
    cases.push(("noise6_bump".into(), bump_root.join("noise6_bump"), None));
    match std::env::var_os("BLENDSYNTH_COLON_EXPORT") {
        Some(dir) => cases.push(("Fat.001".into(), dir.into(), Some("Fat.001"))),
        None => println!("shading Fat.001: skipped (set BLENDSYNTH_COLON_EXPORT to a converted colon_nodes.blend)"),
    }
    let only: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    for (case, dir, name) in &cases {
        if !only.is_empty() && !only.iter().any(|o| o == case) {
            continue;
        }
        let scene = Scene::load(dir).expect("scene");
        let material = name
            .map(str::to_string)
            .unwrap_or_else(|| scene.file.materials[0].name.clone());
        let program = compile_material(&scene, &material).expect("compiles");
        let mut stack = program.new_stack();
        // BLENDSYNTH_BENCH_POINTS=N (a multiple of 1000) shortens the slow materials' runs.
        let n: u32 = std::env::var("BLENDSYNTH_BENCH_POINTS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(2_000_000);
        let (start, cpu_start) = (Instant::now(), cpu_ns());
        let mut acc = 0.0f32;
        for i in 0..n {
            // Points spread over the unit square, as a bake or a render would visit them.
            let u = (i % 1000) as f32 / 1000.0;
            let v = (i / 1000) as f32 / (n / 1000) as f32;
            let sp = ShadingPoint {
                position: [u, v, 0.1],
                normal: [0.0, 0.0, 1.0],
                object_position: [2.0 * u - 1.0, 2.0 * v - 1.0, 0.0],
                object_normal: [0.0, 0.0, 1.0],
                generated: [u, v, 0.5],
                uv: [u, v, 0.0],
                ..bump_point()
            };
            program.run(black_box(&sp), &mut stack);
            acc += program.surface_emission(&stack)[0];
        }
        let secs = start.elapsed().as_secs_f64();
        let cpu = cpu_ns()
            .zip(cpu_start)
            .map_or(f64::NAN, |(b, a)| (b - a) as f64);
        black_box(acc);
        println!(
            "shading {case:<10} {:>4} ops: {:>6.1} M points/s per core ({:.1} ns/point; cpu {:.1} ns/point)",
            program.ops.len(),
            n as f64 / secs / 1e6,
            secs * 1e9 / n as f64,
            cpu / n as f64
        );
    }
}

/// This thread's CPU time in ns (Linux): on a shared machine, unlike wall time, it does
/// not count time spent waiting for a core.
fn cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Ray differentials of a 1/1000 step on the unit square, so Bump nodes run their dx/dy
/// copies as in a bake or a render (`noise6_bump`: 6-octave fBm Noise into a Bump).
fn bump_point() -> ShadingPoint {
    ShadingPoint {
        ng: [0.0, 0.0, 1.0],
        dp_dx: [1e-3, 0.0, 0.0],
        dp_dy: [0.0, 1e-3, 0.0],
        generated_dx: [1e-3, 0.0, 0.0],
        generated_dy: [0.0, 1e-3, 0.0],
        uv_dx: [1e-3, 0.0, 0.0],
        uv_dy: [0.0, 1e-3, 0.0],
        ..ShadingPoint::default()
    }
}
