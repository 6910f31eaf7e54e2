//! Integer values the module makes constant once locals are forwarded.
//!
//! Unoptimised compiler output (glslang without `-O`, rtlint's own HLSL, naga
//! `var`s) keeps values such as ray flags in a function-local variable:
//! stored once, loaded at the trace. Here a load from a local whose every
//! write stores the same foldable value is that value, and integer
//! arithmetic over such values is folded. No optimiser runs; anything else
//! is not constant.

use super::{Id, OperandValue, Program, TraceOperands, Type};
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};

/// How deep folding follows operands.
const MAX_DEPTH: u32 = 16;

/// The most constants [`Program::fold_choices_in`] lists for one value.
pub const MAX_CHOICES: usize = 8;

impl Program {
    /// The value of integer (or boolean) `id` when it folds to a constant:
    /// a constant, a local variable holding one constant, or integer
    /// arithmetic and conversions of those.
    pub fn fold(&self, id: Id) -> Option<u64> {
        self.fold_at(id, &[], 0)
    }

    /// [`Program::fold`] in the context of a call chain (`OpFunctionCall`
    /// indices, outermost first): a function parameter is the argument the
    /// chain's call passes, so the operands of a trace in a helper (naga
    /// wraps every `traceRay` in one, taking the `RayDesc` as a parameter)
    /// fold per caller.
    pub fn fold_in(&self, id: Id, chain: &[usize]) -> Option<u64> {
        self.fold_at(id, chain, 0)
    }

    /// The constants integer `id` may be through `chain` when it is a
    /// choice between foldable values: a `select`, a phi, a local variable
    /// whose every write stores one (`flags = RAY_FLAG_FORCE_OPAQUE;` on one
    /// branch), and ORs and ANDs of those; sorted, each once, at most
    /// [`MAX_CHOICES`]. `None` when any part is not known.
    pub fn fold_choices_in(&self, id: Id, chain: &[usize]) -> Option<Vec<u64>> {
        let mut v = self.choices_at(id, chain, 0)?;
        v.sort_unstable();
        v.dedup();
        Some(v)
    }

    fn choices_at(&self, id: Id, chain: &[usize], depth: u32) -> Option<Vec<u64>> {
        if let Some(v) = self.fold_at(id, chain, depth) {
            return Some(vec![v]);
        }
        if depth > MAX_DEPTH {
            return None;
        }
        let inst = self.def(id)?;
        let ids: Vec<Id> = inst
            .operands
            .iter()
            .filter_map(|o| match o {
                Operand::IdRef(x) => Some(*x),
                _ => None,
            })
            .collect();
        let of = |x: Id| self.choices_at(x, chain, depth + 1);
        let union = |parts: &mut dyn Iterator<Item = Id>| -> Option<Vec<u64>> {
            let mut out = Vec::new();
            for x in parts {
                out.extend(of(x)?);
                out.sort_unstable();
                out.dedup();
                if out.len() > MAX_CHOICES {
                    return None;
                }
            }
            Some(out)
        };
        let pairs = |f: fn(u64, u64) -> u64| -> Option<Vec<u64>> {
            let (a, b) = (of(*ids.first()?)?, of(*ids.get(1)?)?);
            let mut out: Vec<u64> = a
                .iter()
                .flat_map(|&x| b.iter().map(move |&y| f(x, y)))
                .collect();
            out.sort_unstable();
            out.dedup();
            (out.len() <= MAX_CHOICES).then_some(out)
        };
        match inst.class.opcode {
            // The condition is not folded (else `fold_at` would have).
            Op::Select => union(&mut ids.iter().skip(1).copied()),
            // Values and parent blocks alternate.
            Op::Phi => union(&mut ids.iter().step_by(2).copied()),
            Op::BitwiseOr => pairs(|x, y| x | y),
            Op::BitwiseAnd => pairs(|x, y| x & y),
            Op::CopyObject | Op::Bitcast | Op::UConvert | Op::SConvert => of(*ids.first()?),
            Op::FunctionParameter => {
                let (arg, outer) = self.argument(id, chain)?;
                self.choices_at(arg, outer, depth + 1)
            }
            Op::Load => self.stored_choices(*ids.first()?, chain, depth + 1),
            _ => None,
        }
    }

