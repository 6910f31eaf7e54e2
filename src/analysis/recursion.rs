//! Recursion depth of a pipeline, cycle bounds from depth guards, and loops
//! that trace rays.
//!
//! Ray generation runs at level 0; a trace from a shader at level L invokes
//! its targets at L + 1, and `maxPipelineRayRecursionDepth` must cover the
//! deepest level. A cycle in the trace graph (a closest-hit shader that can
//! reach itself) is bounded only when each trace on it is dominated by a
//! comparison of a depth counter carried in the payload against a constant
//! (or a push / specialization constant the description gives), and the
//! counter grows along the cycle.

use super::callgraph::{trace_graph, EdgeKind, TraceGraph};
use crate::diag::Location;
use crate::pipeline::{DescribedConstant, Pipeline};
use crate::program::cfg::{
    call_chains, components, dominates, dominators, function_cfgs, natural_loops,
};
use crate::program::{Constant, Function, Id, Program, Type};
use crate::shader::Stage;
use rspirv::dr::{Instruction, Operand};
use rustc_hash::{FxHashMap, FxHashSet};
use spirv::{Op, StorageClass};
use std::collections::{BTreeMap, HashSet};

/// Where a loop or recursion bound comes from.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum BoundSource {
    Constant(i64),
    /// A specialization constant: its value in the pipeline description, else
    /// its default.
    SpecConstant {
        name: String,
        value: i64,
        described: bool,
    },
    /// A push-constant, uniform, storage-buffer or shader-record value that
    /// the pipeline description gives.
    Described {
        kind: ValueKind,
        key: String,
        value: i64,
    },
}

/// Where a value that is not a constant is read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum ValueKind {
    PushConstant,
    Uniform,
    StorageBuffer,
    ShaderRecord,
}

/// Why a bound is not known at compile time.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum UnknownBound {
    /// An id the module does not define.
    UnknownValue,
    RuntimeValue,
    /// A value the pipeline description could give but does not.
    NotDescribed {
        kind: ValueKind,
        name: String,
    },
}

/// Why no depth guard was recognised on a trace that closes a cycle.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum NoGuard {
    ModuleMissing,
    TraceMissing,
    OutsideFunction,
    /// The counter is compared with a bound that is not known.
    BoundUnknown {
        counter: String,
        bound: UnknownBound,
    },
    /// The counter guards the trace but the traced copy does not grow.
    CounterDoesNotGrow {
        counter: String,
    },
    /// No dominating comparison of a counter (named when one was seen) with a
    /// known bound.
    NoComparison {
        counter: Option<String>,
    },
}

/// Why no bound was recognised on a loop that traces.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NoLoopBound {
    NotIncremented {
        counter: String,
    },
    BoundUnknown {
        counter: String,
        bound: UnknownBound,
    },
    NoCounter,
}

/// A recognised depth guard on a trace that closes a cycle.
#[derive(Clone, Debug)]
pub struct Guard {
    /// `payload.depth`-style name of the counter.
    pub counter: String,
    /// `<` or `<=`: the trace happens while `counter op bound`.
    pub op: &'static str,
    pub bound: i64,
    /// Where the bound comes from.
    pub bound_source: BoundSource,
    /// How much the counter grows per trace.
    pub step: i64,
    /// The counter's value where the cycle is entered.
    pub initial: i64,
    /// True when no constant initial store was found and 0 was assumed.
    pub initial_assumed: bool,
    /// How many times the cycle can trace in one chain.
    pub traces: u64,
    pub location: Option<Location>,
    /// The incoming payload variable and member path of the counter.
    pub key: (Id, Vec<u64>),
}

/// One trace site that closes a cycle.
#[derive(Clone, Debug)]
pub struct CycleSite {
    pub program: usize,
    pub inst: usize,
    pub location: Option<Location>,
    /// The guard, or why none was recognised.
    pub guard: Result<Guard, NoGuard>,
}

/// A strongly connected part of the trace graph with a cycle.
#[derive(Clone, Debug)]
pub struct Cycle {
    pub nodes: Vec<usize>,
    pub sites: Vec<CycleSite>,
    /// Extra levels the cycle adds; `None` when unbounded at compile time.
    pub extra_levels: Option<u64>,
}

#[derive(Clone, Debug)]
pub struct ChainStep {
    pub node: usize,
    /// The level the node is entered at.
    pub level: u32,
    /// Further levels reached by a bounded cycle through this node.
    pub repeat: u64,
    /// No level bounds this step: it is on an unbounded cycle, or reached
    /// from one (then `level` means nothing).
    pub unbounded: bool,
    /// The trace that invoked it.
    pub via: Option<Location>,
}

/// A trace from a closest-hit or miss shader.
#[derive(Clone, Debug)]
pub struct RecursiveSite {
    pub node: usize,
    pub program: usize,
    pub inst: usize,
    pub location: Option<Location>,
}

#[derive(Clone, Debug)]
pub struct RecursionReport {
    pub graph: TraceGraph,
    /// Required `maxPipelineRayRecursionDepth`; `None` when unbounded.
    pub required_depth: Option<u32>,
    pub declared_depth: Option<u32>,
    pub device_limit: u32,
    /// The chain that needs the required depth.
    pub chain: Vec<ChainStep>,
    pub cycles: Vec<Cycle>,
    /// Deepest level each node runs at (`None`: unreached or unbounded).
    pub node_level: Vec<Option<u32>>,
    pub recursive_sites: Vec<RecursiveSite>,
}

impl RecursionReport {
    pub fn unbounded_cycle(&self) -> Option<&Cycle> {
        self.cycles.iter().find(|c| c.extra_levels.is_none())
    }
}

