//! Traversal facts of each ray a module traces or queries: its flags, its
//! interval, origin and direction where the module makes them constant,
//! whether the origin is a hit point and whether a distance bound for the
//! direction is computed beside it; and, over a pipeline, which traces are
//! visibility tests (every shader they reach only records hit or miss).

use super::callgraph::{EdgeKind, Slot, TraceGraph};
use crate::diag::Location;
use crate::pipeline::{HitGroupKind, Pipeline};
use crate::program::{Id, Program, SiteKind, Type};
use crate::shader::Stage;
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};
use std::collections::BTreeSet;

/// Ray flag bits (`RayFlagsKHR`).
pub mod flags {
    pub const OPAQUE: u64 = 0x1;
    pub const NO_OPAQUE: u64 = 0x2;
    pub const TERMINATE_ON_FIRST_HIT: u64 = 0x4;
    pub const SKIP_CLOSEST_HIT: u64 = 0x8;
    pub const CULL_BACK_FACING: u64 = 0x10;
    pub const CULL_FRONT_FACING: u64 = 0x20;
    pub const SKIP_TRIANGLES: u64 = 0x100;
}

const BUILTIN_RAY_TMAX: u32 = 5326;
const BUILTIN_OBJECT_TO_WORLD: u32 = 5330;
const BUILTIN_HIT_T_NV: u32 = 5332;
const GLSL_LENGTH: u32 = 66;
const GLSL_DISTANCE: u32 = 67;
const GLSL_NORMALIZE: u32 = 69;

/// Where a ray's origin comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// Exactly a hit point: `origin + direction × t` with `t` the hit
    /// distance (`RayTmax`, a distance read from a payload), or a position
    /// transformed by `ObjectToWorld`, with nothing added.
    HitPoint,
    /// Anything else, offset hit points included.
    Other,
}

/// One trace (`OpTraceRayKHR`) or ray-query initialisation as a call chain
/// from an entry point reaches it.
#[derive(Clone, Debug)]
pub struct Ray {
    /// Index into [`Program::sites`].
    pub site: usize,
    pub query: bool,
    pub stage: Stage,
    pub location: Option<Location>,
    pub flags: Option<u64>,
    pub tmin: Option<f64>,
    pub tmax: Option<f64>,
    pub origin_value: Option<Vec<f64>>,
    pub direction: Option<Vec<f64>>,
    pub origin: Origin,
    /// The length or distance instruction whose result bounds the ray: the
    /// direction is `normalize(v)` (or `v / length(v)`) and `length(v)` is
    /// computed too.
    pub bound: Option<Bound>,
}

/// A distance computed beside the ray's direction.
#[derive(Clone, Debug)]
pub struct Bound {
    pub location: Option<Location>,
}

/// Every trace and ray-query initialisation of a module, once per call
/// chain position (a helper traced from several places yields one ray per
/// distinct position). Computed once per Program: five rules ask.
pub fn rays(program: &Program) -> std::sync::Arc<Vec<Ray>> {
    struct Rays(std::sync::Arc<Vec<Ray>>);
    program
        .memo
        .get_or(|| Rays(std::sync::Arc::new(find_rays(program))))
        .0
        .clone()
}

fn find_rays(program: &Program) -> Vec<Ray> {
    let mut out: Vec<Ray> = Vec::new();
    let mut seen: BTreeSet<(usize, String)> = BTreeSet::new();
    for ep in &program.entry_points {
        let reach = program.reachable_functions(ep.function);
        for (si, site) in program.sites.iter().enumerate() {
            let query = site.op == Op::RayQueryInitializeKHR;
            if !(site.kind == SiteKind::TraceRay || query) {
                continue;
            }
            let Some(f) = program.functions.get(site.function) else {
                continue;
            };
            if !reach.contains(&f.id) {
                continue;
            }
            let chains = crate::program::cfg::call_chains(
                program,
                ep.function,
                f.id,
                super::liveness::MAX_CHAINS,
            );
            for chain in chains {
                let location = program
                    .location_in(site.inst, &chain)
                    .or_else(|| program.site_location(site.inst));
                let key = (
                    si,
                    location.as_ref().map(|l| l.to_string()).unwrap_or_default(),
                );
                if seen.contains(&key) {
                    continue;
                }
                if let Some(r) = ray(program, si, query, ep.stage, &chain, location) {
                    seen.insert(key);
                    out.push(r);
                }
            }
        }
    }
    out
}

