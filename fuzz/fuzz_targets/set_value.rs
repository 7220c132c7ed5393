//! `--set PATH=VALUE` on a committed fixture scene: parse the override, apply it and
//! validate the result, as `render --set` does before rendering.
#![no_main]
use std::sync::OnceLock;

use blendsynth::scene::{Override, Scene};
use libfuzzer_sys::fuzz_target;

static SCENE: OnceLock<Scene> = OnceLock::new();

fuzz_target!(|data: &[u8]| {
    let scene = SCENE.get_or_init(|| {
        let json = include_bytes!("../../fixtures/scenes/geonodes/scene.json");
        Scene::from_json(std::path::Path::new("/nonexistent-fuzz-scene"), json)
            .expect("the committed fixture loads")
    });
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(o) = Override::parse(text) {
        let _ = scene.with_overrides(&[o]);
    }
});
