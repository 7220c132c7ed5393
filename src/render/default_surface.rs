//! Materials with Use Nodes off, as Cycles 4.5 renders them (blender/shader.cpp): a
//! Diffuse BSDF of the material's Viewport Display colour (`diffuse_color`, roughness 0)
//! into the surface output, whatever node tree the material still carries. Written here
//! as the node tree it amounts to, so the one shader compiler handles it.

use std::borrow::Cow;

use serde_json::{json, Value};

use crate::scene::{NodeTree, Scene};

/// The scene with every Use Nodes off material given Cycles' surface for it; borrowed
/// unchanged when there is none.
pub fn apply(scene: &Scene) -> Result<Cow<'_, Scene>, String> {
    if scene.file.materials.iter().all(|m| m.use_nodes) {
        return Ok(Cow::Borrowed(scene));
    }
    let mut out = scene.clone();
    for m in out.file.materials.iter_mut().filter(|m| !m.use_nodes) {
        let Some(colour) = crate::scene::settings::MaterialSettings::of(m).diffuse_color else {
            return Err(format!(
                "material {:?}: Use Nodes is off and the export has no diffuse_color",
                m.name
            ));
        };
        m.node_tree = Some(diffuse_tree(colour)?);
    }
    Ok(Cow::Owned(out))
}

fn socket(index: usize, id: &str, kind: &str, default: Value, enabled: bool) -> Value {
    let mut s = json!({"index": index, "identifier": id, "name": id, "type": kind,
        "is_linked": false, "enabled": enabled});
    if !default.is_null() {
        s["default_value"] = default;
    }
    s
}

fn diffuse_tree(c: [f64; 3]) -> Result<NodeTree, String> {
    let v = json!({
        "name": "Use Nodes off", "bl_idname": "ShaderNodeTree", "interface": [],
        "nodes": [
            {"name": "Diffuse BSDF", "bl_idname": "ShaderNodeBsdfDiffuse",
             "inputs": [
                socket(0, "Color", "RGBA", json!([c[0], c[1], c[2], 1.0]), true),
                socket(1, "Roughness", "VALUE", json!(0.0), true),
                socket(2, "Normal", "VECTOR", json!([0.0, 0.0, 0.0]), true),
                socket(3, "Weight", "VALUE", json!(0.0), false)],
             "outputs": [socket(0, "BSDF", "SHADER", Value::Null, true)]},
            {"name": "Material Output", "bl_idname": "ShaderNodeOutputMaterial",
             "properties": {"is_active_output": true, "target": "ALL"},
             "inputs": [
                socket(0, "Surface", "SHADER", Value::Null, true),
                socket(1, "Volume", "SHADER", Value::Null, true),
                socket(2, "Displacement", "VECTOR", json!([0.0, 0.0, 0.0]), true),
                socket(3, "Thickness", "VALUE", json!(0.0), true)],
             "outputs": []}
        ],
        "links": [{"from_node": "Diffuse BSDF", "from_socket": "BSDF", "from_index": 0,
                   "to_node": "Material Output", "to_socket": "Surface", "to_index": 0}]
    });
    serde_json::from_value(v).map_err(|e| format!("default surface: {e}"))
}
