//! Volumes inside closed meshes, as Cycles 4.5 integrates them (kernel/integrator/
//! shade_volume.h, volume_stack.h, volume_shader.h): the stack of volumes a path is
//! inside, entered and left where it transmits through a surface whose material has a
//! Volume; along each ray segment inside them, the material's volume closures summed into
//! extinction, scattering and emission, one step for a constant medium (analytic
//! transmittance) and ray-marched steps for a varying one; a scattering distance drawn by
//! Cycles' spectral distance sampling, light sampled there through the phase function
//! (MIS with phase sampling) and the path continued in a phase-sampled direction. Shadow
//! rays are attenuated by the volumes they cross.
//!
//! Direct light is sampled as Cycles does: one light picked ahead of each segment, and
//! the scatter point for it drawn by distance sampling, by equiangular sampling toward a
//! point on that light, or by either with MIS (the material's Volume > Sampling).

use crate::scene::settings::{Integrator, MaterialSettings, VolumeSampling};
use crate::scene::Scene as BlendScene;
use crate::shader::point::{ray, PathState};
use crate::shader::program::{Closure, Program};
use crate::shader::ShadingPoint;

use super::build::Geometry;
use super::integrator::path_state::{Path, SETS_PER_VERTEX};
use super::integrator::shade::Material;
use super::integrator::{Scene, Scratch, SurfaceHit};
use super::light::tree::{Pick, Viewer};
use super::math::*;
use super::sampler::PixelSampler;
use super::volume_world::{WorldVolume, ESCAPE, WORLD};

/// Volumes a path can be inside at once (Cycles sizes its stack from the scene; deeper
/// nesting is ignored, as Cycles ignores entries past its stack).
pub const STACK_SIZE: usize = 8;

/// Cycles' VOLUME_THROUGHPUT_EPSILON: a segment that lets less through ends the path.
const THROUGHPUT_EPSILON: f32 = 1e-6;

/// The volumes a ray segment is inside: (mesh instance, material) pairs, in the order
/// they were entered.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Stack {
    entries: [(u32, u32); STACK_SIZE],
    len: usize,
}

impl Stack {
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Cycles' volume_stack_clean for a ray that escapes the scene: every volume but the
    /// world's is left (only precision errors leave a mesh's volume open there).
    pub fn keep_world(&mut self) {
        let world = self.entries().first() == Some(&(WORLD, WORLD));
        self.len = usize::from(world);
    }

    /// The world volume, entered first (Cycles' stack init) and never left.
    fn push_world(&mut self) {
        if self.len < STACK_SIZE - 1 {
            self.entries[self.len] = (WORLD, WORLD);
            self.len += 1;
        }
    }

    pub fn entries(&self) -> &[(u32, u32)] {
        &self.entries[..self.len]
    }

    /// Cycles' volume_stack_enter_exit at a surface of instance `inst` with a volume
    /// material: seen from its back the ray leaves the volume, else it enters it (once).
    pub fn enter_exit(&mut self, inst: u32, material: u32, backfacing: bool) {
        let at = self.entries().iter().position(|e| *e == (inst, material));
        if backfacing {
            if let Some(i) = at {
                self.entries.copy_within(i + 1..self.len, i);
                self.len -= 1;
            }
        } else if at.is_none() && self.len < STACK_SIZE - 1 {
            self.entries[self.len] = (inst, material);
            self.len += 1;
        }
    }
}

/// A material's volume as the renderer runs it.
#[derive(Debug, Clone, Copy)]
struct VolumeMaterial {
    /// Ray-marched: its closures read computed values and Volume > Homogeneous is off
    /// (Cycles: heterogeneous_volume with spatially varying nodes).
    varying: bool,
    /// Volume > Step Rate.
    step_rate: f32,
    /// Volume > Sampling.
    sampling: VolumeSampling,
    /// Volume > Interpolation is Cubic: voxel grids are sampled tricubically.
    cubic: bool,
}

/// Every volume of the scene and the render's volume settings.
#[derive(Debug, Clone, Default)]
pub struct Volumes {
    /// Per material (scene order): its volume, if its Volume output is linked.
    materials: Vec<Option<VolumeMaterial>>,
    /// Per material: a volume and no surface (Cycles' SD_HAS_ONLY_VOLUME): rays pass its
    /// boundary without a bounce.
    only_volume: Vec<bool>,
    /// Per mesh instance: its ray-marching step (Cycles' object volume step size times
    /// the render's step rate), infinite when none of its volumes varies.
    step: Vec<f32>,
    /// Light Paths > Volume bounces.
    pub max_bounces: u32,
    /// Volumes > Max Steps.
    max_steps: u32,
    /// Some material has a volume.
    pub any: bool,
    /// World bounds of the instances with a volume (where a camera may be inside one).
    bounds: Vec<(V3, V3)>,
    /// Per mesh instance with voxel grids: per volume material of its slots, which grid
    /// each of the material's attribute requests reads.
    grid_binds: Vec<Vec<(u32, super::volume_grid::GridBinding)>>,
    /// The world volume (render/volume_world.rs), and its ray-marching step (its Step
    /// Size times the render's step rate; infinite when it does not vary).
    world: Option<WorldVolume>,
    world_step: f32,
}

impl Volumes {
    pub fn build(
        scene: &BlendScene,
        geo: &Geometry,
        materials: &[Material],
        integrator: &Integrator,
    ) -> Volumes {
        let mut v = Volumes {
            max_bounces: integrator.volume_bounces,
            max_steps: integrator.volume_max_steps.max(1),
            ..Volumes::default()
        };
        for (i, m) in materials.iter().enumerate() {
            let p = m.program.as_ref().filter(|p| p.volume.is_some());
            let settings = scene.file.materials.get(i).map(MaterialSettings::of);
            v.materials.push(p.map(|p| {
                VolumeMaterial {
                    varying: p.volume_varying
                        && !settings.as_ref().is_some_and(|s| s.homogeneous_volume),
                    step_rate: settings.as_ref().map_or(1.0, |s| s.volume_step_rate as f32),
                    sampling: settings
                        .as_ref()
                        .map_or(VolumeSampling::MultipleImportance, |s| s.volume_sampling),
                    cubic: settings.as_ref().is_some_and(|s| s.volume_cubic),
                }
            }));
            v.only_volume.push(p.is_some_and(|p| p.surface.is_none()));
        }
        let render_rate = integrator.volume_step_rate as f32;
        // `check_objects` has refused a world volume that does not compile.
        v.world = super::volume_world::world_volume(scene).ok().flatten();
        v.world_step = match &v.world {
            // Cycles' background volume_step_size times the render's step rate.
            Some(w) if w.varying => w.step_size * render_rate,
            _ => f32::INFINITY,
        };
        v.any = v.materials.iter().any(Option::is_some) || v.world.is_some();
        for inst in &geo.instances {
            // Cycles' Object::compute_volume_step_size: the smallest step rate of its
            // varying volumes times a tenth of the average size of its world bounds.
            let rate = inst
                .slots
                .iter()
                .flatten()
                .filter_map(|&m| v.materials.get(m).copied().flatten())
                .filter(|m| m.varying)
                .map(|m| m.step_rate)
                .fold(f32::INFINITY, f32::min);
            let (lo, hi) = inst.world_bounds;
            let size = average(sub(hi, lo));
            if inst
                .slots
                .iter()
                .flatten()
                .any(|&m| v.materials.get(m).copied().flatten().is_some())
            {
                v.bounds.push(inst.world_bounds);
            }
            let mut binds = Vec::new();
            if let Some(g) = &inst.grids {
                // Cycles: reading voxel attributes makes a volume heterogeneous, and the
                // step follows the voxel size (Object::compute_volume_step_size).
                let mut rate = f32::INFINITY;
                for &m in inst.slots.iter().flatten() {
                    let (Some(Some(vm)), Some(p)) =
                        (v.materials.get(m), materials[m].program.as_ref())
                    else {
                        continue;
                    };
                    rate = rate.min(vm.step_rate);
                    binds.push((m as u32, g.bind(&p.attributes)));
                }
                let voxel = g.step(&inst.to_world);
                let step = if voxel.is_finite() { voxel } else { 0.1 * size };
                v.step.push(if rate.is_finite() {
                    step * rate * render_rate
                } else {
                    f32::INFINITY
                });
            } else {
                v.step.push(if rate.is_finite() {
                    0.1 * size * rate * render_rate
                } else {
                    f32::INFINITY
                });
            }
            v.grid_binds.push(binds);
        }
        v
    }

