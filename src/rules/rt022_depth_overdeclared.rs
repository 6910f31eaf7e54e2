//! RT022 `depth-overdeclared`: the declared recursion depth is above what
//! the pipeline needs, and the default stack pays for every extra level.

use crate::analysis::recursion::RecursionReport;
use crate::analysis::stack::{vulkan_default, StackReport};
use crate::diag::{Diagnostic, Severity};
use crate::pipeline::Pipeline;

pub const CODE: &str = "RT022";
pub const NAME: &str = "depth-overdeclared";
pub const LEVEL: Severity = Severity::Warning;

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

pub static RULE: super::Rule = super::Rule {
    code: CODE,
    name: NAME,
    group: super::Group::Perf,
    level: LEVEL,
    summary: "declared recursion depth above what the pipeline needs",
    doc: include_str!("../../rules/RT022.md"),
    kind: super::Kind::Pipeline(run),
};

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
