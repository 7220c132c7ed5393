//! Every ray acceleration backend renders the same image, bit for bit: the CLI renders
//! fixture scenes with `BLENDSYNTH_ACCEL=bvh2` (binary BVH), `bvh4` (4-wide BVH) and
//! `embree` (where `libembree3.so.3` loads; required in CI, which installs it with
//! `.ci/embree.sh`) and the EXRs must be byte-identical. Subsurface (many short walk
//! rays), depth of field, a light with soft shadows, object visibility, a holdout,
//! motion blur and Geometry Nodes instances cover the query kinds (nearest hit,
//! occlusion, visibility masks).

mod common;

/// The backends to compare: the two BVHs, and Embree where it loads (in CI it must).
fn backends() -> Vec<&'static str> {
    let mut v = vec!["bvh2", "bvh4"];
    match Backend::parse("embree") {
        Ok(_) => v.push("embree"),
        Err(e) => {
            assert!(
                !common::in_ci(),
                "Embree is required in CI (CI=true; .ci/embree.sh installs it): {e}"
            );
            eprintln!("SKIPPED Embree: {e}");
        }
    }
    v
}

/// `scene` is a folder under `fixtures/`.
fn render(scene: &str, backend: &str, out: &std::path::Path) -> Vec<u8> {
    let dir = common::repo().join("fixtures").join(scene);
    let o = common::run(
        &[
            "render",
            dir.to_str().unwrap(),
            "--samples",
            "4",
            "--resolution",
            "40x40",
            "--threshold",
            "0",
            "--denoise",
            "off",
            "-o",
            out.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_ACCEL", backend)],
    );
    assert!(
        o.status.success(),
        "{scene} with {backend}: {}",
        common::stderr(&o)
    );
    std::fs::read(out).unwrap()
}

#[test]
fn every_backend_renders_identical_images() {
    let tmp = tempfile::tempdir().unwrap();
    let backends = backends();
    for scene in [
        "render/scenes/sss_principled",
        "render/scenes/sss_rw_tube_3cm",
        "render/scenes/dof",
        "render/scenes/area_glossy_mis",
        "render/scenes/object_visibility",
        "render/scenes/holdout_object",
        "render/scenes/motion_blur",
        "render/scenes/object_motion",
        "scenes/geonodes",
    ] {
        let name = scene.replace('/', "_");
        let a = render(scene, "bvh2", &tmp.path().join(format!("{name}_bvh2.exr")));
        for b in &backends[1..] {
            let img = render(scene, b, &tmp.path().join(format!("{name}_{b}.exr")));
            assert!(a == img, "{scene}: bvh2 and {b} images differ");
        }
    }
}

#[test]
fn an_unknown_backend_is_refused_by_name() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = common::repo().join("fixtures/render/scenes/dof");
    let out = tmp.path().join("x.exr");
    let o = common::run(
        &[
            "render",
            dir.to_str().unwrap(),
            "--samples",
            "1",
            "--resolution",
            "8x8",
            "-o",
            out.to_str().unwrap(),
        ],
        &[("BLENDSYNTH_ACCEL", "optix")],
    );
    assert!(!o.status.success());
    let e = common::stderr(&o);
    assert!(e.contains("BLENDSYNTH_ACCEL") && e.contains("optix"), "{e}");
    assert!(!out.exists(), "no output on an error");
}

use blendsynth::foundation::bvh::{visibility, Accel, Backend, Bvh, Hit};
use blendsynth::foundation::bvh4::Bvh4;
use blendsynth::foundation::embree::EmbreeAccel;
use blendsynth::foundation::math::V3;

/// A fixed-seed generator (no dependence on a random draw).
struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn grid_z(x: f32, y: f32) -> f32 {
    0.05 * ((x * 9.0).sin() + (y * 7.0).cos())
}

