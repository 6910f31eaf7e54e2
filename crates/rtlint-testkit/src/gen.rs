//! Random valid ray-tracing SPIR-V modules for checking the analyses'
//! invariants (`tests/spirv_gen.rs`, the `spirv_gen` fuzz target).
//!
//! A module holds one ray generation shader and up to six more entry points
//! of any ray-tracing stage, payload and callable-data globals of random
//! struct types, Function-storage locals of random sizes, structured
//! control flow (if/else with `OpSelectionMerge`, counted loops with
//! `OpLoopMerge`, `OpPhi` at merges and loop headers), arithmetic on locals
//! and their parts, `OpTraceRayKHR` and `OpExecuteCallableKHR` anywhere a
//! statement may go, and calls of helper functions (a helper calls only
//! helpers after it, so there is no recursion). With `debug` the same
//! module also carries `NonSemantic.Shader.DebugInfo.100`: the random
//! choices do not depend on it, so stripping the debug instructions gives
//! the module generated without them, id for id.
//!
//! Every choice is read from a [`Source`]: a seed, or a fuzzer's bytes
//! (read one choice at a time; once they run out every choice is the
//! first, so generation always ends).

use rspirv::binary::Assemble;
use rspirv::dr::{Block, Builder, Function, Instruction, Operand};
use rtlint::shader::Stage;
use spirv::{
    Capability, Decoration, ExecutionModel, FunctionControl, LoopControl, Op, SelectionControl,
    StorageClass, Word,
};
use std::collections::HashMap;

/// Where the choices come from.
pub struct Source<'a> {
    bytes: Option<&'a [u8]>,
    state: u64,
}

impl Source<'static> {
    pub fn seed(seed: u64) -> Self {
        Source {
            bytes: None,
            state: seed ^ 0x9e37_79b9_7f4a_7c15,
        }
    }
}

impl<'a> Source<'a> {
    pub fn bytes(bytes: &'a [u8]) -> Self {
        Source {
            bytes: Some(bytes),
            state: 0,
        }
    }

    /// A number in `0..n` (0 when `n` is 0).
    pub fn below(&mut self, n: u32) -> u32 {
        if n <= 1 {
            return 0;
        }
        let x = match &mut self.bytes {
            Some(b) => {
                // One byte per choice keeps the fuzzer's mutations local.
                let (first, rest) = b.split_first().map(|(f, r)| (*f, r)).unwrap_or((0, &[]));
                *b = rest;
                u64::from(first)
            }
            None => {
                // splitmix64
                self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
                let mut z = self.state;
                z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
                z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
                z ^ (z >> 31)
            }
        };
        (x % u64::from(n)) as u32
    }

    fn chance(&mut self, percent: u32) -> bool {
        // A fuzzer's exhausted input (all zeros) says "no" to every option.
        self.below(100) >= 100 - percent
    }

    fn pick<T: Clone>(&mut self, v: &[T]) -> Option<T> {
        if v.is_empty() {
            return None;
        }
        Some(v[self.below(v.len() as u32) as usize].clone())
    }
}

/// One trace of an entry point (its own or in a helper it calls): the SBT
/// offset and miss index, `None` when computed at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GenTrace {
    pub sbt_offset: Option<u32>,
    pub miss_index: Option<u32>,
    /// Ray flag `OpaqueKHR`: no any-hit shader runs.
    pub opaque: bool,
}

/// An entry point as generated, in module order.
#[derive(Clone, Debug)]
pub struct GenEntry {
    pub name: String,
    pub stage: Stage,
    /// Every trace reachable from it, helpers included.
    pub traces: Vec<GenTrace>,
}

#[derive(Clone, Debug)]
pub struct Generated {
    pub words: Vec<u32>,
    pub entries: Vec<GenEntry>,
}

/// A module from `src`; with `debug`, with its debug info.
pub fn module(src: &mut Source, debug: bool) -> Generated {
    Gen::new(debug).run(src)
}

