#![no_main]
//! Any bytes: a Program or an input error, and the rules run on any Program.
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.spv");
    if let Ok(words) = rtlint::program::words_from_bytes(data, path) {
        if let Ok(p) = rtlint::program::parse(&words, path, rtlint::shader::Language::Spirv) {
            let _ = rtlint::rules::check_program(&p, &rtlint::config::Config::default());
        }
    }
});
