use super::{indent, Context};
use crate::analysis::layout::Role;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Lays out each ray payload and callable-data struct of an HLSL (DXR) shader
    /// under HLSL's 16-byte packing (no scalar or vector crosses a 16-byte row; structs, arrays and
    /// matrices start a new row; the last member is not padded) and compares the
    /// declared member order with the best possible order. When another order needs
    /// fewer bytes, it reports both sizes and offers the reordered struct. Among
    /// equally small orders it picks the one that moves members least (the
    /// lexicographically smallest list of declared positions). The search is exact
    /// for structs of up to 16 members.
    ///
    /// Only HLSL shaders are checked: the module's language is HLSL, or its
    /// SPIR-V debug info names an `.hlsl` source. Vulkan sizes GLSL and WGSL
    /// payloads with its scalar payload rule (every scalar aligned to the largest
    /// scalar alignment in the block), which has no 16-byte rows, so no member
    /// order of a GLSL or WGSL payload wastes rows; those modules are not
    /// reported.
    ///
    /// ## Why is this bad?
    ///
    /// Shaders compiled with 16-byte packing (DXC's cbuffer rules, and the way many
    /// engines share payload structs with constant buffers) store each row of the
    /// payload as a register quadruple. Padding inside those rows is stored, copied
    /// and spilled like data, so a badly ordered payload costs the same as a larger
    /// one.
    ///
    /// Fixtures: `fixtures/RT002/` (HLSL bad and good; GLSL and WGSL payloads that
    /// are not reported).
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;     // row 0, bytes 0..12
    ///     float2 uv;        // would cross row 0: moved to row 1
    ///     float distance;   // row 1
    /// };                    // 28 bytes, 2 rows, 4 bytes padding
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;
    ///     float distance;   // fills row 0
    ///     float2 uv;        // row 1
    /// };                    // 24 bytes
    /// ```
    ///
    /// ## How to fix
    ///
    /// Reorder the members as the help shows. Put vectors of three next to a scalar,
    /// pair two-component vectors, and put structs and arrays first or last.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Microsoft, "Packing rules for constant variables" (HLSL).
    /// - Vulkan specification, the payload size rule for
    ///   `maxPipelineRayPayloadSize`.
    "RT002" "payload-packing-waste" {
        group: Perf,
        summary: "payload member order wastes 16-byte rows",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    if !ctx.source_is_hlsl() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let packed_roles = |r: &Role| {
        matches!(
            r,
            Role::RayPayload
                | Role::IncomingRayPayload
                | Role::CallableData
                | Role::IncomingCallableData
        )
    };
    for t in ctx
        .layouts
        .iter()
        .filter(|t| t.is_struct && t.roles.iter().any(packed_roles))
    {
        let (Some(best), Some(best_rows), Some(order)) = (
            t.optimal_hlsl_packed_size,
            t.optimal_hlsl_rows,
            &t.optimal_indices,
        ) else {
            continue;
        };
        if best >= t.hlsl_packed_size {
            continue;
        }
        let decl =
            crate::explain::struct_declaration(ctx.program.language, &t.name, order, &t.members);
        let d = ctx
            .diagnostic(
                &RULE,
                format!(
                    "`{}` packs into {} rows ({} bytes) as declared, {} rows ({} bytes) reordered",
                    t.name, t.hlsl_rows, t.hlsl_packed_size, best_rows, best
                ),
            )
            .with_primary(ctx.type_location(t), "members declared in this order")
            .with_subject(ctx.subject(t))
            .with_note(format!(
                "{} bytes of the declared layout are padding",
                t.hlsl_padding
            ))
            .with_help(format!("reorder the members:\n{}", indent(&decl)))
            .with_fix(ctx.type_location(t), decl);
        out.push(d);
    }
    out
}
