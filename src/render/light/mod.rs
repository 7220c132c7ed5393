//! Light objects with Cycles' units: point and spot (W; sphere of `shadow_soft_size`
//! radius, radiance = power / (4 pi^2 r^2)), area (W; one-sided square, rectangle, disk
//! or ellipse, radiance = power / (pi A), with Spread; sampled as `area_light` says),
//! sun (W/m^2; cone of `angle`).
//! Sampling returns direction, distance and the contribution divided by the pdf.

pub mod area;
pub mod shader;
pub mod tree;
pub mod triangle;
pub mod world;

use serde_json::Value;
use std::f32::consts::PI;

use crate::anim::EvaluatedScene;
use crate::render::light::area::{rect_solid_angle, Region, Spread};
use crate::render::math::{vec3, Affine, Vec3, V3};
use crate::render::RenderError;
use crate::scene::settings::{AreaShape, LightSettings};
use crate::scene::Scene;
use crate::shader::compile::compile_light;
use crate::shader::view::object_info;
use shader::LightShader;
use std::sync::Arc;

#[derive(Debug, Clone)]
pub enum Shape {
    /// `sphere`: Cycles' sphere light (Soft Falloff off); otherwise a disk of the radius
    /// facing the shading point (Soft Falloff on, Blender's default).
    Point {
        radius: f32,
        spot: Option<Spot>,
        sphere: bool,
    },
    /// `u`, `v`: the light's full extent along its axes; `spread`: None at 180 degrees.
    Area {
        u: Vec3,
        v: Vec3,
        ellipse: bool,
        area: f32,
        spread: Option<Spread>,
    },
    Sun {
        half_angle: f32,
    },
}

