//! Hair curves as Cycles 4.5 renders them by default: Rounded Ribbons (Render > Curves >
//! Shape), Catmull-Rom interpolation through the keys (end keys repeated), each segment
//! cut into 2^subdivisions straight pieces that are intersected as flat quads facing the
//! ray (kernel/geom/curve_intersect.h, ribbon_intersect), and shaded with a normal
//! rounded across the ribbon as if it were a tube (kernel/geom/curve.h,
//! curve_shader_setup). Keys are in world space with the radius scaled by the cube root
//! of the object's determinant, as Cycles applies an object's transform to its hair.
//!
//! Scene prims: a curve segment is a `TriRef` (instance, segment) after every triangle,
//! with a degenerate triangle at its index in `Geometry::tris` so per-prim arrays line up;
//! `CurveAccel` finds the segments, `with_curves` puts it beside the triangle BVH.

use std::sync::Arc;

use crate::foundation::box_tree::{BoxTree, Split};
use crate::foundation::bvh::{Accel, Hit};
use crate::render::math::*;
use crate::scene::hair::HairData;

/// A 3x3 matrix by rows.
pub type Mat3 = [[f32; 3]; 3];

/// One object's hair in world space.
#[derive(Debug, Clone, Default)]
pub struct ObjectCurves {
    /// x, y, z, radius per key.
    pub keys: Vec<[f32; 4]>,
    /// Per curve: first key and key count.
    pub curves: Vec<(u32, u32)>,
    /// Per curve: the object's material slot.
    pub slot: Vec<u32>,
    /// Per curve: its length in object space (Hair Info > Length, Cycles' curve_length).
    pub length: Vec<f32>,
    /// Per key: the fraction of its curve's length up to it (Hair Info > Intercept).
    pub intercept: Vec<f32>,
    /// Per segment: its curve and first key (the segment runs to the next key).
    pub segments: Vec<(u32, u32)>,
    /// Ribbons: straight pieces per segment are 2^subdivisions.
    pub pieces: u32,
    /// Cycles' 3D Curves (`render::thick_curves`) instead of ribbons.
    pub thick: bool,
    /// Per key: the curves' normal attribute (a Curves object's exported normals, object
    /// space, as Cycles reads them: its hair transform leaves them as they are); empty
    /// without.
    pub normals: Vec<[f32; 3]>,
    /// Whether the export carried the normals (`HairData::has_normals`).
    pub has_normals: bool,
    /// Attributes by name, per key (true) or per curve (`HairData::attributes`).
    pub attributes: Vec<(String, bool, crate::scene::mesh::AttributeData)>,
    /// The hair's UV (Texture Coordinate > UV): one value per curve or per key.
    pub uv: Option<(bool, Vec<[f32; 2]>)>,
    /// A point cloud instead (`render::points`): each key a sphere (centre, radius),
    /// each its own "curve" and "segment"; `pieces` is 0.
    pub points: bool,
    /// Points: each one's index in its own cloud (Point Info > Random hashes it).
    pub point_index: Vec<u32>,
    /// Points under a transform that is no rotation times one scale: its linear part and
    /// that part's inverse. Cycles then keeps the cloud in object space, so each point is
    /// the ellipsoid its sphere becomes (keys hold world centres and object radii).
    pub ellipsoid: Option<(Mat3, Mat3)>,
}

