//! Rendering an exported scene with a Cycles-compatible path tracer.
//!
//! Laid out as Cycles' kernel is: `bsdf/` (closures), `light/` (lights, the world, the
//! light tree), `subsurface/`, `camera/`, `motion/`, `integrator/` (the path loop and
//! `shade`, materials to closures), `film/` (filter, adaptive sampling, denoiser features,
//! flow). `build` is the scene at a frame as triangles and instances, `accel` the ray
//! queries, `sampler` the Owen-scrambled Sobol pattern. The film's tiles, passes and
//! progress are here.
//!
//! Determinism: every random number comes from (pixel, sample index, seed), tiles are
//! independent, and pixels are summed in sample order, so the image has the same bits
//! for any thread count.

/// The BVH lives in the foundation (Geometry Nodes' Raycast uses it too).
pub use crate::foundation::bvh as accel;
pub mod bake;
pub mod bsdf;
pub mod build;
pub mod camera;
pub mod control;
pub mod curves;
pub mod default_surface;
pub mod displace;
pub mod film;
pub mod integrator;
pub mod light;
pub mod limits;
pub mod thick_curves;
pub use crate::foundation::math;
pub mod motion;
pub mod points;
pub mod realized;
pub mod sampler;
pub mod scene_mesh;
pub mod shader_rays;
pub mod subsurface;
pub mod volume;
pub mod volume_grid;
pub mod volume_world;

use std::time::Instant;

use rayon::prelude::*;
use serde_json::Value;

use crate::scene::{settings, Scene};
use accel::Accel;
use integrator::{Scratch, Settings};
use light::tree::LightSelect;
use math::*;
use sampler::PixelSampler;

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenderError(pub String);

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}
impl std::error::Error for RenderError {}

impl RenderError {
    /// Whether the render stopped because its `Control` was cancelled.
    pub fn is_cancelled(&self) -> bool {
        self.0 == control::CANCELLED
    }
}

#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    pub frame: Option<f64>,
    pub samples: Option<u32>,
    pub threshold: Option<f32>,
    pub resolution: Option<(u32, u32)>,
    pub seed: Option<u32>,
    pub threads: Option<usize>,
    pub progress: bool,
}

#[derive(Debug, Clone, Default)]
pub struct RenderStats {
    pub samples: u32,
    /// Camera samples actually traced over all pixels (fewer than pixels x samples when
    /// adaptive sampling stops converged pixels early).
    pub samples_taken: u64,
    pub wall_seconds: f64,
    pub rays: u64,
    pub triangles: usize,
    pub build_seconds: f64,
}

#[derive(Debug, Clone)]
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub color: Vec<[f32; 4]>,
    pub passes: Passes,
    pub stats: RenderStats,
}

#[derive(Debug, Clone, Default)]
pub struct Passes {
    /// Camera-space depth (Z along the view axis) of the pixel centre's surface.
    pub depth: Vec<f32>,
    /// Distance from the camera ray's origin to that surface (`depth` is Cycles' Z pass).
    pub distance: Vec<f32>,
    pub object_index: Vec<u32>,
    pub instance_id: Vec<u32>,
    pub material_index: Vec<u32>,
    pub normal: Vec<[f32; 3]>,
    /// The denoiser's guides, averaged over each pixel's samples as Cycles' "Denoising
    /// Albedo" and "Denoising Normal" passes are (`denoise_features`); the normal in world
    /// space (the denoiser turns it into Cycles' camera space).
    pub albedo: Vec<[f32; 3]>,
    pub denoise_normal: Vec<[f32; 3]>,
    pub uv: Vec<[f32; 2]>,
    /// Samples taken per pixel (Cycles' Debug Sample Count pass, unnormalised).
    pub sample_count: Vec<u32>,
    pub instances: Vec<InstanceInfo>,
    /// What each pixel centre's primary ray hit (None: background), for `flow`.
    pub hits: Vec<Option<film::flow::PixelHit>>,
    /// The view layer's shader AOV passes, in its order (`film::aov`).
    pub aovs: Vec<film::aov::AovImage>,
}

#[derive(Debug, Clone)]
pub struct InstanceInfo {
    pub object: String,
    pub instance_index: Option<u32>,
    pub world_bounds: ([f32; 3], [f32; 3]),
    pub world_transform: [[f32; 4]; 4],
}

pub use limits::MAX_SIDE;
const TILE: u32 = 16;
/// Sample dimension set of the shutter time (apart from the sets paths use).
const TIME_SET: u32 = 0x7000_0000;

/// Cycles' `transparent_roughness_squared_threshold` (scene/background.cpp): with Film >
/// Transparent and Transparent Glass, the Roughness Threshold to the fourth (squared once
/// for the roughness-to-alpha convention, once to compare with alpha_x * alpha_y);
/// otherwise -1.
fn transparent_glass_threshold(i: &settings::Integrator) -> f32 {
    if i.film_transparent && i.film_transparent_glass {
        let t = i.film_transparent_roughness as f32;
        (t * t) * (t * t)
    } else {
        -1.0
    }
}

/// Renders `scene` (overrides already applied) at the options' frame.
pub fn render(scene: &Scene, opts: &RenderOptions) -> Result<RenderOutput, RenderError> {
    render_with_overrides(scene, opts, &[])
}

