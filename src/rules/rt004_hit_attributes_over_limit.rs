use super::{Context, Group, Kind, Rule};
use crate::analysis::layout::Role;
use crate::diag::{Diagnostic, Severity};

pub static RULE: Rule = Rule {
    code: "RT004",
    name: "hit-attributes-over-limit",
    group: Group::Correctness,
    level: Severity::Error,
    summary: "hit attributes larger than the 32-byte limit",
    doc: include_str!("../../rules/RT004.md"),
    kind: Kind::Module(check),
};

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
