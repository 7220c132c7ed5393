//! Node-graph evaluation shared by shader graphs and Geometry Nodes.
//!
//! Each node family gets its own file here, named as Blender names it (math, noise,
//! voronoi, ramp, ...), used by the shader compiler (`shader/`) and by Geometry Nodes'
//! field nodes (`geometry/nodes/function.rs`, `texture.rs`, `color.rs`). Where Blender's
//! Geometry Nodes compute differently from Cycles (Gradient's clamp, the ramp's table,
//! curve clipping) the family offers both as siblings. Until a family is implemented
//! and proven against Blender's numbers, the shader node table (`shader::compile::NODES`,
//! read by `shader::compile::support`) reports it as unsupported:
//! `blendsynth inspect` must never claim a node that would be evaluated as something else.

/// Declares a node-mode enum together with the Blender RNA enum identifiers it is parsed
/// from (`from_blender`) and printed as (`blender_name`), plus `ALL` in Blender's order.
macro_rules! blender_enum {
    ($(#[$meta:meta])* $vis:vis enum $name:ident { $($(#[$vmeta:meta])* $variant:ident = $id:literal,)+ }) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $name { $($(#[$vmeta])* $variant,)+ }

        impl $name {
            /// Every mode, in the order Blender lists them.
            pub const ALL: &'static [$name] = &[$($name::$variant,)+];

            /// Parses Blender's enum identifier (e.g. `"MULTIPLY"`).
            pub fn from_blender(id: &str) -> Option<Self> {
                match id {
                    $($id => Some($name::$variant),)+
                    _ => None,
                }
            }

            /// Blender's enum identifier for this mode.
            pub fn blender_name(self) -> &'static str {
                match self {
                    $($name::$variant => $id,)+
                }
            }
        }
    };
}

pub mod blackbody;
pub mod clamp;
pub mod color;
pub mod curves;
pub mod graph;
pub mod map_range;
pub mod math;
pub mod mix;
pub mod noise;
pub mod ramp;
pub mod random;
pub mod sepcomb;
pub mod wavelength;
// Textures.
pub mod checker;
pub mod gradient;
pub mod magic;
pub mod mapping;
pub mod vector_rotate;
pub mod vector_transform;
pub mod voronoi;
pub mod wave;
pub mod white_noise;
// Gabor Texture.
pub mod gabor;
// Sky Texture (sky.rs; the Hosek/Wilkie data in sky_hosek.rs).
pub mod sky;
pub mod sky_hosek;
// Brick, Image and Environment Textures.
pub mod brick;
pub mod image;
// IES Texture.
pub mod ies;
pub mod point_density;
// Input nodes that read the shading context.
pub mod fresnel;
pub mod light_falloff;

/// How blendsynth handles a node type (by its `bl_idname`; `shader::compile::support`
/// answers for shader nodes from the shader node table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Support {
    /// Evaluated with Blender's semantics and covered by the conformance suite.
    Supported,
    /// Graph structure, resolved when a tree is compiled (frames, reroutes, group
    /// sockets, group nodes); nothing to evaluate.
    Structural,
    /// Not implemented yet: a scene using it cannot be evaluated faithfully.
    Unsupported,
    /// Cycles' Blender sync creates nothing for it (EEVEE-only and legacy nodes): its
    /// links are dropped, so the sockets it feeds keep their own values. blendsynth does
    /// the same (`graph::flatten`), proven by tests/bake.rs' `cycles_ignored` bake.
    IgnoredByCycles,
}

/// Shader node types Cycles 4.5 ignores (`add_node` in intern/cycles/blender/shader.cpp
/// has no case for them): Shader to RGB and Specular BSDF are EEVEE-only, Squeeze Value
/// is legacy, UV Along Stroke and Line Style Output are Freestyle's.
pub const IGNORED_BY_CYCLES: &[&str] = &[
    "ShaderNodeShaderToRGB",
    "ShaderNodeEeveeSpecular",
    "ShaderNodeSqueeze",
    "ShaderNodeUVAlongStroke",
    "ShaderNodeOutputLineStyle",
];

/// Node types that only shape the graph: frames and reroutes are dropped, group nodes
/// are inlined, group input/output nodes become the group's boundary.
pub const STRUCTURAL: &[&str] = &[
    "NodeFrame",
    "NodeReroute",
    "NodeGroupInput",
    "NodeGroupOutput",
    "ShaderNodeGroup",
    "GeometryNodeGroup",
];
