//! Geometry Nodes node implementations, dispatched by `bl_idname`. A node type missing
//! here is an error naming the tree and node: it is never evaluated as something else.

pub mod attribute;
pub mod bounding_box;
pub mod curve;
pub mod curve_fields;
pub mod curve_primitives;
pub mod delete;
pub mod distribute;
pub mod extrude;
pub mod fill_curve;
pub mod field_nodes;
pub mod flip_faces;
pub mod float_curve;
pub mod function;
pub mod geometry_ops;
pub mod input;
pub mod instance_transform;
pub mod merge_by_distance;
pub mod curve_to_points;
pub mod mesh_to_curve;
pub mod dual_mesh;
pub mod sample_curve;
pub mod sample_nearest;
pub mod primitives;
pub mod proximity;
pub mod raycast;
pub mod rotation;
pub mod subdivide;
pub mod subdivision_surface;

use super::error::GeometryError;
use super::eval::{NodeCtx, Outputs};

/// Node types the evaluator implements (each covered by a Blender parity case in
/// `tests/geometry.rs` unless noted in the report).
pub const SUPPORTED: &[&str] = &[
    "ShaderNodeValue",
    "FunctionNodeInputInt",
    "FunctionNodeInputBool",
    "FunctionNodeInputVector",
    "FunctionNodeInputString",
    "GeometryNodeInputPosition",
    "GeometryNodeInputIndex",
    "GeometryNodeInputNormal",
    "GeometryNodeInputID",
    "GeometryNodeInputNamedAttribute",
    "GeometryNodeInputMaterial",
    "GeometryNodeObjectInfo",
    "GeometryNodeSelfObject",
    "GeometryNodeInputSceneTime",
    "GeometryNodeIsViewport",
    "ShaderNodeMath",
    "ShaderNodeVectorMath",
    "FunctionNodeCompare",
    "FunctionNodeBooleanMath",
    "ShaderNodeMapRange",
    "ShaderNodeClamp",
    "ShaderNodeMix",
    "ShaderNodeCombineXYZ",
    "ShaderNodeSeparateXYZ",
    "FunctionNodeRandomValue",
    "ShaderNodeTexNoise",
    "GeometryNodeSwitch",
    "GeometryNodeTransform",
    "GeometryNodeSetPosition",
    "GeometryNodeJoinGeometry",
    "GeometryNodeSetMaterial",
    "GeometryNodeSetShadeSmooth",
    "GeometryNodeMeshGrid",
    "GeometryNodeMeshCube",
    "GeometryNodeMeshUVSphere",
    "GeometryNodeMeshIcoSphere",
    "GeometryNodeMeshCylinder",
    "GeometryNodeMeshCone",
    "GeometryNodeMeshCircle",
    "GeometryNodeMeshLine",
    "GeometryNodeMeshToPoints",
    "GeometryNodePointsToVertices",
    "GeometryNodeInstanceOnPoints",
    "GeometryNodeRealizeInstances",
    "GeometryNodeStoreNamedAttribute",
    "GeometryNodeCaptureAttribute",
    "GeometryNodeSubdivideMesh",
    "GeometryNodeDistributePointsOnFaces",
    "GeometryNodeDeleteGeometry",
    "GeometryNodeSeparateGeometry",
    "GeometryNodeFieldOnDomain",
    "GeometryNodeFieldAtIndex",
    "GeometryNodeSampleIndex",
    "GeometryNodeInputMeshFaceArea",
    "FunctionNodeEulerToRotation",
    "FunctionNodeRotationToEuler",
    "FunctionNodeInputRotation",
    "GeometryNodeExtrudeMesh",
    "GeometryNodeResampleCurve",
    "GeometryNodeSetCurveRadius",
    "GeometryNodeSetCurveTilt",
    "GeometryNodeCurveToMesh",
    "GeometryNodeProximity",
    "GeometryNodeCurvePrimitiveLine",
    "GeometryNodeCurvePrimitiveCircle",
    "GeometryNodeCurveStar",
    "GeometryNodeCurveSpiral",
    "GeometryNodeCurvePrimitiveQuadrilateral",
    "GeometryNodeCurvePrimitiveBezierSegment",
    "GeometryNodeSplineParameter",
    "GeometryNodeCurveLength",
    "GeometryNodeSubdivisionSurface",
    "GeometryNodeFlipFaces",
    "GeometryNodeBoundBox",
    "GeometryNodeTranslateInstances",
    "GeometryNodeRotateInstances",
    "GeometryNodeScaleInstances",
    "FunctionNodeAxisAngleToRotation",
    "FunctionNodeRotateRotation",
    "FunctionNodeAlignEulerToVector",
    "FunctionNodeAlignRotationToVector",
    "ShaderNodeFloatCurve",
    "GeometryNodeMergeByDistance",
    "GeometryNodeCurveToPoints",
    "GeometryNodeMeshToCurve",
    "GeometryNodeDualMesh",
    "GeometryNodeSampleCurve",
    "GeometryNodeFillCurve",
    "GeometryNodeRaycast",
    "GeometryNodeSampleNearestSurface",
    "GeometryNodeSampleNearest",
];

