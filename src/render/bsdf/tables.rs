//! Directional albedo tables of GGX, integrated here and embedded in the binary as
//! integrated (`tables.bin`; Cycles precomputes its own too): E(mu, roughness) with
//! Fresnel one, for multiple-scattering energy compensation, and the dielectric Fresnel
//! average (Cycles' ggx_gen_schlick_ior_s, the Fresnel-weighted albedo over the
//! Fresnel-one albedo, stored as a blend from F0 to 1) for layering Principled's specular
//! and coat over what lies beneath.

use crate::render::bsdf::{f0_from_ior, fresnel_dielectric, ggx_lambda, sample_vndf};
use crate::render::sampler::PixelSampler;
use rayon::prelude::*;

const N1: usize = 32;
const N3: usize = 16;
/// Directions per entry of the GGX albedo table and cosines for its mean. At 256 and a
/// 32-point sum, entries read up to 0.004 off Cycles' ggx_E and the mean up to 0.005 off
/// its ggx_Eavg (tests/closures.rs compares them).
const E_SAMPLES: u32 = 1024;
const EAVG_POINTS: usize = 64;

pub struct Tables {
    ggx_e: Vec<f32>,
    ggx_e_avg: Vec<f32>,
    dielectric_s: Vec<f32>,
    /// Glass albedo E(z, roughness, mu) for eta > 1 and for 1 / eta (Cycles' ggx_glass_E
    /// and ggx_glass_inv_E), for Multiscatter GGX glass: integrated on first use, since
    /// most scenes have no rough glass and the table is the dearest to build.
    glass: std::sync::OnceLock<(Vec<f32>, Vec<f32>)>,
}

