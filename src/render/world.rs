//! The world background: a Background node's colour times strength feeding the World
//! Output (constant), the world's viewport colour without nodes, or, for any other
//! world node graph (environment images, gradients by direction), the compiled world
//! program run per escaping ray (`WorldShader`).

use serde_json::Value;

use super::math::V3;
use super::RenderError;
use crate::scene::Scene;

pub fn background(scene: &Scene) -> Result<V3, RenderError> {
    let Some(name) = scene.file.scene.world.as_deref() else { return Ok([0.0; 3]) };
    let Some(w) = scene.file.worlds.iter().find(|w| w.name == name) else { return Ok([0.0; 3]) };
    let tree = match (&w.node_tree, w.use_nodes) {
        (Some(t), true) => t,
        _ => return Ok(w.color.map(|c| c.map(|x| x as f32)).unwrap_or([0.05; 3])),
    };
    if !is_constant(tree) {
        // Varies with direction: `shader` evaluates it per ray.
        return Ok([0.0; 3]);
    }
    let out = tree
        .nodes
        .iter()
        .filter(|n| n.bl_idname == "ShaderNodeOutputWorld")
        .find(|n| n.properties.get("is_active_output").and_then(Value::as_bool).unwrap_or(true))
        .or_else(|| tree.nodes.iter().find(|n| n.bl_idname == "ShaderNodeOutputWorld"));
    let Some(out) = out else { return Ok([0.0; 3]) };
    let Some(link) = tree.links.iter().find(|l| l.to_node == out.name && l.to_socket == "Surface" && !l.is_muted) else { return Ok([0.0; 3]) };
    let node = tree.nodes.iter().find(|n| n.name == link.from_node).ok_or_else(|| RenderError(format!("world {name:?}: link from missing node {:?}", link.from_node)))?;
    if node.bl_idname != "ShaderNodeBackground" && node.bl_idname != "ShaderNodeEmission" {
        return Err(RenderError(format!("world {name:?}: node {:?} ({}) is not supported as the world surface yet", node.name, node.bl_idname)));
    }
    let input = |id: &str| -> Result<Option<&Value>, RenderError> {
        if tree.links.iter().any(|l| l.to_node == node.name && l.to_socket == id && !l.is_muted) {
            return Err(RenderError(format!("world {name:?}: a linked {id:?} on {:?} is not supported yet (constant backgrounds only)", node.name)));
        }
        Ok(node.inputs.iter().find(|s| s.identifier == id).and_then(|s| s.default_value.as_ref()))
    };
    let color = input("Color")?.and_then(Value::as_array).map(|a| [0, 1, 2].map(|i| a.get(i).and_then(Value::as_f64).unwrap_or(0.0) as f32)).unwrap_or([0.8; 3]);
    let strength = input("Strength")?.and_then(Value::as_f64).unwrap_or(1.0) as f32;
    Ok(color.map(|c| c * strength))
}

/// A world whose surface varies with direction (an Environment Texture, a Texture
/// Coordinate, any linked Background input): its compiled node program, run per ray
/// that leaves the scene.
pub struct WorldShader {
    pub program: crate::shader::Program,
}

impl WorldShader {
    /// Radiance arriving along `-d` from the world (`d`: the ray's unit direction), as
    /// Cycles shades the background with the ray direction as position.
    pub fn eval(&self, d: V3, stack: &mut Vec<f32>) -> V3 {
        let p = &self.program;
        if stack.len() != p.initial.len() {
            stack.clear();
            stack.extend_from_slice(&p.initial);
        }
        p.run(&crate::shader::compile::world_point(d), stack);
        p.surface_emission(stack)
    }
}

/// The scene world's shader when it is not a constant colour (None: `background`
/// gives its constant radiance).
pub fn shader(scene: &Scene) -> Result<Option<WorldShader>, RenderError> {
    let Some(name) = scene.file.scene.world.as_deref() else { return Ok(None) };
    let Some(w) = scene.file.worlds.iter().find(|w| w.name == name) else { return Ok(None) };
    let tree = match (&w.node_tree, w.use_nodes) {
        (Some(t), true) => t,
        _ => return Ok(None),
    };
    if is_constant(tree) {
        return Ok(None);
    }
    let program = crate::shader::compile::compile_world(scene, name).map_err(|e| RenderError(e.to_string()))?;
    Ok(Some(WorldShader { program }))
}

/// True when the world output is fed by a Background or Emission node with unlinked
/// inputs (or by nothing): `background` handles that without a program.
fn is_constant(tree: &crate::scene::NodeTree) -> bool {
    let out = tree
        .nodes
        .iter()
        .filter(|n| n.bl_idname == "ShaderNodeOutputWorld")
        .find(|n| n.properties.get("is_active_output").and_then(Value::as_bool).unwrap_or(true))
        .or_else(|| tree.nodes.iter().find(|n| n.bl_idname == "ShaderNodeOutputWorld"));
    let Some(out) = out else { return true };
    let Some(link) = tree.links.iter().find(|l| l.to_node == out.name && l.to_socket == "Surface" && !l.is_muted) else { return true };
    let Some(node) = tree.nodes.iter().find(|n| n.name == link.from_node) else { return true };
    (node.bl_idname == "ShaderNodeBackground" || node.bl_idname == "ShaderNodeEmission") && !node.mute && !tree.links.iter().any(|l| l.to_node == node.name && !l.is_muted)
}
