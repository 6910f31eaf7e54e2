use super::{Context, Group, Kind, Rule};
use crate::diag::{Diagnostic, Severity};
use crate::program::{Constant, Type};
use rspirv::dr::Operand;
use spirv::Op;

pub static RULE: Rule = Rule {
    code: "RT005",
    name: "ray-query-null-constant",
    group: Group::Correctness,
    level: Severity::Error,
    summary: "ray-query object initialised from OpConstantNull",
    doc: include_str!("../../rules/RT005.md"),
    kind: Kind::Module(check),
};

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let is_null = |id: u32| matches!(p.constants.get(&id), Some(Constant::Null));
    let points_to_ray_query = |ptr: u32| -> bool {
        let ty = p.def(ptr).and_then(|i| i.result_type);
        matches!(
            ty.and_then(|t| p.ty(t)),
            Some(Type::Pointer { pointee, .. }) if matches!(p.ty(*pointee), Some(Type::RayQuery))
        )
    };
    let mut out = Vec::new();
    for (i, inst) in p.insts.iter().enumerate() {
        let (var, value) = match (inst.class.opcode, inst.operands.as_slice()) {
            (Op::Store, [Operand::IdRef(ptr), Operand::IdRef(v), ..]) => (*ptr, *v),
            (Op::Variable, [_, Operand::IdRef(init)]) => match inst.result_id {
                Some(r) => (r, *init),
                None => continue,
            },
            _ => continue,
        };
        if !is_null(value) || !points_to_ray_query(var) {
            continue;
        }
        let name = p.display_name(var);
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("ray query `{name}` is initialised from a null constant, which is invalid SPIR-V"),
            )
            .with_primary(p.site_location(i), "null ray query stored here")
            .with_secondary(p.var_location(var).filter(|_| inst.class.opcode != Op::Variable), "ray query declared here")
            .with_subject(format!("ray query `{name}` (instruction at word {})", p.offsets[i]))
            .with_note("spirv-val rejects it (a ray query cannot have a null value) and Mesa fails to compile it; naga 30 emits it for a `ray_query` declared inside a loop body, and its validator does not notice")
            .with_help("declare the ray query at the top of the function, outside any loop"),
        );
    }
    out
}