/// Depth analysis of a pipeline.
pub fn recursion_report(pipeline: &Pipeline) -> RecursionReport {
    let graph = trace_graph(pipeline);
    let n = graph.nodes.len();
    // Each node's successors once, in first-seen order, without a scan per
    // edge (a folder's loose pipeline joins every trace to every hit
    // shader): sorted with each pair's first position, duplicates dropped,
    // then back in order per node.
    let mut adj: Vec<(usize, usize, usize)> = graph
        .traces()
        .enumerate()
        .map(|(k, e)| (e.from, e.to, k))
        .collect();
    adj.sort_unstable();
    adj.dedup_by_key(|&mut (from, to, _)| (from, to));
    adj.sort_unstable_by_key(|&(from, _, k)| (from, k));
    let adj: Vec<(usize, usize)> = adj.into_iter().map(|(from, to, _)| (from, to)).collect();
    let sccs = components(n, &adj);
    let mut scc_of = vec![0usize; n];
    for c in 0..sccs.len() {
        for &v in sccs.get(c) {
            scc_of[v] = c;
        }
    }
    // Each component's traces, in the graph's order (with their index
    // among the traces): those inside it, and those entering it. One pass,
    // not a scan of every trace per component (a folder's loose pipeline
    // has hundreds of components and tens of thousands of traces).
    let traces: Vec<_> = graph.traces().collect();
    let mut inside: Vec<Vec<usize>> = vec![Vec::new(); sccs.len()];
    let mut entering: Vec<Vec<usize>> = vec![Vec::new(); sccs.len()];
    for (k, e) in traces.iter().enumerate() {
        let (from, to) = (scc_of[e.from], scc_of[e.to]);
        if from == to {
            inside[to].push(k);
        } else {
            entering[to].push(k);
        }
    }
    // Cycles and their bounds.
    let mut extra: Vec<Option<u64>> = vec![Some(0); sccs.len()];
    let mut cycles = Vec::new();
    for (c, extra) in extra.iter_mut().enumerate() {
        let nodes = sccs.get(c);
        if inside[c].is_empty() {
            continue;
        }
        let mut sites: Vec<CycleSite> = Vec::new();
        for e in inside[c].iter().map(|&k| traces[k]) {
            if sites
                .iter()
                .any(|s| s.program == e.program && s.inst == e.inst)
            {
                continue;
            }
            let guard = recognise_guard(pipeline, &graph, &scc_of, c, e.from, e.inst);
            sites.push(CycleSite {
                program: e.program,
                inst: e.inst,
                location: e.location.clone(),
                guard,
            });
        }
        let bound = if sites.iter().all(|s| s.guard.is_ok()) {
            // Sites sharing a counter share its budget; distinct counters add.
            let mut per_counter: BTreeMap<&str, u64> = BTreeMap::new();
            for g in sites.iter().filter_map(|s| s.guard.as_ref().ok()) {
                let e = per_counter.entry(&g.counter).or_default();
                *e = (*e).max(g.traces);
            }
            Some(per_counter.values().sum())
        } else {
            None
        };
        *extra = bound;
        cycles.push(Cycle {
            nodes: nodes.to_vec(),
            sites,
            extra_levels: bound,
        });
    }
    // Levels in topological order (Tarjan yields sinks first).
    #[derive(Clone, Copy)]
    enum Lv {
        Unreached,
        At(u64),
        Unbounded,
    }
    // A trace leaving a bounded cycle that the cycle's one counter guards
    // too runs only from the levels the guard allows (once per site).
    let exit_of = |e: &super::callgraph::Edge| -> Option<u64> {
        let cy = cycles.iter().find(|cy| cy.nodes.contains(&e.from))?;
        let guards: Vec<&Guard> = cy
            .sites
            .iter()
            .filter_map(|s| s.guard.as_ref().ok())
            .collect();
        let g = guards.iter().max_by_key(|g| g.traces)?;
        if guards.len() != cy.sites.len()
            || guards
                .iter()
                .any(|o| o.key != g.key || o.step != g.step || o.initial != g.initial)
        {
            return None;
        }
        exit_levels(pipeline, &graph, e.from, e.inst, g)
    };
    let mut exit_memo: FxHashMap<(usize, usize), Option<u64>> = FxHashMap::default();
    let mut entry = vec![Lv::Unreached; sccs.len()];
    let mut pred: Vec<Option<(usize, usize)>> = vec![None; sccs.len()];
    for c in (0..sccs.len()).rev() {
        if sccs
            .get(c)
            .iter()
            .any(|&v| graph.nodes[v].shader.stage == Stage::RayGeneration)
        {
            entry[c] = Lv::At(0);
        }
        for &k in &entering[c] {
            let e = traces[k];
            let from = scc_of[e.from];
            // A guarded trace that closes the cycle stops tracing at the
            // cycle's last level; other traces (shadow rays) leave from it.
            let closes_cycle = cycles.iter().any(|cy: &Cycle| {
                cy.nodes.contains(&e.from)
                    && cy
                        .sites
                        .iter()
                        .any(|s| s.program == e.program && s.inst == e.inst)
            });
            // A trace leaving a bounded cycle that the cycle's one counter
            // guards too runs only from the levels the guard allows.
            let mut guarded_exit = || {
                if let Some(&k) = exit_memo.get(&(e.from, e.inst)) {
                    return k;
                }
                let k = exit_of(e);
                exit_memo.insert((e.from, e.inst), k);
                k
            };
            let top = match (entry[from], extra[from]) {
                (Lv::At(_), Some(0)) if closes_cycle => Lv::Unreached,
                (Lv::At(l), Some(x)) if closes_cycle => Lv::At(l + x),
                (Lv::At(l), Some(x)) => match guarded_exit() {
                    Some(0) => Lv::Unreached,
                    Some(k) => Lv::At(l + k.min(x + 1)),
                    None => Lv::At(l + x + 1),
                },
                (Lv::Unreached, _) => Lv::Unreached,
                _ => Lv::Unbounded,
            };
            match (entry[c], top) {
                (_, Lv::Unreached) | (Lv::Unbounded, _) => {}
                (_, Lv::Unbounded) => {
                    entry[c] = Lv::Unbounded;
                    pred[c] = Some((k, from));
                }
                (Lv::Unreached, Lv::At(t)) => {
                    entry[c] = Lv::At(t);
                    pred[c] = Some((k, from));
                }
                (Lv::At(l), Lv::At(t)) => {
                    if t > l {
                        entry[c] = Lv::At(t);
                        pred[c] = Some((k, from));
                    }
                }
            }
        }
    }
    let top_of = |c: usize| match (entry[c], extra[c]) {
        (Lv::At(l), Some(x)) => Lv::At(l + x),
        (Lv::Unreached, _) => Lv::Unreached,
        _ => Lv::Unbounded,
    };
    let node_level: Vec<Option<u32>> = (0..n)
        .map(|v| match top_of(scc_of[v]) {
            Lv::At(l) => u32::try_from(l).ok(),
            _ => None,
        })
        .collect();
    let mut required = Some(0u64);
    let mut deepest: Option<usize> = None;
    for c in 0..sccs.len() {
        match top_of(c) {
            Lv::Unbounded => {
                required = None;
                deepest = Some(c);
                break;
            }
            Lv::At(l) => {
                if required.is_some_and(|r| l > r) || deepest.is_none() {
                    required = Some(l.max(required.unwrap_or(0)));
                    deepest = Some(c);
                }
            }
            Lv::Unreached => {}
        }
    }
    // The chain, back from the deepest part.
    let mut chain = Vec::new();
    let mut cur = deepest;
    let traces: Vec<_> = graph.traces().collect();
    let mut guard_steps = 0;
    while let Some(c) = cur {
        guard_steps += 1;
        if guard_steps > sccs.len() + 1 {
            break;
        }
        let (node, via) = match pred[c] {
            Some((k, _)) => (traces[k].to, traces[k].location.clone()),
            None => (sccs.get(c)[0], None),
        };
        let (level, unbounded) = match (entry[c], extra[c]) {
            (Lv::At(l), Some(_)) => (l as u32, false),
            // Entered at a known level, but the cycle through it has no bound.
            (Lv::At(l), None) => (l as u32, true),
            _ => (0, true),
        };
        chain.push(ChainStep {
            node,
            level,
            repeat: extra[c].unwrap_or(0),
            unbounded,
            via,
        });
        cur = pred[c].map(|(_, from)| from);
    }
    chain.reverse();
    let mut recursive_sites: Vec<RecursiveSite> = Vec::new();
    let mut listed = FxHashSet::default();
    for e in graph.traces() {
        let stage = graph.nodes[e.from].shader.stage;
        if matches!(stage, Stage::ClosestHit | Stage::Miss) && listed.insert((e.program, e.inst)) {
            recursive_sites.push(RecursiveSite {
                node: e.from,
                program: e.program,
                inst: e.inst,
                location: e.location.clone(),
            });
        }
    }
    RecursionReport {
        required_depth: required.and_then(|r| u32::try_from(r).ok()),
        declared_depth: pipeline.max_recursion_depth,
        device_limit: pipeline.device_max_recursion_depth,
        graph,
        chain,
        cycles,
        node_level,
        recursive_sites,
    }
}

// ---------------------------------------------------------------------------
// Values: counters, bounds, conditions.

fn ids(inst: &Instruction) -> impl Iterator<Item = Id> + '_ {
    inst.operands.iter().filter_map(|o| match o {
        Operand::IdRef(x) => Some(*x),
        _ => None,
    })
}

/// What a depth or loop counter is.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Counter {
    /// A member path of the incoming payload.
    Payload { var: Id, path: Vec<u64> },
    /// A variable (local, private, or the payload a shader traces) or a
    /// member of one.
    Var { var: Id, path: Vec<u64> },
}

fn global(program: &Program, id: Id) -> Option<&crate::program::Global> {
    program.globals.iter().find(|g| g.id == id)
}

/// How far value and pointer resolution follows copies and calls.
const MAX_RESOLVE: u32 = 24;

/// The base variable and constant member path of a pointer: through access
/// chains (indices folded), copies, and function parameters whose every
/// call passes the same place (`inout` parameters, glslang's
/// copy-in/copy-out temporaries).
fn pointer_path(program: &Program, ptr: Id) -> Option<(Id, Vec<u64>)> {
    place_of(program, ptr, 0)
}