/// `render`, also passing data-path overrides to Geometry Nodes evaluation.
pub fn render_with_overrides(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
) -> Result<RenderOutput, RenderError> {
    render_controlled(scene, opts, overrides, None)
}

/// `render_with_overrides` that another thread can follow and stop through `control`
/// (checked between pixels; the image is the same when it is not cancelled).
pub fn render_controlled(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
    control: Option<&control::Control>,
) -> Result<RenderOutput, RenderError> {
    render_frame(scene, opts, overrides, control).map(|(out, ..)| out)
}

/// Why optical flow and occlusion cannot be labelled on `scene`, before anything renders:
/// an object rendered with hair curves (its export's strands, particle hair or a Curves
/// object) or exported points, which the flow and occlusion passes do not trace (point
/// clouds blendsynth's Geometry Nodes make are refused at the frame). The same words as
/// `render_with_motion` gives at the frame.
pub fn flow_refusal(scene: &Scene) -> Option<String> {
    scene
        .file
        .evaluated
        .iter()
        .filter(|e| {
            e.hair
                .as_ref()
                .is_some_and(|h| h.systems.iter().any(|s| s.curve_count > 0))
                || e.points.as_ref().is_some_and(|p| p.count > 0)
        })
        .find(|e| {
            scene
                .file
                .objects
                .iter()
                .any(|o| o.name == e.object && !o.hide_render && o.in_render_layer)
        })
        .map(|e| {
            let hair = e
                .hair
                .as_ref()
                .is_some_and(|h| h.systems.iter().any(|s| s.curve_count > 0));
            flow_refused(&e.object, !hair)
        })
}

/// Why optical flow is refused on `object`'s hair curves or point cloud (`points`).
fn flow_refused(object: &str, points: bool) -> String {
    let what = if points {
        "a point cloud"
    } else {
        "hair curves"
    };
    format!("optical flow: object {object:?} has {what}, which the flow and occlusion passes do not trace (not supported yet)")
}

/// `render_controlled` with optical flow and occlusion (`flow`) to the scene frames
/// `frame + step` (forward) and `frame - step` (backward; a sequence's step may be
/// negative), from the primary hits the label passes use. Panoramic cameras are refused
/// (their projection has no inverse here).
pub fn render_with_motion(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
    control: Option<&control::Control>,
    step: f64,
) -> Result<(RenderOutput, film::flow::Motion), RenderError> {
    if !(step.is_finite() && step != 0.0) {
        return Err(RenderError(format!(
            "optical flow: the frame step is {step}: must be a non-zero number"
        )));
    }
    let (out, camera, geo, frame) = render_frame(scene, opts, overrides, control)?;
    // The flow and its occlusion test trace triangles only: hair would be missing from
    // both, so its pixels and what it hides would be labelled wrongly.
    if let Some((h, c)) = geo
        .instances
        .iter()
        .find_map(|i| i.curves.as_ref().map(|c| (i, c)))
    {
        return Err(RenderError(flow_refused(&h.name, c.points)));
    }
    let here = film::flow::FrameView {
        camera: &camera,
        geo: &geo,
    };
    let to = |f: f64| -> Result<film::flow::FlowField, RenderError> {
        let at = RenderOptions {
            frame: Some(f),
            ..opts.clone()
        };
        let p = prepare(scene, &at, overrides)
            .map_err(|e| RenderError(format!("optical flow to frame {f}: {e}")))?;
        let there = film::flow::FrameView {
            camera: &p.camera,
            geo: &p.geo,
        };
        Ok(film::flow::flow_to(&here, &out.passes.hits, &there, f))
    };
    let forward = to(frame + step)?;
    let backward = to(frame - step)?;
    Ok((out, film::flow::Motion { forward, backward }))
}

/// The scene the render at `opts`' frame would trace, as one world-space mesh
/// (`scene_mesh`): for reconstruction ground truth.
pub fn evaluated_scene_mesh(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
) -> Result<crate::geometry::mesh::Mesh, RenderError> {
    prepare(scene, opts, overrides).map(|p| scene_mesh::scene_mesh(&p.geo))
}

type FrameResult = Result<(RenderOutput, camera::Camera, build::Geometry, f64), RenderError>;

/// The render, with the camera and geometry it traced and the frame it rendered. With
/// `opts.threads` the whole of it (Geometry Nodes, displacement, BVH build, tiles) runs on
/// a pool of that many threads: a one-thread render uses one core from start to end.
fn render_frame(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
    control: Option<&control::Control>,
) -> FrameResult {
    let Some(n) = opts.threads else {
        return render_frame_here(scene, opts, overrides, control);
    };
    limits::check_threads(n)?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| RenderError(format!("thread pool: {e}")))?
        .install(|| render_frame_here(scene, opts, overrides, control))
}

