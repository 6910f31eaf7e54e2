//! One function's instructions as the liveness reads them, decoded once.
//!
//! Every pass of the liveness (roots, copies, use counts, calls, steps,
//! mentions, the fixpoint, the values across a site, recomputability)
//! reads an instruction's opcode, result and id operands many times;
//! rspirv keeps each instruction's operands in a vector of its own, as
//! enums, and the debug-info test looks at them again each time. Here they
//! are flat arrays filled in one walk over the function.

use crate::program::{Function, Id, Program};
use rspirv::dr::Operand;
use spirv::Op;

/// The instructions `start..start + len` of one function.
pub(super) struct Body {
    start: usize,
    op: Vec<Op>,
    /// Result id, 0 for none (SPIR-V ids start at 1).
    result: Vec<Id>,
    /// Where each instruction's id operands start in `ids` (one more
    /// entry than instructions).
    at: Vec<u32>,
    ids: Vec<Id>,
    /// Debug-info instructions (an `OpExtInst` of a set without
    /// semantics): they neither read nor write.
    debug: Vec<bool>,
    /// The instructions every pass reads, in order: not debug info, and
    /// no `OpLine`/`OpNoLine` (which neither read nor write, and are
    /// about a fifth of a function compiled with positions).
    kept: Vec<u32>,
    /// Each block's instructions in `kept`: `kept[block_kept[b].0..block_kept[b].1]`.
    block_kept: Vec<(u32, u32)>,
    /// The lowest and highest result id of the body proper (not the
    /// function's, its parameters' or debug info's).
    pub lo: Id,
    pub hi: Id,
}

impl Body {
    pub fn new(program: &Program, f: &Function) -> Body {
        let n = f.end + 1 - f.start;
        let mut b = Body {
            start: f.start,
            op: Vec::with_capacity(n),
            result: Vec::with_capacity(n),
            at: Vec::with_capacity(n + 1),
            // At most about three id operands an instruction.
            ids: Vec::with_capacity(3 * n),
            debug: Vec::with_capacity(n),
            kept: Vec::with_capacity(n),
            block_kept: Vec::with_capacity(f.blocks.len()),
            lo: Id::MAX,
            hi: 0,
        };
        for inst in &program.insts[f.start..=f.end] {
            let op = inst.class.opcode;
            b.at.push(b.ids.len() as u32);
            let debug = op == Op::ExtInst
                && matches!(inst.operands.first(),
                    Some(Operand::IdRef(x)) if program.debug_sets.contains(x));
            let r = inst.result_id.unwrap_or(0);
            // Debug info and positions are read by no pass: no operands kept.
            if !debug && !matches!(op, Op::Line | Op::NoLine) {
                b.kept.push((b.start + b.op.len()) as u32);
                for o in &inst.operands {
                    if let Operand::IdRef(x) = o {
                        b.ids.push(*x);
                    }
                }
            }
            if r != 0 && !debug && !matches!(op, Op::Function | Op::FunctionParameter) {
                b.lo = b.lo.min(r);
                b.hi = b.hi.max(r);
            }
            b.op.push(op);
            b.result.push(r);
            b.debug.push(debug);
        }
        b.at.push(b.ids.len() as u32);
        for block in &f.blocks {
            let from = b.kept.partition_point(|&i| (i as usize) < block.start);
            let to = b.kept.partition_point(|&i| (i as usize) <= block.end);
            b.block_kept.push((from as u32, to.max(from) as u32));
        }
        b
    }

    /// The instructions the passes read (see `kept`), by index.
    pub fn kept(&self) -> &[u32] {
        &self.kept
    }

    /// Those of block `b`.
    pub fn block(&self, b: usize) -> &[u32] {
        let (from, to) = self.block_kept[b];
        &self.kept[from as usize..to as usize]
    }

    /// Those of block `b` after instruction `inst` (which is in it).
    pub fn block_after(&self, b: usize, inst: usize) -> &[u32] {
        let all = self.block(b);
        &all[all.partition_point(|&i| i as usize <= inst)..]
    }

    /// The index of the first instruction.
    pub fn start(&self) -> usize {
        self.start
    }

    #[inline]
    pub fn op(&self, i: usize) -> Op {
        self.op[i - self.start]
    }

    #[inline]
    pub fn result(&self, i: usize) -> Option<Id> {
        Some(self.result[i - self.start]).filter(|&r| r != 0)
    }

    /// The id operands of instruction `i`, in order (none kept for debug
    /// info and `OpLine`/`OpNoLine`).
    #[inline]
    pub fn ids(&self, i: usize) -> &[Id] {
        let k = i - self.start;
        &self.ids[self.at[k] as usize..self.at[k + 1] as usize]
    }

    #[inline]
    pub fn debug(&self, i: usize) -> bool {
        self.debug[i - self.start]
    }

    /// The first id operand of instruction `i`.
    #[inline]
    pub fn first(&self, i: usize) -> Option<Id> {
        self.ids(i).first().copied()
    }
}
