use super::{indent, Context, Group, Kind, Rule};
use crate::analysis::layout::Role;
use crate::diag::{Diagnostic, Severity};

pub static RULE: Rule = Rule {
    code: "RT002",
    name: "payload-packing-waste",
    group: Group::Perf,
    level: Severity::Warning,
    summary: "payload member order wastes 16-byte rows",
    doc: include_str!("../../rules/RT002.md"),
    kind: Kind::Module(check),
};

fn check(ctx: &Context) -> Vec<Diagnostic> {
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
            .with_fix(decl);
        out.push(d);
    }
    out
}
