//! `rtlint live` in words.

use crate::analysis::liveness::{LiveReport, Storage};

/// The human form of `rtlint live`.
pub fn human(report: &LiveReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    if report.sites.is_empty() {
        s.push_str("no trace, callable or ray-query sites\n");
        return s;
    }
    for site in &report.sites {
        // A line belongs to the source file the debug info names, not to
        // the module.
        let at = match &site.location {
            Some(l) if l.column > 0 => format!("{}:{}:{}", l.path.display(), l.line, l.column),
            Some(l) => format!("{}:{}", l.path.display(), l.line),
            None => site.path.display().to_string(),
        };
        let _ = writeln!(
            s,
            "{at}: {} in `{}` ({}): {} bytes live, {} rematerializable",
            site.kind.as_str(),
            site.entry,
            site.stage.as_str(),
            site.live_bytes,
            site.rematerializable_bytes
        );
        if let Some(p) = &site.payload {
            let size = p
                .size
                .map(|b| format!("{b} bytes"))
                .unwrap_or("unsized".into());
            let _ = writeln!(s, "  payload `{}`: {} ({size}, not counted)", p.name, p.ty);
        }
        for v in &site.values {
            let line = |what: &str, l: Option<u32>| {
                l.map(|l| format!("{what} line {l}"))
                    .unwrap_or(format!("{what} at no known line"))
            };
            let _ = writeln!(
                s,
                "  {:>4} B  {:<16} {:<10} {:<8} {}, {}{}",
                v.size,
                v.name,
                v.ty,
                match v.storage {
                    Storage::Ssa => "value",
                    Storage::Variable => "variable",
                },
                line("defined", v.def_line),
                line("used", v.use_line),
                if v.rematerializable {
                    "  (rematerializable)"
                } else {
                    ""
                }
            );
        }
    }
    s
}
