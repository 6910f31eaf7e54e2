//! The arrows point one way (docs/architecture.md): each layer imports only
//! the layers below it. This test reads the library's sources and fails on an
//! import against the direction, or on a rule that imports another rule.
//! Unit-test modules (`#[cfg(test)]`) are exempt: tests may load fixtures
//! through the front-ends and render through reports.
//!
//! The HLSL compiler is not in this scan: it is its own crate
//! (`crates/rtlint-hlsl`), so Cargo refuses any use of rtlint from it. The
//! last test here checks that its manifest keeps it that way.

use std::path::{Path, PathBuf};

/// Top-level modules a folder or file must not name, and why.
const FORBIDDEN: &[(&str, &[&str])] = &[
    (
        "shader.rs",
        &[
            "diag",
            "program",
            "front",
            "analysis",
            "explain",
            "rules",
            "report",
            "config",
            "pipeline",
            "lint",
            "vk",
            "reference",
        ],
    ),
    (
        "diag.rs",
        &[
            "program", "front", "analysis", "explain", "rules", "report", "config", "pipeline",
            "lint", "vk",
        ],
    ),
    (
        "program",
        &[
            "front", "analysis", "explain", "rules", "report", "config", "pipeline", "lint", "vk",
        ],
    ),
    (
        "analysis",
        &[
            "front", "explain", "rules", "report", "config", "lint", "vk",
        ],
    ),
    (
        "explain.rs",
        &["front", "rules", "report", "config", "lint", "vk"],
    ),
    ("rules", &["front", "report", "lint", "vk", "build"]),
    ("lint.rs", &["report", "vk", "build"]),
    ("cache.rs", &["report", "vk", "build"]),
    ("report", &["vk", "build"]),
    (
        "config.rs",
        &[
            "program", "front", "analysis", "explain", "rules", "report", "pipeline", "lint", "vk",
        ],
    ),
    (
        "vk",
        &[
            "analysis", "explain", "rules", "report", "config", "lint", "front", "tradeoff",
        ],
    ),
    (
        "reference",
        &[
            "program", "front", "analysis", "explain", "rules", "report", "config", "pipeline",
            "lint", "vk", "verify", "tradeoff",
        ],
    ),
    ("verify", &["rules", "report", "lint", "build", "tradeoff"]),
    (
        "tradeoff",
        &["rules", "report", "lint", "build", "explain", "config"],
    ),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_dir() {
        let mut entries: Vec<_> = std::fs::read_dir(p)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for e in entries {
            rust_files(&e, out);
        }
    } else if p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    }
}

/// The source without its unit-test module(s).
fn library_code(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    match text.find("#[cfg(test)]") {
        Some(at) => text[..at].to_string(),
        None => text,
    }
}

/// Every `crate::NAME` the code names (in `use` lines and paths alike),
/// and the modules a `use crate::{a, b}` group names.
fn crate_modules(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find("crate::") {
        let after = &rest[at + 7..];
        if after.starts_with('{') {
            let group = &after[1..after.find('}').unwrap_or(after.len())];
            for item in group.split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                out.push(name);
            }
        } else {
            out.push(
                after
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect(),
            );
        }
        rest = after;
    }
    out
}

#[test]
fn imports_follow_the_layers() {
    let mut violations = Vec::new();
    for (place, forbidden) in FORBIDDEN {
        let mut files = Vec::new();
        rust_files(&src().join(place), &mut files);
        assert!(!files.is_empty(), "src/{place} is missing");
        for f in files {
            for m in crate_modules(&library_code(&f)) {
                if forbidden.contains(&m.as_str()) {
                    violations.push(format!(
                        "{} imports crate::{m}",
                        f.strip_prefix(src()).unwrap().display()
                    ));
                }
            }
        }
    }
    violations.sort();
    violations.dedup();
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn no_rule_imports_another_rule() {
    let mut files = Vec::new();
    rust_files(&src().join("rules"), &mut files);
    let mut violations = Vec::new();
    for f in files {
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        if !name.starts_with("rt") {
            continue;
        }
        let code = library_code(&f);
        for other in ["super::rt", "crate::rules::rt", "rules::rt"] {
            if let Some(at) = code.find(other) {
                let target: String = code[at + other.len() - 2..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if target != name {
                    violations.push(format!("{name} imports {target}"));
                }
            }
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

/// The checker itself: it must see imports in every spelling used here.
#[test]
fn the_checker_finds_imports() {
    let code = "use crate::front::load;\nuse crate::{config, report::human};\nlet x = crate::vk::Context::new();\n#[cfg(test)]\nmod tests { use crate::lint; }";
    let stripped = &code[..code.find("#[cfg(test)]").unwrap()];
    let found = crate_modules(stripped);
    assert_eq!(found, ["front", "config", "report", "vk"]);
}

/// The HLSL compiler's boundary is Cargo's: its manifest names no rtlint
/// crate and no path dependency, so nothing of rtlint can be imported there.
#[test]
fn the_hlsl_crate_depends_on_nothing_of_rtlint() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest: toml::Table = std::fs::read_to_string(root.join("crates/rtlint-hlsl/Cargo.toml"))
        .unwrap()
        .parse()
        .unwrap();
    let mut tables = vec![&manifest];
    if let Some(t) = manifest.get("target").and_then(|t| t.as_table()) {
        tables.extend(t.values().filter_map(|v| v.as_table()));
    }
    let mut deps = Vec::new();
    for t in tables {
        for kind in ["dependencies", "dev-dependencies", "build-dependencies"] {
            if let Some(d) = t.get(kind).and_then(|d| d.as_table()) {
                deps.extend(d.iter());
            }
        }
    }
    assert!(
        deps.iter().any(|(n, _)| *n == "rspirv"),
        "the scan sees the deps"
    );
    for (name, spec) in deps {
        assert!(!name.starts_with("rtlint"), "rtlint-hlsl depends on {name}");
        let path = spec.as_table().and_then(|t| t.get("path"));
        assert!(path.is_none(), "rtlint-hlsl has a path dependency: {name}");
    }
    // And rtlint uses it, not a copy: the sources are gone from src/.
    assert!(!src().join("front/hlsl").exists());
}
