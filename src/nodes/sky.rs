//! Sky Texture, as Cycles 4.5 evaluates it (`kernel/svm/sky.h`) after its per-node
//! precomputation (`SkyTextureNode::compile`, `intern/sky`).
//!
//! - Preetham and Hosek/Wilkie are analytic: the node's sun direction and turbidity (and
//!   ground albedo) become nine coefficients per XYZ channel and a zenith radiance, once
//!   per node; each lookup evaluates the model in the lookup direction.
//! - Nishita precomputes single scattering of the sun through Earth's atmosphere
//!   (Rayleigh, Mie and ozone over 21 wavelengths, integrated in f32 exactly as
//!   `SKY_nishita_skymodel_precompute_texture` does) into a 512x128 XYZ image over
//!   longitude and the square root of elevation, read back bilinearly with clamped edges;
//!   the sun disc is two precomputed XYZ values (its bottom and top edge) interpolated by
//!   elevation and limb-darkened.
//!
//! Every result is XYZ converted to the scene-linear space and clamped at 0.

// The physical tables keep Cycles' literals digit for digit, so they round to the same f32.
#![allow(clippy::excessive_precision)]

use std::f32::consts::{FRAC_PI_2, PI};

use crate::foundation::math::{add, dot, len, mul, scale, sub};

use super::color::{mat3_mul, SceneLinear};
use super::image::{Extension, Interpolation, Pixels};
use super::math::V3;

const TAU: f32 = 2.0 * PI;

blender_enum! {
    /// `ShaderNodeTexSky.sky_type`.
    pub enum SkyType {
        Preetham = "PREETHAM",
        HosekWilkie = "HOSEK_WILKIE",
        Nishita = "NISHITA",
    }
}

/// The Sky Texture node's properties, as Blender stores them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkySettings {
    pub sky_type: SkyType,
    /// Preetham and Hosek/Wilkie: towards the sun (normalised by Blender's sync).
    pub sun_direction: V3,
    pub turbidity: f32,
    /// Hosek/Wilkie only.
    pub ground_albedo: f32,
    /// Nishita only from here on.
    pub sun_disc: bool,
    /// Angular diameter (radians).
    pub sun_size: f32,
    pub sun_intensity: f32,
    pub sun_elevation: f32,
    pub sun_rotation: f32,
    /// Metres above sea level.
    pub altitude: f32,
    pub air_density: f32,
    pub dust_density: f32,
    pub ozone_density: f32,
}

/// A Sky Texture node ready to evaluate.
#[derive(Debug, Clone)]
pub enum Sky {
    /// Preetham (`hosek` false) or Hosek/Wilkie, with Cycles' nine coefficients per XYZ
    /// channel and the channel radiances.
    Analytic {
        hosek: bool,
        sun_phi: f32,
        sun_theta: f32,
        radiance: [f32; 3],
        config: [[f32; 9]; 3],
    },
    Nishita(Box<Nishita>),
}

/// The precomputed Nishita sky.
#[derive(Debug, Clone)]
pub struct Nishita {
    pixel_bottom: V3,
    pixel_top: V3,
    sun_elevation: f32,
    sun_rotation: f32,
    /// Negative without a sun disc.
    angular_diameter: f32,
    sun_intensity: f32,
    /// `TEX_WIDTH` x `TEX_HEIGHT` XYZ texels, row 0 at the horizon.
    texels: Vec<[f32; 4]>,
}

/// What Cycles' world light needs to sample a Nishita sun disc directly
/// (`LightManager::device_update_background`'s sun guiding).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SunGuide {
    /// Unit direction toward the sun's centre.
    pub direction: V3,
    /// Half the sun's angular diameter (radians).
    pub half_angle: f32,
    /// Cycles' `get_sun_average_radiance`: the disc centre's mean XYZ times the squared
    /// angular diameter, scaled by its empirical piecewise factor.
    pub average_radiance: f32,
}