fn place_of(program: &Program, ptr: Id, depth: u32) -> Option<(Id, Vec<u64>)> {
    if depth > MAX_RESOLVE {
        return None;
    }
    let inst = program.def(ptr)?;
    match inst.class.opcode {
        Op::Variable => Some((ptr, Vec::new())),
        Op::AccessChain | Op::InBoundsAccessChain => {
            let v: Vec<Id> = ids(inst).collect();
            let (&base, idx) = v.split_first()?;
            let (root, mut path) = place_of(program, base, depth + 1)?;
            for &i in idx {
                path.push(program.fold(i)?);
            }
            Some((root, path))
        }
        Op::CopyObject => place_of(program, ids(inst).next()?, depth + 1),
        Op::FunctionParameter => {
            let fi = program.function_of(*program.defs.get(&ptr)?)?;
            let f = program.functions.get(fi)?;
            let k = f.params.iter().position(|&p| p == ptr)?;
            let mut place = None;
            for call in program.callers(f.id) {
                let arg = ids(&program.insts[call]).nth(1 + k)?;
                let here = place_of(program, arg, depth + 1)?;
                if place.as_ref().is_some_and(|p| *p != here) {
                    return None;
                }
                place = Some(here);
            }
            place
        }
        _ => None,
    }
}

fn is_local(program: &Program, var: Id) -> bool {
    program.def(var).is_some_and(|d| {
        d.class.opcode == Op::Variable
            && matches!(
                d.operands.first(),
                Some(Operand::StorageClass(StorageClass::Function))
            )
    })
}

/// Where a value comes from, as far as copies can be followed.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Source {
    /// Computed: this SSA value.
    Value(Id),
    /// Read from a global variable's member (the incoming payload, a
    /// push constant) at the time of the copy.
    Read(Id, Vec<u64>),
}

/// Every value a place can hold, following whole-struct copies, composite
/// construction and insertion, and local variables (flow-insensitive: every
/// write in the module counts).
fn values_of(program: &Program, place: (Id, Vec<u64>)) -> Vec<Source> {
    let mut out = Vec::new();
    let mut seen = FxHashSet::default();
    stored_values(program, &place, &mut out, &mut seen, 0);
    out
}

fn stored_values(
    program: &Program,
    place: &(Id, Vec<u64>),
    out: &mut Vec<Source>,
    seen: &mut FxHashSet<(Id, Vec<u64>)>,
    depth: u32,
) {
    if depth > MAX_RESOLVE || !seen.insert(place.clone()) {
        return;
    }
    let (var, path) = place;
    if let Some(Operand::IdRef(init)) = program.def(*var).and_then(|d| d.operands.get(1)) {
        component(program, *init, path, out, seen, depth + 1);
    }
    let stores = stores_by_var(program);
    for (dp, src_value, src_ptr) in stores.0.get(var).map_or(&[][..], Vec::as_slice) {
        if !path.starts_with(dp) {
            continue;
        }
        let rest = &path[dp.len()..];
        if let Some(value) = *src_value {
            component(program, value, rest, out, seen, depth + 1);
        } else if let Some((sv, mut sp)) = src_ptr.and_then(|p| place_of(program, p, 0)) {
            sp.extend_from_slice(rest);
            read_place(program, (sv, sp), out, seen, depth + 1);
        }
    }
}

/// Every `OpStore` and `OpCopyMemory` of a program by the variable it
/// writes, in module order: the member path written, and the stored value
/// or the pointer copied from. Listed once per Program (each query for a
/// place's values scanned every instruction).
struct StoresByVar(FxHashMap<Id, Vec<StoreTo>>);

type StoreTo = (Vec<u64>, Option<Id>, Option<Id>);

fn stores_by_var(program: &Program) -> std::sync::Arc<StoresByVar> {
    program.memo.get_or(|| {
        let mut by_var: FxHashMap<Id, Vec<StoreTo>> = FxHashMap::default();
        for inst in &program.insts {
            let (dst, src_value, src_ptr) = match inst.class.opcode {
                Op::Store => {
                    let mut v = ids(inst);
                    match (v.next(), v.next()) {
                        (Some(d), Some(s)) => (d, Some(s), None),
                        _ => continue,
                    }
                }
                Op::CopyMemory | Op::CopyMemorySized => {
                    let mut v = ids(inst);
                    match (v.next(), v.next()) {
                        (Some(d), Some(s)) => (d, None, Some(s)),
                        _ => continue,
                    }
                }
                _ => continue,
            };
            if let Some((dv, dp)) = place_of(program, dst, 0) {
                by_var.entry(dv).or_default().push((dp, src_value, src_ptr));
            }
        }
        StoresByVar(by_var)
    })
}

/// The sources of a load from `place`: a local's stored values, else the
/// read itself.
fn read_place(
    program: &Program,
    place: (Id, Vec<u64>),
    out: &mut Vec<Source>,
    seen: &mut FxHashSet<(Id, Vec<u64>)>,
    depth: u32,
) {
    if is_local(program, place.0) {
        stored_values(program, &place, out, seen, depth + 1);
    } else {
        out.push(Source::Read(place.0, place.1));
    }
}

/// The sources of element `path` of composite value `value`.
fn component(
    program: &Program,
    value: Id,
    path: &[u64],
    out: &mut Vec<Source>,
    seen: &mut FxHashSet<(Id, Vec<u64>)>,
    depth: u32,
) {
    if depth > MAX_RESOLVE {
        return;
    }
    let value = strip_conversions(program, value);
    let Some(inst) = program.def(value) else {
        return;
    };
    let v: Vec<Id> = ids(inst).collect();
    match inst.class.opcode {
        Op::Load => {
            if let Some((var, mut p)) = v.first().and_then(|&ptr| place_of(program, ptr, 0)) {
                p.extend_from_slice(path);
                read_place(program, (var, p), out, seen, depth + 1);
            }
        }
        Op::CompositeConstruct if !path.is_empty() => {
            // Struct and array constructors take one operand per element.
            if let Some(&e) = v.get(path[0] as usize) {
                component(program, e, &path[1..], out, seen, depth + 1);
            }
        }
        Op::CompositeInsert if !path.is_empty() => {
            let lits: Vec<u64> = inst
                .operands
                .iter()
                .filter_map(|o| match o {
                    Operand::LiteralBit32(x) => Some(*x as u64),
                    _ => None,
                })
                .collect();
            if let [obj, composite, ..] = v.as_slice() {
                if path.starts_with(&lits) {
                    component(program, *obj, &path[lits.len()..], out, seen, depth + 1);
                } else if !lits.starts_with(path) {
                    component(program, *composite, path, out, seen, depth + 1);
                }
            }
        }
        Op::CompositeExtract => {
            let mut p: Vec<u64> = inst
                .operands
                .iter()
                .filter_map(|o| match o {
                    Operand::LiteralBit32(x) => Some(*x as u64),
                    _ => None,
                })
                .collect();
            p.extend_from_slice(path);
            if let Some(&c) = v.first() {
                component(program, c, &p, out, seen, depth + 1);
            }
        }
        _ if !path.is_empty() => {
            if let Some(Constant::Composite(parts)) = program.constants.get(&value) {
                if let Some(&e) = parts.get(path[0] as usize) {
                    component(program, e, &path[1..], out, seen, depth + 1);
                }
            } else if program.constants.get(&value) == Some(&Constant::Null) {
                out.push(Source::Value(value));
            }
        }
        _ => out.push(Source::Value(value)),
    }
}

fn strip_conversions(program: &Program, mut id: Id) -> Id {
    for _ in 0..16 {
        match program.def(id) {
            Some(i)
                if matches!(
                    i.class.opcode,
                    Op::Bitcast | Op::UConvert | Op::SConvert | Op::CopyObject
                ) =>
            {
                id = ids(i).next().unwrap_or(id);
            }
            _ => break,
        }
    }
    id
}

