//! Snapshots of the command line's other outputs: `check` as JSON, SARIF
//! and GitHub annotations, and the text of `layout`, `live` and `stack`.
//! (The human `check` output is snapshotted per fixture in fixtures.rs.)
//! Each snapshot holds the command, its exit code, stdout and stderr; paths
//! are relative to the crate root, where the command runs.
//! `RTLINT_BLESS=1` rewrites them; review the diff.

mod common;

use common::{root, rtlint, snapshot};

/// Runs `rtlint args` in the crate root and snapshots what it printed.
fn snapshot_run(name: &str, args: &[&str]) -> String {
    let o = rtlint().args(args).output().unwrap();
    let stdout = String::from_utf8(o.stdout).unwrap();
    let stderr = String::from_utf8(o.stderr).unwrap();
    assert!(!stderr.contains("panicked"), "{stderr}");
    let code = o.status.code().map_or("none".into(), |c| c.to_string());
    let text = format!(
        "$ rtlint {}\nexit code {code}\n--- stdout\n{stdout}--- stderr\n{stderr}",
        args.join(" ")
    );
    assert!(
        !text.contains(&root().display().to_string()),
        "{name}: an absolute path would make the snapshot depend on the checkout:\n{text}"
    );
    snapshot(name, &text);
    stdout
}

/// A shader of each input language, and a pipeline description with an error.
const CHECKED: [&str; 3] = [
    "fixtures/glsl/payloads.rgen.gV.spv",
    "fixtures/RT001/bad.wgsl",
    "fixtures/RT021/bad.pipeline.toml",
];

#[test]
fn check_json() {
    let out = snapshot_run(
        "outputs__check_json",
        &[&["check", "--format", "json"], &CHECKED[..]].concat(),
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["summary"]["errors"], 1, "{v}");
}

#[test]
fn check_github() {
    let out = snapshot_run(
        "outputs__check_github",
        &[&["check", "--format", "github"], &CHECKED[..]].concat(),
    );
    assert!(out.lines().all(|l| l.starts_with("::")), "{out}");
}

/// SARIF carries every rule's page as its help text: checked here against
/// rules/*.md and left out of the snapshot, which would otherwise repeat them.
#[test]
fn check_sarif() {
    let o = rtlint()
        .args([&["check", "--format", "sarif"], &CHECKED[..]].concat())
        .output()
        .unwrap();
    let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rules = v["runs"][0]["tool"]["driver"]["rules"]
        .as_array_mut()
        .unwrap();
    assert!(rules.len() >= 12, "{rules:?}");
    for r in rules {
        let code = r["id"].as_str().unwrap().to_string();
        let page = std::fs::read_to_string(root().join(format!("rules/{code}.md"))).unwrap();
        for key in ["text", "markdown"] {
            assert_eq!(r["help"][key].as_str(), Some(page.as_str()), "{code} {key}");
            r["help"][key] = format!("<rules/{code}.md>").into();
        }
    }
    let code = o.status.code().map_or("none".into(), |c| c.to_string());
    let text = format!(
        "$ rtlint check --format sarif {}\nexit code {code}\n(rule help texts replaced by the page they equal)\n--- stdout\n{}\n--- stderr\n{}",
        CHECKED.join(" "),
        serde_json::to_string_pretty(&v).unwrap(),
        String::from_utf8(o.stderr).unwrap()
    );
    snapshot("outputs__check_sarif", &text);
}

#[test]
fn layout_text() {
    snapshot_run(
        "outputs__layout",
        &[
            "layout",
            "fixtures/glsl/payloads.rgen.g.spv",
            "fixtures/hlsl/payloads.hlsl",
            "fixtures/RT001/bad.wgsl",
        ],
    );
}

#[test]
fn live_text() {
    snapshot_run(
        "outputs__live",
        // Named one by one: a directory walk would also compile the GLSL
        // sources beside the modules, and so depend on glslang.
        &[
            "live",
            "fixtures/live/lets.wgsl",
            "fixtures/live/loop.rgen.spv",
            "fixtures/live/query.rgen.spv",
            "fixtures/live/seed.rchit.spv",
            "shaders/reflect_recursive.wgsl",
        ],
    );
}

#[test]
fn stack_text() {
    snapshot_run(
        "outputs__stack",
        &[
            "stack",
            "shaders/reflect_recursive.pipeline.toml",
            "fixtures/pipelines/callable.pipeline.toml",
            "fixtures/pipelines/procedural.pipeline.toml",
        ],
    );
    // Loose shaders: no description, every trace assumed to reach every shader.
    snapshot_run(
        "outputs__stack_loose",
        &["stack", "shaders/reflect_recursive.wgsl"],
    );
}
