//! The sped-up procedural textures give the same bits as the code before the speed work
//! (tests/noise_speed/reference.rs, a verbatim copy of it) on many random inputs: every
//! Voronoi feature, metric and dimension, the fractal noise types in both flavours,
//! white noise, the cell hashes and the Wave texture. Values agree with Blender through
//! the bake tests (tests/bake.rs, tests/textures.rs); this test pins that the speed work
//! changed no result, not even in the last bit. `cargo test --release --test noise_speed`.

#[path = "noise_speed/reference.rs"]
mod reference;

use blendsynth::nodes::{noise, voronoi, wave, white_noise};
use reference as old;

/// xorshift64*: reproducible inputs without a dependency.
struct Rng(u64);
impl Rng {
    fn u64(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn unit(&mut self) -> f32 {
        (self.u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[(self.u64() % xs.len() as u64) as usize]
    }
    /// A coordinate from one of several regimes: ordinary, cell boundaries (integers and
    /// halves, where ties and floor matter), large (the 1e5 wrap and the 1e6 shift),
    /// tiny, signed zeros, and now and then infinities and NaN.
    fn coord(&mut self) -> f32 {
        match self.u64() % 16 {
            0..=5 => self.range(-8.0, 8.0),
            6 => self.range(-1000.0, 1000.0),
            7 => (self.range(-20.0, 20.0) * 2.0).round() / 2.0,
            8 => self.range(-20.0, 20.0).round(),
            9 => self.range(-3e6, 3e6),
            10 => self.range(9e4, 1.1e5) * self.pick(&[1.0, -1.0]),
            11 => self.range(-1e-6, 1e-6),
            12 => self.pick(&[
                0.0, -0.0, 1.0, -1.0, 0.5, 99999.5, 1e5, -3e5, 1e6, -1e6, 16777215.0, 16777216.0,
            ]),
            13 => self.range(-1e9, 1e9),
            14 => f32::from_bits(self.u64() as u32),
            _ => self.pick(&[
                f32::INFINITY,
                f32::NEG_INFINITY,
                f32::NAN,
                f32::MIN_POSITIVE,
                3.4e38,
            ]),
        }
    }
    fn vec3(&mut self) -> [f32; 3] {
        [self.coord(), self.coord(), self.coord()]
    }
    fn vec4(&mut self) -> [f32; 4] {
        [self.coord(), self.coord(), self.coord(), self.coord()]
    }
    /// An ordinary coordinate (as shading points give), for the costly fractal cases.
    fn near(&mut self) -> f32 {
        if self.u64().is_multiple_of(8) {
            self.coord()
        } else {
            self.range(-4.0, 4.0)
        }
    }
    /// A node setting: mostly in its useful range, sometimes at or past its clamps.
    fn setting(&mut self, lo: f32, hi: f32, specials: &[f32]) -> f32 {
        if self.u64().is_multiple_of(4) {
            self.pick(specials)
        } else {
            self.range(lo, hi)
        }
    }
}

/// Same bits, or both NaN (a NaN's payload is not part of any node's meaning).
fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[track_caller]
fn check(what: &str, new: &[f32], old: &[f32], input: &dyn std::fmt::Debug) {
    assert_eq!(new.len(), old.len());
    for (i, (a, b)) in new.iter().zip(old).enumerate() {
        assert!(
            same(*a, *b),
            "{what}[{i}]: new {a:e} ({:#010x}) != old {b:e} ({:#010x}) for {input:?}",
            a.to_bits(),
            b.to_bits()
        );
    }
}

#[test]
fn cell_hashes_and_white_noise_match_the_old_code() {
    let mut r = Rng(0x9e37_79b9_7f4a_7c15);
    for _ in 0..200_000 {
        let v = r.vec4();
        let k1 = v[0];
        let k2 = [v[0], v[1]];
        let k3 = [v[0], v[1], v[2]];
        check(
            "hash_f1_to_f3",
            &white_noise::hash_f1_to_f3(k1),
            &old::white_noise::hash_f1_to_f3(k1),
            &v,
        );
        check(
            "hash_f2_to_f2",
            &white_noise::hash_f2_to_f2(k2),
            &old::white_noise::hash_f2_to_f2(k2),
            &v,
        );
        check(
            "hash_f2_to_f3",
            &white_noise::hash_f2_to_f3(k2),
            &old::white_noise::hash_f2_to_f3(k2),
            &v,
        );
        check(
            "hash_f3_to_f3",
            &white_noise::hash_f3_to_f3(k3),
            &old::white_noise::hash_f3_to_f3(k3),
            &v,
        );
        check(
            "hash_f4_to_f4",
            &white_noise::hash_f4_to_f4(v),
            &old::white_noise::hash_f4_to_f4(v),
            &v,
        );
        check(
            "hash_f4_to_f3",
            &white_noise::hash_f4_to_f3(v),
            &old::white_noise::hash_f4_to_f3(v),
            &v,
        );
        for dims in 1..=4 {
            let (f, c) = white_noise::white_noise(dims, k3, v[3]);
            let (of, oc) = old::white_noise::white_noise(dims, k3, v[3]);
            check(
                "white_noise",
                &[f, c[0], c[1], c[2]],
                &[of, oc[0], oc[1], oc[2]],
                &(dims, v),
            );
        }
    }
}

fn voronoi_case(r: &mut Rng) -> (voronoi::VoronoiParams, old::voronoi::VoronoiParams, String) {
    use voronoi::{VoronoiFeature, VoronoiMetric};
    let feature = r.pick(VoronoiFeature::ALL);
    let metric = r.pick(VoronoiMetric::ALL);
    let normalize = r.u64().is_multiple_of(2);
    let scale = r.setting(-5.0, 30.0, &[0.0, 1.0, 5.0, 21.8, -1.0]);
    // Fractal octaves multiply the cost; most cases keep to one or two.
    let detail = if r.u64().is_multiple_of(8) {
        r.setting(0.0, 15.0, &[15.0, 16.0, 2.5])
    } else {
        r.setting(0.0, 2.0, &[0.0, 1.0, -1.0, 0.5])
    };
    let roughness = r.setting(0.0, 1.0, &[0.0, 1.0, -0.5, 1.5]);
    let lacunarity = r.setting(0.0, 4.0, &[0.0, 1.0, 2.0, -1.0]);
    let smoothness = r.setting(0.0, 1.0, &[0.0, 1.0, 2.0, -1.0, 1e-6]);
    let exponent = r.setting(0.1, 4.0, &[0.5, 1.0, 2.0, 0.0, -1.0]);
    let randomness = r.setting(0.0, 1.0, &[0.0, 1.0, 1.5, -0.5]);
    let args = (
        feature, metric, normalize, scale, detail, roughness, lacunarity, smoothness, exponent,
        randomness,
    );
    let new = voronoi::VoronoiParams::new(
        feature, metric, normalize, scale, detail, roughness, lacunarity, smoothness, exponent,
        randomness,
    );
    let old = old::voronoi::VoronoiParams::new(
        feature, metric, normalize, scale, detail, roughness, lacunarity, smoothness, exponent,
        randomness,
    );
    (new, old, format!("{args:?}"))
}

fn voronoi_outputs(o: voronoi::VoronoiOutput) -> [f32; 9] {
    [
        o.distance,
        o.color[0],
        o.color[1],
        o.color[2],
        o.position[0],
        o.position[1],
        o.position[2],
        o.w,
        o.radius,
    ]
}
fn old_voronoi_outputs(o: old::voronoi::VoronoiOutput) -> [f32; 9] {
    [
        o.distance,
        o.color[0],
        o.color[1],
        o.color[2],
        o.position[0],
        o.position[1],
        o.position[2],
        o.w,
        o.radius,
    ]
}

#[test]
fn voronoi_matches_the_old_code_for_every_feature_metric_and_dimension() {
    let mut r = Rng(0x0123_4567_89ab_cdef);
    for i in 0..60_000 {
        let (new, old, args) = voronoi_case(&mut r);
        let dims = (i % 4 + 1) as u8;
        let (v, w) = if r.u64().is_multiple_of(4) {
            (r.vec3(), r.coord())
        } else {
            ([r.near(), r.near(), r.near()], r.near())
        };
        let a = voronoi_outputs(voronoi::voronoi_texture(dims, v, w, new));
        let b = old_voronoi_outputs(old::voronoi::voronoi_texture(dims, v, w, old));
        check("voronoi_texture", &a, &b, &(dims, v, w, &args));
    }
}

/// Exact distance ties between lattice points (randomness 0, integer and half-integer
/// coordinates) decide which cell wins: the visiting order must not change.
#[test]
fn voronoi_ties_match_the_old_code() {
    use voronoi::{VoronoiFeature, VoronoiMetric};
    let mut r = Rng(42);
    for i in 0..40_000 {
        let dims = (i % 4 + 1) as u8;
        let feature = r.pick(VoronoiFeature::ALL);
        let metric = r.pick(VoronoiMetric::ALL);
        let randomness = r.pick(&[0.0, 0.0, 1.0, 0.5]);
        let smoothness = r.pick(&[0.0, 1.0, 0.25]);
        let new = voronoi::VoronoiParams::new(
            feature, metric, false, 1.0, 0.0, 0.5, 2.0, smoothness, 1.0, randomness,
        );
        let old = old::voronoi::VoronoiParams::new(
            feature, metric, false, 1.0, 0.0, 0.5, 2.0, smoothness, 1.0, randomness,
        );
        let mut c = || (r.range(-6.0, 6.0) * 2.0).round() / 2.0;
        let (v, w) = ([c(), c(), c()], c());
        let a = voronoi_outputs(voronoi::voronoi_texture(dims, v, w, new));
        let b = old_voronoi_outputs(old::voronoi::voronoi_texture(dims, v, w, old));
        check(
            "voronoi_texture (ties)",
            &a,
            &b,
            &(dims, v, w, feature, metric, randomness, smoothness),
        );
    }
}

fn noise_params(r: &mut Rng) -> noise::NoiseParams {
    use noise::NoiseType::*;
    noise::NoiseParams {
        kind: r.pick(&[
            MultiFractal,
            Fbm,
            HybridMultiFractal,
            RidgedMultiFractal,
            HeteroTerrain,
        ]),
        normalize: r.u64().is_multiple_of(2),
        detail: if r.u64().is_multiple_of(4) {
            r.setting(0.0, 16.0, &[15.0, 16.0, 10.689_58])
        } else {
            r.setting(0.0, 4.0, &[0.0, 1.0, 2.0, -1.0])
        },
        roughness: r.setting(0.0, 1.0, &[0.0, 0.5, 1.0, -0.5]),
        lacunarity: r.setting(0.0, 4.0, &[2.0, 1.0, 0.0]),
        offset: r.setting(-1.0, 2.0, &[0.0, 1.0]),
        gain: r.setting(0.0, 3.0, &[1.0, 0.0]),
        distortion: r.setting(-2.0, 4.0, &[0.0, 0.0, 1.0]),
    }
}

#[test]
fn noise_texture_matches_the_old_code_in_both_flavours() {
    let mut r = Rng(0xfeed_f00d);
    for i in 0..60_000 {
        let params = noise_params(&mut r);
        let dims = (i % 4 + 1) as u8;
        let (v, w) = if r.u64().is_multiple_of(4) {
            (r.vec3(), r.coord())
        } else {
            ([r.near(), r.near(), r.near()], r.near())
        };
        let scale = r.setting(0.0, 30.0, &[0.0, 1.0, 11.438_896, -2.0]);
        let (f, c) = noise::noise_texture_cycles(dims, v, w, scale, params);
        let (of, oc) = old::noise::noise_texture_cycles(dims, v, w, scale, params);
        check(
            "noise_texture_cycles",
            &[f, c[0], c[1], c[2]],
            &[of, oc[0], oc[1], oc[2]],
            &(dims, v, w, scale, params),
        );
        // Fac alone (Color unlinked) is the same bits as the full node's Fac.
        check(
            "noise_texture_cycles_fac",
            &[noise::noise_texture_cycles_fac(dims, v, w, scale, params)],
            &[of],
            &(dims, v, w, scale, params),
        );
        let want_color = r.u64().is_multiple_of(2);
        let (f, c) = noise::noise_texture(dims, v, w, scale, params, want_color);
        let (of, oc) = old::noise::noise_texture(dims, v, w, scale, params, want_color);
        check(
            "noise_texture",
            &[f, c[0], c[1], c[2], c[3]],
            &[of, oc[0], oc[1], oc[2], oc[3]],
            &(dims, v, w, scale, params, want_color),
        );
    }
}

#[test]
fn perlin_matches_the_old_code_on_every_regime() {
    use noise::{perlin, Cycles};
    let mut r = Rng(7);
    for _ in 0..300_000 {
        let v = r.vec4();
        let (a2, a3) = ([v[0], v[1]], [v[0], v[1], v[2]]);
        let new = [
            perlin(v[0]),
            perlin(a2),
            perlin(a3),
            perlin(v),
            perlin(Cycles(v[0])),
            perlin(Cycles(a2)),
            perlin(Cycles(a3)),
            perlin(Cycles(v)),
        ];
        use old::noise::Cycles as O;
        let old = [
            old::noise::perlin(v[0]),
            old::noise::perlin(a2),
            old::noise::perlin(a3),
            old::noise::perlin(v),
            old::noise::perlin(O(v[0])),
            old::noise::perlin(O(a2)),
            old::noise::perlin(O(a3)),
            old::noise::perlin(O(v)),
        ];
        check("perlin (1-4D, Blender then Cycles)", &new, &old, &v);
    }
}

#[test]
fn wave_matches_the_old_code() {
    use wave::{BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType};
    let mut r = Rng(0xabcdef);
    for _ in 0..100_000 {
        let s = WaveSettings {
            kind: r.pick(WaveType::ALL),
            bands: r.pick(BandsDirection::ALL),
            rings: r.pick(RingsDirection::ALL),
            profile: r.pick(WaveProfile::ALL),
        };
        let v = if r.u64().is_multiple_of(4) {
            r.vec3()
        } else {
            [r.near(), r.near(), r.near()]
        };
        let a = [
            r.setting(0.0, 30.0, &[0.0, 1.0, 19.33]),
            r.setting(-2.0, 8.0, &[0.0, 6.0, 2.0]),
            r.setting(0.0, 6.0, &[0.0, 2.0, 15.0]),
            r.setting(0.0, 3.0, &[1.0, 0.0]),
            r.setting(0.0, 1.0, &[0.5, 0.0, 1.0]),
            r.setting(-3.0, 3.0, &[0.0]),
        ];
        let new = wave::wave(s, v, a[0], a[1], a[2], a[3], a[4], a[5]);
        let old = old::wave::wave(s, v, a[0], a[1], a[2], a[3], a[4], a[5]);
        check("wave", &[new], &[old], &(s, v, a));
    }
}

/// Voronoi settings as the node's sockets give them (before `VoronoiParams::new`).
type VoronoiArgs = (
    voronoi::VoronoiFeature,
    voronoi::VoronoiMetric,
    bool,
    [f32; 7],
);

fn voronoi_args(r: &mut Rng) -> VoronoiArgs {
    use voronoi::{VoronoiFeature, VoronoiMetric};
    (
        r.pick(VoronoiFeature::ALL),
        r.pick(VoronoiMetric::ALL),
        r.u64().is_multiple_of(2),
        [
            r.setting(0.5, 8.0, &[1.0, 5.0]),
            r.setting(0.0, 2.0, &[0.0, 1.0]),
            r.setting(0.0, 1.0, &[0.5]),
            r.setting(1.0, 3.0, &[2.0]),
            r.setting(0.0, 1.0, &[0.0, 1.0]),
            r.setting(0.5, 3.0, &[1.0, 2.0]),
            r.setting(0.0, 1.0, &[0.0, 1.0]),
        ],
    )
}

fn both_voronoi(a: &VoronoiArgs) -> (voronoi::VoronoiParams, old::voronoi::VoronoiParams) {
    let (f, m, n, s) = *a;
    (
        voronoi::VoronoiParams::new(f, m, n, s[0], s[1], s[2], s[3], s[4], s[5], s[6]),
        old::voronoi::VoronoiParams::new(f, m, n, s[0], s[1], s[2], s[3], s[4], s[5], s[6]),
    )
}

/// The per-thread cache of hashed cell blocks returns what new hashing gives: each case
/// evaluates a point, points a differential away (same cells), the point again, and the
/// point with one input changed at a time (every setting, the mode enums, the dimension,
/// w), interleaved so a cache keyed on too little would answer for the wrong input
/// (with the randomness left out of the key, this test fails).
#[test]
fn repeated_and_nearby_voronoi_evaluations_match_the_old_code() {
    use voronoi::{VoronoiFeature, VoronoiMetric};
    let mut r = Rng(0x5eed_cace);
    for i in 0..3_000 {
        let base = voronoi_args(&mut r);
        let dims = (i % 4 + 1) as u8;
        let v = [r.range(-4.0, 4.0), r.range(-4.0, 4.0), r.range(-4.0, 4.0)];
        let w = r.range(-4.0, 4.0);
        let mut runs: Vec<(u8, [f32; 3], f32, VoronoiArgs)> = vec![(dims, v, w, base)];
        for d in [1e-4f32, -2e-4, 3e-5] {
            runs.push((dims, [v[0] + d, v[1], v[2] - d], w + d, base));
            runs.push((dims, v, w, base));
        }
        for k in 0..7 {
            let mut a = base;
            a.3[k] = match k {
                6 => r.pick(&[0.0, 0.25, 1.0]),
                _ => a.3[k] + r.pick(&[0.5, 1.0, -0.25]),
            };
            runs.push((dims, v, w, a));
            runs.push((dims, v, w, base));
        }
        let other = |f| {
            VoronoiFeature::ALL
                .iter()
                .copied()
                .find(|&x| x != f)
                .unwrap()
        };
        let other_m = |m| {
            VoronoiMetric::ALL
                .iter()
                .copied()
                .find(|&x| x != m)
                .unwrap()
        };
        for a in [
            (other(base.0), base.1, base.2, base.3),
            (base.0, other_m(base.1), base.2, base.3),
            (base.0, base.1, !base.2, base.3),
        ] {
            runs.push((dims, v, w, a));
            runs.push((dims, v, w, base));
        }
        runs.push((dims % 4 + 1, v, w, base));
        runs.push((dims, v, w + 0.5, base));
        runs.push((dims, v, w, base));
        for (dims, v, w, a) in runs {
            let (new, old) = both_voronoi(&a);
            let x = voronoi_outputs(voronoi::voronoi_texture(dims, v, w, new));
            let y = old_voronoi_outputs(old::voronoi::voronoi_texture(dims, v, w, old));
            check("voronoi_texture (repeated)", &x, &y, &(dims, v, w, a));
        }
    }
}