impl ObjectCurves {
    /// `hair` (object space) placed by `to_world`, each curve of n keys as n - 1
    /// segments (Cycles' curve segments).
    pub fn new(hair: &HairData, to_world: &Affine, subdivisions: u32, thick: bool) -> ObjectCurves {
        let det = {
            let m = &to_world.m;
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let radius_scale = det.abs().cbrt();
        let keys: Vec<[f32; 4]> = hair
            .keys
            .iter()
            .map(|k| {
                let p = to_world.point([k[0], k[1], k[2]]);
                [p[0], p[1], p[2], k[3] * radius_scale]
            })
            .collect();
        let mut length = Vec::with_capacity(hair.curves.len());
        let mut intercept = vec![0.0; keys.len()];
        let mut segments = Vec::new();
        for (ci, &(first, count)) in hair.curves.iter().enumerate() {
            let (f, n) = (first as usize, count as usize);
            let mut along = 0.0f32;
            let mut acc = vec![0.0f32; n];
            for k in 1..n {
                let (a, b) = (hair.keys[f + k - 1], hair.keys[f + k]);
                along += len(sub([b[0], b[1], b[2]], [a[0], a[1], a[2]]));
                acc[k] = along;
            }
            for k in 0..n {
                intercept[f + k] = if along > 0.0 { acc[k] / along } else { 0.0 };
            }
            length.push(along);
            for k in 0..n.saturating_sub(1) {
                segments.push((ci as u32, (f + k) as u32));
            }
        }
        ObjectCurves {
            keys,
            curves: hair.curves.clone(),
            slot: hair.curve_slot.clone(),
            length,
            intercept,
            segments,
            pieces: 1 << subdivisions.min(24),
            thick,
            normals: hair.normals.clone(),
            has_normals: hair.has_normals,
            attributes: hair.attributes.clone(),
            uv: hair.uv.as_deref().and_then(|n| {
                hair.attributes
                    .iter()
                    .find(|a| a.0 == n)
                    .and_then(|a| match &a.2 {
                        crate::scene::mesh::AttributeData::Float2(v) => Some((a.1, v.clone())),
                        _ => None,
                    })
            }),
            points: false,
            point_index: Vec::new(),
            ellipsoid: None,
        }
    }

    /// The curves' normal attribute at `u` along segment `seg`, linear between its keys
    /// as Cycles' curve_attribute reads a key attribute (zero without one).
    pub fn normal_at(&self, seg: u32, u: f32) -> V3 {
        if self.points || self.normals.is_empty() {
            return [0.0; 3];
        }
        let k0 = self.segments[seg as usize].1 as usize;
        let (a, b) = (self.normals[k0], self.normals[k0 + 1]);
        std::array::from_fn(|i| (b[i] - a[i]) * u + a[i])
    }

    /// What a ray query needs of segment `seg`: its shape and four points (a point's
    /// centre and radius first; for an ellipsoid then the rows of its inverse linear map).
    pub fn query_prim(&self, seg: u32) -> (Shape, [[f32; 4]; 4]) {
        if self.points {
            let k = self.keys[seg as usize];
            return match &self.ellipsoid {
                None => (Shape::Sphere, [k; 4]),
                Some((_, inv)) => (
                    Shape::Ellipsoid,
                    [
                        k,
                        [inv[0][0], inv[0][1], inv[0][2], 0.0],
                        [inv[1][0], inv[1][1], inv[1][2], 0.0],
                        [inv[2][0], inv[2][1], inv[2][2], 0.0],
                    ],
                ),
            };
        }
        let shape = if self.thick {
            Shape::Thick
        } else {
            Shape::Ribbon(self.pieces)
        };
        (shape, self.control_points(seg))
    }

    /// The hair's UV at `u` along segment `seg` (zero without one).
    pub fn uv_at(&self, seg: u32, u: f32) -> [f32; 3] {
        let (c, k0) = self.segments[seg as usize];
        match &self.uv {
            _ if self.points => [0.0; 3],
            Some((true, v)) => {
                let (a, b) = (v[k0 as usize], v[k0 as usize + 1]);
                [(b[0] - a[0]) * u + a[0], (b[1] - a[1]) * u + a[1], 0.0]
            }
            Some((false, v)) => [v[c as usize][0], v[c as usize][1], 0.0],
            None => [0.0; 3],
        }
    }

    /// The four control points of segment `seg`: the keys before, at its ends and after,
    /// the end keys repeated at a curve's ends (Cycles' ka, k0, k1, kb).
    #[inline]
    pub fn control_points(&self, seg: u32) -> [[f32; 4]; 4] {
        if self.points {
            return [self.keys[seg as usize]; 4];
        }
        let (c, k0) = self.segments[seg as usize];
        let (first, count) = self.curves[c as usize];
        let last = first + count - 1;
        let k = [
            k0.saturating_sub(1).max(first),
            k0,
            k0 + 1,
            (k0 + 2).min(last),
        ];
        k.map(|i| self.keys[i as usize])
    }

    /// What Hair Info reads at `u` along segment `seg`, with the curve's tangent `dpdu`
    /// there and `wi` the unit direction back along the ray (Cycles' sd->wi).
    pub fn hair_point(&self, seg: u32, u: f32, dpdu: V3, wi: V3) -> crate::shader::HairPoint {
        if self.points {
            // Cycles' Hair Info reads nothing on points.
            return crate::shader::HairPoint::default();
        }
        let (c, k0) = self.segments[seg as usize];
        let (k0, k1) = (k0 as usize, k0 as usize + 1);
        let lerp = |a: f32, b: f32| (b - a) * u + a;
        let d2 = dot(dpdu, dpdu);
        let along = if d2 > 0.0 { dot(dpdu, wi) / d2 } else { 0.0 };
        crate::shader::HairPoint {
            is_strand: 1.0,
            intercept: lerp(self.intercept[k0], self.intercept[k1]),
            length: self.length[c as usize],
            thickness: 2.0 * lerp(self.keys[k0][3], self.keys[k1][3]),
            tangent_normal: normalize(sub(wi, scale(dpdu, along))),
            random: crate::nodes::random::hash_to_float2(c, 0),
            thick: self.thick,
            curve_normal: self.normal_at(seg, u),
        }
    }

    /// World-space bounds of segment `seg` with its radius: the Bezier form of the
    /// Catmull-Rom segment lies in its control points' hull.
    pub fn segment_bounds(&self, seg: u32) -> (V3, V3) {
        if self.points {
            let k = self.keys[seg as usize];
            let r = k[3].abs();
            // An ellipsoid reaches r times its linear map's row length along each axis.
            let e: V3 = match &self.ellipsoid {
                None => [r; 3],
                Some((m, _)) => std::array::from_fn(|i| r * len(m[i])),
            };
            return (sub([k[0], k[1], k[2]], e), add([k[0], k[1], k[2]], e));
        }
        let p = self.control_points(seg);
        let b = [
            p[1],
            std::array::from_fn(|i| p[1][i] + (p[2][i] - p[0][i]) / 6.0),
            std::array::from_fn(|i| p[2][i] - (p[3][i] - p[1][i]) / 6.0),
            p[2],
        ];
        let r = b.iter().fold(0.0f32, |m, q: &[f32; 4]| m.max(q[3].abs()));
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for q in &b {
            lo = vmin(lo, [q[0], q[1], q[2]]);
            hi = vmax(hi, [q[0], q[1], q[2]]);
        }
        (sub(lo, [r; 3]), add(hi, [r; 3]))
    }
}

/// Catmull-Rom point (and radius in w) at `u` in [0, 1] of the segment between
/// `c[1]` and `c[2]` (Cycles' catmull_rom_basis_eval).
#[inline]
pub fn catmull_rom(c: &[[f32; 4]; 4], u: f32) -> [f32; 4] {
    let (t, s) = (u, 1.0 - u);
    let n = [
        -t * s * s,
        2.0 + t * t * (3.0 * t - 5.0),
        2.0 + s * s * (3.0 * s - 5.0),
        -s * t * t,
    ];
    std::array::from_fn(|i| {
        0.5 * (c[0][i] * n[0] + c[1][i] * n[1] + c[2][i] * n[2] + c[3][i] * n[3])
    })
}

/// d/du of `catmull_rom` (Cycles' catmull_rom_basis_derivative).
#[inline]
pub fn catmull_rom_derivative(c: &[[f32; 4]; 4], u: f32) -> [f32; 4] {
    let (t, s) = (u, 1.0 - u);
    let n = [
        -s * s + 2.0 * s * t,
        2.0 * t * (3.0 * t - 5.0) + 3.0 * t * t,
        2.0 * s * (3.0 * t + 2.0) - 3.0 * s * s,
        -2.0 * s * t + t * t,
    ];
    std::array::from_fn(|i| {
        0.5 * (c[0][i] * n[0] + c[1][i] * n[1] + c[2][i] * n[2] + c[3][i] * n[3])
    })
}

/// A ribbon hit: distance, position along the segment (0..1) and across the ribbon
/// (-1..1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RibbonHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// The ray's frame (Cycles' ribbon_ray_space): two axes across `d` (unit) and `d`.
#[inline]
fn ray_space(d: V3) -> [V3; 3] {
    let dx0 = [0.0, d[2], -d[1]];
    let dx1 = [-d[2], 0.0, d[0]];
    let x = normalize(if dot(dx0, dx0) > dot(dx1, dx1) {
        dx0
    } else {
        dx1
    });
    let y = normalize(cross(d, x));
    [x, y, d]
}

/// The ray `org + t dir` (`dir` unit) against the ribbon of the Catmull-Rom segment `c`
/// cut into `pieces` straight quads facing the ray, as Cycles' ribbon_intersect: the
/// first quad hit within [tmin, tmax] farther than twice its radius (Cycles' self-
/// intersection avoidance).
pub fn ribbon_intersect(
    org: V3,
    dir: V3,
    tmin: f32,
    tmax: f32,
    pieces: u32,
    c: &[[f32; 4]; 4],
) -> Option<RibbonHit> {
    let space = ray_space(dir);
    let cr: [[f32; 4]; 4] = c.map(|p| {
        let q = sub([p[0], p[1], p[2]], org);
        [dot(space[0], q), dot(space[1], q), dot(space[2], q), p[3]]
    });
    let mx = cr.iter().fold(0.0f32, |m, p| {
        m.max(p[0].abs())
            .max(p[1].abs())
            .max(p[2].abs())
            .max(p[3].abs())
    });
    let eps = 4.0 * f32::EPSILON * mx;
    let step = 1.0 / pieces as f32;
    let xyz = |p: [f32; 4]| [p[0], p[1], p[2]];
    let side = |d: V3, r: f32| scale(normalize([d[1], -d[0], 0.0]), r);
    let mut p0 = catmull_rom(&cr, 0.0);
    let mut d0 = xyz(catmull_rom_derivative(&cr, 0.0));
    if max3(d0.map(f32::abs)) < eps {
        d0 = sub(xyz(catmull_rom(&cr, step)), xyz(p0));
    }
    let mut wn0 = side(d0, p0[3]);
    for i in 0..pieces {
        let u = i as f32 * step;
        let p1 = catmull_rom(&cr, u + step);
        let valid = cylinder_culling([p0[0], p0[1]], [p1[0], p1[1]], p0[3].max(p1[3]));
        let mut d1 = xyz(catmull_rom_derivative(&cr, u + step));
        if max3(d1.map(f32::abs)) < eps {
            d1 = sub(xyz(p1), xyz(p0));
        }
        let wn1 = side(d1, p1[3]);
        if valid {
            let lp0 = add(xyz(p0), wn0);
            let lp1 = add(xyz(p1), wn1);
            let up0 = sub(xyz(p0), wn0);
            let up1 = sub(xyz(p1), wn1);
            if let Some((vu, vv, vt)) = intersect_quad(tmin, tmax, lp0, lp1, up1, up0) {
                let r = p0[3] + (p1[3] - p0[3]) * vu;
                if vt > 2.0 * r {
                    return Some(RibbonHit {
                        t: vt,
                        u: u + vu * step,
                        v: 2.0 * vv - 1.0,
                    });
                }
            }
        }
        p0 = p1;
        wn0 = wn1;
    }
    None
}

/// Whether the piece from `a` to `b` (ray space, the ray along z through the origin)
/// passes within `r` of the ray (Cycles' cylinder_culling_test).
#[inline]
fn cylinder_culling(a: [f32; 2], b: [f32; 2], r: f32) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let num = d[0] * a[1] - d[1] * a[0];
    num * num <= r * r * (d[0] * d[0] + d[1] * d[1])
}

