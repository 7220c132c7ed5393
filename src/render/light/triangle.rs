//! Light samples on an emissive triangle as Cycles 4.x takes them (kernel/light/triangle.h):
//! by solid angle (Arvo's stratified sampling of spherical triangles) when the triangle is
//! large for its distance, otherwise uniformly over its area (Heitz's low-distortion map
//! from the square), and the pdf of a BSDF ray that finds the triangle by the same choice.
//! Either is unbiased; matching Cycles' choice matches its noise, and with clamping on, what
//! the clamp cuts.

use crate::render::math::{Vec3, V3};

pub struct TriangleSample {
    pub wi: V3,
    pub dist: f32,
    /// Solid-angle pdf of the direction (before the triangle's selection probability).
    pub pdf: f32,
    /// Weights of corners 1 and 2 of the sampled point.
    pub b1: f32,
    pub b2: f32,
}

fn sin_from_cos(c: f32) -> f32 {
    (1.0 - c * c).max(0.0).sqrt()
}

/// Cycles' heuristic: solid angle sampling when the longest edge is longer than the
/// distance to the triangle's plane (a distance Cycles divides by |N|^2, not |N|; kept).
fn by_solid_angle(v: &[Vec3; 3], plane_distance: f32) -> bool {
    let e = [v[1] - v[0], v[2] - v[0], v[2] - v[1]];
    let longest = e[0].dot(e[0]).max(e[1].dot(e[1])).max(e[2].dot(e[2]));
    longest > plane_distance * plane_distance
}

/// The solid angle of the triangle seen from `p` (Van Oosterom and Strackee).
fn solid_angle(v: &[Vec3; 3], p: Vec3) -> f32 {
    let (a, b, c) = (
        (v[0] - p).normalize(),
        (v[1] - p).normalize(),
        (v[2] - p).normalize(),
    );
    2.0 * a
        .dot(b.cross(c))
        .abs()
        .atan2(1.0 + b.dot(c) + a.dot(c) + a.dot(b))
}

/// Ray-triangle intersection: distance and the weights of corners 1 and 2.
fn intersect(v: &[Vec3; 3], o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = o - v[0];
    let b1 = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let qv = tv.cross(e1);
    let b2 = d.dot(qv) * inv;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > 0.0).then_some((t, b1, b2))
}

/// A light sample toward triangle `v` from `p`. `front`, `back`: the sides light sampling
/// may draw from (the material's Emission Sampling); None from the other side.
pub fn sample(v: &[V3; 3], p: V3, u: [f32; 2], front: bool, back: bool) -> Option<TriangleSample> {
    let (v, p) = (&v.map(Vec3::from), Vec3::from(p));
    let n0 = (v[1] - v[0]).cross(v[2] - v[0]);
    let nn = n0.dot(n0);
    if !(nn > 0.0) {
        return None;
    }
    let plane_distance = n0.dot(v[0] - p) / nn;
    // A point behind the normal sees the back.
    if !(if plane_distance > 0.0 { back } else { front }) {
        return None;
    }
    let area = 0.5 * nn.sqrt();
    if by_solid_angle(v, plane_distance) {
        let (a, b, c) = (
            (v[0] - p).normalize(),
            (v[1] - p).normalize(),
            (v[2] - p).normalize(),
        );
        let (cos_a, cos_b, cos_c) = (b.dot(c), a.dot(c), a.dot(b));
        let omega = 2.0 * a.dot(b.cross(c)).abs().atan2(1.0 + cos_a + cos_b + cos_c);
        if !(omega > 0.0) {
            return None;
        }
        // The angle at A, then the sub-triangle of area u0 * omega and a point on its edge.
        let cos_alpha = a.cross(b).normalize().dot(a.cross(c).normalize());
        let sin_alpha = sin_from_cos(cos_alpha);
        let alpha = cos_alpha.clamp(-1.0, 1.0).acos();
        let (sin_phi, cos_phi) = (u[0] * omega - alpha).sin_cos();
        let uu = cos_phi - cos_alpha;
        let vv = sin_phi + sin_alpha * cos_c;
        let num = (vv * cos_phi - uu * sin_phi) * cos_alpha - vv;
        let den = (vv * sin_phi + uu * cos_phi) * sin_alpha;
        let q = if den == 0.0 { 1.0 } else { num / den };
        let uvec = (c - a * cos_b).normalize();
        let c2 = (a * q + uvec * sin_from_cos(q)).normalize();
        let z = 1.0 - u[1] * (1.0 - c2.dot(b));
        let d = b * z + (c2 - b * c2.dot(b)).normalize() * sin_from_cos(z);
        let (t, b1, b2) = intersect(v, p, d)?;
        Some(TriangleSample {
            wi: d.into(),
            dist: t,
            pdf: 1.0 / omega,
            b1,
            b2,
        })
    } else {
        let (mut s, mut t) = (u[0], u[1]);
        if t > s {
            s *= 0.5;
            t -= s;
        } else {
            t *= 0.5;
            s -= t;
        }
        let q = v[0] * (1.0 - s - t) + v[1] * s + v[2] * t;
        let to = q - p;
        let dist = to.length();
        if !(dist > 0.0) {
            return None;
        }
        let wi = to * (1.0 / dist);
        let cos = (n0 * (1.0 / (2.0 * area))).dot(wi).abs();
        if cos == 0.0 {
            return None;
        }
        Some(TriangleSample {
            wi: wi.into(),
            dist,
            pdf: dist * dist / cos / area,
            b1: s,
            b2: t,
        })
    }
}

