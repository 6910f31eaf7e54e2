//! Reports: the only place that turns diagnostics and analysis reports into
//! text, for every command and format.

pub mod human;
pub mod json;
pub mod layout;
pub mod live;
pub mod sarif;
pub mod stack;

use crate::diag::{Diagnostic, Location, Severity};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Human,
    Json,
    Github,
    Sarif,
}

impl Format {
    pub fn parse(s: &str) -> Option<Format> {
        Some(match s {
            "human" | "text" => Format::Human,
            "json" => Format::Json,
            "github" => Format::Github,
            "sarif" => Format::Sarif,
            _ => return None,
        })
    }
}

/// Counts for the closing summary.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Summary {
    pub files: usize,
    pub errors: usize,
    pub warnings: usize,
    pub notes: usize,
    /// Inputs that could not be analysed (counted in `errors` too).
    pub input_errors: usize,
}

impl Summary {
    pub fn count(files: usize, diagnostics: &[Diagnostic]) -> Summary {
        let mut s = Summary {
            files,
            ..Summary::default()
        };
        for d in diagnostics {
            match d.severity {
                Severity::Error => s.errors += 1,
                Severity::Warning => s.warnings += 1,
                Severity::Note => s.notes += 1,
            }
            if d.is_input_error() {
                s.input_errors += 1;
            }
        }
        s
    }
}

/// Source text for rendering snippets: files on disk, else the text a module
/// embedded in its debug info.
#[derive(Default)]
pub struct Sources {
    embedded: HashMap<PathBuf, String>,
    cache: HashMap<PathBuf, Option<String>>,
}

impl Sources {
    pub fn add_embedded(&mut self, path: &Path, text: &str) {
        self.embedded
            .entry(path.to_path_buf())
            .or_insert_with(|| text.to_string());
    }

    pub fn add_program(&mut self, program: &crate::program::Program) {
        for f in &program.files {
            if let Some(t) = &f.text {
                self.add_embedded(&f.path, t);
            }
        }
    }

    /// Reads the texts of `paths` not read yet, in parallel.
    pub fn prefetch<'a>(&mut self, paths: impl Iterator<Item = &'a Path>) {
        use rayon::prelude::*;
        let mut todo: Vec<&Path> = paths.filter(|p| !self.cache.contains_key(*p)).collect();
        todo.sort_unstable();
        todo.dedup();
        let texts: Vec<Option<String>> = todo
            .par_iter()
            .map(|p| crate::shader::read_source_text(p))
            .collect();
        for (p, text) in todo.into_iter().zip(texts) {
            let text = text.or_else(|| self.embedded.get(p).cloned());
            self.cache.insert(p.to_path_buf(), text);
        }
    }

    /// A text [`Sources::text`] or [`Sources::prefetch`] read before.
    pub fn read_before(&self, path: &Path) -> Option<&str> {
        self.cache.get(path).and_then(|t| t.as_deref())
    }

    pub fn text(&mut self, path: &Path) -> Option<&str> {
        if !self.cache.contains_key(path) {
            let text =
                crate::shader::read_source_text(path).or_else(|| self.embedded.get(path).cloned());
            self.cache.insert(path.to_path_buf(), text);
        }
        self.cache.get(path).and_then(|t| t.as_deref())
    }
}

/// Byte range of a location in `text`. A point location widens to the token
/// it starts; a line without a column covers the line's text.
pub fn byte_range(text: &str, loc: &Location) -> Option<std::ops::Range<usize>> {
    let line_start = |line: u32| -> Option<usize> {
        if line == 0 {
            return None;
        }
        let mut at = 0;
        for _ in 1..line {
            at += text[at..].find('\n')? + 1;
        }
        Some(at)
    };
    let col_offset = |start: usize, col: u32| -> usize {
        let line = &text[start..text[start..].find('\n').map_or(text.len(), |e| start + e)];
        start
            + line
                .char_indices()
                .nth(col.saturating_sub(1) as usize)
                .map_or(line.len(), |(i, _)| i)
    };
    let ls = line_start(loc.line)?;
    let line_end = text[ls..].find('\n').map_or(text.len(), |e| ls + e);
    if loc.column == 0 {
        let line = &text[ls..line_end];
        let lead = line.len() - line.trim_start().len();
        return Some(ls + lead..ls + line.trim_end().len().max(lead));
    }
    let start = col_offset(ls, loc.column);
    let end = if loc.end_line > loc.line {
        line_start(loc.end_line).map_or(line_end, |s| col_offset(s, loc.end_column))
    } else if loc.end_column > loc.column {
        col_offset(ls, loc.end_column)
    } else {
        start
    };
    if end > start {
        return Some(start..end);
    }
    // A point: widen to the identifier (or the one character) there.
    let rest = &text[start..line_end];
    let ident = rest
        .char_indices()
        .find(|(_, c)| !(c.is_alphanumeric() || *c == '_'))
        .map_or(rest.len(), |(i, _)| i);
    let len = if ident > 0 {
        ident
    } else {
        rest.chars().next().map_or(0, char::len_utf8)
    };
    Some(start..start + len)
}

/// One line per finding: `path:line:col: level[CODE] message`.
pub fn concise(diagnostics: &[Diagnostic]) -> String {
    let mut out = String::new();
    for d in diagnostics {
        let (path, line, col, _, _) = d.position();
        let mut at = path.display().to_string();
        if line > 0 {
            at.push_str(&format!(":{line}"));
            if col > 0 {
                at.push_str(&format!(":{col}"));
            }
        }
        let code = d.code.unwrap_or(d.name);
        let mut message = d.message.clone();
        if let Some(s) = d.subject.as_ref().filter(|_| d.primary.is_none()) {
            message.push_str(&format!(" ({s})"));
        }
        out.push_str(&format!(
            "{at}: {}[{code}] {message}\n",
            d.severity.as_str()
        ));
    }
    out
}

