//! RT026 `subobject-depth-mismatch`: an HLSL library's
//! `RaytracingPipelineConfig` declares another recursion depth than the
//! pipeline description that uses it.

use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;

/// A finding for each subobject depth that differs from the description's.
pub fn check(pipeline: &Pipeline) -> Vec<Diagnostic> {
    // Only a `*.pipeline.toml` is a second declaration: a pipeline built from
    // the subobjects takes its depth from them.
    let (true, Some(declared)) = (pipeline.described(), pipeline.max_recursion_depth) else {
        return Vec::new();
    };
    pipeline
        .subobject_depths
        .iter()
        .filter(|d| d.value != declared)
        .map(|d| {
            let value = d.value;
            Diagnostic::new(
                LEVEL,
                NAME,
                &d.location.path,
                format!(
                    "`RaytracingPipelineConfig` declares recursion depth {value}, the pipeline description {declared}"
                ),
            )
            .with_code(CODE)
            .with_primary(Some(d.location.clone()), format!("declared {value} here"))
            .with_secondary(
                pipeline.max_recursion_depth_location.clone(),
                format!("the pipeline description declares {declared}"),
            )
            .with_note(
                "D3D12 creates the state object with the subobject's depth; a Vulkan port with the description's: the two builds recurse to different limits",
            )
            .with_help("declare one depth in both, the one `rtlint stack` gives as required")
        })
        .collect()
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Compares the `maxTraceRecursionDepth` of every `RaytracingPipelineConfig`
    /// (or `RaytracingPipelineConfig1`) subobject in the HLSL libraries of a
    /// described pipeline with the description's `max_recursion_depth`, and
    /// reports each one that differs. The primary label is the subobject, the
    /// secondary the description's line.
    ///
    /// A library that no `*.pipeline.toml` names is described by its own
    /// subobjects (see `docs/pipeline.md`); then there is nothing to compare,
    /// and a subobject depth below what the pipeline needs is RT021's finding,
    /// above it RT022's.
    ///
    /// ## Why is this bad?
    ///
    /// Two declarations of one number drift apart. The D3D12 build creates its
    /// state object with the subobject's depth, the Vulkan build (or the tool
    /// that sizes the stack) with the description's; when the lower one is
    /// below what the shaders need, one of the builds recurses past its
    /// declared depth, which is undefined behaviour (RT021), and only on that
    /// build.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// RaytracingPipelineConfig config = { 1 };
    /// ```
    ///
    /// ```toml
    /// max_recursion_depth = 2
    /// ```
    ///
    /// ```
    /// warning[RT026]: `RaytracingPipelineConfig` declares recursion depth 1, the pipeline description 2
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// RaytracingPipelineConfig config = { 2 };
    /// ```
    ///
    /// ## How to fix
    ///
    /// Declare the same depth in both places: the depth `rtlint stack` reports
    /// as required.
    ///
    /// ## References
    ///
    /// - D3D12 Raytracing Functional Spec, `D3D12_RAYTRACING_PIPELINE_CONFIG`
    ///
    /// Fixtures: `fixtures/RT026/bad.pipeline.toml`, `fixtures/RT026/good.pipeline.toml`.
    "RT026" "subobject-depth-mismatch" {
        group: Suspicious,
        summary: "subobject recursion depth differs from the pipeline description",
        kind: super::Kind::Pipeline(run),
        // Two declared numbers compared: no recursion analysis.
        analysis: Fast,
    }
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(ctx.pipeline)
}
