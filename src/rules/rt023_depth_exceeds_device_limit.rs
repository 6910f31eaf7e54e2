//! RT023 `depth-exceeds-device-limit`: the declared or required recursion
//! depth is above what devices support (31 on lavapipe, NVIDIA and DXR).

use crate::analysis::recursion::RecursionReport;
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;


/// `device_limit` is `maxRayRecursionDepth` (31 on the devices measured;
/// the description's `device_max_recursion_depth` overrides it).
pub fn check(pipeline: &Pipeline, rec: &RecursionReport, device_limit: u32) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let file = pipeline.file();
    let note = "NVIDIA fails pipeline creation above 31; lavapipe accepts it (measured running to about 1,000 levels, crashing at 5,000), so a test on lavapipe does not catch it";
    if let Some(declared) = pipeline.max_recursion_depth.filter(|&d| d > device_limit) {
        out.push(
            Diagnostic::new(
                LEVEL,
                NAME,
                &file,
                format!(
                    "declared recursion depth {declared} exceeds the device limit of {device_limit}"
                ),
            )
            .with_code(CODE)
            .with_primary(
                pipeline.max_recursion_depth_location.clone(),
                format!("declared {declared} here"),
            )
            .with_note(note)
            .with_help(format!(
                "declare at most {device_limit} and bound the recursion in the shaders"
            )),
        );
    }
    if let Some(required) = rec.required_depth.filter(|&d| d > device_limit) {
        let deepest = rec.chain.iter().rev().find_map(|s| s.via.clone());
        out.push(
            Diagnostic::new(
                LEVEL,
                NAME,
                &file,
                format!(
                    "pipeline needs recursion depth {required}, above the device limit of {device_limit}"
                ),
            )
            .with_code(CODE)
            .with_primary(deepest, format!("this trace runs at depth {required}"))
            .with_note(format!("deepest chain: {}", crate::explain::recursion_chain(rec)))
            .with_note(note)
            .with_help("loop over bounces in the ray generation shader instead of recursing"),
        );
    }
    out
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a declared recursion depth, or a required one, above the device's
    /// `maxRayRecursionDepth` (31 on lavapipe, NVIDIA and in DXR; set
    /// `device_max_recursion_depth` in the description for another device).
    ///
    /// ## Why is this bad?
    ///
    /// A declared depth above 31 fails pipeline creation on NVIDIA
    /// (`VK_ERROR_INITIALIZATION_FAILED`) while lavapipe accepts it — the pipeline
    /// works on one driver and not on another. A required depth above the limit
    /// cannot be declared at all: the deepest rays recurse past the declared depth,
    /// which crashes lavapipe and hangs NVIDIA GPUs.
    ///
    /// ## Example
    ///
    /// ```toml
    /// # 38 reflections and a shadow ray
    /// max_recursion_depth = 40
    /// ```
    ///
    /// ```
    /// error[RT023]: declared recursion depth 40 exceeds the device limit of 31
    /// error[RT023]: pipeline needs recursion depth 40, above the device limit of 31
    /// ```
    ///
    /// Use instead: bound the recursion to at most 29 reflections (depth 31), or
    /// loop over bounces in the ray generation shader.
    ///
    /// ## How to fix
    ///
    /// Declare at most the device limit and bound the recursion in the shaders;
    /// for deep bounce counts, use the iterative loop (depth 1 or 2 for any
    /// number of bounces).
    ///
    /// Fixtures: `fixtures/RT023/bad.pipeline.toml`, `fixtures/RT023/good.pipeline.toml`.
    "RT023" "depth-exceeds-device-limit" {
        group: Correctness,
        summary: "recursion depth above the device limit",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(
        ctx.pipeline,
        &ctx.recursion,
        ctx.pipeline.device_max_recursion_depth,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::recursion::recursion_report;
    use crate::pipeline::{load, DEFAULT_DEVICE_MAX_RECURSION_DEPTH};
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &recursion_report(&p), p.device_max_recursion_depth)
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT023/bad.pipeline.toml");
        assert_eq!(d.len(), 2, "{d:?}");
        assert_eq!(
            d[0].message,
            "declared recursion depth 40 exceeds the device limit of 31"
        );
        assert_eq!(
            d[1].message,
            "pipeline needs recursion depth 40, above the device limit of 31"
        );
        assert!(run("fixtures/RT023/good.pipeline.toml").is_empty());
        assert_eq!(DEFAULT_DEVICE_MAX_RECURSION_DEPTH, 31);
    }
}