/// The counter a value reads: a member of the incoming payload (loaded
/// directly, through a local copy of it or of the whole payload, or through
/// an `inout` parameter), else the variable or member it is loaded from.
fn counter_of(program: &Program, id: Id) -> Option<Counter> {
    let id = strip_conversions(program, id);
    let inst = program.def(id)?;
    if inst.class.opcode != Op::Load {
        return None;
    }
    let ptr = ids(inst).next()?;
    let incoming = |v: Id| {
        global(program, v).is_some_and(|g| g.storage == StorageClass::IncomingRayPayloadKHR)
    };
    if let Some(c) = parameter_counter(program, ptr, &[], &incoming) {
        return Some(c);
    }
    let (var, path) = pointer_path(program, ptr)?;
    if incoming(var) {
        return Some(Counter::Payload { var, path });
    }
    if is_local(program, var) {
        // A local copy of the payload counter (`uint depth = payload.depth;`,
        // `Payload p = payload; p.depth`): every value it holds is that read.
        let sources = values_of(program, (var, path.clone()));
        if let Some(Source::Read(v, p)) = sources.first() {
            if incoming(*v) && sources.iter().all(|s| *s == sources[0]) {
                return Some(Counter::Payload {
                    var: *v,
                    path: p.clone(),
                });
            }
        }
    }
    Some(Counter::Var { var, path })
}

/// A parameter passed by pointer (HLSL copies an `in` argument into a
/// temporary and passes that): the incoming payload member every call from
/// a hit or miss shader copies into it, when they all agree (`TraceRadianceRay(ray,
/// payload.recursionDepth)` with the guard inside the helper).
fn parameter_counter(
    program: &Program,
    param: Id,
    path: &[u64],
    incoming: &dyn Fn(Id) -> bool,
) -> Option<Counter> {
    if program.def(param)?.class.opcode != Op::FunctionParameter {
        return None;
    }
    let f = program
        .functions
        .iter()
        .find(|f| f.params.contains(&param))?;
    let k = f.params.iter().position(|&p| p == param)?;
    // Only calls from shaders that can close a recursion cycle (those with
    // an incoming payload) matter to a depth guard: the ray generation
    // shader's first call passes its own start value.
    let mut in_cycle_stages: HashSet<Id> = HashSet::new();
    for e in program.entry_points.iter().filter(|e| {
        matches!(
            e.stage,
            Stage::ClosestHit | Stage::AnyHit | Stage::Miss | Stage::Intersection
        )
    }) {
        in_cycle_stages.extend(program.reachable_functions(e.function));
    }
    let mut found: Option<Counter> = None;
    for (_, call) in program.insts.iter().enumerate().filter(|(n, i)| {
        i.class.opcode == Op::FunctionCall
            && matches!(i.operands.first(), Some(Operand::IdRef(x)) if *x == f.id)
            && program
                .function_of(*n)
                .and_then(|k| program.functions.get(k))
                .is_some_and(|g| in_cycle_stages.contains(&g.id))
    }) {
        let Some(Operand::IdRef(arg)) = call.operands.get(1 + k) else {
            return None;
        };
        let (var, mut arg_path) = pointer_path(program, *arg)?;
        if !is_local(program, var) {
            return None;
        }
        arg_path.extend_from_slice(path);
        let sources = values_of(program, (var, arg_path));
        let Some(Source::Read(v, p)) = sources.first() else {
            return None;
        };
        if !incoming(*v) || sources.iter().any(|s| *s != sources[0]) {
            return None;
        }
        let c = Counter::Payload {
            var: *v,
            path: p.clone(),
        };
        if found.as_ref().is_some_and(|f| *f != c) {
            return None;
        }
        found = Some(c);
    }
    found
}

/// Whether `value` is `counter + c` with a constant `c > 0`; `c`.
fn step_of(program: &Program, value: Id, counter: &Counter) -> Option<i64> {
    let add = program.def(strip_conversions(program, value))?;
    if add.class.opcode != Op::IAdd {
        return None;
    }
    let ops: Vec<Id> = ids(add).collect();
    [(0, 1), (1, 0)].iter().find_map(|&(x, c)| {
        let (&x, &c) = (ops.get(x)?, ops.get(c)?);
        let step = signed(program, c, program.fold(c)?);
        (step > 0 && counter_of(program, x).as_ref() == Some(counter)).then_some(step)
    })
}

fn counter_name(program: &Program, c: &Counter) -> String {
    let (Counter::Payload { var, path } | Counter::Var { var, path }) = c;
    let mut s = program.display_name(*var);
    let mut ty = global(program, *var).map(|g| g.ty).or_else(|| {
        program
            .def(*var)
            .and_then(|d| d.result_type)
            .and_then(|t| match program.ty(t) {
                Some(Type::Pointer { pointee, .. }) => Some(*pointee),
                _ => None,
            })
    });
    for &k in path {
        match ty.and_then(|t| program.ty(t)) {
            Some(Type::Struct { members }) => {
                s.push('.');
                s.push_str(&program.member_name(ty.unwrap_or(0), k as u32));
                ty = members.get(k as usize).copied();
            }
            _ => {
                s.push_str(&format!("[{k}]"));
                ty = None;
            }
        }
    }
    s
}

/// Names a description may use for a uniform or push-constant member:
/// `block.member`, `Type.member`, `member`.
fn member_keys(program: &Program, ptr: Id) -> Vec<String> {
    let Some((var, path)) = pointer_path(program, ptr) else {
        return Vec::new();
    };
    let Some(g) = global(program, var) else {
        return Vec::new();
    };
    let mut segs = Vec::new();
    let mut ty = Some(g.ty);
    for &k in &path {
        let Some(t) = ty else { break };
        match program.ty(t) {
            Some(Type::Struct { members }) => {
                // naga wraps uniform structs in an unnamed block member.
                if let Some(n) = program.member_names.get(&(t, k as u32)) {
                    if !n.is_empty() {
                        segs.push(n.clone());
                    }
                }
                ty = members.get(k as usize).copied();
            }
            _ => {
                segs.push(k.to_string());
                ty = None;
            }
        }
    }
    let mut keys = Vec::new();
    if let Some(name) = g.name.as_ref().filter(|n| !n.is_empty()) {
        keys.push(
            std::iter::once(name.clone())
                .chain(segs.clone())
                .collect::<Vec<_>>()
                .join("."),
        );
    }
    if let Some(tn) = program.name(g.ty).filter(|n| !n.is_empty()) {
        keys.push(
            std::iter::once(tn.to_string())
                .chain(segs.clone())
                .collect::<Vec<_>>()
                .join("."),
        );
    }
    for k in 1..segs.len().max(1) {
        keys.push(segs[k..].join("."));
    }
    if segs.len() == 1 {
        keys.push(segs[0].clone());
    }
    keys
}

/// A loop or recursion bound: its value and where it comes from.
fn bound_of(
    program: &Program,
    id: Id,
    constants: &BTreeMap<String, DescribedConstant>,
) -> Result<(i64, BoundSource), UnknownBound> {
    let id = strip_conversions(program, id);
    if let Some(Constant::Int(v)) = program.constants.get(&id) {
        return Ok((signed(program, id, *v), BoundSource::Constant(*v as i64)));
    }
    // A local holding one constant (unoptimised output).
    if let Some(v) = program.fold(id) {
        let v = signed(program, id, v);
        return Ok((v, BoundSource::Constant(v)));
    }
    if let Some(Constant::Int(v)) = program.spec_constants.get(&id) {
        let name = program.display_name(id);
        if let Some(c) = constants.get(&name) {
            return Ok((
                c.value,
                BoundSource::SpecConstant {
                    name,
                    value: c.value,
                    described: true,
                },
            ));
        }
        return Ok((
            *v as i64,
            BoundSource::SpecConstant {
                name,
                value: *v as i64,
                described: false,
            },
        ));
    }
    let Some(inst) = program.def(id) else {
        return Err(UnknownBound::UnknownValue);
    };
    if inst.class.opcode == Op::Load {
        let ptr = ids(inst).next().unwrap_or(0);
        let storage = pointer_path(program, ptr)
            .and_then(|(v, _)| global(program, v))
            .map(|g| g.storage);
        let kind = match storage {
            Some(StorageClass::PushConstant) => ValueKind::PushConstant,
            Some(StorageClass::Uniform) => ValueKind::Uniform,
            Some(StorageClass::StorageBuffer) => ValueKind::StorageBuffer,
            Some(StorageClass::ShaderRecordBufferKHR) => ValueKind::ShaderRecord,
            _ => return Err(UnknownBound::RuntimeValue),
        };
        let keys = member_keys(program, ptr);
        for k in &keys {
            if let Some(c) = constants.get(k) {
                return Ok((
                    c.value,
                    BoundSource::Described {
                        kind,
                        key: k.clone(),
                        value: c.value,
                    },
                ));
            }
        }
        let name = keys.first().cloned().unwrap_or_else(|| "?".into());
        return Err(UnknownBound::NotDescribed { kind, name });
    }
    Err(UnknownBound::RuntimeValue)
}

