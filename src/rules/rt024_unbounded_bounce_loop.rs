//! RT024 `unbounded-bounce-loop`: a loop around a trace, or a recursion
//! cycle, whose bound is not known at compile time.

use crate::analysis::recursion::{trace_loops, RecursionReport};
use crate::diag::{Diagnostic, Severity};
use crate::pipeline::Pipeline;

pub const CODE: &str = "RT024";
pub const NAME: &str = "unbounded-bounce-loop";
pub const LEVEL: Severity = Severity::Warning;

/// Loops around traces in every program of the pipeline (bounds may come
/// from its `[constants]`), and recursion cycles without a recognised guard.
pub fn check(pipeline: &Pipeline, rec: &RecursionReport) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for program in &pipeline.programs {
        for l in trace_loops(program, &pipeline.constants) {
            let Err(why) = &l.bound else { continue };
            out.push(
                Diagnostic::new(
                    LEVEL,
                    NAME,
                    &program.path,
                    format!(
                        "loop around a trace in `{}` has no bound known at compile time",
                        l.entry
                    ),
                )
                .with_code(CODE)
                .with_subject(l.entry.clone())
                .with_primary(l.location.clone(), "loop starts here")
                .with_secondary(l.site_location.clone(), "traces here")
                .with_note(why.to_string())
                .with_help(
                    "compare the bounce counter with a constant, or give the bound under `[constants]` in the pipeline description",
                ),
            );
        }
    }
    for c in rec.cycles.iter().filter(|c| c.extra_levels.is_none()) {
        for site in &c.sites {
            let Err(why) = &site.guard else { continue };
            let file = pipeline
                .programs
                .get(site.program)
                .map(|p| p.path.clone())
                .unwrap_or_default();
            let names: Vec<String> = c
                .nodes
                .iter()
                .map(|&n| crate::explain::node(&rec.graph.nodes[n]))
                .collect();
            out.push(
                Diagnostic::new(
                    LEVEL,
                    NAME,
                    &file,
                    format!(
                        "recursion through {} is unbounded at compile time",
                        names.join(", ")
                    ),
                )
                .with_code(CODE)
                .with_primary(site.location.clone(), "this trace closes the cycle")
                .with_note(why.to_string())
                .with_help(
                    "guard the trace with a depth counter carried in the payload and compared with a constant",
                ),
            );
        }
    }
    out
}

pub static RULE: super::Rule = super::Rule {
    code: CODE,
    name: NAME,
    group: super::Group::Perf,
    level: LEVEL,
    summary: "bounce loop or recursion with no bound known at compile time",
    doc: include_str!("../../rules/RT024.md"),
    kind: super::Kind::Pipeline(run),
};

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(ctx.pipeline, &ctx.recursion)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::recursion::recursion_report;
    use crate::pipeline::load;
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &recursion_report(&p))
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT024/bad.pipeline.toml");
        assert_eq!(d.len(), 2, "{d:?}");
        assert_eq!(
            d[0].message,
            "loop around a trace in `main` has no bound known at compile time"
        );
        assert_eq!(d[0].notes[0], "no exit compares a counter with a bound");
        assert_eq!(
            d[1].message,
            "recursion through closesthit `main` (hit group 0) is unbounded at compile time"
        );
        assert!(
            d[1].notes[0].contains("pushConst.maxDepth"),
            "{:?}",
            d[1].notes
        );
        assert!(run("fixtures/RT024/good.pipeline.toml").is_empty());
        // The reference pipeline's loop is bounded by its description.
        assert!(run("shaders/reflect_iterative.pipeline.toml").is_empty());
    }
}