/// The ray along +z from the origin against the quad v0 v1 v2 v3 (ray space), split into
/// the triangles v0 v1 v3 and v2 v3 v1 by the side of edge v1 v3 the ray passes (Cycles'
/// ribbon_intersect_quad): (u along v0 v1, v along v0 v3, t).
#[inline]
fn intersect_quad(tmin: f32, tmax: f32, va: V3, vb: V3, vc: V3, vd: V3) -> Option<(f32, f32, f32)> {
    let dz = |a: V3| a[2];
    let edb = sub(vb, vd);
    let ww = dz(cross(vd, edb));
    let first = ww <= 0.0;
    let (v0, v1, v2) = if first { (va, vb, vd) } else { (vc, vd, vb) };
    let e0 = sub(v2, v0);
    let e1 = sub(v0, v1);
    let uu = dz(cross(v0, e0));
    let vv = dz(cross(v1, e1));
    if !(uu.max(vv) <= 0.0) {
        return None;
    }
    let ng = cross(e1, e0);
    let den = ng[2];
    let rcp = 1.0 / den;
    let t = rcp * dot(v0, ng);
    if !(t >= tmin && t <= tmax) || den == 0.0 {
        return None;
    }
    let (mut u, mut v) = (uu * rcp, vv * rcp);
    if !first {
        u = 1.0 - u;
        v = 1.0 - v;
    }
    Some((u, v, t))
}

