//! Cycles' panoramic cameras (kernel/camera/projection.h): each maps the viewplane
//! coordinate (u, v) in [0, 1]^2 (plus the camera's shift) to a direction in Cycles'
//! panorama space, where +X is the view direction, and `to_blender_camera` turns that
//! into Blender's camera space (looking down -Z) as Cycles' camera matrix does. A zero
//! direction means the point is outside the lens: the sample sees nothing (black).

use crate::scene::settings::CameraSettings;

use crate::render::math::*;

#[derive(Debug, Clone, PartialEq)]
pub enum Panorama {
    /// (phi scale, phi offset, theta scale, theta offset) from the longitude/latitude range.
    Equirectangular([f32; 4]),
    EquiangularCubemapFace,
    MirrorBall,
    FisheyeEquidistant {
        fov: f32,
    },
    FisheyeEquisolid {
        lens: f32,
        fov: f32,
        sensor: [f32; 2],
    },
    FisheyeLensPolynomial {
        k0: f32,
        k: [f32; 4],
        fov: f32,
        sensor: [f32; 2],
    },
    /// (-u_min, -u_max, v_min / radius, v_max / radius).
    CentralCylindrical([f32; 4]),
}

impl Panorama {
    /// The camera data's panorama settings; `xratio`, `yratio` are the render's size
    /// with pixel aspect, for the sensor size the equisolid and polynomial fisheyes use.
    pub fn from_camera(c: &CameraSettings, xratio: f32, yratio: f32) -> Result<Panorama, String> {
        let p = &c.panorama;
        // Blender's sensor fit decides which side the sensor size spans (blender_camera_sync).
        let sensor = || {
            let (horizontal, size) = c.fit(xratio as f64, yratio as f64);
            let size = size as f32;
            if horizontal {
                [size, size * yratio / xratio]
            } else {
                [size * xratio / yratio, size]
            }
        };
        let fov = p.fisheye_fov as f32;
        let k = p.fisheye_polynomial.map(|k| k as f32);
        Ok(match p.panorama_type.as_str() {
            "EQUIRECTANGULAR" => {
                let [lo_min, lo_max] = p.longitude.map(|v| v as f32);
                let [la_min, la_max] = p.latitude.map(|v| v as f32);
                Panorama::Equirectangular([
                    lo_min - lo_max,
                    -lo_min,
                    la_min - la_max,
                    -la_min + std::f32::consts::FRAC_PI_2,
                ])
            }
            "EQUIANGULAR_CUBEMAP_FACE" => Panorama::EquiangularCubemapFace,
            "MIRRORBALL" => Panorama::MirrorBall,
            "FISHEYE_EQUIDISTANT" => Panorama::FisheyeEquidistant { fov },
            "FISHEYE_EQUISOLID" => Panorama::FisheyeEquisolid {
                lens: p.fisheye_lens as f32,
                fov,
                sensor: sensor(),
            },
            "FISHEYE_LENS_POLYNOMIAL" => Panorama::FisheyeLensPolynomial {
                k0: k[0],
                k: [k[1], k[2], k[3], k[4]],
                fov,
                sensor: sensor(),
            },
            "CENTRAL_CYLINDRICAL" => {
                let r = p.central_cylindrical_radius as f32;
                let [u_min, u_max] = p.central_cylindrical_range_u.map(|v| v as f32);
                let [v_min, v_max] = p.central_cylindrical_range_v.map(|v| v as f32);
                Panorama::CentralCylindrical([-u_min, -u_max, v_min / r, v_max / r])
            }
            other => return Err(format!("panorama type {other:?} is not supported")),
        })
    }

