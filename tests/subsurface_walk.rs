//! The random walk's own rules, as Cycles 4.5's `subsurface_random_walk` and
//! `subsurface_entry_bounce` have them (kernel/integrator/subsurface_random_walk.h,
//! subsurface.h), checked on a walk against a mock surface: at most 256 steps, the first
//! ray ignoring the entry triangle instead of starting off the surface, no length but the
//! radius, and which method enters through a diffuse bounce.

use blendsynth::render::math::{dot, V3};
use blendsynth::render::subsurface::{
    entry_direction, random_walk, setup, Bssrdf, LocalTrace, Method,
};

/// Random numbers for step `bounce` of walk `seed` (a fixed hash: the test is
/// deterministic).
fn numbers(seed: u32, bounce: u32) -> [f32; 8] {
    let mut x = seed
        .wrapping_mul(0x9E37_79B9)
        .wrapping_add(bounce.wrapping_mul(0x85EB_CA6B))
        ^ 0x27d4_eb2f;
    [0; 8].map(|_| {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        (x >> 8) as f32 / (1u32 << 24) as f32
    })
}

fn bssrdf(radius: f32, albedo: f32, roughness: f32, method: Method) -> Bssrdf {
    let (b, _, _) = setup(
        [albedo; 3],
        [radius, radius * 0.5, radius * 0.25],
        [albedo; 3],
        0.0,
        1.4,
        roughness,
        method,
    );
    b.expect("a usable radius").0
}

/// Open space: no surface to leave through. Counts the rays.
struct Nothing(u32);

impl LocalTrace for Nothing {
    fn local_hit(
        &mut self,
        _: V3,
        _: V3,
        _: f32,
        _: u32,
        _: Option<u32>,
    ) -> Option<(f32, u32, f32, f32)> {
        self.0 += 1;
        None
    }
}

#[test]
fn a_walk_that_never_meets_the_surface_ends_after_256_steps() {
    // Albedo near one: the throughput stays far above Cycles' 1e-6 cut, so only the step
    // limit ends the walk (1024 steps before issue 32, which let walks that wandered away
    // from an open surface come back).
    let b = bssrdf(1.0, 0.98, 0.5, Method::RandomWalk);
    for seed in 0..8 {
        let mut trace = Nothing(0);
        let mut tp = [1.0; 3];
        let exit = random_walk(
            &b,
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            0,
            7,
            &mut tp,
            &mut trace,
            &|i| numbers(seed, i),
        );
        assert!(exit.is_none());
        assert_eq!(trace.0, 256, "seed {seed}: rays cast");
    }
}

/// The plane z = 0 (triangle 7 of instance 0), seen from both sides. Records the `skip`
/// argument of each ray.
struct Plane(Vec<Option<u32>>);

impl LocalTrace for Plane {
    fn local_hit(
        &mut self,
        org: V3,
        dir: V3,
        tmax: f32,
        _: u32,
        skip: Option<u32>,
    ) -> Option<(f32, u32, f32, f32)> {
        self.0.push(skip);
        if skip == Some(7) || dir[2] == 0.0 {
            return None;
        }
        let t = -org[2] / dir[2];
        (t > 0.0 && t < tmax).then_some((t, 7, 0.25, 0.25))
    }
}

#[test]
fn the_walk_has_no_length_scale_but_the_radius() {
    // The same walks (same random numbers) under a single-sided plane with the radius at
    // 1 mm and at 1 km: the same weights, directions and step counts.
    for seed in 0..64 {
        let run = |k: f32| {
            let b = bssrdf(1e-3 * k, 0.8, 0.5, Method::RandomWalk);
            let mut trace = Plane(Vec::new());
            let mut tp = [1.0; 3];
            let exit = random_walk(
                &b,
                [0.0; 3],
                [0.0, 0.0, 1.0],
                [0.6, 0.0, -0.8],
                0,
                7,
                &mut tp,
                &mut trace,
                &|i| numbers(seed, i),
            );
            (exit.map(|e| e.dir), tp, trace.0)
        };
        let (d1, t1, s1) = run(1.0);
        let (d2, t2, s2) = run(1e6);
        assert_eq!(d1.is_some(), d2.is_some(), "seed {seed}");
        if let (Some(a), Some(b)) = (d1, d2) {
            assert!(dot(a, b) > 0.9999, "seed {seed}: {a:?} vs {b:?}");
            for c in 0..3 {
                let rel = (t1[c] - t2[c]).abs() / t1[c].abs().max(1e-12);
                assert!(rel < 1e-3, "seed {seed}: throughput {t1:?} vs {t2:?}");
            }
        }
        assert_eq!(s1.len(), s2.len(), "seed {seed}: steps");
        // Only the first ray, which starts on the entry triangle, passes through it.
        assert_eq!(s1[0], Some(7));
        assert!(s1[1..].iter().all(|s| s.is_none()), "seed {seed}: {s1:?}");
    }
}

fn entries(b: &Bssrdf) -> Vec<V3> {
    let n = [0.0, 0.0, 1.0];
    let v = [0.6, 0.0, 0.8];
    let mut out = Vec::new();
    for i in 0..16 {
        for j in 0..16 {
            let u = [(i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0];
            out.extend(entry_direction(b, n, v, u));
        }
    }
    out
}

#[test]
fn only_random_walk_skin_enters_through_a_diffuse_bounce() {
    // Plain Random Walk: the closure's roughness (0 here), every entry refracted, so all
    // go one way. Random Walk (Skin): roughness fixed at one and half the entries diffuse
    // (cosine about the inward normal). Swapped before issue 32.
    let plain = bssrdf(1.0, 0.8, 0.0, Method::RandomWalk);
    assert_eq!(plain.alpha, 0.0);
    let d = entries(&plain);
    assert_eq!(d.len(), 256);
    assert!(
        d.iter().all(|x| dot(*x, d[0]) > 0.999),
        "plain entries spread"
    );
    let skin = bssrdf(1.0, 0.8, 0.0, Method::RandomWalkSkin);
    assert_eq!(skin.alpha, 1.0);
    let d = entries(&skin);
    assert_eq!(d.len(), 256);
    assert!(d.iter().all(|x| x[2] < 0.0), "entries go into the surface");
    // Spread over the hemisphere, unlike the plain method's smooth refraction.
    let nearest = d.iter().map(|x| dot(*x, d[0])).fold(1.0f32, f32::min);
    assert!(
        nearest < 0.5,
        "skin entries within {nearest} of one direction"
    );
}

#[test]
fn the_walks_two_dimension_draws_are_get4s_first_two() {
    // The walk draws only the first two dimensions of each bounce's second set (`get2`):
    // they must be `get4`'s bits, or the walk would change.
    use blendsynth::render::sampler::PixelSampler;
    for (x, y, seed) in [(0, 0, 0), (3, 5, 7), (127, 64, 0x9e37_79b9)] {
        let s = PixelSampler::new(x, y, seed);
        for index in [0, 1, 2, 63, 1000, u32::MAX] {
            for set in [0, 5, 17, 0x8000_0001] {
                let a = s.get4(index, set);
                let b = s.get2(index, set);
                assert_eq!(
                    [a[0].to_bits(), a[1].to_bits()],
                    [b[0].to_bits(), b[1].to_bits()]
                );
            }
        }
    }
}