/// `render_frame` on the current rayon pool.
// Long because the render driver still holds film, tiles, adaptive ranges and passes; separating them is open work (issue 25).
fn render_frame_here(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
    control: Option<&control::Control>,
) -> FrameResult {
    let frame = opts.frame.unwrap_or(scene.file.scene.frame_current as f64);
    let Prepared {
        start,
        w,
        h,
        shutter,
        samples,
        seed,
        camera,
        geo,
        materials,
        lights,
        background,
        world_shader,
        moving,
    } = prepare(scene, opts, overrides)?;
    let integrator = settings::Integrator::of(&scene.file.scene);
    let tables = bsdf::tables::Tables::shared();
    if materials.iter().any(|m| m.multiscatter_glass) {
        tables.warm_glass();
    }
    // With moving objects the static rest goes in a BVH of its own (`object_motion`).
    let motion_accel = (moving > 0).then(|| motion::object::MotionAccel::build(&geo));
    let backend = accel::Backend::from_env().map_err(RenderError)?;
    let bvh = if motion_accel.is_some() {
        backend.build_masked(&[], &[])
    } else {
        with_curves(backend, &geo)
    }
    .map_err(RenderError)?;
    let filter = film::filter::FilterTable::blackman_harris(integrator.filter_width as f32);
    let i = &integrator;
    let settings = Settings {
        max_bounces: i.max_bounces,
        max_diffuse: i.diffuse_bounces,
        max_glossy: i.glossy_bounces,
        max_transmission: i.transmission_bounces,
        max_transparent: i.transparent_max_bounces,
        // The clamp compares the sum of the three channels, so Cycles (integrator.cpp)
        // stores the per-channel setting times three; 0 stays off.
        clamp_direct: 3.0 * i.sample_clamp_direct as f32,
        clamp_indirect: 3.0 * i.sample_clamp_indirect as f32,
        min_light_bounces: i.min_light_bounces,
        min_transparent_bounces: i.min_transparent_bounces,
        filter_glossy: i.blur_glossy as f32,
        film_transparent: i.film_transparent,
        transparent_shadows: materials.iter().any(|m| m.transparent_shadow),
        transparent_glass: transparent_glass_threshold(i),
    };
    let exposure = 1.0f32;
    let build_seconds = start.elapsed().as_secs_f64();
    let use_light_tree = i.use_light_tree;
    let light_select = light_select(
        &geo,
        &materials,
        &lights,
        world_shader.as_ref(),
        use_light_tree,
    );
    let accel: &dyn Accel = match &motion_accel {
        Some(m) => m,
        None => bvh.as_ref(),
    };
    let local = shader_rays::LocalAccels::new(&geo);
    let volumes = volume::Volumes::build(scene, &geo, &materials, &integrator);
    let aovs = film::aov::Layout::of(&scene.file.scene.view_layer);
    let tracer = integrator::Scene {
        aovs: &aovs,
        local: &local,
        light_select: &light_select,
        accel,
        geo: &geo,
        materials: &materials,
        lights: &lights,
        background,
        world_exclude: light::world::excluded_rays(scene),
        tables,
        settings,
        world: world_shader.as_ref(),
        view: camera.view(),
        volumes: &volumes,
    };

    let adaptive = film::adaptive::Adaptive::from_settings(&integrator, samples, opts.threshold);
    let tiles_x = w.div_ceil(TILE);
    let tiles_y = h.div_ceil(TILE);
    let n_tiles = (tiles_x * tiles_y) as usize;
    let bar = if opts.progress {
        let b = indicatif::ProgressBar::new(samples as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} samples  ETA {eta}  {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        Some(b)
    } else {
        None
    };
    let render_start = Instant::now();
    let nmat = materials.len();
    let npix = (w * h) as usize;
    if let Some(c) = control {
        c.start(npix as u64 * samples as u64);
    }
    let cancelled = || control.is_some_and(|c| c.is_cancelled());
    // Per-pixel accumulators live in image order; tiles read and write disjoint pixels.
    let mut film = film::adaptive::Film::new(npix);
    let mut tiles: Vec<TileWork> = (0..n_tiles)
        .map(|t| {
            let tx = (t as u32 % tiles_x) * TILE;
            let ty = (t as u32 / tiles_x) * TILE;
            TileWork {
                tx,
                ty,
                tw: TILE.min(w - tx),
                th: TILE.min(h - ty),
                acc: Vec::new(),
                passes: TilePasses::default(),
                rays: 0,
            }
        })
        .collect();
    let mut start_sample = 0u32;
    let mut taken = 0u64;
    while start_sample < samples {
        // Sample ranges end where Cycles would run its convergence check, so the
        // check sees the same sample counts whatever the thread count or timing.
        let n = adaptive.align_samples(start_sample, samples - start_sample);
        let end_sample = start_sample + n;
        let first = start_sample == 0;
        for t in tiles.iter_mut() {
            t.acc.clear();
            for y in t.ty..t.ty + t.th {
                for x in t.tx..t.tx + t.tw {
                    t.acc.push(film.pixel((y * w + x) as usize));
                }
            }
        }
        let run = |tiles: &mut Vec<TileWork>| {
            tiles.par_iter_mut().for_each_init(
                || Scratch::new(nmat),
                |scratch, tile| {
                    if cancelled() {
                        return;
                    }
                    let rays0 = scratch.rays;
                    let mut k = 0;
                    for y in tile.ty..tile.ty + tile.th {
                        for x in tile.tx..tile.tx + tile.tw {
                            let px = &mut tile.acc[k];
                            k += 1;
                            if first {
                                primary_passes(&tracer, &camera, x, y, scratch, &mut tile.passes);
                                tile.passes.aov.resize(k * aovs.stride, 0.0);
                            }
                            if px.converged {
                                continue;
                            }
                            // A sample range can be long (all samples without adaptive
                            // sampling), so a cancel is also seen between pixels.
                            if cancelled() {
                                return;
                            }
                            let rng = PixelSampler::new(x, y, seed);
                            // Like Cycles with a sample count pass, a pixel's sample
                            // index is its own count, so a pixel resumed by dilation
                            // continues its sequence.
                            for _ in start_sample..end_sample {
                                let i = px.count;
                                let u = rng.get4(i, 0);
                                let fx = x as f32 + 0.5 + filter.sample(u[0]);
                                let fy = y as f32 + 0.5 + filter.sample(u[1]);
                                scratch.time =
                                    shutter.as_ref().map_or(motion::object::CENTRE_TIME, |sh| {
                                        sh.time(rng.get4(i, TIME_SET)[0])
                                    });
                                let (o, d, t0, t1) = match &shutter {
                                    Some(_) => camera.ray_at(fx, fy, [u[2], u[3]], scratch.time),
                                    None => camera.ray(fx, fy, [u[2], u[3]]),
                                };
                                (scratch.ray_dp, scratch.ray_dd) =
                                    camera.ray_differentials(fx, fy, [u[2], u[3]]);
                                // A panoramic camera's sample outside the lens sees nothing (black, opaque).
                                let c = if t1 > 0.0 {
                                    tracer.radiance(o, d, t0, t1, &rng, i, scratch)
                                } else {
                                    scratch.transparent = 0.0;
                                    scratch.features = Default::default();
                                    scratch.aov.iter_mut().for_each(|v| *v = 0.0);
                                    [0.0; 3]
                                };
                                px.add(i, c, scratch.transparent);
                                let stride = aovs.stride;
                                for (a, v) in tile.passes.aov[(k - 1) * stride..k * stride]
                                    .iter_mut()
                                    .zip(&scratch.aov)
                                {
                                    *a += v;
                                }
                                let f = &scratch.features;
                                let sum = |a: V3, b: V3| (Vec3::from(a) + b.into()).into();
                                let (n, a) = (
                                    &mut tile.passes.feature_normal[k - 1],
                                    &mut tile.passes.feature_albedo[k - 1],
                                );
                                *n = sum(*n, f.normal);
                                *a = sum(*a, f.albedo);
                            }
                        }
                    }
                    tile.rays += scratch.rays - rays0;
                    if let Some(c) = control {
                        c.add((tile.tw * tile.th) as u64 * n as u64);
                    }
                },
            )
        };
        run(&mut tiles);
        if cancelled() {
            return Err(RenderError(control::CANCELLED.into()));
        }
        for t in &tiles {
            let mut k = 0;
            for y in t.ty..t.ty + t.th {
                for x in t.tx..t.tx + t.tw {
                    let i = (y * w + x) as usize;
                    taken += (t.acc[k].count - film.pixel(i).count) as u64;
                    film.set(i, t.acc[k]);
                    k += 1;
                }
            }
        }
        start_sample = end_sample;
        if let Some(b) = &bar {
            b.set_position(end_sample as u64);
            let secs = render_start.elapsed().as_secs_f64().max(1e-6);
            b.set_message(format!("{:.2} M samples/s", taken as f64 / secs / 1e6));
        }
        if adaptive.need_filter(end_sample - 1)
            && film.converge_and_dilate(&adaptive, exposure, w as usize, h as usize) == 0
        {
            break;
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Some(c) = control {
        c.finish();
    }
    let mut color = vec![[0.0f32; 4]; npix];
    let mut sample_count = vec![0u32; npix];
    for i in 0..npix {
        let p = film.pixel(i);
        let inv = exposure as f64 / p.count.max(1) as f64;
        // Colour stays premultiplied (the background and holdouts added none); alpha is
        // 1 - transparency, as Cycles' combined pass gives it.
        let alpha = (1.0 - p.transparent / p.count.max(1) as f64).clamp(0.0, 1.0);
        color[i] = [
            (p.sum[0] * inv) as f32,
            (p.sum[1] * inv) as f32,
            (p.sum[2] * inv) as f32,
            alpha as f32,
        ];
        sample_count[i] = p.count;
    }
    let mut passes = Passes {
        depth: vec![f32::INFINITY; npix],
        distance: vec![f32::INFINITY; npix],
        object_index: vec![0; npix],
        instance_id: vec![0; npix],
        material_index: vec![0; npix],
        normal: vec![[0.0; 3]; npix],
        albedo: vec![[0.0; 3]; npix],
        denoise_normal: vec![[0.0; 3]; npix],
        uv: vec![[0.0; 2]; npix],
        sample_count,
        hits: vec![None; npix],
        aovs: Vec::new(),
        instances: geo
            .instances
            .iter()
            .map(|i| InstanceInfo {
                object: i.name.clone(),
                instance_index: i.instance_index,
                world_bounds: i.world_bounds,
                world_transform: i.to_world.to_rows(),
            })
            .collect(),
    };
    let mut aov_images: Vec<film::aov::AovImage> = aovs
        .passes
        .iter()
        .map(|p| film::aov::AovImage {
            name: p.name.clone(),
            color: p.color,
            data: vec![0.0; npix * p.channels()],
        })
        .collect();
    let mut rays = 0;
    for t in &tiles {
        rays += t.rays;
        let p = &t.passes;
        let mut k = 0;
        for y in t.ty..t.ty + t.th {
            for x in t.tx..t.tx + t.tw {
                let i = (y * w + x) as usize;
                passes.depth[i] = p.depth[k];
                passes.distance[i] = p.distance[k];
                passes.object_index[i] = p.object_index[k];
                passes.instance_id[i] = p.instance_id[k];
                passes.material_index[i] = p.material_index[k];
                passes.normal[i] = p.normal[k];
                // The guides average the pixel's samples, as Cycles' passes do.
                let inv = 1.0 / passes.sample_count[i].max(1) as f32;
                passes.albedo[i] = (Vec3::from(p.feature_albedo[k]) * inv).into();
                passes.denoise_normal[i] = (Vec3::from(p.feature_normal[k]) * inv).into();
                passes.uv[i] = p.uv[k];
                passes.hits[i] = p.hits[k];
                // AOVs: the samples' sum over the pixel's sample count, as Cycles reads
                // its AOV passes.
                for (img, pass) in aov_images.iter_mut().zip(&aovs.passes) {
                    let c = pass.channels();
                    let src = &p.aov[k * aovs.stride + pass.offset..][..c];
                    for (d, v) in img.data[i * c..(i + 1) * c].iter_mut().zip(src) {
                        *d = v * inv;
                    }
                }
                k += 1;
            }
        }
    }
    passes.aovs = aov_images;
    let triangles = build::triangle_count(&geo);
    drop(motion_accel);
    Ok((
        RenderOutput {
            width: w,
            height: h,
            color,
            passes,
            stats: RenderStats {
                samples,
                samples_taken: taken,
                wall_seconds: start.elapsed().as_secs_f64(),
                rays,
                triangles,
                build_seconds,
            },
        },
        camera,
        geo,
        frame,
    ))
}

/// Everything a render needs before it traces: the scene evaluated at the frame, its
/// geometry built, materials compiled, lights, world and camera.
struct Prepared {
    start: Instant,
    w: u32,
    h: u32,
    shutter: Option<motion::Shutter>,
    samples: u32,
    seed: u32,
    camera: camera::Camera,
    geo: build::Geometry,
    materials: Vec<integrator::shade::Material>,
    lights: Vec<light::Light>,
    background: V3,
    world_shader: Option<light::world::WorldShader>,
    moving: usize,
}

/// Every check `render` makes of the scene (objects, modifiers, frozen geometry, nodes,
/// materials, lights, world, camera, options) at the options' frame, without tracing a
/// ray: `inspect` runs this, so its exit status is the render's.
pub fn check(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
) -> Result<Checked, RenderError> {
    prepare(scene, opts, overrides).map(|p| Checked {
        triangles: build::triangle_count(&p.geo),
        frozen_instead: p.geo.frozen_instead,
    })
}

/// What `check` found: the triangles the render would trace, and the objects it would
/// render from Blender's evaluated mesh although blendsynth evaluates them.
#[derive(Debug)]
pub struct Checked {
    pub triangles: usize,
    pub frozen_instead: Vec<build::FrozenInstead>,
}

/// A Point Density grid is Blender's at the exported frame (particles and animated points
/// move): rendering a used material's grid at another frame is an error naming the node.
fn check_point_density_frames(scene: &Scene, used: &[bool], frame: f64) -> Result<(), RenderError> {
    fn walk(
        scene: &Scene,
        tree: &crate::scene::format::NodeTree,
        path: &str,
        frame: f64,
        depth: u32,
    ) -> Result<(), RenderError> {
        if depth > 64 {
            return Ok(());
        }
        for n in &tree.nodes {
            if let Some(pd) = &n.point_density {
                if (pd.frame - frame).abs() > 1e-6 {
                    return Err(RenderError(format!(
                        "{path}: node {:?}: its Point Density grid was computed by Blender at frame {}, not {frame}: convert the file at this frame (`convert --frame`)",
                        n.name, pd.frame
                    )));
                }
            }
            if let Some(g) = n.node_tree.as_deref().and_then(|g| scene.node_group(g)) {
                walk(scene, g, path, frame, depth + 1)?;
            }
        }
        Ok(())
    }
    for (m, _) in scene.file.materials.iter().zip(used).filter(|(_, u)| **u) {
        if let Some(t) = &m.node_tree {
            walk(scene, t, &format!("material {:?}", m.name), frame, 0)?;
        }
    }
    Ok(())
}

fn prepare(
    scene: &Scene,
    opts: &RenderOptions,
    overrides: &[(String, Value)],
) -> Result<Prepared, RenderError> {
    let with_surfaces = default_surface::apply(scene).map_err(RenderError)?;
    let scene: &Scene = &with_surfaces;
    let start = Instant::now();
    let s = &scene.file.scene;
    let integrator = settings::Integrator::of(s);
    let (w, h) = match opts.resolution {
        Some((w, h)) => {
            limits::check_film(w, h, "--resolution")?;
            (w, h)
        }
        None => {
            let (w, h) = settings::Output::of(s).size().map_err(RenderError)?;
            limits::check_film(w, h, "the scene's resolution (scenes.render)")?;
            (w, h)
        }
    };
    let shutter =
        motion::Shutter::from_settings(&settings::MotionBlur::of(s).map_err(RenderError)?)
            .map_err(RenderError)?;
    let samples = match opts.samples {
        Some(n) => {
            limits::check_samples(n, "--samples")?;
            n
        }
        None => {
            let n = integrator.samples;
            if !(n >= 1.0 && n <= limits::MAX_SAMPLES as f64 && n.fract() == 0.0) {
                return Err(RenderError(format!(
                    "scenes.cycles.samples is {n}: must be a whole number from 1 to {}",
                    limits::MAX_SAMPLES
                )));
            }
            n as u32
        }
    };
    if let Some(t) = opts.threshold {
        limits::check_threshold(t)?;
    }
    if let Some(n) = opts.threads {
        limits::check_threads(n)?;
    }
    let seed = opts.seed.unwrap_or(integrator.seed as u32);
    let frame = opts.frame.unwrap_or(s.frame_current as f64);
    if !frame.is_finite() {
        return Err(RenderError(format!("frame {frame} is not finite")));
    }
    // With motion blur Cycles syncs the scene at the shutter's centre (START and END
    // positions move it off the frame), and the camera at the shutter's ends too.
    let centre = frame + shutter.as_ref().map_or(0.0, |s| s.centre_delta);
    let eval = crate::anim::evaluate_scene(scene, centre)
        .map_err(|e| RenderError(format!("evaluating the scene at frame {centre}: {e}")))?;
    // Blender switches the camera at the rendered frame, before Cycles syncs the shutter.
    let cam_name = camera::active_camera(scene, frame)?;
    let mut camera = camera::Camera::of_object(scene, &eval, cam_name, w, h)?;
    // Objects' world matrices at the motion steps (`motion::object::evaluate_steps`).
    let mut object_steps: Vec<Vec<crate::anim::Mat4>> = Vec::new();
    if let Some(sh) = &shutter {
        let mut steps = Vec::new();
        for (k, f) in sh.step_frames(frame).into_iter().enumerate() {
            let e = if k == 1 {
                None
            } else {
                Some(crate::anim::evaluate_scene(scene, f).map_err(|e| {
                    RenderError(format!(
                        "evaluating the scene at frame {f} (motion blur): {e}"
                    ))
                })?)
            };
            let at = e.as_ref().unwrap_or(&eval);
            steps.push(camera::Camera::of_object(scene, at, cam_name, w, h)?.to_world);
        }
        object_steps = motion::object::evaluate_steps(scene, &eval, sh)?;
        motion::object::warn_deformation(&eval);
        camera.set_motion(&steps);
    }
    volume::check_objects(scene, frame)?;
    let mut geo = build::build(scene, &eval, overrides)?;
    let mut used = vec![false; scene.file.materials.len()];
    for inst in &geo.instances {
        for m in inst.slots.iter().flatten() {
            used[*m] = true;
        }
    }
    let materials = integrator::shade::compile_all(scene, &used)?;
    check_point_density_frames(scene, &used, frame)?;
    points::check(&geo, &materials)?;
    curves::check(scene, &geo, &materials)?;
    build::bind_attributes(&mut geo, &materials)?;
    if displace::apply(&mut geo, &materials) > 0 {
        (geo.tris, geo.refs) = build::world_triangles(&geo.instances);
    }
    let moving = motion::object::attach(
        &mut geo,
        &eval.data.objects,
        &eval.world_matrices,
        &object_steps,
    );
    if moving > 0 {
        if let Some(h) = geo.instances.iter().find(|i| i.curves.is_some()) {
            return Err(RenderError(format!("object {:?}: hair curves with motion blur (moving objects in the shutter) are not supported: turn motion blur off", h.name)));
        }
    }
    let lights = light::collect(scene, &eval)?;
    let background = light::world::background(scene)?;
    let world_shader = light::world::shader(scene)?;
    Ok(Prepared {
        start,
        w,
        h,
        shutter,
        samples,
        seed,
        camera,
        geo,
        materials,
        lights,
        background,
        world_shader,
        moving,
    })
}

/// The emitters light sampling picks from, as Cycles collects them (LightManager): every
/// light, the world when it varies with direction, and the triangles of materials whose
/// emission Cycles light-samples; in its light tree, or in its flat distribution when the
/// scene turns the tree off. Energies are Cycles' estimates (a triangle's area times the
/// mean of its material's emission estimate), not the emission itself: they set the
/// selection probabilities, which decide how clamping acts.
// Long because it collects every kind of emitter (lights, world, emissive triangles) as Cycles' LightManager does, in its order.
fn light_select(
    geo: &build::Geometry,
    materials: &[integrator::shade::Material],
    lights: &[light::Light],
    world: Option<&light::world::WorldShader>,
    use_tree: bool,
) -> LightSelect {
    use light::tree::{Cone, Emitter, Measure, Pick, Shape};
    use std::f32::consts::{FRAC_PI_2, PI};
    let mut local = Vec::new();
    let mut distant = Vec::new();
    let mut flat_lights = Vec::new();
    for (li, l) in lights.iter().enumerate() {
        if l.tree_energy == 0.0 || !l.tree_energy.is_finite() {
            continue;
        }
        let pick = Some(Pick::Lamp(li as u32));
        flat_lights.push(Pick::Lamp(li as u32));
        match &l.shape {
            light::Shape::Point {
                radius,
                spot,
                sphere,
            } => {
                let r = Vec3::splat(*radius);
                let (cone, spot_smooth) = match spot {
                    None => (
                        Cone {
                            axis: l.dir,
                            theta_o: PI,
                            theta_e: FRAC_PI_2,
                        },
                        None,
                    ),
                    Some(s) => {
                        // Cycles widens the cone by the light's scale (its axes).
                        let (lu, lv, lw) = (s.u.length(), s.v.length(), s.w.length());
                        let stretch = if lu > 0.0 && lv > 0.0 {
                            lw / lu.min(lv)
                        } else {
                            1.0
                        };
                        let half = s.cos_half.clamp(-1.0, 1.0).acos();
                        (
                            Cone {
                                axis: l.dir,
                                theta_o: 0.0,
                                theta_e: (half.tan() * stretch).atan(),
                            },
                            Some(s.smooth),
                        )
                    }
                };
                let measure = Measure::new(&[l.pos - r, l.pos + r], cone, l.tree_energy);
                local.push(Emitter {
                    pick,
                    shape: Shape::Point {
                        pos: l.pos,
                        radius: *radius,
                        sphere: *sphere,
                        spot_smooth,
                    },
                    centroid: l.pos,
                    measure,
                });
            }
            light::Shape::Area { u, v, .. } => {
                let (hu, hv) = (*u * 0.5, *v * 0.5);
                let corners = [
                    l.pos + hu + hv,
                    l.pos + hu - hv,
                    l.pos - hu + hv,
                    l.pos - hu - hv,
                ];
                let measure = Measure::new(
                    &corners,
                    Cone {
                        axis: l.dir,
                        theta_o: 0.0,
                        theta_e: 0.5 * l.spread,
                    },
                    l.tree_energy,
                );
                local.push(Emitter {
                    pick,
                    shape: Shape::Area {
                        pos: l.pos,
                        eu: *u,
                        ev: *v,
                    },
                    centroid: l.pos,
                    measure,
                });
            }
            light::Shape::Sun { half_angle } => {
                let measure = Measure::new(
                    &[],
                    Cone {
                        axis: l.dir,
                        theta_o: 0.0,
                        theta_e: *half_angle,
                    },
                    l.tree_energy,
                );
                distant.push(Emitter {
                    pick,
                    shape: Shape::Distant,
                    centroid: l.dir,
                    measure,
                });
            }
        }
    }
    if let Some((w, map)) = world.and_then(|w| w.map.as_ref().map(|m| (w, m))) {
        let energy = (average(w.program.emission_estimate) * map.average_radiance * PI).abs();
        if energy > 0.0 && energy.is_finite() {
            let measure = Measure::new(
                &[],
                Cone {
                    axis: Vec3::Z,
                    theta_o: PI,
                    theta_e: 0.0,
                },
                energy,
            );
            distant.push(Emitter {
                pick: Some(Pick::World),
                shape: Shape::World,
                centroid: Vec3::ZERO,
                measure,
            });
            flat_lights.push(Pick::World);
        }
    }
    let sampled: Vec<Option<f32>> = materials
        .iter()
        .map(|m| {
            m.program
                .as_ref()
                .filter(|p| light_sampled(p, &m.sampling))
                .map(|p| average(p.emission_estimate))
        })
        .collect();
    let mut meshes: Vec<Vec<Emitter>> = Vec::new();
    let mut flat_tris = Vec::new();
    let mut last_inst = u32::MAX;
    for (prim, r) in geo.refs.iter().enumerate() {
        let inst = &geo.instances[r.inst as usize];
        // A moving emitter is found by BSDF sampling alone (it is no emitter here, so the
        // MIS weight is 1): light samples on it would need its pose at the ray's time.
        if inst.motion.is_some() {
            continue;
        }
        let Some(mi) = inst.material_of(r.tri as usize) else {
            continue;
        };
        let Some(estimate) = sampled[mi] else {
            continue;
        };
        let v = geo.tris[prim].map(Vec3::from);
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        let area = 0.5 * n.length();
        if !(area > 0.0) {
            continue;
        }
        let cone = match materials[mi].sampling.as_str() {
            "FRONT" => Cone {
                axis: n.normalize(),
                theta_o: 0.0,
                theta_e: FRAC_PI_2,
            },
            "BACK" => Cone {
                axis: -n.normalize(),
                theta_o: 0.0,
                theta_e: FRAC_PI_2,
            },
            _ => Cone {
                axis: (v[0] - v[1]).normalize(),
                theta_o: FRAC_PI_2,
                theta_e: FRAC_PI_2,
            },
        };
        let centroid = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
        let e = Emitter {
            pick: Some(light::tree::Pick::Triangle(prim as u32)),
            shape: Shape::Triangle { v },
            centroid,
            measure: Measure::new(&v, cone, area * estimate),
        };
        // One subtree per object (an instance's triangles are consecutive).
        if r.inst != last_inst || meshes.is_empty() {
            meshes.push(Vec::new());
            last_inst = r.inst;
        }
        meshes.last_mut().expect("pushed above").push(e);
        flat_tris.push((prim as u32, area));
    }
    if local.is_empty() && distant.is_empty() && meshes.is_empty() {
        return LightSelect::None;
    }
    if use_tree {
        LightSelect::Tree(light::tree::LightTree::build(local, distant, meshes))
    } else {
        LightSelect::Flat(light::tree::Distribution::build(&flat_tris, &flat_lights))
    }
}

/// Whether Cycles light-samples a material's emitting triangles (Shader::estimate_emission):
/// never when its emission estimate is zero; with "Auto" only when the estimate's largest
/// channel exceeds 0.5 (weaker emitters are found by BSDF rays alone), a tenth of it for a
/// colour linked straight into the Surface.
fn light_sampled(p: &crate::shader::program::Program, sampling: &str) -> bool {
    let e = p.emission_estimate;
    if e.iter().all(|&x| x == 0.0) {
        return false;
    }
    let scale = if p.surface_from_value { 0.1 } else { 1.0 };
    match sampling {
        "NONE" => false,
        "AUTO" => e.iter().any(|x| (x * scale).abs() > 0.5),
        _ => true,
    }
}

/// One tile's share of the work: its rectangle, a copy of its pixels' accumulators
/// for the current sample range, and its label passes.
struct TileWork {
    tx: u32,
    ty: u32,
    tw: u32,
    th: u32,
    acc: Vec<film::adaptive::PixelAcc>,
    passes: TilePasses,
    rays: u64,
}

#[derive(Default)]
struct TilePasses {
    depth: Vec<f32>,
    distance: Vec<f32>,
    object_index: Vec<u32>,
    instance_id: Vec<u32>,
    material_index: Vec<u32>,
    normal: Vec<[f32; 3]>,
    uv: Vec<[f32; 2]>,
    hits: Vec<Option<film::flow::PixelHit>>,
    /// Sums over the pixel's samples of the denoiser's guides (`denoise_features`).
    feature_normal: Vec<[f32; 3]>,
    feature_albedo: Vec<[f32; 3]>,
    /// Sums over the pixel's samples of its AOV values (`film::aov::Layout::stride` per
    /// pixel).
    aov: Vec<f32>,
}

/// Label passes from the primary ray through the pixel centre (exact ids, unfiltered), at
/// the shutter's centre: with motion blur the labels show moving objects where the scene
/// was synced (the frame for a centred shutter), sharp, not blurred as in the image.
fn primary_passes(
    tracer: &integrator::Scene,
    camera: &camera::Camera,
    x: u32,
    y: u32,
    scratch: &mut Scratch,
    out: &mut TilePasses,
) {
    out.feature_normal.push([0.0; 3]);
    out.feature_albedo.push([0.0; 3]);
    let (o, d, t0, t1) = camera.ray(x as f32 + 0.5, y as f32 + 0.5, [0.5, 0.5]);
    match tracer.accel.intersect_vis(
        o,
        d,
        t0,
        t1,
        motion::object::CENTRE_TIME,
        accel::visibility::of_path(crate::shader::point::ray::CAMERA),
    ) {
        Some(h) => {
            let wo = (-Vec3::from(d)).into();
            let hit = tracer.surface(h.prim, h.u, h.v, wo);
            tracer.shade(&hit, wo, scratch);
            let inst = &tracer.geo.instances[hit.inst as usize];
            out.depth.push(camera.depth(hit.p));
            out.distance.push(camera.distance(hit.p));
            out.object_index.push(inst.object as u32 + 1);
            out.instance_id.push(hit.inst + 1);
            out.material_index
                .push(hit.material.map(|m| m as u32 + 1).unwrap_or(0));
            out.normal.push(hit.sp.normal);
            out.uv.push([hit.sp.uv[0], hit.sp.uv[1]]);
            let r = tracer.geo.refs[h.prim as usize];
            out.hits.push(Some(film::flow::PixelHit {
                inst: r.inst,
                tri: r.tri,
                u: h.u,
                v: h.v,
            }));
        }
        None => {
            out.depth.push(f32::INFINITY);
            out.distance.push(f32::INFINITY);
            out.object_index.push(0);
            out.instance_id.push(0);
            out.material_index.push(0);
            out.normal.push([0.0; 3]);
            out.uv.push([0.0; 2]);
            out.hits.push(None);
        }
    }
}

#[doc(hidden)]
pub fn _assert_accel_object_safe(_: &dyn Accel) {}

/// The scene's ray structure: `backend`'s over the triangles, beside the hair curves'
/// (`curves::WithCurves`) when there are any; Embree is refused with curves (blendsynth
/// gives it triangles only).
fn with_curves(backend: accel::Backend, geo: &build::Geometry) -> Result<Box<dyn Accel>, String> {
    let n = build::triangle_count(geo);
    let masks = build::triangle_masks(geo);
    let Some(c) = curves::CurveAccel::build(geo) else {
        return backend.build_masked(&geo.tris, &masks);
    };
    if backend == accel::Backend::Embree {
        let name = geo
            .instances
            .iter()
            .find(|i| i.curves.is_some())
            .map(|i| i.name.clone())
            .unwrap_or_default();
        return Err(format!("BLENDSYNTH_ACCEL=embree: object {name:?} has hair curves, which blendsynth's Embree backend does not take yet (use bvh4 or bvh2)"));
    }
    Ok(Box::new(curves::WithCurves {
        tris: backend.build_masked(&geo.tris[..n], &masks[..n])?,
        curves: std::sync::Arc::new(c),
    }))
}
