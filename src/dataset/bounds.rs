//! `--renderer bounds`: a debugging stand-in for the path tracer that draws each mesh
//! object's world-space bounding box, projected through the scene camera, as a flat
//! rectangle with a depth test. It exercises the whole dataset pipeline (spec,
//! transforms and camera from the scene, labels, files) with no path tracing; its images
//! are not renders of the scene's surfaces.

use std::collections::HashMap;

use super::renderer::{resolution, FrameRenderer, RenderedFrame};
use super::spec::RenderSettings;
use crate::label::{FrameIds, Instance};
use crate::scene::Scene;

pub struct BoundsRenderer {
    /// Local-space bounds of each mesh datablock, by name.
    local: HashMap<String, ([f64; 3], [f64; 3])>,
}

impl BoundsRenderer {
    pub fn new(scene: &Scene) -> Result<BoundsRenderer, String> {
        let mut local = HashMap::new();
        for (i, m) in scene.file.meshes.iter().enumerate() {
            let mesh = scene.load_mesh(i).map_err(|e| e.to_string())?;
            if let Some(b) = positions_bounds(&mesh.positions) {
                local.insert(m.name.clone(), b);
            }
        }
        Ok(BoundsRenderer { local })
    }
}

/// Bounds of a set of points (None when empty).
pub fn positions_bounds(positions: &[[f32; 3]]) -> Option<([f64; 3], [f64; 3])> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] as f64);
            hi[k] = hi[k].max(p[k] as f64);
        }
    }
    (!positions.is_empty()).then_some((lo, hi))
}

fn xform(m: &[[f64; 4]; 4], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
}

#[allow(clippy::needless_range_loop)]
/// Inverse of an affine matrix (rotation/scale/shear plus translation).
fn affine_inverse(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let a = |r: usize, c: usize| m[r][c];
    let det = a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1))
        - a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0))
        + a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
    if det.abs() < 1e-300 {
        return None;
    }
    let mut inv = [[0.0; 4]; 4];
    for r in 0..3 {
        for c in 0..3 {
            let (r1, r2, c1, c2) = ((c + 1) % 3, (c + 2) % 3, (r + 1) % 3, (r + 2) % 3);
            inv[r][c] = (a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)) / det;
        }
    }
    for r in 0..3 {
        inv[r][3] = -(inv[r][0] * m[0][3] + inv[r][1] * m[1][3] + inv[r][2] * m[2][3]);
    }
    inv[3][3] = 1.0;
    Some(inv)
}

/// A stable colour per object name.
fn colour(name: &str) -> [f32; 3] {
    let h = super::rng::key(name);
    [0, 1, 2].map(|k| 0.25 + 0.7 * (((h >> (k * 16)) & 0xffff) as f32 / 65535.0))
}

impl FrameRenderer for BoundsRenderer {
    fn render(
        &self,
        scene: &Scene,
        frame: f64,
        _seed: u32,
        settings: &RenderSettings,
        _threads: usize,
    ) -> Result<RenderedFrame, String> {
        let (w, h) = resolution(scene, settings)?;
        let cam = super::generate::scene_camera(scene, frame, w, h)?;
        let world_to_cam = affine_inverse(&cam.matrix_world).ok_or("camera matrix is singular")?;
        let ev = crate::anim::evaluate_scene(scene, frame).map_err(|e| e.to_string())?;
        let n = (w * h) as usize;
        let mut depth = vec![f32::INFINITY; n];
        let mut ids = vec![0u32; n];
        let mut color = vec![[0.02, 0.02, 0.02, 1.0]; n];
        let mut instances = Vec::new();
        for (oi, o) in ev.data.objects.iter().enumerate() {
            if o.kind != "MESH" || o.hide_render {
                continue;
            }
            let Some(&(lo, hi)) = o.data.as_ref().and_then(|d| self.local.get(d)) else {
                continue;
            };
            let m = ev.world_matrices[oi];
            let corners: Vec<[f64; 3]> = (0..8)
                .map(|c| {
                    xform(
                        &m,
                        [0, 1, 2].map(|k| if c >> k & 1 == 1 { hi[k] } else { lo[k] }),
                    )
                })
                .collect();
            let mut wlo = [f64::INFINITY; 3];
            let mut whi = [f64::NEG_INFINITY; 3];
            for p in &corners {
                for k in 0..3 {
                    wlo[k] = wlo[k].min(p[k]);
                    whi[k] = whi[k].max(p[k]);
                }
            }
            instances.push(Instance {
                object: o.name.clone(),
                instance_index: None,
                world_bounds: (wlo.map(|v| v as f32), whi.map(|v| v as f32)),
                world_transform: m.map(|r| r.map(|v| v as f32)),
            });
            let id = instances.len() as u32;
            // Project; boxes reaching behind the camera's near plane are not drawn.
            let mut x0 = f64::INFINITY;
            let mut y0 = f64::INFINITY;
            let mut x1 = f64::NEG_INFINITY;
            let mut y1 = f64::NEG_INFINITY;
            let mut near = f64::INFINITY;
            let mut behind = false;
            for p in &corners {
                let c = xform(&world_to_cam, *p);
                let z = -c[2];
                if z <= cam.clip_start {
                    behind = true;
                    break;
                }
                let (x, y) = (cam.cx + cam.fx * c[0] / z, cam.cy - cam.fy * c[1] / z);
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
                near = near.min(z);
            }
            if behind || near > cam.clip_end {
                continue;
            }
            let xa = x0.max(0.0).round() as i64;
            let xb = x1.min(w as f64).round() as i64;
            let ya = y0.max(0.0).round() as i64;
            let yb = y1.min(h as f64).round() as i64;
            let shade = colour(&o.name);
            let fade = (1.0 / (1.0 + 0.1 * near)) as f32;
            for y in ya.max(0)..yb.min(h as i64) {
                for x in xa.max(0)..xb.min(w as i64) {
                    let p = y as usize * w as usize + x as usize;
                    if (near as f32) < depth[p] {
                        depth[p] = near as f32;
                        ids[p] = id;
                        color[p] = [shade[0] * fade, shade[1] * fade, shade[2] * fade, 1.0];
                    }
                }
            }
        }
        Ok(RenderedFrame {
            width: w,
            height: h,
            color,
            ids: FrameIds {
                width: w,
                height: h,
                instance_id: ids,
                depth: Some(depth),
                normal: None,
                instances,
                aov_channels: Vec::new(),
            },
        })
    }
}
