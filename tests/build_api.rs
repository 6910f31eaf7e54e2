//! The build-script API in process (`Builder::run_to` with an explicit
//! output folder): output names, warnings beside a failing shader, outputs
//! of deleted shaders, and where generated types say they come from.
//! `tests/build_script.rs` builds a real crate; these need no cargo run.

use rtlint::build::Builder;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-build-api-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("shaders")).unwrap();
    std::fs::create_dir_all(d.join("out")).unwrap();
    d
}

const PAYLOAD_GLSL: &str = "struct Payload {\n    vec4 color;\n    float t;\n};\n";

const RGEN: &str = "#version 460\n\
#extension GL_EXT_ray_tracing : require\n\
#extension GL_GOOGLE_include_directive : require\n\
#include \"payload.glsl\"\n\
layout(location = 0) rayPayloadEXT Payload p;\n\
layout(binding = 0) uniform accelerationStructureEXT tlas;\n\
layout(binding = 1, rgba8) uniform image2D img;\n\
void main() {\n\
    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3(0.0), 0.001, vec3(0.0, 0.0, 1.0), 100.0, 0);\n\
    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p.color);\n\
}\n";

const RMISS: &str = "#version 460\n\
#extension GL_EXT_ray_tracing : require\n\
#extension GL_GOOGLE_include_directive : require\n\
#include \"payload.glsl\"\n\
layout(location = 0) rayPayloadInEXT Payload p;\n\
void main() { p.color = vec4(1.0); p.t = 0.0; }\n";

const SHADOW_MISS: &str = "#version 460\n\
#extension GL_EXT_ray_tracing : require\n\
layout(location = 1) rayPayloadInEXT float shadowed;\n\
void main() { shadowed = 0.0; }\n";

const SHADOW_AHIT: &str = "#version 460\n\
#extension GL_EXT_ray_tracing : require\n\
layout(location = 1) rayPayloadInEXT float shadowed;\n\
void main() { shadowed = 1.0; ignoreIntersectionEXT; }\n";

/// A WGSL raygen whose 48-byte payload is over the 32-byte budget (RT001).
const FAT_WGSL: &str = "enable wgpu_ray_tracing_pipeline;\n\
struct Fat { a: vec4<f32>, b: vec4<f32>, c: vec4<f32> }\n\
var<ray_payload> p: Fat;\n\
@group(0) @binding(0) var tlas: acceleration_structure;\n\
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;\n\
@ray_generation fn main() {\n\
    traceRay(tlas, RayDesc(0u, 0xFFu, 0.001, 100.0, vec3(0.0), vec3(0.0, 0.0, 1.0)), &p);\n\
    out[0] = p.a;\n\
}\n";

fn write(dir: &Path, files: &[(&str, &str)]) {
    for (name, text) in files {
        std::fs::write(dir.join("shaders").join(name), text).unwrap();
    }
}

/// Runs the builder over `dir/shaders` into `dir/out`: cargo's lines and
/// whether it succeeded.
fn run(dir: &Path, layouts: bool) -> (String, bool) {
    let mut b = Builder::new()
        .shaders(dir.join("shaders"))
        .emit_spirv()
        .out_dir(dir.join("out"));
    if layouts {
        b = b.generate_layouts("layouts.rs");
    }
    let mut out = Vec::new();
    let result = b.run_to(&mut out);
    let mut text = String::from_utf8(out).unwrap();
    if let Err(e) = &result {
        text.push_str(&e.to_string());
    }
    (text, result.is_ok())
}

fn outputs(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".spv"))
        .collect();
    v.sort();
    v
}

fn have_glslang() -> bool {
    rtlint_testkit::require(
        "glslangValidator",
        std::process::Command::new("glslangValidator")
            .arg("--version")
            .output()
            .map(|_| ())
            .map_err(|e| e.to_string()),
    )
    .is_some()
}

/// GLSL outputs are named with their stage, so `raytrace.rgen` and
/// `raytrace.rmiss`, or `shadow.rmiss` and `shadow.rahit`, do not collide;
/// WGSL keeps `<stem>.<entry>.spv`.
#[test]
fn glsl_outputs_are_named_with_the_stage() {
    if !have_glslang() {
        return;
    }
    let d = scratch("names");
    write(
        &d,
        &[
            ("payload.glsl", PAYLOAD_GLSL),
            ("raytrace.rgen", RGEN),
            ("raytrace.rmiss", RMISS),
            ("shadow.rmiss", SHADOW_MISS),
            ("shadow.rahit", SHADOW_AHIT),
            ("fat.wgsl", FAT_WGSL),
        ],
    );
    let (text, ok) = run(&d, false);
    assert!(ok, "{text}");
    assert_eq!(
        outputs(&d),
        [
            "fat.main.spv",
            "raytrace.rgen.spv",
            "raytrace.rmiss.spv",
            "shadow.rahit.spv",
            "shadow.rmiss.spv"
        ],
        "{text}"
    );
}

