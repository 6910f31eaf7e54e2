//! Every fixture yields exactly the findings its `//~ CODE` markers name, on
//! the marked lines, from WGSL and from glslang's `-g` and `-gV` SPIR-V alike;
//! the rendered output matches its reviewed snapshot.

mod common;

use common::root;
use rtlint::config::Config;
use rtlint::lint::check_input;
use rtlint::report::{human, Sources};
use rtlint::shader::Language;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// (line, code) pairs marked in a source file (`//~ CODE` or `#~ CODE`).
fn markers(source: &Path) -> BTreeSet<(u32, String)> {
    placed_markers(source)
        .into_iter()
        .filter(|(p, _, _)| p == source)
        .map(|(_, l, c)| (l, c))
        .collect()
}

/// Markers with their file: `#~ CODE` on a line marks that line;
/// `#~ CODE @ rel/path:LINE` marks a line of another file (a shader a
/// pipeline description uses), relative to the marking file.
fn placed_markers(source: &Path) -> BTreeSet<(PathBuf, u32, String)> {
    let text = std::fs::read_to_string(source).unwrap();
    let mut out = BTreeSet::new();
    for (i, line) in text.lines().enumerate() {
        let Some(at) = line.find("//~").or_else(|| line.find("#~")) else {
            continue;
        };
        let rest = line[at..].trim_start_matches(['/', '#', '~']);
        match rest.split_once('@') {
            Some((codes, place)) => {
                let (file, l) = place.trim().rsplit_once(':').unwrap();
                let path = rtlint::program::debug::normalize(&source.parent().unwrap().join(file));
                for code in codes.split_whitespace() {
                    out.insert((path.clone(), l.parse().unwrap(), code.to_string()));
                }
            }
            None => {
                for code in rest.split_whitespace() {
                    out.insert((source.to_path_buf(), i as u32 + 1, code.to_string()));
                }
            }
        }
    }
    out
}

/// Each module to check with the source holding its markers.
fn cases() -> Vec<(PathBuf, PathBuf)> {
    let mut cases = Vec::new();
    for dir in [
        "fixtures/glsl",
        "fixtures/hlsl",
        "fixtures/RT001",
        "fixtures/RT004",
        "fixtures/RT005",
        "fixtures/RT010",
    ] {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_str().unwrap().to_string();
            if name.ends_with(".wgsl") || name.ends_with(".hlsl") {
                cases.push((p.clone(), p));
            } else if let Some(src) = name
                .strip_suffix(".g.spv")
                .or_else(|| name.strip_suffix(".gV.spv"))
                .or_else(|| name.strip_suffix(".spv"))
            {
                cases.push((p.clone(), p.with_file_name(src)));
            }
        }
    }
    cases
}

fn relative(p: &Path) -> PathBuf {
    p.strip_prefix(root()).unwrap_or(p).to_path_buf()
}

/// Rendered text with the crate root taken off every path, so snapshots read
/// as a user in the crate root would see them (no working directory is
/// changed: tests run in parallel).
fn relative_text(text: &str) -> String {
    text.replace(&format!("{}/", root().display()), "")
}

