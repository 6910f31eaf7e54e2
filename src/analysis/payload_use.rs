//! Which members of a ray payload (or hit-attribute block) a shader reads and
//! writes.
//!
//! An access is followed from the variable through `OpAccessChain`,
//! `OpCopyObject` and function parameters; the first index of a chain from
//! the whole variable names the member. A load or store of the whole value
//! reads or writes every member, except a plain copy between the variable and
//! a function-local (or private) variable: compilers copy payloads in and out
//! of locals (an HLSL `inout` parameter, a local passed to `TraceRay`), so
//! such a local stands for the variable and its own member accesses count.
//! Any use the analysis does not model counts as reading and writing the
//! members it can reach, so a member is reported unused only when no
//! instruction can touch it.

use crate::analysis::layout::Shape;
use crate::program::{Id, Program, Type};
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};
use std::collections::HashMap;

/// How one member is used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Access {
    pub read: bool,
    pub written: bool,
}

impl Access {
    pub fn merge(&mut self, other: Access) {
        self.read |= other.read;
        self.written |= other.written;
    }
}

/// The members of a variable's value: struct members, vector components or
/// the elements of a small constant array; anything else is one member.
pub fn member_count(program: &Program, ty: Id) -> usize {
    match program.ty(ty) {
        Some(Type::Struct { members }) if !members.is_empty() => members.len(),
        Some(Type::Vector { count, .. }) if *count > 0 => *count as usize,
        Some(Type::Array { len, .. }) => match len.value() {
            Some(n @ 1..=16) => n as usize,
            _ => 1,
        },
        _ => 1,
    }
}

/// The type of member `k` of `ty` (itself for a one-member value).
pub fn member_type(program: &Program, ty: Id, k: usize) -> Id {
    match program.ty(ty) {
        Some(Type::Struct { members }) => members.get(k).copied().unwrap_or(ty),
        Some(Type::Vector { elem, count }) if *count > 0 => *elem,
        Some(Type::Array { elem, len }) if matches!(len.value(), Some(1..=16)) => *elem,
        _ => ty,
    }
}

/// A structural key for matching payload types across modules: two shaders
/// exchange a payload when its layout agrees, whatever the names.
pub fn shape_of(program: &Program, ty: Id) -> Shape {
    Shape::from_type(program, ty)
}

/// What a pointer reaches: every member, or one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reach {
    Whole,
    Member(usize),
}