fn ray(
    program: &Program,
    si: usize,
    query: bool,
    stage: Stage,
    chain: &[usize],
    location: Option<Location>,
) -> Option<Ray> {
    let site = &program.sites[si];
    let inst = &program.insts[site.inst];
    // OpTraceRayKHR: accel, flags, cull, offset, stride, miss, origin, tmin,
    // direction, tmax, payload. OpRayQueryInitializeKHR: query, accel,
    // flags, cull, origin, tmin, direction, tmax.
    let (flags_at, first) = if query { (2, 4) } else { (1, 6) };
    let id = |k: usize| match inst.operands.get(k) {
        Some(Operand::IdRef(x)) => Some(*x),
        _ => None,
    };
    let (origin, tmin, dir, tmax) = (id(first)?, id(first + 1)?, id(first + 2)?, id(first + 3)?);
    let scalar = |x: Id| {
        program
            .fold_floats_in(x, chain)
            .filter(|v| v.len() == 1)
            .map(|v| v[0])
    };
    Some(Ray {
        site: si,
        query,
        stage,
        location,
        flags: id(flags_at).and_then(|f| program.fold_in(f, chain)),
        tmin: scalar(tmin),
        tmax: scalar(tmax),
        origin_value: program.fold_floats_in(origin, chain),
        direction: program.fold_floats_in(dir, chain),
        origin: origin_kind(program, origin, chain, 0),
        bound: bound(program, dir, chain, site.function),
    })
}

