use super::{Context, Group, Kind, Rule};
use crate::diag::{Diagnostic, Severity};

pub static RULE: Rule = Rule {
    code: "RT001",
    name: "payload-over-budget",
    group: Group::Perf,
    level: Severity::Warning,
    summary: "ray payload larger than the payload budget",
    doc: include_str!("../../rules/RT001.md"),
    kind: Kind::Module(check),
};

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let budget = ctx.config.payload_budget;
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