    /// The values the writes to local variable `ptr` store, when each is a
    /// choice of constants and nothing else writes it (see
    /// [`Program::fold_choices_in`]).
    fn stored_choices(&self, ptr: Id, chain: &[usize], depth: u32) -> Option<Vec<u64>> {
        let mut out: Vec<u64> = Vec::new();
        for stored in self.local_writes(ptr)? {
            out.extend(self.choices_at(stored, chain, depth)?);
            out.sort_unstable();
            out.dedup();
            if out.len() > MAX_CHOICES {
                return None;
            }
        }
        (!out.is_empty()).then_some(out)
    }

    /// What local variable `ptr` is written with: its initialiser, then the
    /// value of each whole store, in order; `None` when it is no local of a
    /// function or something else may write it (an access chain, a call).
    fn local_writes(&self, ptr: Id) -> Option<Vec<Id>> {
        let var = self.def(ptr)?;
        let local = var.class.opcode == Op::Variable
            && matches!(
                var.operands.first(),
                Some(Operand::StorageClass(StorageClass::Function))
            );
        if !local {
            return None;
        }
        let f = self
            .functions
            .get(self.function_of(*self.defs.get(&ptr)?)?)?;
        let mut out: Vec<Id> = match var.operands.get(1) {
            Some(Operand::IdRef(init)) => vec![*init],
            _ => Vec::new(),
        };
        for inst in &self.insts[f.start..=f.end] {
            let mut uses = inst
                .operands
                .iter()
                .enumerate()
                .filter(|(_, o)| matches!(o, Operand::IdRef(x) if *x == ptr));
            let Some((k, _)) = uses.next() else { continue };
            if self.is_debug_inst(inst) {
                continue;
            }
            match inst.class.opcode {
                Op::Load => {}
                Op::Store if k == 0 && uses.next().is_none() => match inst.operands.get(1) {
                    Some(Operand::IdRef(stored)) => out.push(*stored),
                    _ => return None,
                },
                // An access chain, a call or anything else may write it.
                _ => return None,
            }
        }
        Some(out)
    }

    /// The bits of integer `id` that are set whatever its dynamic parts
    /// hold, through `chain`: all of them when it folds, else the constant
    /// side of an OR (`RAY_FLAG_SKIP_CLOSEST_HIT_SHADER | extraFlags`), the
    /// bits every store to a local sets, and so on through copies.
    pub fn known_ones_in(&self, id: Id, chain: &[usize]) -> u64 {
        self.known_ones_at(id, chain, 0)
    }

    fn known_ones_at(&self, id: Id, chain: &[usize], depth: u32) -> u64 {
        if let Some(v) = self.fold_at(id, chain, depth) {
            return v;
        }
        if depth > MAX_DEPTH {
            return 0;
        }
        let Some(inst) = self.def(id) else {
            return 0;
        };
        let op = |k: usize| match inst.operands.get(k) {
            Some(Operand::IdRef(x)) => self.known_ones_at(*x, chain, depth + 1),
            _ => 0,
        };
        match inst.class.opcode {
            Op::BitwiseOr => op(0) | op(1),
            Op::BitwiseAnd => op(0) & op(1),
            Op::CopyObject | Op::Bitcast => op(0),
            Op::FunctionParameter => match self.argument(id, chain) {
                Some((arg, outer)) => self.known_ones_at(arg, outer, depth + 1),
                None => 0,
            },
            Op::Load => match inst.operands.first() {
                Some(Operand::IdRef(ptr)) => self.stored_ones(*ptr, chain, depth + 1),
                _ => 0,
            },
            _ => 0,
        }
    }

    /// The bits every write to local variable `ptr` sets.
    fn stored_ones(&self, ptr: Id, chain: &[usize], depth: u32) -> u64 {
        self.local_writes(ptr)
            .and_then(|writes| {
                writes
                    .into_iter()
                    .map(|stored| self.known_ones_at(stored, chain, depth))
                    .reduce(|a, b| a & b)
            })
            .unwrap_or(0)
    }

