//! The shader node table: every node type the compiler runs, with its compile step and
//! where its semantics and their proof against Cycles live. `support` (and so `inspect`),
//! the compiler's dispatch and docs/features.md all read this one table; a new shader
//! node is one line here plus its compile function below, in its Blender group.

use serde_json::Value;

use crate::nodes::clamp::ClampType;
use crate::nodes::curves::CurveKind;
use crate::nodes::gabor::GaborType;
use crate::nodes::gradient::GradientType;
use crate::nodes::graph::Source;
use crate::nodes::map_range::MapRangeInterpolation;
use crate::nodes::mapping::MappingType;
use crate::nodes::math::{MathOp, VectorMathOp};
use crate::nodes::mix::MixBlend;
use crate::nodes::noise::NoiseType;
use crate::nodes::sepcomb::ColorMode;
use crate::nodes::vector_rotate::VectorRotateType;
use crate::nodes::vector_transform::{TransformSpace, VectorTransformType};
use crate::nodes::voronoi::{VoronoiFeature, VoronoiMetric};
use crate::nodes::wave::{BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType};
use crate::nodes::{Support, IGNORED_BY_CYCLES, STRUCTURAL};

use super::super::bump::{BumpSettings, MapSpace};
use super::super::bump_graph::{self, Schedule};
use super::{
    aov_index, dimensions, floats, kind_of, linked, mode, prop, prop_bool, prop_str, Closure,
    CompileError, Compiler, Kind, Op,
};
use crate::shader::program::AovWrite;
use Kind::{Color as C, Float as F, Vector as V};

/// One node type's compile step: node `i` of the compiler's graph into ops, output slots
/// and closures (the schedule gives the bump copies).
pub(super) type Compile = fn(&mut Compiler<'_, '_>, usize, &Schedule) -> Result<(), CompileError>;

/// A shader node type blendsynth evaluates with Cycles' semantics.
pub struct ShaderNode {
    /// Blender's node type (`bl_idname`).
    pub bl_idname: &'static str,
    /// Where its semantics live and what proves them against Cycles.
    pub notes: &'static str,
    pub(super) compile: Compile,
}

const fn node(bl_idname: &'static str, compile: Compile, notes: &'static str) -> ShaderNode {
    ShaderNode {
        bl_idname,
        notes,
        compile,
    }
}

/// How blendsynth handles a shader node type (by its `bl_idname`): graph structure,
/// ignored as Cycles ignores it, compiled from this table, or not supported.
pub fn support(bl_idname: &str) -> Support {
    if STRUCTURAL.contains(&bl_idname) {
        Support::Structural
    } else if IGNORED_BY_CYCLES.contains(&bl_idname) {
        Support::IgnoredByCycles
    } else if find(bl_idname).is_some() {
        Support::Supported
    } else {
        Support::Unsupported
    }
}

/// The table entry of a node type, if blendsynth compiles it.
pub fn find(bl_idname: &str) -> Option<&'static ShaderNode> {
    NODES.iter().find(|n| n.bl_idname == bl_idname)
}

const INPUT_CONSTANT: &str =
    "constant and coordinate inputs (shader/compile); tests/bake.rs, tests/inputs.rs";
const INPUT_CONTEXT: &str =
    "reads the shading context (shader/inputs.rs; nodes/fresnel.rs, light_falloff.rs; Pointiness and Random Per Island from shader/derived.rs); tests/inputs.rs against Cycles' EMIT bakes";
const ATTRIBUTE: &str =
    "mesh attributes (shader/attributes.rs, tangent.rs); tests/attributes.rs; types Object/Instancer/View Layer are compile errors naming the node";
const WIREFRAME: &str =
    "shader/inputs.rs (the hit triangle's world-space corners): Size in world units and in pixels, Cycles' EMIT bakes in tests/bake.rs";
const RAY_TRACED: &str =
    "ray-traced at the shading point (shader/trace.rs, render/shader_rays.rs: Cycles' svm/ao.h and svm/bevel.h; 1 and the shading normal where Cycles cannot trace: displacement, shadow and light shading, the world); Cycles parity scenes in tests/render.rs (ambient_occlusion*, bevel*); AO's Distance 0 (the world's AO distance) and `bake` of such a material are errors naming the node";
const PARTICLE_INFO: &str =
    "on an object a particle system instances, its particle as Cycles' sync_dupli_particle reads it (the realised instance's particle record: index, Random the hash of the index, age, lifetime, location, size, velocity, angular velocity at the frame), Cycles parity scene particle_info in tests/render.rs; elsewhere and on child particles Cycles' dummy particle (all zero, Random the hash of index 0), Cycles' EMIT bakes in tests/bake.rs; an export without the record is a compile error naming the object";
const INFO_ON_MESH: &str =
    "on meshes, hair and points every output is zero as in Cycles, Cycles' EMIT bakes in tests/bake.rs";
const POINT_INFO: &str =
    "every output as Cycles 4.5 computes it on point clouds (svm_node_point_info, geom/point.h: the point's world-space centre and radius, random by the point's index in its cloud, as blender/pointcloud.cpp makes ATTR_STD_POINT_RANDOM), zero on meshes and hair; Cycles parity scene point_info in tests/render.rs";
const HAIR_INFO: &str =
    "every output as Cycles 4.5 computes it on hair curves (svm_node_hair_info, geom/curve.h: intercept and length from the keys, thickness, tangent normal, random by curve index), zero on meshes; Cycles parity scene hair_info in tests/render.rs";
const AOV: &str =
    "written to the view layer's AOV pass it names (render/film/aov.rs, Cycles' svm/aov.h): Color or Value by the AOV's type, on camera rays and through transparent bounces until a surface reaches the Alpha Threshold, in materials and the world; a name the view layer lacks writes nothing; `render --passes` writes aovs.exr with Blender's channel names; inside node groups at any depth, used or not, as Cycles' sync keeps them; Cycles parity scenes aov (every channel) and aov_groups in tests/render.rs";
const LIGHT_OUTPUT: &str =
    "the output of a light's node tree (shader::compile_light, evaluated at every light sample by render/light/shader.rs; nodes that read what a light sample lacks are errors naming the light and node); Cycles parity scene light_ies in tests/render.rs; in a material Cycles renders only the Material Output (fixtures/bake/nodes, case freestyle_and_light_nodes)";
const METALLIC: &str =
    "render/bsdf/metallic.rs: F82 Tint and Physical Conductor (Cycles' fresnel_conductor) with GGX, Multiscatter GGX and Beckmann, Cycles parity scenes in tests/render.rs (metallic_bsdf, metallic_conductor); anisotropic Beckmann is a compile error naming the node";
const HAIR: &str =
    "render/bsdf/hair.rs (closure/bsdf_hair.h): Reflection and Transmission on hair curves, and on a mesh's faces about the triangle's dP/dv as Cycles does; Cycles parity scenes tests/render.rs hair_bsdf, hair_on_mesh";