/// A bumpy n x n grid of quads (shared edges and vertices everywhere) and a soup of
/// random triangles crossing it.
fn scene(n: usize, soup: usize, rng: &mut Lcg) -> Vec<[V3; 3]> {
    let p = |i: usize, j: usize| {
        let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
        [x, y, grid_z(x, y)]
    };
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    for _ in 0..soup {
        let c = [rng.f(), rng.f(), rng.f() * 0.4 - 0.2];
        let mut t = [[0.0; 3]; 3];
        for v in &mut t {
            *v = [
                c[0] + 0.1 * (rng.f() - 0.5),
                c[1] + 0.1 * (rng.f() - 0.5),
                c[2] + 0.1 * (rng.f() - 0.5),
            ];
        }
        tris.push(t);
    }
    tris
}

fn same(a: Option<Hit>, b: Option<Hit>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            a.prim == b.prim
                && a.t.to_bits() == b.t.to_bits()
                && a.u.to_bits() == b.u.to_bits()
                && a.v.to_bits() == b.v.to_bits()
        }
        _ => false,
    }
}

/// Every query of the wide BVH and of Embree (where it loads) returns exactly the binary
/// BVH's hit: rays aimed at the
/// grid's shared vertices and edges (where two or more triangles tie at the same
/// distance, so the visiting order would pick one if the tie rule, least triangle index,
/// did not), random rays, with visibility masks and finite ranges.
#[test]
fn every_backend_returns_the_binary_bvh_hits() {
    let mut rng = Lcg(7);
    let n = 24;
    let tris = scene(n, 600, &mut rng);
    let masks: Vec<u32> = (0..tris.len())
        .map(|i| {
            if i % 7 == 3 {
                visibility::ALL & !visibility::SHADOW
            } else {
                visibility::ALL
            }
        })
        .collect();
    let bin = Bvh::build_masked(&tris, &masks);
    let wide = Bvh4::build_masked(&tris, &masks);
    let embree = backends()
        .contains(&"embree")
        .then(|| EmbreeAccel::build_masked(&tris, &masks).unwrap());
    // One structure per triangle, to find ties by brute force.
    let singles: Vec<Bvh> = tris.iter().map(|t| Bvh::build(&[*t])).collect();
    let mut ties = 0;
    for k in 0..20_000 {
        let target = if k % 2 == 0 {
            // A grid vertex or an edge midpoint.
            let (i, j) = ((k / 2) % (n + 1), (k / 2 / (n + 1)) % (n + 1));
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            let x = if k % 4 == 0 { x } else { x + 0.5 / n as f32 };
            [x, y, grid_z(x, y)]
        } else {
            [rng.f(), rng.f(), rng.f() * 0.3 - 0.15]
        };
        let org = [
            rng.f() * 3.0 - 1.0,
            rng.f() * 3.0 - 1.0,
            if k % 3 == 0 { -1.5 } else { 1.5 },
        ];
        let dir = [target[0] - org[0], target[1] - org[1], target[2] - org[2]];
        let (tmin, tmax) = if k % 5 == 0 {
            (0.0, 0.9)
        } else {
            (1e-4, f32::INFINITY)
        };
        let mask = if k % 2 == 0 {
            visibility::ALL
        } else {
            visibility::SHADOW
        };
        let a = bin.intersect_or_occluded::<false>(org, dir, tmin, tmax, mask);
        let b = wide.intersect_or_occluded::<false>(org, dir, tmin, tmax, mask);
        assert!(same(a, b), "ray {k}: binary {a:?}, wide {b:?}");
        assert_eq!(
            bin.occluded_vis(org, dir, tmin, tmax, 0.5, mask),
            wide.occluded_vis(org, dir, tmin, tmax, 0.5, mask),
            "ray {k} occlusion"
        );
        if let Some(e) = &embree {
            let c = e.intersect_vis(org, dir, tmin, tmax, 0.5, mask);
            assert!(same(a, c), "ray {k}: binary {a:?}, Embree {c:?}");
            assert_eq!(
                bin.occluded_vis(org, dir, tmin, tmax, 0.5, mask),
                e.occluded_vis(org, dir, tmin, tmax, 0.5, mask),
                "ray {k} occlusion (Embree)"
            );
        }
        if k < 3000 && mask == visibility::ALL {
            if let Some(h) = a {
                let tied = singles.iter().enumerate().any(|(i, s)| {
                    i as u32 != h.prim
                        && s.intersect(org, dir, tmin, tmax)
                            .is_some_and(|o| o.t == h.t)
                });
                ties += tied as usize;
            }
        }
    }
    // The test means something only if ties occur.
    assert!(ties > 100, "only {ties} ties");
}