impl Sky {
    /// The sun disc of a Nishita sky with its disc on (None otherwise).
    pub fn sun_guide(&self) -> Option<SunGuide> {
        let Sky::Nishita(n) = self else { return None };
        if n.angular_diameter < 0.0 {
            return None;
        }
        let d = n.angular_diameter;
        let centre = scale(add(n.pixel_bottom, n.pixel_top), 0.5 * n.sun_intensity);
        let mut average = (centre[0] + centre[1] + centre[2]) / 3.0 * d * d;
        let (first, second) = (0.8f32.to_radians(), 1.0f32.to_radians());
        average *= if d < first {
            1.0
        } else if d < second {
            1.0 + (0.8 - 1.0) / (second - first) * (d - first)
        } else {
            0.8 + (0.45 - 0.8) / (FRAC_PI_2 - second) * (d - second)
        };
        // The kernel's sun direction (longitude = simplified rotation + pi / 2).
        Some(SunGuide {
            direction: geographical_to_direction(n.sun_elevation, n.sun_rotation + FRAC_PI_2),
            half_angle: d * 0.5,
            average_radiance: average,
        })
    }

    /// The node precomputed as Cycles' `SkyTextureNode::compile` does.
    pub fn new(s: &SkySettings) -> Result<Sky, String> {
        match s.sky_type {
            SkyType::Preetham => Ok(preetham(s.sun_direction, s.turbidity)),
            SkyType::HosekWilkie => {
                super::sky_hosek::hosek(s.sun_direction, s.turbidity, s.ground_albedo).map(
                    |(sun_theta, sun_phi, radiance, config)| Sky::Analytic {
                        hosek: true,
                        sun_phi,
                        sun_theta,
                        radiance,
                        config,
                    },
                )
            }
            SkyType::Nishita => Ok(Sky::Nishita(Box::new(Nishita::new(s)))),
        }
    }

    /// The Color output for direction `dir` (the node's Vector, as given).
    pub fn eval(&self, dir: V3, space: &SceneLinear) -> V3 {
        let xyz = match self {
            Sky::Analytic {
                hosek,
                sun_phi,
                sun_theta,
                radiance,
                config,
            } => {
                let (theta, spherical_phi) = direction_to_spherical(dir);
                let phi = -spherical_phi + FRAC_PI_2;
                let gamma = angle_between(theta, phi, *sun_theta, *sun_phi);
                let theta = theta.min(FRAC_PI_2 - 0.001);
                if *hosek {
                    let f = |c: usize| hosek_radiance(&config[c], theta, gamma) * radiance[c];
                    let rgb = to_rgb_clamped(space, [f(0), f(1), f(2)]);
                    return rgb.map(|c| c * (TAU / 683.0));
                }
                let x = radiance[1] * perez(&config[1], theta, gamma);
                let y = radiance[2] * perez(&config[2], theta, gamma);
                let big_y = radiance[0] * perez(&config[0], theta, gamma);
                xy_big_y_to_xyz(x, y, big_y)
            }
            Sky::Nishita(n) => n.eval(dir),
        };
        to_rgb_clamped(space, xyz)
    }
}

fn to_rgb_clamped(space: &SceneLinear, xyz: V3) -> V3 {
    mat3_mul(&space.xyz_to_rgb, xyz).map(|c| c.max(0.0))
}

/// Cycles' `direction_to_spherical`: (acos z, atan2(y, x)).
fn direction_to_spherical(d: V3) -> (f32, f32) {
    (d[2].clamp(-1.0, 1.0).acos(), d[1].atan2(d[0]))
}

