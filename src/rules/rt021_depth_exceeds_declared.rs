//! RT021 `depth-exceeds-declared`: the pipeline recurses deeper than the
//! `maxPipelineRayRecursionDepth` the application declares.

use crate::analysis::recursion::RecursionReport;
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;


/// A finding when the required depth (bounded) exceeds the declared one.
pub fn check(pipeline: &Pipeline, rec: &RecursionReport) -> Vec<Diagnostic> {
    let (Some(required), Some(declared)) = (rec.required_depth, pipeline.max_recursion_depth)
    else {
        return Vec::new();
    };
    if required <= declared {
        return Vec::new();
    }
    let deepest = rec.chain.iter().rev().find_map(|s| s.via.clone());
    vec![Diagnostic::new(
        LEVEL,
        NAME,
        &pipeline.file(),
        format!("pipeline needs recursion depth {required}, above the declared {declared}"),
    )
    .with_code(CODE)
    .with_primary(
        pipeline.max_recursion_depth_location.clone(),
        format!("declared {declared} here"),
    )
    .with_secondary(deepest, format!("this trace runs at depth {required}"))
    .with_note(format!("deepest chain: {}", crate::explain::recursion_chain(rec)))
    .with_note(
        "recursing past the declared depth is undefined: lavapipe crashes at once; NVIDIA returns correct results for some extra levels, then hangs the GPU",
    )
    .with_help(format!("set `max_recursion_depth = {required}` (maxPipelineRayRecursionDepth)"))]
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Computes the recursion depth the described pipeline needs (the deepest
    /// chain of traces, cycles bounded by their depth guards) and reports it when
    /// it is above `max_recursion_depth`, the `maxPipelineRayRecursionDepth` the
    /// application declares. The primary label points at the declaration in the
    /// pipeline description, the secondary at the deepest trace.
    ///
    /// ## Why is this bad?
    ///
    /// Tracing past the declared depth is undefined behaviour. Measured: lavapipe
    /// crashes the process at once (SIGSEGV/SIGBUS); NVIDIA (H100, driver 580)
    /// returns correct results for about 10–17 extra levels and then hangs the GPU
    /// (fence timeout) beyond about 23 — so the bug can pass testing on one
    /// machine and take down another.
    ///
    /// ## Example
    ///
    /// ```toml
    /// # 3 reflections (pushConst.maxDepth = 3) and a shadow ray from every hit
    /// max_recursion_depth = 3
    /// ```
    ///
    /// ```
    /// error[RT021]: pipeline needs recursion depth 5, above the declared 3
    /// ```
    ///
    /// Use instead:
    ///
    /// ```toml
    /// max_recursion_depth = 5
    /// ```
    ///
    /// ## How to fix
    ///
    /// Declare the required depth (rtlint prints it and the chain that needs it),
    /// or lower the depth guard's bound in the shaders.
    ///
    /// Fixtures: `fixtures/RT021/bad.pipeline.toml`, `fixtures/RT021/good.pipeline.toml`.
    "RT021" "depth-exceeds-declared" {
        group: Correctness,
        summary: "pipeline needs more recursion than it declares",
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
    use crate::diag::Severity;
    use crate::analysis::recursion::recursion_report;
    use crate::pipeline::load;
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &recursion_report(&p))
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT021/bad.pipeline.toml");
        assert_eq!(d.len(), 1);
        assert_eq!(
            d[0].message,
            "pipeline needs recursion depth 5, above the declared 3"
        );
        assert_eq!(d[0].severity, Severity::Error);
        assert_eq!(d[0].primary.as_ref().unwrap().location.line, 2);
        assert_eq!(d[0].secondary.len(), 1);
        assert!(run("fixtures/RT021/good.pipeline.toml").is_empty());
    }
}
