//! Bad HLSL: every error names the file, line and column of the construct, and
//! out-of-scope constructs say "not supported: ...". Nothing panics.

mod common;

use rtlint::front::hlsl::{self, pp::MemLoader, HlslOptions};
use rtlint::report::{human, Sources};
use std::path::{Path, PathBuf};

/// Compiles `main.hlsl` (plus extra in-memory files); returns "line:col: message".
fn error_of(files: &[(&str, &str)]) -> String {
    let mut loader = MemLoader(
        files
            .iter()
            .map(|(p, t)| (PathBuf::from(p), t.to_string()))
            .collect(),
    );
    let (path, text) = files[0];
    let e = hlsl::compile_source(Path::new(path), text, &mut loader, &HlslOptions::default())
        .err()
        .unwrap_or_else(|| panic!("expected an error for:\n{text}"));
    let d = e.diagnostic();
    let l = &d.primary.as_ref().expect("error has a position").location;
    let mut s = format!(
        "{}:{}:{}: {}",
        l.path.display(),
        l.line,
        l.column,
        d.message
    );
    for n in &d.notes {
        s.push_str(&format!("\n  note: {n}"));
    }
    s
}

fn err(src: &str) -> String {
    error_of(&[("main.hlsl", src)])
}

const RG: &str = "[shader(\"raygeneration\")]\nvoid rg()\n{\n";

#[test]
fn unknown_names_and_types() {
    assert_eq!(
        err(&format!("{RG}    x = 1;\n}}")),
        "main.hlsl:4:5: unknown name `x`"
    );
    assert_eq!(
        err(&format!("{RG}    Foo f;\n}}")),
        "main.hlsl:4:5: unknown type `Foo`"
    );
    assert_eq!(
        err(&format!("{RG}    frobnicate(1);\n}}")),
        "main.hlsl:4:5: unknown function `frobnicate`"
    );
}

#[test]
fn type_errors() {
    assert_eq!(
        err(&format!("{RG}    float3 v = float2(1, 2);\n}}")),
        "main.hlsl:4:16: cannot convert `float2` to `float3`"
    );
    assert_eq!(
        err(&format!("{RG}    float4 v = float4(1, 2, 3);\n}}")),
        "main.hlsl:4:16: `float4` needs 4 components, 3 given"
    );
    assert_eq!(
        err(&format!("{RG}    float2 v = 0;\n    v.z = 1;\n}}")),
        "main.hlsl:5:7: swizzle `z` reaches past a float2"
    );
    assert_eq!(
        err(&format!("{RG}    float a[2];\n    a[2] = 1;\n}}")),
        "main.hlsl:5:7: index 2 is out of bounds for an array of 2"
    );
    assert_eq!(
        err("cbuffer C { float k; };\n[numthreads(1,1,1)]\nvoid m()\n{\n    k = 1;\n}"),
        "main.hlsl:5:5: cannot assign to a read-only value (constant buffer or input)"
    );
}

#[test]
fn stage_rules() {
    let src = "RaytracingAccelerationStructure s;\nstruct P { float x; };\n[shader(\"anyhit\")]\nvoid ah(inout P p, in BuiltInTriangleIntersectionAttributes a)\n{\n    RayDesc r = (RayDesc)0;\n    TraceRay(s, 0, 0xff, 0, 1, 0, r, p);\n}";
    assert_eq!(
        err(src),
        "main.hlsl:7:5: `TraceRay` is not available in anyhit shaders"
    );
    let src = "struct P { float x; };\n[shader(\"closesthit\")]\nvoid ch(inout P p, in BuiltInTriangleIntersectionAttributes a)\n{\n    IgnoreHit();\n}";
    assert_eq!(
        err(src),
        "main.hlsl:5:5: `IgnoreHit` is not available in closesthit shaders"
    );
    assert_eq!(
        err("[numthreads(1,1,1)]\nvoid m()\n{\n    uint3 i = DispatchRaysIndex();\n}"),
        "main.hlsl:4:15: `DispatchRaysIndex` is not available in compute shaders"
    );
    assert_eq!(
        err("[shader(\"miss\")]\nvoid m(float x)\n{\n}"),
        "main.hlsl:2:14: not supported: this parameter in a miss entry point\n  note: ray-tracing entry points take `inout` payload / callable data and `in` hit attributes (structs)"
    );
}

