//! A sequence's camera path as text files other tools read: TUM's trajectory format
//! (`timestamp tx ty tz qx qy qz qw`, camera-to-world) and COLMAP's text model
//! (`cameras.txt`, `images.txt`, an empty `points3D.txt`; world-to-camera), both in
//! OpenCV camera axes (x right, y down, z forward).

use super::camera::CameraInfo;
use super::record::FrameRecord;

/// Unit quaternion (w, x, y, z) of a rotation matrix (rows), with w >= 0.
pub fn quaternion(r: [[f64; 3]; 3]) -> [f64; 4] {
    let tr = r[0][0] + r[1][1] + r[2][2];
    let q = if tr > 0.0 {
        let s = (tr + 1.0).sqrt() * 2.0;
        [
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        [
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        ]
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        [
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        ]
    };
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
    q.map(|v| sign * v / n)
}

fn rotation(c: &CameraInfo) -> [[f64; 3]; 3] {
    let m = &c.world_to_camera_opencv;
    std::array::from_fn(|r| std::array::from_fn(|k| m[r][k]))
}

/// TUM: one line per frame, `timestamp tx ty tz qx qy qz qw`: the camera's position and
/// its camera-to-world rotation (OpenCV camera axes), timestamp in seconds.
pub fn tum(records: &[&FrameRecord]) -> String {
    let mut out = String::from("# timestamp tx ty tz qx qy qz qw (camera-to-world, OpenCV camera axes: x right, y down, z forward)\n");
    for r in records {
        let w2c = rotation(&r.camera);
        let c2w: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|k| w2c[k][i]));
        let q = quaternion(c2w);
        let p = r.camera.location;
        let t = r.time.unwrap_or(r.frame as f64);
        out.push_str(&format!(
            "{t} {} {} {} {} {} {} {}\n",
            p[0], p[1], p[2], q[1], q[2], q[3], q[0]
        ));
    }
    out
}

/// COLMAP's text model of a sequence (cameras.txt, images.txt, points3D.txt), or None
/// when a frame's camera is not a pinhole (COLMAP's PINHOLE model has no orthographic or
/// panoramic counterpart). One camera per distinct set of intrinsics; images are named
/// by their path in the dataset folder.
pub fn colmap(records: &[&FrameRecord]) -> Option<[String; 3]> {
    if records.iter().any(|r| r.camera.projection != "PERSP") {
        return None;
    }
    let mut cams: Vec<(u32, u32, [f64; 4])> = Vec::new();
    let mut images = String::from(
        "# Image list with two lines of data per image:\n#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n#   POINTS2D[] as (X, Y, POINT3D_ID)\n",
    );
    for (k, r) in records.iter().enumerate() {
        let c = &r.camera;
        let key = (c.width, c.height, [c.fx, c.fy, c.cx, c.cy]);
        let id = match cams.iter().position(|x| *x == key) {
            Some(i) => i + 1,
            None => {
                cams.push(key);
                cams.len()
            }
        };
        let q = quaternion(rotation(c));
        let m = &c.world_to_camera_opencv;
        images.push_str(&format!(
            "{} {} {} {} {} {} {} {} {id} {}\n\n",
            k + 1,
            q[0],
            q[1],
            q[2],
            q[3],
            m[0][3],
            m[1][3],
            m[2][3],
            r.image
        ));
    }
    let mut cameras = format!(
        "# Camera list with one line of data per camera:\n#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: {}\n",
        cams.len()
    );
    for (i, (w, h, p)) in cams.iter().enumerate() {
        cameras.push_str(&format!(
            "{} PINHOLE {w} {h} {} {} {} {}\n",
            i + 1,
            p[0],
            p[1],
            p[2],
            p[3]
        ));
    }
    let points = "# 3D point list with one line of data per point:\n#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n# Number of points: 0, mean track length: 0\n".to_string();
    Some([cameras, images, points])
}

#[cfg(test)]
mod tests {
    use super::quaternion;

    /// The quaternion turns vectors as its matrix does, for rotations near each branch.
    #[test]
    fn quaternion_matches_its_matrix() {
        let rot = |a: f64, b: f64, c: f64| {
            let (sa, ca, sb, cb, sc, cc) = (a.sin(), a.cos(), b.sin(), b.cos(), c.sin(), c.cos());
            let rx = [[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]];
            let ry = [[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]];
            let rz = [[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]];
            let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
                std::array::from_fn(|i| {
                    std::array::from_fn(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum())
                })
            };
            mul(rz, mul(ry, rx))
        };
        for (a, b, c) in [
            (0.1, 0.2, 0.3),
            (3.1, 0.0, 0.0),
            (0.0, 3.1, 0.0),
            (0.0, 0.0, 3.1),
            (1.0, -2.0, 2.5),
            (2.9, 1.4, -3.0),
        ] {
            let r = rot(a, b, c);
            let [w, x, y, z] = quaternion(r);
            // Matrix of the quaternion.
            let m = [
                [
                    1.0 - 2.0 * (y * y + z * z),
                    2.0 * (x * y - z * w),
                    2.0 * (x * z + y * w),
                ],
                [
                    2.0 * (x * y + z * w),
                    1.0 - 2.0 * (x * x + z * z),
                    2.0 * (y * z - x * w),
                ],
                [
                    2.0 * (x * z - y * w),
                    2.0 * (y * z + x * w),
                    1.0 - 2.0 * (x * x + y * y),
                ],
            ];
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (m[i][j] - r[i][j]).abs() < 1e-12,
                        "{a} {b} {c}: {m:?} vs {r:?}"
                    );
                }
            }
            assert!(w >= 0.0);
        }
    }
}
