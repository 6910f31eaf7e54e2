//! What a new user's project looks like to `rtlint`: includes found beside
//! the shader whatever the path's spelling, one set of compile options for
//! every shader however it was found, headers, stages, WGSL composition,
//! and honest messages.

mod common;

use common::rtlint;
use rtlint_testkit::tool;
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-inputs-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

/// `rtlint ARGS` run in `dir`.
fn run_in(dir: &Path, args: &[&str]) -> Output {
    rtlint().current_dir(dir).args(args).output().unwrap()
}

/// `rtlint ARGS` in `dir` with `stdin` on standard input.
fn run_stdin(dir: &Path, args: &[&str], stdin: &[u8]) -> Output {
    use std::io::Write;
    let mut child = rtlint()
        .current_dir(dir)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(stdin).unwrap();
    child.wait_with_output().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) {
    let p = dir.join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, text).unwrap();
}

const GLSL_HEADER: &str = "struct Payload { vec4 color; };\n";

const GLSL_HIT: &str = "#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include \"common.glsl\"
layout(location = 0) rayPayloadInEXT Payload p;
void main() { p.color = vec4(1.0); }
";

const GLSL_RAYGEN: &str = "#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include \"common.glsl\"
layout(binding = 0) uniform accelerationStructureEXT scene;
layout(location = 0) rayPayloadEXT Payload p;
void main() {
    traceRayEXT(scene, 0, 0xFF, 0, 1, 0, vec3(0.0), 0.0, vec3(0.0, 0.0, 1.0), 100.0, 0);
}
";

const HLSL_HEADER: &str = "struct Payload { float4 color; };\n";

