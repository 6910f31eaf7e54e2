use super::Context;
use crate::analysis::layout::Role;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a scalar or vector member of an HLSL (DXR) payload, callable-data or
    /// hit-attribute struct that, placed where its declared order puts it in the
    /// tight (scalar) layout, crosses a 16-byte row. Under HLSL 16-byte packing
    /// such a member is moved to the next row and the bytes before it become
    /// padding.
    ///
    /// Only HLSL shaders are checked: the module's language is HLSL, or its
    /// SPIR-V debug info names an `.hlsl` source. Vulkan sizes GLSL and WGSL
    /// payloads with its scalar rule, which has no rows to cross; no reordering
    /// of such a payload changes what the driver stores (`rtlint layout` shows
    /// the same), so those modules are not reported.
    ///
    /// ## Why is this bad?
    ///
    /// The padding that 16-byte packing inserts before the member is stored and
    /// copied with the payload on every trace, and the member needs a register
    /// quadruple of its own.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;   // bytes 0..12
    ///     float2 uv;      // bytes 12..20: crosses the row at 16
    /// };
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;
    ///     float hitT;     // fills row 0
    ///     float2 uv;      // row 1
    /// };
    /// ```
    ///
    /// RT002 computes the best order.
    ///
    /// ## How to fix
    ///
    /// Place the member where its row has room, usually by moving a scalar next to a
    /// three-component vector, or apply the order RT002 suggests.
    ///
    /// Fixtures: `fixtures/RT003/` (HLSL bad and good; GLSL and WGSL payloads that
    /// are not reported).
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Microsoft, "Packing rules for constant variables" (HLSL).
    "RT003" "member-straddles-row" {
        group: Perf,
        summary: "payload member crosses a 16-byte row",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    if !ctx.source_is_hlsl() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for t in ctx.layouts.iter().filter(|t| {
        t.roles
            .iter()
            .any(|r| !matches!(r, Role::ShaderRecord | Role::PushConstant))
    }) {
        for (k, m) in t.members.iter().enumerate().filter(|(_, m)| m.straddles) {
            let end = m.scalar_offset + m.size;
            let d = ctx
                .diagnostic(
                    &RULE,
                    format!(
                        "member `{}` of `{}` crosses a 16-byte row at bytes {}..{}",
                        m.name, t.name, m.scalar_offset, end
                    ),
                )
                .with_primary(ctx.member_location(t, k), "crosses a row boundary")
                .with_secondary(ctx.type_location(t), "in this type")
                .with_subject(format!("member `{}` of {}", m.name, ctx.subject(t)))
                .with_note(format!(
                    "16-byte packing moves it from byte {} to {}, leaving {} bytes of padding",
                    m.scalar_offset,
                    m.hlsl_packed_offset,
                    m.hlsl_packed_offset - m.scalar_offset
                ))
                .with_help(format!(
                    "place `{}` where its row has {} bytes free, or reorder as RT002 suggests",
                    m.name, m.size
                ));
            out.push(d);
        }
    }
    out
}
