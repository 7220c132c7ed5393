//! Every committed fixture export loads, its meshes read back with the counts
//! scene.json declares, and it holds everything Blender reported when it was made
//! (`blender_counts.json`, written by `fixtures/blender_counts.py` from the .blend).

mod common;
use common::*;

use blendsynth::scene::Scene;

#[test]
fn committed_fixture_exports_hold_what_blender_reported() {
    let root = repo().join("fixtures/scenes");
    let mut seen = 0;
    for e in std::fs::read_dir(&root).unwrap() {
        let dir = e.unwrap().path();
        if !dir.join("scene.json").is_file() {
            continue;
        }
        let s = Scene::load(&dir).unwrap_or_else(|e| panic!("{e}"));
        for i in 0..s.file.meshes.len() {
            s.load_mesh(i).unwrap_or_else(|e| panic!("{e}"));
        }
        for i in 0..s.file.evaluated.len() {
            s.load_evaluated(i).unwrap_or_else(|e| panic!("{e}"));
        }
        let blender: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("blender_counts.json")).unwrap())
                .unwrap();
        assert_eq!(
            export_counts(&s),
            blender,
            "{}: export differs from Blender's counts",
            dir.display()
        );
        seen += 1;
    }
    assert!(
        seen >= 3,
        "expected the material_zoo, geonodes and animated_camera fixtures, found {seen}"
    );
}

#[test]
fn material_zoo_has_what_the_issue_asks_for() {
    let s = Scene::load(&repo().join("fixtures/scenes/material_zoo")).unwrap();
    let trees = s.node_trees();
    let mat = s
        .file
        .materials
        .iter()
        .find_map(|m| m.node_tree.as_ref())
        .expect("a material with nodes");
    let mut kinds: Vec<&str> = mat
        .nodes
        .iter()
        .map(|n| n.bl_idname.as_str())
        .filter(|k| k.starts_with("ShaderNode"))
        .collect();
    for (_, g) in &trees {
        kinds.extend(
            g.nodes
                .iter()
                .map(|n| n.bl_idname.as_str())
                .filter(|k| k.starts_with("ShaderNode")),
        );
    }
    kinds.sort();
    kinds.dedup();
    assert!(
        kinds.len() >= 20,
        "only {} shader node types: {kinds:?}",
        kinds.len()
    );
    assert!(
        trees.iter().flat_map(|(_, t)| &t.nodes).any(|n| n.mute),
        "no muted node"
    );
    assert!(
        trees
            .iter()
            .flat_map(|(_, t)| &t.nodes)
            .any(|n| n.bl_idname == "NodeReroute"),
        "no reroute"
    );
    // A group that itself contains a group node.
    let nested = s
        .file
        .node_groups
        .iter()
        .any(|g| g.nodes.iter().any(|n| n.node_tree.is_some()));
    assert!(nested, "no nested node group");
}

#[test]
fn animated_camera_fixture_has_keys_and_a_parented_light() {
    let s = Scene::load(&repo().join("fixtures/scenes/animated_camera")).unwrap();
    let light = s
        .file
        .objects
        .iter()
        .find(|o| o.kind == "LIGHT")
        .expect("a light");
    let parent = s
        .object(light.parent.as_deref().expect("light is parented"))
        .unwrap();
    assert_eq!(parent.kind, "CAMERA");
    let anim = s
        .file
        .animation
        .iter()
        .find(|a| a.id_path.contains(&parent.name))
        .expect("camera animation");
    let interps: std::collections::BTreeSet<&str> = anim
        .fcurves
        .iter()
        .flat_map(|f| &f.keyframes)
        .map(|k| k.interpolation.as_str())
        .collect();
    for i in ["BEZIER", "LINEAR", "CONSTANT"] {
        assert!(interps.contains(i), "no {i} keyframe: {interps:?}");
    }
}

#[test]
fn geonodes_fixture_has_modifier_inputs() {
    let s = Scene::load(&repo().join("fixtures/scenes/geonodes")).unwrap();
    let m = s
        .file
        .objects
        .iter()
        .flat_map(|o| &o.modifiers)
        .find(|m| m.kind == "NODES")
        .expect("a NODES modifier");
    let g = s.node_group(m.node_group.as_deref().unwrap()).unwrap();
    assert!(!m.inputs.is_empty());
    assert!(g
        .interface
        .iter()
        .any(|i| i.item_type == "SOCKET" && i.in_out.as_deref() == Some("INPUT")));
    assert!(!s.file.evaluated.is_empty(), "no evaluated reference mesh");
}

#[test]
fn packed_image_is_exported_and_referenced() {
    let dir = repo().join("fixtures/scenes/material_zoo");
    let s = Scene::load(&dir).unwrap();
    let img = s
        .file
        .images
        .iter()
        .find(|i| i.name == "Swatch")
        .expect("the packed image");
    assert!(img.packed && !img.missing);
    assert_eq!(img.size, Some([8, 8]));
    let path = s
        .resolve(
            img.file.as_deref().expect("copied next to the export"),
            "images",
        )
        .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert!(
        bytes.starts_with(b"\x89PNG"),
        "{} is not a PNG",
        path.display()
    );
    let node = s
        .file
        .materials
        .iter()
        .flat_map(|m| m.node_tree.iter())
        .flat_map(|t| &t.nodes)
        .find(|n| n.bl_idname == "ShaderNodeTexImage")
        .unwrap();
    assert_eq!(node.properties["image"]["name"], "Swatch");
    assert_eq!(node.properties["interpolation"], "Closest");
}
