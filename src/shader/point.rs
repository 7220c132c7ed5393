//! What a shader knows about the surface point it shades.

use crate::nodes::math::V3;

use super::bump::ObjectTransform;

/// A shading point, in the spaces Cycles' texture-coordinate nodes read.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ShadingPoint {
    /// World-space position and shading normal.
    pub position: V3,
    pub normal: V3,
    /// Object-space position (Texture Coordinate > Object) and normal (> Normal).
    pub object_position: V3,
    pub object_normal: V3,
    /// Position in the mesh's texture space, 0..1 over its bounds (> Generated).
    pub generated: V3,
    /// The active render UV map, with w = 0 (> UV).
    pub uv: V3,
    /// Geometric (flat triangle) normal in world space, facing the incoming ray as Cycles'
    /// sd->Ng does; zero when unknown (then bumps use the shading normal's frame).
    pub ng: V3,
    /// Ray differentials of the position (world units per pixel), expanded from Cycles'
    /// compact form around `ng`: the Bump node's dx/dy offsets. Zero: no bump.
    pub dp_dx: V3,
    pub dp_dy: V3,
    /// Changes of Generated and UV along `dp_dx` / `dp_dy` (the attribute differentials
    /// of Cycles' bump variants of the coordinate nodes).
    pub generated_dx: V3,
    pub generated_dy: V3,
    pub uv_dx: V3,
    pub uv_dy: V3,
    /// The object's transform (object-space bump, displacement and normal maps).
    pub transform: ObjectTransform,
    /// The ray hit the back of the surface (normals already flipped toward it).
    pub backfacing: bool,
    /// Unit vector from the point back along the ray that reached it (Cycles' `sd->wi`,
    /// Geometry > Incoming). An EMIT bake sets it to the shading normal.
    pub incoming: V3,
    /// World-space geometric normal (Geometry > True Normal), flipped with `normal`
    /// when the ray hit the back of the surface.
    pub true_normal: V3,
    /// Cycles' barycentric (u, v) in its triangle: Geometry > Parametric is (1-u-v, u, 0).
    pub parametric: [f32; 2],
    /// On a hair curve (zero elsewhere): the curve's tangent dP/du in world space (Cycles'
    /// sd->dPdu, which the hair closures turn about).
    pub dpdu: V3,
    /// Length of the ray segment that reached the point (Light Path > Ray Length; 1 in a bake).
    pub ray_length: f32,
    /// What kind of ray reached the point, and the path's bounce counts (Light Path).
    pub path: PathState,
    /// Position in Cycles' camera space: x right, y up, z forward (Texture Coordinate >
    /// Camera, Camera Data).
    pub camera_position: V3,
    /// Cycles' camera-to-world transform and its inverse (Vector Transform).
    pub camera: crate::nodes::vector_transform::Affine,
    /// The world-space corners of the triangle hit (Wireframe); zero where there is none.
    pub triangle: [V3; 3],
    /// Position in the camera's normalised frame, 0..1 over the image, z = 0
    /// (Texture Coordinate > Window).
    pub window: V3,
    /// The shaded object (Object Info, object-space transforms).
    pub object: ObjectInfo,
    /// Mesh attribute values the program requested (`Program::attributes`, in order), as
    /// (x, y, z, alpha); filled by `attributes::BoundAttributes::fill`.
    pub attrs: [[f32; 4]; super::attributes::MAX_ATTRIBUTES],
    /// The Attribute node's Fac of each (x for 2D values, else the mean of x, y, z).
    pub attr_fac: [f32; super::attributes::MAX_ATTRIBUTES],
    /// Bit i set: request i is not on the mesh (Cycles' "attribute not found").
    pub attr_missing: u32,
    /// Changes of `attrs` and `attr_fac` along `dp_dx` ([0]) and `dp_dy` ([1]): the
    /// attribute differentials a Bump's dx/dy copy reads (Cycles' svm_node_attr_bump_dx).
    pub attrs_d: [[[f32; 4]; 2]; super::attributes::MAX_ATTRIBUTES],
    pub attr_fac_d: [[f32; 2]; super::attributes::MAX_ATTRIBUTES],
    /// On a truly displaced mesh: the point before displacement, which the material's
    /// displacement bump reads ("Both").
    pub undisplaced: Option<Undisplaced>,
    /// What the Hair Info node reads: zero everywhere but on hair curves.
    pub hair: HairPoint,
    /// Evaluating a Volume: the shaded object's texture space (location, size), which
    /// Point Density's Object space maps into; None on surfaces (where Cycles leaves the
    /// volume-only nodes out).
    pub volume_texspace: Option<([f32; 3], [f32; 3])>,
    /// What the Point Info node reads: zero everywhere but on point clouds.
    pub point: PointPoint,
}