/// The hit point, smooth normal and tangent (dP/du, world space) of a ribbon hit at
/// (`u`, `v`) on segment `c` seen along `dir` (unit), as Cycles' curve_shader_setup:
/// the normal turns from facing the ray at the ribbon's middle to its side at the edges,
/// as on a tube. The point is on the straight piece the ray hit.
pub fn ribbon_shading(c: &[[f32; 4]; 4], pieces: u32, u: f32, v: f32, dir: V3) -> (V3, V3, V3) {
    let xyz = |p: [f32; 4]| [p[0], p[1], p[2]];
    let dpdu = xyz(catmull_rom_derivative(c, u));
    let tangent = normalize(dpdu);
    let bitangent = normalize(cross(tangent, neg(dir)));
    let sine = v;
    let cosine = (1.0 - sine * sine).max(0.0).sqrt();
    let n = normalize(sub(
        scale(bitangent, sine),
        scale(normalize(cross(tangent, bitangent)), cosine),
    ));
    // The point on the straight piece: its ends' centres offset across the ray by the
    // radius, mixed as the quad's corners are.
    let step = 1.0 / pieces as f32;
    let i = ((u / step).floor()).clamp(0.0, pieces as f32 - 1.0);
    let (ua, ub) = (i * step, (i + 1.0) * step);
    let f = ((u - ua) / step).clamp(0.0, 1.0);
    let across = |w: f32| {
        let p = catmull_rom(c, w);
        let d = xyz(catmull_rom_derivative(c, w));
        let s = cross(d, dir);
        let s = if is_zero(s) { s } else { normalize(s) };
        // Cycles' side vector (dy, -dx) in ray space is d x dir; v = -1 at +side.
        sub(xyz(p), scale(s, v * p[3]))
    };
    let p = add(scale(across(ua), 1.0 - f), scale(across(ub), f));
    (p, n, dpdu)
}

