#![no_main]
//! Any text: compiled and analysed, or an input error; and the SPIR-V
//! written through statement numbers is naga's own.
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(src) = std::str::from_utf8(data) {
        let path = Path::new("fuzz.wgsl");
        if let Err(e) = rtlint::front::wgsl::check_positions_against_naga(src, path) {
            panic!("{e}");
        }
        if let Ok(words) = rtlint::front::wgsl::compile(src, path) {
            if let Ok(p) = rtlint::program::parse(&words, path, rtlint::shader::Language::Wgsl) {
                let _ = rtlint::rules::check_program(&p, &rtlint::config::Config::default());
            }
        }
    }
});