const PRINCIPLED_HAIR: &str =
    "render/bsdf/hair_chiang.rs (closure/bsdf_principled_hair_chiang.h) and render/bsdf/hair_huang.rs (closure/bsdf_principled_hair_huang.h): Chiang and Huang models, every parametrization, on hair curves and on a mesh's faces (about the triangle's dP/du, as Cycles does; Huang's elliptical fibre is refused on Curves objects, whose normals the export does not carry), Cycles parity scenes in tests/render.rs (hair_chiang_melanin, hair_chiang_color, hair_chiang_absorption, hair_huang_melanin, hair_huang_color, hair_huang_absorption, hair_on_mesh)";
const RAY_PORTAL: &str =
    "render/bsdf/ray_portal.rs (closure/bsdf_ray_portal.h, integrate_surface_ray_portal): the path goes on from Position (unlinked: the hit) in Direction (unlinked: the ray's own) as a transparent bounce that skips MIS, and shadow rays stop at a portal alone (beside a Transparent its weight is transparency, as in Cycles); Cycles parity scene ray_portal in tests/render.rs";
const TOON: &str =
    "render/bsdf/toon.rs (closure/bsdf_toon.h): Diffuse and Glossy components, a Cycles parity scene in tests/render.rs (toon)";
const OUTPUT: &str =
    "closure weights and emission, whole-material bakes (tests/bake.rs); a Displacement the material's method does not use is a compile error";
const WORLD: &str = "world surfaces (render/light/world.rs); tests/world.rs; a world's Volume: render/volume_world.rs, Cycles parity scenes volume_world_* in tests/render.rs";
const SHADER_STRUCTURE: &str = "closure weights and emission, whole-material bakes (tests/bake.rs)";
const CLOSURE: &str =
    "light transport in render/ (bsdf.rs and the closure files), a Cycles parity scene in tests/render.rs";
const VOLUME: &str =
    "in a material's Volume: render/volume.rs (Cycles' svm_node_closure_volume, principled_volume, volume_coefficients; Henyey-Greenstein and Rayleigh phases, other phase functions are compile errors naming the node), Cycles parity scenes volume_* in tests/render.rs; in a Surface it does nothing, as in Cycles; in a world's Volume: render/volume_world.rs (volume_world_* parity scenes)";
const TEXTURE: &str =
    "nodes/<texture>.rs (Cycles flavour); every mode in tests/shader_conformance.rs";
const GABOR: &str =
    "nodes/gabor.rs: 2D and 3D, isotropic and anisotropic, within 1e-4 of Cycles' EMIT bakes (tests/bake.rs, fixtures/bake/nodes)";
const SKY: &str =
    "nodes/sky.rs, sky_hosek.rs: Nishita, Preetham and Hosek/Wilkie, every option, within 1e-4 of Cycles' bakes (tests/sky_texture.rs)";
const IES: &str =
    "nodes/ies.rs: Cycles 4.5's IES parsing and processing (types B and C, TILT, half and quarter files) and its bicubic lookup: within 1e-4 of Cycles' EMIT bakes (tests/bake.rs, fixtures/bake/nodes, cases ies_*), and on lights the Cycles parity scene light_ies in tests/render.rs";
const POINT_DENSITY: &str =
    "nodes/point_density.rs: the voxel grid Blender computes for Cycles (exported per node), read as Cycles' svm_node_tex_voxel reads it: in volumes only (zero on surfaces), Object space through the volume object's texture space, World space through the points object, Closest, Linear and Cubic with Clip; Cycles parity scene point_density in tests/render.rs; an override of a property the grid depends on is a compile error naming the node";
const IMAGE: &str =
    "nodes/brick.rs, image.rs, shader/images.rs: every interpolation, extension, projection and alpha mode in tests/textures.rs; colour spaces other than sRGB, Non-Color and Linear Rec.709, sequences and UDIM are compile errors naming the image";
const COLOR: &str = "nodes/color.rs, mix.rs, curves.rs; tests/shader_conformance.rs";
const VECTOR: &str = "nodes/mapping.rs, vector_rotate.rs, curves.rs; tests/shader_conformance.rs";
const VECTOR_TRANSFORM: &str =
    "nodes/vector_transform.rs: every type, from and to space within 1e-5 of Cycles' EMIT bakes (tests/bake.rs, fixtures/bake/nodes); camera space in a world shader is a compile error";
const BUMP: &str =
    "shader/bump.rs, bump_graph.rs; tests/bump.rs (tangent space through shader/tangent.rs, tests/attributes.rs)";
const CONVERTER: &str =
    "nodes/math.rs, map_range.rs, clamp.rs, ramp.rs, curves.rs, color.rs, sepcomb.rs, blackbody.rs, wavelength.rs; tests/shader_conformance.rs";

