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

use crate::diag::Location;
use crate::program::cfg::call_chains;
use crate::program::scalar::scalar_size;
use crate::program::{Constant, Function, Id, Program, SiteKind, Type};
use crate::shader::Stage;
use rspirv::dr::{Instruction, Operand};
use spirv::{Op, StorageClass};
use std::collections::{HashMap, HashSet, VecDeque};
use std::path::PathBuf;

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

/// The sites of one program with the values live across each.
pub fn live_sites(program: &Program) -> Vec<LiveSite> {
    let mut cache: HashMap<usize, FnLiveness> = HashMap::new();
    let mut out = Vec::new();
    for site in &program.sites {
        let kind = match site.kind {
            SiteKind::TraceRay => LiveSiteKind::TraceRay,
            SiteKind::ExecuteCallable => LiveSiteKind::ExecuteCallable,
            SiteKind::RayQuery if site.op == Op::RayQueryProceedKHR => LiveSiteKind::RayQuery,
            _ => continue,
        };
        for entry in &program.entry_points {
            let Some(g) = program.functions.get(site.function) else {
                continue;
            };
            for chain in call_chains(program, entry.function, g.id, MAX_CHAINS) {
                // Levels: the site in its own function, then each call upwards.
                let mut points = vec![site.inst];
                points.extend(chain.iter().rev().copied());
                let mut values: Vec<LiveValue> = Vec::new();
                let mut seen: HashSet<Id> = HashSet::new();
                for &p in &points {
                    let Some(fi) = program.function_of(p) else {
                        continue;
                    };
                    let fl = cache
                        .entry(fi)
                        .or_insert_with(|| FnLiveness::new(program, fi));
                    for v in fl.live_across(program, p) {
                        if seen.insert(v.id) {
                            values.push(v);
                        }
                    }
                }
                // The query object is the site's own state, like a payload.
                values.retain(|v| Some(v.id) != site.payload);
                values.sort_by(|a, b| b.size.cmp(&a.size).then(a.name.cmp(&b.name)));
                let location = std::iter::once(site.inst)
                    .chain(chain.iter().rev().copied())
                    .find_map(|i| program.inst_location(i));
                let payload = site.payload.map(|id| payload_info(program, id));
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
        }
    }
    out
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

fn pointee(program: &Program, ptr_ty: Id) -> Option<Id> {
    match program.ty(ptr_ty)? {
        Type::Pointer { pointee, .. } => Some(*pointee),
        _ => None,
    }
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

/// Liveness facts of one function.
pub struct FnLiveness {
    func: usize,
    /// Function-local `OpVariable`s.
    vars: HashSet<Id>,
    /// Pointer ids derived from a local variable, to the variable.
    roots: HashMap<Id, Id>,
    /// SSA values that count as state: defined here, not pointers to locals.
    ssa: HashSet<Id>,
    live_out: Vec<HashSet<Id>>,
    /// Variables possibly written at each block's end.
    defined_out: Vec<HashSet<Id>>,
    preds: Vec<Vec<usize>>,
    remat: HashMap<Id, bool>,
    /// Pointers to one member of a local struct variable (an access chain
    /// with one constant index): variable and member.
    member_ptr: HashMap<Id, (Id, u64)>,
    /// Members of each local struct variable.
    var_members: HashMap<Id, usize>,
    /// The debug-info instruction set, whose instructions touch no value.
    debug_set: Option<Id>,
}

/// Whether `inst` is a `NonSemantic.Shader.DebugInfo.100` instruction
/// (`DebugDeclare`, `DebugValue`, …): it names a variable, it neither
/// reads nor writes it.
fn is_debug_info(program: &Program, inst: &Instruction) -> bool {
    inst.class.opcode == Op::ExtInst
        && program.debug_info_set.is_some()
        && matches!(inst.operands.first(), Some(Operand::IdRef(set)) if Some(*set) == program.debug_info_set)
}

/// Members of local struct variables stored since the last read, walking
/// backwards through one block: once every member is stored, the variable
/// is overwritten as a whole (HLSL's `RayDesc ray; ray.Origin = …; …`).
type Pending = HashMap<Id, HashSet<u64>>;

impl FnLiveness {
    pub fn new(program: &Program, func: usize) -> FnLiveness {
        let f = &program.functions[func];
        let mut vars = HashSet::new();
        let mut roots = HashMap::new();
        let mut ssa = HashSet::new();
        for inst in &program.insts[f.start..=f.end] {
            let Some(r) = inst.result_id else { continue };
            match inst.class.opcode {
                Op::Variable => {
                    vars.insert(r);
                    roots.insert(r, r);
                }
                Op::AccessChain
                | Op::InBoundsAccessChain
                | Op::PtrAccessChain
                | Op::CopyObject
                | Op::Bitcast => {
                    let base = id_operands(inst).next();
                    if let Some(root) = base.and_then(|b| roots.get(&b).copied()) {
                        roots.insert(r, root);
                    } else {
                        ssa.insert(r);
                    }
                }
                Op::Label | Op::Function => {}
                _ => {
                    ssa.insert(r);
                }
            }
        }
        let n = f.blocks.len();
        let mut preds = vec![Vec::new(); n];
        for (b, block) in f.blocks.iter().enumerate() {
            for &s in &block.succs {
                if let Some(p) = preds.get_mut(s) {
                    p.push(b);
                }
            }
        }
        let mut member_ptr = HashMap::new();
        let mut var_members = HashMap::new();
        for inst in &program.insts[f.start..=f.end] {
            let Some(r) = inst.result_id else { continue };
            match inst.class.opcode {
                Op::Variable => {
                    if let Some(Type::Pointer { pointee, .. }) =
                        inst.result_type.and_then(|t| program.ty(t))
                    {
                        if let Some(Type::Struct { members }) = program.ty(*pointee) {
                            var_members.insert(r, members.len());
                        }
                    }
                }
                Op::AccessChain | Op::InBoundsAccessChain => {
                    let ids: Vec<Id> = id_operands(inst).collect();
                    if let [base, index] = ids[..] {
                        if vars.contains(&base) {
                            if let Some(i) = program.const_u64(index) {
                                member_ptr.insert(r, (base, i));
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        let mut fl = FnLiveness {
            func,
            vars,
            roots,
            ssa,
            live_out: vec![HashSet::new(); n],
            defined_out: vec![HashSet::new(); n],
            preds,
            remat: HashMap::new(),
            member_ptr,
            var_members,
            debug_set: program.debug_info_set,
        };
        fl.solve(program);
        fl
    }

    fn function<'p>(&self, program: &'p Program) -> &'p Function {
        &program.functions[self.func]
    }

    fn root(&self, id: Id) -> Option<Id> {
        self.roots.get(&id).copied()
    }

    /// Backward transfer of one instruction over the live set.
    fn step_back(&self, inst: &Instruction, live: &mut HashSet<Id>, pending: &mut Pending) {
        let op = inst.class.opcode;
        if op == Op::ExtInst
            && self.debug_set.is_some()
            && matches!(inst.operands.first(), Some(Operand::IdRef(set)) if Some(*set) == self.debug_set)
        {
            return;
        }
        if let Some(r) = inst.result_id {
            live.remove(&r);
        }
        match op {
            // Phi operands are used on the incoming edge, handled by `solve`.
            Op::Phi => return,
            Op::Store => {
                if let Some(Operand::IdRef(ptr)) = inst.operands.first() {
                    if self.vars.contains(ptr) {
                        live.remove(ptr);
                    }
                }
            }
            Op::CopyMemory | Op::CopyMemorySized => {
                if let Some(Operand::IdRef(ptr)) = inst.operands.first() {
                    if self.vars.contains(ptr) {
                        live.remove(ptr);
                    }
                }
                if let Some(Operand::IdRef(src)) = inst.operands.get(1) {
                    if let Some(v) = self.root(*src) {
                        live.insert(v);
                    }
                }
            }
            // An initializer writes the whole variable; the result id was
            // removed above.
            _ => {}
        }
        let derives = matches!(
            op,
            Op::AccessChain
                | Op::InBoundsAccessChain
                | Op::PtrAccessChain
                | Op::CopyObject
                | Op::Bitcast
        );
        for (k, id) in id_operands(inst).enumerate() {
            if self.ssa.contains(&id) {
                live.insert(id);
            }
            if let Some(v) = self.root(id) {
                // Deriving a pointer reads nothing; a store's target is
                // written, not read; anything else may read the variable.
                let reads = match op {
                    _ if derives => false,
                    Op::Store | Op::CopyMemory | Op::CopyMemorySized => k != 0,
                    Op::Variable => false,
                    _ => true,
                };
                if reads {
                    live.insert(v);
                    pending.remove(&v);
                }
            }
        }
        // A store to one member: once every member is stored before the
        // next read, the variable is dead before these stores.
        if op == Op::Store {
            if let Some(Operand::IdRef(ptr)) = inst.operands.first() {
                if let Some(&(v, i)) = self.member_ptr.get(ptr) {
                    let stored = pending.entry(v).or_default();
                    stored.insert(i);
                    if self.var_members.get(&v).is_some_and(|&n| stored.len() >= n) {
                        live.remove(&v);
                        pending.remove(&v);
                    }
                }
            }
        }
    }

    /// Variables an instruction may write. A constant initializer does not
    /// count: until something else is stored, the variable holds a
    /// constant, which is recomputed rather than kept across a call.
    fn writes(&self, program: &Program, inst: &Instruction) -> Vec<Id> {
        if is_debug_info(program, inst) {
            return Vec::new();
        }
        match inst.class.opcode {
            Op::Variable if inst.operands.len() > 1 => {
                let constant = matches!(
                    inst.operands.get(1),
                    Some(Operand::IdRef(init))
                        if program.constants.contains_key(init)
                            || program.spec_constants.contains_key(init)
                );
                if constant {
                    Vec::new()
                } else {
                    inst.result_id.into_iter().collect()
                }
            }
            Op::Load | Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => Vec::new(),
            _ => id_operands(inst)
                .filter_map(|id| self.root(id))
                .collect::<Vec<_>>(),
        }
    }

    fn solve(&mut self, program: &Program) {
        let f = self.function(program);
        let n = f.blocks.len();
        // Phi uses per predecessor block.
        let mut phi_uses: Vec<Vec<Id>> = vec![Vec::new(); n];
        for block in &f.blocks {
            for inst in &program.insts[block.start..=block.end] {
                if inst.class.opcode != Op::Phi {
                    continue;
                }
                let ids: Vec<Id> = id_operands(inst).collect();
                for pair in ids.chunks(2) {
                    if let [value, pred] = pair {
                        if let Some(p) = f.block_by_label(*pred) {
                            if self.ssa.contains(value) {
                                phi_uses[p].push(*value);
                            }
                        }
                    }
                }
            }
        }
        let mut live_in: Vec<HashSet<Id>> = vec![HashSet::new(); n];
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds < 10_000 {
            changed = false;
            rounds += 1;
            for b in (0..n).rev() {
                let mut out: HashSet<Id> = phi_uses[b].iter().copied().collect();
                for &s in &f.blocks[b].succs {
                    if let Some(li) = live_in.get(s) {
                        out.extend(li.iter().copied());
                    }
                }
                let mut live = out.clone();
                let mut pending = Pending::new();
                for inst in program.insts[f.blocks[b].start..=f.blocks[b].end]
                    .iter()
                    .rev()
                {
                    self.step_back(inst, &mut live, &mut pending);
                }
                if out != self.live_out[b] || live != live_in[b] {
                    self.live_out[b] = out;
                    live_in[b] = live;
                    changed = true;
                }
            }
        }
        // Forward: variables possibly written on some path.
        let mut changed = true;
        let mut rounds = 0;
        while changed && rounds < 10_000 {
            changed = false;
            rounds += 1;
            for b in 0..n {
                let mut d: HashSet<Id> = HashSet::new();
                for &p in &self.preds[b] {
                    d.extend(self.defined_out[p].iter().copied());
                }
                for inst in &program.insts[f.blocks[b].start..=f.blocks[b].end] {
                    d.extend(self.writes(program, inst));
                }
                if d != self.defined_out[b] {
                    self.defined_out[b] = d;
                    changed = true;
                }
            }
        }
    }

    /// Ids live just after instruction `inst` (SSA values and variables).
    pub fn live_after(&self, program: &Program, inst: usize) -> HashSet<Id> {
        let f = self.function(program);
        let Some(b) = f.block_of(inst) else {
            return HashSet::new();
        };
        let mut live = self.live_out[b].clone();
        let mut pending = Pending::new();
        for k in (inst + 1..=f.blocks[b].end).rev() {
            self.step_back(&program.insts[k], &mut live, &mut pending);
        }
        live
    }

    /// Variables possibly written before instruction `inst`.
    fn defined_before(&self, program: &Program, inst: usize) -> HashSet<Id> {
        let f = self.function(program);
        let Some(b) = f.block_of(inst) else {
            return HashSet::new();
        };
        let mut d: HashSet<Id> = HashSet::new();
        for &p in &self.preds[b] {
            d.extend(self.defined_out[p].iter().copied());
        }
        for k in f.blocks[b].start..inst {
            d.extend(self.writes(program, &program.insts[k]));
        }
        d
    }

    /// The values live across instruction `inst`, described.
    pub fn live_across(&mut self, program: &Program, inst: usize) -> Vec<LiveValue> {
        let live = self.live_after(program, inst);
        let defined = self.defined_before(program, inst);
        let result = program.insts.get(inst).and_then(|i| i.result_id);
        let mut ids: Vec<Id> = live
            .into_iter()
            .filter(|id| Some(*id) != result)
            .filter(|id| !self.vars.contains(id) || defined.contains(id))
            .collect();
        ids.sort_unstable();
        let mut out = Vec::new();
        for id in ids {
            let is_var = self.vars.contains(&id);
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
                self.remat_var(program, id, 0)
            } else {
                self.remat_ssa(program, id, 0)
            };
            let def = if is_var {
                self.var_def_location(program, id)
            } else {
                program
                    .defs
                    .get(&id)
                    .and_then(|&i| program.inst_location(i))
            };
            let use_at = self.first_use_after(program, inst, id);
            out.push(LiveValue {
                name: value_name(program, id, def.as_ref()),
                ty: program.type_name(ty),
                size: scalar_size(program, ty).unwrap_or(0),
                rematerializable,
                storage: if is_var {
                    Storage::Variable
                } else {
                    Storage::Ssa
                },
                def_line: def.as_ref().map(|l| l.line),
                use_line: use_at.as_ref().map(|l| l.line),
                id,
                def,
                use_at,
            });
        }
        out
    }

    fn reads(&self, inst: &Instruction, id: Id) -> bool {
        if inst.class.opcode == Op::Phi {
            return id_operands(inst).step_by(2).any(|x| x == id);
        }
        if self.vars.contains(&id) {
            match inst.class.opcode {
                Op::Load | Op::FunctionCall | Op::CopyMemory | Op::ExtInst => {
                    id_operands(inst).any(|x| self.root(x) == Some(id))
                }
                _ => false,
            }
        } else {
            id_operands(inst).any(|x| x == id)
        }
    }

    /// The position of the first instruction after `inst` that reads `id`
    /// (breadth-first over the CFG, loops included).
    fn first_use_after(&self, program: &Program, inst: usize, id: Id) -> Option<Location> {
        let f = self.function(program);
        let b0 = f.block_of(inst)?;
        let mut found = None;
        for k in inst + 1..=f.blocks[b0].end {
            if self.reads(&program.insts[k], id) {
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
                    if self.reads(&program.insts[k], id) {
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
                let inst = &program.insts[i];
                inst.class.opcode == Op::Store
                    && id_operands(inst).next().and_then(|p| self.root(p)) == Some(var)
            })
            .find_map(|i| program.inst_location(i))
            .or_else(|| program.decl_location(crate::program::Decl::Var(var)))
    }

    /// Whether an SSA value can be recomputed after the trace from builtins,
    /// push constants, uniform or storage loads and constants.
    fn remat_ssa(&mut self, program: &Program, id: Id, depth: u32) -> bool {
        if program.constants.contains_key(&id) || program.spec_constants.contains_key(&id) {
            return true;
        }
        if let Some(&r) = self.remat.get(&id) {
            return r;
        }
        let Some(&i) = program.defs.get(&id) else {
            return false;
        };
        let inst = &program.insts[i];
        let op = inst.class.opcode;
        if op == Op::Undef {
            return true;
        }
        if depth > 64 || !(self.function(program).start..=self.function(program).end).contains(&i) {
            return false;
        }
        // Cycles through phis are loop-carried: not recomputable.
        self.remat.insert(id, false);
        let name = format!("{op:?}");
        let r = match op {
            Op::Phi | Op::FunctionCall | Op::FunctionParameter | Op::Variable => false,
            _ if name.starts_with("Atomic") || name.starts_with("RayQuery") => false,
            Op::Load => {
                let ptr = id_operands(inst).next().unwrap_or(0);
                match self.root(ptr) {
                    Some(v) => self.remat_var(program, v, depth + 1),
                    None => self.remat_global_ptr(program, ptr, depth + 1),
                }
            }
            _ => {
                let ids: Vec<Id> = id_operands(inst).collect();
                ids.into_iter().all(|x| {
                    // Extended-instruction sets are ids too: they are constant.
                    matches!(
                        program.def(x).map(|d| d.class.opcode),
                        Some(Op::ExtInstImport)
                    ) || self.remat_ssa(program, x, depth + 1)
                })
            }
        };
        self.remat.insert(id, r);
        r
    }

    fn remat_global_ptr(&mut self, program: &Program, ptr: Id, depth: u32) -> bool {
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

    /// A variable is recomputable when every write stores a recomputable
    /// value and nothing else (a call, an atomic) gets its address.
    fn remat_var(&mut self, program: &Program, var: Id, depth: u32) -> bool {
        let key = var;
        if let Some(&r) = self.remat.get(&key) {
            return r;
        }
        self.remat.insert(key, false);
        let f = self.function(program);
        let (start, end) = (f.start, f.end);
        let mut ok = true;
        for i in start..=end {
            let inst = &program.insts[i];
            let ids: Vec<Id> = id_operands(inst).collect();
            if !ids.iter().any(|x| self.root(*x) == Some(var)) && inst.result_id != Some(var) {
                continue;
            }
            match inst.class.opcode {
                Op::Variable => {
                    if let Some(&init) = ids.first() {
                        if !matches!(
                            program.constants.get(&init),
                            Some(Constant::Int(_) | Constant::Float(_) | Constant::Bool(_))
                                | Some(Constant::Null | Constant::Composite(_))
                        ) && !program.spec_constants.contains_key(&init)
                        {
                            ok = false;
                        }
                    }
                }
                Op::Store => {
                    let value = ids.get(1).copied().unwrap_or(0);
                    if !self.remat_ssa(program, value, depth + 1) {
                        ok = false;
                    }
                }
                Op::Load => {}
                Op::AccessChain | Op::InBoundsAccessChain | Op::PtrAccessChain => {
                    if !ids[1..]
                        .iter()
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
        self.remat.insert(key, ok);
        ok
    }
}

/// The human form of `rtlint live`.
pub fn render_human(report: &LiveReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    if report.sites.is_empty() {
        s.push_str("no trace, callable or ray-query sites\n");
        return s;
    }
    for site in &report.sites {
        let at = match (site.line, site.column) {
            (Some(l), Some(c)) if c > 0 => format!("{}:{l}:{c}", site.path.display()),
            (Some(l), _) => format!("{}:{l}", site.path.display()),
            _ => site.path.display().to_string(),
        };
        let _ = writeln!(
            s,
            "{at}: {} in `{}` ({}): {} bytes live, {} rematerializable",
            site.kind.as_str(),
            site.entry,
            site.stage.as_str(),
            site.live_bytes,
            site.rematerializable_bytes
        );
        if let Some(p) = &site.payload {
            let size = p
                .size
                .map(|b| format!("{b} bytes"))
                .unwrap_or("unsized".into());
            let _ = writeln!(s, "  payload `{}`: {} ({size}, not counted)", p.name, p.ty);
        }
        for v in &site.values {
            let line = |l: Option<u32>| l.map(|l| l.to_string()).unwrap_or("?".into());
            let _ = writeln!(
                s,
                "  {:>4} B  {:<16} {:<10} {:<8} defined line {}, used line {}{}",
                v.size,
                v.name,
                v.ty,
                match v.storage {
                    Storage::Ssa => "value",
                    Storage::Variable => "variable",
                },
                line(v.def_line),
                line(v.use_line),
                if v.rematerializable {
                    "  (rematerializable)"
                } else {
                    ""
                }
            );
        }
    }
    s
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
        assert_eq!(s.line, Some(28));
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
        let s = one_site("shaders/reflect_iterative.wgsl");
        // The trace sits in naga's helper; the raygen's state is live across
        // the call: four vec3 variables, the counter, naga's loop guard, and
        // the builtin and TLAS handle (both reloadable).
        assert_eq!(
            names(&s),
            [
                ("bounce", 4, false),
                ("color", 12, false),
                ("dir", 12, false),
                ("id", 12, true),
                ("loop_bound", 8, false),
                ("origin", 12, false),
                ("throughput", 12, false),
                ("tlas", 8, true),
            ]
        );
        assert_eq!((s.live_bytes, s.rematerializable_bytes), (80, 20));
        assert_eq!(s.chain.len(), 1);
        assert_eq!((s.line, s.column), (Some(56), Some(9)));
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
        assert!(render_human(&r).contains("28 bytes live"));
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
}
