//! Values live across ray-tracing calls.
//!
//! A driver suspends the shader at every `OpTraceRayKHR` and
//! `OpExecuteCallableKHR` (and an inline ray query's `OpRayQueryProceedKHR`
//! loop keeps its state in registers around traversal): whatever the shader
//! still needs afterwards must be kept, usually spilled to the ray stack.
//! This module finds those values.
//!
//! Two kinds of state are tracked, both by backward dataflow over the CFG:
//! SSA values (defined before, used after, phis counted on their incoming
//! edge) and the contents of function-local variables (stored before on some
//! path, loaded after before being overwritten as a whole). A trace inside a
//! called function (naga wraps every `traceRay` in a helper) makes the
//! caller's live values live across it too, so each site is expanded along
//! each call chain from an entry point.

use super::bitset::BitSet;
use crate::diag::Location;
use crate::program::cfg::call_chains;
use crate::program::scalar::scalar_size;
use crate::program::{Constant, Function, Id, Program, SiteKind, Type};
use crate::shader::Stage;
use body::Body;
use rspirv::dr::{Instruction, Operand};
use spirv::{Op, StorageClass};
use std::cell::RefCell;
use std::collections::VecDeque;

// Ids and small paths hash far faster with Fx than with SipHash, and no
// input here is adversarial to a hash table (a module's ids are its own).
type HashMap<K, V> = rustc_hash::FxHashMap<K, V>;
type HashSet<T> = rustc_hash::FxHashSet<T>;
use std::path::PathBuf;

mod body;
mod private;
use private::PrivateUse;

/// What suspends the shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LiveSiteKind {
    TraceRay,
    ExecuteCallable,
    RayQuery,
}

impl LiveSiteKind {
    pub fn as_str(self) -> &'static str {
        match self {
            LiveSiteKind::TraceRay => "trace_ray",
            LiveSiteKind::ExecuteCallable => "execute_callable",
            LiveSiteKind::RayQuery => "ray_query",
        }
    }
}

/// Whether a live value is an SSA value or a variable's contents.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Storage {
    Ssa,
    Variable,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct LiveValue {
    pub name: String,
    pub ty: String,
    /// Bytes under the scalar layout; 0 when the type has no size.
    pub size: u64,
    pub rematerializable: bool,
    pub storage: Storage,
    pub def_line: Option<u32>,
    pub use_line: Option<u32>,
    #[serde(skip)]
    pub id: Id,
    #[serde(skip)]
    pub def: Option<Location>,
    #[serde(skip)]
    pub use_at: Option<Location>,
}

/// The variable a site passes to the callee (payload, callable data, query).
#[derive(Clone, Debug, serde::Serialize)]
pub struct PayloadInfo {
    pub name: String,
    pub ty: String,
    pub size: Option<u64>,
    #[serde(skip)]
    pub id: Id,
}

/// One suspension point, along one call chain from an entry point.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LiveSite {
    pub path: PathBuf,
    pub line: Option<u32>,
    pub column: Option<u32>,
    pub entry: String,
    pub stage: Stage,
    pub kind: LiveSiteKind,
    pub live_bytes: u64,
    pub rematerializable_bytes: u64,
    pub payload: Option<PayloadInfo>,
    pub values: Vec<LiveValue>,
    /// Index of the instruction in `Program::insts`.
    #[serde(skip)]
    pub inst: usize,
    /// The `OpFunctionCall`s leading from the entry point to the site,
    /// outermost first.
    #[serde(skip)]
    pub chain: Vec<usize>,
    #[serde(skip)]
    pub location: Option<Location>,
}

/// `rtlint live`: every site in every program.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LiveReport {
    pub sites: Vec<LiveSite>,
}

/// The live-state report over a set of programs.
pub fn live_report(programs: &[Program]) -> LiveReport {
    LiveReport {
        sites: programs.iter().flat_map(live_sites).collect(),
    }
}

/// Call chains are enumerated up to this many per site; SPIR-V has no
/// recursion, but a helper called from many places multiplies them.
pub(crate) const MAX_CHAINS: usize = 64;

/// The sites of one program with the values live across each (computed
/// once per Program: RT010 and the stack model both ask).
pub fn live_sites(program: &Program) -> Vec<LiveSite> {
    shared_live_sites(program).to_vec()
}

/// [`live_sites`] without copying them out of the Program's memo.
pub(crate) fn shared_live_sites(program: &Program) -> std::sync::Arc<LiveSites> {
    program
        .memo
        .get_or(|| LiveSites(compute_live_sites(program, true)))
}

/// The live sites a Program keeps once computed.
pub struct LiveSites(Vec<LiveSite>);

impl std::ops::Deref for LiveSites {
    type Target = [LiveSite];
    fn deref(&self) -> &[LiveSite] {
        &self.0
    }
}

/// Live sites without what only a reader needs: each value's name, type
/// and positions (first use, definition), the payload's description.
/// Bytes, ids, storage and recomputability are the same as [`LiveSites`]'s.
pub struct LiveBytes(Vec<LiveSite>);

/// The sites the stack model reads: the described ones when something
/// (RT010, `rtlint live`) already computed them, else [`LiveBytes`].
pub enum SitesForBytes {
    Described(std::sync::Arc<LiveSites>),
    Bytes(std::sync::Arc<LiveBytes>),
}

impl std::ops::Deref for SitesForBytes {
    type Target = [LiveSite];
    fn deref(&self) -> &[LiveSite] {
        match self {
            SitesForBytes::Described(s) => &s.0,
            SitesForBytes::Bytes(s) => &s.0,
        }
    }
}

/// The live sites' bytes, ids and recomputability, computed once per
/// Program: the stack model asks for nothing else, and naming, typing and
/// placing each value was about a third of the liveness time.
pub fn shared_live_bytes(program: &Program) -> SitesForBytes {
    match program.memo.get::<LiveSites>() {
        Some(s) => SitesForBytes::Described(s),
        None => SitesForBytes::Bytes(
            program
                .memo
                .get_or(|| LiveBytes(compute_live_sites(program, false))),
        ),
    }
}

/// The live sites; with `described`, each value's name, type and
/// positions and the payload's description too.
fn compute_live_sites(program: &Program, described: bool) -> Vec<LiveSite> {
    // Every site along every chain first: then each function is built
    // knowing the instructions it will be asked about (see `Focus`).
    let mut jobs: Vec<(&crate::program::RtSite, LiveSiteKind, usize, Vec<usize>)> = Vec::new();
    // By function index (a few functions of a program ask).
    let mut asked: Vec<Vec<usize>> = Vec::new();
    asked.resize_with(program.functions.len(), Vec::new);
    for site in &program.sites {
        let kind = match site.kind {
            SiteKind::TraceRay => LiveSiteKind::TraceRay,
            SiteKind::ExecuteCallable => LiveSiteKind::ExecuteCallable,
            SiteKind::RayQuery if site.op == Op::RayQueryProceedKHR => LiveSiteKind::RayQuery,
            _ => continue,
        };
        for (e, entry) in program.entry_points.iter().enumerate() {
            let Some(g) = program.functions.get(site.function) else {
                continue;
            };
            for chain in call_chains(program, entry.function, g.id, MAX_CHAINS) {
                for &p in std::iter::once(&site.inst).chain(chain.iter()) {
                    if let Some(fi) = program.function_of(p) {
                        asked[fi].push(p);
                    }
                }
                jobs.push((site, kind, e, chain));
            }
        }
    }
    // Each function's liveness once built, by function index: `slot` into
    // `built` (an option per function moved the large struct around).
    let mut slot: Vec<u32> = vec![u32::MAX; program.functions.len()];
    let mut built: Vec<FnLiveness> =
        Vec::with_capacity(asked.iter().filter(|a| !a.is_empty()).count());
    let mut shared = Shared::default();
    let mut out = Vec::new();
    // Reused by every level of every site.
    let mut seen: HashSet<Id> = HashSet::default();
    let mut places = SitePlaces::default();
    let mut carried = SitePlaces::default();
    let mut rewritten = SitePlaces::default();
    let mut rewritten_next = SitePlaces::default();
    for (site, kind, e, chain) in jobs {
        let entry = &program.entry_points[e];
        let mut values: Vec<LiveValue> = Vec::new();
        seen.clear();
        // Parts behind the previous level's pointer parameters that
        // it still needs after the site: the caller's memory, counted
        // where the caller passes it.
        carried.clear();
        // The previous level's pointer parameters' parts it writes on
        // every path after the site: the caller's arguments there hold
        // nothing kept across it.
        rewritten.clear();
        // Levels: the site in its own function, then each call upwards.
        for p in std::iter::once(site.inst).chain(chain.iter().rev().copied()) {
            let Some(fi) = program.function_of(p) else {
                continue;
            };
            if slot[fi] == u32::MAX {
                slot[fi] = built.len() as u32;
                built.push({
                    // A function with pointer parameters may be asked
                    // what it does with them too: solved whole, once.
                    let f = &program.functions[fi];
                    let focus = if f.params.iter().any(|&p| is_pointer_param(program, p)) {
                        Focus::all(program, fi)
                    } else {
                        Focus::new(program, fi, &asked[fi])
                    };
                    FnLiveness::shared(program, fi, &mut shared, focus)
                });
            }
            let fl = &built[slot[fi] as usize];
            places.clear();
            fl.places_after(program, p, &mut places);
            fl.drop_rewritten(p, &rewritten, &mut places);
            fl.arguments_of(program, p, &carried, &mut places);
            // A set: sorted, each place once.
            places.sort();
            fl.live_across(program, p, &places, described, |v| {
                if seen.insert(v.id) {
                    values.push(v);
                }
            });
            fl.param_parts_across(program, &places, &mut carried);
            fl.params_written_after(program, p, &rewritten, &mut rewritten_next);
            std::mem::swap(&mut rewritten, &mut rewritten_next);
        }
        // A value parameter (naga passes structs by value) is what the
        // caller passed: recomputable when that is.
        let levels: Vec<usize> = std::iter::once(site.inst)
            .chain(chain.iter().rev().copied())
            .collect();
        for v in values
            .iter_mut()
            .filter(|v| !v.rematerializable && v.storage == Storage::Ssa)
        {
            v.rematerializable = argument_remat(program, &built, &slot, &levels, v.id);
        }
        // A value parameter loaded from a caller's variable that is itself
        // counted whole holds the same value: counted once (naga passes
        // structs by value).
        let same: Vec<Id> = values
            .iter()
            .filter(|v| v.storage == Storage::Ssa)
            .filter_map(|v| {
                let src = argument_source(program, &built, &slot, &levels, v.id)?;
                values
                    .iter()
                    .any(|w| w.id == src && w.storage == Storage::Variable && w.size >= v.size)
                    .then_some(v.id)
            })
            .collect();
        values.retain(|v| !same.contains(&v.id));
        // The query object is the site's own state, like a payload.
        values.retain(|v| Some(v.id) != site.payload);
        // Largest first; what counts before what can be recomputed;
        // names only break the remaining ties, so a module without
        // names lists the same shapes in the same order.
        values.sort_by(|a, b| {
            b.size
                .cmp(&a.size)
                .then(a.rematerializable.cmp(&b.rematerializable))
                .then_with(|| a.name.cmp(&b.name))
        });
        let location = std::iter::once(site.inst)
            .chain(chain.iter().rev().copied())
            .find_map(|i| program.inst_location(i));
        let payload = site
            .payload
            .filter(|_| described)
            .map(|id| payload_info(program, id));
        out.push(LiveSite {
            path: program.path.clone(),
            line: location.as_ref().map(|l| l.line),
            column: location.as_ref().map(|l| l.column),
            entry: entry.name.clone(),
            stage: entry.stage,
            kind,
            live_bytes: values.iter().map(|v| v.size).sum(),
            rematerializable_bytes: values
                .iter()
                .filter(|v| v.rematerializable)
                .map(|v| v.size)
                .sum(),
            payload,
            values,
            inst: site.inst,
            chain,
            location,
        });
    }
    out
}

/// Whether SSA parameter `param` of a function on the site's `levels`
/// (the site, then each call upwards) is recomputable where the call
/// above passes it: the argument there, followed up while it is a
/// parameter itself. `false` for any other value.
fn argument_remat(
    program: &Program,
    built: &[FnLiveness],
    slot: &[u32],
    levels: &[usize],
    mut param: Id,
) -> bool {
    for _ in 0..levels.len() {
        let Some(&d) = program.defs.get(&param) else {
            return false;
        };
        if program.insts[d].class.opcode != Op::FunctionParameter {
            return false;
        }
        let Some(fi) = program.function_of(d) else {
            return false;
        };
        let Some(k) = program.functions[fi]
            .params
            .iter()
            .position(|&p| p == param)
        else {
            return false;
        };
        // The call above the level in function `fi`.
        let Some(j) = levels
            .iter()
            .position(|&i| program.function_of(i) == Some(fi))
        else {
            return false;
        };
        let Some(&call) = levels.get(j + 1) else {
            return false;
        };
        let arg = id_operands(&program.insts[call]).nth(1 + k);
        let (Some(arg), Some(caller)) = (arg, program.function_of(call)) else {
            return false;
        };
        let Some(fl) = slot.get(caller).and_then(|&s| built.get(s as usize)) else {
            return false;
        };
        if program.def(arg).map(|i| i.class.opcode) == Some(Op::FunctionParameter) {
            param = arg;
            continue;
        }
        return fl.remat_ssa(program, arg, 0);
    }
    false
}

/// When SSA parameter `param` of a function on the site's `levels` is,
/// at the call above, a load of a whole local variable of the caller made
/// in the call's block with no write of the variable between: that
/// variable.
fn argument_source(
    program: &Program,
    built: &[FnLiveness],
    slot: &[u32],
    levels: &[usize],
    param: Id,
) -> Option<Id> {
    let d = *program.defs.get(&param)?;
    if program.insts[d].class.opcode != Op::FunctionParameter {
        return None;
    }
    let fi = program.function_of(d)?;
    let k = program.functions[fi]
        .params
        .iter()
        .position(|&p| p == param)?;
    let j = levels
        .iter()
        .position(|&i| program.function_of(i) == Some(fi))?;
    let call = *levels.get(j + 1)?;
    let arg = id_operands(&program.insts[call]).nth(1 + k)?;
    let caller = program.function_of(call)?;
    let fl = built.get(*slot.get(caller)? as usize)?;
    let load = *program.defs.get(&arg)?;
    if program.insts[load].class.opcode != Op::Load {
        return None;
    }
    let f = &program.functions[caller];
    if block_at(f, load)? != block_at(f, call)? || load > call {
        return None;
    }
    let root = fl.roots.get(&id_operands(&program.insts[load]).next()?)?;
    if !root.exact
        || !fl.path(root).is_empty()
        || !fl.vars.contains(&root.var)
        || fl.private.is_private(root.var)
    {
        return None;
    }
    let mentions = fl.mentions(program, root.var)?;
    let written = mentions
        .iter()
        .any(|&i| load < i && i <= call && fl.mention_writes(program, i, root.var));
    (!written).then_some(root.var)
}

fn payload_info(program: &Program, id: Id) -> PayloadInfo {
    // Globals carry the pointee type; a function-local ray query or payload
    // is an `OpVariable` whose result type is a pointer.
    let ty = program
        .globals
        .iter()
        .find(|g| g.id == id)
        .map(|g| g.ty)
        .or_else(|| pointee(program, program.def(id)?.result_type?));
    PayloadInfo {
        name: program.display_name(id),
        ty: ty.map(|t| program.type_name(t)).unwrap_or_default(),
        size: ty.and_then(|t| scalar_size(program, t)),
        id,
    }
}

/// The type of element `i` of a composite type.
fn element_type(program: &Program, ty: Id, i: u32) -> Option<Id> {
    match program.ty(ty)? {
        Type::Struct { members } => members.get(i as usize).copied(),
        Type::Vector { elem, .. } | Type::Array { elem, .. } => Some(*elem),
        Type::Matrix { column, .. } => Some(*column),
        _ => None,
    }
}

/// How many elements a composite type has, when fixed.
fn element_count(program: &Program, ty: Id) -> Option<u32> {
    match program.ty(ty)? {
        Type::Struct { members } => Some(members.len() as u32),
        Type::Vector { count, .. } => Some(*count),
        Type::Matrix { columns, .. } => Some(*columns),
        Type::Array { len, .. } => len.value().map(|n| n.min(u32::MAX as u64) as u32),
        _ => None,
    }
}

fn pointee(program: &Program, ptr_ty: Id) -> Option<Id> {
    match program.ty(ptr_ty)? {
        Type::Pointer { pointee, .. } => Some(*pointee),
        _ => None,
    }
}

/// Whether a value of type `ty` points at memory whose parts liveness
/// tracks (any pointer but a `PhysicalStorageBuffer` address).
fn is_pointer_type(program: &Program, ty: Option<Id>) -> bool {
    matches!(
        ty.and_then(|t| program.ty(t)),
        Some(Type::Pointer { storage, .. }) if *storage != StorageClass::PhysicalStorageBuffer
    )
}

/// Whether function parameter `id` is tracked like a variable.
fn is_pointer_param(program: &Program, id: Id) -> bool {
    program.def(id).is_some_and(|inst| {
        inst.class.opcode == Op::FunctionParameter
            && !program.is_debug_inst(inst)
            && is_pointer_type(program, inst.result_type)
    })
}

/// Whether `op` is an atomic, ray-query, group or subgroup operation: one
/// that does not give the same value when done again. (By name: asked for
/// every value whose recomputation is weighed, so each opcode's answer is
/// kept once worked out.)
fn varies(op: Op) -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    // By opcode: 0 not known, 1 no, 2 yes (a load, not a thread-local hash
    // lookup); opcodes past the table are named each time.
    static KNOWN: [AtomicU8; 8192] = [const { AtomicU8::new(0) }; 8192];
    let slot = KNOWN.get(op as usize);
    match slot.map_or(0, |k| k.load(Ordering::Relaxed)) {
        0 => {}
        known => return known == 2,
    }
    let name = format!("{op:?}");
    let v = ["Atomic", "RayQuery", "GroupNonUniform", "Subgroup", "Group"]
        .iter()
        .any(|p| name.starts_with(p));
    if let Some(k) = slot {
        k.store(1 + v as u8, Ordering::Relaxed);
    }
    v
}

/// A name for a value: its `OpName`, the variable it was loaded from, or the
/// `let`/`var` the source line at its definition declares (naga names no
/// `let` bindings in SPIR-V); else `%id`.
fn value_name(program: &Program, id: Id, def: Option<&Location>) -> String {
    if let Some(n) = program.name(id).filter(|n| !n.is_empty()) {
        return n.to_string();
    }
    if let Some(inst) = program.def(id) {
        if inst.class.opcode == Op::Load {
            if let Some(n) = id_operands(inst)
                .next()
                .and_then(|p| program.name(p))
                .filter(|n| !n.is_empty())
            {
                return n.to_string();
            }
        }
    }
    let declared = def.and_then(|l| {
        let text = program
            .files
            .iter()
            .find(|f| f.path == l.path)?
            .text
            .as_ref()?;
        let line = text
            .lines()
            .nth(l.line.checked_sub(1)? as usize)?
            .trim_start();
        let rest = ["let ", "var ", "const "]
            .iter()
            .find_map(|k| line.strip_prefix(k))?;
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        (!name.is_empty()).then_some(name)
    });
    declared.unwrap_or_else(|| format!("%{id}"))
}

fn id_operands(inst: &Instruction) -> impl Iterator<Item = Id> + '_ {
    inst.operands.iter().filter_map(|o| match o {
        Operand::IdRef(x) => Some(*x),
        _ => None,
    })
}

