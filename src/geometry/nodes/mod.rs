//! Geometry Nodes node implementations, dispatched by `bl_idname`. A node type missing
//! here is an error naming the tree and node: it is never evaluated as something else.

pub mod accumulate_field;
pub mod attribute;
pub mod attribute_statistic;
pub mod bake;
pub mod blur_attribute;
pub mod bounding_box;
pub mod camera_info;
pub mod collection_info;
pub mod color;
pub mod convex_hull;
pub mod curve;
pub mod curve_arc;
pub mod curve_fields;
pub mod curve_primitives;
pub mod curve_quadratic_bezier;
pub mod curve_read;
pub mod curve_tangent;
pub mod curve_to_points;
pub mod curve_topology;
pub mod curve_write;
pub mod deform_curves_on_surface;
pub mod delete;
pub mod distribute;
pub mod distribute_points_in_volume;
pub mod domain_size;
pub mod dual_mesh;
pub mod duplicate_elements;
pub mod edge_paths_to_curves;
pub mod edge_paths_to_selection;
pub mod edges_to_face_groups;
pub mod extrude;
pub mod field_average;
pub mod field_min_and_max;
pub mod field_nodes;
pub mod field_statistics;
pub mod field_variance;
pub mod fill_curve;
pub mod fillet_curve;
pub mod flip_faces;
pub mod float_curve;
pub mod foreach_element;
pub mod format_string;
pub mod function;
pub mod geometry_ops;
pub mod geometry_to_instance;
pub mod gizmo_dial;
pub mod gizmo_linear;
pub mod gizmo_transform;
pub mod ico_sphere;
pub mod image_info;
pub mod image_texture;
pub mod import_csv;
pub mod import_file;
pub mod import_obj;
pub mod import_ply;
pub mod import_stl;
pub mod import_text;
pub mod index_of_nearest;
pub mod input;
pub mod input_active_camera;
pub mod input_image;
pub mod instance_bounds;
pub mod instance_transform;
pub mod integer_math;
pub mod interpolate_curves;
pub mod is_smooth;
pub mod material_index;
pub mod material_selection;
pub mod matrix;
pub mod menu_switch;
pub mod merge_by_distance;
pub mod mesh_face_set_boundaries;
pub mod mesh_to_curve;
pub mod mesh_to_volume;
pub mod mesh_topology;
pub mod points;
pub mod points_to_curves;
pub mod points_to_volume;
pub mod primitives;
pub mod proximity;
pub mod radius;
pub mod raycast;
pub mod remove_attribute;
pub mod repeat_zone;
pub mod replace_material;
pub mod reverse_curve;
pub mod rotation;
pub mod sample_curve;
pub mod sample_nearest;
pub mod sample_uv_surface;
pub mod scale_elements;
pub mod separate_components;
pub mod set_geometry_name;
pub mod set_mesh_normal;
pub mod set_spline_type;
pub mod shortest_edge_paths;
pub mod simulation_zone;
pub mod sort_elements;
pub mod split_edges;
pub mod split_to_instances;
pub mod string;
pub mod subdivide;
pub mod subdivide_curve;
pub mod subdivision_surface;
pub mod texture;
pub mod triangulate;
pub mod trim_curve;
pub mod viewer;
pub mod volume_cube;
pub mod volume_to_mesh;
pub mod warning;

use super::error::GeometryError;
use super::eval::{NodeCtx, Outputs};

/// One evaluation function per node type.
pub type Evaluate = fn(&NodeCtx) -> Result<Outputs, GeometryError>;

