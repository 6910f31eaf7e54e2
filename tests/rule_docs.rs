//! Each rule is one declaration: its doc comment is its page. The pages in
//! `rules/`, the README's table and the code list are generated from the
//! registry; these tests fail when a generated file is stale
//! (`RTLINT_BLESS=1 cargo test --test rule_docs` rewrites them for review).

use rtlint::rules::{Group, RULES};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn bless() -> bool {
    std::env::var_os("RTLINT_BLESS").is_some()
}

/// Writes `text` to `path` when blessing; otherwise fails when they differ.
fn generated(path: &Path, text: &str, stale: &mut Vec<String>) {
    let current = std::fs::read_to_string(path).unwrap_or_default();
    if current == text {
        return;
    }
    if bless() {
        std::fs::write(path, text).unwrap();
    } else {
        stale.push(path.display().to_string());
    }
}

#[test]
fn rule_pages_are_generated_from_the_declarations() {
    let mut stale = Vec::new();
    for r in RULES {
        generated(
            &root().join("rules").join(format!("{}.md", r.code)),
            &r.page(),
            &mut stale,
        );
    }
    // No page without a rule.
    for e in std::fs::read_dir(root().join("rules")).unwrap() {
        let p = e.unwrap().path();
        let code = p.file_stem().unwrap().to_string_lossy().into_owned();
        assert!(
            RULES.iter().any(|r| r.code == code),
            "{} has no rule",
            p.display()
        );
    }
    assert!(
        stale.is_empty(),
        "stale (RTLINT_BLESS=1 regenerates): {stale:?}"
    );
}

#[test]
fn the_readme_table_is_generated_from_the_registry() {
    let path = root().join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let start = readme.find("<!-- rules:start").expect("rules:start marker");
    let start = start + readme[start..].find("-->").unwrap() + 3;
    let end = readme.find("<!-- rules:end -->").expect("rules:end marker");
    let mut table = String::from("\n| code | name | group | default level | what it finds |\n| --- | --- | --- | --- | --- |\n");
    for r in RULES {
        let level = if r.group.on_by_default() {
            r.level.as_str()
        } else {
            "off"
        };
        table.push_str(&format!(
            "| [{}](rules/{}.md) | `{}` | {} | {} | {} |\n",
            r.code,
            r.code,
            r.name,
            r.group.as_str(),
            level,
            r.summary
        ));
    }
    let text = format!("{}{}{}", &readme[..start], table, &readme[end..]);
    let mut stale = Vec::new();
    generated(&path, &text, &mut stale);
    assert!(
        stale.is_empty(),
        "README rule table is stale (RTLINT_BLESS=1 regenerates)"
    );
}

/// Adding a rule touches one file: every `src/rules/rt*.rs` declares exactly
/// one rule, and the registry holds exactly those.
#[test]
fn every_rule_file_declares_one_registered_rule() {
    let mut declared = Vec::new();
    for e in std::fs::read_dir(root().join("src/rules")).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        if !name.starts_with("rt") || !name.ends_with(".rs") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            text.matches("declare_rule! {").count(),
            1,
            "{name} must declare one rule"
        );
        let code = name[..5].to_ascii_uppercase();
        assert!(
            text.contains(&format!("\"{code}\" \"")),
            "{name} declares a rule whose code is not {code}"
        );
        declared.push(code);
    }
    declared.sort();
    let registered: Vec<String> = RULES.iter().map(|r| r.code.to_string()).collect();
    assert_eq!(declared, registered);
}

#[test]
fn pages_have_the_sections_and_groups_set_levels() {
    for r in RULES {
        let page = r.page();
        for section in ["## What it does", "## Why is this bad?", "## Example"] {
            assert!(page.contains(section), "{}: page lacks `{section}`", r.code);
        }
        assert!(
            page.contains("Use instead") || page.contains("## How to fix"),
            "{}: page says what to do instead",
            r.code
        );
        assert_eq!(r.level, r.group.level(), "{}", r.code);
    }
    assert_eq!(Group::Correctness.level().as_str(), "error");
    assert!(!Group::Pedantic.on_by_default());
}

/// docs/configuration.md lists every rule option with its default, so a
/// new option cannot go undocumented.
#[test]
fn configuration_docs_list_every_rule_option() {
    let docs = std::fs::read_to_string(root().join("docs/configuration.md")).unwrap();
    for r in rtlint::rules::RULES {
        for o in r.options {
            let row = format!("| `[rules.{}]` | `{}` | {} |", r.code, o.name, o.default);
            assert!(docs.contains(&row), "docs/configuration.md lacks `{row}`");
        }
    }
}
