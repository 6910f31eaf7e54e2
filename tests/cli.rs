//! The command line: exit codes, bad input of every class, JSON contracts.

mod common;

use common::{read_words, rtlint};
use std::path::{Path, PathBuf};
use std::process::Output;

fn run(args: &[&str]) -> Output {
    rtlint().args(args).output().unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write_words(path: &Path, w: &[u32]) {
    std::fs::write(
        path,
        w.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
}

/// A bad input: exit code 2, never a panic, and a message naming the file.
fn assert_input_error(path: &Path, expect: &[&str]) -> String {
    let o = run(&["check", path.to_str().unwrap()]);
    let text = stdout(&o) + &String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{}: {text}", path.display());
    assert!(!text.contains("panicked"), "{text}");
    assert!(
        text.contains(path.file_name().unwrap().to_str().unwrap()),
        "names the file: {text}"
    );
    for e in expect {
        assert!(text.contains(e), "expected `{e}` in: {text}");
    }
    text
}

fn good_module() -> Vec<u32> {
    read_words(&common::root().join("fixtures/RT001/good.rgen.g.spv"))
}

#[test]
fn exit_codes() {
    // Warnings only: 0.
    let o = run(&["check", "fixtures/RT001/bad.rgen.gV.spv"]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    assert!(stdout(&o).contains("warning[RT001]"));
    // --deny-warnings: 1.
    let o = run(&["check", "--deny-warnings", "fixtures/RT001/bad.rgen.gV.spv"]);
    assert_eq!(o.status.code(), Some(1));
    // An error-level finding: 1.
    let o = run(&["check", "fixtures/RT004/bad.rint.gV.spv"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stdout(&o).contains("error[RT004]"));
    // A larger budget silences RT001.
    let o = run(&[
        "check",
        "--payload-budget",
        "64",
        "fixtures/RT001/bad.rgen.gV.spv",
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert!(!stdout(&o).contains("RT001"), "{}", stdout(&o));
    assert!(stdout(&o).contains("0 errors, 0 warnings in 1 file"));
}

#[test]
fn config_file_sets_levels() {
    let d = scratch("config");
    std::fs::copy(
        common::root().join("fixtures/RT001/bad.wgsl"),
        d.join("a.wgsl"),
    )
    .unwrap();
    std::fs::write(
        d.join("rtlint.toml"),
        "[rules]\npayload-over-budget = \"error\"\n",
    )
    .unwrap();
    let o = run(&["check", d.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(stdout(&o).contains("error[RT001]"));
    std::fs::write(d.join("rtlint.toml"), "[rules]\nRT001 = \"allow\"\n").unwrap();
    let o = run(&["check", d.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    assert!(!stdout(&o).contains("RT001"));
    std::fs::write(d.join("rtlint.toml"), "[rules]\nRT001 = \"loud\"\n").unwrap();
    let text = assert_input_error(&d, &["rtlint.toml:2:"]);
    assert!(text.contains("loud"), "{text}");
}

#[test]
fn directories_are_walked_and_bad_files_do_not_hide_good_ones() {
    let d = scratch("walk");
    std::fs::copy(
        common::root().join("fixtures/RT001/bad.wgsl"),
        d.join("a.wgsl"),
    )
    .unwrap();
    std::fs::write(d.join("b.wgsl"), "fn main( {").unwrap();
    std::fs::write(d.join("notes.txt"), "not a shader").unwrap();
    // A header has no entry points of its own: skipped when walking.
    std::fs::write(d.join("common.hlsli"), "struct Shared { float3 c; };\n").unwrap();
    let o = run(&["check", "-v", d.to_str().unwrap()]);
    let text = stdout(&o);
    assert_eq!(o.status.code(), Some(2), "{text}");
    assert!(text.contains("warning[RT001]"), "{text}");
    assert!(text.contains("b.wgsl:1:"), "{text}");
    assert!(
        text.contains("skipped") && text.contains("notes.txt"),
        "{text}"
    );
    assert!(text.contains("in 2 files"), "{text}");
}

#[test]
fn missing_file_and_unknown_language() {
    let d = scratch("missing");
    assert_input_error(&d.join("nope.wgsl"), &["cannot read file"]);
    std::fs::write(d.join("shader.frag"), "void main() {}").unwrap();
    assert_input_error(&d.join("shader.frag"), &["--lang"]);
}

#[test]
fn bad_wgsl() {
    let d = scratch("wgsl");
    std::fs::write(
        d.join("parse.wgsl"),
        "enable wgpu_ray_tracing_pipeline;\nfn f() -> f32 {\n    return 1.0 +;\n}\n",
    )
    .unwrap();
    assert_input_error(&d.join("parse.wgsl"), &["parse.wgsl:3:"]);
    std::fs::write(d.join("valid.wgsl"), "fn f() -> f32 {\n    return 1u;\n}\n").unwrap();
    assert_input_error(
        &d.join("valid.wgsl"),
        &["valid.wgsl:", "invalid WGSL module"],
    );
    std::fs::write(d.join("utf8.wgsl"), b"fn f() {}\n\xff\xfe").unwrap();
    let t = assert_input_error(&d.join("utf8.wgsl"), &["UTF-8", "line 2, column 1"]);
    assert!(t.contains("utf8.wgsl:2:1"), "{t}");
    assert!(!t.contains("offset"), "{t}");
}

#[test]
fn bad_spirv_every_class() {
    let d = scratch("spirv");
    let good = good_module();

    std::fs::write(d.join("short.spv"), [3u8, 2, 0x23, 7]).unwrap();
    assert_input_error(&d.join("short.spv"), &["shorter than the 5-word header"]);

    let mut bytes: Vec<u8> = good.iter().flat_map(|x| x.to_le_bytes()).collect();
    bytes.pop();
    std::fs::write(d.join("odd.spv"), &bytes).unwrap();
    assert_input_error(&d.join("odd.spv"), &["not a whole number of 32-bit words"]);

    let mut w = good.clone();
    w[0] = 0xdead_beef;
    write_words(&d.join("magic.spv"), &w);
    assert_input_error(&d.join("magic.spv"), &["magic number", "word 0"]);

    let mut w = good.clone();
    w.insert(5, 0);
    write_words(&d.join("zero.spv"), &w);
    assert_input_error(&d.join("zero.spv"), &["word 5", "word count of 0"]);

    let mut w = good.clone();
    w.push((5 << 16) | 1);
    let at = w.len() - 1;
    write_words(&d.join("truncated.spv"), &w);
    assert_input_error(
        &d.join("truncated.spv"),
        &["truncated", &format!("word {at}")],
    );

    let mut w = good.clone();
    w.insert(5, (1 << 16) | 0x7ff0);
    write_words(&d.join("opcode.spv"), &w);
    assert_input_error(&d.join("opcode.spv"), &["unknown opcode 32752", "word 5"]);

    // Point the entry point at an id nothing defines (raising the bound so
    // only the dangling reference is wrong).
    let mut w = good.clone();
    let bound = w[3];
    w[3] = bound + 10;
    let mut i = 5;
    while i < w.len() {
        if w[i] & 0xffff == 15 {
            w[i + 2] = bound + 5; // OpEntryPoint model, function id
            break;
        }
        i += (w[i] >> 16) as usize;
    }
    write_words(&d.join("dangling.spv"), &w);
    assert_input_error(
        &d.join("dangling.spv"),
        &[
            &format!("%{} is used but never defined", bound + 5),
            &format!("word {i}"),
        ],
    );
}

#[test]
fn unknown_format_and_rule() {
    let o = run(&["check", "--format", "xml", "fixtures"]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&["rule", "RT999"]);
    assert_eq!(o.status.code(), Some(2));
    let o = run(&["rule", "rt002"]);
    assert_eq!(o.status.code(), Some(0));
    assert!(stdout(&o).contains("## What it does"));
    let o = run(&["rules"]);
    assert!(stdout(&o).contains("RT005  ray-query-null-constant"));
}

#[test]
fn json_check_contract() {
    let o = run(&[
        "check",
        "--format",
        "json",
        // HLSL: RT002 and RT003 (whose fix is checked below) judge HLSL
        // payloads only.
        "fixtures/hlsl/payloads.hlsl",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let diags = v["diagnostics"].as_array().unwrap();
    let codes: Vec<&str> = diags.iter().map(|d| d["code"].as_str().unwrap()).collect();
    assert_eq!(codes, ["RT001", "RT002", "RT003"]);
    let d = &diags[0];
    for key in [
        "code",
        "name",
        "severity",
        "message",
        "path",
        "line",
        "column",
        "end_line",
        "end_column",
        "notes",
        "help",
    ] {
        assert!(d.get(key).is_some(), "missing key {key}");
    }
    assert_eq!(d["path"], "fixtures/hlsl/payloads.hlsl");
    assert_eq!(d["line"], 2);
    assert_eq!(d["severity"], "warning");
    assert_eq!(
        diags[1]["fix"]
            .as_str()
            .unwrap()
            .lines()
            .nth(1)
            .unwrap()
            .trim(),
        "float3 color;"
    );
    assert_eq!(v["summary"]["warnings"], 3);
    assert_eq!(v["summary"]["files"], 1);
}

#[test]
fn json_layout_contract() {
    let o = run(&[
        "layout",
        "--format",
        "json",
        "fixtures/glsl/payloads.rgen.g.spv",
    ]);
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let f = &v["files"][0];
    assert_eq!(f["path"], "fixtures/glsl/payloads.rgen.g.spv");
    assert_eq!(f["language"], "glsl");
    let t = &f["types"][0];
    assert_eq!(t["name"], "SuboptimalPayload");
    assert_eq!(t["roles"], serde_json::json!(["ray_payload"]));
    assert_eq!(t["scalar_size"], 44);
    assert_eq!(t["hlsl_packed_size"], 56);
    assert_eq!(t["hlsl_rows"], 4);
    assert_eq!(
        t["optimal_order"],
        serde_json::json!(["color", "hitT", "uv", "depth", "hit", "normal"])
    );
    assert_eq!(t["optimal_hlsl_packed_size"], 44);
    let uv = &t["members"][1];
    assert_eq!(uv["name"], "uv");
    assert_eq!(uv["ty"], "vec2");
    assert_eq!(uv["size"], 8);
    assert_eq!(uv["scalar_offset"], 12);
    assert_eq!(uv["hlsl_packed_offset"], 16);
    assert_eq!(uv["straddles"], true);
    let slim = &f["types"][1];
    assert_eq!(slim["name"], "OptimizedPayload");
    assert_eq!(
        (
            slim["scalar_size"].as_u64(),
            slim["hlsl_packed_size"].as_u64()
        ),
        (Some(16), Some(16))
    );
}

/// With --enable-16bit-types a payload's `half` and `uint16_t` members are
/// 2 bytes each in `rtlint layout` (without it `half` is a 4-byte float).
#[test]
fn layout_counts_16_bit_members() {
    let o = run(&[
        "layout",
        "--enable-16bit-types",
        "--format",
        "json",
        "tests/hlsl/half.hlsl",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stdout(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let types = v["files"][0]["types"].as_array().unwrap();
    let t = types
        .iter()
        .find(|t| t["name"] == "HalfPayload")
        .expect("HalfPayload");
    assert_eq!(t["scalar_size"], 10);
    assert_eq!(t["hlsl_packed_size"], 10);
    let members: Vec<(String, u64, u64)> = t["members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            (
                m["ty"].as_str().unwrap().to_string(),
                m["size"].as_u64().unwrap(),
                m["scalar_offset"].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        members,
        vec![
            ("half3".to_string(), 6, 0),
            ("half".to_string(), 2, 6),
            ("uint16_t".to_string(), 2, 8)
        ]
    );
}

#[test]
fn github_and_sarif_formats() {
    let o = run(&["check", "--format", "github", "fixtures/RT001/bad.wgsl"]);
    let text = stdout(&o);
    assert!(
        text.starts_with("::warning title=rtlint (RT001),file=fixtures/RT001/bad.wgsl,line=4,"),
        "{text}"
    );
    let o = run(&["check", "--format", "sarif", "fixtures/RT001/bad.wgsl"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["version"], "2.1.0");
    let results = v["runs"][0]["results"].as_array().unwrap();
    assert_eq!(results.len(), 1);
    assert_eq!(results[0]["ruleId"], "RT001");
    assert_eq!(
        results[0]["locations"][0]["physicalLocation"]["region"]["startLine"],
        4
    );
}

/// What `cargo install` builds is lean: the release profile keeps no debug
/// info (an 80 MB binary with it); profiling has its own profile with line
/// tables, and the docs that profile name it.
#[test]
fn the_release_profile_is_lean_and_profiling_has_its_own() {
    let manifest: toml::Table =
        toml::from_str(&std::fs::read_to_string(common::root().join("Cargo.toml")).unwrap())
            .unwrap();
    let profiles = manifest["profile"].as_table().unwrap();
    let release = profiles["release"].as_table().unwrap();
    let off = |v: Option<&toml::Value>| match v {
        None => true,
        Some(toml::Value::Boolean(b)) => !b,
        Some(toml::Value::Integer(n)) => *n == 0,
        Some(toml::Value::String(s)) => s == "none",
        Some(_) => false,
    };
    assert!(off(release.get("debug")), "{release:?}");
    let profiling = profiles["profiling"].as_table().unwrap();
    assert_eq!(profiling["inherits"].as_str(), Some("release"));
    assert!(!off(profiling.get("debug")), "{profiling:?}");
    let perf = std::fs::read_to_string(common::root().join("docs/performance.md")).unwrap();
    assert!(perf.contains("--profile profiling"));
}

/// `rtlint rules` is a table: every column starts at the same place on
/// every line, however long a rule's name.
#[test]
fn the_rules_table_is_aligned() {
    let text = stdout(&run(&["rules"]));
    let starts = |line: &str| -> Vec<usize> {
        let mut v = Vec::new();
        let b = line.as_bytes();
        for i in 1..b.len() {
            if b[i] != b' ' && b[i - 1] == b' ' && i >= 2 && b[i - 2] == b' ' {
                v.push(line[..i].chars().count());
            }
        }
        v.truncate(4);
        v
    };
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), rtlint::rules::RULES.len());
    let first = starts(lines[0]);
    assert_eq!(first.len(), 4, "{}", lines[0]);
    for l in &lines {
        assert_eq!(starts(l), first, "`{l}`");
    }
}

/// `verify --help` says what `--out` receives: every case's GPU image, not
/// only failed cases' (src/verify writes `CASE-gpu.png` for each case).
#[test]
fn verify_help_says_every_case_writes_its_image() {
    let help = stdout(&run(&["verify", "--help"])).replace(char::is_whitespace, " ");
    let help = help.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(help.contains("each case's GPU image"), "{help}");
    assert!(!help.contains("images of failed cases"), "{help}");
}
