//! Every trace an entry point reaches, per call chain: its operands folded
//! for that chain, and whether it runs inside a loop (a bounce loop).

use crate::program::cfg::{call_chains, natural_loops};
use crate::program::{Program, SiteKind, TraceOperands};
use crate::shader::Stage;

/// How many call chains are followed per entry point and site.
const MAX_CHAINS: usize = 16;

/// One trace as one entry point reaches it.
#[derive(Clone, Debug)]
pub struct ReachedTrace {
    /// Index into [`Program::entry_points`].
    pub entry: usize,
    pub stage: Stage,
    /// Index into [`Program::sites`].
    pub site: usize,
    /// `OpFunctionCall` indices from the entry point, outermost first.
    pub chain: Vec<usize>,
    pub operands: TraceOperands,
    /// The trace, or a call on its chain, sits in a loop.
    pub in_loop: bool,
}

/// Whether instruction `inst` sits in a natural loop of its function.
pub fn inst_in_loop(program: &Program, inst: usize) -> bool {
    let Some(f) = program
        .function_of(inst)
        .and_then(|i| program.functions.get(i))
    else {
        return false;
    };
    let Some(b) = f.block_of(inst) else {
        return false;
    };
    natural_loops(f).iter().any(|(_, body)| body.contains(&b))
}

/// Whether instruction `inst`, reached from entry function `entry`, runs in
/// a loop: it sits in one, or a call on some chain from the entry to it does.
pub fn in_loop_from(program: &Program, entry: crate::program::Id, inst: usize) -> bool {
    if inst_in_loop(program, inst) {
        return true;
    }
    let Some(f) = program
        .function_of(inst)
        .and_then(|i| program.functions.get(i))
    else {
        return false;
    };
    call_chains(program, entry, f.id, MAX_CHAINS)
        .iter()
        .any(|chain| chain.iter().any(|&c| inst_in_loop(program, c)))
}

/// The traces (`OpTraceRayKHR`) each ray-tracing entry point reaches.
pub fn reached_traces(program: &Program) -> Vec<ReachedTrace> {
    let mut out = Vec::new();
    for (e, entry) in program.entry_points.iter().enumerate() {
        if !entry.stage.is_ray_tracing() {
            continue;
        }
        for (s, site) in program.sites.iter().enumerate() {
            if site.kind != SiteKind::TraceRay {
                continue;
            }
            let Some(f) = program.functions.get(site.function) else {
                continue;
            };
            for chain in call_chains(program, entry.function, f.id, MAX_CHAINS) {
                let Some(operands) = program.trace_operands_in(site, &chain) else {
                    continue;
                };
                let in_loop = inst_in_loop(program, site.inst)
                    || chain.iter().any(|&c| inst_in_loop(program, c));
                out.push(ReachedTrace {
                    entry: e,
                    stage: entry.stage,
                    site: s,
                    chain,
                    operands,
                    in_loop,
                });
            }
        }
    }
    out
}
