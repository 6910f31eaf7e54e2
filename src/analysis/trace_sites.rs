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
    // Every instruction marked once per Program: asked per trace and per
    // call on each of its chains, the loops were found again each time.
    struct InLoop(Vec<bool>);
    let marks = program.memo.get_or(|| {
        let mut marks = vec![false; program.insts.len()];
        for f in &program.functions {
            for (_, body) in natural_loops(f) {
                for &b in &body {
                    if let Some(block) = f.blocks.get(b) {
                        marks[block.start..=block.end].fill(true);
                    }
                }
            }
        }
        InLoop(marks)
    });
    marks.0.get(inst).copied().unwrap_or(false)
}

/// The traces (`OpTraceRayKHR`) each ray-tracing entry point reaches,
/// computed once per Program (two rules ask).
pub fn reached_traces(program: &Program) -> std::sync::Arc<Vec<ReachedTrace>> {
    struct Reached(std::sync::Arc<Vec<ReachedTrace>>);
    program
        .memo
        .get_or(|| Reached(std::sync::Arc::new(find_reached_traces(program))))
        .0
        .clone()
}

fn find_reached_traces(program: &Program) -> Vec<ReachedTrace> {
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

/// Whether value `id` (in the context of `chain`) is computed from a load of
/// a ray payload: followed through operands, locals (every value stored into
/// a function-local variable the value is loaded from) and parameters.
/// What a bounce loop's next ray looks like: its origin or direction comes
/// from the previous trace's payload.
pub fn depends_on_payload(program: &Program, id: crate::program::Id, chain: &[usize]) -> bool {
    use rspirv::dr::Operand;
    use spirv::{Op, StorageClass};
    /// How many values the search visits at most.
    const LIMIT: usize = 2000;
    let storage_of = |ptr: crate::program::Id| -> Option<StorageClass> {
        let d = program.def(ptr)?;
        match program.ty(d.result_type?) {
            Some(crate::program::Type::Pointer { storage, .. }) => Some(*storage),
            _ => None,
        }
    };
    // The variable an access chain starts from.
    let root = |mut ptr: crate::program::Id| -> crate::program::Id {
        for _ in 0..32 {
            match program.def(ptr) {
                Some(d)
                    if matches!(
                        d.class.opcode,
                        Op::AccessChain | Op::InBoundsAccessChain | Op::CopyObject
                    ) =>
                {
                    match d.operands.first() {
                        Some(Operand::IdRef(b)) => ptr = *b,
                        _ => break,
                    }
                }
                _ => break,
            }
        }
        ptr
    };
    // Every store's value by the variable its pointer starts from, in the
    // module's order: found once per Program, not by a scan of every
    // instruction per local the search loads (quadratic in a module).
    struct StoresByRoot(crate::program::FastMap<crate::program::Id, Vec<crate::program::Id>>);
    let mut stores: Option<std::sync::Arc<StoresByRoot>> = None;
    let mut seen: std::collections::HashSet<(crate::program::Id, usize)> = Default::default();
    let mut work: Vec<(crate::program::Id, usize)> = vec![(id, chain.len())];
    while let Some((v, depth)) = work.pop() {
        if seen.len() > LIMIT || !seen.insert((v, depth)) {
            continue;
        }
        let Some(inst) = program.def(v) else { continue };
        match inst.class.opcode {
            Op::Load => {
                let Some(Operand::IdRef(ptr)) = inst.operands.first() else {
                    continue;
                };
                if matches!(
                    storage_of(*ptr),
                    Some(StorageClass::RayPayloadKHR | StorageClass::IncomingRayPayloadKHR)
                ) {
                    return true;
                }
                let var = root(*ptr);
                if matches!(
                    storage_of(var),
                    Some(StorageClass::Function | StorageClass::Private)
                ) {
                    // Every value stored into the local.
                    let stores = stores.get_or_insert_with(|| {
                        program.memo.get_or(|| {
                            let mut by_root = crate::program::FastMap::default();
                            for s in &program.insts {
                                if s.class.opcode != Op::Store {
                                    continue;
                                }
                                if let (Some(Operand::IdRef(p)), Some(Operand::IdRef(val))) =
                                    (s.operands.first(), s.operands.get(1))
                                {
                                    by_root.entry(root(*p)).or_insert_with(Vec::new).push(*val);
                                }
                            }
                            StoresByRoot(by_root)
                        })
                    });
                    if let Some(vals) = stores.0.get(&var) {
                        work.extend(vals.iter().map(|&val| (val, depth)));
                    }
                }
            }
            Op::FunctionParameter => {
                // The argument the chain's call passes.
                let Some(f) = program
                    .function_of(*program.defs.get(&v).unwrap_or(&0))
                    .and_then(|i| program.functions.get(i))
                else {
                    continue;
                };
                let Some(k) = f.params.iter().position(|&p| p == v) else {
                    continue;
                };
                let Some(at) = chain[..depth.min(chain.len())].iter().rposition(|&c| {
                    matches!(program.insts[c].operands.first(), Some(Operand::IdRef(x)) if *x == f.id)
                }) else {
                    continue;
                };
                if let Some(Operand::IdRef(arg)) = program.insts[chain[at]].operands.get(1 + k) {
                    work.push((*arg, at));
                }
            }
            Op::Variable | Op::Constant | Op::ConstantComposite | Op::FunctionCall => {}
            _ => {
                for o in &inst.operands {
                    if let Operand::IdRef(x) = o {
                        work.push((*x, depth));
                    }
                }
            }
        }
    }
    false
}

/// Whether trace instruction `inst`, reached from entry function `entry`
/// through `chain`, is a bounce: it runs in a loop, and its origin or
/// direction comes from a ray payload (not a loop over samples).
pub fn is_bounce(program: &Program, inst: usize, chain: &[usize], in_loop: bool) -> bool {
    use rspirv::dr::Operand;
    in_loop
        && [6, 8].iter().any(
            |&k| match program.insts.get(inst).and_then(|i| i.operands.get(k)) {
                Some(Operand::IdRef(x)) => depends_on_payload(program, *x, chain),
                _ => false,
            },
        )
}

/// [`is_bounce`] over every call chain from entry function `entry`.
pub fn is_bounce_from(program: &Program, entry: crate::program::Id, inst: usize) -> bool {
    let Some(f) = program
        .function_of(inst)
        .and_then(|i| program.functions.get(i))
    else {
        return false;
    };
    call_chains(program, entry, f.id, MAX_CHAINS)
        .iter()
        .any(|chain| {
            let in_loop =
                inst_in_loop(program, inst) || chain.iter().any(|&c| inst_in_loop(program, c));
            is_bounce(program, inst, chain, in_loop)
        })
}
