//! The Program: one SPIR-V module parsed once into what every analysis reads.
//!
//! Instructions stay in one flat vector in module order (with their word offset
//! and source position); everything else refers to them by index or by SPIR-V
//! id, which already is a dense handle. Structure that the analyses need —
//! types, globals, entry points, functions with their CFG, ray-tracing sites,
//! and the source position of declarations — is derived once in [`build`].

mod binary;
mod build;
mod callpos;
pub mod cfg;
pub mod debug;
pub mod decode;
mod fold;
pub mod scalar;
mod textdecl;
pub mod types;
mod values;

pub use binary::{words_from_bytes, MAGIC};
pub use build::{parse, parse_owned};
pub use types::{ArrayLen, Type};

use crate::diag::Location;
use crate::shader::Language;
use crate::shader::Stage;
use rspirv::dr::{Instruction, Operand};
use spirv::{Op, StorageClass};
// Ids hash far faster with Fx than with SipHash, and the analyses look
// ids up all the time (`defs`, `constants`, `types`); a module's ids are
// its own, not adversarial input to a hash table.
type HashMap<K, V> = rustc_hash::FxHashMap<K, V>;
use std::path::PathBuf;

pub type Id = u32;

/// The Program's maps, Fx-hashed as above.
pub type FastMap<K, V> = HashMap<K, V>;

/// Decorations with their literal operands.
pub type Decorations = Vec<(spirv::Decoration, Vec<u32>)>;

/// A position in one of the module's debug-info source files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SrcPos {
    /// Index into [`Program::files`].
    pub file: u32,
    pub line: u32,
    /// 0 when the debug info has no column.
    pub column: u32,
    pub end_line: u32,
    pub end_column: u32,
}

/// A source file named by the module's debug info.
#[derive(Clone, Debug)]
pub struct SourceFile {
    /// As resolved on this machine (see [`debug::resolve_path`]).
    pub path: PathBuf,
    /// The text embedded in the module (`OpSource`, `DebugSource`), if any.
    pub text: Option<String>,
}

/// Declarations whose source position debug info can give.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Decl {
    Type(Id),
    Member(Id, u32),
    Var(Id),
    Func(Id),
}

/// A declaration named in source, matched to SPIR-V ids through `OpName`:
/// how front-ends hand over declaration positions the module's own debug
/// info lacks (see [`Program::attach_named_decls`]). The HLSL compiler's type.
pub use rtlint_hlsl::NamedDecl;

#[derive(Clone, Debug)]
pub struct EntryPoint {
    pub function: Id,
    pub name: String,
    pub stage: Stage,
    pub interface: Vec<Id>,
}

#[derive(Clone, Debug)]
pub struct Global {
    pub id: Id,
    pub name: Option<String>,
    pub storage: StorageClass,
    /// The pointee type (the variable's value type).
    pub ty: Id,
    pub set: Option<u32>,
    pub binding: Option<u32>,
    /// Index of the `OpVariable` in [`Program::insts`].
    pub inst: usize,
}

#[derive(Clone, Debug)]
pub struct Block {
    pub label: Id,
    /// Instruction indices from the `OpLabel` to the terminator, inclusive.
    pub start: usize,
    pub end: usize,
    /// Successor block indices within the function.
    pub succs: Vec<usize>,
}

#[derive(Clone, Debug)]
pub struct Function {
    pub id: Id,
    pub name: Option<String>,
    pub params: Vec<Id>,
    /// Index of `OpFunction` and of `OpFunctionEnd`.
    pub start: usize,
    pub end: usize,
    pub blocks: Vec<Block>,
    /// Each block's label with its index, sorted by label: branch targets
    /// and phi operands are looked up per use, so not by a scan of the
    /// blocks. Labels are ids, defined once.
    labels: Vec<(Id, usize)>,
}

