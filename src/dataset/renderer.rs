//! The one thing `generate` needs from a renderer: one frame of a scene (overrides
//! already applied) at a frame number with a seed, as a display-referred image plus
//! the label passes. The path tracer implements it (wired in `main.rs`); tests and
//! `--renderer bounds` use stand-ins.

use crate::label::FrameIds;
use crate::scene::Scene;

use super::spec::RenderSettings;

/// A rendered frame.
#[derive(Debug, Clone)]
pub struct RenderedFrame {
    pub width: u32,
    pub height: u32,
    /// Display-referred RGBA in [0, 1] (after the scene's view transform), row-major,
    /// top row first; written as 8-bit sRGB-encoded PNG.
    pub color: Vec<[f32; 4]>,
    pub ids: FrameIds,
}

pub trait FrameRenderer: Sync {
    /// Renders `scene` at `frame` with Cycles seed `seed`. `settings` are the spec's
    /// (None: the scene's own). `threads` is how many threads this frame may use; the
    /// result must not depend on it.
    fn render(&self, scene: &Scene, frame: f64, seed: u32, settings: &RenderSettings, threads: usize) -> Result<RenderedFrame, String>;
}

/// The output resolution: the spec's, else the scene's resolution x percentage / 100
/// as Blender computes it.
pub fn resolution(scene: &Scene, settings: &RenderSettings) -> (u32, u32) {
    if let Some(r) = settings.resolution {
        return r;
    }
    let r = &scene.file.scene.render;
    let g = |k: &str, d: i64| r.get(k).and_then(|v| v.as_i64()).unwrap_or(d);
    let pct = g("resolution_percentage", 100);
    (((g("resolution_x", 1920) * pct) / 100).max(1) as u32, ((g("resolution_y", 1080) * pct) / 100).max(1) as u32)
}