fn spherical_to_direction(theta: f32, phi: f32) -> V3 {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn angle_between(thetav: f32, phiv: f32, theta: f32, phi: f32) -> f32 {
    // Cycles' kernel is built with FMA contraction (the x86-64 AVX2 kernel), which fuses
    // the first product into the sum; near the sun the acos magnifies that last bit.
    let cospsi =
        (thetav.sin() * theta.sin()).mul_add((phi - phiv).cos(), thetav.cos() * theta.cos());
    cospsi.clamp(-1.0, 1.0).acos()
}

fn xy_big_y_to_xyz(x: f32, y: f32, big_y: f32) -> V3 {
    let big_x = if y != 0.0 { (x / y) * big_y } else { 0.0 };
    let big_z = if y != 0.0 && big_y != 0.0 {
        (1.0 - x - y) / y * big_y
    } else {
        0.0
    };
    [big_x, big_y, big_z]
}

// --- Preetham ----------------------------------------------------------------------------

/// "A Practical Analytic Model for Daylight" (Preetham, Shirley, Smits): Perez's
/// distribution.
fn perez(lam: &[f32; 9], theta: f32, gamma: f32) -> f32 {
    let (ctheta, cgamma) = (theta.cos(), gamma.cos());
    (1.0 + lam[0] * (lam[1] / ctheta).exp())
        * (1.0 + lam[2] * (lam[3] * gamma).exp() + lam[4] * cgamma * cgamma)
}

/// The sun's (theta, phi) as `SkyTextureNode` takes them: acos z and atan2(x, y).
fn sun_spherical(dir: V3) -> (f32, f32) {
    (dir[2].acos(), dir[0].atan2(dir[1]))
}

fn preetham(sun_direction: V3, turbidity: f32) -> Sky {
    let (theta, phi) = sun_spherical(sun_direction);
    let theta2 = theta * theta;
    let theta3 = theta2 * theta;
    let t = turbidity;
    let t2 = t * t;
    let chi = (4.0 / 9.0 - t / 120.0) * (PI - 2.0 * theta);
    let mut rad = [0.0f32; 3];
    rad[0] = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    rad[0] *= 0.06;
    rad[1] = (0.00166 * theta3 - 0.00375 * theta2 + 0.00209 * theta) * t2
        + (-0.02903 * theta3 + 0.06377 * theta2 - 0.03202 * theta + 0.00394) * t
        + (0.11693 * theta3 - 0.21196 * theta2 + 0.06052 * theta + 0.25886);
    rad[2] = (0.00275 * theta3 - 0.00610 * theta2 + 0.00317 * theta) * t2
        + (-0.04214 * theta3 + 0.08970 * theta2 - 0.04153 * theta + 0.00516) * t
        + (0.15346 * theta3 - 0.26756 * theta2 + 0.06670 * theta + 0.26688);
    // Perez coefficients of Y, x and y, linear in turbidity (the last four unused).
    let lin: [[(f32, f32); 5]; 3] = [
        [
            (0.1787, -1.4630),
            (-0.3554, 0.4275),
            (-0.0227, 5.3251),
            (0.1206, -2.5771),
            (-0.0670, 0.3703),
        ],
        [
            (-0.0193, -0.2592),
            (-0.0665, 0.0008),
            (-0.0004, 0.2125),
            (-0.0641, -0.8989),
            (-0.0033, 0.0452),
        ],
        [
            (-0.0167, -0.2608),
            (-0.0950, 0.0092),
            (-0.0079, 0.2102),
            (-0.0441, -1.6537),
            (-0.0109, 0.0529),
        ],
    ];
    let mut config = [[0.0f32; 9]; 3];
    for c in 0..3 {
        for (k, (a, b)) in lin[c].iter().enumerate() {
            config[c][k] = a * t + b;
        }
        // Normalised by the zenith's value (theta 0, gamma the sun's theta).
        rad[c] /= perez(&config[c], 0.0, theta);
    }
    Sky::Analytic {
        hosek: false,
        sun_phi: phi,
        sun_theta: theta,
        radiance: rad,
        config,
    }
}

// --- Hosek / Wilkie ----------------------------------------------------------------------

/// "An Analytic Model for Full Spectral Sky-Dome Radiance" (Hosek, Wilkie): one channel.
fn hosek_radiance(c: &[f32; 9], theta: f32, gamma: f32) -> f32 {
    let (ctheta, cgamma) = (theta.cos(), gamma.cos());
    let exp_m = (c[4] * gamma).exp();
    let ray_m = cgamma * cgamma;
    let mie_m = (1.0 + ray_m) / (1.0 + c[8] * c[8] - 2.0 * c[8] * cgamma).powf(1.5);
    let zenith = ctheta.sqrt();
    (1.0 + c[0] * (c[1] / (ctheta + 0.01)).exp())
        * (c[2] + c[3] * exp_m + c[5] * ray_m + c[6] * mie_m + c[7] * zenith)
}

// --- Nishita -----------------------------------------------------------------------------

/// The precomputed sky image Cycles allocates (`SkyLoader::load_metadata`).
pub const TEX_WIDTH: usize = 512;
pub const TEX_HEIGHT: usize = 128;

const RAYLEIGH_SCALE: f32 = 8e3;
const MIE_SCALE: f32 = 1.2e3;
const MIE_COEFF: f32 = 2e-5;
const MIE_G: f32 = 0.76;
const SQR_G: f32 = MIE_G * MIE_G;
const EARTH_RADIUS: f32 = 6360e3;
const ATMOSPHERE_RADIUS: f32 = 6420e3;
/// Segments of the primary ray.
const STEPS: usize = 32;
const WAVELENGTHS: usize = 21;
/// nm between sampled wavelengths (380..780 over 20 steps).
const STEP_LAMBDA: f32 = 20.0;

/// Extraterrestrial solar irradiance (W m^-2 nm^-1) at 380, 400, .., 780 nm.
const IRRADIANCE: [f32; WAVELENGTHS] = [
    1.45756829855592995315,
    1.56596305559738380175,
    1.65148449067670455293,
    1.71496242737209314555,
    1.75797983805020541226,
    1.78256407885924539336,
    1.79095108475838560302,
    1.78541550133410664714,
    1.76815554864306845317,
    1.74122069647250410362,
    1.70647127164943679389,
    1.66556087452739887134,
    1.61993437242451854274,
    1.57083597368892080581,
    1.51932335059305478886,
    1.46628494965214395407,
    1.41245852740172450623,
    1.35844961970384092709,
    1.30474913844739281998,
    1.25174963272610817455,
    1.19975998755420620867,
];
/// Rayleigh scattering coefficients (m^-1) at the same wavelengths.
const RAYLEIGH_COEFF: [f32; WAVELENGTHS] = [
    0.00005424820087636473,
    0.00004418549866505454,
    0.00003635151910165377,
    0.00003017929012024763,
    0.00002526320226989157,
    0.00002130859310621843,
    0.00001809838025320633,
    0.00001547057129129042,
    0.00001330284977336850,
    0.00001150184784075764,
    0.00000999557429990163,
    0.00000872799973630707,
    0.00000765513700977967,
    0.00000674217203751443,
    0.00000596134125832052,
    0.00000529034598065810,
    0.00000471115687557433,
    0.00000420910481110487,
    0.00000377218381260133,
    0.00000339051255477280,
    0.00000305591531679811,
];
/// Ozone absorption coefficients (m^-1).
const OZONE_COEFF: [f32; WAVELENGTHS] = [
    0.00000000325126849861,
    0.00000000585395365047,
    0.00000001977191155085,
    0.00000007309568762914,
    0.00000020084561514287,
    0.00000040383958096161,
    0.00000063551335912363,
    0.00000096707041180970,
    0.00000154797400424410,
    0.00000209038647223331,
    0.00000246128056164565,
    0.00000273551299461512,
    0.00000215125863128643,
    0.00000159051840791988,
    0.00000112356197979857,
    0.00000073527551487574,
    0.00000046450130357806,
    0.00000033096079921048,
    0.00000022512612292678,
    0.00000014879129266490,
    0.00000016828623364192,
];
/// CIE 1931 colour matching functions at the same wavelengths.
const CMF_XYZ: [[f32; 3]; WAVELENGTHS] = [
    [0.00136800000, 0.00003900000, 0.00645000100],
    [0.01431000000, 0.00039600000, 0.06785001000],
    [0.13438000000, 0.00400000000, 0.64560000000],
    [0.34828000000, 0.02300000000, 1.74706000000],
    [0.29080000000, 0.06000000000, 1.66920000000],
    [0.09564000000, 0.13902000000, 0.81295010000],
    [0.00490000000, 0.32300000000, 0.27200000000],
    [0.06327000000, 0.71000000000, 0.07824999000],
    [0.29040000000, 0.95400000000, 0.02030000000],
    [0.59450000000, 0.99500000000, 0.00390000000],
    [0.91630000000, 0.87000000000, 0.00165000100],
    [1.06220000000, 0.63100000000, 0.00080000000],
    [0.85444990000, 0.38100000000, 0.00019000000],
    [0.44790000000, 0.17500000000, 0.00002000000],
    [0.16490000000, 0.06100000000, 0.00000000000],
    [0.04677000000, 0.01700000000, 0.00000000000],
    [0.01135916000, 0.00410200000, 0.00000000000],
    [0.00289932700, 0.00104700000, 0.00000000000],
    [0.00069007860, 0.00024920000, 0.00000000000],
    [0.00016615050, 0.00006000000, 0.00000000000],
    [0.00004150994, 0.00001499000, 0.00000000000],
];
/// Optical depth along a ray to the top of the atmosphere by 8-point Gauss-Laguerre
/// quadrature over [0, 25] scaled to the ray (weights include the exp(x) factor).
const QUADRATURE_NODES: [f32; 8] = [
    0.006811185292,
    0.03614807107,
    0.09004346519,
    0.1706680068,
    0.2818362161,
    0.4303406404,
    0.6296271457,
    0.9145252695,
];
const QUADRATURE_WEIGHTS: [f32; 8] = [
    0.01750893642,
    0.04135477391,
    0.06678839063,
    0.09507698807,
    0.1283416365,
    0.1707430204,
    0.2327233347,
    0.3562490486,
];

/// intern/sky's `reduce_add`.
fn reduce_add(a: V3) -> f32 {
    a[0] + a[1] + a[2]
}

/// intern/sky's geographical direction: latitude up from the horizon, longitude from x.
fn geographical_to_direction(lat: f32, lon: f32) -> V3 {
    [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()]
}

fn spec_to_xyz(spectrum: &[f32; WAVELENGTHS]) -> V3 {
    let mut xyz = [0.0f32; 3];
    for (cmf, s) in CMF_XYZ.iter().zip(spectrum) {
        xyz[0] += cmf[0] * s;
        xyz[1] += cmf[1] * s;
        xyz[2] += cmf[2] * s;
    }
    scale(xyz, STEP_LAMBDA)
}

fn density_rayleigh(height: f32) -> f32 {
    (-height / RAYLEIGH_SCALE).exp()
}

fn density_mie(height: f32) -> f32 {
    (-height / MIE_SCALE).exp()
}

/// A tent of ozone between 10 and 40 km, peaking at 25 km.
fn density_ozone(height: f32) -> f32 {
    if (10000.0..25000.0).contains(&height) {
        1.0 / 15000.0 * height - 2.0 / 3.0
    } else if (25000.0..40000.0).contains(&height) {
        -(1.0 / 15000.0 * height - 8.0 / 3.0)
    } else {
        0.0
    }
}

fn phase_rayleigh(mu: f32) -> f32 {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

fn phase_mie(mu: f32) -> f32 {
    (3.0 * (1.0 - SQR_G) * (1.0 + mu * mu))
        / (8.0 * PI * (2.0 + SQR_G) * (1.0 + SQR_G - 2.0 * MIE_G * mu).powf(1.5))
}

/// Whether the ray from `pos` along `dir` meets the ground.
fn surface_intersection(pos: V3, dir: V3) -> bool {
    if dir[2] >= 0.0 {
        return false;
    }
    let b = -2.0 * dot(dir, scale(pos, -1.0));
    let c = dot(pos, pos) - EARTH_RADIUS * EARTH_RADIUS;
    b * b - 4.0 * c >= 0.0
}

fn atmosphere_intersection(pos: V3, dir: V3) -> V3 {
    let b = -2.0 * dot(dir, scale(pos, -1.0));
    let c = dot(pos, pos) - ATMOSPHERE_RADIUS * ATMOSPHERE_RADIUS;
    let t = (-b + (b * b - 4.0 * c).sqrt()) / 2.0;
    [
        pos[0] + dir[0] * t,
        pos[1] + dir[1] * t,
        pos[2] + dir[2] * t,
    ]
}

/// Optical depth factors (Rayleigh, Mie, ozone) from `origin` along `dir` to space.
fn ray_optical_depth(origin: V3, dir: V3) -> V3 {
    let end = atmosphere_intersection(origin, dir);
    let ray_length = len(sub(end, origin));
    let segment = scale(dir, ray_length);
    let mut depth = [0.0f32; 3];
    for (node, weight) in QUADRATURE_NODES.iter().zip(QUADRATURE_WEIGHTS) {
        let p = add(origin, scale(segment, *node));
        let height = len(p) - EARTH_RADIUS;
        let density = [
            density_rayleigh(height),
            density_mie(height),
            density_ozone(height),
        ];
        depth = add(depth, scale(density, weight));
    }
    scale(depth, ray_length)
}

/// Single in-scattering of the sun along a ray through the atmosphere, per wavelength.
fn single_scattering(
    ray_dir: V3,
    sun_dir: V3,
    origin: V3,
    density_scale: V3,
    spectrum: &mut [f32; WAVELENGTHS],
) {
    let end = atmosphere_intersection(origin, ray_dir);
    let ray_length = len(sub(end, origin));
    let segment_length = ray_length / STEPS as f32;
    let segment = scale(ray_dir, segment_length);
    let mut depth = [0.0f32; 3];
    spectrum.fill(0.0);
    let mu = dot(ray_dir, sun_dir);
    let phase = [phase_rayleigh(mu), phase_mie(mu), 0.0];
    // Each segment is evaluated at its middle.
    let mut p = add(origin, scale(segment, 0.5));
    for _ in 0..STEPS {
        let height = len(p) - EARTH_RADIUS;
        let density = mul(
            density_scale,
            [
                density_rayleigh(height),
                density_mie(height),
                density_ozone(height),
            ],
        );
        depth = add(depth, scale(density, segment_length));
        if !surface_intersection(p, sun_dir) {
            let light_depth = mul(density_scale, ray_optical_depth(p, sun_dir));
            let total = add(depth, light_depth);
            for wl in 0..WAVELENGTHS {
                let extinction = mul(
                    total,
                    [RAYLEIGH_COEFF[wl], 1.11 * MIE_COEFF, OZONE_COEFF[wl]],
                );
                let attenuation = (-reduce_add(extinction)).exp();
                let scattering = mul(density, [RAYLEIGH_COEFF[wl], MIE_COEFF, 0.0]);
                spectrum[wl] += attenuation
                    * reduce_add(mul(phase, scattering))
                    * IRRADIANCE[wl]
                    * segment_length;
            }
        }
        p = add(p, segment);
    }
}

/// The sun's radiance seen along `dir` (its disc's solid angle spreads the irradiance).
fn sun_radiation(
    dir: V3,
    altitude: f32,
    air: f32,
    dust: f32,
    solid_angle: f32,
) -> [f32; WAVELENGTHS] {
    let cam = [0.0, 0.0, EARTH_RADIUS + altitude];
    let depth = ray_optical_depth(cam, dir);
    let mut spectrum = [0.0f32; WAVELENGTHS];
    for (i, s) in spectrum.iter_mut().enumerate() {
        // Cycles 4.5 leaves ozone out of the sun's own transmittance.
        let t = RAYLEIGH_COEFF[i] * depth[0] * air + 1.11 * MIE_COEFF * depth[1] * dust;
        *s = IRRADIANCE[i] * (-t).exp() / solid_angle;
    }
    spectrum
}

/// The sky image: row y at elevation (pi/2 + half a row) (y / height)^2, column x at
/// longitude 2 pi x / width - pi (mirrored about the sun's meridian).
fn precompute_texture(s: &SkySettings) -> Vec<[f32; 4]> {
    use rayon::prelude::*;
    let (w, h) = (TEX_WIDTH, TEX_HEIGHT);
    let cam = [0.0, 0.0, EARTH_RADIUS + s.altitude];
    let sun_dir = geographical_to_direction(s.sun_elevation, 0.0);
    let density_scale = [s.air_density, s.dust_density, s.ozone_density];
    let latitude_step = FRAC_PI_2 / h as f32;
    let longitude_step = TAU / w as f32;
    let half_lat_step = latitude_step / 2.0;
    let mut texels = vec![[0.0f32, 0.0, 0.0, 1.0]; w * h];
    texels.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let f = y as f32 / h as f32;
        let latitude = (FRAC_PI_2 + half_lat_step) * (f * f);
        let mut spectrum = [0.0f32; WAVELENGTHS];
        for x in 0..w / 2 {
            let longitude = longitude_step * x as f32 - PI;
            let dir = geographical_to_direction(latitude, longitude);
            single_scattering(dir, sun_dir, cam, density_scale, &mut spectrum);
            let xyz = spec_to_xyz(&spectrum);
            let t = [xyz[0], xyz[1], xyz[2], 1.0];
            row[x] = t;
            row[w - x - 1] = t;
        }
    });
    texels
}

