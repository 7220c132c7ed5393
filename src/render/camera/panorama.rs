//! Cycles' panoramic cameras (kernel/camera/projection.h): each maps the viewplane
//! coordinate (u, v) in [0, 1]^2 (plus the camera's shift) to a direction in Cycles'
//! panorama space, where +X is the view direction, and `to_blender_camera` turns that
//! into Blender's camera space (looking down -Z) as Cycles' camera matrix does. A zero
//! direction means the point is outside the lens: the sample sees nothing (black).

use crate::scene::settings::CameraSettings;

use crate::render::math::{vec3, Vec3, V3};

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
                vec3(1.0, a, b).normalize().into()
            }
            Panorama::MirrorBall => {
                let (x, z) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                if x * x + z * z > 1.0 {
                    return [0.0; 3];
                }
                let n = vec3(x, -(1.0 - x * x - z * z).max(0.0).sqrt(), z);
                // The view ray (0, -1, 0) reflected about the ball's normal.
                let i = vec3(0.0, -1.0, 0.0);
                (n * (2.0 * n.dot(i)) - i).into()
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

    /// The viewplane point (u, v) a direction in panorama space projects to: the inverse
    /// of `direction`, as Cycles' direction_to_panorama (which its Vector pass uses). None
    /// for a zero direction and, for the fisheyes and the mirror ball, outside the lens.
    pub fn uv_of(&self, d: V3) -> Option<[f32; 2]> {
        let d = Vec3::from(d);
        let l = d.length();
        if !(l > 0.0) {
            return None;
        }
        let d = d * (1.0 / l);
        // The (y, z) direction of a fisheye's image radius.
        let yz = || {
            let r = (d[1] * d[1] + d[2] * d[2]).sqrt();
            if r > 0.0 {
                [d[1] / r, d[2] / r]
            } else {
                [0.0, 0.0]
            }
        };
        let uv = match *self {
            Panorama::Equirectangular(r) => [
                (d[1].atan2(d[0]) - r[1]) / r[0],
                (d[2].clamp(-1.0, 1.0).acos() - r[3]) / r[2],
            ],
            Panorama::EquiangularCubemapFace => {
                if !(d[0] > 0.0) {
                    return None;
                }
                let k = 2.0 / std::f32::consts::PI;
                [0.5 - d[1].atan2(d[0]) * k, d[2].atan2(d[0]) * k + 0.5]
            }
            Panorama::MirrorBall => {
                // The ball's normal halfway between the view ray (0, -1, 0) reversed and d.
                let h = [d[0], d[1] - 1.0, d[2]];
                let div = 2.0 * (-0.5 * h[1]).max(0.0).sqrt();
                if !(div > 0.0) {
                    return None;
                }
                [0.5 * (h[0] / div + 1.0), 0.5 * (h[2] / div + 1.0)]
            }
            Panorama::FisheyeEquidistant { fov } => {
                let theta = (d[1] * d[1] + d[2] * d[2]).sqrt().atan2(d[0]);
                if theta > 0.5 * fov {
                    return None;
                }
                let r = theta / fov;
                let n = yz();
                [0.5 - r * n[0], r * n[1] + 0.5]
            }
            Panorama::FisheyeEquisolid { lens, fov, sensor } => {
                let theta = d[0].clamp(-1.0, 1.0).acos();
                if theta > 0.5 * fov {
                    return None;
                }
                let r = 2.0 * lens * (0.5 * theta).sin();
                let n = yz();
                [0.5 - r * n[0] / sensor[0], r * n[1] / sensor[1] + 0.5]
            }
            Panorama::FisheyeLensPolynomial { k0, k, fov, sensor } => {
                // Newton's method on theta = -(k0 + k1 r + k2 r^2 + k3 r^3 + k4 r^4), from the
                // linear model's root, as Cycles' direction_to_fisheye_lens_polynomial.
                let theta = -d[0].clamp(-1.0, 1.0).acos();
                if theta.abs() > 0.5 * fov {
                    return None;
                }
                let mut r = (theta - k0) / k[0];
                for _ in 0..20 {
                    let (r2, old) = (r * r, r);
                    let f = theta - (k0 + k[0] * r + k[1] * r2 + k[2] * r2 * r + k[3] * r2 * r2);
                    let df = k[0] + 2.0 * k[1] * r + 3.0 * k[2] * r2 + 4.0 * k[3] * r2 * r;
                    r += f / df;
                    if (r - old).abs() < 1e-6 {
                        break;
                    }
                }
                let n = yz();
                [0.5 - r * n[0] / sensor[0], r * n[1] / sensor[1] + 0.5]
            }
            Panorama::CentralCylindrical(r) => {
                let z = d[2] / (d[0] * d[0] + d[1] * d[1]).sqrt();
                let theta = d[1].atan2(d[0]);
                [(theta - r[0]) / (r[1] - r[0]), (z - r[2]) / (r[3] - r[2])]
            }
        };
        uv.iter().all(|x| x.is_finite()).then_some(uv)
    }

    /// Blender's camera space to panorama space (the inverse of `to_blender_camera`).
    pub fn from_blender_camera(&self, b: V3) -> V3 {
        match self {
            Panorama::MirrorBall => [b[0], b[2], b[1]],
            _ => [-b[2], -b[0], b[1]],
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

    /// `uv_of` inverts `direction` wherever the lens sees (Cycles' direction_to_panorama
    /// and panorama_to_direction are each other's inverse).
    #[test]
    fn uv_of_inverts_direction() {
        let pi = std::f32::consts::PI;
        let kinds = [
            Panorama::Equirectangular([-2.0 * pi, pi, -pi, pi]),
            Panorama::Equirectangular([-1.2, 0.4, -0.9, 1.9]),
            Panorama::EquiangularCubemapFace,
            Panorama::MirrorBall,
            Panorama::FisheyeEquidistant { fov: pi },
            Panorama::FisheyeEquidistant { fov: 2.2 },
            Panorama::FisheyeEquisolid {
                lens: 10.5,
                fov: pi,
                sensor: [36.0, 24.0],
            },
            Panorama::FisheyeLensPolynomial {
                k0: -1e-5,
                k: [-0.0526, -2.1e-5, 3.6e-7, -1.2e-9],
                fov: pi,
                sensor: [36.0, 24.0],
            },
            Panorama::CentralCylindrical([-pi / 2.0, pi / 2.0, -1.0, 1.0]),
        ];
        for k in kinds {
            let mut checked = 0;
            for i in 1..20 {
                for j in 1..20 {
                    let (u, v) = (i as f32 / 20.0, j as f32 / 20.0);
                    let d = k.direction(u, v);
                    let (x, z) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                    if matches!(k, Panorama::MirrorBall) && x * x + z * z > 0.95 {
                        // The ball's rim reflects every point to straight behind.
                        continue;
                    }
                    if d == [0.0; 3] {
                        assert_eq!(k.uv_of(d), None);
                        continue;
                    }
                    let back = k
                        .uv_of(k.from_blender_camera(k.to_blender_camera(d)))
                        .unwrap_or_else(|| panic!("{k:?} ({u}, {v}): {d:?} has no uv"));
                    assert!(
                        (back[0] - u).abs() < 2e-4 && (back[1] - v).abs() < 2e-4,
                        "{k:?} ({u}, {v}) -> {d:?} -> {back:?}"
                    );
                    checked += 1;
                }
            }
            assert!(checked > 150, "{k:?}: {checked}");
        }
    }
}