/// Means of F * G2/G1 (the single-scattering albedo) and of G2/G1 (the same with Fresnel
/// one) over the same VNDF samples.
fn albedo_parts(mu: f32, alpha: f32, eta: Option<f32>, samples: &[[f32; 2]]) -> (f32, f32) {
    let mu = mu.max(1e-4);
    let v = crate::render::math::vec3((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let a2 = alpha * alpha;
    let mut sum = 0.0f64;
    let mut sum_g = 0.0f64;
    for u in samples {
        let h = sample_vndf(v, alpha, *u);
        let vh = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
        let wi = [
            2.0 * vh * h[0] - v[0],
            2.0 * vh * h[1] - v[1],
            2.0 * vh * h[2] - v[2],
        ];
        if wi[2] <= 0.0 {
            continue;
        }
        let lo = ggx_lambda(mu, a2);
        let li = ggx_lambda(wi[2], a2);
        let g = (1.0 + lo) / (1.0 + lo + li);
        let f = eta.map(|e| fresnel_dielectric(vh, e)).unwrap_or(1.0);
        sum += (g * f) as f64;
        sum_g += g as f64;
    }
    let n = samples.len().max(1) as f64;
    ((sum / n) as f32, (sum_g / n) as f32)
}

/// The first `n` points of the tables' 2D sample pattern, drawn once for every entry.
fn table_samples(n: u32) -> Vec<[f32; 2]> {
    let s = PixelSampler::new(7, 11, 13);
    (0..n)
        .map(|i| {
            let u = s.get4(i, 0);
            [u[0], u[1]]
        })
        .collect()
}

/// A grid roughness as alpha, with Cycles' precompute clamp (roughness 0 is 1e-4: a mirror).
fn rough_to_alpha(r: f32) -> f32 {
    r.max(1e-4).powi(2)
}

/// The IOR of the 3D tables' slice `zi`: z = sqrt(sqrt(F0)) on a uniform grid, as Cycles
/// parametrises its glass and Schlick tables (lookups invert it from the IOR).
fn grid_eta(zi: usize) -> f32 {
    let z = (zi as f32 / (N3 - 1) as f32).max(0.01);
    let r = z * z;
    ((1.0 + r) / (1.0 - r).max(1e-4)).min(1e4)
}

static SHARED: std::sync::OnceLock<Tables> = std::sync::OnceLock::new();

/// `Tables::new()`'s tables as integrated by this code, little-endian f32s in the order
/// of `Tables::to_le_bytes`: integrating them took a third of a second of CPU time in
/// every process (two thirds more with the glass tables), as much as a quarter of a small
/// render. tests/closures.rs checks they are the integration's bits and rewrites them
/// with BLENDSYNTH_UPDATE_TABLES=1.
pub const EMBEDDED: &[u8] = include_bytes!("tables.bin");

const TABLE_LEN: [usize; 5] = [N1 * N1, N1, N3 * N3 * N3, N3 * N3 * N3, N3 * N3 * N3];

impl Tables {
    /// The tables, once per process: the embedded ones, integrated only if those are
    /// missing (a file of another length).
    pub fn shared() -> &'static Tables {
        SHARED.get_or_init(|| Tables::from_le_bytes(EMBEDDED).unwrap_or_default())
    }

    /// Every table (the glass ones integrated if they were not yet) as little-endian f32s:
    /// GGX albedo, its means, the dielectric Fresnel averages, glass, inverse glass.
    pub fn to_le_bytes(&self) -> Vec<u8> {
        let (g, gi) = self.glass();
        [&self.ggx_e, &self.ggx_e_avg, &self.dielectric_s, g, gi]
            .iter()
            .flat_map(|t| t.iter().flat_map(|x| x.to_le_bytes()))
            .collect()
    }

    /// Tables from `to_le_bytes`' bytes; `None` when their length is not the tables'.
    pub fn from_le_bytes(b: &[u8]) -> Option<Tables> {
        if b.len() != TABLE_LEN.iter().sum::<usize>() * 4 {
            return None;
        }
        let mut floats = b
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]));
        let [e, avg, s, g, gi] = TABLE_LEN.map(|n| floats.by_ref().take(n).collect::<Vec<_>>());
        Some(Tables {
            ggx_e: e,
            ggx_e_avg: avg,
            dielectric_s: s,
            glass: std::sync::OnceLock::from((g, gi)),
        })
    }

    /// Integrates the tables, on rayon's threads when called outside its pool (a worker
    /// asking for `shared` while it is built must not be handed its own job). Each row is
    /// a pure function of its grid point, so the bits are the same either way.
    pub fn new() -> Tables {
        let samples = table_samples(E_SAMPLES);
        let parallel = rayon::current_thread_index().is_none();
        let ggx_row = |ri: usize| {
            let alpha = rough_to_alpha(ri as f32 / (N1 - 1) as f32);
            let e: Vec<f32> = (0..N1)
                .map(|mi| albedo_parts(mi as f32 / (N1 - 1) as f32, alpha, None, &samples).0)
                .collect();
            // The cosine-weighted mean 2 * integral of E(mu) mu, by the midpoint rule on
            // its own finer grid: the 32-point table's Riemann sum read up to 0.005 off
            // Cycles' ggx_Eavg at high roughness.
            let mut avg = 0.0f64;
            for k in 0..EAVG_POINTS {
                let mu = (k as f32 + 0.5) / EAVG_POINTS as f32;
                avg += (2.0 * mu * albedo_parts(mu, alpha, None, &samples).0) as f64;
            }
            (e, (avg / EAVG_POINTS as f64) as f32)
        };
        let dielectric_slice = |zi: usize| {
            let eta = grid_eta(zi);
            let f = f0_from_ior(eta);
            let mut out = Vec::with_capacity(N3 * N3);
            for ri in 0..N3 {
                let alpha = rough_to_alpha(ri as f32 / (N3 - 1) as f32);
                for mi in 0..N3 {
                    let mu = mi as f32 / (N3 - 1) as f32;
                    // As Cycles' ggx_gen_schlick_ior_s: the Fresnel-weighted albedo over
                    // the lobe's own (F = 1) albedo, as a blend factor from F0 to 1.
                    // Interpolating this normalised factor keeps the estimate exact at
                    // normal incidence and going to 1 at grazing, where the two albedos
                    // interpolated apart drift (and a near-mirror's masking is not lost).
                    let (gf, g) = albedo_parts(mu, alpha, Some(eta), &samples[..128]);
                    let ratio = if g > 0.0 { gf / g } else { 1.0 };
                    out.push(((ratio - f) / (1.0 - f).max(1e-6)).clamp(0.0, 1.0));
                }
            }
            out
        };
        // Per roughness row: E over mu, and its cosine-weighted mean.
        type GgxRow = (Vec<f32>, f32);
        let (rows, slices): (Vec<GgxRow>, Vec<Vec<f32>>) = if parallel {
            rayon::join(
                || (0..N1).into_par_iter().map(ggx_row).collect(),
                || (0..N3).into_par_iter().map(dielectric_slice).collect(),
            )
        } else {
            (
                (0..N1).map(ggx_row).collect(),
                (0..N3).map(dielectric_slice).collect(),
            )
        };
        let (e_rows, ggx_e_avg): (Vec<Vec<f32>>, Vec<f32>) = rows.into_iter().unzip();
        Tables {
            ggx_e: e_rows.concat(),
            ggx_e_avg,
            dielectric_s: slices.concat(),
            glass: std::sync::OnceLock::new(),
        }
    }

    /// Single-scattering albedo of GGX with Fresnel one; `roughness` = sqrt(alpha).
    pub fn ggx_e(&self, mu: f32, roughness: f32) -> f32 {
        lerp2(&self.ggx_e, N1, roughness, mu)
    }

    pub fn ggx_e_avg(&self, roughness: f32) -> f32 {
        let x = roughness.clamp(0.0, 1.0) * (N1 - 1) as f32;
        let i = (x as usize).min(N1 - 2);
        let t = x - i as f32;
        self.ggx_e_avg[i] * (1.0 - t) + self.ggx_e_avg[i + 1] * t
    }

    /// Fresnel average of dielectric GGX reflection for relative IOR `eta`: its
    /// single-scattering albedo over the albedo with Fresnel one (Cycles' estimate of a
    /// specular layer's albedo once its energy compensation is applied).
    pub fn dielectric_fresnel_avg(&self, mu: f32, roughness: f32, eta: f32) -> f32 {
        let eta = if eta < 1.0 { 1.0 / eta } else { eta };
        let z = ((eta - 1.0) / (eta + 1.0)).abs().sqrt().clamp(0.0, 1.0);
        let x = z * (N3 - 1) as f32;
        let i = (x as usize).min(N3 - 2);
        let t = x - i as f32;
        let a = lerp2(
            &self.dielectric_s[i * N3 * N3..(i + 1) * N3 * N3],
            N3,
            roughness,
            mu,
        );
        let b = lerp2(
            &self.dielectric_s[(i + 1) * N3 * N3..(i + 2) * N3 * N3],
            N3,
            roughness,
            mu,
        );
        let s = a * (1.0 - t) + b * t;
        let f = f0_from_ior(eta);
        f + (1.0 - f) * s
    }
}

