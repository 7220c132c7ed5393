//! The scene.json loader (parse and cross-reference validation) on arbitrary bytes.
//! The folder does not exist, so nothing named by the scene is read.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ =
        blendsynth::scene::Scene::from_json(std::path::Path::new("/nonexistent-fuzz-scene"), data);
});
