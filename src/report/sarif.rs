//! SARIF 2.1.0, with each rule's page as its help text. Findings are
//! results; input errors (a file that could not be analysed) are tool
//! execution notifications of an invocation that did not succeed.

use crate::diag::{Diagnostic, Severity};
use crate::rules::RULES;
use serde_json::{json, Value};
use std::path::Path;

/// The base id relative artifact locations are resolved against.
const SRCROOT: &str = "%SRCROOT%";

pub fn render(diagnostics: &[Diagnostic]) -> String {
    serde_json::to_string_pretty(&document(diagnostics, false)).unwrap_or_default()
}

/// `--statistics`: no results, the counts per rule in the run's
/// `properties.statistics` (and input errors as notifications, as always).
pub fn render_statistics(diagnostics: &[Diagnostic]) -> String {
    serde_json::to_string_pretty(&document(diagnostics, true)).unwrap_or_default()
}

fn document(diagnostics: &[Diagnostic], statistics: bool) -> Value {
    let rules: Vec<Value> = RULES
        .iter()
        .map(|r| {
            let mut rule = json!({
                "id": r.code,
                "name": r.name,
                "shortDescription": { "text": r.summary },
                "fullDescription": { "text": r.summary },
                "help": { "text": r.page(), "markdown": r.page() },
                "defaultConfiguration": { "level": level(r.level) },
                "properties": { "tags": [r.group.as_str()] },
            });
            if let Some(uri) = help_uri(r.code) {
                rule["helpUri"] = json!(uri);
            }
            rule
        })
        .collect();
    let results: Vec<Value> = diagnostics
        .iter()
        .filter(|d| d.code.is_some() && !statistics)
        .map(|d| {
            let mut text = d.message.clone();
            if let Some(s) = d.subject.as_ref().filter(|_| d.primary.is_none()) {
                text.push_str(&format!(" ({s})"));
            }
            if let Some(h) = &d.help {
                text.push_str(&format!("\nhelp: {h}"));
            }
            let mut r = json!({
                "ruleId": d.code.unwrap_or(d.name),
                "level": level(d.severity),
                "message": { "text": text },
                "locations": [location(d)],
                "partialFingerprints": { "rtlintFinding/v1": fingerprint(d) },
            });
            if let Some(i) = RULES.iter().position(|x| Some(x.code) == d.code) {
                r["ruleIndex"] = json!(i);
            }
            let related: Vec<Value> = d
                .secondary
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    let mut v = physical(
                        &l.location.path,
                        l.location.line,
                        l.location.column,
                        l.location.end_line,
                        l.location.end_column,
                    );
                    v["id"] = json!(i);
                    v["message"] = json!({ "text": l.message });
                    v
                })
                .collect();
            if !related.is_empty() {
                r["relatedLocations"] = json!(related);
            }
            r
        })
        .collect();
    let notifications: Vec<Value> = diagnostics
        .iter()
        .filter(|d| d.code.is_none())
        .map(|d| {
            json!({
                "level": if d.is_input_error() { "error" } else { "note" },
                "message": { "text": d.message },
                "descriptor": { "id": d.name },
                "locations": [location(d)],
            })
        })
        .collect();
    let mut doc = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "rtlint",
                "version": env!("CARGO_PKG_VERSION"),
                "semanticVersion": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "invocations": [{
                "executionSuccessful": notifications.is_empty(),
                "toolExecutionNotifications": notifications,
            }],
            "originalUriBaseIds": {
                SRCROOT: { "description": { "text": "the folder rtlint ran in" } }
            },
            "results": results,
        }],
    });
    if statistics {
        let counts: Vec<Value> = super::counts(diagnostics)
            .iter()
            .map(
                |c| json!({ "ruleId": c.code.unwrap_or(c.name), "name": c.name, "count": c.count }),
            )
            .collect();
        doc["runs"][0]["properties"] = json!({ "statistics": counts });
    }
    doc
}

/// A rule page's address, when the package says where its repository is.
fn help_uri(code: &str) -> Option<String> {
    let repo = env!("CARGO_PKG_REPOSITORY").trim_end_matches('/');
    (!repo.is_empty()).then(|| format!("{repo}/blob/main/rules/{code}.md"))
}

fn location(d: &Diagnostic) -> Value {
    let (path, line, column, end_line, end_column) = d.position();
    physical(path, line, column, end_line, end_column)
}

/// A `location` with a physical location; no `region` when the line is not
/// known (an empty region is invalid).
fn physical(path: &Path, line: u32, column: u32, end_line: u32, end_column: u32) -> Value {
    let mut physical = json!({ "artifactLocation": artifact(path) });
    if line > 0 {
        let mut region = json!({ "startLine": line, "endLine": end_line.max(line) });
        if column > 0 {
            region["startColumn"] = json!(column);
            if end_line > line || end_column > column {
                region["endColumn"] = json!(end_column.max(1));
            }
        }
        physical["region"] = region;
    }
    json!({ "physicalLocation": physical })
}

/// A relative path as a percent-encoded relative reference against
/// `%SRCROOT%`; an absolute one as a `file://` URI.
fn artifact(path: &Path) -> Value {
    let text = path.to_string_lossy().replace('\\', "/");
    if path.is_absolute() {
        json!({ "uri": format!("file://{}", percent_encode(&text)) })
    } else {
        let rel = text.trim_start_matches("./");
        json!({ "uri": percent_encode(rel), "uriBaseId": SRCROOT })
    }
}

/// Percent-encodes everything but unreserved characters and `/`.
pub fn percent_encode(s: &str) -> String {
    let mut out = String::new();
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// A stable identity for a finding across runs: rule, file, the subject and
/// message (not the line, so that edits above it keep the fingerprint).
fn fingerprint(d: &Diagnostic) -> String {
    let (path, ..) = d.position();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in [
        d.code.unwrap_or(d.name),
        &path.to_string_lossy().replace('\\', "/"),
        d.subject.as_deref().unwrap_or(""),
        &d.message,
    ] {
        for b in part.bytes().chain([0]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    format!("{h:016x}")
}

fn level(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Note => "note",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_are_percent_encoded() {
        assert_eq!(percent_encode("a b/ä#1.hlsl"), "a%20b/%C3%A4%231.hlsl");
        assert_eq!(
            artifact(Path::new("./shaders/x y.hlsl")),
            json!({ "uri": "shaders/x%20y.hlsl", "uriBaseId": "%SRCROOT%" })
        );
        assert_eq!(
            artifact(Path::new("/tmp/a b.wgsl")),
            json!({ "uri": "file:///tmp/a%20b.wgsl" })
        );
    }
}