    /// Whether `p` is within the bounds of an instance with a volume.
    fn near_volume(&self, p: V3) -> bool {
        self.bounds
            .iter()
            .any(|(lo, hi)| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]))
    }

    /// Whether material `m` has a volume.
    pub fn has_volume(&self, m: usize) -> bool {
        matches!(self.materials.get(m), Some(Some(_)))
    }

    /// Which grid each attribute request of material `m` reads inside instance `inst`.
    fn grid_bind(&self, inst: u32, m: u32) -> Option<&super::volume_grid::GridBinding> {
        self.grid_binds
            .get(inst as usize)?
            .iter()
            .find(|(mi, _)| *mi == m)
            .map(|(_, b)| b)
    }

    /// Whether material `m` samples voxel grids tricubically.
    fn cubic(&self, m: u32) -> bool {
        matches!(self.materials.get(m as usize), Some(Some(v)) if v.cubic)
    }

    /// Whether material `m` is a volume with no surface.
    pub fn only_volume(&self, m: usize) -> bool {
        self.only_volume.get(m).copied().unwrap_or(false)
    }

    /// Cycles' volume_stack_step_size: the smallest step of the varying volumes in the
    /// stack, infinite when every one is constant.
    fn step_size(&self, stack: &Stack) -> f32 {
        stack
            .entries()
            .iter()
            .map(|&(inst, _)| {
                if inst == WORLD {
                    return self.world_step;
                }
                self.step
                    .get(inst as usize)
                    .copied()
                    .unwrap_or(f32::INFINITY)
            })
            .fold(f32::INFINITY, f32::min)
    }

    /// Cycles' volume_stack_sample_method: MIS when some volume in the stack asks for it
    /// or the volumes disagree, otherwise what they all ask for.
    fn sample_method(&self, stack: &Stack) -> Method {
        let mut method = None;
        for &(_, mi) in stack.entries() {
            let sampling = if mi == WORLD {
                match &self.world {
                    Some(w) => w.sampling,
                    None => continue,
                }
            } else {
                match self.materials.get(mi as usize) {
                    Some(Some(m)) => m.sampling,
                    _ => continue,
                }
            };
            let this = match sampling {
                VolumeSampling::MultipleImportance => return Method::Mis,
                VolumeSampling::Equiangular => Method::Equiangular,
                VolumeSampling::Distance => Method::Distance,
            };
            match method {
                Some(other) if other != this => return Method::Mis,
                _ => method = Some(this),
            }
        }
        method.unwrap_or(Method::Distance)
    }
}

/// How the scatter point for direct light is drawn along a segment (Cycles'
/// VolumeSampleMethod).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    Distance,
    Equiangular,
    Mis,
}

/// Cycles' VOLUME_SAMPLE_PDF_CUTOFF: scatter distances less likely than this are
/// skipped (they contribute next to nothing and lead far away).
const PDF_CUTOFF: f32 = 1e-8;

/// Equiangular sampling of a distance along the ray `o + t d`, t in [tmin, tmax], in
/// proportion to the inverse squared distance to `light` (Cycles'
/// volume_equiangular_sample and _pdf).
#[derive(Debug, Clone, Copy)]
struct Equiangular {
    delta: f32,
    d: f32,
    theta_a: f32,
    theta_b: f32,
    tmin: f32,
    tmax: f32,
}

impl Equiangular {
    fn new(o: V3, dir: V3, light: V3, tmin: f32, tmax: f32) -> Option<Equiangular> {
        let to = sub(light, o);
        let delta = dot(to, dir);
        let d = (dot(to, to) - delta * delta).max(0.0).sqrt();
        let theta_a = (tmin - delta).atan2(d);
        let theta_b = (tmax - delta).atan2(d);
        (d > 0.0 && theta_b != theta_a).then_some(Equiangular {
            delta,
            d,
            theta_a,
            theta_b,
            tmin,
            tmax,
        })
    }

    /// A distance and its pdf.
    fn sample(&self, xi: f32) -> (f32, f32) {
        let t = self.d * (xi * self.theta_b + (1.0 - xi) * self.theta_a).tan();
        let pdf = self.d / ((self.theta_b - self.theta_a) * (self.d * self.d + t * t));
        ((self.delta + t).clamp(self.tmin, self.tmax), pdf)
    }

    fn pdf(&self, t: f32) -> f32 {
        let x = t - self.delta;
        self.d / ((self.theta_b - self.theta_a) * (self.d * self.d + x * x))
    }
}

/// The light a segment's direct light comes from, picked before stepping as Cycles'
/// integrate_volume_equiangular_sample_light does: what light selection chose at the
/// segment's start, its selection probability, and a point on it to sample distances
/// toward (none for the world and suns).
#[derive(Debug, Clone, Copy)]
struct AheadLight {
    pick: Pick,
    p_sel: f32,
    toward: Option<V3>,
}

/// Volumes blendsynth cannot render, refused by name (for `render` and `inspect`): Volume
/// objects it cannot read (`check_volume_object`), a
/// fluid (smoke or fire) domain whose material has a Volume, when the export carries no
/// grids for it (an export older than the grid writer) or the material also has a
/// Surface (Cycles would shade the voxel hull with it; not matched yet). Checked before
/// the geometry (a domain's mesh is frozen, which is not the reason it fails).
pub fn check_objects(scene: &BlendScene, frame: f64) -> Result<(), super::RenderError> {
    let linked = |name: &str, socket: &str| {
        scene
            .material(name)
            .and_then(|m| m.node_tree.as_ref())
            .is_some_and(|t| t.links.iter().any(|l| l.to_socket == socket && !l.is_muted))
    };
    super::volume_world::world_volume(scene)?;
    for obj in scene
        .file
        .objects
        .iter()
        .filter(|o| !o.hide_render && o.kind == "VOLUME")
    {
        check_volume_object(scene, obj, frame, &linked)?;
    }
    for obj in scene.file.objects.iter().filter(|o| !o.hide_render) {
        let domain = obj.modifiers.iter().find(|md| {
            md.show_render
                && md.kind == "FLUID"
                && md.properties.get("fluid_type").and_then(|v| v.as_str()) == Some("DOMAIN")
        });
        let Some(md) = domain else { continue };
        let mesh_materials = obj
            .data
            .as_deref()
            .and_then(|d| scene.file.meshes.iter().find(|m| m.name == d))
            .map(|m| m.materials.clone())
            .unwrap_or_default();
        let volume = obj
            .material_slots
            .iter()
            .filter_map(|s| s.material.clone())
            .chain(mesh_materials.into_iter().flatten())
            .find(|m| linked(m, "Volume"));
        let Some(m) = volume else { continue };
        if !scene.is_smoke_domain(&obj.name) {
            return Err(super::RenderError(format!(
                "object {:?}: the volume of its fluid domain (modifier {:?}, material {m:?}) is rendered from the simulation's grids, which this export does not carry: convert the .blend again with this version's exporter",
                obj.name, md.name
            )));
        }
        if linked(&m, "Surface") {
            return Err(super::RenderError(format!(
                "object {:?}: material {m:?} of its smoke domain (modifier {:?}) has a Surface as well as a Volume: a surface on a smoke domain is not supported yet",
                obj.name, md.name
            )));
        }
    }
    Ok(())
}

