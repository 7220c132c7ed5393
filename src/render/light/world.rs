//! The world background: a Background node's colour times strength feeding the World
//! Output (constant), the world's viewport colour without nodes, or, for any other
//! world node graph (environment images, gradients by direction), the compiled world
//! program run per escaping ray (`WorldShader`).

use serde_json::Value;

use crate::nodes::sky::SunGuide;
use crate::render::math::{Vec3, V3};
use crate::render::RenderError;
use crate::scene::Scene;
use crate::shader::point::PathState;

pub fn background(scene: &Scene) -> Result<V3, RenderError> {
    let Some(name) = scene.file.scene.world.as_deref() else {
        return Ok([0.0; 3]);
    };
    let Some(w) = scene.file.worlds.iter().find(|w| w.name == name) else {
        return Ok([0.0; 3]);
    };
    let tree = match (&w.node_tree, w.use_nodes) {
        (Some(t), true) => t,
        _ => return Ok(w.color.map(|c| c.map(|x| x as f32)).unwrap_or([0.05; 3])),
    };
    if !is_constant(tree) {
        // Varies with direction: `shader` evaluates it per ray.
        return Ok([0.0; 3]);
    }
    // The output the world's program is compiled from (shader::compile), so the two agree.
    let out = crate::nodes::graph::active_output(tree, "ShaderNodeOutputWorld", "CYCLES");
    let Some(out) = out else { return Ok([0.0; 3]) };
    let Some(link) = tree
        .links
        .iter()
        .find(|l| l.to_node == out.name && l.to_socket == "Surface" && !l.is_muted)
    else {
        return Ok([0.0; 3]);
    };
    let node = tree
        .nodes
        .iter()
        .find(|n| n.name == link.from_node)
        .ok_or_else(|| {
            RenderError(format!(
                "world {name:?}: link from missing node {:?}",
                link.from_node
            ))
        })?;
    if node.bl_idname != "ShaderNodeBackground" && node.bl_idname != "ShaderNodeEmission" {
        return Err(RenderError(format!(
            "world {name:?}: node {:?} ({}) is not supported as the world surface yet",
            node.name, node.bl_idname
        )));
    }
    let input = |id: &str| -> Result<Option<&Value>, RenderError> {
        if tree
            .links
            .iter()
            .any(|l| l.to_node == node.name && l.to_socket == id && !l.is_muted)
        {
            return Err(RenderError(format!("world {name:?}: a linked {id:?} on {:?} is not supported yet (constant backgrounds only)", node.name)));
        }
        Ok(node
            .inputs
            .iter()
            .find(|s| s.identifier == id)
            .and_then(|s| s.default_value.as_ref()))
    };
    let color = input("Color")?
        .and_then(Value::as_array)
        .map(|a| [0, 1, 2].map(|i| a.get(i).and_then(Value::as_f64).unwrap_or(0.0) as f32))
        .unwrap_or([0.8; 3]);
    let strength = input("Strength")?.and_then(Value::as_f64).unwrap_or(1.0) as f32;
    Ok(color.map(|c| c * strength))
}

/// The ray types the scene's world is hidden from (World > Settings > Ray Visibility,
/// exported as `cycles_visibility`), as `ray::` flags.
pub fn excluded_rays(scene: &Scene) -> u32 {
    use crate::shader::point::ray;
    let Some(name) = scene.file.scene.world.as_deref() else {
        return 0;
    };
    let Some(w) = scene.file.worlds.iter().find(|w| w.name == name) else {
        return 0;
    };
    let seen = crate::scene::settings::WorldSettings::of(w).visible_to;
    let mut x = 0;
    for (visible, flag) in seen.into_iter().zip([
        ray::CAMERA,
        ray::DIFFUSE,
        ray::GLOSSY,
        ray::TRANSMIT,
        ray::VOLUME_SCATTER,
    ]) {
        if !visible {
            x |= flag;
        }
    }
    x
}