/// Whether `path` begins with `prefix`. Paths are a few indices long: a
/// loop, not a `memcmp` call per comparison (which `starts_with` and `==`
/// make, and which was a sixth of the model's time in `kill`).
#[inline]
fn has_prefix(path: &[u32], prefix: &[u32]) -> bool {
    if prefix.len() > path.len() {
        return false;
    }
    let mut k = 0;
    while k < prefix.len() {
        if path[k] != prefix[k] {
            return false;
        }
        k += 1;
    }
    true
}

/// Calls `f` with path `a` followed by `b`: on the stack when short (a
/// call's effect on its arguments' parts is joined at every visit of the
/// fixpoint, which allocated a vector each time).
fn with_joined<R>(a: &[u32], b: &[u32], f: impl FnOnce(&[u32]) -> R) -> R {
    const ROOM: usize = 16;
    let n = a.len() + b.len();
    if n <= ROOM {
        let mut buf = [0u32; ROOM];
        buf[..a.len()].copy_from_slice(a);
        buf[a.len()..n].copy_from_slice(b);
        f(&buf[..n])
    } else {
        let mut v = a.to_vec();
        v.extend_from_slice(b);
        f(&v)
    }
}

/// Whether two paths are equal (see [`has_prefix`]).
fn same_path(a: &[u32], b: &[u32]) -> bool {
    a.len() == b.len() && has_prefix(a, b)
}

/// Places live across one level of a site. A place is what backward
/// liveness tracks: an SSA value (empty path), or part of a function-local
/// variable, named by the constant access-chain indices that reach it from
/// the variable (empty: all of it). Kept as (id, path) with the paths
/// in one pool: reused for every level of every site (each place was a
/// vector of its own, allocated, sorted and freed per site). Also the
/// room the per-site questions reuse.
#[derive(Default)]
struct SitePlaces {
    /// Each place's id and path (`paths[from..to]`).
    list: Vec<(Id, u32, u32)>,
    paths: Vec<u32>,
    /// The live parts' set and the SSA values' words (see
    /// `FnLiveness::places_after`).
    live: BitSet,
    words: Vec<u64>,
}

impl SitePlaces {
    fn clear(&mut self) {
        self.list.clear();
        self.paths.clear();
    }

    #[inline]
    fn push(&mut self, id: Id, path: &[u32]) {
        let from = self.paths.len() as u32;
        self.paths.extend_from_slice(path);
        self.list.push((id, from, self.paths.len() as u32));
    }

    /// Place `(id, a ++ b)`.
    fn push_joined(&mut self, id: Id, a: &[u32], b: &[u32]) {
        let from = self.paths.len() as u32;
        self.paths.extend_from_slice(a);
        self.paths.extend_from_slice(b);
        self.list.push((id, from, self.paths.len() as u32));
    }

    #[inline]
    fn path(&self, k: usize) -> &[u32] {
        let (_, from, to) = self.list[k];
        &self.paths[from as usize..to as usize]
    }

    /// Sorted by id, then path (as `(Id, Vec<u32>)` sorts), each once: a
    /// value's parts side by side.
    fn sort(&mut self) {
        let paths = &self.paths;
        let path = |&(_, from, to): &(Id, u32, u32)| &paths[from as usize..to as usize];
        self.list
            .sort_unstable_by(|a, b| a.0.cmp(&b.0).then_with(|| path(a).cmp(path(b))));
        self.list
            .dedup_by(|a, b| a.0 == b.0 && same_path(path(a), path(b)));
    }
}

/// The places one function's liveness has met, each with a dense index:
/// a live set is a [`BitSet`] of indices.
#[derive(Debug, Default)]
struct Places {
    /// Each place (one table for its fields: one allocation, not one
    /// per field).
    list: Vec<PlaceRow>,
    paths: Vec<u32>,
    /// Each id's slot: `id - lo` for the ids `lo..lo + dense` (SSA values
    /// and variables), then each of `params` (pointer parameters are
    /// variables too, numbered apart from the body), then the ids of
    /// `sparse` (a module numbered too sparsely for slots by id).
    lo: Id,
    dense: usize,
    params: Vec<Id>,
    sparse: HashMap<Id, u32>,
    /// By slot: the whole id's place, and its first and last part (a
    /// non-empty path; the others chained through `next_part` in the
    /// order met): found without hashing.
    slots: Vec<Slot>,
    /// The parts: by id and hash of the path, `next` chaining the others
    /// with the same key (a variable split into its elements has many).
    first: HashMap<(Id, u64), u32>,
}

/// A place: its id and path (a range of `Places::paths`: one pool for
/// all, not a vector per part), and the next place in its hash chain and
/// among its id's parts.
#[derive(Clone, Copy, Debug)]
struct PlaceRow {
    id: Id,
    from: u32,
    to: u32,
    next: u32,
    next_part: u32,
}

/// An id's places (see `Places::slots`).
#[derive(Clone, Copy, Debug)]
struct Slot {
    whole: u32,
    part_first: u32,
    part_last: u32,
}

impl Slot {
    const NONE: Slot = Slot {
        whole: Places::NONE,
        part_first: Places::NONE,
        part_last: Places::NONE,
    };
}

/// The places of one id: the whole, then its parts (see [`Places::of`]).
struct PlacesOf<'a> {
    whole: u32,
    part: u32,
    list: &'a [PlaceRow],
}

impl Iterator for PlacesOf<'_> {
    type Item = u32;

    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.whole != Places::NONE {
            return Some(std::mem::replace(&mut self.whole, Places::NONE));
        }
        let i = self.part;
        if i == Places::NONE {
            return None;
        }
        self.part = self.list[i as usize].next_part;
        Some(i)
    }
}

impl Places {
    const NONE: u32 = u32::MAX;

    /// For the ids `lo..=hi` defined in one function of `insts`
    /// instructions (about as many places, made room for at once) and its
    /// parameters `params`.
    fn new(lo: Id, hi: Id, params: &[Id], insts: usize) -> Places {
        let n = hi.saturating_sub(lo) as usize + 1;
        // A module with huge, sparse ids falls back to hashing.
        let dense = if n <= 1 << 20 { n } else { 0 };
        Places {
            list: Vec::with_capacity(insts),
            slots: vec![Slot::NONE; dense + params.len()],
            lo,
            dense,
            params: params.to_vec(),
            ..Places::default()
        }
    }

    fn path_hash(path: &[u32]) -> u64 {
        use std::hash::{BuildHasher, BuildHasherDefault};
        BuildHasherDefault::<rustc_hash::FxHasher>::default().hash_one(path)
    }

    #[inline]
    fn slot(&self, id: Id) -> Option<usize> {
        let k = id.wrapping_sub(self.lo) as usize;
        if k < self.dense {
            return Some(k);
        }
        self.slot_apart(id)
    }

    #[inline(never)]
    fn slot_apart(&self, id: Id) -> Option<usize> {
        if let Some(j) = self.params.iter().position(|&p| p == id) {
            return Some(self.dense + j);
        }
        if self.sparse.is_empty() {
            return None;
        }
        self.sparse.get(&id).map(|&k| k as usize)
    }

    /// The slot of `id`, made when it has none.
    fn slot_or_add(&mut self, id: Id) -> usize {
        if let Some(k) = self.slot(id) {
            return k;
        }
        let k = self.slots.len();
        self.sparse.insert(id, k as u32);
        self.slots.push(Slot::NONE);
        k
    }

    #[inline]
    fn find(&self, mut i: u32, path: &[u32]) -> Option<u32> {
        while i != Self::NONE {
            if same_path(self.place(i).1, path) {
                return Some(i);
            }
            i = self.list[i as usize].next;
        }
        None
    }

    /// The index of place `(id, path)`, added when new.
    fn intern(&mut self, id: Id, path: &[u32]) -> u32 {
        let k = self.slot_or_add(id);
        if path.is_empty() {
            if self.slots[k].whole == Self::NONE {
                self.slots[k].whole = self.push(id, path, Self::NONE);
            }
            return self.slots[k].whole;
        }
        let key = (id, Self::path_hash(path));
        let old = self.first.get(&key).copied().unwrap_or(Self::NONE);
        if let Some(i) = self.find(old, path) {
            return i;
        }
        let i = self.push(id, path, old);
        // In front of the chain.
        self.first.insert(key, i);
        match self.slots[k].part_last {
            Self::NONE => self.slots[k].part_first = i,
            last => self.list[last as usize].next_part = i,
        }
        self.slots[k].part_last = i;
        i
    }

    /// A new place, `next` in its hash chain.
    #[inline]
    fn push(&mut self, id: Id, path: &[u32], next: u32) -> u32 {
        let i = self.list.len() as u32;
        let from = self.paths.len() as u32;
        self.paths.extend_from_slice(path);
        self.list.push(PlaceRow {
            id,
            from,
            to: self.paths.len() as u32,
            next,
            next_part: Self::NONE,
        });
        i
    }

    /// The index of place `(id, path)`, if met.
    #[inline]
    fn get(&self, id: Id, path: &[u32]) -> Option<u32> {
        if path.is_empty() {
            let k = self.slot(id)?;
            return Some(self.slots[k].whole).filter(|&i| i != Self::NONE);
        }
        self.find(*self.first.get(&(id, Self::path_hash(path)))?, path)
    }

    /// Every place of `id` met so far (the whole, then its parts in the
    /// order met), by index.
    #[inline]
    fn of(&self, id: Id) -> PlacesOf<'_> {
        let slot = self.slot(id).map_or(Slot::NONE, |k| self.slots[k]);
        PlacesOf {
            whole: slot.whole,
            part: slot.part_first,
            list: &self.list,
        }
    }

    #[inline]
    fn place(&self, i: u32) -> (Id, &[u32]) {
        let p = &self.list[i as usize];
        (p.id, &self.paths[p.from as usize..p.to as usize])
    }
}

/// Facts about the ids one function defines, by id: a slot per id from
/// the function's lowest result id (a module numbers its ids densely, so
/// this is a load instead of a hash lookup per operand), hashing only for
/// huge, sparse ids. Each id added gets the next ordinal (its value's
/// index), so per-id data can also live in plain vectors.
#[derive(Debug)]
struct IdMap<T> {
    index: IdIndex,
    values: Vec<T>,
    /// The id of each value, by ordinal.
    keys: Vec<Id>,
}

/// An id's ordinal: slot `id - lo` holds it, or [`IdIndex::NONE`]. The
/// few ids outside the range (parameters: compilers number them with the
/// function, before its body) are listed in `outside`; a range too huge
/// for slots (a module may number its ids sparsely) has none, and hashes.
#[derive(Debug)]
struct IdIndex {
    lo: Id,
    slots: Vec<u32>,
    outside: Vec<(Id, u32)>,
    sparse: Option<Box<HashMap<Id, u32>>>,
}

impl IdIndex {
    const NONE: u32 = u32::MAX;

    /// For the ids `lo..=hi`: a slot each, unless the range is huge.
    fn new(lo: Id, hi: Id) -> IdIndex {
        let n = hi.saturating_sub(lo) as usize + 1;
        let dense = n <= 1 << 20;
        IdIndex {
            lo,
            slots: if dense {
                vec![IdIndex::NONE; n]
            } else {
                Vec::new()
            },
            outside: Vec::new(),
            sparse: (!dense).then(Box::default),
        }
    }

    /// (The slot lookup is one test: no variant to match first; asked for
    /// every operand of most passes.)
    #[inline]
    fn find(&self, id: Id) -> Option<u32> {
        match self.slots.get(id.wrapping_sub(self.lo) as usize) {
            Some(&k) => (k != Self::NONE).then_some(k),
            // Most operands are ids from outside the function (constants,
            // types, globals): a short list, inline.
            None if self.sparse.is_none() => {
                self.outside.iter().find(|(x, _)| *x == id).map(|&(_, k)| k)
            }
            None => self.find_sparse(id),
        }
    }

    #[cold]
    fn find_sparse(&self, id: Id) -> Option<u32> {
        self.sparse.as_ref()?.get(&id).copied()
    }

    /// The ordinal of `id`, given `next` when it is new.
    #[inline]
    fn find_or_add(&mut self, id: Id, next: u32) -> u32 {
        if let Some(s) = self.slots.get_mut(id.wrapping_sub(self.lo) as usize) {
            if *s == Self::NONE {
                *s = next;
            }
            return *s;
        }
        if let Some(m) = &mut self.sparse {
            return *m.entry(id).or_insert(next);
        }
        match self.outside.iter().find(|(x, _)| *x == id) {
            Some(&(_, k)) => k,
            None => {
                self.outside.push((id, next));
                next
            }
        }
    }
}

impl<T> IdMap<T> {
    /// For the ids `lo..=hi`.
    fn new(lo: Id, hi: Id) -> IdMap<T> {
        IdMap {
            index: IdIndex::new(lo, hi),
            values: Vec::new(),
            keys: Vec::new(),
        }
    }

    #[inline]
    fn get(&self, id: &Id) -> Option<&T> {
        self.values.get(self.index.find(*id)? as usize)
    }

    #[inline]
    fn contains_key(&self, id: &Id) -> bool {
        self.index.find(*id).is_some()
    }

    /// The ordinal of `id`: `0..` in the order ids were added.
    #[inline]
    fn ordinal(&self, id: Id) -> Option<usize> {
        self.index.find(id).map(|k| k as usize)
    }

    fn len(&self) -> usize {
        self.values.len()
    }

    fn insert(&mut self, id: Id, value: T) {
        let next = self.values.len() as u32;
        let k = self.index.find_or_add(id, next);
        if k == next {
            self.values.push(value);
            self.keys.push(id);
        } else {
            self.values[k as usize] = value;
        }
    }
}

impl IdMap<LocalPtr> {
    /// Adds variable (or pointer parameter) `var` as its own root.
    fn insert_whole(&mut self, var: Id) {
        let k = self.index.find_or_add(var, self.values.len() as u32);
        let ptr = LocalPtr::whole(var, k);
        match self.values.get_mut(k as usize) {
            Some(v) => *v = ptr,
            None => {
                self.values.push(ptr);
                self.keys.push(var);
            }
        }
    }
}

/// A set of the ids one function defines (see [`IdMap`]).
type IdSet = IdMap<()>;

impl IdSet {
    #[inline]
    fn contains(&self, id: &Id) -> bool {
        self.contains_key(id)
    }

    #[inline]
    fn add(&mut self, id: Id) {
        self.insert(id, ());
    }
}

/// A pointer into a function-local variable.
#[derive(Clone, Copy, Debug)]
struct LocalPtr {
    var: Id,
    /// The variable's ordinal among the function's roots (its mentions'
    /// key, found without another lookup).
    root: u32,
    /// Constant indices from the variable, up to the first dynamic one:
    /// `FnLiveness::paths[path.0..path.1]` (one list for the function's
    /// pointers, not a vector each).
    path: (u32, u32),
    /// Whether every index was constant (the pointer names exactly `path`).
    exact: bool,
}

impl LocalPtr {
    /// The whole of variable (or pointer parameter) `var`, root `root`.
    fn whole(var: Id, root: u32) -> LocalPtr {
        LocalPtr {
            var,
            root,
            path: (0, 0),
            exact: true,
        }
    }

    fn path_range(&self) -> std::ops::Range<usize> {
        self.path.0 as usize..self.path.1 as usize
    }
}

/// Whether an instruction is half of a copy between local parts (see
/// `FnLiveness::copy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Copy {
    None,
    /// The store; the load's instruction index.
    Store(u32),
    /// The load (its read is the store's).
    Load,
}

/// What a function does with each pointer parameter, as its callers see it.
#[derive(Clone, Debug, Default)]
struct ParamEffect {
    /// The parts it may read before writing them; `None` when not known.
    reads: Option<Vec<Vec<u32>>>,
    /// The parts it writes on every path to its return.
    writes: Vec<Vec<u32>>,
    /// Whether it writes no part at all, on any path (`false` when not
    /// known): a caller's variable passed for it keeps its value.
    never_writes: bool,
}

/// Per parameter of a function.
type ExposedParams = std::rc::Rc<[ParamEffect]>;

/// What the functions of one program share while their liveness is built:
/// answers that depend on nothing but the function (see
/// [`FnLiveness::exposed_params`]), so each function is solved once
/// instead of once per caller that reaches it.
#[derive(Default)]
struct Shared {
    exposed: HashMap<usize, ExposedParams>,
    /// Functions built exactly as callees: a site's function or a
    /// caller on a chain met later takes its build from here (the parts
    /// are solved the same whichever asks; the SSA values on first use).
    built: HashMap<usize, FnLiveness>,
}

/// One top-level build: every answer met on the way, exact or not, and
/// the program's shared exact ones.
#[derive(Default)]
struct Builds {
    memo: HashMap<usize, (ExposedParams, bool)>,
    shared: Shared,
}

/// One instruction's backward transfer, prepared before solving.
#[derive(Clone, Debug)]
enum Step {
    /// Reads and writes no place: debug info, and every instruction that
    /// neither mentions a variable nor writes, calls or takes a parameter.
    Skip,
    /// Kills place `def` (or none: [`Places::NONE`]), then makes the places
    /// `FnLiveness::step_uses[uses]` live.
    Plain {
        def: u32,
        uses: std::ops::Range<u32>,
    },
    /// A store of a value that is no local pointer into exactly part
    /// `FnLiveness::paths[path.0..path.1]` of `var` (most stores): kills
    /// that part, reads nothing tracked. The part's places change while
    /// solving, so the kill is worked out each time, but without the
    /// lookups of [`Step::Other`].
    Store { var: Id, path: (u32, u32) },
    /// Copies, calls, variables and other stores: worked out each time.
    Other,
}

/// A piece of one block's backward transfer (see [`FnLiveness::blocks`]).
#[derive(Debug)]
enum Segment {
    /// A run of [`Step::Plain`]s folded into one: kills the places
    /// `FnLiveness::step_uses[kill]`, then makes `step_uses[gen]` live
    /// (index lists in the shared pool, not two sets per run).
    Run {
        kill: std::ops::Range<u32>,
        gen: std::ops::Range<u32>,
        /// The run's first instruction (it covers the block's instructions
        /// from there to the next segment's).
        from: u32,
    },
    /// An instruction whose transfer depends on the live set.
    Inst(usize),
}

/// Parts are tracked separately up to this many elements per composite.
const MAX_SPLIT: u32 = 64;

/// The blocks of a function whose liveness a site can see: those reachable
/// from the blocks of the instructions it is asked about (the sites and the
/// calls on their chains). What is live after an instruction depends only
/// on what can run after it, so the other blocks are not solved, and the
/// callees they call are not asked what they do with their parameters.
struct Focus {
    blocks: Vec<bool>,
    /// Every block (as a callee is solved, for its entry).
    all: bool,
}

impl Focus {
    fn all(program: &Program, func: usize) -> Focus {
        Focus {
            blocks: vec![true; program.functions[func].blocks.len()],
            all: true,
        }
    }

    /// Function `func`, asked about the instructions `asked`.
    fn new(program: &Program, func: usize, asked: &[usize]) -> Focus {
        let f = &program.functions[func];
        let mut blocks = vec![false; f.blocks.len()];
        let mut work: Vec<usize> = asked.iter().filter_map(|&i| block_at(f, i)).collect();
        while let Some(b) = work.pop() {
            if std::mem::replace(&mut blocks[b], true) {
                continue;
            }
            work.extend(
                f.blocks[b]
                    .succs
                    .iter()
                    .copied()
                    .filter(|&s| s < blocks.len()),
            );
        }
        let all = blocks.iter().all(|&b| b);
        Focus { blocks, all }
    }
}

