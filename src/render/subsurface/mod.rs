//! Subsurface scattering by random walk, as Cycles 4.x does it (closure/bssrdf.h,
//! integrator/subsurface.h, integrator/subsurface_random_walk.h): the BSSRDF closure is
//! picked like a BSDF; the path enters the object through a diffuse or rough-refractive
//! entry bounce, walks a homogeneous medium whose extinction and single-scattering
//! albedo come from the radius and surface colour (Chiang et al. 2016's remap), with
//! Dwivedi-guided directions and spectral MIS over the channels, and leaves where it
//! next meets the same object, continuing from there with a white diffuse closure.
//!
//! The Burley method samples by disk projection instead (`subsurface_disk`). Not done:
//! the quarter-pixel radius fallback (needs ray differentials).

pub mod disk;

use crate::render::bsdf::microfacet::sample_ggx_vndf;
use crate::render::math::*;
use std::f32::consts::PI;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    RandomWalk,
    RandomWalkSkin,
    Burley,
}

impl Method {
    pub fn from_property(p: Option<&str>) -> Method {
        match p {
            Some("RANDOM_WALK_SKIN") => Method::RandomWalkSkin,
            Some("BURLEY") => Method::Burley,
            _ => Method::RandomWalk,
        }
    }
}

/// A BSSRDF closure after Cycles' setup (radius already scaled for the method).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bssrdf {
    pub radius: V3,
    pub albedo: V3,
    pub anisotropy: f32,
    pub ior: f32,
    /// GGX alpha of the refractive entry bounce.
    pub alpha: f32,
    pub method: Method,
}

const MIN_RADIUS: f32 = 1e-8;
/// Cycles' BSSRDF_MAX_BOUNCES: a walk still inside after this many steps is lost (the path
/// ends), which on an open surface is most walks that wander away from it.
const MAX_BOUNCES: u32 = 256;
const THROUGHPUT_EPSILON: f32 = 1e-6;

fn dipole_rd(alpha_prime: f32, fourthird_a: f32) -> f32 {
    let s = (3.0 * (1.0 - alpha_prime)).sqrt();
    0.5 * alpha_prime * (1.0 + (-fourthird_a * s).exp()) * (-s).exp()
}

fn dipole_alpha_prime(rd: f32, fourthird_a: f32) -> f32 {
    if rd < 1e-4 {
        return 0.0;
    }
    if rd >= 0.995 {
        return 0.999_999;
    }
    // Bisection, 12 steps as Cycles.
    let (mut x0, mut x1, mut xm) = (0.0f32, 1.0f32, 0.5f32);
    for _ in 0..12 {
        xm = 0.5 * (x0 + x1);
        if dipole_rd(xm, fourthird_a) < rd {
            x0 = xm;
        } else {
            x1 = xm;
        }
    }
    xm
}

/// Cycles' `bssrdf_setup` for a closure of colour `weight`: returns the BSSRDF (None when
/// no channel has a usable radius) and the part of the weight that falls back to a
/// diffuse closure (channels whose radius is too small), plus the number of channels.
pub fn setup(
    weight: V3,
    radius: V3,
    albedo: V3,
    anisotropy: f32,
    ior: f32,
    roughness: f32,
    method: Method,
) -> (Option<(Bssrdf, V3)>, V3, u32) {
    let anisotropy = anisotropy.clamp(0.0, 0.9);
    let ior = ior.clamp(1.01, 3.8);
    let mut w = weight;
    let mut r = radius.map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 });
    let mut diffuse = [0.0; 3];
    let mut channels = 3;
    for k in 0..3 {
        if r[k] < MIN_RADIUS {
            diffuse[k] = w[k];
            w[k] = 0.0;
            r[k] = 0.0;
            channels -= 1;
        }
    }
    if channels == 0 {
        return (None, diffuse, 0);
    }
    match method {
        Method::RandomWalk | Method::Burley => r = scale(r, 0.25 / PI),
        Method::RandomWalkSkin => {
            let inv = 1.0 / ior;
            let f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * ior;
            let fourthird_a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr);
            for k in 0..3 {
                let ap = dipole_alpha_prime(albedo[k], fourthird_a);
                r[k] *= (3.0 * (1.0 - ap)).sqrt();
            }
        }
    }
    // Cycles' Random Walk (Skin) enters through a rough interface of fixed roughness one
    // (bssrdf_setup); the other methods keep the closure's roughness.
    let alpha = if method == Method::RandomWalkSkin {
        1.0
    } else {
        (roughness * roughness).clamp(0.0, 1.0)
    };
    (
        Some((
            Bssrdf {
                radius: r,
                albedo,
                anisotropy,
                ior,
                alpha,
                method,
            },
            w,
        )),
        diffuse,
        channels,
    )
}