#[derive(Debug, Clone, Copy)]
pub struct Spot {
    pub cos_half: f32,
    pub smooth: f32,
    /// Axes scaled as Cycles does, for non-uniformly scaled spot cones.
    pub u: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

#[derive(Debug, Clone)]
pub struct Light {
    pub shape: Shape,
    pub strength: Vec3,
    pub pos: Vec3,
    /// Emission direction (-Z of the object), unit.
    pub dir: Vec3,
    pub cast_shadow: bool,
    /// Cycles' SHADER_USE_MIS: light and BSDF sampling share the light (Multiple
    /// Importance on, and a light with extent); otherwise only light sampling and camera
    /// rays see it.
    pub mis: bool,
    /// Cycles' per-light Max Bounces: light sampling skips the light at vertices past
    /// this many bounces (light_select_reached_max_bounces).
    pub max_bounces: u32,
    /// Ray types that do not see the light (`ray::` flags: CAMERA, DIFFUSE, GLOSSY,
    /// TRANSMIT, VOLUME_SCATTER), from the object's ray visibility.
    pub exclude: u32,
    /// Cycles' light tree energy of the light: |mean of its strength| (power times colour,
    /// before Normalize) times its eval_fac scale (1/4 for area lights, 1/(4 pi) for
    /// points and spots, 1 for suns).
    pub tree_energy: f32,
    /// Area lights' Spread (radians; pi when not set).
    pub spread: f32,
    /// A node tree that varies, evaluated at every sample (a constant one is folded into
    /// `strength`).
    pub shader: Option<std::sync::Arc<shader::LightShader>>,
}

impl Light {
    /// Cycles' is_light_shader_visible_to_path for a ray with these path flags.
    #[inline]
    pub fn visible_to(&self, flags: u32) -> bool {
        visible_to(self.exclude, flags)
    }
}

/// Whether an emitter hidden from the ray types `x` (`ray::` flags) is seen by a ray with
/// path flags `flags` (Cycles' is_light_shader_visible_to_path; lights and the world).
#[inline]
pub fn visible_to(x: u32, flags: u32) -> bool {
    use crate::shader::point::ray;
    !((x & ray::DIFFUSE != 0 && flags & ray::DIFFUSE != 0)
        || (x & ray::GLOSSY != 0
            && flags & (ray::GLOSSY | ray::REFLECT) == ray::GLOSSY | ray::REFLECT)
        || (x & ray::TRANSMIT != 0 && flags & ray::TRANSMIT != 0)
        || (x & ray::CAMERA != 0 && flags & ray::CAMERA != 0)
        || (x & ray::VOLUME_SCATTER != 0 && flags & ray::VOLUME_SCATTER != 0))
}

/// The ray types an object's ray visibility hides it from, as `ray::` flags; without the
/// setting in the export, Blender 4.5's default for a light (hidden from the camera).
pub fn excluded_rays(v: Option<&crate::scene::format::RayVisibility>) -> u32 {
    use crate::shader::point::ray;
    let Some(v) = v else { return ray::CAMERA };
    let mut x = 0;
    for (on, flag) in [
        (v.camera, ray::CAMERA),
        (v.diffuse, ray::DIFFUSE),
        (v.glossy, ray::GLOSSY),
        (v.transmission, ray::TRANSMIT),
        (v.volume_scatter, ray::VOLUME_SCATTER),
    ] {
        if !on {
            x |= flag;
        }
    }
    x
}

pub struct LightSample {
    pub wi: V3,
    pub dist: f32,
    /// Radiance times cosine at the light over pdf, before the BSDF.
    pub value: V3,
    /// Solid-angle pdf of the sample (infinite for delta lights: no MIS).
    pub pdf: f32,
}

/// A light found by a BSDF ray: distance, radiance, and the pdf with which light
/// sampling would have chosen that direction.
pub struct LightHit {
    pub t: f32,
    pub radiance: V3,
    pub pdf: f32,
}

/// Shader nodes whose closures never emit, whatever their inputs.
const NON_EMITTING_CLOSURES: &[&str] = &[
    "ShaderNodeBsdfDiffuse",
    "ShaderNodeBsdfGlossy",
    "ShaderNodeBsdfAnisotropic",
    "ShaderNodeBsdfGlass",
    "ShaderNodeBsdfRefraction",
    "ShaderNodeBsdfTranslucent",
    "ShaderNodeBsdfTransparent",
    "ShaderNodeBsdfSheen",
    "ShaderNodeBsdfToon",
    "ShaderNodeBsdfHair",
    "ShaderNodeBsdfHairPrincipled",
    "ShaderNodeSubsurfaceScattering",
];

/// The factor a light's node tree puts on its colour and power when the tree reduces to a
/// constant (an Emission node with unlinked inputs into the active Light Output, or
/// nothing that emits): Cycles multiplies the light's strength by the emission its shader
/// evaluates to. None: the tree varies, and is evaluated per sample (`shader`).
fn node_factor(l: &crate::scene::format::Light) -> Result<Option<Vec3>, RenderError> {
    let use_nodes = LightSettings::of(l).use_nodes;
    let Some(tree) = l.node_tree.as_ref().filter(|_| use_nodes) else {
        return Ok(Some(Vec3::ONE));
    };
    // No output, or nothing linked to it: Cycles renders the light black.
    let Some(out) = crate::nodes::graph::active_output(tree, "ShaderNodeOutputLight", "CYCLES")
    else {
        return Ok(Some(Vec3::ZERO));
    };
    let Some(link) = tree
        .links
        .iter()
        .find(|k| k.to_node == out.name && k.to_socket == "Surface" && !k.is_muted)
    else {
        return Ok(Some(Vec3::ZERO));
    };
    let name = &l.name;
    let node = tree
        .nodes
        .iter()
        .find(|n| n.name == link.from_node)
        .ok_or_else(|| {
            RenderError(format!(
                "light {name:?}: its node tree links from a missing node {:?}",
                link.from_node
            ))
        })?;
    // A muted Emission has no closure input to pass through: nothing reaches the output.
    if node.bl_idname == "ShaderNodeEmission" && node.mute {
        return Ok(Some(Vec3::ZERO));
    }
    // A closure that cannot emit (a BSDF wired to the Light Output): Cycles' estimate of
    // the shader's emission is zero, so the light has no contribution and is left out.
    if NON_EMITTING_CLOSURES.contains(&node.bl_idname.as_str()) {
        return Ok(Some(Vec3::ZERO));
    }
    if node.bl_idname != "ShaderNodeEmission"
        || tree
            .links
            .iter()
            .any(|k| k.to_node == node.name && !k.is_muted)
    {
        return Ok(None);
    }
    let input = |id: &str| {
        node.inputs
            .iter()
            .find(|s| s.identifier == id)
            .and_then(|s| s.default_value.as_ref())
    };
    let color = crate::scene::settings::rgb(input("Color"))
        .map_or(Vec3::ONE, |c| Vec3::from(c.map(|x| x as f32)));
    let strength = input("Strength").and_then(Value::as_f64).unwrap_or(1.0) as f32;
    Ok(Some(color * strength))
}

// Long because one arm per light type, reading its settings as Cycles' light sync does.
pub fn collect(scene: &Scene, eval: &EvaluatedScene) -> Result<Vec<Light>, RenderError> {
    let mut out = Vec::new();
    for (oi, obj) in eval.data.objects.iter().enumerate() {
        if obj.kind != "LIGHT" || obj.hide_render || !obj.in_render_layer {
            continue;
        }
        let Some(data) = obj.data.as_deref() else {
            continue;
        };
        let Some(l) = eval.data.lights.iter().find(|l| l.name == data) else {
            continue;
        };
        let p = LightSettings::of(l);
        let m = Affine::from_rows(&eval.world_matrices[oi]);
        let color = p
            .color
            .map_or(Vec3::ONE, |c| Vec3::from(c.map(|x| x as f32)));
        let energy = p.energy as f32;
        let exposure = p.exposure as f32;
        let (factor, shader) = match node_factor(l)? {
            Some(f) => (f, None),
            None => match compile_light(scene, l).map_err(|e| RenderError(e.0))? {
                // No Light Output for Cycles: the light is black.
                None => (Vec3::ZERO, None),
                Some(program) => {
                    let info = object_info(obj, &eval.world_matrices[oi]);
                    let to_world = Affine::from_rows(&eval.world_matrices[oi]).m;
                    (
                        Vec3::ONE,
                        Some(Arc::new(LightShader::new(program, info, to_world))),
                    )
                }
            },
        };
        let mut strength = color * (energy * 2f32.powf(exposure)) * factor;
        // Blender 4.5's light temperature: the colour is multiplied by the blackbody colour
        // Blender computed (`temperature_color`, in the scene's working space).
        if p.use_temperature {
            if let Some(t) = p.temperature_color {
                strength *= Vec3::from(t.map(|x| x as f32));
            }
        }
        // Cycles weighs a light in its tree by its shader's emission estimate.
        let estimate = shader.as_ref().map_or(Vec3::ONE, |s| s.estimate());
        let tree_energy = (strength * estimate).average().abs()
            * match l.kind.as_str() {
                "AREA" => 0.25,
                "SUN" => 1.0,
                _ => 0.25 / PI,
            };
        let spread = p.spread as f32;
        let pos = m.column_vec3(3);
        let dir = (-m.column_vec3(2)).normalize();
        let cast_shadow = p.cast_shadow;
        let shape = match l.kind.as_str() {
            "POINT" | "SPOT" => {
                let radius = p.shadow_soft_size as f32;
                let spot = if l.kind == "SPOT" {
                    let size = p.spot_size as f32;
                    let blend = p.spot_blend as f32;
                    let cos_half = (size * 0.5).cos();
                    let smooth = if blend > 0.0 {
                        1.0 / ((1.0 - cos_half) * blend)
                    } else {
                        f32::INFINITY
                    };
                    // Cycles divides by the axes' squared lengths so scale shapes the cone.
                    let inv = |a: Vec3| {
                        let l2 = a.dot(a);
                        if l2 > 0.0 {
                            a * (1.0 / l2)
                        } else {
                            a
                        }
                    };
                    Some(Spot {
                        cos_half,
                        smooth,
                        u: inv(m.column_vec3(0)),
                        v: inv(m.column_vec3(1)),
                        w: inv(-m.column_vec3(2)),
                    })
                } else {
                    None
                };
                let sphere = !p.use_soft_falloff;
                Shape::Point {
                    radius,
                    spot,
                    sphere,
                }
            }
            // A portal only guides Cycles' sampling of the world through it: it emits
            // nothing, and the world is sampled by its own map here.
            "AREA" if p.is_portal => continue,
            "AREA" => {
                let size = p.size as f32;
                let size_y = match p.shape {
                    AreaShape::Rectangle | AreaShape::Ellipse => p.size_y as f32,
                    AreaShape::Square | AreaShape::Disk => size,
                };
                let u = m.column_vec3(0) * size;
                let v = m.column_vec3(1) * size_y;
                let ellipse = matches!(p.shape, AreaShape::Disk | AreaShape::Ellipse);
                let mut area = u.length() * v.length();
                if ellipse {
                    area *= PI / 4.0;
                }
                if area <= 0.0 {
                    continue;
                }
                Shape::Area {
                    u,
                    v,
                    ellipse,
                    area,
                    spread: Spread::new(p.spread as f32),
                }
            }
            "SUN" => Shape::Sun {
                half_angle: p.angle as f32 * 0.5,
            },
            _ => continue,
        };
        // Normalize off (Blender 4.5): the power is not spread over the light's area, so the
        // radiance is that many times higher (Cycles' Light::area: a point's sphere, 4 when
        // its radius is 0; the rectangle or ellipse; the sun's disk, 1 when its angle is 0).
        if !p.normalize {
            let area = match &shape {
                Shape::Point { radius, .. } => {
                    let a = 4.0 * PI * radius * radius;
                    if a == 0.0 {
                        4.0
                    } else {
                        a
                    }
                }
                Shape::Area { area, .. } => *area,
                Shape::Sun { half_angle } => {
                    if *half_angle > 0.0 {
                        PI * half_angle.sin() * half_angle.sin()
                    } else {
                        1.0
                    }
                }
            };
            strength *= area;
        }
        let exclude = excluded_rays(obj.visibility.as_ref());
        let use_mis = p.use_multiple_importance_sampling;
        let extent = match &shape {
            Shape::Point { radius, .. } => *radius > 0.0,
            Shape::Area { spread, .. } => spread.is_none_or(|s| s.tan_half > 0.0),
            Shape::Sun { half_angle } => *half_angle > 0.0,
        };
        let max_bounces = p.max_bounces;
        out.push(Light {
            shape,
            strength,
            pos,
            dir,
            cast_shadow,
            mis: use_mis && extent,
            max_bounces,
            exclude,
            tree_energy,
            spread,
            shader,
        });
    }
    Ok(out)
}

impl Spot {
    /// Cycles' spot attenuation of light leaving along `ray` (from the light outward).
    fn attenuation(&self, ray: Vec3) -> f32 {
        let sr = vec3(ray.dot(self.u), ray.dot(self.v), ray.dot(self.w)).normalize();
        if self.smooth.is_finite() {
            smoothstep((sr.z - self.cos_half) * self.smooth)
        } else if sr.z > self.cos_half {
            1.0
        } else {
            0.0
        }
    }
}

/// 1 - cos of the angle whose squared sine is `s2`, accurate for small angles.
fn one_minus_cos_from_sin2(s2: f32) -> f32 {
    if s2 < 0.0004 {
        0.5 * s2 + 0.125 * s2 * s2
    } else {
        1.0 - (1.0 - s2).max(0.0).sqrt()
    }
}

/// A direction uniform in the cone about `axis` with 1 - cos(half angle) = `omc`
/// (Cycles' concentric cone mapping), and its cosine to the axis.
pub(super) fn sample_cone(axis: Vec3, omc: f32, u: [f32; 2]) -> (Vec3, f32) {
    let xy = crate::render::camera::concentric_disk(u);
    let r2 = xy[0] * xy[0] + xy[1] * xy[1];
    let cos_theta = 1.0 - r2 * omc;
    let k = (omc * (2.0 - omc * r2)).max(0.0).sqrt();
    let (t, b) = axis.basis();
    (
        t * (xy[0] * k) + b * (xy[1] * k) + axis * cos_theta,
        cos_theta,
    )
}

/// 1 - cos(half angle) of a sun's cone, without the cancellation of `1.0 - cos` at
/// small angles (Cycles passes one_minus_cos for the same reason).
pub(super) fn sun_one_minus_cos(half_angle: f32) -> f32 {
    let s = (0.5 * half_angle).sin();
    2.0 * s * s
}

/// Nearest positive distance along unit `d` from `o` to the sphere, if any.
fn ray_sphere(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<f32> {
    let oc = c - o;
    let tc = oc.dot(d);
    let h2 = r * r - (oc.dot(oc) - tc * tc);
    if h2 < 0.0 {
        return None;
    }
    let h = h2.sqrt();
    let t = if tc - h > 0.0 { tc - h } else { tc + h };
    (t > 0.0).then_some(t)
}

#[inline]
fn smoothstep(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl Light {
    // Long because one arm per light type, as Cycles' light sample functions.
    pub fn sample(&self, p: V3, u: [f32; 2]) -> Option<LightSample> {
        let p = Vec3::from(p);
        let (pos, dir, strength) = (self.pos, self.dir, self.strength);
        match &self.shape {
            Shape::Point {
                radius,
                spot,
                sphere,
            } => {
                let to = pos - p;
                let d2 = to.dot(to);
                if d2 <= 0.0 {
                    return None;
                }
                let d = d2.sqrt();
                let w = to * (1.0 / d);
                if *radius <= 0.0 {
                    let atten = match spot {
                        Some(s) => s.attenuation(-w),
                        None => 1.0,
                    };
                    if atten <= 0.0 {
                        return None;
                    }
                    // Intensity power / (4 pi) over squared distance.
                    let v = strength * (atten / (4.0 * PI * d2));
                    let v = self.shaded(v, pos, -w, w, d);
                    return Some(LightSample {
                        wi: w.into(),
                        dist: d,
                        value: v.into(),
                        pdf: f32::INFINITY,
                    });
                }
                let r2 = radius * radius;
                let radiance = 1.0 / (4.0 * PI * PI * r2);
                if !*sphere || d2 <= r2 {
                    // Cycles' soft-falloff point light: a disk of the radius facing the
                    // point, the spot cone weighing the sampled direction. (Inside a sphere
                    // light Cycles samples the hemisphere, unweighted by the cone; rare,
                    // done here as the disk.)
                    let disk = crate::render::camera::concentric_disk(u);
                    let (t, b) = w.basis();
                    let q = pos + (t * (disk[0] * radius) + b * (disk[1] * radius));
                    let to = q - p;
                    let dq2 = to.dot(to);
                    let dq = dq2.sqrt();
                    let wi = to * (1.0 / dq);
                    let cos_l = w.dot(wi).abs();
                    let atten = match spot {
                        Some(s) if !*sphere => s.attenuation(-wi),
                        _ => 1.0,
                    };
                    if atten <= 0.0 {
                        return None;
                    }
                    let v = strength * (atten * radiance * cos_l * PI * r2 / dq2);
                    let v = self.shaded(v, q, -wi, wi, dq);
                    let pdf = dq2 / (cos_l.max(1e-8) * PI * r2);
                    return Some(LightSample {
                        wi: wi.into(),
                        dist: dq,
                        value: v.into(),
                        pdf,
                    });
                }
                // Cycles' sphere light (light/point.h, spot.h): a direction uniform in the
                // cone the sphere subtends or, for a spot narrower than that, in the spot's
                // spread cone about its axis; the spot cone weighs each sampled direction.
                let cap = one_minus_cos_from_sin2(r2 / d2);
                let spread = spot.map(|s| 1.0 - s.cos_half).unwrap_or(f32::INFINITY);
                let (axis, omc) = if cap < spread {
                    (w, cap)
                } else {
                    (-dir, spread)
                };
                let (wi, cos_theta) = sample_cone(axis, omc, u);
                let dist = if cap < spread {
                    // Law of cosines: the nearer crossing of the sphere along the cone's ray.
                    let cos_w = wi.dot(w);
                    d * cos_w - (r2 - d2 + d2 * cos_w * cos_w).max(0.0).sqrt()
                } else {
                    let _ = cos_theta;
                    ray_sphere(p, wi, pos, *radius)?
                };
                let atten = match spot {
                    Some(s) => s.attenuation(-wi),
                    None => 1.0,
                };
                if atten <= 0.0 {
                    return None;
                }
                let pdf = 1.0 / (2.0 * PI * omc);
                let v = strength * (atten * radiance / pdf);
                let q = p + wi * dist;
                let v = self.shaded(v, q, (q - pos).normalize(), wi, dist);
                Some(LightSample {
                    wi: wi.into(),
                    dist,
                    value: v.into(),
                    pdf,
                })
            }
            Shape::Area {
                u: au,
                v: av,
                ellipse,
                area,
                spread,
            } => {
                // One-sided: nothing behind the light's plane.
                if (p - pos).dot(dir) <= 0.0 {
                    return None;
                }
                let region = self.area_region(p, *au, *av, *ellipse, spread.as_ref())?;
                let (q, pdf_region) = if region.rectangle {
                    let (s, q) = rect_solid_angle(p, &region, Some(u));
                    (q?, 1.0 / s)
                } else {
                    let d = crate::render::camera::concentric_disk(u);
                    let q = region.centre
                        + (region.axis_u * (d[0] * 0.5 * region.len_u)
                            + region.axis_v * (d[1] * 0.5 * region.len_v));
                    (q, 4.0 / (PI * region.len_u * region.len_v))
                };
                // A region larger than the light (a spread circle, or the rectangle about
                // a round light's lens) draws points off it: those samples are lost.
                if !self.area_contains(q, *au, *av, *ellipse) {
                    return None;
                }
                let to = q - p;
                let d2 = to.dot(to);
                if !(d2 > 0.0) || !pdf_region.is_finite() {
                    return None;
                }
                let d = d2.sqrt();
                let wi = to * (1.0 / d);
                let cos_l = -dir.dot(wi);
                if cos_l <= 0.0 {
                    return None;
                }
                let atten = spread.map(|s| s.attenuation(wi, dir)).unwrap_or(1.0);
                if atten <= 0.0 {
                    return None;
                }
                // Rectangles are sampled by solid angle; ellipses by area, in solid angle.
                let pdf = if region.rectangle {
                    pdf_region
                } else {
                    pdf_region * d2 / cos_l
                };
                let radiance = atten / (PI * area);
                let v = strength * (radiance / pdf);
                Some(LightSample {
                    wi: wi.into(),
                    dist: d,
                    value: self.shaded(v, q, dir, wi, d).into(),
                    pdf,
                })
            }
            Shape::Sun { half_angle } => {
                let toward = -dir;
                if *half_angle <= 0.0 {
                    return Some(LightSample {
                        wi: toward.into(),
                        dist: f32::INFINITY,
                        value: self.shaded_sun(strength, toward).into(),
                        pdf: f32::INFINITY,
                    });
                }
                // Uniform in the cone by Cycles' concentric mapping (distant_light_sample:
                // sample_uniform_cone), which keeps the sampler's 2D stratification: a polar
                // mapping stretches strata into thin rings and wedges, noisy where a sharp
                // lobe sees only part of the disk (a glint on rough glass).
                let omc = sun_one_minus_cos(*half_angle);
                let (wi, _) = sample_cone(toward, omc, u);
                let s = half_angle.sin();
                let radiance = 1.0 / (PI * s * s);
                let pdf = 1.0 / (2.0 * PI * omc);
                Some(LightSample {
                    wi: wi.into(),
                    dist: f32::INFINITY,
                    value: self.shaded_sun(strength * (radiance / pdf), wi).into(),
                    pdf,
                })
            }
        }
    }

    /// Where a ray from `o` along unit `d` meets this light before `tmax` (suns: only
    /// rays that leave the scene, `tmax` infinite).
    pub fn intersect(&self, o: V3, d: V3, tmax: f32) -> Option<LightHit> {
        let (o, d) = (Vec3::from(o), Vec3::from(d));
        let (pos, dir, strength) = (self.pos, self.dir, self.strength);
        match &self.shape {
            Shape::Point {
                radius,
                spot,
                sphere,
            } => {
                if *radius <= 0.0 {
                    return None;
                }
                // Rays leaving a spot are not lit by it (Cycles' one-sided test).
                if spot.is_some() && d.dot(o - pos) >= 0.0 {
                    return None;
                }
                if !*sphere {
                    // The disk through the light's centre facing the ray origin.
                    let to = pos - o;
                    let n = (-to).normalize();
                    let denom = d.dot(n);
                    if denom >= 0.0 {
                        return None;
                    }
                    let t = to.dot(n) / denom;
                    if !(t > 0.0 && t < tmax) {
                        return None;
                    }
                    let q = o + d * t - pos;
                    if q.dot(q) > radius * radius {
                        return None;
                    }
                    let atten = spot.map(|s| s.attenuation(-d)).unwrap_or(1.0);
                    let radiance = strength * (atten / (4.0 * PI * PI * radius * radius));
                    let radiance = self.shaded(radiance, o + d * t, -d, d, t);
                    return Some(LightHit {
                        t,
                        radiance: radiance.into(),
                        pdf: t * t / ((-denom).max(1e-8) * PI * radius * radius),
                    });
                }
                let t = ray_sphere(o, d, pos, *radius)?;
                if t >= tmax {
                    return None;
                }
                let to = pos - o;
                let (d2, r2) = (to.dot(to), radius * radius);
                let mut atten = 1.0;
                let mut omc = 2.0;
                if d2 > r2 {
                    omc = one_minus_cos_from_sin2(r2 / d2);
                    if let Some(s) = spot {
                        atten = s.attenuation(-d);
                        omc = omc.min(1.0 - s.cos_half);
                    }
                }
                let radiance = strength * (atten / (4.0 * PI * PI * r2));
                let q = o + d * t;
                let radiance = self.shaded(radiance, q, (q - pos).normalize(), d, t);
                Some(LightHit {
                    t,
                    radiance: radiance.into(),
                    pdf: 1.0 / (2.0 * PI * omc),
                })
            }
            Shape::Area {
                u,
                v,
                ellipse,
                area,
                spread,
            } => {
                let cos_l = -d.dot(dir);
                if cos_l <= 0.0 {
                    return None;
                }
                let t = (pos - o).dot(dir) / d.dot(dir);
                if !(t > 0.0 && t < tmax) {
                    return None;
                }
                let q = o + d * t;
                if !self.area_contains(q, *u, *v, *ellipse) {
                    return None;
                }
                // The pdf light sampling from `o` would have given this point.
                let region = self.area_region(o, *u, *v, *ellipse, spread.as_ref())?;
                let pdf = if region.rectangle {
                    1.0 / rect_solid_angle(o, &region, None).0
                } else {
                    4.0 / (PI * region.len_u * region.len_v) * t * t / cos_l
                };
                let atten = spread.map(|s| s.attenuation(d, dir)).unwrap_or(1.0);
                if atten <= 0.0 || !pdf.is_finite() {
                    return None;
                }
                let radiance = strength * (atten / (PI * area));
                Some(LightHit {
                    t,
                    radiance: self.shaded(radiance, q, dir, d, t).into(),
                    pdf,
                })
            }
            Shape::Sun { half_angle } => {
                if tmax.is_finite() || *half_angle <= 0.0 {
                    return None;
                }
                let cos_max = half_angle.cos();
                if d.dot(-dir) < cos_max {
                    return None;
                }
                let s = half_angle.sin();
                Some(LightHit {
                    t: f32::INFINITY,
                    radiance: self.shaded_sun(strength * (1.0 / (PI * s * s)), d).into(),
                    pdf: 1.0 / (2.0 * PI * sun_one_minus_cos(*half_angle)),
                })
            }
        }
    }
}

impl Light {
    /// `v` times the light's varying node tree at light point `q` with normal `ng`, lighting
    /// a point `t` away along -`wi` (`wi` from the lit point toward the light).
    #[inline]
    fn shaded(&self, v: Vec3, q: Vec3, ng: Vec3, wi: Vec3, t: f32) -> Vec3 {
        match &self.shader {
            None => v,
            Some(s) => v * s.emission(q, ng, -wi, t),
        }
    }

    /// The same for a sun seen along `wi`: Cycles' light point and normal are then the
    /// direction away from the sun, and its distance f32::MAX.
    #[inline]
    fn shaded_sun(&self, v: Vec3, wi: Vec3) -> Vec3 {
        let away = -wi;
        self.shaded(v, away, away, wi, f32::MAX)
    }

    /// The part of an area light that light sampling from `p` draws from: the whole light
    /// (a rectangle by solid angle, an ellipse by area), or what its spread lets reach `p`.
    fn area_region(
        &self,
        p: Vec3,
        u: Vec3,
        v: Vec3,
        ellipse: bool,
        spread: Option<&Spread>,
    ) -> Option<Region> {
        let (len_u, len_v) = (u.length(), v.length());
        let full = Region {
            centre: self.pos,
            axis_u: u * (1.0 / len_u),
            len_u,
            axis_v: v * (1.0 / len_v),
            len_v,
            rectangle: !ellipse,
        };
        match spread {
            Some(s) => s.clamp(p, self.dir, full),
            None => Some(full),
        }
    }

    /// Whether point `q` of the light's plane lies on the light.
    fn area_contains(&self, q: Vec3, u: Vec3, v: Vec3, ellipse: bool) -> bool {
        let r = q - self.pos;
        let a = r.dot(u) / u.dot(u);
        let b = r.dot(v) / v.dot(v);
        if ellipse {
            a * a + b * b <= 0.25
        } else {
            a.abs() <= 0.5 && b.abs() <= 0.5
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(ellipse: bool, size: (f32, f32), spread_deg: Option<f32>) -> Light {
        let (u, v) = (vec3(size.0, 0.0, 0.0), vec3(0.0, size.1, 0.0));
        let mut a = size.0 * size.1;
        if ellipse {
            a *= PI / 4.0;
        }
        let spread = spread_deg.and_then(|d| Spread::new(d.to_radians()));
        Light {
            shape: Shape::Area {
                u,
                v,
                ellipse,
                area: a,
                spread,
            },
            strength: Vec3::splat(100.0),
            pos: vec3(0.0, 0.0, 2.0),
            dir: vec3(0.0, 0.0, -1.0),
            cast_shadow: true,
            mis: true,
            max_bounces: 1024,
            exclude: 0,
            tree_energy: 25.0,
            spread: PI,
            shader: None,
        }
    }

    /// MIS needs the pdf of a light sample and the pdf a BSDF ray finds for the same
    /// direction to agree, and the same radiance; for every area shape and spread.
    #[test]
    fn area_sample_and_hit_agree() {
        let lights = [
            area(false, (2.0, 1.0), None),
            area(true, (2.0, 2.0), None),
            area(false, (3.0, 1.5), Some(40.0)),
            area(true, (2.0, 2.0), Some(30.0)),
            area(true, (2.5, 1.0), Some(70.0)),
        ];
        for (li, l) in lights.iter().enumerate() {
            // (A narrow spread may light no point of a far region: none is required there.)
            let mut checked = 0;
            for p in [[0.3f32, -0.2, 0.0], [1.5, 0.4, 0.5], [-0.8, 0.6, 1.0]] {
                for i in 0..16 {
                    for j in 0..16 {
                        let u = [(i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0];
                        let Some(s) = l.sample(p, u) else { continue };
                        let h = l
                            .intersect(p, s.wi, f32::INFINITY)
                            .expect("the sampled direction hits the light");
                        assert!(
                            (h.t - s.dist).abs() < 1e-4 * s.dist,
                            "light {li}: t {} vs {}",
                            h.t,
                            s.dist
                        );
                        assert!(
                            (h.pdf - s.pdf).abs() <= 1e-3 * s.pdf,
                            "light {li} at {p:?}: pdf {} vs {}",
                            h.pdf,
                            s.pdf
                        );
                        // value = radiance / pdf
                        let want = h.radiance[0] / h.pdf;
                        assert!(
                            (s.value[0] - want).abs() <= 1e-3 * want,
                            "light {li}: value {} vs {want}",
                            s.value[0]
                        );
                        checked += 1;
                    }
                }
            }
            assert!(checked > 200, "light {li}: {checked} samples");
        }
    }
}