/// Cycles' `SkyTextureNode::simplify_settings`: the sun's elevation wrapped into
/// [-pi/2, pi/2] (past the zenith it continues on the other side, a half turn round), and
/// the rotation wrapped into [0, 2 pi) and mirrored (2 pi - rotation), which is the form
/// the precompute and the kernel take.
fn simplify_sun(elevation: f32, rotation: f32) -> (f32, f32) {
    let mut e = elevation % TAU;
    let mut r = rotation;
    if e.abs() >= PI {
        e -= (2.0f32).copysign(e) * PI;
    }
    if e >= FRAC_PI_2 || e <= -FRAC_PI_2 {
        e = PI.copysign(e) - e;
        r += PI;
    }
    r %= TAU;
    if r < 0.0 {
        r += TAU;
    }
    (e, TAU - r)
}

impl Nishita {
    fn new(settings: &SkySettings) -> Nishita {
        let (sun_elevation, sun_rotation) =
            simplify_sun(settings.sun_elevation, settings.sun_rotation);
        let s = &SkySettings {
            sun_elevation,
            sun_rotation,
            // Cycles precomputes at an altitude clamped to [1 m, 59999 m] (below 1 m is
            // numerically unstable, above 60 km is space): the default 0 m sky is the 1 m
            // sky, 1e-3 brighter at the horizon (measured against the bakes).
            altitude: settings.altitude.clamp(1.0, 59999.0),
            ..*settings
        };
        // Cycles clamps the sun's size for numerical precision (`get_sun_size`).
        let angular_diameter = s.sun_size.max(0.0005);
        let half = angular_diameter / 2.0;
        let solid_angle = TAU * (1.0 - half.cos());
        let bottom = (s.sun_elevation - half).max(0.0);
        let top = (s.sun_elevation + half).max(0.0);
        let pixel = |elevation: f32| {
            let dir = geographical_to_direction(elevation, 0.0);
            spec_to_xyz(&sun_radiation(
                dir,
                s.altitude,
                s.air_density,
                s.dust_density,
                solid_angle,
            ))
        };
        Nishita {
            pixel_bottom: pixel(bottom),
            pixel_top: pixel(top),
            sun_elevation: s.sun_elevation,
            sun_rotation: s.sun_rotation,
            angular_diameter: if s.sun_disc { angular_diameter } else { -1.0 },
            sun_intensity: s.sun_intensity,
            texels: precompute_texture(s),
        }
    }