/// One bit set per block in a single flat table of `w` words a row
/// (widened when a set outgrows it): the fixpoint's sets without an
/// allocation per block.
#[derive(Debug, Default)]
struct Rows {
    n: usize,
    w: usize,
    words: Vec<u64>,
}

impl Rows {
    fn new(n: usize, w: usize) -> Rows {
        Rows {
            n,
            w,
            words: vec![0; n * w],
        }
    }

    #[inline]
    fn row(&self, b: usize) -> &[u64] {
        &self.words[b * self.w..(b + 1) * self.w]
    }

    /// Row `b` := `words` (no longer than a row), zero-padded.
    #[inline]
    fn set_row(&mut self, b: usize, words: &[u64]) {
        let row = &mut self.words[b * self.w..(b + 1) * self.w];
        row[..words.len()].copy_from_slice(words);
        row[words.len()..].fill(0);
    }

    /// Makes rows at least `w` words wide.
    #[inline]
    fn widen(&mut self, w: usize) {
        if w > self.w {
            self.relayout(w);
        }
    }

    #[cold]
    fn relayout(&mut self, w: usize) {
        let mut words = vec![0; self.n * w];
        for b in 0..self.n {
            words[b * w..b * w + self.w].copy_from_slice(self.row(b));
        }
        self.words = words;
        self.w = w;
    }
}

/// The SSA values of one function live at each block's end: its values
/// are those defined in it that are not pointers to its variables or
/// pointer parameters. Solved apart from the parts, by one kill and one
/// gen set per block (each value is defined once, so nothing in a block
/// depends on the live set), in flat word arrays: a row of `words` per
/// block.
struct SsaLive {
    /// Each value's ordinal, by id.
    index: IdIndex,
    /// The id of each ordinal.
    ids: Vec<Id>,
    words: usize,
    live_out: Vec<u64>,
}

impl SsaLive {
    fn new(fl: &FnLiveness, program: &Program) -> SsaLive {
        let f = fl.function(program);
        let body = &fl.body;
        // Dense over the body's ids unless they are spread too far apart
        // (sized by the ids, not the module: a sparse numbering must not
        // ask for gigabytes).
        let mut ssa = SsaLive {
            index: IdIndex::new(body.lo, body.hi.max(body.lo)),
            ids: Vec::new(),
            words: 0,
            live_out: Vec::new(),
        };
        for &r in &fl.ssa_ids {
            let k = ssa.ids.len() as u32;
            if ssa.index.find_or_add(r, k) == k {
                ssa.ids.push(r);
            }
        }
        let n = f.blocks.len();
        let w = ssa.ids.len().div_ceil(64);
        ssa.words = w;
        // Per block: the values it defines, those it reads before defining
        // them, and (as its first live-out) those its successors' phis read
        // on the edge from it.
        let mut kill = vec![0u64; n * w];
        let mut gen = vec![0u64; n * w];
        let mut live_out = vec![0u64; n * w];
        // Forward: a value is in a block's gen when the first instruction
        // of the block that mentions it reads it (as stepping back over
        // the block would leave it), and in its kill when defined there.
        for b in (0..n).filter(|&b| fl.focus.blocks[b]) {
            let row = b * w..(b + 1) * w;
            let (gen, kill) = (&mut gen[row.clone()], &mut kill[row]);
            for &i in body.block(b) {
                let i = i as usize;
                for k in ssa.reads(fl, i) {
                    if kill[k as usize / 64] >> (k % 64) & 1 == 0 {
                        set(gen, k);
                    }
                }
                if let Some(k) = body.result(i).and_then(|r| ssa.ordinal(r)) {
                    set(kill, k);
                }
                if body.op(i) == Op::Phi {
                    for pair in body.ids(i).chunks(2) {
                        if let [value, pred] = pair {
                            if let Some(p) = f.block_by_label(*pred) {
                                if let Some(k) = ssa.ordinal(*value) {
                                    set(&mut live_out[p * w..(p + 1) * w], k);
                                }
                            }
                        }
                    }
                }
            }
        }
        // A worklist, as for the parts (see `FnLiveness::solve`).
        let mut live_in = vec![0u64; n * w];
        let mut work = Worklist::new(n, (0..n).filter(|&b| fl.focus.blocks[b]));
        while let Some(b) = work.pop() {
            for &s in &f.blocks[b].succs {
                if s < n {
                    for k in 0..w {
                        live_out[b * w + k] |= live_in[s * w + k];
                    }
                }
            }
            let mut changed = false;
            for k in b * w..(b + 1) * w {
                let v = gen[k] | (live_out[k] & !kill[k]);
                changed |= v != live_in[k];
                live_in[k] = v;
            }
            if changed {
                for &p in &fl.preds[b] {
                    if fl.focus.blocks[p] {
                        work.push(p);
                    }
                }
            }
        }
        ssa.live_out = live_out;
        ssa
    }

    #[inline]
    fn ordinal(&self, id: Id) -> Option<u32> {
        self.index.find(id)
    }

    /// Steps back over instruction `i`: its result dies, the values it
    /// reads live. A phi reads on its edges,
    /// and a copy's load and store read no value (the copy reads the
    /// source's parts).
    #[inline]
    fn step(&self, fl: &FnLiveness, i: usize, live: &mut [u64]) {
        let body = &fl.body;
        // (Asked only of the instructions the passes read: no debug info.)
        debug_assert!(!body.debug(i));
        if let Some(k) = body.result(i).and_then(|r| self.ordinal(r)) {
            unset(live, k);
        }
        for k in self.reads(fl, i) {
            set(live, k);
        }
    }

    /// The values instruction `i` reads, as ordinals: none for a phi (it
    /// reads on its edges) or a copy's load and store.
    #[inline]
    fn reads<'a>(&'a self, fl: &'a FnLiveness, i: usize) -> impl Iterator<Item = u32> + 'a {
        let body = &fl.body;
        let ids = if body.op(i) != Op::Phi && fl.copy_at(i) == Copy::None {
            body.ids(i)
        } else {
            &[]
        };
        ids.iter().filter_map(|&id| self.ordinal(id))
    }

    /// The values live just after instruction `inst` of block `b`, each
    /// given to `each` (`live` is room for the set, reused).
    fn after(
        &self,
        fl: &FnLiveness,
        b: usize,
        inst: usize,
        live: &mut Vec<u64>,
        mut each: impl FnMut(Id),
    ) {
        let w = self.words;
        live.clear();
        live.extend_from_slice(&self.live_out[b * w..(b + 1) * w]);
        for &k in fl.body.block_after(b, inst).iter().rev() {
            self.step(fl, k as usize, live);
        }
        for (k, &word) in live.iter().enumerate() {
            let mut rest = word;
            while rest != 0 {
                each(self.ids[k * 64 + rest.trailing_zeros() as usize]);
                rest &= rest - 1;
            }
        }
    }
}

/// The blocks a fixpoint has still to visit, each queued at most once at a
/// time (popped last-queued first). It gives up after 10,000 visits per
/// block: a fixpoint that does not settle is a bug, and a hang is worse
/// than the answer so far.
struct Worklist {
    work: Vec<usize>,
    queued: Vec<bool>,
    left: usize,
}

impl Worklist {
    fn new(n: usize, first: impl Iterator<Item = usize>) -> Worklist {
        let mut queued = vec![false; n];
        let work = first.inspect(|&b| queued[b] = true).collect();
        Worklist {
            work,
            queued,
            left: n.saturating_mul(10_000),
        }
    }

    fn pop(&mut self) -> Option<usize> {
        let b = self.work.pop()?;
        self.queued[b] = false;
        self.left = self.left.checked_sub(1)?;
        Some(b)
    }

    fn push(&mut self, b: usize) {
        if !self.queued[b] {
            self.queued[b] = true;
            self.work.push(b);
        }
    }
}

/// Stores, copies, calls and variables: their backward step depends on
/// the live set, so it is worked out while solving ([`Step::Other`] or
/// [`Step::Store`]), never folded into a run.
#[inline]
fn worked_out_each_time(op: Op) -> bool {
    matches!(
        op,
        Op::Store | Op::CopyMemory | Op::CopyMemorySized | Op::FunctionCall | Op::Variable
    )
}

#[inline]
fn set(words: &mut [u64], k: u32) {
    words[k as usize / 64] |= 1 << (k % 64);
}

#[inline]
fn unset(words: &mut [u64], k: u32) {
    words[k as usize / 64] &= !(1 << (k % 64));
}

/// The instructions mentioning each root (by its ordinal among
/// [`FnLiveness::roots`]), in order: one list for all, `start[k]..start[k + 1]`
/// being root `k`'s (one allocation, not one per root).
struct Mentions {
    start: Vec<u32>,
    list: Vec<usize>,
}

/// One root's mentions, shared (the recomputation check recurses into the
/// function's liveness while reading them).
struct MentionList(std::rc::Rc<Mentions>, std::ops::Range<usize>);

impl std::ops::Deref for MentionList {
    type Target = [usize];
    fn deref(&self) -> &[usize] {
        &self.0.list[self.1.clone()]
    }
}

/// A path stored to (a range of `FnLiveness::paths`) and the value stored.
type Stored = ((u32, u32), Id);

/// Spare vectors for nested recomputability questions: reaching writes,
/// and paths stored to.
type Spare = (Vec<Vec<usize>>, Vec<Vec<Stored>>);

/// Variables' recomputability as read at an instruction, once asked: per
/// question, the parts read (sorted, each part as its length then its
/// indices, `flat[from..to]`: one pool, not a vector per question), the
/// answer, and the next question about the same variable and instruction
/// ([`RematAnswers::NONE`]: none). `FnLiveness::remat_at` gives the first.
#[derive(Default)]
struct RematAnswers {
    list: Vec<(u32, u32, bool, u32)>,
    flat: Vec<u32>,
}

impl RematAnswers {
    const NONE: u32 = u32::MAX;
}

/// Whether each SSA value is recomputable, once worked out: a byte per id
/// (the module's ids are dense), hashing only ids past a bound a sparse
/// module may have.
#[derive(Default)]
struct RematMemo {
    /// 0: not known; 1: no; 2: yes.
    dense: Vec<u8>,
    sparse: HashMap<Id, bool>,
}

impl RematMemo {
    const DENSE: usize = 1 << 20;

    #[inline]
    fn get(&self, id: Id) -> Option<bool> {
        match self.dense.get(id as usize) {
            Some(0) => None,
            Some(&v) => Some(v == 2),
            None if id as usize >= Self::DENSE => self.sparse.get(&id).copied(),
            None => None,
        }
    }

    #[inline]
    fn insert(&mut self, id: Id, r: bool) {
        let k = id as usize;
        if k >= Self::DENSE {
            self.sparse.insert(id, r);
            return;
        }
        if k >= self.dense.len() {
            // Grown in steps, not per id.
            self.dense
                .resize((k + 1).next_power_of_two().min(Self::DENSE), 0);
        }
        self.dense[k] = 1 + r as u8;
    }
}

/// Liveness facts of one function.
pub struct FnLiveness {
    func: usize,
    /// The module's `Private` variables this function and its callees
    /// touch (tracked here like locals: see `private`).
    private: std::sync::Arc<PrivateUse>,
    /// Whether the function is an entry point's (no caller wrote its
    /// `Private` variables before it).
    is_entry: bool,
    /// The function's instructions, decoded once.
    body: Body,
    /// The constant index paths of `roots`, one after another.
    paths: Vec<u32>,
    /// Function-local `OpVariable`s.
    vars: IdSet,
    /// Pointer ids derived from a local variable or a pointer parameter.
    roots: IdMap<LocalPtr>,
    /// For each `OpFunctionCall` (by instruction index), the parts each
    /// pointer argument's callee parameter may read before writing.
    call_reads: HashMap<usize, ExposedParams>,
    /// `OpLoad`s of a whole local part whose only use is the store right
    /// after them into another local part (a copy, such as glslang's
    /// copy-in of an `inout` argument): per instruction from the
    /// function's start, the store (with its load's index) and the load
    /// (empty when the function has none: see `copy_at`).
    copy: Vec<Copy>,
    /// The function's SSA values, in the order defined.
    ssa_ids: Vec<Id>,
    /// The blocks solved.
    focus: Focus,
    /// SSA values live at each block's end, solved on first use (only a
    /// site's function and its callers on a chain ask).
    ssa: std::cell::OnceCell<SsaLive>,
    /// Live places at each block's end, as indices into `places`.
    live_out: Rows,
    /// Every place met while solving (the live sets' members).
    places: RefCell<Places>,
    preds: crate::program::cfg::Preds,
    remat: RefCell<RematMemo>,
    /// Variables' rematerialisation as read at an instruction.
    remat_at: RefCell<HashMap<(Id, usize), u32>>,
    /// The answers of `remat_at`, by the slot it gives (so the key is
    /// moved into the table once, not copied for an answer in progress).
    remat_ok: RefCell<RematAnswers>,
    /// Vectors the recomputability questions reuse (they nest): reaching
    /// writes, and the paths stored to.
    spare: RefCell<Spare>,
    /// Vectors a reaching-writes walk reuses (the blocks to visit and
    /// those seen), instead of two allocations per question.
    walk: RefCell<Walk>,
    /// Each instruction's backward transfer (from the function's start).
    steps: Vec<Step>,
    /// The places `Step::Plain` reads.
    step_uses: Vec<u32>,
    /// Each block's backward transfer, last instruction first: the
    /// fixpoint visits a block with a few word operations per run of
    /// plain steps instead of stepping every instruction.
    segments: Vec<Segment>,
    /// Where each block's segments start in `segments` (one more entry
    /// than blocks).
    block_segments: Vec<u32>,
    /// The instructions that define or use each variable, in order (built
    /// on first use).
    mentions: std::cell::OnceCell<std::rc::Rc<Mentions>>,
    /// The mentions by block of each variable a reaching-writes walk
    /// asked about (only a site's function asks, about a few variables).
    mention_blocks: RefCell<MentionBlocks>,
}

/// Root `k`'s mentions grouped by block, once asked: `runs[at[k].0..at[k].1]`,
/// each (block, from, to) into its mention list, in order. By the root's
/// ordinal (`at[k].0 == u32::MAX`: not grouped yet), not hashed.
#[derive(Default)]
struct MentionBlocks {
    at: Vec<(u32, u32)>,
    runs: Vec<(u32, u32, u32)>,
}

/// What a walk over blocks reuses: the blocks to visit, each block's span
/// of the variable's mentions, and per block the stamp of the last walk
/// that saw it (`seen`) or found a write of the variable in it (`wrote`):
/// a new stamp per walk instead of clearing a flag per block.
#[derive(Default)]
struct Walk {
    work: Vec<(usize, usize)>,
    seen: Vec<u32>,
    wrote: Vec<u32>,
    stamp: u32,
    span: Vec<(u32, u32)>,
}

impl Walk {
    /// A fresh stamp for a walk over `n` blocks.
    fn start(&mut self, n: usize) -> u32 {
        if self.seen.len() < n {
            self.seen.resize(n, 0);
            self.wrote.resize(n, 0);
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.wrote.fill(0);
            self.stamp = 1;
        }
        self.stamp
    }
}

impl FnLiveness {
    /// The constant indices of `p` from its variable.
    #[inline]
    fn path(&self, p: &LocalPtr) -> &[u32] {
        &self.paths[p.path_range()]
    }

    pub fn new(program: &Program, func: usize) -> FnLiveness {
        Self::build(
            program,
            func,
            &mut Builds::default(),
            0,
            Focus::all(program, func),
        )
        .0
    }

    /// The liveness of function `func`, built as [`FnLiveness::new`] would,
    /// reusing (and adding to) the callee answers in `shared`.
    fn shared(program: &Program, func: usize, shared: &mut Shared, focus: Focus) -> FnLiveness {
        if let Some(fl) = shared.built.remove(&func) {
            return fl;
        }
        let mut builds = Builds {
            memo: HashMap::default(),
            shared: std::mem::take(shared),
        };
        let whole = focus.all;
        let (fl, exact) = Self::build(program, func, &mut builds, 0, focus);
        // A caller met later asks what this function does with its pointer
        // parameters: answered from this build, not by building it again.
        let f = &program.functions[func];
        if exact
            && whole
            && !builds.shared.exposed.contains_key(&func)
            && f.params.iter().any(|&p| is_pointer_param(program, p))
        {
            let exposed = fl.exposed(program);
            builds.shared.exposed.insert(func, exposed);
        }
        *shared = builds.shared;
        fl
    }

    /// The parts of each pointer parameter of function `func` that it may
    /// read before writing them (`None`: not a pointer, or not known).
    ///
    /// The second value says whether the answer is exact: no call below
    /// was cut off by depth or met while its own answer was in progress
    /// (only then may another build reuse it).
    fn exposed_params(
        program: &Program,
        func: usize,
        builds: &mut Builds,
        depth: u32,
    ) -> (ExposedParams, bool) {
        if let Some((e, exact)) = builds.memo.get(&func) {
            return (e.clone(), *exact);
        }
        if let Some(e) = builds.shared.exposed.get(&func) {
            builds.memo.insert(func, (e.clone(), true));
            return (e.clone(), true);
        }
        let f = &program.functions[func];
        let unknown: ExposedParams = vec![ParamEffect::default(); f.params.len()].into();
        // Without pointer parameters a callee reads and writes nothing of
        // its caller's: no need to solve it for that.
        if !f.params.iter().any(|&p| is_pointer_param(program, p)) {
            builds.memo.insert(func, (unknown.clone(), true));
            builds.shared.exposed.insert(func, unknown.clone());
            return (unknown, true);
        }
        if depth > 16 {
            return (unknown, false);
        }
        builds.memo.insert(func, (unknown, false));
        let (fl, exact) = Self::build(program, func, builds, depth + 1, Focus::all(program, func));
        let exposed = fl.exposed(program);
        builds.memo.insert(func, (exposed.clone(), exact));
        if exact {
            builds.shared.exposed.insert(func, exposed.clone());
            builds.shared.built.insert(func, fl);
        }
        (exposed, exact)
    }

    /// What this function does with each of its pointer parameters.
    fn exposed(&self, program: &Program) -> ExposedParams {
        let f = self.function(program);
        let entry = f.blocks.first().map(|b| b.start);
        // Read from the live set itself (by place index), not from a hash
        // set of owned places: the order of a parameter's parts does not
        // matter to a caller, which makes each of them live.
        let live = entry
            .and_then(|i| self.live_parts_after(program, i))
            .map(|(_, live)| live)
            .unwrap_or_default();
        let places = self.places.borrow();
        f.params
            .iter()
            .map(|p| {
                if !self.roots.contains_key(p) {
                    return ParamEffect::default();
                }
                let reads = live
                    .iter()
                    .filter_map(|i| {
                        let (v, path) = places.place(i);
                        (v == *p).then(|| path.to_vec())
                    })
                    .collect();
                ParamEffect {
                    reads: Some(reads),
                    writes: self.written_on_every_path(program, *p),
                    never_writes: self.never_writes(program, *p),
                }
            })
            .collect()
    }

    /// The parts of pointer parameter (or variable) `var` that every path
    /// from the function's entry to a return writes: stores of exactly
    /// that part, and the writes of calls that pass it.
    fn written_on_every_path(&self, program: &Program, var: Id) -> Vec<Vec<u32>> {
        self.written_on_every_path_from(program, var, None, &[])
    }