/// How a prim of the curve structure is intersected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Rounded Ribbons cut into this many straight pieces per segment.
    Ribbon(u32),
    /// 3D Curves (`render::thick_curves`).
    Thick,
    /// A point's sphere, or its ellipsoid under a non-uniform scale (`render::points`).
    Sphere,
    Ellipsoid,
}

/// The scene's curve segments behind one ray query.
pub struct CurveAccel {
    bvh: BoxTree,
    /// Per segment in the BVH: its scene prim id, control points, shape and the
    /// visibility mask of its object.
    prims: Vec<u32>,
    points: Vec<[[f32; 4]; 4]>,
    shapes: Vec<Shape>,
    masks: Vec<u32>,
    /// Per segment: its curve (instance and curve index), and per scene prim the curve
    /// it belongs to (u32::MAX for triangles): what a ray leaving a curve skips.
    curve_of: Vec<u32>,
    curve_by_prim: Vec<u32>,
}

thread_local! {
    /// The scene prim the current path vertex lies on (Cycles' ray->self.prim): rays
    /// traced from it on this thread skip every segment of its curve.
    static RAY_SELF: std::cell::Cell<Option<u32>> = const { std::cell::Cell::new(None) };
}

/// Sets the prim the rays traced next on this thread leave from (None: the camera, or
/// no surface). Cycles' rays skip the curve they leave (intersection_skip_self: its self
/// prim is the curve, not the segment) besides the hits nearer than twice the radius:
/// without the skip a transmitted ray met its own strand again further on, and
/// `tests/render.rs` scene hair_bsdf rendered 1.45% bright (0.31% with it).
pub fn set_ray_self(prim: Option<u32>) {
    RAY_SELF.with(|c| c.set(prim));
}

/// Clears the ray's self prim when dropped, so that no other ray on the thread
/// inherits it.
pub struct RaySelfGuard;

impl Drop for RaySelfGuard {
    fn drop(&mut self) {
        set_ray_self(None);
    }
}

impl CurveAccel {
    /// The segments of `geo`'s curve instances (their prims after the triangles).
    pub fn build(geo: &crate::render::build::Geometry) -> Option<CurveAccel> {
        let (mut prims, mut points, mut shapes, mut masks, mut boxes) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut curve_of = Vec::new();
        let mut curve_by_prim = vec![u32::MAX; geo.refs.len()];
        // Curves numbered in order: an instance's segments are consecutive, and a curve's.
        let (mut last, mut next_id) = (None, 0u32);
        for (prim, r) in geo.refs.iter().enumerate() {
            let inst = &geo.instances[r.inst as usize];
            let Some(c) = &inst.curves else {
                continue;
            };
            let key = (r.inst, c.segments[r.tri as usize].0);
            if last != Some(key) {
                last = Some(key);
                next_id += 1;
            }
            let cid = next_id - 1;
            curve_of.push(cid);
            curve_by_prim[prim] = cid;
            prims.push(prim as u32);
            let (shape, p) = c.query_prim(r.tri);
            points.push(p);
            shapes.push(shape);
            masks.push(inst.visibility);
            boxes.push(c.segment_bounds(r.tri));
        }
        if prims.is_empty() {
            return None;
        }
        Some(CurveAccel {
            bvh: BoxTree::build(&boxes, Split::Median),
            prims,
            points,
            shapes,
            masks,
            curve_of,
            curve_by_prim,
        })
    }