/// Uses of the members of global `var`, in the functions reachable from
/// entry function `entry`. One entry per member (see [`member_count`]).
pub fn variable_use(program: &Program, entry: Id, var: Id) -> Vec<Access> {
    let ty = program
        .globals
        .iter()
        .find(|g| g.id == var)
        .map(|g| g.ty)
        .unwrap_or(0);
    let n = member_count(program, ty);
    let one_member = n == 1;
    let mut uses = vec![Access::default(); n];
    let functions: Vec<&crate::program::Function> = program
        .reachable_functions(entry)
        .into_iter()
        .filter_map(|f| program.function(f))
        .collect();
    let mut reach: HashMap<Id, Reach> = HashMap::new();
    reach.insert(var, Reach::Whole);
    let is_local = |id: Id| -> bool {
        program.def(id).is_some_and(|i| {
            i.class.opcode == Op::Variable
                && matches!(
                    i.operands.first(),
                    Some(Operand::StorageClass(
                        StorageClass::Function | StorageClass::Private
                    ))
                )
        })
    };
    // Grow the set of pointers that reach the variable until it is stable:
    // access chains, copies, parameters, and locals the whole value is
    // copied to or from.
    for _round in 0..8 {
        let before = reach.len();
        for f in &functions {
            for inst in &program.insts[f.start..=f.end] {
                let ids = || {
                    inst.operands.iter().filter_map(|o| match o {
                        Operand::IdRef(x) => Some(*x),
                        _ => None,
                    })
                };
                match inst.class.opcode {
                    Op::AccessChain | Op::InBoundsAccessChain => {
                        let (Some(r), Some(Operand::IdRef(base))) =
                            (inst.result_id, inst.operands.first())
                        else {
                            continue;
                        };
                        let Some(&b) = reach.get(base) else { continue };
                        let derived = match b {
                            Reach::Member(k) => Reach::Member(k),
                            Reach::Whole if one_member => Reach::Member(0),
                            Reach::Whole => match inst.operands.get(1) {
                                Some(Operand::IdRef(i)) => match program.const_u64(*i) {
                                    Some(k) if (k as usize) < n => Reach::Member(k as usize),
                                    _ => Reach::Whole,
                                },
                                _ => Reach::Whole,
                            },
                        };
                        // An empty chain is the base itself.
                        let derived = if inst.operands.len() == 1 { b } else { derived };
                        reach.entry(r).or_insert(derived);
                    }
                    Op::CopyObject => {
                        if let (Some(r), Some(Operand::IdRef(x))) =
                            (inst.result_id, inst.operands.first())
                        {
                            if let Some(&b) = reach.get(x) {
                                reach.entry(r).or_insert(b);
                            }
                        }
                    }
                    Op::FunctionCall => {
                        let Some(Operand::IdRef(callee)) = inst.operands.first() else {
                            continue;
                        };
                        let Some(cf) = program.function(*callee) else {
                            continue;
                        };
                        for (k, arg) in ids().skip(1).enumerate() {
                            if let (Some(&b), Some(&param)) = (reach.get(&arg), cf.params.get(k)) {
                                reach.entry(param).or_insert(b);
                            }
                        }
                    }
                    Op::Store => {
                        // Copy out of a local: `var = local`, the local stands
                        // for the variable.
                        let (Some(Operand::IdRef(ptr)), Some(Operand::IdRef(val))) =
                            (inst.operands.first(), inst.operands.get(1))
                        else {
                            continue;
                        };
                        match (reach.get(ptr), loaded_from(program, *val)) {
                            (Some(Reach::Whole), Some(src)) if is_local(src) => {
                                reach.entry(src).or_insert(Reach::Whole);
                            }
                            (None, Some(src))
                                if reach.get(&src) == Some(&Reach::Whole) && is_local(*ptr) =>
                            {
                                reach.entry(*ptr).or_insert(Reach::Whole);
                            }
                            _ => {}
                        }
                    }
                    Op::CopyMemory => {
                        let (Some(Operand::IdRef(dst)), Some(Operand::IdRef(src))) =
                            (inst.operands.first(), inst.operands.get(1))
                        else {
                            continue;
                        };
                        match (reach.get(dst).copied(), reach.get(src).copied()) {
                            (Some(Reach::Whole), None) if is_local(*src) => {
                                reach.insert(*src, Reach::Whole);
                            }
                            (None, Some(Reach::Whole)) if is_local(*dst) => {
                                reach.insert(*dst, Reach::Whole);
                            }
                            _ => {}
                        }
                    }
                    _ => {}
                }
            }
        }
        if reach.len() == before {
            break;
        }
    }
    let all = |uses: &mut Vec<Access>, a: Access| {
        for u in uses.iter_mut() {
            u.merge(a);
        }
    };
    let mark = |uses: &mut Vec<Access>, r: Reach, a: Access| match r {
        Reach::Whole => all(uses, a),
        Reach::Member(k) => uses[k.min(n - 1)].merge(a),
    };
    const READ: Access = Access {
        read: true,
        written: false,
    };
    const WRITE: Access = Access {
        read: false,
        written: true,
    };
    const BOTH: Access = Access {
        read: true,
        written: true,
    };
    // Whether a whole-value store `ptr = val` is a copy between the variable
    // and a local standing for it.
    let is_copy = |ptr: Id, val: Id| -> bool {
        reach.get(&ptr) == Some(&Reach::Whole)
            && loaded_from(program, val).is_some_and(|s| reach.get(&s) == Some(&Reach::Whole))
    };
    for f in &functions {
        for inst in &program.insts[f.start..=f.end] {
            if program.is_debug_inst(inst) {
                continue;
            }
            let op = inst.class.opcode;
            match op {
                Op::AccessChain | Op::InBoundsAccessChain | Op::CopyObject | Op::FunctionCall => {
                    // Modelled above; a dynamic index into a member is still
                    // that member. Arguments that are values are not accesses.
                    continue;
                }
                Op::Load => {
                    let Some(Operand::IdRef(ptr)) = inst.operands.first() else {
                        continue;
                    };
                    let Some(&r) = reach.get(ptr) else { continue };
                    let Some(result) = inst.result_id else {
                        continue;
                    };
                    match r {
                        Reach::Member(_) => mark(&mut uses, r, READ),
                        Reach::Whole => {
                            let mut seen = Vec::new();
                            read_value(program, f, result, n, &[], &is_copy, &mut seen, &mut |k| {
                                match k {
                                    Some(k) if k < n && !one_member => uses[k].merge(READ),
                                    _ => all(&mut uses, READ),
                                }
                            })
                        }
                    }
                }
                Op::Store => {
                    let (Some(Operand::IdRef(ptr)), Some(Operand::IdRef(val))) =
                        (inst.operands.first(), inst.operands.get(1))
                    else {
                        continue;
                    };
                    if let Some(&r) = reach.get(ptr) {
                        if r == Reach::Whole && !one_member {
                            // A whole value: the members it carries anew
                            // (not copied from the variable) are written.
                            let fresh = fresh_members(program, *val, n, &|p| {
                                reach.get(&p) == Some(&Reach::Whole)
                            });
                            for (k, new) in fresh.iter().enumerate() {
                                if *new {
                                    uses[k].merge(WRITE);
                                }
                            }
                        } else if !is_copy(*ptr, *val) {
                            mark(&mut uses, r, WRITE);
                        }
                    }
                    // Storing a pointer that reaches the variable somewhere
                    // (variable pointers): anything may happen to it.
                    if let Some(&r) = reach.get(val) {
                        mark(&mut uses, r, BOTH);
                    }
                }
                Op::CopyMemory | Op::CopyMemorySized => {
                    let (Some(Operand::IdRef(dst)), Some(Operand::IdRef(src))) =
                        (inst.operands.first(), inst.operands.get(1))
                    else {
                        continue;
                    };
                    let (d, s) = (reach.get(dst).copied(), reach.get(src).copied());
                    if d == Some(Reach::Whole) && s == Some(Reach::Whole) {
                        continue;
                    }
                    if let Some(d) = d {
                        mark(&mut uses, d, WRITE);
                    }
                    if let Some(s) = s {
                        mark(&mut uses, s, READ);
                    }
                }
                Op::TraceRayKHR | Op::TraceNV | Op::ExecuteCallableKHR | Op::ExecuteCallableNV => {
                    // Handing the payload to the callee is not an access of
                    // the caller's own.
                    continue;
                }
                Op::Name | Op::Decorate | Op::MemberName => continue,
                _ => {
                    // Any other instruction naming a pointer that reaches the
                    // variable: reads and writes what it reaches.
                    for o in &inst.operands {
                        if let Operand::IdRef(x) = o {
                            if let Some(&r) = reach.get(x) {
                                mark(&mut uses, r, BOTH);
                            }
                        }
                    }
                }
            }
        }
    }
    uses
}

