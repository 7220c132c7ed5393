//! A compiled material: a flat list of operations over a float stack, run once per
//! shading point with no allocation and no lookups by name (Cycles' SVM idea).

use crate::foundation::math::{Vec3, V3};
use crate::nodes::checker::checker_texture;
use crate::nodes::clamp::{clamp_node, ClampType};
use crate::nodes::color::{
    bright_contrast, gamma, hue_saturation, invert, rgb_to_bw, LINEAR_REC709,
};
use crate::nodes::curves::CurveTable;
use crate::nodes::gabor::{gabor_texture, GaborType};
use crate::nodes::gradient::{gradient, GradientType};
use crate::nodes::magic::magic;
use crate::nodes::map_range::{map_range_float, map_range_vector, MapRangeInterpolation};
use crate::nodes::mapping::{mapping, MappingType};
use crate::nodes::math::{math_node, vector_math, MathOp, VectorMathOp};
use crate::nodes::mix::{
    mix_color, mix_float, mix_rgb, mix_vector, mix_vector_non_uniform, MixBlend,
};
use crate::nodes::noise::{noise_texture_cycles, noise_texture_cycles_fac, NoiseParams, NoiseType};
use crate::nodes::ramp::RampTable;
use crate::nodes::sepcomb::{combine_color, separate_color, ColorMode};
use crate::nodes::vector_rotate::{vector_rotate, VectorRotateType};
use crate::nodes::vector_transform::{
    vector_transform, Affine, TransformSpace, VectorTransformType,
};
use crate::nodes::voronoi::{voronoi_texture, VoronoiFeature, VoronoiMetric, VoronoiParams};
use crate::nodes::wave::{wave, WaveSettings};
use crate::nodes::white_noise::white_noise;
use crate::nodes::{blackbody, wavelength};
use std::borrow::Cow;

use crate::nodes::brick::{brick_texture, BrickSettings};
use crate::nodes::image::{
    box_uvs, box_weights, direction_to_equirectangular, direction_to_mirrorball, project,
    safe_normalize, EnvProjection, Extension, Interpolation, Projection,
};

use super::bump::{
    bump_normal, differential_from_compact, differential_make_compact, displacement,
    displacement_bump, normal_map, offset_point_into, vector_displacement, BumpPoint, BumpSettings,
    MapSpace,
};
use super::images::TexImage;
use super::inputs::{self, Input};
use super::point::ShadingPoint;
use super::trace::{NoTrace, Trace};

/// A float's position on the stack; vectors and colours take three in a row.
pub type Slot = u32;

/// The socket kinds a shader program carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Float,
    Vector,
    Color,
}

impl Kind {
    pub fn width(self) -> u32 {
        match self {
            Kind::Float => 1,
            _ => 3,
        }
    }
}

