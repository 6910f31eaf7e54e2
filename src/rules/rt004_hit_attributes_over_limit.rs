use super::Context;
use crate::analysis::layout::Role;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a hit-attribute type (`HitAttributeKHR`, HLSL's attribute struct
    /// passed to `ReportHit`) larger than 32 bytes.
    ///
    /// ## Why is this bad?
    ///
    /// 32 bytes is D3D12's fixed `D3D12_RAYTRACING_MAX_ATTRIBUTE_SIZE_IN_BYTES` and
    /// the `maxRayHitAttributeSize` of every Vulkan driver we have measured (lavapipe,
    /// NVIDIA). Pipeline creation fails, or the attributes are silently truncated, on
    /// a driver that does not allow more.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// hitAttributeEXT struct { vec3 normal; vec3 position; vec2 uv; } attribs; // 32 + 8 bytes
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// hitAttributeEXT struct { vec2 uv; float t; } attribs; // recompute normal and position in the hit shader
    /// ```
    ///
    /// ## How to fix
    ///
    /// Report only what the closest-hit shader cannot recompute cheaply (barycentrics,
    /// a primitive-local id, a distance) and derive normals and positions there.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Vulkan specification, `maxRayHitAttributeSize`.
    /// - DirectX Raytracing functional spec, "Intersection attributes".
    "RT004" "hit-attributes-over-limit" {
        group: Correctness,
        summary: "hit attributes larger than the 32-byte limit",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

/// `maxRayHitAttributeSize` on every driver we know, and D3D12's fixed limit.
pub const LIMIT: u64 = 32;

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for t in ctx
        .layouts
        .iter()
        .filter(|t| t.roles.contains(&Role::HitAttribute))
    {
        if t.scalar_size <= LIMIT {
            continue;
        }
        out.push(
            ctx.diagnostic(
                &RULE,
                format!(
                    "hit attributes `{}` are {} bytes, above the {LIMIT}-byte limit",
                    t.name, t.scalar_size
                ),
            )
            .with_primary(ctx.type_location(t), "attribute type declared here")
            .with_subject(ctx.subject(t))
            .with_note(format!(
                "Vulkan's maxRayHitAttributeSize and D3D12's D3D12_RAYTRACING_MAX_ATTRIBUTE_SIZE_IN_BYTES are {LIMIT}; pipeline creation fails above it"
            ))
            .with_help("report only what the closest-hit shader cannot recompute (barycentrics, a primitive-local id) and derive the rest there"),
        );
    }
    out
}
