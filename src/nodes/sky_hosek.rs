//! The Hosek/Wilkie sky model's per-node state (`arhosek_xyz_skymodelstate_alloc_init`).

use super::math::Vec3;

/// (sun theta, sun phi, radiance per XYZ channel, nine coefficients per channel).
pub type HosekState = (f32, f32, [f32; 3], [[f32; 9]; 3]);

/// The model's state for a sun direction, turbidity and ground albedo.
pub fn hosek(
    _sun_direction: Vec3,
    _turbidity: f32,
    _ground_albedo: f32,
) -> Result<HosekState, String> {
    Err("the Hosek/Wilkie sky model is not supported yet".into())
}
