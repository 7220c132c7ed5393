//! Input nodes that read the shading context rather than other nodes (Cycles'
//! svm/geometry.h, camera.h, tex_coord.h, light_path.h, fresnel.h, normal.h,
//! tangent.h): what each output reads from the `ShadingPoint`.

use crate::foundation::math::{Vec3, V3};
use crate::nodes::fresnel::{fresnel, layer_weight};
use crate::nodes::light_falloff::light_falloff;

use super::point::{ray, ShadingPoint};

/// One value a shading point provides, as an input node's output reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    // Geometry.
    Position,
    Normal,
    /// Cycles' radial tangent around the object's Z axis, from Generated coordinates.
    Tangent,
    TrueNormal,
    Incoming,
    Parametric,
    Backfacing,
    // Object Info.
    ObjectLocation,
    ObjectColor,
    ObjectAlpha,
    ObjectIndex,
    ObjectRandom,
    // Camera Data.
    ViewVector,
    ViewZDepth,
    ViewDistance,
    // Texture Coordinate.
    Camera,
    Window,
    Reflection,
    // Light Path: a flag of `ray`, or a count.
    RayFlag(u32),
    RayLength,
    RayDepth,
    DiffuseDepth,
    GlossyDepth,
    TransparentDepth,
    TransmissionDepth,
}

impl Input {
    /// True when the value is a vector (three slots), false for a float.
    pub fn is_vector(self) -> bool {
        use Input::*;
        matches!(
            self,
            Position
                | Normal
                | Tangent
                | TrueNormal
                | Incoming
                | Parametric
                | ObjectLocation
                | ObjectColor
                | ViewVector
                | Camera
                | Window
                | Reflection
        )
    }

    /// The Light Path output with socket identifier `id`.
    pub fn light_path(id: &str) -> Option<Input> {
        Some(match id {
            "Is Camera Ray" => Input::RayFlag(ray::CAMERA),
            "Is Shadow Ray" => Input::RayFlag(ray::SHADOW),
            "Is Diffuse Ray" => Input::RayFlag(ray::DIFFUSE),
            "Is Glossy Ray" => Input::RayFlag(ray::GLOSSY),
            "Is Singular Ray" => Input::RayFlag(ray::SINGULAR),
            "Is Reflection Ray" => Input::RayFlag(ray::REFLECT),
            "Is Transmission Ray" => Input::RayFlag(ray::TRANSMIT),
            "Is Volume Scatter Ray" => Input::RayFlag(ray::VOLUME_SCATTER),
            "Ray Length" => Input::RayLength,
            "Ray Depth" => Input::RayDepth,
            "Diffuse Depth" => Input::DiffuseDepth,
            "Glossy Depth" => Input::GlossyDepth,
            "Transparent Depth" => Input::TransparentDepth,
            "Transmission Depth" => Input::TransmissionDepth,
            _ => return None,
        })
    }
}

/// Cycles' `normalize`: no guard, a zero vector gives NaNs as it does there.
fn normalize(v: Vec3) -> Vec3 {
    v / v.dot(v).sqrt()
}
/// An object-space direction to world space the way Cycles transforms normals
/// (`object_normal_transform`: by the transposed world-to-object matrix).
pub fn object_normal_to_world(sp: &ShadingPoint, n: V3) -> V3 {
    let m = &sp.object.world_to_object;
    std::array::from_fn(|c| m[0][c] * n[0] + m[1][c] * n[1] + m[2][c] * n[2])
}

/// Tangent node, radial mode, around `axis` (0 = X, 1 = Y, 2 = Z) of Generated
/// coordinates; also Geometry > Tangent (axis Z).
pub fn radial_tangent(sp: &ShadingPoint, axis: u8) -> V3 {
    let g = sp.generated;
    let t = match axis {
        0 => [0.0, -(g[2] - 0.5), g[1] - 0.5],
        1 => [-(g[2] - 0.5), 0.0, g[0] - 0.5],
        _ => [-(g[1] - 0.5), g[0] - 0.5, 0.0],
    };
    let t = Vec3::from(object_normal_to_world(sp, t));
    let n = Vec3::from(sp.normal);
    n.cross(normalize(t.cross(n))).into()
}