const HLSL_HIT: &str = "#include \"common.hlsli\"
[shader(\"closesthit\")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a) { p.color = 1; }
";

/// Item 1: the shader's own folder is searched first for its includes,
/// however its path is spelled: `.`, a bare name, `./name`, standard input
/// under `--stdin-filename`, and a description run from that folder.
#[test]
fn includes_beside_the_shader_whatever_the_path_spelling() {
    if !tool("glslangValidator") {
        return;
    }
    let d = scratch("own-folder");
    write(&d, "common.glsl", GLSL_HEADER);
    write(&d, "closesthit.rchit", GLSL_HIT);
    write(&d, "raygen.rgen", GLSL_RAYGEN);
    write(&d, "common.hlsli", HLSL_HEADER);
    write(&d, "hit.hlsl", HLSL_HIT);
    write(
        &d,
        "scene.pipeline.toml",
        "max_recursion_depth = 1\n[[raygen]]\nfile = \"raygen.rgen\"\nentry = \"main\"\n[[hit_group]]\ntype = \"triangles\"\nclosest_hit = { file = \"closesthit.rchit\", entry = \"main\" }\n",
    );
    for args in [
        &["check", "."][..],
        &["check", "closesthit.rchit"],
        &["check", "./closesthit.rchit"],
        &["check", "hit.hlsl", "./hit.hlsl"],
        &["stack", "scene.pipeline.toml"],
    ] {
        let o = run_in(&d, args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {t}");
        assert!(!t.contains("include"), "{args:?}: {t}");
    }
    for (name, source) in [("closesthit.rchit", GLSL_HIT), ("hit.hlsl", HLSL_HIT)] {
        let o = run_stdin(
            &d,
            &["check", "-", "--stdin-filename", name],
            source.as_bytes(),
        );
        assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o));
    }
    // From the folder above, the same files by their longer names.
    let o = run_in(d.parent().unwrap(), &["check", d.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

/// Item 2: `-I`, `-D` and the config's `[hlsl]` include directories and
/// defines reach the shaders a pipeline description names, as they reach
/// every other input.
#[test]
fn compile_options_reach_shaders_a_description_names() {
    let d = scratch("described");
    write(&d, "inc/common.hlsli", HLSL_HEADER);
    write(
        &d,
        "shaders/raygen.hlsl",
        "#include \"common.hlsli\"
RaytracingAccelerationStructure scene : register(t0);
[shader(\"raygeneration\")]
void Gen() {
    RayDesc ray = { float3(0, 0, 0), 0.0, float3(0, 0, 1), 100.0 };
    Payload p = { float4(0, 0, 0, 0) };
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
}
",
    );
    write(
        &d,
        "shaders/hit.hlsl",
        "#include \"common.hlsli\"
#ifndef COLOR
#error COLOR is not defined
#endif
[shader(\"closesthit\")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a) { p.color = COLOR; }
",
    );
    write(
        &d,
        "shaders/scene.pipeline.toml",
        "max_recursion_depth = 1\n[[raygen]]\nfile = \"raygen.hlsl\"\nentry = \"Gen\"\n[[hit_group]]\ntype = \"triangles\"\nclosest_hit = { file = \"hit.hlsl\", entry = \"Hit\" }\n",
    );
    // The command line's.
    for cmd in ["check", "stack"] {
        let o = run_in(&d, &[cmd, "shaders", "-I", "inc", "-D", "COLOR=1"]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{cmd}: {t}");
        assert!(!t.contains("no include directories"), "{cmd}: {t}");
        let o = run_in(
            &d,
            &[
                cmd,
                "shaders/scene.pipeline.toml",
                "-I",
                "inc",
                "-D",
                "COLOR=1",
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{cmd}: {}", text(&o));
    }
    // Without them the error names the directories searched, and says none
    // was given only when none was.
    let o = run_in(
        &d,
        &["check", "shaders/scene.pipeline.toml", "-D", "COLOR=1"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("cannot find include file"),
        "{}",
        text(&o)
    );
    // The config's.
    write(
        &d,
        "rtlint.toml",
        "[hlsl]\ninclude-dirs = [\"inc\"]\n[hlsl.defines]\nCOLOR = \"1\"\n",
    );
    for cmd in ["check", "stack"] {
        let o = run_in(&d, &[cmd, "shaders/scene.pipeline.toml"]);
        assert_eq!(o.status.code(), Some(0), "{cmd}: {}", text(&o));
    }
}

const RAY_QUERY_HEADER: &str = "#extension GL_EXT_ray_query : require
layout(binding = 0) uniform accelerationStructureEXT scene;
float visible(vec3 o) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, scene, gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, 0.0, vec3(0, 1, 0), 10.0);
    while (rayQueryProceedEXT(q)) {}
    return rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionNoneEXT ? 1.0 : 0.0;
}
";

const RAY_QUERY_COMP: &str = "#version 460
#extension GL_GOOGLE_include_directive : require
#include \"rq.glsl\"
layout(local_size_x = 8) in;
layout(binding = 1) buffer Out { float v[]; } outv;
void main() { outv.v[gl_GlobalInvocationID.x] = visible(vec3(gl_GlobalInvocationID)); }
";

/// Item 4: a `.comp` whose `rayQueryEXT` sits in an included file is a
/// ray-query shader, named or found in a folder.
#[test]
fn glsl_ray_query_in_an_included_file() {
    if !tool("glslangValidator") {
        return;
    }
    let d = scratch("rq-include");
    write(&d, "lib/rq.glsl", RAY_QUERY_HEADER);
    write(&d, "shade.comp", RAY_QUERY_COMP);
    write(
        &d,
        "plain.comp",
        "#version 460\nlayout(local_size_x = 8) in;\nvoid main() {}\n",
    );
    let o = run_in(&d, &["check", "shade.comp", "-I", "lib"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("in 1 file"), "{t}");
    // In a walk: linted; the compute shader without ray queries is not.
    let o = run_in(&d, &["check", ".", "-I", "lib", "--verbose"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("skipped plain.comp"), "{t}");
    assert!(!t.contains("skipped shade.comp"), "{t}");
    assert!(t.contains("in 1 file"), "{t}");
}

/// Item 4: the stage of a GLSL file whose extension names none comes from
/// `--stage` or `[stages]`; without one the error says how to give it
/// (not glslang's usage text).
#[test]
fn glsl_stage_from_the_command_line_or_the_config() {
    if !tool("glslangValidator") {
        return;
    }
    let d = scratch("stage");
    write(&d, "common.glsl", GLSL_HEADER);
    write(&d, "hit.x", GLSL_HIT);
    write(&d, "rtlint.toml", "[languages]\nx = \"glsl\"\n");
    let o = run_in(&d, &["check", "hit.x"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("cannot tell the GLSL stage of `hit.x`"), "{t}");
    assert!(t.contains("--stage") && t.contains("[stages]"), "{t}");
    assert!(!t.contains("Usage"), "{t}");
    // `--stage`.
    let o = run_in(&d, &["check", "hit.x", "--stage", "rchit"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    // `[stages]`, named and in a walk.
    write(&d, "rtlint.toml", "[stages]\n\"*.x\" = \"rchit\"\n");
    let o = run_in(&d, &["check", "hit.x"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = run_in(&d, &["check", ".", "--verbose"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(
        t.contains("in 1 file") && !t.contains("skipped hit.x"),
        "{t}"
    );
    // An unknown stage, and an unknown language, list what is allowed.
    write(&d, "rtlint.toml", "[stages]\n\"*.x\" = \"closest\"\n");
    let t = text(&run_in(&d, &["check", "hit.x"]));
    assert!(
        t.contains("unknown GLSL stage `closest`") && t.contains("rchit"),
        "{t}"
    );
    write(&d, "rtlint.toml", "[languages]\nx = \"glsl2\"\n");
    let t = text(&run_in(&d, &["check", "hit.x"]));
    assert!(t.contains("hlsl, wgsl, glsl or spirv"), "{t}");
    // A stage that is neither a GLSL stage nor a DXC profile is refused.
    write(&d, "rtlint.toml", "[languages]\nx = \"glsl\"\n");
    let o = run_in(&d, &["check", "hit.x", "--stage", "closest"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

/// Item 15: an input error without a position does not blame debug info
/// (a missing path, a description, a config are not modules).
#[test]
fn positionless_input_errors_say_no_more_than_they_know() {
    let d = scratch("positionless");
    write(&d, "empty.pipeline.toml", "max_recursion_depth = 1\n");
    for args in [
        &["check", "nope.rgen"][..],
        &["check", "empty.pipeline.toml"],
    ] {
        let o = run_in(&d, args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {t}");
        assert!(!t.contains("debug info"), "{args:?}: {t}");
        assert!(t.contains(&format!("= in {}", args[1])), "{args:?}: {t}");
    }
}

/// Item 3: a `.hlsl` file without an entry point that another linted file
/// includes is a header, linted through its includer; one that nothing
/// includes gets a note, not an input error.
#[test]
fn hlsl_headers_without_entry_points() {
    let d = scratch("hlsl-header");
    write(
        &d,
        "common.hlsl",
        "struct Payload { float4 color; };\nfloat3 Tint() { return float3(1, 0, 0); }\n",
    );
    write(
        &d,
        "hit.hlsl",
        "#include \"common.hlsl\"
[shader(\"closesthit\")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a) { p.color = float4(Tint(), 1); }
",
    );
    for args in [
        &["check", "."][..],
        &["check", "hit.hlsl", "common.hlsl"],
        &["stack", "."],
    ] {
        let o = run_in(&d, args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {t}");
        assert!(!t.contains("entry point"), "{args:?}: {t}");
    }
    write(&d, "lonely.hlsl", "float Lonely() { return 1; }\n");
    for args in [
        &["check", "."][..],
        &["check", "lonely.hlsl"],
        &["stack", "."],
    ] {
        let o = run_in(&d, args);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {t}");
        assert!(t.contains("note: no entry point"), "{args:?}: {t}");
        assert!(t.contains("lonely.hlsl"), "{args:?}: {t}");
    }
    let o = run_in(&d, &["check", ".", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["summary"]["input_errors"], 0, "{v}");
    assert_eq!(v["diagnostics"][0]["severity"], "note", "{v}");
    assert_eq!(v["diagnostics"][0]["name"], "no-entry-point", "{v}");
    // An entry point asked for by name and missing is still an error.
    let o = run_in(&d, &["check", "hit.hlsl", "-E", "Nope", "-T", "closesthit"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

/// Item 15: a bad rule level in rtlint.toml lists the allowed values, not
/// serde's "untagged enum RuleSetting".
#[test]
fn bad_rule_level_lists_the_levels() {
    let d = scratch("level");
    write(&d, "lonely.hlsl", "float Lonely() { return 1; }\n");
    for setting in [
        "RT001 = \"loud\"",
        "[rules.RT001]\nlevel = \"loud\"",
        "RT001 = 3",
    ] {
        write(&d, "rtlint.toml", &format!("[rules]\n{setting}\n"));
        let o = run_in(&d, &["check", "lonely.hlsl"]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{setting}: {t}");
        assert!(
            t.contains("\"allow\", \"warn\" or \"error\""),
            "{setting}: {t}"
        );
        assert!(
            !t.contains("untagged") && !t.contains("RuleSetting"),
            "{setting}: {t}"
        );
        assert!(
            t.contains("rtlint.toml:2:") || t.contains("rtlint.toml:3:"),
            "{setting}: {t}"
        );
    }
    // A table with a level and the rule's options still reads.
    write(
        &d,
        "rtlint.toml",
        "[rules.RT001]\nlevel = \"error\"\nbudget = 8\n",
    );
    let o = run_in(&d, &["check", "lonely.hlsl"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

const WGSL_OVERRIDES: &str = "enable wgpu_ray_query;
override max_dist: f32 = 100.0;
override samples: u32;
@group(0) @binding(0) var acc: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;
@compute @workgroup_size(8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var rq: ray_query;
    rayQueryInitialize(&rq, acc, RayDesc(0u, 0xFFu, 0.0, max_dist, vec3<f32>(0.0), vec3<f32>(0.0, 1.0, 0.0)));
    rayQueryProceed(&rq);
    let hit = rayQueryGetCommittedIntersection(&rq);
    out[id.x] = hit.t * f32(samples);
}
";

/// Item 5: WGSL `override`s are evaluated as a pipeline would: `-D` (or the
/// config's defines) by name, else the default; one with neither is an
/// error at its declaration. Findings keep their lines.
#[test]
fn wgsl_overrides_take_defaults_or_defines() {
    let d = scratch("overrides");
    write(&d, "rq.wgsl", WGSL_OVERRIDES);
    let o = run_in(&d, &["check", "rq.wgsl"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("override `samples` has no default value"), "{t}");
    assert!(t.contains("rq.wgsl:3:10"), "{t}");
    let o = run_in(
        &d,
        &[
            "check",
            "rq.wgsl",
            "-D",
            "samples=4",
            "--select",
            "RT062",
            "--format",
            "concise",
        ],
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("rq.wgsl:10:5: warning[RT062]"), "{t}");
    write(&d, "rtlint.toml", "[hlsl.defines]\nsamples = \"2\"\n");
    let o = run_in(&d, &["check", "rq.wgsl"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let o = run_in(&d, &["check", "rq.wgsl", "-D", "samples=many"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("`many` is not a number"), "{}", text(&o));
}

const COMPOSED_LIB: &str = "#define_import_path my::rays
enable wgpu_ray_query;

const MAX_T: f32 = 100.0;

fn up() -> vec3<f32> {
    return vec3<f32>(0.0, 1.0, 0.0);
}
";

const COMPOSED_SHADER: &str = "enable wgpu_ray_query;
#import my::rays::{MAX_T, up}

@group(0) @binding(0) var acc: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var rq: ray_query;
#ifdef OPAQUE
    let flags = 1u;
#else
    let flags = 0u;
#endif
    rayQueryInitialize(&rq, acc, RayDesc(flags, 0xFFu, 0.0, MAX_T, vec3<f32>(0.0), up()));
    rayQueryProceed(&rq);
    out[id.x] = rayQueryGetCommittedIntersection(&rq).t;
}
";

/// Item 5: WGSL written for naga_oil (`#import`, `#define_import_path`,
/// `#ifdef`) is composed with the modules found beside it or under `-I`,
/// with `-D` as shader defs; findings land on the shader's own lines.
#[test]
fn wgsl_composed_with_naga_oil() {
    let d = scratch("compose");
    write(&d, "lib/rays.wgsl", COMPOSED_LIB);
    write(&d, "shaders/shade.wgsl", COMPOSED_SHADER);
    let args = ["--select", "RT062", "--format", "concise"];
    let o = run_in(
        &d,
        &[&["check", "shaders/shade.wgsl", "-I", "lib"][..], &args].concat(),
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(t.contains("shaders/shade.wgsl:16:5: warning[RT062]"), "{t}");
    // The `#ifdef` branch a define picks: an opaque ray, no finding.
    let o = run_in(
        &d,
        &[
            &["check", "shaders/shade.wgsl", "-I", "lib", "-D", "OPAQUE"][..],
            &args,
        ]
        .concat(),
    );
    let t = text(&o);
    assert_eq!(o.status.code(), Some(0), "{t}");
    assert!(!t.contains("RT062"), "{t}");
    // Found beside the shader (below its folder) as well.
    std::fs::rename(d.join("lib"), d.join("shaders/lib")).unwrap();
    let o = run_in(
        &d.join("shaders"),
        &[&["check", "shade.wgsl"][..], &args].concat(),
    );
    let t = text(&o);
    assert!(t.contains("shade.wgsl:16:5: warning[RT062]"), "{t}");
    // A module nobody provides: an error naming the import.
    std::fs::remove_dir_all(d.join("shaders/lib")).unwrap();
    let o = run_in(&d, &["check", "shaders/shade.wgsl"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("my::rays"), "{t}");
}

/// Item 16: a trace written over several lines is reported on the line its
/// name is on and spans the call; GLSL positions (glslang `-g` has no
/// columns) get one in every format; HLSL trace regions have a width.
#[test]
fn trace_positions_start_at_the_call_and_have_a_width() {
    if !tool("glslangValidator") {
        return;
    }
    let d = scratch("positions");
    write(
        &d,
        "gen.rgen",
        "#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { vec4 a; vec4 b; vec4 c; vec4 d; vec4 e; };
layout(binding = 0) uniform accelerationStructureEXT scene;
layout(location = 0) rayPayloadEXT Payload p;
void main() {
    traceRayEXT(scene, 0, 0xFF, 0, 1, 0,
                vec3(0.0), 0.0,
                vec3(0.0, 0.0, 1.0), 100.0,
                0);
}
",
    );
    let o = run_in(&d, &["live", "gen.rgen"]);
    let t = text(&o);
    assert!(t.starts_with("gen.rgen:7:5: trace_ray"), "{t}");
    let o = run_in(&d, &["check", "gen.rgen", "--format", "sarif"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let region = &v["runs"][0]["results"][0]["relatedLocations"][0]["physicalLocation"]["region"];
    assert_eq!(region["startLine"], 7, "{region}");
    assert_eq!(region["startColumn"], 5, "{region}");
    assert_eq!(region["endLine"], 10, "{region}");
    assert_eq!(region["endColumn"], 19, "{region}");
    // A GLSL line without a column from glslang, in concise output.
    let o = rtlint()
        .args([
            "check",
            "fixtures/RT010/bad.rgen",
            "--format",
            "concise",
            "--select",
            "RT010",
        ])
        .output()
        .unwrap();
    assert!(
        text(&o).contains("fixtures/RT010/bad.rgen:19:5: warning[RT010]"),
        "{}",
        text(&o)
    );
    // An HLSL trace's region is the call, not a point.
    let o = rtlint()
        .args([
            "check",
            "fixtures/RT030/bad.hlsl",
            "--format",
            "json",
            "--select",
            "RT030",
        ])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let f = &v["diagnostics"][0];
    assert_eq!(f["code"], "RT030", "{v}");
    assert_eq!(
        (f["line"].as_u64(), f["end_line"].as_u64()),
        (Some(30), Some(30)),
        "{f}"
    );
    assert!(f["end_column"].as_u64() > f["column"].as_u64(), "{f}");
}

/// Item 16: RT010's "defined here" labels sit under the variable, and
/// `rtlint live` names an HLSL traced payload by its variable.
#[test]
fn hlsl_live_values_and_payloads_by_their_names() {
    let d = scratch("live-names");
    write(
        &d,
        "gen.hlsl",
        "struct Payload { float4 color; };
RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> img : register(u0);
cbuffer C : register(b0) { uint n; };
Texture2D<float4> tex : register(t1);
SamplerState smp : register(s0);
[shader(\"raygeneration\")]
void Gen() {
    float4 acc = float4(0, 0, 0, 0);
    for (uint i = 0; i < n; i++) {
        acc += tex.SampleLevel(smp, float2(i, 0), 0);
    }
    float3 dir = normalize(acc.xyz);
    RayDesc ray = { float3(0, 0, 0), 0.001, dir, 100.0 };
    Payload primary = { float4(0, 0, 0, 0) };
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, primary);
    img[DispatchRaysIndex().xy] = primary.color * acc + float4(dir, 1);
}
",
    );
    write(&d, "rtlint.toml", "[rules.RT010]\nbudget = 8\n");
    let o = run_in(
        &d,
        &["check", "gen.hlsl", "--select", "RT010", "--format", "json"],
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let labels = v["diagnostics"][0]["labels"]
        .as_array()
        .cloned()
        .unwrap_or_default();
    let at = |name: &str| {
        labels
            .iter()
            .find(|l| {
                l["message"]
                    .as_str()
                    .unwrap_or("")
                    .starts_with(&format!("`{name}`"))
            })
            .map(|l| (l["line"].as_u64(), l["column"].as_u64()))
    };
    assert_eq!(at("acc"), Some((Some(9), Some(12))), "{v}");
    assert_eq!(at("dir"), Some((Some(13), Some(12))), "{v}");
    let o = run_in(&d, &["live", "gen.hlsl"]);
    let t = text(&o);
    assert!(t.contains("payload `primary`: Payload"), "{t}");
}