/// The pointer `val` was loaded from, when it is a plain `OpLoad`.
fn loaded_from(program: &Program, val: Id) -> Option<Id> {
    let inst = program.def(val)?;
    if inst.class.opcode != Op::Load {
        return None;
    }
    match inst.operands.first() {
        Some(Operand::IdRef(p)) => Some(*p),
        _ => None,
    }
}

/// Which members of whole value `val` are new rather than copied from the
/// variable (a value loaded through a pointer `whole` accepts): a
/// composite built from parts writes every part that is not undefined;
/// inserting into a value writes the inserted member and keeps the rest.
fn fresh_members(program: &Program, val: Id, n: usize, whole: &dyn Fn(Id) -> bool) -> Vec<bool> {
    let mut v = val;
    let mut inserted = vec![false; n];
    for _ in 0..64 {
        let Some(inst) = program.def(v) else { break };
        match inst.class.opcode {
            Op::Load => {
                if matches!(inst.operands.first(), Some(Operand::IdRef(p)) if whole(*p)) {
                    return inserted;
                }
                break;
            }
            Op::Undef => return inserted,
            Op::CopyObject => match inst.operands.first() {
                Some(Operand::IdRef(x)) => v = *x,
                _ => break,
            },
            Op::CompositeInsert => match (inst.operands.get(1), inst.operands.get(2)) {
                (Some(Operand::IdRef(base)), Some(Operand::LiteralBit32(k))) => {
                    if let Some(m) = inserted.get_mut(*k as usize) {
                        *m = true;
                    }
                    v = *base;
                }
                _ => break,
            },
            Op::CompositeConstruct if inst.operands.len() == n => {
                for (k, o) in inst.operands.iter().enumerate() {
                    let undef = matches!(o, Operand::IdRef(x)
                        if program.def(*x).is_some_and(|d| d.class.opcode == Op::Undef));
                    inserted[k] |= !undef;
                }
                return inserted;
            }
            _ => break,
        }
    }
    vec![true; n]
}