fn operand_ids(program: &Program, id: Id) -> Vec<Id> {
    program
        .def(id)
        .map(|i| {
            i.operands
                .iter()
                .filter_map(|o| match o {
                    Operand::IdRef(x) => Some(*x),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default()
}

fn opcode(program: &Program, id: Id) -> Option<Op> {
    program.def(id).map(|i| i.class.opcode)
}

/// The GLSL.std.450 instruction number of `id`, when it is one.
fn glsl_op(program: &Program, id: Id) -> Option<u32> {
    let i = program.def(id)?;
    if i.class.opcode != Op::ExtInst {
        return None;
    }
    match (i.operands.first(), i.operands.get(1)) {
        (Some(Operand::IdRef(set)), Some(Operand::LiteralExtInstInteger(n)))
            if Some(*set) == program.glsl_std_set() =>
        {
            Some(*n)
        }
        _ => None,
    }
}

/// Whether value `id` is loaded from the built-in `builtins` or from a
/// payload the caller traced with.
fn loads_from(program: &Program, id: Id, chain: &[usize], builtins: &[u32], payload: bool) -> bool {
    let (src, _) = program.value_source(id, chain);
    let Some(i) = program.def(src) else {
        return false;
    };
    if i.class.opcode != Op::Load {
        return false;
    }
    let Some(Operand::IdRef(ptr)) = i.operands.first() else {
        return false;
    };
    let root = program.pointer_root(*ptr);
    program
        .builtin_of(root)
        .is_some_and(|b| builtins.contains(&b))
        || (payload && program.storage_of(root) == Some(StorageClass::RayPayloadKHR))
}

fn is_hit_distance(program: &Program, id: Id, chain: &[usize]) -> bool {
    loads_from(
        program,
        id,
        chain,
        &[BUILTIN_RAY_TMAX, BUILTIN_HIT_T_NV],
        true,
    )
}

/// `direction × t` with `t` a hit distance (either order, or a splat).
fn is_ray_step(program: &Program, id: Id, chain: &[usize]) -> bool {
    let (src, ch) = program.value_source(id, chain);
    let ops = operand_ids(program, src);
    match opcode(program, src) {
        Some(Op::VectorTimesScalar) => ops.get(1).is_some_and(|&t| is_hit_distance(program, t, ch)),
        Some(Op::FMul) => ops.iter().any(|&x| {
            let (s, sch) = program.value_source(x, ch);
            opcode(program, s) == Some(Op::CompositeConstruct)
                && operand_ids(program, s)
                    .iter()
                    .all(|&c| is_hit_distance(program, c, sch))
        }),
        _ => false,
    }
}

fn origin_kind(program: &Program, id: Id, chain: &[usize], depth: u32) -> Origin {
    if depth > 8 {
        return Origin::Other;
    }
    let (src, ch) = program.value_source(id, chain);
    let ops = operand_ids(program, src);
    let hit = match opcode(program, src) {
        Some(Op::FAdd) => ops.iter().any(|&x| is_ray_step(program, x, ch)),
        Some(Op::MatrixTimesVector | Op::VectorTimesMatrix) => ops.iter().any(|&x| {
            let (s, sch) = program.value_source(x, ch);
            let s = match opcode(program, s) {
                Some(Op::Transpose) => operand_ids(program, s).first().copied().unwrap_or(s),
                _ => s,
            };
            loads_from(program, s, sch, &[BUILTIN_OBJECT_TO_WORLD], false)
        }),
        // `.xyz` of a hit point.
        Some(Op::VectorShuffle) if ops.len() == 2 && ops[0] == ops[1] => {
            return origin_kind(program, ops[0], ch, depth + 1)
        }
        _ => false,
    };
    if hit {
        Origin::HitPoint
    } else {
        Origin::Other
    }
}

/// What a vector is, for matching `normalize(v)` with `length(v)`: the
/// value it comes from, or the local variable it is loaded from.
fn identity(program: &Program, id: Id, chain: &[usize]) -> Id {
    let (src, _) = program.value_source(id, chain);
    match program.def(src) {
        Some(i) if i.class.opcode == Op::Load => match i.operands.first() {
            Some(Operand::IdRef(p)) => *p,
            _ => src,
        },
        _ => src,
    }
}

/// A `length(v)` or `distance(a, b)` beside a direction `normalize(v)`,
/// `normalize(b - a)` or `v / length(v)`.
fn bound(program: &Program, dir: Id, chain: &[usize], function: usize) -> Option<Bound> {
    let (src, ch) = program.value_source(dir, chain);
    let ops = operand_ids(program, src);
    // The vector normalised, by identity.
    let v = if glsl_op(program, src) == Some(GLSL_NORMALIZE) {
        *ops.get(1)?
    } else if opcode(program, src) == Some(Op::FDiv) {
        // v / length(v), the divisor possibly splatted.
        let (d, dch) = program.value_source(*ops.get(1)?, ch);
        let d = match opcode(program, d) {
            Some(Op::CompositeConstruct) => {
                program
                    .value_source(*operand_ids(program, d).first()?, dch)
                    .0
            }
            _ => d,
        };
        if glsl_op(program, d) != Some(GLSL_LENGTH) {
            return None;
        }
        return Some(Bound {
            location: program.inst_location(*program.defs.get(&d)?),
        });
    } else {
        return None;
    };
    let want = identity(program, v, ch);
    // `b - a` for a distance.
    let (vs, vch) = program.value_source(v, ch);
    let pair: Option<(Id, Id)> = match (opcode(program, vs), operand_ids(program, vs).as_slice()) {
        (Some(Op::FSub), [a, b]) => Some((identity(program, *a, vch), identity(program, *b, vch))),
        _ => None,
    };
    // Search the trace's function and every function of the chain.
    let mut fns: Vec<usize> = vec![function];
    fns.extend(chain.iter().filter_map(|&c| program.function_of(c)));
    for fi in fns {
        let Some(f) = program.functions.get(fi) else {
            continue;
        };
        for k in f.start..=f.end {
            let Some(rid) = program.insts[k].result_id else {
                continue;
            };
            let args: Vec<Id> = operand_ids(program, rid).into_iter().skip(1).collect();
            let hit = match glsl_op(program, rid) {
                Some(GLSL_LENGTH) => args
                    .first()
                    .is_some_and(|&a| identity(program, a, &[]) == want),
                Some(GLSL_DISTANCE) => match (pair, args.as_slice()) {
                    (Some((x, y)), [a, b]) => {
                        let (a, b) = (identity(program, *a, &[]), identity(program, *b, &[]));
                        (a, b) == (x, y) || (a, b) == (y, x)
                    }
                    _ => false,
                },
                _ => false,
            };
            if hit {
                return Some(Bound {
                    location: program.inst_location(k),
                });
            }
        }
    }
    None
}

/// What one shader does with the payload it is invoked with.
#[derive(Clone, Debug, Default)]
pub struct PayloadUse {
    /// The incoming payload's type, when the shader declares one.
    pub ty: Option<Id>,
    /// Member paths (first index; empty for the whole payload) written with
    /// a constant.
    pub constant_writes: BTreeSet<Vec<u32>>,
    /// Whether any write stores a computed value (or copies memory in).
    pub computed_writes: bool,
    /// Whether the shader traces rays or executes callables.
    pub traces: bool,
}

impl PayloadUse {
    /// Writes only constants (or nothing), traces nothing: it can only
    /// record that the ray hit or missed.
    pub fn records_only(&self) -> bool {
        !self.computed_writes && !self.traces
    }
}

/// How shader `function` of `program` uses its incoming payload.
pub fn payload_use(program: &Program, function: Id) -> PayloadUse {
    let mut u = PayloadUse::default();
    let reach = program.reachable_functions(function);
    for fid in &reach {
        let Some(f) = program.function(*fid) else {
            continue;
        };
        for k in f.start..=f.end {
            let inst = &program.insts[k];
            if program.is_debug_inst(inst) {
                continue;
            }
            match inst.class.opcode {
                Op::TraceRayKHR | Op::TraceNV | Op::ExecuteCallableKHR | Op::ExecuteCallableNV => {
                    u.traces = true
                }
                Op::Store | Op::CopyMemory | Op::CopyMemorySized => {
                    let Some(Operand::IdRef(ptr)) = inst.operands.first() else {
                        continue;
                    };
                    let root = program.pointer_root(*ptr);
                    if program.storage_of(root) != Some(StorageClass::IncomingRayPayloadKHR) {
                        continue;
                    }
                    u.ty =
                        program.def(root).and_then(|d| d.result_type).and_then(|t| {
                            match program.ty(t) {
                                Some(Type::Pointer { pointee, .. }) => Some(*pointee),
                                _ => None,
                            }
                        });
                    let path = member_path(program, *ptr);
                    let constant = inst.class.opcode == Op::Store
                        && match inst.operands.get(1) {
                            Some(Operand::IdRef(v)) => {
                                program.fold(*v).is_some()
                                    || program.fold_floats_in(*v, &[]).is_some()
                            }
                            _ => false,
                        };
                    if constant {
                        u.constant_writes.insert(path);
                    } else {
                        u.computed_writes = true;
                    }
                }
                _ => {}
            }
        }
    }
    if u.ty.is_none() {
        u.ty = program
            .globals_in(StorageClass::IncomingRayPayloadKHR)
            .find(|g| {
                program
                    .entry_points
                    .iter()
                    .find(|e| e.function == function)
                    .is_some_and(|e| e.interface.is_empty() || e.interface.contains(&g.id))
            })
            .map(|g| g.ty);
    }
    u
}

/// The first constant index of an access chain into a payload (empty for
/// the whole payload).
fn member_path(program: &Program, ptr: Id) -> Vec<u32> {
    let mut cur = ptr;
    let mut first = None;
    for _ in 0..32 {
        let Some(i) = program.def(cur) else { break };
        if !matches!(i.class.opcode, Op::AccessChain | Op::InBoundsAccessChain) {
            break;
        }
        first = match i.operands.get(1) {
            Some(Operand::IdRef(x)) => program.const_u64(*x).map(|v| v as u32),
            _ => None,
        }
        .or(Some(u32::MAX));
        match i.operands.first() {
            Some(Operand::IdRef(b)) => cur = *b,
            _ => break,
        }
    }
    first.map(|f| vec![f]).unwrap_or_default()
}

/// A trace whose every reachable shader can only record hit or miss.
#[derive(Clone, Debug)]
pub struct VisibilityTrace {
    pub program: usize,
    pub inst: usize,
    pub location: Option<Location>,
    /// The flags every choice sets (all of them when the flags are one
    /// constant).
    pub flags: u64,
    /// The constants the flags may be (one, or a choice on branches).
    pub flag_choices: Vec<u64>,
    /// The payload variable's type.
    pub payload_ty: Option<Id>,
    /// Entry points of the closest-hit shaders it runs.
    pub closest_hits: Vec<String>,
    /// Closest-hit shaders it runs that write the payload.
    pub recording_closest_hits: usize,
    /// Members written by the shaders it reaches.
    pub written: BTreeSet<Vec<u32>>,
}

/// Trace sites and what they reach, grouped per (caller, site).
pub struct TraceTargets {
    pub from: usize,
    pub program: usize,
    pub inst: usize,
    pub location: Option<Location>,
    pub targets: Vec<usize>,
}

/// The trace edges of a graph grouped by site and caller (without the
/// fallback edges that only count a level).
pub fn trace_targets(graph: &TraceGraph) -> Vec<TraceTargets> {
    let mut out: Vec<TraceTargets> = Vec::new();
    // (from, program, inst) → index in `out`, which keeps first-seen order.
    let mut index = std::collections::HashMap::new();
    for e in graph
        .edges
        .iter()
        .filter(|e| e.kind == EdgeKind::Trace && !e.fallback)
    {
        match index.get(&(e.from, e.program, e.inst)) {
            Some(&i) => {
                let t: &mut TraceTargets = &mut out[i];
                t.targets.push(e.to)
            }
            None => {
                index.insert((e.from, e.program, e.inst), out.len());
                out.push(TraceTargets {
                    from: e.from,
                    program: e.program,
                    inst: e.inst,
                    location: e.location.clone(),
                    targets: vec![e.to],
                })
            }
        }
    }
    out
}

/// The constant ray flags of the trace at `inst` as `from` reaches it.
pub fn trace_flags(pipeline: &Pipeline, graph: &TraceGraph, t: &TraceTargets) -> Option<u64> {
    let shader = &graph.nodes.get(t.from)?.shader;
    let program = pipeline.programs.get(t.program)?;
    let site = program.sites.iter().find(|s| s.inst == t.inst)?;
    let f = program.functions.get(site.function)?;
    let chain = crate::program::cfg::call_chains(program, shader.function, f.id, 1)
        .into_iter()
        .next()
        .unwrap_or_default();
    let ops = program.trace_operands_in(site, &chain).or(site.trace)?;
    ops.ray_flags.constant()
}

/// The constants the ray flags of the trace at `inst` may be as `from`
/// reaches it (one when they fold; a `select`, phi or variable assigned on
/// branches gives several: see `Program::fold_choices_in`).
pub fn trace_flag_choices(
    pipeline: &Pipeline,
    graph: &TraceGraph,
    t: &TraceTargets,
) -> Option<Vec<u64>> {
    if let Some(f) = trace_flags(pipeline, graph, t) {
        return Some(vec![f]);
    }
    let shader = &graph.nodes.get(t.from)?.shader;
    let program = pipeline.programs.get(t.program)?;
    let site = program.sites.iter().find(|s| s.inst == t.inst)?;
    let f = program.functions.get(site.function)?;
    let chain = crate::program::cfg::call_chains(program, shader.function, f.id, 1)
        .into_iter()
        .next()
        .unwrap_or_default();
    let id = match program.insts[site.inst].operands.get(1) {
        Some(rspirv::dr::Operand::IdRef(x)) => *x,
        _ => return None,
    };
    program.fold_choices_in(id, &chain)
}

/// The `IncomingRayPayloadKHR` variable shader `function` uses (the first
/// a function it reaches names), if any.
pub fn incoming_payload_var(program: &Program, function: Id) -> Option<Id> {
    let incoming: Vec<Id> = program
        .globals_in(StorageClass::IncomingRayPayloadKHR)
        .map(|g| g.id)
        .collect();
    if incoming.is_empty() {
        return None;
    }
    let reached = program.reached_functions(function);
    program
        .functions
        .iter()
        .enumerate()
        .filter(|(k, _)| reached.get(*k).copied().unwrap_or(false))
        .flat_map(|(_, f)| program.insts[f.start..=f.end].iter())
        .flat_map(|inst| inst.operands.iter())
        .find_map(|o| match o {
            Operand::IdRef(x) if incoming.contains(x) => Some(*x),
            _ => None,
        })
}

/// A trace site: index of the program, of the instruction, and where it is.
pub type TraceSite = (usize, usize, Option<Location>);

/// The traces whose SBT operands select hit or miss shaders (graph nodes)
/// that the reach analysis left out because their incoming payload differs:
/// per site (program, instruction, its location), those shaders. Only with
/// a description: a folder's loose pipeline joins every trace to every
/// shader, so a shader with another payload there is another ray type, not
/// a mismatch (and pairing by the GLSL `layout(location)` would need the
/// source, which SPIR-V without debug info does not carry).
pub fn mismatched_targets(pipeline: &Pipeline, graph: &TraceGraph) -> Vec<(TraceSite, Vec<usize>)> {
    let mut out: Vec<(TraceSite, Vec<usize>)> = Vec::new();
    if !pipeline.described() {
        return out;
    }
    // A trace no miss shader takes keeps the refused ones as fallback edges
    // (its level counts): those differ too.
    let refused = graph.edges.iter().filter(|e| e.fallback);
    for e in graph.mismatched.iter().chain(refused) {
        if !matches!(
            graph.nodes[e.to].shader.stage,
            Stage::ClosestHit | Stage::AnyHit | Stage::Miss
        ) {
            continue;
        }
        match out
            .iter_mut()
            .find(|(k, _)| k.0 == e.program && k.1 == e.inst)
        {
            Some((_, v)) if !v.contains(&e.to) => v.push(e.to),
            Some(_) => {}
            None => out.push(((e.program, e.inst, e.location.clone()), vec![e.to])),
        }
    }
    out
}

/// The payload type a trace passes.
pub fn trace_payload_ty(program: &Program, inst: usize) -> Option<Id> {
    let site = program.sites.iter().find(|s| s.inst == inst)?;
    let var = site.payload?;
    match program.ty(program.def(var)?.result_type?)? {
        Type::Pointer { pointee, .. } => Some(*pointee),
        _ => None,
    }
}

/// Traces of a pipeline that are visibility tests, over the shaders each
/// reaches (the reach analysis leaves out those whose incoming payload
/// differs from the trace's).
pub fn visibility_traces(pipeline: &Pipeline, graph: &TraceGraph) -> Vec<VisibilityTrace> {
    let mut out = Vec::new();
    // Per shader, not per trace and target: a folder's loose pipeline joins
    // every trace to every hit shader.
    let mut uses: std::collections::HashMap<(usize, Id), PayloadUse> =
        std::collections::HashMap::new();
    for t in trace_targets(graph) {
        let Some(program) = pipeline.programs.get(t.program) else {
            continue;
        };
        let Some(flag_choices) = trace_flag_choices(pipeline, graph, &t) else {
            continue;
        };
        let flags = flag_choices.iter().fold(u64::MAX, |a, &f| a & f);
        let payload_ty = trace_payload_ty(program, t.inst);
        let mut written = BTreeSet::new();
        let mut closest_hits = Vec::new();
        let mut recording = 0;
        let mut visibility = true;
        let mut any_writer = false;
        for &n in &t.targets {
            let node = &graph.nodes[n];
            let Some(callee) = pipeline.program(&node.shader) else {
                visibility = false;
                break;
            };
            let u = uses
                .entry((node.shader.program, node.shader.function))
                .or_insert_with(|| payload_use(callee, node.shader.function));
            if node.shader.stage == Stage::Intersection {
                continue;
            }
            if !u.records_only() {
                visibility = false;
                break;
            }
            if !u.constant_writes.is_empty() {
                any_writer = true;
            }
            written.extend(u.constant_writes.iter().cloned());
            if node.shader.stage == Stage::ClosestHit {
                closest_hits.push(node.shader.entry.clone());
                if !u.constant_writes.is_empty() {
                    recording += 1;
                }
            }
        }
        // Without a description, a trace that can run closest-hit shaders
        // but reaches none may be missing its own (a shader of the folder
        // that could not be read): do not judge it, unless the folder has
        // closest-hit shaders, none takes this payload, and a miss shader
        // does (a shadow ray type, whose hit group often has no closest hit).
        let skips_closest_hit = flags & flags::SKIP_CLOSEST_HIT != 0;
        let own_miss = pipeline.hit_groups.iter().any(|g| g.closest_hit.is_some())
            && t.targets
                .iter()
                .any(|&n| graph.nodes[n].shader.stage == Stage::Miss);
        if !visibility
            || !any_writer
            || (!pipeline.described() && !skips_closest_hit && closest_hits.is_empty() && !own_miss)
        {
            continue;
        }
        out.push(VisibilityTrace {
            program: t.program,
            inst: t.inst,
            location: t.location.clone(),
            flags,
            flag_choices,
            payload_ty,
            closest_hits,
            recording_closest_hits: recording,
            written,
        });
    }
    out
}

/// The hit groups a trace's reached nodes belong to.
pub fn reached_groups(graph: &TraceGraph, t: &TraceTargets) -> BTreeSet<usize> {
    t.targets
        .iter()
        .filter_map(|&n| match graph.nodes[n].slot {
            Slot::HitGroup(g) => Some(g),
            _ => None,
        })
        .collect()
}

/// Whether every group in `groups` is procedural (and there is one).
pub fn all_procedural(pipeline: &Pipeline, groups: &BTreeSet<usize>) -> bool {
    !groups.is_empty()
        && groups.iter().all(|&g| {
            pipeline
                .hit_groups
                .get(g)
                .is_some_and(|h| h.kind == HitGroupKind::Procedural)
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shader::Language;
    use std::path::Path;

    fn load(rel: &str, language: Language) -> Program {
        crate::front::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel), language).unwrap()
    }

    /// HLSL's `RayDesc` is written member by member into a local; the
    /// interval folds through it, the origin is the hit point, and the
    /// direction `l / length(l)` is bounded by that length.
    #[test]
    fn hlsl_ray_desc_members_fold() {
        let p = load("fixtures/RT034/bad.hlsl", Language::Hlsl);
        let r = rays(&p);
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!(r[0].tmin, Some(f64::from(0.001f32)));
        assert_eq!(r[0].tmax, Some(f64::from(1e30f32)));
        assert_eq!(r[0].origin, Origin::HitPoint);
        assert_eq!(r[0].flags, Some(0xC));
        let bound = r[0].bound.as_ref().and_then(|b| b.location.as_ref());
        assert_eq!(bound.map(|l| l.line), Some(11));
    }

    /// naga passes the `RayDesc` to a helper per trace: values fold through
    /// the call chain; an offset origin is not a bare hit point.
    #[test]
    fn wgsl_helper_parameters_fold_per_call() {
        let p = load("fixtures/RT033/bad.wgsl", Language::Wgsl);
        let r = rays(&p);
        assert_eq!(r.len(), 1, "{r:?}");
        assert_eq!((r[0].tmin, r[0].origin), (Some(0.0), Origin::HitPoint));
        let p = load("fixtures/RT036/bad.wgsl", Language::Wgsl);
        assert_eq!(rays(&p)[0].direction, Some(vec![0.0, 0.0, 0.0]));
        let p = load("fixtures/RT033/good.hlsl", Language::Hlsl);
        assert_eq!(rays(&p)[0].origin, Origin::Other);
    }

    /// The shadow trace reaches the shadow closest hit (it only stores 1)
    /// and not the radiance shaders, whose payload type differs; the
    /// radiance trace is no visibility test.
    #[test]
    fn visibility_traces_by_payload_type() {
        let p = load("fixtures/RT031/bad.hlsl", Language::Hlsl);
        let pipeline = Pipeline::from_programs(vec![p]);
        let g = super::super::callgraph::trace_graph(&pipeline);
        let v = visibility_traces(&pipeline, &g);
        assert_eq!(v.len(), 1, "{v:?}");
        assert_eq!(v[0].closest_hits, ["ShadowHit"]);
        assert_eq!(v[0].recording_closest_hits, 1);
        assert_eq!(v[0].flags, flags::TERMINATE_ON_FIRST_HIT);
        assert_eq!(v[0].written.len(), 1);
    }
}
