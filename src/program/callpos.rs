//! Positions as a reader wants them, from the source text the positions
//! point into: a trace or callable call spans its name to its closing
//! parenthesis, starting on the line the call starts on (glslang `-g` gives
//! a call written over several lines the line of its last argument, and no
//! column); a position without a column (glslang `-g`) spans its line's
//! text, so every output has a column and a width.

use super::{Program, SiteKind, SrcPos};

/// Call names a trace is written with: GLSL, HLSL, WGSL, and GLSL's NV form.
const TRACE: &[&str] = &["traceRayEXT", "TraceRay", "traceRay", "traceNV"];
const CALLABLE: &[&str] = &["executeCallableEXT", "CallShader", "executeCallableNV"];

/// How far above its recorded line a call may start.
const MAX_LINES_BACK: usize = 40;

pub(super) fn refine(p: &mut Program) {
    let texts: Vec<Option<String>> = p
        .files
        .iter()
        .map(|f| {
            f.text
                .clone()
                .or_else(|| std::fs::read_to_string(&f.path).ok())
        })
        .collect();
    let lines: Vec<Option<Vec<&str>>> = texts
        .iter()
        .map(|t| t.as_deref().map(|t| t.lines().collect()))
        .collect();
    for site in &p.sites {
        let names = match site.kind {
            SiteKind::TraceRay => TRACE,
            SiteKind::ExecuteCallable => CALLABLE,
            _ => continue,
        };
        let Some(Some(pos)) = p.locs.get(site.inst).copied() else {
            continue;
        };
        let Some(Some(text)) = lines.get(pos.file as usize) else {
            continue;
        };
        if let Some(found) = call_at(text, pos, names) {
            p.locs[site.inst] = Some(found);
        }
    }
    for pos in p.locs.iter_mut().flatten() {
        if pos.column == 0 {
            if let Some(Some(text)) = lines.get(pos.file as usize) {
                whole_line(text, pos);
            }
        }
    }
}

impl Program {
    /// Where `name` is on the line of `at` (its definition there, `name =`,
    /// before any other use), as a span of the name: a value's label sits
    /// under the variable, not under the call that computes it.
    pub fn name_location(
        &self,
        at: &crate::diag::Location,
        name: &str,
    ) -> Option<crate::diag::Location> {
        let file = self.files.iter().find(|f| f.path == at.path)?;
        let text = match &file.text {
            Some(t) => std::borrow::Cow::Borrowed(t.as_str()),
            None => std::borrow::Cow::Owned(std::fs::read_to_string(&file.path).ok()?),
        };
        let line = text.lines().nth((at.line as usize).checked_sub(1)?)?;
        let code = line.split("//").next().unwrap_or(line);
        let word = |c: char| c.is_alphanumeric() || c == '_';
        let mut found: Vec<usize> = Vec::new();
        let mut from = 0;
        while let Some(i) = code[from..].find(name) {
            let s = from + i;
            from = s + name.len();
            let before = code[..s].chars().next_back().is_none_or(|c| !word(c));
            let after = code[from..].chars().next().is_none_or(|c| !word(c));
            if before && after && !name.is_empty() {
                found.push(s);
            }
        }
        let defines = |&s: &usize| {
            let rest = code[s + name.len()..].trim_start();
            let rest = rest.trim_start_matches(['+', '-', '*', '/', '|', '&', '^', '%']);
            rest.starts_with('=') && !rest.starts_with("==")
        };
        let s = found
            .iter()
            .copied()
            .find(defines)
            .or_else(|| found.first().copied())?;
        let col = code[..s].chars().count() as u32 + 1;
        Some(crate::diag::Location::span(
            at.path.clone(),
            at.line,
            col,
            name.chars().count() as u32,
        ))
    }
}

/// A position without a column: from the line's first to its last
/// character that is not blank.
fn whole_line(text: &[&str], pos: &mut SrcPos) {
    let Some(line) = text.get(pos.line as usize - 1) else {
        return;
    };
    let lead = line.chars().take_while(|c| c.is_whitespace()).count();
    let len = line.trim_end().chars().count();
    if len > lead {
        pos.column = lead as u32 + 1;
        pos.end_line = pos.line;
        pos.end_column = len as u32 + 1;
    }
}

