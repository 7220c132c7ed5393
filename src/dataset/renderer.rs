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
    fn render(
        &self,
        scene: &Scene,
        frame: f64,
        seed: u32,
        settings: &RenderSettings,
        threads: usize,
    ) -> Result<RenderedFrame, String>;

    /// `render` with optical flow and occlusion to the scene frames `step` after and
    /// before `frame` (`render::flow`). Renderers without geometry give none.
    fn render_with_motion(
        &self,
        _scene: &Scene,
        _frame: f64,
        _seed: u32,
        _settings: &RenderSettings,
        _threads: usize,
        _step: f64,
    ) -> Result<(RenderedFrame, crate::render::film::flow::Motion), String> {
        Err("this renderer gives no optical flow or occlusion (the spec's [labels] ask for flow or occlusion)".into())
    }
}

/// The output resolution: the spec's, else the scene's resolution x percentage / 100
/// as Blender computes it (an error when that is below a pixel).
pub fn resolution(scene: &Scene, settings: &RenderSettings) -> Result<(u32, u32), String> {
    match settings.resolution {
        Some(r) => Ok(r),
        None => crate::scene::settings::Output::of(&scene.file.scene).size(),
    }
}

/// The path tracer as a `FrameRenderer`: render, denoise when the spec or the scene asks
/// for it (as Cycles does after the last sample), then the scene's view transform.
struct PathTracer {
    /// Found when the first frame asks for denoising (so a run that never denoises never
    /// downloads OIDN); every frame then uses the same one.
    denoiser: std::sync::OnceLock<Result<Option<crate::denoise::Denoiser>, String>>,
}

impl FrameRenderer for PathTracer {
    fn render(
        &self,
        scene: &Scene,
        frame: f64,
        seed: u32,
        s: &RenderSettings,
        threads: usize,
    ) -> Result<RenderedFrame, String> {
        self.frame(scene, frame, seed, s, threads, None)
            .map(|(f, _)| f)
    }

    fn render_with_motion(
        &self,
        scene: &Scene,
        frame: f64,
        seed: u32,
        s: &RenderSettings,
        threads: usize,
        step: f64,
    ) -> Result<(RenderedFrame, crate::render::film::flow::Motion), String> {
        let (f, m) = self.frame(scene, frame, seed, s, threads, Some(step))?;
        Ok((f, m.expect("asked for motion")))
    }
}

impl PathTracer {
    /// One frame, with its motion when `step` is set.
    fn frame(
        &self,
        scene: &Scene,
        frame: f64,
        seed: u32,
        s: &RenderSettings,
        threads: usize,
        step: Option<f64>,
    ) -> Result<(RenderedFrame, Option<crate::render::film::flow::Motion>), String> {
        let opts = crate::render::RenderOptions {
            frame: Some(frame),
            samples: s.samples,
            threshold: s.threshold,
            resolution: Some(resolution(scene, s)?),
            seed: Some(seed),
            threads: Some(threads.max(1)),
            progress: false,
        };
        let (mut out, motion) = match step {
            None => (
                crate::render::render(scene, &opts).map_err(|e| e.to_string())?,
                None,
            ),
            Some(step) => {
                let (o, m) = crate::render::render_with_motion(scene, &opts, &[], None, step)
                    .map_err(|e| e.to_string())?;
                (o, Some(m))
            }
        };
        if s.denoise
            .unwrap_or_else(|| crate::denoise::scene_wants_denoising(scene))
        {
            let found = self
                .denoiser
                .get_or_init(|| crate::denoise::find_for_render(None).map_err(|e| e.to_string()));
            if let Some(d) = found.as_ref().map_err(Clone::clone)? {
                crate::denoise::denoise_render(d, scene, frame, &mut out)
                    .map_err(|e| format!("denoising: {e}"))?;
            }
        }
        crate::color::to_display(scene, &mut out.color).map_err(|e| e.to_string())?;
        let p = out.passes;
        let instances = p
            .instances
            .into_iter()
            .map(|i| crate::label::Instance {
                object: i.object,
                instance_index: i.instance_index,
                world_bounds: i.world_bounds,
                world_transform: i.world_transform,
            })
            .collect();
        let aov_channels =
            crate::label::passes::aov_channels(&crate::label::passes::PassImages::aovs_only(
                out.width,
                out.height,
                &p.aovs,
                &scene.file.scene.view_layer.name,
            ))?;
        let frame = RenderedFrame {
            width: out.width,
            height: out.height,
            color: out.color,
            ids: crate::label::FrameIds {
                width: out.width,
                height: out.height,
                instance_id: p.instance_id,
                depth: Some(p.depth),
                normal: Some(p.normal),
                instances,
                aov_channels,
            },
        };
        Ok((frame, motion))
    }
}

/// The path tracer, with Open Image Denoise when one can be found or fetched (a notice
/// otherwise: frames are then written noisy).
pub fn path_tracer(_scene: &Scene) -> Result<Box<dyn FrameRenderer>, String> {
    // An installed library that cannot be used fails the run before any frame; a missing
    // one is fetched into the cache folder by the first frame that asks for denoising (a
    // notice, not an error, when that fails: frames are then written noisy).
    let denoiser = std::sync::OnceLock::new();
    if let Some(d) = crate::denoise::Denoiser::load(None).map_err(|e| e.to_string())? {
        let _ = denoiser.set(Ok(Some(d)));
    }
    Ok(Box::new(PathTracer { denoiser }))
}
