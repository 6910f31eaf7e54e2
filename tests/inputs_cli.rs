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
