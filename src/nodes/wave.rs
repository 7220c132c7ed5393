//! Wave Texture (Cycles `svm_wave`): bands or rings, sine/saw/triangle profiles, with an
//! fBm distortion.

use super::math::V3;
use super::noise::{fbm, Cycles};

blender_enum! {
    pub enum WaveType { Bands = "BANDS", Rings = "RINGS", }
}
blender_enum! {
    pub enum BandsDirection { X = "X", Y = "Y", Z = "Z", Diagonal = "DIAGONAL", }
}
blender_enum! {
    pub enum RingsDirection { X = "X", Y = "Y", Z = "Z", Spherical = "SPHERICAL", }
}
blender_enum! {
    pub enum WaveProfile { Sin = "SIN", Saw = "SAW", Tri = "TRI", }
}

#[derive(Debug, Clone, Copy)]
pub struct WaveSettings {
    pub kind: WaveType,
    pub bands: BandsDirection,
    pub rings: RingsDirection,
    pub profile: WaveProfile,
}

/// Fac of the Wave Texture at `vector` (Color is Fac in all three channels).
#[allow(clippy::too_many_arguments)]
pub fn wave(
    s: WaveSettings,
    vector: V3,
    scale: f32,
    distortion: f32,
    detail: f32,
    detail_scale: f32,
    detail_roughness: f32,
    phase: f32,
) -> f32 {
    // The nudge avoids precision trouble on unit coordinates, as Cycles does.
    let p = vector.map(|v| (v * scale + 0.000001) * 0.999999);
    let mut n = match s.kind {
        WaveType::Bands => match s.bands {
            BandsDirection::X => p[0] * 20.0,
            BandsDirection::Y => p[1] * 20.0,
            BandsDirection::Z => p[2] * 20.0,
            BandsDirection::Diagonal => (p[0] + p[1] + p[2]) * 10.0,
        },
        WaveType::Rings => {
            let mut r = p;
            match s.rings {
                RingsDirection::X => r[0] = 0.0,
                RingsDirection::Y => r[1] = 0.0,
                RingsDirection::Z => r[2] = 0.0,
                RingsDirection::Spherical => {}
            }
            (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt() * 20.0
        }
    };
    n += phase;
    if distortion != 0.0 {
        let q = p.map(|v| v * detail_scale);
        n += distortion * (fbm(Cycles(q), detail, detail_roughness, 2.0, true) * 2.0 - 1.0);
    }
    let tau = 2.0 * std::f32::consts::PI;
    match s.profile {
        WaveProfile::Sin => 0.5 + 0.5 * (n - std::f32::consts::FRAC_PI_2).sin(),
        WaveProfile::Saw => {
            let n = n / tau;
            n - n.floor()
        }
        WaveProfile::Tri => {
            let n = n / tau;
            (n - (n + 0.5).floor()).abs() * 2.0
        }
    }
}
