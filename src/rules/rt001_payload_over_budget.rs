use super::Context;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a ray payload type (a `RayPayloadKHR` or `IncomingRayPayloadKHR`
    /// variable's type) whose size is above the payload budget. The size is the one
    /// drivers count for `maxPipelineRayPayloadSize`: every scalar aligned to the
    /// largest scalar alignment in the block, with no 16-byte rows (DXC computes the
    /// same size for a DXR payload).
    ///
    /// ## Why is this bad?
    ///
    /// The payload is copied in and out of every shader a ray reaches, and it lives on
    /// the ray stack for every level of recursion. Drivers keep small payloads in
    /// registers; large ones spill to memory, and the whole pipeline's stack grows
    /// with the largest payload. A payload that carries a matrix or a material
    /// description when the caller reads only a colour and a distance pays that cost
    /// on every ray.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;
    ///     float hitT;
    ///     float4x4 objectToWorld; // 64 bytes the caller never reads
    /// };
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// struct Payload {
    ///     float3 color;
    ///     float hitT;
    ///     uint instanceIndex;     // fetch the matrix in the hit shader
    /// };
    /// ```
    ///
    /// ## How to fix
    ///
    /// Keep in the payload only what the caller reads after `TraceRay`. Store an
    /// index instead of the data it points at, pack normals and colours (for example
    /// into `uint`s), and recompute what the hit shader can recompute.
    ///
    /// ## Options
    ///
    /// - `payload-budget` in `rtlint.toml`, or `--payload-budget BYTES` on the command
    ///   line (default 32).
    ///
    /// ## References
    ///
    /// - Vulkan specification, `maxPipelineRayPayloadSize` and the payload size rule.
    /// - DirectX Raytracing functional spec, "Ray payload structure".
    "RT001" "payload-over-budget" {
        group: Perf,
        summary: "ray payload larger than the payload budget",
        kind: super::Kind::Module(check),
        analysis: Fast,
        options: [super::RuleOption {
            name: "budget",
            default: "32",
            doc: "payloads above this many bytes are reported (top-level `payload-budget` and `--payload-budget` too)",
        }],
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let budget = super::option_u64(ctx.config, &RULE, "budget", ctx.config.payload_budget);
    let mut out = Vec::new();
    for t in ctx
        .layouts
        .iter()
        .filter(|t| t.roles.iter().any(|r| r.is_payload()))
    {
        if t.scalar_size <= budget {
            continue;
        }
        let mut d = ctx
            .diagnostic(
                &RULE,
                format!(
                    "ray payload `{}` is {} bytes, above the {budget}-byte budget",
                    t.name, t.scalar_size
                ),
            )
            .with_primary(ctx.type_location(t), "payload type declared here")
            .with_subject(ctx.subject(t));
        for site in ctx.sites_using(&t.variable_ids) {
            d = d.with_secondary(Some(site), "traced with this payload");
        }
        let mut note = format!(
            "under HLSL 16-byte packing it occupies {} rows ({} bytes)",
            t.hlsl_rows, t.hlsl_packed_size
        );
        if let Some(best) = t
            .optimal_hlsl_packed_size
            .filter(|b| *b < t.hlsl_packed_size)
        {
            note.push_str(&format!("; reordered it packs into {best}"));
        }
        d = d.with_note(note).with_help(
            "keep in the payload only what the caller reads after the trace; fetch or recompute the rest in the hit shader",
        );
        out.push(d);
    }
    out
}