/// How many findings one rule (or input errors of one kind: `code` none)
/// produced.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct RuleCount<'a> {
    pub code: Option<&'a str>,
    pub name: &'a str,
    pub count: usize,
}

/// Findings counted per rule, most frequent first (`--statistics`, in
/// every format).
pub fn counts(diagnostics: &[Diagnostic]) -> Vec<RuleCount<'_>> {
    let mut counts: Vec<RuleCount> = Vec::new();
    for d in diagnostics {
        match counts
            .iter_mut()
            .find(|c| c.code == d.code && c.name == d.name)
        {
            Some(e) => e.count += 1,
            None => counts.push(RuleCount {
                code: d.code,
                name: d.name,
                count: 1,
            }),
        }
    }
    counts.sort_by(|a, b| {
        b.count
            .cmp(&a.count)
            .then(a.code.unwrap_or("input").cmp(b.code.unwrap_or("input")))
            .then(a.name.cmp(b.name))
    });
    counts
}

/// `--statistics` as text: count, code (`input` for input errors), name.
pub fn statistics(diagnostics: &[Diagnostic]) -> String {
    counts(diagnostics)
        .iter()
        .map(|c| {
            format!(
                "{:>6}  {:<6} {}\n",
                c.count,
                c.code.unwrap_or("input"),
                c.name
            )
        })
        .collect()
}

/// `--statistics --format github`: one notice annotation holding the
/// counts, and the same as a Markdown table for the job summary.
pub fn github_statistics(diagnostics: &[Diagnostic]) -> (String, String) {
    let counts = counts(diagnostics);
    let lines: Vec<String> = counts
        .iter()
        .map(|c| format!("{} {} {}", c.count, c.code.unwrap_or("input"), c.name))
        .collect();
    let message = if lines.is_empty() {
        "no findings".to_string()
    } else {
        lines.join("\n")
    };
    let notice = format!(
        "::notice title=rtlint statistics::{}\n",
        escape_data(&message)
    );
    let mut table =
        String::from("### rtlint statistics\n\n| count | code | rule |\n| ---: | --- | --- |\n");
    for c in &counts {
        table.push_str(&format!(
            "| {} | {} | {} |\n",
            c.count,
            c.code.unwrap_or("input"),
            c.name
        ));
    }
    if counts.is_empty() {
        table.push_str("| 0 | | no findings |\n");
    }
    (notice, table)
}

/// `::warning title=rtlint (RT001),file=…,line=…,col=…::message` lines.
pub fn github(diagnostics: &[Diagnostic]) -> String {
    let mut out = String::new();
    for d in diagnostics {
        let level = match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "notice",
        };
        let (path, line, col, end_line, end_col) = d.position();
        let title = match d.code {
            Some(c) => format!("rtlint ({c})"),
            None => format!("rtlint ({})", d.name),
        };
        let mut props = format!(
            "title={},file={}",
            escape_property(&title),
            escape_property(&path.to_string_lossy())
        );
        if line > 0 {
            props.push_str(&format!(",line={line},endLine={}", end_line.max(line)));
            if col > 0 {
                props.push_str(&format!(",col={col}"));
                // GitHub highlights `col..endColumn` on a single line.
                if end_line <= line {
                    props.push_str(&format!(",endColumn={}", end_col.max(col)));
                }
            }
        }
        let mut message = d.message.clone();
        if let Some(s) = d.subject.as_ref().filter(|_| d.primary.is_none()) {
            message.push_str(&format!(" ({s})"));
        }
        if let Some(h) = &d.help {
            message.push_str(&format!("\nhelp: {h}"));
        }
        out.push_str(&format!("::{level} {props}::{}\n", escape_data(&message)));
    }
    out
}

fn escape_data(s: &str) -> String {
    s.replace('%', "%25")
        .replace('\r', "%0D")
        .replace('\n', "%0A")
}

fn escape_property(s: &str) -> String {
    escape_data(s).replace(':', "%3A").replace(',', "%2C")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_ranges() {
        let text = "struct Payload {\n    vec3 color;\n};\n";
        let l = |line, column, end_column| Location {
            path: "x".into(),
            line,
            column,
            end_line: line,
            end_column,
        };
        assert_eq!(&text[byte_range(text, &l(1, 8, 8)).unwrap()], "Payload");
        assert_eq!(&text[byte_range(text, &l(2, 0, 0)).unwrap()], "vec3 color;");
        assert_eq!(&text[byte_range(text, &l(2, 5, 9)).unwrap()], "vec3");
        assert_eq!(&text[byte_range(text, &l(1, 16, 16)).unwrap()], "{");
        assert_eq!(byte_range(text, &l(9, 1, 1)), None);
    }

    #[test]
    fn github_lines_escape_their_fields() {
        let d = Diagnostic::new(
            Severity::Warning,
            "payload-over-budget",
            Path::new("a.spv"),
            "too big: 40%\nsee",
        )
        .with_code("RT001")
        .with_primary(Some(Location::span("dir,x/a.glsl", 3, 8, 7)), "here");
        assert_eq!(
            github(&[d]),
            "::warning title=rtlint (RT001),file=dir%2Cx/a.glsl,line=3,endLine=3,col=8,endColumn=15::too big: 40%25%0Asee\n"
        );
    }
}