    /// Whether nothing here may write any part of pointer parameter (or
    /// variable) `var`: it is only loaded, indexed, or passed to callees
    /// that never write it.
    fn never_writes(&self, program: &Program, var: Id) -> bool {
        let Some(mentions) = self.mentions(program, var) else {
            return true;
        };
        let body = &self.body;
        mentions.iter().all(|&i| match body.op(i) {
            Op::Load | Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => true,
            _ if body.debug(i) => true,
            Op::FunctionCall => self.call_never_writes(program, i, var),
            _ => false,
        })
    }

    /// Whether call `i` leaves variable `var` as it was: each argument
    /// pointing into it goes to a parameter its callee never writes.
    fn call_never_writes(&self, program: &Program, i: usize, var: Id) -> bool {
        // A `Private` variable the callee may write without being passed it.
        if self.private.is_private(var)
            && self
                .private_callee(program, i)
                .is_none_or(|c| self.private.writes(c, var))
        {
            return false;
        }
        let effects = self.call_reads.get(&i);
        self.body
            .ids(i)
            .iter()
            .enumerate()
            .skip(1)
            .filter(|(_, a)| self.root(**a) == Some(var))
            .all(|(k, _)| {
                effects
                    .and_then(|e| e.get(k - 1))
                    .is_some_and(|e| e.never_writes)
            })
    }

    /// [`FnLiveness::written_on_every_path`] from just after instruction
    /// `from` (`None`: the entry), with `seed` written there already: what
    /// a caller's part passed for `var` is sure to hold anew once the
    /// function returns, whatever it held while suspended at `from`.
    fn written_on_every_path_from(
        &self,
        program: &Program,
        var: Id,
        from: Option<usize>,
        seed: &[Vec<u32>],
    ) -> Vec<Vec<u32>> {
        let f = self.function(program);
        let n = f.blocks.len();
        let start = match from {
            Some(i) => match block_at(f, i) {
                Some(b) => Some((b, i)),
                None => return Vec::new(),
            },
            None => None,
        };
        // Only an instruction that mentions `var` can write it.
        let mentions = self.mentions(program, var);
        if mentions.is_none() && seed.is_empty() {
            return Vec::new();
        }
        // Every part written somewhere, once (an index each), and the
        // (block, index, instruction) of each write: the analysis below
        // runs on bit rows of those indices, not on hash sets of paths per
        // block.
        let mut parts: Vec<Vec<u32>> = Vec::new();
        let mut writes: Vec<(usize, usize, usize)> = Vec::new();
        let mut add = |b: usize, i: usize, path: &[u32]| {
            let k = match parts.iter().position(|q| same_path(q, path)) {
                Some(k) => k,
                None => {
                    parts.push(path.to_vec());
                    parts.len() - 1
                }
            };
            writes.push((b, k, i));
        };
        for &i in mentions.iter().flat_map(|m| m.iter()) {
            let Some(b) = block_at(f, i) else {
                continue;
            };
            match self.body.op(i) {
                Op::Store => {
                    let t = self.body.first(i).and_then(|t| self.roots.get(&t));
                    if let Some(t) = t.filter(|t| t.var == var && t.exact) {
                        add(b, i, self.path(t));
                    }
                }
                Op::FunctionCall => {
                    for (k, a) in self.body.ids(i).iter().enumerate().skip(1) {
                        let Some(t) = self.roots.get(a).filter(|t| t.var == var && t.exact) else {
                            continue;
                        };
                        let e = self.call_reads.get(&i).and_then(|e| e.get(k - 1));
                        for x in e.map(|e| e.writes.as_slice()).unwrap_or_default() {
                            with_joined(self.path(t), x, |path| add(b, i, path));
                        }
                    }
                }
                _ => {}
            }
        }
        // The seed: written at the start, before anything else.
        let seeded: Vec<usize> = seed
            .iter()
            .map(|path| match parts.iter().position(|q| same_path(q, path)) {
                Some(k) => k,
                None => {
                    parts.push(path.clone());
                    parts.len() - 1
                }
            })
            .collect();
        // Nothing written here at all: nothing written on every path.
        if writes.is_empty() && seeded.is_empty() {
            return Vec::new();
        }
        let w = parts.len().div_ceil(64);
        let mut own = vec![0u64; n * w];
        // From `from`: the seed, then the writes after it in its block.
        let mut first = vec![0u64; w];
        for &k in &seeded {
            first[k / 64] |= 1 << (k % 64);
        }
        for &(b, k, i) in &writes {
            own[b * w + k / 64] |= 1 << (k % 64);
            if start.is_some_and(|(b0, at)| b == b0 && i > at) {
                first[k / 64] |= 1 << (k % 64);
            }
        }
        // Forward must-analysis, in rounds over the blocks in order; an
        // unreached block's set is "everything". From `from`, its block's
        // successors start from `first`, and the block itself counts
        // again only when a path comes back to it.
        let mut out = vec![0u64; n * w];
        let mut reached = vec![false; n];
        let mut set = vec![0u64; w];
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds < 1000 {
            changed = false;
            rounds += 1;
            for b in 0..n {
                let mut any = start.is_none() && b == 0;
                set.fill(0);
                let mut meet = |o: &[u64], any: &mut bool| {
                    if *any {
                        set.iter_mut().zip(o).for_each(|(s, o)| *s &= o);
                    } else {
                        set.copy_from_slice(o);
                        *any = true;
                    }
                };
                for &p in &self.preds[b] {
                    if start.is_some_and(|(b0, _)| p == b0) {
                        meet(&first, &mut any);
                    }
                    if reached[p] {
                        meet(&out[p * w..(p + 1) * w], &mut any);
                    }
                }
                if !any {
                    continue;
                }
                set.iter_mut()
                    .zip(&own[b * w..(b + 1) * w])
                    .for_each(|(s, o)| *s |= o);
                if !reached[b] || out[b * w..(b + 1) * w] != set[..] {
                    out[b * w..(b + 1) * w].copy_from_slice(&set);
                    reached[b] = true;
                    changed = true;
                }
            }
        }
        // Written on every path to every return (one not reached writes
        // nothing).
        let mut must: Option<Vec<u64>> = None;
        let mut meet_return = |o: &[u64]| {
            let m = must.get_or_insert_with(|| vec![u64::MAX; w]);
            for (k, m) in m.iter_mut().enumerate() {
                *m &= o.get(k).copied().unwrap_or(0);
            }
        };
        for (b, block) in f.blocks.iter().enumerate() {
            if !matches!(
                program.insts[block.end].class.opcode,
                Op::Return | Op::ReturnValue
            ) {
                continue;
            }
            if start.is_some_and(|(b0, _)| b == b0) {
                meet_return(&first);
                if !reached[b] {
                    continue;
                }
            } else if start.is_some() && !reached[b] {
                // A return no path from `from` reaches says nothing.
                continue;
            }
            let o = if reached[b] {
                &out[b * w..(b + 1) * w]
            } else {
                &[][..]
            };
            meet_return(o);
        }
        let must = must.unwrap_or_default();
        let mut v: Vec<Vec<u32>> = parts
            .into_iter()
            .enumerate()
            .filter(|(k, _)| must.get(k / 64).is_some_and(|m| m >> (k % 64) & 1 == 1))
            .map(|(_, p)| p)
            .collect();
        v.sort();
        v
    }

    /// The liveness of `func`, and whether every callee's answer it used
    /// was exact. Below the top (`depth` > 0) only its variables' parts.
    fn build(
        program: &Program,
        func: usize,
        builds: &mut Builds,
        depth: u32,
        focus: Focus,
    ) -> (FnLiveness, bool) {
        let f = &program.functions[func];
        // Only the variables' parts are solved here; the SSA values apart,
        // where a site asks (`SsaLive`): what SSA values are live never
        // changes which parts are (a load reads its variable whether or not
        // its value is used), and no part changes which values are.
        // The body's ids (`Body::lo..=hi`): the function's own and its
        // parameters' are often numbered long before it, and would widen
        // the dense tables; so are debug-info instructions' (our HLSL
        // compiler numbers them after every function), which nothing here
        // looks up.
        // One walk decodes each instruction and classifies its result.
        let mut body = Body::begin(program, f);
        let (lo, hi) = (body.lo, body.hi);
        let private = PrivateUse::of(program);
        let is_entry = program.entry_points.iter().any(|e| e.function == f.id);
        let mut vars = IdSet::new(lo, hi);
        let mut roots: IdMap<LocalPtr> = IdMap::new(lo, hi);
        // Room made once (growing these was a good part of the allocations):
        // about a pointer and a value an instruction at most.
        let n_insts = f.end + 1 - f.start;
        roots.values.reserve(n_insts);
        roots.keys.reserve(n_insts);
        let mut paths: Vec<u32> = Vec::with_capacity(2 * n_insts);
        // The results that are no pointers to locals (the SSA values, in
        // the order defined: see `SsaLive`).
        let mut ssa_ids: Vec<Id> = Vec::with_capacity(n_insts);
        // Copies from one local part to another: `%v = OpLoad %a; OpStore %b %v`
        // with `%v` used nowhere else and nothing between the two.
        // Candidates are met in this walk, which goes on to count the uses
        // of their loaded values.
        let mut candidates: Vec<(usize, usize, Id)> = Vec::new();
        let mut calls: Vec<usize> = Vec::new();
        // The instructions whose backward step can be more than nothing
        // (see `prepare_steps`): those that store, copy, call, declare a
        // variable or take a parameter, phis (which may name a pointer
        // defined further on), and those with a root among their operands,
        // found here, as each operand is read.
        let mut touched: Vec<u32> = Vec::with_capacity(n_insts);
        let mut prev: Option<usize> = None;
        // The candidates' loaded values, and their uses counted as met
        // (after its load, only a phi can name a value before its
        // definition: phis are counted at the end).
        let mut loaded: Option<(IdSet, Vec<usize>)> = None;
        let mut phis: Vec<usize> = Vec::new();
        // (An exclusive range: an inclusive one's iterator costs more.)
        for i in f.start..f.end + 1 {
            let Some((op, result, from)) = body.push(program, i) else {
                continue;
            };
            let ids = body.ids_from(from);
            if !private.all.is_empty() {
                // A `Private` variable mentioned here, or touched by the
                // callee, is tracked like a local of this function.
                let callee = (op == Op::FunctionCall)
                    .then(|| ids.first().and_then(|&c| program.function_index(c)))
                    .flatten();
                let touched_by_callee = callee
                    .into_iter()
                    .flat_map(|c| private.reads[c].iter().chain(&private.writes[c]));
                for &v in ids
                    .iter()
                    .filter(|&&id| private.is_private(id))
                    .chain(touched_by_callee)
                {
                    if !roots.contains_key(&v) {
                        roots.insert_whole(v);
                        vars.add(v);
                    }
                }
            }
            let touches = worked_out_each_time(op)
                || matches!(op, Op::FunctionParameter | Op::Phi)
                || ids.iter().any(|id| roots.contains_key(id));
            if touches {
                touched.push(i as u32);
            }
            if op == Op::Label {
                // A copy's load and store lie in one block.
                prev = None;
            }
            if let Some(l) = prev.replace(i) {
                if body.op(l) == Op::Load && op == Op::Store {
                    let (ld, st) = (body.ids(l), ids);
                    if let (Some(v), Some(&src)) = (body.result(l), ld.first()) {
                        let exact = |p: Id| roots.get(&p).is_some_and(|r| r.exact);
                        if st.len() == 2 && st[1] == v && exact(src) && exact(st[0]) {
                            candidates.push((i, l, v));
                            let (set, uses) =
                                loaded.get_or_insert_with(|| (IdMap::new(lo, hi), Vec::new()));
                            set.add(v);
                            uses.resize(set.len(), 0);
                        }
                    }
                }
            }
            if op == Op::Phi {
                phis.push(i);
            } else if let Some((set, uses)) = &mut loaded {
                for id in ids {
                    if let Some(k) = set.ordinal(*id) {
                        uses[k] += 1;
                    }
                }
            }
            if op == Op::FunctionCall {
                calls.push(i);
            }
            let Some(r) = result else { continue };
            match op {
                // A pointer parameter is tracked like a variable (its
                // contents belong to the caller, which counts them).
                Op::FunctionParameter if is_pointer_type(program, program.insts[i].result_type) => {
                    roots.insert_whole(r);
                }
                Op::Variable => {
                    vars.add(r);
                    roots.insert_whole(r);
                }
                Op::AccessChain
                | Op::InBoundsAccessChain
                | Op::PtrAccessChain
                | Op::CopyObject
                | Op::Bitcast => {
                    match ids.first().and_then(|b| roots.get(b)).copied() {
                        Some(mut ptr) => {
                            let chain = matches!(op, Op::AccessChain | Op::InBoundsAccessChain);
                            if op == Op::PtrAccessChain || op == Op::Bitcast {
                                ptr.exact = false;
                            }
                            if chain {
                                // The base's path, then the constant indices
                                // (while every index so far is constant).
                                let from = paths.len() as u32;
                                paths.extend_from_within(ptr.path_range());
                                for &ix in &ids[1..] {
                                    match program.const_u64(ix) {
                                        Some(c) if ptr.exact => paths.push(c as u32),
                                        _ => ptr.exact = false,
                                    }
                                }
                                ptr.path = (from, paths.len() as u32);
                            }
                            roots.insert(r, ptr);
                        }
                        None => ssa_ids.push(r),
                    }
                }
                Op::Label | Op::Function => {}
                _ => ssa_ids.push(r),
            }
        }
        body.finish(f);
        let preds = crate::program::cfg::Preds::of(f);
        // Per instruction: the load a copy's store copies from, or that a
        // load is a copy's (read at the store).
        // (Empty when there is none: most functions.)
        let mut copy = Vec::new();
        if let Some((loaded, mut uses)) = loaded {
            for &p in &phis {
                for id in body.ids(p) {
                    if let Some(k) = loaded.ordinal(*id) {
                        uses[k] += 1;
                    }
                }
            }
            for (store, load, v) in candidates {
                if loaded.ordinal(v).map(|k| uses[k]) == Some(1) {
                    copy.resize(f.end + 1 - f.start, Copy::None);
                    copy[store - f.start] = Copy::Store(load as u32);
                    copy[load - f.start] = Copy::Load;
                }
            }
        }
        // What each call reads through the pointers it passes.
        let mut call_reads = HashMap::default();
        let mut exact = true;
        for i in calls {
            // A call no site can see past needs no answer from its callee.
            if !block_at(f, i).is_some_and(|b| focus.blocks[b]) {
                continue;
            }
            let callee = body.first(i).and_then(|c| program.function_index(c));
            if let Some(c) = callee {
                let (e, e_exact) = Self::exposed_params(program, c, builds, depth);
                exact &= e_exact;
                call_reads.insert(i, e);
            }
        }
        let mut fl = FnLiveness {
            func,
            private,
            is_entry,
            body,
            paths,
            vars,
            roots,
            call_reads,
            copy,
            ssa_ids,
            focus,
            ssa: std::cell::OnceCell::new(),
            live_out: Rows::default(),
            places: RefCell::new(Places::new(lo, hi, &f.params, f.end + 1 - f.start)),
            preds,
            remat: RefCell::default(),
            remat_at: RefCell::default(),
            remat_ok: RefCell::default(),
            spare: RefCell::default(),
            walk: RefCell::default(),
            steps: Vec::new(),
            step_uses: Vec::new(),
            segments: Vec::new(),
            block_segments: Vec::new(),
            mentions: std::cell::OnceCell::new(),
            mention_blocks: RefCell::default(),
        };
        fl.prepare_steps(program, &touched);
        fl.solve(program);
        (fl, exact)
    }

    /// Prepares the backward transfer of every instruction that only kills
    /// its result and reads its operands (most of them), so the fixpoint
    /// does no lookups for those. Only the instructions `touched` (in
    /// order) can do more than nothing: the others skip.
    fn prepare_steps(&mut self, program: &Program, touched: &[u32]) {
        let f = &program.functions[self.func];
        let places = self.places.get_mut();
        let mut steps = vec![Step::Skip; f.end + 1 - f.start];
        // About two operands an instruction, and as many run entries.
        let mut pool = Vec::with_capacity(4 * (f.end + 1 - f.start));
        // Every function built asks for its variables' mentions (the
        // "written before" sets, a parameter's must-writes): gathered in
        // this walk, not another.
        let mut mentions = MentionPairs::new(self.roots.len(), f.end + 1 - f.start);
        let body = &self.body;
        let mut others = 0;
        for &at in touched {
            let at = at as usize;
            let op = body.op(at);
            let copy = self.copy.get(at - f.start).copied().unwrap_or(Copy::None);
            let other = matches!(copy, Copy::Store(_)) || worked_out_each_time(op);
            // Only SSA values and variables (pointer parameters) are ever
            // places; another result cannot be live.
            let result = body.result(at);
            // (Only a pointer parameter is its own root and not `other`: a
            // variable is `other`, a derived pointer's root is its base's.)
            let def = match result {
                Some(r) if op == Op::FunctionParameter => {
                    if self.roots.get(&r).is_some_and(|p| p.var == r) {
                        places.intern(r, &[])
                    } else {
                        Places::NONE
                    }
                }
                _ => Places::NONE,
            };
            // The operands once, for both the mentions and a plain step's
            // reads (in that order, as the places are numbered).
            // A copy's load reads nothing here (the store does), and phi
            // operands are used on the incoming edge (`solve`).
            let reads = !(other || op == Op::Phi || copy == Copy::Load);
            let derives = derives_pointer(op);
            let start = pool.len() as u32;
            // (Only an `OpVariable` defines a variable.)
            if let Some(r) = result.filter(|r| op == Op::Variable && self.vars.contains(r)) {
                mentions.add(&self.roots, at, r);
            }
            for &id in body.ids(at) {
                let root = self.roots.get(&id);
                if let Some(p) = root {
                    mentions.add_root(at, p.root);
                }
                if !reads {
                    continue;
                }
                if let Some(p) = root.filter(|_| !derives) {
                    pool.push(places.intern(p.var, &self.paths[p.path_range()]));
                }
            }
            // A call mentions the `Private` variables its callee touches.
            let callee = (!self.private.all.is_empty() && op == Op::FunctionCall)
                .then(|| body.first(at).and_then(|c| program.function_index(c)))
                .flatten();
            if let Some(c) = callee {
                let private = &self.private;
                for v in private.reads[c].iter().chain(&private.writes[c]) {
                    if let Some(p) = self.roots.get(v) {
                        mentions.add_root(at, p.root);
                    }
                }
            }
            others += other as usize;
            // (The first id operand is the pointer; the others are the
            // value and any memory-model scope.)
            let store = (op == Op::Store && copy == Copy::None)
                .then(|| body.ids(at).split_first())
                .flatten()
                .and_then(|(ptr, rest)| {
                    let p = self.roots.get(ptr).filter(|p| p.exact)?;
                    (!rest.iter().any(|x| self.roots.contains_key(x))).then_some(p)
                });
            steps[at - f.start] = if let Some(p) = store {
                Step::Store {
                    var: p.var,
                    path: p.path,
                }
            } else if other {
                Step::Other
            } else {
                Step::Plain {
                    def,
                    uses: start..pool.len() as u32,
                }
            };
        }
        // Fold each block's runs of plain steps: stepping back over
        // "kill d, then make U live" after (kill K, then make G live) is
        // (kill K ∪ {d}, then make (G − {d}) ∪ U live).
        // At most a run before each other step and one at each block's end.
        let mut segments = Vec::with_capacity(2 * others + f.blocks.len());
        let mut block_segments = Vec::with_capacity(f.blocks.len() + 1);
        // The run being folded, as short lists (only the variables' parts
        // a run reads: most instructions touch none); written to the pool
        // when it ends, and not at all when empty.
        let (mut kill, mut gen): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
        let mut from = 0u32;
        let end_run = |kill: &mut Vec<u32>,
                       gen: &mut Vec<u32>,
                       pool: &mut Vec<u32>,
                       segments: &mut Vec<Segment>,
                       from: u32| {
            if kill.is_empty() && gen.is_empty() {
                return;
            }
            let k0 = pool.len() as u32;
            pool.append(kill);
            let g0 = pool.len() as u32;
            pool.append(gen);
            let g1 = pool.len() as u32;
            segments.push(Segment::Run {
                kill: k0..g0,
                gen: g0..g1,
                from,
            });
        };
        for b in 0..f.blocks.len() {
            block_segments.push(segments.len() as u32);
            for &at in Body::in_block(touched, f, b).iter().rev() {
                let at = at as usize;
                match &steps[at - f.start] {
                    Step::Skip => {}
                    Step::Plain { def, uses } => {
                        from = at as u32;
                        if *def != Places::NONE {
                            if !kill.contains(def) {
                                kill.push(*def);
                            }
                            gen.retain(|g| g != def);
                        }
                        for &u in &pool[uses.start as usize..uses.end as usize] {
                            if !gen.contains(&u) {
                                gen.push(u);
                            }
                        }
                    }
                    Step::Store { .. } | Step::Other => {
                        end_run(&mut kill, &mut gen, &mut pool, &mut segments, from);
                        segments.push(Segment::Inst(at));
                    }
                }
            }
            end_run(&mut kill, &mut gen, &mut pool, &mut segments, from);
        }
        block_segments.push(segments.len() as u32);
        self.steps = steps;
        self.step_uses = pool;
        self.segments = segments;
        self.block_segments = block_segments;
        let _ = self.mentions.set(mentions.finish());
    }