/// The solid-angle pdf with which `sample` from `o` draws direction `wi` that reaches the
/// triangle at distance `t` (Cycles' triangle_light_pdf without the selection).
pub fn pdf(v: &[V3; 3], o: V3, wi: V3, t: f32) -> f32 {
    let (v, o, wi) = (&v.map(Vec3::from), Vec3::from(o), Vec3::from(wi));
    let n0 = (v[1] - v[0]).cross(v[2] - v[0]);
    let nn = n0.dot(n0);
    if !(nn > 0.0) {
        return 0.0;
    }
    let plane_distance = n0.dot(wi * t).abs() / nn;
    if by_solid_angle(v, plane_distance) {
        let omega = solid_angle(v, o);
        if omega > 0.0 {
            1.0 / omega
        } else {
            0.0
        }
    } else {
        let area = 0.5 * nn.sqrt();
        let cos = (n0 * (1.0 / (2.0 * area))).dot(wi).abs();
        if cos == 0.0 {
            0.0
        } else {
            t * t / cos / area
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every sample lands on the triangle at the distance it reports, `pdf` agrees with the
    /// sample's, and the pdf integrates to one over the directions toward the triangle
    /// (the mean of 1/pdf is the solid angle); near (solid angle) and far (area) triangles.
    #[test]
    fn sample_and_pdf_agree() {
        let v = [[-1.0f32, -0.5, 2.0], [1.5, -0.3, 2.2], [0.2, 1.2, 1.8]];
        for p in [[0.1f32, 0.1, 1.5], [0.3, -0.2, -20.0]] {
            let omega = solid_angle(&v.map(Vec3::from), p.into());
            let (mut sum_inv, mut n) = (0.0f64, 0);
            for i in 0..64 {
                for j in 0..64 {
                    let u = [(i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0];
                    let s = sample(&v, p, u, true, true).expect("a sample");
                    let w = v.map(Vec3::from);
                    let q = w[0] * (1.0 - s.b1 - s.b2) + w[1] * s.b1 + w[2] * s.b2;
                    let hit = Vec3::from(p) + Vec3::from(s.wi) * s.dist;
                    assert!(
                        (q - hit).length() < 1e-3 * s.dist.max(1.0),
                        "{q:?} vs {hit:?}"
                    );
                    let back = pdf(&v, p, s.wi, s.dist);
                    assert!(
                        (back - s.pdf).abs() <= 2e-3 * s.pdf,
                        "pdf {back} vs {}",
                        s.pdf
                    );
                    sum_inv += 1.0 / s.pdf as f64;
                    n += 1;
                }
            }
            let mean = sum_inv / n as f64;
            assert!(
                (mean - omega as f64).abs() < 0.01 * omega as f64,
                "mean 1/pdf {mean} vs solid angle {omega}"
            );
        }
    }

    #[test]
    fn one_sided_emission_samples_only_its_side() {
        let v = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        // The normal is +z: a point above sees the front.
        assert!(sample(&v, [0.2, 0.2, 1.0], [0.3, 0.6], true, false).is_some());
        assert!(sample(&v, [0.2, 0.2, -1.0], [0.3, 0.6], true, false).is_none());
        assert!(sample(&v, [0.2, 0.2, -1.0], [0.3, 0.6], false, true).is_some());
    }
}