/// A world whose surface varies with direction (an Environment Texture, a Texture
/// Coordinate, any linked Background input): its compiled node program, run per ray
/// that leaves the scene.
pub struct WorldShader {
    pub program: crate::shader::Program,
    /// Importance map for light sampling toward the world (None: black world).
    pub map: Option<WorldMap>,
}

impl WorldShader {
    /// Radiance arriving along `-d` from the world (`d`: the ray's unit direction), as
    /// Cycles shades the background with the ray direction as position, for a ray in
    /// `path` (its flags must include Emission, as Cycles adds it).
    pub fn eval(&self, d: V3, path: PathState, stack: &mut Vec<f32>) -> V3 {
        let p = &self.program;
        if stack.len() != p.initial.len() {
            stack.clear();
            stack.extend_from_slice(&p.initial);
        }
        p.run(&crate::shader::compile::world_point(d, path), stack);
        p.surface_emission(stack)
    }
}

/// The scene world and its node tree, when it has one in use (Use Nodes on).
pub(crate) fn node_tree(scene: &Scene) -> Option<(&crate::scene::World, &crate::scene::NodeTree)> {
    let name = scene.file.scene.world.as_deref()?;
    let w = scene.file.worlds.iter().find(|w| w.name == name)?;
    match (&w.node_tree, w.use_nodes) {
        (Some(t), true) => Some((w, t)),
        _ => None,
    }
}

/// The scene world's shader when it is not a constant colour (None: `background`
/// gives its constant radiance).
pub fn shader(scene: &Scene) -> Result<Option<WorldShader>, RenderError> {
    let Some((w, tree)) = node_tree(scene) else {
        return Ok(None);
    };
    let name = w.name.as_str();
    // A constant surface needs no program; the world's Volume is compiled and checked by
    // render/volume_world.rs.
    if is_constant(tree) {
        return Ok(None);
    }
    let program = crate::shader::compile::compile_world(scene, name)
        .map_err(|e| RenderError(e.to_string()))?;
    let mut shader = WorldShader { program, map: None };
    // World > Settings > Surface > Sampling "None": Cycles does not light-sample the world
    // (its background light is off); BSDF rays alone find it.
    let sampled = crate::scene::settings::WorldSettings::of(w).sampled;
    if sampled {
        shader.map = WorldMap::build(&shader, MAP_WIDTH, MAP_WIDTH / 2).map(|mut m| {
            if let Some(sun) = shader.program.sun_guide() {
                m.guide_sun(sun);
            }
            m
        });
    }
    Ok(Some(shader))
}

/// Columns of the world importance map (rows: half as many).
const MAP_WIDTH: usize = 512;

/// True when the world output is fed by a Background or Emission node with unlinked
/// inputs (or by nothing): `background` handles that without a program.
fn is_constant(tree: &crate::scene::NodeTree) -> bool {
    // The output the world's program is compiled from (shader::compile), so the two agree.
    let out = crate::nodes::graph::active_output(tree, "ShaderNodeOutputWorld", "CYCLES");
    let Some(out) = out else { return true };
    // AOV Outputs run with the world's program (the camera rays' AOV passes).
    if tree
        .nodes
        .iter()
        .any(|n| !n.mute && n.bl_idname == "ShaderNodeOutputAOV")
    {
        return false;
    }
    let Some(link) = tree
        .links
        .iter()
        .find(|l| l.to_node == out.name && l.to_socket == "Surface" && !l.is_muted)
    else {
        return true;
    };
    let Some(node) = tree.nodes.iter().find(|n| n.name == link.from_node) else {
        return true;
    };
    (node.bl_idname == "ShaderNodeBackground" || node.bl_idname == "ShaderNodeEmission")
        && !node.mute
        && !tree
            .links
            .iter()
            .any(|l| l.to_node == node.name && !l.is_muted)
}