/// Chiang et al. 2016's inversion of the multiple-scattering albedo, with anisotropy
/// (Wrenninge et al.): (extinction, single-scattering albedo) of one channel.
fn remap(albedo: f32, d: f32, g: f32) -> (f32, f32) {
    let g2 = g * g;
    let g3 = g2 * g;
    let g4 = g3 * g;
    let g5 = g4 * g;
    let g6 = g5 * g;
    let g7 = g6 * g;
    let a = 1.826_052_4 - 1.284_510_6 * g - 1.799_046_3 * g2 + 9.193_932_9 * g3 - 22.821_558 * g4
        + 32.023_487 * g5
        - 23.626_48 * g6
        + 7.210_670_2 * g7;
    let b = 4.985_112
        + 0.127_355_96
            * (31.149_158 * g - 201.847_02 * g2 + 841.576_04 * g3 - 2018.092_9 * g4
                + 2731.715_6 * g5
                - 1935.414_2 * g6
                + 559.009_03 * g7)
                .exp();
    let c = 1.096_861 - 0.394_704_06 * g + 1.052_581_2 * g2 - 8.839_637 * g3 + 28.864_323 * g4
        - 46.880_29 * g5
        + 38.540_283 * g6
        - 12.718_104 * g7;
    let dd = 0.496_310_2 + 0.360_146_6 * g - 2.151_393 * g2 + 17.889_69 * g3 - 55.298_4 * g4
        + 82.065_98 * g5
        - 58.510_6 * g6
        + 15.847_83 * g7;
    let e = 4.231_903
        + 0.003_106_039_5
            * (76.731_63 * g - 594.356_8 * g2 + 2448.883_4 * g3 - 5576.685_5 * g4 + 7116.602 * g5
                - 4763.544_7 * g6
                + 1303.531_8 * g7)
                .exp();
    let f = 2.406_03 - 2.518_148_4 * g + 9.184_949 * g2 - 79.219_17 * g3 + 259.082_87 * g4
        - 403.613_8 * g5
        + 302.857_12 * g6
        - 87.437_05 * g7;
    let blend = albedo.max(0.0).powf(0.25);
    let alpha =
        (1.0 - blend) * a * (b * albedo).atan().powf(c) + blend * dd * (e * albedo).atan().powf(f);
    let alpha = if alpha.is_finite() {
        alpha.clamp(0.0, 0.999_999)
    } else {
        0.0
    };
    let sigma_t = 1.0 / d.max(1e-16) / (1.0 - g);
    (sigma_t, alpha)
}

fn hg_pdf(cos: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
}

fn direction_from_cosine(axis: V3, cos: f32, u: f32) -> V3 {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = 2.0 * PI * u;
    let (t, b) = basis(axis);
    add(
        add(scale(t, sin * phi.cos()), scale(b, sin * phi.sin())),
        scale(axis, cos),
    )
}

fn hg_sample(d: V3, g: f32, u: [f32; 2]) -> (V3, f32) {
    let cos = if g.abs() < 1e-3 {
        1.0 - 2.0 * u[0]
    } else {
        let k = (1.0 - g * g) / (1.0 - g + 2.0 * g * u[0]);
        ((1.0 + g * g - k * k) / (2.0 * g)).clamp(-1.0, 1.0)
    };
    (direction_from_cosine(d, cos, u[1]), hg_pdf(cos, g))
}

