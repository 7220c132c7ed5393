//! Serde types for `scene.json`, version 1 (see `blender_export/FORMAT.md`).
//!
//! Fields the renderer and evaluators depend on are typed and required; the long tail of
//! Blender settings that the exporter dumps generically from RNA is kept as JSON maps
//! (`Rna`), so a newer Blender's extra properties load without a format change.
//! Unknown keys are ignored everywhere, so newer exporters stay readable.

use serde::{Deserialize, Serialize};

/// The `format` tag every scene file must carry.
pub const FORMAT_TAG: &str = "blendsynth-scene";
/// The newest format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// Generic RNA values as the exporter dumps them (property identifier -> value).
pub type Rna = serde_json::Map<String, serde_json::Value>;

/// A 4x4 matrix as a list of rows (`m[row][col]`, translation in column 3), as
/// Blender's `mathutils.Matrix` indexes it.
pub type Matrix4 = [[f64; 4]; 4];

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SceneFile {
    pub format: String,
    pub version: u32,
    #[serde(default)]
    pub exporter_version: u32,
    pub blender_version: String,
    #[serde(default)]
    pub blender_version_tuple: Vec<u32>,
    #[serde(default)]
    pub file_version: Vec<u32>,
    #[serde(default)]
    pub source_file: String,
    pub scene: SceneSettings,
    pub objects: Vec<Object>,
    pub meshes: Vec<MeshRef>,
    #[serde(default)]
    pub curves: Vec<Curve>,
    pub materials: Vec<Material>,
    #[serde(default)]
    pub worlds: Vec<World>,
    pub node_groups: Vec<NodeTree>,
    /// `bpy.data.collections` (older exports have none).
    #[serde(default)]
    pub collections: Vec<Collection>,
    #[serde(default)]
    pub cameras: Vec<Camera>,
    #[serde(default)]
    pub lights: Vec<Light>,
    #[serde(default)]
    pub images: Vec<Image>,
    /// Files the Geometry Nodes Import nodes may read, copied into the export and keyed
    /// by Blender's path string (FORMAT.md "Import files"); absent in older exports.
    #[serde(default)]
    pub import_files: Vec<ImportFile>,
    #[serde(default)]
    pub animation: Vec<AnimData>,
    #[serde(default)]
    pub evaluated: Vec<Evaluated>,
    /// Smoke (gas fluid) domains and the grids their materials read at the exported
    /// frame (`scene::volume_grid`); absent in older exports.
    #[serde(default)]
    pub smoke_domains: Vec<super::volume_grid::SmokeDomain>,
    /// Volume objects (OpenVDB) and the grids their materials read at the exported
    /// frame (`scene::volume_grid`); absent in older exports.
    #[serde(default)]
    pub volume_objects: Vec<super::volume_grid::VolumeObject>,
    /// Data paths changed by `--set` or a spec since the export (not in scene.json as
    /// written): frozen geometry that reads one of them is refused.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub overridden: Vec<String>,
    #[serde(default)]
    pub color_management: ColorManagement,
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// A timeline marker that binds a camera (`scene.timeline_markers[i].camera`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CameraMarker {
    pub frame: i32,
    pub camera: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SceneSettings {
    pub name: String,
    pub frame_start: i32,
    pub frame_end: i32,
    pub frame_current: i32,
    #[serde(default = "one_i32")]
    pub frame_step: i32,
    /// Where Geometry Nodes simulation zones start (absent in older exports).
    #[serde(default)]
    pub simulation_frame_start: Option<i32>,
    /// Where they end (absent in older exports).
    #[serde(default)]
    pub simulation_frame_end: Option<i32>,
    pub fps: f64,
    #[serde(default = "one_f64")]
    pub fps_base: f64,
    pub camera: Option<String>,
    /// Timeline markers bound to a camera, in Blender's list order (absent in older
    /// exports): Blender switches the active camera at them (`Scene::camera_at`).
    #[serde(default)]
    pub camera_markers: Vec<CameraMarker>,
    #[serde(default)]
    pub world: Option<String>,
    #[serde(default)]
    pub render: Rna,
    #[serde(default)]
    pub cycles: Rna,
    /// Cycles' Curves panel (`scene.cycles_curves`: shape, subdivisions); absent in older
    /// exports, whose defaults then apply.
    #[serde(default)]
    pub cycles_curves: Rna,
    #[serde(default)]
    pub view_settings: Rna,
    #[serde(default)]
    pub display_settings: Rna,
    #[serde(default)]
    pub unit_settings: Rna,
    /// The rendered view layer (absent in older exports: no AOVs).
    #[serde(default)]
    pub view_layer: ViewLayer,
}

/// The view layer a render writes: its shader AOVs and the Alpha Threshold.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ViewLayer {
    #[serde(default)]
    pub name: String,
    #[serde(default = "half_f64")]
    pub pass_alpha_threshold: f64,
    #[serde(default)]
    pub aovs: Vec<Aov>,
}