/// Importance sampling of a world that varies with direction: a piecewise-constant
/// distribution over the equirectangular square, each cell weighted by the mean of the
/// world's channels at its centre times the cell's solid angle (sin theta), as Cycles builds
/// its background map. The pdf is exact for the distribution it samples, so any map
/// gives unbiased results; a better map only lowers noise.
pub struct WorldMap {
    w: usize,
    h: usize,
    /// Per row: the cumulative distribution over its columns (w + 1 entries).
    rows: Vec<f32>,
    /// Cumulative distribution over rows (h + 1 entries).
    marginal: Vec<f32>,
    /// Cell weights, normalised so that the mean is 1 (pdf over the unit square).
    pdf: Vec<f32>,
    /// Cycles' average radiance of the map (its light tree energy of the world): the
    /// mean over cells of the channels' mean times sin theta, times pi / 2 (with a sun
    /// guided, 0.8 of that plus 0.2 of the sun's).
    pub average_radiance: f32,
    /// A Nishita sun disc sampled directly (Cycles' sun guiding), with its share of the
    /// samples.
    sun: Option<(SunGuide, f32)>,
}

/// Cycles' sun and map method weights (`sun_weight` 4, `map_weight` 1: empirical).
const SUN_WEIGHT: f32 = 4.0;
const MAP_WEIGHT: f32 = 1.0;

fn equirect_direction(u: f32, v: f32) -> (V3, f32) {
    use std::f32::consts::PI;
    let phi = -2.0 * PI * u + PI;
    let theta = -PI * v + PI;
    let st = theta.sin();
    ([st * phi.cos(), st * phi.sin(), theta.cos()], st)
}

/// Index of the bucket of `cdf` (ascending, 0..1) holding `x`, and the position in it.
fn pick(cdf: &[f32], x: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let i = cdf
        .partition_point(|&c| c <= x)
        .saturating_sub(1)
        .min(n - 1);
    let width = cdf[i + 1] - cdf[i];
    let t = if width > 0.0 {
        ((x - cdf[i]) / width).clamp(0.0, 1.0)
    } else {
        0.5
    };
    (i, t)
}

impl WorldMap {
    /// Builds the map by running the world program at every cell centre. None when the
    /// world is black everywhere (nothing to sample).
    pub fn build(shader: &WorldShader, w: usize, h: usize) -> Option<WorldMap> {
        let mut stack = Vec::new();
        let mut f = vec![0.0f64; w * h];
        let mut radiance = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                let (d, st) =
                    equirect_direction((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                // Cycles bakes its map with the Emission flag alone (shader_eval_background).
                let c = shader.eval(d, PathState::EMISSION, &mut stack);
                // Cycles weighs each cell by the mean of its channels' magnitudes
                // (background_cdf's `average(fabs(color))`), not by luminance.
                let mean = (c[0].abs() + c[1].abs() + c[2].abs()) / 3.0;
                if mean.is_finite() {
                    radiance += mean as f64 * st as f64;
                }
                f[j * w + i] = if mean.is_finite() && mean > 0.0 {
                    mean as f64 * st as f64
                } else {
                    0.0
                };
            }
        }
        let total: f64 = f.iter().sum();
        if !total.is_finite() || total <= 0.0 {
            return None;
        }
        let mut rows = Vec::with_capacity(h * (w + 1));
        let mut marginal = Vec::with_capacity(h + 1);
        marginal.push(0.0f32);
        let mut acc_rows = 0.0f64;
        for j in 0..h {
            let row = &f[j * w..(j + 1) * w];
            let sum: f64 = row.iter().sum();
            let mut acc = 0.0f64;
            rows.push(0.0f32);
            for &x in row {
                acc += x;
                rows.push(if sum > 0.0 { (acc / sum) as f32 } else { 0.0 });
            }
            acc_rows += sum;
            marginal.push((acc_rows / total) as f32);
        }
        let n = (w * h) as f64;
        let pdf = f.iter().map(|&x| (x * n / total) as f32).collect();
        let average_radiance = (radiance / n * std::f64::consts::FRAC_PI_2) as f32;
        Some(WorldMap {
            w,
            h,
            rows,
            marginal,
            pdf,
            average_radiance,
            sun: None,
        })
    }

