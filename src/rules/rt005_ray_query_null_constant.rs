use super::Context;
use crate::diag::Diagnostic;
use crate::program::{Constant, Type};
use rspirv::dr::Operand;
use spirv::Op;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a ray-query object that is stored from, or initialised with,
    /// `OpConstantNull`.
    ///
    /// ## Why is this bad?
    ///
    /// A ray query is an opaque object and cannot have a null value: `spirv-val`
    /// rejects the module ("cannot have a null value") and Mesa fails to compile it.
    /// naga 30 emits exactly this for a WGSL `var rq: ray_query;` declared inside a
    /// loop body, and naga's own validator does not notice, so the shader passes
    /// `wgpu` validation and fails at pipeline creation.
    ///
    /// ## Example
    ///
    /// ```wgsl
    /// for (var i = 0u; i < 4u; i++) {
    ///     var rq: ray_query;           // emitted as OpStore %rq (OpConstantNull)
    ///     rayQueryInitialize(&rq, tlas, desc);
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```wgsl
    /// var rq: ray_query;               // declared once at the top of the function
    /// for (var i = 0u; i < 4u; i++) {
    ///     rayQueryInitialize(&rq, tlas, desc);
    /// }
    /// ```
    ///
    /// ## How to fix
    ///
    /// Declare the ray query at the top of the function, outside any loop.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - SPIR-V specification, `OpTypeRayQueryKHR` (no null value).
    "RT005" "ray-query-null-constant" {
        group: Correctness,
        summary: "ray-query object initialised from OpConstantNull",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

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