#[test]
fn unsupported_constructs_are_named() {
    assert_eq!(
        err("template<typename T> T id(T x) { return x; }\n[numthreads(1,1,1)]\nvoid m() { uint x = id<1, 2>(3); }"),
        "main.hlsl:3:21: `id` takes 1 template argument(s), 2 given"
    );
    assert_eq!(
        err("float g = 2;\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:11: not supported: initializers of constant-buffer members (declare the global `static const`)"
    );
    assert_eq!(
        err("Texture2D t;\nSamplerState s;\n[shader(\"raygeneration\")]\nvoid rg()\n{\n    float4 c = t.Sample(s, float2(0, 0));\n}"),
        "main.hlsl:6:18: not supported: `Sample` (implicit level of detail) outside pixel shaders; use `SampleLevel`"
    );
    assert_eq!(
        err(&format!(
            "{RG}    float w = WaveMultiPrefixSum(1.0, 1);\n}}"
        )),
        "main.hlsl:4:15: not supported: wave intrinsic `WaveMultiPrefixSum`"
    );
    assert_eq!(
        err(&format!("{RG}    double d = 1;\n}}")),
        "main.hlsl:4:5: not supported: type `double` (only 32-bit floats, 32- and 64-bit integers)"
    );
}

#[test]
fn control_flow_errors() {
    assert_eq!(
        err(&format!("{RG}    break;\n}}")),
        "main.hlsl:4:5: `break` outside a loop or switch"
    );
    assert_eq!(
        err(&format!(
            "{RG}    switch (1) {{ case 1: break; case 1: break; }}\n}}"
        )),
        "main.hlsl:4:38: duplicate case 1"
    );
    assert_eq!(
        err("float f(float x) { return f(x); }\n[numthreads(1,1,1)]\nvoid m() { float y = f(1.0); }"),
        "main.hlsl:1:7: function `f` is recursive; HLSL does not allow recursion"
    );
    assert_eq!(
        err("float f() { }\n[shader(\"raygeneration\")]\nfloat rg() { return 1; }"),
        "main.hlsl:3:1: not supported: raygeneration entry points returning a value"
    );
}

#[test]
fn parse_errors_point_at_the_token() {
    assert_eq!(
        err(&format!("{RG}    float x = (1 + ;\n}}")),
        "main.hlsl:4:20: expected an expression, found `;`"
    );
    assert_eq!(
        err("struct S { float a }"),
        "main.hlsl:1:20: expected `;`, found `}`"
    );
}

#[test]
fn preprocessor_errors_show_the_include_chain() {
    let e = error_of(&[
        ("dir/main.hlsl", "#include \"a.hlsli\"\n"),
        ("dir/a.hlsli", "\n#include \"missing.hlsli\"\n"),
    ]);
    assert_eq!(
        e,
        "dir/a.hlsli:2:2: cannot find include file `missing.hlsli`\n  note: `dir/a.hlsli` included from dir/main.hlsl:1\n  note: `dir/main.hlsl` is the file being compiled\n  note: no include directories were given (-I)"
    );
    let e = error_of(&[("m.hlsl", "#include \"m.hlsl\"\n")]);
    assert!(
        e.starts_with("m.hlsl:1:2: include cycle: `m.hlsl` includes itself"),
        "{e}"
    );
    assert_eq!(
        err("#if 1\n#error stop: no\n#endif"),
        "main.hlsl:2:2: #error stop: no"
    );
}

#[test]
fn errors_in_macros_and_includes_point_at_the_real_file() {
    // The macro is used on line 5; its body's bad name reports that use.
    let e = err("#define BAD(x) (x + undefinedThing)\n[shader(\"raygeneration\")]\nvoid rg()\n{\n    float f = BAD(1.0);\n}");
    assert_eq!(e, "main.hlsl:5:15: unknown name `undefinedThing`");
    let e = error_of(&[
        (
            "main.hlsl",
            "#include \"lib.hlsli\"\n[numthreads(1,1,1)]\nvoid m() { float y = helper(1.0); }",
        ),
        (
            "lib.hlsli",
            "float helper(float x)\n{\n    return x + nope;\n}",
        ),
    ]);
    assert_eq!(e, "lib.hlsli:3:16: unknown name `nope`");
}

#[test]
fn missing_entry_point() {
    let mut loader = MemLoader::default();
    let e = hlsl::compile_source(
        Path::new("a.hlsl"),
        "float f(float x) { return x; }",
        &mut loader,
        &HlslOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("no entry points"), "{e}");
    let opts = HlslOptions {
        entry: Some("nope".into()),
        ..Default::default()
    };
    let e = hlsl::compile_source(
        Path::new("a.hlsl"),
        "[numthreads(1,1,1)] void m() {}",
        &mut loader,
        &opts,
    )
    .unwrap_err();
    assert!(e.to_string().contains("no entry point named `nope`"), "{e}");
}

#[test]
fn matrices_in_component_intrinsics_are_refused() {
    assert_eq!(
        err(&format!(
            "{RG}    float3x3 m = 1;\n    float3x3 a = abs(m);\n}}"
        )),
        "main.hlsl:5:18: not supported: matrix arguments to this intrinsic"
    );
}

#[test]
fn templated_methods_are_refused() {
    assert_eq!(
        err("ByteAddressBuffer b;\n[numthreads(1,1,1)]\nvoid m()\n{\n    float4x4 v = b.Load<float4x4>(0);\n}"),
        "main.hlsl:5:20: not supported: `Load<float4x4>` (only 32-bit scalars, vectors, and structs and arrays of them)"
    );
}

#[test]
fn layout_changing_constructs_are_refused() {
    assert_eq!(
        err("#pragma pack_matrix(diagonal)\n"),
        "main.hlsl:1:2: #pragma pack_matrix needs row_major or column_major, not `diagonal`"
    );
    assert_eq!(
        err("row_major StructuredBuffer<float4x4> m;\n[numthreads(1,1,1)] void f() {}"),
        "main.hlsl:1:38: not supported: a StructuredBuffer of row_major matrices (wrap the matrix in a struct)"
    );
}

#[test]
fn entry_parameters_follow_dxr_positions() {
    let e = err("struct P { float x; };\nstruct A { float2 b; };\n[shader(\"closesthit\")]\nvoid ch(in A a, inout P p)\n{\n}");
    assert!(
        e.starts_with("main.hlsl:4:14: not supported: this parameter in a closesthit entry point"),
        "{e}"
    );
    let e = err("struct P { float x; };\n[shader(\"miss\")]\nvoid m(in P p)\n{\n}");
    assert!(
        e.starts_with("main.hlsl:3:13: not supported: this parameter in a miss entry point"),
        "{e}"
    );
}

/// Errors after `#line N "file"` are reported in that file from line N on;
/// a bad `#line` is an error at its argument.
#[test]
fn line_directive_moves_error_positions() {
    assert_eq!(
        err(&format!("#line 100 \"virtual.hlsl\"\n{RG}\n    x = 1;\n}}")),
        "virtual.hlsl:104:5: unknown name `x`"
    );
    // Without a file name only the numbering changes.
    assert_eq!(
        err(&format!("{RG}#line 10\n    float3 v = float2(1, 2);\n}}")),
        "main.hlsl:10:16: cannot convert `float2` to `float3`"
    );
    // In an include; the include chain keeps the real including line.
    let e = error_of(&[
        (
            "main.hlsl",
            "#include \"a.hlsli\"\n[shader(\"raygeneration\")]\nvoid rg() { f(); }\n",
        ),
        ("a.hlsli", "#line 7 \"gen.hlsl\"\nvoid f() { y = 2; }\n"),
    ]);
    assert_eq!(e, "gen.hlsl:7:12: unknown name `y`");
    assert_eq!(
        err("#line 1 2\n"),
        "main.hlsl:1:9: #line takes a file name in double quotes"
    );
    assert_eq!(
        err("#line -3\n"),
        "main.hlsl:1:7: #line needs a line number from 1 to 2147483647"
    );
}

const PS: &str = "[shader(\"pixel\")]\n";

/// Derivatives exist only in pixel shaders: in another stage's entry body,
/// or in a helper that such an entry point reaches, they are errors at the call.
#[test]
fn derivatives_outside_pixel_shaders() {
    assert_eq!(
        err("[numthreads(1, 1, 1)]\nvoid cs()\n{\n    float a = ddx(1.0);\n}"),
        "main.hlsl:4:15: `ddx` is only available in pixel shaders, not compute shaders"
    );
    assert_eq!(
        err("struct P { float4 c; };\n[shader(\"closesthit\")]\nvoid ch(inout P p, BuiltInTriangleIntersectionAttributes a)\n{\n    p.c = fwidth(p.c);\n}"),
        "main.hlsl:5:11: `fwidth` is only available in pixel shaders, not closesthit shaders"
    );
    assert_eq!(
        err("[shader(\"raygeneration\")]\nvoid rg()\n{\n    float a = ddy_coarse(2.0);\n}"),
        "main.hlsl:4:15: `ddy_coarse` is only available in pixel shaders, not raygeneration shaders"
    );
    // Through a helper: the error is at the call in the helper.
    let e = err("float f(float x) { return ddx_fine(x); }\n[numthreads(1, 1, 1)]\nvoid cs()\n{\n    float a = f(1.0);\n}");
    assert_eq!(
        e,
        "main.hlsl:1:27: `ddx_fine` is only available in pixel shaders"
    );
    // Implicit-LOD `Sample` takes derivatives too.
    let e = err("Texture2D t;\nSamplerState s;\nfloat4 f() { return t.Sample(s, float2(0, 0)); }\n[numthreads(1, 1, 1)]\nvoid cs() { float4 c = f(); }");
    assert_eq!(
        e,
        "main.hlsl:3:23: `Sample` is only available in pixel shaders"
    );
    // `discard` likewise, in an entry body and through a helper.
    assert_eq!(
        err(&format!("{RG}    discard;\n}}")),
        "main.hlsl:4:5: `discard` is only available in pixel shaders, not raygeneration shaders"
    );
    let e = err("void f() { discard; }\n[numthreads(1, 1, 1)]\nvoid cs() { f(); }");
    assert_eq!(
        e,
        "main.hlsl:1:12: `discard` is only available in pixel shaders"
    );
    // The same helper is fine from a pixel shader.
    let ok = "float f(float x) { return ddx_fine(x); }\n[shader(\"pixel\")]\nfloat4 ps(float2 uv : UV) : SV_Target { return f(uv.x); }";
    let mut loader = MemLoader::default();
    hlsl::compile_source(
        Path::new("main.hlsl"),
        ok,
        &mut loader,
        &HlslOptions::default(),
    )
    .unwrap();
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(float2 uv : UV) : SV_Target {{ return ddx(uv, uv); }}"
        )),
        "main.hlsl:2:48: `ddx` takes 1 argument(s), 2 given"
    );
}