fn signed(program: &Program, id: Id, v: u64) -> i64 {
    let ty = program.def(id).and_then(|i| i.result_type);
    match ty.and_then(|t| program.ty(t)) {
        Some(Type::Int {
            width: 32,
            signed: true,
        }) => v as u32 as i32 as i64,
        _ => v as i64,
    }
}

/// A relation `lhs < rhs` (strict) or `lhs <= rhs` that holds.
#[derive(Clone, Copy, Debug)]
struct Rel {
    lhs: Id,
    rhs: Id,
    strict: bool,
}

/// The relations that hold when `cond` has value `want`.
/// The label of the block that defines `id`.
fn inst_block_label(program: &Program, id: Id) -> Option<Id> {
    let at = *program.defs.get(&id)?;
    let f = program.functions.get(program.function_of(at)?)?;
    let b = f.blocks.iter().find(|b| b.start <= at && at <= b.end)?;
    program.insts[b.start].result_id
}

/// The value bool `v` must have on the edge from block `from` to block `to`:
/// when `from` ends in a conditional branch on `v` (or on its negation)
/// that reaches `to` on one side only (glslang's `a || b` passes `a` itself
/// to the phi, from the block that found it true).
fn edge_value(program: &Program, v: Id, from: Id, to: Option<Id>) -> Option<bool> {
    let to = to?;
    let f = program
        .functions
        .iter()
        .find(|f| f.block_by_label(from).is_some())?;
    let end = &program.insts[f.blocks[f.block_by_label(from)?].end];
    if end.class.opcode != Op::BranchConditional {
        return None;
    }
    let o: Vec<Id> = ids(end).collect();
    let [c, t, e, ..] = o.as_slice() else {
        return None;
    };
    let taken = match (*t == to, *e == to) {
        (true, false) => true,
        (false, true) => false,
        _ => return None,
    };
    if *c == v {
        return Some(taken);
    }
    let not = program.def(*c)?;
    (not.class.opcode == Op::LogicalNot && ids(not).next() == Some(v)).then_some(!taken)
}

fn relations(program: &Program, cond: Id, want: bool, out: &mut Vec<Rel>, depth: u32) {
    if depth > 8 {
        return;
    }
    let Some(inst) = program.def(cond) else {
        return;
    };
    if inst.class.opcode == Op::Load {
        // A bool kept in a local: naga lowers `a && b` to `if a { t = b }
        // else { t = false }` and branches on `t`. Where exactly one store
        // can give the wanted value, the branch implies that stored value.
        let Some(ptr) = ids(inst).next() else { return };
        let Some(var) = program.def(ptr).filter(|d| {
            d.class.opcode == Op::Variable
                && matches!(
                    d.operands.first(),
                    Some(rspirv::dr::Operand::StorageClass(
                        spirv::StorageClass::Function
                    ))
                )
        }) else {
            return;
        };
        let initializer = ids(var).next();
        let stores = program.insts.iter().filter_map(|i| {
            let mut o = ids(i);
            (i.class.opcode == Op::Store && o.next() == Some(ptr))
                .then(|| o.next())
                .flatten()
        });
        let possible: Vec<Id> = stores
            .chain(initializer)
            .filter(|v| {
                // A null bool is false.
                let c = program.constants.get(v);
                c != Some(&crate::program::Constant::Bool(!want))
                    && !(want && c == Some(&crate::program::Constant::Null))
            })
            .collect();
        if let [only] = possible.as_slice() {
            relations(program, *only, want, out, depth + 1);
        }
        return;
    }
    if inst.class.opcode == Op::Phi {
        // glslang's `a || b` and `a && b`: a phi of a constant (the operand
        // that decided) and the second operand. Where exactly one incoming
        // value can be the wanted one, the branch implies it.
        let possible: Vec<Id> = inst
            .operands
            .chunks(2)
            .filter_map(|pair| match pair {
                [rspirv::dr::Operand::IdRef(v), rspirv::dr::Operand::IdRef(from)] => {
                    Some((*v, *from))
                }
                _ => None,
            })
            .filter(|&(v, from)| {
                let c = program.constants.get(&v);
                let known = match c {
                    Some(crate::program::Constant::Bool(b)) => Some(*b),
                    Some(crate::program::Constant::Null) => Some(false),
                    _ => edge_value(program, v, from, inst_block_label(program, cond)),
                };
                known != Some(!want)
            })
            .map(|(v, _)| v)
            .collect();
        if let [only] = possible.as_slice() {
            relations(program, *only, want, out, depth + 1);
        }
        return;
    }
    let v: Vec<Id> = ids(inst).collect();
    let (a, b) = match v.as_slice() {
        [a, b] => (*a, *b),
        [a] => (*a, 0),
        _ => return,
    };
    use Op::*;
    let op = inst.class.opcode;
    let (lhs, rhs, strict) = match (op, want) {
        (LogicalNot, _) => return relations(program, a, !want, out, depth + 1),
        (LogicalAnd, true) | (LogicalOr, false) => {
            relations(program, a, want, out, depth + 1);
            relations(program, b, want, out, depth + 1);
            return;
        }
        (ULessThan | SLessThan, true) | (UGreaterThanEqual | SGreaterThanEqual, false) => {
            (a, b, true)
        }
        (ULessThanEqual | SLessThanEqual, true) | (UGreaterThan | SGreaterThan, false) => {
            (a, b, false)
        }
        (UGreaterThan | SGreaterThan, true) | (ULessThanEqual | SLessThanEqual, false) => {
            (b, a, true)
        }
        (UGreaterThanEqual | SGreaterThanEqual, true) | (ULessThan | SLessThan, false) => {
            (b, a, false)
        }
        _ => return,
    };
    out.push(Rel { lhs, rhs, strict });
}

/// Relations guaranteed to hold at instruction `inst` by the conditional
/// branches that dominate it.
fn dominating_relations(program: &Program, fi: usize, inst: usize) -> Vec<(Rel, usize)> {
    let Some(f) = program.functions.get(fi) else {
        return Vec::new();
    };
    let cfgs = function_cfgs(program);
    let idom = cfgs.idom(program, fi);
    let Some(b) = f.block_of(inst) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut d = idom.get(b).copied().flatten();
    let mut steps = 0;
    while let Some(db) = d {
        steps += 1;
        if steps > f.blocks.len() + 1 {
            break;
        }
        let term_i = f.blocks[db].end;
        let term = &program.insts[term_i];
        if term.class.opcode == Op::BranchConditional {
            let v: Vec<Id> = ids(term).collect();
            if let [cond, t, e, ..] = v.as_slice() {
                let (tb, eb) = (f.block_by_label(*t), f.block_by_label(*e));
                if let (Some(tb), Some(eb)) = (tb, eb) {
                    let want = if tb != eb && dominates(idom, tb, b) {
                        Some(true)
                    } else if tb != eb && dominates(idom, eb, b) {
                        Some(false)
                    } else {
                        None
                    };
                    if let Some(w) = want {
                        let mut rels = Vec::new();
                        relations(program, *cond, w, &mut rels, 0);
                        out.extend(rels.into_iter().map(|r| (r, term_i)));
                    }
                }
            }
        }
        if idom[db] == Some(db) {
            break;
        }
        d = idom[db];
    }
    out
}