/// Follows the uses of a whole loaded value `value` in function `f`: a
/// composite extract reads one member (`Some(k)`), inserting into it keeps
/// following the members not replaced (`replaced`), a copy into a local that
/// stands for the variable reads nothing, anything else reads what the value
/// still carries of the variable.
#[allow(clippy::too_many_arguments)]
fn read_value(
    program: &Program,
    f: &crate::program::Function,
    value: Id,
    n: usize,
    replaced: &[usize],
    is_copy: &dyn Fn(Id, Id) -> bool,
    seen: &mut Vec<Id>,
    on_read: &mut dyn FnMut(Option<usize>),
) {
    if seen.contains(&value) || seen.len() > 256 {
        return;
    }
    seen.push(value);
    let read_rest = |on_read: &mut dyn FnMut(Option<usize>)| {
        if replaced.is_empty() {
            on_read(None);
        } else {
            for k in (0..n).filter(|k| !replaced.contains(k)) {
                on_read(Some(k));
            }
        }
    };
    for inst in &program.insts[f.start..=f.end] {
        if program.is_debug_inst(inst) {
            continue;
        }
        let uses = inst
            .operands
            .iter()
            .any(|o| matches!(o, Operand::IdRef(x) if *x == value));
        if !uses {
            continue;
        }
        match inst.class.opcode {
            Op::CompositeExtract if matches!(inst.operands.first(), Some(Operand::IdRef(x)) if *x == value) => {
                match inst.operands.get(1) {
                    Some(Operand::LiteralBit32(k)) if !replaced.contains(&(*k as usize)) => {
                        on_read(Some(*k as usize))
                    }
                    Some(Operand::LiteralBit32(_)) => {}
                    _ => read_rest(on_read),
                }
            }
            Op::CompositeInsert
                if matches!(inst.operands.get(1), Some(Operand::IdRef(x)) if *x == value)
                    && !matches!(inst.operands.first(), Some(Operand::IdRef(x)) if *x == value) =>
            {
                let (Some(r), Some(Operand::LiteralBit32(k))) =
                    (inst.result_id, inst.operands.get(2))
                else {
                    read_rest(on_read);
                    continue;
                };
                let mut more = replaced.to_vec();
                more.push(*k as usize);
                read_value(program, f, r, n, &more, is_copy, seen, on_read);
            }
            Op::CopyObject | Op::Phi => match inst.result_id {
                Some(r) => read_value(program, f, r, n, replaced, is_copy, seen, on_read),
                None => read_rest(on_read),
            },
            Op::Store => {
                let Some(Operand::IdRef(ptr)) = inst.operands.first() else {
                    read_rest(on_read);
                    continue;
                };
                if !is_copy(*ptr, value) && !is_copy_through(program, *ptr, value, is_copy) {
                    read_rest(on_read);
                }
            }
            Op::Name => {}
            _ => read_rest(on_read),
        }
    }
}