    fn lookup(&self, x: f32, y: f32) -> V3 {
        let r = Pixels {
            data: &self.texels,
            width: TEX_WIDTH as i32,
            height: TEX_HEIGHT as i32,
        }
        .interp(x, y, Interpolation::Linear, Extension::Extend);
        [r[0], r[1], r[2]]
    }

    /// XYZ towards `dir` (`sky_radiance_nishita`).
    fn eval(&self, dir: V3) -> V3 {
        let (theta, phi) = direction_to_spherical(dir);
        let fract = |v: f32| v - v.floor();
        let x = fract((-phi - FRAC_PI_2 + self.sun_rotation) / TAU);
        if dir[2] < 0.0 {
            // Below the horizon: the horizon row fading to black by z = -0.4.
            if dir[2] < -0.4 {
                return [0.0; 3];
            }
            let fade = 1.0 + dir[2] * 2.5;
            let fade = fade * fade * fade;
            return scale(self.lookup(x, -0.5), fade);
        }
        let half = self.angular_diameter * 0.5;
        let sun_dir = spherical_to_direction(
            self.sun_elevation - FRAC_PI_2,
            self.sun_rotation - FRAC_PI_2,
        );
        let sun_angle = 2.0 * len(sub(dir, sun_dir)).atan2(len(add(dir, sun_dir)));
        let dir_elevation = FRAC_PI_2 - theta;
        if self.angular_diameter >= 0.0 && sun_angle < half {
            let (bottom, top) = (self.pixel_bottom, self.pixel_top);
            let lerp = |y: f32| {
                let d = sub(top, bottom);
                scale(add(bottom, scale(d, y)), self.sun_intensity)
            };
            let xyz = if self.sun_elevation - half > 0.0 {
                lerp((dir_elevation - self.sun_elevation) / self.angular_diameter + 0.5)
            } else if self.sun_elevation + half > 0.0 {
                lerp(dir_elevation / (self.sun_elevation + half))
            } else {
                [0.0; 3]
            };
            let r = sun_angle / half;
            let limb_darkening = 1.0 - 0.6 * (1.0 - (1.0 - r * r).sqrt());
            return scale(xyz, limb_darkening);
        }
        // More texels toward the horizon.
        let y = (dir_elevation / FRAC_PI_2).max(0.0).sqrt();
        self.lookup(x, y)
    }
}