// ---------------------------------------------------------------------------
// Depth guards.

fn recognise_guard(
    pipeline: &Pipeline,
    graph: &TraceGraph,
    scc_of: &[usize],
    scc: usize,
    node: usize,
    site_inst: usize,
) -> Result<Guard, NoGuard> {
    let shader = &graph.nodes[node].shader;
    let program = pipeline.program(shader).ok_or(NoGuard::ModuleMissing)?;
    let site = program
        .sites
        .iter()
        .find(|s| s.inst == site_inst)
        .ok_or(NoGuard::TraceMissing)?;
    let out_payload = site.payload.unwrap_or(0);
    // Every point from the trace up the call chain to the entry point.
    let g = program
        .functions
        .get(site.function)
        .ok_or(NoGuard::OutsideFunction)?;
    let chains = call_chains(program, shader.function, g.id, super::liveness::MAX_CHAINS);
    let mut points = vec![site_inst];
    if let Some(chain) = chains.first() {
        points.extend(chain.iter().rev().copied());
    }
    let mut seen_counter: Option<String> = None;
    let mut why_not: Option<NoGuard> = None;
    for &p in &points {
        let Some(fi) = program
            .function_of(p)
            .filter(|&i| i < program.functions.len())
        else {
            continue;
        };
        for (rel, term) in dominating_relations(program, fi, p) {
            let Some(counter @ Counter::Payload { .. }) = counter_of(program, rel.lhs) else {
                continue;
            };
            let name = counter_name(program, &counter);
            seen_counter.get_or_insert(name.clone());
            let (bound, bound_source) = match bound_of(program, rel.rhs, &pipeline.constants) {
                Ok(b) => b,
                Err(bound) => {
                    why_not = Some(NoGuard::BoundUnknown {
                        counter: name,
                        bound,
                    });
                    continue;
                }
            };
            let Counter::Payload { path, .. } = &counter else {
                continue;
            };
            let Some(step) = growth(program, shader.function, out_payload, &counter) else {
                why_not = Some(NoGuard::CounterDoesNotGrow { counter: name });
                continue;
            };
            let (initial, initial_assumed) =
                initial_value(pipeline, graph, scc_of, scc, path).map_or((0, true), |v| (v, false));
            let limit = if rel.strict { bound } else { bound + 1 };
            let traces = if limit <= initial {
                0
            } else {
                ((limit - initial) as u64).div_ceil(step as u64)
            };
            return Ok(Guard {
                counter: name,
                op: if rel.strict { "<" } else { "<=" },
                bound,
                bound_source,
                step,
                initial,
                initial_assumed,
                traces,
                location: program
                    .inst_location(term)
                    .or_else(|| program.site_location(term)),
                key: (counter_var(&counter), path.clone()),
            });
        }
    }
    Err(why_not.unwrap_or(NoGuard::NoComparison {
        counter: seen_counter,
    }))
}

fn counter_var(c: &Counter) -> Id {
    let (Counter::Payload { var, .. } | Counter::Var { var, .. }) = c;
    *var
}

/// How many of a bounded cycle's levels a trace that leaves it (a shadow
/// ray) runs from, when the cycle's own counter guards it too: the samples
/// write `if (payload.depth < MAX)` before the shadow ray as before the
/// reflection. `None` when no such guard dominates the trace (it may run
/// at every level). The cycle is entered with the counter at `g.initial`
/// and each level adds `g.step`.
fn exit_levels(
    pipeline: &Pipeline,
    graph: &TraceGraph,
    node: usize,
    site_inst: usize,
    g: &Guard,
) -> Option<u64> {
    let shader = &graph.nodes[node].shader;
    let program = pipeline.program(shader)?;
    let site = program.sites.iter().find(|s| s.inst == site_inst)?;
    let f = program.functions.get(site.function)?;
    let chains = call_chains(program, shader.function, f.id, super::liveness::MAX_CHAINS);
    let mut points = vec![site_inst];
    if let Some(chain) = chains.first() {
        points.extend(chain.iter().rev().copied());
    }
    let mut fewest: Option<u64> = None;
    for &p in &points {
        let Some(fi) = program
            .function_of(p)
            .filter(|&i| i < program.functions.len())
        else {
            continue;
        };
        for (rel, _) in dominating_relations(program, fi, p) {
            let Some(counter @ Counter::Payload { .. }) = counter_of(program, rel.lhs) else {
                continue;
            };
            let Counter::Payload { var, path } = &counter else {
                continue;
            };
            if (*var, path) != (g.key.0, &g.key.1) {
                continue;
            }
            let Ok((bound, _)) = bound_of(program, rel.rhs, &pipeline.constants) else {
                continue;
            };
            let limit = if rel.strict { bound } else { bound + 1 };
            let levels = if limit <= g.initial {
                0
            } else {
                ((limit - g.initial) as u64).div_ceil(g.step as u64)
            };
            fewest = Some(fewest.map_or(levels, |f| f.min(levels)));
        }
    }
    fewest
}

/// By how much the traced payload's copy of the counter exceeds the
/// incoming one: the traced payload's member holds `counter + c`, `c > 0`,
/// stored directly or through a copy (a fresh payload written field by
/// field, a constructed one, an `inout` parameter).
fn growth(program: &Program, _entry: Id, out_payload: Id, counter: &Counter) -> Option<i64> {
    let Counter::Payload { path, .. } = counter else {
        return None;
    };
    values_of(program, (out_payload, path.clone()))
        .into_iter()
        .filter_map(|s| match s {
            Source::Value(v) => step_of(program, v, counter),
            Source::Read(..) => None,
        })
        .max()
}

/// The constant the counter member gets in shaders that enter the cycle.
fn initial_value(
    pipeline: &Pipeline,
    graph: &TraceGraph,
    scc_of: &[usize],
    scc: usize,
    path: &[u64],
) -> Option<i64> {
    let mut value = None;
    for e in graph.traces() {
        if scc_of[e.to] != scc || scc_of[e.from] == scc || e.kind != EdgeKind::Trace {
            continue;
        }
        let shader = &graph.nodes[e.from].shader;
        let program = pipeline.program(shader)?;
        let site = program.sites.iter().find(|s| s.inst == e.inst)?;
        let payload = site.payload?;
        // A helper's parameter (the depth a ray generation shader passes to
        // the function that traces) folds per call chain.
        let mut chains = program
            .functions
            .get(site.function)
            .map(|f| call_chains(program, shader.function, f.id, super::liveness::MAX_CHAINS))
            .unwrap_or_default();
        if chains.is_empty() {
            chains.push(Vec::new());
        }
        for source in values_of(program, (payload, path.to_vec())) {
            if let Source::Value(val) = source {
                for chain in &chains {
                    if let Some(c) = program.fold_in(val, chain) {
                        let c = signed(program, val, c);
                        value = Some(value.map_or(c, |v: i64| v.min(c)));
                    }
                }
            }
        }
    }
    value
}

// ---------------------------------------------------------------------------
// Loops that trace.

#[derive(Clone, Debug)]
pub struct LoopBound {
    pub counter: String,
    pub op: &'static str,
    pub bound: i64,
    pub bound_source: BoundSource,
}

/// A loop whose body traces (or calls a function that does).
#[derive(Clone, Debug)]
pub struct TraceLoop {
    pub entry: String,
    pub stage: Stage,
    /// Index of the loop header's `OpLabel`.
    pub header: usize,
    pub location: Option<Location>,
    pub site_location: Option<Location>,
    /// The recognised bound, or why none was.
    pub bound: Result<LoopBound, NoLoopBound>,
}

