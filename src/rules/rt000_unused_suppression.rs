//! RT000: the lint driver reports suppressions that allowed nothing; this
//! file holds the rule's declaration and the finding's words.

use crate::diag::{Diagnostic, Severity};
use crate::shader::Location;
use crate::suppress::Suppression;
use std::path::Path;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a suppression that allowed nothing in this run: a
    /// `// rtlint: allow(...)` comment (or a WGSL
    /// `diagnostic(off, rtlint.rule_name)` filter) on a line where none of the
    /// rules it names reported a finding, on that line or the next. Only rules
    /// that ran are judged: with `--select RT001`, a suppression of RT003 is
    /// left alone.
    ///
    /// ## Why is this bad?
    ///
    /// A suppression outlives the finding it silenced: after the shader is fixed,
    /// or the code moves a line down, it stays behind and hides the next real
    /// finding in its place. Stale suppressions also teach readers that a problem
    /// exists where there is none.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// // rtlint: allow(RT001, reason = "legacy payload")
    /// struct Payload { float3 color; float hitT; };  // 16 bytes: nothing to allow
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// struct Payload { float3 color; float hitT; };
    /// ```
    ///
    /// ## How to fix
    ///
    /// Delete the suppression, or move it to the line the finding is reported on
    /// (or the line above it). `rtlint check --select RT000` lists them all.
    ///
    /// ## Options
    ///
    /// None. Turn it off with `RT000 = "allow"` under `[rules]` in `rtlint.toml` or
    /// `--ignore RT000`.
    ///
    /// ## References
    ///
    /// - ruff's `unused-noqa` (RUF100), the model for this rule.
    "RT000" "unused-suppression" {
        group: Suspicious,
        summary: "suppression comment that allowed no finding",
        kind: super::Kind::Driver,
        analysis: Fast,
    }
}

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
