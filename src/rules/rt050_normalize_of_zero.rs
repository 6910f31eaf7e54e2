use super::Context;
use crate::diag::Diagnostic;
use crate::program::{Constant, Id, Program};
use rspirv::dr::Operand;
use spirv::Op;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds `normalize` of a vector that is zero on some path: a zero constant,
    /// a local that only ever holds zero, the difference of a value with itself,
    /// or a `select` / φ with a zero operand (a default the code keeps when no
    /// branch assigns a direction).
    ///
    /// ## Why is this bad?
    ///
    /// `normalize(0)` divides by a zero length: the result is NaN on every GPU.
    /// A NaN direction makes `TraceRay` undefined (DXR drops the ray, Vulkan
    /// leaves it undefined), and a NaN normal spreads through shading into the
    /// accumulation buffer, where it never goes away.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// float3 n = float3(0, 0, 0);
    /// if (hit) n = ComputeNormal();
    /// n = normalize(n);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// float3 n = float3(0, 0, 1);
    /// if (hit) n = ComputeNormal();
    /// n = normalize(n);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Give the vector a non-zero default, or normalize only where it was
    /// assigned.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - GLSL.std.450 `Normalize` (undefined for a zero vector).
    "RT050" "normalize-of-zero" {
        group: Suspicious,
        summary: "normalize of a vector that is zero on some path",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

/// Whether `id` is zero (every component), following local variables that
/// hold one value.
fn zero(p: &Program, id: Id, depth: u32) -> bool {
    if depth > 8 {
        return false;
    }
    match p.constants.get(&id) {
        Some(Constant::Null) => return true,
        Some(Constant::Float(f)) => return *f == 0.0,
        Some(Constant::Int(_) | Constant::Bool(_)) => return false,
        Some(Constant::Composite(parts)) => {
            return !parts.is_empty() && parts.iter().all(|x| zero(p, *x, depth + 1))
        }
        None => {}
    }
    let Some(inst) = p.def(id) else { return false };
    match (inst.class.opcode, inst.operands.as_slice()) {
        (Op::CompositeConstruct, parts) => {
            !parts.is_empty()
                && parts
                    .iter()
                    .all(|o| matches!(o, Operand::IdRef(x) if zero(p, *x, depth + 1)))
        }
        (Op::CopyObject, [Operand::IdRef(x)]) => zero(p, *x, depth + 1),
        (Op::Load, [Operand::IdRef(ptr), ..]) => {
            only_stored(p, *ptr).is_some_and(|vals| vals.iter().all(|v| zero(p, *v, depth + 1)))
        }
        _ => false,
    }
}

/// The values every store to a function-local variable writes, when the
/// variable is written only whole (no access chain reaches it).
fn only_stored(p: &Program, var: Id) -> Option<Vec<Id>> {
    let def = p.def(var)?;
    if def.class.opcode != Op::Variable
        || !matches!(def.operands.first(), Some(Operand::StorageClass(spirv::StorageClass::Function)))
    {
        return None;
    }
    let mut vals = Vec::new();
    if let Some(Operand::IdRef(init)) = def.operands.get(1) {
        vals.push(*init);
    }
    let f = p.function_of(*p.defs.get(&var)?)?;
    let f = &p.functions[f];
    for inst in &p.insts[f.start..=f.end] {
        let uses = inst
            .operands
            .iter()
            .enumerate()
            .filter(|(_, o)| matches!(o, Operand::IdRef(x) if *x == var))
            .map(|(k, _)| k)
            .collect::<Vec<_>>();
        if uses.is_empty() || p.is_debug_inst(inst) {
            continue;
        }
        match inst.class.opcode {
            Op::Load => {}
            Op::Store if uses == [0] => {
                if let Some(Operand::IdRef(v)) = inst.operands.get(1) {
                    vals.push(*v);
                }
            }
            _ => return None,
        }
    }
    (!vals.is_empty()).then_some(vals)
}

/// Why `id` can be zero, if it can.
fn why_zero(p: &Program, id: Id) -> Option<&'static str> {
    if zero(p, id, 0) {
        return Some("the vector is always zero");
    }
    let inst = p.def(id)?;
    match (inst.class.opcode, inst.operands.as_slice()) {
        (Op::FSub, [Operand::IdRef(a), Operand::IdRef(b)]) if a == b => {
            Some("the vector is a difference of a value with itself")
        }
        (Op::FSub, [Operand::IdRef(a), Operand::IdRef(b)]) => {
            let load = |x: &Id| {
                p.def(*x)
                    .filter(|i| i.class.opcode == Op::Load)
                    .and_then(|i| i.operands.first().cloned())
            };
            let (la, lb) = (load(a)?, load(b)?);
            let (Operand::IdRef(pa), Operand::IdRef(pb)) = (&la, &lb) else {
                return None;
            };
            // Both loads of one pointer with no store between them.
            let (ia, ib) = (*p.defs.get(a)?, *p.defs.get(b)?);
            let (lo, hi) = (ia.min(ib), ia.max(ib));
            let stored = p.insts[lo..hi].iter().any(|i| {
                matches!(i.class.opcode, Op::Store | Op::FunctionCall)
                    || i.class.opcode == Op::Label
            });
            (pa == pb && !stored).then_some("the vector is a difference of a value with itself")
        }
        (Op::Select, [_, Operand::IdRef(a), Operand::IdRef(b)])
            if zero(p, *a, 0) || zero(p, *b, 0) =>
        {
            Some("one side of the `select` is a zero vector")
        }
        (Op::Phi, ops) => ops
            .chunks(2)
            .any(|c| matches!(c.first(), Some(Operand::IdRef(x)) if zero(p, *x, 0)))
            .then_some("a path reaching it leaves the vector zero"),
        _ => None,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let glsl_std: Vec<Id> = p
        .insts
        .iter()
        .filter(|i| {
            i.class.opcode == Op::ExtInstImport
                && matches!(i.operands.first(), Some(Operand::LiteralString(s)) if s == "GLSL.std.450")
        })
        .filter_map(|i| i.result_id)
        .collect();
    let mut out = Vec::new();
    for (i, inst) in p.insts.iter().enumerate() {
        let (Op::ExtInst, [Operand::IdRef(set), Operand::LiteralExtInstInteger(69), Operand::IdRef(arg)]) =
            (inst.class.opcode, inst.operands.as_slice())
        else {
            continue;
        };
        if !glsl_std.contains(set) {
            continue;
        }
        let Some(why) = why_zero(p, *arg) else {
            continue;
        };
        out.push(
            ctx.diagnostic(&RULE, "`normalize` of a vector that can be zero, which gives NaN")
                .with_primary(p.site_location(i), "normalized here")
                .with_note(why)
                .with_help("give the vector a non-zero default, or normalize only where it is assigned"),
        );
    }
    out
}