#[derive(Debug, Clone)]
pub enum Op {
    /// Blender's implicit socket conversions.
    VectorToFloat {
        src: Slot,
        dst: Slot,
    },
    ColorToFloat {
        src: Slot,
        dst: Slot,
    },
    FloatToVector {
        src: Slot,
        dst: Slot,
    },
    /// Texture Coordinate outputs this program uses (None: not used).
    TexCoord {
        generated: Option<Slot>,
        normal: Option<Slot>,
        uv: Option<Slot>,
        object: Option<Slot>,
    },
    UvMap {
        dst: Slot,
    },
    Math {
        op: MathOp,
        clamp: bool,
        a: Slot,
        b: Slot,
        c: Slot,
        dst: Slot,
    },
    VectorMath {
        op: VectorMathOp,
        a: Slot,
        b: Slot,
        c: Slot,
        scale: Slot,
        vector: Slot,
        value: Slot,
    },
    MapRangeFloat {
        interp: MapRangeInterpolation,
        clamp: bool,
        args: [Slot; 6],
        dst: Slot,
    },
    MapRangeVector {
        interp: MapRangeInterpolation,
        clamp: bool,
        args: [Slot; 6],
        dst: Slot,
    },
    Clamp {
        kind: ClampType,
        value: Slot,
        min: Slot,
        max: Slot,
        dst: Slot,
    },
    MixFloat {
        clamp_factor: bool,
        factor: Slot,
        a: Slot,
        b: Slot,
        dst: Slot,
    },
    MixVector {
        clamp_factor: bool,
        factor: Slot,
        a: Slot,
        b: Slot,
        dst: Slot,
    },
    MixVectorNonUniform {
        clamp_factor: bool,
        factor: Slot,
        a: Slot,
        b: Slot,
        dst: Slot,
    },
    MixColor {
        blend: MixBlend,
        clamp_factor: bool,
        clamp_result: bool,
        factor: Slot,
        a: Slot,
        b: Slot,
        dst: Slot,
    },
    MixRgb {
        blend: MixBlend,
        clamp: bool,
        factor: Slot,
        a: Slot,
        b: Slot,
        dst: Slot,
    },
    Ramp {
        table: u32,
        fac: Slot,
        color: Slot,
        alpha: Slot,
    },
    /// RGB Curves / Vector Curves: `curves[table]` per channel.
    Curves3 {
        table: u32,
        fac: Slot,
        v: Slot,
        dst: Slot,
    },
    /// Float Curve.
    Curve1 {
        table: u32,
        fac: Slot,
        v: Slot,
        dst: Slot,
    },
    Invert {
        fac: Slot,
        color: Slot,
        dst: Slot,
    },
    Gamma {
        color: Slot,
        gamma: Slot,
        dst: Slot,
    },
    BrightContrast {
        color: Slot,
        bright: Slot,
        contrast: Slot,
        dst: Slot,
    },
    HueSaturation {
        hue: Slot,
        saturation: Slot,
        value: Slot,
        fac: Slot,
        color: Slot,
        dst: Slot,
    },
    RgbToBw {
        color: Slot,
        dst: Slot,
    },
    SeparateXyz {
        v: Slot,
        x: Slot,
        y: Slot,
        z: Slot,
    },
    CombineXyz {
        x: Slot,
        y: Slot,
        z: Slot,
        dst: Slot,
    },
    SeparateColor {
        mode: ColorMode,
        color: Slot,
        a: Slot,
        b: Slot,
        c: Slot,
    },
    CombineColor {
        mode: ColorMode,
        a: Slot,
        b: Slot,
        c: Slot,
        dst: Slot,
    },
    Blackbody {
        temperature: Slot,
        dst: Slot,
    },
    Wavelength {
        wavelength: Slot,
        dst: Slot,
    },
    /// World-space position (unlinked White Noise vectors).
    Position {
        dst: Slot,
    },
    /// Textures: inputs in socket order after Vector; outputs Fac/Distance first.
    TexNoise {
        dims: u8,
        kind: NoiseType,
        normalize: bool,
        vector: Slot,
        w: Slot,
        args: [Slot; 7],
        fac: Slot,
        color: Slot,
        want_color: bool,
    },
    TexVoronoi {
        dims: u8,
        feature: VoronoiFeature,
        metric: VoronoiMetric,
        normalize: bool,
        vector: Slot,
        w: Slot,
        args: [Slot; 7],
        distance: Slot,
        color: Slot,
        position: Slot,
        w_out: Slot,
        radius: Slot,
    },
    TexWave {
        settings: WaveSettings,
        vector: Slot,
        args: [Slot; 6],
        fac: Slot,
        color: Slot,
    },
    TexGradient {
        kind: GradientType,
        vector: Slot,
        fac: Slot,
        color: Slot,
    },
    TexMagic {
        depth: i32,
        vector: Slot,
        scale: Slot,
        distortion: Slot,
        fac: Slot,
        color: Slot,
    },
    TexWhiteNoise {
        dims: u8,
        vector: Slot,
        w: Slot,
        value: Slot,
        color: Slot,
    },
    TexChecker {
        vector: Slot,
        color1: Slot,
        color2: Slot,
        scale: Slot,
        fac: Slot,
        color: Slot,
    },
    VectorRotate {
        kind: VectorRotateType,
        invert: bool,
        vector: Slot,
        center: Slot,
        axis: Slot,
        angle: Slot,
        rotation: Slot,
        dst: Slot,
    },
    /// Vector Transform; `object` false where there is no object (a world shader).
    VectorTransform {
        kind: VectorTransformType,
        from: TransformSpace,
        to: TransformSpace,
        object: bool,
        vector: Slot,
        dst: Slot,
    },
    Wireframe {
        size: Slot,
        pixel_size: bool,
        dst: Slot,
    },
    /// Hair Info's outputs from the shading point's `hair` (is strand, intercept,
    /// length, thickness, tangent normal (3 slots), random).
    HairInfo {
        dst: [Slot; 6],
    },
    /// Point Info's outputs from the shading point's `point` (position (3 slots),
    /// radius, random).
    PointInfo {
        dst: [Slot; 3],
    },
    /// Particle Info's outputs from the object's particle (index, random, age,
    /// lifetime, location (3 slots), size, velocity (3), angular velocity (3)).
    ParticleInfo {
        dst: [Slot; 8],
    },
    /// Ambient Occlusion (svm/ao.h), traced through the `Trace` the program runs with
    /// (`inside` turns the normal around before tracing).
    AmbientOcclusion {
        color: Slot,
        distance: Slot,
        normal: Option<Slot>,
        samples: u32,
        inside: bool,
        only_local: bool,
        ao: Slot,
        color_out: Slot,
    },
    /// Bevel (svm/bevel.h): the traced normal, with a linked Normal input kept as the
    /// base the bevel's change is added to.
    Bevel {
        radius: Slot,
        normal: Option<Slot>,
        samples: u32,
        dst: Slot,
    },
    /// Gabor Texture: args are Scale, Frequency, Anisotropy, Orientation 2D.
    TexGabor {
        kind: GaborType,
        vector: Slot,
        args: [Slot; 4],
        orientation: Slot,
        value: Slot,
        phase: Slot,
        intensity: Slot,
    },
    Mapping {
        kind: MappingType,
        vector: Slot,
        location: Slot,
        rotation: Slot,
        scale: Slot,
        dst: Slot,
    },
    /// Brick Texture: args are Color1, Color2, Mortar, Scale, Mortar Size, Mortar Smooth,
    /// Bias, Brick Width, Row Height.
    TexBrick {
        settings: BrickSettings,
        vector: Slot,
        args: [Slot; 9],
        fac: Slot,
        color: Slot,
    },
    /// Image Texture; `unassociate`: the Alpha output is used and the image is colour.
    TexImage {
        image: std::sync::Arc<TexImage>,
        projection: Projection,
        blend: f32,
        interpolation: Interpolation,
        extension: Extension,
        unassociate: bool,
        vector: Slot,
        color: Slot,
        alpha: Slot,
    },
    /// Sky Texture, precomputed per node. `generated`: its Vector is the unlinked
    /// Generated coordinate (for a world, the ray direction), so Cycles can guide light
    /// samples toward its sun disc.
    TexSky {
        sky: std::sync::Arc<crate::nodes::sky::Sky>,
        vector: Slot,
        color: Slot,
        generated: bool,
    },
    /// Point Density: the grid Blender computed, in volumes only (zero on surfaces).
    TexPointDensity {
        grid: crate::nodes::point_density::VoxelGrid,
        interpolation: crate::nodes::point_density::Interpolation,
        space: crate::nodes::point_density::Space,
        vector: Slot,
        density: Slot,
        color: Slot,
    },
    /// IES Texture: Fac from the photometric table at the vector's direction.
    TexIes {
        table: std::sync::Arc<crate::nodes::ies::IesTable>,
        vector: Slot,
        strength: Slot,
        fac: Slot,
    },
    /// Environment Texture (the vector is a direction).
    TexEnvironment {
        image: std::sync::Arc<TexImage>,
        projection: EnvProjection,
        interpolation: Interpolation,
        unassociate: bool,
        vector: Slot,
        color: Slot,
        alpha: Slot,
    },
    /// The shading point the following ops read: a Bump height copy's offset point.
    BumpPoint {
        point: BumpPoint,
        width: f32,
    },
    /// Bump node; `normal` None: the shading normal.
    Bump {
        settings: BumpSettings,
        normal: Option<Slot>,
        strength: Slot,
        distance: Slot,
        center: Slot,
        dx: Slot,
        dy: Slot,
        dst: Slot,
    },
    Displacement {
        object_space: bool,
        height: Slot,
        midlevel: Slot,
        scale: Slot,
        normal: Option<Slot>,
        dst: Slot,
    },
    VectorDisplacement {
        space: MapSpace,
        vector: Slot,
        midlevel: Slot,
        scale: Slot,
        dst: Slot,
    },
    /// Material Output's Displacement as a bump: sets the shading normal for all that follows.
    DisplacementBump {
        object_space: bool,
        center: Slot,
        dx: Slot,
        dy: Slot,
        dst: Slot,
    },
    NormalMap {
        space: MapSpace,
        color: Slot,
        strength: Slot,
        dst: Slot,
    },
    /// A value of the shading context (Geometry, Object Info, Camera Data, Light Path,
    /// Texture Coordinate's Camera/Window/Reflection).
    Input {
        what: Input,
        dst: Slot,
    },
    /// Fresnel / Layer Weight: `normal` is None when unlinked (the shading normal).
    Fresnel {
        ior: Slot,
        normal: Option<Slot>,
        dst: Slot,
    },
    LayerWeight {
        blend: Slot,
        normal: Option<Slot>,
        fresnel: Slot,
        facing: Slot,
    },
    /// Light Falloff: Quadratic, Linear, Constant.
    LightFalloff {
        strength: Slot,
        smooth: Slot,
        dst: [Slot; 3],
    },
    /// Normal node's Dot output (its Normal output is a constant).
    NormalDot {
        direction: V3,
        normal: Slot,
        dst: Slot,
    },
    /// Texture Coordinate > Object relative to another object (its world-to-object).
    ObjectSpace {
        to_object: [[f32; 4]; 3],
        dst: Slot,
    },
    /// Tangent node, radial mode around axis 0/1/2 (X/Y/Z).
    TangentRadial {
        axis: u8,
        dst: Slot,
    },
    /// Attribute node (Geometry type): request `attr` as Color/Vector, Fac, Alpha.
    Attribute {
        attr: u8,
        vector: Slot,
        fac: Slot,
        alpha: Slot,
    },
    /// Color Attribute node: request `attr` as Color, Alpha (0 when missing, as Cycles).
    ColorAttribute {
        attr: u8,
        color: Slot,
        alpha: Slot,
    },
    /// UV Map node with a named map: request `attr` as (u, v, 0).
    NamedUv {
        attr: u8,
        dst: Slot,
    },
    /// Normal Map in tangent space: `tangent` and `normal` are requests (Tangent, MapNormal).
    NormalMapTangent {
        tangent: u8,
        normal: u8,
        color: Slot,
        strength: Slot,
        dst: Slot,
    },
    /// Vector Displacement in tangent space.
    VectorDisplacementTangent {
        tangent: u8,
        vector: Slot,
        midlevel: Slot,
        scale: Slot,
        dst: Slot,
    },
    /// Tangent node, UV Map mode.
    TangentUv {
        tangent: u8,
        dst: Slot,
    },
}

