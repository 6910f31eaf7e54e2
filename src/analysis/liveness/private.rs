//! Module-scope `Private` variables (GLSL globals, HLSL `static`, WGSL
//! `var<private>`): state of the invocation like a local, but any function
//! may read or write them, so a call is a use of those its callees touch.

use crate::program::{Id, Program};
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};

/// Per function (by index): the `Private` variables it or a function it
/// calls may read, and may write, each sorted.
#[derive(Debug, Default)]
pub(super) struct PrivateUse {
    pub reads: Vec<Vec<Id>>,
    pub writes: Vec<Vec<Id>>,
    /// Those it writes whole before anything can branch: stored in its
    /// first block, or by a call there to a function that does (so on
    /// every path; a call to it overwrites them).
    pub must: Vec<Vec<Id>>,
    /// Every `Private` variable of the module, sorted (empty: nothing to do).
    pub all: Vec<Id>,
    /// The variables only ever written whole with one constant (GLSL's
    /// global initializers, stored at the start of `main`), sorted.
    pub constant: Vec<Id>,
}

impl PrivateUse {
    /// Worked out once per program.
    pub fn of(program: &Program) -> std::sync::Arc<PrivateUse> {
        program.memo.get_or(|| PrivateUse::new(program))
    }

    fn new(program: &Program) -> PrivateUse {
        let mut all: Vec<Id> = program
            .globals
            .iter()
            .filter(|g| g.storage == StorageClass::Private)
            .map(|g| g.id)
            .collect();
        all.sort_unstable();
        let n = program.functions.len();
        if all.is_empty() {
            return PrivateUse {
                reads: vec![Vec::new(); n],
                writes: vec![Vec::new(); n],
                must: vec![Vec::new(); n],
                all,
                constant: Vec::new(),
            };
        }
        let mut reads = vec![Vec::new(); n];
        let mut writes = vec![Vec::new(); n];
        let mut calls: Vec<Vec<usize>> = vec![Vec::new(); n];
        let mut must: Vec<Vec<Id>> = vec![Vec::new(); n];
        // Calls in each function's first block, in order.
        let mut first_calls: Vec<Vec<usize>> = vec![Vec::new(); n];
        // Per variable: the one constant stored whole so far (`Some`), or
        // another write met (`None`).
        let mut stored: rustc_hash::FxHashMap<Id, Option<Id>> = Default::default();
        for (fi, f) in program.functions.iter().enumerate() {
            // Pointers into a `Private` variable, by the variable.
            let mut into: rustc_hash::FxHashMap<Id, Id> = Default::default();
            let first_end = f.blocks.first().map_or(f.start, |b| b.end);
            for (at, inst) in program.insts[f.start..=f.end].iter().enumerate() {
                let in_first = f.start + at <= first_end;
                if program.is_debug_inst(inst) {
                    continue;
                }
                let op = inst.class.opcode;
                let ids: Vec<Id> = inst
                    .operands
                    .iter()
                    .filter_map(|o| match o {
                        Operand::IdRef(x) => Some(*x),
                        _ => None,
                    })
                    .collect();
                let var_of = |id: Id| {
                    if all.binary_search(&id).is_ok() {
                        Some(id)
                    } else {
                        into.get(&id).copied()
                    }
                };
                match op {
                    Op::AccessChain
                    | Op::InBoundsAccessChain
                    | Op::PtrAccessChain
                    | Op::CopyObject
                    | Op::Bitcast => {
                        if let (Some(v), Some(r)) =
                            (ids.first().and_then(|&b| var_of(b)), inst.result_id)
                        {
                            into.insert(r, v);
                        }
                        continue;
                    }
                    Op::FunctionCall => {
                        if let Some(c) = ids.first().and_then(|&c| program.function_index(c)) {
                            calls[fi].push(c);
                            if in_first {
                                first_calls[fi].push(c);
                            }
                        }
                    }
                    Op::Store if in_first => {
                        if let Some(&v) = ids.first().filter(|v| all.binary_search(v).is_ok()) {
                            must[fi].push(v);
                        }
                    }
                    _ => {}
                }
                for (k, &id) in ids.iter().enumerate() {
                    let Some(v) = var_of(id) else { continue };
                    if op != Op::Load {
                        let value = ids.get(1).copied();
                        let one = (op == Op::Store && k == 0 && id == v)
                            .then_some(value)
                            .flatten()
                            .filter(|c| program.constants.contains_key(c));
                        let e = stored.entry(v).or_insert(one);
                        if one.is_none() || *e != one {
                            *e = None;
                        }
                    }
                    match op {
                        Op::Store if k == 0 => writes[fi].push(v),
                        Op::Load => reads[fi].push(v),
                        // A copy, a call given its address, an atomic: may
                        // do either.
                        _ => {
                            reads[fi].push(v);
                            writes[fi].push(v);
                        }
                    }
                }
            }
        }
        // What the callees touch, to a fixpoint (SPIR-V has no recursion,
        // but a malformed module may).
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds <= n {
            changed = false;
            rounds += 1;
            for fi in 0..n {
                for &c in &calls[fi] {
                    if c == fi {
                        continue;
                    }
                    for set in [&mut reads, &mut writes] {
                        let more: Vec<Id> = set[c]
                            .iter()
                            .copied()
                            .filter(|v| !set[fi].contains(v))
                            .collect();
                        if !more.is_empty() {
                            set[fi].extend(more);
                            changed = true;
                        }
                    }
                }
            }
        }
        // Whole writes through calls in the first block, to a fixpoint.
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds <= n {
            changed = false;
            rounds += 1;
            for fi in 0..n {
                for &c in &first_calls[fi] {
                    if c == fi {
                        continue;
                    }
                    let more: Vec<Id> = must[c]
                        .iter()
                        .copied()
                        .filter(|v| !must[fi].contains(v))
                        .collect();
                    if !more.is_empty() {
                        must[fi].extend(more);
                        changed = true;
                    }
                }
            }
        }
        for set in reads
            .iter_mut()
            .chain(writes.iter_mut())
            .chain(must.iter_mut())
        {
            set.sort_unstable();
            set.dedup();
        }
        let mut constant: Vec<Id> = stored
            .into_iter()
            .filter_map(|(v, c)| c.map(|_| v))
            .collect();
        constant.sort_unstable();
        PrivateUse {
            reads,
            writes,
            must,
            all,
            constant,
        }
    }

    /// Whether `var` only ever holds one constant once written.
    pub fn is_constant(&self, var: Id) -> bool {
        self.constant.binary_search(&var).is_ok()
    }

    /// Whether function `fi` (or a callee) may read `var`.
    pub fn reads(&self, fi: usize, var: Id) -> bool {
        self.reads
            .get(fi)
            .is_some_and(|s| s.binary_search(&var).is_ok())
    }

    /// Whether function `fi` (or a callee) may write `var`.
    pub fn writes(&self, fi: usize, var: Id) -> bool {
        self.writes
            .get(fi)
            .is_some_and(|s| s.binary_search(&var).is_ok())
    }

    /// Whether `id` is a `Private` variable.
    pub fn is_private(&self, id: Id) -> bool {
        self.all.binary_search(&id).is_ok()
    }
}
