//! Float values and value sources the module makes known once locals are
//! forwarded: the ray interval, origin and direction of a trace.
//!
//! Like [`Program::fold`], no optimiser runs. A load from a function-local
//! variable (or a member of one, as HLSL's `RayDesc` and naga's `var`s are
//! written member by member) is the value every write to that place stores,
//! when they all store the same id; a function parameter is the argument of
//! the call chain's call. Anything else is unknown.

use super::{Constant, Id, Program, Type};
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};

const MAX_DEPTH: u32 = 24;

impl Program {
    /// The components of float (or integer) scalar, vector or composite
    /// value `id` when they fold to constants, in the context of call chain
    /// `chain`.
    pub fn fold_floats_in(&self, id: Id, chain: &[usize]) -> Option<Vec<f64>> {
        self.ffold(id, chain, 0)
    }

    /// The instruction that computes value `id` once loads from locals that
    /// hold one stored value, copies and parameters are seen through, with
    /// the part of `chain` that it lives in.
    pub fn value_source<'c>(&self, id: Id, chain: &'c [usize]) -> (Id, &'c [usize]) {
        let mut cur = (id, chain);
        for _ in 0..MAX_DEPTH {
            let Some(inst) = self.def(cur.0) else {
                return cur;
            };
            let next = match inst.class.opcode {
                Op::CopyObject => first_id(&inst.operands).map(|x| (x, cur.1)),
                Op::FunctionParameter => self.argument(cur.0, cur.1),
                Op::Load => first_id(&inst.operands)
                    .and_then(|p| self.stored_at(p, &[]))
                    .map(|x| (x, cur.1)),
                Op::CompositeExtract => {
                    let path = literals(&inst.operands);
                    first_id(&inst.operands).and_then(|b| self.element_source(b, &path, cur.1, 0))
                }
                _ => None,
            };
            match next {
                Some(n) => cur = n,
                None => return cur,
            }
        }
        cur
    }

    /// The variable a pointer points into (through access chains).
    pub fn pointer_root(&self, mut ptr: Id) -> Id {
        for _ in 0..MAX_DEPTH {
            match self.def(ptr) {
                Some(i)
                    if matches!(
                        i.class.opcode,
                        Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain
                    ) =>
                {
                    match first_id(&i.operands) {
                        Some(b) => ptr = b,
                        None => return ptr,
                    }
                }
                _ => return ptr,
            }
        }
        ptr
    }

    /// The storage class of a variable.
    pub fn storage_of(&self, var: Id) -> Option<StorageClass> {
        let i = self.def(var)?;
        if i.class.opcode != Op::Variable {
            return None;
        }
        match i.operands.first() {
            Some(Operand::StorageClass(s)) => Some(*s),
            _ => None,
        }
    }

    /// The `BuiltIn` a variable is decorated with.
    pub fn builtin_of(&self, var: Id) -> Option<u32> {
        self.decoration(var, spirv::Decoration::BuiltIn)
            .and_then(|v| v.first().copied())
    }

    /// The id of the `GLSL.std.450` import, if any.
    pub fn glsl_std_set(&self) -> Option<Id> {
        let glsl = |o: Option<&Operand>| matches!(o, Some(Operand::LiteralString(s)) if s == "GLSL.std.450");
        // Imports come before the memory model.
        self.insts
            .iter()
            .take_while(|i| i.class.opcode != Op::MemoryModel)
            .find(|i| i.class.opcode == Op::ExtInstImport && glsl(i.operands.first()))
            .and_then(|i| i.result_id)
    }

    /// Element `path` of composite `base`'s source.
    fn element_source<'c>(
        &self,
        base: Id,
        path: &[u32],
        chain: &'c [usize],
        depth: u32,
    ) -> Option<(Id, &'c [usize])> {
        if path.is_empty() {
            return Some((base, chain));
        }
        if depth > MAX_DEPTH {
            return None;
        }
        if let Some(Constant::Composite(parts)) = self.constants.get(&base) {
            return self.element_source(
                *parts.get(path[0] as usize)?,
                &path[1..],
                chain,
                depth + 1,
            );
        }
        let inst = self.def(base)?;
        match inst.class.opcode {
            Op::CompositeConstruct if self.is_struct_or_array(inst.result_type?) => {
                let Some(Operand::IdRef(e)) = inst.operands.get(path[0] as usize) else {
                    return None;
                };
                self.element_source(*e, &path[1..], chain, depth + 1)
            }
            Op::FunctionParameter => {
                let (arg, outer) = self.argument(base, chain)?;
                self.element_source(arg, path, outer, depth + 1)
            }
            Op::CopyObject => {
                self.element_source(first_id(&inst.operands)?, path, chain, depth + 1)
            }
            Op::Load => {
                let v = self.stored_at(first_id(&inst.operands)?, path)?;
                Some((v, chain))
            }
            _ => None,
        }
    }

    fn is_struct_or_array(&self, ty: Id) -> bool {
        matches!(self.ty(ty), Some(Type::Struct { .. } | Type::Array { .. }))
    }

    /// The one id every write to place `path` of function-local variable
    /// `ptr` stores (whole-variable stores count, projected to `path`);
    /// `None` when writes differ, one is not understood, or the variable
    /// escapes into a call.
    fn stored_at(&self, ptr: Id, path: &[u32]) -> Option<Id> {
        self.stored_at_depth(ptr, path, 0)
    }

    fn stored_at_depth(&self, ptr: Id, path: &[u32], depth: u32) -> Option<Id> {
        if depth > MAX_DEPTH {
            return None;
        }
        // A pointer into a member: extend the path.
        let def = self.def(ptr)?;
        if matches!(def.class.opcode, Op::AccessChain | Op::InBoundsAccessChain) {
            let mut idx = Vec::new();
            for o in def.operands.iter().skip(1) {
                let Operand::IdRef(i) = o else { return None };
                idx.push(u32::try_from(self.const_u64(*i)?).ok()?);
            }
            idx.extend_from_slice(path);
            return self.stored_at_depth(first_id(&def.operands)?, &idx, depth + 1);
        }
        if self.storage_of(ptr) != Some(StorageClass::Function) {
            return None;
        }
        let f = self
            .functions
            .get(self.function_of(*self.defs.get(&ptr)?)?)?;
        // Every pointer into the variable, with its constant index path.
        let mut pointers: Vec<(Id, Vec<u32>)> = vec![(ptr, Vec::new())];
        let mut value: Option<Id> = None;
        let mut merge = |v: Option<Id>| -> Option<()> {
            let v = v?;
            match value {
                Some(w) if w != v => None,
                _ => {
                    value = Some(v);
                    Some(())
                }
            }
        };
        if let Some(Operand::IdRef(init)) = def.operands.get(1) {
            merge(self.project(*init, path, 0))?;
        }
        for inst in &self.insts[f.start..=f.end] {
            if self.is_debug_inst(inst) {
                continue;
            }
            let uses: Vec<(usize, Vec<u32>)> = inst
                .operands
                .iter()
                .enumerate()
                .filter_map(|(k, o)| match o {
                    Operand::IdRef(x) => pointers
                        .iter()
                        .find(|(p, _)| p == x)
                        .map(|(_, path)| (k, path.clone())),
                    _ => None,
                })
                .collect();
            let Some((k, at)) = uses.first().cloned() else {
                continue;
            };
            match inst.class.opcode {
                Op::Load => {}
                Op::AccessChain | Op::InBoundsAccessChain if k == 0 => {
                    let mut idx = at.clone();
                    for o in inst.operands.iter().skip(1) {
                        let Operand::IdRef(i) = o else { return None };
                        idx.push(u32::try_from(self.const_u64(*i)?).ok()?);
                    }
                    pointers.push((inst.result_id?, idx));
                }
                Op::Store if k == 0 && uses.len() == 1 => {
                    let Some(Operand::IdRef(stored)) = inst.operands.get(1) else {
                        return None;
                    };
                    if at.len() <= path.len() && path[..at.len()] == at[..] {
                        // The store covers the place.
                        merge(self.project(*stored, &path[at.len()..], 0))?;
                    } else if path.len() < at.len() && at[..path.len()] == path[..] {
                        // The store writes part of the place.
                        return None;
                    }
                }
                _ => return None,
            }
        }
        value
    }

    /// Element `path` of value `id` as an id, when it can be named.
    fn project(&self, id: Id, path: &[u32], depth: u32) -> Option<Id> {
        if path.is_empty() {
            return Some(id);
        }
        if depth > MAX_DEPTH {
            return None;
        }
        if let Some(Constant::Composite(parts)) = self.constants.get(&id) {
            return self.project(*parts.get(path[0] as usize)?, &path[1..], depth + 1);
        }
        let inst = self.def(id)?;
        if inst.class.opcode == Op::CompositeConstruct && self.is_struct_or_array(inst.result_type?)
        {
            if let Some(Operand::IdRef(e)) = inst.operands.get(path[0] as usize) {
                return self.project(*e, &path[1..], depth + 1);
            }
        }
        None
    }

    fn ffold(&self, id: Id, chain: &[usize], depth: u32) -> Option<Vec<f64>> {
        if depth > MAX_DEPTH {
            return None;
        }
        if let Some(c) = self.constants.get(&id) {
            return match c {
                Constant::Float(f) => Some(vec![*f]),
                Constant::Int(v) => {
                    let signed = self
                        .def(id)
                        .and_then(|i| i.result_type)
                        .and_then(|t| self.ty(t))
                        .is_some_and(|t| {
                            matches!(
                                t,
                                Type::Int {
                                    signed: true,
                                    width: 32
                                }
                            )
                        });
                    Some(vec![if signed {
                        *v as u32 as i32 as f64
                    } else {
                        *v as f64
                    }])
                }
                Constant::Bool(b) => Some(vec![f64::from(u8::from(*b))]),
                Constant::Null => {
                    let ty = self.def(id)?.result_type?;
                    Some(vec![0.0; self.components(ty)?])
                }
                Constant::Composite(parts) => {
                    let mut v = Vec::new();
                    for p in parts {
                        v.extend(self.ffold(*p, chain, depth + 1)?);
                    }
                    Some(v)
                }
            };
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
        let arg = |k: usize| ids.get(k).and_then(|&x| self.ffold(x, chain, depth + 1));
        let zip = |f: fn(f64, f64) -> f64| -> Option<Vec<f64>> {
            let (a, b) = (arg(0)?, arg(1)?);
            if a.len() == b.len() {
                Some(a.iter().zip(&b).map(|(x, y)| f(*x, *y)).collect())
            } else if b.len() == 1 {
                Some(a.iter().map(|x| f(*x, b[0])).collect())
            } else {
                None
            }
        };
        match inst.class.opcode {
            Op::Load | Op::CopyObject | Op::FunctionParameter | Op::CompositeExtract => {
                let (src, outer) = self.value_source(id, chain);
                if src == id {
                    return None;
                }
                self.ffold(src, outer, depth + 1)
            }
            Op::CompositeConstruct => {
                let mut v = Vec::new();
                for k in 0..ids.len() {
                    v.extend(arg(k)?);
                }
                Some(v)
            }
            Op::FConvert | Op::ConvertSToF | Op::ConvertUToF => arg(0),
            Op::FNegate => Some(arg(0)?.iter().map(|x| -x).collect()),
            Op::FAdd => zip(|a, b| a + b),
            Op::FSub => zip(|a, b| a - b),
            Op::FMul | Op::VectorTimesScalar => zip(|a, b| a * b),
            Op::FDiv => zip(|a, b| a / b),
            Op::ExtInst if Some(ids.first().copied()?) == self.glsl_std_set() => {
                match inst.operands.get(1) {
                    // Normalize
                    Some(Operand::LiteralExtInstInteger(69)) => {
                        let v = self.ffold(*ids.get(1)?, chain, depth + 1)?;
                        let len = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                        Some(v.iter().map(|x| x / len).collect())
                    }
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// The number of scalar components of a type.
    fn components(&self, ty: Id) -> Option<usize> {
        match self.ty(ty)? {
            Type::Bool | Type::Int { .. } | Type::Float { .. } => Some(1),
            Type::Vector { count, .. } => Some(*count as usize),
            Type::Matrix { column, columns } => Some(self.components(*column)? * *columns as usize),
            Type::Struct { members } => members.iter().map(|m| self.components(*m)).sum(),
            Type::Array { elem, len } => Some(self.components(*elem)? * len.value()? as usize),
            _ => None,
        }
    }
}

fn first_id(ops: &[Operand]) -> Option<Id> {
    match ops.first() {
        Some(Operand::IdRef(x)) => Some(*x),
        _ => None,
    }
}

fn literals(ops: &[Operand]) -> Vec<u32> {
    ops.iter()
        .filter_map(|o| match o {
            Operand::LiteralBit32(x) => Some(*x),
            _ => None,
        })
        .collect()
}