/// The walk's direction into the surface (Cycles' `subsurface_entry_bounce`): half the
/// Random Walk (Skin)'s entries are diffuse, the rest (and every entry of the plain Random
/// Walk) refract about a GGX normal; `v` is the direction toward the viewer, `n` the
/// closure normal.
pub fn entry_direction(b: &Bssrdf, n: V3, v: V3, mut u: [f32; 2]) -> Option<V3> {
    if b.method == Method::RandomWalkSkin {
        if u[0] < 0.5 {
            u[0] *= 2.0;
            let d = crate::render::camera::concentric_disk(u);
            let z = (1.0 - d[0] * d[0] - d[1] * d[1]).max(0.0).sqrt();
            let (t, bb) = basis(n);
            return Some(add(add(scale(t, d[0]), scale(bb, d[1])), scale(n, -z)));
        }
        u[0] = 2.0 * (u[0] - 0.5);
    }
    let cos_nv = dot(n, v);
    if cos_nv <= 0.0 {
        return None;
    }
    let (t, bb) = basis(n);
    let lv = [dot(t, v), dot(bb, v), cos_nv];
    let a = b.alpha.max(1e-4);
    let hl = sample_ggx_vndf(lv, a, a, u);
    let h = add(add(scale(t, hl[0]), scale(bb, hl[1])), scale(n, hl[2]));
    let neta = 1.0 / b.ior;
    let cos_hv = dot(h, v);
    let arg = 1.0 - neta * neta * (1.0 - cos_hv * cos_hv);
    let dnp = arg.max(0.0).sqrt().max(1e-7);
    Some(normalize(add(
        scale(v, -neta),
        scale(h, neta * cos_hv - dnp),
    )))
}

/// Where a walk leaves the object.
pub struct Exit {
    pub prim: u32,
    pub u: f32,
    pub v: f32,
    /// Direction of the last step (pointing out of the object at the exit).
    pub dir: V3,
}

/// Ray casts against one object only: the nearest hit within (0, tmax) on instance `inst`,
/// both sides of its faces, passing through triangle `skip` (the walk's first ray starts on
/// its entry triangle and, as Cycles' ray self-exclusion, ignores it instead of being
/// offset off it).
pub trait LocalTrace {
    fn local_hit(
        &mut self,
        org: V3,
        dir: V3,
        tmax: f32,
        inst: u32,
        skip: Option<u32>,
    ) -> Option<(f32, u32, f32, f32)>;
}

