//! The dataset spec parser (the library's public `Spec::parse`) on arbitrary text.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = blendsynth::dataset::spec::Spec::parse(text);
    }
});