/// Pixel shader inputs and outputs: semantics are required and checked.
#[test]
fn pixel_shader_interface_errors() {
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(float2 uv) : SV_Target {{ return 0; }}"
        )),
        "main.hlsl:2:18: pixel shader inputs need a semantic"
    );
    assert_eq!(
        err(&format!("{PS}float4 ps(float2 uv : UV) {{ return 0; }}")),
        "main.hlsl:2:1: a pixel shader's return value needs a semantic such as `SV_Target`"
    );
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(float2 uv : UV) : COLOR {{ return 0; }}"
        )),
        "main.hlsl:2:29: pixel shader outputs are render targets (`SV_Target[n]`), not `COLOR`"
    );
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(float2 uv : UV) : SV_Target9 {{ return 0; }}"
        )),
        "main.hlsl:2:29: `SV_Target9` names no render target (SV_Target0 to SV_Target7)"
    );
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(uint s : SV_SampleIndex) : SV_Target {{ return 0; }}"
        )),
        "main.hlsl:2:20: not supported: semantic `SV_SampleIndex` on a pixel shader input"
    );
    assert_eq!(
        err(&format!(
            "{PS}float4 ps(float2 p : SV_Position) : SV_Target {{ return 0; }}"
        )),
        "main.hlsl:2:18: `SV_Position` must be a `float4`"
    );
    assert_eq!(
        err(&format!("{PS}void ps(float a : A, out float4 c : SV_Target, out float4 d : SV_Target0) {{ c = a; d = a; }}")),
        "main.hlsl:2:63: `SV_Target0` takes output location 0, already taken by `SV_Target`"
    );
    assert_eq!(
        err(&format!("{PS}float4 ps([[vk::location(2)]] float a : A, float b : B) : SV_Target {{ return a + b; }}")),
        "main.hlsl:2:54: pixel shader inputs either all have `[[vk::location]]` or none do"
    );
    assert_eq!(
        err(&format!("{PS}float4 ps(float3x3 m : M) : SV_Target {{ return 0; }}")),
        "main.hlsl:2:20: not supported: `float3x3` as a pixel shader input (scalars and vectors only)"
    );
}

