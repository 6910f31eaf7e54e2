//! `rtlint check` as CI users run it: suppressions, selection, per-file
//! configs, the walk (gitignore, excludes, link loops, duplicates), output
//! controls, standard input, SARIF against the official schema, and
//! determinism under parallel linting.

mod common;

use common::{root, rtlint};
use rtlint_testkit::require;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-lint-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

/// `path:line:col: level[CODE]` prefixes of concise output, sorted.
fn findings(o: &Output) -> Vec<String> {
    let mut v: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.contains("]"))
        .filter_map(|l| {
            let end = l.find(']')? + 1;
            Some(l[..end].to_string())
        })
        .collect();
    v.sort();
    v
}

fn check_in(dir: &Path, args: &[&str]) -> Output {
    rtlint()
        .current_dir(dir)
        .arg("check")
        .args(["--format", "concise"])
        .args(args)
        .env_remove("NO_COLOR")
        .env_remove("FORCE_COLOR")
        .env_remove("CLICOLOR_FORCE")
        .output()
        .unwrap()
}

/// A WGSL raygen whose 48-byte payload breaks the 32-byte budget (RT001,
/// line 3) and nothing else.
const FAT_WGSL: &str = "enable wgpu_ray_tracing_pipeline;\n\
struct Fat { a: vec4<f32>, b: vec4<f32>, c: vec4<f32> }\n\
var<ray_payload> p: Fat;\n\
@group(0) @binding(0) var tlas: acceleration_structure;\n\
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;\n\
@ray_generation fn main() {\n\
    traceRay(tlas, RayDesc(0u, 0xFFu, 0.001, 100.0, vec3(0.0), vec3(0.0, 0.0, 1.0)), &p);\n\
    out[0] = p.a;\n\
}\n";

#[test]
fn suppression_fixtures_match_their_markers() {
    let options = rtlint::lint::Options::default();
    for name in ["bad.hlsl", "good.hlsl"] {
        let path = root().join("fixtures/RT000").join(name);
        let report = rtlint::lint::check_paths(std::slice::from_ref(&path), &options);
        let got: Vec<(u32, &str)> = report
            .diagnostics
            .iter()
            .map(|d| (d.primary.as_ref().unwrap().location.line, d.code.unwrap()))
            .collect();
        let source = std::fs::read_to_string(&path).unwrap();
        let expected: Vec<(u32, &str)> = source
            .lines()
            .enumerate()
            .filter_map(|(i, l)| {
                let at = l.find("//~")?;
                Some((i as u32 + 1, l[at + 3..].trim()))
            })
            .collect();
        assert_eq!(got, expected, "{name}: {:#?}", report.diagnostics);
    }
}

