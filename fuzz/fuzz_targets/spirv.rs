#![no_main]
//! Any bytes: a Program or an input error; the module rules run on any
//! Program, and so do the pipeline analyses (recursion, stack) and rules
//! over it as a loose pipeline.
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.spv");
    if let Ok(words) = rtlint::program::words_from_bytes(data, path) {
        if let Ok(p) = rtlint::program::parse(&words, path, rtlint::shader::Language::Spirv) {
            let config = rtlint::config::Config::default();
            let _ = rtlint::rules::check_program(&p, &config);
            let _ = rtlint::lint::check_loose(vec![(p, Default::default())], &[], &config);
        }
    }
});