/// Every shader node type blendsynth compiles, grouped as Blender's Add menu groups them.
pub const NODES: &[ShaderNode] = &[
    // Input
    node("ShaderNodeValue", value, INPUT_CONSTANT),
    node("ShaderNodeRGB", rgb, INPUT_CONSTANT),
    node("ShaderNodeTexCoord", texture_coordinate, INPUT_CONSTANT),
    node("ShaderNodeUVMap", uv_map, INPUT_CONSTANT),
    node("ShaderNodeFresnel", input, INPUT_CONTEXT),
    node("ShaderNodeLayerWeight", input, INPUT_CONTEXT),
    node("ShaderNodeNewGeometry", input, INPUT_CONTEXT),
    node("ShaderNodeObjectInfo", input, INPUT_CONTEXT),
    node("ShaderNodeCameraData", input, INPUT_CONTEXT),
    node("ShaderNodeLightPath", input, INPUT_CONTEXT),
    node("ShaderNodeLightFalloff", input, INPUT_CONTEXT),
    node("ShaderNodeNormal", input, INPUT_CONTEXT),
    node("ShaderNodeTangent", input, INPUT_CONTEXT),
    node("ShaderNodeAttribute", attribute, ATTRIBUTE),
    node("ShaderNodeVertexColor", attribute, ATTRIBUTE),
    node("ShaderNodeWireframe", wireframe, WIREFRAME),
    node("ShaderNodeAmbientOcclusion", ambient_occlusion, RAY_TRACED),
    node("ShaderNodeBevel", bevel, RAY_TRACED),
    node("ShaderNodeParticleInfo", particle_info, PARTICLE_INFO),
    node("ShaderNodePointInfo", point_info, POINT_INFO),
    node("ShaderNodeHairInfo", hair_info, HAIR_INFO),
    node("ShaderNodeVolumeInfo", info_on_mesh, INFO_ON_MESH),
    // Output
    node("ShaderNodeOutputMaterial", material_output, OUTPUT),
    node("ShaderNodeOutputAOV", aov_output, AOV),
    node("ShaderNodeOutputLight", light_output, LIGHT_OUTPUT),
    node("ShaderNodeOutputWorld", world_output, WORLD),
    node("ShaderNodeBackground", background, WORLD),
    // Shader
    node("ShaderNodeEmission", emission, SHADER_STRUCTURE),
    node("ShaderNodeMixShader", mix_shader, SHADER_STRUCTURE),
    node("ShaderNodeAddShader", add_shader, SHADER_STRUCTURE),
    node("ShaderNodeBsdfPrincipled", principled_bsdf, CLOSURE),
    node("ShaderNodeBsdfDiffuse", bsdf, CLOSURE),
    node("ShaderNodeBsdfGlossy", bsdf, CLOSURE),
    node("ShaderNodeBsdfAnisotropic", bsdf, CLOSURE),
    node("ShaderNodeBsdfGlass", bsdf, CLOSURE),
    node("ShaderNodeBsdfRefraction", bsdf, CLOSURE),
    node("ShaderNodeBsdfTranslucent", bsdf, CLOSURE),
    node("ShaderNodeBsdfTransparent", bsdf, CLOSURE),
    node("ShaderNodeBsdfRayPortal", bsdf, RAY_PORTAL),
    node("ShaderNodeSubsurfaceScattering", bsdf, CLOSURE),
    node("ShaderNodeHoldout", bsdf, CLOSURE),
    node("ShaderNodeBsdfSheen", bsdf, CLOSURE),
    node("ShaderNodeBsdfMetallic", metallic_bsdf, METALLIC),
    node("ShaderNodeBsdfToon", bsdf, TOON),
    node("ShaderNodeBsdfHair", bsdf, HAIR),
    node(
        "ShaderNodeBsdfHairPrincipled",
        principled_hair_bsdf,
        PRINCIPLED_HAIR,
    ),
    node("ShaderNodeVolumeAbsorption", volume, VOLUME),
    node("ShaderNodeVolumeScatter", volume, VOLUME),
    node("ShaderNodeVolumePrincipled", volume, VOLUME),
    node("ShaderNodeVolumeCoefficients", volume, VOLUME),
    // Texture
    node("ShaderNodeTexNoise", noise_texture, TEXTURE),
    node("ShaderNodeTexVoronoi", voronoi_texture, TEXTURE),
    node("ShaderNodeTexWave", wave_texture, TEXTURE),
    node("ShaderNodeTexGradient", gradient_texture, TEXTURE),
    node("ShaderNodeTexMagic", magic_texture, TEXTURE),
    node("ShaderNodeTexWhiteNoise", white_noise_texture, TEXTURE),
    node("ShaderNodeTexChecker", checker_texture, TEXTURE),
    node("ShaderNodeTexGabor", gabor_texture, GABOR),
    node("ShaderNodeTexSky", sky_texture, SKY),
    node("ShaderNodeTexIES", ies_texture, IES),
    node(
        "ShaderNodeTexPointDensity",
        point_density_texture,
        POINT_DENSITY,
    ),
    node("ShaderNodeTexBrick", brick_texture, IMAGE),
    node("ShaderNodeTexImage", image_texture, IMAGE),
    node("ShaderNodeTexEnvironment", environment_texture, IMAGE),
    // Color
    node("ShaderNodeMix", mix, COLOR),
    node("ShaderNodeMixRGB", mix_rgb, COLOR),
    node("ShaderNodeInvert", invert, COLOR),
    node("ShaderNodeGamma", gamma, COLOR),
    node("ShaderNodeBrightContrast", bright_contrast, COLOR),
    node("ShaderNodeHueSaturation", hue_saturation, COLOR),
    node("ShaderNodeRGBCurve", rgb_vector_curves, COLOR),
    // Vector
    node("ShaderNodeMapping", mapping, VECTOR),
    node(
        "ShaderNodeVectorTransform",
        vector_transform,
        VECTOR_TRANSFORM,
    ),
    node("ShaderNodeVectorRotate", vector_rotate, VECTOR),
    node("ShaderNodeVectorCurve", rgb_vector_curves, VECTOR),
    node("ShaderNodeBump", bump, BUMP),
    node("ShaderNodeDisplacement", displacement, BUMP),
    node("ShaderNodeVectorDisplacement", vector_displacement, BUMP),
    node("ShaderNodeNormalMap", normal_map, BUMP),
    // Converter
    node("ShaderNodeMath", math, CONVERTER),
    node("ShaderNodeVectorMath", vector_math, CONVERTER),
    node("ShaderNodeMapRange", map_range, CONVERTER),
    node("ShaderNodeClamp", clamp, CONVERTER),
    node("ShaderNodeValToRGB", color_ramp, CONVERTER),
    node("ShaderNodeFloatCurve", float_curve, CONVERTER),
    node("ShaderNodeRGBToBW", rgb_to_bw, CONVERTER),
    node("ShaderNodeSeparateXYZ", separate_xyz, CONVERTER),
    node("ShaderNodeCombineXYZ", combine_xyz, CONVERTER),
    node("ShaderNodeSeparateColor", separate_color, CONVERTER),
    node("ShaderNodeCombineColor", combine_color, CONVERTER),
    node("ShaderNodeSeparateRGB", separate_color, CONVERTER),
    node("ShaderNodeCombineRGB", combine_color, CONVERTER),
    node("ShaderNodeSeparateHSV", separate_color, CONVERTER),
    node("ShaderNodeCombineHSV", combine_color, CONVERTER),
    node("ShaderNodeBlackbody", blackbody, CONVERTER),
    node("ShaderNodeWavelength", wavelength, CONVERTER),
];

// Input.

fn value(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let v = n.node.outputs[0]
        .default_value
        .as_ref()
        .map(floats)
        .unwrap_or([0.0; 4]);
    let s = c.constant(F, [v[0]; 3]);
    c.outputs(i, n, &[("Value", s, F)]);
    Ok(())
}

fn rgb(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let v = n.node.outputs[0]
        .default_value
        .as_ref()
        .map(floats)
        .unwrap_or([0.0; 4]);
    let s = c.constant(C, [v[0], v[1], v[2]]);
    c.outputs(i, n, &[("Color", s, C)]);
    Ok(())
}

fn texture_coordinate(
    c: &mut Compiler<'_, '_>,
    i: usize,
    _: &Schedule,
) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (g, nn, uv, ob) = (c.alloc(V), c.alloc(V), c.alloc(V), c.alloc(V));
    c.ops.push(Op::TexCoord {
        generated: Some(g),
        normal: Some(nn),
        uv: Some(uv),
        object: Some(ob),
    });
    c.outputs(
        i,
        n,
        &[
            ("Generated", g, V),
            ("Normal", nn, V),
            ("UV", uv, V),
            ("Object", ob, V),
        ],
    );
    c.tex_coord_more(i)?;
    Ok(())
}

fn uv_map(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    if !prop_str(n, "uv_map")?.is_empty()
        || n.property("from_instancer").and_then(Value::as_bool) == Some(true)
    {
        return c.named_uv(i);
    }
    let d = c.alloc(V);
    c.ops.push(Op::UvMap { dst: d });
    c.outputs(i, n, &[("UV", d, V)]);
    Ok(())
}

fn input(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.input_node(i)
}

fn attribute(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.attribute_node(i)
}

