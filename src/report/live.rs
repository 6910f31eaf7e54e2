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
        let at = match (site.line, site.column) {
            (Some(l), Some(c)) if c > 0 => format!("{}:{l}:{c}", site.path.display()),
            (Some(l), _) => format!("{}:{l}", site.path.display()),
            _ => site.path.display().to_string(),
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
            let line = |l: Option<u32>| l.map(|l| l.to_string()).unwrap_or("?".into());
            let _ = writeln!(
                s,
                "  {:>4} B  {:<16} {:<10} {:<8} defined line {}, used line {}{}",
                v.size,
                v.name,
                v.ty,
                match v.storage {
                    Storage::Ssa => "value",
                    Storage::Variable => "variable",
                },
                line(v.def_line),
                line(v.use_line),
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
