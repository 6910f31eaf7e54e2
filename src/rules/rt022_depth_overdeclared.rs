//! RT022 `depth-overdeclared`: the declared recursion depth is above what
//! the pipeline needs, and the default stack pays for every extra level.

use crate::analysis::recursion::RecursionReport;
use crate::analysis::stack::{vulkan_default, StackReport};
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;


/// A finding when the declared depth exceeds the (bounded) required depth.
pub fn check(pipeline: &Pipeline, rec: &RecursionReport, stack: &StackReport) -> Vec<Diagnostic> {
    let (Some(required), Some(declared)) = (rec.required_depth, pipeline.max_recursion_depth)
    else {
        return Vec::new();
    };
    if declared <= required {
        return Vec::new();
    }
    let m = &stack.driver_comparable.stage_max;
    let (at_declared, at_required) = (vulkan_default(m, declared), vulkan_default(m, required));
    let mut d = Diagnostic::new(
        LEVEL,
        NAME,
        &pipeline.file(),
        format!("declared recursion depth {declared} is above the {required} the pipeline needs"),
    )
    .with_code(CODE)
    .with_primary(
        pipeline.max_recursion_depth_location.clone(),
        format!("declared {declared} here"),
    )
    .with_note(format!(
        "deepest chain: {}",
        crate::explain::recursion_chain(rec)
    ));
    if at_declared > at_required {
        d = d.with_note(format!(
            "the default stack is {at_declared} bytes per thread at depth {declared} and {at_required} at depth {required} (driver-comparable model)"
        ));
    }
    vec![d.with_help(format!(
        "set `max_recursion_depth = {required}` (maxPipelineRayRecursionDepth)"
    ))]
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a declared `maxPipelineRayRecursionDepth` above the depth the
    /// described pipeline needs, with the default stack size at both depths.
    ///
    /// ## Why is this bad?
    ///
    /// When the application does not set the stack size itself, the driver sizes
    /// it by the default formula, in which every declared level beyond the first
    /// adds the largest closest-hit or miss stack — memory reserved per thread
    /// and never used. With large payloads this is what makes the default stack
    /// dangerous (see RT025).
    ///
    /// ## Example
    ///
    /// ```toml
    /// # the iterative pipeline needs depth 2
    /// max_recursion_depth = 8
    /// ```
    ///
    /// ```
    /// warning[RT022]: declared recursion depth 8 is above the 2 the pipeline needs
    ///   = note: the default stack is 256 bytes per thread at depth 8 and 64 at depth 2 (driver-comparable model)
    /// ```
    ///
    /// Use instead:
    ///
    /// ```toml
    /// max_recursion_depth = 2
    /// ```
    ///
    /// ## How to fix
    ///
    /// Declare the required depth, or set the stack size explicitly with
    /// `vkCmdSetRayTracingPipelineStackSizeKHR` / `SetPipelineStackSize` to the
    /// value `rtlint stack` recommends.
    ///
    /// Fixtures: `fixtures/RT022/bad.pipeline.toml`, `fixtures/RT022/good.pipeline.toml`.
    "RT022" "depth-overdeclared" {
        group: Perf,
        summary: "declared recursion depth above what the pipeline needs",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(ctx.pipeline, &ctx.recursion, &ctx.stack)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::recursion::recursion_report;
    use crate::analysis::stack::stack_report;
    use crate::pipeline::load;
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &recursion_report(&p), &stack_report(&p))
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT022/bad.pipeline.toml");
        assert_eq!(d.len(), 1);
        assert_eq!(
            d[0].message,
            "declared recursion depth 8 is above the 2 the pipeline needs"
        );
        // 64 + 1 × 32 + 7 × 32 against 64 + 1 × 32 + 1 × 32.
        assert_eq!(
            d[0].notes[1],
            "the default stack is 320 bytes per thread at depth 8 and 128 at depth 2 (driver-comparable model)"
        );
        assert!(run("fixtures/RT022/good.pipeline.toml").is_empty());
    }
}
