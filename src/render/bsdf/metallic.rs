//! Metallic BSDF (Blender 4.3+), as Cycles' CLOSURE_BSDF_F82_CONDUCTOR and
//! CLOSURE_BSDF_PHYSICAL_CONDUCTOR (svm/closure.h): one microfacet reflection with the
//! F82-tint Fresnel of the Principled BSDF's metallic layer (Base Color and Edge Tint
//! clamped to [0, 1]) or a physical conductor's (IOR and Extinction, clamped at 0:
//! Cycles' fresnel_conductor). GGX and Multiscatter GGX (energy compensated, coloured by
//! the Fresnel's average as Cycles' microfacet_ggx_preserve_energy), anisotropy as the
//! Principled stretches it; Beckmann isotropic (anisotropic Beckmann is a compile error
//! naming the node, shader/compile/node_table.rs).

use crate::shader::program::{socket, BsdfNode};
use crate::shader::ShadingPoint;

use crate::render::bsdf::{fresnel_conductor, Fresnel, LobeKind, LobeSet};
use crate::render::integrator::shade::{
    input_c, input_f, input_n, is_multiggx, multiscatter_darkening, multiscatter_energy,
    push_glossy, tangent_input, valid_n, Context,
};
use crate::render::math::Vec3;

/// F82-tint Schlick (Cycles' bsdf_microfacet_setup_fresnel_f82_tint): `b` chosen so that
/// F(acos 1/7) = Schlick's value there times `tint`.
pub fn f82_tint(f0: [f32; 3], tint: [f32; 3]) -> Fresnel {
    let f = 6.0f32 / 7.0;
    let f6 = f.powi(6);
    let mut b = [0.0; 3];
    for k in 0..3 {
        let schlick = f0[k] + (1.0 - f0[k]) * f.powi(5);
        b[k] = schlick * (1.0 - tint[k]) * 7.0 / f6;
    }
    Fresnel::F82 { f0, b }
}

/// Cycles' fresnel_f82_B: the F82 model's `b` from its values at 0 and acos(1/7).
fn f82_b(f0: [f32; 3], f82: [f32; 3]) -> [f32; 3] {
    let f = 6.0f32 / 7.0;
    let f5 = f.powi(5);
    std::array::from_fn(|k| 7.0 / (f5 * f) * (f0[k] + (1.0 - f0[k]) * f5 - f82[k]))
}

/// Cycles' fresnel_f82_Fss: the F82 model's average single-scattering Fresnel.
pub(crate) fn f82_fss(f0: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|k| f0[k] + (1.0 - f0[k]) / 21.0 - b[k] / 126.0)
}

/// The Fresnel of the node's mode and its average single-scattering value (Cycles'
/// fresnel_conductor_Fss fits the F82 model to the conductor at 0 and acos(1/7)).
fn fresnel_of(b: &BsdfNode, s: &[f32]) -> (Fresnel, [f32; 3]) {
    if b.property("fresnel_type") == Some("PHYSICAL_CONDUCTOR") {
        let non_negative = |c: [f32; 3]| c.map(|x| x.max(0.0));
        let eta = non_negative(input_c(b, s, socket!("IOR"), [2.757, 2.513, 2.231]));
        let k = non_negative(input_c(b, s, socket!("Extinction"), [3.867, 3.404, 3.009]));
        let f0 = fresnel_conductor(1.0, eta.into(), k.into()).into();
        let f82 = fresnel_conductor(1.0 / 7.0, eta.into(), k.into()).into();
        let fss = f82_fss(f0, f82_b(f0, f82)).map(|x| x.clamp(0.0, 1.0));
        return (Fresnel::Conductor { eta, k }, fss);
    }
    let unit = |c: [f32; 3]| c.map(|x| x.clamp(0.0, 1.0));
    let color = unit(input_c(b, s, socket!("Base Color"), [0.617, 0.577, 0.54]));
    let tint = unit(input_c(b, s, socket!("Edge Tint"), [0.695, 0.726, 0.77]));
    let fresnel = f82_tint(color, tint);
    let Fresnel::F82 { f0, b: bb } = fresnel else {
        unreachable!("f82_tint gives an F82 Fresnel")
    };
    (fresnel, f82_fss(f0, bb))
}

/// The Metallic BSDF node's lobe, weighted `w`.
pub(crate) fn metallic(
    b: &BsdfNode,
    w: f32,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
) {
    let roughness = input_f(b, s, socket!("Roughness"), 0.5).clamp(0.0, 1.0);
    let n = input_n(b, s, socket!("Normal"), sp);
    let vn = valid_n(sp, ctx, n);
    let multi = is_multiggx(b);
    let (fresnel, fss) = fresnel_of(b, s);
    // The lobe's sampling weight: its average single-scattering reflectance.
    let albedo = ((fss[0] + fss[1] + fss[2]) / 3.0).clamp(1e-3, 1.0);
    let mu = Vec3::from(vn).dot(ctx.wo.into()).clamp(0.0, 1.0);
    if b.property("distribution") == Some("BECKMANN") {
        // Anisotropic Beckmann is refused at compile time (shader/compile/node_table.rs).
        let r = crate::render::bsdf::microfacet::Reflection {
            dist: crate::render::bsdf::microfacet::Distribution::Beckmann,
            alpha: roughness * roughness,
            fresnel,
        };
        out.push_scaled(LobeKind::Reflection(r), [w; 3], vn, albedo);
        return;
    }
    let (ax, ay) = crate::render::bsdf::anisotropic::principled_alphas(
        roughness,
        input_f(b, s, socket!("Anisotropy"), 0.0),
    );
    let weight = if multi {
        let rough = (ax * ay).sqrt().sqrt();
        multiscatter_darkening(ctx.tables, mu, rough, fss).map(|x| x * w)
    } else {
        [w; 3]
    };
    if ax != ay {
        let t = tangent_input(
            b,
            s,
            sp,
            socket!("Tangent"),
            input_f(b, s, socket!("Rotation"), 0.0),
            n,
        );
        push_glossy(out, ctx, ax, ay, t, fresnel, multi, weight, vn, albedo);
        return;
    }
    let energy = if multi {
        multiscatter_energy(ctx.tables, mu, roughness)
    } else {
        1.0
    };
    out.push_scaled(
        LobeKind::Glossy {
            alpha: roughness * roughness,
            fresnel,
            energy,
        },
        weight,
        vn,
        albedo,
    );
}