/// A Volume object (OpenVDB grids) is rendered from the grids the export carries for it;
/// refused by name: an export without them, grids that could not be read (the OpenVDB
/// module missing, a value type, level set or transform not handled), a material with a
/// Surface as well (Cycles would shade the voxel hull), and motion blur of a Volume with a
/// velocity grid (Cycles moves the voxels by it; not done).
fn check_volume_object(
    scene: &BlendScene,
    obj: &crate::scene::Object,
    frame: f64,
    linked: &dyn Fn(&str, &str) -> bool,
) -> Result<(), super::RenderError> {
    let fail = |why: String| {
        Err(super::RenderError(format!(
            "object {:?}: Volume object {why}",
            obj.name
        )))
    };
    let Some((_, v)) = scene.volume_object(&obj.name, frame) else {
        return fail(
            "is rendered from its OpenVDB grids, which this export does not carry: convert the .blend again with this version's exporter".into(),
        );
    };
    if let Some(e) = &v.error {
        return fail(format!("{:?}: its grids could not be read: {e}", v.volume));
    }
    if let Some((g, why)) = v.unread.first() {
        return fail(format!(
            "{:?}: grid {g:?} is not supported: {why}",
            v.volume
        ));
    }
    let materials = obj
        .material_slots
        .iter()
        .filter_map(|s| s.material.clone())
        .chain(v.materials.iter().flatten().cloned());
    for m in materials {
        if linked(&m, "Volume") && linked(&m, "Surface") {
            return fail(format!(
                "{:?}: material {m:?} has a Surface as well as a Volume: a surface on a Volume object is not supported yet",
                v.volume
            ));
        }
    }
    let blur = crate::scene::settings::MotionBlur::of(&scene.file.scene).is_ok_and(|m| m.enabled);
    if let Some(g) = v
        .velocity_grid
        .as_ref()
        .filter(|_| blur && v.velocity_scale != 0.0)
    {
        return fail(format!(
            "{:?}: motion blur by its velocity grid {g:?} is not supported yet (turn off Render > Motion Blur, or set the Volume's Velocity Scale to 0)",
            v.volume
        ));
    }
    Ok(())
}

/// A phase function of Cycles 4.5 (closure/volume_*.h).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Phase {
    HenyeyGreenstein(f32),
    Rayleigh,
}

impl Phase {
    /// Cycles' setup: g kept within (-1, 1), near-zero g isotropic.
    fn henyey_greenstein(g: f32) -> Phase {
        let g = if g.is_finite() { g } else { 0.0 };
        Phase::HenyeyGreenstein(g.signum() * g.abs().min(1.0 - 1e-3))
    }

    /// The phase function (its own pdf) for light travelling along `d` and leaving
    /// toward `wi`.
    pub fn eval(&self, d: V3, wi: V3) -> f32 {
        let cos = dot(d, wi);
        match *self {
            Phase::HenyeyGreenstein(g) => hg(cos, g),
            Phase::Rayleigh => 3.0 / (16.0 * std::f32::consts::PI) * (1.0 + cos * cos),
        }
    }

    /// A direction for light travelling along `d`, and its pdf.
    pub fn sample(&self, d: V3, u: [f32; 2]) -> (V3, f32) {
        let cos = match *self {
            Phase::HenyeyGreenstein(g) if g.abs() >= 1e-3 => {
                let k = (1.0 - g * g) / (1.0 - g + 2.0 * g * u[0]);
                ((1.0 + g * g - k * k) / (2.0 * g)).clamp(-1.0, 1.0)
            }
            Phase::HenyeyGreenstein(_) => 1.0 - 2.0 * u[0],
            Phase::Rayleigh => {
                // The inverse of the cdf (cos^3 + 3 cos + 4) / 8, by Cardano.
                let a = 4.0 * u[0] - 2.0;
                let s = (a + (a * a + 1.0).sqrt()).cbrt();
                (s - 1.0 / s).clamp(-1.0, 1.0)
            }
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * u[1];
        let (t, b) = basis(d);
        let wi = normalize(add(
            scale(d, cos),
            add(scale(t, sin * phi.cos()), scale(b, sin * phi.sin())),
        ));
        (wi, self.eval(d, wi))
    }
}

/// The Henyey-Greenstein phase function at cosine `cos` from the forward direction.
fn hg(cos: f32, g: f32) -> f32 {
    if g.abs() < 1e-3 {
        return 0.25 * std::f32::consts::FRAC_1_PI;
    }
    let d = 1.0 + g * g - 2.0 * g * cos;
    (1.0 - g * g) / (4.0 * std::f32::consts::PI * d * d.sqrt())
}

/// The phase closures at a point, each with its sample weight (Cycles: |average of the
/// closure weight|).
#[derive(Debug, Clone, Copy, Default)]
pub struct Phases {
    items: [(f32, Option<Phase>); 8],
    n: usize,
}

impl Phases {
    fn push(&mut self, weight: V3, phase: Phase) {
        let w = average(weight).abs();
        // Cycles' bsdf_alloc drops closures below its weight cutoff.
        if max3(weight.map(f32::abs)) < 1e-5 || self.n == self.items.len() {
            return;
        }
        self.items[self.n] = (w, Some(phase));
        self.n += 1;
    }

    fn iter(&self) -> impl Iterator<Item = (f32, Phase)> + '_ {
        self.items[..self.n]
            .iter()
            .filter_map(|(w, p)| p.map(|p| (*w, p)))
    }

    /// Cycles' _volume_shader_phase_eval_mis: the phases averaged by sample weight, and
    /// the pdf of sampling `wi` the same way.
    pub fn eval(&self, d: V3, wi: V3) -> (f32, f32) {
        let (mut f, mut sum) = (0.0, 0.0);
        for (w, p) in self.iter() {
            f += w * p.eval(d, wi);
            sum += w;
        }
        if sum > 0.0 {
            (f / sum, f / sum)
        } else {
            (0.0, 0.0)
        }
    }

    /// Cycles' volume_shader_phase_pick and sample: one phase by sample weight, its
    /// direction; weight and pdf of that phase alone.
    pub fn sample(&self, d: V3, u: [f32; 2]) -> Option<(V3, f32)> {
        let mut u = u;
        let mut picked = None;
        let mut sum = 0.0;
        for (w, p) in self.iter() {
            sum += w;
            if picked.is_none() {
                picked = Some(p);
                continue;
            }
            let thresh = w / sum;
            if u[0] < thresh {
                picked = Some(p);
                u[0] /= thresh;
            } else {
                u[0] = (u[0] - thresh) / (1.0 - thresh);
            }
        }
        let (wi, pdf) = picked?.sample(d, u);
        (pdf > 0.0).then_some((wi, pdf))
    }
}

/// The volume coefficients at a point: the sum over the stack (Cycles'
/// VolumeShaderCoefficients).
#[derive(Debug, Clone, Copy, Default)]
pub struct Coefficients {
    pub sigma_t: V3,
    pub sigma_s: V3,
    pub emission: V3,
    pub phases: Phases,
    /// Some closure set extinction, scattering or emission.
    extinction: bool,
    scatter: bool,
    emit: bool,
}

fn v3(s: &[f32], at: u32) -> V3 {
    let i = at as usize;
    [s[i], s[i + 1], s[i + 2]]
}

fn finite_or(v: f32, d: f32) -> f32 {
    if v.is_finite() {
        v
    } else {
        d
    }
}

impl Coefficients {
    fn add_extinction(&mut self, w: V3) {
        self.sigma_t = add(self.sigma_t, w);
        self.extinction = true;
    }

    fn add_scatter(&mut self, w: V3, phase: Phase) {
        // Cycles' bsdf_alloc allows no negative weight (a colour below zero, from a Point
        // Density's normals say); the extinction keeps the weight as it is.
        let w = w.map(|x| x.max(0.0));
        if max3(w.map(f32::abs)) < 1e-5 {
            return;
        }
        self.sigma_s = add(self.sigma_s, w);
        self.phases.push(w, phase);
        self.scatter = true;
    }

    fn add_emission(&mut self, e: V3) {
        self.emission = add(self.emission, e);
        self.emit = true;
    }