fn wireframe(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let pixel_size = prop_bool(n, "use_pixel_size")?;
    let size = c.input(n, "Size", F)?;
    let dst = c.alloc(F);
    c.ops.push(Op::Wireframe {
        size,
        pixel_size,
        dst,
    });
    c.outputs(i, n, &[("Fac", dst, F)]);
    Ok(())
}

/// A node's integer property (AO and Bevel Samples: Cycles packs them in a byte).
fn prop_samples(n: &crate::nodes::graph::FlatNode, key: &str) -> Result<u32, CompileError> {
    prop(n, key)?
        .as_i64()
        .and_then(|v| u8::try_from(v).ok())
        .map(u32::from)
        .ok_or_else(|| {
            CompileError(format!(
                "node {:?}: property {key:?} is not an integer in 0..=255",
                n.path
            ))
        })
}

/// Ambient Occlusion. An unlinked Distance of 0 is Cycles' global-radius flag (the
/// world's AO distance, which the exchange format does not carry): refused by name.
fn ambient_occlusion(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let samples = prop_samples(n, "samples")?;
    let (inside, only_local) = (prop_bool(n, "inside")?, prop_bool(n, "only_local")?);
    if !linked(n, "Distance") {
        if let Some(Source::Default(sock)) = n.input("Distance").and_then(|x| x.sources.first()) {
            if sock.default_value.as_ref().map(floats).map(|f| f[0]) == Some(0.0) {
                return Err(CompileError(format!(
                    "node {:?}: Ambient Occlusion with Distance 0 uses the world's AO distance, which is not supported",
                    n.path
                )));
            }
        }
    }
    let color = c.input(n, "Color", C)?;
    let distance = c.input(n, "Distance", F)?;
    let normal = if linked(n, "Normal") {
        Some(c.input(n, "Normal", V)?)
    } else {
        None
    };
    let (ao, color_out) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::AmbientOcclusion {
        color,
        distance,
        normal,
        samples,
        inside,
        only_local,
        ao,
        color_out,
    });
    c.outputs(i, n, &[("Color", color_out, C), ("AO", ao, F)]);
    Ok(())
}

fn bevel(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let samples = prop_samples(n, "samples")?;
    let radius = c.input(n, "Radius", F)?;
    let normal = if linked(n, "Normal") {
        Some(c.input(n, "Normal", V)?)
    } else {
        None
    };
    let dst = c.alloc(V);
    c.ops.push(Op::Bevel {
        radius,
        normal,
        samples,
        dst,
    });
    c.outputs(i, n, &[("Normal", dst, V)]);
    Ok(())
}

/// Point, Curves and Volume Info on a triangle mesh, as Cycles evaluates them there: the
/// point, curve and volume data are absent (zero).
fn info_on_mesh(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let mut slots = Vec::new();
    for o in &n.node.outputs {
        let kind = kind_of(&o.kind).unwrap_or(F);
        let s = c.constant(kind, [0.0; 3]);
        slots.push((o.identifier.as_str(), s, kind));
    }
    c.outputs(i, n, &slots);
    Ok(())
}

/// Particle Info: the values of the particle the object stands for (its realised
/// instance's record), Cycles' dummy particle elsewhere. An export older than the record
/// is refused where particle systems instance objects.
fn particle_info(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    if let Some(e) = c.scene.and_then(|s| {
        s.file.evaluated.iter().find(|e| {
            e.realized
                .as_ref()
                .is_some_and(|r| r.instances.iter().any(|i| i.particle.is_none()))
        })
    }) {
        return Err(CompileError(format!(
            "node {:?}: Particle Info, and the export of object {:?} predates the particle record of its instances: convert the .blend again",
            n.path, e.object
        )));
    }
    let kinds = [F, F, F, F, V, F, V, V];
    let dst = kinds.map(|k| c.alloc(k));
    c.ops.push(Op::ParticleInfo { dst });
    let names = [
        "Index",
        "Random",
        "Age",
        "Lifetime",
        "Location",
        "Size",
        "Velocity",
        "Angular Velocity",
    ];
    let slots: Vec<(&str, u32, Kind)> = names
        .iter()
        .zip(dst.iter().zip(kinds))
        .map(|(n, (d, k))| (*n, *d, k))
        .collect();
    c.outputs(i, n, &slots);
    Ok(())
}

/// Hair Info: the shading point's hair values (zero off hair, as in Cycles).
fn hair_info(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let dst = [F, F, F, F, V, F].map(|k| c.alloc(k));
    c.ops.push(Op::HairInfo { dst });
    c.outputs(
        i,
        n,
        &[
            ("Is Strand", dst[0], F),
            ("Intercept", dst[1], F),
            ("Length", dst[2], F),
            ("Thickness", dst[3], F),
            ("Tangent Normal", dst[4], V),
            ("Random", dst[5], F),
        ],
    );
    Ok(())
}

/// Point Info: the shading point's point-cloud values (zero off points, as in Cycles).
fn point_info(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let dst = [V, F, F].map(|k| c.alloc(k));
    c.ops.push(Op::PointInfo { dst });
    c.outputs(
        i,
        n,
        &[
            ("Position", dst[0], V),
            ("Radius", dst[1], F),
            ("Random", dst[2], F),
        ],
    );
    Ok(())
}

// Output.

fn material_output(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    if c.displace.is_none()
        && !c.true_displacement
        && n.input("Displacement")
            .is_some_and(|d| matches!(d.sources.first(), Some(Source::Link { .. })))
    {
        return Err(CompileError(format!(
            "node {:?}: displacement is not supported yet",
            n.path
        )));
    }
    c.surface = c.closure_input(n, "Surface")?;
    // The mesh's inside, rendered by render/volume.rs.
    c.volume = c.closure_input(n, "Volume")?;
    Ok(())
}

/// AOV Output: its input for the view-layer AOV it names (Color for a colour AOV, else
/// Value), read by the renderer after the program runs (Cycles' svm_node_aov_color /
/// svm_node_aov_value). Only nodes naming a valid AOV reach the graph (`aov_outputs`).
fn aov_output(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let Some((aov, color)) = c.scene.and_then(|s| aov_index(s, n.node)) else {
        return Ok(());
    };
    let slot = if color {
        c.input(n, "Color", C)?
    } else {
        c.input(n, "Value", F)?
    };
    c.aovs.push(AovWrite { aov, color, slot });
    Ok(())
}

/// A light's output (`compile_light`); in a material or world only their own output node
/// is compiled, so this is never reached there.
fn light_output(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    c.surface = c.closure_input(n, "Surface")?;
    Ok(())
}

fn world_output(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    c.surface = c.closure_input(n, "Surface")?;
    // The world volume, filling all space (render/volume_world.rs).
    c.volume = c.closure_input(n, "Volume")?;
    Ok(())
}

fn background(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    // A world's Background is emission seen along the ray.
    let (color, strength) = (c.input(n, "Color", C)?, c.input(n, "Strength", F)?);
    c.closure(i, Closure::Emission { color, strength });
    Ok(())
}

// Shader.

