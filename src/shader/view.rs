//! What a shading point knows about the camera and the object it belongs to: Cycles'
//! world-to-camera and world-to-NDC transforms (Texture Coordinate > Camera and Window,
//! Camera Data) and the per-object values of Object Info.

use crate::nodes::math::V3;
use crate::nodes::random::hash2;
use crate::scene::Object;

use super::point::ObjectInfo;

/// The render camera as the texture-coordinate nodes see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// World to Cycles camera space (x right, y up, z forward; Blender's camera looks down -Z).
    pub world_to_camera: [[f32; 4]; 3],
    /// Its inverse, Cycles' cameratoworld (Vector Transform).
    pub camera_to_world: [[f32; 4]; 3],
    pub ortho: bool,
    /// tan(fov/2) of a perspective camera, so screen = camera xy / (z tan_half).
    pub tan_half: f32,
    /// Cycles' viewplane, already shifted: the window spans [left, right] x [bottom, top].
    pub left: f32,
    pub right: f32,
    pub bottom: f32,
    pub top: f32,
}

impl Default for View {
    /// A camera at the origin looking down -Z with a square 90 degree view, for scenes
    /// without one.
    fn default() -> Self {
        View {
            world_to_camera: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, -1.0, 0.0],
            ],
            camera_to_world: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, -1.0, 0.0],
            ],
            ortho: false,
            tan_half: 1.0,
            left: -1.0,
            right: 1.0,
            bottom: -1.0,
            top: 1.0,
        }
    }
}

impl View {
    /// A view from a camera-to-world transform (Blender convention, scale removed).
    pub fn new(
        camera_to_world: &[[f32; 4]; 3],
        ortho: bool,
        tan_half: f32,
        viewplane: [f32; 4],
    ) -> View {
        let m: [[f64; 4]; 4] = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if r < 3 {
                    camera_to_world[r][c] as f64
                } else if c == 3 {
                    1.0
                } else {
                    0.0
                }
            })
        });
        let inv = invert_affine(&m).unwrap_or([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
        // Cycles flips Blender's camera Z so that it looks down +Z.
        let world_to_camera = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if r == 2 {
                    -inv[r][c] as f32
                } else {
                    inv[r][c] as f32
                }
            })
        });
        // Cycles' cameratoworld: Blender's camera-to-world with its Z axis flipped.
        let camera_to_world = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                if c == 2 {
                    -m[r][c] as f32
                } else {
                    m[r][c] as f32
                }
            })
        });
        View {
            world_to_camera,
            camera_to_world,
            ortho,
            tan_half,
            left: viewplane[0],
            right: viewplane[1],
            bottom: viewplane[2],
            top: viewplane[3],
        }
    }

    /// Cycles' camera-to-world transform and its inverse (Vector Transform's camera space).
    pub fn camera(&self) -> crate::nodes::vector_transform::Affine {
        crate::nodes::vector_transform::Affine {
            forward: self.camera_to_world,
            inverse: self.world_to_camera,
        }
    }

    /// A world point in Cycles' camera space.
    #[inline]
    pub fn camera_space(&self, p: V3) -> V3 {
        let m = &self.world_to_camera;
        std::array::from_fn(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
    }

    /// A camera-space point in normalised window coordinates (0..1 over the image, z = 0).
    #[inline]
    pub fn window(&self, c: V3) -> V3 {
        let (sx, sy) = if self.ortho {
            (c[0], c[1])
        } else {
            (c[0] / (c[2] * self.tan_half), c[1] / (c[2] * self.tan_half))
        };
        [
            (sx - self.left) / (self.right - self.left),
            (sy - self.bottom) / (self.top - self.bottom),
            0.0,
        ]
    }
}

/// Cycles' string hash (`hash_string`): i = i * 37 + byte.
fn hash_string(s: &str) -> u32 {
    s.bytes().fold(0u32, |i, c| {
        i.wrapping_mul(37).wrapping_add(c as i8 as i32 as u32)
    })
}

/// Object Info > Random of an object that is not an instance: Cycles hashes its name.
pub fn object_random(name: &str) -> f32 {
    let id = hash2(hash_string(name), 0);
    id as f32 * (1.0 / 0xFFFF_FFFFu32 as f32)
}

/// The Object Info values of an exported object at its world transform `to_world`.
pub fn object_info(obj: &Object, to_world: &[[f64; 4]; 4]) -> ObjectInfo {
    let inv = invert_affine(to_world).unwrap_or([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    let color = obj.color.unwrap_or([1.0; 4]);
    ObjectInfo {
        location: [
            to_world[0][3] as f32,
            to_world[1][3] as f32,
            to_world[2][3] as f32,
        ],
        color: color.map(|c| c as f32),
        pass_index: obj.pass_index as f32,
        random: object_random(&obj.name),
        world_to_object: std::array::from_fn(|r| std::array::from_fn(|c| inv[r][c] as f32)),
        particle: None,
    }
}

/// The inverse of an affine transform (rows; last row 0 0 0 1).
pub fn invert_affine(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let a = |r: usize, c: usize| m[r][c];
    let cof = |r: usize, c: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
        a(r1, c1) * a(r2, c2) - a(r1, c2) * a(r2, c1)
    };
    let det = a(0, 0) * cof(0, 0) + a(0, 1) * cof(0, 1) + a(0, 2) * cof(0, 2);
    if det.abs() < 1e-30 {
        return None;
    }
    let mut out = [[0.0; 4]; 4];
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] = cof(j, i) / det;
        }
        out[i][3] = -(out[i][0] * m[0][3] + out[i][1] * m[1][3] + out[i][2] * m[2][3]);
    }
    out[3][3] = 1.0;
    Some(out)
}
