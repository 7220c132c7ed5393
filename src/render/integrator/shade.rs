//! Materials as the renderer runs them: each compiled once with `shader::compile`, run
//! per hit on a reused stack, and its closure tree turned into weighted lobes the way
//! Cycles' SVM builds closures (Mix Shader factors clamped, Principled BSDF layered).

use crate::scene::Scene;
use crate::shader::program::{socket, BsdfKind, BsdfNode, Closure, Program};
use crate::shader::{compile_material, ShadingPoint};

use crate::render::bsdf::ray_portal::RayPortal;
use crate::render::bsdf::tables::Tables;
use crate::render::bsdf::{Fresnel, LobeKind, LobeSet};
use crate::render::math::*;
use crate::render::subsurface::Method;
use crate::render::RenderError;

pub struct Material {
    pub program: Option<Program>,
    /// Per closure: index into `program.bsdfs`.
    bsdf_of: Vec<Option<u32>>,
    pub name: String,
    /// The material's emission sampling setting (Cycles' AUTO, NONE, FRONT, BACK, FRONT_BACK).
    pub sampling: String,
    /// Cycles' "Bump Map Correction" (material setting, on by default).
    pub bump_correction: bool,
    /// Cycles' SD_HAS_BSSRDF_BUMP: a subsurface exit on this material lights with the
    /// BSSRDF's (bumped) normal, so the material runs there (see `subsurface::exit_normal`).
    pub bssrdf_bump: bool,
    /// Cycles' SD_HAS_TRANSPARENT_SHADOW: the material can be transparent (a Transparent
    /// BSDF, or a Principled BSDF whose Alpha is linked or below 1), so shadow rays run
    /// it instead of stopping at it.
    pub transparent_shadow: bool,
    /// The material can make a Multiscatter GGX glass closure (Glass BSDF, or a
    /// Principled BSDF whose Transmission Weight is linked or above zero) or a Huang hair
    /// closure (its energy scale), which read the glass albedo table.
    pub multiscatter_glass: bool,
}

/// Every material of the scene, in `scene.file.materials` order.
pub fn compile_all(scene: &Scene, used: &[bool]) -> Result<Vec<Material>, RenderError> {
    let mut out = Vec::new();
    for (i, m) in scene.file.materials.iter().enumerate() {
        if !used.get(i).copied().unwrap_or(false) {
            out.push(Material {
                program: None,
                bsdf_of: Vec::new(),
                name: m.name.clone(),
                sampling: String::new(),
                bump_correction: true,
                bssrdf_bump: false,
                transparent_shadow: false,
                multiscatter_glass: false,
            });
            continue;
        }
        let p = compile_material(scene, &m.name).map_err(|e| RenderError(format!("{e}")))?;
        let mut bsdf_of = vec![None; p.closures.len()];
        // Volume nodes shade only a Volume (render/volume.rs): in a Surface they do
        // nothing, as in Cycles.
        for (bi, b) in p.bsdfs.iter().enumerate() {
            if b.kind == BsdfKind::Volume {
                continue;
            }
            if let Some(slot) = bsdf_of.get_mut(b.closure as usize) {
                *slot = Some(bi as u32);
            }
        }
        let ms = crate::scene::settings::MaterialSettings::of(m);
        let sampling = ms.emission_sampling;
        let bump_correction = ms.use_bump_map_correction;
        let bssrdf_bump = has_bssrdf_bump(&p);
        let transparent_shadow = can_be_transparent(&p);
        let multiscatter_glass = has_multiscatter_glass(&p);
        out.push(Material {
            program: Some(p),
            bsdf_of,
            name: m.name.clone(),
            sampling,
            bump_correction,
            bssrdf_bump,
            transparent_shadow,
            multiscatter_glass,
        });
    }
    Ok(out)
}

/// True when the ops of the material's true displacement read mesh attributes or
/// tangents: the renderer's displacement points (`displace`) do not carry them.
pub fn displacement_reads_attributes(p: &Program) -> bool {
    use crate::shader::program::Op;
    let Some(d) = p.displacement else {
        return false;
    };
    p.ops[..d.center_end.min(p.ops.len())].iter().any(|op| {
        matches!(
            op,
            Op::Attribute { .. }
                | Op::ColorAttribute { .. }
                | Op::NamedUv { .. }
                | Op::NormalMapTangent { .. }
                | Op::VectorDisplacementTangent { .. }
                | Op::TangentUv { .. }
        )
    })
}

/// Whether BSDF node `b`'s input `name` is linked, or unlinked with a constant for which
/// `constant` holds (false when the node has no such input).
fn linked_or_constant(
    p: &Program,
    b: &crate::shader::program::BsdfNode,
    name: &str,
    constant: impl Fn(f32) -> bool,
) -> bool {
    match b.input(name) {
        Some((_, true)) => true,
        Some((slot, false)) => p.initial.get(slot as usize).is_some_and(|v| constant(*v)),
        None => false,
    }
}

/// Whether a microfacet node compensates multiple scattering (Cycles' is_multiggx): the
/// Principled BSDF unless its distribution is GGX (Multiscatter GGX is its default), the
/// other nodes only when theirs is Multiscatter GGX.
pub(crate) fn is_multiggx(b: &BsdfNode) -> bool {
    match b.bl_idname.as_str() {
        "ShaderNodeBsdfPrincipled" => b.property("distribution") != Some("GGX"),
        _ => b.property("distribution") == Some("MULTI_GGX"),
    }
}

/// Whether the material can make a Multiscatter GGX glass closure (see
/// `Material::multiscatter_glass`).
fn has_multiscatter_glass(p: &Program) -> bool {
    p.bsdfs.iter().any(|b| match b.bl_idname.as_str() {
        "ShaderNodeBsdfGlass" => is_multiggx(b),
        "ShaderNodeBsdfHairPrincipled" => b.property("model") == Some("HUANG"),
        "ShaderNodeBsdfPrincipled" => {
            is_multiggx(b) && linked_or_constant(p, b, "Transmission Weight", |w| w > 0.0)
        }
        _ => false,
    })
}