/// Loops around trace sites in every entry point of a program; bounds come
/// from constants, specialization constants, or `constants` (by name).
pub fn trace_loops(
    program: &Program,
    constants: &BTreeMap<String, DescribedConstant>,
) -> Vec<TraceLoop> {
    let mut out: Vec<TraceLoop> = Vec::new();
    for e in &program.entry_points {
        for site in &program.sites {
            if site.kind != crate::program::SiteKind::TraceRay {
                continue;
            }
            let Some(g) = program.functions.get(site.function) else {
                continue;
            };
            for chain in call_chains(program, e.function, g.id, super::liveness::MAX_CHAINS) {
                let mut points = vec![site.inst];
                points.extend(chain.iter().rev().copied());
                for &p in &points {
                    let Some(f) = program
                        .function_of(p)
                        .and_then(|i| program.functions.get(i))
                    else {
                        continue;
                    };
                    for (header, body) in natural_loops(f) {
                        let Some(pb) = f.block_of(p) else { continue };
                        if !body.contains(&pb) {
                            continue;
                        }
                        let header_inst = f.blocks[header].start;
                        if out
                            .iter()
                            .any(|l| l.header == header_inst && l.entry == e.name)
                        {
                            continue;
                        }
                        let location = (f.blocks[header].start..=f.blocks[header].end)
                            .find_map(|i| program.inst_location(i))
                            .or_else(|| program.site_location(header_inst));
                        out.push(TraceLoop {
                            entry: e.name.clone(),
                            stage: e.stage,
                            header: header_inst,
                            location,
                            site_location: program.site_location(site.inst),
                            bound: loop_bound(program, f, header, &body, constants),
                        });
                    }
                }
            }
        }
    }
    out
}

fn loop_bound(
    program: &Program,
    f: &Function,
    header: usize,
    body: &HashSet<usize>,
    constants: &BTreeMap<String, DescribedConstant>,
) -> Result<LoopBound, NoLoopBound> {
    let mut why: Option<NoLoopBound> = None;
    let mut blocks: Vec<usize> = body.iter().copied().collect();
    blocks.sort_unstable();
    // An exit bounds the loop only when every iteration passes it: its
    // block dominates every back edge.
    let idom = dominators(f);
    let latches: Vec<usize> = blocks
        .iter()
        .copied()
        .filter(|&b| f.blocks[b].succs.contains(&header))
        .collect();
    for b in blocks {
        if !latches.iter().all(|&l| dominates(&idom, b, l)) {
            continue;
        }
        let term = &program.insts[f.blocks[b].end];
        if term.class.opcode != Op::BranchConditional {
            continue;
        }
        let v: Vec<Id> = ids(term).collect();
        let [cond, t, e, ..] = v.as_slice() else {
            continue;
        };
        let (Some(tb), Some(eb)) = (f.block_by_label(*t), f.block_by_label(*e)) else {
            continue;
        };
        // A target outside the loop, or a block in it that only branches out
        // (`if (…) break;`), leaves the loop.
        let leaves = |blk: usize| {
            if !body.contains(&blk) {
                return true;
            }
            let end = &program.insts[f.blocks[blk].end];
            end.class.opcode == Op::Branch
                && ids(end)
                    .next()
                    .and_then(|l| f.block_by_label(l))
                    .is_some_and(|to| !body.contains(&to))
        };
        let stay = match (leaves(tb), leaves(eb)) {
            (false, true) => true,
            (true, false) => false,
            _ => continue,
        };
        let mut rels = Vec::new();
        relations(program, *cond, stay, &mut rels, 0);
        for rel in rels {
            let Some(counter) = counter_of(program, rel.lhs) else {
                continue;
            };
            let name = counter_name(program, &counter);
            if !increments(program, f, body, &counter) {
                why.get_or_insert(NoLoopBound::NotIncremented { counter: name });
                continue;
            }
            match bound_of(program, rel.rhs, constants) {
                Ok((bound, bound_source)) => {
                    return Ok(LoopBound {
                        counter: name,
                        op: if rel.strict { "<" } else { "<=" },
                        bound,
                        bound_source,
                    })
                }
                Err(bound) => {
                    why = Some(NoLoopBound::BoundUnknown {
                        counter: name,
                        bound,
                    })
                }
            }
        }
    }
    Err(why.unwrap_or(NoLoopBound::NoCounter))
}

