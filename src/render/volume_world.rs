//! The world volume: a World Output's Volume, as Cycles 4.5 integrates it (scene/
//! background.cpp, integrator/volume_stack.h, shade_volume.h). It fills all space: it is
//! the first entry of every path's volume stack (the camera is inside it) and is never
//! left; a ray that escapes keeps it alone (volume_stack_clean) and crosses it up to
//! FLT_MAX, so wherever it absorbs or scatters, the background and the suns are
//! extinguished (exp(-sigma FLT_MAX)) and only lights at a finite distance are seen.
//! It is shaded with no object: the position is the point in world space.

use crate::scene::settings::{VolumeSampling, WorldSettings};
use crate::scene::Scene as BlendScene;
use crate::shader::program::{Op, Program};

use super::RenderError;

/// The volume stack entry of the world volume (Cycles' OBJECT_NONE with the background's
/// volume shader): (WORLD, WORLD).
pub const WORLD: u32 = u32::MAX;

/// Cycles' length of a ray segment that escapes the scene (FLT_MAX, not infinity: its
/// transmittance is exp(-sigma FLT_MAX), so a channel that does not extinguish keeps 1).
pub const ESCAPE: f32 = f32::MAX;

/// The scene world's volume as the renderer runs it.
#[derive(Debug, Clone)]
pub struct WorldVolume {
    /// The world's compiled program (its `volume` closure is the world volume).
    pub program: Program,
    /// Ray-marched: its closures read computed values and Homogeneous is off.
    pub varying: bool,
    /// World > Settings > Volume > Step Size.
    pub step_size: f32,
    /// World > Settings > Volume > Sampling.
    pub sampling: VolumeSampling,
}

/// The scene world's volume, if its active World Output has a linked Volume; an error
/// naming the world for what blendsynth cannot evaluate in it.
pub fn world_volume(scene: &BlendScene) -> Result<Option<WorldVolume>, RenderError> {
    let Some((w, tree)) = super::light::world::node_tree(scene) else {
        return Ok(None);
    };
    let name = w.name.as_str();
    let Some(out) = crate::nodes::graph::active_output(tree, "ShaderNodeOutputWorld", "CYCLES")
    else {
        return Ok(None);
    };
    if !tree
        .links
        .iter()
        .any(|l| l.to_node == out.name && l.to_socket == "Volume" && !l.is_muted)
    {
        return Ok(None);
    }
    let program = crate::shader::compile::compile_world(scene, name)
        .map_err(|e| RenderError(e.to_string()))?;
    if program.volume.is_none() {
        return Ok(None);
    }
    // Point Density samples the texture space of the volume's object; the world has none
    // (Cycles' volume_normalized_position with no object is not matched).
    if program
        .ops
        .iter()
        .any(|op| matches!(op, Op::TexPointDensity { .. }))
    {
        return Err(RenderError(format!(
            "world {name:?}: Point Density in a world's node tree (its Volume is linked) is not supported yet"
        )));
    }
    let settings = WorldSettings::of(w);
    let step_size = settings.volume_step_size as f32;
    if !(step_size > 0.0 && step_size.is_finite()) {
        return Err(RenderError(format!(
            "world {name:?}: Volume Step Size {step_size} is not a positive number"
        )));
    }
    Ok(Some(WorldVolume {
        varying: program.volume_varying && !settings.homogeneous_volume,
        program,
        step_size,
        sampling: settings.volume_sampling,
    }))
}