/// Writes input `what` of `sp` to the stack at `dst` (three slots for a vector).
#[inline]
pub fn read(what: Input, sp: &ShadingPoint, s: &mut [f32], dst: u32) {
    let d = dst as usize;
    let path = &sp.path;
    let f = |b: bool| if b { 1.0 } else { 0.0 };
    let v: V3 = match what {
        Input::Position => sp.position,
        Input::Normal => sp.normal,
        Input::Tangent => radial_tangent(sp, 2),
        Input::TrueNormal => sp.true_normal,
        Input::Incoming => sp.incoming,
        Input::Parametric => [
            1.0 - sp.parametric[0] - sp.parametric[1],
            sp.parametric[0],
            0.0,
        ],
        Input::ObjectLocation => sp.object.location,
        Input::ObjectColor => [sp.object.color[0], sp.object.color[1], sp.object.color[2]],
        Input::ViewVector => normalize(sp.camera_position.into()).into(),
        Input::Camera => sp.camera_position,
        Input::Window => sp.window,
        Input::Reflection => {
            let (n, i) = (Vec3::from(sp.normal), Vec3::from(sp.incoming));
            (2.0 * n.dot(i) * n - i).into()
        }
        scalar => {
            s[d] = match scalar {
                Input::Backfacing => f(sp.backfacing),
                Input::ObjectAlpha => sp.object.color[3],
                Input::ObjectIndex => sp.object.pass_index,
                Input::ObjectRandom => sp.object.random,
                Input::ViewZDepth => sp.camera_position[2],
                Input::ViewDistance => Vec3::from(sp.camera_position).length(),
                Input::RayFlag(flag) => f(path.flags & flag != 0),
                Input::RayLength => sp.ray_length,
                // Shadow rays and light emission are one bounce further (Cycles).
                Input::RayDepth => {
                    path.bounce as f32 + f(path.flags & (ray::SHADOW | ray::EMISSION) != 0)
                }
                Input::DiffuseDepth => path.diffuse as f32,
                Input::GlossyDepth => path.glossy as f32,
                Input::TransparentDepth => path.transparent as f32,
                Input::TransmissionDepth => path.transmission as f32,
                _ => 0.0,
            };
            return;
        }
    };
    s[d..d + 3].copy_from_slice(&v);
}

/// Fresnel node; `normal` is the linked Normal input, or the shading normal.
#[inline]
pub fn fresnel_node(sp: &ShadingPoint, ior: f32, normal: Option<V3>) -> f32 {
    fresnel(ior, sp.incoming, normal.unwrap_or(sp.normal), sp.backfacing)
}

/// Layer Weight node: (Fresnel, Facing).
#[inline]
pub fn layer_weight_node(sp: &ShadingPoint, blend: f32, normal: Option<V3>) -> (f32, f32) {
    layer_weight(
        blend,
        sp.incoming,
        normal.unwrap_or(sp.normal),
        sp.backfacing,
    )
}

/// Light Falloff node: (Quadratic, Linear, Constant).
#[inline]
pub fn light_falloff_node(sp: &ShadingPoint, strength: f32, smooth: f32) -> [f32; 3] {
    light_falloff(strength, smooth, sp.ray_length)
}

/// Normal node's Dot output: its (normalised) direction against the normalised input.
#[inline]
pub fn normal_dot(direction: V3, normal: V3) -> f32 {
    Vec3::from(direction).dot(normalize(normal.into()))
}

/// Cycles' Wireframe (svm/wireframe.h): 1 where the point lies within half of `size`
/// (world units, or pixel widths with `pixel_size`) of an edge of its triangle; the
/// neighbouring triangle draws the other half.
pub fn wireframe_node(sp: &ShadingPoint, size: f32, pixel_size: bool) -> f32 {
    let co = sp.triangle;
    let mut width = 1.0;
    if pixel_size {
        // The position's differentials projected onto the plane facing the ray.
        let wi = Vec3::from(sp.incoming);
        let across = |d: V3| {
            let d = Vec3::from(d);
            (d - d.dot(wi) * wi).length()
        };
        width = (across(sp.dp_dx) + across(sp.dp_dy)) * 0.5;
    }
    width *= 0.5 * size;
    width *= width;
    for i in 0..3 {
        let i2 = if i > 0 { i - 1 } else { 2 };
        let p = Vec3::from(sp.position);
        let dir = p - co[i].into();
        let edge = Vec3::from(co[i]) - co[i2].into();
        let c = edge.cross(dir);
        // |c|^2 / |edge|^2 is the squared distance to the edge.
        if c.dot(c) < edge.dot(edge) * width {
            return 1.0;
        }
    }
    0.0
}
