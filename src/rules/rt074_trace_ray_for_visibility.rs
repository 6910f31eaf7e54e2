//! RT074 `trace-ray-for-visibility`: a pipeline trace used for a plain
//! visibility query.

use super::Context;
use crate::analysis::trace_sites::reached_traces;
use crate::diag::Diagnostic;
use crate::program::OperandValue;

/// `SkipClosestHitShaderKHR`.
const SKIP_CLOSEST_HIT: u64 = 0x8;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a `TraceRay` whose constant ray flags skip the closest-hit shader
    /// (`SkipClosestHitShader`): a shadow or occlusion ray whose only result is
    /// whether anything was hit, set by the miss shader.
    ///
    /// This is advice (pedantic), under an assumption the shader cannot show: that
    /// the target supports inline ray tracing (`VK_KHR_ray_query`, DXR 1.1). Some
    /// drivers expose ray tracing pipelines without ray queries (NVIDIA's Vulkan
    /// driver on the project's H200 machine did).
    ///
    /// ## Why is this bad?
    ///
    /// A pipeline trace is a call into the scheduler: the caller's live state is
    /// saved to the ray stack, a miss shader runs to report the result, and the
    /// payload makes the round trip. An inline `RayQuery` with
    /// `RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH` answers the same question in the
    /// calling shader, with no payload, no miss shader and no stack frame.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// ShadowPayload shadow = { true };
    /// TraceRay(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH |
    ///                 RAY_FLAG_SKIP_CLOSEST_HIT_SHADER, 0xFF, 0, 1, 1, ray, shadow);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// RayQuery<RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE> q;
    /// q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    /// q.Proceed();
    /// bool shadowed = q.CommittedStatus() != COMMITTED_NOTHING;
    /// ```
    ///
    /// ## How to fix
    ///
    /// Replace the trace by an inline ray query where the target supports it; keep
    /// the pipeline trace where any-hit shaders (alpha-tested shadows) must run.
    ///
    /// Fixtures: `fixtures/RT074/`.
    ///
    /// ## References
    ///
    /// - Microsoft, DirectX Raytracing functional spec, "Inline raytracing" (when
    ///   to prefer `RayQuery`).
    /// - Vulkan specification, `VK_KHR_ray_query`.
    "RT074" "trace-ray-for-visibility" {
        group: Pedantic,
        summary: "pipeline trace used for a visibility query an inline ray query would answer",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    let mut out = Vec::new();
    let mut reported = super::Reported::default();
    for t in reached_traces(program).iter() {
        let OperandValue::Const(flags) = t.operands.ray_flags else {
            continue;
        };
        if flags & SKIP_CLOSEST_HIT == 0 {
            continue;
        }
        let site = &program.sites[t.site];
        let at = program.location_in(site.inst, &t.chain);
        if !reported.first(0, site.inst, &at) {
            continue;
        }
        let entry = &program.entry_points[t.entry];
        out.push(
            ctx.diagnostic(
                &RULE,
                format!(
                    "trace skips the closest-hit shader (flags `{flags:#x}`): a visibility query"
                ),
            )
            .with_primary(at, "visibility ray")
            .with_subject(format!("trace in `{}`", entry.name))
            .with_note("assumes the target supports inline ray tracing (`VK_KHR_ray_query`, DXR 1.1)")
            .with_help("answer the query with an inline ray query where the target supports it"),
        );
    }
    out
}
