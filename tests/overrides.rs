//! `PATH=VALUE` overrides by Blender data path, on the committed fixture exports.

mod common;
use common::*;

use blendsynth::scene::{Override, Scene};
use serde_json::json;

fn zoo() -> Scene {
    Scene::load(&repo().join("fixtures/scenes/material_zoo")).unwrap()
}
fn geonodes() -> Scene {
    Scene::load(&repo().join("fixtures/scenes/geonodes")).unwrap()
}
fn ov(s: &str) -> Override {
    Override::parse(s).unwrap()
}
fn node<'a>(s: &'a Scene, name: &str) -> &'a blendsynth::scene::Node {
    s.file.materials[0]
        .node_tree
        .as_ref()
        .unwrap()
        .nodes
        .iter()
        .find(|n| n.name == name)
        .unwrap()
}

#[test]
fn parse_forms() {
    assert_eq!(
        ov("bpy.data.lights[\"Key\"].energy=90"),
        Override {
            path: "lights[\"Key\"].energy".into(),
            value: json!(90)
        }
    );
    assert_eq!(ov("a[\"x=y\"].b = MULTIPLY").value, json!("MULTIPLY"));
    assert_eq!(ov("a[\"x=y\"].b=[1, 0.5]").path, "a[\"x=y\"].b");
    assert!(Override::parse("no_equals_sign").is_err());
    assert!(Override::parse("a.b=").is_err());
}

#[test]
fn node_sockets_by_name_index_and_identifier() {
    let s = zoo();
    let before = node(&s, "Noise Texture")
        .inputs
        .iter()
        .find(|i| i.name == "Scale")
        .unwrap()
        .default_value
        .clone();
    assert_ne!(before, Some(json!(7.0)));
    let t = s
        .with_overrides(&[
            ov("materials[\"Zoo\"].node_tree.nodes[\"Noise Texture\"].inputs[\"Scale\"].default_value=7"),
            ov("bpy.data.materials[\"Zoo\"].node_tree.nodes[\"Emission\"].inputs[1].default_value=2.5"),
            ov("materials[\"Zoo\"].node_tree.nodes[\"Mix\"].inputs[\"Factor_Float\"].default_value=0.25"),
            ov("materials[\"Zoo\"].node_tree.nodes[\"Mapping\"].inputs[\"Scale\"].default_value[2]=9"),
        ])
        .unwrap();
    let get = |n: &str, i: &str| {
        node(&t, n)
            .inputs
            .iter()
            .find(|s| s.name == i || s.identifier == i)
            .unwrap()
            .default_value
            .clone()
            .unwrap()
    };
    assert_eq!(get("Noise Texture", "Scale"), json!(7.0));
    assert_eq!(
        node(&t, "Emission").inputs[1].default_value,
        Some(json!(2.5))
    );
    assert_eq!(get("Mix", "Factor_Float"), json!(0.25));
    assert_eq!(get("Mapping", "Scale"), json!([3.0, 3.0, 9.0]));
    // The original is untouched.
    assert_eq!(
        node(&s, "Noise Texture")
            .inputs
            .iter()
            .find(|i| i.name == "Scale")
            .unwrap()
            .default_value,
        before
    );
}

#[test]
fn node_properties_and_color_ramp_elements() {
    let t = zoo()
        .with_overrides(&[
            ov("materials[\"Zoo\"].node_tree.nodes[\"Math\"].operation=ADD"),
            ov("materials[\"Zoo\"].node_tree.nodes[\"Color Ramp\"].color_ramp.elements[1].color=[0, 1, 0, 1]"),
            ov("materials[\"Zoo\"].node_tree.nodes[\"Color Ramp\"].color_ramp.elements[1].position=0.3"),
        ])
        .unwrap();
    assert_eq!(node(&t, "Math").properties["operation"], json!("ADD"));
    let ramp = &node(&t, "Color Ramp").properties["color_ramp"]["elements"][1];
    assert_eq!(ramp["color"], json!([0.0, 1.0, 0.0, 1.0]));
    assert_eq!(ramp["position"], json!(0.3));
}

#[test]
fn objects_modifiers_cameras_lights_scene() {
    let t = geonodes()
        .with_overrides(&[
            ov("objects[\"Terrain\"].modifiers[\"Terrain\"][\"Socket_1\"]=1234"),
            ov("objects[\"Terrain\"].modifiers[\"Terrain\"][\"Socket_2\"]=0.5"),
            ov("objects[\"Camera\"].location[2]=4.5"),
            ov("objects[\"Camera\"].rotation_euler=[0.1, 0.2, 0.3]"),
            ov("cameras[\"Camera\"].dof.aperture_fstop=2"),
            ov("cameras[\"Camera\"].lens=35"),
            ov("lights[\"Key\"].energy=90"),
            ov("lights[\"Key\"].color=[1, 0.5, 0.25]"),
            ov("scenes[\"Scene\"].render.resolution_x=64"),
            ov("scenes[\"Scene\"].cycles.samples=8"),
            ov("scenes[\"Scene\"].frame_current=12"),
        ])
        .unwrap();
    let m = &t.object("Terrain").unwrap().modifiers[0];
    assert_eq!(m.inputs["Socket_1"], json!(1234));
    assert_eq!(m.inputs["Socket_2"], json!(0.5));
    let cam = t.object("Camera").unwrap();
    assert_eq!(cam.location[2], 4.5);
    assert_eq!(cam.rotation_euler, [0.1, 0.2, 0.3]);
    assert_eq!(
        t.file.cameras[0].properties["dof"]["aperture_fstop"],
        json!(2.0)
    );
    assert_eq!(t.file.cameras[0].properties["lens"], json!(35.0));
    assert_eq!(t.file.lights[0].properties["energy"], json!(90.0));
    assert_eq!(t.file.scene.render["resolution_x"], json!(64));
    assert_eq!(t.file.scene.cycles["samples"], json!(8));
    assert_eq!(t.file.scene.frame_current, 12);
}

#[test]
fn bad_overrides_name_the_path() {
    let s = geonodes();
    let cases = [
        ("objects[\"Nope\"].location[0]=1", "nothing named \"Nope\""),
        (
            "objects[\"Camera\"].no_such_thing=1",
            "no property \"no_such_thing\"",
        ),
        ("objects[\"Camera\"].location[7]=1", "out of range"),
        ("objects[\"Camera\"].location=[1, 2]", "expects 3 values"),
        (
            "objects[\"Terrain\"].modifiers[\"Terrain\"][\"Socket_1\"]=1.5",
            "expects an integer",
        ),
        ("lights[\"Key\"].energy=bright", "expects a number"),
        ("scenes[\"Other\"].frame_current=3", "no scene named"),
        ("textures[\"T\"].x=1", "not a bpy.data collection"),
        ("objects[\"Camera\"].location[0=1", "data path"),
    ];
    for (o, why) in cases {
        let e = s.with_overrides(&[ov(o)]).unwrap_err().to_string();
        let path = o.split('=').next().unwrap();
        assert!(e.contains(why), "{o}: {e}");
        assert!(
            e.contains(path) || e.contains("data path"),
            "{o}: error must name the path: {e}"
        );
    }
}