/// A point-cloud hit as Cycles' Point Info node reads it (svm_node_point_info,
/// geom/point.h).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PointPoint {
    /// The point's centre in world space (point_position).
    pub position: V3,
    /// Its radius in world space (point_radius).
    pub radius: f32,
    /// hash_uint2_to_float(point index in its cloud, 0) (ATTR_STD_POINT_RANDOM).
    pub random: f32,
}

/// A hair hit as Cycles' Hair Info node reads it (svm_node_hair_info, geom/curve.h).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct HairPoint {
    /// 1 on a curve.
    pub is_strand: f32,
    /// The fraction of the curve's length at the hit (its keys' values, linear along
    /// the segment: an ATTR_STD_CURVE_INTERCEPT key attribute).
    pub intercept: f32,
    /// The curve's length in object space (ATTR_STD_CURVE_LENGTH).
    pub length: f32,
    /// Twice the radius, linear between the segment's keys (curve_thickness).
    pub thickness: f32,
    /// The incoming direction with its part along the curve removed, unit
    /// (curve_tangent_normal).
    pub tangent_normal: V3,
    /// hash_uint2_to_float(curve index, 0) (ATTR_STD_CURVE_RANDOM).
    pub random: f32,
    /// On a thick curve (3D Curves: a tube whose true normal the hair closures read)
    /// rather than a ribbon.
    pub thick: bool,
    /// The curves' normal attribute at the hit (ATTR_STD_VERTEX_NORMAL on curves: a
    /// Curves object's normals), zero without one.
    pub curve_normal: V3,
}

/// A shading point's position and differentials before true displacement (Cycles'
/// undisplaced position attribute, interpolated with the hit's barycentrics).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Undisplaced {
    pub position: V3,
    pub object_position: V3,
    pub dp_dx: V3,
    pub dp_dy: V3,
}

/// Cycles' path flags (`PATH_RAY_*`): defined in the foundation, since the BVH's ray
/// visibility reads them too.
pub use crate::foundation::ray;

/// The path state a Light Path node reads: flags from `ray` and bounce counts so far.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PathState {
    pub flags: u32,
    /// Non-transparent bounces (Ray Depth, before Cycles' +1 for shadow and emission rays).
    pub bounce: u32,
    pub diffuse: u32,
    pub glossy: u32,
    pub transmission: u32,
    pub transparent: u32,
}

impl PathState {
    /// An emitter evaluated for light sampling, outside any path (Cycles' bake of the
    /// world's importance map).
    pub const EMISSION: PathState = PathState {
        flags: ray::EMISSION,
        bounce: 0,
        diffuse: 0,
        glossy: 0,
        transmission: 0,
        transparent: 0,
    };

    /// A camera ray, as Cycles' EMIT bake and camera rays start.
    pub const CAMERA: PathState = PathState {
        flags: ray::CAMERA,
        bounce: 0,
        diffuse: 0,
        glossy: 0,
        transmission: 0,
        transparent: 0,
    };
}

/// The object a shading point belongs to, as Cycles' Object Info node and object-space
/// transforms see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectInfo {
    /// World-space origin of the object.
    pub location: V3,
    /// Object colour (RGBA; Alpha is the fourth).
    pub color: [f32; 4],
    /// Object pass index (Object Index).
    pub pass_index: f32,
    /// Cycles' per-object random number in [0, 1] (hash of the object name).
    pub random: f32,
    /// World to object transform, rows of an affine 3x4 matrix.
    pub world_to_object: [[f32; 4]; 3],
    /// The particle an instance stands for (Particle Info); None: Cycles' dummy particle
    /// (every value zero, index 0).
    pub particle: Option<crate::scene::format::Particle>,
}

impl Default for ObjectInfo {
    fn default() -> Self {
        ObjectInfo {
            location: [0.0; 3],
            color: [1.0; 4],
            pass_index: 0.0,
            random: 0.0,
            world_to_object: [
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 1.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
            ],
            particle: None,
        }
    }
}
