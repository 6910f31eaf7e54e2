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

/// (set, binding) of a variable named `name` in a module.
fn binding_of(words: &[u32], name: &str) -> (Option<u32>, Option<u32>) {
    let p = rtlint::program::parse(
        words,
        std::path::Path::new("m.spv"),
        rtlint::shader::Language::Spirv,
    )
    .unwrap();
    let g = p
        .globals
        .iter()
        .find(|g| g.name.as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no global {name}"));
    (g.set, g.binding)
}

/// A DXC command line, pasted as a project's build writes it: no-op flags,
/// `-Fo`, the target environment and the register shifts. The shifts land
/// where DXC's documentation puts them.
#[test]
fn a_dxc_command_line_is_accepted_unchanged() {
    let d = scratch("dxc");
    let out = d.join("rt.spv");
    let o = rtlint()
        .args([
            "compile",
            "-spirv",
            "-T",
            "lib_6_3",
            "-HV",
            "2021",
            "-fspv-target-env=vulkan1.2",
            "-fvk-t-shift",
            "1000",
            "all",
            "-fvk-u-shift",
            "2000",
            "all",
            "-fvk-b-shift",
            "3000",
            "0",
            "-O3",
            "-Zi",
            "-Qembed_debug",
            "-fcgl",
            "-Vd",
            "-fspv-debug=vulkan-with-source",
            "-fvk-use-dx-position-w",
            "-Fo",
        ])
        .arg(&out)
        .args(["fixtures/RT041/good_d3d12_only.hlsl", "--whole", "-v"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("note: -O3: accepted, changes nothing here"),
        "{err}"
    );
    let words = common::read_words(&out);
    assert_eq!(binding_of(&words, "scene"), (Some(0), Some(1000)));
    assert_eq!(binding_of(&words, "colors"), (Some(0), Some(1001)));
    assert_eq!(binding_of(&words, "output"), (Some(0), Some(2000)));
    assert_eq!(binding_of(&words, "Camera"), (Some(0), Some(3001)));

    // A bad value is an error naming the option, exit code 2.
    let o = rtlint()
        .args(["compile", "-fvk-t-shift", "ten", "all", "x.hlsl", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("-fvk-t-shift: expected a number"));
}

/// RT041 reads Vulkan intent from the DXC options: `-spirv` alone checks the
/// D3D12-style registers (t0 and u0 collide), shifts that separate the
/// classes leave nothing to report, and `[hlsl] args` says the same.
#[test]
fn rt041_judges_collisions_after_the_shifts() {
    let check = |args: &[&str]| {
        let o = rtlint()
            .arg("check")
            .args(args)
            .args([
                "--select",
                "RT041",
                "--no-config",
                "fixtures/RT041/good_d3d12_only.hlsl",
            ])
            .output()
            .unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    assert!(
        !check(&[]).contains("warning[RT041]"),
        "D3D12-only HLSL without options"
    );
    let spirv = check(&["-spirv"]);
    assert!(spirv.contains("warning[RT041]"), "{spirv}");
    let shifted = check(&[
        "-spirv",
        "-fvk-t-shift",
        "100",
        "0",
        "-fvk-u-shift",
        "200",
        "0",
    ]);
    assert!(!shifted.contains("warning[RT041]"), "{shifted}");
    // Shifting only one class keeps one collision: t1 (colors) and b1 (Camera).
    let partly = check(&["-fvk-u-shift", "200", "0"]);
    assert!(
        partly.contains("warning[RT041]") && partly.contains("Camera"),
        "{partly}"
    );

    let d = scratch("config-args");
    std::fs::copy("fixtures/RT041/good_d3d12_only.hlsl", d.join("a.hlsl")).unwrap();
    std::fs::write(
        d.join("rtlint.toml"),
        "[hlsl]\nargs = [\"-spirv\", \"-fvk-u-shift\", \"200\", \"all\"]\n",
    )
    .unwrap();
    let o = rtlint()
        .args(["check", "--select", "RT041"])
        .arg(d.join("a.hlsl"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("warning[RT041]") && out.contains("Camera"),
        "{out}"
    );
    std::fs::write(
        d.join("rtlint.toml"),
        "[hlsl]\nargs = [\"-fvk-u-shift\", \"x\", \"all\"]\n",
    )
    .unwrap();
    let o = rtlint()
        .args(["check"])
        .arg(d.join("a.hlsl"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let out = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(
        out.contains("[hlsl] args: -fvk-u-shift: expected a number"),
        "{out}"
    );
}

/// Windows-1252 bytes in the main file and in a header, as `rtlint check`
/// and `rtlint compile` read them: accepted, and an error after them is at
/// its line and column with its line of source shown.
#[test]
fn windows_1252_sources_through_the_command_line() {
    let d = scratch("cp1252");
    std::fs::write(
        d.join("h.hlsli"),
        b"// the light\x92s colour\r\nfloat Shade() { return 0.5; }\r\n",
    )
    .unwrap();
    std::fs::write(
        d.join("main.hlsl"),
        b"// caf\xe9 \x96 \x93main\x94\r\n#include \"h.hlsli\"\r\nRWStructuredBuffer<float> o : register(u0);\r\n[numthreads(1, 1, 1)] void main() { o[0] = Shade(); }\r\n",
    )
    .unwrap();
    let o = rtlint()
        .arg("check")
        .arg(d.join("main.hlsl"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{out}");
    let o = rtlint()
        .args(["compile", "-T", "cs_6_0"])
        .arg(d.join("main.hlsl"))
        .arg("-o")
        .arg(d.join("m.spv"))
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );

    std::fs::write(
        d.join("bad.hlsl"),
        b"/* \x92\x92 */ float Shade() { return nope; }\r\n[numthreads(1, 1, 1)] void main() { Shade(); }\r\n",
    )
    .unwrap();
    let o = rtlint()
        .arg("check")
        .arg(d.join("bad.hlsl"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{out}");
    assert!(out.contains("bad.hlsl:1:33"), "{out}");
    assert!(out.contains("return nope;"), "the line is shown: {out}");
}

/// `-T lib_6_x` without `-E` is the whole library in one module, as DXC
/// writes it; without `-o`/`-Fo` the file is compiled and nothing written.
#[test]
fn a_library_profile_without_an_entry_is_the_whole_library() {
    let d = scratch("lib");
    let out = d.join("lib.spv");
    let o = rtlint()
        .args([
            "compile",
            "-T",
            "lib_6_3",
            "tests/hlsl/pipeline.hlsl",
            "-Fo",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let p = rtlint::program::parse(
        &common::read_words(&out),
        &out,
        rtlint::shader::Language::Spirv,
    )
    .unwrap();
    assert_eq!(p.entry_points.len(), 4);
    let o = rtlint()
        .args(["compile", "-T", "lib_6_x", "tests/hlsl/pipeline.hlsl"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(
        err.contains("4 entry points compiled (no -o: nothing written)"),
        "{err}"
    );
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