#[test]
fn wgsl_filters_and_comments_suppress() {
    let d = scratch("wgsl");
    std::fs::write(d.join("plain.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(
        d.join("directive.wgsl"),
        format!("diagnostic(off, rtlint.payload_over_budget);\n{FAT_WGSL}"),
    )
    .unwrap();
    std::fs::write(
        d.join("comment.wgsl"),
        FAT_WGSL.replace("struct Fat", "// rtlint: allow(RT001)\nstruct Fat"),
    )
    .unwrap();
    std::fs::write(
        d.join("stale.wgsl"),
        format!("diagnostic(off, rtlint.member_straddles_row);\n{FAT_WGSL}"),
    )
    .unwrap();
    let o = check_in(&d, &["."]);
    assert_eq!(
        findings(&o),
        [
            "plain.wgsl:2:8: warning[RT001]",
            "stale.wgsl:1:1: warning[RT000]",
            "stale.wgsl:3:8: warning[RT001]",
        ],
        "{}",
        text(&o)
    );
}

/// An HLSL raygen tracing two 48-byte payloads declared on lines 1 and 2.
const TWO_FAT_HLSL: &str = "struct Fat { float4 a; float4 b; float4 c; };\n\
struct Big { float4 a; float4 b; float4 c; };\n\
RaytracingAccelerationStructure tlas : register(t0);\n\
RWTexture2D<float4> image : register(u1);\n\
[shader(\"raygeneration\")]\n\
void Gen()\n\
{\n\
    RayDesc ray;\n\
    ray.Origin = float3(0.0, 0.0, 0.0);\n\
    ray.Direction = float3(0.0, 0.0, 1.0);\n\
    ray.TMin = 0.001;\n\
    ray.TMax = 10.0;\n\
    Fat p = (Fat)0;\n\
    Big q = (Big)0;\n\
    TraceRay(tlas, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, ray, p);\n\
    TraceRay(tlas, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, ray, q);\n\
    image[DispatchRaysIndex().xy] = p.a + q.a;\n\
}\n";

/// A suppression after code covers its own line only; one alone on its line
/// covers the next; a selector that names nothing is an input error at the
/// name, in comments and in WGSL filters alike.
#[test]
fn suppressions_cover_their_line_and_unknown_selectors_are_errors() {
    let d = scratch("suppress-lines");
    let end_of_line = TWO_FAT_HLSL.replacen("};\n", "}; // rtlint: allow(RT001)\n", 1);
    std::fs::write(d.join("eol.hlsl"), &end_of_line).unwrap();
    std::fs::write(
        d.join("above.hlsl"),
        TWO_FAT_HLSL.replacen("struct Big", "// rtlint: allow(RT001)\nstruct Big", 1),
    )
    .unwrap();
    let o = check_in(&d, &["--no-cache", "eol.hlsl", "above.hlsl"]);
    assert_eq!(
        findings(&o),
        [
            "above.hlsl:1:8: warning[RT001]",
            "eol.hlsl:2:8: warning[RT001]"
        ],
        "{}",
        text(&o)
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));

    std::fs::write(
        d.join("unknown.hlsl"),
        end_of_line.replace("allow(RT001)", "allow(RT999, RT001)"),
    )
    .unwrap();
    std::fs::write(
        d.join("unknown.wgsl"),
        FAT_WGSL.replacen(";\n", ";\ndiagnostic(off, rtlint.no_such_rule);\n", 1),
    )
    .unwrap();
    let o = check_in(&d, &["--no-cache", "unknown.hlsl", "unknown.wgsl"]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(
        t.contains("unknown.hlsl:1:64: error[invalid-suppression] suppression names unknown rule or group `RT999`"),
        "{t}"
    );
    assert!(
        t.contains("unknown.wgsl:2:24: error[invalid-suppression]"),
        "{t}"
    );
    // The known selector beside the unknown one still applies.
    assert!(!t.contains("unknown.hlsl:1:8"), "{t}");
}

/// A GLSL raygen with the same 48-byte payload; the suppression names the
/// rule by name on the line above.
const FAT_GLSL: &str = "#version 460\n\
#extension GL_EXT_ray_tracing : require\n\
// rtlint: allow(payload-over-budget, reason = \"measured: fits in registers\")\n\
struct Fat { vec4 a; vec4 b; vec4 c; };\n\
layout(location = 0) rayPayloadEXT Fat p;\n\
layout(binding = 0) uniform accelerationStructureEXT tlas;\n\
layout(binding = 1, rgba8) uniform image2D img;\n\
void main() {\n\
    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3(0.0), 0.001, vec3(0.0, 0.0, 1.0), 100.0, 0);\n\
    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p.a);\n\
}\n";

#[test]
fn glsl_sources_are_linted_and_their_suppressions_found() {
    let d = scratch("glsl");
    std::fs::write(d.join("allowed.rgen"), FAT_GLSL).unwrap();
    std::fs::write(
        d.join("plain.rgen"),
        FAT_GLSL.replace(
            "// rtlint: allow(payload-over-budget, reason = \"measured: fits in registers\")\n",
            "",
        ),
    )
    .unwrap();
    std::fs::write(
        d.join("broken.rchit"),
        "#version 460\nvoid main() { nope; }\n",
    )
    .unwrap();
    let o = check_in(&d, &["."]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    let f = findings(&o);
    assert!(
        f.contains(&"plain.rgen:3:8: warning[RT001]".to_string()),
        "{t}"
    );
    assert!(!f.iter().any(|l| l.starts_with("allowed.rgen")), "{t}");
    // glslang's error, at its line, as an input error.
    assert!(t.contains("broken.rchit:2"), "{t}");
    assert!(t.contains("glsl-error"), "{t}");
    // The same suppression through a `-g` module's embedded source.
    let spv = d.join("allowed.rgen.spv");
    let g = Command::new("glslangValidator")
        .args(["-V", "--target-env", "vulkan1.2", "-g", "-o"])
        .arg(&spv)
        .arg(d.join("allowed.rgen"))
        .output();
    let compiled = g.map_err(|e| e.to_string()).and_then(|g| {
        if g.status.success() {
            Ok(())
        } else {
            Err(text(&g))
        }
    });
    if require("glslangValidator", compiled).is_some() {
        std::fs::remove_file(d.join("allowed.rgen")).unwrap();
        let o = check_in(&d, &["allowed.rgen.spv"]);
        assert!(findings(&o).is_empty(), "{}", text(&o));
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    }
}

#[test]
fn missing_glslang_is_a_clear_input_error() {
    let d = scratch("noglslang");
    std::fs::write(d.join("a.rgen"), FAT_GLSL).unwrap();
    let o = rtlint()
        .current_dir(&d)
        .args(["check", "a.rgen"])
        .env("RTLINT_GLSLANG", d.join("no-such-glslang"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let t = text(&o);
    assert!(t.contains("a.rgen") && t.contains("RTLINT_GLSLANG"), "{t}");
}

#[test]
fn selection_by_code_name_group_and_prefix() {
    let src = root().join("fixtures/hlsl/payloads.hlsl");
    let src = src.to_str().unwrap();
    let codes = |args: &[&str]| -> Vec<String> {
        let mut a = vec![src];
        a.extend_from_slice(args);
        let o = check_in(&root(), &a);
        let mut c: Vec<String> = findings(&o)
            .iter()
            .map(|l| l[l.find('[').unwrap() + 1..l.len() - 1].to_string())
            .collect();
        c.dedup();
        c
    };
    assert_eq!(codes(&[]), ["RT001", "RT002", "RT003"]);
    assert_eq!(codes(&["--select", "RT001"]), ["RT001"]);
    assert_eq!(
        codes(&["--select", "payload-packing-waste,RT003"]),
        ["RT002", "RT003"]
    );
    assert_eq!(codes(&["--ignore", "RT00"]), Vec::<String>::new());
    assert_eq!(
        codes(&["--select", "RT001", "--extend-select", "RT003"]),
        ["RT001", "RT003"]
    );
    assert_eq!(codes(&["--ignore", "perf"]), Vec::<String>::new());
    assert_eq!(
        codes(&["--select", "ALL", "--ignore", "RT002"]),
        ["RT001", "RT003"]
    );
    let o = check_in(&root(), &[src, "--select", "RT999"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o).contains("unknown rule or group `RT999`"),
        "{}",
        text(&o)
    );
}

#[test]
fn config_per_file_per_file_ignores_and_excludes() {
    let d = scratch("configs");
    std::fs::create_dir_all(d.join("strict")).unwrap();
    std::fs::create_dir_all(d.join("lax/legacy")).unwrap();
    std::fs::create_dir_all(d.join("lax/generated")).unwrap();
    for sub in ["strict", "lax", "lax/legacy", "lax/generated"] {
        std::fs::write(d.join(sub).join("fat.wgsl"), FAT_WGSL).unwrap();
    }
    std::fs::write(d.join("strict/rtlint.toml"), "[rules]\nRT001 = \"error\"\n").unwrap();
    std::fs::write(
        d.join("lax/rtlint.toml"),
        "payload-budget = 64\nexclude = [\"generated\"]\n[per-file-ignores]\n\"legacy/*.wgsl\" = [\"RT010\"]\n",
    )
    .unwrap();
    // Budget 64 in lax/: no RT001 there; RT001 is an error in strict/.
    let a = check_in(&d, &["strict", "lax"]);
    let b = check_in(&d, &["lax", "strict"]);
    assert_eq!(
        findings(&a),
        ["strict/fat.wgsl:2:8: error[RT001]"],
        "{}",
        text(&a)
    );
    assert_eq!(findings(&a), findings(&b), "argument order changes nothing");
    assert_eq!(a.status.code(), Some(1));
    // --no-config: the defaults everywhere, excludes included.
    let o = check_in(&d, &["--no-config", "."]);
    assert_eq!(findings(&o).len(), 4, "{}", text(&o));
    // --config: one file for all.
    let o = check_in(&d, &["--config", "strict/rtlint.toml", "lax"]);
    assert_eq!(findings(&o).len(), 3, "{}", text(&o));
    assert!(findings(&o).iter().all(|l| l.contains("error[RT001]")));
    // per-file-ignores: a selector that never fires on the file still
    // parses; RT001 ignored only under legacy/.
    std::fs::write(
        d.join("lax/rtlint.toml"),
        "exclude = [\"generated\"]\n[per-file-ignores]\n\"legacy/*.wgsl\" = [\"payload-over-budget\"]\n",
    )
    .unwrap();
    let o = check_in(&d, &["lax"]);
    assert_eq!(
        findings(&o),
        ["lax/fat.wgsl:2:8: warning[RT001]"],
        "{}",
        text(&o)
    );
    // A bad glob is an error in the config, with its position.
    std::fs::write(d.join("lax/rtlint.toml"), "exclude = [\"a[\"]\n").unwrap();
    let o = check_in(&d, &["lax"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("rtlint.toml:1"), "{}", text(&o));
}

#[test]
fn the_walk_respects_gitignore_survives_link_loops_and_reads_each_file_once() {
    let d = scratch("walk");
    std::fs::create_dir_all(d.join("a/b")).unwrap();
    std::fs::write(d.join("a/b/fat.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(d.join("a/ignored.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(d.join(".gitignore"), "ignored.wgsl\n").unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("..", d.join("a/b/up")).unwrap();
        std::os::unix::fs::symlink("../..", d.join("a/b/upup")).unwrap();
        std::os::unix::fs::symlink("b", d.join("a/again")).unwrap();
    }
    let o = check_in(&d, &[".", "a/b/fat.wgsl", "a/b/fat.wgsl"]);
    assert_eq!(
        findings(&o),
        ["a/b/fat.wgsl:2:8: warning[RT001]"],
        "{}",
        text(&o)
    );
    assert!(text(&o).contains("in 1 file"), "{}", text(&o));
    let o = check_in(&d, &["--no-gitignore", "."]);
    assert_eq!(findings(&o).len(), 2, "{}", text(&o));
}

#[test]
fn output_controls() {
    let d = scratch("output");
    std::fs::write(d.join("fat.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(d.join("strict.toml"), "[rules]\nRT001 = \"error\"\n").unwrap();
    // --exit-zero: findings do not fail; input errors still do.
    let o = check_in(&d, &["--config", "strict.toml", "fat.wgsl"]);
    assert_eq!(o.status.code(), Some(1));
    let o = check_in(&d, &["--config", "strict.toml", "--exit-zero", "fat.wgsl"]);
    assert_eq!(o.status.code(), Some(0));
    let o = check_in(&d, &["--exit-zero", "missing.wgsl"]);
    assert_eq!(o.status.code(), Some(2));
    // --statistics.
    let o = check_in(&d, &["--statistics", "fat.wgsl"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        "     1  RT001  payload-over-budget\n"
    );
    // --quiet: no summary line.
    let o = check_in(&d, &["--quiet", "fat.wgsl"]);
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        "fat.wgsl:2:8: warning[RT001] ray payload `Fat` is 48 bytes, above the 32-byte budget\n"
    );
    // --output-file: nothing on standard output.
    let o = check_in(&d, &["--output-file", "report.txt", "--quiet", "fat.wgsl"]);
    assert!(o.stdout.is_empty());
    let written = std::fs::read_to_string(d.join("report.txt")).unwrap();
    assert!(
        written.starts_with("fat.wgsl:2:8: warning[RT001]"),
        "{written}"
    );
    // No files: a warning, an error with --deny-warnings.
    std::fs::create_dir_all(d.join("empty")).unwrap();
    let o = check_in(&d, &["empty"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&o.stderr).contains("warning: no files to lint"));
    let o = check_in(&d, &["--deny-warnings", "empty"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn colour_follows_the_flag_and_the_environment() {
    let d = scratch("color");
    std::fs::write(d.join("fat.wgsl"), FAT_WGSL).unwrap();
    let run = |args: &[&str], env: &[(&str, &str)]| -> bool {
        let mut c = rtlint();
        c.current_dir(&d).arg("check").args(args).arg("fat.wgsl");
        for k in ["NO_COLOR", "FORCE_COLOR", "CLICOLOR_FORCE"] {
            c.env_remove(k);
        }
        for (k, v) in env {
            c.env(k, v);
        }
        c.output().unwrap().stdout.contains(&0x1b)
    };
    assert!(!run(&[], &[]), "not a terminal: no colour");
    assert!(run(&["--color", "always"], &[]));
    assert!(run(&[], &[("FORCE_COLOR", "1")]));
    assert!(run(&[], &[("CLICOLOR_FORCE", "1")]));
    assert!(!run(&[], &[("FORCE_COLOR", "1"), ("NO_COLOR", "1")]));
    assert!(!run(&["--color", "never"], &[("FORCE_COLOR", "1")]));
}

#[test]
fn standard_input_with_a_file_name() {
    let d = scratch("stdin");
    let mut child = rtlint()
        .current_dir(&d)
        .args([
            "check",
            "--format",
            "concise",
            "--stdin-filename",
            "shaders/fat.wgsl",
            "-",
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(FAT_WGSL.as_bytes())
        .unwrap();
    let o = child.wait_with_output().unwrap();
    assert_eq!(
        findings(&o),
        ["shaders/fat.wgsl:2:8: warning[RT001]"],
        "{}",
        text(&o)
    );
    // Without a name there is no language to read it as.
    let o = rtlint()
        .current_dir(&d)
        .args(["check", "-"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("--stdin-filename"), "{}", text(&o));
}

#[test]
fn a_closed_output_pipe_ends_quietly() {
    let d = scratch("pipe");
    for i in 0..200 {
        std::fs::write(d.join(format!("f{i:03}.wgsl")), FAT_WGSL).unwrap();
    }
    let mut child = rtlint()
        .current_dir(&d)
        .args(["check", "."])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read one byte, then hang up, as `| head -c1` does.
    let mut out = child.stdout.take().unwrap();
    let mut one = [0u8; 1];
    std::io::Read::read_exact(&mut out, &mut one).unwrap();
    drop(out);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(o.status.code(), Some(0), "{err}");
}

#[test]
fn sarif_is_valid_against_the_official_schema() {
    let schema = Path::new("/usr/local/share/rtlint/sarif-schema-2.1.0.json");
    let have_validator = if !schema.is_file() {
        Err(format!("{} is missing", schema.display()))
    } else if !Command::new("python3")
        .args(["-c", "import jsonschema"])
        .status()
        .is_ok_and(|s| s.success())
    {
        Err("python3 cannot import jsonschema".to_string())
    } else {
        Ok(())
    };
    if require("the SARIF schema validator", have_validator).is_none() {
        return;
    }
    let d = scratch("sarif dir");
    std::fs::write(d.join("fat shader.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(d.join("bad.spv"), [1u8, 2, 3]).unwrap();
    let cases: Vec<Vec<String>> = vec![
        // Findings with positions, relative paths with a space.
        vec!["fat shader.wgsl".into()],
        // An input error without a line; a pipeline finding.
        vec!["bad.spv".into()],
        // Absolute paths, and the repository's own fixtures.
        vec![d.join("fat shader.wgsl").display().to_string()],
        vec![root().join("fixtures").display().to_string()],
    ];
    for args in cases {
        let o = rtlint()
            .current_dir(&d)
            .args(["check", "--format", "sarif"])
            .args(&args)
            .output()
            .unwrap();
        let sarif: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let file = d.join("out.sarif");
        std::fs::write(&file, serde_json::to_vec(&sarif).unwrap()).unwrap();
        let v = Command::new("python3")
            .args([
                "-c",
                "import json, sys, jsonschema\n\
                 schema = json.load(open(sys.argv[1]))\n\
                 doc = json.load(open(sys.argv[2]))\n\
                 jsonschema.validate(doc, schema)\n\
                 def walk(v):\n\
                 \x20   if isinstance(v, dict):\n\
                 \x20       assert v != {} or True\n\
                 \x20       if 'region' in v: assert v['region'], 'empty region'\n\
                 \x20       [walk(x) for x in v.values()]\n\
                 \x20   elif isinstance(v, list): [walk(x) for x in v]\n\
                 walk(doc)\n",
            ])
            .arg(schema)
            .arg(&file)
            .output()
            .unwrap();
        assert!(
            v.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&v.stderr)
        );
        let run = &sarif["runs"][0];
        assert!(run["invocations"][0]["executionSuccessful"].is_boolean());
        for r in run["results"].as_array().unwrap() {
            assert!(r["partialFingerprints"].is_object());
            let uri = r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
                .as_str()
                .unwrap();
            assert!(!uri.contains(' '), "{uri}");
        }
    }
}

#[test]
fn github_annotations_carry_help_and_end_column() {
    let d = scratch("github");
    std::fs::write(d.join("fat.wgsl"), FAT_WGSL).unwrap();
    let o = rtlint()
        .current_dir(&d)
        .args(["check", "--format", "github", "fat.wgsl"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.starts_with("::warning title=rtlint (RT001),file=fat.wgsl,line=2,endLine=2,col=8,endColumn=11::ray payload `Fat` is 48 bytes"),
        "{out}"
    );
    assert!(out.contains("%0Ahelp: keep in the payload"), "{out}");
}

#[test]
fn json_outputs_carry_a_version() {
    let wgsl = root().join("shaders/reflect_iterative.wgsl");
    let wgsl = wgsl.to_str().unwrap();
    for cmd in ["check", "layout", "live", "stack"] {
        let o = rtlint()
            .args([cmd, "--format", "json", wgsl])
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&o.stdout)
            .unwrap_or_else(|e| panic!("{cmd}: {e}: {}", text(&o)));
        assert_eq!(v["version"], 1, "{cmd}");
    }
}

#[test]
fn output_is_the_same_whatever_the_thread_count() {
    let run = |threads: &str| {
        rtlint()
            .current_dir(root())
            .args(["check", "--format", "json", "fixtures", "shaders"])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap()
            .stdout
    };
    let one = run("1");
    assert!(one.len() > 1000);
    assert_eq!(one, run("4"));
    assert_eq!(one, run("4"));
}

#[test]
fn the_ci_recipe_is_valid_yaml() {
    let doc = std::fs::read_to_string(root().join("docs/ci.md")).unwrap();
    let start = doc.find("```yaml\n").expect("a yaml block") + 8;
    let end = start + doc[start..].find("```").unwrap();
    let yaml = &doc[start..end];
    let file = scratch("yaml").join("ci.yml");
    std::fs::write(&file, yaml).unwrap();
    let o = Command::new("python3")
        .args([
            "-c",
            "import sys, yaml\n\
             w = yaml.safe_load(open(sys.argv[1]))\n\
             steps = [s for j in w['jobs'].values() for s in j['steps']]\n\
             runs = ' '.join(s.get('run', '') for s in steps)\n\
             assert 'rtlint check' in runs and '--format github' in runs, runs\n\
             assert any('upload-sarif' in s.get('uses', '') for s in steps)\n",
        ])
        .arg(&file)
        .output()
        .unwrap();
    let missing = String::from_utf8_lossy(&o.stderr).contains("No module named 'yaml'");
    if missing && require("PyYAML", Err::<(), _>("python3 cannot import yaml")).is_none() {
        return;
    }
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_struct_in_a_shared_header_is_reported_once() {
    let d = scratch("header");
    std::fs::write(
        d.join("payload.hlsli"),
        "struct Fat {\n    float4 a;\n    float4 b;\n    float4 c;\n};\n",
    )
    .unwrap();
    let shader = |entry: &str| {
        format!(
            "#include \"payload.hlsli\"\nRaytracingAccelerationStructure tlas : register(t0);\nRWTexture2D<float4> image : register(u1);\n[shader(\"raygeneration\")]\nvoid {entry}()\n{{\n    RayDesc ray;\n    ray.Origin = float3(0.0, 0.0, 0.0);\n    ray.Direction = float3(0.0, 0.0, 1.0);\n    ray.TMin = 0.001;\n    ray.TMax = 10.0;\n    Fat p = (Fat)0;\n    TraceRay(tlas, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, ray, p);\n    image[DispatchRaysIndex().xy] = p.a;\n}}\n"
        )
    };
    std::fs::write(d.join("a.hlsl"), shader("A")).unwrap();
    std::fs::write(d.join("b.hlsl"), shader("B")).unwrap();
    let o = check_in(&d, &["."]);
    assert_eq!(
        findings(&o),
        ["payload.hlsli:1:8: warning[RT001]"],
        "{}",
        text(&o)
    );
    let o = check_in(&d, &["--select", "RT001", "a.hlsl", "b.hlsl", "a.hlsl"]);
    assert_eq!(findings(&o).len(), 1, "{}", text(&o));
    assert!(text(&o).contains("in 2 files"), "{}", text(&o));
}

/// glslang accepts a Latin-1 comment; so does rtlint, for GLSL sources as for
/// the modules glslang makes of them.
#[test]
fn glsl_sources_need_not_be_utf8() {
    let o = check_in(&root(), &["fixtures/live/latin1.rgen"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
}

/// `half` is 32-bit unless 16-bit types are enabled, on the command line
/// (`--enable-16bit-types`) or in `[hlsl]`; then it is 16-bit, and a 16-bit
/// construct not yet lowered (`asuint` of a `half`) is refused (exit 2),
/// never silently widened.
#[test]
fn sixteen_bit_types_follow_the_flag_and_the_config() {
    let d = scratch("half");
    let src = "RWStructuredBuffer<uint> o : register(u0);\n[numthreads(1,1,1)]\nvoid m() { half h = 0.5; o[0] = asuint(h); }\n";
    std::fs::write(d.join("m.hlsl"), src).unwrap();
    assert_eq!(check_in(&d, &["m.hlsl"]).status.code(), Some(0));
    let o = check_in(&d, &["--enable-16bit-types", "m.hlsl"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("not supported: `asuint` of 16-bit values"),
        "{}",
        text(&o)
    );
    std::fs::write(d.join("rtlint.toml"), "[hlsl]\nenable-16bit-types = true\n").unwrap();
    assert_eq!(check_in(&d, &["m.hlsl"]).status.code(), Some(2));
    // `compile` reads the flag: `half` becomes OpTypeFloat 16.
    let scalar = "RWStructuredBuffer<float> o : register(u0);\n[numthreads(1,1,1)]\nvoid m() { half h = 0.5; o[0] = h; }\n";
    std::fs::write(d.join("s.hlsl"), scalar).unwrap();
    let out = d.join("s.spv");
    let compile = |extra: &[&str]| {
        let o = rtlint()
            .arg("compile")
            .arg(d.join("s.hlsl"))
            .args(extra)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        let words = rtlint_testkit::words_of_bytes(&std::fs::read(&out).unwrap());
        // OpTypeFloat (22, 3 words) of width 16.
        words
            .windows(3)
            .any(|w| w[0] == (3 << 16 | 22) && w[2] == 16)
    };
    assert!(!compile(&[]));
    assert!(compile(&["--enable-16bit-types"]));
}

/// `--statistics` speaks each format: JSON's `statistics`, SARIF's run
/// properties (also through `-o x.sarif`), a GitHub notice and job summary;
/// the counts are those of the findings a plain run lists.
#[test]
fn statistics_in_every_format() {
    let d = scratch("statistics");
    std::fs::write(d.join("a.wgsl"), FAT_WGSL).unwrap();
    std::fs::write(d.join("b.wgsl"), FAT_WGSL).unwrap();
    let plain = check_in(&d, &["--no-cache", "."]);
    let listed = findings(&plain).len();
    assert_eq!(listed, 2, "{}", text(&plain));
    let run = |args: &[&str]| {
        rtlint()
            .current_dir(&d)
            .args(["check", "--no-cache", "--statistics"])
            .args(args)
            .arg(".")
            .env("GITHUB_STEP_SUMMARY", d.join("summary.md"))
            .output()
            .unwrap()
    };
    let o = run(&["--format", "json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    assert_eq!(v["statistics"][0]["code"], "RT001", "{v}");
    assert_eq!(v["statistics"][0]["count"], listed, "{v}");
    assert_eq!(v["diagnostics"].as_array().unwrap().len(), 0, "{v}");

    let o = run(&["--format", "sarif", "-o", "x.sarif"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let v: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("x.sarif")).unwrap()).expect("SARIF");
    assert_eq!(v["version"], "2.1.0");
    let run0 = &v["runs"][0];
    assert_eq!(run0["results"].as_array().unwrap().len(), 0);
    assert_eq!(run0["properties"]["statistics"][0]["ruleId"], "RT001");
    assert_eq!(run0["properties"]["statistics"][0]["count"], listed);

    let o = run(&["--format", "github"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        out,
        format!("::notice title=rtlint statistics::{listed} RT001 payload-over-budget\n")
    );
    let summary = std::fs::read_to_string(d.join("summary.md")).unwrap();
    assert!(
        summary.contains(&format!("| {listed} | RT001 | payload-over-budget |")),
        "{summary}"
    );
}

/// Two traces with the same invalid interval in a module without debug
/// info: two findings, not one (they are two places, even without lines).
#[test]
fn alike_findings_without_positions_stay_apart() {
    let d = scratch("alike");
    let src = d.join("two.rgen");
    std::fs::write(
        &src,
        "#version 460\n#extension GL_EXT_ray_tracing : require\n\
layout(location = 0) rayPayloadEXT vec4 p;\n\
layout(binding = 0) uniform accelerationStructureEXT tlas;\n\
layout(binding = 1, rgba8) uniform image2D img;\n\
void main() {\n\
    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3(0.0), 10.0, vec3(0.0, 0.0, 1.0), 1.0, 0);\n\
    vec4 a = p;\n\
    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3(1.0), 10.0, vec3(0.0, 0.0, 1.0), 1.0, 0);\n\
    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p + a);\n\
}\n",
    )
    .unwrap();
    let compiled = Command::new("glslangValidator")
        .args(["-V", "--target-env", "vulkan1.2", "-o"])
        .arg(d.join("two.spv"))
        .arg(&src)
        .output()
        .map_err(|e| e.to_string())
        .and_then(|g| {
            if g.status.success() {
                Ok(())
            } else {
                Err(text(&g))
            }
        });
    if require("glslangValidator", compiled).is_none() {
        return;
    }
    let o = check_in(&d, &["--no-cache", "--select", "RT035", "two.spv"]);
    assert_eq!(
        findings(&o),
        ["two.spv: error[RT035]", "two.spv: error[RT035]"],
        "{}",
        text(&o)
    );
    let o = check_in(&d, &["--no-cache", "--select", "RT035", "two.rgen"]);
    assert_eq!(
        findings(&o),
        ["two.rgen:7:1: error[RT035]", "two.rgen:9:1: error[RT035]"],
        "{}",
        text(&o)
    );
}

/// A struct in a header two `-g` modules include is one finding at the
/// header, also when the header is found twice (the copy beside the
/// modules and the original their debug info names): the copies' identical
/// declarations are one place, not an ambiguity that loses the position
/// and gives one finding per module.
#[test]
fn a_header_struct_in_g_modules_is_reported_once() {
    let d = scratch("g-header");
    std::fs::create_dir_all(d.join("src")).unwrap();
    std::fs::create_dir_all(d.join("out")).unwrap();
    let header = "struct Fat { vec4 a; vec4 b; vec4 c; };\n";
    std::fs::write(d.join("src/fat.glsl"), header).unwrap();
    std::fs::write(d.join("out/fat.glsl"), header).unwrap();
    for (name, origin) in [("a", "0.0"), ("b", "1.0")] {
        std::fs::write(
            d.join(format!("src/{name}.rgen")),
            format!("#version 460\n#extension GL_EXT_ray_tracing : require\n#extension GL_GOOGLE_include_directive : require\n#include \"fat.glsl\"\nlayout(location = 0) rayPayloadEXT Fat p;\nlayout(binding = 0) uniform accelerationStructureEXT tlas;\nlayout(binding = 1, rgba8) uniform image2D img;\nvoid main() {{\n    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3({origin}), 0.001, vec3(0.0, 0.0, 1.0), 100.0, 0);\n    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p.a);\n}}\n"),
        )
        .unwrap();
        let g = Command::new("glslangValidator")
            .current_dir(&d)
            .args(["-V", "--target-env", "vulkan1.2", "-g", "-o"])
            .arg(format!("out/{name}.spv"))
            .arg(format!("src/{name}.rgen"))
            .output()
            .map_err(|e| e.to_string())
            .and_then(|g| {
                if g.status.success() {
                    Ok(())
                } else {
                    Err(text(&g))
                }
            });
        if require("glslangValidator", g).is_none() {
            return;
        }
    }
    let o = check_in(&d, &["--no-cache", "--select", "RT001", "out"]);
    assert_eq!(
        findings(&o),
        ["out/fat.glsl:1:8: warning[RT001]"],
        "{}",
        text(&o)
    );
}

/// A payload struct in a GLSL header two shaders include: one finding (one
/// SARIF result, one annotation) at the header, listing both includers'
/// traces as evidence.
#[test]
fn a_glsl_header_finding_lists_every_includer() {
    let d = scratch("glsl-header");
    std::fs::write(
        d.join("fat.glsl"),
        "struct Fat { vec4 a; vec4 b; vec4 c; };\n",
    )
    .unwrap();
    for (name, origin) in [("a", "0.0"), ("b", "1.0")] {
        std::fs::write(
            d.join(format!("{name}.rgen")),
            format!("#version 460\n#extension GL_EXT_ray_tracing : require\n#extension GL_GOOGLE_include_directive : require\n#include \"fat.glsl\"\nlayout(location = 0) rayPayloadEXT Fat p;\nlayout(binding = 0) uniform accelerationStructureEXT tlas;\nlayout(binding = 1, rgba8) uniform image2D img;\nvoid main() {{\n    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3({origin}), 0.001, vec3(0.0, 0.0, 1.0), 100.0, 0);\n    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p.a);\n}}\n"),
        )
        .unwrap();
    }
    let have = Command::new("glslangValidator")
        .arg("--version")
        .output()
        .map(|_| ())
        .map_err(|e| e.to_string());
    if require("glslangValidator", have).is_none() {
        return;
    }
    let o = rtlint()
        .current_dir(d.parent().unwrap())
        .args([
            "check",
            "--no-cache",
            "--select",
            "RT001",
            "--format",
            "sarif",
        ])
        .arg(d.file_name().unwrap())
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("SARIF");
    let results = v["runs"][0]["results"].as_array().unwrap();
    assert_eq!(results.len(), 1, "{v}");
    let related: Vec<String> = results[0]["relatedLocations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            let uri = l["physicalLocation"]["artifactLocation"]["uri"]
                .as_str()
                .unwrap();
            uri.rsplit('/').next().unwrap().to_string()
        })
        .collect();
    assert_eq!(related, ["a.rgen", "b.rgen"], "{v}");
    let o = rtlint()
        .current_dir(d.parent().unwrap())
        .args([
            "check",
            "--no-cache",
            "--select",
            "RT001",
            "--format",
            "github",
        ])
        .arg(d.file_name().unwrap())
        .output()
        .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&o.stdout).lines().count(),
        1,
        "{}",
        text(&o)
    );
}