/// The node types the evaluator implements, each with its function: the one list that
/// dispatch, `inspect` and docs/features.md read (each covered by a Blender parity case in
/// `tests/geometry.rs` unless noted in the report). A new node is one line here and its
/// file beside its Blender group's.
pub const NODES: &[(&str, Evaluate)] = &[
    ("ShaderNodeValue", function::value),
    ("FunctionNodeInputInt", function::integer),
    ("FunctionNodeInputBool", function::boolean),
    ("FunctionNodeInputVector", function::vector),
    ("FunctionNodeInputString", input::input_string),
    ("GeometryNodeInputPosition", input::position),
    ("GeometryNodeInputIndex", input::index),
    ("GeometryNodeInputNormal", input::normal),
    ("GeometryNodeInputID", input::id),
    (
        "GeometryNodeInputNamedAttribute",
        attribute::named_attribute,
    ),
    ("GeometryNodeInputMaterial", input::input_material),
    ("GeometryNodeObjectInfo", input::object_info),
    ("GeometryNodeSelfObject", input::self_object),
    ("GeometryNodeInputSceneTime", input::scene_time),
    ("GeometryNodeIsViewport", input::is_viewport),
    ("ShaderNodeMath", function::math),
    ("ShaderNodeVectorMath", function::vector_math_node),
    ("FunctionNodeCompare", function::compare),
    ("FunctionNodeBooleanMath", function::boolean_math),
    ("ShaderNodeMapRange", function::map_range),
    ("ShaderNodeClamp", function::clamp),
    ("ShaderNodeMix", function::mix),
    ("ShaderNodeCombineXYZ", function::combine_xyz),
    ("ShaderNodeSeparateXYZ", function::separate_xyz),
    ("FunctionNodeRandomValue", function::random_value),
    ("ShaderNodeTexNoise", function::noise_texture_node),
    ("GeometryNodeSwitch", function::switch),
    ("GeometryNodeIndexSwitch", function::index_switch),
    ("GeometryNodeTransform", geometry_ops::transform),
    ("GeometryNodeSetPosition", geometry_ops::set_position),
    ("GeometryNodeJoinGeometry", geometry_ops::join),
    ("GeometryNodeSetMaterial", geometry_ops::set_material),
    ("GeometryNodeSetShadeSmooth", geometry_ops::set_shade_smooth),
    (
        "GeometryNodeSetMeshNormal",
        set_mesh_normal::set_mesh_normal,
    ),
    ("GeometryNodeMeshGrid", primitives::grid),
    ("GeometryNodeMeshCube", primitives::cube),
    ("GeometryNodeMeshUVSphere", primitives::uv_sphere),
    ("GeometryNodeMeshIcoSphere", ico_sphere::ico_sphere),
    ("GeometryNodeMeshCylinder", primitives::cylinder),
    ("GeometryNodeMeshCone", primitives::cone),
    ("GeometryNodeMeshCircle", primitives::circle),
    ("GeometryNodeMeshLine", primitives::line),
    ("GeometryNodeMeshToPoints", geometry_ops::mesh_to_points),
    (
        "GeometryNodePointsToVertices",
        geometry_ops::points_to_vertices,
    ),
    (
        "GeometryNodeInstanceOnPoints",
        geometry_ops::instance_on_points,
    ),
    ("GeometryNodeRealizeInstances", geometry_ops::realize),
    (
        "GeometryNodeStoreNamedAttribute",
        attribute::store_named_attribute,
    ),
    ("GeometryNodeCaptureAttribute", attribute::capture_attribute),
    ("GeometryNodeSubdivideMesh", subdivide::subdivide_node),
    (
        "GeometryNodeDistributePointsOnFaces",
        distribute::distribute_points_on_faces,
    ),
    ("GeometryNodeDeleteGeometry", delete::delete_geometry),
    ("GeometryNodeSeparateGeometry", delete::separate_geometry),
    ("GeometryNodeFieldOnDomain", field_nodes::evaluate_on_domain),
    ("GeometryNodeFieldAtIndex", field_nodes::field_at_index),
    ("GeometryNodeSampleIndex", field_nodes::sample_index),
    ("GeometryNodeInputMeshFaceArea", field_nodes::face_area),
    (
        "FunctionNodeEulerToRotation",
        field_nodes::euler_to_rotation,
    ),
    (
        "FunctionNodeRotationToEuler",
        field_nodes::rotation_to_euler,
    ),
    ("FunctionNodeInputRotation", field_nodes::input_rotation),
    ("GeometryNodeExtrudeMesh", extrude::extrude_mesh),
    ("GeometryNodeResampleCurve", curve::resample_curve),
    ("GeometryNodeSetCurveRadius", curve::set_curve_radius),
    ("GeometryNodeSetCurveTilt", curve::set_curve_tilt),
    ("GeometryNodeCurveToMesh", curve::curve_to_mesh),
    ("GeometryNodeProximity", proximity::geometry_proximity),
    ("GeometryNodeCurvePrimitiveLine", curve_primitives::line),
    ("GeometryNodeCurvePrimitiveCircle", curve_primitives::circle),
    ("GeometryNodeCurveStar", curve_primitives::star),
    ("GeometryNodeCurveSpiral", curve_primitives::spiral),
    (
        "GeometryNodeCurvePrimitiveQuadrilateral",
        curve_primitives::quadrilateral,
    ),
    (
        "GeometryNodeCurvePrimitiveBezierSegment",
        curve_primitives::bezier_segment,
    ),
    (
        "GeometryNodeSplineParameter",
        curve_fields::spline_parameter,
    ),
    ("GeometryNodeCurveLength", curve_fields::curve_length),
    (
        "GeometryNodeSubdivisionSurface",
        subdivision_surface::subdivision_surface_node,
    ),
    ("GeometryNodeFlipFaces", flip_faces::flip_faces),
    ("GeometryNodeBoundBox", bounding_box::bounding_box),
    ("GeometryNodeConvexHull", convex_hull::convex_hull),
    (
        "GeometryNodeInputMaterialIndex",
        material_index::material_index,
    ),
    (
        "GeometryNodeSetMaterialIndex",
        material_index::set_material_index,
    ),
    (
        "GeometryNodeTranslateInstances",
        instance_transform::translate_instances,
    ),
    (
        "GeometryNodeRotateInstances",
        instance_transform::rotate_instances,
    ),
    (
        "GeometryNodeScaleInstances",
        instance_transform::scale_instances,
    ),
    (
        "FunctionNodeAxisAngleToRotation",
        rotation::axis_angle_to_rotation,
    ),
    ("FunctionNodeRotateRotation", rotation::rotate_rotation),
    (
        "FunctionNodeAlignEulerToVector",
        rotation::align_euler_to_vector,
    ),
    (
        "FunctionNodeAlignRotationToVector",
        rotation::align_rotation_to_vector,
    ),
    ("FunctionNodeRotateEuler", rotation::rotate_euler),
    ("ShaderNodeFloatCurve", float_curve::float_curve),
    (
        "GeometryNodeMergeByDistance",
        merge_by_distance::merge_by_distance,
    ),
    (
        "GeometryNodeCurveToPoints",
        curve_to_points::curve_to_points,
    ),
    ("GeometryNodeMeshToCurve", mesh_to_curve::mesh_to_curve),
    ("GeometryNodeDualMesh", dual_mesh::dual_mesh),
    ("GeometryNodeSampleCurve", sample_curve::sample_curve),
    ("GeometryNodeFillCurve", fill_curve::fill_curve),
    ("GeometryNodeRaycast", raycast::raycast),
    (
        "GeometryNodeSampleNearestSurface",
        sample_nearest::sample_nearest_surface,
    ),
    ("GeometryNodeSampleNearest", sample_nearest::sample_nearest),
    (
        "GeometryNodeSampleUVSurface",
        sample_uv_surface::sample_uv_surface,
    ),
    ("ShaderNodeTexVoronoi", texture::voronoi),
    ("ShaderNodeTexWhiteNoise", texture::white_noise_node),
    ("ShaderNodeTexGradient", texture::gradient_node),
    ("ShaderNodeTexWave", texture::wave_node),
    ("ShaderNodeTexMagic", texture::magic_node),
    ("ShaderNodeTexChecker", texture::checker_node),
    ("ShaderNodeTexBrick", texture::brick_node),
    ("ShaderNodeValToRGB", color::color_ramp),
    ("ShaderNodeRGBCurve", color::rgb_curves),
    ("ShaderNodeVectorCurve", color::vector_curves),
    ("FunctionNodeSeparateColor", color::separate_color),
    ("FunctionNodeCombineColor", color::combine_color),
    ("ShaderNodeMixRGB", color::mix_rgb),
    ("ShaderNodeVectorRotate", color::vector_rotate_node),
    ("FunctionNodeRotateVector", color::rotate_vector),
    ("FunctionNodeFloatToInt", color::float_to_int),
    ("ShaderNodeBlackbody", color::blackbody_node),
    ("GeometryNodeImageTexture", image_texture::image_texture),
    ("GeometryNodeMenuSwitch", menu_switch::menu_switch),
    ("GeometryNodeCurveArc", curve_arc::arc),
    ("GeometryNodeInputTangent", curve_tangent::curve_tangent),
    ("GeometryNodeInputRadius", radius::radius),
    (
        "GeometryNodeAttributeStatistic",
        attribute_statistic::attribute_statistic,
    ),
    (
        "GeometryNodeCollectionInfo",
        collection_info::collection_info,
    ),
    ("GeometryNodeSplitEdges", split_edges::split_edges),
    (
        "GeometryNodeSplitToInstances",
        split_to_instances::split_to_instances,
    ),
    ("GeometryNodeAttributeDomainSize", domain_size::domain_size),
    ("GeometryNodeInputShadeSmooth", is_smooth::is_face_smooth),
    ("GeometryNodeInputEdgeSmooth", is_smooth::is_edge_smooth),
    (
        "GeometryNodeMaterialSelection",
        material_selection::material_selection,
    ),
    (
        "GeometryNodeSeparateComponents",
        separate_components::separate_components,
    ),
    (
        "GeometryNodeGeometryToInstance",
        geometry_to_instance::geometry_to_instance,
    ),
    // Mesh topology fields (issue 26).
    (
        "GeometryNodeInputMeshEdgeNeighbors",
        mesh_topology::edge_neighbors,
    ),
    (
        "GeometryNodeInputMeshFaceNeighbors",
        mesh_topology::face_neighbors,
    ),
    (
        "GeometryNodeInputMeshVertexNeighbors",
        mesh_topology::vertex_neighbors,
    ),
    (
        "GeometryNodeInputMeshEdgeVertices",
        mesh_topology::edge_vertices,
    ),
    ("GeometryNodeInputMeshEdgeAngle", mesh_topology::edge_angle),
    ("GeometryNodeInputMeshIsland", mesh_topology::mesh_island),
    (
        "GeometryNodeInputMeshFaceIsPlanar",
        mesh_topology::face_is_planar,
    ),
    ("GeometryNodeCornersOfFace", mesh_topology::corners_of_face),
    (
        "GeometryNodeCornersOfVertex",
        mesh_topology::corners_of_vertex,
    ),
    ("GeometryNodeEdgesOfVertex", mesh_topology::edges_of_vertex),
    ("GeometryNodeEdgesOfCorner", mesh_topology::edges_of_corner),
    ("GeometryNodeFaceOfCorner", mesh_topology::face_of_corner),
    (
        "GeometryNodeVertexOfCorner",
        mesh_topology::vertex_of_corner,
    ),
    (
        "GeometryNodeOffsetCornerInFace",
        mesh_topology::offset_corner_in_face,
    ),
    (
        "GeometryNodeAccumulateField",
        accumulate_field::accumulate_field,
    ),
    ("GeometryNodeBlurAttribute", blur_attribute::blur_attribute),
    ("FunctionNodeIntegerMath", integer_math::integer_math),
    ("FunctionNodeBitMath", integer_math::bit_math),
    ("FunctionNodeHashValue", integer_math::hash_value),
    ("FunctionNodeInvertRotation", rotation::invert_rotation),
    (
        "FunctionNodeQuaternionToRotation",
        rotation::quaternion_to_rotation,
    ),
    (
        "FunctionNodeRotationToQuaternion",
        rotation::rotation_to_quaternion,
    ),
    (
        "FunctionNodeRotationToAxisAngle",
        rotation::rotation_to_axis_angle,
    ),
    ("FunctionNodeCombineTransform", matrix::combine_transform),
    ("FunctionNodeSeparateTransform", matrix::separate_transform),
    ("FunctionNodeTransformPoint", matrix::transform_point_node),
    (
        "FunctionNodeTransformDirection",
        matrix::transform_direction_node,
    ),
    ("FunctionNodeProjectPoint", matrix::project_point_node),
    ("FunctionNodeInvertMatrix", matrix::invert_matrix),
    ("FunctionNodeMatrixMultiply", matrix::multiply_matrices),
    ("FunctionNodeTransposeMatrix", matrix::transpose_matrix),
    ("FunctionNodeMatrixDeterminant", matrix::matrix_determinant),
    ("FunctionNodeCombineMatrix", matrix::combine_matrix),
    ("FunctionNodeSeparateMatrix", matrix::separate_matrix),
    ("GeometryNodeVolumeCube", volume_cube::volume_cube),
    ("GeometryNodeVolumeToMesh", volume_to_mesh::volume_to_mesh),
    ("GeometryNodeMeshToVolume", mesh_to_volume::mesh_to_volume),
    (
        "GeometryNodePointsToVolume",
        points_to_volume::points_to_volume,
    ),
    (
        "GeometryNodeDistributePointsInVolume",
        distribute_points_in_volume::distribute_points_in_volume,
    ),
    ("GeometryNodePoints", points::points),
    ("GeometryNodeSetPointRadius", points::set_point_radius),
    ("GeometryNodeSetID", points::set_id),
    ("GeometryNodeInstancesToPoints", points::instances_to_points),
    ("GeometryNodeInstanceTransform", points::instance_transform),
    (
        "GeometryNodeInputInstanceRotation",
        points::instance_rotation,
    ),
    ("GeometryNodeInputInstanceScale", points::instance_scale),
    ("GeometryNodeTriangulate", triangulate::triangulate_node),
    ("GeometryNodeScaleElements", scale_elements::scale_elements),
    ("GeometryNodeSortElements", sort_elements::sort_elements),
    ("GeometryNodeRepeatInput", repeat_zone::repeat_input),
    ("GeometryNodeRepeatOutput", repeat_zone::repeat_output),
    (
        "GeometryNodeForeachGeometryElementInput",
        foreach_element::foreach_input,
    ),
    (
        "GeometryNodeForeachGeometryElementOutput",
        foreach_element::foreach_output,
    ),
    ("FunctionNodeValueToString", string::value_to_string),
    ("FunctionNodeFormatString", format_string::format_string),
    ("GeometryNodeStringJoin", string::join_strings),
    ("FunctionNodeSliceString", string::slice_string),
    ("FunctionNodeStringLength", string::string_length),
    (
        "FunctionNodeInputSpecialCharacters",
        string::special_characters,
    ),
    ("FunctionNodeReplaceString", string::replace_string),
    ("FunctionNodeFindInString", string::find_in_string),
    ("FunctionNodeMatchString", string::match_string),
    (
        "GeometryNodeSimulationInput",
        simulation_zone::simulation_input,
    ),
    (
        "GeometryNodeSimulationOutput",
        simulation_zone::simulation_output,
    ),
    ("GeometryNodeReverseCurve", reverse_curve::reverse_curve),
    (
        "GeometryNodeSetSplineCyclic",
        curve_write::set_spline_cyclic,
    ),
    (
        "GeometryNodeSetSplineResolution",
        curve_write::set_spline_resolution,
    ),
    ("GeometryNodeCurveSetHandles", curve_write::set_handle_type),
    (
        "GeometryNodeSetCurveHandlePositions",
        curve_write::set_handle_positions,
    ),
    ("GeometryNodeSetCurveNormal", curve_write::set_curve_normal),
    (
        "GeometryNodeInputCurveHandlePositions",
        curve_read::curve_handle_positions,
    ),
    (
        "GeometryNodeCurveHandleTypeSelection",
        curve_read::handle_type_selection,
    ),
    (
        "GeometryNodeCurveEndpointSelection",
        curve_read::endpoint_selection,
    ),
    (
        "GeometryNodeInputSplineCyclic",
        curve_read::is_spline_cyclic,
    ),
    (
        "GeometryNodeInputSplineResolution",
        curve_read::spline_resolution,
    ),
    ("GeometryNodeSplineLength", curve_read::spline_length),
    ("GeometryNodeInputCurveTilt", curve_read::curve_tilt),
    ("GeometryNodeCurveOfPoint", curve_topology::curve_of_point),
    ("GeometryNodePointsOfCurve", curve_topology::points_of_curve),
    (
        "GeometryNodeOffsetPointInCurve",
        curve_topology::offset_point_in_curve,
    ),
    (
        "GeometryNodeCurveSplineType",
        set_spline_type::set_spline_type,
    ),
    (
        "GeometryNodeSubdivideCurve",
        subdivide_curve::subdivide_curve,
    ),
    ("GeometryNodeTrimCurve", trim_curve::trim_curve),
    (
        "GeometryNodeInterpolateCurves",
        interpolate_curves::interpolate_curves,
    ),
    (
        "GeometryNodeIndexOfNearest",
        index_of_nearest::index_of_nearest,
    ),
    (
        "GeometryNodeInputShortestEdgePaths",
        shortest_edge_paths::shortest_edge_paths,
    ),
    (
        "GeometryNodeEdgePathsToSelection",
        edge_paths_to_selection::edge_paths_to_selection,
    ),
    (
        "GeometryNodeEdgePathsToCurves",
        edge_paths_to_curves::edge_paths_to_curves,
    ),
    ("GeometryNodeFilletCurve", fillet_curve::fillet_curve_node),
    // Topology and curve nodes (issue 26 item 4).
    (
        "GeometryNodeDuplicateElements",
        duplicate_elements::duplicate_elements,
    ),
    (
        "GeometryNodeCurveQuadraticBezier",
        curve_quadratic_bezier::quadratic_bezier,
    ),
    (
        "GeometryNodePointsToCurves",
        points_to_curves::points_to_curves,
    ),
    (
        "GeometryNodeMeshFaceSetBoundaries",
        mesh_face_set_boundaries::face_set_boundaries,
    ),
    (
        "GeometryNodeEdgesToFaceGroups",
        edges_to_face_groups::edges_to_face_groups,
    ),
    // Inputs and pass-throughs (issue 26 item 4).
    ("FunctionNodeInputColor", input::input_color),
    ("GeometryNodeInputObject", input::input_object),
    ("GeometryNodeInputCollection", input::input_collection),
    ("GeometryNodeViewer", viewer::viewer),
    ("GeometryNodeWarning", warning::warning),
    ("GeometryNodeBake", bake::bake),
    (
        "GeometryNodeSetGeometryName",
        set_geometry_name::set_geometry_name,
    ),
    (
        "GeometryNodeRemoveAttribute",
        remove_attribute::remove_attribute,
    ),
    (
        "GeometryNodeReplaceMaterial",
        replace_material::replace_material,
    ),
    (
        "GeometryNodeSetInstanceTransform",
        instance_transform::set_instance_transform,
    ),
    ("FunctionNodeAxesToRotation", rotation::axes_to_rotation),
    ("GeometryNodeCornersOfEdge", mesh_topology::corners_of_edge),
    (
        "GeometryNodeInputInstanceBounds",
        instance_bounds::instance_bounds,
    ),
    // Field statistics (issue 26 item 4).
    ("GeometryNodeFieldAverage", field_average::field_average),
    (
        "GeometryNodeFieldMinAndMax",
        field_min_and_max::field_min_and_max,
    ),
    ("GeometryNodeFieldVariance", field_variance::field_variance),
    // Camera and image inputs (issue 26 item 4).
    (
        "GeometryNodeInputActiveCamera",
        input_active_camera::active_camera,
    ),
    ("GeometryNodeCameraInfo", camera_info::camera_info),
    ("GeometryNodeInputImage", input_image::input_image),
    ("GeometryNodeImageInfo", image_info::image_info),
    // Gizmos: nothing in a render evaluation (issue 26 item 4).
    ("GeometryNodeGizmoDial", gizmo_dial::gizmo_dial),
    ("GeometryNodeGizmoLinear", gizmo_linear::gizmo_linear),
    (
        "GeometryNodeGizmoTransform",
        gizmo_transform::gizmo_transform,
    ),
    // Import nodes: the export's copies of the files (issue 26 item 4).
    ("GeometryNodeImportSTL", import_stl::import_stl),
    ("GeometryNodeImportCSV", import_csv::import_csv),
    (
        "GeometryNodeDeformCurvesOnSurface",
        deform_curves_on_surface::deform_curves_on_surface,
    ),
    ("GeometryNodeImportText", import_text::import_text),
    ("GeometryNodeImportPLY", import_ply::import_ply),
    ("GeometryNodeImportOBJ", import_obj::import_obj),
];

/// The `bl_idname`s of `NODES`.
pub fn supported() -> impl Iterator<Item = &'static str> {
    NODES.iter().map(|(name, _)| *name)
}

fn lookup(bl_idname: &str) -> Option<Evaluate> {
    static BY_NAME: std::sync::OnceLock<std::collections::HashMap<&'static str, Evaluate>> =
        std::sync::OnceLock::new();
    BY_NAME
        .get_or_init(|| NODES.iter().copied().collect())
        .get(bl_idname)
        .copied()
}

/// Whether the evaluator implements a node type.
pub fn supports(bl_idname: &str) -> bool {
    lookup(bl_idname).is_some()
}

pub fn evaluate(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    match lookup(ctx.node().bl_idname.as_str()) {
        Some(f) => f(ctx),
        None => {
            Err(ctx.err("this node type is not supported by blendsynth's Geometry Nodes evaluator"))
        }
    }
}
