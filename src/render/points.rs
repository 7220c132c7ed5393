//! Point clouds as Cycles 4.5 renders them: each point a sphere of its radius
//! (kernel/geom/point_intersect.h): the ray's first crossing into the sphere only
//! (Cycles culls its back faces, so a ray leaving a point never hits it again), shaded
//! with the sphere's normal, true and shading alike (point_shader_setup). Under a
//! transform that is no rotation times one scale Cycles keeps the cloud in object space
//! (its transform is not applied), so a point is the ellipsoid its sphere becomes, and
//! point_shader_setup still takes the direction from the centre as the normal. A point cloud
//! rides the hair machinery (`render::curves`): an `ObjectCurves` with `points` set,
//! each key a sphere, in the same box BVH beside the triangles.

use crate::render::curves::{ObjectCurves, RibbonHit};
use crate::render::math::*;

/// `points` (object space: x, y, z, radius) placed by `to_world`: centres in world
/// space, radii scaled by the cube root of the transform's determinant, as Cycles
/// applies an object's transform to its points; under a transform that is no rotation
/// times one scale, object radii and the transform's linear part (`ellipsoid`).
pub fn object_points(points: &[[f32; 4]], to_world: &Affine) -> ObjectCurves {
    let m = &to_world.m;
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let linear: [[f32; 3]; 3] = std::array::from_fn(|i| [m[i][0], m[i][1], m[i][2]]);
    let ellipsoid = (!similarity(to_world)).then(|| (linear, inverse3(&linear, det)));
    let scale_r = if ellipsoid.is_some() {
        1.0
    } else {
        det.abs().cbrt()
    };
    let keys: Vec<[f32; 4]> = points
        .iter()
        .map(|k| {
            let p = to_world.point([k[0], k[1], k[2]]);
            [p[0], p[1], p[2], k[3] * scale_r]
        })
        .collect();
    let n = keys.len() as u32;
    ObjectCurves {
        curves: (0..n).map(|i| (i, 1)).collect(),
        slot: vec![0; n as usize],
        length: vec![0.0; n as usize],
        intercept: vec![0.0; n as usize],
        segments: (0..n).map(|i| (i, i)).collect(),
        keys,
        pieces: 0,
        points: true,
        ellipsoid,
        ..ObjectCurves::default()
    }
}

/// Cycles' point_intersect_test: the nearer crossing of the ray into sphere `p` (centre,
/// radius) within [tmin, tmax], front faces only. The hit's (u, v) carry the unit normal
/// at it as polar and azimuth angles (`normal_of`), since shading gets no ray.
pub fn sphere_intersect(org: V3, dir: V3, tmin: f32, tmax: f32, p: [f32; 4]) -> Option<RibbonHit> {
    let (org, dir) = (Vec3::from(org), Vec3::from(dir));
    let center = vec3(p[0], p[1], p[2]);
    let r2 = p[3] * p[3];
    let rd2 = 1.0 / dir.dot(dir);
    let c0 = center - org;
    let proj = c0.dot(dir) * rd2;
    let perp = c0 - dir * proj;
    let l2 = perp.dot(perp);
    if !(l2 <= r2) {
        return None;
    }
    let t = proj - ((r2 - l2) * rd2).sqrt();
    if !(tmin <= t && t <= tmax) {
        return None;
    }
    let hit = org + dir * t;
    let n = hit - center;
    let n = if n.is_zero() { -dir } else { n.normalize() };
    Some(RibbonHit {
        t,
        u: n.z.clamp(-1.0, 1.0).acos(),
        v: n.y.atan2(n.x),
    })
}

/// The ray against the ellipsoid `p`: its centre and radius in `p[0]`, the rows of the
/// inverse of its transform's linear part in `p[1..4]`. The ray is taken to the sphere's
/// space (t unchanged) and met there as Cycles meets a point in object space; the hit's
/// (u, v) carry the unit direction from the centre in that space (`normal_of`).
pub fn ellipsoid_intersect(
    org: V3,
    dir: V3,
    tmin: f32,
    tmax: f32,
    p: &[[f32; 4]; 4],
) -> Option<RibbonHit> {
    let row = |i: usize| vec3(p[i][0], p[i][1], p[i][2]);
    let inv = |v: Vec3| [row(1).dot(v), row(2).dot(v), row(3).dot(v)];
    let o = inv(Vec3::from(org) - row(0));
    sphere_intersect(o, inv(dir.into()), tmin, tmax, [0.0, 0.0, 0.0, p[0][3]])
}