/// Cycles' `subsurface_random_walk`: walks from `p` (on triangle `prim` of instance
/// `inst`, normal `n` facing the side the path came from) along `d0` into the object;
/// multiplies `throughput` by the walk's weight. `rand(bounce)` gives the walk's random
/// numbers for one bounce (it reads r[0..6]; at bounce 0 only r[0] and r[1]). Nothing in
/// it has a length of its own: every distance comes from the radius, so the walk is the
/// same at any scene scale.
#[allow(clippy::too_many_arguments)]
pub fn random_walk(
    b: &Bssrdf,
    p: V3,
    n: V3,
    d0: V3,
    inst: u32,
    prim: u32,
    throughput: &mut V3,
    trace: &mut dyn LocalTrace,
    rand: &dyn Fn(u32) -> [f32; 8],
) -> Option<Exit> {
    let g = b.anisotropy;
    let mut sigma_t = [0.0; 3];
    let mut alpha = [0.0; 3];
    let mut tp = *throughput;
    for k in 0..3 {
        let (st, a) = remap(b.albedo[k], b.radius[k], g);
        sigma_t[k] = st;
        alpha[k] = a;
        // The closure weight holds the albedo, which the walk's scattering adds back.
        tp[k] = if b.albedo[k] != 0.0 {
            tp[k] / b.albedo[k]
        } else {
            0.0
        };
        const MIN_ALPHA: f32 = 0.2;
        if alpha[k] < MIN_ALPHA {
            tp[k] *= alpha[k] / MIN_ALPHA;
            alpha[k] = MIN_ALPHA;
        }
    }
    let amax = max3(alpha);
    let diffusion_length =
        1.0 / (1.0 - amax.powf(2.442_94 - 0.021_581_3 * amax + 0.578_637 / amax)).sqrt();
    if !(diffusion_length.is_finite()) || diffusion_length <= 1.0 {
        return None;
    }
    let phase_log = ((diffusion_length + 1.0) / (diffusion_length - 1.0)).ln();
    let guided_fraction_org = 1.0 - 0.5f32.max(g.abs().powf(0.125));
    let sigma_s_org = mul(sigma_t, alpha);
    // Similarity theory past bounce 9: an isotropic medium with reduced coefficients.
    let sigma_s_star = scale(sigma_s_org, 1.0 - g);
    let sigma_t_star = add(sub(sigma_t, sigma_s_org), sigma_s_star);

    let mut pos = p;
    let mut dir = d0;
    let mut have_opposite = false;
    let mut opposite_distance = 0.0f32;
    let mut hit = None;
    for bounce in 0..MAX_BOUNCES {
        let (g, guided_fraction, st, ss) = if bounce <= 9 {
            (g, guided_fraction_org, sigma_t, sigma_s_org)
        } else {
            (0.0, 0.75, sigma_t_star, sigma_s_star)
        };
        let r = rand(bounce);
        // Channel by throughput * albedo, MIS (balance) over the channels.
        let wts = [0, 1, 2].map(|k| (tp[k] * alpha[k]).abs());
        let sum = wts[0] + wts[1] + wts[2];
        let channel_pdf = if sum > 0.0 {
            scale(wts, 1.0 / sum)
        } else {
            [1.0 / 3.0; 3]
        };
        let x = r[0];
        let channel = if x < channel_pdf[0] {
            0
        } else if x < channel_pdf[0] + channel_pdf[1] {
            1
        } else {
            2
        };
        let mut sample_sigma_t = st[channel];
        let randt = r[1];
        let mut backward_fraction = 0.0;
        let (mut fwd_factor, mut bwd_factor, mut fwd_stretch, mut bwd_stretch) =
            (0.0, 0.0, 1.0, 1.0);
        if bounce > 0 {
            let guided = r[2] < guided_fraction;
            let mut guide_backward = false;
            if have_opposite {
                // Cycles' clamp is min(max(x, 0), d): the opposite hit can sit a hair behind the
                // entry plane (d slightly negative), where f32::clamp would panic.
                let x = dot(sub(pos, p), neg(n)).max(0.0).min(opposite_distance);
                backward_fraction =
                    1.0 / (1.0 + ((opposite_distance - 2.0 * x) / diffusion_length).exp());
                guide_backward = r[3] < backward_fraction;
            }
            let (cos, hgp) = if guided {
                let mut c = diffusion_length - (diffusion_length + 1.0) * (-r[4] * phase_log).exp();
                if guide_backward {
                    c = -c;
                }
                let nd = direction_from_cosine(n, c, r[5]);
                let hgp = hg_pdf(dot(dir, nd), g);
                dir = nd;
                (c, hgp)
            } else {
                let (nd, hgp) = hg_sample(dir, g, [r[4], r[5]]);
                dir = nd;
                (dot(nd, n), hgp)
            };
            let dw = |c: f32| 1.0 / ((diffusion_length - c) * phase_log);
            fwd_factor = dw(cos) / (2.0 * PI) / hgp;
            bwd_factor = dw(-cos) / (2.0 * PI) / hgp;
            fwd_stretch = 1.0 - cos / diffusion_length;
            bwd_stretch = 1.0 + cos / diffusion_length;
            if guided {
                sample_sigma_t *= if guide_backward {
                    bwd_stretch
                } else {
                    fwd_stretch
                };
            }
        }
        let mut t = -(1.0 - randt).max(1e-30).ln() / sample_sigma_t;
        let tmax = if bounce == 0 {
            t.max(10.0 / sigma_t[0].min(sigma_t[1]).min(sigma_t[2]))
        } else {
            t
        };
        // Only the first ray starts on a surface (the entry triangle); after it the walk may
        // meet that triangle again.
        let skip = if bounce == 0 { Some(prim) } else { None };
        let h = trace.local_hit(pos, dir, tmax, inst, skip);
        let mut is_hit = h.is_some();
        if bounce == 0 {
            if let Some((th, ..)) = h {
                have_opposite = true;
                opposite_distance = dot(sub(madd(pos, dir, th), p), neg(n));
            }
            is_hit = h.map(|x| x.0 < t).unwrap_or(false);
        }
        if is_hit {
            t = h.unwrap().0;
        }
        pos = madd(pos, dir, t);
        let pdf_of = |s: V3| -> V3 {
            [0, 1, 2].map(|k| {
                if is_hit {
                    (-s[k] * t).exp()
                } else {
                    s[k] * (-s[k] * t).exp()
                }
            })
        };
        let transmittance = [0, 1, 2].map(|k| (-st[k] * t).exp());
        // pdf_of(st) from the transmittance's exponentials (the same bits, three fewer
        // expf per bounce: the walk's exponentials were 4% of endo_colon's samples).
        let mut pdf = if is_hit {
            transmittance
        } else {
            mul(st, transmittance)
        };
        if bounce > 0 {
            let mut guided_pdf = pdf_of(scale(st, fwd_stretch));
            if have_opposite {
                let back = pdf_of(scale(st, bwd_stretch));
                guided_pdf = [0, 1, 2].map(|k| {
                    guided_pdf[k] * fwd_factor * (1.0 - backward_fraction)
                        + back[k] * bwd_factor * backward_fraction
                });
            } else {
                guided_pdf = scale(guided_pdf, fwd_factor);
            }
            pdf = [0, 1, 2]
                .map(|k| pdf[k] * (1.0 - guided_fraction) + guided_pdf[k] * guided_fraction);
        }
        let denom = dot(channel_pdf, pdf);
        if !(denom > 0.0) || !denom.is_finite() {
            return None;
        }
        let num = if is_hit {
            transmittance
        } else {
            mul(ss, transmittance)
        };
        tp = scale(mul(tp, num), 1.0 / denom);
        if is_hit {
            let (_, prim, u, v) = h.unwrap();
            hit = Some(Exit { prim, u, v, dir });
            break;
        }
        if max3(tp) < THROUGHPUT_EPSILON || !tp.iter().all(|x| x.is_finite()) {
            break;
        }
    }
    let exit = hit?;
    *throughput = tp;
    Some(exit)
}

