//! The preprocessor must never panic or hang, whatever the input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rtlint::front::hlsl::pp::{preprocess, MemLoader};
use std::path::{Path, PathBuf};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    // The input can include itself (cycles) and one other header.
    let mut loader = MemLoader(
        [
            (PathBuf::from("main.hlsl"), text.to_string()),
            (PathBuf::from("inc.hlsli"), "#pragma once\n#define INC 1\n".to_string()),
        ]
        .into_iter()
        .collect(),
    );
    let _ = preprocess(Path::new("main.hlsl"), text, &mut loader, &[], &[("D".into(), "1".into())]);
});
