//! Geometry Nodes without Blender: geometry sets (mesh, curves, point cloud, instances)
//! with Blender's attributes and domain interpolation, fields, and an evaluator for node
//! trees of NODES modifiers, proven node by node against Blender's own evaluated meshes
//! (`tests/geometry.rs`, references made by `fixtures/geometry/make_gn_refs.py`).
//!
//! One idea per file: `types` (domains, data types, values, conversions), `attribute`,
//! `mesh`, `curves`, `pointcloud`, `instances`, `set`, `interpolate` (domain
//! interpolation), `field`, `value` (socket values), `eval` (modifier stacks and trees),
//! `nodes/*` (node implementations), `realize` (join and realize), `export` (PLY, OBJ,
//! glb), `animated` (overrides and animated node values), `math`, `nearest` (nearest
//! elements), `mesh_sample` (values at points on corner triangles).
//!
//! ```no_run
//! use blendsynth::{geometry, scene::Scene};
//! let scene = Scene::load(std::path::Path::new("export")).unwrap();
//! let set = geometry::evaluate_object(&scene, "Terrain", 1.0, &[
//!     ("objects[\"Terrain\"].modifiers[\"Terrain\"][\"Socket_1\"]".into(), serde_json::json!(7)),
//! ]).unwrap();
//! let mesh = geometry::realize_to_mesh(&set).unwrap();
//! geometry::write_ply(std::path::Path::new("terrain.ply"), &mesh).unwrap();
//! ```

// Mesh code indexes several parallel arrays by the same element index.
#![allow(clippy::needless_range_loop)]

pub mod animated;
pub mod attribute;
pub mod beautify;
pub mod bezier_handles;
pub mod bisect_plane;
pub mod bmesh;
pub mod catmull_clark;
pub mod cdt;
pub mod curve_eval;
pub mod curves;
pub mod error;
pub mod eval;
pub mod export;
pub mod field;
pub mod instances;
pub mod interpolate;
pub mod kdtree;
pub mod legacy_curve;
pub mod limits;
pub mod math;
pub mod mesh;
pub mod mesh_sample;
pub mod modifiers;
pub mod nearest;
pub mod nodes;
pub mod nurbs;
pub mod pointcloud;
pub mod polyfill;
pub mod realize;
pub mod set;
pub mod source;
pub mod subdivide_curves;
pub mod types;
pub mod value;
pub mod volume;
pub mod weld;
pub mod zones;

pub use error::GeometryError;
pub use export::{write_glb, write_mesh, write_obj, write_ply};
pub use mesh::Mesh;
pub use set::GeometrySet;

use crate::scene::Scene;

/// Evaluates `object`'s geometry at `frame`: its mesh data through its Geometry Nodes
/// modifiers, with node values and modifier inputs animated at `frame` and `overrides`
/// (Blender data paths, as `--set` takes them) applied on top.
///
/// Overrides address anything the export holds, e.g.
/// `node_groups["G"].nodes["Value"].outputs[0].default_value` = 3 or
/// `objects["Terrain"].modifiers["Terrain"]["Socket_2"]` = 7.
pub fn evaluate_object(
    scene: &Scene,
    object: &str,
    frame: f64,
    overrides: &[(String, serde_json::Value)],
) -> Result<GeometrySet, GeometryError> {
    if !frame.is_finite() {
        return Err(GeometryError::new(format!("frame {frame} is not finite")));
    }
    // Simulation zones continue the state of the frame before: play them from their
    // start, one whole evaluation per frame (nodes::simulation_zone).
    let mut states = eval::SimulationStates::new();
    for f in nodes::simulation_zone::playback_frames(scene, object, frame)? {
        let scene = animated::scene_at(scene, f, overrides)?;
        let session = session_at(&scene, f)?.with_simulation_states(states);
        session.evaluate_object(object).map_err(|e| {
            GeometryError::new(format!(
                "playing the simulation to frame {frame}, at frame {f}: {e}"
            ))
        })?;
        states = session.into_simulation_states();
    }
    let scene = animated::scene_at(scene, frame, overrides)?;
    let session = session_at(&scene, frame)?.with_simulation_states(states);
    session.evaluate_object(object)
}

fn session_at(scene: &Scene, frame: f64) -> Result<eval::Session<'_>, GeometryError> {
    let anim = crate::anim::evaluate_scene(scene, frame)?;
    let world = anim
        .world_matrices
        .iter()
        .map(math::from_rows_f64)
        .collect();
    let sort_ids = animated::link_sort_ids(scene)?;
    Ok(eval::Session::new(
        scene,
        frame,
        world,
        sort_ids,
        anim.data.cameras,
    ))
}

/// The geometry as one mesh: instances realized (Blender's Realize Instances order),
/// point clouds appended as loose vertices. Curves are an error for now.
pub fn realize_to_mesh(set: &GeometrySet) -> Result<Mesh, GeometryError> {
    realize::to_mesh(set).map_err(GeometryError::new)
}

/// Whether the evaluator implements a node type (by `bl_idname`).
pub fn supports_node(bl_idname: &str) -> bool {
    nodes::supports(bl_idname)
}

/// Support for a node inside a tree of type `tree` (`ShaderNodeTree`,
/// `GeometryNodeTree`, ...): the shared maths only counts where an evaluator for that
/// tree type runs it. In Geometry Nodes trees that is this evaluator's own table
/// (`nodes::NODES`: shader-named texture, ramp, curve and colour nodes count there once
/// they run as fields with Blender's Geometry Nodes semantics); in shader trees, the
/// shader node table (`crate::shader::compile::support`). It lives here, above both evaluators.
pub fn support_in(tree: &str, bl_idname: &str) -> crate::nodes::Support {
    use crate::nodes::Support;
    if tree == "GeometryNodeTree"
        && crate::shader::compile::support(bl_idname) != Support::Structural
    {
        return if supports_node(bl_idname) {
            Support::Supported
        } else {
            Support::Unsupported
        };
    }
    match crate::shader::compile::support(bl_idname) {
        Support::Supported if tree != "ShaderNodeTree" => Support::Unsupported,
        s => s,
    }
}