    /// Adds closure `c` of program `p` (stack `s`, already run) with mix weight `w`.
    fn closure(&mut self, p: &Program, c: u32, w: f32, s: &[f32], sp: &ShadingPoint, shadow: bool) {
        match p.closures[c as usize] {
            Closure::Emission { color, strength } => {
                if !shadow {
                    let e = scale(v3(s, color), finite_or(s[strength as usize], 0.0) * w);
                    self.add_emission(e.map(|x| finite_or(x, 0.0)));
                }
            }
            Closure::Mix { fac, a, b } => {
                let f = finite_or(s[fac as usize], 0.0).clamp(0.0, 1.0);
                if let Some(a) = a.filter(|_| w * (1.0 - f) > 0.0) {
                    self.closure(p, a, w * (1.0 - f), s, sp, shadow);
                }
                if let Some(b) = b.filter(|_| w * f > 0.0) {
                    self.closure(p, b, w * f, s, sp, shadow);
                }
            }
            Closure::Add { a, b } => {
                for x in [a, b].into_iter().flatten() {
                    self.closure(p, x, w, s, sp, shadow);
                }
            }
            Closure::Bsdf { .. } => {
                if let Some(b) = p.bsdfs.iter().find(|b| b.closure == c) {
                    self.volume_node(b, w, s, sp, shadow);
                }
            }
        }
    }

    /// One volume node (surface BSDFs in a Volume do nothing, as in Cycles).
    fn volume_node(
        &mut self,
        b: &crate::shader::program::BsdfNode,
        w: f32,
        s: &[f32],
        sp: &ShadingPoint,
        shadow: bool,
    ) {
        // Principled Volume's Density/Color/Temperature Attribute: the request index the
        // compiler recorded, when the point has that attribute (a voxel grid).
        let attr = |id: &str| -> Option<[f32; 4]> {
            let k: usize = b.property(&format!("attribute:{id}"))?.parse().ok()?;
            (k < sp.attrs.len() && sp.attr_missing & (1 << k) == 0).then(|| sp.attrs[k])
        };
        let f = |id: &str, d: f32| {
            b.input(id)
                .map_or(d, |(at, _)| finite_or(s[at as usize], d))
        };
        let c = |id: &str, d: V3| {
            b.input(id)
                .map_or(d, |(at, _)| v3(s, at).map(|x| finite_or(x, 0.0)))
        };
        let phase = || match b.property("phase") {
            Some("RAYLEIGH") => Phase::Rayleigh,
            _ => Phase::henyey_greenstein(f("Anisotropy", 0.0)),
        };
        match b.bl_idname.as_str() {
            // svm_node_closure_volume: the colour is the closure weight; absorption
            // takes its complement; both scaled by the mix weight times the density.
            "ShaderNodeVolumeAbsorption" => {
                let density = w * f("Density", 1.0).max(0.0);
                let col = c("Color", [0.8; 3]);
                self.add_extinction(scale(sub([1.0; 3], col), density));
            }
            "ShaderNodeVolumeScatter" => {
                let density = w * f("Density", 1.0).max(0.0);
                let sigma = scale(c("Color", [0.8; 3]), density);
                self.add_scatter(sigma, phase());
                self.add_extinction(sigma);
            }
            // svm_node_volume_coefficients.
            "ShaderNodeVolumeCoefficients" => {
                let scatter = c("Scatter Coefficients", [1.0; 3]);
                if !is_zero(scatter) {
                    self.add_scatter(scale(scatter, w), phase());
                }
                let absorption = c("Absorption Coefficients", [1.0; 3]);
                self.add_extinction(scale(add(scatter, absorption), w));
                let emission = c("Emission Coefficients", [0.0; 3]);
                if !shadow && !is_zero(emission) {
                    self.add_emission(scale(emission, w));
                }
            }
            // svm_node_principled_volume: the density, colour and temperature scaled by
            // their attributes where the point has them (voxel grids; a mesh has none).
            "ShaderNodeVolumePrincipled" => {
                let mut density = w * f("Density", 1.0).max(0.0);
                if density > 0.0 {
                    if let Some(a) = attr("Density Attribute") {
                        density = (density * (a[0] + a[1] + a[2]) / 3.0).max(0.0);
                    }
                }
                if density > 0.0 {
                    let mut color = c("Color", [0.5; 3]);
                    if let Some(a) = attr("Color Attribute") {
                        color = mul(color, [a[0], a[1], a[2]]);
                    }
                    self.add_scatter(
                        scale(color, density),
                        Phase::henyey_greenstein(f("Anisotropy", 0.0)),
                    );
                    let absorption_color =
                        c("Absorption Color", [0.0; 3]).map(|x| x.sqrt().max(0.0));
                    let absorption: V3 = [0, 1, 2]
                        .map(|k| (1.0 - color[k]).max(0.0) * (1.0 - absorption_color[k]).max(0.0));
                    self.add_extinction(scale(add(color, absorption), density));
                }
                if shadow {
                    return;
                }
                let emission = f("Emission Strength", 0.0);
                if emission > 0.0 {
                    self.add_emission(scale(c("Emission Color", [1.0; 3]), emission * w));
                }
                let blackbody = f("Blackbody Intensity", 0.0);
                if blackbody > 0.0 {
                    let mut t = f("Temperature", 1000.0);
                    if let Some(a) = attr("Temperature Attribute") {
                        t *= ((a[0] + a[1] + a[2]) / 3.0).max(0.0);
                    }
                    let t = t.max(0.0);
                    let t4 = (t * t) * (t * t);
                    // Stefan-Boltzmann, in Cycles' units.
                    let sigma = 5.670373e-8 * 1e-6 / std::f32::consts::PI;
                    let intensity = sigma * (1.0 + blackbody * (t4 - 1.0));
                    if intensity > 0.0 {
                        let tint = c("Blackbody Tint", [1.0; 3]);
                        let bb = crate::nodes::blackbody::blackbody_rec709(t);
                        self.add_emission(scale(mul(tint, bb), intensity * w));
                    }
                }
            }
            _ => {}
        }
    }
}

/// What a ray segment inside volumes did to the path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Segment {
    /// The path went through (its throughput attenuated) to what ends the segment.
    Passed,
    /// It scattered: the path's next ray leaves from the scatter point.
    Scattered,
    /// The path ends here.
    Stop,
}

/// Cycles' volume_sample_channel: a colour channel in proportion to throughput times
/// albedo; the channel, the three probabilities, and `u` rescaled for reuse.
fn sample_channel(albedo: V3, throughput: V3, u: &mut f32) -> (usize, V3) {
    let w = mul(throughput, albedo).map(f32::abs);
    let sum = w[0] + w[1] + w[2];
    let pdf = if (1.0 - sum) < 1.0 {
        scale(w, 1.0 / sum)
    } else {
        [1.0 / 3.0; 3]
    };
    let mut acc = 0.0;
    for (k, &p) in pdf.iter().enumerate() {
        if *u < acc + p {
            *u = (*u - acc) / p;
            return (k, pdf);
        }
        acc += p;
    }
    (2, pdf)
}

fn transmittance(sigma_t: V3, t: f32) -> V3 {
    sigma_t.map(|s| (-s * t).exp())
}

