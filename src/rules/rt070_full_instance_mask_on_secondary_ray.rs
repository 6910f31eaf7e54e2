//! RT070 `full-instance-mask-on-secondary-ray`: a secondary ray traced with
//! the full instance mask.

use super::Context;
use crate::analysis::trace_sites::{is_bounce, reached_traces};
use crate::diag::Diagnostic;
use crate::program::OperandValue;
use crate::shader::Stage;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a secondary ray — one traced from a closest-hit or miss shader, or
    /// inside a loop of the ray generation shader whose origin or direction comes
    /// from a ray payload (a bounce loop, not a loop over samples) — whose instance
    /// (cull) mask is the constant `0xFF`, so it tests every instance of the scene.
    /// Traces whose mask is not a compile-time constant are not reported.
    ///
    /// This is advice (pedantic): whether some instances can be left out of
    /// secondary rays depends on the scene, which the shader does not show.
    ///
    /// ## Why is this bad?
    ///
    /// Reflection, shadow and indirect rays rarely need every instance: particles,
    /// decals, first-person geometry, light proxies and small detail objects can be
    /// given their own mask bit and left out of secondary rays. The mask is tested
    /// before any traversal of the instance, so every instance it excludes is
    /// traversal work saved on the most numerous rays.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// for (int bounce = 0; bounce < maxBounces; ++bounce) {
    ///     traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, origin, 0.001, dir, 1e4, 0);
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// const uint MASK_SECONDARY = 0x01; // instances that matter to bounces
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, bounce == 0 ? 0xFF : MASK_SECONDARY, ...);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Give instances that secondary rays can skip their own mask bit
    /// (`VkAccelerationStructureInstanceKHR::mask`, `D3D12_RAYTRACING_INSTANCE_DESC::InstanceMask`)
    /// and trace secondary rays with a mask that leaves that bit out.
    ///
    /// Fixtures: `fixtures/RT070/`.
    ///
    /// ## References
    ///
    /// - NVIDIA, "Best Practices for Using NVIDIA RTX Ray Tracing" (instance masks).
    /// - Vulkan specification, "Ray Culling Mask".
    "RT070" "full-instance-mask-on-secondary-ray" {
        group: Pedantic,
        summary: "secondary ray traced with the full instance mask 0xFF",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    for t in reached_traces(program).iter() {
        let site = &program.sites[t.site];
        let secondary = match t.stage {
            Stage::ClosestHit | Stage::Miss => true,
            // A bounce: in a loop, and the ray starts from or goes where the
            // previous trace's payload says (not a loop over samples).
            Stage::RayGeneration => is_bounce(program, site.inst, &t.chain, t.in_loop),
            _ => false,
        };
        if !secondary || t.operands.cull_mask != OperandValue::Const(0xFF) {
            continue;
        }
        let at = program.location_in(site.inst, &t.chain);
        if !reported.first(0, site.inst, &at) {
            continue;
        }
        let why = match t.stage {
            Stage::RayGeneration => "in a loop of the ray generation shader",
            Stage::Miss => "from a miss shader",
            _ => "from a closest-hit shader",
        };
        let entry = &program.entry_points[t.entry];
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("secondary ray traced {why} tests every instance (mask `0xFF`)"),
            )
            .with_primary(at, "full instance mask")
            .with_subject(format!("trace in `{}`", entry.name))
            .with_help("trace secondary rays with a mask that leaves out instances they can skip"),
        );
    }
    out
}
