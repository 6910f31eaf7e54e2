//! Uniformity: which values of a module may differ between the invocations
//! of one draw, dispatch or trace (are not dynamically uniform).
//!
//! A data-flow over the whole module, to a fixed point, ignoring control
//! dependence (a value chosen under a varying branch counts as uniform: the
//! analysis errs towards "uniform", so rules built on it report less, not
//! more). Varying sources: builtins other than sizes and counts, other
//! inputs, ray payloads, hit attributes, callable data, ray-query results,
//! atomics. Loads are varying when their address is (an index or pointer
//! that varies) or the variable holds a varying value (a local stored from
//! one). Subgroup operations that return one value for the whole subgroup
//! (`subgroupBroadcastFirst`, `WaveReadLaneFirst`, votes, reductions) are
//! uniform.

use crate::program::{Id, Program};
use rspirv::dr::Operand;
use spirv::{BuiltIn, Decoration, GroupOperation, Op, StorageClass};
use std::collections::HashSet;

/// The ids (values, and variables whose contents) that may vary.
#[derive(Debug, Default)]
pub struct Varying {
    ids: HashSet<Id>,
}

impl Varying {
    pub fn contains(&self, id: Id) -> bool {
        self.ids.contains(&id)
    }
}

/// Builtins with one value for the whole dispatch.
fn uniform_builtin(b: u32) -> bool {
    [
        BuiltIn::LaunchSizeKHR,
        BuiltIn::NumWorkgroups,
        BuiltIn::WorkgroupSize,
        BuiltIn::SubgroupSize,
        BuiltIn::NumSubgroups,
        BuiltIn::ViewIndex,
        BuiltIn::DrawIndex,
        BuiltIn::BaseInstance,
        BuiltIn::BaseVertex,
    ]
    .iter()
    .any(|x| *x as u32 == b)
}

fn is_varying_source_var(p: &Program, var: Id, storage: StorageClass) -> bool {
    match storage {
        StorageClass::Input => match p.decoration(var, Decoration::BuiltIn) {
            Some([b, ..]) => !uniform_builtin(*b),
            // A struct of builtins (gl_PerVertex) or a user input.
            _ => true,
        },
        StorageClass::IncomingRayPayloadKHR
        | StorageClass::RayPayloadKHR
        | StorageClass::HitAttributeKHR
        | StorageClass::CallableDataKHR
        | StorageClass::IncomingCallableDataKHR
        | StorageClass::ShaderRecordBufferKHR => {
            // The shader record differs per hit group record: varying in hit stages.
            storage != StorageClass::ShaderRecordBufferKHR
                || !p.entry_points.iter().all(|e| {
                    matches!(
                        e.stage,
                        crate::shader::Stage::RayGeneration | crate::shader::Stage::Compute
                    )
                })
        }
        _ => false,
    }
}

/// Results uniform across the subgroup whatever their operands.
fn subgroup_uniform(p: &Program, inst: &rspirv::dr::Instruction) -> bool {
    match inst.class.opcode {
        Op::GroupNonUniformBroadcastFirst
        | Op::SubgroupFirstInvocationKHR
        | Op::GroupNonUniformAll
        | Op::GroupNonUniformAny
        | Op::GroupNonUniformAllEqual
        | Op::SubgroupAllKHR
        | Op::SubgroupAnyKHR
        | Op::SubgroupAllEqualKHR
        | Op::GroupNonUniformBallot => true,
        Op::GroupNonUniformBroadcast => {
            // Uniform when the lane id is.
            matches!(inst.operands.get(2), Some(Operand::IdRef(l)) if p.constants.contains_key(l))
        }
        Op::GroupNonUniformIAdd
        | Op::GroupNonUniformFAdd
        | Op::GroupNonUniformIMul
        | Op::GroupNonUniformFMul
        | Op::GroupNonUniformSMin
        | Op::GroupNonUniformUMin
        | Op::GroupNonUniformFMin
        | Op::GroupNonUniformSMax
        | Op::GroupNonUniformUMax
        | Op::GroupNonUniformFMax
        | Op::GroupNonUniformBitwiseAnd
        | Op::GroupNonUniformBitwiseOr
        | Op::GroupNonUniformBitwiseXor => matches!(
            inst.operands.get(1),
            Some(Operand::GroupOperation(GroupOperation::Reduce))
        ),
        _ => false,
    }
}

/// The root variable (or function parameter) a pointer is derived from.
pub fn pointer_root(p: &Program, mut id: Id) -> Id {
    for _ in 0..64 {
        let Some(inst) = p.def(id) else { return id };
        match (inst.class.opcode, inst.operands.first()) {
            (
                Op::AccessChain
                | Op::InBoundsAccessChain
                | Op::PtrAccessChain
                | Op::CopyObject
                | Op::Bitcast,
                Some(Operand::IdRef(base)),
            ) => id = *base,
            _ => return id,
        }
    }
    id
}

