//! The exporter glb reader on arbitrary bytes: an error or a validated mesh, never a
//! panic or an allocation sized by an unchecked number.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = blendsynth::scene::mesh::parse_glb(data, std::path::Path::new("fuzz.glb"));
});