/// The inverse of `m` whose determinant is `det` (zero when `det` is zero: a flattened
/// cloud then hits nothing).
fn inverse3(m: &[[f32; 3]; 3], det: f32) -> [[f32; 3]; 3] {
    if det == 0.0 || !det.is_finite() {
        return [[0.0; 3]; 3];
    }
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let r = 1.0 / det;
    [
        [c(1, 1, 2, 2) * r, -c(0, 1, 2, 2) * r, c(0, 1, 1, 2) * r],
        [-c(1, 0, 2, 2) * r, c(0, 0, 2, 2) * r, -c(0, 0, 1, 2) * r],
        [c(1, 0, 2, 1) * r, -c(0, 0, 2, 1) * r, c(0, 0, 1, 1) * r],
    ]
}

/// The world position and normal of a point hit whose (u, v) carry the direction from
/// the centre (`normal_of`) in the point's own space: on a sphere the point at its
/// radius; on an ellipsoid that point mapped by the linear part, the normal pointing from
/// the centre to it (Cycles' point_shader_setup: normalize(P - centre), not the
/// ellipsoid's surface normal).
pub fn point_hit(c: &ObjectCurves, point: usize, u: f32, v: f32) -> (V3, V3) {
    let k = c.keys[point];
    let center = vec3(k[0], k[1], k[2]);
    let n = Vec3::from(normal_of(u, v));
    let (p, n) = match &c.ellipsoid {
        None => (center + n * k[3], n),
        Some((m, _)) => {
            let local = n * k[3];
            let off = vec3(
                Vec3::from(m[0]).dot(local),
                Vec3::from(m[1]).dot(local),
                Vec3::from(m[2]).dot(local),
            );
            let n = if off.is_zero() { n } else { off.normalize() };
            (center + off, n)
        }
    };
    (p.into(), n.into())
}

/// What Point Info > Radius reads for `point`: its radius, or on an ellipsoid the length
/// of the linear part applied to (r, r, r) / sqrt(3) (Cycles' point_radius when the
/// object's transform is not applied).
pub fn point_radius(c: &ObjectCurves, point: usize) -> f32 {
    let r = c.keys[point][3];
    match &c.ellipsoid {
        None => r,
        Some((m, _)) => {
            let d = Vec3::splat(r * (1.0 / 3f32.sqrt()));
            let row = |i: usize| Vec3::from(m[i]).dot(d);
            vec3(row(0), row(1), row(2)).length()
        }
    }
}

/// Each point's index in its own cloud: the clouds of an object follow each other, each
/// in a material slot of its own (`slots`), and Cycles numbers every cloud from 0.
pub fn index_in_cloud(slots: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(slots.len());
    let mut k = 0u32;
    for (i, s) in slots.iter().enumerate() {
        k = if i > 0 && slots[i - 1] == *s {
            k + 1
        } else {
            0
        };
        out.push(k);
    }
    out
}

/// The unit normal a `sphere_intersect` hit carries in (u, v).
#[inline]
pub fn normal_of(u: f32, v: f32) -> V3 {
    let (s, c) = u.sin_cos();
    [s * v.cos(), s * v.sin(), c]
}

/// What blendsynth cannot render on point clouds, named: materials with a volume, true
/// displacement, emission, the Hair BSDFs or Subsurface Scattering (as on hair).
pub fn check(
    geo: &crate::render::build::Geometry,
    materials: &[crate::render::integrator::shade::Material],
) -> Result<(), crate::render::RenderError> {
    let points = geo
        .instances
        .iter()
        .filter(|i| i.curves.as_ref().is_some_and(|c| c.points));
    for inst in points {
        for mi in inst.slots.iter().flatten() {
            let m = &materials[*mi];
            let Some(p) = &m.program else {
                continue;
            };
            let why = if p.volume.is_some() {
                Some("a volume".to_string())
            } else if p.displacement.is_some() {
                Some("true displacement".to_string())
            } else if p.emission_estimate.iter().any(|&e| e != 0.0) {
                Some("emission".to_string())
            } else {
                p.bsdfs
                    .iter()
                    .find(|b| {
                        matches!(
                            b.bl_idname.as_str(),
                            "ShaderNodeBsdfHair"
                                | "ShaderNodeBsdfHairPrincipled"
                                | "ShaderNodeSubsurfaceScattering"
                        )
                    })
                    .map(|b| format!("node {}", b.bl_idname))
            };
            if let Some(why) = why {
                return Err(crate::render::RenderError(format!(
                    "object {:?}: its point cloud's material {:?} has {why}, which blendsynth does not render on points yet",
                    inst.name, m.name
                )));
            }
        }
    }
    Ok(())
}

