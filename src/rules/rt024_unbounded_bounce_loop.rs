//! RT024 `unbounded-bounce-loop`: a loop around a trace, or a recursion
//! cycle, whose bound is not known at compile time.

use crate::analysis::recursion::{trace_loops, NoGuard, NoLoopBound, RecursionReport};
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;


/// Loops around traces in every program of the pipeline (bounds may come
/// from its `[constants]`), and recursion cycles without a recognised guard.
pub fn check(pipeline: &Pipeline, rec: &RecursionReport) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    // A counter compared with a push constant or uniform is bounded by the
    // application; only a description's `[constants]` can give that bound,
    // so without one there is nothing the shader could change.
    let described = pipeline.described();
    for program in &pipeline.programs {
        for l in trace_loops(program, &pipeline.constants) {
            let Err(why) = &l.bound else { continue };
            if !described && matches!(why, NoLoopBound::BoundUnknown { .. }) {
                continue;
            }
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
            if !described && matches!(why, NoGuard::BoundUnknown { .. }) {
                continue;
            }
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
                        "recursion through {} is unbounded at compile time: the trace{} has no depth bound",
                        names.join(", "),
                        // Named by its shader, which every build of the
                        // module has; the label gives its line when debug
                        // info does.
                        c.nodes
                            .iter()
                            .map(|&n| &rec.graph.nodes[n])
                            .find(|n| n.shader.program == site.program)
                            .map(|n| format!(" in {}", crate::explain::node(n)))
                            .unwrap_or_default()
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

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds loops around traces whose iteration count is not bounded at compile
    /// time, and recursion cycles (a closest-hit shader that can reach itself)
    /// without a recognised depth guard. A loop is bounded when an exit compares a
    /// counter, incremented by a constant in the loop, with a constant, a
    /// specialization constant, or a push-constant / uniform value the pipeline
    /// description gives under `[constants]`. A cycle is bounded when each trace
    /// closing it is dominated by a comparison of a depth counter carried in the
    /// payload with such a bound and the traced payload's counter grows by a
    /// constant. The message names the trace that closes the cycle without a
    /// bound, and the note says what was found instead. `rtlint stack` then
    /// recommends a stack only on the condition that the recursion stops
    /// within the declared depth (else the device's limit) and says so.
    ///
    /// Without a `*.pipeline.toml` (loose shaders, or a library described by
    /// its DXR subobjects) a bound read from a push constant or uniform is
    /// not reported: the application sets it, and only a description's
    /// `[constants]` could give it (on public shaders, 16 of 22 findings were
    /// such bounds; `docs/rules-precision.md`).
    ///
    /// The rule is pedantic (off unless selected): of what remained on public
    /// shaders, none was a loop that really ends only on a miss, and one was a
    /// recursion bounded in a way the analysis does not follow (a
    /// `SkipShading` flag in the payload instead of a counter).
    ///
    /// ## Why is this bad?
    ///
    /// A loop that ends only when a ray misses can run for as long as the scene
    /// lets rays bounce: per-pixel cost without limit, and GPU time-outs on
    /// pathological views. A recursion cycle without a guard needs an unbounded
    /// depth: no declared `maxPipelineRayRecursionDepth` is provably enough, and
    /// rtlint cannot compute an exact stack size for it.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// while (true) {
    ///     traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, origin, 0.001, dir, 100.0, 0);
    ///     if (hit.w <= 0.0) break;
    ///     // ...
    /// }
    /// ```
    ///
    /// ```
    /// warning[RT024]: loop around a trace in `main` has no bound known at compile time
    ///   = note: no exit compares a counter with a bound
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// const int MAX_BOUNCES = 8;
    /// for (int bounce = 0; bounce < MAX_BOUNCES; bounce++) { ... }
    /// ```
    ///
    /// A bound read from a uniform (`params.max_bounces`) or a push constant
    /// (`pushConst.maxDepth`) counts once the description gives its value:
    ///
    /// ```toml
    /// [constants]
    /// "pushConst.maxDepth" = 3
    /// ```
    ///
    /// ## How to fix
    ///
    /// Compare the bounce counter with a constant, or give the bound under
    /// `[constants]` in the pipeline description.
    ///
    /// Fixtures: `fixtures/RT024/bad.pipeline.toml` (both cases),
    /// `fixtures/RT024/good.pipeline.toml`.
    "RT024" "unbounded-bounce-loop" {
        group: Pedantic,
        summary: "bounce loop or recursion with no bound known at compile time",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

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
        // The message names the trace that makes the depth unbounded.
        assert_eq!(
            d[1].message,
            "recursion through closesthit `main` (hit group 0) is unbounded at compile time: the trace in closesthit `main` (hit group 0) has no depth bound"
        );
        // Its line is the label's, where debug info gives one.
        let at = &d[1].primary.as_ref().unwrap().location;
        assert!(at.path.ends_with("fixtures/pipelines/recursive/reflect.rchit"), "{at:?}");
        assert_eq!(at.line, 25);
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