#[test]
fn malformed_subobjects() {
    assert_eq!(
        err("RaytracingShaderConfig c = { 16 };\n[numthreads(1,1,1)] void m() {}"),
        "main.hlsl:1:24: a `RaytracingShaderConfig` has 2 field(s) (maximum payload size, maximum attribute size), 1 given"
    );
    assert_eq!(
        err("TriangleHitGroup g = { 1, \"Hit\" };\n[numthreads(1,1,1)] void m() {}"),
        "main.hlsl:1:24: the any-hit shader of a `TriangleHitGroup` must be a string"
    );
}

#[test]
fn resource_helpers_that_cannot_be_inlined_are_refused() {
    assert_eq!(
        err("Texture2D a;\nTexture2D b;\nTexture2D pick(bool x) { if (x) return a; return b; }\n[numthreads(1,1,1)]\nvoid m()\n{\n    uint w, h;\n    pick(true).GetDimensions(w, h);\n}"),
        "main.hlsl:3:11: not supported: a function returning a resource whose body is more than `return <resource>;`"
    );
    assert_eq!(
        err("SamplerState a;\nSamplerState b;\nTexture2D t;\nSamplerState pick(bool x) { return x ? a : b; }\n[numthreads(1,1,1)]\nvoid m()\n{\n    float4 c = t.SampleLevel(pick(true), float2(0, 0), 0);\n}"),
        "main.hlsl:4:38: not supported: choosing a resource with `?:`"
    );
}