/// Whether `t`'s linear part is a rotation times one scale (columns of one length, at
/// right angles), to a relative 1e-5.
pub fn similarity(t: &Affine) -> bool {
    let c = [t.column_vec3(0), t.column_vec3(1), t.column_vec3(2)];
    let s = c[0].dot(c[0]);
    let eps = 1e-5 * s;
    (c[1].dot(c[1]) - s).abs() <= eps
        && (c[2].dot(c[2]) - s).abs() <= eps
        && c[0].dot(c[1]).abs() <= eps
        && c[0].dot(c[2]).abs() <= eps
        && c[1].dot(c[2]).abs() <= eps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_numbered_within_their_own_cloud() {
        assert_eq!(index_in_cloud(&[3, 3, 3, 4, 4, 0]), vec![0, 1, 2, 0, 1, 0]);
        assert!(index_in_cloud(&[]).is_empty());
    }

    #[test]
    fn only_uniform_scales_keep_spheres() {
        let t = |d: [f32; 3]| Affine {
            m: [
                [d[0], 0.0, 0.0, 1.0],
                [0.0, d[1], 0.0, 2.0],
                [0.0, 0.0, d[2], 3.0],
            ],
        };
        assert!(similarity(&t([1.3, 1.3, 1.3])));
        assert!(!similarity(&t([1.0, 1.0, 1.3])));
    }

    #[test]
    fn a_non_uniform_scale_makes_ellipsoids() {
        let t = Affine {
            m: [
                [2.0, 0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 0.5, 0.0],
            ],
        };
        let c = object_points(&[[0.0, 0.0, 0.0, 0.1]], &t);
        assert_eq!(c.keys[0], [1.0, 0.0, 0.0, 0.1]);
        let (_, p) = c.query_prim(0);
        // Along x the point reaches 0.2 from its centre, along z 0.05.
        let h = ellipsoid_intersect([-5.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 100.0, &p).unwrap();
        assert!((h.t - 5.8).abs() < 1e-5, "{h:?}");
        let h = ellipsoid_intersect([1.0, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &p).unwrap();
        assert!((h.t - 4.95).abs() < 1e-5, "{h:?}");
        let (q, n) = point_hit(&c, 0, h.u, h.v);
        assert!(
            (Vec3::from(q) - vec3(1.0, 0.0, 0.05)).length() < 1e-5 && (n[2] - 1.0).abs() < 1e-5
        );
        // Off the axes the normal points from the centre, not across the surface.
        let h = ellipsoid_intersect([1.1, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, &p).unwrap();
        let (q, n) = point_hit(&c, 0, h.u, h.v);
        assert!(
            (q[0] - 1.1).abs() < 1e-5
                && (Vec3::from(n) - (Vec3::from(q) - Vec3::X).normalize()).length() < 1e-5
        );
        let (lo, hi) = c.segment_bounds(0);
        assert!((hi[0] - 1.2).abs() < 1e-6 && (lo[2] + 0.05).abs() < 1e-6);
        // A uniform scale keeps spheres of the scaled radius.
        let u = object_points(
            &[[0.0, 0.0, 0.0, 0.1]],
            &Affine {
                m: [
                    [2.0, 0.0, 0.0, 0.0],
                    [0.0, 2.0, 0.0, 0.0],
                    [0.0, 0.0, 2.0, 0.0],
                ],
            },
        );
        assert!(u.ellipsoid.is_none() && (u.keys[0][3] - 0.2).abs() < 1e-6);
    }

    #[test]
    fn a_ray_hits_the_front_of_the_sphere_only() {
        let p = [0.0, 0.0, 5.0, 1.0];
        let h = sphere_intersect([0.0; 3], [0.0, 0.0, 1.0], 0.0, 100.0, p).unwrap();
        assert!((h.t - 4.0).abs() < 1e-5);
        let n = normal_of(h.u, h.v);
        assert!((n[2] + 1.0).abs() < 1e-5, "{n:?}");
        // From inside (leaving the point): no hit, as Cycles culls back faces.
        assert!(sphere_intersect([0.0, 0.0, 5.0], [0.0, 0.0, 1.0], 0.0, 100.0, p).is_none());
        // A miss beside it, and a hit beyond tmax.
        assert!(sphere_intersect([1.5, 0.0, 0.0], [0.0, 0.0, 1.0], 0.0, 100.0, p).is_none());
        assert!(sphere_intersect([0.0; 3], [0.0, 0.0, 1.0], 0.0, 3.0, p).is_none());
        // An unnormalised direction gives t in its units.
        let h = sphere_intersect([0.0; 3], [0.0, 0.0, 2.0], 0.0, 100.0, p).unwrap();
        assert!((h.t - 2.0).abs() < 1e-5);
    }
}