/// A shader that fails does not silence the others: their warnings still
/// reach cargo beside the error.
#[test]
fn warnings_of_other_shaders_survive_a_failing_one() {
    let d = scratch("failing");
    write(
        &d,
        &[("fat.wgsl", FAT_WGSL), ("broken.wgsl", "fn main( {\n")],
    );
    let (text, ok) = run(&d, true);
    assert!(!ok, "{text}");
    assert!(
        text.lines()
            .any(|l| l.starts_with("cargo:warning=") && l.contains("RT001")),
        "{text}"
    );
    // And in the error cargo prints when the script fails.
    let failure = &text[text.find("rtlint: ").expect("the error's text")..];
    assert!(failure.contains("broken.wgsl"), "{failure}");
    assert!(
        failure.contains("also found (not failing the build):")
            && failure.contains("fat.wgsl:2: RT001"),
        "{failure}"
    );
}

/// The SPIR-V of a deleted shader leaves the output folder on the next run;
/// files rtlint did not write stay.
#[test]
fn outputs_of_deleted_shaders_are_removed() {
    let d = scratch("deleted");
    let other = FAT_WGSL
        .replace("Fat", "Thin")
        .replace("a: vec4<f32>, b: vec4<f32>, c: vec4<f32>", "a: vec4<f32>");
    write(&d, &[("fat.wgsl", FAT_WGSL), ("thin.wgsl", &other)]);
    std::fs::write(d.join("out/mine.spv"), b"not rtlint's").unwrap();
    let (text, ok) = run(&d, false);
    assert!(ok, "{text}");
    assert_eq!(
        outputs(&d),
        ["fat.main.spv", "mine.spv", "thin.main.spv"],
        "{text}"
    );
    std::fs::remove_file(d.join("shaders/thin.wgsl")).unwrap();
    let (text, ok) = run(&d, false);
    assert!(ok, "{text}");
    assert_eq!(outputs(&d), ["fat.main.spv", "mine.spv"], "{text}");
}

/// A generated type's comment names the header that declares it, not the
/// first shader that includes the header.
#[test]
fn a_generated_glsl_type_names_its_header() {
    if !have_glslang() {
        return;
    }
    // The brace on the struct's line or the next; the header beside the
    // shaders or in a folder of its own.
    let brace_below = PAYLOAD_GLSL.replace("Payload {", "Payload\n{");
    for (k, (header, at)) in [
        (PAYLOAD_GLSL, "payload.glsl"),
        (brace_below.as_str(), "payload.glsl"),
        (PAYLOAD_GLSL, "include/payload.glsl"),
    ]
    .into_iter()
    .enumerate()
    {
        let d = scratch(&format!("header{k}"));
        std::fs::create_dir_all(d.join("shaders/include")).unwrap();
        let include = format!("#include \"{at}\"");
        write(
            &d,
            &[
                (at, header),
                (
                    "raytrace.rgen",
                    &RGEN.replace("#include \"payload.glsl\"", &include),
                ),
                (
                    "raytrace.rmiss",
                    &RMISS.replace("#include \"payload.glsl\"", &include),
                ),
            ],
        );
        let (text, ok) = run(&d, true);
        assert!(ok, "{text}");
        let layouts = std::fs::read_to_string(d.join("out/layouts.rs")).unwrap();
        let doc = layouts
            .lines()
            .find(|l| l.starts_with("///") && l.contains("`Payload`"))
            .unwrap_or_else(|| panic!("{layouts}"));
        assert!(doc.contains(&format!("{at}:1")), "{k}: {doc}");
    }
    // The same shaders as SPIR-V compiled with `-g` (the header's text is
    // embedded in the module).
    let d = scratch("header-spv");
    write(
        &d,
        &[
            ("payload.glsl", PAYLOAD_GLSL),
            ("raytrace.rgen", RGEN),
            ("raytrace.rmiss", RMISS),
        ],
    );
    for name in ["raytrace.rgen", "raytrace.rmiss"] {
        let src = d.join("shaders").join(name);
        let o = std::process::Command::new("glslangValidator")
            .args(["-V", "--target-env", "vulkan1.2", "-g", "-o"])
            .arg(d.join("shaders").join(format!("{name}.spv")))
            .arg(&src)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
        std::fs::remove_file(src).unwrap();
    }
    let (text, ok) = run(&d, true);
    assert!(ok, "{text}");
    let layouts = std::fs::read_to_string(d.join("out/layouts.rs")).unwrap();
    let doc = layouts
        .lines()
        .find(|l| l.starts_with("///") && l.contains("`Payload`"))
        .unwrap_or_else(|| panic!("{layouts}"));
    assert!(doc.contains("payload.glsl:1"), "spv: {doc}");
}
