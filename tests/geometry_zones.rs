//! Geometry Nodes zones beyond the parity cases (those are in tests/geometry.rs, scene
//! `zones`): hostile Iterations and fields that grow without bound, errors naming the
//! tree and the zone's node (docs/limits.md). (Geometry a zone doubles stops at the
//! element limit too, but reaching 2^26 elements takes seconds and gigabytes: untested.)

use std::path::PathBuf;

use blendsynth::geometry;
use blendsynth::scene::Scene;

fn load(name: &str) -> Scene {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/geometry/scenes");
    Scene::load(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"))
}

fn evaluate(
    scene: &Scene,
    object: &str,
    overrides: &[(&str, serde_json::Value)],
) -> Result<usize, String> {
    let over: Vec<(String, serde_json::Value)> = overrides
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    geometry::evaluate_object(scene, object, 1.0, &over)
        .and_then(|g| geometry::realize_to_mesh(&g))
        .map(|m| m.vertex_count())
        .map_err(|e| e.to_string())
}

fn iterations(tree: &str, node: &str) -> String {
    format!("node_groups[\"{tree}\"].nodes[\"{node}\"].inputs[\"Iterations\"].default_value")
}

#[test]
fn hostile_iterations_are_an_error_naming_the_zone() {
    let scene = load("zones");
    let e = evaluate(
        &scene,
        "repeat_fields",
        &[(
            &iterations("repeat_fields", "Repeat Input"),
            1_000_000_000.into(),
        )],
    )
    .unwrap_err();
    assert!(
        e.contains("repeat_fields") && e.contains("Repeat Output") && e.contains("1000000000"),
        "{e}"
    );
    // Just under the limit per zone, but nested: the budget is for all zones together.
    let e = evaluate(
        &scene,
        "repeat_nested",
        &[
            (&iterations("repeat_nested", "Repeat Input"), 1000.into()),
            (
                &iterations("repeat_nested", "Repeat Input.001"),
                1_048_000.into(),
            ),
        ],
    )
    .unwrap_err();
    assert!(
        e.contains("Repeat Output.001") && e.contains("limit"),
        "{e}"
    );
    // The same zones at a few iterations evaluate.
    assert_eq!(evaluate(&scene, "repeat_nested", &[]).unwrap(), 64);
}

#[test]
fn a_field_growing_with_the_iterations_stops_at_the_depth_limit() {
    // Acc = Acc * 0.5 + Iteration + Index * 0.1 wraps the field item in more operations
    // every iteration: evaluating it would recurse thousands deep.
    let scene = load("zones");
    let e = evaluate(
        &scene,
        "repeat_fields",
        &[(&iterations("repeat_fields", "Repeat Input"), 5000.into())],
    )
    .unwrap_err();
    assert!(
        e.contains("Repeat Output") && e.contains("\"Item_1\"") && e.contains("deep"),
        "{e}"
    );
    // Zero and negative counts pass the items through (the parity cases compare them).
    for n in [0, -1, -1_000_000_000] {
        evaluate(
            &scene,
            "repeat_fields",
            &[(&iterations("repeat_fields", "Repeat Input"), n.into())],
        )
        .unwrap();
    }
}

#[test]
fn an_older_export_evaluates_a_simulation_zone_at_its_start_frame_only() {
    // The `zones` scene was exported before `bake_states`: whether its zone is baked is
    // unknown, so only its start frame (1, a parity case: the body runs once with Delta
    // Time 0) evaluates; other frames ask for a new conversion, naming the zone.
    // (Playback past the start: tests/geometry.rs, scene `simulation`.)
    let scene = load("zones");
    let mesh = |frame: f64| {
        geometry::evaluate_object(&scene, "simulation_start", frame, &[])
            .and_then(|g| geometry::realize_to_mesh(&g))
            .map(|m| m.vertex_count())
            .map_err(|e| e.to_string())
    };
    assert_eq!(mesh(1.0).unwrap(), 8);
    for frame in [2.0, 0.0, 1.5] {
        let e = mesh(frame).unwrap_err();
        assert!(
            e.contains("simulation_start")
                && e.contains("Simulation Output")
                && e.contains("convert the .blend again"),
            "{e}"
        );
    }
}

#[test]
fn objects_of_an_older_export_with_a_simulation_zone_are_frozen_after_the_start_frame() {
    // `render`, `mesh` and `inspect` ask `object_source`: at the start frame blendsynth
    // evaluates the zone; at any other frame the object is Blender's evaluated mesh,
    // which the export has only for its own frame (the zone depends on the frame), so
    // another frame is an error naming the object and the zone.
    let scene = load("zones");
    let o = scene.object("simulation_start").unwrap();
    let at = |frame: f64| geometry::source::object_source(&scene, o, frame, &[]);
    assert!(!matches!(at(1.0), Ok(geometry::source::Source::Frozen(_))));
    let e = match at(2.0) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("frame 2 of a simulation evaluated"),
    };
    assert!(
        e.contains("simulation_start") && e.contains("Simulation Output") && e.contains("frame 2"),
        "{e}"
    );
}

#[test]
fn a_for_each_zone_over_too_many_elements_is_an_error_naming_it() {
    // 3000 x 1000 grid points, every other one selected: 1.5 million runs.
    let scene = load("zones");
    let grid = |input: &str| {
        format!("node_groups[\"foreach_points\"].nodes[\"Grid\"].inputs[\"{input}\"].default_value")
    };
    let e = evaluate(
        &scene,
        "foreach_points",
        &[
            (&grid("Vertices X"), 3000.into()),
            (&grid("Vertices Y"), 1000.into()),
        ],
    )
    .unwrap_err();
    assert!(
        e.contains("foreach_points")
            && e.contains("For Each Geometry Element Output")
            && e.contains("1500000 elements"),
        "{e}"
    );
}