fn emission(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (color, strength) = (c.input(n, "Color", C)?, c.input(n, "Strength", F)?);
    c.closure(i, Closure::Emission { color, strength });
    Ok(())
}

/// Metallic BSDF: F82 Tint and Physical Conductor, GGX, Multiscatter GGX and isotropic
/// Beckmann (render/bsdf/metallic.rs).
fn metallic_bsdf(c: &mut Compiler<'_, '_>, i: usize, s: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let fresnel = prop_str(n, "fresnel_type")?;
    let distribution = prop_str(n, "distribution")?;
    if !matches!(fresnel, "F82" | "PHYSICAL_CONDUCTOR")
        || !matches!(distribution, "GGX" | "MULTI_GGX" | "BECKMANN")
    {
        return Err(CompileError(format!(
            "node {:?}: Metallic BSDF with fresnel_type {fresnel:?} and distribution {distribution:?} is not supported",
            n.path
        )));
    }
    if distribution == "BECKMANN" {
        let anisotropic = linked(n, "Anisotropy")
            || matches!(
                n.input("Anisotropy").and_then(|x| x.sources.first()),
                Some(Source::Default(sock)) if sock.default_value.as_ref().map(floats).is_some_and(|f| f[0] != 0.0)
            );
        if anisotropic {
            return Err(CompileError(format!(
                "node {:?}: Metallic BSDF with the Beckmann distribution and Anisotropy is not supported yet",
                n.path
            )));
        }
    }
    bsdf(c, i, s)
}

fn mix_shader(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let fac = c.input(n, "Fac", F)?;
    let (a, b) = (
        c.closure_input(n, "Shader")?,
        c.closure_input(n, "Shader_001")?,
    );
    c.closure(i, Closure::Mix { fac, a, b });
    Ok(())
}

fn add_shader(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (a, b) = (
        c.closure_input(n, "Shader")?,
        c.closure_input(n, "Shader_001")?,
    );
    c.closure(i, Closure::Add { a, b });
    Ok(())
}

fn principled_bsdf(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (color, strength) = (
        c.input(n, "Emission Color", C)?,
        c.input(n, "Emission Strength", F)?,
    );
    c.closure(
        i,
        Closure::Bsdf {
            emission: Some((color, strength)),
        },
    );
    c.record_bsdf(i)?;
    Ok(())
}

fn bsdf(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    // No emission; their scattering parameters are compiled with the renderer.
    c.closure(i, Closure::Bsdf { emission: None });
    c.record_bsdf(i)?;
    Ok(())
}

/// The Principled Hair BSDF. Cycles folds a constant linked into Random (a Value node)
/// into the socket, which then counts as unlinked: the closure reads the curve's random
/// number instead. So a Random fed a constant is recorded as unlinked.
fn principled_hair_bsdf(
    c: &mut Compiler<'_, '_>,
    i: usize,
    s: &Schedule,
) -> Result<(), CompileError> {
    bsdf(c, i, s)?;
    let constants = &c.constants;
    if let Some(b) = c.bsdfs.last_mut() {
        for input in b.inputs.iter_mut().filter(|x| x.0 == "Random") {
            if constants.contains(&input.1) {
                input.2 = false;
            }
        }
    }
    Ok(())
}

/// A volume closure (render/volume.rs builds its coefficients). Cycles 4.5's phase
/// functions other than Henyey-Greenstein and Rayleigh are refused by name.
fn volume(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    if let Some(phase) = n.node.properties.get("phase").and_then(Value::as_str) {
        if !matches!(phase, "HENYEY_GREENSTEIN" | "RAYLEIGH") {
            return Err(CompileError(format!(
                "node {:?}: phase function {phase:?} is not supported yet (Henyey-Greenstein and Rayleigh are)",
                n.path
            )));
        }
    }
    c.closure(i, Closure::Bsdf { emission: None });
    c.record_bsdf(i)?;
    if n.node.bl_idname == "ShaderNodeVolumePrincipled" {
        c.principled_volume_attributes(i)?;
    }
    Ok(())
}

// Texture.

fn noise_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (dims, vector, w) = c.texture_point(n, Some("noise_dimensions"))?;
    let kind = mode(n, "noise_type", NoiseType::from_blender)?;
    let normalize = prop_bool(n, "normalize")?;
    let ids = [
        "Scale",
        "Detail",
        "Roughness",
        "Lacunarity",
        "Offset",
        "Gain",
        "Distortion",
    ];
    let args = c.inputs_n(n, ids, F)?;
    let (fac, color) = (c.alloc(F), c.alloc(C));
    // Without a link from Color only Fac is computed (as Cycles does).
    let want_color = c.output_used(i, "Color");
    c.ops.push(Op::TexNoise {
        dims,
        kind,
        normalize,
        vector,
        w,
        args,
        fac,
        color,
        want_color,
    });
    c.outputs(i, n, &[("Fac", fac, F), ("Color", color, C)]);
    Ok(())
}

fn voronoi_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (dims, vector, w) = c.texture_point(n, Some("voronoi_dimensions"))?;
    let feature = mode(n, "feature", VoronoiFeature::from_blender)?;
    let metric = mode(n, "distance", VoronoiMetric::from_blender)?;
    let normalize = prop_bool(n, "normalize")?;
    let ids = [
        "Scale",
        "Detail",
        "Roughness",
        "Lacunarity",
        "Smoothness",
        "Exponent",
        "Randomness",
    ];
    let args = c.inputs_n(n, ids, F)?;
    let (distance, color, position, w_out, radius) =
        (c.alloc(F), c.alloc(C), c.alloc(V), c.alloc(F), c.alloc(F));
    c.ops.push(Op::TexVoronoi {
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
    });
    c.outputs(
        i,
        n,
        &[
            ("Distance", distance, F),
            ("Color", color, C),
            ("Position", position, V),
            ("W", w_out, F),
            ("Radius", radius, F),
        ],
    );
    Ok(())
}

fn wave_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (_, vector, _) = c.texture_point(n, None)?;
    let settings = WaveSettings {
        kind: mode(n, "wave_type", WaveType::from_blender)?,
        bands: mode(n, "bands_direction", BandsDirection::from_blender)?,
        rings: mode(n, "rings_direction", RingsDirection::from_blender)?,
        profile: mode(n, "wave_profile", WaveProfile::from_blender)?,
    };
    let ids = [
        "Scale",
        "Distortion",
        "Detail",
        "Detail Scale",
        "Detail Roughness",
        "Phase Offset",
    ];
    let args = c.inputs_n(n, ids, F)?;
    let (fac, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexWave {
        settings,
        vector,
        args,
        fac,
        color,
    });
    c.outputs(i, n, &[("Fac", fac, F), ("Color", color, C)]);
    Ok(())
}

fn gradient_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (_, vector, _) = c.texture_point(n, None)?;
    let kind = mode(n, "gradient_type", GradientType::from_blender)?;
    let (fac, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexGradient {
        kind,
        vector,
        fac,
        color,
    });
    c.outputs(i, n, &[("Fac", fac, F), ("Color", color, C)]);
    Ok(())
}