    fn query(&self, org: V3, dir: V3, tmin: f32, tmax: f32, mask: u32, any: bool) -> Option<Hit> {
        let mut best = None;
        let skip = RAY_SELF
            .with(|c| c.get())
            .and_then(|p| self.curve_by_prim.get(p as usize).copied())
            .filter(|&c| c != u32::MAX);
        self.bvh.traverse(org, dir, tmin, tmax, any, |i, far| {
            let i = i as usize;
            if self.masks[i] & mask == 0 {
                return None;
            }
            if skip == Some(self.curve_of[i]) {
                return None;
            }
            let p = &self.points[i];
            let h = match self.shapes[i] {
                Shape::Ribbon(pieces) => ribbon_intersect(org, dir, tmin, far, pieces, p)?,
                Shape::Thick => {
                    crate::render::thick_curves::thick_intersect(org, dir, tmin, far, p)?
                }
                Shape::Sphere => {
                    crate::render::points::sphere_intersect(org, dir, tmin, far, p[0])?
                }
                Shape::Ellipsoid => {
                    crate::render::points::ellipsoid_intersect(org, dir, tmin, far, p)?
                }
            };
            best = Some(Hit {
                t: h.t,
                prim: self.prims[i],
                u: h.u,
                v: h.v,
            });
            Some(h.t)
        });
        best
    }
}

/// The triangle structure and the curves together: the nearer hit of the two.
pub struct WithCurves {
    pub tris: Box<dyn Accel>,
    pub curves: Arc<CurveAccel>,
}

impl Accel for WithCurves {
    fn intersect(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> Option<Hit> {
        self.intersect_vis(
            org,
            dir,
            tmin,
            tmax,
            0.5,
            crate::foundation::bvh::visibility::ALL,
        )
    }
    fn occluded(&self, org: V3, dir: V3, tmin: f32, tmax: f32) -> bool {
        self.occluded_vis(
            org,
            dir,
            tmin,
            tmax,
            0.5,
            crate::foundation::bvh::visibility::ALL,
        )
    }
    fn intersect_vis(
        &self,
        org: V3,
        dir: V3,
        tmin: f32,
        tmax: f32,
        time: f32,
        mask: u32,
    ) -> Option<Hit> {
        let tri = self.tris.intersect_vis(org, dir, tmin, tmax, time, mask);
        let far = tri.map_or(tmax, |h| h.t);
        self.curves.query(org, dir, tmin, far, mask, false).or(tri)
    }
    fn occluded_vis(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32, mask: u32) -> bool {
        self.tris.occluded_vis(org, dir, tmin, tmax, time, mask)
            || self
                .curves
                .query(org, dir, tmin, tmax, mask, true)
                .is_some()
    }
    fn intersect_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32) -> Option<Hit> {
        self.intersect_vis(
            org,
            dir,
            tmin,
            tmax,
            time,
            crate::foundation::bvh::visibility::ALL,
        )
    }
    fn occluded_at(&self, org: V3, dir: V3, tmin: f32, tmax: f32, time: f32) -> bool {
        self.occluded_vis(
            org,
            dir,
            tmin,
            tmax,
            time,
            crate::foundation::bvh::visibility::ALL,
        )
    }
}

/// What blendsynth cannot render on hair, named: materials with volume, true
/// displacement, emission (Cycles' curves are no lights), the Subsurface Scattering node,
/// a Principled Hair BSDF model it does not know, and the Huang model's elliptical fibre
/// on a Curves object exported without its normals; and hair with motion blur or under
/// Embree.
pub fn check(
    scene: &crate::scene::Scene,
    geo: &crate::render::build::Geometry,
    materials: &[crate::render::integrator::shade::Material],
) -> Result<(), crate::render::RenderError> {
    use crate::render::RenderError;
    if geo.instances.iter().any(|i| i.curves.is_some()) {
        let backend = crate::foundation::bvh::Backend::from_env().map_err(RenderError)?;
        if backend == crate::foundation::bvh::Backend::Embree {
            return Err(RenderError("BLENDSYNTH_ACCEL=embree: the scene has hair curves, which blendsynth's Embree backend does not take yet (use bvh4 or bvh2)".into()));
        }
    }
    for inst in geo.instances.iter().filter(|i| i.curves.is_some()) {
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
                p.bsdfs.iter().find_map(|b| match b.bl_idname.as_str() {
                    "ShaderNodeSubsurfaceScattering" => Some(format!("node {}", b.bl_idname)),
                    "ShaderNodeBsdfHairPrincipled"
                        if !matches!(b.property("model"), Some("CHIANG" | "HUANG")) =>
                    {
                        Some(format!(
                            "node {} with model {:?} (the Chiang and Huang models are rendered)",
                            b.bl_idname,
                            b.property("model").unwrap_or("?")
                        ))
                    }
                    // Cycles turns an elliptical fibre about the curve's normal attribute,
                    // which particle hair lacks (an arbitrary frame then) but a Curves
                    // object carries; exports made before the normals were exported lack it.
                    "ShaderNodeBsdfHairPrincipled"
                        if b.property("model") == Some("HUANG")
                            && is_curves_object(scene, &inst.name)
                            && inst.curves.as_ref().is_some_and(|c| !c.has_normals)
                            && huang_aspect_ratio(p, b) != Some(1.0) =>
                    {
                        Some(format!(
                            "node {} (Huang model) with an Aspect Ratio other than 1 on a Curves object whose export lacks the curves' normals the ellipse turns about (convert the .blend again)",
                            b.bl_idname
                        ))
                    }
                    _ => None,
                })
            };
            if let Some(why) = why {
                return Err(RenderError(format!(
                    "object {:?}: its hair's material {:?} has {why}, which blendsynth does not render on hair curves",
                    inst.name, m.name
                )));
            }
        }
    }
    Ok(())
}

