//! JSON output: a stable contract (`diagnostics[]`, `summary`), keys only added.

use super::Summary;
use crate::diag::Diagnostic;

#[derive(serde::Serialize)]
pub struct JsonDiagnostic<'a> {
    pub code: Option<&'a str>,
    pub name: &'a str,
    pub severity: &'a str,
    pub message: &'a str,
    /// Where the finding is: the source file when debug info says, else the input.
    pub path: String,
    pub line: Option<u32>,
    pub column: Option<u32>,
    pub end_line: Option<u32>,
    pub end_column: Option<u32>,
    /// The input file that was analysed.
    pub file: String,
    pub subject: Option<&'a str>,
    pub labels: Vec<JsonLabel>,
    pub notes: &'a [String],
    pub help: Option<&'a str>,
    /// Replacement text for the declaration at `fix_location`.
    pub fix: Option<&'a str>,
    pub fix_location: Option<JsonLabel>,
}

#[derive(serde::Serialize)]
pub struct JsonLabel {
    pub path: String,
    pub line: u32,
    pub column: u32,
    pub message: String,
}

pub fn diagnostic(d: &Diagnostic) -> JsonDiagnostic<'_> {
    let (path, line, column, end_line, end_column) = d.position();
    let placed = d.primary.is_some();
    JsonDiagnostic {
        code: d.code,
        name: d.name,
        severity: d.severity.as_str(),
        message: &d.message,
        path: path.display().to_string(),
        line: placed.then_some(line),
        column: placed.then_some(column),
        end_line: placed.then_some(end_line),
        end_column: placed.then_some(end_column),
        file: d.file.display().to_string(),
        subject: d.subject.as_deref(),
        labels: d
            .secondary
            .iter()
            .map(|l| JsonLabel {
                path: l.location.path.display().to_string(),
                line: l.location.line,
                column: l.location.column,
                message: l.message.clone(),
            })
            .collect(),
        notes: &d.notes,
        help: d.help.as_deref(),
        fix: d.fix.as_ref().map(|f| f.replacement.as_str()),
        fix_location: d
            .fix
            .as_ref()
            .and_then(|f| f.location.as_ref())
            .map(|l| JsonLabel {
                path: l.path.display().to_string(),
                line: l.line,
                column: l.column,
                message: "replace this declaration".into(),
            }),
    }
}

pub fn render(diagnostics: &[Diagnostic], summary: &Summary) -> String {
    let value = serde_json::json!({
        "version": 1,
        "diagnostics": diagnostics.iter().map(diagnostic).collect::<Vec<_>>(),
        "summary": summary,
    });
    serde_json::to_string_pretty(&value).unwrap_or_default()
}

/// `--statistics`: counts per rule instead of findings; input errors are
/// still listed in full under `diagnostics`.
pub fn render_statistics(diagnostics: &[Diagnostic], summary: &Summary) -> String {
    let value = serde_json::json!({
        "version": 1,
        "statistics": super::counts(diagnostics),
        "diagnostics": diagnostics
            .iter()
            .filter(|d| d.code.is_none())
            .map(diagnostic)
            .collect::<Vec<_>>(),
        "summary": summary,
    });
    serde_json::to_string_pretty(&value).unwrap_or_default()
}