/// The varying values of `p`.
pub fn varying(p: &Program) -> Varying {
    let mut v: HashSet<Id> = HashSet::new();
    for g in &p.globals {
        if is_varying_source_var(p, g.id, g.storage) {
            v.insert(g.id);
        }
    }
    // Parameters by function, and return values, for calls.
    let mut changed = true;
    let mut rounds = 0;
    while changed && rounds < 64 {
        changed = false;
        rounds += 1;
        for (i, inst) in p.insts.iter().enumerate() {
            if p.is_debug_inst(inst) {
                continue;
            }
            let op = inst.class.opcode;
            let ids = |skip: usize| {
                inst.operands
                    .iter()
                    .skip(skip)
                    .filter_map(|o| match o {
                        Operand::IdRef(x) => Some(*x),
                        _ => None,
                    })
                    .collect::<Vec<_>>()
            };
            let mut mark = |id: Id, v: &mut HashSet<Id>| {
                if v.insert(id) {
                    changed = true;
                }
            };
            match op {
                Op::Store => {
                    let (Some(Operand::IdRef(ptr)), Some(Operand::IdRef(val))) =
                        (inst.operands.first(), inst.operands.get(1))
                    else {
                        continue;
                    };
                    if v.contains(val) || v.contains(ptr) {
                        let root = pointer_root(p, *ptr);
                        mark(root, &mut v);
                        // Through a pointer parameter: what each caller passes.
                        for arg in param_args(p, root) {
                            mark(pointer_root(p, arg), &mut v);
                        }
                    }
                }
                Op::FunctionCall => {
                    let Some(Operand::IdRef(callee)) = inst.operands.first() else {
                        continue;
                    };
                    let Some(f) = p.function(*callee) else {
                        continue;
                    };
                    for (k, a) in ids(1).iter().enumerate() {
                        if let Some(&param) = f.params.get(k) {
                            // A pointer argument carries its variable's contents.
                            let root = pointer_root(p, *a);
                            if v.contains(a) || v.contains(&root) {
                                mark(param, &mut v);
                            }
                        }
                    }
                    let returns_varying = p.insts[f.start..=f.end].iter().any(|r| {
                        r.class.opcode == Op::ReturnValue
                            && matches!(r.operands.first(), Some(Operand::IdRef(x)) if v.contains(x))
                    });
                    if let Some(r) = inst.result_id {
                        if returns_varying {
                            mark(r, &mut v);
                        }
                    }
                }
                Op::AtomicIAdd
                | Op::AtomicISub
                | Op::AtomicExchange
                | Op::AtomicCompareExchange
                | Op::AtomicIIncrement
                | Op::AtomicIDecrement
                | Op::AtomicUMax
                | Op::AtomicUMin
                | Op::AtomicSMax
                | Op::AtomicSMin
                | Op::AtomicOr
                | Op::AtomicAnd
                | Op::AtomicXor => {
                    if let Some(r) = inst.result_id {
                        mark(r, &mut v);
                    }
                }
                _ if crate::program::is_ray_query_op(op) => {
                    if let Some(r) = inst.result_id {
                        mark(r, &mut v);
                    }
                }
                _ if subgroup_uniform(p, inst) => {}
                Op::Load => {
                    let (Some(r), Some(Operand::IdRef(ptr))) =
                        (inst.result_id, inst.operands.first())
                    else {
                        continue;
                    };
                    let root = pointer_root(p, *ptr);
                    if v.contains(ptr) || v.contains(&root) {
                        mark(r, &mut v);
                    }
                }
                Op::Variable | Op::Function | Op::FunctionParameter | Op::Label => {}
                _ => {
                    let Some(r) = inst.result_id else { continue };
                    if p.types.contains_key(&r) || p.constants.contains_key(&r) {
                        continue;
                    }
                    if ids(0).iter().any(|x| v.contains(x)) {
                        mark(r, &mut v);
                    }
                }
            }
            let _ = i;
        }
    }
    Varying { ids: v }
}

/// The arguments callers pass for function parameter `param` (empty when
/// `param` is not a parameter).
fn param_args(p: &Program, param: Id) -> Vec<Id> {
    let Some(&at) = p.defs.get(&param) else {
        return Vec::new();
    };
    if p.insts[at].class.opcode != Op::FunctionParameter {
        return Vec::new();
    }
    let Some(f) = p.function_of(at).and_then(|f| p.functions.get(f)) else {
        return Vec::new();
    };
    let Some(k) = f.params.iter().position(|&x| x == param) else {
        return Vec::new();
    };
    p.callers(f.id)
        .into_iter()
        .filter_map(|c| match p.insts[c].operands.get(1 + k) {
            Some(Operand::IdRef(a)) => Some(*a),
            _ => None,
        })
        .collect()
}
