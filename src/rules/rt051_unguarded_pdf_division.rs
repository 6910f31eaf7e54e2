use super::Context;
use crate::diag::Diagnostic;
use crate::program::{Constant, Id, Program};
use rspirv::dr::Operand;
use spirv::Op;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a floating-point division whose divisor is a dot product (`N·L`,
    /// `N·V`, `N·H`, or a product of such, as in a GGX pdf), without a guard: no
    /// `max(…, ε)` / `clamp` with a positive lower bound, no `+ ε`, and no
    /// comparison of that dot product anywhere in the function. Locals holding
    /// one dot product are followed.
    ///
    /// ## Why is this bad?
    ///
    /// A dot product of unit vectors is zero at grazing angles and negative
    /// behind the surface. Dividing by it gives ±∞ or NaN (0/0 when the
    /// numerator vanishes too, as in `D·G / (4·N·L·N·V)`), and one NaN sample
    /// poisons an accumulated image forever. Many divisions are safe because
    /// the caller rejected such directions earlier, in a way a static check
    /// cannot see: the rule is pedantic.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// float pdf = D * NdotH / (4.0 * dot(V, H));
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// float pdf = D * NdotH / max(4.0 * dot(V, H), 1e-6);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Clamp the divisor with `max(…, ε)`, or return early when the dot product
    /// is not positive.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Walter et al., "Microfacet Models for Refraction through Rough
    ///   Surfaces" (2007): the pdf of GGX sampling divides by `4·|V·H|`.
    "RT051" "unguarded-pdf-division" {
        group: Pedantic,
        summary: "division by a dot product without a guard",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

/// GLSL.std.450 instructions that bound a value away from zero (when their
/// bound is a positive constant): FMax, FClamp, NMax, NClamp.
const BOUNDING: [u32; 4] = [40, 43, 80, 81];

fn positive_const(p: &Program, id: Id) -> bool {
    match p.constants.get(&id) {
        Some(Constant::Float(f)) => *f > 0.0,
        Some(Constant::Composite(parts)) => parts.iter().all(|x| positive_const(p, *x)),
        _ => false,
    }
}

/// The dot products a divisor is made of (through multiplication,
/// negation, conversions and locals holding one value), or `None` when it is
/// guarded or not made of dot products alone.
fn dots(p: &Program, id: Id, depth: u32, out: &mut Vec<Id>) -> bool {
    if depth > 8 {
        return false;
    }
    let Some(inst) = p.def(id) else { return false };
    match (inst.class.opcode, inst.operands.as_slice()) {
        // `dot(v, v)` is a squared length (a ray-sphere test's `a`), not a cosine.
        (Op::Dot, [Operand::IdRef(a), Operand::IdRef(b)]) if same_value(p, *a, *b) => false,
        (Op::Dot, _) => {
            out.push(id);
            true
        }
        (Op::FMul, [Operand::IdRef(a), Operand::IdRef(b)]) => {
            // A constant factor keeps a zero zero; at least one side must be a dot.
            let ca = p.constants.contains_key(a);
            let cb = p.constants.contains_key(b);
            match (ca, cb) {
                (true, false) => dots(p, *b, depth + 1, out),
                (false, true) => dots(p, *a, depth + 1, out),
                (false, false) => {
                    let l = dots(p, *a, depth + 1, out);
                    let r = dots(p, *b, depth + 1, out);
                    l || r
                }
                _ => false,
            }
        }
        (Op::FNegate | Op::CopyObject, [Operand::IdRef(x)]) => dots(p, *x, depth + 1, out),
        // A scalar splatted to a vector (`float4(...) / NdotV`).
        (Op::CompositeConstruct, [Operand::IdRef(x), rest @ ..])
            if rest.iter().all(|o| matches!(o, Operand::IdRef(y) if y == x)) =>
        {
            dots(p, *x, depth + 1, out)
        }
        (Op::Load, [Operand::IdRef(ptr), ..]) => {
            let stores = single_store(p, *ptr);
            stores.is_some_and(|v| dots(p, v, depth + 1, out))
        }
        _ => false,
    }
}

/// Whether two ids are one value: the same id, or loads of one pointer.
fn same_value(p: &Program, a: Id, b: Id) -> bool {
    let ptr = |x: Id| {
        p.def(x)
            .filter(|i| i.class.opcode == Op::Load)
            .and_then(|i| i.operands.first().cloned())
    };
    // One pointer, or two access chains with the same base and indices.
    let same_ptr = |x: Id, y: Id| {
        x == y
            || matches!((p.def(x), p.def(y)), (Some(i), Some(j))
                if i.class.opcode == Op::AccessChain
                    && j.class.opcode == Op::AccessChain
                    && i.operands == j.operands)
    };
    let extract = |x: Id| {
        p.def(x)
            .filter(|i| i.class.opcode == Op::CompositeExtract)
            .map(|i| i.operands.clone())
    };
    a == b
        || matches!((ptr(a), ptr(b)), (Some(Operand::IdRef(x)), Some(Operand::IdRef(y))) if same_ptr(x, y))
        || matches!((extract(a), extract(b)), (Some(ea), Some(eb))
            if ea[1..] == eb[1..]
                && matches!((&ea[0], &eb[0]), (Operand::IdRef(x), Operand::IdRef(y))
                    if x == y || matches!((ptr(*x), ptr(*y)), (Some(Operand::IdRef(u)), Some(Operand::IdRef(v))) if same_ptr(u, v))))
}

/// The one value stored to a function-local variable, when it is written
/// once and only whole.
fn single_store(p: &Program, var: Id) -> Option<Id> {
    let def = p.def(var)?;
    if def.class.opcode != Op::Variable {
        return None;
    }
    let f = &p.functions[p.function_of(*p.defs.get(&var)?)?];
    let mut value = None;
    for inst in &p.insts[f.start..=f.end] {
        if p.is_debug_inst(inst) {
            continue;
        }
        let uses: Vec<usize> = inst
            .operands
            .iter()
            .enumerate()
            .filter(|(_, o)| matches!(o, Operand::IdRef(x) if *x == var))
            .map(|(k, _)| k)
            .collect();
        if uses.is_empty() {
            continue;
        }
        match inst.class.opcode {
            Op::Load => {}
            Op::Store if uses == [0] && value.is_none() => {
                if let Some(Operand::IdRef(v)) = inst.operands.get(1) {
                    value = Some(*v);
                }
            }
            _ => return None,
        }
    }
    value
}

/// Whether a dot product is compared, bounded or offset anywhere in its
/// function (directly or through the local that holds it).
fn guarded(p: &Program, dot: Id) -> bool {
    let Some(at) = p.defs.get(&dot) else {
        return true;
    };
    let Some(f) = p.function_of(*at).and_then(|f| p.functions.get(f)) else {
        return true;
    };
    // The dot product and every local value that is the same number.
    let mut same = vec![dot];
    for inst in &p.insts[f.start..=f.end] {
        if let (Op::Store, [Operand::IdRef(ptr), Operand::IdRef(v)]) =
            (inst.class.opcode, inst.operands.as_slice())
        {
            if same.contains(v) {
                same.push(*ptr);
            }
        }
    }
    for inst in &p.insts[f.start..=f.end] {
        if let (Op::Load, Some(Operand::IdRef(ptr)), Some(r)) =
            (inst.class.opcode, inst.operands.first(), inst.result_id)
        {
            if same.contains(ptr) {
                same.push(r);
            }
        }
    }
    p.insts[f.start..=f.end].iter().any(|inst| {
        let uses = |k: usize| matches!(inst.operands.get(k), Some(Operand::IdRef(x)) if same.contains(x));
        match inst.class.opcode {
            op if crate::program::is_float_compare_op(op) => uses(0) || uses(1),
            Op::FAdd => (uses(0) || uses(1)) && inst.operands.iter().any(|o| matches!(o, Operand::IdRef(x) if positive_const(p, *x))),
            Op::ExtInst => {
                matches!(inst.operands.get(1), Some(Operand::LiteralExtInstInteger(n)) if BOUNDING.contains(n))
                    && (2..inst.operands.len()).any(uses)
            }
            _ => false,
        }
    })
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    for (i, inst) in p.insts.iter().enumerate() {
        let (Op::FDiv, [_, Operand::IdRef(divisor)]) = (inst.class.opcode, inst.operands.as_slice())
        else {
            continue;
        };
        let mut found = Vec::new();
        if !dots(p, *divisor, 0, &mut found) || found.is_empty() {
            continue;
        }
        let Some(&dot) = found.iter().find(|&&d| !guarded(p, d)) else {
            continue;
        };
        out.push(
            ctx.diagnostic(&RULE, "division by a dot product that can be zero, without a guard")
                .with_primary(p.site_location(i), "divides here")
                .with_secondary(
                    p.defs.get(&dot).and_then(|&d| p.inst_location(d)).filter(|l| Some(l) != p.site_location(i).as_ref()),
                    "dot product computed here",
                )
                .with_note("the dot product is zero at grazing angles; nothing compares or clamps it")
                .with_help("clamp the divisor with `max(..., 1e-6)`, or return early when the dot product is not positive"),
        );
    }
    out
}
