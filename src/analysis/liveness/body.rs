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
    /// Its id operands: `ids[from..from + len]` (an instruction has
    /// fewer than 2^16 words).
    from: u32,
    len: u16,
    /// Debug info (an `OpExtInst` of a set without semantics): it
    /// neither reads nor writes.
    debug: bool,
}

impl Body {
    /// An empty body for `f` (its instructions added by [`Body::push`] in
    /// order, then [`Body::finish`]), with its id range worked out first:
    /// the tables by id are made before the walk that decodes and
    /// classifies each instruction fills them.
    pub fn begin(program: &Program, f: &Function) -> Body {
        let n = f.end + 1 - f.start;
        let (mut lo, mut hi) = (Id::MAX, 0);
        for inst in &program.insts[f.start..=f.end] {
            let Some(r) = inst.result_id else { continue };
            let op = inst.class.opcode;
            if !matches!(op, Op::Function | Op::FunctionParameter) && !is_debug(program, inst) {
                lo = lo.min(r);
                hi = hi.max(r);
            }
        }
        Body {
            start: f.start,
            rows: Vec::with_capacity(n),
            // At most about three id operands an instruction.
            ids: Vec::with_capacity(3 * n),
            kept: Vec::with_capacity(n),
            block_kept: Vec::new(),
            lo,
            hi,
        }
    }

    /// Decodes instruction `i` (the next one). For one the passes read,
    /// its opcode, result and where its id operands start (see
    /// [`Body::ids_from`]), handed back so the walk that decodes reads
    /// them from here.
    #[inline]
    pub fn push(&mut self, program: &Program, i: usize) -> Option<(Op, Option<Id>, usize)> {
        let inst = &program.insts[i];
        let op = inst.class.opcode;
        let debug = is_debug(program, inst);
        let from = self.ids.len();
        // Debug info and positions are read by no pass: no operands kept.
        let kept = !debug && !matches!(op, Op::Line | Op::NoLine);
        if kept {
            self.kept.push(i as u32);
            for o in &inst.operands {
                if let Operand::IdRef(x) = o {
                    self.ids.push(*x);
                }
            }
        }
        self.rows.push(Row {
            op,
            result: inst.result_id.unwrap_or(0),
            from: from as u32,
            len: (self.ids.len() - from) as u16,
            debug,
        });
        kept.then_some((op, inst.result_id.filter(|&r| r != 0), from))
    }

    /// The id operands from `from` on: the last instruction pushed's.
    #[inline]
    pub fn ids_from(&self, from: usize) -> &[Id] {
        &self.ids[from..]
    }

    /// Ends the body of `f` once every instruction is pushed.
    pub fn finish(&mut self, f: &Function) {
        let kept = &self.kept;
        self.block_kept = f
            .blocks
            .iter()
            .map(|block| {
                let from = kept.partition_point(|&i| (i as usize) < block.start);
                let to = kept.partition_point(|&i| (i as usize) <= block.end);
                (from as u32, to.max(from) as u32)
            })
            .collect();
    }

    /// Those of `kept` in block `b` of `f`, from a sorted list of them.
    pub fn in_block<'a>(list: &'a [u32], f: &Function, b: usize) -> &'a [u32] {
        let block = &f.blocks[b];
        let from = list.partition_point(|&i| (i as usize) < block.start);
        let to = list.partition_point(|&i| (i as usize) <= block.end);
        &list[from..to.max(from)]
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
        let row = &self.rows[i - self.start];
        let from = row.from as usize;
        &self.ids[from..from + row.len as usize]
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

/// Debug info: an `OpExtInst` of a set without semantics.
#[inline]
fn is_debug(program: &Program, inst: &rspirv::dr::Instruction) -> bool {
    inst.class.opcode == Op::ExtInst
        && matches!(inst.operands.first(),
            Some(Operand::IdRef(x)) if program.debug_sets.contains(x))
}
