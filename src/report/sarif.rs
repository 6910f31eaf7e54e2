//! SARIF 2.1.0, with each rule's page as its help text.

use crate::diag::{Diagnostic, Severity};
use crate::rules::RULES;
use serde_json::{json, Value};

pub fn render(diagnostics: &[Diagnostic]) -> String {
    let rules: Vec<Value> = RULES
        .iter()
        .map(|r| {
            json!({
                "id": r.code,
                "name": r.name,
                "shortDescription": { "text": r.summary },
                "help": { "text": r.doc, "markdown": r.doc },
                "defaultConfiguration": { "level": level(r.level) },
            })
        })
        .collect();
    let results: Vec<Value> = diagnostics
        .iter()
        .map(|d| {
            let (path, line, column, end_line, end_column) = d.position();
            let mut region = json!({});
            if line > 0 {
                region = json!({ "startLine": line, "endLine": end_line.max(line) });
                if column > 0 {
                    region["startColumn"] = json!(column);
                    if end_column > column || end_line > line {
                        region["endColumn"] = json!(end_column);
                    }
                }
            }
            let mut text = d.message.clone();
            if let Some(h) = &d.help {
                text.push_str(&format!("\nhelp: {h}"));
            }
            let mut r = json!({
                "ruleId": d.code.unwrap_or(d.name),
                "level": level(d.severity),
                "message": { "text": text },
                "locations": [{
                    "physicalLocation": {
                        "artifactLocation": { "uri": path.to_string_lossy().replace('\\', "/") },
                        "region": region,
                    }
                }],
            });
            if let Some(i) = RULES.iter().position(|x| Some(x.code) == d.code) {
                r["ruleIndex"] = json!(i);
            }
            r
        })
        .collect();
    let doc = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "rtlint",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "results": results,
        }],
    });
    serde_json::to_string_pretty(&doc).unwrap_or_default()
}

fn level(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Note => "note",
    }
}