impl Tables {
    /// The glass tables, integrated on first use. Renders build them before their tiles
    /// start (`warm_glass`); a first use inside a rayon worker builds them sequentially,
    /// since a parallel build there could steal a render job that asks for the table
    /// while it is being built (OnceLock re-entry).
    fn glass(&self) -> &(Vec<f32>, Vec<f32>) {
        self.glass
            .get_or_init(|| glass_tables(rayon::current_thread_index().is_none()))
    }

    /// Builds the glass tables now, on the calling thread (in parallel outside rayon's
    /// pool), so that the render's first glass closure does not.
    pub fn warm_glass(&self) {
        let _ = self.glass();
    }

    /// Single-scattering albedo of GGX glass (reflection plus refraction) for relative
    /// IOR `eta`; `roughness` = sqrt(alpha).
    pub fn glass_e(&self, mu: f32, roughness: f32, eta: f32) -> f32 {
        let (glass_e, glass_inv_e) = self.glass();
        let (t, e) = if eta < 1.0 {
            (glass_inv_e, 1.0 / eta)
        } else {
            (glass_e, eta)
        };
        let z = ((e - 1.0) / (e + 1.0)).abs().sqrt().clamp(0.0, 1.0);
        let x = z * (N3 - 1) as f32;
        let i = (x as usize).min(N3 - 2);
        let f = x - i as f32;
        let a = lerp2(&t[i * N3 * N3..(i + 1) * N3 * N3], N3, roughness, mu);
        let b = lerp2(&t[(i + 1) * N3 * N3..(i + 2) * N3 * N3], N3, roughness, mu);
        a * (1.0 - f) + b * f
    }
}

