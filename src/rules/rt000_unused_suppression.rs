//! RT000: the lint driver reports suppressions that allowed nothing; this
//! file holds the rule's declaration and the finding's words.

use super::{Group, Kind, Rule};
use crate::diag::{Diagnostic, Severity};
use crate::shader::Location;
use crate::suppress::Suppression;
use std::path::Path;

pub static RULE: Rule = Rule {
    code: "RT000",
    name: "unused-suppression",
    group: Group::Correctness,
    level: Severity::Warning,
    summary: "suppression comment that allowed no finding",
    doc: include_str!("../../rules/RT000.md"),
    kind: Kind::Driver,
};

/// The finding for the `unused` selectors of one suppression in `path`.
pub fn finding(path: &Path, s: &Suppression, unused: &[&str], severity: Severity) -> Diagnostic {
    let mut d = Diagnostic::new(
        severity,
        RULE.name,
        path,
        format!("suppression of {} allowed no finding", unused.join(", ")),
    )
    .with_code(RULE.code)
    .with_primary(
        Some(Location::span(path, s.line, s.column, 6)),
        "unused suppression",
    )
    .with_help(if unused.len() == s.selectors.len() {
        "delete the suppression"
    } else {
        "delete the unused codes from the suppression"
    });
    if let Some(r) = &s.reason {
        d = d.with_note(format!("its reason: {r}"));
    }
    d
}