/// Whether storing `value` (derived from a whole load by inserts) into
/// `ptr` puts it back where it came from: `ptr` stands for the variable.
fn is_copy_through(
    program: &Program,
    ptr: Id,
    value: Id,
    is_copy: &dyn Fn(Id, Id) -> bool,
) -> bool {
    // Walk the insert chain back to its load.
    let mut v = value;
    for _ in 0..64 {
        let Some(inst) = program.def(v) else {
            return false;
        };
        match inst.class.opcode {
            Op::Load => return is_copy(ptr, v),
            Op::CompositeInsert | Op::CopyObject => {
                let base = if inst.class.opcode == Op::CompositeInsert {
                    1
                } else {
                    0
                };
                match inst.operands.get(base) {
                    Some(Operand::IdRef(b)) => v = *b,
                    _ => return false,
                }
            }
            _ => return false,
        }
    }
    false
}

/// The globals of `storage` that code reachable from `entry` names.
pub fn globals_used(program: &Program, entry: Id, storage: StorageClass) -> Vec<Id> {
    let wanted: Vec<Id> = program.globals_in(storage).map(|g| g.id).collect();
    if wanted.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for f in program.reachable_functions(entry) {
        let Some(f) = program.function(f) else {
            continue;
        };
        for inst in &program.insts[f.start..=f.end] {
            for o in &inst.operands {
                if let Operand::IdRef(x) = o {
                    if wanted.contains(x) && !out.contains(x) {
                        out.push(*x);
                    }
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shader::Language;

    fn hlsl(src: &str) -> Program {
        let dir = std::env::temp_dir().join(format!("rtlint-payload-use-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("t{}.hlsl", src.len()));
        std::fs::write(&path, src).unwrap();
        crate::front::load(&path, Language::Hlsl).unwrap()
    }

    fn uses_of(p: &Program, entry: &str, storage: StorageClass) -> Vec<Access> {
        let e = p.entry_points.iter().find(|e| e.name == entry).unwrap();
        let v = globals_used(p, e.function, storage);
        assert_eq!(v.len(), 1, "{entry}: {v:?}");
        variable_use(p, e.function, v[0])
    }

    const SRC: &str = r#"
RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> output : register(u0);
struct Payload { float3 color; float hitT; uint spare; };
[shader("raygeneration")]
void RayGen() {
    RayDesc ray; ray.Origin = float3(0,0,0); ray.Direction = float3(0,0,1); ray.TMin = 0.001; ray.TMax = 100;
    Payload p; p.color = float3(0,0,0); p.hitT = 0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    output[DispatchRaysIndex().xy] = float4(p.color, 1);
}
[shader("closesthit")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a) {
    p.color = float3(a.barycentrics, p.hitT);
}
"#;

    #[test]
    fn hlsl_copies_through_locals_do_not_count() {
        let p = hlsl(SRC);
        let rg = uses_of(&p, "RayGen", StorageClass::RayPayloadKHR);
        assert_eq!(
            rg,
            [
                Access {
                    read: true,
                    written: true
                },
                Access {
                    read: false,
                    written: true
                },
                Access::default()
            ]
        );
        let hit = uses_of(&p, "Hit", StorageClass::IncomingRayPayloadKHR);
        assert_eq!(
            hit,
            [
                Access {
                    read: false,
                    written: true
                },
                Access {
                    read: true,
                    written: false
                },
                Access::default()
            ]
        );
    }
}