    /// Samples the sun disc directly too, as Cycles does for one Nishita sun: a share
    /// 4 / 5 of the samples goes uniformly into its cone, the rest to the map, and every
    /// direction's pdf is the mixture of both.
    pub fn guide_sun(&mut self, sun: SunGuide) {
        let share = SUN_WEIGHT / (SUN_WEIGHT + MAP_WEIGHT);
        self.average_radiance = 0.8 * self.average_radiance + 0.2 * sun.average_radiance;
        self.sun = Some((sun, share));
    }

    /// The pdf of the sun cone toward `d` (Cycles' pdf_uniform_cone).
    fn sun_pdf(sun: &SunGuide, d: V3) -> f32 {
        let (d, axis) = (Vec3::from(d), Vec3::from(sun.direction));
        let angle = 2.0 * (d - axis).length().atan2((d + axis).length());
        if angle < sun.half_angle {
            1.0 / (2.0
                * std::f32::consts::PI
                * crate::render::light::sun_one_minus_cos(sun.half_angle))
        } else {
            0.0
        }
    }

    /// A direction drawn from the map (and the sun, when guided) and its solid-angle
    /// pdf over both methods.
    pub fn sample(&self, u: [f32; 2]) -> Option<(V3, f32)> {
        let Some((sun, share)) = self.sun else {
            return self.sample_map(u);
        };
        if u[0] < share {
            let omc = crate::render::light::sun_one_minus_cos(sun.half_angle);
            let axis = Vec3::from(sun.direction);
            let (d, _) = crate::render::light::sample_cone(axis, omc, [u[0] / share, u[1]]);
            let d = d.normalize().into();
            // The cone's own pdf, as Cycles takes it for the direction it sampled (an
            // angle test at the cone's rim could drop it).
            let cone = 1.0 / (2.0 * std::f32::consts::PI * omc);
            return Some((d, share * cone + (1.0 - share) * self.map_pdf(d)));
        }
        let (d, p) = self.sample_map([(u[0] - share) / (1.0 - share), u[1]])?;
        Some((d, (1.0 - share) * p + share * Self::sun_pdf(&sun, d)))
    }

    /// The solid-angle pdf with which `sample` draws direction `d` (unit).
    pub fn pdf(&self, d: V3) -> f32 {
        match self.sun {
            Some((sun, share)) => share * Self::sun_pdf(&sun, d) + (1.0 - share) * self.map_pdf(d),
            None => self.map_pdf(d),
        }
    }

    /// A direction drawn from the map alone and its solid-angle pdf.
    fn sample_map(&self, u: [f32; 2]) -> Option<(V3, f32)> {
        let (j, tv) = pick(&self.marginal, u[0]);
        let row = &self.rows[j * (self.w + 1)..(j + 1) * (self.w + 1)];
        let (i, tu) = pick(row, u[1]);
        let p = self.pdf[j * self.w + i];
        if p <= 0.0 {
            return None;
        }
        let (d, st) = equirect_direction(
            (i as f32 + tu) / self.w as f32,
            (j as f32 + tv) / self.h as f32,
        );
        if st <= 0.0 {
            return None;
        }
        Some((
            d,
            p / (2.0 * std::f32::consts::PI * std::f32::consts::PI * st),
        ))
    }

    /// The solid-angle pdf with which `sample_map` draws direction `d` (unit).
    fn map_pdf(&self, d: V3) -> f32 {
        let uv = crate::nodes::image::direction_to_equirectangular(d);
        let u = uv[0] - uv[0].floor();
        let i = ((u * self.w as f32) as usize).min(self.w - 1);
        let j = ((uv[1].clamp(0.0, 1.0) * self.h as f32) as usize).min(self.h - 1);
        let st = (1.0 - d[2] * d[2]).max(0.0).sqrt();
        if st <= 0.0 {
            return 0.0;
        }
        self.pdf[j * self.w + i] / (2.0 * std::f32::consts::PI * std::f32::consts::PI * st)
    }
}