    /// Direction in Cycles' panorama space (+X forward) for viewplane point (u, v);
    /// zero outside the lens.
    pub fn direction(&self, u: f32, v: f32) -> V3 {
        match *self {
            Panorama::Equirectangular(r) => {
                let phi = r[0] * u + r[1];
                let theta = r[2] * v + r[3];
                let s = theta.sin();
                [s * phi.cos(), s * phi.sin(), theta.cos()]
            }
            Panorama::EquiangularCubemapFace => {
                let a = ((0.5 - u) * std::f32::consts::FRAC_PI_2).tan();
                let b = ((v - 0.5) * std::f32::consts::FRAC_PI_2).tan();
                normalize([1.0, a, b])
            }
            Panorama::MirrorBall => {
                let (x, z) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                if x * x + z * z > 1.0 {
                    return [0.0; 3];
                }
                let n = [x, -(1.0 - x * x - z * z).max(0.0).sqrt(), z];
                // The view ray (0, -1, 0) reflected about the ball's normal.
                let i = [0.0, -1.0, 0.0];
                sub(scale(n, 2.0 * dot(n, i)), i)
            }
            Panorama::FisheyeEquidistant { fov } => {
                let (x, y) = ((u - 0.5) * 2.0, (v - 0.5) * 2.0);
                let r = (x * x + y * y).sqrt();
                if r > 1.0 {
                    return [0.0; 3];
                }
                fisheye(r * fov * 0.5, x, y, r)
            }
            Panorama::FisheyeEquisolid { lens, fov, sensor } => {
                let (x, y) = ((u - 0.5) * sensor[0], (v - 0.5) * sensor[1]);
                let rmax = 2.0 * lens * (fov * 0.25).sin();
                let r = (x * x + y * y).sqrt();
                if r > rmax {
                    return [0.0; 3];
                }
                fisheye(2.0 * (r / (2.0 * lens)).asin(), x, y, r)
            }
            Panorama::FisheyeLensPolynomial { k0, k, fov, sensor } => {
                let (x, y) = ((u - 0.5) * sensor[0], (v - 0.5) * sensor[1]);
                let r = (x * x + y * y).sqrt();
                let r2 = r * r;
                let theta = -(k0 + (k[0] * r + k[1] * r2 + k[2] * r2 * r + k[3] * r2 * r2));
                if theta.abs() > 0.5 * fov {
                    return [0.0; 3];
                }
                fisheye(theta, x, y, r)
            }
            Panorama::CentralCylindrical(r) => {
                let theta = r[0] + (r[1] - r[0]) * u;
                let z = r[2] + (r[3] - r[2]) * v;
                [theta.cos(), theta.sin(), z]
            }
        }
    }

    /// Panorama space to Blender's camera space: Cycles' camera matrix points +X (or -Y
    /// for the mirror ball) down the Blender camera's -Z.
    pub fn to_blender_camera(&self, d: V3) -> V3 {
        match self {
            Panorama::MirrorBall => [d[0], d[2], d[1]],
            _ => [-d[1], d[2], -d[0]],
        }
    }
}

/// Cycles' fisheye_to_direction: polar angle `theta` from +X, azimuth from (u, v).
fn fisheye(theta: f32, u: f32, v: f32, r: f32) -> V3 {
    let c = if r != 0.0 {
        (u / r).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let mut phi = c.acos();
    if v < 0.0 {
        phi = -phi;
    }
    [
        theta.cos(),
        -phi.cos() * theta.sin(),
        phi.sin() * theta.sin(),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_looks_down_the_view_axis() {
        let kinds = [
            Panorama::Equirectangular([
                -2.0 * std::f32::consts::PI,
                std::f32::consts::PI,
                -std::f32::consts::PI,
                std::f32::consts::PI,
            ]),
            Panorama::EquiangularCubemapFace,
            Panorama::MirrorBall,
            Panorama::FisheyeEquidistant { fov: 3.0 },
            Panorama::FisheyeEquisolid {
                lens: 10.5,
                fov: 3.0,
                sensor: [36.0, 24.0],
            },
        ];
        for k in kinds {
            let d = k.to_blender_camera(k.direction(0.5, 0.5));
            assert!(
                (d[2] + 1.0).abs() < 1e-5 && d[0].abs() < 1e-5 && d[1].abs() < 1e-5,
                "{k:?}: {d:?}"
            );
        }
    }
}
