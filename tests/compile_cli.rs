//! `rtlint compile`: HLSL to SPIR-V from the command line.

mod common;

use common::rtlint;

fn scratch(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-compile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn one_module_per_entry_point_into_a_directory() {
    let d = scratch("dir");
    let o = rtlint()
        .args(["compile", "tests/hlsl/pipeline.hlsl", "-o"])
        .arg(&d)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let validate = rtlint_testkit::tool("spirv-val");
    for entry in ["RayGen", "Miss", "ShadowMiss", "ClosestHit"] {
        let words = common::read_words(&d.join(format!("{entry}.spv")));
        if validate {
            common::spirv_val(&words).unwrap_or_else(|e| panic!("{entry}: {e}"));
        }
        let p = rtlint::program::parse(&words, &d.join("m.spv"), rtlint::shader::Language::Spirv)
            .unwrap();
        assert_eq!(p.entry_points.len(), 1);
        assert_eq!(p.entry_points[0].name, entry);
    }
}

#[test]
fn entry_whole_module_defines_and_ambiguity() {
    let d = scratch("one");
    let src = d.join("m.hlsl");
    std::fs::write(
        &src,
        "#include \"inc.hlsli\"\nRWStructuredBuffer<uint> o : register(u0);\n[numthreads(1,1,1)]\nvoid A() { o[0] = VALUE + INC; }\n[numthreads(1,1,1)]\nvoid B() { o[1] = 2; }\n",
    )
    .unwrap();
    std::fs::create_dir_all(d.join("inc")).unwrap();
    std::fs::write(d.join("inc/inc.hlsli"), "#define INC 1\n").unwrap();
    let run = |args: &[&str]| rtlint().args(args).output().unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    // Two entry points and a file output: ambiguous.
    let o = run(&[
        "compile",
        &s(&src),
        "-I",
        &s(&d.join("inc")),
        "-D",
        "VALUE=7",
        "-o",
        &s(&d.join("x.spv")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("2 entry points (A, B)"));
    // -E picks one; -D and -I reach the preprocessor.
    let o = run(&[
        "compile",
        &s(&src),
        "-I",
        &s(&d.join("inc")),
        "-D",
        "VALUE=7",
        "-E",
        "A",
        "-o",
        &s(&d.join("a.spv")),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let a = common::read_words(&d.join("a.spv"));
    if rtlint_testkit::tool("spirv-val") {
        common::spirv_val(&a).unwrap();
    }
    // VALUE + INC folds or stays as 7 and 1: either way a constant 7 is there.
    let p = rtlint::program::parse(&a, &d.join("a.spv"), rtlint::shader::Language::Spirv).unwrap();
    assert!(p.constants.values().any(
        |c| *c == rtlint::program::Constant::Int(7) || *c == rtlint::program::Constant::Int(8)
    ));
    // Without the include directory: an error naming the include.
    let o = run(&["compile", &s(&src), "-E", "A", "-o", &s(&d.join("a.spv"))]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("inc.hlsli"));
    // --whole: both entry points in one module.
    let o = run(&[
        "compile",
        &s(&src),
        "-I",
        &s(&d.join("inc")),
        "-D",
        "VALUE=7",
        "--whole",
        "-o",
        &s(&d.join("w.spv")),
    ]);
    assert_eq!(o.status.code(), Some(0));
    let w = common::read_words(&d.join("w.spv"));
    let p = rtlint::program::parse(&w, &d.join("w.spv"), rtlint::shader::Language::Spirv).unwrap();
    assert_eq!(p.entry_points.len(), 2);
}

#[test]
fn compile_errors_name_file_and_position() {
    let d = scratch("err");
    let src = d.join("bad.hlsl");
    std::fs::write(&src, "void f() {\n    int x = ;\n}\n").unwrap();
    let o = rtlint()
        .args([
            "compile",
            src.to_str().unwrap(),
            "-o",
            d.join("b.spv").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("bad.hlsl:2:13"), "{err}");
    assert!(!d.join("b.spv").exists());
}

/// `-o newdir/` names a folder that does not exist yet: it is created.
#[test]
fn a_missing_output_folder_is_created() {
    let d = scratch("newdir").join("new/sub");
    let o = rtlint()
        .args(["compile", "tests/hlsl/pipeline.hlsl", "-o"])
        .arg(format!("{}/", d.display()))
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    for entry in ["RayGen", "Miss", "ShadowMiss", "ClosestHit"] {
        assert!(d.join(format!("{entry}.spv")).is_file(), "{entry}");
    }
}