/// Every attribute in the table is implemented (and a test shader uses it),
/// a hint (and a test shader uses it), or refused at its position; names not
/// in the table are refused too. No attribute is silently ignored.
#[test]
fn every_attribute_is_implemented_or_refused() {
    use rtlint::front::hlsl::attrs::{Support, ATTRIBUTES};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl");
    let shaders: String = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| std::fs::read_to_string(e.ok()?.path()).ok())
        .collect::<Vec<_>>()
        .join("\n")
        .to_ascii_lowercase();
    for a in ATTRIBUTES {
        match a.support {
            Support::Implemented | Support::Hint => {
                let written = [format!("[{}", a.name), format!("[[{}", a.name)];
                assert!(
                    written.iter().any(|w| shaders.contains(w.as_str())),
                    "no test shader under tests/hlsl uses `{}`",
                    a.name
                );
            }
            Support::Refused(what) => {
                let src = format!("[[{}(1)]]\n[numthreads(1,1,1)]\nvoid m() {{}}", a.name);
                assert_eq!(
                    err(&src),
                    format!("main.hlsl:1:3: not supported: {what}"),
                    "{}",
                    a.name
                );
            }
        }
    }
    assert_eq!(
        err("[[vk::made_up]]\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: attribute `vk::made_up`"
    );
    // Implemented, but not where it is written.
    assert_eq!(
        err("[[vk::binding(0)]]\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: `vk::binding` on a function"
    );
    assert_eq!(
        err("[numthreads(1,1,1)]\nvoid m()\n{\n    [[vk::image_format(\"rgba8\")]] uint x = 0;\n}"),
        "main.hlsl:4:7: not supported: `vk::image_format` on a statement"
    );
    assert_eq!(
        err("[[vk::image_format(\"rgba8\")]] Texture2D t;\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: `vk::image_format` on anything but an RWTexture"
    );
    // A capability only OpenCL kernels have (ImageBasic, 13, implies Kernel)
    // would make the module invalid for Vulkan: refused at the number.
    assert_eq!(
        err("[[vk::ext_capability(13)]]\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:22: capability `ImageBasic` (13) is for OpenCL kernels (it implies `Kernel`), which Vulkan does not allow"
    );
    // An instruction set spirv-val does not know is refused at its name.
    assert_eq!(
        err("[[vk::ext_instruction(1, \"MySet.1\")]]\nvoid f();\n[numthreads(1,1,1)]\nvoid m() { f(); }"),
        "main.hlsl:1:26: not supported: extended instruction set \"MySet.1\""
    );
    // Inline-SPIR-V decorations on members, variables and parameters; a
    // declaration that becomes no variable of its own refuses them.
    assert_eq!(
        err("[[vk::ext_decorate(0)]] static const uint K = 3;\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: `vk::ext_decorate` on a constant"
    );
    assert_eq!(
        err("[[vk::ext_decorate(0)]] float g;\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: `vk::ext_decorate` on a member of `$Globals`"
    );
    assert_eq!(
        err("[[vk::ext_decorate(0)]] cbuffer C { float c; };\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:3: not supported: `vk::ext_decorate` on a `cbuffer`"
    );
    assert_eq!(
        err("[numthreads(1,1,1)]\nvoid m([[vk::ext_decorate(0)]] uint3 id : SV_DispatchThreadID) {}"),
        "main.hlsl:2:10: not supported: `vk::ext_decorate` on an entry point's parameter"
    );
    assert_eq!(
        err("[numthreads(1,1,1)]\nvoid m()\n{\n    [[vk::ext_decorate(0)]] uint x = 0;\n}"),
        "main.hlsl:4:7: not supported: `vk::ext_decorate` on a statement"
    );
    assert_eq!(
        err("struct S { [[vk::ext_decorate(9999)]] float x; };\n[numthreads(1,1,1)]\nvoid m() { S s; s.x = 1; }"),
        "main.hlsl:1:31: unknown SPIR-V decoration 9999"
    );
    // Early fragment tests exist for pixel shaders only.
    assert_eq!(
        err("[earlydepthstencil]\n[numthreads(1,1,1)]\nvoid m() {}"),
        "main.hlsl:1:2: `[earlydepthstencil]` applies to pixel shaders only"
    );
}

#[test]
fn inline_spirv_instructions_and_outputs_refuse_what_they_cannot_do() {
    const CS: &str = "[numthreads(1,1,1)]\nvoid m()\n{\n";
    assert_eq!(
        err(&format!("[[vk::ext_instruction(81)]] float e(float4 v, [[vk::ext_literal]] int i);\n{CS}    int k = 1;\n    float f = e(1, k);\n}}")),
        "main.hlsl:6:20: a `vk::ext_literal` argument must be a constant"
    );
    assert_eq!(
        err(&format!("[[vk::ext_instruction(61)]] float l([[vk::ext_reference]] float x);\n{CS}    float f = l(1.0);\n}}")),
        "main.hlsl:5:17: not supported: a `vk::ext_reference` argument other than a variable of type `float`"
    );
    assert_eq!(
        err(&format!(
            "[[vk::ext_instruction(65000)]] float u(float x);\n{CS}    float f = u(1.0);\n}}"
        )),
        "main.hlsl:1:23: not supported: SPIR-V opcode 65000 (unknown to rtlint)"
    );
    assert_eq!(
        err(&format!("[[vk::ext_instruction(13, \"GLSL.std.450\")]] float s(float x) {{ return x; }}\n{CS}}}")),
        "main.hlsl:1:3: a `vk::ext_instruction` function is a declaration without a body"
    );
    assert_eq!(
        err(&format!("[[vk::ext_instruction(13, \"GLSL.std.450\")]] float s(out float x);\n{CS}    float f;\n    s(f);\n}}")),
        "main.hlsl:1:63: not supported: `out` parameters of a `vk::ext_instruction` function (use `vk::ext_reference`)"
    );
    assert_eq!(
        err(&format!("[[vk::ext_builtin_output(5014)]] static const int s;\n{CS}}}")),
        "main.hlsl:1:51: a `vk::ext_builtin_output` variable must be `static` without an initializer"
    );
}

#[test]
fn device_address_loads_are_scalars_and_vectors() {
    assert_eq!(
        err("struct S { float a; };\n[numthreads(1,1,1)]\nvoid m() { S s = vk::RawBufferLoad<S>(0); }"),
        "main.hlsl:3:18: not supported: `vk::RawBufferLoad<S>` (scalars and vectors only)"
    );
    assert_eq!(
        err("[numthreads(1,1,1)]\nvoid m() { uint u = vk::RawBufferLoad<uint>(0, 3); }"),
        "main.hlsl:2:48: the alignment must be a power of two, not 3"
    );
}

#[test]
fn unsupported_helpers_are_refused_where_called() {
    // Never called: not compiled, not refused.
    let mut loader = MemLoader::default();
    let src = "uint hash64(uint64_t v) { return uint(v); }\n[numthreads(1,1,1)]\nvoid m() {}";
    assert!(hlsl::compile_source(
        Path::new("a.hlsl"),
        src,
        &mut loader,
        &HlslOptions::default()
    )
    .is_ok());
    // Called: refused at the unsupported construct.
    assert_eq!(
        err("uint hash64(double v) { return uint(v); }\n[numthreads(1,1,1)]\nvoid m() { uint h = hash64(1); }"),
        "main.hlsl:1:13: not supported: type `double` (only 32-bit floats, 32- and 64-bit integers)"
    );
}

#[test]
fn bit_fields_are_refused_where_their_struct_is_used() {
    let mut loader = MemLoader::default();
    let src = "struct Packed { uint material : 24; uint sampler : 8; };\n[numthreads(1,1,1)]\nvoid m() {}";
    assert!(hlsl::compile_source(
        Path::new("a.hlsl"),
        src,
        &mut loader,
        &HlslOptions::default()
    )
    .is_ok());
    assert_eq!(
        err("struct Packed { uint material : 24; uint sampler : 8; };\n[numthreads(1,1,1)]\nvoid m() { Packed p; p.material = 1; }"),
        "main.hlsl:1:33: not supported: bit fields"
    );
}

#[test]
fn hit_objects_are_made_in_place() {
    let rg = "RaytracingAccelerationStructure s;\nstruct P { float x; };\n[shader(\"raygeneration\")]\nvoid rg()\n{\n";
    assert_eq!(
        err(&format!("{rg}    dx::HitObject a = dx::HitObject::MakeNop();\n    dx::HitObject b = a;\n}}")),
        "main.hlsl:7:23: not supported: copying a HitObject; make it with HitObject::TraceRay, MakeMiss or MakeNop"
    );
    assert_eq!(
        err(&format!("{rg}    RayDesc r = (RayDesc)0;\n    dx::HitObject m = dx::HitObject::MakeMiss(RAY_FLAG_FORCE_OPAQUE, 0, r);\n}}")),
        "main.hlsl:7:47: not supported: ray flags other than 0 in HitObject::MakeMiss (SPV_NV_shader_invocation_reorder has none)"
    );
    assert_eq!(
        err("struct P { float x; };\n[shader(\"closesthit\")]\nvoid ch(inout P p, in BuiltInTriangleIntersectionAttributes a)\n{\n    dx::MaybeReorderThread(1, 1);\n}"),
        "main.hlsl:5:5: `MaybeReorderThread` is not available in closesthit shaders"
    );
}

#[test]
fn stage_rules_hold_in_helpers_reached_from_an_entry_point() {
    let src = "RaytracingAccelerationStructure s;\nstruct P { float x; };\nvoid trace()\n{\n    RayDesc r = (RayDesc)0;\n    P p;\n    TraceRay(s, 0, 0xff, 0, 1, 0, r, p);\n}\n[numthreads(1,1,1)]\nvoid main()\n{\n    trace();\n}";
    let e = error_of(&[("main.hlsl", src)]);
    assert_eq!(
        e,
        "main.hlsl:7:5: `TraceRay` is not available in compute shaders"
    );
}

/// Errors as a user sees them: rendered by the report layer with their source
/// snippets, labels and notes. One snapshot holds every case, in order.
#[test]
fn rendered_errors_match_the_snapshot() {
    let rg = |body: &str| format!("{RG}{body}\n}}");
    let cases: Vec<Vec<(&str, String)>> = vec![
        vec![("main.hlsl", rg("    x = 1;"))],
        vec![("main.hlsl", rg("    float3 v = float2(1, 2);"))],
        vec![("main.hlsl", rg("    float x = (1 + ;"))],
        vec![("main.hlsl", rg("    switch (1) { case 1: break; case 1: break; }"))],
        vec![(
            "main.hlsl",
            "float f(float x) { return f(x); }\n[numthreads(1,1,1)]\nvoid m() { float y = f(1.0); }"
                .into(),
        )],
        vec![
            ("dir/main.hlsl", "#include \"a.hlsli\"\n".into()),
            ("dir/a.hlsli", "\n#include \"missing.hlsli\"\n".into()),
        ],
        vec![(
            "main.hlsl",
            "#define BAD(x) (x + undefinedThing)\n[shader(\"raygeneration\")]\nvoid rg()\n{\n    float f = BAD(1.0);\n}"
                .into(),
        )],
        vec![
            (
                "main.hlsl",
                "#include \"lib.hlsli\"\n[numthreads(1,1,1)]\nvoid m() { float y = helper(1.0); }"
                    .into(),
            ),
            ("lib.hlsli", "float helper(float x)\n{\n    return x + nope;\n}".into()),
        ],
        vec![("main.hlsl", "#pragma pack_matrix(diagonal)\n".into())],
        vec![("main.hlsl", "float f(float x) { return x; }".into())],
    ];
    let mut all = String::new();
    for files in &cases {
        let mut loader = MemLoader(
            files
                .iter()
                .map(|(p, t)| (PathBuf::from(p), t.clone()))
                .collect(),
        );
        let (path, text) = &files[0];
        let e = hlsl::compile_source(Path::new(path), text, &mut loader, &HlslOptions::default())
            .err()
            .unwrap_or_else(|| panic!("expected an error for:\n{text}"));
        let mut sources = Sources::default();
        for (p, t) in files {
            sources.add_embedded(Path::new(p), t);
        }
        let mut buf = codespan_reporting::term::termcolor::NoColor::new(Vec::new());
        human::render(std::slice::from_ref(e.diagnostic()), &mut sources, &mut buf).unwrap();
        let rendered = String::from_utf8(buf.into_inner()).unwrap();
        // Every positioned error shows its line of source.
        if let Some(l) = &e.diagnostic().primary {
            let file = files
                .iter()
                .find(|(p, _)| Path::new(p) == l.location.path)
                .expect("the error is in one of the files");
            let line = file.1.lines().nth(l.location.line as usize - 1).unwrap();
            assert!(rendered.contains(line), "{rendered}");
        }
        all.push_str(&format!("=== {path}\n{rendered}"));
    }
    common::snapshot("hlsl_errors__rendered", &all);
}

#[test]
fn ray_queries_are_returned_only_as_one_local() {
    assert_eq!(
        err("RaytracingAccelerationStructure s;\nRayQuery<0> trace(RayDesc r, bool b)\n{\n    RayQuery<0> q;\n    RayQuery<0> p;\n    if (b) return p;\n    return q;\n}\n[numthreads(1,1,1)]\nvoid m()\n{\n    RayDesc r = (RayDesc)0;\n    RayQuery<0> q = trace(r, true);\n}"),
        "main.hlsl:2:1: not supported: functions returning a RayQuery other than one local variable"
    );
}

/// `half` is `float` unless 16-bit types are enabled, as in DXC, and
/// `float16_t` needs the flag; with it, the 16-bit constructs not yet
/// lowered are refused at their position, never widened to 32 bits.
#[test]
fn sixteen_bit_types_are_refused_rather_than_widened() {
    let src = "[numthreads(1,1,1)]\nvoid m() { half h = 1; float16_t f = h; }";
    assert_eq!(
        err(src),
        "main.hlsl:2:24: not supported: 16-bit type `float16_t` (DXC needs -enable-16bit-types for it)"
    );
    let with_flag = |text: &str| {
        let opts = HlslOptions {
            enable_16bit_types: true,
            ..Default::default()
        };
        let e = hlsl::compile_source(
            Path::new("main.hlsl"),
            text,
            &mut MemLoader::default(),
            &opts,
        )
        .unwrap_err();
        let d = e.diagnostic();
        let l = &d.primary.as_ref().unwrap().location;
        format!("{}:{}: {}", l.line, l.column, d.message)
    };
    assert_eq!(
        with_flag("RWStructuredBuffer<uint> o;\n[numthreads(1,1,1)]\nvoid m() { min16float h = 1; o[0] = asuint(h); }"),
        "3:37: not supported: `asuint` of 16-bit values"
    );
    // `countbits` of 16-bit integers is lowered; the other bit operations are not.
    assert_eq!(
        with_flag("RWStructuredBuffer<uint> o;\n[numthreads(1,1,1)]\nvoid m() { uint16_t u = 3; o[0] = firstbithigh(u); }"),
        "3:35: not supported: `firstbithigh` of 16-bit values"
    );
    assert_eq!(
        with_flag(
            "[shader(\"pixel\")]\nhalf4 p(int16_t4 c : COLOR) : SV_Target { return ddx(c); }"
        ),
        "2:50: not supported: `ddx` of 16-bit integers"
    );
    // Without the flag, `half` and `min16float` are 32-bit floats.
    let ok = "RWStructuredBuffer<float> o;\n[numthreads(1,1,1)]\nvoid m() { half h = 1.5; min16float g = h; o[0] = g; }";
    assert!(hlsl::compile_source(
        Path::new("main.hlsl"),
        ok,
        &mut MemLoader::default(),
        &HlslOptions::default()
    )
    .is_ok());
}
