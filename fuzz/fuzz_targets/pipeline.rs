#![no_main]
//! Any text as a `*.pipeline.toml`: a description or an error with a
//! position (the shaders it names do not exist here).
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = rtlint::pipeline::parse(text, Path::new("fuzz.pipeline.toml"));
});