/// The shader part of a material: closures as a small tree over stack values.
#[derive(Debug, Clone)]
pub enum Closure {
    Emission {
        color: Slot,
        strength: Slot,
    },
    /// A BSDF node: its emission, if it has one (Principled), counts for EMIT bakes;
    /// its scattering is the renderer's business.
    Bsdf {
        emission: Option<(Slot, Slot)>,
    },
    Mix {
        fac: Slot,
        a: Option<u32>,
        b: Option<u32>,
    },
    Add {
        a: Option<u32>,
        b: Option<u32>,
    },
}

#[derive(Debug, Clone)]
pub struct Program {
    pub ops: Vec<Op>,
    /// The stack as it starts: constants in place, the rest zero.
    pub initial: Vec<f32>,
    pub ramps: Vec<RampTable>,
    /// Lookup tables of RGB/Vector/Float Curve nodes.
    pub curves: Vec<CurveTable>,
    pub closures: Vec<Closure>,
    /// The closure plugged into the Material Output's Surface.
    pub surface: Option<u32>,
    /// The closure plugged into the Material Output's Volume (render/volume.rs runs it
    /// at points inside the mesh).
    pub volume: Option<u32>,
    /// The volume's coefficients can vary from point to point (some value its closures
    /// read is computed, not constant): the renderer ray-marches it.
    pub volume_varying: bool,
    /// Every BSDF node's inputs, for the renderer to build its closures from.
    pub bsdfs: Vec<BsdfNode>,
    /// Where the normal bumped by the material's displacement lands after `run` (the
    /// shading normal of every closure), when the material has one.
    pub displaced_normal: Option<Slot>,
    /// The mesh attributes the ops read (`ShadingPoint::attrs`, in this order).
    pub attributes: Vec<super::attributes::AttributeRequest>,
    /// True displacement ("Displacement Only" or "Both"): where its ops end.
    pub displacement: Option<TrueDisplacement>,
    /// Cycles' emission estimate of the surface (Shader::estimate_emission): zero means
    /// the material never emits; its size decides whether emitters are light-sampled.
    pub emission_estimate: [f32; 3],
    /// The Surface is a colour or value linked straight into the output, which Cycles
    /// makes an Emission of and, as likely a preview, light-samples under Auto emission
    /// sampling only when a tenth of its estimate passes the threshold
    /// (Shader::estimate_emission).
    pub surface_from_value: bool,
    /// The AOV Outputs Cycles runs (naming a valid AOV of the view layer): after `run`
    /// their values are in the stack, for the renderer's AOV passes.
    pub aovs: Vec<AovWrite>,
    /// Some op moves the shading point to a Bump's dx/dy copy, the only reader of the
    /// Generated, UV and attribute differentials: without one the renderer skips them,
    /// as Cycles' SVM computes them only for the nodes that ask.
    pub reads_differentials: bool,
}

/// An AOV Output node: the view-layer AOV it writes (index into the exported list) and
/// where its value lands, the Color input for a colour AOV, else the Value input.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AovWrite {
    pub aov: u32,
    pub color: bool,
    pub slot: Slot,
}

/// Where a material's true displacement lives in its program. Ops `..center_end`
/// compute the displacement vector (world space) into `value`: the renderer runs them
/// alone at each vertex. With "Both", ops `..bump_end` are Cycles' separate bump shader,
/// which runs at the undisplaced surface (`ShadingPoint::undisplaced`) before the
/// surface ops; with "Displacement Only" shading skips the displacement ops.
#[derive(Debug, Clone, Copy)]
pub struct TrueDisplacement {
    pub center_end: usize,
    pub value: Slot,
    pub bump_end: Option<usize>,
}

/// A BSDF node as the renderer sees it: which closure it is, its type, and where each
/// of its (non-shader) inputs lives on the stack after `run`.
#[derive(Debug, Clone)]
pub struct BsdfNode {
    pub closure: u32,
    pub bl_idname: String,
    /// What the renderer shades for it, resolved when the material is compiled.
    pub kind: BsdfKind,
    /// (socket identifier, slot, linked): an unlinked Normal means the shading normal.
    pub inputs: Vec<(String, Slot, bool)>,
    /// The node's enum properties (distribution, subsurface method, ...).
    pub properties: Vec<(String, String)>,
    /// `inputs` by index into SHADING_SOCKETS (`index_sockets`): the slot, bit 31 set
    /// when linked, NO_SOCKET where the node has no such input.
    pub by_socket: Vec<u32>,
}

/// The BSDF input sockets the renderer reads at every shading point. Closures look
/// them up by index (`socket!`, resolved at compile time) in `BsdfNode::by_socket`:
/// comparing the identifiers as strings, some thirty times per Principled BSDF, was a
/// few percent of a render's time, which Cycles' SVM (stack offsets in the node) does
/// not spend.
pub const SHADING_SOCKETS: &[&str] = &[
    "Color",
    "Normal",
    "Roughness",
    "IOR",
    "Tangent",
    "Anisotropy",
    "Rotation",
    "Offset",
    "Coat Normal",
    "Base Color",
    "Aspect Ratio",
    "Transmission Weight",
    "Tint",
    "Thin Film Thickness",
    "Thin Film IOR",
    "TT lobe",
    "TRT lobe",
    "Subsurface Weight",
    "Subsurface Scale",
    "Subsurface Radius",
    "Subsurface IOR",
    "Subsurface Anisotropy",
    "Specular Tint",
    "Specular IOR Level",
    "Smooth",
    "Size",
    "Sheen Weight",
    "Sheen Tint",
    "Sheen Roughness",
    "Scale",
    "RoughnessV",
    "RoughnessU",
    "Random",
    "Random Roughness",
    "Random Color",
    "Radius",
    "Radial Roughness",
    "R lobe",
    "Position",
    "Metallic",
    "Melanin",
    "Melanin Redness",
    "Extinction",
    "Emission Strength",
    "Emission Color",
    "Edge Tint",
    "Direction",
    "Diffuse Roughness",
    "Coat",
    "Coat Weight",
    "Coat Tint",
    "Coat Roughness",
    "Coat IOR",
    "Anisotropic",
    "Anisotropic Rotation",
    "Alpha",
    "Absorption Coefficient",
];

