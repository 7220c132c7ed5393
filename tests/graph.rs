//! Node-tree flattening on the material zoo fixture: groups inlined (nested), reroutes
//! followed, the muted node passed through, unreachable nodes dropped.

mod common;
use common::*;

use blendsynth::nodes::graph::{active_output, flatten, Source};
use blendsynth::scene::Scene;

#[test]
fn material_zoo_flattens_as_blender_evaluates_it() {
    let s = Scene::load(&repo().join("fixtures/scenes/material_zoo")).unwrap();
    let tree = s.file.materials[0].node_tree.as_ref().unwrap();
    let out = active_output(tree, "ShaderNodeOutputMaterial", "CYCLES").unwrap();
    let g = flatten(tree, &s.file.node_groups, &out.name).unwrap();
    let kinds: Vec<&str> = g.nodes.iter().map(|n| n.node.bl_idname.as_str()).collect();
    for structural in [
        "NodeReroute",
        "NodeFrame",
        "NodeGroupInput",
        "NodeGroupOutput",
        "ShaderNodeGroup",
    ] {
        assert!(
            !kinds.contains(&structural),
            "{structural} left in the flat graph"
        );
    }
    assert!(
        !g.nodes.iter().any(|n| n.node.mute),
        "a muted node is evaluated"
    );
    // Dependency order: every link points backwards.
    for (i, n) in g.nodes.iter().enumerate() {
        for inp in &n.inputs {
            for src in &inp.sources {
                if let Source::Link { node, .. } = src {
                    assert!(*node < i, "{} reads a later node", n.path);
                }
            }
        }
    }
    assert_eq!(g.nodes[g.root].node.bl_idname, "ShaderNodeOutputMaterial");

    // The nested group's node appears once, under both group names.
    let hsv: Vec<_> = g
        .nodes
        .iter()
        .filter(|n| n.node.bl_idname == "ShaderNodeHueSaturation")
        .collect();
    assert_eq!(hsv.len(), 1);
    assert_eq!(hsv[0].path, "Group > Group > Hue/Saturation/Value");
    // The group's Amount input was never linked: the inner group node's default flows in.
    match &hsv[0].input("Hue").unwrap().sources[0] {
        Source::Default(sock) => assert_eq!(
            sock.default_value.as_ref().unwrap().as_f64().unwrap() as f32,
            0.3
        ),
        other => panic!("{other:?}"),
    }

    // Base Color: Mix -> [Outer group: Inner group -> Gamma] -> Reroute -> muted Invert.
    let principled = g
        .nodes
        .iter()
        .find(|n| n.node.bl_idname == "ShaderNodeBsdfPrincipled")
        .unwrap();
    match &principled.input("Base Color").unwrap().sources[0] {
        Source::Link { node, kind, .. } => {
            assert_eq!(g.nodes[*node].node.bl_idname, "ShaderNodeGamma");
            assert_eq!(g.nodes[*node].path, "Group > Gamma");
            assert_eq!(*kind, "RGBA");
        }
        other => panic!("{other:?}"),
    }
}