/// Whether the loop stores `counter + c` (c > 0) into the counter somewhere
/// in its body (a local, a member of the traced payload, `prd.depth++`).
fn increments(program: &Program, f: &Function, body: &HashSet<usize>, counter: &Counter) -> bool {
    let (Counter::Payload { var, path } | Counter::Var { var, path }) = counter;
    body.iter().any(|&b| {
        program.insts[f.blocks[b].start..=f.blocks[b].end]
            .iter()
            .any(|inst| {
                let v: Vec<Id> = ids(inst).collect();
                inst.class.opcode == Op::Store
                    && v.len() >= 2
                    && pointer_path(program, v[0]) == Some((*var, path.clone()))
                    && step_of(program, v[1], counter).is_some()
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::load;
    use std::path::Path;

    fn pipeline(rel: &str) -> Pipeline {
        load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
    }

    #[test]
    fn recursive_reflections_need_n_plus_two() {
        let r = recursion_report(&pipeline(
            "fixtures/pipelines/reflect_recursive.pipeline.toml",
        ));
        // 3 reflections (maxDepth = 3), a shadow ray from the deepest hit.
        assert_eq!(r.required_depth, Some(5));
        assert_eq!(r.cycles.len(), 1);
        let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
        assert_eq!(g.counter, "payload.depth");
        assert_eq!(
            (g.op, g.bound, g.step, g.initial, g.traces),
            ("<", 3, 1, 0, 3)
        );
        assert!(!g.initial_assumed);
        assert!(
            matches!(&g.bound_source, BoundSource::Described { kind: ValueKind::PushConstant, key, .. } if key == "pushConst.maxDepth"),
            "{:?}",
            g.bound_source
        );
        assert_eq!(
            crate::explain::recursion_chain(&r),
            "raygeneration `main` (raygen 0) at level 0 → closesthit `main` (hit group 0) at levels 1–4 → miss `main` (miss 1) at level 5"
        );
        assert_eq!(r.recursive_sites.len(), 2);
    }

    #[test]
    fn recursion_without_the_push_constant_is_unbounded() {
        let mut p = pipeline("fixtures/pipelines/reflect_recursive.pipeline.toml");
        p.constants.clear();
        let r = recursion_report(&p);
        assert_eq!(r.required_depth, None);
        let c = r.unbounded_cycle().unwrap();
        let why = c.sites[0].guard.as_ref().unwrap_err();
        assert_eq!(
            why,
            &NoGuard::BoundUnknown {
                counter: "payload.depth".into(),
                bound: UnknownBound::NotDescribed {
                    kind: ValueKind::PushConstant,
                    name: "pushConst.maxDepth".into()
                }
            }
        );
        assert_eq!(
            why.to_string(),
            "`payload.depth` is compared with push constant `pushConst.maxDepth`, which the pipeline description does not give"
        );
    }

    #[test]
    fn iterative_reflections_need_two() {
        let r = recursion_report(&pipeline(
            "fixtures/pipelines/reflect_iterative.pipeline.toml",
        ));
        assert_eq!(r.required_depth, Some(2));
        assert!(r.cycles.is_empty());
        assert_eq!(r.recursive_sites.len(), 1);
        let p = pipeline("fixtures/pipelines/reflect_iterative.pipeline.toml");
        let loops = trace_loops(&p.programs[0], &p.constants);
        assert_eq!(loops.len(), 1);
        let b = loops[0].bound.as_ref().unwrap();
        assert_eq!((b.counter.as_str(), b.op, b.bound), ("bounce", "<=", 4));
        assert_eq!(
            b.bound_source,
            BoundSource::SpecConstant {
                name: "MAX_BOUNCES".into(),
                value: 4,
                described: false
            }
        );
    }

    #[test]
    fn reference_wgsl_pipeline_needs_one() {
        let p = pipeline("shaders/reflect_iterative.pipeline.toml");
        let r = recursion_report(&p);
        assert_eq!(r.required_depth, Some(1));
        let loops = trace_loops(&p.programs[0], &p.constants);
        assert_eq!(loops.len(), 1);
        let b = loops[0].bound.as_ref().unwrap();
        assert_eq!((b.counter.as_str(), b.bound), ("bounce", 3));
        let none = trace_loops(&p.programs[0], &BTreeMap::new());
        assert_eq!(
            none[0].bound.as_ref().unwrap_err().to_string(),
            "the loop runs while `bounce` is below uniform value `params.max_bounces`, which the pipeline description does not give"
        );
    }

    #[test]
    fn guard_behind_a_short_circuit_and() {
        // `if reflectivity > 0.0 && incoming.depth < params.max_bounces`:
        // naga stores the second comparison (or `false`) in a local bool and
        // branches on it; the branch still implies the comparison.
        let r = recursion_report(&pipeline("shaders/reflect_recursive.pipeline.toml"));
        // Three bounces, the primary ray, and a shadow ray from the deepest hit.
        assert_eq!(r.required_depth, Some(5));
        let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
        assert_eq!(
            (g.counter.as_str(), g.bound, g.traces),
            ("incoming.depth", 3, 3)
        );
    }

    #[test]
    fn wgsl_guard_at_the_helper_call() {
        // naga puts the trace in a helper: the guard dominates the call.
        let r = recursion_report(&pipeline(
            "fixtures/pipelines/reflect_recursive_wgsl.pipeline.toml",
        ));
        assert_eq!(r.required_depth, Some(5));
        let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
        assert_eq!(
            (g.counter.as_str(), g.bound, g.traces),
            ("incoming.depth", 4, 4)
        );
        assert_eq!(
            g.bound_source,
            BoundSource::Described {
                kind: ValueKind::Uniform,
                key: "params.max_depth".into(),
                value: 4
            }
        );
    }

    fn loose(rels: &[&str]) -> Pipeline {
        let programs = rels
            .iter()
            .map(|rel| {
                let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
                let lang = crate::shader::Language::from_path(&path).unwrap();
                crate::front::load(&path, lang).unwrap()
            })
            .collect();
        Pipeline::from_programs(programs)
    }

    /// GLSL through glslang with `-g` and `-gV`: a guard in a helper that
    /// takes the payload `inout` (glslang's copy-in temporaries), a shadow
    /// ray whose flags sit in a local (skip closest hit: no recursion), a
    /// raygen loop counting bounces in the payload (`prd.depth++`).
    #[test]
    fn glsl_guards_through_inout_locals_and_payload_counters() {
        for v in ["g", "gV"] {
            let p = loose(&[
                &format!("fixtures/guards/loop.rgen.{v}.spv"),
                &format!("fixtures/guards/hit.rchit.{v}.spv"),
                &format!("fixtures/guards/miss.rmiss.{v}.spv"),
            ]);
            let r = recursion_report(&p);
            // depth < 3 from 0: hit at levels 1–4, the shadow ray's miss at 5.
            assert_eq!(r.required_depth, Some(5), "{v}");
            assert_eq!(r.cycles.len(), 1, "{v}");
            assert_eq!(
                r.cycles[0].sites.len(),
                1,
                "{v}: the shadow ray closes no cycle"
            );
            let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
            assert_eq!((g.bound, g.step, g.traces), (3, 1, 3), "{v}");
            assert!(!g.initial_assumed, "{v}");
            let loops = trace_loops(&p.programs[0], &p.constants);
            assert_eq!(loops.len(), 1, "{v}");
            let b = loops[0].bound.as_ref().unwrap();
            assert_eq!(
                (b.counter.as_str(), b.op, b.bound),
                ("prd.depth", "<", 10),
                "{v}"
            );
        }
    }

    /// A shadow ray guarded by the reflection's own counter leaves the
    /// cycle only from the levels that guard allows (the shape of
    /// Microsoft's procedural-geometry sample): GLSL with the shadow guard
    /// in a helper and the reflection's inline, from 1 to 3, and HLSL with
    /// both in helpers, from 0 to 3. Without that rule both needed 4.
    #[test]
    fn exit_guarded_by_the_cycle_counter() {
        for v in ["g", "gV"] {
            let p = loose(&[
                &format!("fixtures/guards/shared.rgen.{v}.spv"),
                &format!("fixtures/guards/shared.rchit.{v}.spv"),
                &format!("fixtures/guards/shared.rmiss.{v}.spv"),
                &format!("fixtures/guards/shared_shadow.rmiss.{v}.spv"),
            ]);
            let r = recursion_report(&p);
            assert_eq!(r.required_depth, Some(3), "{v}");
            let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
            assert_eq!((g.initial, g.bound, g.traces), (1, 3, 2), "{v}");
        }
        let r = recursion_report(&loose(&["fixtures/guards/shared_counter.hlsl"]));
        assert_eq!(r.required_depth, Some(3));
    }

    /// HLSL through rtlint: the traced payload is a fresh local written field
    /// by field from the incoming one (`next.depth = payload.depth + 1`);
    /// the shadow ray's flags sit in a local (skip closest hit: no cycle).
    #[test]
    fn hlsl_guard_through_a_fresh_payload() {
        let p = loose(&["fixtures/guards/fresh.hlsl"]);
        let r = recursion_report(&p);
        // Hit at levels 1–4, the deepest hit's shadow ray reaches a miss at 5.
        assert_eq!(r.required_depth, Some(5));
        assert_eq!(r.cycles[0].sites.len(), 1);
        // The raygen's sample loop counts in its payload's member.
        let loops = trace_loops(&p.programs[0], &p.constants);
        assert_eq!(loops.len(), 1);
        let b = loops[0].bound.as_ref().unwrap();
        assert_eq!((b.op, b.bound), ("<", 2));
        let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
        assert_eq!((g.bound, g.step, g.initial, g.traces), (3, 1, 0, 3));
        assert!(!g.initial_assumed);
    }

    /// WGSL: the traced payload is constructed (`Payload(…, incoming.depth +
    /// 1u)`), and the shadow ray's flags come through a `var` and naga's
    /// helper's `RayDesc` parameter.
    #[test]
    fn wgsl_guard_through_a_constructed_payload() {
        let p = loose(&["fixtures/guards/constructed.wgsl"]);
        let r = recursion_report(&p);
        assert_eq!(r.required_depth, Some(6));
        let loops = trace_loops(&p.programs[0], &p.constants);
        let raygen: Vec<_> = loops.iter().filter(|l| l.entry == "raygen").collect();
        assert_eq!(raygen.len(), 1);
        let b = raygen[0].bound.as_ref().unwrap();
        assert_eq!(
            (b.counter.as_str(), b.op, b.bound),
            ("bounce.depth", "<", 2)
        );
        assert_eq!(r.cycles[0].sites.len(), 1);
        let g = r.cycles[0].sites[0].guard.as_ref().unwrap();
        assert_eq!(
            (g.counter.as_str(), g.bound, g.traces),
            ("incoming.depth", 4, 4)
        );
        // The recursive trace is the closest hit's, not the raygen's.
        assert_eq!(
            r.cycles[0].sites[0].location.as_ref().map(|l| l.line),
            Some(42)
        );
    }

    /// An unbounded chain says so at every step past the cycle; no shader is
    /// placed "at level 0" after it.
    #[test]
    fn unbounded_chain_has_no_level_past_the_cycle() {
        let r = recursion_report(&pipeline("fixtures/RT024/bad.pipeline.toml"));
        assert_eq!(r.required_depth, None);
        let text = crate::explain::recursion_chain(&r);
        assert!(
            text.contains("at levels 1 and deeper, without bound"),
            "{text}"
        );
        assert!(!text.contains("(miss 0) at level 0"), "{text}");
    }

    /// A helper called twice with different flags is folded per call: only
    /// flags every call agrees on prune targets.
    #[test]
    fn helper_called_with_different_flags() {
        let r = recursion_report(&loose(&["fixtures/guards/two_calls.wgsl"]));
        assert_eq!(r.required_depth, None);
        assert_eq!(r.cycles.len(), 1);
    }
}
