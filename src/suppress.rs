//! Suppressions written in the shader source: `// rtlint: allow(RT001)` or
//! `// rtlint: allow(payload-over-budget, reason = "...")` at the end of the
//! finding's line or alone on the line above, in HLSL, WGSL and GLSL alike (a GLSL-compiled
//! module finds them through the source it embeds); and WGSL's own
//! `diagnostic(off, rtlint.payload_over_budget)`, as a directive (the whole
//! file) or an `@diagnostic` attribute (the item it stands on).

/// One suppression comment or WGSL diagnostic filter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Suppression {
    /// 1-based line of the comment (or of the WGSL filter).
    pub line: u32,
    /// 1-based column where `rtlint:` (or `diagnostic`) starts.
    pub column: u32,
    /// Lines it covers, inclusive.
    pub covers: (u32, u32),
    /// The codes, names or groups it allows.
    pub selectors: Vec<String>,
    /// Each selector's 1-based column and length in characters (where an
    /// unknown one is reported).
    pub spans: Vec<(u32, u32)>,
    /// The reason given, if any.
    pub reason: Option<String>,
}

/// Every suppression in `text`.
pub fn parse(text: &str) -> Vec<Suppression> {
    let mut out = Vec::new();
    // Most files have neither marker: one search of the whole text each,
    // not two per line (a sixth of a warm cached run went here).
    if !text.contains("rtlint") && !text.contains("diagnostic") {
        return out;
    }
    let lines: Vec<&str> = text.lines().collect();
    for (i, line) in lines.iter().enumerate() {
        let n = i as u32 + 1;
        // `rtlint: allow(...)` inside a `//` comment.
        if let Some(c) = line.find("//") {
            let comment = &line[c + 2..];
            if let Some(at) = comment.find("rtlint:") {
                let rest = comment[at + 7..].trim_start();
                if let Some(args) = rest
                    .strip_prefix("allow")
                    .map(str::trim_start)
                    .and_then(|r| r.strip_prefix('('))
                    .and_then(|r| r.rfind(')').map(|e| &r[..e]))
                {
                    let (selectors, reason) = split_args(args);
                    // After code it speaks of its own line; alone on its
                    // line, of the next one too.
                    let alone = line[..c].trim().is_empty();
                    // `args` is a slice of `line`: its byte offset there.
                    let args_at = args.as_ptr() as usize - line.as_ptr() as usize;
                    let spans = spans_in(line, args_at, &selectors);
                    out.push(Suppression {
                        line: n,
                        column: (line[..c + 2 + at].chars().count() + 1) as u32,
                        covers: (n, if alone { n + 1 } else { n }),
                        selectors,
                        spans,
                        reason,
                    });
                }
            }
        }
        // WGSL: `diagnostic(off, rtlint.rule_name)`.
        let code = line.split("//").next().unwrap_or("");
        let mut from = 0;
        while let Some(at) = code[from..].find("diagnostic") {
            let start = from + at;
            from = start + "diagnostic".len();
            let Some(args) = code[from..]
                .trim_start()
                .strip_prefix('(')
                .and_then(|r| r.find(')').map(|e| &r[..e]))
            else {
                continue;
            };
            let mut parts = args.split(',').map(str::trim);
            if parts.next() != Some("off") {
                continue;
            }
            let Some(rule) = parts.next().and_then(|r| r.strip_prefix("rtlint.")) else {
                continue;
            };
            let attribute = code[..start].trim_end().ends_with('@');
            let covers = if attribute {
                (n, item_end(&lines, i))
            } else {
                (1, u32::MAX)
            };
            let name_at = from + code[from..].find(rule).unwrap_or(0);
            out.push(Suppression {
                line: n,
                column: (code[..start].chars().count() + 1) as u32,
                covers,
                selectors: vec![rule.replace('_', "-")],
                spans: vec![(
                    (code[..name_at].chars().count() + 1) as u32,
                    rule.chars().count() as u32,
                )],
                reason: None,
            });
        }
    }
    out
}

/// `RT001, payload-over-budget, reason = "..."` → selectors and reason.
fn split_args(args: &str) -> (Vec<String>, Option<String>) {
    let (list, reason) = match args.find("reason") {
        Some(r) => {
            let tail = args[r + 6..].trim_start().trim_start_matches('=').trim();
            let reason = tail.trim_matches(|c| c == '"' || c == '\'').to_string();
            (&args[..r], Some(reason))
        }
        None => (args, None),
    };
    let selectors = list
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect();
    (selectors, reason)
}

/// Columns and lengths of `selectors` in `line`, searched in order from
/// byte `from`.
fn spans_in(line: &str, mut from: usize, selectors: &[String]) -> Vec<(u32, u32)> {
    selectors
        .iter()
        .map(|sel| {
            let at = line[from..].find(sel.as_str()).map_or(from, |k| from + k);
            from = at + sel.len();
            (
                (line[..at].chars().count() + 1) as u32,
                sel.chars().count() as u32,
            )
        })
        .collect()
}

/// The last line of the item that starts at line index `i`: the line of the
/// brace closing the first `{` from there on.
fn item_end(lines: &[&str], i: usize) -> u32 {
    let mut depth = 0i32;
    let mut opened = false;
    for (k, line) in lines.iter().enumerate().skip(i) {
        for ch in line.split("//").next().unwrap_or("").chars() {
            match ch {
                '{' => {
                    depth += 1;
                    opened = true;
                }
                '}' => depth -= 1,
                _ => {}
            }
            if opened && depth == 0 {
                return k as u32 + 1;
            }
        }
    }
    lines.len() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_with_codes_names_and_reasons() {
        let s = parse(
            "struct P {  // rtlint: allow(RT001, member-straddles-row, reason = \"legacy\")\n  float x;\n};\n",
        );
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].selectors, ["RT001", "member-straddles-row"]);
        assert_eq!(s[0].reason.as_deref(), Some("legacy"));
        // At the end of a line of code: that line only.
        assert_eq!((s[0].line, s[0].column, s[0].covers), (1, 16, (1, 1)));
        assert_eq!(s[0].spans, [(30, 5), (37, 20)]);
        // Alone on its line: that line and the next.
        let s = parse("  // rtlint: allow(RT001)\nstruct P { float x; };\n");
        assert_eq!(s[0].covers, (1, 2));
        assert!(parse("// rtlint: deny(RT001)\n// rtlint allow(RT001)\n").is_empty());
    }

    #[test]
    fn wgsl_directives_and_attributes() {
        let text = "diagnostic(off, rtlint.payload_over_budget);\n\n@diagnostic(off, rtlint.payload_packing_waste)\nfn f() {\n  let a = 1;\n}\nfn g() {}\n";
        let s = parse(text);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].selectors, ["payload-over-budget"]);
        assert_eq!(s[0].covers, (1, u32::MAX));
        assert_eq!(s[1].selectors, ["payload-packing-waste"]);
        assert_eq!(s[1].covers, (3, 6));
        assert_eq!(s[1].spans, [(25, 21)]);
        // Other filters are naga's business.
        assert!(parse("diagnostic(off, derivative_uniformity);\n").is_empty());
        assert!(parse("@diagnostic(warning, rtlint.x) fn f() {}\n").is_empty());
    }
}
