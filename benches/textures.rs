//! Single procedural textures, single-threaded, in ns per call: the texture settings of the
//! published tissue material "Fat.001" (Smooth F1, F1 and Distance-to-Edge 3D Voronoi, an
//! 11-octave fBm Noise, Wave with and without distortion) plus the other Voronoi
//! features and dimensions and the hashes. `cargo bench --bench textures [FILTER]`;
//! `BLENDSYNTH_BENCH_POINTS=N` sets the calls per case (default 200000).
//!
//! The machine may be shared: besides wall time each case reports the thread's own CPU
//! time (Linux `/proc/thread-self/schedstat`), which time spent waiting for a core does
//! not inflate; both are the best of three runs.

use std::hint::black_box;
use std::time::Instant;

use blendsynth::nodes::noise::{noise_texture_cycles, NoiseParams, NoiseType};
use blendsynth::nodes::voronoi::{voronoi_texture, VoronoiFeature, VoronoiMetric, VoronoiParams};
use blendsynth::nodes::wave::{
    wave, BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType,
};
use blendsynth::nodes::white_noise::{hash_f3_to_f3, white_noise};

/// Points spread over [-1, 1]^3 with an LCG, the same sequence for every case.
fn points(n: usize) -> Vec<[f32; 3]> {
    let mut s = 12345u32;
    let mut next = move || {
        s = s.wrapping_mul(1664525).wrapping_add(1013904223);
        (s >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

/// This thread's CPU time in ns, if the kernel reports it.
fn cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

fn voronoi(feature: VoronoiFeature, scale: f32, detail: f32) -> VoronoiParams {
    VoronoiParams::new(
        feature,
        VoronoiMetric::Euclidean,
        false,
        scale,
        detail,
        0.5,
        2.0,
        1.0,
        0.5,
        1.0,
    )
}

fn main() {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let n: usize = std::env::var("BLENDSYNTH_BENCH_POINTS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200_000);
    let pts = points(n);
    let fbm11 = NoiseParams {
        kind: NoiseType::Fbm,
        normalize: true,
        detail: 10.689_58,
        roughness: 0.5,
        lacunarity: 2.0,
        offset: 0.0,
        gain: 1.0,
        distortion: 0.0,
    };
    let bands = |d| WaveSettings {
        kind: WaveType::Bands,
        bands: d,
        rings: RingsDirection::X,
        profile: WaveProfile::Sin,
    };
    type Case<'a> = (&'a str, Box<dyn Fn([f32; 3]) -> f32 + 'a>);
    let smooth = VoronoiParams::new(
        VoronoiFeature::SmoothF1,
        VoronoiMetric::Euclidean,
        false,
        5.0,
        0.0,
        0.5,
        2.0,
        0.5,
        0.5,
        1.0,
    );
    let cases: Vec<Case> = vec![
        ("hash_f3_to_f3", Box::new(|p| hash_f3_to_f3(p)[1])),
        ("white_noise_3d", Box::new(|p| white_noise(3, p, 0.0).1[2])),
        (
            "voronoi_smooth_f1_3d",
            Box::new(move |p| voronoi_texture(3, p, 0.0, smooth).color[0]),
        ),
        (
            "voronoi_f1_3d",
            Box::new(|p| {
                voronoi_texture(3, p, 0.0, voronoi(VoronoiFeature::F1, 21.8, 0.0)).distance
            }),
        ),
        (
            "voronoi_edge_3d",
            Box::new(|p| {
                voronoi_texture(
                    3,
                    p,
                    0.0,
                    voronoi(VoronoiFeature::DistanceToEdge, 29.3, 0.0),
                )
                .distance
            }),
        ),
        (
            "voronoi_f2_3d",
            Box::new(|p| {
                voronoi_texture(3, p, 0.0, voronoi(VoronoiFeature::F2, 21.8, 0.0)).distance
            }),
        ),
        (
            "voronoi_sphere_3d",
            Box::new(|p| {
                voronoi_texture(3, p, 0.0, voronoi(VoronoiFeature::NSphereRadius, 21.8, 0.0)).radius
            }),
        ),
        (
            "voronoi_f1_3d_detail2",
            Box::new(|p| {
                voronoi_texture(3, p, 0.0, voronoi(VoronoiFeature::F1, 21.8, 2.0)).distance
            }),
        ),
        (
            "voronoi_f1_2d",
            Box::new(|p| {
                voronoi_texture(2, p, 0.0, voronoi(VoronoiFeature::F1, 21.8, 0.0)).distance
            }),
        ),
        (
            "voronoi_f1_4d",
            Box::new(|p| {
                voronoi_texture(4, p, p[0], voronoi(VoronoiFeature::F1, 21.8, 0.0)).distance
            }),
        ),
        (
            "voronoi_smooth_f1_4d",
            Box::new(move |p| voronoi_texture(4, p, p[0], smooth).distance),
        ),
        (
            "noise_fbm11_3d",
            Box::new(|p| noise_texture_cycles(3, p, 0.0, 11.438_896, fbm11).0),
        ),
        (
            "noise_fbm11_4d",
            Box::new(|p| noise_texture_cycles(4, p, p[0], 11.438_896, fbm11).0),
        ),
        (
            "wave_bands_x",
            Box::new(|p| wave(bands(BandsDirection::X), p, 19.33, 0.0, 2.0, 1.0, 0.5, 0.0)),
        ),
        (
            "wave_bands_x_distorted",
            Box::new(|p| wave(bands(BandsDirection::X), p, 22.39, 6.0, 0.0, 1.0, 0.5, 0.0)),
        ),
    ];
    for (name, f) in &cases {
        if !filter.is_empty() && !filter.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let (mut wall, mut cpu) = (f64::MAX, f64::MAX);
        let mut acc = 0.0f32;
        for _ in 0..3 {
            let (start, cpu_start) = (Instant::now(), cpu_ns());
            for &p in &pts {
                acc += f(black_box(p));
            }
            wall = wall.min(start.elapsed().as_secs_f64() * 1e9);
            cpu = cpu.min(
                cpu_ns()
                    .zip(cpu_start)
                    .map_or(f64::NAN, |(b, a)| (b - a) as f64),
            );
        }
        black_box(acc);
        println!(
            "texture {name:<24} {:>9.1} ns/call (cpu {:>9.1} ns/call)",
            wall / n as f64,
            cpu / n as f64
        );
    }
}
