//! Terminal output through codespan-reporting, in the style of STYLE.md.

use super::{byte_range, Sources, Summary};
use crate::diag::{Diagnostic, Severity};
use codespan_reporting::diagnostic::{
    Diagnostic as CsDiagnostic, Label, LabelStyle, Severity as CsSeverity,
};
use codespan_reporting::files::SimpleFiles;
use codespan_reporting::term;
use codespan_reporting::term::termcolor::{Buffer, WriteColor};
use std::collections::HashMap;
use std::path::PathBuf;

pub fn render(
    diagnostics: &[Diagnostic],
    sources: &mut Sources,
    out: &mut dyn WriteColor,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    sources.prefetch(
        diagnostics
            .iter()
            .flat_map(|d| d.primary.iter().chain(&d.secondary))
            .map(|l| l.location.path.as_path()),
    );
    let sources = &*sources;
    // Rendered in parallel by chunks, each into a buffer, written in order:
    // a run over thousands of files prints thousands of findings.
    const CHUNK: usize = 64;
    let color = out.supports_color();
    let chunks: Vec<std::io::Result<Buffer>> = diagnostics
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut buf = if color {
                Buffer::ansi()
            } else {
                Buffer::no_color()
            };
            render_chunk(chunk, sources, &mut buf)?;
            Ok(buf)
        })
        .collect();
    for buf in chunks {
        out.write_all(buf?.as_slice())?;
    }
    Ok(())
}

fn render_chunk(
    diagnostics: &[Diagnostic],
    sources: &Sources,
    out: &mut dyn WriteColor,
) -> std::io::Result<()> {
    let mut files = SimpleFiles::new();
    let mut ids: HashMap<PathBuf, Option<usize>> = HashMap::new();
    let config = term::Config::default();
    for d in diagnostics {
        let mut cs = CsDiagnostic::new(match d.severity {
            Severity::Error => CsSeverity::Error,
            Severity::Warning => CsSeverity::Warning,
            Severity::Note => CsSeverity::Note,
        })
        .with_message(&d.message);
        if let Some(code) = d.code {
            cs = cs.with_code(code);
        }
        let mut unplaced = Vec::new();
        let labels = d
            .primary
            .iter()
            .map(|l| (LabelStyle::Primary, l))
            .chain(d.secondary.iter().map(|l| (LabelStyle::Secondary, l)));
        for (style, label) in labels {
            let path = &label.location.path;
            let id = *ids.entry(path.clone()).or_insert_with(|| {
                sources
                    .read_before(path)
                    .map(|t| files.add(path.display().to_string(), t))
            });
            let range = id.and_then(|id| {
                let text = files.get(id).ok()?.source();
                byte_range(text, &label.location)
            });
            match (id, range) {
                (Some(id), Some(range)) => cs
                    .labels
                    .push(Label::new(style, id, range).with_message(&label.message)),
                _ => unplaced.push(format!("{}: {}", label.location, label.message)),
            }
        }
        if d.primary.is_none() {
            // Only a finding in a module lacks a position for want of debug
            // info; an input error (a config, a missing path) has none to give.
            match (d.subject.as_deref(), d.code) {
                (Some(what), _) => cs.notes.push(format!("in {}: {what}", d.file.display())),
                (None, Some(_)) => cs.notes.push(format!(
                    "in {}: no source position in debug info",
                    d.file.display()
                )),
                (None, None) => cs.notes.push(format!("in {}", d.file.display())),
            }
        }
        for u in unplaced {
            cs.notes.push(format!("at {u}"));
        }
        for n in &d.notes {
            cs.notes.push(format!("note: {n}"));
        }
        if let Some(h) = &d.help {
            cs.notes.push(format!("help: {h}"));
        }
        if let Some(code) = d.code {
            cs.notes
                .push(format!("note: `rtlint rule {code}` explains this rule"));
        }
        term::emit_to_write_style(out, &config, &files, &cs).map_err(|e| match e {
            // Keep the kind: a closed pipe is not an error to report.
            codespan_reporting::files::Error::Io(e) => e,
            e => std::io::Error::other(e),
        })?;
    }
    Ok(())
}

pub fn summary_line(s: &Summary) -> String {
    let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
    let mut line = format!(
        "{}, {} in {}",
        plural(s.errors, "error"),
        plural(s.warnings, "warning"),
        plural(s.files, "file")
    );
    if s.input_errors > 0 {
        line.push_str(&format!(
            " ({} could not be analysed)",
            plural(s.input_errors, "input")
        ));
    }
    line
}
