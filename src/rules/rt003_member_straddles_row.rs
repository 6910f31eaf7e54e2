use super::{Context, Group, Kind, Rule};
use crate::analysis::layout::Role;
use crate::diag::{Diagnostic, Severity};

pub static RULE: Rule = Rule {
    code: "RT003",
    name: "member-straddles-row",
    group: Group::Perf,
    level: Severity::Warning,
    summary: "payload member crosses a 16-byte row",
    doc: include_str!("../../rules/RT003.md"),
    kind: Kind::Module(check),
};

fn check(ctx: &Context) -> Vec<Diagnostic> {
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
