//! RT025 `default-stack-unsafe`: the stack size a driver picks by default
//! for the declared depth is larger than a device is known to survive.

use crate::analysis::stack::StackReport;
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;

pub use crate::analysis::stack::NVIDIA_KNOWN_SAFE_STACK_BYTES as DEFAULT_LIMIT_BYTES;

/// A finding when the Vulkan default stack, from the driver-comparable
/// sizes and the declared depth, exceeds `limit_bytes`.
pub fn check(pipeline: &Pipeline, stack: &StackReport, limit_bytes: u64) -> Vec<Diagnostic> {
    let Some(default) = stack.driver_comparable.vulkan_default else {
        return Vec::new();
    };
    if default <= limit_bytes {
        return Vec::new();
    }
    let declared = pipeline.max_recursion_depth.unwrap_or(0);
    let mut d = Diagnostic::new(
        LEVEL,
        NAME,
        &pipeline.file(),
        format!(
            "default pipeline stack of {default} bytes per thread is above the {limit_bytes} bytes known to run"
        ),
    )
    .with_code(CODE)
    .with_primary(
        pipeline.max_recursion_depth_location.clone(),
        format!("depth {declared} multiplies the largest closest-hit or miss stack"),
    )
    .with_note(
        "on an NVIDIA H200 (driver 580.159.04) a pipeline stack of 14,746 bytes per thread lost the device at the first trace and 14,702 ran; a stack set below what the call chain needs hung the GPU",
    );
    // A recommendation conditional on an assumed depth is no call chain.
    let help = match stack
        .recommended
        .filter(|_| stack.assumed_depth.is_none())
        .or(stack.driver_comparable.exact_call_chain)
    {
        Some(v) => {
            d = d.with_note(format!(
                "the deepest call chain needs {v} bytes ({})",
                if stack.depth_chain.is_empty() {
                    "no chain".into()
                } else {
                    crate::explain::stack_chain(stack)
                }
            ));
            if v <= limit_bytes {
                format!("set the stack explicitly: vkCmdSetRayTracingPipelineStackSizeKHR(cmd, {v}) or SetPipelineStackSize({v})")
            } else {
                // The scene itself needs more than is known to run.
                "reduce the recursion depth or the payload until the call chain fits, then set the stack explicitly".into()
            }
        }
        None => "declare the depth the pipeline needs and set the stack size explicitly".into(),
    };
    vec![d.with_help(help)]
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Computes the stack size a driver picks by default for the described
    /// pipeline — the Vulkan/DXR default formula over the per-shader sizes a
    /// driver reports (rtlint's driver-comparable model, calibrated on NVIDIA) with
    /// the declared depth — and reports it when it is above the largest stack
    /// measured to run (14,702 bytes per thread). It prints the exact call-chain
    /// value to set instead when that value fits.
    ///
    /// ## Why is this bad?
    ///
    /// The default formula multiplies the largest closest-hit stack by the
    /// declared depth, however deep the shaders really recurse. Measured on an
    /// NVIDIA H200 (driver 580.159.04): a pipeline stack of 14,746 bytes per thread
    /// loses the device at the first trace (`VK_ERROR_DEVICE_LOST`) and 14,702 runs,
    /// whatever the dispatch size. FIELD-NOTES record the same failure on an H100
    /// for a 256-byte payload at depth 29–31 (a default of 15,936–17,024 bytes).
    ///
    /// Setting a smaller stack is not automatically safe either: with 30 levels of
    /// real recursion, explicit stacks of 4,096 and 5,056 bytes hung the GPU, while
    /// the exact call-chain value ran. Set the value the call chain needs.
    ///
    /// ## Example
    ///
    /// ```toml
    /// # a 512-byte payload; the closest-hit shader reflects up to 30 times
    /// max_recursion_depth = 31
    /// ```
    ///
    /// ```
    /// error[RT025]: default pipeline stack of 17280 bytes per thread is above the 14702 bytes known to run
    ///   = help: reduce the recursion depth or the payload until the call chain fits, then set the stack explicitly
    /// ```
    ///
    /// Here the guard really allows 30 reflections, so the deepest call chain
    /// needs the same 17,280 bytes. When the declared depth is only a generous
    /// upper bound (the guard allows 2 reflections), the help gives the exact
    /// call-chain value to set instead:
    /// `vkCmdSetRayTracingPipelineStackSizeKHR(cmd, 2048)`.
    ///
    /// Use instead: a smaller payload (past 128 bytes every byte is on the
    /// stack), fewer levels (depth 8: 4,768 bytes), or the iterative loop; then
    /// set the stack size explicitly to the value `rtlint stack` recommends.
    ///
    /// ## How to fix
    ///
    /// Set the stack size explicitly with `vkCmdSetRayTracingPipelineStackSizeKHR`
    /// / `SetPipelineStackSize` to the exact call-chain value, and reduce the
    /// declared depth or the payload until that value is small.
    ///
    /// ## Options
    ///
    /// - `stack-limit` in `rtlint.toml` (bytes per thread; default 14,702, the
    ///   largest stack measured to run on an NVIDIA H200).
    ///
    /// Fixtures: `fixtures/RT025/bad.pipeline.toml`, `fixtures/RT025/good.pipeline.toml`.
    "RT025" "default-stack-unsafe" {
        group: Correctness,
        summary: "default pipeline stack above what the device is known to survive",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
        options: [super::RuleOption {
            name: "limit",
            default: "14702",
            doc: "the largest default pipeline stack, in bytes per thread, the device is known to run (top-level `stack-limit` too)",
        }],
    }
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(
        ctx.pipeline,
        &ctx.stack,
        super::option_u64(ctx.config, &RULE, "limit", ctx.config.stack_limit),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::stack::stack_report;
    use crate::pipeline::load;
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &stack_report(&p), DEFAULT_LIMIT_BYTES)
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT025/bad.pipeline.toml");
        assert_eq!(d.len(), 1);
        // 416 + 31 × 544, the calibrated model for a 512-byte payload.
        assert_eq!(
            d[0].message,
            "default pipeline stack of 17280 bytes per thread is above the 14702 bytes known to run"
        );
        // 30 reflections really need 17,280 bytes: setting it would not help.
        assert_eq!(
            d[0].help.as_deref(),
            Some("reduce the recursion depth or the payload until the call chain fits, then set the stack explicitly")
        );
        // Depth 8: 416 + 8 × 544 = 4768.
        assert!(run("fixtures/RT025/good.pipeline.toml").is_empty());
        // Declared 31 but the guard allows 2 reflections: the recommended
        // size, the exact chain of the full model with its safety margin
        // (448 + 3 × 576 = 2,176), is safe to set.
        let mut p =
            load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/RT025/bad.pipeline.toml"))
                .unwrap();
        p.constants.get_mut("pushConst.maxDepth").unwrap().value = 2;
        let d = check(&p, &stack_report(&p), DEFAULT_LIMIT_BYTES);
        assert_eq!(
            d[0].help.as_deref(),
            Some("set the stack explicitly: vkCmdSetRayTracingPipelineStackSizeKHR(cmd, 2176) or SetPipelineStackSize(2176)")
        );
        // Without the bound the recursion is unbounded: the recommendation
        // is conditional on the declared depth, no call chain's need.
        p.constants.remove("pushConst.maxDepth");
        let r = stack_report(&p);
        assert_eq!(r.assumed_depth, Some(31));
        let d = check(&p, &r, DEFAULT_LIMIT_BYTES);
        assert!(
            !d[0].notes.iter().any(|n| n.contains("deepest call chain")),
            "{:?}",
            d[0].notes
        );
    }
}