    /// Backward transfer of a whole block over the live set (as stepping
    /// back over each of its instructions).
    fn block_back(&self, program: &Program, b: usize, live: &mut BitSet) {
        let range = self.block_segments[b] as usize..self.block_segments[b + 1] as usize;
        for seg in &self.segments[range] {
            self.segment_back(program, seg, live);
        }
    }

    #[inline]
    fn segment_back(&self, program: &Program, seg: &Segment, live: &mut BitSet) {
        match seg {
            Segment::Run { kill, gen, .. } => {
                for &k in &self.step_uses[kill.start as usize..kill.end as usize] {
                    live.remove(k);
                }
                for &g in &self.step_uses[gen.start as usize..gen.end as usize] {
                    live.insert(g);
                }
            }
            Segment::Inst(at) => self.step_back(program, *at, live),
        }
    }

    /// Whether instruction `i` is half of a copy.
    #[inline]
    fn copy_at(&self, i: usize) -> Copy {
        let k = i - self.body.start();
        self.copy.get(k).copied().unwrap_or(Copy::None)
    }

    fn function<'p>(&self, program: &'p Program) -> &'p Function {
        &program.functions[self.func]
    }

    #[inline]
    fn root(&self, id: Id) -> Option<Id> {
        self.roots.get(&id).map(|p| p.var)
    }

    /// Backward transfer of one instruction over the live set. Debug-info
    /// instructions (`DebugDeclare`, `DebugValue`) neither read nor write.
    fn step_back(&self, program: &Program, at: usize, live: &mut BitSet) {
        let start = program.functions[self.func].start;
        match at.checked_sub(start).and_then(|k| self.steps.get(k)) {
            Some(Step::Skip) => return,
            Some(Step::Plain { def, uses }) => {
                if *def != Places::NONE {
                    live.remove(*def);
                }
                for &u in &self.step_uses[uses.start as usize..uses.end as usize] {
                    live.insert(u);
                }
                return;
            }
            Some(Step::Store { var, path }) => {
                let places = &mut *self.places.borrow_mut();
                let path = &self.paths[path.0 as usize..path.1 as usize];
                self.kill(program, places, live, *var, path);
                return;
            }
            _ => {}
        }
        let body = &self.body;
        if body.debug(at) {
            return;
        }
        let places = &mut *self.places.borrow_mut();
        let op = body.op(at);
        if let Some(r) = body.result(at) {
            if let Some(i) = places.get(r, &[]) {
                live.remove(i);
            }
            // An initializer writes the whole variable.
            if op == Op::Variable {
                for i in places.of(r) {
                    live.remove(i);
                }
            }
        }
        let copy = self.copy_at(at);
        if let Copy::Store(load) = copy {
            // A copy: the parts of the target live after it were the same
            // parts of the source.
            let dst_ptr = body.first(at);
            let src_ptr = body.first(load as usize);
            if let (Some(dst), Some(src)) = (
                dst_ptr.and_then(|p| self.roots.get(&p)),
                src_ptr.and_then(|p| self.roots.get(&p)),
            ) {
                let dst_path = self.path(dst);
                let wanted: Vec<Vec<u32>> = places
                    .of(dst.var)
                    .filter(|&i| live.contains(i))
                    .filter_map(|i| {
                        let q = places.place(i).1;
                        if has_prefix(q, dst_path) {
                            Some(q[dst_path.len()..].to_vec())
                        } else if has_prefix(dst_path, q) {
                            Some(Vec::new())
                        } else {
                            None
                        }
                    })
                    .collect();
                self.kill(program, places, live, dst.var, dst_path);
                for r in wanted {
                    with_joined(self.path(src), &r, |path| {
                        live.insert(places.intern(src.var, path));
                    });
                }
                return;
            }
        }
        if copy == Copy::Load {
            // Its read is the copy's, handled at the store.
            if let Some(i) = body.result(at).and_then(|r| places.get(r, &[])) {
                live.remove(i);
            }
            return;
        }
        match op {
            // Phi operands are used on the incoming edge, handled by `solve`.
            Op::Phi => return,
            Op::Store | Op::CopyMemory | Op::CopyMemorySized => {
                if let Some(ptr) = body.first(at) {
                    if let Some(p) = self.roots.get(&ptr).filter(|p| p.exact) {
                        self.kill(program, places, live, p.var, self.path(p));
                    }
                }
            }
            _ => {}
        }
        let derives = derives_pointer(op);
        for (k, id) in body.ids(at).iter().enumerate() {
            if let Some(p) = self.roots.get(id) {
                // Deriving a pointer reads nothing; a store's target is
                // written, not read; anything else may read the variable.
                let reads = match op {
                    _ if derives => false,
                    Op::Store | Op::CopyMemory | Op::CopyMemorySized => k != 0,
                    Op::Variable => false,
                    _ => true,
                };
                if !reads {
                    continue;
                }
                // A call writes what the callee writes on every path, then
                // reads only what it may read before writing (an `out`
                // parameter's temporary is not read).
                let effect = (op == Op::FunctionCall && k > 0 && p.exact)
                    .then(|| self.call_reads.get(&at)?.get(k - 1))
                    .flatten();
                let base = self.path(p);
                if let Some(e) = effect {
                    for w in &e.writes {
                        with_joined(base, w, |path| {
                            self.kill(program, places, live, p.var, path);
                        });
                    }
                }
                match effect.and_then(|e| e.reads.as_ref()) {
                    Some(parts) => {
                        for q in parts {
                            with_joined(base, q, |path| {
                                live.insert(places.intern(p.var, path));
                            });
                        }
                    }
                    None => {
                        live.insert(places.intern(p.var, base));
                    }
                }
            }
        }
        // A call overwrites the `Private` variables its callee writes
        // whole before anything can branch, and may read those it reads
        // (others it writes are not taken as overwritten: the safe side).
        if let Some(c) = self.private_callee(program, at) {
            for v in &self.private.must[c] {
                if self.roots.contains_key(v) {
                    self.kill(program, places, live, *v, &[]);
                }
            }
            for v in &self.private.reads[c] {
                if self.roots.contains_key(v) {
                    live.insert(places.intern(*v, &[]));
                }
            }
        }
    }

    /// The callee of call `at` when the module has `Private` variables.
    #[inline]
    fn private_callee(&self, program: &Program, at: usize) -> Option<usize> {
        if self.private.all.is_empty() || self.body.op(at) != Op::FunctionCall {
            return None;
        }
        self.body.first(at).and_then(|c| program.function_index(c))
    }

    /// A write of exactly part `path` of `var`: that part and everything
    /// inside it is dead before the write; a live enclosing part stays
    /// live only in the pieces the write does not cover.
    fn kill(
        &self,
        program: &Program,
        places: &mut Places,
        live: &mut BitSet,
        var: Id,
        path: &[u32],
    ) {
        // The parts inside go at once; the (rare) enclosing ones are split
        // after, when the places can be added to: a short list for those,
        // on the stack. (A split piece is never inside the part written,
        // so the order does not matter.)
        const ROOM: usize = 8;
        let mut enclosing = [0u32; ROOM];
        let mut n = 0;
        let mut more: Vec<u32> = Vec::new();
        for i in places.of(var) {
            if !live.contains(i) {
                continue;
            }
            let q = places.place(i).1;
            if has_prefix(q, path) {
                live.remove(i);
            } else if has_prefix(path, q) {
                if n < ROOM {
                    enclosing[n] = i;
                    n += 1;
                } else {
                    more.push(i);
                }
            }
        }
        for i in enclosing[..n].iter().copied().chain(more) {
            // (An enclosing part is a prefix of `path`: its length says it.)
            let outer = &path[..places.place(i).1.len()];
            if let Some(pieces) = self.split(program, var, outer, path) {
                live.remove(i);
                // Each piece is `path[..d]` and one sibling index.
                for (d, j) in pieces {
                    with_joined(&path[..d], &[j], |p| {
                        live.insert(places.intern(var, p));
                    });
                }
            }
        }
    }

    /// The parts of `outer` not inside `inner` (a longer path below it), as
    /// the siblings met on the way down, each `inner[..depth]` and a last
    /// index (given as the pair); `None` when a composite on the way has no
    /// known, small element count.
    fn split(
        &self,
        program: &Program,
        var: Id,
        outer: &[u32],
        inner: &[u32],
    ) -> Option<Vec<(usize, u32)>> {
        let mut ty = program
            .def(var)
            .and_then(|d| d.result_type)
            .and_then(|t| pointee(program, t))?;
        for &i in outer {
            ty = element_type(program, ty, i)?;
        }
        let mut out = Vec::new();
        for (depth, &at) in inner.iter().enumerate().skip(outer.len()) {
            let n = element_count(program, ty)?;
            if n > MAX_SPLIT {
                return None;
            }
            out.extend((0..n).filter(|&j| j != at).map(|j| (depth, j)));
            ty = element_type(program, ty, at)?;
        }
        Some(out)
    }

    /// Variables an instruction may write. A constant initializer does not
    /// count: until something else is stored, the variable holds a
    /// constant, which is recomputed rather than kept across a call.
    /// (Given to `each` one by one: asked of every instruction, and most
    /// write nothing.)
    fn writes(&self, program: &Program, i: usize, each: impl FnMut(Id)) {
        let body = &self.body;
        match body.op(i) {
            Op::Load | Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => {}
            _ if body.debug(i) => {}
            Op::Variable if !body.ids(i).is_empty() => {
                let init = body.ids(i)[0];
                let constant = program.constants.contains_key(&init)
                    || program.spec_constants.contains_key(&init);
                if !constant {
                    body.result(i).into_iter().for_each(each);
                }
            }
            _ => body
                .ids(i)
                .iter()
                .filter_map(|&id| self.root(id))
                .for_each(each),
        }
    }

    fn solve(&mut self, program: &Program) {
        let f = self.function(program);
        let n = f.blocks.len();
        // Every place met so far fits from the start: the rows widen only
        // when the loop below meets new places (a copy's or a call's parts).
        let known = self.places.get_mut().list.len();
        let mut live_in = Rows::new(n, known.div_ceil(64));
        let mut live_out = Rows::new(n, known.div_ceil(64));
        // A worklist: a block is redone only when a successor's live-in
        // grew (every block once first, last block first), instead of every
        // block every round until a whole round changes nothing.
        let mut work = Worklist::new(n, (0..n).filter(|&b| self.focus.blocks[b]));
        // One live set and one live-out set, reused for every visit.
        let mut live = BitSet::default();
        let mut out = BitSet::default();
        while let Some(b) = work.pop() {
            out.clear();
            out.reserve_indices((live_in.w * 64) as u32);
            for &s in &f.blocks[b].succs {
                if s < n {
                    out.union_words(live_in.row(s));
                }
            }
            live.clone_from(&out);
            self.block_back(program, b, &mut live);
            let w = live.words().len().max(out.words().len());
            live_in.widen(w);
            live_out.widen(w);
            live_out.set_row(b, out.words());
            if !live.same_words(live_in.row(b)) {
                live_in.set_row(b, live.words());
                for &p in &self.preds[b] {
                    if self.focus.blocks[p] {
                        work.push(p);
                    }
                }
            }
        }
        self.live_out = live_out;
    }

    /// Ids live just after instruction `inst` (SSA values and variables).
    pub fn live_after(&self, program: &Program, inst: usize) -> HashSet<Id> {
        let mut places = SitePlaces::default();
        self.places_after(program, inst, &mut places);
        places.list.iter().map(|&(id, _, _)| id).collect()
    }

    /// Adds the SSA values and parts of variables live just after
    /// instruction `inst` to `out` (each once).
    fn places_after(&self, program: &Program, inst: usize, out: &mut SitePlaces) {
        let mut live = std::mem::take(&mut out.live);
        if let Some(b) = self.live_parts_into(program, inst, &mut live) {
            {
                let places = self.places.borrow();
                for i in live.iter() {
                    let (id, path) = places.place(i);
                    out.push(id, path);
                }
            }
            let ssa = self.ssa.get_or_init(|| SsaLive::new(self, program));
            let mut words = std::mem::take(&mut out.words);
            ssa.after(self, b, inst, &mut words, |id| out.push(id, &[]));
            out.words = words;
        }
        out.live = live;
    }

    /// The block of instruction `inst`, and the places of the parts live
    /// just after it (by index).
    fn live_parts_after(&self, program: &Program, inst: usize) -> Option<(usize, BitSet)> {
        let mut live = BitSet::default();
        let b = self.live_parts_into(program, inst, &mut live)?;
        Some((b, live))
    }

    /// The block of instruction `inst`; `live` := the places of the parts
    /// live just after it (by index).
    fn live_parts_into(&self, program: &Program, inst: usize, live: &mut BitSet) -> Option<usize> {
        let f = self.function(program);
        let b = block_at(f, inst)?;
        live.clear();
        live.union_words(self.live_out.row(b));
        // The block's folded segments wholly after `inst` first (a callee's
        // entry asks about the whole block), then instruction by
        // instruction below the last one taken.
        let mut below = f.blocks[b].end + 1;
        let range = self.block_segments[b] as usize..self.block_segments[b + 1] as usize;
        for seg in &self.segments[range] {
            let first = match *seg {
                Segment::Run { from, .. } => from as usize,
                Segment::Inst(at) => at,
            };
            if first <= inst {
                break;
            }
            self.segment_back(program, seg, live);
            below = first;
        }
        for &k in self.body.block_after(b, inst).iter().rev() {
            if (k as usize) < below {
                self.step_back(program, k as usize, live);
            }
        }
        Some(b)
    }

    /// Bytes of the live parts of variable `var` (of type `ty`): all of it
    /// when the whole is live, else the sum of the outermost live parts.
    fn live_part_size<'a>(
        program: &Program,
        ty: Id,
        paths: impl Iterator<Item = &'a [u32]> + Clone,
    ) -> u64 {
        let whole = scalar_size(program, ty).unwrap_or(0);
        if paths.clone().any(|p| p.is_empty()) {
            return whole;
        }
        let outer = paths
            .clone()
            .filter(|p| !paths.clone().any(|q| q.len() < p.len() && has_prefix(p, q)));
        let mut sum = 0;
        for p in outer {
            let mut t = ty;
            for &i in p.iter() {
                match element_type(program, t, i) {
                    Some(e) => t = e,
                    None => return whole,
                }
            }
            sum += scalar_size(program, t).unwrap_or(0);
        }
        sum.min(whole)
    }

    /// Whether variable `var` may be written before instruction `inst`
    /// (on some path to it): asked only of the live variables, so only
    /// their own writes are looked at. A write earlier in the block, or
    /// one in a block with a path to it (a walk back over the
    /// predecessors), not a forward solution for every variable.
    fn written_before(&self, program: &Program, var: Id, inst: usize) -> bool {
        let f = self.function(program);
        let Some(b) = block_at(f, inst) else {
            return false;
        };
        // Only an instruction that mentions `var` can write it.
        let Some(mentions) = self.mentions(program, var) else {
            return false;
        };
        let writes = |k: usize| self.mention_writes(program, k, var);
        let from = mentions.partition_point(|&i| i < f.blocks[b].start);
        let to = mentions.partition_point(|&i| i < inst);
        if mentions[from..to.max(from)].iter().any(|&k| writes(k)) {
            return true;
        }
        let mut mb = self.mention_blocks.borrow_mut();
        let runs = self.mention_runs(&mut mb, program, var, &mentions);
        let mut walk = self.walk.borrow_mut();
        let stamp = walk.start(f.blocks.len());
        let Walk {
            work, seen, wrote, ..
        } = &mut *walk;
        let mut any = false;
        for &(wb, from, to) in runs {
            if mentions[from as usize..to as usize]
                .iter()
                .any(|&k| writes(k))
            {
                wrote[wb as usize] = stamp;
                any = true;
            }
        }
        if !any {
            return false;
        }
        // The blocks with a path to `b`: any of them that writes `var`.
        work.clear();
        work.push((b, 0));
        while let Some((c, _)) = work.pop() {
            for &p in &self.preds[c] {
                if seen[p] != stamp {
                    if wrote[p] == stamp {
                        return true;
                    }
                    seen[p] = stamp;
                    work.push((p, 0));
                }
            }
        }
        false
    }

    /// [`FnLiveness::written_before`], but for a `Private` variable in a
    /// function a caller may have written it before: whether anything in
    /// the module writes it.
    fn written_before_here(&self, program: &Program, var: Id, inst: usize) -> bool {
        if !self.is_entry && self.private.is_private(var) {
            return self
                .private
                .writes
                .iter()
                .any(|w| w.binary_search(&var).is_ok());
        }
        self.written_before(program, var, inst)
    }

    /// Whether instruction `i`, which mentions variable `var`, may write it
    /// (as [`FnLiveness::writes`] says): without looking through its
    /// operands again, since mentioning `var` is having an operand in it
    /// (or being its `OpVariable`).
    #[inline]
    fn mention_writes(&self, program: &Program, i: usize, var: Id) -> bool {
        let body = &self.body;
        match body.op(i) {
            Op::Load | Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => false,
            _ if body.debug(i) => false,
            // An initializer, or no write; an odd instruction that defines
            // `var` as well as mentioning it, looked at in full.
            Op::Variable => self.writes_var(program, i, var),
            _ if body.result(i) == Some(var) => self.writes_var(program, i, var),
            // A `Private` variable a call mentions only through its callee.
            Op::FunctionCall
                if self.private.is_private(var) && !self.writes_var(program, i, var) =>
            {
                self.private_callee(program, i)
                    .is_some_and(|c| self.private.writes(c, var))
            }
            _ => true,
        }
    }

    /// Whether instruction `i` may write variable `var` (see
    /// [`FnLiveness::writes`]).
    fn writes_var(&self, program: &Program, i: usize, var: Id) -> bool {
        let mut hit = false;
        self.writes(program, i, |id| hit |= id == var);
        hit
    }

    /// Adds to `out` the places in this function that call `call` passes
    /// for the callee's parameter parts in `params` (parameter index, path).
    fn arguments_of(
        &self,
        program: &Program,
        call: usize,
        params: &SitePlaces,
        out: &mut SitePlaces,
    ) {
        if self.body.op(call) != Op::FunctionCall {
            return;
        }
        let args = &self.body.ids(call)[1..];
        for (k, &(param, _, _)) in params.list.iter().enumerate() {
            let Some(root) = args.get(param as usize).and_then(|a| self.roots.get(a)) else {
                continue;
            };
            // A copy the callee only reads holds what its source does
            // while the callee runs: the source's part, counted once.
            let never_writes = self
                .call_reads
                .get(&call)
                .and_then(|e| e.get(param as usize))
                .is_some_and(|e| e.never_writes);
            let source = (root.exact && never_writes)
                .then(|| self.copied_from(program, call, root.var))
                .flatten();
            if let Some((src, src_path)) = source {
                let mut path = src_path.to_vec();
                path.extend_from_slice(self.path(root));
                out.push_joined(src, &path, params.path(k));
            } else if root.exact {
                out.push_joined(root.var, self.path(root), params.path(k));
            } else {
                out.push(root.var, self.path(root));
            }
        }
    }

    /// When local variable `tmp` holds, at call `call`, a whole copy of a
    /// part of another local variable made just before in the same block
    /// (glslang's and rtlint's temporary for an argument passed by value),
    /// with neither written since and the source not passed to the call:
    /// that source and its path.
    fn copied_from(&self, program: &Program, call: usize, tmp: Id) -> Option<(Id, &[u32])> {
        if !self.vars.contains(&tmp) || self.private.is_private(tmp) {
            return None;
        }
        let f = self.function(program);
        let b = block_at(f, call)?;
        let mentions = self.mentions(program, tmp)?;
        let before = mentions.partition_point(|&i| i < call);
        // The last mention of the temporary before the call: the copy.
        let store = *mentions[..before].last()?;
        if store < f.blocks[b].start {
            return None;
        }
        let Copy::Store(load) = self.copy_at(store) else {
            return None;
        };
        let dst = self.roots.get(&self.body.first(store)?)?;
        if dst.var != tmp || !self.path(dst).is_empty() {
            return None;
        }
        let src = self.roots.get(&self.body.first(load as usize)?)?;
        if !src.exact
            || src.var == tmp
            || !self.vars.contains(&src.var)
            || self.private.is_private(src.var)
        {
            return None;
        }
        // Neither written between the copy and the call; the source not
        // given to the call.
        let src_mentions = self.mentions(program, src.var)?;
        let between = |i: usize| load as usize <= i && i < call;
        if src_mentions.iter().any(|&i| {
            (between(i) && i != load as usize && self.mention_writes(program, i, src.var))
                || i == call
        }) {
            return None;
        }
        Some((src.var, self.path(src)))
    }

    /// The caller's parts that call `call` passes for the callee's
    /// parameter parts in `written` (parameter index, path), each as
    /// (variable, path): only exact ones (a part reached through a
    /// variable index may be another).
    fn rewritten_arguments(&self, call: usize, written: &SitePlaces) -> Vec<(Id, Vec<u32>)> {
        if self.body.op(call) != Op::FunctionCall {
            return Vec::new();
        }
        let args = &self.body.ids(call)[1..];
        let mut out = Vec::new();
        for (k, &(param, _, _)) in written.list.iter().enumerate() {
            let Some(root) = args.get(param as usize).and_then(|a| self.roots.get(a)) else {
                continue;
            };
            if root.exact {
                let mut path = self.path(root).to_vec();
                path.extend_from_slice(written.path(k));
                out.push((root.var, path));
            }
        }
        out
    }

    /// Drops from `places` (live just after call `call`) the parts the
    /// callee writes on every path from its site to its return (`written`,
    /// by parameter index): they get a new value before anything reads
    /// them, so what they held during the site is not kept (glslang's
    /// `out` temporaries, an `inout` payload copied back).
    fn drop_rewritten(&self, call: usize, written: &SitePlaces, places: &mut SitePlaces) {
        if written.list.is_empty() {
            return;
        }
        let parts = self.rewritten_arguments(call, written);
        let paths = &places.paths;
        places.list.retain(|&(id, from, to)| {
            let q = &paths[from as usize..to as usize];
            !parts
                .iter()
                .any(|(var, path)| *var == id && has_prefix(q, path))
        });
    }

    /// `out` := the parts of this function's pointer parameters written on
    /// every path from instruction `at` to a return, by parameter index;
    /// with call `at`'s callee writing `written` (by its parameter index)
    /// after the site below it.
    fn params_written_after(
        &self,
        program: &Program,
        at: usize,
        written: &SitePlaces,
        out: &mut SitePlaces,
    ) {
        out.clear();
        let f = self.function(program);
        if !f
            .params
            .iter()
            .any(|p| self.roots.get(p).is_some_and(|r| r.var == *p))
        {
            return;
        }
        let seeds = self.rewritten_arguments(at, written);
        for (k, &param) in f.params.iter().enumerate() {
            if self.roots.get(&param).is_none_or(|r| r.var != param) {
                continue;
            }
            let seed: Vec<Vec<u32>> = seeds
                .iter()
                .filter(|(v, _)| *v == param)
                .map(|(_, p)| p.clone())
                .collect();
            for path in self.written_on_every_path_from(program, param, Some(at), &seed) {
                out.push(k as Id, &path);
            }
        }
    }

    /// `out` := the parts behind this function's pointer parameters among
    /// the `places` live across an instruction, by parameter index.
    fn param_parts_across(&self, program: &Program, places: &SitePlaces, out: &mut SitePlaces) {
        let f = self.function(program);
        out.clear();
        for (k, &(v, _, _)) in places.list.iter().enumerate() {
            if let Some(param) = f.params.iter().position(|&p| p == v) {
                out.push(param as Id, places.path(k));
            }
        }
    }

    /// The values among `places` (those live just after instruction
    /// `inst`, with the caller's parts passed to this function) that count
    /// across `inst`; with `described`, named, typed and placed too.
    fn live_across(
        &self,
        program: &Program,
        inst: usize,
        places: &SitePlaces,
        described: bool,
        mut each: impl FnMut(LiveValue),
    ) {
        // The places by id: each value's parts side by side, in order
        // (see `SitePlaces::sort`).
        let by_id = &places.list;
        let result = self.body.result(inst);
        let mut k = 0;
        while k < by_id.len() {
            let id = by_id[k].0;
            let from = k;
            while k < by_id.len() && by_id[k].0 == id {
                k += 1;
            }
            let parts = (from..k).map(|j| places.path(j));
            if Some(id) == result {
                continue;
            }
            let is_var = self.vars.contains(&id);
            if is_var && !self.written_before_here(program, id, inst) {
                continue;
            }
            let ty = if is_var {
                program
                    .def(id)
                    .and_then(|d| d.result_type)
                    .and_then(|t| pointee(program, t))
            } else {
                program.def(id).and_then(|d| d.result_type)
            };
            let Some(ty) = ty else { continue };
            // Logical pointers are addresses the compiler folds away, and
            // void call results are no values.
            match program.ty(ty) {
                Some(Type::Pointer { storage, .. })
                    if *storage != StorageClass::PhysicalStorageBuffer =>
                {
                    continue
                }
                Some(Type::Void) | None => continue,
                _ => {}
            }
            let rematerializable = if is_var {
                self.remat_var(program, id, inst, parts.clone(), 0)
            } else {
                self.remat_ssa(program, id, 0)
            };
            let size = if is_var {
                FnLiveness::live_part_size(program, ty, parts)
            } else {
                scalar_size(program, ty).unwrap_or(0)
            };
            let storage = if is_var {
                Storage::Variable
            } else {
                Storage::Ssa
            };
            if !described {
                each(LiveValue {
                    name: String::new(),
                    ty: String::new(),
                    size,
                    rematerializable,
                    storage,
                    def_line: None,
                    use_line: None,
                    id,
                    def: None,
                    use_at: None,
                });
                continue;
            }
            let def = if is_var {
                self.var_def_location(program, id)
            } else {
                program.defs.get(&id).and_then(|&i| {
                    program.inst_location(i).or_else(|| {
                        // A builtin or resource loaded where the compiler
                        // gave no line (naga's entry-point prologue): where
                        // the global is declared.
                        let inst = &program.insts[i];
                        let ptr = id_operands(inst).next()?;
                        (inst.class.opcode == Op::Load
                            && program.globals.iter().any(|g| g.id == ptr))
                        .then(|| program.var_location(ptr))
                        .flatten()
                    })
                })
            };
            // A variable is read only where it is mentioned: look nowhere else.
            let mentions = if is_var {
                self.mentions(program, id)
            } else {
                None
            };
            let use_at = self.first_use_after(program, inst, id, mentions.as_deref());
            each(LiveValue {
                name: value_name(program, id, def.as_ref()),
                ty: program.type_name(ty),
                size,
                rematerializable,
                storage,
                def_line: def.as_ref().map(|l| l.line),
                use_line: use_at.as_ref().map(|l| l.line),
                id,
                def,
                use_at,
            });
        }
    }

    fn reads(&self, program: &Program, i: usize, id: Id) -> bool {
        let body = &self.body;
        if body.debug(i) {
            return false;
        }
        let ids = body.ids(i);
        if body.op(i) == Op::Phi {
            return ids.iter().step_by(2).any(|&x| x == id);
        }
        if self.vars.contains(&id) {
            match body.op(i) {
                Op::Load | Op::FunctionCall | Op::CopyMemory | Op::ExtInst => {
                    ids.iter().any(|&x| self.root(x) == Some(id))
                        || self
                            .private_callee(program, i)
                            .is_some_and(|c| self.private.reads(c, id))
                }
                _ => false,
            }
        } else {
            ids.contains(&id)
        }
    }

    /// The position of the first instruction after `inst` that reads `id`
    /// (breadth-first over the CFG, loops included).
    fn first_use_after(
        &self,
        program: &Program,
        inst: usize,
        id: Id,
        only: Option<&[usize]>,
    ) -> Option<Location> {
        let f = self.function(program);
        let b0 = block_at(f, inst)?;
        let reads = |k: usize| {
            only.is_none_or(|m| m.binary_search(&k).is_ok()) && self.reads(program, k, id)
        };
        let mut found = None;
        for k in inst + 1..=f.blocks[b0].end {
            if reads(k) {
                found = Some(k);
                break;
            }
        }
        if found.is_none() {
            let mut seen = vec![false; f.blocks.len()];
            let mut queue: VecDeque<usize> = f.blocks[b0].succs.iter().copied().collect();
            'bfs: while let Some(b) = queue.pop_front() {
                if std::mem::replace(&mut seen[b], true) {
                    continue;
                }
                for k in f.blocks[b].start..=f.blocks[b].end {
                    if reads(k) {
                        found = Some(k);
                        break 'bfs;
                    }
                }
                queue.extend(f.blocks[b].succs.iter().copied());
            }
        }
        let k = found?;
        // Compiler-generated loads often lack a line; the next one with a
        // position is where the source uses the value.
        (k..=f.end).find_map(|i| program.inst_location(i))
    }

    /// Where a variable gets its value: the first write with a position,
    /// else its declaration.
    fn var_def_location(&self, program: &Program, var: Id) -> Option<Location> {
        let f = self.function(program);
        (f.start..=f.end)
            .filter(|&i| {
                self.body.op(i) == Op::Store
                    && self.body.first(i).and_then(|p| self.root(p)) == Some(var)
            })
            .find_map(|i| program.inst_location(i))
            .or_else(|| program.decl_location(crate::program::Decl::Var(var)))
    }

    /// Whether an SSA value can be recomputed after the trace from builtins,
    /// push constants, uniform or storage loads and constants.
    fn remat_ssa(&self, program: &Program, id: Id, depth: u32) -> bool {
        // Answers that do not depend on `depth` are kept too (constants,
        // ids defined outside the function): asked again for every use.
        if let Some(r) = self.remat.borrow().get(id) {
            return r;
        }
        if program.constants.contains_key(&id) || program.spec_constants.contains_key(&id) {
            self.remat.borrow_mut().insert(id, true);
            return true;
        }
        let Some(&i) = program.defs.get(&id) else {
            self.remat.borrow_mut().insert(id, false);
            return false;
        };
        let f = self.function(program);
        let inside = (f.start..=f.end).contains(&i);
        let op = if inside {
            self.body.op(i)
        } else {
            program.insts[i].class.opcode
        };
        if op == Op::Undef || !inside {
            self.remat.borrow_mut().insert(id, op == Op::Undef);
            return op == Op::Undef;
        }
        if depth > 64 {
            return false;
        }
        // Cycles through phis are loop-carried: not recomputable.
        self.remat.borrow_mut().insert(id, false);
        let r = match op {
            Op::Phi | Op::FunctionCall | Op::FunctionParameter | Op::Variable => false,
            // A clock reads time, and subgroup operations depend on which
            // invocations are active: neither gives the same value again.
            Op::ReadClockKHR => false,
            _ if varies(op) => false,
            Op::Load => {
                let ptr = self.body.first(i).unwrap_or(0);
                match self.root(ptr) {
                    // The caller's value: not known here.
                    Some(v) if !self.vars.contains(&v) => false,
                    Some(v) => {
                        let part = self.roots.get(&ptr).map(|p| self.path(p));
                        self.remat_var(program, v, i, part.into_iter(), depth + 1)
                    }
                    // A buffer_reference pointer is an address computed like
                    // any value: the load is recomputable when it is.
                    None if self.physical_pointer(program, ptr) => {
                        self.remat_ssa(program, ptr, depth + 1)
                    }
                    None => self.remat_global_ptr(program, ptr, depth + 1),
                }
            }
            // Extended-instruction sets are ids too: they are constant.
            // (Asked after the value itself, which is no set but for those:
            // the set's definition is looked up only then.)
            _ => self.body.ids(i).iter().all(|&x| {
                self.remat_ssa(program, x, depth + 1)
                    || matches!(
                        program.def(x).map(|d| d.class.opcode),
                        Some(Op::ExtInstImport)
                    )
            }),
        };
        self.remat.borrow_mut().insert(id, r);
        r
    }

    /// Whether `ptr` is a `PhysicalStorageBuffer` pointer (GLSL
    /// `buffer_reference`, HLSL `vk::RawBufferLoad`).
    fn physical_pointer(&self, program: &Program, ptr: Id) -> bool {
        let ty = program.def(ptr).and_then(|d| d.result_type);
        matches!(
            ty.and_then(|t| program.ty(t)),
            Some(Type::Pointer {
                storage: StorageClass::PhysicalStorageBuffer,
                ..
            })
        )
    }

    fn remat_global_ptr(&self, program: &Program, ptr: Id, depth: u32) -> bool {
        // As deep as `remat_ssa` looks; an access chain that is its own base
        // (invalid, found by fuzzing) recursed until the stack overflowed.
        if depth > 64 {
            return false;
        }
        if let Some(g) = program.globals.iter().find(|g| g.id == ptr) {
            return matches!(
                g.storage,
                StorageClass::Input
                    | StorageClass::PushConstant
                    | StorageClass::Uniform
                    | StorageClass::UniformConstant
                    | StorageClass::StorageBuffer
                    | StorageClass::ShaderRecordBufferKHR
            );
        }
        let Some(inst) = program.def(ptr) else {
            return false;
        };
        match inst.class.opcode {
            Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => {
                let ids: Vec<Id> = id_operands(inst).collect();
                let Some((&base, idx)) = ids.split_first() else {
                    return false;
                };
                self.remat_global_ptr(program, base, depth + 1)
                    && idx.iter().all(|&x| self.remat_ssa(program, x, depth + 1))
            }
            _ => false,
        }
    }

    /// A variable read at instruction `at` is recomputable when the writes
    /// that reach `at` store recomputable values, no two of them store
    /// different values into the same part (a merge of paths, like a phi, or
    /// a value that changed), and nothing else (a call, an atomic) gets its
    /// address. Only writes to the `parts` read count (all of them when
    /// `parts` is empty or holds the whole variable).
    fn remat_var<'a>(
        &self,
        program: &Program,
        var: Id,
        at: usize,
        parts: impl Iterator<Item = &'a [u32]> + Clone,
        depth: u32,
    ) -> bool {
        // A `Private` variable outside an entry point's function holds what
        // a caller stored: not known here, unless only ever one constant.
        if !self.is_entry && self.private.is_private(var) {
            return self.private.is_constant(var);
        }
        // The parts in order, flattened at the end of the pool (see
        // `RematAnswers`); the callers' come sorted.
        let slot = {
            let mut answers = self.remat_ok.borrow_mut();
            let RematAnswers { list, flat } = &mut *answers;
            let from = flat.len();
            let mut push = |p: &[u32]| {
                flat.push(p.len() as u32);
                flat.extend_from_slice(p);
            };
            if parts.clone().is_sorted() {
                parts.clone().for_each(&mut push);
            } else {
                let mut sorted: Vec<&[u32]> = parts.clone().collect();
                sorted.sort();
                sorted.into_iter().for_each(&mut push);
            }
            let to = flat.len();
            let first = self
                .remat_at
                .borrow()
                .get(&(var, at))
                .copied()
                .unwrap_or(RematAnswers::NONE);
            let mut q = first;
            while q != RematAnswers::NONE {
                let (f, t, ok, next) = list[q as usize];
                if same_path(&flat[f as usize..t as usize], &flat[from..to]) {
                    flat.truncate(from);
                    return ok;
                }
                q = next;
            }
            // In progress: a question that comes back to itself answers no.
            list.push((from as u32, to as u32, false, first));
            list.len() - 1
        };
        self.remat_at.borrow_mut().insert((var, at), slot as u32);
        let no_parts = parts.clone().next().is_none();
        let mentions = self.mentions(program, var);
        let (mut reaching, mut stored) = {
            let mut spare = self.spare.borrow_mut();
            (
                spare.0.pop().unwrap_or_default(),
                spare.1.pop().unwrap_or_default(),
            )
        };
        self.reaching_writes(
            program,
            var,
            at,
            mentions.as_deref().unwrap_or(&[]),
            &mut reaching,
        );
        // Both lists are sorted, and every reaching write is among the
        // mentions: whether a mention reaches is a walk along `reaching`
        // beside the mentions, not a binary search each.
        let mut next = 0;
        let mut reaches = |i: usize| {
            while next < reaching.len() && reaching[next] < i {
                next += 1;
            }
            reaching.get(next) == Some(&i)
        };
        let mut ok = true;
        // The paths stored to, as ranges of `self.paths`.
        stored.clear();
        let body = &self.body;
        for &i in mentions.iter().flat_map(|m| m.iter()) {
            let ids = body.ids(i);
            match body.op(i) {
                Op::Variable => {
                    if let Some(&init) = ids.first().filter(|_| reaches(i)) {
                        if !matches!(
                            program.constants.get(&init),
                            Some(Constant::Int(_) | Constant::Float(_) | Constant::Bool(_))
                                | Some(Constant::Null | Constant::Composite(_))
                        ) && !program.spec_constants.contains_key(&init)
                        {
                            ok = false;
                        }
                        stored.push(((0, 0), init));
                    }
                }
                // A store that cannot reach `at` does not give the value read there.
                Op::Store if !reaches(i) => {}
                Op::Store => {
                    let ptr = ids.first();
                    let value = ids.get(1).copied().unwrap_or(0);
                    let range = ptr
                        .and_then(|p| self.roots.get(p))
                        .map_or((0, 0), |p| p.path);
                    let path = &self.paths[range.0 as usize..range.1 as usize];
                    let overlaps = no_parts
                        || parts
                            .clone()
                            .any(|q| has_prefix(q, path) || has_prefix(path, q));
                    if !overlaps {
                        continue;
                    }
                    let clash = stored.iter().any(|&((s, e), v)| {
                        let q = &self.paths[s as usize..e as usize];
                        v != value && (has_prefix(q, path) || has_prefix(path, q))
                    });
                    if clash || !self.remat_ssa(program, value, depth + 1) {
                        ok = false;
                    }
                    stored.push((range, value));
                }
                Op::Load => {}
                // A callee given its address that never writes through it
                // (a struct passed by value) leaves the value as it was.
                Op::FunctionCall if self.call_never_writes(program, i, var) => {}
                Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => {
                    if !ids
                        .iter()
                        .skip(1)
                        .all(|&x| self.remat_ssa(program, x, depth + 1))
                    {
                        ok = false;
                    }
                }
                _ => ok = false,
            }
            if !ok {
                break;
            }
        }
        self.remat_ok.borrow_mut().list[slot].2 = ok;
        let mut spare = self.spare.borrow_mut();
        spare.0.push(reaching);
        spare.1.push(stored);
        ok
    }

    /// The instructions (not debug info) that define a variable or use a
    /// pointer into it, per variable, in order.
    fn mentions(&self, program: &Program, var: Id) -> Option<MentionList> {
        let all = self.mentions.get_or_init(|| {
            let f = &program.functions[self.func];
            let mut pairs = MentionPairs::new(self.roots.len(), f.end + 1 - f.start);
            for &i in self.body.kept() {
                pairs.add_inst(&self.roots, &self.vars, &self.body, i as usize);
            }
            pairs.finish()
        });
        let k = self.roots.ordinal(var)?;
        let range = *all.start.get(k)? as usize..*all.start.get(k + 1)? as usize;
        (!range.is_empty()).then(|| MentionList(all.clone(), range))
    }
}

