//! Ray queries: each ray-query object of a module with the instructions
//! that initialise it, advance it (`Proceed`), commit candidates and read its
//! intersections, the ray flags of each initialisation (folded per call
//! chain), and two must-facts along every path of a function: whether the
//! query is initialised at a `Proceed`, and whether it has proceeded since
//! its last initialisation at a read of the committed intersection.

use crate::program::cfg;
use crate::program::{Id, Program};
use rspirv::dr::Operand;
use spirv::{Op, StorageClass};
use std::collections::HashSet;

/// `gl_RayFlagsOpaqueEXT` / `RAY_FLAG_FORCE_OPAQUE`.
pub const FLAG_OPAQUE: u64 = 0x1;
/// `RAY_FLAG_CULL_NON_OPAQUE`.
pub const FLAG_CULL_NO_OPAQUE: u64 = 0x80;
/// `RAY_FLAG_SKIP_TRIANGLES`.
pub const FLAG_SKIP_TRIANGLES: u64 = 0x100;
/// `RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES`.
pub const FLAG_SKIP_AABBS: u64 = 0x200;

/// How many call chains are followed to fold an initialisation's flags.
const MAX_CHAINS: usize = 16;

/// One ray-query object and what the module does with it.
#[derive(Clone, Debug, Default)]
pub struct Query {
    /// The variable holding it (a function parameter when no caller passes one).
    pub var: Id,
    /// Instruction indices of each kind of use.
    pub inits: Vec<usize>,
    pub proceeds: Vec<usize>,
    pub confirms: Vec<usize>,
    pub generates: Vec<usize>,
    /// Reads of the committed intersection (`Intersection` operand 1).
    pub committed_reads: Vec<usize>,
    /// The ray flags of each initialisation: every value the call chains
    /// reaching it fold to, `None` where one does not fold.
    pub init_flags: Vec<Vec<Option<u64>>>,
}

impl Query {
    /// Whether every initialisation's flags are known constants.
    pub fn flags_known(&self) -> bool {
        !self.inits.is_empty() && self.init_flags.iter().flatten().all(Option::is_some)
    }

    /// Known flag values (one per initialisation and call chain).
    pub fn known_flags(&self) -> impl Iterator<Item = u64> + '_ {
        self.init_flags.iter().flatten().flatten().copied()
    }

    /// The first initialisation whose flags do not contain any of `bits`.
    pub fn init_without(&self, bits: u64) -> Option<usize> {
        self.inits
            .iter()
            .zip(&self.init_flags)
            .find(|(_, fl)| fl.iter().any(|f| f.is_some_and(|f| f & bits == 0)))
            .map(|(i, _)| *i)
    }
}

/// The ray-query objects of `p`, in order of their first use: computed once
/// per Program, since five rules ask.
pub fn queries(p: &Program) -> std::sync::Arc<Vec<Query>> {
    struct Queries(std::sync::Arc<Vec<Query>>);
    p.memo
        .get_or(|| Queries(std::sync::Arc::new(find_queries(p))))
        .0
        .clone()
}

fn find_queries(p: &Program) -> Vec<Query> {
    let mut out: Vec<Query> = Vec::new();
    for (i, inst) in p.insts.iter().enumerate() {
        let op = inst.class.opcode;
        if !crate::program::is_ray_query_op(op) {
            continue;
        }
        let Some(Operand::IdRef(ptr)) = inst.operands.first() else {
            continue;
        };
        for root in roots(p, *ptr) {
            let k = match out.iter().position(|q| q.var == root) {
                Some(k) => k,
                None => {
                    out.push(Query {
                        var: root,
                        ..Query::default()
                    });
                    out.len() - 1
                }
            };
            let q = &mut out[k];
            match op {
                Op::RayQueryInitializeKHR => {
                    q.inits.push(i);
                    q.init_flags.push(init_flags(p, i, root));
                }
                Op::RayQueryProceedKHR => q.proceeds.push(i),
                Op::RayQueryConfirmIntersectionKHR => q.confirms.push(i),
                Op::RayQueryGenerateIntersectionKHR => q.generates.push(i),
                _ if is_committed_read(p, i) => q.committed_reads.push(i),
                _ => {}
            }
        }
    }
    out
}