/// The call `names` at `pos`: on its line (the one nearest the column), or
/// starting on a line above whose parentheses close on or after it.
fn call_at(text: &[&str], pos: SrcPos, names: &[&str]) -> Option<SrcPos> {
    let line = pos.line as usize;
    if line == 0 || line > text.len() {
        return None;
    }
    let here = calls_on(text[line - 1], names);
    let (start_line, start) = if !here.is_empty() {
        let col = pos.column.saturating_sub(1) as usize;
        let pick = here
            .iter()
            .copied()
            .rfind(|&(c, _)| pos.column == 0 || c <= col)
            .unwrap_or(here[0]);
        (line, pick)
    } else {
        let mut found = None;
        for l in (line.saturating_sub(MAX_LINES_BACK).max(1)..line).rev() {
            if let Some(&last) = calls_on(text[l - 1], names).last() {
                found = Some((l, last));
                break;
            }
        }
        let (l, c) = found?;
        // Only a call still open on the recorded line is this one.
        let (end_line, _) = close_paren(text, l, c.1)?;
        if end_line < line {
            return None;
        }
        (l, c)
    };
    let (end_line, end_col) = close_paren(text, start_line, start.1)?;
    Some(SrcPos {
        file: pos.file,
        line: start_line as u32,
        column: char_col(text[start_line - 1], start.0) + 1,
        end_line: end_line as u32,
        end_column: char_col(text[end_line - 1], end_col) + 1,
    })
}

/// Each call of one of `names` on a line: (byte column of the name, byte
/// column of its `(`).
fn calls_on(line: &str, names: &[&str]) -> Vec<(usize, usize)> {
    let code = line.split("//").next().unwrap_or(line);
    let mut out = Vec::new();
    for name in names {
        let mut from = 0;
        while let Some(i) = code[from..].find(name) {
            let at = from + i;
            from = at + name.len();
            let before_ok = code[..at]
                .chars()
                .next_back()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
            let rest = &code[from..];
            let paren = rest.len() - rest.trim_start().len();
            if before_ok && rest.trim_start().starts_with('(') {
                out.push((at, from + paren));
            }
        }
    }
    out.sort();
    out.dedup();
    out
}

/// The line (1-based) and byte column just after the `)` matching the `(`
/// at byte `open` of line `line`.
fn close_paren(text: &[&str], line: usize, open: usize) -> Option<(usize, usize)> {
    let mut depth = 0i32;
    for (l, t) in text
        .iter()
        .enumerate()
        .skip(line - 1)
        .take(MAX_LINES_BACK + 1)
    {
        let from = if l + 1 == line { open } else { 0 };
        let code = t.split("//").next().unwrap_or(t);
        for (i, c) in code.char_indices().filter(|(i, _)| *i >= from) {
            match c {
                '(' => depth += 1,
                ')' => {
                    depth -= 1;
                    if depth == 0 {
                        return Some((l + 1, i + 1));
                    }
                }
                _ => {}
            }
        }
    }
    None
}

/// The 0-based character column of byte `at` in `line`.
fn char_col(line: &str, at: usize) -> u32 {
    line.get(..at.min(line.len()))
        .map_or(0, |s| s.chars().count()) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(line: u32, column: u32) -> SrcPos {
        SrcPos {
            file: 0,
            line,
            column,
            end_line: line,
            end_column: column,
        }
    }

    #[test]
    fn a_call_over_several_lines_starts_where_its_name_is() {
        let text = [
            "void main() {",
            "    traceRayEXT(scene, 0, 0xFF, 0, 1, 0,",
            "                vec3(0.0), 0.0,",
            "                0);",
            "}",
        ];
        let p = call_at(&text, pos(4, 0), TRACE).unwrap();
        assert_eq!((p.line, p.column, p.end_line, p.end_column), (2, 5, 4, 19));
    }

    #[test]
    fn a_point_on_one_line_gets_the_call_s_width() {
        let text = ["    TraceRay(s, 0, 0xFF, 0, 1, 0, r, p); // TraceRay(x)"];
        let p = call_at(&text, pos(1, 5), TRACE).unwrap();
        assert_eq!((p.line, p.column, p.end_line, p.end_column), (1, 5, 1, 40));
    }

    #[test]
    fn a_call_closed_above_the_line_is_not_taken() {
        let text = ["    traceRayEXT(a);", "    x = 1;"];
        assert!(call_at(&text, pos(2, 0), TRACE).is_none());
        let mut p = pos(2, 0);
        whole_line(&text, &mut p);
        assert_eq!((p.column, p.end_column), (5, 11));
    }
}
