//! Properties the closures must have whatever the scene: sampling agrees with
//! evaluation (same value and pdf), and the energy-preserving closures keep a white
//! furnace white (Cycles' Multiscatter GGX glass and its Oren-Nayar both promise this).

use blendsynth::render::bsdf::microfacet::{glass_closure, Dielectric, Distribution};
use blendsynth::render::bsdf::oren_nayar::OrenNayar;
use blendsynth::render::bsdf::tables::Tables;
use blendsynth::render::math::{vec3, Vec3};
use blendsynth::render::sampler::PixelSampler;

fn view(mu: f32) -> Vec3 {
    vec3((1.0 - mu * mu).sqrt(), 0.0, mu)
}

const N: Vec3 = Vec3::Z;

#[test]
fn rough_glass_sample_matches_eval() {
    let s = PixelSampler::new(3, 5, 7);
    for dist in [Distribution::Ggx, Distribution::Beckmann] {
        for eta in [1.5f32, 1.0 / 1.5] {
            let g = Dielectric {
                dist,
                alpha: 0.3,
                eta,
                refract_only: false,
                tint_r: [1.0; 3],
                tint_t: [1.0; 3],
                energy: 1.0,
                film: None,
            };
            let v = view(0.6);
            let mut checked = 0;
            for i in 0..2000 {
                let u = s.get4(i, 0);
                let Some(ds) = g.sample(N, v, N, [u[0], u[1], u[2]]) else {
                    continue;
                };
                let (f, pdf) = g.eval(N, v, ds.l, N);
                assert!(!ds.singular);
                let rel = (pdf - ds.pdf).abs() / pdf.max(1e-6);
                assert!(
                    rel < 2e-3,
                    "{dist:?} eta {eta}: pdf {pdf} vs sampled {}",
                    ds.pdf
                );
                let w = f[0] / pdf;
                assert!(
                    (w - ds.weight[0]).abs() <= 2e-3 * w.max(1.0),
                    "{dist:?} eta {eta}: weight {w} vs {}",
                    ds.weight[0]
                );
                checked += 1;
            }
            assert!(
                checked > 1500,
                "{dist:?} eta {eta}: only {checked} valid samples"
            );
        }
    }
}

/// Mean sampled weight of Multiscatter GGX glass: one (all light reflected or refracted).
#[test]
fn multiscatter_glass_is_white() {
    let tables = Tables::shared();
    let s = PixelSampler::new(9, 4, 2);
    // Light entering glass only: for light leaving it Cycles' table (ggx_glass_inv_E)
    // counts refractions that leave on the wrong side, so its glass is not white there
    // either (about 3% dark at roughness 0.5, cos 0.3); glass_albedo_tables_match_cycles
    // checks that table instead.
    for (rough, ior, backfacing) in [
        (0.3f32, 1.5f32, false),
        (0.7, 1.45, false),
        (0.5, 1.33, false),
    ] {
        for mu in [0.3f32, 0.8] {
            let g = glass_closure(tables, Some("MULTI_GGX"), false, rough, ior, backfacing, mu);
            let v = view(mu);
            let n = 20000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let u = s.get4(i, 1);
                if let Some(ds) = g.sample(N, v, N, [u[0], u[1], u[2]]) {
                    sum += ds.weight[0] as f64;
                }
            }
            let e = sum / n as f64;
            assert!(
                (e - 1.0).abs() < 0.03,
                "roughness {rough} ior {ior} back {backfacing} mu {mu}: albedo {e}"
            );
        }
    }
    // Plain GGX glass (single scattering) loses energy at this roughness.
    let g = glass_closure(tables, Some("GGX"), false, 0.7, 1.45, false, 0.3);
    let n = 20000;
    let sum: f64 = (0..n)
        .filter_map(|i| {
            let u = s.get4(i, 3);
            g.sample(N, view(0.3), N, [u[0], u[1], u[2]])
                .map(|ds| ds.weight[0] as f64)
        })
        .sum();
    assert!(
        sum / (n as f64) < 0.97,
        "single-scattering GGX glass albedo {}",
        sum / n as f64
    );
}

/// Oren-Nayar of white albedo reflects everything (energy-preserving multiscatter term).
#[test]
fn oren_nayar_white_furnace() {
    let s = PixelSampler::new(1, 2, 3);
    for rough in [0.3f32, 1.0] {
        for mu in [0.2f32, 0.9] {
            let v = view(mu);
            let on = OrenNayar::new(rough, [1.0; 3], mu);
            let n = 20000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let u = s.get4(i, 2);
                // Cosine-weighted direction: weight = eval / (cos / pi).
                let r = u[0].sqrt();
                let phi = 2.0 * std::f32::consts::PI * u[1];
                let l = vec3(r * phi.cos(), r * phi.sin(), (1.0 - u[0]).sqrt());
                let f = on.eval(N, v, l)[0];
                sum += (f / (l[2] / std::f32::consts::PI)) as f64;
            }
            let e = sum / n as f64;
            assert!(
                (e - 1.0).abs() < 0.02,
                "roughness {rough} mu {mu}: albedo {e}"
            );
        }
    }
    // And single scattering alone loses energy at high roughness (the term matters).
    let on = OrenNayar::new(1.0, [0.0; 3], 0.5);
    let l = vec3(0.3, 0.2, 0.9).normalize();
    let (t, b) = N.basis();
    assert!(t.dot(b).abs() < 1e-6);
    assert!(
        on.eval(N, view(0.5), l)[0] < OrenNayar::new(1.0, [1.0; 3], 0.5).eval(N, view(0.5), l)[0]
    );
}