/// The normal a subsurface exit lights with when its material has a bumped BSSRDF
/// (Cycles' `surface_shader_bssrdf_normal`): the BSSRDF closures' normals (already bump
/// corrected for the exit, whose incoming direction is the true normal) weighted by
/// their mean weight; `fallback` (the shading normal) when there is none.
pub fn exit_normal(lobes: &crate::render::bsdf::LobeSet, fallback: V3) -> V3 {
    let mut n = [0.0; 3];
    for l in &lobes.lobes[..lobes.len] {
        if let crate::render::bsdf::LobeKind::Subsurface(_) = l.kind {
            let w = ((l.weight[0] + l.weight[1] + l.weight[2]) / 3.0).abs();
            n = madd(n, l.n, w);
        }
    }
    if is_zero(n) || !n.iter().all(|x| x.is_finite()) {
        fallback
    } else {
        normalize(n)
    }
}

/// After a diffuse bounce Cycles replaces every BSSRDF by a diffuse closure of its weight.
pub fn to_diffuse(lobes: &mut crate::render::bsdf::LobeSet) {
    let n = lobes.len;
    for l in &mut lobes.lobes[..n] {
        if let crate::render::bsdf::LobeKind::Subsurface(b) = l.kind {
            let channels = b.radius.iter().filter(|r| **r > 0.0).count().max(1) as f32;
            l.kind = crate::render::bsdf::LobeKind::Diffuse;
            l.sample_weight /= channels;
        }
    }
}

struct Local<'a, 'b> {
    scene: &'a crate::render::integrator::Scene<'b>,
    rays: u64,
    /// The path's shutter time (moving objects are posed at it).
    time: f32,
}