pub fn evaluate(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let id = ctx.node().bl_idname.as_str();
    match id {
        "ShaderNodeValue" => function::value(ctx),
        "FunctionNodeInputInt" => function::integer(ctx),
        "FunctionNodeInputBool" => function::boolean(ctx),
        "FunctionNodeInputVector" => function::vector(ctx),
        "FunctionNodeInputString" => input::input_string(ctx),
        "GeometryNodeInputPosition" => input::position(ctx),
        "GeometryNodeInputIndex" => input::index(ctx),
        "GeometryNodeInputNormal" => input::normal(ctx),
        "GeometryNodeInputID" => input::id(ctx),
        "GeometryNodeInputNamedAttribute" => attribute::named_attribute(ctx),
        "GeometryNodeInputMaterial" => input::input_material(ctx),
        "GeometryNodeObjectInfo" => input::object_info(ctx),
        "GeometryNodeSelfObject" => input::self_object(ctx),
        "GeometryNodeInputSceneTime" => input::scene_time(ctx),
        "GeometryNodeIsViewport" => input::is_viewport(ctx),
        "ShaderNodeMath" => function::math(ctx),
        "ShaderNodeVectorMath" => function::vector_math_node(ctx),
        "FunctionNodeCompare" => function::compare(ctx),
        "FunctionNodeBooleanMath" => function::boolean_math(ctx),
        "ShaderNodeMapRange" => function::map_range(ctx),
        "ShaderNodeClamp" => function::clamp(ctx),
        "ShaderNodeMix" => function::mix(ctx),
        "ShaderNodeCombineXYZ" => function::combine_xyz(ctx),
        "ShaderNodeSeparateXYZ" => function::separate_xyz(ctx),
        "FunctionNodeRandomValue" => function::random_value(ctx),
        "ShaderNodeTexNoise" => function::noise_texture_node(ctx),
        "GeometryNodeSwitch" => function::switch(ctx),
        "GeometryNodeTransform" => geometry_ops::transform(ctx),
        "GeometryNodeSetPosition" => geometry_ops::set_position(ctx),
        "GeometryNodeJoinGeometry" => geometry_ops::join(ctx),
        "GeometryNodeSetMaterial" => geometry_ops::set_material(ctx),
        "GeometryNodeSetShadeSmooth" => geometry_ops::set_shade_smooth(ctx),
        "GeometryNodeMeshGrid" => primitives::grid(ctx),
        "GeometryNodeMeshCube" => primitives::cube(ctx),
        "GeometryNodeMeshUVSphere" => primitives::uv_sphere(ctx),
        "GeometryNodeMeshIcoSphere" => primitives::ico_sphere(ctx),
        "GeometryNodeMeshCylinder" => primitives::cylinder(ctx),
        "GeometryNodeMeshCone" => primitives::cone(ctx),
        "GeometryNodeMeshCircle" => primitives::circle(ctx),
        "GeometryNodeMeshLine" => primitives::line(ctx),
        "GeometryNodeMeshToPoints" => geometry_ops::mesh_to_points(ctx),
        "GeometryNodePointsToVertices" => geometry_ops::points_to_vertices(ctx),
        "GeometryNodeInstanceOnPoints" => geometry_ops::instance_on_points(ctx),
        "GeometryNodeRealizeInstances" => geometry_ops::realize(ctx),
        "GeometryNodeStoreNamedAttribute" => attribute::store_named_attribute(ctx),
        "GeometryNodeCaptureAttribute" => attribute::capture_attribute(ctx),
        "GeometryNodeSubdivideMesh" => subdivide::subdivide_node(ctx),
        "GeometryNodeDistributePointsOnFaces" => distribute::distribute_points_on_faces(ctx),
        "GeometryNodeDeleteGeometry" => delete::delete_geometry(ctx),
        "GeometryNodeSeparateGeometry" => delete::separate_geometry(ctx),
        "GeometryNodeFieldOnDomain" => field_nodes::evaluate_on_domain(ctx),
        "GeometryNodeFieldAtIndex" => field_nodes::field_at_index(ctx),
        "GeometryNodeSampleIndex" => field_nodes::sample_index(ctx),
        "GeometryNodeInputMeshFaceArea" => field_nodes::face_area(ctx),
        "FunctionNodeEulerToRotation" => field_nodes::euler_to_rotation(ctx),
        "FunctionNodeRotationToEuler" => field_nodes::rotation_to_euler(ctx),
        "FunctionNodeInputRotation" => field_nodes::input_rotation(ctx),
        "GeometryNodeExtrudeMesh" => extrude::extrude_mesh(ctx),
        "GeometryNodeResampleCurve" => curve::resample_curve(ctx),
        "GeometryNodeSetCurveRadius" => curve::set_curve_radius(ctx),
        "GeometryNodeSetCurveTilt" => curve::set_curve_tilt(ctx),
        "GeometryNodeCurveToMesh" => curve::curve_to_mesh(ctx),
        "GeometryNodeProximity" => proximity::geometry_proximity(ctx),
        "GeometryNodeCurvePrimitiveLine" => curve_primitives::line(ctx),
        "GeometryNodeCurvePrimitiveCircle" => curve_primitives::circle(ctx),
        "GeometryNodeCurveStar" => curve_primitives::star(ctx),
        "GeometryNodeCurveSpiral" => curve_primitives::spiral(ctx),
        "GeometryNodeCurvePrimitiveQuadrilateral" => curve_primitives::quadrilateral(ctx),
        "GeometryNodeCurvePrimitiveBezierSegment" => curve_primitives::bezier_segment(ctx),
        "GeometryNodeSplineParameter" => curve_fields::spline_parameter(ctx),
        "GeometryNodeCurveLength" => curve_fields::curve_length(ctx),
        "GeometryNodeSubdivisionSurface" => subdivision_surface::subdivision_surface_node(ctx),
        "GeometryNodeFlipFaces" => flip_faces::flip_faces(ctx),
        "GeometryNodeBoundBox" => bounding_box::bounding_box(ctx),
        "GeometryNodeTranslateInstances" => instance_transform::translate_instances(ctx),
        "GeometryNodeRotateInstances" => instance_transform::rotate_instances(ctx),
        "GeometryNodeScaleInstances" => instance_transform::scale_instances(ctx),
        "FunctionNodeAxisAngleToRotation" => rotation::axis_angle_to_rotation(ctx),
        "FunctionNodeRotateRotation" => rotation::rotate_rotation(ctx),
        "FunctionNodeAlignEulerToVector" => rotation::align_euler_to_vector(ctx),
        "FunctionNodeAlignRotationToVector" => rotation::align_rotation_to_vector(ctx),
        "ShaderNodeFloatCurve" => float_curve::float_curve(ctx),
        "GeometryNodeMergeByDistance" => merge_by_distance::merge_by_distance(ctx),
        "GeometryNodeCurveToPoints" => curve_to_points::curve_to_points(ctx),
        "GeometryNodeMeshToCurve" => mesh_to_curve::mesh_to_curve(ctx),
        "GeometryNodeDualMesh" => dual_mesh::dual_mesh(ctx),
        "GeometryNodeSampleCurve" => sample_curve::sample_curve(ctx),
        "GeometryNodeFillCurve" => fill_curve::fill_curve(ctx),
        "GeometryNodeRaycast" => raycast::raycast(ctx),
        "GeometryNodeSampleNearestSurface" => sample_nearest::sample_nearest_surface(ctx),
        "GeometryNodeSampleNearest" => sample_nearest::sample_nearest(ctx),
        _ => Err(ctx.err("this node type is not supported by blendsynth's Geometry Nodes evaluator")),
    }
}