const NO_SOCKET: u32 = u32::MAX;
const LINKED: u32 = 1 << 31;

/// The index of `id` in SHADING_SOCKETS; a compile error (const panic) for any other.
pub const fn socket_index(id: &str) -> usize {
    let id = id.as_bytes();
    let mut i = 0;
    while i < SHADING_SOCKETS.len() {
        let s = SHADING_SOCKETS[i].as_bytes();
        if s.len() == id.len() {
            let mut k = 0;
            while k < s.len() && s[k] == id[k] {
                k += 1;
            }
            if k == s.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("not in SHADING_SOCKETS")
}

/// `socket!("Base Color")`: the socket's index in SHADING_SOCKETS, as a constant.
macro_rules! socket {
    ($id:literal) => {
        const { $crate::shader::program::socket_index($id) }
    };
}
pub(crate) use socket;

/// The closure nodes the renderer shades, one per Blender node type (the legacy
/// Anisotropic BSDF is the Glossy BSDF). A closure node without one is a compile error, so
/// the renderer's dispatch has no fallback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BsdfKind {
    Principled,
    Diffuse,
    Glossy,
    Glass,
    Refraction,
    Translucent,
    Transparent,
    Subsurface,
    Holdout,
    Sheen,
    Metallic,
    Toon,
    Hair,
    PrincipledHair,
    RayPortal,
    /// Volume Absorption, Scatter, Principled Volume, Coefficients: shaded in a Volume by
    /// render/volume.rs; nothing in a Surface (as in Cycles).
    Volume,
}

impl BsdfKind {
    pub fn of(bl_idname: &str) -> Option<BsdfKind> {
        Some(match bl_idname {
            "ShaderNodeBsdfPrincipled" => BsdfKind::Principled,
            "ShaderNodeBsdfDiffuse" => BsdfKind::Diffuse,
            "ShaderNodeBsdfGlossy" | "ShaderNodeBsdfAnisotropic" => BsdfKind::Glossy,
            "ShaderNodeBsdfGlass" => BsdfKind::Glass,
            "ShaderNodeBsdfRefraction" => BsdfKind::Refraction,
            "ShaderNodeBsdfTranslucent" => BsdfKind::Translucent,
            "ShaderNodeBsdfTransparent" => BsdfKind::Transparent,
            "ShaderNodeSubsurfaceScattering" => BsdfKind::Subsurface,
            "ShaderNodeHoldout" => BsdfKind::Holdout,
            "ShaderNodeBsdfSheen" => BsdfKind::Sheen,
            "ShaderNodeBsdfMetallic" => BsdfKind::Metallic,
            "ShaderNodeBsdfToon" => BsdfKind::Toon,
            "ShaderNodeBsdfHair" => BsdfKind::Hair,
            "ShaderNodeBsdfHairPrincipled" => BsdfKind::PrincipledHair,
            "ShaderNodeBsdfRayPortal" => BsdfKind::RayPortal,
            "ShaderNodeVolumeAbsorption"
            | "ShaderNodeVolumeScatter"
            | "ShaderNodeVolumePrincipled"
            | "ShaderNodeVolumeCoefficients" => BsdfKind::Volume,
            _ => return None,
        })
    }
}

impl BsdfNode {
    pub fn input(&self, id: &str) -> Option<(Slot, bool)> {
        self.inputs.iter().find(|i| i.0 == id).map(|i| (i.1, i.2))
    }
    /// The input at `socket!(...)` index `k` (as `input` of that identifier).
    #[inline]
    pub fn input_at(&self, k: usize) -> Option<(Slot, bool)> {
        debug_assert_eq!(
            self.by_socket.len(),
            SHADING_SOCKETS.len(),
            "index_sockets ran"
        );
        match self.by_socket.get(k) {
            Some(&v) if v != NO_SOCKET => Some((v & !LINKED, v & LINKED != 0)),
            _ => None,
        }
    }
    /// Fills `by_socket` from `inputs` (the first input of an identifier, as `input`).
    pub fn index_sockets(&mut self) {
        self.by_socket = SHADING_SOCKETS
            .iter()
            .map(|id| match self.input(id) {
                Some((slot, linked)) => {
                    assert!(slot < LINKED, "stack slot {slot} out of range");
                    slot | if linked { LINKED } else { 0 }
                }
                None => NO_SOCKET,
            })
            .collect();
    }
    pub fn property(&self, key: &str) -> Option<&str> {
        self.properties
            .iter()
            .find(|p| p.0 == key)
            .map(|p| p.1.as_str())
    }
}

fn v3(s: &[f32], at: Slot) -> V3 {
    let i = at as usize;
    [s[i], s[i + 1], s[i + 2]]
}
fn put3(s: &mut [f32], at: Slot, v: V3) {
    let i = at as usize;
    s[i..i + 3].copy_from_slice(&v);
}

impl Program {
    /// A stack for `run`; reuse it across shading points.
    pub fn new_stack(&self) -> Vec<f32> {
        self.initial.clone()
    }

    /// Runs the program for one shading point, with no ray tracing (`NoTrace`).
    pub fn run(&self, sp: &ShadingPoint, s: &mut [f32]) {
        self.run_traced(sp, s, &NoTrace)
    }

    /// The sun disc Cycles' world light samples directly: the one Nishita sky with its
    /// disc read at the ray direction (None with none, or with several: Cycles then falls
    /// back to its importance map alone).
    pub fn sun_guide(&self) -> Option<crate::nodes::sky::SunGuide> {
        let mut suns = self.ops.iter().filter_map(|op| match op {
            Op::TexSky { sky, .. } => sky.sun_guide().map(|g| (g, op)),
            _ => None,
        });
        let (guide, op) = suns.next()?;
        if suns.next().is_some() {
            return None;
        }
        matches!(
            op,
            Op::TexSky {
                generated: true,
                ..
            }
        )
        .then_some(guide)
    }

    /// Whether the program traces rays at its shading point (Ambient Occlusion, Bevel).
    pub fn traces_rays(&self) -> bool {
        self.ops
            .iter()
            .any(|op| matches!(op, Op::AmbientOcclusion { .. } | Op::Bevel { .. }))
    }

    /// Runs the program for one shading point, its Ambient Occlusion and Bevel nodes
    /// tracing through `trace`. True displacement's ops never trace (Cycles has no BVH
    /// yet when it displaces; its displacement bump runs with the surface, and does).
    pub fn run_traced(&self, sp: &ShadingPoint, s: &mut [f32], trace: &dyn Trace) {
        s.copy_from_slice(&self.initial);
        let Some(d) = self.displacement else {
            self.exec(sp, s, &self.ops, trace);
            return;
        };
        match (d.bump_end, self.displaced_normal) {
            (Some(end), Some(normal)) => {
                // Cycles' bump shader of a displaced mesh reads the surface as it was
                // before displacement (svm_node_enter_bump_eval), then the surface ops
                // read the displaced point with the bumped normal. There the coordinate
                // copies move by the undisplaced differential in its compact form,
                // expanded around the displaced true normal as always; only the bump
                // itself takes the full undisplaced differential (`DisplacementBump`).
                let before = sp.undisplaced.map_or(*sp, |u| {
                    let (dp_dx, dp_dy) = differential_from_compact(
                        sp.ng,
                        differential_make_compact(u.dp_dx, u.dp_dy),
                    );
                    ShadingPoint {
                        position: u.position,
                        object_position: u.object_position,
                        dp_dx,
                        dp_dy,
                        ..*sp
                    }
                });
                self.exec(&before, s, &self.ops[..end], trace);
                let n = v3(s, normal);
                let after = ShadingPoint {
                    normal: n,
                    object_normal: sp.transform.inverse_normal(n),
                    ..*sp
                };
                self.exec(&after, s, &self.ops[end..], trace);
            }
            _ => self.exec(sp, s, &self.ops[d.center_end..], trace),
        }
    }

    /// The world-space vector true displacement moves the vertex at `sp` by (None: the
    /// material has no true displacement).
    pub fn displacement_at(&self, sp: &ShadingPoint, s: &mut [f32]) -> Option<V3> {
        let d = self.displacement?;
        s.copy_from_slice(&self.initial);
        self.exec(sp, s, &self.ops[..d.center_end], &NoTrace);
        Some(v3(s, d.value))
    }

    // Long because one arm per op, kept in one function so the interpreter's loop stays one jump table.
    fn exec(&self, sp: &ShadingPoint, s: &mut [f32], ops: &[Op], trace: &dyn Trace) {
        // `sp` is what the ops read: `base`, or a bump copy's offset point. Both borrow the
        // caller's point until an op changes one: the point is over a kilobyte, and copying
        // it twice per run showed as memmove in the profiles.
        let mut base = Cow::Borrowed(sp);
        let mut sp = Cow::Borrowed(sp);
        for op in ops {
            match *op {
                Op::VectorToFloat { src, dst } => {
                    let v = v3(s, src);
                    s[dst as usize] = (v[0] + v[1] + v[2]) * (1.0 / 3.0);
                }
                Op::ColorToFloat { src, dst } => {
                    s[dst as usize] = rgb_to_bw(v3(s, src), &LINEAR_REC709)
                }
                Op::FloatToVector { src, dst } => {
                    let f = s[src as usize];
                    put3(s, dst, [f, f, f]);
                }
                Op::TexCoord {
                    generated,
                    normal,
                    uv,
                    object,
                } => {
                    if let Some(d) = generated {
                        put3(s, d, sp.generated);
                    }
                    if let Some(d) = normal {
                        put3(s, d, sp.object_normal);
                    }
                    if let Some(d) = uv {
                        put3(s, d, sp.uv);
                    }
                    if let Some(d) = object {
                        put3(s, d, sp.object_position);
                    }
                }
                Op::UvMap { dst } => put3(s, dst, sp.uv),
                Op::Math {
                    op,
                    clamp,
                    a,
                    b,
                    c,
                    dst,
                } => {
                    s[dst as usize] =
                        math_node(op, clamp, s[a as usize], s[b as usize], s[c as usize])
                }
                Op::VectorMath {
                    op,
                    a,
                    b,
                    c,
                    scale,
                    vector,
                    value,
                } => {
                    let r = vector_math(op, v3(s, a), v3(s, b), v3(s, c), s[scale as usize]);
                    put3(s, vector, r.vector);
                    s[value as usize] = r.value;
                }
                Op::MapRangeFloat {
                    interp,
                    clamp,
                    args,
                    dst,
                } => {
                    let a = args.map(|i| s[i as usize]);
                    s[dst as usize] =
                        map_range_float(interp, clamp, a[0], a[1], a[2], a[3], a[4], a[5]);
                }
                Op::MapRangeVector {
                    interp,
                    clamp,
                    args,
                    dst,
                } => {
                    let a = args.map(|i| v3(s, i));
                    put3(
                        s,
                        dst,
                        map_range_vector(interp, clamp, a[0], a[1], a[2], a[3], a[4], a[5]),
                    );
                }
                Op::Clamp {
                    kind,
                    value,
                    min,
                    max,
                    dst,
                } => {
                    s[dst as usize] =
                        clamp_node(kind, s[value as usize], s[min as usize], s[max as usize])
                }
                Op::MixFloat {
                    clamp_factor,
                    factor,
                    a,
                    b,
                    dst,
                } => {
                    s[dst as usize] = mix_float(
                        clamp_factor,
                        s[factor as usize],
                        s[a as usize],
                        s[b as usize],
                    )
                }
                Op::MixVector {
                    clamp_factor,
                    factor,
                    a,
                    b,
                    dst,
                } => {
                    let r = mix_vector(clamp_factor, s[factor as usize], v3(s, a), v3(s, b));
                    put3(s, dst, r)
                }
                Op::MixVectorNonUniform {
                    clamp_factor,
                    factor,
                    a,
                    b,
                    dst,
                } => {
                    let r = mix_vector_non_uniform(clamp_factor, v3(s, factor), v3(s, a), v3(s, b));
                    put3(s, dst, r)
                }
                Op::MixColor {
                    blend,
                    clamp_factor,
                    clamp_result,
                    factor,
                    a,
                    b,
                    dst,
                } => {
                    let r = mix_color(
                        blend,
                        clamp_factor,
                        clamp_result,
                        s[factor as usize],
                        v3(s, a),
                        v3(s, b),
                    );
                    put3(s, dst, r)
                }
                Op::MixRgb {
                    blend,
                    clamp,
                    factor,
                    a,
                    b,
                    dst,
                } => {
                    let r = mix_rgb(blend, clamp, s[factor as usize], v3(s, a), v3(s, b));
                    put3(s, dst, r)
                }
                Op::Ramp {
                    table,
                    fac,
                    color,
                    alpha,
                } => {
                    let (c, a) = self.ramps[table as usize].color_ramp(s[fac as usize]);
                    put3(s, color, c);
                    s[alpha as usize] = a;
                }
                Op::Curves3 { table, fac, v, dst } => {
                    let r = self.curves[table as usize].eval3(s[fac as usize], v3(s, v));
                    put3(s, dst, r)
                }
                Op::Curve1 { table, fac, v, dst } => {
                    s[dst as usize] =
                        self.curves[table as usize].eval1(s[fac as usize], s[v as usize]);
                }
                Op::Invert { fac, color, dst } => {
                    let r = invert(s[fac as usize], v3(s, color));
                    put3(s, dst, r)
                }
                Op::Gamma {
                    color,
                    gamma: g,
                    dst,
                } => {
                    let r = gamma(v3(s, color), s[g as usize]);
                    put3(s, dst, r)
                }
                Op::BrightContrast {
                    color,
                    bright,
                    contrast,
                    dst,
                } => {
                    let r = bright_contrast(v3(s, color), s[bright as usize], s[contrast as usize]);
                    put3(s, dst, r)
                }
                Op::HueSaturation {
                    hue,
                    saturation,
                    value,
                    fac,
                    color,
                    dst,
                } => {
                    let r = hue_saturation(
                        s[hue as usize],
                        s[saturation as usize],
                        s[value as usize],
                        s[fac as usize],
                        v3(s, color),
                    );
                    put3(s, dst, r)
                }
                Op::RgbToBw { color, dst } => {
                    s[dst as usize] = rgb_to_bw(v3(s, color), &LINEAR_REC709)
                }
                Op::SeparateXyz { v, x, y, z } => {
                    let c = v3(s, v);
                    s[x as usize] = c[0];
                    s[y as usize] = c[1];
                    s[z as usize] = c[2];
                }
                Op::CombineXyz { x, y, z, dst } => {
                    let r = [s[x as usize], s[y as usize], s[z as usize]];
                    put3(s, dst, r)
                }
                Op::SeparateColor {
                    mode,
                    color,
                    a,
                    b,
                    c,
                } => {
                    let r = separate_color(mode, v3(s, color));
                    s[a as usize] = r[0];
                    s[b as usize] = r[1];
                    s[c as usize] = r[2];
                }
                Op::CombineColor { mode, a, b, c, dst } => {
                    let r = combine_color(mode, [s[a as usize], s[b as usize], s[c as usize]]);
                    put3(s, dst, r)
                }
                Op::Blackbody { temperature, dst } => {
                    let r = blackbody::blackbody(s[temperature as usize]);
                    put3(s, dst, r)
                }
                Op::Wavelength { wavelength: w, dst } => {
                    let r = wavelength::wavelength(s[w as usize], &LINEAR_REC709);
                    put3(s, dst, r)
                }
                Op::Position { dst } => put3(s, dst, sp.position),
                Op::TexNoise {
                    dims,
                    kind,
                    normalize,
                    vector,
                    w,
                    args,
                    fac,
                    color,
                    want_color,
                } => {
                    let a = args.map(|i| s[i as usize]);
                    let params = NoiseParams {
                        kind,
                        normalize,
                        detail: a[1],
                        roughness: a[2],
                        lacunarity: a[3],
                        offset: a[4],
                        gain: a[5],
                        distortion: a[6],
                    };
                    if want_color {
                        let (f, c) =
                            noise_texture_cycles(dims, v3(s, vector), s[w as usize], a[0], params);
                        s[fac as usize] = f;
                        put3(s, color, c);
                    } else {
                        s[fac as usize] = noise_texture_cycles_fac(
                            dims,
                            v3(s, vector),
                            s[w as usize],
                            a[0],
                            params,
                        );
                    }
                }
                Op::TexVoronoi {
                    dims,
                    feature,
                    metric,
                    normalize,
                    vector,
                    w,
                    args,
                    distance,
                    color,
                    position,
                    w_out,
                    radius,
                } => {
                    let a = args.map(|i| s[i as usize]);
                    let p = VoronoiParams::new(
                        feature, metric, normalize, a[0], a[1], a[2], a[3], a[4], a[5], a[6],
                    );
                    let o = voronoi_texture(dims, v3(s, vector), s[w as usize], p);
                    s[distance as usize] = o.distance;
                    put3(s, color, o.color);
                    put3(s, position, o.position);
                    s[w_out as usize] = o.w;
                    s[radius as usize] = o.radius;
                }
                Op::TexWave {
                    settings,
                    vector,
                    args,
                    fac,
                    color,
                } => {
                    let a = args.map(|i| s[i as usize]);
                    let f = wave(settings, v3(s, vector), a[0], a[1], a[2], a[3], a[4], a[5]);
                    s[fac as usize] = f;
                    put3(s, color, [f; 3]);
                }
                Op::TexGradient {
                    kind,
                    vector,
                    fac,
                    color,
                } => {
                    let f = gradient(kind, v3(s, vector));
                    s[fac as usize] = f;
                    put3(s, color, [f; 3]);
                }
                Op::TexMagic {
                    depth,
                    vector,
                    scale,
                    distortion,
                    fac,
                    color,
                } => {
                    let (c, f) = magic(
                        v3(s, vector),
                        s[scale as usize],
                        depth,
                        s[distortion as usize],
                    );
                    s[fac as usize] = f;
                    put3(s, color, c);
                }
                Op::TexWhiteNoise {
                    dims,
                    vector,
                    w,
                    value,
                    color,
                } => {
                    let (v, c) = white_noise(dims, v3(s, vector), s[w as usize]);
                    s[value as usize] = v;
                    put3(s, color, c);
                }
                Op::VectorTransform {
                    kind,
                    from,
                    to,
                    object,
                    vector,
                    dst,
                } => {
                    let o = Affine {
                        forward: sp.transform.to_world,
                        inverse: sp.transform.to_object,
                    };
                    let v = vector_transform(
                        kind,
                        from,
                        to,
                        v3(s, vector),
                        object.then_some(&o),
                        &sp.camera,
                    );
                    put3(s, dst, v);
                }
                Op::Wireframe {
                    size,
                    pixel_size,
                    dst,
                } => s[dst as usize] = inputs::wireframe_node(&sp, s[size as usize], pixel_size),
                Op::HairInfo { dst } => {
                    let h = &sp.hair;
                    s[dst[0] as usize] = h.is_strand;
                    s[dst[1] as usize] = h.intercept;
                    s[dst[2] as usize] = h.length;
                    s[dst[3] as usize] = h.thickness;
                    put3(s, dst[4], h.tangent_normal);
                    s[dst[5] as usize] = h.random;
                }
                Op::ParticleInfo { dst } => {
                    // Cycles' svm_node_particle_info; without a particle its dummy
                    // particle: all zero, index 0.
                    let p = sp
                        .object
                        .particle
                        .unwrap_or(crate::scene::format::Particle {
                            index: 0,
                            age: 0.0,
                            lifetime: 0.0,
                            location: [0.0; 3],
                            size: 0.0,
                            velocity: [0.0; 3],
                            angular_velocity: [0.0; 3],
                        });
                    s[dst[0] as usize] = p.index as f32;
                    s[dst[1] as usize] = crate::nodes::random::hash_to_float2(p.index, 0);
                    s[dst[2] as usize] = p.age;
                    s[dst[3] as usize] = p.lifetime;
                    put3(s, dst[4], p.location);
                    s[dst[5] as usize] = p.size;
                    put3(s, dst[6], p.velocity);
                    put3(s, dst[7], p.angular_velocity);
                }
                Op::PointInfo { dst } => {
                    let p = &sp.point;
                    put3(s, dst[0], p.position);
                    s[dst[1] as usize] = p.radius;
                    s[dst[2] as usize] = p.random;
                }
                Op::AmbientOcclusion {
                    color,
                    distance,
                    normal,
                    samples,
                    inside,
                    only_local,
                    ao,
                    color_out,
                } => {
                    let n = safe_normalize(normal.map_or(sp.normal, |n| v3(s, n)));
                    let n = if inside { n.map(|x| -x) } else { n };
                    let dist = s[distance as usize];
                    // Cycles' early out: nothing to trace.
                    let f = if dist > 0.0 && samples >= 1 {
                        trace.ambient_occlusion(&sp, n, dist, samples, only_local)
                    } else {
                        1.0
                    };
                    s[ao as usize] = f;
                    let c = v3(s, color);
                    put3(s, color_out, c.map(|x| x * f));
                }
                Op::Bevel {
                    radius,
                    normal,
                    samples,
                    dst,
                } => {
                    let r = s[radius as usize];
                    let b = if r > 0.0 && samples >= 1 {
                        trace.bevel(&sp, r, samples)
                    } else {
                        sp.normal
                    };
                    // A linked Normal keeps its own direction plus the bevel's change.
                    let out = match normal {
                        Some(n) => {
                            let d = Vec3::from(v3(s, n)) + b.into() - sp.normal.into();
                            // Cycles' normalize: a true division by the length.
                            (d / d.length()).into()
                        }
                        None => b,
                    };
                    put3(s, dst, out);
                }
                Op::TexGabor {
                    kind,
                    vector,
                    args,
                    orientation,
                    value,
                    phase,
                    intensity,
                } => {
                    let a = args.map(|a| s[a as usize]);
                    let r = gabor_texture(
                        kind,
                        v3(s, vector),
                        a[0],
                        a[1],
                        a[2],
                        a[3],
                        v3(s, orientation),
                    );
                    s[value as usize] = r[0];
                    s[phase as usize] = r[1];
                    s[intensity as usize] = r[2];
                }
                Op::VectorRotate {
                    kind,
                    invert,
                    vector,
                    center,
                    axis,
                    angle,
                    rotation,
                    dst,
                } => {
                    let r = vector_rotate(
                        kind,
                        invert,
                        v3(s, vector),
                        v3(s, center),
                        v3(s, axis),
                        s[angle as usize],
                        v3(s, rotation),
                    );
                    put3(s, dst, r);
                }
                Op::Mapping {
                    kind,
                    vector,
                    location,
                    rotation,
                    scale,
                    dst,
                } => {
                    let r = mapping(
                        kind,
                        v3(s, vector),
                        v3(s, location),
                        v3(s, rotation),
                        v3(s, scale),
                    );
                    put3(s, dst, r);
                }
                Op::TexChecker {
                    vector,
                    color1,
                    color2,
                    scale,
                    fac,
                    color,
                } => {
                    let (c, f) = checker_texture(
                        v3(s, vector),
                        v3(s, color1),
                        v3(s, color2),
                        s[scale as usize],
                    );
                    s[fac as usize] = f;
                    put3(s, color, c);
                }
                Op::TexBrick {
                    settings,
                    vector,
                    args,
                    fac,
                    color,
                } => {
                    let [c1, c2, m, scale, size, smooth, bias, width, height] = args;
                    let (c, f) = brick_texture(
                        v3(s, vector),
                        v3(s, c1),
                        v3(s, c2),
                        v3(s, m),
                        s[scale as usize],
                        s[size as usize],
                        s[smooth as usize],
                        s[bias as usize],
                        s[width as usize],
                        s[height as usize],
                        settings,
                    );
                    s[fac as usize] = f;
                    put3(s, color, c);
                }
                Op::TexImage {
                    ref image,
                    projection,
                    blend,
                    interpolation,
                    extension,
                    unassociate,
                    vector,
                    color,
                    alpha,
                } => {
                    let co = v3(s, vector);
                    let r = if projection == Projection::Box {
                        // Cycles weighs the three axis images by the object-space normal.
                        let n = sp.object_normal;
                        let w = box_weights(n, blend);
                        let uvs = box_uvs(n, co);
                        let mut f = [0.0f32; 4];
                        for k in 0..3 {
                            if w[k] > 0.0 {
                                let t = image.lookup(
                                    uvs[k][0],
                                    uvs[k][1],
                                    interpolation,
                                    extension,
                                    unassociate,
                                );
                                f = std::array::from_fn(|c| f[c] + w[k] * t[c]);
                            }
                        }
                        f
                    } else {
                        let uv = project(projection, co);
                        image.lookup(uv[0], uv[1], interpolation, extension, unassociate)
                    };
                    put3(s, color, [r[0], r[1], r[2]]);
                    s[alpha as usize] = r[3];
                }
                Op::TexSky {
                    ref sky,
                    vector,
                    color,
                    ..
                } => put3(s, color, sky.eval(v3(s, vector), &LINEAR_REC709)),
                Op::TexPointDensity {
                    ref grid,
                    interpolation,
                    space,
                    vector,
                    density,
                    color,
                } => {
                    use crate::nodes::point_density::Space;
                    let r = match sp.volume_texspace {
                        None => [0.0; 4],
                        Some((loc, size)) => {
                            let co = v3(s, vector);
                            let tex = match space {
                                // Cycles' volume_normalized_position.
                                Space::Object => {
                                    let o = crate::foundation::math::transform_point(
                                        &sp.transform.to_object,
                                        co,
                                    );
                                    [0, 1, 2].map(|k| (o[k] - loc[k]) / (2.0 * size[k]) + 0.5)
                                }
                                Space::World(t) => crate::foundation::math::transform_point(&t, co),
                            };
                            grid.sample(tex, interpolation)
                        }
                    };
                    s[density as usize] = r[3];
                    put3(s, color, [r[0], r[1], r[2]]);
                }
                Op::TexIes {
                    ref table,
                    vector,
                    strength,
                    fac,
                } => {
                    s[fac as usize] =
                        crate::nodes::ies::ies(table, v3(s, vector), s[strength as usize]);
                }
                Op::TexEnvironment {
                    ref image,
                    projection,
                    interpolation,
                    unassociate,
                    vector,
                    color,
                    alpha,
                } => {
                    let d = safe_normalize(v3(s, vector));
                    let uv = match projection {
                        EnvProjection::Equirectangular => direction_to_equirectangular(d),
                        EnvProjection::MirrorBall => direction_to_mirrorball(d),
                    };
                    // Environment textures always repeat (Cycles' EXTENSION_REPEAT).
                    let r =
                        image.lookup(uv[0], uv[1], interpolation, Extension::Repeat, unassociate);
                    put3(s, color, [r[0], r[1], r[2]]);
                    s[alpha as usize] = r[3];
                }
                Op::BumpPoint { point, width } => {
                    offset_point_into(sp.to_mut(), &base, point, width)
                }
                Op::Bump {
                    settings,
                    normal,
                    strength,
                    distance,
                    center,
                    dx,
                    dy,
                    dst,
                } => {
                    let n = normal.map_or(sp.normal, |n| v3(s, n));
                    let r = bump_normal(
                        &sp,
                        settings,
                        n,
                        s[strength as usize],
                        s[distance as usize],
                        s[center as usize],
                        s[dx as usize],
                        s[dy as usize],
                    );
                    put3(s, dst, r);
                }
                Op::Displacement {
                    object_space,
                    height,
                    midlevel,
                    scale,
                    normal,
                    dst,
                } => {
                    let n = normal.map_or(sp.normal, |n| v3(s, n));
                    let r = displacement(
                        &sp,
                        object_space,
                        s[height as usize],
                        s[midlevel as usize],
                        s[scale as usize],
                        n,
                    );
                    put3(s, dst, r);
                }
                Op::VectorDisplacement {
                    space,
                    vector,
                    midlevel,
                    scale,
                    dst,
                } => {
                    let r = vector_displacement(
                        &sp,
                        space,
                        v3(s, vector),
                        s[midlevel as usize],
                        s[scale as usize],
                    );
                    put3(s, dst, r);
                }
                Op::DisplacementBump {
                    object_space,
                    center,
                    dx,
                    dy,
                    dst,
                } => {
                    // At the undisplaced surface, Cycles' bump reads the full differential
                    // svm_node_enter_bump_eval saved, not the compact one.
                    let mut full = *base;
                    if let Some(u) = base.undisplaced {
                        (full.dp_dx, full.dp_dy) = (u.dp_dx, u.dp_dy);
                    }
                    let n =
                        displacement_bump(&full, object_space, v3(s, center), v3(s, dx), v3(s, dy));
                    let b = base.to_mut();
                    b.normal = n;
                    b.object_normal = b.transform.inverse_normal(n);
                    sp = base.clone();
                    put3(s, dst, n);
                }
                Op::NormalMap {
                    space,
                    color,
                    strength,
                    dst,
                } => {
                    let r = normal_map(&sp, space, v3(s, color), s[strength as usize]);
                    put3(s, dst, r);
                }
                Op::Input { what, dst } => inputs::read(what, &sp, s, dst),
                Op::Fresnel { ior, normal, dst } => {
                    s[dst as usize] =
                        inputs::fresnel_node(&sp, s[ior as usize], normal.map(|n| v3(s, n)))
                }
                Op::LayerWeight {
                    blend,
                    normal,
                    fresnel,
                    facing,
                } => {
                    let (f, g) =
                        inputs::layer_weight_node(&sp, s[blend as usize], normal.map(|n| v3(s, n)));
                    s[fresnel as usize] = f;
                    s[facing as usize] = g;
                }
                Op::LightFalloff {
                    strength,
                    smooth,
                    dst,
                } => {
                    let r =
                        inputs::light_falloff_node(&sp, s[strength as usize], s[smooth as usize]);
                    for (d, v) in dst.iter().zip(r) {
                        s[*d as usize] = v;
                    }
                }
                Op::NormalDot {
                    direction,
                    normal,
                    dst,
                } => s[dst as usize] = inputs::normal_dot(direction, v3(s, normal)),
                Op::ObjectSpace { to_object, dst } => put3(
                    s,
                    dst,
                    crate::foundation::math::transform_point(&to_object, sp.position),
                ),
                Op::TangentRadial { axis, dst } => put3(s, dst, inputs::radial_tangent(&sp, axis)),
                Op::Attribute {
                    attr,
                    vector,
                    fac,
                    alpha,
                } => {
                    let (a, missing) =
                        (sp.attrs[attr as usize], sp.attr_missing & (1 << attr) != 0);
                    put3(s, vector, [a[0], a[1], a[2]]);
                    s[fac as usize] = sp.attr_fac[attr as usize];
                    // Cycles reads a missing attribute's Alpha as 1 (its float3 fallback).
                    s[alpha as usize] = if missing { 1.0 } else { a[3] };
                }
                Op::ColorAttribute { attr, color, alpha } => {
                    let a = sp.attrs[attr as usize];
                    put3(s, color, [a[0], a[1], a[2]]);
                    s[alpha as usize] = a[3];
                }
                Op::NamedUv { attr, dst } => {
                    let a = sp.attrs[attr as usize];
                    put3(s, dst, [a[0], a[1], 0.0]);
                }
                Op::NormalMapTangent {
                    tangent,
                    normal,
                    color,
                    strength,
                    dst,
                } => {
                    let t = (sp.attr_missing & (1 << tangent) == 0)
                        .then_some(sp.attrs[tangent as usize]);
                    let n = sp.attrs[normal as usize];
                    let r = super::tangent::normal_map_tangent(
                        &sp,
                        t,
                        [n[0], n[1], n[2]],
                        v3(s, color),
                        s[strength as usize],
                    );
                    put3(s, dst, r);
                }
                Op::VectorDisplacementTangent {
                    tangent,
                    vector,
                    midlevel,
                    scale,
                    dst,
                } => {
                    let t = (sp.attr_missing & (1 << tangent) == 0)
                        .then_some(sp.attrs[tangent as usize]);
                    let r = super::tangent::vector_displacement_tangent(
                        &sp,
                        t,
                        v3(s, vector),
                        s[midlevel as usize],
                        s[scale as usize],
                    );
                    put3(s, dst, r);
                }
                Op::TangentUv { tangent, dst } => {
                    let t = (sp.attr_missing & (1 << tangent) == 0)
                        .then_some(sp.attrs[tangent as usize]);
                    put3(s, dst, super::tangent::tangent_uv(&sp, t));
                }
            }
        }
    }

    /// Total emission of the surface closure tree after `run` (what a Cycles EMIT bake
    /// records): Mix Shader weights clamp their factor to [0, 1] as Cycles does.
    pub fn surface_emission(&self, s: &[f32]) -> V3 {
        match self.surface {
            Some(c) => self.emission(c, s, 1.0),
            None => [0.0; 3],
        }
    }

    fn emission(&self, c: u32, s: &[f32], w: f32) -> V3 {
        let add = |a: V3, b: V3| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
        let sub = |x: Option<u32>, w: f32| match x {
            Some(x) if w != 0.0 => self.emission(x, s, w),
            _ => [0.0; 3],
        };
        match self.closures[c as usize] {
            Closure::Emission { color, strength }
            | Closure::Bsdf {
                emission: Some((color, strength)),
            } => {
                let k = w * s[strength as usize];
                let col = v3(s, color);
                [col[0] * k, col[1] * k, col[2] * k]
            }
            Closure::Bsdf { emission: None } => [0.0; 3],
            Closure::Mix { fac, a, b } => {
                let f = s[fac as usize].clamp(0.0, 1.0);
                add(sub(a, w * (1.0 - f)), sub(b, w * f))
            }
            Closure::Add { a, b } => add(sub(a, w), sub(b, w)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `input_at(socket!(id))` finds what `input(id)` finds, for every identifier the
    /// renderer reads, present, linked, unlinked or missing, the first of duplicates.
    #[test]
    fn socket_index_agrees_with_lookup_by_name() {
        for (i, id) in SHADING_SOCKETS.iter().enumerate() {
            assert_eq!(socket_index(id), i, "{id} listed twice");
        }
        let mut b = BsdfNode {
            closure: 0,
            bl_idname: "ShaderNodeBsdfPrincipled".into(),
            kind: BsdfKind::Principled,
            inputs: vec![
                ("Base Color".into(), 7, true),
                ("Roughness".into(), 3, false),
                ("Coat Normal".into(), 12, true),
                ("Roughness".into(), 40, true),
                ("Not Read".into(), 1, true),
            ],
            properties: Vec::new(),
            by_socket: Vec::new(),
        };
        b.index_sockets();
        for (i, id) in SHADING_SOCKETS.iter().enumerate() {
            assert_eq!(b.input_at(i), b.input(id), "{id}");
        }
        assert_eq!(b.input_at(socket!("Roughness")), Some((3, false)));
        assert_eq!(b.input_at(socket!("Coat Normal")), Some((12, true)));
        assert_eq!(b.input_at(socket!("Metallic")), None);
    }
}