/// Whether instruction `i` reads the committed intersection of a query.
fn is_committed_read(p: &Program, i: usize) -> bool {
    let inst = &p.insts[i];
    let with_intersection = matches!(
        inst.class.opcode,
        Op::RayQueryGetIntersectionTypeKHR
            | Op::RayQueryGetIntersectionTKHR
            | Op::RayQueryGetIntersectionInstanceCustomIndexKHR
            | Op::RayQueryGetIntersectionInstanceIdKHR
            | Op::RayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetKHR
            | Op::RayQueryGetIntersectionGeometryIndexKHR
            | Op::RayQueryGetIntersectionPrimitiveIndexKHR
            | Op::RayQueryGetIntersectionBarycentricsKHR
            | Op::RayQueryGetIntersectionFrontFaceKHR
            | Op::RayQueryGetIntersectionObjectRayDirectionKHR
            | Op::RayQueryGetIntersectionObjectRayOriginKHR
            | Op::RayQueryGetIntersectionObjectToWorldKHR
            | Op::RayQueryGetIntersectionWorldToObjectKHR
    );
    with_intersection
        && matches!(inst.operands.get(1), Some(Operand::IdRef(k)) if p.fold(*k) == Some(1))
}

/// The flags operand of initialisation `i` of the query variable `root`,
/// folded along every call chain from an entry point that passes through
/// the function declaring `root` (or as is, when none reaches it). naga
/// initialises every query in one generated helper: the flags other queries
/// pass to it are not this one's.
fn init_flags(p: &Program, i: usize, root: Id) -> Vec<Option<u64>> {
    let Some(Operand::IdRef(flags)) = p.insts[i].operands.get(2) else {
        return vec![None];
    };
    if let Some(v) = p.fold(*flags) {
        return vec![Some(v)];
    }
    let Some(f) = p.function_of(i).and_then(|f| p.functions.get(f)) else {
        return vec![None];
    };
    let home = p
        .defs
        .get(&root)
        .and_then(|&d| p.function_of(d))
        .map(|k| p.functions[k].id);
    let mut vals = Vec::new();
    for e in &p.entry_points {
        for chain in cfg::call_chains(p, e.function, f.id, MAX_CHAINS) {
            let through_home = home.is_none_or(|h| {
                e.function == h
                    || chain
                        .iter()
                        .any(|&c| p.function_of(c).map(|k| p.functions[k].id) == Some(h))
            });
            if through_home {
                vals.push(p.fold_in(*flags, &chain));
            }
        }
    }
    if vals.is_empty() {
        vals.push(None);
    }
    vals
}

/// The variables a ray-query pointer can name: through access chains and
/// copies to its `OpVariable`, through function parameters to what each
/// caller passes.
pub fn roots(p: &Program, ptr: Id) -> Vec<Id> {
    let mut out = Vec::new();
    let mut seen = HashSet::new();
    let mut work = vec![ptr];
    while let Some(id) = work.pop() {
        if !seen.insert(id) {
            continue;
        }
        let Some(&at) = p.defs.get(&id) else {
            continue;
        };
        let inst = &p.insts[at];
        match inst.class.opcode {
            Op::AccessChain | Op::InBoundsAccessChain | Op::CopyObject => {
                if let Some(Operand::IdRef(base)) = inst.operands.first() {
                    work.push(*base);
                }
            }
            Op::FunctionParameter => {
                let Some(f) = p.function_of(at).and_then(|f| p.functions.get(f)) else {
                    continue;
                };
                let Some(k) = f.params.iter().position(|&x| x == id) else {
                    continue;
                };
                let calls = p.callers(f.id);
                if calls.is_empty() {
                    out.push(id);
                }
                for c in calls {
                    if let Some(Operand::IdRef(arg)) = p.insts[c].operands.get(1 + k) {
                        work.push(*arg);
                    }
                }
            }
            _ => out.push(id),
        }
    }
    out.sort_unstable();
    out
}

/// What a must-fact tracks along the paths of one function.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum PathFact {
    /// The query has been initialised (`rayQueryInitializeEXT`, `TraceRayInline`).
    Initialised,
    /// The query has proceeded at least once since its last initialisation.
    Proceeded,
}