impl Function {
    pub fn new(
        id: Id,
        name: Option<String>,
        params: Vec<Id>,
        start: usize,
        end: usize,
        blocks: Vec<Block>,
    ) -> Function {
        let mut labels: Vec<(Id, usize)> = blocks
            .iter()
            .enumerate()
            .map(|(k, b)| (b.label, k))
            .collect();
        labels.sort_unstable();
        Function {
            id,
            name,
            params,
            start,
            end,
            blocks,
            labels,
        }
    }

    /// Index of the block holding instruction `inst`.
    pub fn block_of(&self, inst: usize) -> Option<usize> {
        self.blocks
            .iter()
            .position(|b| b.start <= inst && inst <= b.end)
    }

    pub fn block_by_label(&self, label: Id) -> Option<usize> {
        let k = self.labels.binary_search_by_key(&label, |&(l, _)| l).ok()?;
        Some(self.labels[k].1)
    }
}

/// A trace or query operand's value: a constant when the module makes it
/// one, a specialization constant with its default, else a runtime value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OperandValue {
    Const(u64),
    /// A specialization constant with its default value.
    Spec {
        id: Id,
        default: u64,
    },
    Dynamic(Id),
}

impl OperandValue {
    pub fn constant(&self) -> Option<u64> {
        match self {
            OperandValue::Const(v) => Some(*v),
            _ => None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SiteKind {
    TraceRay,
    ExecuteCallable,
    ReportIntersection,
    IgnoreIntersection,
    TerminateRay,
    RayQuery,
}

/// One ray-tracing instruction with its operands resolved where constant.
#[derive(Clone, Debug)]
pub struct RtSite {
    pub kind: SiteKind,
    pub op: Op,
    /// Index into [`Program::functions`].
    pub function: usize,
    pub inst: usize,
    /// `OpTraceRayKHR`: ray flags, cull mask, SBT offset, SBT stride, miss index.
    pub trace: Option<TraceOperands>,
    /// The payload / callable-data variable, or the ray-query object.
    pub payload: Option<Id>,
    /// `OpExecuteCallableKHR`: the SBT index.
    pub sbt_index: Option<OperandValue>,
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TraceOperands {
    pub ray_flags: OperandValue,
    pub cull_mask: OperandValue,
    pub sbt_offset: OperandValue,
    pub sbt_stride: OperandValue,
    pub miss_index: OperandValue,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Constant {
    /// Integer bits, zero-extended; see the type for signedness.
    Int(u64),
    Float(f64),
    Bool(bool),
    Null,
    Composite(Vec<Id>),
}

#[derive(Debug)]
pub struct Program {
    /// The file the module came from.
    pub path: PathBuf,
    /// The language of the original source, from `OpSource` or the front-end.
    pub language: Language,
    pub version: (u8, u8),
    /// The module as read, for handing to a driver.
    pub words: Vec<u32>,
    pub insts: Vec<Instruction>,
    /// Word offset of each instruction in the binary.
    pub offsets: Vec<u32>,
    /// Source position in effect at each instruction.
    pub locs: Vec<Option<SrcPos>>,
    pub files: Vec<SourceFile>,
    pub types: FastMap<Id, Type>,
    pub names: FastMap<Id, String>,
    pub member_names: FastMap<(Id, u32), String>,
    /// `OpDecorate` on ids: decoration and its literal operands.
    pub decorations: FastMap<Id, Decorations>,
    pub member_decorations: FastMap<(Id, u32), Decorations>,
    pub constants: FastMap<Id, Constant>,
    /// Default values of specialization constants.
    pub spec_constants: FastMap<Id, Constant>,
    pub globals: Vec<Global>,
    pub entry_points: Vec<EntryPoint>,
    pub functions: Vec<Function>,
    pub sites: Vec<RtSite>,
    pub decl_pos: FastMap<Decl, SrcPos>,
    /// Instruction index defining each result id.
    pub defs: FastMap<Id, usize>,
    /// The id of the `NonSemantic.Shader.DebugInfo.100` import, if any.
    pub debug_info_set: Option<Id>,
    /// Imports of instruction sets without semantics (`NonSemantic.*`,
    /// `OpenCL.DebugInfo.100`, `DebugInfo`): their instructions only describe
    /// the code, so no analysis may count them as reads or writes.
    pub debug_sets: Vec<Id>,
    /// Analyses of the finished Program that several rules need, computed
    /// once ([`Memo::get_or`]).
    pub memo: Memo,
}

/// [`Program::call_index`]: every call by callee, and each
/// function's callees by function index, in flat vectors (a module has a
/// handful of functions: hash maps of them cost more to build than to
/// search, and reachability walks indices).
pub(crate) struct CallIndex {
    /// `(callee, instruction)` of every `OpFunctionCall`, sorted.
    by_callee: Vec<(Id, usize)>,
    /// Function `fi`'s callees, in the order of its calls, are
    /// `callees[callee_start[fi]..callee_start[fi + 1]]`: the callee's id
    /// and the index of the first function of that id ([`NOT_A_FUNCTION`]
    /// when none).
    callee_start: Vec<usize>,
    callees: Vec<(Id, usize)>,
    /// Per function: the index of the first function of its id, whose calls
    /// count for it, as [`Program::function`] finds it.
    first: Vec<usize>,
}

const NOT_A_FUNCTION: usize = usize::MAX;

impl CallIndex {
    /// The `(callee, instruction)` pairs of the calls to `f`, in module order.
    pub(crate) fn calls_to(&self, f: Id) -> &[(Id, usize)] {
        let from = self.by_callee.partition_point(|&(c, _)| c < f);
        let to = from + self.by_callee[from..].partition_point(|&(c, _)| c == f);
        &self.by_callee[from..to]
    }
}

/// Results computed once per Program, one per type: the module rules and
/// the pipeline's stack model both need each shader's live state, and a
/// Program is not changed once built.
#[derive(Default)]
pub struct Memo(
    std::sync::Mutex<HashMap<std::any::TypeId, std::sync::Arc<dyn std::any::Any + Send + Sync>>>,
);

impl Memo {
    /// The stored `T`, if something computed it.
    pub fn get<T: std::any::Any + Send + Sync>(&self) -> Option<std::sync::Arc<T>> {
        let key = std::any::TypeId::of::<T>();
        let found = self.0.lock().ok().and_then(|m| m.get(&key).cloned());
        found.and_then(|v| v.downcast::<T>().ok())
    }

    /// The stored `T`, else `f()` stored.
    pub fn get_or<T: std::any::Any + Send + Sync>(
        &self,
        f: impl FnOnce() -> T,
    ) -> std::sync::Arc<T> {
        let key = std::any::TypeId::of::<T>();
        let found = self.0.lock().ok().and_then(|m| m.get(&key).cloned());
        if let Some(v) = found.and_then(|v| v.downcast::<T>().ok()) {
            return v;
        }
        // Computed without the lock: `f` may use the memo itself.
        let v = std::sync::Arc::new(f());
        if let Ok(mut m) = self.0.lock() {
            m.insert(key, v.clone());
        }
        v
    }
}

impl std::fmt::Debug for Memo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Memo")
    }
}

impl Program {
    /// Whether `inst` is an extended instruction of a set without semantics
    /// (`DebugDeclare`, `DebugValue`, `DebugScope`, …): debug info, not code.
    pub fn is_debug_inst(&self, inst: &Instruction) -> bool {
        inst.class.opcode == Op::ExtInst
            && matches!(inst.operands.first(), Some(Operand::IdRef(set)) if self.debug_sets.contains(set))
    }

    pub fn name(&self, id: Id) -> Option<&str> {
        self.names.get(&id).map(String::as_str)
    }

    /// The name of an id for messages: its `OpName`, else `%id`.
    pub fn display_name(&self, id: Id) -> String {
        match self.names.get(&id) {
            Some(n) if !n.is_empty() => n.clone(),
            _ => format!("%{id}"),
        }
    }

    pub fn member_name(&self, ty: Id, index: u32) -> String {
        match self.member_names.get(&(ty, index)) {
            Some(n) if !n.is_empty() => n.clone(),
            _ => format!("member{index}"),
        }
    }

    pub fn ty(&self, id: Id) -> Option<&Type> {
        self.types.get(&id)
    }

    pub fn def(&self, id: Id) -> Option<&Instruction> {
        self.defs.get(&id).map(|&i| &self.insts[i])
    }

    pub fn decoration(&self, id: Id, d: spirv::Decoration) -> Option<&[u32]> {
        self.decorations
            .get(&id)?
            .iter()
            .find(|(k, _)| *k == d)
            .map(|(_, v)| v.as_slice())
    }

    pub fn member_decoration(&self, ty: Id, index: u32, d: spirv::Decoration) -> Option<&[u32]> {
        self.member_decorations
            .get(&(ty, index))?
            .iter()
            .find(|(k, _)| *k == d)
            .map(|(_, v)| v.as_slice())
    }

    /// An integer constant's value (not a specialization constant).
    pub fn const_u64(&self, id: Id) -> Option<u64> {
        match self.constants.get(&id)? {
            Constant::Int(v) => Some(*v),
            Constant::Bool(b) => Some(*b as u64),
            Constant::Null => Some(0),
            _ => None,
        }
    }

    pub fn operand_value(&self, id: Id) -> OperandValue {
        if let Some(v) = self.const_u64(id) {
            return OperandValue::Const(v);
        }
        if let Some(Constant::Int(v)) = self.spec_constants.get(&id) {
            return OperandValue::Spec { id, default: *v };
        }
        if let Some(v) = self.fold(id) {
            return OperandValue::Const(v);
        }
        OperandValue::Dynamic(id)
    }

    /// Converts a debug-info position to a diagnostic location.
    pub fn location(&self, pos: SrcPos) -> Location {
        let path = self
            .files
            .get(pos.file as usize)
            .map(|f| f.path.clone())
            .unwrap_or_else(|| self.path.clone());
        Location {
            path,
            line: pos.line,
            column: pos.column,
            end_line: pos.end_line.max(pos.line),
            end_column: pos.end_column,
        }
    }

    pub fn decl_location(&self, decl: Decl) -> Option<Location> {
        self.decl_pos.get(&decl).map(|p| self.location(*p))
    }

    pub fn inst_location(&self, inst: usize) -> Option<Location> {
        self.locs
            .get(inst)
            .copied()
            .flatten()
            .map(|p| self.location(p))
    }

    /// Instruction indices of the `OpFunctionCall`s that call function `f`.
    pub fn callers(&self, f: Id) -> Vec<usize> {
        self.call_index()
            .calls_to(f)
            .iter()
            .map(|&(_, i)| i)
            .collect()
    }

    /// Every call by callee and each function's callees, indexed in one
    /// pass over the module: call chains ask per function, and the
    /// analyses ask for reachable functions per shader and per entry point.
    pub(crate) fn call_index(&self) -> std::sync::Arc<CallIndex> {
        self.memo.get_or(|| {
            // Every call, also one outside every function (a module no
            // validator accepts): it calls nothing, but it is a caller.
            let mut by_callee: Vec<(Id, usize)> = Vec::new();
            for (i, inst) in self.insts.iter().enumerate() {
                if inst.class.opcode == Op::FunctionCall {
                    if let Some(Operand::IdRef(x)) = inst.operands.first() {
                        by_callee.push((*x, i));
                    }
                }
            }
            // Function indices by id; the first of an id wins (stable sort).
            let mut ids: Vec<(Id, usize)> = self
                .functions
                .iter()
                .enumerate()
                .map(|(k, f)| (f.id, k))
                .collect();
            ids.sort_by_key(|&(id, _)| id);
            ids.dedup_by_key(|&mut (id, _)| id);
            let index_of = |id: Id| match ids.binary_search_by_key(&id, |&(id, _)| id) {
                Ok(k) => ids[k].1,
                Err(_) => NOT_A_FUNCTION,
            };
            let first: Vec<usize> = self.functions.iter().map(|f| index_of(f.id)).collect();
            // Calls in module order, each function's from its range.
            let mut calls: Vec<(usize, Id)> = by_callee.iter().map(|&(c, i)| (i, c)).collect();
            calls.sort_unstable();
            let mut callee_start = Vec::with_capacity(self.functions.len() + 1);
            let mut callees = Vec::with_capacity(calls.len());
            for f in &self.functions {
                callee_start.push(callees.len());
                let from = calls.partition_point(|&(i, _)| i < f.start);
                for &(i, c) in &calls[from..] {
                    if i > f.end {
                        break;
                    }
                    callees.push((c, index_of(c)));
                }
            }
            callee_start.push(callees.len());
            by_callee.sort_unstable();
            CallIndex {
                by_callee,
                callee_start,
                callees,
                first,
            }
        })
    }

    /// The function (index into `functions`) containing instruction `inst`.
    pub fn function_of(&self, inst: usize) -> Option<usize> {
        self.functions
            .iter()
            .position(|f| f.start <= inst && inst <= f.end)
    }

    /// An instruction's position; for one without (code a compiler generated,
    /// such as naga's wrapper around each `traceRay`), the position of the
    /// first call that reaches its function (see `location_in` for the call
    /// in a given chain).
    pub fn site_location(&self, inst: usize) -> Option<Location> {
        let mut inst = inst;
        let mut seen = Vec::new();
        loop {
            if let Some(l) = self.inst_location(inst) {
                return Some(l);
            }
            let f = self.functions.get(self.function_of(inst)?)?.id;
            if seen.contains(&f) {
                return None;
            }
            seen.push(f);
            inst = *self.callers(f).first()?;
        }
    }

    /// The location of a variable: its declaration, else the first instruction
    /// with a position that uses it.
    pub fn var_location(&self, var: Id) -> Option<Location> {
        if let Some(l) = self.decl_location(Decl::Var(var)) {
            return Some(l);
        }
        self.insts.iter().enumerate().find_map(|(i, inst)| {
            let uses = inst
                .operands
                .iter()
                .any(|o| matches!(o, Operand::IdRef(x) if *x == var));
            if uses && inst.class.opcode != Op::Name && inst.class.opcode != Op::Decorate {
                self.inst_location(i)
            } else {
                None
            }
        })
    }

    /// The entry points whose call graph reaches function `f`.
    pub fn entry_points_reaching(&self, f: Id) -> Vec<&EntryPoint> {
        self.entry_points
            .iter()
            .filter(|e| self.reachable_functions(e.function).contains(&f))
            .collect()
    }

    /// Function ids reachable from `root` through `OpFunctionCall`, `root` first.
    pub fn reachable_functions(&self, root: Id) -> Vec<Id> {
        self.reach(root, true).0
    }

    /// Per function (index into `functions`): whether `root` reaches it
    /// through `OpFunctionCall`. The analyses ask per shader and per site;
    /// a module of one function needs no call index for it.
    pub fn reached_functions(&self, root: Id) -> Vec<bool> {
        match self.functions.as_slice() {
            [only] => vec![only.id == root],
            _ => self.reach(root, false).1,
        }
    }

    /// [`Program::reachable_functions`] (when `list`) and
    /// [`Program::reached_functions`].
    fn reach(&self, root: Id, list: bool) -> (Vec<Id>, Vec<bool>) {
        let index = self.call_index();
        let n = self.functions.len();
        // Flags by the first function of each id; ids that name no
        // function are listed but call nothing.
        let mut reached = vec![false; n];
        let mut others: Vec<Id> = Vec::new();
        let mut ids = if list { vec![root] } else { Vec::new() };
        let mut queue: Vec<usize> = Vec::with_capacity(n);
        match self.functions.iter().position(|f| f.id == root) {
            Some(fi) => {
                reached[fi] = true;
                queue.push(fi);
            }
            None => others.push(root),
        }
        let mut k = 0;
        while k < queue.len() {
            let fi = queue[k];
            for &(callee, ci) in &index.callees[index.callee_start[fi]..index.callee_start[fi + 1]]
            {
                let new = if ci == NOT_A_FUNCTION {
                    !others.contains(&callee) && {
                        others.push(callee);
                        true
                    }
                } else if reached[ci] {
                    false
                } else {
                    reached[ci] = true;
                    queue.push(ci);
                    true
                };
                if new && list {
                    ids.push(callee);
                }
            }
            k += 1;
        }
        // A later function with a reached function's id is reached too.
        for k in 0..n {
            let fi = index.first[k];
            if fi != k && fi != NOT_A_FUNCTION {
                reached[k] = reached[fi];
            }
        }
        (ids, reached)
    }

    pub fn function(&self, id: Id) -> Option<&Function> {
        self.functions.iter().find(|f| f.id == id)
    }

    pub fn function_index(&self, id: Id) -> Option<usize> {
        self.functions.iter().position(|f| f.id == id)
    }

    /// The global variables of one storage class.
    pub fn globals_in(&self, storage: StorageClass) -> impl Iterator<Item = &Global> {
        self.globals.iter().filter(move |g| g.storage == storage)
    }

    /// Adds declaration positions a front-end knows by name (WGSL: naga keeps
    /// spans that its SPIR-V writer does not emit), matched through `OpName`.
    pub fn attach_named_decls(&mut self, decls: &[(NamedDecl, Location)]) {
        use NamedDecl as N;
        // Each name's ids, globals and functions, found once: a lookup per
        // declaration, not a scan of every name (generated sources declare
        // thousands of functions).
        // Only struct types take a type's or a member's position, so only
        // they are listed.
        let mut by_name: HashMap<&str, Vec<Id>> = HashMap::default();
        for (id, n) in &self.names {
            if matches!(self.types.get(id), Some(Type::Struct { .. })) {
                by_name.entry(n.as_str()).or_default().push(*id);
            }
        }
        for ids in by_name.values_mut() {
            ids.sort_unstable();
        }
        let mut globals_named: HashMap<&str, Vec<Id>> = HashMap::default();
        for g in &self.globals {
            if let Some(n) = g.name.as_deref() {
                globals_named.entry(n).or_default().push(g.id);
            }
        }
        let mut functions_named: HashMap<&str, Vec<Id>> = HashMap::default();
        for f in &self.functions {
            if let Some(n) = f.name.as_deref() {
                functions_named.entry(n).or_default().push(f.id);
            }
        }
        fn named<'m>(map: &'m HashMap<&str, Vec<Id>>, name: &str) -> &'m [Id] {
            map.get(name).map_or(&[], Vec::as_slice)
        }
        let mut decl_pos = std::mem::take(&mut self.decl_pos);
        for (decl, loc) in decls {
            let file = match self.files.iter().position(|f| f.path == loc.path) {
                Some(i) => i as u32,
                None => {
                    self.files.push(SourceFile {
                        path: loc.path.clone(),
                        text: None,
                    });
                    (self.files.len() - 1) as u32
                }
            };
            let pos = SrcPos {
                file,
                line: loc.line,
                column: loc.column,
                end_line: loc.end_line,
                end_column: loc.end_column,
            };
            match decl {
                N::Type(name) => {
                    for &id in named(&by_name, name) {
                        decl_pos.insert(Decl::Type(id), pos);
                    }
                }
                N::Member(name, k) => {
                    for &id in named(&by_name, name) {
                        decl_pos.insert(Decl::Member(id, *k), pos);
                    }
                }
                N::Global(name) => {
                    for &id in named(&globals_named, name) {
                        decl_pos.insert(Decl::Var(id), pos);
                    }
                }
                N::Function(name) => {
                    for &id in named(&functions_named, name) {
                        decl_pos.insert(Decl::Func(id), pos);
                    }
                }
            }
        }
        self.decl_pos = decl_pos;
    }

    /// A short type name for messages (`vec3<f32>`-neutral: `float3`-like HLSL
    /// spelling, since that is what most ray-tracing shaders are written in).
    pub fn type_name(&self, id: Id) -> String {
        debug::type_name(self, id, self.language)
    }
}

/// Whether `op` is a ray-query instruction (`OpRayQuery*`): a match, not
/// the opcode's name, since analyses ask it of every instruction.
pub fn is_ray_query_op(op: Op) -> bool {
    matches!(
        op,
        Op::RayQueryInitializeKHR
            | Op::RayQueryTerminateKHR
            | Op::RayQueryGenerateIntersectionKHR
            | Op::RayQueryConfirmIntersectionKHR
            | Op::RayQueryProceedKHR
            | Op::RayQueryGetIntersectionTypeKHR
            | Op::RayQueryGetIntersectionTriangleVertexPositionsKHR
            | Op::RayQueryGetIntersectionClusterIdNV
            | Op::RayQueryGetIntersectionSpherePositionNV
            | Op::RayQueryGetIntersectionSphereRadiusNV
            | Op::RayQueryGetIntersectionLSSPositionsNV
            | Op::RayQueryGetIntersectionLSSRadiiNV
            | Op::RayQueryGetIntersectionLSSHitValueNV
            | Op::RayQueryIsSphereHitNV
            | Op::RayQueryIsLSSHitNV
            | Op::RayQueryGetRayTMinKHR
            | Op::RayQueryGetRayFlagsKHR
            | Op::RayQueryGetIntersectionTKHR
            | Op::RayQueryGetIntersectionInstanceCustomIndexKHR
            | Op::RayQueryGetIntersectionInstanceIdKHR
            | Op::RayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetKHR
            | Op::RayQueryGetIntersectionGeometryIndexKHR
            | Op::RayQueryGetIntersectionPrimitiveIndexKHR
            | Op::RayQueryGetIntersectionBarycentricsKHR
            | Op::RayQueryGetIntersectionFrontFaceKHR
            | Op::RayQueryGetIntersectionCandidateAABBOpaqueKHR
            | Op::RayQueryGetIntersectionObjectRayDirectionKHR
            | Op::RayQueryGetIntersectionObjectRayOriginKHR
            | Op::RayQueryGetWorldRayDirectionKHR
            | Op::RayQueryGetWorldRayOriginKHR
            | Op::RayQueryGetIntersectionObjectToWorldKHR
            | Op::RayQueryGetIntersectionWorldToObjectKHR
    )
}

/// Whether `op` is an ordered or unordered float comparison
/// (`OpFOrd*`, `OpFUnord*`).
pub fn is_float_compare_op(op: Op) -> bool {
    matches!(
        op,
        Op::FOrdEqual
            | Op::FUnordEqual
            | Op::FOrdNotEqual
            | Op::FUnordNotEqual
            | Op::FOrdLessThan
            | Op::FUnordLessThan
            | Op::FOrdGreaterThan
            | Op::FUnordGreaterThan
            | Op::FOrdLessThanEqual
            | Op::FUnordLessThanEqual
            | Op::FOrdGreaterThanEqual
            | Op::FUnordGreaterThanEqual
    )
}

/// Whether `op` reads a texture (samples, fetches or gathers): the texture
/// work rules look for in any-hit shaders and ray-query loops.
pub fn is_texture_read(op: spirv::Op) -> bool {
    use spirv::Op;
    matches!(
        op,
        Op::ImageSampleImplicitLod
            | Op::ImageSampleExplicitLod
            | Op::ImageSampleDrefImplicitLod
            | Op::ImageSampleDrefExplicitLod
            | Op::ImageSampleProjImplicitLod
            | Op::ImageSampleProjExplicitLod
            | Op::ImageFetch
            | Op::ImageGather
    )
}

#[cfg(test)]
mod op_tests {
    /// The matches above are the opcodes whose names say so: every opcode
    /// the `spirv` crate knows, by its name.
    #[test]
    fn opcode_families_match_their_names() {
        let mut ray_query = 0;
        for w in 0..=0xffffu32 {
            let Some(op) = spirv::Op::from_u32(w) else {
                continue;
            };
            let name = format!("{op:?}");
            assert_eq!(
                super::is_ray_query_op(op),
                name.starts_with("RayQuery"),
                "{name}"
            );
            assert_eq!(
                super::is_float_compare_op(op),
                name.starts_with("FOrd") || name.starts_with("FUnord"),
                "{name}"
            );
            ray_query += name.starts_with("RayQuery") as usize;
        }
        assert_eq!(ray_query, 32);
    }
}

#[cfg(test)]
mod call_tests {
    use super::*;
    use std::path::Path;