    /// A trace's operands as the given call chain reaches it.
    pub fn trace_operands_in(
        &self,
        site: &super::RtSite,
        chain: &[usize],
    ) -> Option<TraceOperands> {
        let inst = &self.insts[site.inst];
        if site.kind != super::SiteKind::TraceRay {
            return None;
        }
        let base = site.trace?;
        let o = |n: usize, old: OperandValue| match (old, inst.operands.get(n)) {
            (OperandValue::Dynamic(_), Some(Operand::IdRef(id))) => {
                self.fold_in(*id, chain).map_or(old, OperandValue::Const)
            }
            _ => old,
        };
        Some(TraceOperands {
            ray_flags: o(1, base.ray_flags),
            cull_mask: o(2, base.cull_mask),
            sbt_offset: o(3, base.sbt_offset),
            sbt_stride: o(4, base.sbt_stride),
            miss_index: o(5, base.miss_index),
        })
    }

    /// The position of instruction `inst` reached through `chain`: its own,
    /// else that of the innermost call with one.
    pub fn location_in(&self, inst: usize, chain: &[usize]) -> Option<crate::diag::Location> {
        std::iter::once(inst)
            .chain(chain.iter().rev().copied())
            .find_map(|i| self.inst_location(i))
    }

    /// The argument a call chain passes for function parameter `param`, with
    /// the rest of the chain (outside that call).
    pub(super) fn argument<'c>(&self, param: Id, chain: &'c [usize]) -> Option<(Id, &'c [usize])> {
        let f = self
            .functions
            .get(self.function_of(*self.defs.get(&param)?)?)?;
        let k = f.params.iter().position(|&p| p == param)?;
        let at = chain.iter().rposition(
            |&c| matches!(self.insts[c].operands.first(), Some(Operand::IdRef(x)) if *x == f.id),
        )?;
        match self.insts[chain[at]].operands.get(1 + k) {
            Some(Operand::IdRef(arg)) => Some((*arg, &chain[..at])),
            _ => None,
        }
    }

    /// Element `path` of composite value `id`, folded.
    fn fold_element(&self, id: Id, path: &[u32], chain: &[usize], depth: u32) -> Option<u64> {
        if path.is_empty() {
            return self.fold_at(id, chain, depth + 1);
        }
        if depth > MAX_DEPTH {
            return None;
        }
        if let Some(super::Constant::Composite(parts)) = self.constants.get(&id) {
            return self.fold_element(*parts.get(path[0] as usize)?, &path[1..], chain, depth + 1);
        }
        let inst = self.def(id)?;
        match inst.class.opcode {
            Op::CompositeConstruct => {
                let Some(Operand::IdRef(e)) = inst.operands.get(path[0] as usize) else {
                    return None;
                };
                self.fold_element(*e, &path[1..], chain, depth + 1)
            }
            Op::FunctionParameter => {
                let (arg, outer) = self.argument(id, chain)?;
                self.fold_element(arg, path, outer, depth + 1)
            }
            Op::CopyObject => match inst.operands.first() {
                Some(Operand::IdRef(x)) => self.fold_element(*x, path, chain, depth + 1),
                _ => None,
            },
            _ => None,
        }
    }

    fn fold_at(&self, id: Id, chain: &[usize], depth: u32) -> Option<u64> {
        if let Some(v) = self.const_u64(id) {
            return Some(v);
        }
        if depth > MAX_DEPTH {
            return None;
        }
        let inst = self.def(id)?;
        let ops: Vec<Id> = inst
            .operands
            .iter()
            .filter_map(|o| match o {
                Operand::IdRef(x) => Some(*x),
                _ => None,
            })
            .collect();
        let arg = |k: usize| ops.get(k).and_then(|&x| self.fold_at(x, chain, depth + 1));
        let mask = match inst.result_type.and_then(|t| self.ty(t)) {
            Some(Type::Int { width, .. }) if *width < 64 => (1u64 << width) - 1,
            Some(Type::Bool) => 1,
            _ => u64::MAX,
        };
        let v = match inst.class.opcode {
            Op::Load => return self.forwarded(*ops.first()?, chain, depth + 1),
            Op::FunctionParameter => {
                let (arg, outer) = self.argument(id, chain)?;
                return self.fold_at(arg, outer, depth + 1);
            }
            Op::CompositeExtract => {
                let path: Vec<u32> = inst
                    .operands
                    .iter()
                    .filter_map(|o| match o {
                        Operand::LiteralBit32(x) => Some(*x),
                        _ => None,
                    })
                    .collect();
                return self
                    .fold_element(*ops.first()?, &path, chain, depth + 1)
                    .map(|v| v & mask);
            }
            Op::CopyObject | Op::Bitcast | Op::UConvert | Op::SConvert => arg(0)?,
            Op::BitwiseOr => arg(0)? | arg(1)?,
            Op::BitwiseAnd => arg(0)? & arg(1)?,
            Op::BitwiseXor => arg(0)? ^ arg(1)?,
            Op::Not => !arg(0)?,
            Op::IAdd => arg(0)?.wrapping_add(arg(1)?),
            Op::ISub => arg(0)?.wrapping_sub(arg(1)?),
            Op::IMul => arg(0)?.wrapping_mul(arg(1)?),
            Op::ShiftLeftLogical => arg(0)?.checked_shl(arg(1)? as u32)?,
            Op::ShiftRightLogical => arg(0)?.checked_shr(arg(1)? as u32)?,
            Op::Select => {
                if arg(0)? != 0 {
                    arg(1)?
                } else {
                    arg(2)?
                }
            }
            _ => return None,
        };
        Some(v & mask)
    }

    /// Whether the function `call` calls never stores through, nor passes
    /// on, its parameter for operand `k` (an `in` argument's copy).
    fn reads_only(&self, call: &rspirv::dr::Instruction, k: usize) -> bool {
        let Some(Operand::IdRef(callee)) = call.operands.first() else {
            return false;
        };
        let Some(f) = self.functions.iter().find(|f| f.id == *callee) else {
            return false;
        };
        let Some(&param) = f.params.get(k - 1) else {
            return false;
        };
        self.insts[f.start..=f.end].iter().all(|i| {
            self.is_debug_inst(i)
                || !i
                    .operands
                    .iter()
                    .any(|o| matches!(o, Operand::IdRef(x) if *x == param))
                || i.class.opcode == Op::Load
        })
    }

    /// The one value every write to local variable `ptr` stores, folded.
    fn forwarded(&self, ptr: Id, chain: &[usize], depth: u32) -> Option<u64> {
        let var = self.def(ptr)?;
        if var.class.opcode == Op::FunctionParameter && depth <= MAX_DEPTH {
            // A pointer parameter (HLSL's copy of an `in` argument): the
            // temporary the chain's call passes.
            let (arg, outer) = self.argument(ptr, chain)?;
            return self.forwarded(arg, outer, depth + 1);
        }
        if var.class.opcode != Op::Variable
            || !matches!(
                var.operands.first(),
                Some(Operand::StorageClass(StorageClass::Function))
            )
        {
            return None;
        }
        let f = self
            .functions
            .get(self.function_of(*self.defs.get(&ptr)?)?)?;
        let mut value: Option<u64> = match var.operands.get(1) {
            Some(Operand::IdRef(init)) => Some(self.fold_at(*init, chain, depth)?),
            _ => None,
        };
        for inst in &self.insts[f.start..=f.end] {
            let mut uses = inst
                .operands
                .iter()
                .enumerate()
                .filter(|(_, o)| matches!(o, Operand::IdRef(x) if *x == ptr));
            let Some((k, _)) = uses.next() else { continue };
            if self.is_debug_inst(inst) {
                continue;
            }
            match inst.class.opcode {
                Op::Load => {}
                // Passed to a function that only reads it (HLSL's copy of an
                // `in` argument).
                Op::FunctionCall if k > 0 && uses.next().is_none() && self.reads_only(inst, k) => {}
                Op::Store if k == 0 && uses.next().is_none() => {
                    let Some(Operand::IdRef(stored)) = inst.operands.get(1) else {
                        return None;
                    };
                    let v = self.fold_at(*stored, chain, depth)?;
                    if value.is_some_and(|w| w != v) {
                        return None;
                    }
                    value = Some(v);
                }
                // An access chain, a call or anything else may write it.
                _ => return None,
            }
        }
        value
    }
}
