//! Fixtures by convention: every rule has a folder `fixtures/RTnnn/` whose
//! `bad.*` and `good.*` files (HLSL, WGSL, GLSL sources, SPIR-V modules,
//! pipeline descriptions) are linted with only that rule selected. Each
//! finding must sit on a line marked `//~ RTnnn` (or `#~ RTnnn` in TOML;
//! `//~ RTnnn @ rel/path:LINE` marks a line of another file), every marker
//! must be found, and the rendered output must match its snapshot. A new
//! rule's fixtures are run by adding the folder: nothing else to register.

mod common;

use common::root;
use rtlint::lint::{check_paths, ConfigChoice, Options, Overrides};
use rtlint::rules::RULES;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// (file, line, code) a source marks.
fn markers(source: &Path) -> BTreeSet<(PathBuf, u32, String)> {
    let text = std::fs::read_to_string(source).unwrap_or_default();
    let mut out = BTreeSet::new();
    for (i, line) in text.lines().enumerate() {
        let Some(at) = line.find("//~").or_else(|| line.find("#~")) else {
            continue;
        };
        let rest = line[at..].trim_start_matches(['/', '#', '~']);
        let (codes, place) = match rest.split_once('@') {
            Some((codes, place)) => {
                let (file, l) = place.trim().rsplit_once(':').expect("FILE:LINE after @");
                let path = rtlint::program::debug::normalize(&source.parent().unwrap().join(file));
                (codes, Some((path, l.trim().parse::<u32>().unwrap())))
            }
            None => (rest, None),
        };
        for code in codes.split_whitespace() {
            let (p, l) = place
                .clone()
                .unwrap_or_else(|| (source.to_path_buf(), i as u32 + 1));
            out.insert((p, l, code.to_string()));
        }
    }
    out
}

/// The source whose markers a fixture file is judged by: a module's GLSL,
/// HLSL or WGSL source beside it (`bad.rgen.g.spv` → `bad.rgen`).
fn marker_source(file: &Path) -> PathBuf {
    let name = file.file_name().unwrap().to_str().unwrap();
    for suffix in [".g.spv", ".gV.spv", ".spv"] {
        if let Some(src) = name.strip_suffix(suffix) {
            let s = file.with_file_name(src);
            if s.exists() {
                return s;
            }
        }
    }
    file.to_path_buf()
}

/// Fixture files of one rule's folder, sorted: `bad*` and `good*`, leaving
/// out build scripts, notes, configs and headers.
fn fixture_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_str().unwrap();
            let fixture = n.starts_with("bad") || n.starts_with("good");
            let skipped = [".sh", ".md", ".hlsli"].iter().any(|e| n.ends_with(e))
                // A plain `.glsl` is a header; `bad.rgen.glsl` is a shader.
                || (n.ends_with(".glsl") && n.matches('.').count() == 1)
                || (n.ends_with(".toml") && !n.ends_with(".pipeline.toml"));
            fixture && !skipped
        })
        .collect();
    v.sort();
    v
}

fn relative(p: &Path) -> PathBuf {
    p.strip_prefix(root()).unwrap_or(p).to_path_buf()
}

#[test]
fn every_rule_has_bad_and_good_fixtures_in_its_folder() {
    let mut missing = Vec::new();
    for r in RULES {
        let dir = root().join("fixtures").join(r.code);
        let files = if dir.is_dir() {
            fixture_files(&dir)
        } else {
            Vec::new()
        };
        let bad = files.iter().any(|f| {
            f.file_name().unwrap().to_str().unwrap().starts_with("bad")
                && markers(&marker_source(f))
                    .iter()
                    .any(|(_, _, c)| c == r.code)
        });
        let good = files
            .iter()
            .any(|f| f.file_name().unwrap().to_str().unwrap().starts_with("good"));
        if !(bad && good) {
            missing.push(r.code);
        }
    }
    assert!(
        missing.is_empty(),
        "rules without fixtures/RTnnn/{{bad,good}}.*: {missing:?}"
    );
}

#[test]
fn rule_folder_fixtures_match_their_markers_with_only_that_rule() {
    let mut failures = Vec::new();
    for r in RULES {
        let dir = root().join("fixtures").join(r.code);
        if !dir.is_dir() {
            continue;
        }
        // A folder may carry an rtlint.toml for the rule's options.
        let config = if dir.join("rtlint.toml").is_file() {
            ConfigChoice::File(dir.join("rtlint.toml"))
        } else {
            ConfigChoice::Defaults
        };
        let options = Options {
            config,
            overrides: Overrides {
                select: Some(vec![r.code.to_string()]),
                ..Overrides::default()
            },
            ..Options::default()
        };
        for file in fixture_files(&dir) {
            let report = check_paths(std::slice::from_ref(&file), &options);
            let mut actual = BTreeSet::new();
            for d in &report.diagnostics {
                match (d.code, &d.primary) {
                    (Some(code), Some(p)) => {
                        actual.insert((
                            rtlint::program::debug::normalize(&p.location.path),
                            p.location.line,
                            code.to_string(),
                        ));
                    }
                    _ => failures.push(format!(
                        "{}: a finding without a position or an input error: {} {}",
                        relative(&file).display(),
                        d.name,
                        d.message
                    )),
                }
            }
            let expected: BTreeSet<_> = markers(&marker_source(&file))
                .into_iter()
                .filter(|(_, _, c)| c == r.code)
                .collect();
            if actual != expected {
                failures.push(format!(
                    "{}: expected {expected:?}, got {actual:?}",
                    relative(&file).display()
                ));
            }
            let mut sources = rtlint::report::Sources::default();
            for (p, t) in &report.embedded {
                sources.add_embedded(p, t);
            }
            let mut buf = codespan_reporting::term::termcolor::NoColor::new(Vec::new());
            rtlint::report::human::render(&report.diagnostics, &mut sources, &mut buf).unwrap();
            let text = String::from_utf8(buf.into_inner())
                .unwrap()
                .replace(&format!("{}/", root().display()), "");
            let name = relative(&file).to_string_lossy().replace(['/', '\\'], "__");
            common::snapshot(&format!("rules__{name}"), &text);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