    fn load(rel: &str) -> Program {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
        let lang = crate::shader::Language::from_path(&path).unwrap();
        crate::front::load(&path, lang).unwrap()
    }

    /// Every `OpFunctionCall` of the module: `(instruction, callee)`.
    fn scanned_calls(p: &Program) -> Vec<(usize, Id)> {
        p.insts
            .iter()
            .enumerate()
            .filter(|(_, i)| i.class.opcode == Op::FunctionCall)
            .filter_map(|(k, i)| match i.operands.first() {
                Some(Operand::IdRef(x)) => Some((k, *x)),
                _ => None,
            })
            .collect()
    }

    /// The call index answers as a scan of the module does: callers in
    /// module order, reachable functions breadth-first from each entry
    /// point, and a flag per function; a call outside every function
    /// (invalid, but readable) is still one of its callee's callers.
    #[test]
    fn index_answers_as_a_scan_does() {
        let mut helpers = 0;
        for rel in [
            "fixtures/guards/constructed.wgsl",
            "fixtures/guards/fresh.hlsl",
            "fixtures/guards/two_calls.wgsl",
            "fixtures/guards/loop.rgen.g.spv",
        ] {
            let mut p = load(rel);
            let Some(helper) = p
                .functions
                .iter()
                .map(|f| f.id)
                .find(|&id| scanned_calls(&p).iter().any(|&(_, c)| c == id))
            else {
                continue;
            };
            helpers += 1;
            // An instruction before the first function made a call.
            let k = p.functions[0].start - 1;
            p.insts[k] = rspirv::dr::Instruction::new(
                Op::FunctionCall,
                Some(1),
                Some(1),
                vec![Operand::IdRef(helper)],
            );
            let calls = scanned_calls(&p);
            for f in &p.functions {
                let want: Vec<usize> = calls
                    .iter()
                    .filter(|&&(_, c)| c == f.id)
                    .map(|&(i, _)| i)
                    .collect();
                assert_eq!(p.callers(f.id), want, "{rel} %{}", f.id);
            }
            assert_eq!(p.callers(helper).first(), Some(&k), "{rel}");
            for e in &p.entry_points {
                let mut want = vec![e.function];
                let mut n = 0;
                while n < want.len() {
                    if let Some(f) = p.function(want[n]) {
                        for &(i, c) in &calls {
                            if f.start <= i && i <= f.end && !want.contains(&c) {
                                want.push(c);
                            }
                        }
                    }
                    n += 1;
                }
                assert_eq!(p.reachable_functions(e.function), want, "{rel} {}", e.name);
                let flags: Vec<bool> = p.functions.iter().map(|f| want.contains(&f.id)).collect();
                assert_eq!(p.reached_functions(e.function), flags, "{rel} {}", e.name);
            }
        }
        assert!(helpers >= 2, "{helpers}");
    }
}