/// The mentions of a function's roots as they are met: (root ordinal,
/// instruction) pairs in instruction order, then placed by a counting sort,
/// which keeps that order per root. By the variable's ordinal among the
/// roots (every variable and pointer parameter is its own root): no
/// hashing per mention.
struct MentionPairs {
    n: usize,
    pairs: Vec<(u32, usize)>,
    /// Where the pairs of the instruction met last start (a root is
    /// listed once per instruction).
    at: usize,
}

impl MentionPairs {
    /// For `n` roots in a function of `insts` instructions (about as many
    /// mentions at most, made room for at once).
    fn new(n: usize, insts: usize) -> MentionPairs {
        MentionPairs {
            n,
            pairs: Vec::with_capacity(if n == 0 { 0 } else { insts }),
            at: 0,
        }
    }

    /// Instruction `i` (not debug info) of a function with these roots and
    /// variables.
    fn add_inst(&mut self, roots: &IdMap<LocalPtr>, vars: &IdSet, body: &Body, i: usize) {
        let used = body
            .ids(i)
            .iter()
            .filter_map(|x| roots.get(x).map(|p| p.var));
        let defined = body.result(i).filter(|r| vars.contains(r));
        for v in defined.into_iter().chain(used) {
            self.add(roots, i, v);
        }
    }