fn magic_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (_, vector, _) = c.texture_point(n, None)?;
    let depth = prop(n, "turbulence_depth")?.as_i64().ok_or_else(|| {
        CompileError(format!(
            "node {:?}: turbulence_depth is not an integer",
            n.path
        ))
    })? as i32;
    let (scale, distortion) = (c.input(n, "Scale", F)?, c.input(n, "Distortion", F)?);
    let (fac, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexMagic {
        depth,
        vector,
        scale,
        distortion,
        fac,
        color,
    });
    c.outputs(i, n, &[("Fac", fac, F), ("Color", color, C)]);
    Ok(())
}

fn white_noise_texture(
    c: &mut Compiler<'_, '_>,
    i: usize,
    _: &Schedule,
) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let dims = dimensions(n, "noise_dimensions")?;
    // An unlinked White Noise vector is the world position, not Generated.
    let vector = if linked(n, "Vector") {
        c.input(n, "Vector", V)?
    } else {
        let d = c.alloc(V);
        c.ops.push(Op::Position { dst: d });
        d
    };
    let w = c.opt_input(n, "W", F)?;
    let (value, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexWhiteNoise {
        dims,
        vector,
        w,
        value,
        color,
    });
    c.outputs(i, n, &[("Value", value, F), ("Color", color, C)]);
    Ok(())
}

fn checker_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (_, vector, _) = c.texture_point(n, None)?;
    let (color1, color2, scale) = (
        c.input(n, "Color1", C)?,
        c.input(n, "Color2", C)?,
        c.input(n, "Scale", F)?,
    );
    let (fac, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexChecker {
        vector,
        color1,
        color2,
        scale,
        fac,
        color,
    });
    c.outputs(i, n, &[("Fac", fac, F), ("Color", color, C)]);
    Ok(())
}

fn sky_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.sky_texture(i)
}

fn ies_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    // Cycles' default vector is the texture Normal (object space), with no mapping.
    let vector = if linked(n, "Vector") {
        c.input(n, "Vector", V)?
    } else {
        let d = c.alloc(V);
        c.ops.push(Op::TexCoord {
            generated: None,
            normal: Some(d),
            uv: None,
            object: None,
        });
        d
    };
    let strength = c.input(n, "Strength", F)?;
    let text = n.node.ies.as_deref().ok_or_else(|| {
        CompileError(format!(
            "node {:?}: the export has no IES data for it (convert the .blend again)",
            n.path
        ))
    })?;
    let table = std::sync::Arc::new(crate::nodes::ies::IesTable::new(text));
    let fac = c.alloc(F);
    c.ops.push(Op::TexIes {
        table,
        vector,
        strength,
        fac,
    });
    c.outputs(i, n, &[("Fac", fac, F)]);
    Ok(())
}

/// Point Density: the grid Blender computed at export, which Cycles samples in volumes
/// (nodes/point_density.rs). The properties it was computed with must still hold: an
/// override of one would need Blender to compute it again.
fn point_density_texture(
    c: &mut Compiler<'_, '_>,
    i: usize,
    _: &Schedule,
) -> Result<(), CompileError> {
    use crate::nodes::point_density::{world_space, Interpolation, Space, VoxelGrid};
    let n = &c.g.nodes[i];
    let pd = n.node.point_density.as_ref().ok_or_else(|| {
        CompileError(format!(
            "node {:?}: the export has no point density grid for it (convert the .blend again)",
            n.path
        ))
    })?;
    for (k, v) in &pd.properties {
        if n.property(k) != Some(v) {
            return Err(CompileError(format!(
                "node {:?}: Point Density property {k:?} differs from the one Blender computed its grid with at export ({v}): convert the .blend again with the new value",
                n.path
            )));
        }
    }
    let interpolation = mode(n, "interpolation", Interpolation::from_blender)?;
    let space = match prop_str(n, "space")? {
        "OBJECT" => Space::Object,
        // Without an object, or with empty bounds, Blender's grid is all zero.
        _ => Space::World(
            pd.object_matrix
                .and_then(|m| world_space(&m, pd.min, pd.max))
                .unwrap_or([[0.0; 4]; 3]),
        ),
    };
    let scene = c.scene.ok_or_else(|| {
        CompileError(format!(
            "node {:?}: Point Density needs the scene's files",
            n.path
        ))
    })?;
    let voxels = scene
        .load_point_density(pd, &n.path)
        .map_err(|e| CompileError(e.to_string()))?;
    let grid = VoxelGrid {
        resolution: pd.resolution as usize,
        voxels: std::sync::Arc::new(voxels),
    };
    // Cycles' LINK_POSITION: an unlinked vector is the shading point's position.
    let vector = if linked(n, "Vector") {
        c.input(n, "Vector", V)?
    } else {
        let d = c.alloc(V);
        c.ops.push(Op::Position { dst: d });
        d
    };
    let (density, color) = (c.alloc(F), c.alloc(C));
    c.ops.push(Op::TexPointDensity {
        grid,
        interpolation,
        space,
        vector,
        density,
        color,
    });
    c.outputs(i, n, &[("Density", density, F), ("Color", color, C)]);
    Ok(())
}

fn gabor_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (_, vector, _) = c.texture_point(n, None)?;
    let kind = mode(n, "gabor_type", GaborType::from_blender)?;
    let ids = ["Scale", "Frequency", "Anisotropy", "Orientation 2D"];
    let args = c.inputs_n(n, ids, F)?;
    let orientation = c.opt_input(n, "Orientation 3D", V)?;
    let (value, phase, intensity) = (c.alloc(F), c.alloc(F), c.alloc(F));
    c.ops.push(Op::TexGabor {
        kind,
        vector,
        args,
        orientation,
        value,
        phase,
        intensity,
    });
    c.outputs(
        i,
        n,
        &[
            ("Value", value, F),
            ("Phase", phase, F),
            ("Intensity", intensity, F),
        ],
    );
    Ok(())
}

fn brick_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.brick(i)
}

fn image_texture(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.image_texture(i)
}

fn environment_texture(
    c: &mut Compiler<'_, '_>,
    i: usize,
    _: &Schedule,
) -> Result<(), CompileError> {
    c.environment_texture(i)
}

// Color.

fn mix(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    c.mix(i)
}