/// Cycles' albedo tables, read from bpy's library by fixtures/render/cycles_albedo_tables.py.
fn cycles_tables() -> serde_json::Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/render/cycles_albedo_tables.json");
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Our integrated GGX albedo table (Fresnel one) and its cosine-weighted mean against
/// Cycles' ggx_E and ggx_Eavg, which Multiscatter GGX reflection scales by.
#[test]
fn ggx_albedo_tables_match_cycles() {
    let v = cycles_tables();
    let tables = Tables::shared();
    let (mut worst, mut at, mut sum) = (0.0f32, String::new(), 0.0f64);
    for (i, row) in v["tables"]["ggx_E"].as_array().unwrap().iter().enumerate() {
        for (j, c) in row.as_array().unwrap().iter().enumerate() {
            let c = c.as_f64().unwrap() as f32;
            let ours = tables.ggx_e(i as f32 / 31.0, j as f32 / 31.0);
            let d = (ours - c).abs();
            sum += d as f64;
            if d > worst {
                worst = d;
                at = format!("cos {i}/31 roughness {j}/31: ours {ours}, Cycles {c}");
            }
        }
    }
    let mean = sum / 1024.0;
    eprintln!("ggx_E: worst {worst:.5} ({at}), mean {mean:.6}");
    assert!(
        worst < 0.0025 && mean < 3e-4,
        "ggx_E: worst {worst} at {at}, mean {mean}"
    );
    for (j, c) in v["tables"]["ggx_Eavg"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let c = c.as_f64().unwrap() as f32;
        let ours = tables.ggx_e_avg(j as f32 / 31.0);
        assert!(
            (ours - c).abs() < 1e-3,
            "ggx_Eavg at roughness {j}/31: ours {ours}, Cycles {c}"
        );
    }
}

/// Our integrated glass albedo tables (render/bsdf/tables.rs) against Cycles' own: light
/// entering glass (ggx_glass_E) and leaving it (ggx_glass_inv_E), at each grid point of
/// the slices kept.
#[test]
fn glass_albedo_tables_match_cycles() {
    let v = cycles_tables();
    let slices: Vec<usize> = v["slices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_u64().unwrap() as usize)
        .collect();
    let tables = Tables::shared();
    for (name, leaving) in [("glass_E", false), ("glass_inv_E", true)] {
        let t = v["tables"][name].as_array().unwrap();
        let (mut worst, mut at, mut sum, mut n) = (0.0f32, String::new(), 0.0f64, 0);
        for (k, &zi) in slices.iter().enumerate() {
            // The IOR whose lookup lands exactly on slice zi (the last slice is looked up
            // at z = 1, however large the IOR).
            let z = zi as f32 / 15.0;
            let ior = if zi == 15 {
                1e6
            } else {
                (1.0 + z * z) / (1.0 - z * z)
            };
            let eta = if leaving { 1.0 / ior } else { ior };
            for (i, row) in t[k].as_array().unwrap().iter().enumerate() {
                for (j, c) in row.as_array().unwrap().iter().enumerate() {
                    let c = c.as_f64().unwrap() as f32;
                    let ours = tables.glass_e(i as f32 / 15.0, j as f32 / 15.0, eta);
                    let d = (ours - c).abs();
                    sum += d as f64;
                    n += 1;
                    if d > worst {
                        worst = d;
                        at = format!(
                            "slice {zi} cos {i}/15 roughness {j}/15: ours {ours}, Cycles {c}"
                        );
                    }
                }
            }
        }
        let mean = sum / n as f64;
        eprintln!("{name}: worst {worst:.5} ({at}), mean {mean:.6}");
        assert!(
            worst < 0.005 && mean < 6e-4,
            "{name}: worst {worst} at {at}, mean {mean}"
        );
    }
}

/// The albedo tables the renderer embeds (src/render/bsdf/tables.bin) are the bits this
/// code integrates, so embedding them changes no image. After a change to the tables'
/// integration, rewrite them with
/// `BLENDSYNTH_UPDATE_TABLES=1 cargo test --release --test closures embedded`.
#[test]
fn embedded_albedo_tables_are_the_integrated_ones() {
    let integrated = Tables::new().to_le_bytes();
    if std::env::var_os("BLENDSYNTH_UPDATE_TABLES").is_some() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/render/bsdf/tables.bin");
        std::fs::write(path, &integrated).unwrap();
        return;
    }
    assert!(
        integrated == blendsynth::render::bsdf::tables::EMBEDDED,
        "src/render/bsdf/tables.bin is not what the code integrates: rewrite it with \
         BLENDSYNTH_UPDATE_TABLES=1 cargo test --release --test closures embedded"
    );
    // The round trip gives back the same tables.
    let back = Tables::from_le_bytes(&integrated).unwrap();
    assert!(back.to_le_bytes() == integrated);
    assert!(Tables::from_le_bytes(&integrated[4..]).is_none());
}
