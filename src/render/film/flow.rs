//! Optical flow and occlusion from the geometry the image is rendered with.
//!
//! Per pixel: the surface point the label passes see (the primary ray through the pixel
//! centre: instance, triangle and barycentrics), placed on the same triangle of the same
//! instance in the scene evaluated at another frame, and projected with that frame's
//! camera. This is what Cycles' Vector pass computes from its previous/next-frame
//! object transforms and ATTR_STD_MOTION_VERTEX_POSITION (kernel/geom/primitive.h,
//! primitive_motion_vector), without its sign and y conventions: here flow is the
//! motion *to* the other frame, in pixels, x right and y down.
//!
//! A pixel's flow is invalid (NaN) when it sees no surface, when its instance is not in
//! the other frame (or not once), when the instance's mesh changes topology between the
//! frames (vertex or triangle lists differ), or when the point is behind the other
//! camera. It is occluded when, at the other frame, the point is off the image, outside
//! the clipping range, or not the first thing the other camera's ray towards it hits.

use rayon::prelude::*;

use crate::render::accel::{self, Accel};
use crate::render::build::Geometry;
use crate::render::camera::Camera;
use crate::render::math::{Vec3, V3};

/// What the primary ray through a pixel centre hit: an instance of the frame's geometry,
/// a triangle of its mesh, and the hit's barycentrics (the corner weights are 1 - u - v,
/// u, v).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelHit {
    pub inst: u32,
    pub tri: u32,
    pub u: f32,
    pub v: f32,
}

/// Flow to one other frame.
#[derive(Debug, Clone)]
pub struct FlowField {
    /// The scene frame the flow goes to.
    pub frame: f64,
    /// Pixels the surface point moves by, x right and y down; NaN where invalid.
    pub flow: Vec<[f32; 2]>,
    /// The point is not visible at that frame (hidden, off the image or clipped); false
    /// where the flow is invalid.
    pub occluded: Vec<bool>,
}

/// Forward (to the next frame of the step) and backward (to the previous) flow.
#[derive(Debug, Clone)]
pub struct Motion {
    pub forward: FlowField,
    pub backward: FlowField,
}

/// One frame's evaluated scene as far as flow needs it.
pub struct FrameView<'a> {
    pub camera: &'a Camera,
    pub geo: &'a Geometry,
}

/// Relative depth below which a surface in front of the point is taken for the point's
/// own surface (a neighbouring triangle of the same surface, float error).
const SAME_SURFACE: f32 = 1e-4;

/// The world-space point at barycentrics (u, v) of triangle `tri` of instance `inst`,
/// computed as the renderer computes the hit point (world-space corners, f32).
fn point(geo: &Geometry, inst: usize, tri: u32, u: f32, v: f32) -> Option<V3> {
    let i = geo.instances.get(inst)?;
    let m = &i.mesh;
    let t = m.triangles.get(tri as usize)?;
    let c = t.map(|c| {
        Vec3::from(
            i.to_world
                .point(m.positions[m.corner_verts[c as usize] as usize]),
        )
    });
    let w0 = 1.0 - u - v;
    Some((c[0] * w0 + c[1] * u + c[2] * v).into())
}

/// For each instance of `here`, its instance in `there` when it is there exactly once
/// with the same mesh topology.
fn match_instances(here: &Geometry, there: &Geometry) -> Vec<Option<usize>> {
    use std::collections::HashMap;
    let key = |i: &crate::render::build::MeshInstance| (i.object, i.instance_index);
    let mut count: HashMap<_, (usize, usize)> = HashMap::new();
    for (k, i) in there.instances.iter().enumerate() {
        count.entry(key(i)).or_insert((k, 0)).1 += 1;
    }
    let mut here_count: HashMap<_, usize> = HashMap::new();
    for i in &here.instances {
        *here_count.entry(key(i)).or_insert(0) += 1;
    }
    here.instances
        .iter()
        .map(|i| {
            let (k, n) = *count.get(&key(i))?;
            if n != 1 || here_count[&key(i)] != 1 {
                return None;
            }
            let (a, b) = (&i.mesh, &there.instances[k].mesh);
            let same = std::sync::Arc::ptr_eq(a, b)
                || (a.positions.len() == b.positions.len()
                    && a.triangles == b.triangles
                    && a.corner_verts == b.corner_verts);
            same.then_some(k)
        })
        .collect()
}