impl LocalTrace for Local<'_, '_> {
    fn local_hit(
        &mut self,
        org: V3,
        dir: V3,
        tmax: f32,
        inst: u32,
        skip: Option<u32>,
    ) -> Option<(f32, u32, f32, f32)> {
        let mut t0 = 0.0f32;
        // Pass through other objects (Cycles' local intersection sees one object only) and
        // the skipped triangle. The next search starts just past the hit (hits count only
        // beyond t0): no absolute epsilon, which would not scale with the scene.
        let mut searches = 0;
        while searches < 64 {
            let h = match skip {
                // The first search passes the entry triangle in one traversal where the
                // structure can (half the walks met it first and searched twice); it
                // counts as the searches it stands for.
                Some(s) if searches == 0 => {
                    let (h, twice) = self
                        .scene
                        .accel
                        .intersect_past(org, dir, tmax, self.time, s);
                    searches += 1 + twice as u32;
                    self.rays += 1 + twice as u64;
                    h?
                }
                _ => {
                    self.rays += 1;
                    searches += 1;
                    self.scene
                        .accel
                        .intersect_at(org, dir, t0, tmax, self.time)?
                }
            };
            if self.scene.geo.refs[h.prim as usize].inst == inst && Some(h.prim) != skip {
                return Some((h.t, h.prim, h.u, h.v));
            }
            t0 = h.t.next_up();
        }
        None
    }
}

/// The BSSRDF bounce at `hit` (viewer toward `wo`, closure normal `n`): entry direction,
/// then the walk. Returns the exit as a hit and the direction the walk left along.
#[allow(clippy::too_many_arguments)]
pub fn enter_and_walk(
    scene: &crate::render::integrator::Scene,
    b: &Bssrdf,
    hit: &crate::render::integrator::SurfaceHit,
    wo: V3,
    n: V3,
    rng: &crate::render::sampler::PixelSampler,
    index: u32,
    set: u32,
    throughput: &mut V3,
    rays: &mut u64,
) -> Option<(crate::render::accel::Hit, V3)> {
    // The Burley method samples by disk projection instead of walking.
    if b.method == Method::Burley {
        return crate::render::subsurface::disk::disk_exit(
            scene, b, hit, rng, index, set, throughput, rays,
        );
    }
    let base = bssrdf_dimensions(set);
    let ue = rng.get4(index, base);
    let d0 = entry_direction(b, n, wo, [ue[0], ue[1]])?;
    if dot(hit.ng, d0) >= 0.0 {
        return None;
    }
    // Cycles starts the walk on the surface itself (no offset: the first ray ignores the
    // entry triangle instead), so the walk has no length scale but the radius.
    // The walk reads r[0..6] and, at bounce 0 (no direction to sample), r[0..2] only:
    // the second set's dimensions 2 and 3 are never drawn, nor that set at bounce 0.
    let rand = |bounce: u32| {
        let a = rng.get4(index, base.wrapping_add(1 + 2 * bounce));
        let c = if bounce == 0 {
            [0.0; 2]
        } else {
            rng.get2(index, base.wrapping_add(2 + 2 * bounce))
        };
        [a[0], a[1], a[2], a[3], c[0], c[1], 0.0, 0.0]
    };
    let mut local = Local {
        scene,
        rays: 0,
        time: hit.time,
    };
    let exit = random_walk(
        b, hit.p, n, d0, hit.inst, hit.prim, throughput, &mut local, &rand,
    );
    *rays += local.rays;
    let e = exit?;
    Some((
        crate::render::accel::Hit {
            t: 0.0,
            prim: e.prim,
            u: e.u,
            v: e.v,
        },
        e.dir,
    ))
}

/// First sampler dimension of a subsurface bounce's random numbers (walk or disk probe):
/// a range apart from the path's own dimensions, one range per bounce `set`.
pub fn bssrdf_dimensions(set: u32) -> u32 {
    0x2000_0000u32.wrapping_add(set.wrapping_mul(4096))
}
