//! The Christensen-Burley BSSRDF sampled by disk projection, as Cycles 4.x does for the
//! Subsurface Scattering node's Burley method (closure/bssrdf.h, integrator/
//! subsurface_disk.h; King et al. 2013, "BSSRDF Importance Sampling"): a radius from the
//! Burley profile of one channel, a disk about one of three axes (the normal half the
//! time), a probe ray through the disk finding up to `MAX_HITS` points on the same
//! object, each weighted by profile over pdf with MIS between the axes, and one of them
//! resampled by weight. The path leaves from there with a white diffuse closure, as
//! after a random walk.

use crate::render::math::*;
use crate::render::subsurface::Bssrdf;

/// Profile truncation in units of d, and the profile's CDF there.
const TRUNCATE: f32 = 16.0;
const TRUNCATE_CDF: f32 = 0.996_379_01;
/// Cycles' BSSRDF_MAX_HITS.
const MAX_HITS: usize = 4;
/// Hits gathered along one probe before giving up on the rest.
const MAX_PROBE_HITS: usize = 64;

/// The Burley profile as Cycles normalises it: a density in r (it integrates to one).
fn eval_channel(d: f32, r: f32) -> f32 {
    if r >= TRUNCATE * d {
        return 0.0;
    }
    let e3 = (-r / (3.0 * d)).exp();
    (e3 * e3 * e3 + e3) / (4.0 * d)
}

fn pdf_channel(d: f32, r: f32) -> f32 {
    if d <= 0.0 || r == 0.0 {
        return 0.0;
    }
    eval_channel(d, r) / TRUNCATE_CDF
}

/// Radius (in units of d) where the profile's CDF is `xi`: Newton from Cycles' guess.
fn root_find(xi: f32) -> f32 {
    let mut r = if xi <= 0.9 {
        (xi * xi * 2.4).exp() - 1.0
    } else {
        15.0
    };
    for _ in 0..10 {
        let e3 = (-r / 3.0).exp();
        let e = e3 * e3 * e3;
        let f = 1.0 - 0.25 * e - 0.75 * e3 - xi;
        let df = 0.25 * e + 0.25 * e3;
        if f.abs() < 1e-6 || df == 0.0 {
            break;
        }
        r = (r - f / df).max(0.0);
    }
    r
}

fn channels(radius: V3) -> f32 {
    radius.iter().filter(|r| **r > 0.0).count() as f32
}

/// A disk radius and the probe's half height: one channel picked uniformly among those
/// with a radius, `xi` reused within it.
fn sample(radius: V3, xi: f32) -> (f32, f32) {
    let mut xi = xi * channels(radius);
    let mut d = 0.0;
    let mut sum = 0.0;
    for &c in &radius {
        if c > 0.0 {
            if xi < sum + 1.0 {
                xi -= sum;
                d = c;
                break;
            }
            sum += 1.0;
        }
    }
    let rm = TRUNCATE * d;
    let r = root_find(xi * TRUNCATE_CDF) * d;
    (r, (rm * rm - r * r).max(0.0).sqrt())
}

fn eval(radius: V3, r: f32) -> V3 {
    radius.map(|d| pdf_channel(d, r))
}

fn pdf(radius: V3, r: f32) -> f32 {
    let e = eval(radius, r);
    (e[0] + e[1] + e[2]) / channels(radius).max(1.0)
}

/// A hit of the probe: distance, triangle, barycentrics.
#[derive(Clone, Copy)]
struct ProbeHit {
    t: f32,
    prim: u32,
    u: f32,
    v: f32,
}

/// The disk a probe ray is cast through, as Cycles' subsurface_disk and svm_bevel choose
/// it: about the geometric normal with probability 1/2, about each tangent 1/4.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProbeAxis {
    /// The disk's normal (the probe runs along it) and its two in-plane axes.
    pub n: V3,
    t: V3,
    b: V3,
    /// The probabilities of the three axes, in the order normal, first, second tangent.
    pick: [f32; 3],
}

impl ProbeAxis {
    /// The axis `xi` picks about geometric normal `ng`, and `xi` rescaled to [0, 1) within
    /// its choice (Cycles reuses it for the angle on the disk).
    pub(crate) fn pick(ng: V3, mut xi: f32) -> (ProbeAxis, f32) {
        let (t0, b0) = basis(ng);
        let (n, t, b, pick) = if xi < 0.5 {
            xi *= 2.0;
            (ng, t0, b0, [0.5, 0.25, 0.25])
        } else if xi < 0.75 {
            xi = (xi - 0.5) * 4.0;
            (t0, ng, b0, [0.25, 0.5, 0.25])
        } else {
            xi = (xi - 0.75) * 4.0;
            (b0, t0, ng, [0.25, 0.25, 0.5])
        };
        (ProbeAxis { n, t, b, pick }, xi)
    }

    /// The probe's origin: `h` above `p` along the axis, at radius `r` and angle 2 pi
    /// `xi_phi` on the disk.
    pub(crate) fn origin(&self, p: V3, xi_phi: f32, r: f32, h: f32) -> V3 {
        let phi = std::f32::consts::TAU * xi_phi;
        let disk_p = add(scale(self.t, r * phi.cos()), scale(self.b, r * phi.sin()));
        add(madd(p, self.n, h), disk_p)
    }

    /// The multiple-importance terms of a hit with normal `ng` over the three axes: this
    /// axis's pdf factor and the sum of the squared factors (the power heuristic's
    /// denominator).
    pub(crate) fn mis(&self, ng: V3) -> (f32, f32) {
        let pn = self.pick[0] * dot(self.n, ng).abs();
        let pt = self.pick[1] * dot(self.t, ng).abs();
        let pb = self.pick[2] * dot(self.b, ng).abs();
        (pn, pn * pn + pt * pt + pb * pb)
    }
}

