//! Scene evaluation at a frame, as Blender's depsgraph does it for transforms: animation
//! (F-curves with modifiers) is written into a copy of the datablocks, then every object's
//! world matrix is solved through parents and constraints (Follow Path on the curve's
//! path, Track To, Damped Track).
//!
//! One idea per file: `fcurve` (keyframes, easing), `fmodifier` (modifier stack), `noise`
//! (Perlin for the Noise modifier), `animate` (writing
//! animated values), `transform` (basis, parenting, solve order), `path` (curve path),
//! `constraint`, `math`.

// Matrix code reads best with explicit row/column indices.
#![allow(clippy::needless_range_loop)]

mod animate;
mod constraint;
mod error;
mod fcurve;
mod fmodifier;
mod math;
mod noise;
mod path;
mod transform;

use std::collections::HashMap;

pub use animate::{ctime, Datablocks};
pub use error::AnimError;
pub use fcurve::{CompiledFCurve, ValueKind};
pub use math::{qslerp, Mat4};
pub use transform::basis_matrix;

use crate::scene::{FCurve, Scene};

/// Evaluation settings.
#[derive(Debug, Clone, Copy)]
pub struct EvalOptions {
    /// Use curves' render resolution (`render_resolution_u`, when set) for paths, as a
    /// final render does; the viewport (and `bpy` `frame_set`) uses `resolution_u`.
    pub for_render: bool,
}

impl Default for EvalOptions {
    fn default() -> Self {
        EvalOptions { for_render: true }
    }
}

/// A scene evaluated at one frame.
#[derive(Debug, Clone)]
pub struct EvaluatedScene {
    pub frame: f64,
    /// Objects, curves, cameras and lights with animated values written in.
    pub data: Datablocks,
    /// World matrices in `scene.file.objects` order, `m[row][col]`.
    pub world_matrices: Vec<Mat4>,
    /// F-curves (and drivers on things that do not move objects) that were not applied,
    /// as `id_path data_path[index]`, so callers can decide whether they matter.
    pub unapplied: Vec<String>,
}

/// Evaluates one F-curve at `frame` (keyframes, extrapolation, modifiers), like Blender's
/// `FCurve.evaluate`: mute is not applied here (it only stops the curve animating).
/// The animated property is taken to be a float; see `evaluate_fcurve_as` for others.
pub fn evaluate_fcurve(fc: &FCurve, frame: f64) -> Result<f64, AnimError> {
    evaluate_fcurve_as(fc, frame, ValueKind::default())
}

/// `evaluate_fcurve` for a property of the given kind: Blender rounds F-curves of integer
/// properties and steps those of booleans and enums (`ValueKind::of_json` tells the kind
/// from a value as the exporter wrote it).
pub fn evaluate_fcurve_as(fc: &FCurve, frame: f64, kind: ValueKind) -> Result<f64, AnimError> {
    let label = format!("fcurve {}[{}]", fc.data_path, fc.array_index);
    let c = CompiledFCurve::new(fc, kind).map_err(|e| e.within(&label))?;
    Ok(c.eval(ctime(frame)) as f64)
}

/// World matrices of all objects at `frame`, in `scene.file.objects` order.
pub fn evaluate_transforms(scene: &Scene, frame: f64) -> Result<Vec<Mat4>, AnimError> {
    Ok(evaluate_scene(scene, frame)?.world_matrices)
}

/// Evaluates animation and transforms at `frame` with default options (render mode).
pub fn evaluate_scene(scene: &Scene, frame: f64) -> Result<EvaluatedScene, AnimError> {
    evaluate_scene_with(scene, frame, EvalOptions::default())
}

pub fn evaluate_scene_with(
    scene: &Scene,
    frame: f64,
    opts: EvalOptions,
) -> Result<EvaluatedScene, AnimError> {
    if !frame.is_finite() {
        return Err(AnimError::new(
            "frame",
            format!("{frame} is not a finite frame"),
        ));
    }
    let mut data = Datablocks::from_file(&scene.file);
    let unapplied = animate::apply(&scene.file.animation, frame, &mut data)?;
    let axes = track_axes(scene);
    let bones = transform::BoneParents {
        frame,
        export_frame: scene.file.scene.frame_current as f64,
        posed: posed_armatures(scene),
    };
    // A camera that is never the scene's moves nothing that renders (issue 26: a
    // constraint blendsynth does not evaluate on it must not block the frame). Every
    // camera a timeline marker binds is solved: a motion step may fall on the far side
    // of a marker from the frame whose camera it moves.
    let s = &scene.file.scene;
    let is_scene_camera = |name: &str| {
        s.camera.as_deref() == Some(name) || s.camera_markers.iter().any(|m| m.camera == name)
    };
    let world_matrices = transform::Solver::new(&data, opts.for_render, &axes)
        .with_bone_parents(bones)
        .solve_needed(|o| o.kind != "CAMERA" || is_scene_camera(&o.name))?;
    Ok(EvaluatedScene {
        frame,
        data,
        world_matrices,
        unapplied,
    })
}

/// Armature objects whose pose is animated (F-curves or drivers under `pose`), each with
/// one such path.
fn posed_armatures(scene: &Scene) -> HashMap<String, String> {
    let mut out = HashMap::new();
    for a in &scene.file.animation {
        if a.id_type != "OBJECT" {
            continue;
        }
        if let Some(fc) = a
            .fcurves
            .iter()
            .chain(&a.drivers)
            .find(|fc| fc.data_path.starts_with("pose"))
        {
            out.entry(a.id_name.clone())
                .or_insert_with(|| format!("{}.{}", a.id_path, fc.data_path));
        }
    }
    // NLA strips are not exported: they may pose the armature at any frame.
    for o in scene.file.objects.iter().filter(|o| o.kind == "ARMATURE") {
        let prefix = format!("objects[{}]: NLA strips", crate::scene::quote(&o.name));
        if scene.file.warnings.iter().any(|w| w.starts_with(&prefix)) {
            out.entry(o.name.clone()).or_insert_with(|| {
                format!("objects[{}] (NLA strips)", crate::scene::quote(&o.name))
            });
        }
    }
    out
}

/// Objects' `track_axis`/`up_axis` as indices (only children of following path curves
/// use them); objects exported without them are left out.
fn track_axes(scene: &Scene) -> HashMap<String, (i32, i32)> {
    let mut out = HashMap::new();
    for o in &scene.file.objects {
        let track = o.track_axis.as_deref().and_then(|t| match t {
            "POS_X" => Some(0),
            "POS_Y" => Some(1),
            "POS_Z" => Some(2),
            "NEG_X" => Some(3),
            "NEG_Y" => Some(4),
            "NEG_Z" => Some(5),
            _ => None,
        });
        let up = o.up_axis.as_deref().and_then(|t| match t {
            "X" => Some(0),
            "Y" => Some(1),
            "Z" => Some(2),
            _ => None,
        });
        if let (Some(track), Some(up)) = (track, up) {
            out.insert(o.name.clone(), (track, up));
        }
    }
    out
}