/// Whether the material has a closure that can be transparent (Cycles marks such
/// shaders for transparent shadows).
fn can_be_transparent(p: &Program) -> bool {
    p.bsdfs.iter().any(|b| match b.bl_idname.as_str() {
        "ShaderNodeBsdfTransparent" => true,
        "ShaderNodeBsdfPrincipled" => linked_or_constant(p, b, "Alpha", |a| a < 1.0),
        // Not the Huang hair BSDF, though Cycles flags an elliptical one so
        // (has_surface_transparent): its shadow rays run shaders with no closure slots, so
        // the Huang setup, which makes its transparency, never runs there and the fibre
        // stays opaque to shadows (scene hair_huang_color matches so, and is 3% bright
        // with transparent shadows).
        _ => false,
    })
}

/// Cycles' `has_bssrdf_bump` (svm.cpp: the displacement's bump, or a BSSRDF node whose
/// Normal is linked; a Principled BSDF counts as BSSRDF when its Subsurface Weight is
/// linked or above the closure cutoff).
fn has_bssrdf_bump(p: &Program) -> bool {
    p.displaced_normal.is_some()
        || p.bsdfs.iter().any(|b| {
            let bssrdf = match b.bl_idname.as_str() {
                "ShaderNodeSubsurfaceScattering" => true,
                "ShaderNodeBsdfPrincipled" => {
                    linked_or_constant(p, b, "Subsurface Weight", |w| w > 1e-5)
                }
                _ => false,
            };
            bssrdf && matches!(b.input_at(socket!("Normal")), Some((_, true)))
        })
}

/// What the shading of one hit needs besides the shading point.
pub struct Context<'a> {
    pub tables: &'a Tables,
    /// Unit direction toward the viewer.
    pub wo: V3,
    /// The ray hit the back of the surface (normals are already flipped to face it).
    pub backfacing: bool,
    /// The material's Bump Map Correction (set by `Material::shade`).
    pub bump_correction: bool,
    /// The ray queries its Ambient Occlusion and Bevel nodes make (`NoTrace` where
    /// Cycles shades without ray tracing: shadow and light-emission shading).
    pub trace: &'a dyn crate::shader::trace::Trace,
}

