#![no_main]
//! Any bytes: wherever rtlint's own SPIR-V decoder gives instructions,
//! rspirv's parser gives the same ones (the decoder is a fast path, never a
//! second opinion).
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(words) = rtlint::program::words_from_bytes(data, std::path::Path::new("fuzz.spv")) {
        if let Err(e) = rtlint::program::decode::check_against_rspirv(&words) {
            panic!("{e}");
        }
    }
});
