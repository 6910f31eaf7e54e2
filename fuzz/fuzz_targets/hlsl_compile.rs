//! The whole compiler must never panic: bad input is an error with a span.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rtlint::front::hlsl::{compile_source_whole, pp::MemLoader, HlslOptions};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let mut loader = MemLoader::default();
    let _ = compile_source_whole(Path::new("main.hlsl"), text, &mut loader, &HlslOptions::default());
});
