//! Ray Portal BSDF (Cycles' closure/bsdf_ray_portal.h and shade_surface.h's
//! integrate_surface_ray_portal): when the path picks it, the ray goes on from another
//! position in another direction, as a transparent bounce that skips MIS. It reflects no
//! light (its eval is zero), so light sampling gets nothing from it. Shadow rays stop at a
//! portal, unless the material is also transparent: Cycles' shadow shading allocates no
//! closures, so SD_RAY_PORTAL is never set there, and the portal's weight joins the
//! transparency whenever a Transparent closure sets SD_TRANSPARENT (`LobeSet::
//! shadow_transparency`).

use crate::render::math::*;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayPortal {
    /// Where the ray continues from.
    pub position: V3,
    /// The unit direction it continues in.
    pub direction: V3,
    /// The position is not the hit point: the ray starts there exactly (Cycles unsets the
    /// current object, so it can hit the same polygon again); otherwise it starts offset
    /// from the hit along the direction, as any ray leaving a surface.
    pub moved: bool,
}

impl RayPortal {
    /// Cycles' bsdf_ray_portal_setup at a hit `p` seen from `incoming` (toward the viewer):
    /// a zero direction (the unlinked socket) continues the ray's own direction.
    /// `position` is the hit point when its socket is unlinked (Cycles' LINK_POSITION).
    pub fn new(p: V3, position: V3, direction: V3, incoming: V3) -> RayPortal {
        let (p, position) = (Vec3::from(p), Vec3::from(position));
        let (direction, incoming) = (Vec3::from(direction), Vec3::from(incoming));
        let d = if direction.is_zero() {
            -incoming
        } else {
            direction
        };
        // Cycles keeps the direction as given; the hit along a scaled ray is the same.
        let n = d.normalize();
        let direction = if n.is_finite() && !n.is_zero() {
            n
        } else {
            -incoming
        };
        let delta = p - position;
        RayPortal {
            position: position.into(),
            direction: direction.into(),
            moved: delta.dot(delta) > 1e-9,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unlinked_sockets_continue_the_ray_from_the_hit() {
        let p = [1.0, 2.0, 3.0];
        let r = RayPortal::new(p, p, [0.0; 3], [0.0, 0.0, 1.0]);
        assert_eq!(r.direction, [0.0, 0.0, -1.0]);
        assert!(!r.moved);
    }

    #[test]
    fn a_moved_position_and_direction_are_kept_normalised() {
        let r = RayPortal::new([0.0; 3], [0.0, 0.0, 1e-4], [0.0, 3.0, 4.0], [1.0, 0.0, 0.0]);
        assert!(r.moved);
        assert!((r.direction[1] - 0.6).abs() < 1e-6 && (r.direction[2] - 0.8).abs() < 1e-6);
        // Within Cycles' 1e-9 squared distance the hit point is kept.
        assert!(!RayPortal::new([0.0; 3], [0.0, 0.0, 3e-5], [1.0, 0.0, 0.0], [1.0; 3]).moved);
    }

    #[test]
    fn shadow_rays_pass_a_portal_only_beside_a_transparent_closure() {
        use crate::render::bsdf::{LobeKind, LobeSet};
        let portal = LobeKind::RayPortal(RayPortal::new(
            [0.0; 3],
            [0.0; 3],
            [0.0; 3],
            [0.0, 0.0, 1.0],
        ));
        let mut lobes = LobeSet::default();
        lobes.push(portal, [0.25; 3], [0.0, 0.0, 1.0]);
        lobes.push(LobeKind::Diffuse, [0.5; 3], [0.0, 0.0, 1.0]);
        assert_eq!(lobes.shadow_transparency(), [0.0; 3]);
        lobes.push(LobeKind::Transparent, [0.25; 3], [0.0, 0.0, 1.0]);
        assert_eq!(lobes.shadow_transparency(), [0.5; 3]);
        // The path's own transparency (the bounce limit, holdouts) is the Transparent's.
        assert_eq!(lobes.transparent, [0.25; 3]);
    }
}
