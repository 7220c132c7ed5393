//! Metallic BSDF (Blender 4.3+) in its F82 Tint mode, as Cycles' CLOSURE_BSDF_F82_CONDUCTOR
//! (svm/closure.h): one GGX reflection (Multiscatter GGX compensated) with the F82-tint
//! Fresnel of the Principled BSDF's metallic layer, Base Color and Edge Tint clamped to
//! [0, 1], anisotropy as the Principled stretches it. The Physical Conductor mode and
//! the Beckmann distribution are compile errors naming the node
//! (shader/compile/node_table.rs).

use crate::shader::program::BsdfNode;
use crate::shader::ShadingPoint;

use crate::render::bsdf::{Fresnel, LobeKind, LobeSet};
use crate::render::integrator::shade::{
    input_c, input_f, input_n, is_multiggx, multiscatter_energy, push_glossy, tangent_input,
    valid_n, Context,
};

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

/// The Metallic BSDF node's lobe, weighted `w`.
pub(crate) fn metallic(
    b: &BsdfNode,
    w: f32,
    s: &[f32],
    sp: &ShadingPoint,
    ctx: &Context,
    out: &mut LobeSet,
) {
    let unit = |c: [f32; 3]| c.map(|x| x.clamp(0.0, 1.0));
    let color = unit(input_c(b, s, "Base Color", [0.617, 0.577, 0.54]));
    let tint = unit(input_c(b, s, "Edge Tint", [0.695, 0.726, 0.77]));
    let roughness = input_f(b, s, "Roughness", 0.5).clamp(0.0, 1.0);
    let n = input_n(b, s, "Normal", sp);
    let vn = valid_n(sp, ctx, n);
    let multi = is_multiggx(b);
    let fresnel = f82_tint(color, tint);
    // The lobe's sampling weight, as the Principled's metallic layer estimates it.
    let avg_f0 = (color[0] + color[1] + color[2]) / 3.0;
    let albedo = (avg_f0 + (1.0 - avg_f0) / 21.0).clamp(0.0, 1.0).max(1e-3);
    let (ax, ay) = crate::render::bsdf::anisotropic::principled_alphas(
        roughness,
        input_f(b, s, "Anisotropy", 0.0),
    );
    if ax != ay {
        let t = tangent_input(b, s, sp, "Tangent", input_f(b, s, "Rotation", 0.0), n);
        push_glossy(out, ctx, ax, ay, t, fresnel, multi, [w; 3], vn, albedo);
        return;
    }
    let mu = crate::render::math::dot(vn, ctx.wo).clamp(0.0, 1.0);
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
        [w; 3],
        vn,
        albedo,
    );
}