/// Finds the exit of a Burley BSSRDF entered at `hit` (whose geometric normal faces the
/// viewer), multiplying `throughput` by the resampled weight. Returns the exit and the
/// direction the exit is seen from (outward), like the random walk.
#[allow(clippy::too_many_arguments)]
pub fn disk_exit(
    scene: &crate::render::integrator::Scene,
    b: &Bssrdf,
    hit: &crate::render::integrator::SurfaceHit,
    rng: &crate::render::sampler::PixelSampler,
    index: u32,
    set: u32,
    throughput: &mut V3,
    rays: &mut u64,
) -> Option<(crate::render::accel::Hit, V3)> {
    let base = crate::render::subsurface::bssrdf_dimensions(set);
    let u = rng.get4(index, base);
    let (xi_r, xi_axis, xi_resample) = (u[0], u[1], u[2]);
    // Axis: the normal with probability 1/2, each tangent 1/4.
    let (axis, xi_phi) = ProbeAxis::pick(hit.ng, xi_axis);
    let (disk_r, h) = sample(b.radius, xi_r);
    if !(h > 0.0) {
        return None;
    }
    let org = axis.origin(hit.p, xi_phi, disk_r, h);
    let dir = neg(axis.n);
    let tmax = 2.0 * h;

    // Every hit on the entry object along the probe (up to MAX_PROBE_HITS), in order.
    let mut found = [ProbeHit {
        t: 0.0,
        prim: 0,
        u: 0.0,
        v: 0.0,
    }; MAX_PROBE_HITS];
    let mut n_found = 0;
    let mut tmin = 0.0f32;
    while n_found < MAX_PROBE_HITS {
        *rays += 1;
        let Some(x) = scene.accel.intersect(org, dir, tmin, tmax) else {
            break;
        };
        if scene.geo.refs[x.prim as usize].inst == hit.inst {
            found[n_found] = ProbeHit {
                t: x.t,
                prim: x.prim,
                u: x.u,
                v: x.v,
            };
            n_found += 1;
        }
        tmin = x.t * (1.0 + 1e-6) + 1e-7;
    }
    if n_found == 0 {
        return None;
    }
    // More hits than Cycles keeps: a random subset of MAX_HITS (reservoir sampling), then
    // in distance order, and each weighted up by the kept fraction.
    let mut kept = [found[0]; MAX_HITS];
    let n_kept = n_found.min(MAX_HITS);
    kept[..n_kept].copy_from_slice(&found[..n_kept]);
    if n_found > MAX_HITS {
        let mut state = (u[3] * 4_294_967_296.0) as u32 ^ 0x68bc_21eb;
        for (i, f) in found[..n_found].iter().enumerate().skip(MAX_HITS) {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let j = ((state as u64 * (i as u64 + 1)) >> 32) as usize;
            if j < MAX_HITS {
                kept[j] = *f;
            }
        }
        kept[..n_kept].sort_by(|a, b| a.t.total_cmp(&b.t));
    }
    let mut weights = [[0.0f32; 3]; MAX_HITS];
    let mut normals = [[0.0f32; 3]; MAX_HITS];
    let mut sum = 0.0f32;
    let disk_pdf = pdf(b.radius, disk_r);
    for k in 0..n_kept {
        let tri = &scene.geo.tris[kept[k].prim as usize];
        let mut ng = normalize(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])));
        if hit.backfacing {
            ng = neg(ng);
        }
        let (pn, denom) = axis.mis(ng);
        let mut w = if denom > 0.0 { pn / denom } else { 0.0 };
        if n_found > MAX_HITS {
            w *= n_found as f32 / MAX_HITS as f32;
        }
        let p = madd(org, dir, kept[k].t);
        let r = len(sub(p, hit.p));
        let e = if disk_pdf > 0.0 {
            scale(eval(b.radius, r), w / disk_pdf)
        } else {
            [0.0; 3]
        };
        weights[k] = e;
        normals[k] = ng;
        sum += (e[0].abs() + e[1].abs() + e[2].abs()) / 3.0;
    }
    if !(sum > 0.0) || !sum.is_finite() {
        return None;
    }
    let target = xi_resample * sum;
    let mut partial = 0.0;
    for k in 0..n_kept {
        let sw = (weights[k][0].abs() + weights[k][1].abs() + weights[k][2].abs()) / 3.0;
        let next = partial + sw;
        if target < next && sw > 0.0 {
            *throughput = mul(*throughput, scale(weights[k], sum / sw));
            let h = kept[k];
            return Some((
                crate::render::accel::Hit {
                    t: 0.0,
                    prim: h.prim,
                    u: h.u,
                    v: h.v,
                },
                normals[k],
            ));
        }
        partial = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_sampling_inverts_its_cdf() {
        // The profile's CDF, 1 - e^-r/4 - 3/4 e^(-r/3), at the sampled radius is xi.
        for xi in [0.05f32, 0.3, 0.6, 0.9, 0.99] {
            let r = root_find(xi);
            let cdf = 1.0 - 0.25 * (-r).exp() - 0.75 * (-r / 3.0).exp();
            assert!((cdf - xi).abs() < 1e-5, "xi {xi}: r {r}, cdf {cdf}");
        }
        // And the profile (a density in r) integrates to its truncated CDF.
        let d = 0.2f32;
        let (mut s, n) = (0.0f64, 200_000);
        let rm = TRUNCATE * d;
        for i in 0..n {
            let r = (i as f32 + 0.5) / n as f32 * rm;
            s += eval_channel(d, r) as f64 * (rm / n as f32) as f64;
        }
        assert!((s - TRUNCATE_CDF as f64).abs() < 1e-3, "{s}");
    }
}
