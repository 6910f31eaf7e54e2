//! Preprocess + parse must never panic, whatever the input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rtlint::front::hlsl::{parse_source, pp::MemLoader, HlslOptions};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let mut loader = MemLoader::default();
    let _ = parse_source(Path::new("main.hlsl"), text, &mut loader, &HlslOptions::default());
});