#[test]
fn wide_bvh_small_and_empty_scenes() {
    let one = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
    let w = Bvh4::build(&one);
    let h = w
        .intersect([0.2, 0.2, 1.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY)
        .unwrap();
    assert_eq!(h.prim, 0);
    assert!(w
        .intersect([2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY)
        .is_none());
    let empty = Bvh4::build(&[]);
    assert!(empty
        .intersect([0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY)
        .is_none());
    assert!(!empty.occluded([0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY));
}

#[test]
fn backend_names() {
    assert_eq!(Backend::parse("bvh2"), Ok(Backend::Binary));
    assert_eq!(Backend::parse("bvh4"), Ok(Backend::Wide4));
    assert_eq!(Backend::parse(""), Ok(Backend::DEFAULT));
    let e = Backend::parse("optix").unwrap_err();
    assert!(e.contains("BLENDSYNTH_ACCEL") && e.contains("optix"), "{e}");
    // Embree is a backend where its library loads, and otherwise an error naming it.
    match Backend::parse("embree") {
        Ok(b) => assert_eq!(b, Backend::Embree),
        Err(e) => assert!(
            e.contains("BLENDSYNTH_ACCEL=embree") && e.contains("libembree3.so.3"),
            "{e}"
        ),
    }
}

/// Embree's small cases: one triangle, a miss, and an empty scene.
#[test]
fn embree_small_and_empty_scenes() {
    if !backends().contains(&"embree") {
        return;
    }
    let one = [[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]];
    let e = EmbreeAccel::build_masked(&one, &[]).unwrap();
    let h = e
        .intersect([0.2, 0.2, 1.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY)
        .unwrap();
    assert_eq!(h.prim, 0);
    assert!(e
        .intersect([2.0, 2.0, 1.0], [0.0, 0.0, -1.0], 0.0, f32::INFINITY)
        .is_none());
    assert!(e.occluded([0.2, 0.2, 1.0], [0.0, 0.0, -1.0], 0.0, 2.0));
    assert!(!e.occluded([0.2, 0.2, 1.0], [0.0, 0.0, -1.0], 0.0, 0.5));
    let empty = EmbreeAccel::build_masked(&[], &[]).unwrap();
    assert!(empty
        .intersect([0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY)
        .is_none());
    assert!(!empty.occluded([0.0; 3], [0.0, 0.0, 1.0], 0.0, f32::INFINITY));
}

/// A triangle with an infinite vertex (never hit by our test) does not hide the finite
/// triangles of its leaf from Embree: its hits are the binary BVH's.
#[test]
fn embree_with_a_non_finite_triangle() {
    if !backends().contains(&"embree") {
        return;
    }
    let mut rng = Lcg(11);
    let mut tris = scene(6, 20, &mut rng);
    tris.push([[0.5, 0.5, 0.0], [f32::INFINITY, 0.5, 0.0], [0.5, 0.6, 0.0]]);
    tris.push([[0.2, 0.2, 0.1], [0.3, f32::NAN, 0.1], [0.2, 0.3, 0.1]]);
    let bin = Bvh::build(&tris);
    let e = EmbreeAccel::build_masked(&tris, &[]).unwrap();
    let mut hits = 0;
    for k in 0..2000 {
        let org = [rng.f() * 2.0 - 0.5, rng.f() * 2.0 - 0.5, 1.5];
        let dir = [rng.f() - 0.5, rng.f() - 0.5, -1.0];
        let a = bin.intersect(org, dir, 0.0, f32::INFINITY);
        let b = e.intersect(org, dir, 0.0, f32::INFINITY);
        assert!(same(a, b), "ray {k}: binary {a:?}, Embree {b:?}");
        hits += a.is_some() as usize;
    }
    assert!(hits > 300, "only {hits} hits");
}