/// The instructions among `at` (indices of uses of `q`) reached on some path
/// of their function where `fact` does not hold. A call whose callee (or a
/// function it calls) initialises or advances the query counts as doing so
/// (naga wraps each ray-query operation in such a helper); a function that
/// did not declare the query itself is not judged.
pub fn reached_without(p: &Program, q: &Query, fact: PathFact, at: &[usize]) -> Vec<usize> {
    let decl = p.defs.get(&q.var).copied();
    let storage = decl.and_then(|d| match p.insts[d].operands.first() {
        Some(Operand::StorageClass(s)) if p.insts[d].class.opcode == Op::Variable => Some(*s),
        _ => None,
    });
    let mut out = Vec::new();
    for (fi, f) in p.functions.iter().enumerate() {
        // At entry the fact fails only where the query starts afresh.
        let fresh = match storage {
            Some(StorageClass::Function) => decl.and_then(|d| p.function_of(d)) == Some(fi),
            Some(StorageClass::Private) => p.entry_points.iter().any(|e| e.function == f.id),
            _ => false,
        };
        // Asked first: finding the uses below costs a walk of the function.
        if !fresh {
            continue;
        }
        // The uses in this function, and the calls that reach one.
        let here: Vec<usize> = (f.start..=f.end)
            .filter(|&i| {
                at.contains(&i)
                    || (p.insts[i].class.opcode == Op::FunctionCall
                        && matches!(p.insts[i].operands.first(), Some(Operand::IdRef(c)) if {
                            // A callee that establishes the fact itself is trusted to
                            // do so before its own uses.
                            let funcs = p.reachable_functions(*c);
                            let (inits, proceeds) = callee_effects(p, q, *c);
                            let own = match fact {
                                PathFact::Initialised => inits,
                                PathFact::Proceeded => proceeds,
                            };
                            !own && at.iter().any(|a| p.function_of(*a).is_some_and(|g| funcs.contains(&p.functions[g].id)))
                        }))
            })
            .collect();
        if here.is_empty() || f.blocks.is_empty() {
            continue;
        }
        let names_query = |id: Id| roots(p, id).contains(&q.var);
        // Transfer over instructions start..=end from state `s`; records misses.
        let step = |s: bool, from: usize, to: usize, misses: Option<&mut Vec<usize>>| -> bool {
            let mut s = s;
            let mut misses = misses;
            for i in from..=to {
                let inst = &p.insts[i];
                let op = inst.class.opcode;
                // `here` lists instructions in order.
                if !s && here.binary_search(&i).is_ok() {
                    if let Some(m) = misses.as_deref_mut() {
                        m.push(i);
                    }
                }
                let on_q =
                    || matches!(inst.operands.first(), Some(Operand::IdRef(x)) if names_query(*x));
                match op {
                    Op::RayQueryInitializeKHR if on_q() => {
                        s = fact == PathFact::Initialised;
                    }
                    Op::RayQueryProceedKHR if fact == PathFact::Proceeded && on_q() => {
                        s = true;
                    }
                    Op::FunctionCall => {
                        let (inits, proceeds) = match inst.operands.first() {
                            Some(Operand::IdRef(callee)) => callee_effects(p, q, *callee),
                            _ => (false, false),
                        };
                        match fact {
                            PathFact::Initialised => s |= inits,
                            PathFact::Proceeded if proceeds => s = true,
                            PathFact::Proceeded if inits => s = false,
                            PathFact::Proceeded => {}
                        }
                    }
                    _ => {}
                }
            }
            s
        };
        let n = f.blocks.len();
        let mut preds = vec![Vec::new(); n];
        for (b, blk) in f.blocks.iter().enumerate() {
            let skip = bound_exit(p, f, b);
            for &s in &blk.succs {
                if s < n && Some(s) != skip {
                    preds[s].push(b);
                }
            }
        }
        // Must-analysis: out[b] starts true (top) except at the entry.
        let mut outs = vec![true; n];
        let in_of = |b: usize, outs: &[bool]| -> bool {
            if b == 0 {
                false
            } else {
                preds[b].iter().all(|&q| outs[q])
            }
        };
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds < 4 * n + 8 {
            changed = false;
            rounds += 1;
            for b in 0..n {
                let blk = &f.blocks[b];
                let o = step(in_of(b, &outs), blk.start, blk.end, None);
                if o != outs[b] {
                    outs[b] = o;
                    changed = true;
                }
            }
        }
        let reachable = reachable_blocks(f);
        for b in 0..n {
            if !reachable.contains(&b) {
                continue;
            }
            let blk = &f.blocks[b];
            step(in_of(b, &outs), blk.start, blk.end, Some(&mut out));
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The exit edge of a loop-bounding check that cannot be taken in a loop's
/// first iteration: naga guards every loop with a counter variable
/// initialised to a constant, `if all(counter == C) { break; }`, and the exit
/// is taken only after the counter has run down (never in practice). The
/// must-facts ignore it, so a `while (Proceed)` loop of WGSL counts as
/// proceeding.
fn bound_exit(p: &Program, f: &crate::program::Function, b: usize) -> Option<usize> {
    let blk = &f.blocks[b];
    let term = &p.insts[blk.end];
    let (Op::BranchConditional, [Operand::IdRef(cond), Operand::IdRef(yes), ..]) =
        (term.class.opcode, term.operands.as_slice())
    else {
        return None;
    };
    let all = p.def(*cond)?;
    let test = match (all.class.opcode, all.operands.as_slice()) {
        (Op::All, [Operand::IdRef(x)]) => p.def(*x)?,
        _ => return None,
    };
    let [Operand::IdRef(a), Operand::IdRef(c)] = test.operands.as_slice() else {
        return None;
    };
    if test.class.opcode != Op::IEqual {
        return None;
    }
    let (k, load) = if p.constants.contains_key(a) {
        (a, c)
    } else {
        (c, a)
    };
    let load = p.def(*load)?;
    let Some(Operand::IdRef(var)) = load.operands.first() else {
        return None;
    };
    let var = p.def(*var)?;
    match (load.class.opcode, var.class.opcode, var.operands.as_slice()) {
        (Op::Load, Op::Variable, [_, Operand::IdRef(init)])
            if p.constants.contains_key(init) && p.constants.get(init) != p.constants.get(k) =>
        {
            f.block_by_label(*yes)
        }
        _ => None,
    }
}

/// Whether function `callee` or a function it calls initialises, and
/// whether one advances, query `q`.
fn callee_effects(p: &Program, q: &Query, callee: Id) -> (bool, bool) {
    let funcs = p.reachable_functions(callee);
    let inside = |i: &usize| {
        p.function_of(*i)
            .is_some_and(|f| funcs.contains(&p.functions[f].id))
    };
    (q.inits.iter().any(inside), q.proceeds.iter().any(inside))
}

fn reachable_blocks(f: &crate::program::Function) -> HashSet<usize> {
    let mut seen = HashSet::new();
    let mut work = vec![0usize];
    while let Some(b) = work.pop() {
        if b < f.blocks.len() && seen.insert(b) {
            work.extend(f.blocks[b].succs.iter().copied());
        }
    }
    seen
}

/// Whether instruction `i` repeats without passing any of `resets`: it sits
/// in a natural loop of its function that holds none of them, or in a
/// function called (transitively) from inside such a loop. With the query's
/// initialisations as `resets`, a `Proceed` in a loop that also initialises
/// the query each iteration is a single `Proceed`.
pub fn in_loop(p: &Program, i: usize, resets: &[usize]) -> bool {
    let mut seen = HashSet::new();
    let mut work = vec![i];
    while let Some(i) = work.pop() {
        if !seen.insert(i) || seen.len() > 256 {
            continue;
        }
        let Some(f) = p.function_of(i).and_then(|f| p.functions.get(f)) else {
            continue;
        };
        let Some(b) = f.block_of(i) else { continue };
        // Blocks that reset: holding one of `resets`, or a call that reaches one.
        let reset_blocks: Vec<usize> = (f.start..=f.end)
            .filter(|&k| {
                resets.contains(&k)
                    || (p.insts[k].class.opcode == Op::FunctionCall
                        && matches!(p.insts[k].operands.first(), Some(Operand::IdRef(c)) if {
                            let funcs = p.reachable_functions(*c);
                            resets.iter().any(|r| {
                                p.function_of(*r)
                                    .is_some_and(|g| funcs.contains(&p.functions[g].id))
                            })
                        }))
            })
            .filter_map(|k| f.block_of(k))
            .collect();
        if cfg::natural_loops(f)
            .iter()
            .any(|(_, body)| body.contains(&b) && !reset_blocks.iter().any(|r| body.contains(r)))
        {
            return true;
        }
        // Each call of a function that initialises the query starts afresh.
        if reset_blocks.is_empty() {
            work.extend(p.callers(f.id));
        }
    }
    false
}