impl Default for ViewLayer {
    fn default() -> ViewLayer {
        ViewLayer {
            name: "ViewLayer".into(),
            pass_alpha_threshold: 0.5,
            aovs: Vec::new(),
        }
    }
}

/// One of a view layer's shader AOVs (`view_layer.aovs`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Aov {
    pub name: String,
    /// "COLOR" or "VALUE".
    #[serde(rename = "type")]
    pub kind: String,
    /// False for a repeated name or one a built-in pass has: Cycles writes no pass.
    #[serde(default = "yes")]
    pub is_valid: bool,
}

fn half_f64() -> f64 {
    0.5
}

fn one_i32() -> i32 {
    1
}
fn one_f64() -> f64 {
    1.0
}

/// Which rays see an object (Blender's `visible_camera`, `visible_diffuse`, ...).
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq)]
pub struct RayVisibility {
    pub camera: bool,
    pub diffuse: bool,
    pub glossy: bool,
    pub transmission: bool,
    pub volume_scatter: bool,
    pub shadow: bool,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Object {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    pub data: Option<String>,
    pub parent: Option<String>,
    #[serde(default)]
    pub parent_type: Option<String>,
    /// The parent bone of a bone-parented object (parent_type BONE).
    #[serde(default)]
    pub parent_bone: Option<String>,
    pub matrix_world: Matrix4,
    #[serde(default)]
    pub matrix_local: Option<Matrix4>,
    #[serde(default)]
    pub matrix_basis: Option<Matrix4>,
    #[serde(default)]
    pub matrix_parent_inverse: Option<Matrix4>,
    pub location: [f64; 3],
    pub rotation_mode: String,
    pub rotation_euler: [f64; 3],
    pub rotation_quaternion: [f64; 4],
    #[serde(default)]
    pub rotation_axis_angle: Option<[f64; 4]>,
    pub scale: [f64; 3],
    #[serde(default)]
    pub delta_location: Option<[f64; 3]>,
    #[serde(default)]
    pub delta_rotation_euler: Option<[f64; 3]>,
    #[serde(default)]
    pub delta_rotation_quaternion: Option<[f64; 4]>,
    #[serde(default)]
    pub delta_scale: Option<[f64; 3]>,
    #[serde(default)]
    pub hide_render: bool,
    #[serde(default)]
    pub hide_viewport: bool,
    /// Object > Simulation Cache (on by default): Simulation zones stop at the end of
    /// their frame range; without it they keep stepping.
    #[serde(default = "yes")]
    pub use_simulation_cache: bool,
    #[serde(default = "yes")]
    pub visible: bool,
    /// In a view-layer collection that is neither excluded nor disabled in renders (nor
    /// any collection above it): false for objects in no scene collection, in another
    /// scene, or only in a library collection an empty instances. True in older exports.
    #[serde(default = "yes")]
    pub in_render_layer: bool,
    /// Cycles' ray visibility; absent in exports made before it was written (then
    /// Blender 4.5's defaults apply: everything visible but lights to the camera).
    #[serde(default)]
    pub visibility: Option<RayVisibility>,
    #[serde(default)]
    pub pass_index: i32,
    #[serde(default)]
    pub collections: Vec<String>,
    #[serde(default)]
    pub material_slots: Vec<MaterialSlot>,
    #[serde(default)]
    pub modifiers: Vec<Modifier>,
    #[serde(default)]
    pub constraints: Vec<Constraint>,
    #[serde(default)]
    pub custom_properties: Rna,
    /// Per name an Object or Instancer Attribute node reads: what Blender's
    /// find_rna_property_rgba finds on the object and on its data (a custom property or an
    /// RNA path of that name, as RGBA). Absent in older exports.
    #[serde(default)]
    pub attribute_lookups: std::collections::BTreeMap<String, AttributeLookup>,
    /// The object's own track and up axes (POS_X.., X/Y/Z): a child of a path curve
    /// with "Follow" on is oriented by them.
    #[serde(default)]
    pub track_axis: Option<String>,
    #[serde(default)]
    pub up_axis: Option<String>,
    #[serde(default)]
    pub instance_type: Option<String>,
    #[serde(default)]
    pub instance_collection: Option<String>,
    /// Object colour RGBA (Object Info > Color and Alpha); absent in older exports.
    #[serde(default)]
    pub color: Option<[f64; 4]>,
    /// Cycles' object settings (`use_motion_blur`, `use_deform_motion`, `motion_steps`);
    /// absent in older exports.
    #[serde(default)]
    pub cycles: Option<Rna>,
    /// Object > Visibility > Holdout and Shadow Catcher; false in older exports.
    #[serde(default)]
    pub is_holdout: bool,
    #[serde(default)]
    pub is_shadow_catcher: bool,
    /// Object > Shading > Shadow Terminator > Geometry Offset; Blender's default 0.1 in
    /// older exports.
    #[serde(default = "default_terminator_offset")]
    pub shadow_terminator_geometry_offset: f32,
    /// Object > Shading > Shadow Terminator > Shading Offset (default 0).
    #[serde(default)]
    pub shadow_terminator_shading_offset: f32,
}

fn default_terminator_offset() -> f32 {
    0.1
}

fn yes() -> bool {
    true
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MaterialSlot {
    pub material: Option<String>,
    #[serde(default)]
    pub link: Option<String>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Modifier {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default = "yes")]
    pub show_render: bool,
    #[serde(default = "yes")]
    pub show_viewport: bool,
    #[serde(default)]
    pub properties: Rna,
    #[serde(default)]
    pub node_group: Option<String>,
    #[serde(default)]
    pub inputs: Rna,
    /// A Geometry Nodes modifier's bake items, one per Simulation zone or Bake node
    /// (absent in older exports).
    #[serde(default)]
    pub bake_states: Option<Vec<BakeState>>,
}

/// One bake item of a Geometry Nodes modifier (FORMAT.md, `bake_states`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BakeState {
    pub bake_id: i64,
    /// The zone's output node (or Bake node) and the node tree holding it.
    #[serde(default)]
    pub node: Option<String>,
    #[serde(default)]
    pub node_tree: Option<String>,
    #[serde(default)]
    pub use_custom_simulation_frame_range: bool,
    #[serde(default)]
    pub frame_start: i32,
    #[serde(default)]
    pub frame_end: i32,
    #[serde(default)]
    pub target: Option<String>,
    /// Whether baked data exists (packed in the file or on disk); None when the exporter
    /// could not tell.
    #[serde(default)]
    pub baked: Option<bool>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Constraint {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub mute: bool,
    #[serde(default = "one_f64")]
    pub influence: f64,
    #[serde(default)]
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeshRef {
    pub name: String,
    pub file: String,
    pub vertex_count: usize,
    pub edge_count: usize,
    pub face_count: usize,
    pub corner_count: usize,
    #[serde(default)]
    pub materials: Vec<Option<String>>,
    #[serde(default)]
    pub uv_layers: Vec<String>,
    #[serde(default)]
    pub active_uv: Option<String>,
    #[serde(default)]
    pub active_render_uv: Option<String>,
    #[serde(default)]
    pub attributes: Vec<AttributeInfo>,
    #[serde(default)]
    pub texspace_location: Option<[f64; 3]>,
    #[serde(default)]
    pub texspace_size: Option<[f64; 3]>,
    #[serde(default)]
    pub use_auto_texspace: Option<bool>,
    /// The colour attribute a Color Attribute node without a name reads (Blender's
    /// default colour attribute).
    #[serde(default)]
    pub default_color_attribute: Option<String>,
    /// Whether the mesh has shape keys (their blend is only in the evaluated mesh).
    #[serde(default)]
    pub shape_keys: bool,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AttributeInfo {
    pub name: String,
    pub domain: String,
    pub data_type: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Curve {
    pub name: String,
    #[serde(default)]
    pub properties: Rna,
    #[serde(default)]
    pub materials: Vec<Option<String>>,
    pub splines: Vec<Spline>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Spline {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub use_cyclic_u: bool,
    #[serde(default = "twelve")]
    pub resolution_u: u32,
    #[serde(default = "four")]
    pub order_u: u32,
    #[serde(default)]
    pub use_endpoint_u: bool,
    #[serde(default)]
    pub use_bezier_u: bool,
    #[serde(default = "yes")]
    pub use_smooth: bool,
    #[serde(default)]
    pub material_index: u32,
    #[serde(default)]
    pub tilt_interpolation: Option<String>,
    #[serde(default)]
    pub radius_interpolation: Option<String>,
    #[serde(default)]
    pub bezier_points: Vec<BezierPoint>,
    #[serde(default)]
    pub points: Vec<SplinePoint>,
}

fn twelve() -> u32 {
    12
}
fn four() -> u32 {
    4
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BezierPoint {
    pub co: [f64; 3],
    pub handle_left: [f64; 3],
    pub handle_right: [f64; 3],
    pub handle_left_type: String,
    pub handle_right_type: String,
    #[serde(default = "one_f64")]
    pub radius: f64,
    #[serde(default)]
    pub tilt: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SplinePoint {
    pub co: [f64; 4],
    #[serde(default = "one_f64")]
    pub radius: f64,
    #[serde(default)]
    pub tilt: f64,
    #[serde(default = "one_f64")]
    pub weight: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    #[serde(default)]
    pub use_nodes: bool,
    pub node_tree: Option<NodeTree>,
    #[serde(default)]
    pub pass_index: i32,
    #[serde(default)]
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct World {
    pub name: String,
    #[serde(default)]
    pub color: Option<[f64; 3]>,
    #[serde(default)]
    pub use_nodes: bool,
    pub node_tree: Option<NodeTree>,
    #[serde(default)]
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NodeTree {
    pub name: String,
    pub bl_idname: String,
    #[serde(default)]
    pub interface: Vec<InterfaceItem>,
    pub nodes: Vec<Node>,
    pub links: Vec<Link>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct InterfaceItem {
    pub item_type: String,
    #[serde(default)]
    pub in_out: Option<String>,
    pub name: String,
    #[serde(default)]
    pub identifier: Option<String>,
    #[serde(default)]
    pub socket_type: Option<String>,
    #[serde(default)]
    pub default_value: Option<serde_json::Value>,
    #[serde(default)]
    pub min_value: Option<serde_json::Value>,
    #[serde(default)]
    pub max_value: Option<serde_json::Value>,
    #[serde(default)]
    pub parent: Option<String>,
    #[serde(default)]
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Node {
    pub name: String,
    pub bl_idname: String,
    #[serde(default)]
    pub label: String,
    #[serde(default)]
    pub mute: bool,
    #[serde(default)]
    pub parent: Option<String>,
    #[serde(default)]
    pub location: Option<[f64; 2]>,
    #[serde(default)]
    pub hide: bool,
    #[serde(default)]
    pub node_tree: Option<String>,
    #[serde(default)]
    pub properties: Rna,
    pub inputs: Vec<Socket>,
    pub outputs: Vec<Socket>,
    /// Blender's pass-through links, used when the node is muted: input identifier
    /// (`from`) to output identifier (`to`).
    #[serde(default)]
    pub internal_links: Vec<InternalLink>,
    /// The IES Texture node's photometric data as Cycles loads it: the Text's content
    /// (Internal) or the file's (External); "\n" where Cycles finds none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ies: Option<String>,
    /// The Point Density node's voxel grid as Blender computed it for Cycles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point_density: Option<PointDensityGrid>,
}

/// A Point Density node's grid (`point_density/*.bin`: RGBA float32 little-endian, x
/// fastest), computed by Blender at the exported frame over the bounds `min`..`max` in
/// the points object's space (`calc_point_density`, `calc_point_density_minmax`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PointDensityGrid {
    pub file: String,
    pub resolution: u32,
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// The points object's world matrix (rows), None without an object.
    #[serde(default)]
    pub object_matrix: Option<[[f32; 4]; 4]>,
    pub frame: f64,
    /// The node properties the grid was computed with.
    #[serde(default)]
    pub properties: serde_json::Map<String, serde_json::Value>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct InternalLink {
    pub from: String,
    pub to: String,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Socket {
    pub index: usize,
    pub identifier: String,
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub bl_idname: String,
    #[serde(default)]
    pub default_value: Option<serde_json::Value>,
    #[serde(default)]
    pub is_linked: bool,
    #[serde(default)]
    pub hide: bool,
    #[serde(default = "yes")]
    pub enabled: bool,
    #[serde(default)]
    pub hide_value: bool,
    #[serde(default)]
    pub is_multi_input: bool,
}

impl InterfaceItem {
    /// A Geometry Nodes group input's Default Input when it is a field (`INDEX`,
    /// `ID_OR_INDEX`, `NORMAL`, `POSITION`, `INSTANCE_TRANSFORM`, `HANDLE_LEFT`,
    /// `HANDLE_RIGHT`): what the input gives while its socket is unlinked. `None` for
    /// the socket's own value (`VALUE`, or an export without the setting).
    pub fn default_input_field(&self) -> Option<&str> {
        self.properties
            .get("default_input")
            .and_then(|v| v.as_str())
            .filter(|v| *v != "VALUE")
    }
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Link {
    pub from_node: String,
    pub from_socket: String,
    #[serde(default)]
    pub from_index: Option<usize>,
    pub to_node: String,
    pub to_socket: String,
    #[serde(default)]
    pub to_index: Option<usize>,
    #[serde(default)]
    pub is_muted: bool,
    #[serde(default = "yes")]
    pub is_valid: bool,
    /// Order of this link among the links into a multi-input socket (Join Geometry);
    /// 0 when the exporter did not write it.
    #[serde(default)]
    pub multi_input_sort_id: i64,
}

/// A collection: its objects and child collections in Blender's order, and the offset
/// instancing subtracts.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Collection {
    pub name: String,
    #[serde(default)]
    pub objects: Vec<String>,
    #[serde(default)]
    pub children: Vec<String>,
    #[serde(default)]
    pub instance_offset: [f32; 3],
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Camera {
    pub name: String,
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: String,
    /// The light's shader nodes (used when `properties.use_nodes`); absent in older exports.
    #[serde(default)]
    pub node_tree: Option<NodeTree>,
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Image {
    pub name: String,
    #[serde(default)]
    pub source: Option<String>,
    #[serde(default)]
    pub filepath: String,
    pub file: Option<String>,
    #[serde(default)]
    pub packed: bool,
    #[serde(default)]
    pub missing: bool,
    #[serde(default)]
    pub colorspace: Option<String>,
    #[serde(default)]
    pub alpha_mode: Option<String>,
    #[serde(default)]
    pub size: Option<[u32; 2]>,
}

/// One file an Import node may read: Blender's path string and the export's copy.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ImportFile {
    pub path: String,
    #[serde(default)]
    pub file: Option<String>,
    /// No file there when exported: Blender's node gives empty geometry.
    #[serde(default)]
    pub missing: bool,
    /// Outside the .blend's folder (and every allowed one): not copied.
    #[serde(default)]
    pub outside: bool,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct AnimData {
    pub id_type: String,
    pub id_name: String,
    pub id_path: String,
    #[serde(default)]
    pub action: Option<String>,
    #[serde(default)]
    pub fcurves: Vec<FCurve>,
    #[serde(default)]
    pub drivers: Vec<FCurve>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FCurve {
    pub data_path: String,
    #[serde(default)]
    pub array_index: usize,
    pub extrapolation: String,
    #[serde(default)]
    pub mute: bool,
    pub keyframes: Vec<Keyframe>,
    #[serde(default)]
    pub modifiers: Vec<FModifier>,
    /// Present on drivers only: the driver's RNA (type, expression, variables).
    #[serde(default)]
    pub driver: Option<Rna>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Keyframe {
    pub co: [f64; 2],
    pub handle_left: [f64; 2],
    pub handle_right: [f64; 2],
    #[serde(default)]
    pub handle_left_type: Option<String>,
    #[serde(default)]
    pub handle_right_type: Option<String>,
    pub interpolation: String,
    #[serde(default)]
    pub easing: Option<String>,
    #[serde(default)]
    pub back: Option<f64>,
    #[serde(default)]
    pub amplitude: Option<f64>,
    #[serde(default)]
    pub period: Option<f64>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FModifier {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default)]
    pub mute: bool,
    #[serde(default)]
    pub properties: Rna,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Evaluated {
    pub object: String,
    pub frame: f64,
    pub file: String,
    #[serde(default)]
    pub vertex_count: Option<usize>,
    #[serde(default)]
    pub face_count: Option<usize>,
    #[serde(default)]
    pub instances_realized: Option<usize>,
    /// Grids in the volume of Blender's evaluated geometry (Geometry Nodes' volume
    /// component), which the frozen mesh does not carry; 0 in older exports.
    #[serde(default)]
    pub volume_grids: usize,
    /// What the object's evaluation reads, as Blender data path prefixes (its modifiers,
    /// its data, shape keys, objects its modifiers reference); None in exports made
    /// before frozen geometry, which are reference meshes only.
    #[serde(default)]
    pub reads: Option<Vec<String>>,
    /// The animated (F-curve or driver) properties under `reads`, as full data paths.
    #[serde(default)]
    pub animated: Vec<String>,
    /// The evaluated mesh's material slots, UV maps and default colour attribute.
    #[serde(default)]
    pub materials: Vec<Option<String>>,
    #[serde(default)]
    pub uv_layers: Vec<String>,
    #[serde(default)]
    pub active_render_uv: Option<String>,
    #[serde(default)]
    pub default_color_attribute: Option<String>,
    /// What the object renders that its evaluated mesh lacks (hair particle systems,
    /// ...), named: such an object is refused.
    #[serde(default)]
    pub unsupported: Vec<String>,
    /// The hair strands Cycles renders with the object (its Path hair particle
    /// systems), None when it has none (`scene::hair`).
    #[serde(default)]
    pub hair: Option<HairRef>,
    /// The instances Blender realised into the evaluated mesh, each of which Cycles
    /// renders as an object of its own; None without instances (and in exports made
    /// before it was written).
    #[serde(default)]
    pub realized: Option<Realized>,
    /// The object's point clouds (its own points, and those its Geometry Nodes make):
    /// `count` x, y, z, radius (float32, object space), then a uint32 index into
    /// `materials` per point.
    #[serde(default)]
    pub points: Option<PointsRef>,
}

/// How an evaluated mesh splits into the instancer's own geometry and the instances
/// realised after it: parts follow each other in every domain, in this order.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Realized {
    /// Vertex, edge, face, corner and triangle counts of the instancer's own geometry.
    pub own_counts: [usize; 5],
    pub instances: Vec<RealizedInstance>,
}

/// One realised instance: its part's counts, its transform in the instancer's object
/// space (rows), and what Object Info and Generated read on it in Cycles.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RealizedInstance {
    pub counts: [usize; 5],
    pub matrix: [[f64; 4]; 4],
    /// Blender's DepsgraphObjectInstance.random_id (Object Info > Random).
    pub random_id: u32,
    /// The instanced object (its colour and pass index below).
    pub object: String,
    pub color: [f64; 4],
    pub pass_index: i64,
    /// The instanced mesh's texture space; None for other object types (Generated then
    /// spans the part's bounds).
    #[serde(default)]
    pub texspace_location: Option<[f32; 3]>,
    #[serde(default)]
    pub texspace_size: Option<[f32; 3]>,
    /// The particle it stands for (Particle Info): `Some(None)` for an instance no
    /// particle made (or a child particle: Cycles' dummy particle), `None` in exports
    /// older than the record.
    #[serde(
        default,
        deserialize_with = "present",
        skip_serializing_if = "Option::is_none"
    )]
    pub particle: Option<Option<Particle>>,
}

/// A key that is present, even as null, deserializes to `Some` (absent: the default).
fn present<'de, D, T>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    T::deserialize(d).map(Some)
}

/// A particle as Cycles' sync_dupli_particle reads it from Blender at the frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Particle {
    /// Its index among the system's particles.
    pub index: u32,
    /// The frame (with subframe) minus its birth time.
    pub age: f32,
    pub lifetime: f32,
    pub location: [f32; 3],
    pub size: f32,
    pub velocity: [f32; 3],
    pub angular_velocity: [f32; 3],
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PointsRef {
    pub file: String,
    pub count: usize,
}

/// An object's hair strands: a file of x, y, z, radius per key (little-endian f32,
/// object space), curve after curve, system after system.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HairRef {
    pub file: String,
    pub systems: Vec<HairSystem>,
    /// Per-curve and per-key attributes (UV maps and colours from the emitter, a Curves
    /// object's attributes): float32 values, attribute after attribute, in this file.
    #[serde(default)]
    pub attributes_file: Option<String>,
    #[serde(default)]
    pub attributes: Vec<HairAttribute>,
    /// The attribute Cycles reads as the hair's UV (Texture Coordinate / UV Map default).
    #[serde(default)]
    pub uv: Option<String>,
    /// A Curves object's normals at its keys (little-endian f32 x, y, z per key, object
    /// space): the normal attribute Cycles gives its curves. None for particle hair and
    /// exports made before normals were exported.
    #[serde(default)]
    pub normals_file: Option<String>,
}

/// One hair attribute: `domain` CURVE (a value per curve) or POINT (per key);
/// `data_type` FLOAT, FLOAT2, FLOAT_VECTOR or FLOAT_COLOR (1 to 4 floats).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HairAttribute {
    pub name: String,
    pub domain: String,
    pub data_type: String,
}

/// One hair particle system's strands as Cycles syncs them.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HairSystem {
    pub name: String,
    /// The object's material slot the strands use (Cycles' omat - 1, clamped).
    pub material_slot: usize,
    pub curve_count: usize,
    /// Keys of every curve (particle hair); 0 for a Curves object's system, whose curves
    /// differ: its `key_count` keys are then followed by one u32 key count per curve.
    pub keys_per_curve: usize,
    /// A Curves object's keys in all (with `keys_per_curve` 0).
    #[serde(default)]
    pub key_count: Option<usize>,
    /// Whether the strands are the children (the parents then do not render).
    #[serde(default)]
    pub children: bool,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct ColorManagement {
    #[serde(default)]
    pub dir: Option<String>,
    #[serde(default)]
    pub config: Option<String>,
}

/// What an Object / Instancer Attribute node finds on an object and on its data.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct AttributeLookup {
    #[serde(default)]
    pub object: Option<[f32; 4]>,
    #[serde(default)]
    pub data: Option<[f32; 4]>,
}