    /// That instruction `i` mentions root `v` (its variable, or a pointer
    /// into it), met in order.
    #[inline]
    fn add(&mut self, roots: &IdMap<LocalPtr>, i: usize, v: Id) {
        if let Some(k) = roots.ordinal(v) {
            self.add_root(i, k as u32);
        }
    }

    /// That instruction `i` mentions the root of ordinal `k`.
    #[inline]
    fn add_root(&mut self, i: usize, k: u32) {
        if k as usize >= self.n {
            return;
        }
        // Instructions come in order: only the last one's pairs can hold `k`.
        if self.pairs.get(self.at).is_none_or(|&(_, j)| j != i) {
            self.at = self.pairs.len();
        }
        if !self.pairs[self.at..].iter().any(|&(q, _)| q == k) {
            self.pairs.push((k, i));
        }
    }

    fn finish(self) -> std::rc::Rc<Mentions> {
        let MentionPairs { n, pairs, .. } = self;
        // A counting sort: `start[k + 1]` counts root `k`'s mentions, then
        // (summed) is where root `k + 1`'s start; filling moves each
        // `start[k]` to the end of root `k`'s, so one shift restores it.
        let mut start = vec![0u32; n + 1];
        for &(k, _) in &pairs {
            start[k as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut list = vec![0usize; pairs.len()];
        for (k, i) in pairs {
            list[start[k as usize] as usize] = i;
            start[k as usize] += 1;
        }
        start.copy_within(0..n, 1);
        start[0] = 0;
        std::rc::Rc::new(Mentions { start, list })
    }
}

impl FnLiveness {
    /// The writes to `var` (stores, and its `OpVariable` when it has an
    /// initializer) that can give the value read at `at`: walking back from
    /// `at` along every path, up to a store of the whole variable; sorted, into `found`.
    /// Only the variable's `mentions` (sorted) can write it: a block is
    /// searched through those, not instruction by instruction.
    fn reaching_writes(
        &self,
        program: &Program,
        var: Id,
        at: usize,
        mentions: &[usize],
        found: &mut Vec<usize>,
    ) {
        let f = self.function(program);
        found.clear();
        let Some(b0) = block_at(f, at) else {
            return;
        };
        let body = &self.body;
        let whole = |i: usize| -> Option<bool> {
            match body.op(i) {
                Op::Store => {
                    let p = body.first(i).and_then(|p| self.roots.get(&p))?;
                    (p.var == var).then_some(p.exact && p.path.0 == p.path.1)
                }
                Op::Variable if body.result(i) == Some(var) => {
                    (!body.ids(i).is_empty()).then_some(true)
                }
                _ => None,
            }
        };
        // Each block's span of the mentions, looked up as the walk meets
        // it (two binary searches per block visited were most of the walk).
        let mut mb = self.mention_blocks.borrow_mut();
        let runs = self.mention_runs(&mut mb, program, var, mentions);
        let mut walk = self.walk.borrow_mut();
        let stamp = walk.start(f.blocks.len());
        let Walk {
            work, seen, span, ..
        } = &mut *walk;
        if span.len() < f.blocks.len() {
            span.resize(f.blocks.len(), (0, 0));
        }
        for &(b, from, to) in runs {
            span[b as usize] = (from, to);
        }
        // (block, last instruction to look at)
        work.clear();
        work.push((b0, at));
        while let Some((b, last)) = work.pop() {
            let mut killed = false;
            let (from, to) = span[b];
            for &i in mentions[from as usize..to as usize].iter().rev() {
                if i >= last {
                    continue;
                }
                if let Some(w) = whole(i) {
                    found.push(i);
                    if w {
                        killed = true;
                        break;
                    }
                }
            }
            if killed {
                continue;
            }
            if b == 0 {
                // The entry block holds the variables and their initializers.
                // (A module-scope variable's is outside the function.)
                if let Some(&d) = program
                    .defs
                    .get(&var)
                    .filter(|&&d| f.start <= d && d <= f.end)
                {
                    if whole(d) == Some(true) {
                        found.push(d);
                    }
                }
            }
            for &p in &self.preds[b] {
                if seen[p] != stamp {
                    seen[p] = stamp;
                    // All of it (without reading the block's bounds).
                    work.push((p, usize::MAX));
                }
            }
        }
        for &(b, _, _) in runs {
            span[b as usize] = (0, 0);
        }
        found.sort_unstable();
        found.dedup();
    }

    /// Root `var`'s mentions (`mentions`) by block (see [`MentionBlocks`]),
    /// grouped on its first question.
    fn mention_runs<'m>(
        &self,
        mb: &'m mut MentionBlocks,
        program: &Program,
        var: Id,
        mentions: &[usize],
    ) -> &'m [(u32, u32, u32)] {
        let Some(k) = self.roots.ordinal(var) else {
            return &[];
        };
        if mb.at.len() <= k {
            mb.at.resize(self.roots.len().max(k + 1), (u32::MAX, 0));
        }
        if mb.at[k].0 == u32::MAX {
            let f = self.function(program);
            let first = mb.runs.len() as u32;
            let mut j = 0;
            // Sorted: a binary search only when a mention leaves the block.
            while j < mentions.len() {
                let Some(b) = block_at(f, mentions[j]) else {
                    j += 1;
                    continue;
                };
                let from = j;
                while j < mentions.len() && mentions[j] <= f.blocks[b].end {
                    j += 1;
                }
                mb.runs.push((b as u32, from as u32, j as u32));
            }
            mb.at[k] = (first, mb.runs.len() as u32);
        }
        let (a, b) = mb.at[k];
        &mb.runs[a as usize..b as usize]
    }
}

/// The block of function `f` holding instruction `inst` (blocks are in
/// order and disjoint: a binary search, not a scan).
#[inline]
fn block_at(f: &Function, inst: usize) -> Option<usize> {
    let b = f
        .blocks
        .partition_point(|b| b.start <= inst)
        .checked_sub(1)?;
    (inst <= f.blocks[b].end).then_some(b)
}