fn mix_rgb(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let blend = mode(n, "blend_type", MixBlend::from_blender)?;
    let clamp = prop_bool(n, "use_clamp")?;
    let (factor, a, b) = (
        c.input(n, "Fac", F)?,
        c.input(n, "Color1", C)?,
        c.input(n, "Color2", C)?,
    );
    let d = c.alloc(C);
    c.ops.push(Op::MixRgb {
        blend,
        clamp,
        factor,
        a,
        b,
        dst: d,
    });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn invert(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (fac, color) = (c.input(n, "Fac", F)?, c.input(n, "Color", C)?);
    let d = c.alloc(C);
    c.ops.push(Op::Invert { fac, color, dst: d });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn gamma(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (color, gamma) = (c.input(n, "Color", C)?, c.input(n, "Gamma", F)?);
    let d = c.alloc(C);
    c.ops.push(Op::Gamma {
        color,
        gamma,
        dst: d,
    });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn bright_contrast(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (color, bright, contrast) = (
        c.input(n, "Color", C)?,
        c.input(n, "Bright", F)?,
        c.input(n, "Contrast", F)?,
    );
    let d = c.alloc(C);
    c.ops.push(Op::BrightContrast {
        color,
        bright,
        contrast,
        dst: d,
    });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn hue_saturation(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let hue = c.input(n, "Hue", F)?;
    let saturation = c.input(n, "Saturation", F)?;
    let value = c.input(n, "Value", F)?;
    let fac = c.input(n, "Fac", F)?;
    let color = c.input(n, "Color", C)?;
    let d = c.alloc(C);
    c.ops.push(Op::HueSaturation {
        hue,
        saturation,
        value,
        fac,
        color,
        dst: d,
    });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn rgb_vector_curves(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (kind, sock, k) = if n.node.bl_idname == "ShaderNodeRGBCurve" {
        (CurveKind::Rgb, "Color", C)
    } else {
        (CurveKind::Vector, "Vector", V)
    };
    let table = c.curve_table(n, kind)?;
    let (fac, v) = (c.input(n, "Fac", F)?, c.input(n, sock, k)?);
    let d = c.alloc(k);
    c.ops.push(Op::Curves3 {
        table,
        fac,
        v,
        dst: d,
    });
    c.outputs(i, n, &[(sock, d, k)]);
    Ok(())
}

// Vector.

fn mapping(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = mode(n, "vector_type", MappingType::from_blender)?;
    let vector = c.input(n, "Vector", V)?;
    // Location is hidden (and unused) for Vector and Normal mappings.
    let location = c.opt_input(n, "Location", V)?;
    let rotation = c.input(n, "Rotation", V)?;
    let scale = c.input(n, "Scale", V)?;
    let d = c.alloc(V);
    c.ops.push(Op::Mapping {
        kind,
        vector,
        location,
        rotation,
        scale,
        dst: d,
    });
    c.outputs(i, n, &[("Vector", d, V)]);
    Ok(())
}

fn vector_transform(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = mode(n, "vector_type", VectorTransformType::from_blender)?;
    let from = mode(n, "convert_from", TransformSpace::from_blender)?;
    let to = mode(n, "convert_to", TransformSpace::from_blender)?;
    if c.world && from != to && (from == TransformSpace::Camera || to == TransformSpace::Camera) {
        return Err(CompileError(format!(
            "node {:?}: Vector Transform to or from camera space in a world shader is not supported yet",
            n.path
        )));
    }
    let vector = c.input(n, "Vector", V)?;
    let dst = c.alloc(V);
    c.ops.push(Op::VectorTransform {
        kind,
        from,
        to,
        object: !c.world,
        vector,
        dst,
    });
    c.outputs(i, n, &[("Vector", dst, V)]);
    Ok(())
}

fn vector_rotate(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = mode(n, "rotation_type", VectorRotateType::from_blender)?;
    let invert = prop_bool(n, "invert")?;
    let vector = c.input(n, "Vector", V)?;
    let center = c.input(n, "Center", V)?;
    // Inputs the rotation type hides are unused.
    let axis = c.opt_input(n, "Axis", V)?;
    let angle = c.opt_input(n, "Angle", F)?;
    let rotation = c.opt_input(n, "Rotation", V)?;
    let d = c.alloc(V);
    c.ops.push(Op::VectorRotate {
        kind,
        invert,
        vector,
        center,
        axis,
        angle,
        rotation,
        dst: d,
    });
    c.outputs(i, n, &[("Vector", d, V)]);
    Ok(())
}

fn bump(c: &mut Compiler<'_, '_>, i: usize, schedule: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let settings = BumpSettings {
        invert: prop_bool(n, "invert")?,
        object_space: false,
        filter_width: bump_graph::filter_width(c.g, i).map_err(CompileError)?,
    };
    let (strength, distance) = (c.input(n, "Strength", F)?, c.input(n, "Distance", F)?);
    let normal = if linked(n, "Normal") {
        Some(c.input(n, "Normal", V)?)
    } else {
        None
    };
    let center = c.input(n, "Height", F)?;
    let (dx, dy) = match schedule.bump_copies[i] {
        Some((cx, cy)) => (
            c.input_in_copy(cx, i, "Height", F)?,
            c.input_in_copy(cy, i, "Height", F)?,
        ),
        None => (center, center),
    };
    let d = c.alloc(V);
    c.ops.push(Op::Bump {
        settings,
        normal,
        strength,
        distance,
        center,
        dx,
        dy,
        dst: d,
    });
    c.outputs(i, n, &[("Normal", d, V)]);
    Ok(())
}

fn displacement(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let object_space = match prop_str(n, "space")? {
        "OBJECT" => true,
        "WORLD" => false,
        other => {
            return Err(CompileError(format!(
                "node {:?}: space {other:?} is not supported",
                n.path
            )))
        }
    };
    let (height, midlevel, scale) = (
        c.input(n, "Height", F)?,
        c.input(n, "Midlevel", F)?,
        c.input(n, "Scale", F)?,
    );
    let normal = if linked(n, "Normal") {
        Some(c.input(n, "Normal", V)?)
    } else {
        None
    };
    let d = c.alloc(V);
    c.ops.push(Op::Displacement {
        object_space,
        height,
        midlevel,
        scale,
        normal,
        dst: d,
    });
    c.outputs(i, n, &[("Displacement", d, V)]);
    Ok(())
}

fn vector_displacement(
    c: &mut Compiler<'_, '_>,
    i: usize,
    _: &Schedule,
) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let space = mode(n, "space", MapSpace::from_blender)?;
    if space == MapSpace::Tangent {
        c.vector_displacement_tangent(i)?;
        return Ok(());
    }
    let (vector, midlevel, scale) = (
        c.input(n, "Vector", V)?,
        c.input(n, "Midlevel", F)?,
        c.input(n, "Scale", F)?,
    );
    let d = c.alloc(V);
    c.ops.push(Op::VectorDisplacement {
        space,
        vector,
        midlevel,
        scale,
        dst: d,
    });
    c.outputs(i, n, &[("Displacement", d, V)]);
    Ok(())
}

fn normal_map(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let space = mode(n, "space", MapSpace::from_blender)?;
    if space == MapSpace::Tangent {
        c.normal_map_tangent(i)?;
        return Ok(());
    }
    let (color, strength) = (c.input(n, "Color", C)?, c.input(n, "Strength", F)?);
    let d = c.alloc(V);
    c.ops.push(Op::NormalMap {
        space,
        color,
        strength,
        dst: d,
    });
    c.outputs(i, n, &[("Normal", d, V)]);
    Ok(())
}

// Converter.

fn math(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let op = mode(n, "operation", MathOp::from_blender)?;
    let clamp = prop_bool(n, "use_clamp")?;
    let (a, b, third) = (
        c.input(n, "Value", F)?,
        c.opt_input(n, "Value_001", F)?,
        c.opt_input(n, "Value_002", F)?,
    );
    let d = c.alloc(F);
    c.ops.push(Op::Math {
        op,
        clamp,
        a,
        b,
        c: third,
        dst: d,
    });
    c.outputs(i, n, &[("Value", d, F)]);
    Ok(())
}

fn vector_math(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let op = mode(n, "operation", VectorMathOp::from_blender)?;
    let a = c.input(n, "Vector", V)?;
    let b = c.opt_input(n, "Vector_001", V)?;
    let third = c.opt_input(n, "Vector_002", V)?;
    let scale = c.opt_input(n, "Scale", F)?;
    let (vector, value) = (c.alloc(V), c.alloc(F));
    c.ops.push(Op::VectorMath {
        op,
        a,
        b,
        c: third,
        scale,
        vector,
        value,
    });
    c.outputs(i, n, &[("Vector", vector, V), ("Value", value, F)]);
    Ok(())
}

fn map_range(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let interp = mode(n, "interpolation_type", MapRangeInterpolation::from_blender)?;
    let clamp = prop_bool(n, "clamp")?;
    match prop_str(n, "data_type")? {
        "FLOAT" => {
            let ids = ["Value", "From Min", "From Max", "To Min", "To Max", "Steps"];
            let args = c.inputs6(n, ids, F)?;
            let d = c.alloc(F);
            c.ops.push(Op::MapRangeFloat {
                interp,
                clamp,
                args,
                dst: d,
            });
            c.outputs(i, n, &[("Result", d, F)]);
        }
        "FLOAT_VECTOR" => {
            let ids = [
                "Vector",
                "From_Min_FLOAT3",
                "From_Max_FLOAT3",
                "To_Min_FLOAT3",
                "To_Max_FLOAT3",
                "Steps_FLOAT3",
            ];
            let args = c.inputs6(n, ids, V)?;
            let d = c.alloc(V);
            c.ops.push(Op::MapRangeVector {
                interp,
                clamp,
                args,
                dst: d,
            });
            c.outputs(i, n, &[("Vector", d, V)]);
        }
        other => {
            return Err(CompileError(format!(
                "node {:?}: Map Range data type {other:?} is not supported",
                n.path
            )))
        }
    }
    Ok(())
}

fn clamp(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = mode(n, "clamp_type", ClampType::from_blender)?;
    let (value, min, max) = (
        c.input(n, "Value", F)?,
        c.input(n, "Min", F)?,
        c.input(n, "Max", F)?,
    );
    let d = c.alloc(F);
    c.ops.push(Op::Clamp {
        kind,
        value,
        min,
        max,
        dst: d,
    });
    c.outputs(i, n, &[("Result", d, F)]);
    Ok(())
}

fn color_ramp(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let table = c.ramp(n)?;
    let fac = c.input(n, "Fac", F)?;
    let (color, alpha) = (c.alloc(C), c.alloc(F));
    c.ops.push(Op::Ramp {
        table,
        fac,
        color,
        alpha,
    });
    c.outputs(i, n, &[("Color", color, C), ("Alpha", alpha, F)]);
    Ok(())
}

fn float_curve(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let table = c.curve_table(n, CurveKind::Float)?;
    let (fac, v) = (c.input(n, "Factor", F)?, c.input(n, "Value", F)?);
    let d = c.alloc(F);
    c.ops.push(Op::Curve1 {
        table,
        fac,
        v,
        dst: d,
    });
    c.outputs(i, n, &[("Value", d, F)]);
    Ok(())
}

fn rgb_to_bw(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let color = c.input(n, "Color", C)?;
    let d = c.alloc(F);
    c.ops.push(Op::RgbToBw { color, dst: d });
    c.outputs(i, n, &[("Val", d, F)]);
    Ok(())
}

fn separate_xyz(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let v = c.input(n, "Vector", V)?;
    let (x, y, z) = (c.alloc(F), c.alloc(F), c.alloc(F));
    c.ops.push(Op::SeparateXyz { v, x, y, z });
    c.outputs(i, n, &[("X", x, F), ("Y", y, F), ("Z", z, F)]);
    Ok(())
}

fn combine_xyz(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let (x, y, z) = (
        c.input(n, "X", F)?,
        c.input(n, "Y", F)?,
        c.input(n, "Z", F)?,
    );
    let d = c.alloc(V);
    c.ops.push(Op::CombineXyz { x, y, z, dst: d });
    c.outputs(i, n, &[("Vector", d, V)]);
    Ok(())
}

fn separate_color(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = c.g.nodes[i].node.bl_idname.as_str();
    let (cm, input, outs) = match kind {
        "ShaderNodeSeparateColor" => (
            mode(n, "mode", ColorMode::from_blender)?,
            "Color",
            ["Red", "Green", "Blue"],
        ),
        "ShaderNodeSeparateRGB" => (ColorMode::Rgb, "Image", ["R", "G", "B"]),
        _ => (ColorMode::Hsv, "Color", ["H", "S", "V"]),
    };
    let color = c.input(n, input, C)?;
    let (a, b, third) = (c.alloc(F), c.alloc(F), c.alloc(F));
    c.ops.push(Op::SeparateColor {
        mode: cm,
        color,
        a,
        b,
        c: third,
    });
    c.outputs(
        i,
        n,
        &[(outs[0], a, F), (outs[1], b, F), (outs[2], third, F)],
    );
    Ok(())
}

fn combine_color(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let kind = c.g.nodes[i].node.bl_idname.as_str();
    let (cm, ins, out) = match kind {
        "ShaderNodeCombineColor" => (
            mode(n, "mode", ColorMode::from_blender)?,
            ["Red", "Green", "Blue"],
            "Color",
        ),
        "ShaderNodeCombineRGB" => (ColorMode::Rgb, ["R", "G", "B"], "Image"),
        _ => (ColorMode::Hsv, ["H", "S", "V"], "Color"),
    };
    let (a, b, third) = (
        c.input(n, ins[0], F)?,
        c.input(n, ins[1], F)?,
        c.input(n, ins[2], F)?,
    );
    let d = c.alloc(C);
    c.ops.push(Op::CombineColor {
        mode: cm,
        a,
        b,
        c: third,
        dst: d,
    });
    c.outputs(i, n, &[(out, d, C)]);
    Ok(())
}

fn blackbody(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let temperature = c.input(n, "Temperature", F)?;
    let d = c.alloc(C);
    c.ops.push(Op::Blackbody {
        temperature,
        dst: d,
    });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}

fn wavelength(c: &mut Compiler<'_, '_>, i: usize, _: &Schedule) -> Result<(), CompileError> {
    let n = &c.g.nodes[i];
    let wavelength = c.input(n, "Wavelength", F)?;
    let d = c.alloc(C);
    c.ops.push(Op::Wavelength { wavelength, dst: d });
    c.outputs(i, n, &[("Color", d, C)]);
    Ok(())
}