/// Cycles' `maybe_ensure_valid_specular_reflection`: the normal of the closures whose
/// mirror direction must stay above the surface (microfacet, glass, translucent, BSSRDF),
/// raised toward the true normal when the material's Bump Map Correction is on.
pub(crate) fn valid_n(sp: &ShadingPoint, ctx: &Context, n: V3) -> V3 {
    if ctx.bump_correction && n != sp.true_normal {
        crate::render::bsdf::bump_correction::ensure_valid_specular_reflection(
            sp.true_normal,
            ctx.wo,
            n,
        )
    } else {
        n
    }
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
fn finite3(v: V3) -> V3 {
    v.map(|x| if x.is_finite() { x } else { 0.0 })
}

impl Material {
    /// Runs the material at `sp` and fills `out`. A material without a program is
    /// Cycles' default surface (diffuse grey 0.8).
    pub fn shade(&self, sp: &ShadingPoint, stack: &mut Vec<f32>, ctx: &Context, out: &mut LobeSet) {
        out.clear();
        let Some(p) = &self.program else {
            out.push(LobeKind::Diffuse, [0.8; 3], sp.normal);
            return;
        };
        if stack.len() != p.initial.len() {
            stack.clear();
            stack.extend_from_slice(&p.initial);
        }
        p.run_traced(sp, stack, ctx.trace);
        // The caller's false (a curve hit) keeps normals as they are.
        let ctx = &Context {
            bump_correction: self.bump_correction && ctx.bump_correction,
            ..*ctx
        };
        // The material's displacement, bumped, is the shading normal of every closure.
        let bumped;
        let sp = match p.displaced_normal {
            Some(slot) => {
                bumped = ShadingPoint {
                    normal: v3(stack, slot),
                    ..*sp
                };
                &bumped
            }
            None => sp,
        };
        out.smooth_n = sp.normal;
        out.bump_correction = self.bump_correction;
        if let Some(c) = p.surface {
            self.closure(p, c, 1.0, stack, sp, ctx, out);
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn closure(
        &self,
        p: &Program,
        c: u32,
        w: f32,
        s: &[f32],
        sp: &ShadingPoint,
        ctx: &Context,
        out: &mut LobeSet,
    ) {
        match p.closures[c as usize] {
            Closure::Emission { color, strength } => {
                let e = scale(v3(s, color), finite_or(s[strength as usize], 0.0) * w);
                out.emission = add(out.emission, finite3(e));
            }
            Closure::Mix { fac, a, b } => {
                let f = finite_or(s[fac as usize], 0.0).clamp(0.0, 1.0);
                if let Some(a) = a {
                    if w * (1.0 - f) > 0.0 {
                        self.closure(p, a, w * (1.0 - f), s, sp, ctx, out);
                    }
                }
                if let Some(b) = b {
                    if w * f > 0.0 {
                        self.closure(p, b, w * f, s, sp, ctx, out);
                    }
                }
            }
            Closure::Add { a, b } => {
                if let Some(a) = a {
                    self.closure(p, a, w, s, sp, ctx, out);
                }
                if let Some(b) = b {
                    self.closure(p, b, w, s, sp, ctx, out);
                }
            }
            Closure::Bsdf { .. } => {
                if let Some(bi) = self.bsdf_of.get(c as usize).copied().flatten() {
                    bsdf(&p.bsdfs[bi as usize], w, s, sp, ctx, out);
                }
            }
        }
    }
}

/// Input `id` (a `socket!` index) of `b` from stack `s`, or `d` where `b` has none.
#[inline]
pub(crate) fn input_f(b: &BsdfNode, s: &[f32], id: usize, d: f32) -> f32 {
    b.input_at(id)
        .map(|(slot, _)| finite_or(s[slot as usize], d))
        .unwrap_or(d)
}
#[inline]
pub(crate) fn input_c(b: &BsdfNode, s: &[f32], id: usize, d: V3) -> V3 {
    b.input_at(id)
        .map(|(slot, _)| finite3(v3(s, slot)))
        .unwrap_or(d)
}
#[inline]
pub(crate) fn input_n(b: &BsdfNode, s: &[f32], id: usize, sp: &ShadingPoint) -> V3 {
    match b.input_at(id) {
        Some((slot, true)) => {
            let v = v3(s, slot);
            // Cycles' safe_normalize keeps a NaN (or infinite) normal; the closure then
            // poisons the point's lighting (LobeSet::poisoned).
            if !v.iter().all(|c| c.is_finite()) {
                return [f32::NAN; 3];
            }
            let n = normalize(v);
            if is_zero(n) {
                sp.normal
            } else {
                n
            }
        }
        _ => sp.normal,
    }
}

pub(crate) fn multiscatter_energy(tables: &Tables, mu: f32, roughness: f32) -> f32 {
    let e = tables.ggx_e(mu, roughness).max(1e-3);
    1.0 / e
}

/// Cycles' microfacet_ggx_preserve_energy beyond the energy scale 1 / E: light lost
/// between microfacets returns only after more Fresnel bounces, so a closure whose
/// average Fresnel `fss` is below one gets back less (Fms, the appendix of Kulla and
/// Conty's "Revisiting Physically Based Shading at Imageworks", with the cosine-weighted
/// mean albedo E_avg). A factor on the closure weight, one where `fss` is one.
pub(crate) fn multiscatter_darkening(tables: &Tables, mu: f32, roughness: f32, fss: V3) -> V3 {
    let e = tables.ggx_e(mu, roughness).max(1e-3);
    let e_avg = tables.ggx_e_avg(roughness);
    let missing = (1.0 - e) / e;
    fss.map(|f| {
        let fms = f * e_avg / (1.0 - f * (1.0 - e_avg));
        (1.0 + fms * missing) / (1.0 + missing)
    })
}

/// Cycles' fresnel_dielectric_Fss: the average dielectric Fresnel of relative IOR `eta`.
pub(crate) fn dielectric_fss(eta: f32) -> f32 {
    if eta < 1.0 {
        0.997118 + eta * (0.1014 - eta * (0.965241 + eta * 0.130607))
    } else {
        (eta - 1.0) / (4.08567 + 1.00071 * eta)
    }
}

fn bsdf(b: &BsdfNode, w: f32, s: &[f32], sp: &ShadingPoint, ctx: &Context, out: &mut LobeSet) {
    match b.kind {
        BsdfKind::Diffuse => {
            let c = input_c(b, s, socket!("Color"), [0.8; 3]);
            let n = input_n(b, s, socket!("Normal"), sp);
            let r = input_f(b, s, socket!("Roughness"), 0.0);
            if r >= 1e-5 {
                let on = crate::render::bsdf::oren_nayar::OrenNayar::new(r, c, dot(n, ctx.wo));
                out.push(LobeKind::OrenNayar(on), scale(c, w), n);
            } else {
                out.push(LobeKind::Diffuse, scale(c, w), n);
            }
        }
        BsdfKind::Translucent => {
            let c = input_c(b, s, socket!("Color"), [0.8; 3]);
            out.push(
                LobeKind::Translucent,
                scale(c, w),
                valid_n(sp, ctx, input_n(b, s, socket!("Normal"), sp)),
            );
        }
        BsdfKind::Transparent => {
            let c = input_c(b, s, socket!("Color"), [1.0; 3]);
            out.push(LobeKind::Transparent, scale(c, w), sp.normal);
        }
        BsdfKind::Holdout => {
            out.holdout = add(out.holdout, [w; 3]);
        }
        BsdfKind::RayPortal => {
            let c = input_c(b, s, socket!("Color"), [1.0; 3]);
            // Position is Cycles' LINK_POSITION socket: unlinked, the hit point.
            let position = match b.input_at(socket!("Position")) {
                Some((slot, true)) => finite3(v3(s, slot)),
                _ => sp.position,
            };
            let direction = input_c(b, s, socket!("Direction"), [0.0; 3]);
            let portal = RayPortal::new(sp.position, position, direction, sp.incoming);
            out.push(LobeKind::RayPortal(portal), scale(c, w), sp.normal);
        }
        BsdfKind::Glossy => glossy(b, w, s, sp, ctx, out),
        BsdfKind::Principled => principled(b, w, s, sp, ctx, out),
        BsdfKind::Metallic => crate::render::bsdf::metallic::metallic(b, w, s, sp, ctx, out),
        BsdfKind::Toon => {
            let c = input_c(b, s, socket!("Color"), [0.8; 3]);
            let toon = crate::render::bsdf::toon::Toon::new(
                input_f(b, s, socket!("Size"), 0.5),
                input_f(b, s, socket!("Smooth"), 0.0),
                b.property("component") == Some("GLOSSY"),
            );
            // Cycles gives the toon closures the normal as given (no specular correction).
            out.push(
                LobeKind::Toon(toon),
                scale(c, w),
                input_n(b, s, socket!("Normal"), sp),
            );
        }
        BsdfKind::Glass | BsdfKind::Refraction => {
            let c = input_c(b, s, socket!("Color"), [1.0; 3]);
            let ior = input_f(b, s, socket!("IOR"), 1.45);
            let r = input_f(b, s, socket!("Roughness"), 0.0);
            let n = valid_n(sp, ctx, input_n(b, s, socket!("Normal"), sp));
            let refract_only = b.kind == BsdfKind::Refraction;
            let g = crate::render::bsdf::microfacet::glass_closure(
                ctx.tables,
                b.property("distribution"),
                refract_only,
                r,
                ior,
                ctx.backfacing,
                dot(n, ctx.wo),
            );
            out.push(LobeKind::Glass(g), scale(c, w), n);
        }
        BsdfKind::Subsurface => {
            let c = input_c(b, s, socket!("Color"), [0.8; 3]);
            let radius = scale(
                input_c(b, s, socket!("Radius"), [1.0, 0.2, 0.1]),
                input_f(b, s, socket!("Scale"), 0.05),
            );
            let method = Method::from_property(b.property("falloff"));
            let ior = input_f(b, s, socket!("IOR"), 1.4);
            let r = input_f(b, s, socket!("Roughness"), 1.0);
            let aniso = input_f(b, s, socket!("Anisotropy"), 0.0);
            push_bssrdf(
                out,
                scale(c, w),
                radius,
                c,
                aniso,
                ior,
                r,
                method,
                valid_n(sp, ctx, input_n(b, s, socket!("Normal"), sp)),
            );
        }
        BsdfKind::Sheen => {
            let c = input_c(b, s, socket!("Color"), [0.8; 3]);
            let r = input_f(b, s, socket!("Roughness"), 0.5);
            let n = input_n(b, s, socket!("Normal"), sp);
            push_sheen_node(out, b.property("distribution"), scale(c, w), r, n, ctx.wo);
        }
        BsdfKind::Hair => hair_bsdf(b, w, s, sp, ctx, out),
        BsdfKind::PrincipledHair => principled_hair(b, w, s, sp, ctx, out),
        // Volume closures shade only a material's Volume (render/volume.rs).
        BsdfKind::Volume => {}
    }
}

/// Cycles' sd->dPdu and sd->dPdv where the hair closures read them: the curve's tangent
/// on hair; on a triangle its edges from the first corner (triangle_dPdudv), turned over
/// with the normals when seen from the back.
fn hair_frame(sp: &ShadingPoint) -> (V3, V3) {
    if sp.hair.is_strand > 0.0 {
        return (sp.dpdu, [0.0; 3]);
    }
    let t = &sp.triangle;
    let (u, v) = (sub(t[1], t[0]), sub(t[2], t[0]));
    if sp.backfacing {
        (neg(u), neg(v))
    } else {
        (u, v)
    }
}

/// Where the hit lies across the fibre (`hair::Across`): a ribbon's v, or on a mesh's
/// faces the true and shading normals.
fn across_fibre(sp: &ShadingPoint) -> crate::render::bsdf::hair::Across {
    use crate::render::bsdf::hair::Across;
    if sp.hair.thick {
        Across::Tube { n: sp.true_normal }
    } else if sp.hair.is_strand > 0.0 {
        Across::Ribbon {
            v: sp.parametric[1],
        }
    } else {
        Across::Surface {
            ng: sp.true_normal,
            n: sp.normal,
        }
    }
}

/// The Hair BSDF node as Cycles' svm_node_closure_bsdf sets it up: the tangent is the
/// linked Tangent input, or the curve's dP/du with the Offset negated; on a mesh's faces
/// the triangle's dP/dv, and no Offset.
fn hair_bsdf(b: &BsdfNode, w: f32, s: &[f32], sp: &ShadingPoint, ctx: &Context, out: &mut LobeSet) {
    let c = input_c(b, s, socket!("Color"), [0.8; 3]);
    let offset = -input_f(b, s, socket!("Offset"), 0.0);
    let (tangent, offset) = match b.input_at(socket!("Tangent")) {
        Some((slot, true)) => (normalize(finite3(v3(s, slot))), offset),
        _ if sp.hair.is_strand > 0.0 => (normalize(sp.dpdu), offset),
        _ => (normalize(hair_frame(sp).1), 0.0),
    };
    if is_zero(tangent) || !tangent.iter().all(|t| t.is_finite()) {
        return;
    }
    let hair = crate::render::bsdf::hair::Hair::new(
        tangent,
        input_f(b, s, socket!("RoughnessU"), 0.1),
        input_f(b, s, socket!("RoughnessV"), 1.0),
        offset,
        b.property("component") == Some("Transmission"),
    );
    out.push(
        LobeKind::Hair(hair),
        scale(c, w),
        valid_n(sp, ctx, sp.normal),
    );
}

/// The Principled Hair BSDF node as Cycles' svm_node_closure_bsdf sets it up: Random from
/// the linked input (a constant link reads as unlinked, as Cycles folds it) or else the
/// curve's random number, randomising Roughness (and the Chiang model's Radial
/// Roughness) and, for Melanin Concentration, the melanin; the absorption from the
/// parametrization (the Huang model takes its Roughness where Chiang's takes the Radial
/// Roughness); weight one (the colour is in the absorption).
fn principled_hair(
    b: &BsdfNode,
    w: f32,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
) {
    use crate::render::bsdf::hair_chiang::{self as chiang, Chiang};
    let huang = b.property("model") == Some("HUANG");
    let random = match b.input_at(socket!("Random")) {
        Some((slot, true)) => finite_or(s[slot as usize], 0.0),
        // The curve's random number (ATTR_STD_CURVE_RANDOM, as Hair Info > Random).
        _ => sp.hair.random,
    };
    let factor = 1.0 + 2.0 * (random - 0.5) * input_f(b, s, socket!("Random Roughness"), 0.0);
    let roughness = input_f(b, s, socket!("Roughness"), 0.3) * factor;
    let radial = if huang {
        roughness
    } else {
        input_f(b, s, socket!("Radial Roughness"), 0.3) * factor
    };
    let sigma = match b.property("parametrization") {
        Some("ABSORPTION") => input_c(
            b,
            s,
            socket!("Absorption Coefficient"),
            [0.245531, 0.52, 1.365],
        ),
        Some("MELANIN") => chiang::sigma_from_melanin(
            input_f(b, s, socket!("Melanin"), 0.8),
            input_f(b, s, socket!("Melanin Redness"), 1.0),
            input_c(b, s, socket!("Tint"), [1.0; 3]),
            random,
            input_f(b, s, socket!("Random Color"), 0.0),
            radial,
        ),
        _ => chiang::sigma_from_reflectance(
            input_c(b, s, socket!("Color"), [0.017513, 0.005763, 0.002059]),
            radial,
        ),
    };
    let offset = input_f(b, s, socket!("Offset"), 2f32.to_radians());
    let ior = input_f(b, s, socket!("IOR"), 1.55);
    if huang {
        huang_hair(b, w, s, sp, ctx, out, sigma, roughness, offset, ior);
        return;
    }
    let Some((c, y)) = Chiang::new(
        sigma,
        roughness,
        radial,
        input_f(b, s, socket!("Coat"), 0.0),
        offset,
        ior,
        hair_frame(sp).0,
        ctx.wo,
        across_fibre(sp),
    ) else {
        return;
    };
    out.push(LobeKind::Chiang(c), [w; 3], y);
}

/// The Huang model's closure (Cycles' svm_node_closure_bsdf and bsdf_hair_huang_setup):
/// none when every lobe multiplier is at most zero; on camera rays the half pixel over
/// the fibre's radius for the near field; Aspect Ratio about the curve's normal, which
/// particle hair lacks (Cycles then takes an arbitrary frame about the tangent); a hit
/// outside the fibre's projected width is transparent.
#[allow(clippy::too_many_arguments)]
fn huang_hair(
    b: &BsdfNode,
    w: f32,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
    sigma: V3,
    roughness: f32,
    offset: f32,
    ior: f32,
) {
    use crate::render::bsdf::hair_huang::{Huang, Params, Setup};
    // Reflection, Transmission and Secondary Reflection, by their identifiers.
    let lobes = [
        input_f(b, s, socket!("R lobe"), 1.0),
        input_f(b, s, socket!("TT lobe"), 1.0),
        input_f(b, s, socket!("TRT lobe"), 1.0),
    ];
    if lobes.iter().all(|&l| l <= 0.0) {
        return;
    }
    let radius = 0.5 * sp.hair.thickness;
    // Cycles' sd->dP: the compact differential the hit's dP/dx was expanded from.
    let dp = dot(sp.dp_dx, sp.dp_dx).sqrt();
    let pixel_coverage = if sp.path.flags & crate::shader::point::ray::CAMERA != 0 && radius > 0.0 {
        0.5 * dp / radius
    } else {
        1.0
    };
    let p = Params {
        sigma,
        roughness,
        offset,
        ior,
        aspect_ratio: input_f(b, s, socket!("Aspect Ratio"), 0.85),
        lobes,
    };
    match Huang::setup(
        &p,
        hair_frame(sp).0,
        ctx.wo,
        across_fibre(sp),
        sp.hair.curve_normal,
        pixel_coverage,
    ) {
        Some(Setup::Closure(c)) => out.push(LobeKind::Huang(c), [w; 3], c.n),
        Some(Setup::Transparent) => out.push(LobeKind::Transparent, [w; 3], sp.normal),
        None => {}
    }
}

/// The Glossy BSDF node (and the legacy Anisotropic BSDF): GGX, Multiscatter GGX or
/// Beckmann, isotropic or anisotropic.
fn glossy(b: &BsdfNode, w: f32, s: &[f32], sp: &ShadingPoint, ctx: &Context, out: &mut LobeSet) {
    let c = input_c(b, s, socket!("Color"), [0.8; 3]);
    let r = input_f(b, s, socket!("Roughness"), 0.5).clamp(0.0, 1.0);
    let n = valid_n(sp, ctx, input_n(b, s, socket!("Normal"), sp));
    if b.property("distribution") == Some("BECKMANN") {
        let r = crate::render::bsdf::microfacet::Reflection {
            dist: crate::render::bsdf::microfacet::Distribution::Beckmann,
            alpha: r * r,
            fresnel: Fresnel::Constant,
        };
        out.push(LobeKind::Reflection(r), scale(c, w), n);
        return;
    }
    let multi = is_multiggx(b);
    let mu = dot(n, ctx.wo).clamp(0.0, 1.0);
    let aniso = input_f(b, s, socket!("Anisotropy"), 0.0).clamp(-0.99, 0.99);
    // Multiscatter GGX takes the colour as its Fresnel (Cycles'
    // bsdf_microfacet_setup_fresnel_constant): a colour below white gets back less
    // of the energy lost between microfacets.
    let darkened = |table_roughness: f32| {
        let weight = scale(c, w);
        if multi {
            let fss = c.map(|x| x.max(0.0));
            mul(
                weight,
                multiscatter_darkening(ctx.tables, mu, table_roughness, fss),
            )
        } else {
            weight
        }
    };
    if aniso.abs() > 1e-4 {
        let (ax, ay) = crate::render::bsdf::anisotropic::glossy_alphas(r, aniso);
        let t = tangent_input(
            b,
            s,
            sp,
            socket!("Tangent"),
            input_f(b, s, socket!("Rotation"), 0.0),
            n,
        );
        push_glossy(
            out,
            ctx,
            ax,
            ay,
            t,
            Fresnel::Constant,
            multi,
            darkened((ax * ay).sqrt().sqrt()),
            n,
            1.0,
        );
        return;
    }
    let energy = if multi {
        multiscatter_energy(ctx.tables, mu, r)
    } else {
        1.0
    };
    out.push(
        LobeKind::Glossy {
            alpha: r * r,
            fresnel: Fresnel::Constant,
            energy,
        },
        darkened(r),
        n,
    );
}

// Long because it follows Cycles' Principled BSDF node layer by layer.
fn principled(
    b: &BsdfNode,
    w: f32,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
) {
    let base = input_c(b, s, socket!("Base Color"), [0.8; 3]).map(|x| x.max(0.0));
    let metallic = input_f(b, s, socket!("Metallic"), 0.0).clamp(0.0, 1.0);
    let roughness = input_f(b, s, socket!("Roughness"), 0.5).clamp(0.0, 1.0);
    let ior = input_f(b, s, socket!("IOR"), 1.5).max(1e-5);
    let alpha = input_f(b, s, socket!("Alpha"), 1.0).clamp(0.0, 1.0);
    let transmission = input_f(b, s, socket!("Transmission Weight"), 0.0).clamp(0.0, 1.0);
    let spec_level = input_f(b, s, socket!("Specular IOR Level"), 0.5).max(0.0);
    let spec_tint = input_c(b, s, socket!("Specular Tint"), [1.0; 3]).map(|x| x.max(0.0));
    // Cycles clamps the base colour to 1 for the layers that must conserve energy
    // (metallic F0, transmission tint, subsurface); only the diffuse takes it unclamped.
    let clamped = base.map(|x| x.min(1.0));
    let n = input_n(b, s, socket!("Normal"), sp);
    // The reflecting layers and the BSSRDF use the bump-corrected normal; diffuse and
    // sheen the normal as given (Cycles' valid_reflection_N).
    let vn = valid_n(sp, ctx, n);
    let mut weight = [w; 3];
    if alpha < 1.0 {
        out.push(LobeKind::Transparent, [w * (1.0 - alpha); 3], sp.normal);
        weight = scale(weight, alpha);
    }
    let mu = dot(vn, ctx.wo).clamp(0.0, 1.0);
    // The Principled's distribution: Multiscatter GGX (the default) compensates the
    // metallic, specular and transmission lobes for energy lost between microfacets; GGX
    // does not (Cycles' is_multiggx).
    let multi = is_multiggx(b);
    let energy = if multi {
        multiscatter_energy(ctx.tables, mu, roughness)
    } else {
        1.0
    };
    let a = roughness * roughness;
    // Anisotropic metallic and specular layers (alphas stretched along the tangent).
    let (ax, ay) = crate::render::bsdf::anisotropic::principled_alphas(
        roughness,
        input_f(b, s, socket!("Anisotropic"), 0.0),
    );
    let tangent = if ax != ay {
        tangent_input(
            b,
            s,
            sp,
            socket!("Tangent"),
            input_f(b, s, socket!("Anisotropic Rotation"), 0.0),
            n,
        )
    } else {
        [0.0; 3]
    };
    let coat = input_f(b, s, socket!("Coat Weight"), 0.0).clamp(0.0, 1.0);
    // Thin film (4.2+): on the dielectric specular layer and the transmission; Cycles 4.5
    // leaves the metallic layer without it.
    let film_thickness = input_f(b, s, socket!("Thin Film Thickness"), 0.0).max(1e-5);
    let film_ior = input_f(b, s, socket!("Thin Film IOR"), 1.33).max(1e-5);
    let film = film_thickness > crate::render::bsdf::thin_film::CUTOFF;
    weight = principled_sheen(b, s, sp, ctx, out, weight, n, coat);
    if coat > 0.0 {
        weight = principled_coat(b, s, sp, ctx, out, weight, coat);
    }
    // Emission below alpha, sheen and coat, above the rest (Cycles' emission_setup with
    // the layered weight); colour and strength unclamped.
    let emission = scale(
        input_c(b, s, socket!("Emission Color"), [1.0; 3]),
        input_f(b, s, socket!("Emission Strength"), 0.0),
    );
    out.emission = add(out.emission, finite3(mul(emission, weight)));
    if metallic > 0.0 {
        // F82-tint Schlick: b chosen so F(acos 1/7) = Schlick * tint.
        let f = 6.0f32 / 7.0;
        let f6 = f.powi(6);
        let mut bb = [0.0; 3];
        for k in 0..3 {
            let schlick = clamped[k] + (1.0 - clamped[k]) * f.powi(5);
            bb[k] = schlick * (1.0 - spec_tint[k]) * 7.0 / f6;
        }
        let avg_f0 = (clamped[0] + clamped[1] + clamped[2]) / 3.0;
        let albedo = (avg_f0 + (1.0 - avg_f0) / 21.0).clamp(0.0, 1.0);
        let mut metal_weight = scale(weight, metallic);
        if multi {
            // Cycles darkens the compensation by the F82 model's average Fresnel.
            let fss = crate::render::bsdf::metallic::f82_fss(clamped, bb);
            let table_roughness = (ax * ay).sqrt().sqrt();
            metal_weight = mul(
                metal_weight,
                multiscatter_darkening(ctx.tables, mu, table_roughness, fss),
            );
        }
        if ax != ay {
            push_glossy(
                out,
                ctx,
                ax,
                ay,
                tangent,
                Fresnel::F82 { f0: clamped, b: bb },
                multi,
                metal_weight,
                vn,
                albedo.max(1e-3),
            );
        } else {
            out.push_scaled(
                LobeKind::Glossy {
                    alpha: a,
                    fresnel: Fresnel::F82 { f0: clamped, b: bb },
                    energy,
                },
                metal_weight,
                vn,
                albedo.max(1e-3),
            );
        }
        weight = scale(weight, 1.0 - metallic);
    }
    if transmission > 0.0 {
        // Rough glass: reflection tinted by the specular tint, refraction by sqrt of the base
        // colour (light crosses the surface twice), as Cycles' Principled sets it up.
        let mut g = crate::render::bsdf::microfacet::glass_closure(
            ctx.tables,
            Some(if multi { "MULTI_GGX" } else { "GGX" }),
            false,
            roughness,
            ior,
            ctx.backfacing,
            mu,
        );
        g.tint_r = spec_tint;
        g.tint_t = clamped.map(f32::sqrt);
        if film {
            // Cycles' film IOR is relative to the side the light comes from: film / ior
            // seen from inside. The specular tint scales the film's reflectance instead.
            let f0 = crate::render::bsdf::f0_from_ior(ior);
            let film_eta = if ctx.backfacing {
                film_ior / ior
            } else {
                film_ior
            };
            g.film = Some(crate::render::bsdf::thin_film::ThinFilm {
                thickness: film_thickness,
                ior: film_eta,
                eta: g.eta,
                f0_scale: spec_tint.map(|t| (f0 * t).min(1.0) / f0),
            });
            g.tint_r = [1.0; 3];
        }
        out.push(LobeKind::Glass(g), scale(weight, transmission), vn);
        weight = scale(weight, 1.0 - transmission);
    }
    // Dielectric specular: IOR adjusted by the specular IOR level as Cycles does.
    let mut eta = ior;
    if spec_level != 0.5 {
        // Cycles' ior_from_F0 clamps F0 to 0.99.
        let f0 = (crate::render::bsdf::f0_from_ior(ior) * 2.0 * spec_level).clamp(0.0, 0.99);
        let sq = f0.sqrt();
        eta = (1.0 + sq) / (1.0 - sq);
        if ior < 1.0 {
            eta = 1.0 / eta;
        }
    }
    if film && max3(weight) > 0.0 {
        principled_film_specular(
            ctx,
            out,
            &mut weight,
            ior,
            eta,
            spec_level,
            spec_tint,
            (film_thickness, film_ior),
            (a, ax, ay, tangent, energy, multi),
            vn,
            mu,
        );
    } else if spec_level > 0.0 && max3(weight) > 0.0 {
        // Anisotropic: the albedo tables at Cycles' equivalent roughness (alpha_x alpha_y)^(1/4).
        let table_roughness = if ax != ay {
            (ax * ay).sqrt().sqrt()
        } else {
            roughness
        };
        let e = ctx
            .tables
            .dielectric_fresnel_avg(mu, table_roughness, eta)
            .clamp(0.0, 1.0);
        // Multiscatter: Cycles' generalized-Schlick Fss, the lobe's F0 (tinted) blended
        // towards one as far as the dielectric's average Fresnel lies from its F0.
        let darkening = if multi {
            let f0 = crate::render::bsdf::f0_from_ior(eta);
            let s_blend = ((dielectric_fss(eta) - f0) / (1.0 - f0)).clamp(0.0, 1.0);
            let fss = spec_tint.map(|t| {
                let tf0 = (f0 * t).clamp(0.0, 1.0);
                tf0 + (1.0 - tf0) * s_blend
            });
            multiscatter_darkening(ctx.tables, mu, table_roughness, fss)
        } else {
            [1.0; 3]
        };
        // Cycles' generalized Schlick: F0 (the level's, times the tint) at normal
        // incidence, white at grazing. Untinted it is the plain dielectric Fresnel of eta.
        let (fresnel, lobe_weight, albedo) = if spec_tint == [1.0; 3] {
            (Fresnel::Dielectric { eta }, mul(weight, darkening), [e; 3])
        } else {
            let f0 = crate::render::bsdf::f0_from_ior(ior) * 2.0 * spec_level;
            let f0t = spec_tint.map(|t| (f0 * t).clamp(0.0, 1.0));
            let real_f0 = crate::render::bsdf::f0_from_ior(eta);
            let s = ((e - real_f0) / (1.0 - real_f0)).clamp(0.0, 1.0);
            (
                Fresnel::Schlick { f0: f0t, eta },
                mul(weight, darkening),
                f0t.map(|f| f + (1.0 - f) * s),
            )
        };
        let sel = average(albedo).max(1e-3);
        if ax != ay {
            push_glossy(
                out,
                ctx,
                ax,
                ay,
                tangent,
                fresnel,
                multi,
                lobe_weight,
                vn,
                sel,
            );
        } else {
            out.push_scaled(
                LobeKind::Glossy {
                    alpha: a,
                    fresnel,
                    energy,
                },
                lobe_weight,
                vn,
                sel,
            );
        }
        // Attenuate the layers below by the specular layer's albedo (Cycles' bsdf_albedo:
        // the closure weight, darkening included, times the estimated albedo).
        let albedo = mul(albedo, darkening);
        weight = scale(weight, (1.0 - max3(albedo)).clamp(0.0, 1.0));
    }
    let ss = input_f(b, s, socket!("Subsurface Weight"), 0.0).clamp(0.0, 1.0);
    if ss > 0.0 {
        let radius = scale(
            input_c(b, s, socket!("Subsurface Radius"), [1.0, 0.2, 0.1]),
            input_f(b, s, socket!("Subsurface Scale"), 0.05),
        );
        let method = Method::from_property(b.property("subsurface_method"));
        // Random Walk (Skin) has its own IOR input; the other methods use the BSDF's.
        let ss_ior = if method == Method::RandomWalkSkin {
            input_f(b, s, socket!("Subsurface IOR"), 1.4)
        } else {
            ior
        };
        let aniso = input_f(b, s, socket!("Subsurface Anisotropy"), 0.0);
        push_bssrdf(
            out,
            scale(mul(weight, clamped), ss),
            radius,
            clamped,
            aniso,
            ss_ior,
            roughness,
            method,
            vn,
        );
        weight = scale(weight, 1.0 - ss);
    }
    let diffuse_roughness = input_f(b, s, socket!("Diffuse Roughness"), 0.0);
    if diffuse_roughness >= 1e-5 {
        let on = crate::render::bsdf::oren_nayar::OrenNayar::new(
            diffuse_roughness,
            base,
            dot(n, ctx.wo),
        );
        out.push(LobeKind::OrenNayar(on), mul(weight, base), n);
        return;
    }
    out.push(LobeKind::Diffuse, mul(weight, base), n);
}

/// The Principled dielectric specular layer under a thin film. Its Fresnel is the film's
/// (f0 / F0 scaling for the Specular Tint and IOR Level, as Cycles' generalized Schlick);
/// Cycles estimates its albedo, for the selection weight and for darkening the layers
/// below, by the film's reflectance toward the viewer (no table fits iridescence), and
/// keeps the film-free multiple-scattering compensation.
#[allow(clippy::too_many_arguments)]
fn principled_film_specular(
    ctx: &Context,
    out: &mut LobeSet,
    weight: &mut V3,
    ior: f32,
    eta: f32,
    spec_level: f32,
    spec_tint: V3,
    (thickness, film_ior): (f32, f32),
    (a, ax, ay, tangent, energy, multi): (f32, f32, f32, V3, f32, bool),
    vn: V3,
    mu: f32,
) {
    let f0_real = crate::render::bsdf::f0_from_ior(eta);
    let f0 = crate::render::bsdf::f0_from_ior(ior) * 2.0 * spec_level;
    let f0_scale = if f0_real > 0.0 {
        spec_tint.map(|t| (f0 * t).clamp(0.0, 1.0) / f0_real)
    } else {
        [1.0; 3]
    };
    let tf = crate::render::bsdf::thin_film::ThinFilm {
        thickness,
        ior: film_ior,
        eta,
        f0_scale,
    };
    let albedo = tf.eval(mu);
    let sel = average(albedo).max(1e-3);
    if ax != ay {
        push_glossy(
            out,
            ctx,
            ax,
            ay,
            tangent,
            Fresnel::ThinFilm(tf),
            multi,
            *weight,
            vn,
            sel,
        );
    } else {
        out.push_scaled(
            LobeKind::Glossy {
                alpha: a,
                fresnel: Fresnel::ThinFilm(tf),
                energy,
            },
            *weight,
            vn,
            sel,
        );
    }
    *weight = scale(*weight, (1.0 - max3(albedo)).clamp(0.0, 1.0));
}

/// A BSSRDF closure after Cycles' `bssrdf_setup`: its selection weight counts every
/// channel, channels with no radius become diffuse.
#[allow(clippy::too_many_arguments)]
fn push_bssrdf(
    out: &mut LobeSet,
    weight: V3,
    radius: V3,
    albedo: V3,
    aniso: f32,
    ior: f32,
    roughness: f32,
    method: Method,
    n: V3,
) {
    let (bssrdf, diffuse, channels) =
        crate::render::subsurface::setup(weight, radius, albedo, aniso, ior, roughness, method);
    if !is_zero(diffuse) {
        out.push(LobeKind::Diffuse, diffuse, n);
    }
    if let Some((b, w)) = bssrdf {
        let before = out.len;
        out.push(LobeKind::Subsurface(b), w, n);
        if out.len > before {
            out.lobes[before].sample_weight *= channels as f32;
        }
    }
}

/// Principled coat as Cycles 4.x layers it: a dielectric GGX lobe (Multiscatter) on top,
/// the layers below attenuated by its albedo and by the coat tint along the refracted
/// path (tint^(1 / cos) mixed by the coat weight). Returns the weight left for them.
fn principled_coat(
    b: &BsdfNode,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
    weight: V3,
    coat: f32,
) -> V3 {
    let rough = input_f(b, s, socket!("Coat Roughness"), 0.03).clamp(0.0, 1.0);
    let coat_ior = input_f(b, s, socket!("Coat IOR"), 1.5).max(1.0);
    let tint = input_c(b, s, socket!("Coat Tint"), [1.0; 3]).map(|x| x.max(0.0));
    let n = valid_n(sp, ctx, input_n(b, s, socket!("Coat Normal"), sp));
    let mu = dot(n, ctx.wo).clamp(0.0, 1.0);
    let energy = multiscatter_energy(ctx.tables, mu, rough);
    let e = ctx
        .tables
        .dielectric_fresnel_avg(mu, rough, coat_ior)
        .clamp(0.0, 1.0);
    // Cycles always compensates the coat, darkened by its dielectric Fss.
    let darkening = multiscatter_darkening(ctx.tables, mu, rough, [dielectric_fss(coat_ior); 3]);
    out.push_scaled(
        LobeKind::Glossy {
            alpha: rough * rough,
            fresnel: Fresnel::Dielectric { eta: coat_ior },
            energy,
        },
        mul(scale(weight, coat), darkening),
        n,
        e.max(1e-3),
    );
    // The layers below see the coat's albedo, darkening included (Cycles' bsdf_albedo).
    let mut below = scale(weight, (1.0 - coat * e * darkening[0]).clamp(0.0, 1.0));
    if tint != [1.0; 3] {
        let cos_t = (1.0 - (1.0 - mu * mu) / (coat_ior * coat_ior))
            .max(1e-6)
            .sqrt();
        let depth = 1.0 / cos_t;
        below = mul(below, tint.map(|t| 1.0 - coat + coat * t.powf(depth)));
    }
    below
}

/// The Sheen BSDF node: microfiber sheen (the default) or Ashikhmin velvet.
fn push_sheen_node(
    out: &mut LobeSet,
    distribution: Option<&str>,
    weight: V3,
    roughness: f32,
    n: V3,
    wo: V3,
) {
    let r = roughness.clamp(0.0, 1.0);
    if distribution == Some("ASHIKHMIN") {
        out.push(
            LobeKind::Velvet(crate::render::bsdf::sheen::Velvet::new(r)),
            weight,
            n,
        );
        return;
    }
    let (sheen, albedo) = crate::render::bsdf::sheen::Sheen::new(n, wo, r);
    out.push(LobeKind::Sheen(sheen), scale(weight, albedo), n);
}

/// Principled sheen as Cycles 4.x layers it: the first layer, a microfiber sheen of
/// weight x tint about the normal leaned toward the coat normal by the coat weight; the
/// layers below are scaled by 1 - max(its albedo). Returns the weight left for them.
#[allow(clippy::too_many_arguments)]
fn principled_sheen(
    b: &BsdfNode,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
    weight: V3,
    n: V3,
    coat: f32,
) -> V3 {
    let sheen_w = input_f(b, s, socket!("Sheen Weight"), 0.0).max(0.0);
    if sheen_w <= 1e-5 {
        return weight;
    }
    let tint = input_c(b, s, socket!("Sheen Tint"), [1.0; 3]).map(|x| x.max(0.0));
    let r = input_f(b, s, socket!("Sheen Roughness"), 0.5).clamp(0.0, 1.0);
    let coat_n = input_n(b, s, socket!("Coat Normal"), sp);
    let sn = normalize(add(scale(n, 1.0 - coat), scale(coat_n, coat)));
    let sn = if is_zero(sn) || !sn.iter().all(|x| x.is_finite()) {
        n
    } else {
        sn
    };
    let lobe_w = mul(scale(weight, sheen_w), tint);
    if lobe_w[0].abs() + lobe_w[1].abs() + lobe_w[2].abs() <= 1e-5 {
        return weight;
    }
    let (sheen, albedo) = crate::render::bsdf::sheen::Sheen::new(sn, ctx.wo, r);
    out.push(LobeKind::Sheen(sheen), scale(lobe_w, albedo), sn);
    // Cycles' closure_layering_weight: albedo over weight is sheen weight x tint x albedo.
    let layer = scale(tint, sheen_w * albedo);
    scale(weight, (1.0 - max3(layer)).clamp(0.0, 1.0))
}

/// The tangent of an anisotropic closure: the node's Tangent input when linked, else
/// Cycles' default (Geometry > Tangent: radial about the object's Z), rotated about the
/// closure normal `n` by `rotation` turns.
pub(crate) fn tangent_input(
    b: &BsdfNode,
    s: &[f32],
    sp: &ShadingPoint,
    id: usize,
    rotation: f32,
    n: V3,
) -> V3 {
    let t = match b.input_at(id) {
        Some((slot, true)) => finite3(v3(s, slot)),
        _ => crate::shader::inputs::radial_tangent(sp, 2),
    };
    if rotation != 0.0 {
        crate::render::bsdf::anisotropic::rotate_around_axis(t, n, rotation * std::f32::consts::TAU)
    } else {
        t
    }
}

/// A GGX reflection lobe with alphas (`ax`, `ay`) along tangent `t`: anisotropic unless
/// singular, Multiscatter energy from the isotropic table at (ax ay)^(1/4) when `multi`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn push_glossy(
    out: &mut LobeSet,
    ctx: &Context,
    ax: f32,
    ay: f32,
    t: V3,
    fresnel: Fresnel,
    multi: bool,
    weight: V3,
    n: V3,
    albedo: f32,
) {
    let lobe = crate::render::bsdf::anisotropic::AnisoGgx::new(n, t, ax, ay);
    let mu = dot(n, ctx.wo).clamp(0.0, 1.0);
    let energy = if multi {
        multiscatter_energy(ctx.tables, mu, lobe.table_roughness())
    } else {
        1.0
    };
    if lobe.singular() {
        out.push_scaled(
            LobeKind::Glossy {
                alpha: (ax * ay).sqrt(),
                fresnel,
                energy,
            },
            weight,
            n,
            albedo,
        );
    } else {
        out.push_scaled(
            LobeKind::GlossyAniso {
                lobe,
                fresnel,
                energy,
            },
            weight,
            n,
            albedo,
        );
    }
}
