//! What Cycles does about bumped normals (kernel/closure/bsdf_util.h, bsdf.h):
//! - the bump map correction (`ensure_valid_specular_reflection`, applied through
//!   `maybe_ensure_valid_specular_reflection` when the material's "Bump Map Correction"
//!   is on): a shading normal whose mirror reflection of the incoming direction would dip
//!   below the true surface is raised toward the geometric normal until the reflection
//!   just clears it. Reflecting closures, glass, translucent and BSSRDFs get it; the
//!   BSSRDF's is the normal a subsurface exit lights with.
//! - the bump shadowing term (`bump_shadowing_term`, after Conty Estevez et al., "A
//!   Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem"): light
//!   reaching a bumped closure from across the smooth surface is cut, and diffuse closures
//!   are darkened toward grazing light.

use crate::render::math::*;

/// The corrected normal for geometric normal `ng`, direction toward the viewer `i` (on
/// `ng`'s side) and shading normal `n`; `n` itself when its reflection is valid.
pub fn ensure_valid_specular_reflection(ng: V3, i: V3, n: V3) -> V3 {
    ensure_valid(ng.into(), i.into(), n.into()).into()
}

fn ensure_valid(ng: Vec3, i: Vec3, n: Vec3) -> Vec3 {
    let r = n * (2.0 * n.dot(i)) - i;
    let iz = i.dot(ng);
    // A reflection may be as shallow as the incoming ray, up to 0.01.
    let threshold = (0.9 * iz).min(0.01);
    if ng.dot(r) >= threshold {
        return n;
    }
    // In the plane of ng and n: x is n's part across ng, and n' = nx x + nz ng solves
    // 2 (n'.i) n'.z - i.z = threshold, the root with the sign Cycles takes.
    let across = n - ng * n.dot(ng);
    let l = across.length();
    let x = if l > 0.0 { across * (1.0 / l) } else { n };
    let ix = i.dot(x);
    let a = ix * ix + iz * iz;
    let b = 2.0 * (a + iz * threshold);
    let c = (threshold + iz) * (threshold + iz);
    let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
    let nz2 = if ix < 0.0 {
        0.25 * (b + disc) / a
    } else {
        0.25 * (b - disc) / a
    };
    let nx = (1.0 - nz2).max(0.0).sqrt();
    let nz = nz2.max(0.0).sqrt();
    x * nx + ng * nz
}

/// Cycles' `bump_shadowing_term` for a closure of normal `n` on a surface of smooth
/// shading normal `ns`, light toward `i`. Any closure whose normal is bumped across the
/// smooth surface relative to the light gets 0 (light leaking to the far side); a diffuse
/// one (`diffuse`) is further faded by a GGX shadowing term whose roughness grows with
/// the bump's tilt, when the material's bump map correction (`soften`) is on.
pub fn bump_shadowing_term(ns: Vec3, n: Vec3, i: Vec3, diffuse: bool, soften: bool) -> f32 {
    if n == ns {
        return 1.0;
    }
    let cos_si = ns.dot(i);
    let cos_sn = ns.dot(n);
    if cos_si * cos_sn * n.dot(i) < 0.0 {
        return 0.0;
    }
    if !diffuse || !soften {
        return 1.0;
    }
    let (cos_i, cos_d) = (cos_si.abs(), cos_sn.abs());
    if cos_d >= 1.0 || cos_i >= 1.0 {
        return 1.0;
    }
    if cos_i < 1e-6 {
        return 0.0;
    }
    let tan2_d = 1.0 / (cos_d * cos_d) - 1.0;
    let alpha2 = (0.125 * tan2_d).clamp(0.0, 1.0);
    // Smith G1 of GGX.
    let lambda = 0.5 * ((1.0 + alpha2 * (1.0 / (cos_i * cos_i) - 1.0).max(0.0)).sqrt() - 1.0);
    1.0 / (1.0 + lambda)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reflect(n: Vec3, i: Vec3) -> Vec3 {
        n * (2.0 * n.dot(i)) - i
    }

    #[test]
    fn valid_normals_are_kept_and_invalid_ones_raised_to_the_threshold() {
        let ng = Vec3::Z;
        // Head-on view: a normal within 45 degrees of ng reflects above the surface.
        let i = ng;
        let n = vec3(0.5, 0.0, 1.0).normalize();
        assert_eq!(ensure_valid(ng, i, n), n);
        // Tilted 70 degrees: raised until the reflection's height is the threshold 0.01.
        let n = vec3(2.75, 0.0, 1.0).normalize();
        let c = ensure_valid(ng, i, n);
        assert!((c.length() - 1.0).abs() < 1e-5);
        assert!((reflect(c, i).dot(ng) - 0.01).abs() < 1e-4, "{c:?}");
        assert!(
            c[1].abs() < 1e-6 && c[0] > 0.0,
            "stays in the plane of ng and n: {c:?}"
        );
        // Grazing view from the side the normal leans away from.
        let i = vec3(-1.0, 0.3, 0.2).normalize();
        let n = vec3(1.0, 0.2, 0.6).normalize();
        assert!(reflect(n, i).dot(ng) < 0.0);
        let c = ensure_valid(ng, i, n);
        let t = (0.9 * i.dot(ng)).min(0.01);
        assert!((reflect(c, i).dot(ng) - t).abs() < 1e-4, "{c:?}");
    }

    #[test]
    fn bump_shadowing_cuts_leaks_and_fades_diffuse_light() {
        let ns = Vec3::Z;
        let n = vec3(0.6, 0.0, 0.8).normalize();
        // Unbumped closures are untouched.
        assert_eq!(
            bump_shadowing_term(ns, ns, vec3(1.0, 0.0, -0.1).normalize(), true, true),
            1.0
        );
        // Light below the smooth surface but above the bumped normal: cut for every closure.
        let below = vec3(1.0, 0.0, -0.1).normalize();
        assert!(n.dot(below) > 0.0);
        assert_eq!(bump_shadowing_term(ns, n, below, false, true), 0.0);
        // Glossy closures and uncorrected materials get no fading.
        let i = vec3(-0.3, 0.0, 1.0).normalize();
        assert_eq!(bump_shadowing_term(ns, n, i, false, true), 1.0);
        assert_eq!(bump_shadowing_term(ns, n, i, true, false), 1.0);
        // Diffuse: GGX G1 at the light's angle to the smooth normal, alpha^2 = tan^2(tilt) / 8.
        let (cos_i, cos_d) = (ns.dot(i), ns.dot(n));
        let a2 = (1.0 / (cos_d * cos_d) - 1.0) / 8.0;
        let t2 = 1.0 / (cos_i * cos_i) - 1.0;
        let g1 = 2.0 / (1.0 + (1.0 + a2 * t2).sqrt());
        let t = bump_shadowing_term(ns, n, i, true, true);
        assert!((t - g1).abs() < 1e-6 && t < 1.0, "{t} {g1}");
    }
}