#[test]
fn findings_match_markers_and_snapshots() {
    let config = Config::default();
    let cases = cases();
    assert!(cases.len() >= 15, "fixtures missing: {}", cases.len());
    let mut failures = Vec::new();
    for (module, source) in cases {
        let language = Language::from_path(&module).unwrap();
        let checked = check_input(&module, language, &config);
        assert!(
            checked.program.is_some(),
            "{} did not load: {:?}",
            module.display(),
            checked.diagnostics
        );
        let src_name = source.file_name().unwrap();
        let actual: BTreeSet<(u32, String)> = checked
            .diagnostics
            .iter()
            .map(|d| {
                let p = d.primary.as_ref().unwrap_or_else(|| {
                    panic!("{}: finding without a position: {d:?}", module.display())
                });
                assert_eq!(
                    p.location.path.file_name(),
                    Some(src_name),
                    "{}",
                    module.display()
                );
                (p.location.line, d.code.unwrap().to_string())
            })
            .collect();
        for d in &checked.diagnostics {
            style_problems(d, &mut failures);
        }
        let expected = markers(&source);
        if actual != expected {
            failures.push(format!(
                "{}: expected {expected:?}, got {actual:?}",
                module.display()
            ));
        }
        let mut sources = Sources::default();
        if let Some(p) = &checked.program {
            sources.add_program(p);
        }
        let mut buf = codespan_reporting::term::termcolor::NoColor::new(Vec::new());
        human::render(&checked.diagnostics, &mut sources, &mut buf).unwrap();
        let text = relative_text(&String::from_utf8(buf.into_inner()).unwrap());
        let name = relative(&module)
            .to_string_lossy()
            .replace(['/', '\\'], "__");
        common::snapshot(&name, &text);
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

// Pipeline descriptions under fixtures/RTnnn/ run with only their rule
// selected in tests/rule_fixtures.rs.

#[test]
fn every_rule_has_bad_and_good_fixtures() {
    for rule in rtlint::rules::RULES {
        let mut bad = false;
        let mut good = false;
        // Per-rule folders: fixtures/RT0xx/bad.* and good.*.
        if let Ok(rd) = std::fs::read_dir(root().join("fixtures").join(rule.code)) {
            for e in rd {
                let p = e.unwrap().path();
                let name = p.file_name().unwrap().to_str().unwrap().to_string();
                if name.ends_with(".spv") || name.ends_with(".sh") {
                    continue;
                }
                if name.starts_with("bad") {
                    bad |= placed_markers(&p).iter().any(|(_, _, c)| c == rule.code);
                }
                good |= name.starts_with("good");
            }
        }
        assert!(bad, "{} has no bad fixture marking it", rule.code);
        assert!(good, "{} has no good fixture", rule.code);
    }
}

#[test]
fn glsl_fixture_modules_are_current_and_valid() {
    // Every GLSL fixture compiled twice has both forms, and each passes
    // spirv-val.
    let validate = rtlint_testkit::tool("spirv-val");
    for (dir, script) in [
        ("fixtures/glsl", "regenerate.sh"),
        ("fixtures/RT001", "build.sh"),
        ("fixtures/RT004", "build.sh"),
    ] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_str().unwrap().to_string();
            if name.ends_with(".spv") {
                if validate {
                    common::spirv_val(&common::read_words(&p))
                        .unwrap_or_else(|e| panic!("{name}: {e}"));
                }
                continue;
            }
            let stages = [".rgen", ".rchit", ".rmiss", ".rahit", ".rint", ".rcall"];
            if !stages.iter().any(|s| name.ends_with(s)) {
                continue;
            }
            for suffix in ["g.spv", "gV.spv"] {
                let m = p.with_file_name(format!("{name}.{suffix}"));
                assert!(m.exists(), "{} is missing: run {dir}/{script}", m.display());
            }
        }
    }
}

#[test]
fn wgsl_fixtures_compile_to_valid_spirv_except_the_null_ray_query() {
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    for dir in ["fixtures/RT001", "fixtures/RT005"] {
        for e in std::fs::read_dir(root().join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "wgsl") {
                wgsl_valid(&p);
            }
        }
    }
}

fn wgsl_valid(p: &Path) {
    let text = std::fs::read_to_string(p).unwrap();
    let words = rtlint::front::wgsl::compile(&text, p).unwrap();
    let valid = common::spirv_val(&words);
    if p.ends_with("RT005/bad.wgsl") {
        // The bug RT005 exists for: naga accepts it, spirv-val does not.
        let err = valid.expect_err("naga's null ray query should fail spirv-val");
        assert!(err.contains("null"), "{err}");
    } else {
        valid.unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    }
}

/// Messages are matter of fact (clippy's habit): lowercase first word, no
/// final period; help is one imperative suggestion.
fn style_problems(d: &rtlint::diag::Diagnostic, out: &mut Vec<String>) {
    let m = &d.message;
    let first = m.split_whitespace().next().unwrap_or("");
    if first.chars().next().is_some_and(|c| c.is_uppercase()) && !first.starts_with('`') {
        out.push(format!("message starts with a capital: {m}"));
    }
    if m.ends_with('.') {
        out.push(format!("message ends with a period: {m}"));
    }
    if let Some(h) = &d.help {
        let lower = h.to_lowercase();
        if lower.starts_with("try")
            || lower.starts_with("consider")
            || lower.starts_with("you ")
            || h.ends_with('.')
        {
            out.push(format!("help is not one imperative suggestion: {h}"));
        }
    }
}
