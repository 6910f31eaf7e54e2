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
    /// Each instruction's opcode, result and id operands, side by side
    /// (one push an instruction while decoding, one cache line to read).
    /// (One more row than instructions: the last one only ends the
    /// last instruction's operands.)
    rows: Vec<Row>,
    ids: Vec<Id>,
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

/// One instruction.
#[derive(Clone, Copy)]
struct Row {
    op: Op,
    /// Result id, 0 for none (SPIR-V ids start at 1).
    result: Id,
    /// Where its id operands start in `ids` (they end where the next
    /// instruction's start).
    from: u32,
    /// Debug info (an `OpExtInst` of a set without semantics): it
    /// neither reads nor writes.
    debug: bool,
}

impl Body {
    pub fn new(program: &Program, f: &Function) -> Body {
        let n = f.end + 1 - f.start;
        let mut rows = Vec::with_capacity(n + 1);
        // At most about three id operands an instruction.
        let mut ids = Vec::with_capacity(3 * n);
        let mut kept = Vec::with_capacity(n);
        let (mut lo, mut hi) = (Id::MAX, 0);
        for (k, inst) in program.insts[f.start..=f.end].iter().enumerate() {
            let op = inst.class.opcode;
            let from = ids.len() as u32;
            let r = inst.result_id.unwrap_or(0);
            let debug = op == Op::ExtInst
                && matches!(inst.operands.first(),
                    Some(Operand::IdRef(x)) if program.debug_sets.contains(x));
            // Debug info and positions are read by no pass: no operands kept.
            if !debug && !matches!(op, Op::Line | Op::NoLine) {
                kept.push((f.start + k) as u32);
                for o in &inst.operands {
                    if let Operand::IdRef(x) = o {
                        ids.push(*x);
                    }
                }
                if r != 0 && !matches!(op, Op::Function | Op::FunctionParameter) {
                    lo = lo.min(r);
                    hi = hi.max(r);
                }
            }
            rows.push(Row {
                op,
                result: r,
                from,
                debug,
            });
        }
        rows.push(Row {
            op: Op::Nop,
            result: 0,
            from: ids.len() as u32,
            debug: false,
        });
        let mut block_kept = Vec::with_capacity(f.blocks.len());
        for block in &f.blocks {
            let from = kept.partition_point(|&i| (i as usize) < block.start);
            let to = kept.partition_point(|&i| (i as usize) <= block.end);
            block_kept.push((from as u32, to.max(from) as u32));
        }
        Body {
            start: f.start,
            rows,
            ids,
            kept,
            block_kept,
            lo,
            hi,
        }
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
        self.rows[i - self.start].op
    }

    #[inline]
    pub fn result(&self, i: usize) -> Option<Id> {
        Some(self.rows[i - self.start].result).filter(|&r| r != 0)
    }

    /// The id operands of instruction `i`, in order (none kept for debug
    /// info and `OpLine`/`OpNoLine`).
    #[inline]
    pub fn ids(&self, i: usize) -> &[Id] {
        let k = i - self.start;
        &self.ids[self.rows[k].from as usize..self.rows[k + 1].from as usize]
    }

    #[inline]
    pub fn debug(&self, i: usize) -> bool {
        self.rows[i - self.start].debug
    }

    /// The first id operand of instruction `i`.
    #[inline]
    pub fn first(&self, i: usize) -> Option<Id> {
        self.ids(i).first().copied()
    }
}