/// Flow and occlusion of every pixel of `here` (its hits, image order) to `there`.
pub fn flow_to(
    here: &FrameView,
    hits: &[Option<PixelHit>],
    there: &FrameView,
    there_frame: f64,
) -> FlowField {
    let matched = match_instances(here.geo, there.geo);
    let backend = accel::Backend::from_env().unwrap_or(accel::Backend::DEFAULT);
    let masks = crate::render::build::triangle_masks(there.geo);
    // The render itself already reported an Embree that cannot build; every backend
    // returns the same hits, so the default serves the flow then.
    let accel = backend
        .build_masked(&there.geo.tris, &masks)
        .unwrap_or_else(|_| {
            Box::new(crate::foundation::bvh4::Bvh4::build_masked(
                &there.geo.tris,
                &masks,
            ))
        });
    let (w, h) = (there.camera.width as f64, there.camera.height as f64);
    let per_pixel: Vec<([f32; 2], bool)> = hits
        .par_iter()
        .map(|hit| {
            let invalid = ([f32::NAN; 2], false);
            let Some(hit) = hit else { return invalid };
            let Some(k) = matched.get(hit.inst as usize).copied().flatten() else {
                return invalid;
            };
            let (Some(p0), Some(p1)) = (
                point(here.geo, hit.inst as usize, hit.tri, hit.u, hit.v),
                point(there.geo, k, hit.tri, hit.u, hit.v),
            ) else {
                return invalid;
            };
            let (Some(r0), Some(r1)) = (here.camera.raster_of(p0), there.camera.raster_of(p1))
            else {
                return invalid;
            };
            let f = [(r1[0] - r0[0]) as f32, (r1[1] - r0[1]) as f32];
            if !f.iter().all(|x| x.is_finite()) {
                return invalid;
            }
            let on_image = r1[0] >= 0.0 && r1[0] < w && r1[1] >= 0.0 && r1[1] < h;
            let occluded =
                !on_image || !visible(&*accel, there, k as u32, hit.tri, p1, [r1[0], r1[1]]);
            (f, occluded)
        })
        .collect();
    FlowField {
        frame: there_frame,
        flow: per_pixel.iter().map(|p| p.0).collect(),
        occluded: per_pixel.iter().map(|p| p.1).collect(),
    }
}

/// Whether `p` (on triangle `tri` of instance `inst` of `there`) is the first thing the
/// camera ray through its raster position `r` hits, within the clipping range.
fn visible(accel: &dyn Accel, there: &FrameView, inst: u32, tri: u32, p: V3, r: [f64; 2]) -> bool {
    let (o, d, t0, t1) = there.camera.ray(r[0] as f32, r[1] as f32, [0.5, 0.5]);
    let tp = (Vec3::from(p) - o.into()).dot(d.into());
    if !(tp > t0) || tp > t1 {
        return false;
    }
    let camera = accel::visibility::of_path(crate::shader::point::ray::CAMERA);
    match accel.intersect_vis(
        o,
        d,
        t0,
        t1,
        crate::render::motion::object::CENTRE_TIME,
        camera,
    ) {
        None => true,
        Some(h) => {
            let r = there.geo.refs[h.prim as usize];
            (r.inst == inst && r.tri == tri) || h.t >= tp * (1.0 - SAME_SURFACE)
        }
    }
}

/// The Middlebury `.flo` file of a flow field (little-endian: "PIEH", width, height,
/// then (u, v) float pairs row by row, top row first); invalid pixels are written as
/// the format's unknown-flow value 1e10 rather than NaN, as its readers expect.
pub fn flo_bytes(width: u32, height: u32, flow: &[[f32; 2]]) -> Vec<u8> {
    let mut b = Vec::with_capacity(12 + flow.len() * 8);
    b.extend_from_slice(b"PIEH");
    b.extend_from_slice(&width.to_le_bytes());
    b.extend_from_slice(&height.to_le_bytes());
    for f in flow {
        for &x in f {
            let x = if x.is_finite() { x } else { 1e10 };
            b.extend_from_slice(&x.to_le_bytes());
        }
    }
    b
}