/// Directions per glass table entry. 128 left the albedo a few percent off at moderate
/// roughness (a roughness 0.25 glass cube against a flat world rendered 1-2% bright next to
/// Cycles, whose tables are precomputed offline). Against Cycles' tables
/// (tests/closures.rs), 1024 leaves a worst entry 0.0011 off for light entering glass and
/// 0.0033 for light leaving it (means 1e-4 and 4e-4); 4096 gives 0.0004 and 0.0012 but
/// takes three times as long to build, once per process, for no visible change.
const GLASS_TABLE_SAMPLES: u32 = 1024;

/// The IOR of the glass tables' slice `zi`, with Cycles' precompute clamps (z within
/// 1e-4..0.99): its first slice is IOR 1 to float precision, where refraction is treated
/// as a mirror, and its last is IOR 99.5, not infinity.
fn glass_grid_eta(zi: usize) -> f32 {
    let z = (zi as f32 / (N3 - 1) as f32).clamp(1e-4, 0.99);
    let r = z * z;
    (1.0 + r) / (1.0 - r)
}

fn glass_tables(parallel: bool) -> (Vec<f32>, Vec<f32>) {
    let s = PixelSampler::new(7, 11, 17);
    let samples: Vec<[f32; 2]> = (0..GLASS_TABLE_SAMPLES)
        .map(|i| {
            let u = s.get4(i, 0);
            [u[0], u[1]]
        })
        .collect();
    // Each entry is a pure function of its grid point, so the parallel and the
    // sequential build give the same bits on any thread count.
    let entry = |k: usize| {
        let (zi, ri, mi) = (k / (N3 * N3), (k / N3) % N3, k % N3);
        let eta = glass_grid_eta(zi);
        let alpha = rough_to_alpha(ri as f32 / (N3 - 1) as f32);
        let mu = mi as f32 / (N3 - 1) as f32;
        (
            crate::render::bsdf::microfacet::glass_albedo(mu, alpha, eta, &samples),
            crate::render::bsdf::microfacet::glass_albedo(mu, alpha, 1.0 / eta, &samples),
        )
    };
    let entries: Vec<(f32, f32)> = if parallel {
        (0..N3 * N3 * N3).into_par_iter().map(entry).collect()
    } else {
        (0..N3 * N3 * N3).map(entry).collect()
    };
    entries.into_iter().unzip()
}

impl Default for Tables {
    fn default() -> Self {
        Tables::new()
    }
}

fn lerp2(t: &[f32], n: usize, y: f32, x: f32) -> f32 {
    let fx = x.clamp(0.0, 1.0) * (n - 1) as f32;
    let fy = y.clamp(0.0, 1.0) * (n - 1) as f32;
    let (ix, iy) = ((fx as usize).min(n - 2), (fy as usize).min(n - 2));
    let (tx, ty) = (fx - ix as f32, fy - iy as f32);
    let at = |i: usize, j: usize| t[j * n + i];
    let a = at(ix, iy) * (1.0 - tx) + at(ix + 1, iy) * tx;
    let b = at(ix, iy + 1) * (1.0 - tx) + at(ix + 1, iy + 1) * tx;
    a * (1.0 - ty) + b * ty
}