impl Scene<'_> {
    /// The volumes a camera ray starting at `org` is inside, as Cycles'
    /// integrator_volume_stack_init finds them: along +Z from the origin, a volume whose
    /// boundary is crossed from the inside before it was entered encloses the origin.
    pub(super) fn volume_stack_init(&self, org: V3, scratch: &mut Scratch) {
        scratch.volume_stack.clear();
        if self.volumes.world.is_some() {
            scratch.volume_stack.push_world();
        }
        if !self.volumes.any || !self.volumes.near_volume(org) {
            return;
        }
        let dir = [0.0, 0.0, 1.0];
        let mut o = org;
        let mut entered = [u32::MAX; 2 * STACK_SIZE];
        let mut n_entered = 0;
        // Surfaces without a volume are stepped over too; the bound only guards
        // against a degenerate mesh.
        for _ in 0..256 {
            scratch.rays += 1;
            let Some(h) = self.accel.intersect_vis(
                o,
                dir,
                0.0,
                f32::INFINITY,
                scratch.time,
                super::accel::visibility::ALL,
            ) else {
                break;
            };
            let hit = self.surface_at(h.prim, h.u, h.v, neg(dir), scratch.time);
            o = offset_origin(hit.p, hit.ng, dir);
            let Some(mi) = hit.material.filter(|&m| self.volumes.has_volume(m)) else {
                continue;
            };
            if !hit.backfacing {
                if n_entered < entered.len() {
                    entered[n_entered] = hit.inst;
                    n_entered += 1;
                }
            } else if !entered[..n_entered].contains(&hit.inst) {
                scratch.volume_stack.enter_exit(hit.inst, mi as u32, false);
            }
        }
    }

    /// The distance along `path`'s ray to the nearest light it can hit before
    /// `t_surface`, slightly past it (so `lights_along` to there gathers it).
    pub(super) fn light_in_segment(&self, path: &Path, t_surface: f32) -> Option<f32> {
        let flags = path.state.flags;
        self.lights
            .iter()
            .filter(|l| l.visible_to(flags) && (l.mis || flags & ray::CAMERA != 0))
            .filter_map(|l| l.intersect(path.o, path.d, t_surface).map(|h| h.t))
            .min_by(f32::total_cmp)
            .map(|t| t * (1.0 + 1e-5) + 1e-7)
            .filter(|&t| t < t_surface)
    }

    /// The path goes on past the light at `t` along its ray, with fresh sampler
    /// dimensions for the rest of the segment.
    pub(super) fn past_light(&self, path: &mut Path, t: f32) {
        path.o = madd(path.o, path.d, t);
        path.t0 = 0.0;
        if path.t1.is_finite() {
            path.t1 -= t;
        }
        path.set += SETS_PER_VERTEX;
        let o = path.o;
        path.passed_through(o);
    }

    /// The volume coefficients of every volume in `stack` at `p` on a ray along `d`
    /// (Cycles' volume_shader_eval: each material's program run at the point; shadow
    /// rays skip emission).
    fn volume_coefficients(
        &self,
        stack: &Stack,
        p: V3,
        d: V3,
        state: PathState,
        scratch: &mut Scratch,
    ) -> Coefficients {
        let mut co = Coefficients::default();
        let shadow = state.flags & ray::SHADOW != 0;
        for &(inst_i, mi) in stack.entries() {
            if inst_i == WORLD {
                if let Some(w) = &self.volumes.world {
                    self.world_volume_closures(w, p, d, state, shadow, &mut co, scratch);
                }
                continue;
            }
            let Some(prog) = self.materials[mi as usize].program.as_ref() else {
                continue;
            };
            let Some(vc) = prog.volume else { continue };
            let inst = &self.geo.instances[inst_i as usize];
            let (to_world, to_object) = inst.pose_at(scratch.time);
            let local = to_object.point(p);
            // Cycles' shader_setup_from_volume: the normals face back along the ray.
            let n = neg(d);
            let camera_position = self.view.camera_space(p);
            let mut sp = ShadingPoint {
                position: p,
                normal: n,
                true_normal: n,
                object_position: local,
                object_normal: normalize(Affine::normal_by_inverse(&to_world, n)),
                incoming: n,
                camera_position,
                camera: self.view.camera(),
                window: self.view.window(camera_position),
                object: inst.info,
                path: state,
                ray_length: 1.0,
                volume_texspace: Some((inst.tex_loc, inst.tex_size)),
                ..Default::default()
            };
            sp.generated = inst.generated(local);
            sp.transform = crate::shader::bump::ObjectTransform {
                to_world: to_world.m,
                to_object: to_object.m,
            };
            let stack = &mut scratch.stacks[mi as usize];
            if stack.len() != prog.initial.len() {
                stack.clear();
                stack.extend_from_slice(&prog.initial);
            }
            match (&inst.grids, self.volumes.grid_bind(inst_i, mi)) {
                (Some(g), Some(bind)) => g.fill(bind, local, self.volumes.cubic(mi), &mut sp),
                // Cycles finds no volume attribute on a mesh.
                _ => sp.attr_missing = !0,
            }
            prog.run(&sp, stack);
            // Cycles' object_volume_density (a Volume object in Object space).
            let w = inst.grids.as_ref().map_or(1.0, |g| g.density_scale);
            co.closure(prog, vc, w, stack, &sp, shadow);
        }
        co
    }

    /// Adds the world volume's closures at `p` on a ray along `d` to `co`: shaded with no
    /// object (Cycles' OBJECT_NONE), every coordinate the world-space point.
    #[allow(clippy::too_many_arguments)]
    fn world_volume_closures(
        &self,
        w: &WorldVolume,
        p: V3,
        d: V3,
        state: PathState,
        shadow: bool,
        co: &mut Coefficients,
        scratch: &mut Scratch,
    ) {
        let prog = &w.program;
        let Some(vc) = prog.volume else { return };
        let n = neg(d);
        let camera_position = self.view.camera_space(p);
        let sp = ShadingPoint {
            position: p,
            normal: n,
            true_normal: n,
            object_position: p,
            object_normal: n,
            generated: p,
            incoming: n,
            camera_position,
            camera: self.view.camera(),
            window: self.view.window(camera_position),
            path: state,
            ray_length: 1.0,
            // A world has no volume attributes.
            attr_missing: !0,
            ..Default::default()
        };
        // The world program's own stack (shared with the world surface: the same program).
        let Some(stack) = scratch.stacks.last_mut() else {
            return;
        };
        if stack.len() != prog.initial.len() {
            stack.clear();
            stack.extend_from_slice(&prog.initial);
        }
        prog.run(&sp, stack);
        co.closure(prog, vc, 1.0, stack, &sp, shadow);
    }

    /// The transmittance of the world volume alone along a shadow ray from `o` along `d`
    /// that escapes the scene (Cycles: up to FLT_MAX); 1 without a world volume.
    pub(super) fn world_escape_transmittance(&self, o: V3, d: V3, scratch: &mut Scratch) -> V3 {
        if self.volumes.world.is_none() {
            return [1.0; 3];
        }
        let mut world = Stack::default();
        world.push_world();
        self.volume_transmittance(o, d, ESCAPE, &world, scratch)
    }

    /// The transmittance of the volumes in `stack` along `dist` of the ray from `o` along
    /// `d` (Cycles' volume_shadow_heterogeneous; a varying medium is sampled at the middle
    /// of each step).
    pub(super) fn volume_transmittance(
        &self,
        o: V3,
        d: V3,
        dist: f32,
        stack: &Stack,
        scratch: &mut Scratch,
    ) -> V3 {
        let state = PathState {
            flags: ray::SHADOW,
            ..PathState::default()
        };
        let step = self.volumes.step_size(stack);
        let (size, steps, shade) = if step.is_finite() {
            let mut size = step.min(dist);
            let max = self.volumes.max_steps;
            if dist > max as f32 * size {
                size = dist / max as f32;
            }
            (size, max, 0.5)
        } else {
            (dist, 1, 0.0)
        };
        let mut sum = [0.0f32; 3];
        let mut t1 = 0.0f32;
        for i in 0..steps {
            if t1 >= dist {
                break;
            }
            let t0 = t1;
            t1 = dist.min((i + 1) as f32 * size);
            let p = madd(o, d, t0 + (t1 - t0) * shade);
            let co = self.volume_coefficients(stack, p, d, state, scratch);
            if co.extinction {
                sum = madd(sum, co.sigma_t, t1 - t0);
                // Stop once every channel is blocked (Cycles: the largest channel of the
                // transmittance below its epsilon); a channel that does not extinguish
                // still passes.
                if sum.iter().all(|&s| s > 50.0) {
                    return [0.0; 3];
                }
            }
        }
        sum.map(|s| (-s).exp())
    }

    /// Cycles' volume_integrate for the ray segment of `path` up to `t_hit` inside the
    /// volumes of `scratch.volume_stack`: emission added, the throughput attenuated, and,
    /// where the path scatters, light sampled at the direct-light scatter point and the
    /// next ray set up from the indirect one (the two are one point under distance
    /// sampling, two under equiangular sampling).
    pub(super) fn volume_segment(
        &self,
        path: &mut Path,
        t_hit: f32,
        rng: &PixelSampler,
        index: u32,
        scratch: &mut Scratch,
    ) -> Segment {
        let stack = scratch.volume_stack;
        let st = &self.settings;
        let r = rng.get4(index, path.set + 2);
        let u_light = rng.get4(index, path.set + 1);
        let (mut rscatter, mut rchannel) = (r[0], r[1]);
        let (tmin, tmax) = (path.t0, t_hit);
        let step = self.volumes.step_size(&stack);
        let (size, max_steps, offset, shade_offset) = if step.is_finite() {
            let t = tmax - tmin;
            let mut size = step.min(t);
            let max = self.volumes.max_steps;
            if t > max as f32 * size {
                size = t / max as f32;
            }
            (size, max, r[3], r[2])
        } else {
            (tmax - tmin, 1, 1.0, 0.0)
        };
        // The segment's length as light selection sees it: an escaping ray's (FLT_MAX in
        // Cycles) is unbounded, which gives suns and the world their ray length of 1
        // (distant_light_tree_parameters: t == FLT_MAX).
        let light_len = if tmax >= ESCAPE {
            f32::INFINITY
        } else {
            tmax - tmin
        };
        // The light is picked before stepping, so that the direct-light scatter point can
        // be drawn toward it; a world or sun light keeps distance sampling.
        let ahead = if path.terminate_next {
            None
        } else {
            self.volume_light_ahead(path, light_len, u_light)
        };
        let equiangular = ahead.and_then(|a| {
            let (t0, t1) = self.lit_range(a.pick, path.o, path.d, tmin, tmax)?;
            Equiangular::new(path.o, path.d, a.toward?, t0, t1)
        });
        let mut method = match equiangular {
            Some(_) => self.volumes.sample_method(&stack),
            None => Method::Distance,
        };
        let use_mis = method == Method::Mis;
        if use_mis {
            // One strategy per sample, each half the time (the factor 2 in the weights).
            if rscatter < 0.5 {
                rscatter *= 2.0;
                method = Method::Distance;
            } else {
                rscatter = (rscatter - 0.5) * 2.0;
                method = Method::Equiangular;
            }
        }
        let (mut direct_t, mut equiangular_pdf) = (0.0f32, 0.0f32);
        if method == Method::Equiangular {
            if let Some(e) = &equiangular {
                (direct_t, equiangular_pdf) = e.sample(rscatter);
            }
        }
        // The pdf of distance sampling reaching where the path is (for the MIS weights).
        let mut distance_pdf = 1.0f32;
        let mut indirect_tp = path.throughput;
        let mut direct_tp = path.throughput;
        let mut indirect: Option<(f32, Phases)> = None;
        let mut direct: Option<(f32, Phases)> = None;
        let mut emission = [0.0f32; 3];
        let mut t1 = tmin;
        let mut stepi = 0u32;
        while t1 < tmax && stepi < max_steps {
            let t0 = t1;
            t1 = tmax.min(tmin + (stepi as f32 + offset) * size);
            stepi += 1;
            let p = madd(path.o, path.d, t0 + (t1 - t0) * shade_offset);
            let co = self.volume_coefficients(&stack, p, path.d, path.state, scratch);
            let dt = t1 - t0;
            let tr = if co.extinction {
                transmittance(co.sigma_t, dt)
            } else {
                [1.0; 3]
            };
            // Emission up to the indirect scatter point only: stepping past it goes on
            // for the direct one alone.
            if co.emit && indirect.is_none() {
                // The emission integrated over the step: E (1 - T) / sigma_t, E dt where
                // nothing absorbs.
                let e: V3 = [0, 1, 2].map(|k| {
                    if co.extinction && co.sigma_t[k] > 0.0 {
                        co.emission[k] * (1.0 - tr[k]) / co.sigma_t[k]
                    } else {
                        co.emission[k] * dt
                    }
                });
                emission = add(emission, mul(indirect_tp, e));
            }
            // Past a bounce limit (Cycles' PATH_RAY_TERMINATE_AFTER_TRANSPARENT) the
            // volume keeps no scattering closures: it only absorbs (its whole extinction)
            // and emits, and the path goes on to what lies beyond, for MIS.
            if co.scatter && !path.terminate_next {
                // Cycles' volume_integrate_step_scattering: the channel by the balance
                // heuristic over channels.
                let albedo: V3 = [0, 1, 2].map(|k| {
                    if co.sigma_t[k] != 0.0 {
                        co.sigma_s[k] / co.sigma_t[k]
                    } else {
                        1.0
                    }
                });
                let (ch, pdf) = sample_channel(albedo, indirect_tp, &mut rchannel);
                if method == Method::Equiangular && direct.is_none() {
                    if t0 <= direct_t && direct_t <= t1 && equiangular_pdf > PDF_CUTOFF {
                        let new_tr = transmittance(co.sigma_t, direct_t - t0);
                        direct_tp = scale(
                            mul(direct_tp, mul(co.sigma_s, new_tr)),
                            1.0 / equiangular_pdf,
                        );
                        if use_mis {
                            let dpdf = distance_pdf * dot(pdf, mul(co.sigma_t, new_tr));
                            let w = super::integrator::power_heuristic(equiangular_pdf, dpdf);
                            direct_tp = scale(direct_tp, 2.0 * w);
                        }
                        direct = Some((direct_t, co.phases));
                    } else {
                        direct_tp = mul(direct_tp, tr);
                        distance_pdf *= dot(pdf, tr);
                    }
                }
                if indirect.is_none() {
                    // Cycles' volume_sample_indirect_scatter.
                    let sample_tr = tr[ch];
                    if 1.0 - rscatter >= sample_tr {
                        let new_dt = -(1.0 - rscatter).ln() / co.sigma_t[ch];
                        let new_tr = transmittance(co.sigma_t, new_dt);
                        let dpdf = dot(pdf, mul(co.sigma_t, new_tr));
                        if distance_pdf * dpdf > PDF_CUTOFF {
                            let t = t0 + new_dt;
                            indirect_tp =
                                scale(mul(indirect_tp, mul(co.sigma_s, new_tr)), 1.0 / dpdf);
                            if method != Method::Equiangular {
                                distance_pdf *= dpdf;
                                // Direct light at the same point.
                                direct_tp = indirect_tp;
                                if use_mis {
                                    let e = equiangular.map_or(0.0, |e| e.pdf(t));
                                    let w = super::integrator::power_heuristic(distance_pdf, e);
                                    direct_tp = scale(direct_tp, 2.0 * w);
                                }
                                direct = Some((t, co.phases));
                            }
                            indirect = Some((t, co.phases));
                        }
                    } else {
                        let dpdf = dot(pdf, tr);
                        indirect_tp = scale(mul(indirect_tp, tr), 1.0 / dpdf);
                        if method != Method::Equiangular {
                            distance_pdf *= dpdf;
                        }
                        rscatter = 1.0 - (1.0 - rscatter) / sample_tr;
                    }
                }
            } else if co.extinction {
                indirect_tp = mul(indirect_tp, tr);
                direct_tp = mul(direct_tp, tr);
            }
            // Cycles' volume_integrate_should_stop.
            if indirect.is_none() {
                if max3(indirect_tp) < THROUGHPUT_EPSILON {
                    indirect_tp = [0.0; 3];
                    break;
                }
            } else if direct.is_none() && max3(direct_tp) < THROUGHPUT_EPSILON {
                break;
            }
            if direct.is_some() && indirect.is_some() {
                break;
            }
        }
        if !is_zero(emission) {
            scratch.features.add_emission(emission);
            let c = super::integrator::clamp_contrib(emission, path.hit_clamp(st));
            if finite(c) {
                path.l = add(path.l, c);
            }
        }
        if direct.is_none() && indirect.is_none() {
            path.throughput = indirect_tp;
            return if is_zero(indirect_tp) {
                Segment::Stop
            } else {
                Segment::Passed
            };
        }
        // Russian roulette on what the path carried into the segment (Cycles' continuation
        // probability), for the direct and the indirect estimate alike.
        let Some(q) = path.continuation(st, u_light[3]) else {
            return Segment::Stop;
        };
        let segment = (path.o, path.d, light_len);
        if let (Some((t, phases)), Some(light)) = (direct, ahead) {
            let p = madd(path.o, path.d, t);
            let tp = scale(direct_tp, 1.0 / q);
            if let Some(c) = self.volume_direct_light(path, tp, p, &phases, u_light, light, scratch)
            {
                path.l = add(path.l, c);
            }
        }
        path.throughput = scale(indirect_tp, 1.0 / q);
        let Some((t, phases)) = indirect else {
            return if is_zero(path.throughput) {
                Segment::Stop
            } else {
                Segment::Passed
            };
        };
        let u_phase = rng.get4(index, path.set);
        let p = madd(path.o, path.d, t);
        let Some((wi, pdf)) = phases.sample(path.d, [u_phase[0], u_phase[1]]) else {
            return Segment::Stop;
        };
        self.volume_bounce(path, p, wi, pdf, segment, scratch);
        Segment::Scattered
    }

    /// The part of the ray `o + t d`, t in [`tmin`, `tmax`], on the side light `pick`
    /// emits to (Cycles' volume_equiangular_valid_ray_segment, less its narrowing to a
    /// spot's cone or an area light's spread): the whole range for points and spots, in
    /// front of an area light, on the sampled side of a one-sided emissive triangle. None
    /// when nothing of it is lit (distance sampling then).
    fn lit_range(&self, pick: Pick, o: V3, d: V3, tmin: f32, tmax: f32) -> Option<(f32, f32)> {
        let (on_plane, n) = match pick {
            Pick::Lamp(li) => {
                let light = &self.lights[li as usize];
                match light.shape {
                    super::light::Shape::Area { .. } => (light.pos.into(), light.dir.into()),
                    _ => return Some((tmin, tmax)),
                }
            }
            Pick::Triangle(tri) => {
                let v = &self.geo.tris[tri as usize];
                let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
                match self.emission_sides(tri) {
                    (true, false) => (v[0], n),
                    (false, true) => (v[0], neg(n)),
                    _ => return Some((tmin, tmax)),
                }
            }
            Pick::World => return Some((tmin, tmax)),
        };
        // Cycles' ray_plane_intersect: keep the part on the side `n` points to.
        let dn = dot(d, n);
        let t = -dot(sub(o, on_plane), n) / dn;
        let (mut t0, mut t1) = (tmin, tmax);
        if dn > 0.0 {
            t0 = t0.max(t);
        } else {
            t1 = t1.min(t);
        }
        (t0 < t1).then_some((t0, t1))
    }

    /// The light a segment's direct light comes from (Cycles'
    /// integrate_volume_equiangular_sample_light): picked for the segment of length `t`
    /// (Cycles' in_volume_segment light selection), with a point on it from the same
    /// random numbers the light sample at the scatter point will use. None when it cannot
    /// light a volume scatter.
    fn volume_light_ahead(&self, path: &Path, t: f32, u: [f32; 4]) -> Option<AheadLight> {
        let o = path.o;
        let (pick, p_sel) = self
            .light_select
            .select_for(Viewer::Segment { p: o, d: path.d, t }, u[2])?;
        let toward = match pick {
            Pick::Lamp(li) => {
                let light = &self.lights[li as usize];
                if light.exclude & ray::VOLUME_SCATTER != 0 {
                    return None;
                }
                match light.shape {
                    super::light::Shape::Sun { .. } => None,
                    // Any point that does not depend on the scatter point will do; the
                    // sampled one where the light can be sampled from the start.
                    _ => Some(
                        light
                            .sample(o, [u[0], u[1]])
                            .filter(|ls| ls.dist.is_finite())
                            .map_or(light.pos.into(), |ls| madd(o, ls.wi, ls.dist)),
                    ),
                }
            }
            Pick::Triangle(tri) => {
                let r = self.geo.refs[tri as usize];
                if self.geo.instances[r.inst as usize].visibility & ray::VOLUME_SCATTER == 0 {
                    return None;
                }
                let v = &self.geo.tris[tri as usize];
                let (front, back) = self.emission_sides(tri);
                Some(
                    super::light::triangle::sample(v, o, [u[0], u[1]], front, back)
                        .map_or(scale(add(add(v[0], v[1]), v[2]), 1.0 / 3.0), |ts| {
                            madd(o, ts.wi, ts.dist)
                        }),
                )
            }
            Pick::World => {
                if self.world_exclude & ray::VOLUME_SCATTER != 0 {
                    return None;
                }
                None
            }
        };
        Some(AheadLight {
            pick,
            p_sel,
            toward,
        })
    }

    /// Cycles' path_state_next after a volume scatter, and the next ray from `p` along
    /// `wi` (phase-sampled with `pdf`; its weight is 1).
    fn volume_bounce(
        &self,
        path: &mut Path,
        p: V3,
        wi: V3,
        pdf: f32,
        segment: (V3, V3, f32),
        scratch: &mut Scratch,
    ) {
        let st = &self.settings;
        if path.state.bounce >= st.max_bounces {
            path.terminate_next = true;
        }
        path.state.bounce += 1;
        if scratch.volume_bounce >= self.volumes.max_bounces {
            path.terminate_next = true;
        }
        scratch.volume_bounce += 1;
        path.state.flags = ray::VOLUME_SCATTER;
        path.transparent_bg = false;
        // Light selection for the segment saw no normal and both sides, at its start.
        path.mis_n = [0.0; 3];
        path.mis_trans = true;
        path.mis_segment = Some(segment);
        path.prev_pdf = pdf;
        path.prev_singular = false;
        path.min_ray_pdf = path.min_ray_pdf.min(pdf);
        path.o = p;
        path.d = wi;
        path.t0 = 0.0;
        path.t1 = f32::INFINITY;
        path.new_origin();
        path.set += SETS_PER_VERTEX;
    }

    /// Next-event estimation at a volume scatter point `p` with path throughput
    /// `throughput`: the segment's light sampled again from `p`, weighted by the phase
    /// functions, MIS against phase sampling for emitters shared with it, the shadow ray
    /// attenuated by the volumes.
    #[allow(clippy::too_many_arguments)]
    fn volume_direct_light(
        &self,
        path: &Path,
        throughput: V3,
        p: V3,
        phases: &Phases,
        u: [f32; 4],
        light: AheadLight,
        scratch: &mut Scratch,
    ) -> Option<V3> {
        let clamp = path.light_clamp(&self.settings);
        let d = path.d;
        let bounce = path.state.bounce;
        let stack = scratch.volume_stack;
        let c = match (light.pick, light.p_sel) {
            (Pick::Lamp(li), p_sel) => {
                let light = &self.lights[li as usize];
                if bounce > light.max_bounces || light.exclude & ray::VOLUME_SCATTER != 0 {
                    return None;
                }
                let ls = light.sample(p, [u[0], u[1]])?;
                let (f, pdf) = phases.eval(d, ls.wi);
                let w = if light.mis {
                    super::integrator::power_heuristic(ls.pdf * p_sel, pdf)
                } else {
                    1.0
                };
                let c = scale(mul(throughput, ls.value), f * w / p_sel);
                if is_zero(c) || !finite(c) {
                    return None;
                }
                let tr = if light.cast_shadow {
                    let dist = if ls.dist.is_finite() {
                        ls.dist * (1.0 - 1e-4)
                    } else {
                        f32::INFINITY
                    };
                    self.shadow_transmittance(p, ls.wi, dist, stack, scratch)
                } else {
                    [1.0; 3]
                };
                mul(c, tr)
            }
            (Pick::Triangle(tri), p_sel) => {
                let r = self.geo.refs[tri as usize];
                if self.geo.instances[r.inst as usize].visibility & ray::VOLUME_SCATTER == 0 {
                    return None;
                }
                let (front, back) = self.emission_sides(tri);
                let ts = super::light::triangle::sample(
                    &self.geo.tris[tri as usize],
                    p,
                    [u[0], u[1]],
                    front,
                    back,
                )?;
                let (f, pdf_b) = phases.eval(d, ts.wi);
                if f <= 0.0 {
                    return None;
                }
                let pdf_l = p_sel * ts.pdf;
                let tr =
                    self.shadow_transmittance(p, ts.wi, ts.dist * (1.0 - 1e-4), stack, scratch);
                if is_zero(tr) {
                    return None;
                }
                let le =
                    self.light_emission(tri, ts.b1, ts.b2, neg(ts.wi), ts.dist, bounce, scratch);
                let w = super::integrator::power_heuristic(pdf_l, pdf_b);
                mul(scale(mul(throughput, le), f * w / pdf_l), tr)
            }
            (Pick::World, p_sel) => {
                if self.world_exclude & ray::VOLUME_SCATTER != 0 {
                    return None;
                }
                let map = self.world.and_then(|w| w.map.as_ref())?;
                let (wi, pdf_l) = map.sample([u[0], u[1]])?;
                let pdf_l = pdf_l * p_sel;
                let (f, pdf_b) = phases.eval(d, wi);
                if f <= 0.0 || pdf_l.is_nan() || pdf_l <= 0.0 {
                    return None;
                }
                let tr = self.shadow_transmittance(p, wi, f32::INFINITY, stack, scratch);
                if is_zero(tr) {
                    return None;
                }
                // The Emission flag alone and the path's bounces, as for a surface.
                let state = crate::shader::point::PathState {
                    flags: 0,
                    ..path.state
                };
                let le = self.background_toward(wi, state, scratch);
                let w = super::integrator::power_heuristic(pdf_l, pdf_b);
                mul(scale(mul(throughput, le), f * w / pdf_l), tr)
            }
        };
        (finite(c) && !is_zero(c)).then(|| super::integrator::clamp_contrib(c, clamp))
    }

    /// The volume stack a shadow ray from surface `hit` toward `wi` starts with: the
    /// path's, with the surface's volume entered or left when the ray goes through it
    /// (Cycles' shadow_volume_stack_enter_exit for transmission).
    pub(super) fn shadow_stack(&self, hit: &SurfaceHit, wi: V3, scratch: &Scratch) -> Stack {
        let mut s = scratch.volume_stack;
        if let Some(mi) = hit.material {
            if dot(wi, hit.ng) < 0.0 && self.volumes.has_volume(mi) {
                s.enter_exit(hit.inst, mi as u32, hit.backfacing);
            }
        }
        s
    }

    /// At a surface of the path: a material with a volume and no surface is passed
    /// through without a bounce (Cycles' integrate_surface_volume_only_bounce), even past
    /// a bounce limit; true when it was (the path's next ray is set up).
    pub(super) fn volume_boundary(
        &self,
        path: &mut Path,
        hit: &SurfaceHit,
        scratch: &mut Scratch,
    ) -> bool {
        let Some(mi) = hit.material else {
            return false;
        };
        if !self.volumes.only_volume(mi) {
            return false;
        }
        scratch
            .volume_stack
            .enter_exit(hit.inst, mi as u32, hit.backfacing);
        path.o = offset_origin(hit.p, hit.ng, path.d);
        path.t0 = 0.0;
        path.t1 = f32::INFINITY;
        path.passed_through(hit.p);
        // Fresh dimensions for what lies beyond: the segment's own were drawn from
        // this set's spare one.
        path.set += SETS_PER_VERTEX;
        true
    }

    /// After the path transmitted through `hit` (refraction or transparency): its
    /// volume entered or left.
    pub(super) fn volume_cross(&self, hit: &SurfaceHit, scratch: &mut Scratch) {
        if let Some(mi) = hit.material.filter(|&m| self.volumes.has_volume(m)) {
            scratch
                .volume_stack
                .enter_exit(hit.inst, mi as u32, hit.backfacing);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stack_enters_once_and_leaves_by_the_back() {
        let mut s = Stack::default();
        s.enter_exit(3, 1, false);
        s.enter_exit(3, 1, false);
        s.enter_exit(5, 2, false);
        assert_eq!(s.entries(), &[(3, 1), (5, 2)]);
        s.enter_exit(3, 1, true);
        assert_eq!(s.entries(), &[(5, 2)]);
        // Leaving a volume never entered changes nothing.
        s.enter_exit(9, 9, true);
        assert_eq!(s.entries(), &[(5, 2)]);
        for i in 0..20 {
            s.enter_exit(100 + i, 0, false);
        }
        assert_eq!(s.entries().len(), STACK_SIZE - 1);
    }

    /// Each phase function integrates to 1 over the sphere, and sampling draws
    /// directions with the pdf it reports (a histogram of cosines against the pdf).
    #[test]
    fn phase_functions_are_normalised_and_sampled_by_their_pdf() {
        let d = normalize([0.3, -0.2, 0.9]);
        for ph in [
            Phase::henyey_greenstein(0.0),
            Phase::henyey_greenstein(0.6),
            Phase::henyey_greenstein(-0.8),
            Phase::Rayleigh,
        ] {
            // Integral over cos in [-1, 1] times 2 pi.
            let n = 20000;
            let (t, _) = basis(d);
            let mut sum = 0.0f64;
            for i in 0..n {
                let c = -1.0 + (i as f32 + 0.5) * 2.0 / n as f32;
                let s = (1.0 - c * c).sqrt();
                let wi = add(scale(d, c), scale(t, s));
                sum += ph.eval(d, wi) as f64 * 2.0 / n as f64;
            }
            let integral = sum * 2.0 * std::f64::consts::PI;
            assert!((integral - 1.0).abs() < 1e-3, "{ph:?}: {integral}");
            // Histogram of sampled cosines in 8 bins against the pdf's mass per bin.
            let bins = 8;
            let mut hist = vec![0usize; bins];
            // A stratified first dimension (the cosine), a golden-ratio second.
            let m = 8192;
            for i in 0..m {
                let u = [(i as f32 + 0.5) / m as f32, (i as f32 * 0.618_034).fract()];
                let (wi, pdf) = ph.sample(d, u);
                assert!((pdf - ph.eval(d, wi)).abs() <= 1e-4 * pdf.max(1.0));
                let c = dot(d, wi).clamp(-1.0, 0.999_999);
                hist[((c + 1.0) * 0.5 * bins as f32) as usize] += 1;
            }
            for (b, &h) in hist.iter().enumerate() {
                let k = 200;
                let mut mass = 0.0f64;
                for i in 0..k {
                    let c = -1.0 + (b as f32 + (i as f32 + 0.5) / k as f32) * 2.0 / bins as f32;
                    let s = (1.0 - c * c).sqrt();
                    let wi = add(scale(d, c), scale(t, s));
                    mass += ph.eval(d, wi) as f64 * (2.0 / bins as f64) / k as f64;
                }
                mass *= 2.0 * std::f64::consts::PI;
                let got = h as f64 / m as f64;
                assert!((got - mass).abs() < 0.01, "{ph:?} bin {b}: {got} vs {mass}");
            }
        }
    }

    #[test]
    fn channel_sampling_follows_throughput_times_albedo() {
        let mut u = 0.7;
        let (ch, pdf) = sample_channel([1.0, 1.0, 1.0], [1.0, 1.0, 2.0], &mut u);
        assert_eq!(pdf, [0.25, 0.25, 0.5]);
        assert_eq!(ch, 2);
        assert!((u - 0.4).abs() < 1e-6);
        let mut u = 0.1;
        let (_, pdf) = sample_channel([0.0; 3], [1.0; 3], &mut u);
        assert_eq!(pdf, [1.0 / 3.0; 3]);
    }
}
