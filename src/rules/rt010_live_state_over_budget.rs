//! RT010 `live-state-over-budget`: more state kept alive across a trace
//! than the budget allows.

use crate::analysis::liveness::LiveSite;
use crate::diag::{Diagnostic, Severity};
use crate::program::Program;

pub const CODE: &str = "RT010";
pub const NAME: &str = "live-state-over-budget";
pub const LEVEL: Severity = Severity::Warning;
/// Sixteen 32-bit values: what fits in a closest-hit shader's 32-B stack
/// step twice over.
pub const DEFAULT_BUDGET_BYTES: u64 = 64;

/// One finding per trace or callable site whose state that cannot be
/// recomputed (live bytes minus rematerializable bytes) exceeds
/// `budget_bytes`. Ray-query loops are left out: an inline query is no shader
/// call, so its live values stay in registers rather than on a ray stack
/// (`rtlint live` still lists them).
pub fn check(program: &Program, sites: &[LiveSite], budget_bytes: u64) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for site in sites.iter().filter(|s| {
        s.path == program.path && s.kind != crate::analysis::liveness::LiveSiteKind::RayQuery
    }) {
        let kept = site.live_bytes - site.rematerializable_bytes;
        if kept <= budget_bytes {
            continue;
        }
        let what = match site.kind {
            crate::analysis::liveness::LiveSiteKind::TraceRay => "the trace",
            crate::analysis::liveness::LiveSiteKind::ExecuteCallable => "the callable",
            crate::analysis::liveness::LiveSiteKind::RayQuery => "the ray-query loop",
        };
        let mut d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            format!(
                "{kept} bytes of state are live across {what} in `{}`, above the {budget_bytes}-byte budget",
                site.entry
            ),
        )
        .with_code(CODE)
        .with_subject(site.entry.clone())
        .with_primary(site.location.clone(), format!("{kept} bytes kept across this call"));
        for v in site.values.iter().filter(|v| !v.rematerializable).take(4) {
            d = d.with_secondary(
                v.def.clone(),
                format!("`{}` ({}, {} bytes) defined here", v.name, v.ty, v.size),
            );
        }
        let list: Vec<String> = site
            .values
            .iter()
            .map(|v| {
                format!(
                    "`{}` {} B{}",
                    v.name,
                    v.size,
                    if v.rematerializable {
                        " (recomputable)"
                    } else {
                        ""
                    }
                )
            })
            .collect();
        d = d.with_note(format!("live values: {}", list.join(", ")));
        if site.rematerializable_bytes > 0 {
            d = d.with_note(format!(
                "{} of the {} live bytes can be recomputed after the call and are not counted",
                site.rematerializable_bytes, site.live_bytes
            ));
        }
        out.push(d.with_help(
            "recompute values after the trace from builtins and buffers, or carry them in the payload",
        ));
    }
    out
}

pub static RULE: super::Rule = super::Rule {
    code: CODE,
    name: NAME,
    group: super::Group::Perf,
    level: LEVEL,
    summary: "state kept alive across a trace call above the budget",
    doc: include_str!("../../rules/RT010.md"),
    kind: super::Kind::Module(run),
};

fn run(ctx: &super::Context) -> Vec<Diagnostic> {
    check(
        ctx.program,
        &crate::analysis::liveness::live_sites(ctx.program),
        ctx.config.live_state_budget.unwrap_or(DEFAULT_BUDGET_BYTES),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::liveness::live_sites;
    use crate::front::load;
    use crate::shader::Language;
    use std::path::Path;

    fn run(rel: &str, budget: u64) -> Vec<Diagnostic> {
        let p = load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join(rel),
            Language::Spirv,
        )
        .unwrap();
        check(&p, &live_sites(&p), budget)
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT010/bad.rgen.spv", DEFAULT_BUDGET_BYTES);
        assert_eq!(d.len(), 1);
        assert_eq!(
            d[0].message,
            "128 bytes of state are live across the trace in `main`, above the 64-byte budget"
        );
        assert_eq!(d[0].primary.as_ref().unwrap().location.line, 19);
        assert!(run("fixtures/RT010/good.rgen.spv", DEFAULT_BUDGET_BYTES).is_empty());
        // The seed keeps 24 bytes, 12 of them recomputable (`directLight`).
        assert_eq!(run("fixtures/live/seed.rchit.spv", 11).len(), 1);
        assert!(run("fixtures/live/seed.rchit.spv", 12).is_empty());
    }
}