/// The module of `seed`.
pub fn module_of_seed(seed: u64, debug: bool) -> Generated {
    module(&mut Source::seed(seed), debug)
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Ty {
    F32,
    U32,
    Vec(u32),
    Arr(Box<Ty>, u32),
    Struct(Vec<Ty>),
}

impl Ty {
    fn is_scalar(&self) -> bool {
        matches!(self, Ty::F32 | Ty::U32)
    }

    /// Paths to every scalar inside, with the scalar's type.
    fn leaves(&self) -> Vec<(Vec<u32>, Ty)> {
        match self {
            Ty::F32 | Ty::U32 => vec![(Vec::new(), self.clone())],
            Ty::Vec(n) => (0..*n).map(|i| (vec![i], Ty::F32)).collect(),
            Ty::Arr(e, n) => (0..*n)
                .flat_map(|i| {
                    e.leaves().into_iter().map(move |(mut p, t)| {
                        p.insert(0, i);
                        (p, t)
                    })
                })
                .collect(),
            Ty::Struct(m) => m
                .iter()
                .enumerate()
                .flat_map(|(i, t)| {
                    t.leaves().into_iter().map(move |(mut p, s)| {
                        p.insert(0, i as u32);
                        (p, s)
                    })
                })
                .collect(),
        }
    }

    fn bytes(&self) -> u32 {
        match self {
            Ty::F32 | Ty::U32 => 4,
            Ty::Vec(n) => 4 * n,
            Ty::Arr(e, n) => e.bytes() * n,
            Ty::Struct(m) => m.iter().map(Ty::bytes).sum(),
        }
    }
}

fn random_ty(src: &mut Source, depth: u32) -> Ty {
    match src.below(if depth > 1 { 3 } else { 6 }) {
        0 => Ty::F32,
        1 => Ty::U32,
        2 => Ty::Vec(2 + src.below(3)),
        3 => Ty::Arr(
            Box::new(if src.chance(50) { Ty::F32 } else { Ty::U32 }),
            1 + src.below(16),
        ),
        4 => Ty::Arr(Box::new(random_ty(src, depth + 1)), 1 + src.below(4)),
        _ => {
            let n = 1 + src.below(4);
            Ty::Struct((0..n).map(|_| random_ty(src, depth + 1)).collect())
        }
    }
}

fn random_struct(src: &mut Source) -> Ty {
    let n = 1 + src.below(5);
    Ty::Struct((0..n).map(|_| random_ty(src, 1)).collect())
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Entry(Stage),
    /// A helper that may trace and execute callables: called only from
    /// ray generation, closest-hit and miss shaders.
    Tracing,
    /// A helper doing arithmetic only: callable from anywhere.
    Pure,
}

struct Helper {
    id: Word,
    kind: Kind,
    /// Parameters: `floats` floats, then a pointer to a local of `ptr_ty`.
    floats: u32,
    ptr_ty: Option<Ty>,
    returns_float: bool,
}

/// Module-wide state.
struct Gen {
    b: Builder,
    debug: bool,
    types: HashMap<Ty, Word>,
    ptrs: HashMap<(StorageClass, Ty), Word>,
    consts: HashMap<(Word, u32), Word>,
    nulls: HashMap<Word, Word>,
    void: Word,
    bool_ty: Word,
    f32: Word,
    u32: Word,
    vec3: Word,
    accel: Word,
    accel_ty: Word,
    /// Whether the module uses inline ray queries, and their type.
    queries: bool,
    query_ty: Word,
    payloads: Vec<(Word, Ty)>,
    callable_data: Vec<(Word, Ty)>,
    hit_attr: Word,
    helpers: Vec<Helper>,
    /// Globals and functions each function uses, by function id.
    uses: HashMap<Word, (Vec<Word>, Vec<Word>)>,
    traces: HashMap<Word, Vec<GenTrace>>,
    n_groups: u32,
    n_miss: u32,
    n_callable: u32,
    names: u32,
    dbg: Option<Dbg>,
}

/// Debug-info ids shared by the module.
struct Dbg {
    set: Word,
    source: Word,
    unit: Word,
    expr: Word,
    types: HashMap<Ty, Word>,
    line: u32,
}

impl Gen {
    fn new(debug: bool) -> Gen {
        let mut b = Builder::new();
        b.set_version(1, 4);
        let void = b.type_void();
        let bool_ty = b.type_bool();
        let f32 = b.type_float(32, None);
        let u32 = b.type_int(32, 0);
        let vec3 = b.type_vector(f32, 3);
        let accel_ty = b.type_acceleration_structure_khr();
        Gen {
            b,
            debug,
            types: HashMap::new(),
            ptrs: HashMap::new(),
            consts: HashMap::new(),
            nulls: HashMap::new(),
            void,
            bool_ty,
            f32,
            u32,
            vec3,
            accel: 0,
            accel_ty,
            queries: false,
            query_ty: 0,
            payloads: Vec::new(),
            callable_data: Vec::new(),
            hit_attr: 0,
            helpers: Vec::new(),
            uses: HashMap::new(),
            traces: HashMap::new(),
            n_groups: 0,
            n_miss: 0,
            n_callable: 0,
            names: 0,
            dbg: None,
        }
    }

    fn ty(&mut self, t: &Ty) -> Word {
        if let Some(id) = self.types.get(t) {
            return *id;
        }
        let id = match t {
            Ty::F32 => self.f32,
            Ty::U32 => self.u32,
            Ty::Vec(n) => self.b.type_vector(self.f32, *n),
            Ty::Arr(e, n) => {
                let e = self.ty(e);
                let len = self.uconst(*n);
                // Not deduplicated by the builder: one id per shape here.
                let id = self.b.id();
                self.b
                    .module_mut()
                    .types_global_values
                    .push(Instruction::new(
                        Op::TypeArray,
                        None,
                        Some(id),
                        vec![Operand::IdRef(e), Operand::IdRef(len)],
                    ));
                id
            }
            Ty::Struct(m) => {
                let members: Vec<Word> = m.iter().map(|x| self.ty(x)).collect();
                let id = self.b.id();
                self.b
                    .module_mut()
                    .types_global_values
                    .push(Instruction::new(
                        Op::TypeStruct,
                        None,
                        Some(id),
                        members.into_iter().map(Operand::IdRef).collect(),
                    ));
                let name = format!("S{}", self.types.len());
                self.b.name(id, name);
                id
            }
        };
        self.types.insert(t.clone(), id);
        id
    }

    fn ptr(&mut self, sc: StorageClass, t: &Ty) -> Word {
        if let Some(id) = self.ptrs.get(&(sc, t.clone())) {
            return *id;
        }
        let inner = self.ty(t);
        let id = self.b.id();
        self.b
            .module_mut()
            .types_global_values
            .push(Instruction::new(
                Op::TypePointer,
                None,
                Some(id),
                vec![Operand::StorageClass(sc), Operand::IdRef(inner)],
            ));
        self.ptrs.insert((sc, t.clone()), id);
        id
    }

    fn constant(&mut self, ty: Word, bits: u32) -> Word {
        if let Some(id) = self.consts.get(&(ty, bits)) {
            return *id;
        }
        let id = self.b.constant_bit32(ty, bits);
        self.consts.insert((ty, bits), id);
        id
    }

    fn uconst(&mut self, v: u32) -> Word {
        self.constant(self.u32, v)
    }

    fn fconst(&mut self, v: f32) -> Word {
        self.constant(self.f32, v.to_bits())
    }

    fn null(&mut self, ty: Word) -> Word {
        if let Some(id) = self.nulls.get(&ty) {
            return *id;
        }
        let id = self.b.constant_null(ty);
        self.nulls.insert(ty, id);
        id
    }

    fn global(&mut self, sc: StorageClass, t: &Ty, name: &str) -> Word {
        let p = self.ptr(sc, t);
        let id = self.b.variable(p, None, sc, None);
        self.b.name(id, name);
        id
    }

    fn fresh_name(&mut self, prefix: &str) -> String {
        self.names += 1;
        format!("{prefix}{}", self.names)
    }

    fn run(mut self, src: &mut Source) -> Generated {
        self.b.capability(Capability::Shader);
        self.b.capability(Capability::RayTracingKHR);
        self.b.extension("SPV_KHR_ray_tracing");
        self.queries = src.chance(40);
        if self.queries {
            self.b.capability(Capability::RayQueryKHR);
            self.b.extension("SPV_KHR_ray_query");
            self.query_ty = self.b.type_ray_query_khr();
        }
        if self.debug {
            self.b.extension("SPV_KHR_non_semantic_info");
        }
        let set = self
            .debug
            .then(|| self.b.ext_inst_import("NonSemantic.Shader.DebugInfo.100"));
        self.b
            .memory_model(spirv::AddressingModel::Logical, spirv::MemoryModel::GLSL450);
        let accel_ptr = self
            .b
            .type_pointer(None, StorageClass::UniformConstant, self.accel_ty);
        self.accel = self
            .b
            .variable(accel_ptr, None, StorageClass::UniformConstant, None);
        self.b.name(self.accel, "scene");
        self.b.decorate(
            self.accel,
            Decoration::DescriptorSet,
            [Operand::LiteralBit32(0)],
        );
        self.b
            .decorate(self.accel, Decoration::Binding, [Operand::LiteralBit32(0)]);

        // Stages: one ray generation shader first, then the others.
        let mut stages = vec![Stage::RayGeneration];
        for _ in 0..src.below(7) {
            stages.push(match src.below(6) {
                0 => Stage::RayGeneration,
                1 => Stage::ClosestHit,
                2 => Stage::Miss,
                3 => Stage::AnyHit,
                4 => Stage::Intersection,
                _ => Stage::Callable,
            });
        }
        self.n_groups = stages
            .iter()
            .filter(|s| matches!(s, Stage::ClosestHit | Stage::AnyHit | Stage::Intersection))
            .count() as u32;
        self.n_miss = stages.iter().filter(|s| **s == Stage::Miss).count() as u32;
        self.n_callable = stages.iter().filter(|s| **s == Stage::Callable).count() as u32;

        // One payload type for every trace and every hit and miss shader:
        // rtlint joins a trace only to the shaders whose incoming payload has
        // its shape, and the generator's own graph (the depth bounds the
        // checks compare with) knows the SBT operands, not payload types.
        // Reach by payload has tests of its own.
        let payload_ty = random_struct(src);
        for k in 0..1 + src.below(3) {
            let t = payload_ty.clone();
            let v = self.global(StorageClass::RayPayloadKHR, &t, &format!("payload{k}"));
            self.payloads.push((v, t));
        }
        for k in 0..1 + src.below(2) {
            let t = random_struct(src);
            let v = self.global(StorageClass::CallableDataKHR, &t, &format!("callData{k}"));
            self.callable_data.push((v, t));
        }
        self.hit_attr = self.global(StorageClass::HitAttributeKHR, &Ty::Vec(2), "attribs");

        // The source language, said alike with and without debug info (it
        // decides the HLSL-only rules).
        let lang = [0u32, 2, 5][src.below(3) as usize];
        let language = match lang {
            2 => spirv::SourceLanguage::GLSL,
            5 => spirv::SourceLanguage::HLSL,
            _ => spirv::SourceLanguage::Unknown,
        };
        self.b.source(language, 460, None, None::<String>);
        if let Some(set) = set {
            self.dbg_init(set, lang);
        }

        // Helpers, each calling only later ones.
        for _ in 0..src.below(5) {
            let kind = if src.chance(50) {
                Kind::Tracing
            } else {
                Kind::Pure
            };
            let ptr_ty = src.chance(50).then(|| random_ty(src, 0));
            let h = Helper {
                id: self.b.id(),
                kind,
                floats: src.below(3),
                ptr_ty,
                returns_float: src.chance(60),
            };
            self.helpers.push(h);
        }
        for k in 0..self.helpers.len() {
            let (id, kind) = (self.helpers[k].id, self.helpers[k].kind);
            let name = format!("helper{k}");
            self.function(src, id, kind, Some(k), &name, None);
        }

        let mut entries = Vec::new();
        let mut counts: HashMap<Stage, u32> = HashMap::new();
        for stage in stages {
            let c = counts.entry(stage).or_default();
            let name = format!("{}{}", stage.as_str(), *c);
            *c += 1;
            let incoming = match stage {
                Stage::ClosestHit | Stage::Miss | Stage::AnyHit => {
                    let t = payload_ty.clone();
                    Some((
                        self.global(
                            StorageClass::IncomingRayPayloadKHR,
                            &t,
                            &format!("{name}_in"),
                        ),
                        t,
                    ))
                }
                Stage::Callable => {
                    let t = random_struct(src);
                    Some((
                        self.global(
                            StorageClass::IncomingCallableDataKHR,
                            &t,
                            &format!("{name}_in"),
                        ),
                        t,
                    ))
                }
                _ => None,
            };
            let id = self.b.id();
            self.function(src, id, Kind::Entry(stage), None, &name, incoming);
            let (globals, _) = self.closure(id);
            let model = match stage {
                Stage::RayGeneration => ExecutionModel::RayGenerationKHR,
                Stage::ClosestHit => ExecutionModel::ClosestHitKHR,
                Stage::Miss => ExecutionModel::MissKHR,
                Stage::AnyHit => ExecutionModel::AnyHitKHR,
                Stage::Intersection => ExecutionModel::IntersectionKHR,
                _ => ExecutionModel::CallableKHR,
            };
            self.b.entry_point(model, id, name.clone(), globals);
            let (_, funcs) = self.closure(id);
            let traces = funcs
                .iter()
                .flat_map(|f| self.traces.get(f).cloned().unwrap_or_default())
                .collect();
            entries.push(GenEntry {
                name,
                stage,
                traces,
            });
        }
        Generated {
            words: self.b.module().assemble(),
            entries,
        }
    }

    /// Globals used by `f` and every function it calls, and those functions.
    fn closure(&self, f: Word) -> (Vec<Word>, Vec<Word>) {
        let mut funcs = vec![f];
        let mut globals = Vec::new();
        let mut k = 0;
        while k < funcs.len() {
            if let Some((g, calls)) = self.uses.get(&funcs[k]) {
                for x in g {
                    if !globals.contains(x) {
                        globals.push(*x);
                    }
                }
                for c in calls {
                    if !funcs.contains(c) {
                        funcs.push(*c);
                    }
                }
            }
            k += 1;
        }
        (globals, funcs)
    }

    fn function(
        &mut self,
        src: &mut Source,
        id: Word,
        kind: Kind,
        helper: Option<usize>,
        name: &str,
        incoming: Option<(Word, Ty)>,
    ) {
        self.b.name(id, name);
        let (floats, ptr_ty, returns_float) = match helper {
            Some(k) => {
                let h = &self.helpers[k];
                (h.floats, h.ptr_ty.clone(), h.returns_float)
            }
            None => (0, None, false),
        };
        let ret = if returns_float { self.f32 } else { self.void };
        let mut param_tys = vec![self.f32; floats as usize];
        let ptr_param_ty = ptr_ty.as_ref().map(|t| self.ptr(StorageClass::Function, t));
        param_tys.extend(ptr_param_ty);
        let fn_ty = self.b.type_function(ret, param_tys.clone());
        let mut f = Function::new();
        f.def = Some(Instruction::new(
            Op::Function,
            Some(ret),
            Some(id),
            vec![
                Operand::FunctionControl(FunctionControl::NONE),
                Operand::IdRef(fn_ty),
            ],
        ));
        let mut fg = FnGen {
            kind,
            helper,
            blocks: Vec::new(),
            cur: Vec::new(),
            label: self.b.id(),
            vars: Vec::new(),
            locals: Vec::new(),
            scopes: vec![Vec::new()],
            globals: Vec::new(),
            calls: Vec::new(),
            traces: Vec::new(),
            incoming,
            returns_float,
            budget: 4 + src.below(24),
            depth: 0,
            dbg_fn: None,
            dbg_pending: Vec::new(),
        };
        for (k, t) in param_tys.iter().enumerate() {
            let p = self.b.id();
            f.parameters.push(Instruction::new(
                Op::FunctionParameter,
                Some(*t),
                Some(p),
                vec![],
            ));
            if Some(*t) == ptr_param_ty && k == param_tys.len() - 1 {
                self.b.name(p, "inout");
                fg.locals.push((p, ptr_ty.clone().unwrap(), false));
            } else {
                fg.scopes[0].push((p, Ty::F32));
            }
        }
        if self.dbg.is_some() {
            let scope = self.dbg_function(name, returns_float, floats);
            fg.dbg_fn = Some(scope);
            let set = self.dbg.as_ref().unwrap().set;
            let def = self.b.id();
            fg.dbg_pending.push(Instruction::new(
                Op::ExtInst,
                Some(self.void),
                Some(def),
                vec![
                    Operand::IdRef(set),
                    Operand::LiteralExtInstInteger(D_FUNCTION_DEFINITION),
                    Operand::IdRef(scope),
                    Operand::IdRef(id),
                ],
            ));
        }
        // Locals.
        for _ in 0..src.below(5) {
            let t = random_ty(src, 0);
            fg.new_local(self, t);
        }
        fg.statements(self, src);
        fg.exit(self, src, false);
        // Variables first in the entry block, then the debug declarations.
        let mut blocks = std::mem::take(&mut fg.blocks);
        let first = &mut blocks[0].instructions;
        let mut head = std::mem::take(&mut fg.vars);
        head.append(&mut fg.dbg_pending);
        head.append(first);
        *first = head;
        f.blocks = blocks;
        f.end = Some(Instruction::new(Op::FunctionEnd, None, None, vec![]));
        self.b.module_mut().functions.push(f);
        self.uses.insert(id, (fg.globals, fg.calls));
        self.traces.insert(id, fg.traces);
    }

    // ---- debug info -------------------------------------------------------

    fn dbg_inst(&mut self, which: u32, args: &[Word]) -> Word {
        let set = self.dbg.as_ref().map(|d| d.set).unwrap_or(0);
        let id = self.b.id();
        let mut ops = vec![Operand::IdRef(set), Operand::LiteralExtInstInteger(which)];
        ops.extend(args.iter().map(|a| Operand::IdRef(*a)));
        self.b
            .module_mut()
            .types_global_values
            .push(Instruction::new(
                Op::ExtInst,
                Some(self.void),
                Some(id),
                ops,
            ));
        id
    }

    fn dbg_init(&mut self, set: Word, lang: u32) {
        let text: String = (1..=400)
            .map(|i| format!("// generated line {i}\n"))
            .collect();
        let file = self.b.string("generated.rt");
        let text = self.b.string(text);
        self.dbg = Some(Dbg {
            set,
            source: 0,
            unit: 0,
            expr: 0,
            types: HashMap::new(),
            line: 1,
        });
        let source = self.dbg_inst(D_SOURCE, &[file, text]);
        let version = self.uconst(100);
        let dwarf = self.uconst(4);
        let lang = self.uconst(lang);
        let unit = self.dbg_inst(D_COMPILATION_UNIT, &[version, dwarf, source, lang]);
        let expr = self.dbg_inst(D_EXPRESSION, &[]);
        let d = self.dbg.as_mut().unwrap();
        d.source = source;
        d.unit = unit;
        d.expr = expr;
    }

    fn next_line(&mut self) -> u32 {
        let d = self.dbg.as_mut().unwrap();
        d.line = d.line % 399 + 1;
        d.line
    }

    fn dbg_type(&mut self, t: &Ty) -> Word {
        if let Some(id) = self.dbg.as_ref().unwrap().types.get(t) {
            return *id;
        }
        let flags = self.uconst(3);
        let id = match t {
            Ty::F32 | Ty::U32 => {
                let name = self.b.string(if *t == Ty::F32 { "float" } else { "uint" });
                let size = self.uconst(32);
                let enc = self.uconst(if *t == Ty::F32 { 3 } else { 6 });
                let flags = self.uconst(0);
                self.dbg_inst(D_TYPE_BASIC, &[name, size, enc, flags])
            }
            Ty::Vec(n) => {
                let e = self.dbg_type(&Ty::F32);
                let n = self.uconst(*n);
                self.dbg_inst(D_TYPE_VECTOR, &[e, n])
            }
            Ty::Arr(e, n) => {
                let e = self.dbg_type(e);
                let n = self.uconst(*n);
                self.dbg_inst(D_TYPE_ARRAY, &[e, n])
            }
            Ty::Struct(m) => {
                let (source, unit) = {
                    let d = self.dbg.as_ref().unwrap();
                    (d.source, d.unit)
                };
                let mut members = Vec::new();
                let mut offset = 0;
                for (k, x) in m.iter().enumerate() {
                    let ty = self.dbg_type(x);
                    let name = self.b.string(format!("m{k}"));
                    let line = self.next_line();
                    let line = self.uconst(line);
                    let col = self.uconst(1);
                    let off = self.uconst(offset * 8);
                    let bits = self.uconst(x.bytes() * 8);
                    offset += x.bytes();
                    members.push(self.dbg_inst(
                        D_TYPE_MEMBER,
                        &[name, ty, source, line, col, off, bits, flags],
                    ));
                }
                let name = self
                    .b
                    .string(format!("T{}", self.dbg.as_ref().unwrap().types.len()));
                let tag = self.uconst(1);
                let line = self.next_line();
                let line = self.uconst(line);
                let col = self.uconst(1);
                let bits = self.uconst(t.bytes() * 8);
                let mut args = vec![name, tag, source, line, col, unit, name, bits, flags];
                args.extend(members);
                self.dbg_inst(D_TYPE_COMPOSITE, &args)
            }
        };
        self.dbg.as_mut().unwrap().types.insert(t.clone(), id);
        id
    }

    fn dbg_function(&mut self, name: &str, returns_float: bool, floats: u32) -> Word {
        let flags = self.uconst(3);
        let ret = if returns_float {
            self.dbg_type(&Ty::F32)
        } else {
            self.void
        };
        let mut targs = vec![flags, ret];
        for _ in 0..floats {
            targs.push(self.dbg_type(&Ty::F32));
        }
        let fty = self.dbg_inst(D_TYPE_FUNCTION, &targs);
        let n = self.b.string(name);
        let (source, unit) = {
            let d = self.dbg.as_ref().unwrap();
            (d.source, d.unit)
        };
        let line = self.next_line();
        let line = self.uconst(line);
        let col = self.uconst(1);
        self.dbg_inst(
            D_FUNCTION,
            &[n, fty, source, line, col, unit, n, flags, line],
        )
    }

    fn dbg_local(&mut self, scope: Word, name: &str, t: &Ty) -> Word {
        let ty = self.dbg_type(t);
        let n = self.b.string(name);
        let source = self.dbg.as_ref().unwrap().source;
        let line = self.next_line();
        let line = self.uconst(line);
        let col = self.uconst(1);
        let flags = self.uconst(4);
        self.dbg_inst(D_LOCAL_VARIABLE, &[n, ty, source, line, col, scope, flags])
    }
}

// NonSemantic.Shader.DebugInfo.100 instruction numbers.
const D_SCOPE: u32 = 23;
const D_LINE: u32 = 103;
const D_SOURCE: u32 = 35;
const D_COMPILATION_UNIT: u32 = 1;
const D_TYPE_BASIC: u32 = 2;
const D_TYPE_ARRAY: u32 = 5;
const D_TYPE_VECTOR: u32 = 6;
const D_TYPE_FUNCTION: u32 = 8;
const D_TYPE_COMPOSITE: u32 = 10;
const D_TYPE_MEMBER: u32 = 11;
const D_FUNCTION: u32 = 20;
const D_LOCAL_VARIABLE: u32 = 26;
const D_DECLARE: u32 = 28;
const D_VALUE: u32 = 29;
const D_EXPRESSION: u32 = 31;
const D_FUNCTION_DEFINITION: u32 = 101;

/// One function being generated.
struct FnGen {
    kind: Kind,
    helper: Option<usize>,
    blocks: Vec<Block>,
    cur: Vec<Instruction>,
    label: Word,
    vars: Vec<Instruction>,
    /// Locals (variables, and the pointer parameter) with their type and
    /// whether they are an `OpVariable` (may be passed to a call).
    locals: Vec<(Word, Ty, bool)>,
    /// SSA values in scope, innermost construct last.
    scopes: Vec<Vec<(Word, Ty)>>,
    globals: Vec<Word>,
    calls: Vec<Word>,
    traces: Vec<GenTrace>,
    incoming: Option<(Word, Ty)>,
    returns_float: bool,
    budget: u32,
    depth: u32,
    dbg_fn: Option<Word>,
    /// Debug instructions for after the variables in the entry block.
    dbg_pending: Vec<Instruction>,
}

impl FnGen {
    fn stage(&self) -> Option<Stage> {
        match self.kind {
            Kind::Entry(s) => Some(s),
            _ => None,
        }
    }

    fn can_trace(&self) -> bool {
        match self.kind {
            Kind::Entry(s) => matches!(s, Stage::RayGeneration | Stage::ClosestHit | Stage::Miss),
            Kind::Tracing => true,
            Kind::Pure => false,
        }
    }

    fn can_call(&self) -> bool {
        match self.kind {
            Kind::Entry(s) => matches!(
                s,
                Stage::RayGeneration | Stage::ClosestHit | Stage::Miss | Stage::Callable
            ),
            Kind::Tracing => true,
            Kind::Pure => false,
        }
    }

    fn use_global(&mut self, g: Word) {
        if !self.globals.contains(&g) {
            self.globals.push(g);
        }
    }

    fn end_block(&mut self) {
        let mut b = Block::new();
        b.label = Some(Instruction::new(Op::Label, None, Some(self.label), vec![]));
        b.instructions = std::mem::take(&mut self.cur);
        self.blocks.push(b);
    }

    fn start_block(&mut self, label: Word) {
        self.label = label;
    }

    /// An instruction without a result (stores, branches, merges, traces).
    fn stmt(&mut self, op: Op, ops: Vec<Operand>) {
        self.cur.push(Instruction::new(op, None, None, ops));
    }

    fn push(&mut self, g: &mut Gen, op: Op, ty: Word, ops: Vec<Operand>) -> Word {
        let id = g.b.id();
        self.cur.push(Instruction::new(op, Some(ty), Some(id), ops));
        id
    }

    fn add_value(&mut self, g: &mut Gen, src: &mut Source, id: Word, t: Ty) {
        if let (Some(scope), Some(_)) = (self.dbg_fn, &g.dbg) {
            // Draws nothing from `src`, so debug info never changes the code.
            if t.is_scalar() && id % 3 == 0 {
                let name = format!("v{id}");
                let local = g.dbg_local(scope, &name, &t);
                let expr = g.dbg.as_ref().unwrap().expr;
                self.dbg(g, D_VALUE, &[local, id, expr]);
            }
        }
        let _ = src;
        self.scopes.last_mut().unwrap().push((id, t));
    }

    fn dbg(&mut self, g: &mut Gen, which: u32, args: &[Word]) {
        let set = g.dbg.as_ref().unwrap().set;
        let id = g.b.id();
        let mut ops = vec![Operand::IdRef(set), Operand::LiteralExtInstInteger(which)];
        ops.extend(args.iter().map(|a| Operand::IdRef(*a)));
        self.cur
            .push(Instruction::new(Op::ExtInst, Some(g.void), Some(id), ops));
    }

    /// `DebugScope` and `DebugLine` before a statement.
    fn dbg_line(&mut self, g: &mut Gen) {
        let Some(scope) = self.dbg_fn else { return };
        let source = g.dbg.as_ref().unwrap().source;
        let line = g.next_line();
        let line = g.uconst(line);
        let col = g.uconst(5);
        self.dbg(g, D_SCOPE, &[scope]);
        self.dbg(g, D_LINE, &[source, line, line, col, col]);
    }

    fn new_local(&mut self, g: &mut Gen, t: Ty) -> Word {
        let p = g.ptr(StorageClass::Function, &t);
        let id = g.b.id();
        self.vars.push(Instruction::new(
            Op::Variable,
            Some(p),
            Some(id),
            vec![Operand::StorageClass(StorageClass::Function)],
        ));
        let name = g.fresh_name("local");
        g.b.name(id, name.clone());
        if let Some(scope) = self.dbg_fn {
            let local = g.dbg_local(scope, &name, &t);
            let set = g.dbg.as_ref().unwrap().set;
            let expr = g.dbg.as_ref().unwrap().expr;
            let d = g.b.id();
            self.dbg_pending.push(Instruction::new(
                Op::ExtInst,
                Some(g.void),
                Some(d),
                vec![
                    Operand::IdRef(set),
                    Operand::LiteralExtInstInteger(D_DECLARE),
                    Operand::IdRef(local),
                    Operand::IdRef(id),
                    Operand::IdRef(expr),
                ],
            ));
        }
        self.locals.push((id, t, true));
        id
    }

    /// A value of type `t` in scope, or a constant for a scalar.
    fn value(&mut self, g: &mut Gen, src: &mut Source, t: &Ty) -> Option<Word> {
        let pool: Vec<Word> = self
            .scopes
            .iter()
            .flatten()
            .filter(|(_, x)| x == t)
            .map(|(id, _)| *id)
            .collect();
        if !pool.is_empty() && !src.chance(15) {
            return src.pick(&pool);
        }
        match t {
            Ty::F32 => Some(g.fconst(1.0 + src.below(8) as f32)),
            Ty::U32 => Some(g.uconst(src.below(8))),
            _ => None,
        }
    }

    fn scalar(src: &mut Source) -> Ty {
        if src.chance(50) {
            Ty::F32
        } else {
            Ty::U32
        }
    }

    /// A pointer to a random scalar part of `(var, ty)` in storage `sc`.
    fn leaf_ptr(
        &mut self,
        g: &mut Gen,
        src: &mut Source,
        sc: StorageClass,
        var: Word,
        ty: &Ty,
    ) -> (Word, Ty) {
        let leaves = ty.leaves();
        let (path, st) = src.pick(&leaves).unwrap();
        if path.is_empty() {
            return (var, st);
        }
        let p = g.ptr(sc, &st);
        let mut ops = vec![Operand::IdRef(var)];
        let mut at = ty.clone();
        for i in path {
            // Now and then an element of an array or vector chosen at run
            // time: the pointer no longer names one part.
            let (next, dynamic_ok) = match &at {
                Ty::Arr(e, _) => ((**e).clone(), true),
                Ty::Vec(_) => (Ty::F32, true),
                Ty::Struct(m) => (m[i as usize].clone(), false),
                _ => (at.clone(), false),
            };
            let index = if dynamic_ok && src.chance(15) {
                self.value(g, src, &Ty::U32).unwrap()
            } else {
                g.uconst(i)
            };
            ops.push(Operand::IdRef(index));
            at = next;
        }
        (self.push(g, Op::AccessChain, p, ops), st)
    }

    fn statements(&mut self, g: &mut Gen, src: &mut Source) {
        let n = 1 + src.below(6);
        for _ in 0..n {
            if self.budget == 0 {
                return;
            }
            self.budget -= 1;
            self.statement(g, src);
        }
    }

    fn statement(&mut self, g: &mut Gen, src: &mut Source) {
        self.dbg_line(g);
        match src.below(16) {
            0 | 1 => self.arith(g, src),
            2 | 3 => {
                // Load a part of a local.
                if let Some((var, ty, _)) = src.pick(&self.locals) {
                    let (p, st) = self.leaf_ptr(g, src, StorageClass::Function, var, &ty);
                    let t = g.ty(&st);
                    let v = self.push(g, Op::Load, t, vec![Operand::IdRef(p)]);
                    self.add_value(g, src, v, st);
                }
            }
            4 | 5 => {
                // Store into a part of a local.
                if let Some((var, ty, _)) = src.pick(&self.locals) {
                    let (p, st) = self.leaf_ptr(g, src, StorageClass::Function, var, &ty);
                    let v = self.value(g, src, &st).unwrap();
                    self.stmt(Op::Store, vec![Operand::IdRef(p), Operand::IdRef(v)]);
                }
            }
            6 => {
                // A whole local: loaded (and a part extracted), or cleared.
                if let Some((var, ty, _)) = src.pick(&self.locals) {
                    let t = g.ty(&ty);
                    if src.chance(50) {
                        let whole = self.push(g, Op::Load, t, vec![Operand::IdRef(var)]);
                        self.add_value(g, src, whole, ty.clone());
                        if !ty.is_scalar() {
                            let leaves = ty.leaves();
                            let (path, st) = src.pick(&leaves).unwrap();
                            let stid = g.ty(&st);
                            let mut ops = vec![Operand::IdRef(whole)];
                            ops.extend(path.into_iter().map(Operand::LiteralBit32));
                            let v = self.push(g, Op::CompositeExtract, stid, ops);
                            self.add_value(g, src, v, st);
                        }
                    } else {
                        let z = g.null(t);
                        self.stmt(Op::Store, vec![Operand::IdRef(var), Operand::IdRef(z)]);
                    }
                }
            }
            7 if self.depth < 3 => self.if_else(g, src),
            8 if self.depth < 3 => self.counted_loop(g, src),
            9 | 10 | 14 if self.can_trace() => self.trace(g, src),
            11 if self.can_call() => self.execute_callable(g, src),
            12 => self.call(g, src),
            13 => self.stage_specific(g, src),
            15 if g.queries && self.depth < 3 => self.ray_query(g, src),
            _ => self.arith(g, src),
        }
    }

    /// Ends the current block by leaving the function: a return, or with
    /// `early` in an any-hit shader sometimes `OpTerminateRayKHR` or
    /// `OpIgnoreIntersectionKHR`.
    fn exit(&mut self, g: &mut Gen, src: &mut Source, early: bool) {
        let inst = if early && self.stage() == Some(Stage::AnyHit) && src.chance(60) {
            let op = if src.chance(50) {
                Op::TerminateRayKHR
            } else {
                Op::IgnoreIntersectionKHR
            };
            Instruction::new(op, None, None, vec![])
        } else if self.returns_float {
            let v = self.value(g, src, &Ty::F32).unwrap();
            Instruction::new(Op::ReturnValue, None, None, vec![Operand::IdRef(v)])
        } else {
            Instruction::new(Op::Return, None, None, vec![])
        };
        self.cur.push(inst);
        self.end_block();
    }

    fn arith(&mut self, g: &mut Gen, src: &mut Source) {
        let st = Self::scalar(src);
        let a = self.value(g, src, &st).unwrap();
        let b = self.value(g, src, &st).unwrap();
        let (op, ty) = if st == Ty::F32 {
            ([Op::FAdd, Op::FMul, Op::FSub][src.below(3) as usize], g.f32)
        } else {
            (
                [Op::IAdd, Op::IMul, Op::BitwiseXor][src.below(3) as usize],
                g.u32,
            )
        };
        let v = self.push(g, op, ty, vec![Operand::IdRef(a), Operand::IdRef(b)]);
        self.add_value(g, src, v, st);
    }

    fn condition(&mut self, g: &mut Gen, src: &mut Source) -> Word {
        let st = Self::scalar(src);
        let a = self.value(g, src, &st).unwrap();
        let b = self.value(g, src, &st).unwrap();
        let op = if st == Ty::F32 {
            Op::FOrdLessThan
        } else {
            Op::ULessThan
        };
        self.push(g, op, g.bool_ty, vec![Operand::IdRef(a), Operand::IdRef(b)])
    }

    fn if_else(&mut self, g: &mut Gen, src: &mut Source) {
        let cond = self.condition(g, src);
        let (then_l, else_l, merge) = (g.b.id(), g.b.id(), g.b.id());
        let has_else = src.chance(60);
        let before = self.label;
        self.stmt(
            Op::SelectionMerge,
            vec![
                Operand::IdRef(merge),
                Operand::SelectionControl(SelectionControl::NONE),
            ],
        );
        self.stmt(
            Op::BranchConditional,
            vec![
                Operand::IdRef(cond),
                Operand::IdRef(then_l),
                Operand::IdRef(if has_else { else_l } else { merge }),
            ],
        );
        self.end_block();
        let phi_ty = Self::scalar(src);
        // The then-branch may leave the function instead of reaching the merge.
        let then_exits = src.chance(12);
        let mut incoming = Vec::new();
        for (label, present) in [(then_l, true), (else_l, has_else)] {
            if !present {
                let v = self.value(g, src, &phi_ty).unwrap();
                incoming.push((v, before));
                continue;
            }
            self.start_block(label);
            self.depth += 1;
            self.scopes.push(Vec::new());
            self.statements(g, src);
            if label == then_l && then_exits {
                self.exit(g, src, true);
                self.scopes.pop();
                self.depth -= 1;
                continue;
            }
            let v = self.value(g, src, &phi_ty).unwrap();
            incoming.push((v, self.label));
            self.scopes.pop();
            self.depth -= 1;
            self.stmt(Op::Branch, vec![Operand::IdRef(merge)]);
            self.end_block();
        }
        self.start_block(merge);
        if src.chance(60) {
            let t = g.ty(&phi_ty);
            let mut ops = Vec::new();
            for (v, l) in incoming {
                ops.push(Operand::IdRef(v));
                ops.push(Operand::IdRef(l));
            }
            let id = g.b.id();
            self.cur
                .push(Instruction::new(Op::Phi, Some(t), Some(id), ops));
            self.scopes.last_mut().unwrap().push((id, phi_ty));
        }
    }

    /// An inline ray query: initialised, a `OpRayQueryProceedKHR` loop
    /// whose body holds more statements (reading the candidate, sometimes
    /// confirming it), then the committed intersection's type read.
    fn ray_query(&mut self, g: &mut Gen, src: &mut Source) {
        let ptr = g.b.type_pointer(None, StorageClass::Function, g.query_ty);
        let rq = g.b.id();
        self.vars.push(Instruction::new(
            Op::Variable,
            Some(ptr),
            Some(rq),
            vec![Operand::StorageClass(StorageClass::Function)],
        ));
        let name = g.fresh_name("query");
        g.b.name(rq, name);
        self.use_global(g.accel);
        let accel = self.push(g, Op::Load, g.accel_ty, vec![Operand::IdRef(g.accel)]);
        let flags = g.uconst(if src.chance(30) { 1 } else { 0 });
        let mask = g.uconst(0xff);
        let origin = self.vec3(g, src);
        let tmin = g.fconst(0.001);
        let dir = self.vec3(g, src);
        let tmax = self.value(g, src, &Ty::F32).unwrap();
        self.stmt(
            Op::RayQueryInitializeKHR,
            [rq, accel, flags, mask, origin, tmin, dir, tmax]
                .into_iter()
                .map(Operand::IdRef)
                .collect(),
        );
        let (header, body, cont, merge) = (g.b.id(), g.b.id(), g.b.id(), g.b.id());
        self.stmt(Op::Branch, vec![Operand::IdRef(header)]);
        self.end_block();
        self.start_block(header);
        let more = self.push(
            g,
            Op::RayQueryProceedKHR,
            g.bool_ty,
            vec![Operand::IdRef(rq)],
        );
        self.stmt(
            Op::LoopMerge,
            vec![
                Operand::IdRef(merge),
                Operand::IdRef(cont),
                Operand::LoopControl(LoopControl::NONE),
            ],
        );
        self.stmt(
            Op::BranchConditional,
            vec![
                Operand::IdRef(more),
                Operand::IdRef(body),
                Operand::IdRef(merge),
            ],
        );
        self.end_block();
        self.start_block(body);
        self.depth += 1;
        self.scopes.push(Vec::new());
        if src.chance(60) {
            let candidate = g.uconst(0);
            let t = self.push(
                g,
                Op::RayQueryGetIntersectionTypeKHR,
                g.u32,
                vec![Operand::IdRef(rq), Operand::IdRef(candidate)],
            );
            self.add_value(g, src, t, Ty::U32);
        }
        self.statements(g, src);
        if src.chance(40) {
            self.stmt(Op::RayQueryConfirmIntersectionKHR, vec![Operand::IdRef(rq)]);
        }
        self.stmt(Op::Branch, vec![Operand::IdRef(cont)]);
        self.end_block();
        self.scopes.pop();
        self.depth -= 1;
        self.start_block(cont);
        self.stmt(Op::Branch, vec![Operand::IdRef(header)]);
        self.end_block();
        self.start_block(merge);
        let committed = g.uconst(1);
        let t = self.push(
            g,
            Op::RayQueryGetIntersectionTypeKHR,
            g.u32,
            vec![Operand::IdRef(rq), Operand::IdRef(committed)],
        );
        self.add_value(g, src, t, Ty::U32);
    }

    fn counted_loop(&mut self, g: &mut Gen, src: &mut Source) {
        let (header, body, cont, merge) = (g.b.id(), g.b.id(), g.b.id(), g.b.id());
        let pre = self.label;
        let init = self.value(g, src, &Ty::F32).unwrap();
        self.stmt(Op::Branch, vec![Operand::IdRef(header)]);
        self.end_block();
        self.start_block(header);
        let (i, i_next, acc, acc_next) = (g.b.id(), g.b.id(), g.b.id(), g.b.id());
        let zero = g.uconst(0);
        let one = g.uconst(1);
        let count = g.uconst(1 + src.below(4));
        self.cur.push(Instruction::new(
            Op::Phi,
            Some(g.u32),
            Some(i),
            vec![
                Operand::IdRef(zero),
                Operand::IdRef(pre),
                Operand::IdRef(i_next),
                Operand::IdRef(cont),
            ],
        ));
        self.cur.push(Instruction::new(
            Op::Phi,
            Some(g.f32),
            Some(acc),
            vec![
                Operand::IdRef(init),
                Operand::IdRef(pre),
                Operand::IdRef(acc_next),
                Operand::IdRef(cont),
            ],
        ));
        self.stmt(
            Op::LoopMerge,
            vec![
                Operand::IdRef(merge),
                Operand::IdRef(cont),
                Operand::LoopControl(LoopControl::NONE),
            ],
        );
        self.stmt(Op::Branch, vec![Operand::IdRef(body)]);
        self.end_block();
        // The header dominates the body, the continue block and the merge.
        self.scopes
            .last_mut()
            .unwrap()
            .extend([(i, Ty::U32), (acc, Ty::F32)]);
        self.start_block(body);
        self.depth += 1;
        self.scopes.push(Vec::new());
        self.statements(g, src);
        let step = self.value(g, src, &Ty::F32).unwrap();
        self.stmt(Op::Branch, vec![Operand::IdRef(cont)]);
        self.end_block();
        self.scopes.pop();
        self.depth -= 1;
        self.start_block(cont);
        self.cur.push(Instruction::new(
            Op::IAdd,
            Some(g.u32),
            Some(i_next),
            vec![Operand::IdRef(i), Operand::IdRef(one)],
        ));
        self.cur.push(Instruction::new(
            Op::FAdd,
            Some(g.f32),
            Some(acc_next),
            vec![Operand::IdRef(acc), Operand::IdRef(step)],
        ));
        let more = self.push(
            g,
            Op::ULessThan,
            g.bool_ty,
            vec![Operand::IdRef(i_next), Operand::IdRef(count)],
        );
        self.stmt(
            Op::BranchConditional,
            vec![
                Operand::IdRef(more),
                Operand::IdRef(header),
                Operand::IdRef(merge),
            ],
        );
        self.end_block();
        self.start_block(merge);
    }

    fn vec3(&mut self, g: &mut Gen, src: &mut Source) -> Word {
        let parts: Vec<Operand> = (0..3)
            .map(|_| Operand::IdRef(self.value(g, src, &Ty::F32).unwrap()))
            .collect();
        self.push(g, Op::CompositeConstruct, g.vec3, parts)
    }

    fn trace(&mut self, g: &mut Gen, src: &mut Source) {
        let (payload, pty) = src.pick(&g.payloads).unwrap();
        self.use_global(payload);
        self.use_global(g.accel);
        if src.chance(50) {
            let (p, st) = self.leaf_ptr(g, src, StorageClass::RayPayloadKHR, payload, &pty);
            let v = self.value(g, src, &st).unwrap();
            self.stmt(Op::Store, vec![Operand::IdRef(p), Operand::IdRef(v)]);
        }
        let accel = self.push(g, Op::Load, g.accel_ty, vec![Operand::IdRef(g.accel)]);
        // Flags: none, or opaque (which only keeps any-hit shaders out).
        let opaque = src.chance(30);
        let flags = g.uconst(u32::from(opaque));
        let mask = g.uconst(0xff);
        let sbt_offset = if src.chance(85) {
            Some(src.below(g.n_groups + 1))
        } else {
            None
        };
        let miss_index = if src.chance(85) {
            Some(src.below(g.n_miss + 1))
        } else {
            None
        };
        fn dynamic(c: Option<u32>, fg: &mut FnGen, g: &mut Gen, src: &mut Source) -> Word {
            match c {
                Some(c) => g.uconst(c),
                None => fg.value(g, src, &Ty::U32).unwrap(),
            }
        }
        let off = dynamic(sbt_offset, self, g, src);
        // A dynamic operand may have been a constant after all.
        let sbt_offset = g.const_value(off).or(sbt_offset);
        let stride = g.uconst(src.below(2));
        let miss = dynamic(miss_index, self, g, src);
        let miss_index = g.const_value(miss).or(miss_index);
        let origin = self.vec3(g, src);
        let dir = self.vec3(g, src);
        let tmin = g.fconst(0.001);
        let tmax = self.value(g, src, &Ty::F32).unwrap();
        self.stmt(
            Op::TraceRayKHR,
            [
                accel, flags, mask, off, stride, miss, origin, tmin, dir, tmax, payload,
            ]
            .into_iter()
            .map(Operand::IdRef)
            .collect(),
        );
        self.traces.push(GenTrace {
            sbt_offset,
            miss_index,
            opaque,
        });
        if src.chance(60) {
            let (p, st) = self.leaf_ptr(g, src, StorageClass::RayPayloadKHR, payload, &pty);
            let t = g.ty(&st);
            let v = self.push(g, Op::Load, t, vec![Operand::IdRef(p)]);
            self.add_value(g, src, v, st);
        }
    }

    fn execute_callable(&mut self, g: &mut Gen, src: &mut Source) {
        let (data, dty) = src.pick(&g.callable_data).unwrap();
        self.use_global(data);
        let (p, st) = self.leaf_ptr(g, src, StorageClass::CallableDataKHR, data, &dty);
        let v = self.value(g, src, &st).unwrap();
        self.stmt(Op::Store, vec![Operand::IdRef(p), Operand::IdRef(v)]);
        let index = if src.chance(80) {
            g.uconst(src.below(g.n_callable + 1))
        } else {
            self.value(g, src, &Ty::U32).unwrap()
        };
        self.stmt(
            Op::ExecuteCallableKHR,
            vec![Operand::IdRef(index), Operand::IdRef(data)],
        );
        if src.chance(60) {
            let (p, st) = self.leaf_ptr(g, src, StorageClass::CallableDataKHR, data, &dty);
            let t = g.ty(&st);
            let v = self.push(g, Op::Load, t, vec![Operand::IdRef(p)]);
            self.add_value(g, src, v, st);
        }
    }

    fn call(&mut self, g: &mut Gen, src: &mut Source) {
        let first = self.helper.map_or(0, |k| k + 1);
        let can_trace = self.can_trace();
        let candidates: Vec<usize> = (first..g.helpers.len())
            .filter(|&k| g.helpers[k].kind == Kind::Pure || can_trace)
            .collect();
        let Some(k) = src.pick(&candidates) else {
            return self.arith(g, src);
        };
        let (id, floats, ptr_ty, returns_float) = {
            let h = &g.helpers[k];
            (h.id, h.floats, h.ptr_ty.clone(), h.returns_float)
        };
        let mut ops = vec![Operand::IdRef(id)];
        for _ in 0..floats {
            ops.push(Operand::IdRef(self.value(g, src, &Ty::F32).unwrap()));
        }
        if let Some(t) = ptr_ty {
            // Only a variable itself may be passed (logical addressing).
            let vars: Vec<Word> = self
                .locals
                .iter()
                .filter(|(_, x, is_var)| *is_var && *x == t)
                .map(|(v, _, _)| *v)
                .collect();
            let v = match src.pick(&vars) {
                Some(v) => v,
                None => self.new_local(g, t),
            };
            ops.push(Operand::IdRef(v));
        }
        let ret = if returns_float { g.f32 } else { g.void };
        let v = self.push(g, Op::FunctionCall, ret, ops);
        if returns_float {
            self.add_value(g, src, v, Ty::F32);
        }
        if !self.calls.contains(&id) {
            self.calls.push(id);
        }
    }

    fn stage_specific(&mut self, g: &mut Gen, src: &mut Source) {
        match self.stage() {
            Some(Stage::ClosestHit | Stage::Miss | Stage::AnyHit | Stage::Callable) => {
                let (var, ty) = self.incoming.clone().unwrap();
                self.use_global(var);
                let sc = if self.stage() == Some(Stage::Callable) {
                    StorageClass::IncomingCallableDataKHR
                } else {
                    StorageClass::IncomingRayPayloadKHR
                };
                let (p, st) = self.leaf_ptr(g, src, sc, var, &ty);
                if src.chance(50) {
                    let t = g.ty(&st);
                    let v = self.push(g, Op::Load, t, vec![Operand::IdRef(p)]);
                    self.add_value(g, src, v, st);
                } else {
                    let v = self.value(g, src, &st).unwrap();
                    self.stmt(Op::Store, vec![Operand::IdRef(p), Operand::IdRef(v)]);
                }
                if matches!(self.stage(), Some(Stage::ClosestHit | Stage::AnyHit)) && src.chance(50)
                {
                    self.use_global(g.hit_attr);
                    let t = g.ty(&Ty::Vec(2));
                    let v = self.push(g, Op::Load, t, vec![Operand::IdRef(g.hit_attr)]);
                    self.add_value(g, src, v, Ty::Vec(2));
                }
            }
            Some(Stage::Intersection) => {
                self.use_global(g.hit_attr);
                let t = g.ty(&Ty::Vec(2));
                let z = g.null(t);
                self.stmt(
                    Op::Store,
                    vec![Operand::IdRef(g.hit_attr), Operand::IdRef(z)],
                );
                let hit_t = self.value(g, src, &Ty::F32).unwrap();
                let kind = g.uconst(src.below(4));
                let v = self.push(
                    g,
                    Op::ReportIntersectionKHR,
                    g.bool_ty,
                    vec![Operand::IdRef(hit_t), Operand::IdRef(kind)],
                );
                let _ = v;
            }
            _ => self.arith(g, src),
        }
    }
}

impl Gen {
    /// The value of a `u32` constant this generator made.
    fn const_value(&self, id: Word) -> Option<u32> {
        self.consts
            .iter()
            .find(|((t, _), c)| *t == self.u32 && **c == id)
            .map(|((_, v), _)| *v)
    }
}