/// Whether `op` makes a pointer into (or a copy of) its operand: using the
/// result is what reads the variable, not this instruction.
fn derives_pointer(op: Op) -> bool {
    matches!(
        op,
        Op::AccessChain
            | Op::InBoundsAccessChain
            | Op::PtrAccessChain
            | Op::CopyObject
            | Op::Bitcast
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::front::load;
    use crate::shader::Language;
    use std::path::Path;

    fn program(rel: &str) -> Program {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
        let lang = Language::from_path(&path).unwrap();
        load(&path, lang).unwrap()
    }

    fn one_site(rel: &str) -> LiveSite {
        let p = program(rel);
        let mut sites = live_sites(&p);
        assert_eq!(sites.len(), 1, "{rel}: {sites:?}");
        sites.remove(0)
    }

    fn names(site: &LiveSite) -> Vec<(&str, u64, bool)> {
        let mut v: Vec<_> = site
            .values
            .iter()
            .map(|v| (v.name.as_str(), v.size, v.rematerializable))
            .collect();
        v.sort();
        v
    }

    #[test]
    fn places_intern_once_and_list_each_ids_parts() {
        let mut p = Places::new(10, 20, &[3], 4);
        let whole = p.intern(12, &[]);
        assert_eq!(p.intern(12, &[]), whole, "interned once");
        let a = p.intern(12, &[1, 2]);
        let b = p.intern(12, &[1]);
        assert!(a != b && a != whole && b != whole);
        assert_eq!(p.intern(12, &[1, 2]), a);
        assert_eq!(p.get(12, &[1]), Some(b));
        assert_eq!(p.get(12, &[2]), None);
        assert_eq!(p.get(13, &[]), None);
        // Ids outside the dense range get their slot through a hash table.
        let far = p.intern(5, &[]);
        let far_part = p.intern(1_000, &[0]);
        assert_eq!(p.get(5, &[]), Some(far));
        assert_eq!(p.get(1_000, &[0]), Some(far_part));
        assert_eq!(p.of(12).collect::<Vec<_>>(), [whole, a, b]);
        assert_eq!(p.of(1_000).collect::<Vec<_>>(), [far_part]);
        assert_eq!(p.of(14).count(), 0);
        assert_eq!(p.place(a), (12, &[1, 2][..]));
        // A parameter (numbered apart from the body) has a slot too; its
        // parts are listed in the order met.
        let q1 = p.intern(3, &[4]);
        let q = p.intern(3, &[]);
        let q0 = p.intern(3, &[0]);
        assert_eq!(p.intern(3, &[4]), q1);
        assert_eq!(p.get(3, &[]), Some(q));
        assert_eq!(p.get(3, &[0]), Some(q0));
        assert_eq!(p.of(3).collect::<Vec<_>>(), [q, q1, q0]);
    }

    #[test]
    fn mentions_from_the_step_walk_match_a_walk_of_their_own_and_blocks_are_found() {
        // The mentions are gathered while the steps are prepared; the
        // lazy path (a walk of their own) must give the same lists, and
        // the binary search the same block as the scan.
        for rel in [
            "shaders/reflect_adaptive.hlsl",
            "shaders/reflect_glossy.wgsl",
            "shaders/reflect_hybrid.hlsl",
            "fixtures/live/loop_local.rgen.gV.spv",
        ] {
            let p = program(rel);
            let mut mentioned = 0;
            for (func, f) in p.functions.iter().enumerate() {
                let fl = FnLiveness::new(&p, func);
                let from_steps = fl.mentions.get().expect("gathered while preparing").clone();
                let mut own = MentionPairs::new(fl.roots.len(), f.end + 1 - f.start);
                for i in f.start..=f.end {
                    if !p.is_debug_inst(&p.insts[i]) {
                        own.add_inst(&fl.roots, &fl.vars, &fl.body, i);
                    }
                }
                let own = own.finish();
                assert_eq!(from_steps.start, own.start, "{rel} function {func}");
                assert_eq!(from_steps.list, own.list, "{rel} function {func}");
                mentioned += own.list.len();
                for i in f.start..=f.end {
                    assert_eq!(block_at(f, i), f.block_of(i), "{rel} instruction {i}");
                }
            }
            assert!(mentioned > 0, "{rel}: no variable mentioned");
        }
    }

    /// A function whose ids are spread over four billion (here one label
    /// numbered 1,953,523,044: a fuzzer's find) is solved with tables
    /// sized by its values, not by the span of its ids (the SSA table
    /// once asked for 7.8 GB), and answers as the same function numbered
    /// densely.
    #[test]
    fn sparse_ids_answer_as_dense_ones() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fuzz/regressions/spirv/sparse-label-id-oom.spv");
        let bytes = std::fs::read(&path).unwrap();
        let words = crate::program::words_from_bytes(&bytes, &path).unwrap();
        let label = 1_953_523_044u32;
        let at = words.iter().position(|&w| w == label).unwrap();
        let mut dense = words.clone();
        // An id below the module's others' bound and unused elsewhere.
        dense[at] = 1000;
        assert!(!words.contains(&1000));
        let sites = |w: &[u32]| -> Vec<(u64, usize)> {
            let p = crate::program::parse(w, &path, crate::shader::Language::Spirv).unwrap();
            live_sites(&p)
                .iter()
                .map(|s| (s.live_bytes, s.values.len()))
                .collect()
        };
        let sparse = sites(&words);
        assert_eq!(sparse.len(), 1, "the trace is a site");
        assert_eq!(sparse, sites(&dense));
    }

    #[test]
    fn id_maps_dense_with_parameters_apart_and_sparse() {
        // A small range is a table; the huge one hashes.
        for (lo, hi) in [(100, 200), (0, u32::MAX)] {
            let mut m: IdMap<&str> = IdMap::new(lo, hi);
            m.insert(150, "a");
            // Below the body's range, as a parameter numbered before it.
            m.insert(7, "param");
            m.insert(150, "b");
            assert_eq!(m.get(&150), Some(&"b"), "replaced, not added");
            assert_eq!(m.get(&7), Some(&"param"));
            assert!(m.contains_key(&7) && !m.contains_key(&151));
            assert_eq!(m.get(&300), None, "above the range");
            assert_eq!(m.get(&99), None, "below the range, never added");
            assert_eq!(
                (m.ordinal(150), m.ordinal(7), m.ordinal(8), m.len()),
                (Some(0), Some(1), None, 2)
            );
        }
    }

    #[test]
    fn folded_blocks_step_like_their_instructions() {
        // The fixpoint applies each block's folded runs; stepping back over
        // every instruction must give the same set, from the solved set at
        // the block's end and from one holding every place met.
        for rel in [
            "shaders/reflect_adaptive.hlsl",
            "shaders/reflect_iterative.wgsl",
            "fixtures/live/loop_local.rgen.gV.spv",
        ] {
            let p = program(rel);
            let mut runs = 0;
            for func in 0..p.functions.len() {
                let fl = FnLiveness::new(&p, func);
                runs += fl
                    .segments
                    .iter()
                    .filter(|s| matches!(s, Segment::Run { .. }))
                    .count();
                let mut all = BitSet::default();
                for i in 0..fl.places.borrow().list.len() as u32 {
                    all.insert(i);
                }
                let f = &p.functions[func];
                for (b, block) in f.blocks.iter().enumerate() {
                    let mut out = BitSet::default();
                    out.union_words(fl.live_out.row(b));
                    for start in [&out, &all] {
                        let mut by_block = start.clone();
                        fl.block_back(&p, b, &mut by_block);
                        let mut by_inst = start.clone();
                        for k in (block.start..=block.end).rev() {
                            fl.step_back(&p, k, &mut by_inst);
                        }
                        assert_eq!(by_block, by_inst, "{rel}: function {func}, block {b}");
                    }
                    // After each instruction: the segments wholly after
                    // it, then the rest one by one, as every one by one.
                    for k in block.start..=block.end {
                        let mut by_inst = out.clone();
                        for &i in fl.body.block_after(b, k).iter().rev() {
                            fl.step_back(&p, i as usize, &mut by_inst);
                        }
                        let after = fl.live_parts_after(&p, k).map(|(_, l)| l);
                        assert_eq!(after, Some(by_inst), "{rel}: function {func}, inst {k}");
                    }
                }
            }
            assert!(runs > 0, "{rel}: some runs were folded");
        }
    }

    #[test]
    fn path_prefixes() {
        assert!(has_prefix(&[1, 2, 3], &[1, 2]));
        assert!(has_prefix(&[1, 2], &[]));
        assert!(has_prefix(&[1, 2], &[1, 2]));
        assert!(!has_prefix(&[1, 2], &[1, 2, 3]));
        assert!(!has_prefix(&[1, 3], &[1, 2]));
        assert!(same_path(&[4, 5], &[4, 5]));
        assert!(!same_path(&[4, 5], &[4]) && !same_path(&[4], &[4, 5]));
        assert!(same_path(&[], &[]));
    }

    #[test]
    fn places_with_colliding_keys_stay_apart() {
        // A huge id range has no dense table: every place is hashed, and
        // many parts of one variable share chains of the same key space.
        let mut p = Places::new(0, u32::MAX, &[], 0);
        let ids: Vec<u32> = (0..200u32)
            .map(|i| p.intern(7, &[i % 10, i / 10]))
            .collect();
        for (i, &ix) in ids.iter().enumerate() {
            let i = i as u32;
            assert_eq!(p.get(7, &[i % 10, i / 10]), Some(ix));
        }
        let mut sorted = ids.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 200, "distinct paths, distinct indices");
    }

    #[test]
    fn seed_example_throughput_and_direct_light() {
        let s = one_site("fixtures/live/seed.rchit.spv");
        assert_eq!(s.kind, LiveSiteKind::TraceRay);
        assert_eq!(s.stage, Stage::ClosestHit);
        // `before` is used only before, `scratch` overwritten after the trace
        // before any read, `k` a constant: none of them is live.
        assert_eq!(
            names(&s),
            [("directLight", 12, true), ("throughput", 12, false)]
        );
        assert_eq!((s.live_bytes, s.rematerializable_bytes), (24, 12));
        // The trace is written over lines 27-28: it starts on 27.
        assert_eq!(s.line, Some(27));
        let p = s.payload.as_ref().unwrap();
        assert_eq!((p.name.as_str(), p.size), ("shadowed", Some(4)));
        let t = s.values.iter().find(|v| v.name == "throughput").unwrap();
        assert_eq!((t.def_line, t.use_line), (Some(16), Some(33)));
    }

    #[test]
    fn loop_carried_accumulator() {
        let s = one_site("fixtures/live/loop.rgen.spv");
        assert_eq!(names(&s), [("acc", 12, false), ("i", 4, false)]);
        assert_eq!(s.live_bytes, 16);
    }

    #[test]
    fn iterative_reflection_loop() {
        let p = program("shaders/reflect_iterative.wgsl");
        let sites = live_sites(&p);
        assert_eq!(sites.len(), 2, "the bounce trace and the shadow trace");
        let s = &sites[0];
        // The trace sits in naga's helper; the raygen's state is live across
        // the call: three vec3 variables, the throughput, the counter,
        // naga's loop guard, and the builtin and TLAS handle (both reloadable).
        assert_eq!(
            names(s),
            [
                ("bounce", 4, false),
                ("color", 12, false),
                ("dir", 12, false),
                ("id", 12, true),
                ("loop_bound", 8, false),
                ("origin", 12, false),
                ("throughput", 4, false),
                ("tlas", 8, true),
            ]
        );
        assert_eq!((s.live_bytes, s.rematerializable_bytes), (72, 20));
        assert_eq!(s.chain.len(), 1);
        assert_eq!((s.line, s.column), (Some(91), Some(9)));
        // Across the shadow trace the shader keeps what it lights (`lit`)
        // instead of the normal and albedo: 64 bytes, within RT010's budget.
        let shadow = &sites[1];
        assert_eq!(shadow.payload.as_ref().unwrap().name, "shadow");
        assert_eq!(
            shadow.live_bytes - shadow.rematerializable_bytes,
            64,
            "{:?}",
            names(shadow)
        );
    }

    #[test]
    fn ray_query_proceed_loop() {
        let s = one_site("fixtures/live/query.rgen.spv");
        assert_eq!(s.kind, LiveSiteKind::RayQuery);
        assert_eq!(names(&s), [("hits", 4, false), ("tint", 12, true)]);
        assert_eq!(s.payload.as_ref().unwrap().name, "rq");
    }

    #[test]
    fn wgsl_let_values() {
        let s = one_site("fixtures/live/lets.wgsl");
        assert_eq!(
            names(&s),
            [("a", 4, false), ("b", 12, false), ("id", 12, true)]
        );
        assert_eq!(s.live_bytes, 28);
        let r = live_report(&[program("fixtures/live/lets.wgsl")]);
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["sites"][0]["kind"], "trace_ray");
        assert_eq!(json["sites"][0]["live_bytes"], 28);
        assert_eq!(json["sites"][0]["values"][0]["name"], "b");
        assert!(crate::report::live::human(&r).contains("28 bytes live"));
    }

    #[test]
    fn execute_callable_site() {
        let p = program("fixtures/pipelines/callable/sky.rgen.spv");
        let sites = live_sites(&p);
        assert_eq!(sites.len(), 2);
        let call = sites
            .iter()
            .find(|s| s.kind == LiveSiteKind::ExecuteCallable)
            .unwrap();
        assert_eq!(names(call), [("uv", 8, true), ("weight", 4, false)]);
        assert_eq!(call.payload.as_ref().unwrap().name, "sky");
        let trace = sites
            .iter()
            .find(|s| s.kind == LiveSiteKind::TraceRay)
            .unwrap();
        assert_eq!(names(trace), [("uv", 8, true)]);
    }

    /// Debug info never changes the answer: `-g`, `-gV` (DebugDeclare and
    /// DebugValue name every local), WGSL and rtlint's HLSL alike. Loop-local
    /// state written at the top of each iteration is not live, a struct
    /// written field by field no more than one built whole.
    #[test]
    fn loop_locals_are_dead_whatever_the_debug_info() {
        for rel in [
            "fixtures/live/loop_local.rgen.spv",
            "fixtures/live/loop_local.rgen.gV.spv",
        ] {
            let sites = live_sites(&program(rel));
            assert_eq!(sites.len(), 2, "{rel}");
            assert_eq!(
                names(&sites[0]),
                [("acc", 12, false), ("dir", 12, false), ("i", 4, false)],
                "{rel}"
            );
            assert_eq!(
                names(&sites[1]),
                [("acc", 12, false), ("i", 4, false)],
                "{rel}"
            );
        }
        let s = one_site("fixtures/live/loop_local.hlsl");
        assert_eq!(names(&s), [("acc", 12, false), ("i", 4, false)]);
        let s = one_site("fixtures/live/loop_local.wgsl");
        let n = names(&s);
        assert!(!n.iter().any(|v| v.0 == "ray" || v.0 == "dir"), "{n:?}");
        assert!(n.contains(&("acc", 12, false)) && n.contains(&("i", 4, false)));
    }

    /// One value per rematerialisation class (docs/stack.md), with and
    /// without NonSemantic debug info.
    #[test]
    fn rematerialisation_classes() {
        for rel in [
            "fixtures/live/classes.rgen.spv",
            "fixtures/live/classes.rgen.gV.spv",
        ] {
            let sites = live_sites(&program(rel));
            assert_eq!(
                names(&sites[0]),
                [
                    ("fromBuiltin", 16, true),
                    ("fromImage", 16, true),
                    ("fromStorage", 16, true),
                    ("fromTexture", 16, true),
                    ("fromUniform", 16, true),
                    ("fromClock", 8, false),
                    ("fromRealtime", 8, false),
                ]
                .iter()
                .copied()
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect::<Vec<_>>(),
                "{rel}"
            );
            let second = names(&sites[1]);
            assert!(
                second.contains(&("fromPayload", 16, false)),
                "{rel}: {second:?}"
            );
        }
        // The same classes in HLSL (rtlint's compiler) and WGSL (naga).
        for (rel, names_of) in [
            (
                "fixtures/live/classes.hlsl",
                [
                    "fromBuiltin",
                    "fromUniform",
                    "fromStorage",
                    "fromTexture",
                    "fromImage",
                    "fromPayload",
                ],
            ),
            (
                "fixtures/live/classes.wgsl",
                [
                    "from_builtin",
                    "from_uniform",
                    "from_storage",
                    "from_texture",
                    "from_load",
                    "from_payload",
                ],
            ),
        ] {
            let sites = live_sites(&program(rel));
            let remat = |k: usize, name: &str| {
                sites[k]
                    .values
                    .iter()
                    .find(|v| v.name == name)
                    .map(|v| v.rematerializable)
            };
            for name in &names_of[..5] {
                assert_eq!(remat(0, name), Some(true), "{rel}: {name}");
            }
            assert_eq!(remat(0, names_of[5]), None, "{rel}");
            assert_eq!(remat(1, names_of[5]), Some(false), "{rel}");
        }
        // buffer_reference loads are as recomputable as storage-buffer loads.
        let s = one_site("fixtures/live/reference.rgen.spv");
        assert_eq!(names(&s), [("albedo", 16, true), ("scale", 16, true)]);
    }

    /// glslang -g copies a Latin-1 comment byte into OpSource; spirv-val
    /// accepts the module, and so does rtlint (each bad byte read as `?`).
    #[test]
    fn non_utf8_source_is_read() {
        let p = program("fixtures/live/latin1.rgen.spv");
        let text = p.files.iter().find_map(|f| f.text.clone()).unwrap();
        assert!(text.contains("// Gr??e: a Latin-1 comment"), "{text}");
        for rel in [
            "fixtures/live/latin1.rgen.spv",
            "fixtures/live/latin1.rgen.gV.spv",
        ] {
            let s = one_site(rel);
            assert_eq!(names(&s), [("k", 4, true)], "{rel}");
            assert_eq!(s.line, Some(10), "{rel}");
        }
    }

    /// `rtlint live` names the source file the debug info gives, not the
    /// module, and says when a value has no known line.
    #[test]
    fn live_report_names_the_source() {
        let r = live_report(&[program("fixtures/live/loop_local.rgen.gV.spv")]);
        let text = crate::report::live::human(&r);
        assert!(
            text.contains("fixtures/live/loop_local.rgen:23:9: trace_ray"),
            "{text}"
        );
        assert!(!text.contains(".spv"), "{text}");
        assert!(!text.contains("line ?"), "{text}");
        let r = live_report(&[program("fixtures/live/lets.wgsl")]);
        let text = crate::report::live::human(&r);
        assert!(!text.contains("line ?"), "{text}");
        // A WGSL builtin argument is defined where the entry point names it.
        let id = r.sites[0].values.iter().find(|v| v.name == "id").unwrap();
        assert_eq!(id.def_line, Some(20), "{text}");
    }

    /// `out` arguments pass through temporaries the callee writes on every
    /// path without reading: not live. An `inout` one the callee reads is.
    #[test]
    fn out_argument_temporaries_are_not_live() {
        for rel in [
            "fixtures/live/out_params.rgen.spv",
            "fixtures/live/out_params.rgen.gV.spv",
            "fixtures/live/out_params.hlsl",
        ] {
            let s = one_site(rel);
            assert_eq!(
                names(&s),
                [
                    ("acc", 12, false),
                    ("i", 4, false),
                    ("seed", 4, false),
                    ("weight", 4, false)
                ],
                "{rel}"
            );
        }
    }

    /// rtlint's HLSL lowering keeps nothing live that the source does not:
    /// `?:` leaves no temporary per side (was 40 B more), and the `out`
    /// temporaries of a callee that returns early start undefined at each
    /// call (was 16 B more). `tests/invariance.rs` checks the same without
    /// debug info.
    #[test]
    fn hlsl_lowering_adds_no_live_state() {
        let s = one_site("fixtures/live/ternary.hlsl");
        assert_eq!(names(&s), [("acc", 12, false), ("i", 4, false)]);
        assert_eq!((s.live_bytes, s.rematerializable_bytes), (16, 0));
        let s = one_site("fixtures/live/out_early.hlsl");
        assert_eq!(
            names(&s),
            [("acc", 12, false), ("i", 4, false), ("seed", 4, false)]
        );
        assert_eq!(s.live_bytes, 20);
    }

    /// An HLSL local declared after the trace is not live across it, its
    /// `DebugDeclare` is where it is declared (after the trace; `acc`'s is
    /// before), and a copy of `DispatchRaysIndex()` stays recomputable.
    #[test]
    fn hlsl_locals_declared_where_declared() {
        let rel = "fixtures/live/declared_after.hlsl";
        let p = program(rel);
        let s = one_site(rel);
        assert_eq!(
            names(&s),
            [("acc", 12, false), ("i", 4, false), ("id", 12, true)]
        );
        assert_eq!((s.live_bytes, s.rematerializable_bytes), (28, 12));
        let trace = p.sites[0].inst;
        let declared_at = |name: &str| -> usize {
            let var = p
                .names
                .iter()
                .find(|(_, n)| n.as_str() == name)
                .map(|(id, _)| *id)
                .unwrap();
            p.insts
                .iter()
                .position(|inst| {
                    p.is_debug_inst(inst)
                        && matches!(
                            inst.operands.get(1),
                            Some(Operand::LiteralExtInstInteger(28)) // DebugDeclare
                        )
                        && matches!(inst.operands.get(3), Some(Operand::IdRef(v)) if *v == var)
                })
                .unwrap_or_else(|| panic!("no DebugDeclare of `{name}`"))
        };
        assert!(declared_at("acc") < trace);
        assert!(declared_at("n") > trace);
        assert!(declared_at("h") > trace);
    }

    /// Parts behind a pointer parameter that the callee needs after its
    /// trace are live, counted at the caller's argument (glslang's and
    /// rtlint's temporaries for a struct passed by value).
    #[test]
    fn state_behind_a_parameter_is_live() {
        for rel in [
            "fixtures/live/param_state.rgen.spv",
            "fixtures/live/param_state.rgen.gV.spv",
            "fixtures/live/param_state.hlsl",
        ] {
            let s = one_site(rel);
            assert_eq!(s.live_bytes - s.rematerializable_bytes, 40, "{rel}: {s:?}");
            let kept: Vec<(u64, &str)> = s
                .values
                .iter()
                .filter(|v| !v.rematerializable)
                .map(|v| (v.size, v.ty.as_str()))
                .collect();
            assert!(kept.contains(&(24, "Ray")), "{rel}: {kept:?}");
        }
    }
    /// Bytes that must be kept across the one site of `rel` (live and not
    /// recomputable), and all live bytes.
    fn kept_and_live(rel: &str) -> (u64, u64) {
        let s = one_site(rel);
        (s.live_bytes - s.rematerializable_bytes, s.live_bytes)
    }

    /// A helper and the same code written inline keep the same bytes
    /// across the trace (`kept`); with `same_live`, the same live bytes
    /// too (naga loads a resource once per function, so its WGSL pairs
    /// differ in recomputable bytes only).
    fn same_as_inline(pairs: &[(&str, &str, bool)], kept: u64) {
        for &(helper, inline, same_live) in pairs {
            let (h, i) = (kept_and_live(helper), kept_and_live(inline));
            assert_eq!(h.0, kept, "{helper}: {:?}", one_site(helper));
            assert_eq!(i.0, kept, "{inline}: {:?}", one_site(inline));
            if same_live {
                assert_eq!(h.1, i.1, "{helper} vs {inline}");
            }
        }
    }

    /// A helper that writes its `out` parameters on every path after its
    /// trace: the caller's parts passed for them (glslang's and rtlint's
    /// temporaries, WGSL's pointers) are not live across it (were 16 B
    /// more).
    #[test]
    fn parts_a_callee_rewrites_after_its_trace_are_not_live() {
        same_as_inline(
            &[
                (
                    "fixtures/live/out_after.rgen.spv",
                    "fixtures/live/out_after_inline.rgen.spv",
                    true,
                ),
                (
                    "fixtures/live/out_after.hlsl",
                    "fixtures/live/out_after_inline.hlsl",
                    true,
                ),
            ],
            16,
        );
        // naga's loop guard (`loop_bound`, 8 B) is kept as well.
        same_as_inline(
            &[(
                "fixtures/live/out_after.wgsl",
                "fixtures/live/out_after_inline.wgsl",
                false,
            )],
            24,
        );
    }

    /// Module-scope `Private` variables (GLSL globals, HLSL `static`, WGSL
    /// `var<private>`) written before a trace and read after it are live,
    /// as the same state in locals is (were 0 B: the 68 B of `seed` and
    /// `xf` were missed).
    #[test]
    fn module_scope_private_variables_are_live() {
        same_as_inline(
            &[
                (
                    "fixtures/live/private_state.rgen.spv",
                    "fixtures/live/private_state_local.rgen.spv",
                    true,
                ),
                (
                    "fixtures/live/private_state.hlsl",
                    "fixtures/live/private_state_local.hlsl",
                    true,
                ),
                (
                    "fixtures/live/private_state.wgsl",
                    "fixtures/live/private_state_local.wgsl",
                    true,
                ),
            ],
            68,
        );
        // Written by the entry point, read by the helper after its trace;
        // a table only ever holding its initializer is recomputable.
        let s = one_site("fixtures/live/private_helper.rgen.spv");
        let vals = names(&s);
        assert!(vals.contains(&("seed", 4, false)), "{vals:?}");
        assert!(vals.contains(&("table", 24, true)), "{vals:?}");
        assert_eq!(s.live_bytes - s.rematerializable_bytes, 4);
        // A helper called after the trace overwrites the variable before
        // anything reads it (was 16 B more).
        let s = one_site("fixtures/live/private_rewritten.rgen.spv");
        assert_eq!(names(&s), [("i", 4, false)]);
    }

    /// A constant-buffer struct passed by value to a helper that reads it
    /// after its trace is recomputable (a load from the buffer again):
    /// through glslang's and rtlint's temporaries, which the callee never
    /// writes, and naga's value parameters, followed to the caller's
    /// argument (were 64 B and 80 B kept).
    #[test]
    fn a_constant_buffer_struct_by_value_is_recomputable() {
        same_as_inline(
            &[
                (
                    "fixtures/live/cbuffer_arg.rgen.spv",
                    "fixtures/live/cbuffer_arg_inline.rgen.spv",
                    false,
                ),
                (
                    "fixtures/live/cbuffer_arg.hlsl",
                    "fixtures/live/cbuffer_arg_inline.hlsl",
                    false,
                ),
                (
                    "fixtures/live/cbuffer_arg.wgsl",
                    "fixtures/live/cbuffer_arg_inline.wgsl",
                    false,
                ),
            ],
            0,
        );
        for rel in [
            "fixtures/live/cbuffer_arg.rgen.spv",
            "fixtures/live/cbuffer_arg.hlsl",
            "fixtures/live/cbuffer_arg.wgsl",
        ] {
            let s = one_site(rel);
            assert!(
                s.values
                    .iter()
                    .any(|v| v.ty == "Camera" && v.size >= 64 && v.rematerializable),
                "{rel}: {s:?}"
            );
        }
    }

    /// A struct passed by value to a helper that reads it after its trace,
    /// while the caller reads it after the call: the callee's copy
    /// (glslang's and rtlint's temporary, naga's value parameter) and the
    /// caller's original are kept once (were 12 B and 24 B more).
    #[test]
    fn an_in_struct_argument_is_not_counted_twice() {
        same_as_inline(
            &[
                (
                    "fixtures/live/in_struct.rgen.spv",
                    "fixtures/live/in_struct_inline.rgen.spv",
                    true,
                ),
                (
                    "fixtures/live/in_struct.hlsl",
                    "fixtures/live/in_struct_inline.hlsl",
                    true,
                ),
                (
                    "fixtures/live/in_struct.wgsl",
                    "fixtures/live/in_struct_inline.wgsl",
                    true,
                ),
            ],
            24,
        );
    }

    /// An HLSL helper tracing with the `inout` payload it is passed: the
    /// caller's copy is the payload, written back after the trace, not
    /// live state (was 16 B).
    #[test]
    fn an_inout_payload_through_a_helper_is_not_live() {
        same_as_inline(
            &[(
                "fixtures/live/inout_payload.hlsl",
                "fixtures/live/inout_payload_inline.hlsl",
                true,
            )],
            0,
        );
        assert_eq!(kept_and_live("fixtures/live/inout_payload.hlsl").1, 0);
    }

    /// The stack model's undescribed sites carry the same bytes, values and
    /// recomputability as the described ones, and nothing that describes.
    #[test]
    fn bytes_only_sites_match_the_described_ones() {
        let key = |s: &LiveSite| {
            let mut v: Vec<_> = s
                .values
                .iter()
                .map(|v| (v.id, v.size, v.rematerializable, v.storage == Storage::Ssa))
                .collect();
            v.sort();
            (
                s.inst,
                s.chain.clone(),
                s.entry.clone(),
                s.kind,
                s.live_bytes,
                s.rematerializable_bytes,
                v,
            )
        };
        let (mut compared, mut live) = (0, 0);
        for rel in [
            "shaders/reflect_hybrid.hlsl",
            "shaders/reflect_recursive.wgsl",
            "shaders/reflect_adaptive.hlsl",
            "fixtures/RT010/bad.rgen.spv",
        ] {
            let p = program(rel);
            let described = compute_live_sites(&p, true);
            let bytes = compute_live_sites(&p, false);
            assert_eq!(
                described.iter().map(key).collect::<Vec<_>>(),
                bytes.iter().map(key).collect::<Vec<_>>(),
                "{rel}"
            );
            live += described.iter().map(|s| s.live_bytes).sum::<u64>();
            assert!(bytes
                .iter()
                .flat_map(|s| &s.values)
                .all(|v| v.name.is_empty() && v.def.is_none() && v.use_at.is_none()));
            compared += described.len();
        }
        assert!(
            compared > 4 && live > 0,
            "{compared} sites, {live} bytes compared"
        );
    }
}
