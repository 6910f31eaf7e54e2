//! SPIR-V from a second real HLSL compiler (Slang, with `-g`) gives the same
//! findings on the same HLSL lines as the markers say. Slang is installed by
//! scripts/setup; without it these fail in CI and skip elsewhere
//! (`rtlint_testkit::require`).

mod common;

use rtlint::shader::Language;
use std::collections::BTreeSet;
use std::path::Path;

#[test]
fn slang_compiled_hlsl_lands_on_source_lines() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    let src = common::root().join("fixtures/hlsl/payloads.hlsl");
    let words = slang
        .compile_hlsl(&src, "RayGen", "raygeneration", &["-g".to_string()])
        .unwrap();
    common::spirv_val(&words).unwrap();
    let program =
        rtlint::program::parse(&words, Path::new("payloads.spv"), Language::Spirv).unwrap();
    let found: BTreeSet<(u32, &str)> =
        rtlint::rules::check_program(&program, &rtlint::config::Config::default())
            .iter()
            .map(|d| {
                let p = d.primary.as_ref().expect("positioned");
                assert_eq!(p.location.path.file_name().unwrap(), "payloads.hlsl");
                (p.location.line, d.code.unwrap())
            })
            .collect();
    assert_eq!(
        found,
        BTreeSet::from([(2, "RT001"), (2, "RT002"), (4, "RT003")])
    );
}

#[test]
fn slang_reports_compile_errors() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("rtlint-slang-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.hlsl");
    std::fs::write(
        &f,
        "[shader(\"raygeneration\")]\nvoid RayGen() { undefined_call(); }\n",
    )
    .unwrap();
    let err = slang
        .compile_hlsl(&f, "RayGen", "raygeneration", &[])
        .unwrap_err();
    assert!(err.contains("undefined_call"), "{err}");
}