/// Whether the instance named `name` is a Curves object's (not particle hair).
fn is_curves_object(scene: &crate::scene::Scene, name: &str) -> bool {
    scene
        .file
        .objects
        .iter()
        .any(|o| o.name == name && o.kind == "CURVES")
}

/// The Huang node's Aspect Ratio when it is a constant (None when linked).
fn huang_aspect_ratio(
    p: &crate::shader::program::Program,
    b: &crate::shader::program::BsdfNode,
) -> Option<f32> {
    match b.input("Aspect Ratio") {
        Some((_, true)) => None,
        Some((slot, false)) => p.initial.get(slot as usize).copied(),
        None => Some(0.85),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight strand along x from 0 to 3 (keys at 0, 1, 2, 3), radius 0.1.
    fn strand() -> ObjectCurves {
        let hair = HairData {
            keys: (0..4).map(|i| [i as f32, 0.0, 0.0, 0.1]).collect(),
            curves: vec![(0, 4)],
            curve_slot: vec![0],
            ..HairData::default()
        };
        let id = Affine {
            m: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
        };
        ObjectCurves::new(&hair, &id, 2, false)
    }

    #[test]
    fn catmull_rom_passes_through_its_keys() {
        let c = [
            [0.0, 0.0, 0.0, 1.0],
            [1.0, 2.0, 0.0, 2.0],
            [3.0, 1.0, 1.0, 3.0],
            [4.0, 0.0, 2.0, 4.0],
        ];
        assert_eq!(catmull_rom(&c, 0.0), c[1]);
        assert_eq!(catmull_rom(&c, 1.0), c[2]);
        // The derivative at the ends is half the chord over the neighbours.
        let d = catmull_rom_derivative(&c, 0.0);
        assert!(
            (d[0] - 1.5).abs() < 1e-6 && (d[1] - 0.5).abs() < 1e-6,
            "{d:?}"
        );
        // Finite differences agree inside.
        let (a, b) = (catmull_rom(&c, 0.399), catmull_rom(&c, 0.401));
        let d = catmull_rom_derivative(&c, 0.4);
        for i in 0..4 {
            assert!(((b[i] - a[i]) / 0.002 - d[i]).abs() < 1e-2);
        }
    }

    #[test]
    fn segments_repeat_the_end_keys_and_measure_the_curve() {
        let s = strand();
        assert_eq!(s.segments, vec![(0, 0), (0, 1), (0, 2)]);
        assert_eq!(s.control_points(0)[0], s.keys[0]);
        assert_eq!(s.control_points(2)[3], s.keys[3]);
        assert_eq!(s.length, vec![3.0]);
        assert_eq!(s.intercept, vec![0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]);
        assert_eq!(s.pieces, 4);
        let (lo, hi) = s.segment_bounds(1);
        assert!(lo[0] <= 1.0 && hi[0] >= 2.0 && lo[1] <= -0.1 && hi[2] >= 0.1);
    }

    #[test]
    fn a_ray_across_the_strand_hits_the_ribbon_at_its_width() {
        let s = strand();
        let c = s.control_points(1);
        // From above, at x = 1.5: hit at t = 5 (the ribbon faces the ray, in the strand's
        // plane), u = 0.5 along the segment, v = 0 across.
        let h = ribbon_intersect([1.5, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, 4, &c).unwrap();
        assert!(
            (h.t - 5.0).abs() < 1e-5 && (h.u - 0.5).abs() < 1e-5 && h.v.abs() < 1e-5,
            "{h:?}"
        );
        // 0.05 off the axis is half way to the edge; 0.11 off misses.
        let h = ribbon_intersect([1.25, 0.05, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, 4, &c).unwrap();
        assert!(
            (h.v.abs() - 0.5).abs() < 1e-4 && (h.u - 0.25).abs() < 1e-5,
            "{h:?}"
        );
        assert!(ribbon_intersect([1.25, 0.11, 5.0], [0.0, 0.0, -1.0], 0.0, 100.0, 4, &c).is_none());
        // Seen from the side (along y) the ribbon turns to face the ray: same width.
        let h = ribbon_intersect([1.5, -5.0, 0.09], [0.0, 1.0, 0.0], 0.0, 100.0, 4, &c).unwrap();
        assert!(
            (h.t - 5.0).abs() < 1e-5 && (h.v.abs() - 0.9).abs() < 1e-4,
            "{h:?}"
        );
        // Beyond tmax, or nearer than twice the radius (self-intersection avoidance): none.
        assert!(ribbon_intersect([1.5, 0.0, 5.0], [0.0, 0.0, -1.0], 0.0, 4.9, 4, &c).is_none());
        assert!(ribbon_intersect([1.5, 0.0, 0.15], [0.0, 0.0, -1.0], 0.0, 100.0, 4, &c).is_none());
        // A ray along the strand itself passes it (no quad faces it).
        assert!(ribbon_intersect([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 100.0, 4, &c).is_none());
    }

    #[test]
    fn the_normal_rounds_across_the_ribbon_and_the_point_lies_on_it() {
        let s = strand();
        let c = s.control_points(1);
        let d = [0.0, 0.0, -1.0];
        // Middle: facing the ray.
        let (p, n, t) = ribbon_shading(&c, 4, 0.5, 0.0, d);
        assert!(
            len(sub(p, [1.5, 0.0, 0.0])) < 1e-5 && len(sub(n, [0.0, 0.0, 1.0])) < 1e-5,
            "{p:?} {n:?}"
        );
        assert!(t[0] > 0.0 && t[1].abs() < 1e-6);
        // Where a ray hit at v: the point is that far across, the normal tilts toward the
        // edge by asin(v), as on a tube.
        let h = ribbon_intersect([1.25, 0.05, 5.0], d, 0.0, 100.0, 4, &c).unwrap();
        let (p, n, _) = ribbon_shading(&c, 4, h.u, h.v, d);
        assert!(len(sub(p, [1.25, 0.05, 0.0])) < 1e-4, "{p:?}");
        assert!(
            (n[1] - 0.5).abs() < 1e-4 && (n[2] - 0.75f32.sqrt()).abs() < 1e-4,
            "{n:?}"
        );
    }

    #[test]
    fn the_accel_finds_the_nearest_of_triangles_and_curves() {
        let s = strand();
        let points: Vec<_> = (0..3).map(|i| s.control_points(i)).collect();
        let boxes: Vec<_> = (0..3).map(|i| s.segment_bounds(i)).collect();
        let curves = CurveAccel {
            bvh: BoxTree::build(&boxes, Split::Median),
            prims: vec![10, 11, 12],
            points,
            shapes: vec![Shape::Ribbon(4); 3],
            masks: vec![crate::foundation::bvh::visibility::ALL; 3],
            // Scene prim 0 is the floor triangle, 10..12 the strand's segments (curve 0).
            curve_of: vec![0; 3],
            curve_by_prim: (0..13)
                .map(|p| if p >= 10 { 0 } else { u32::MAX })
                .collect(),
        };
        // A floor triangle below the strand at z = -1.
        let tri = [[-5.0, -5.0, -1.0], [5.0, -5.0, -1.0], [0.0, 5.0, -1.0]];
        let acc = WithCurves {
            tris: Box::new(crate::foundation::bvh::Bvh::build(&[tri])),
            curves: Arc::new(curves),
        };
        let h = acc
            .intersect([2.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 100.0)
            .unwrap();
        assert_eq!(h.prim, 12);
        assert!((h.t - 3.0).abs() < 1e-5);
        let h = acc
            .intersect([0.5, 1.0, 3.0], [0.0, 0.0, -1.0], 0.0, 100.0)
            .unwrap();
        assert_eq!(h.prim, 0);
        assert!(!acc.occluded([0.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 2.0));
        assert!(acc.occluded([0.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 3.5));
        // A ray leaving any segment of the strand skips the whole curve (Cycles' self
        // prim is the curve): it reaches the floor; leaving the floor, it hits the strand.
        {
            let _guard = RaySelfGuard;
            set_ray_self(Some(10));
            let h = acc
                .intersect([2.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 100.0)
                .unwrap();
            assert_eq!(h.prim, 0);
            assert!((h.t - 4.0).abs() < 1e-5);
            assert!(!acc.occluded([2.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 3.5));
            set_ray_self(Some(0));
            let h = acc
                .intersect([2.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 100.0)
                .unwrap();
            assert_eq!(h.prim, 12);
        }
        let h = acc
            .intersect([2.5, 0.0, 3.0], [0.0, 0.0, -1.0], 0.0, 100.0)
            .unwrap();
        assert_eq!(h.prim, 12, "the guard cleared the self prim");
    }
}
