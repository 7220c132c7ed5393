//! Cycles' shadow terminator geometry offset (Object > Shading > Shadow Terminator >
//! Geometry Offset, default 0.1; kernel/light/sample.h `shadow_ray_offset`). A shadow ray
//! leaving a smooth-shaded triangle at a grazing angle to the light starts from the
//! smooth surface the vertex normals describe, a parabolic lift of the flat triangle,
//! instead of the triangle itself. Without it, coarse smooth meshes (displaced grids, the
//! colon's wall) show each triangle's own shadow terminator as dark facets, and the light
//! reaching their lit side at grazing angles is lower than Cycles'.

use crate::render::math::*;

/// Cycles' shadow terminator shading offset (Object > Shading > Shadow Terminator >
/// Shading Offset; kernel/closure/bsdf.h, after appleseed): every closure's value toward a
/// light or sampled direction on its front side is scaled by cos(angle x frequency) /
/// cos(angle), pushing the terminator toward the light. `frequency` is
/// 1 / (1 - offset / 2); `cos_in` is the direction's cosine to the closure's normal.
#[inline]
pub fn shift_cos_in(cos_in: f32, frequency: f32) -> f32 {
    let c = cos_in.min(1.0);
    (c.acos() * frequency).cos().max(0.0) / c
}

/// How much of the lift a shadow ray toward `l` (unit) gets: Cycles' blend over the 10-20%
/// most grazing directions when `cutoff` is 0.1. `n` is the shading normal, `ng` the true
/// normal on the ray's side of the surface. Returns (amount, the true normal on the
/// light's side), the normal `smooth_surface_offset` takes.
pub fn amount(cutoff: f32, n: V3, ng: V3, l: V3) -> (f32, V3) {
    let (n, ng, l) = (Vec3::from(n), Vec3::from(ng), Vec3::from(l));
    let nl = n.dot(l);
    let ng = if nl < 0.0 { -ng } else { ng };
    let nl = nl.abs();
    let ngl = ng.dot(l);
    let a = if nl < cutoff {
        2.0 - (ngl + nl) / cutoff
    } else {
        1.0 - ngl / cutoff
    };
    (a.clamp(0.0, 1.0), ng.into())
}

/// The lift at barycentrics `b` (weights of corners 0, 1, 2) of the triangle with corners
/// `v` and vertex normals `n` (unit, unflipped), toward true normal `ng`: Cycles'
/// `shadow_ray_smooth_surface_offset`, a parabolic height bounded by each corner's
/// tangent plane (the local linear envelope).
pub fn smooth_surface_offset(v: [V3; 3], n: [V3; 3], b: [f32; 3], ng: V3) -> V3 {
    let (v, n, ng) = (v.map(Vec3::from), n.map(Vec3::from), Vec3::from(ng));
    let [u, w1, w2] = b;
    let p = v[0] * u + v[1] * w1 + v[2] * w2;
    // Cycles does not normalise the interpolated normal.
    let ni = n[0] * u + n[1] * w1 + n[2] * w2;
    let a = (n[2] - n[0]).dot(v[0] - v[2]);
    let bb = (n[2] - n[1]).dot(v[1] - v[2]);
    let c = (n[1] - n[0]).dot(v[1] - v[0]);
    let mut h = a * u * (u - 1.0) + (a + bb + c) * u * w1 + bb * w1 * (w1 - 1.0);
    // The corners' envelope: the highest other corner above each corner's tangent plane.
    let reach = |i: usize, j: usize, k: usize, sign: f32| -> f32 {
        (sign * (v[j] - v[i]).dot(n[i]))
            .max(sign * (v[k] - v[i]).dot(n[i]))
            .max(0.0)
    };
    if ni.dot(ng) > 0.0 {
        let h0 = ((v[0] - p).dot(n[0]) + reach(0, 1, 2, 1.0)).max(0.0);
        let h1 = ((v[1] - p).dot(n[1]) + reach(1, 0, 2, 1.0)).max(0.0);
        let h2 = ((v[2] - p).dot(n[2]) + reach(2, 0, 1, 1.0)).max(0.0);
        h = h0.min(h1).min(h2).max(h * 0.5);
    } else {
        let h0 = ((p - v[0]).dot(n[0]) + reach(0, 1, 2, -1.0)).max(0.0);
        let h1 = ((p - v[1]).dot(n[1]) + reach(1, 0, 2, -1.0)).max(0.0);
        let h2 = ((p - v[2]).dot(n[2]) + reach(2, 0, 1, -1.0)).max(0.0);
        h = (-h0.min(h1).min(h2)).min(h * 0.5);
    }
    (ni * h).into()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat triangle whose vertex normals all equal its face normal gets no lift.
    #[test]
    fn flat_triangle_is_not_lifted() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let n = [[0.0, 0.0, 1.0]; 3];
        assert_eq!(
            smooth_surface_offset(v, n, [0.3, 0.3, 0.4], [0.0, 0.0, 1.0]),
            [0.0, 0.0, 0.0]
        );
    }

    /// Vertex normals splayed outward, as on a coarse sphere: the surface they describe
    /// bulges above the flat triangle inside it, and not at the corners.
    #[test]
    fn convex_triangle_is_lifted_inside() {
        let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let n = [
            vec3(-0.3, -0.3, 1.0).normalize().into(),
            vec3(0.3, 0.0, 1.0).normalize().into(),
            vec3(0.0, 0.3, 1.0).normalize().into(),
        ];
        let up = [0.0, 0.0, 1.0];
        let mid = smooth_surface_offset(v, n, [1.0 / 3.0; 3], up);
        assert!(mid[2] > 0.01, "{mid:?}");
        let corner = smooth_surface_offset(v, n, [1.0, 0.0, 0.0], up);
        assert!(Vec3::from(corner).length() < 1e-6, "{corner:?}");
    }

    /// Cycles' blend: no lift for a light well above the surface, full lift where the
    /// shading normal meets the light at a grazing angle and the true normal does too.
    #[test]
    fn amount_follows_the_grazing_angle() {
        let up = [0.0, 0.0, 1.0];
        assert_eq!(amount(0.1, up, up, up).0, 0.0);
        let grazing: V3 = vec3(1.0, 0.0, 0.02).normalize().into();
        assert_eq!(amount(0.1, up, up, grazing).0, 1.0);
        // Shading normal tilted toward the light, true normal grazing: the band above
        // the cutoff, 1 - NgL / cutoff.
        let l: V3 = vec3(1.0, 0.0, 0.05).normalize().into();
        let a = amount(0.1, vec3(0.5, 0.0, 1.0).normalize().into(), up, l).0;
        assert!(
            (a - (1.0 - l[2] / 0.1)).abs() < 1e-6 && a > 0.4 && a < 0.6,
            "{a}"
        );
        // A light behind the shading normal: the true normal is taken on the light's side.
        let (_, ng) = amount(0.1, up, up, [0.0, 0.0, -1.0]);
        assert_eq!(ng, [0.0, 0.0, -1.0]);
    }
}
