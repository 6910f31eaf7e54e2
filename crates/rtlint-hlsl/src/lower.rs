//! Type checking and SPIR-V emission in one walk over the AST.
//!
//! Follows DXC's HLSL→SPIR-V mapping for Vulkan: ray-tracing payloads become
//! `RayPayloadKHR`/`IncomingRayPayloadKHR` variables, hit attributes a
//! `HitAttributeKHR` variable, system values `BuiltIn` inputs, resources
//! descriptor-set variables with `Binding`/`DescriptorSet`.

mod calls;
mod consts;
mod debug;
mod decl;
mod expr;
mod formats;
mod func;
mod heaps;
mod inline_spirv;
mod intrinsics;
mod methods;
mod pixel;
mod place;
mod raw_buffer;
mod resource_calls;
mod ser;
mod stmt;
mod storage16;
mod system_values;
mod templates;
mod wave;

use super::ast::*;
use super::attrs;
use super::error::{Error, Pos, Result};
use super::parse::split_numeric;
use super::subobject;
use super::types::*;
pub use crate::vocab::Stage;
use crate::vocab::{Location, NamedDecl};
use rspirv::dr::{self, Builder, InsertPoint, Instruction, Operand};
use spirv::{BuiltIn, Capability, Decoration, Op, StorageClass, Word as Id};
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::PathBuf;
use system_values::system_value;

#[derive(Clone, Debug)]
pub struct Val {
    pub id: Id,
    pub ty: Ty,
}

/// Something that can be read and maybe written.
#[derive(Clone, Debug)]
enum Place {
    /// Memory: a pointer, the type it holds, its layout and storage class.
    Ptr {
        ptr: Id,
        ty: Ty,
        layout: Layout,
        class: StorageClass,
    },
    /// Components of a vector place (`v.xz`).
    Swizzle {
        base: Box<Place>,
        comps: Vec<u32>,
        ty: Ty,
    },
    /// A texel of a storage image: `img[coord]`.
    Texel {
        image: Id,
        img: Ty,
        coord: Id,
        ty: Ty,
    },
    /// A value with no storage (a call's result, a constant).
    Value(Val),
}

impl Place {
    fn ty(&self) -> &Ty {
        match self {
            Place::Ptr { ty, .. } | Place::Swizzle { ty, .. } | Place::Texel { ty, .. } => ty,
            Place::Value(v) => &v.ty,
        }
    }
}

#[derive(Clone, Debug)]
enum Global {
    Place(Place),
    Const(Val),
}

#[derive(Clone, Debug)]
struct Param {
    ty: Ty,
    out: bool,
    input: bool,
}

#[derive(Clone, Debug)]
struct FnSig<'a> {
    name: String,
    params: Vec<Param>,
    ret: Ty,
    id: Id,
    func: &'a Function,
    /// Parameters bound to a resource variable (a specialized copy, see
    /// `specialize`): (parameter index, the variable's place).
    bound: Vec<(usize, Place)>,
    /// A function returning a ray query: the type and the local it returns,
    /// which is the caller's variable passed as a last, hidden parameter.
    ret_slot: Option<(Ty, String)>,
    /// Default values of the trailing parameters that have one.
    defaults: Vec<&'a Expr>,
    /// For methods: the struct whose `this` is the first parameter.
    this: Option<u32>,
    stage: Option<Stage>,
    numthreads: [u32; 3],
}

struct Flow {
    brk: Id,
    cont: Option<Id>,
}

pub struct EntryInfo {
    pub name: String,
    pub stage: Stage,
}

/// Per-function state: reset when a function's lowering starts.
struct FnCtx {
    /// Index of the function in `Lowerer::funcs`.
    cur_fn: usize,
    /// Enclosing namespace (`a::b::`), where unqualified names look first.
    cur_ns: String,
    cur_stage: Option<Stage>,
    /// The block instructions are appended to.
    cur_label: Id,
    ret_ty: Ty,
    /// Local names, innermost scope last.
    scopes: Vec<HashMap<String, Place>>,
    /// Enclosing loops and switches (break and continue targets).
    flow: Vec<Flow>,
    /// The current block is terminated (after return/break/...).
    term: bool,
    /// `this` of the method being lowered; its members resolve by bare name.
    this_place: Option<Place>,
    /// Resource-returning helpers being inlined (see `resource_call`).
    inline_depth: u32,
    /// In a function returning a ray query: the returned local's name and
    /// the hidden parameter that holds it.
    ret_slot: Option<(String, Place)>,
    /// The variable a call returning a ray query writes (set by the declaration
    /// it initializes).
    ret_dest: Option<(Id, Ty)>,
}

impl FnCtx {
    fn new(cur_fn: usize, ns: &str, stage: Option<Stage>, ret_ty: Ty) -> Self {
        FnCtx {
            cur_fn,
            cur_ns: ns.to_string(),
            cur_stage: stage,
            cur_label: 0,
            ret_ty,
            scopes: vec![HashMap::new()],
            flow: Vec::new(),
            term: false,
            this_place: None,
            inline_depth: 0,
            ret_slot: None,
            ret_dest: None,
        }
    }
}

/// Module-wide state and the function being lowered (`f`).
pub struct Lowerer<'a> {
    b: Builder,
    items: &'a [Item],
    files: &'a [PathBuf],
    file_ids: Vec<Id>,
    structs: Vec<StructDef>,
    struct_names: HashMap<String, u32>,
    typedefs: HashMap<String, Ty>,
    globals: HashMap<String, Global>,
    funcs: Vec<FnSig<'a>>,
    fn_by_name: HashMap<String, Vec<usize>>,
    /// `[[vk::ext_instruction]]` declarations by name: a call is the instruction.
    ext_insts: HashMap<String, &'a Function>,
    /// Instruction sets imported for `vk::ext_instruction`, by name.
    ext_sets: HashMap<String, Id>,
    ty_cache: HashMap<(Ty, Layout, bool), Id>,
    /// `OpUndef` of each type id, at module scope.
    undefs: HashMap<Id, Id>,
    consts: HashMap<(Id, u32), Id>,
    glsl: Id,
    caps: HashSet<Capability>,
    exts: HashSet<String>,
    builtins: HashMap<BuiltIn, Id>,
    /// Every built-in variable (read by a system value or declared with
    /// inline SPIR-V), for the decorations its readers' stages need.
    builtin_vars: HashMap<Id, system_values::BuiltinVar>,
    rt_vars: HashMap<(StorageClass, Ty), Id>,
    next_location: HashMap<StorageClass, u32>,
    fn_used: HashMap<usize, BTreeSet<Id>>,
    fn_calls: HashMap<usize, BTreeSet<usize>>,
    pending: Vec<usize>,
    lowered: HashSet<usize>,
    pub decls: Vec<(NamedDecl, Location)>,
    /// The function being lowered.
    f: FnCtx,
    /// An entry point named on the command line with its stage, for
    /// functions without `[shader(...)]`.
    pub forced_entry: Option<(String, Stage)>,
    /// `-enable-16bit-types`: `half` and `min16*` are 16-bit (refused).
    pub sixteen_bit_types: bool,
    /// How registers become descriptor sets and bindings (DXC's options).
    pub bindings: crate::Bindings,
    /// DXR subobjects the file declares.
    pub subobjects: super::subobject::Subobjects,
    /// Function templates by qualified name (never lowered themselves).
    fn_templates: HashMap<String, Vec<&'a Function>>,
    /// Struct templates by qualified name.
    struct_templates: HashMap<String, &'a StructDecl>,
    /// Method templates by `Struct::method`.
    method_templates: HashMap<String, Vec<&'a Function>>,
    /// Instances of struct templates (`S<float>`), declared where first used.
    instance_structs: HashMap<String, &'a StructDecl>,
    /// Descriptor-heap arrays by element type, and the heaps' (set, binding).
    heap_vars: HashMap<Ty, Id>,
    heap_bindings: ((u32, u32), (u32, u32)),
    /// Stage-restricted operations used in helpers: (name, stages, position).
    fn_stage_uses: HashMap<usize, Vec<(String, Vec<Stage>, Pos)>>,
    /// Helpers whose signatures use something unsupported: the error, given
    /// when one is called.
    unusable: HashMap<String, Error>,
    /// Template instances this round of lowering found missing.
    pub needed: Vec<super::template::Instance>,
    /// Functions specialized on their buffer arguments: (function, bound) → copy.
    specialized: HashMap<(usize, Vec<(usize, Id)>), usize>,
    /// Globals whose attributes add extensions or capabilities when used.
    global_reqs: HashMap<Id, Requirements>,
    /// Namespaces named by `using namespace`, searched after the enclosing ones.
    usings: Vec<String>,
    /// `NonUniformResourceIndex` results, decorated when they index resources.
    nonuniform: HashSet<Id>,
    /// cbuffer member name → (variable, type, index, layout, storage class).
    cbuffer_members: HashMap<String, (Id, Ty, u32, Layout, StorageClass)>,
    /// Scalar constants known at compile time (enums, `static const`), for array sizes.
    const_items: HashMap<String, ConstValue>,
    /// Scalar constant id → its bits.
    const_ids: HashMap<Id, u32>,
    /// Static globals whose initializers run at the start of each entry point.
    /// (variable, type, initializer, its namespace).
    deferred_inits: Vec<(Id, Ty, &'a Expr, String)>,
    /// Pointers into resource arrays indexed with `NonUniformResourceIndex`.
    nonuniform_ptrs: HashSet<Id>,
    /// Globals with source positions, for debug info: (variable, name, type, position).
    global_decls: Vec<(Id, String, Ty, Pos)>,
    /// Locals and parameters for debug info: (function, variable, name, type, position).
    local_decls: Vec<(usize, Id, String, Ty, Pos)>,
    /// Descriptor variables and resource parameters: the memory object
    /// declarations a resource parameter may be given.
    resource_vars: HashSet<Id>,
    /// Per user struct, each member's semantic and attributes (pixel-shader I/O).
    struct_io: HashMap<u32, Vec<MemberIo>>,
    /// Per user struct, `[[vk::ext_decorate]]` member decorations:
    /// (member, decoration, literal operands).
    member_decorations: HashMap<u32, Vec<(u32, Decoration, Vec<u32>)>>,
    /// Whether a device address is loaded from (`vk::RawBufferLoad`): the
    /// module's addressing model is then `PhysicalStorageBuffer64`.
    physical_addressing: bool,
    /// Functions outside an entry body that use derivatives: (name, position),
    /// checked against the entry points that reach them.
    fn_derivs: HashMap<usize, (&'static str, Pos)>,
}

/// Extensions and capabilities a declaration's `vk::ext_*` attributes name.
#[derive(Clone, Debug, Default)]
struct Requirements(Vec<String>, Vec<Capability>);

/// A struct member's semantic, attributes and modifiers (interpolation).
type MemberIo = (Option<(String, Pos)>, Vec<Attr>, Mods);

/// Source positions of named declarations (the side table `Program` reads).
pub type Decls = Vec<(NamedDecl, Location)>;

const RAY_DESC: u32 = 0;
const TRI_ATTRS: u32 = 1;

fn unsupported(pos: Pos, what: impl std::fmt::Display) -> Error {
    Error::unsupported(pos, what)
}

/// A resource reached through something other than a variable (which
/// SPIR-V's logical addressing needs).
/// Storage a shader may not write: constant buffers, push constants, shader
/// records and stage inputs.
fn read_only(class: StorageClass) -> bool {
    matches!(
        class,
        StorageClass::Uniform
            | StorageClass::PushConstant
            | StorageClass::ShaderRecordBufferKHR
            | StorageClass::Input
    )
}

fn not_a_variable(pos: Pos) -> Error {
    unsupported(
        pos,
        "a resource that is not a variable, an element of a resource array or the result of a `return <resource>;` helper",
    )
}

impl From<dr::Error> for Error {
    fn from(e: dr::Error) -> Self {
        Error::internal(e)
    }
}

fn attr_str(a: &Attr) -> Option<&str> {
    match &a.args.first()?.kind {
        ExprKind::Str(s) => Some(s),
        _ => None,
    }
}

/// Constants the HLSL headers define for ray tracing.
fn builtin_constant(name: &str) -> Option<u32> {
    Some(match name {
        "RAY_FLAG_NONE" => 0,
        "RAY_FLAG_FORCE_OPAQUE" => 0x1,
        "RAY_FLAG_FORCE_NON_OPAQUE" => 0x2,
        "RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH" => 0x4,
        "RAY_FLAG_SKIP_CLOSEST_HIT_SHADER" => 0x8,
        "RAY_FLAG_CULL_BACK_FACING_TRIANGLES" => 0x10,
        "RAY_FLAG_CULL_FRONT_FACING_TRIANGLES" => 0x20,
        "RAY_FLAG_CULL_OPAQUE" => 0x40,
        "RAY_FLAG_CULL_NON_OPAQUE" => 0x80,
        "RAY_FLAG_SKIP_TRIANGLES" => 0x100,
        "RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES" => 0x200,
        "HIT_KIND_TRIANGLE_FRONT_FACE" => 0xFE,
        "HIT_KIND_TRIANGLE_BACK_FACE" => 0xFF,
        "COMMITTED_NOTHING" => 0,
        "COMMITTED_TRIANGLE_HIT" => 1,
        "COMMITTED_PROCEDURAL_PRIMITIVE_HIT" => 2,
        "CANDIDATE_NON_OPAQUE_TRIANGLE" => 0,
        "CANDIDATE_PROCEDURAL_PRIMITIVE" => 1,
        _ => return None,
    })
}

/// The OpenCL-only capability (`Kernel`, `Addresses`, `Linkage`) that `c` is
/// or implicitly declares, by the SPIR-V grammar rspirv carries: a module
/// declaring it fails Vulkan validation, so it is refused where written.
fn kernel_only(c: Capability) -> Option<Capability> {
    let mut todo = vec![c];
    let mut seen = Vec::new();
    while let Some(c) = todo.pop() {
        if matches!(
            c,
            Capability::Kernel | Capability::Addresses | Capability::Linkage
        ) {
            return Some(c);
        }
        if !seen.contains(&c) {
            seen.push(c);
            todo.extend(Operand::Capability(c).required_capabilities());
        }
    }
    None
}

fn swizzle_comps(s: &str) -> Option<Vec<u32>> {
    if s.is_empty() || s.len() > 4 {
        return None;
    }
    let xyzw = s.chars().all(|c| "xyzw".contains(c));
    let rgba = s.chars().all(|c| "rgba".contains(c));
    if !xyzw && !rgba {
        return None;
    }
    Some(
        s.chars()
            .map(|c| match c {
                'x' | 'r' => 0,
                'y' | 'g' => 1,
                'z' | 'b' => 2,
                _ => 3,
            })
            .collect(),
    )
}

/// `_m01`/`_12` matrix element names: (row, column), 0-based.
fn matrix_comps(s: &str) -> Option<Vec<(u32, u32)>> {
    let mut out = Vec::new();
    let mut rest = s;
    while !rest.is_empty() {
        rest = rest.strip_prefix('_')?;
        let (zero, r) = match rest.strip_prefix('m') {
            Some(r) => (true, r),
            None => (false, rest),
        };
        let b = r.as_bytes();
        if b.len() < 2 || !b[0].is_ascii_digit() || !b[1].is_ascii_digit() {
            return None;
        }
        let (mut i, mut j) = ((b[0] - b'0') as u32, (b[1] - b'0') as u32);
        if !zero {
            if i == 0 || j == 0 {
                return None;
            }
            i -= 1;
            j -= 1;
        }
        out.push((i, j));
        rest = &r[2..];
    }
    Some(out)
}

impl<'a> Lowerer<'a> {
    pub fn new(items: &'a [Item], files: &'a [PathBuf]) -> Self {
        let mut b = Builder::new();
        b.set_version(1, 4);
        let glsl = b.ext_inst_import("GLSL.std.450");
        b.memory_model(spirv::AddressingModel::Logical, spirv::MemoryModel::GLSL450);
        let mut file_ids = Vec::new();
        for f in files {
            file_ids.push(b.string(f.display().to_string()));
        }
        if let Some(first) = file_ids.first() {
            b.source(
                spirv::SourceLanguage::HLSL,
                600,
                Some(*first),
                None::<String>,
            );
        }
        let f = Ty::ScalarKind(ScalarKind::Float);
        let f3 = Ty::Vec(ScalarKind::Float, 3);
        let field = |name: &str, ty: &Ty| Field {
            name: name.into(),
            ty: ty.clone(),
            pos: Pos::default(),
            row_major: false,
        };
        let structs = vec![
            StructDef {
                name: "RayDesc".into(),
                fields: vec![
                    field("Origin", &f3),
                    field("TMin", &f),
                    field("Direction", &f3),
                    field("TMax", &f),
                ],
                pos: Pos::default(),
            },
            StructDef {
                name: "BuiltInTriangleIntersectionAttributes".into(),
                fields: vec![field("barycentrics", &Ty::Vec(ScalarKind::Float, 2))],
                pos: Pos::default(),
            },
        ];
        let mut caps = HashSet::new();
        caps.insert(Capability::Shader);
        b.capability(Capability::Shader);
        Lowerer {
            b,
            items,
            files,
            file_ids,
            struct_names: HashMap::from([
                ("RayDesc".to_string(), RAY_DESC),
                (
                    "BuiltInTriangleIntersectionAttributes".to_string(),
                    TRI_ATTRS,
                ),
            ]),
            structs,
            typedefs: HashMap::new(),
            globals: HashMap::new(),
            funcs: Vec::new(),
            fn_by_name: HashMap::new(),
            ext_insts: HashMap::new(),
            ext_sets: HashMap::new(),
            ty_cache: HashMap::new(),
            undefs: HashMap::new(),
            consts: HashMap::new(),
            glsl,
            caps,
            exts: HashSet::new(),
            builtins: HashMap::new(),
            builtin_vars: HashMap::new(),
            rt_vars: HashMap::new(),
            next_location: HashMap::new(),
            fn_used: HashMap::new(),
            fn_calls: HashMap::new(),
            pending: Vec::new(),
            lowered: HashSet::new(),
            decls: Vec::new(),
            f: FnCtx::new(usize::MAX, "", None, Ty::Void),
            subobjects: Default::default(),
            forced_entry: None,
            global_reqs: HashMap::new(),
            fn_templates: HashMap::new(),
            struct_templates: HashMap::new(),
            method_templates: HashMap::new(),
            instance_structs: items
                .iter()
                .filter_map(|i| match i {
                    Item::Struct(s) if s.tparams.is_empty() && s.name.contains('<') => {
                        Some((s.name.clone(), s))
                    }
                    _ => None,
                })
                .collect(),
            needed: Vec::new(),
            unusable: HashMap::new(),
            fn_stage_uses: HashMap::new(),
            heap_vars: HashMap::new(),
            heap_bindings: ((0, 0), (0, 0)),
            specialized: HashMap::new(),
            usings: items
                .iter()
                .filter_map(|i| match i {
                    Item::Using(n) => Some(format!("{n}::")),
                    _ => None,
                })
                .collect(),
            struct_io: HashMap::new(),
            member_decorations: HashMap::new(),
            physical_addressing: false,
            sixteen_bit_types: false,
            bindings: crate::Bindings::default(),
            fn_derivs: HashMap::new(),
            nonuniform: HashSet::new(),
            cbuffer_members: HashMap::new(),
            const_items: HashMap::new(),
            const_ids: HashMap::new(),
            deferred_inits: Vec::new(),
            nonuniform_ptrs: HashSet::new(),
            global_decls: Vec::new(),
            local_decls: Vec::new(),
            resource_vars: HashSet::new(),
        }
    }

    fn loc(&self, pos: Pos, len: u32) -> Location {
        let path = self
            .files
            .get(pos.file as usize)
            .cloned()
            .unwrap_or_default();
        Location::span(path, pos.line, pos.col, len)
    }

    fn cap(&mut self, c: Capability) {
        if self.caps.insert(c) {
            self.b.capability(c);
        }
    }

    /// Where an unqualified `name` may be declared, nearest first: the current
    /// namespace (or struct) and each enclosing one, the global scope, then the
    /// `using namespace`s.
    fn scoped_names(&self, name: &str) -> Vec<String> {
        self.names_in_scope(&self.f.cur_ns, name)
    }

    /// [`Self::scoped_names`] seen from namespace `ns` instead of the current one.
    fn names_in_scope(&self, ns: &str, name: &str) -> Vec<String> {
        let mut out = Vec::new();
        let mut prefix = ns;
        loop {
            out.push(format!("{prefix}{name}"));
            if prefix.is_empty() {
                break;
            }
            let inner = &prefix[..prefix.len() - 2];
            prefix = match inner.rfind("::") {
                Some(k) => &inner[..k + 2],
                None => "",
            };
        }
        out.extend(self.usings.iter().map(|u| format!("{u}{name}")));
        out
    }

    fn ext(&mut self, e: &str) {
        if self.exts.insert(e.to_string()) {
            self.b.extension(e);
        }
    }

    /// `[[vk::ext_extension("SPV_...")]]` and `[[vk::ext_capability(N)]]`:
    /// what a declaration needs from the module.
    fn ext_requirements(&mut self, attrs: &[Attr]) -> Result<Requirements> {
        let mut req = Requirements::default();
        for a in attrs {
            match a.name.as_str() {
                "vk::ext_extension" => {
                    let name = attr_str(a).ok_or_else(|| {
                        Error::new(a.pos, "expected [[vk::ext_extension(\"SPV_...\")]]")
                    })?;
                    req.0.push(name.to_string());
                }
                "vk::ext_capability" => {
                    let e = a
                        .args
                        .first()
                        .ok_or_else(|| Error::new(a.pos, "expected [[vk::ext_capability(N)]]"))?;
                    let n = self.const_int(e)?;
                    let c = u32::try_from(n)
                        .ok()
                        .and_then(Capability::from_u32)
                        .ok_or_else(|| {
                            Error::new(e.pos, format!("unknown SPIR-V capability {n}"))
                        })?;
                    if let Some(base) = kernel_only(c) {
                        return Err(Error::new(
                            e.pos,
                            format!(
                                "capability `{c:?}` ({n}) is for OpenCL kernels (it implies `{base:?}`), \
                                 which Vulkan does not allow"
                            ),
                        ));
                    }
                    req.1.push(c);
                }
                _ => {}
            }
        }
        Ok(req)
    }

    /// Adds the extensions and capabilities of `req` to the module.
    fn require(&mut self, req: &Requirements) {
        for e in &req.0 {
            self.ext(e);
        }
        for c in &req.1 {
            self.cap(*c);
            // A capability an extension brings needs that extension (any one
            // of those that bring it); add the first when none is declared.
            let exts = Operand::Capability(*c).required_extensions();
            if !exts.is_empty() && !exts.iter().any(|e| self.exts.contains(*e)) {
                self.ext(exts[0]);
            }
        }
    }

    /// Lowers the given entry points and everything they call; returns the module.
    /// Lowers the given entry points and every function they reach (what
    /// `finish` starts with); used to find the template instances a module needs.
    pub fn lower_reached(&mut self, entries: &[usize]) -> Result<()> {
        for &e in entries {
            if !self.lowered.contains(&e) {
                self.pending.push(e);
            }
        }
        while let Some(k) = self.pending.pop() {
            if self.lowered.insert(k) {
                self.lower_function(k)?;
            }
        }
        Ok(())
    }

    pub fn finish(mut self, entries: &[usize]) -> Result<(Vec<u32>, Decls)> {
        for &e in entries {
            if !self.lowered.contains(&e) {
                self.pending.push(e);
            }
        }
        while let Some(k) = self.pending.pop() {
            if self.lowered.insert(k) {
                self.lower_function(k)?;
            }
        }
        let mut wrappers = HashMap::new();
        for &e in entries {
            if self.funcs[e].stage == Some(Stage::Fragment) && !wrappers.contains_key(&e) {
                let w = self.pixel_wrapper(e)?;
                wrappers.insert(e, w);
            }
        }
        // Static initializers in the wrappers may call functions not yet lowered.
        while let Some(k) = self.pending.pop() {
            if self.lowered.insert(k) {
                self.lower_function(k)?;
            }
        }
        self.check_recursion()?;
        let mut decorated = HashSet::new();
        for &e in entries {
            let sig = self.funcs[e].clone();
            let Some(stage) = sig.stage else { continue };
            // SPIR-V 1.4: the interface lists every global the entry point reaches.
            let mut seen = HashSet::new();
            let mut stack = vec![e];
            let mut vars = BTreeSet::new();
            while let Some(f) = stack.pop() {
                if !seen.insert(f) {
                    continue;
                }
                vars.extend(self.fn_used.get(&f).cloned().unwrap_or_default());
                stack.extend(self.fn_calls.get(&f).cloned().unwrap_or_default());
            }
            if stage != Stage::Fragment {
                self.check_derivatives(&seen, &sig)?;
            }
            self.check_stage_uses(&seen, &sig)?;
            let mut entry_id = sig.id;
            if let Some((w, io)) = wrappers.get(&e) {
                entry_id = *w;
                vars.extend(io.iter().copied());
            }
            self.decorate_builtin_inputs(stage, &vars, &mut decorated);
            let vars: Vec<Id> = vars.into_iter().collect();
            self.b.entry_point(
                stage.model().expect("HLSL stages have an execution model"),
                entry_id,
                sig.name.clone(),
                vars,
            );
            let early = sig
                .func
                .attrs
                .iter()
                .find(|a| attrs::normalize(&a.name) == "earlydepthstencil");
            if let (Some(a), false) = (early, stage == Stage::Fragment) {
                return Err(Error::new(
                    a.pos,
                    "`[earlydepthstencil]` applies to pixel shaders only",
                )
                .len(a.name.len() as u32));
            }
            if stage == Stage::Compute {
                self.b
                    .execution_mode(sig.id, spirv::ExecutionMode::LocalSize, sig.numthreads);
            } else if stage == Stage::Fragment {
                // Vulkan requires it; HLSL's SV_Position has its origin at the top left.
                self.b
                    .execution_mode(entry_id, spirv::ExecutionMode::OriginUpperLeft, []);
                if early.is_some() {
                    self.b
                        .execution_mode(entry_id, spirv::ExecutionMode::EarlyFragmentTests, []);
                }
            } else {
                self.ray_tracing_caps();
            }
        }
        self.acceleration_structure_caps();
        let mut debug = self.emit_debug_info();
        let mut module = self.b.module();
        if self.physical_addressing {
            if let Some(mm) = module.memory_model.as_mut() {
                mm.operands[0] =
                    Operand::AddressingModel(spirv::AddressingModel::PhysicalStorageBuffer64);
            }
        }
        if let Some(d) = &mut debug {
            Self::place_declares(&mut module, d);
        }
        hoist_variables(&mut module);
        if let Some(d) = &debug {
            Self::place_definitions(&mut module, d);
        }
        drop_unused_globals(&mut module);
        storage16::add_16bit_storage(&mut module);
        use rspirv::binary::Assemble;
        Ok((module.assemble(), self.decls))
    }
}

/// A value the lowerer computed at compile time (constant folding).
#[derive(Clone, Debug, PartialEq)]
pub enum ConstValue {
    I(i64),
    F(f64),
}

impl ConstValue {
    fn as_f64(&self) -> f64 {
        match self {
            ConstValue::I(i) => *i as f64,
            ConstValue::F(f) => *f,
        }
    }
}

/// Removes module-scope variables no function touches (with their names and
/// decorations): a module holds the resources its entry points use, as DXC's do.
fn drop_unused_globals(module: &mut dr::Module) {
    let mut used = HashSet::new();
    for e in &module.entry_points {
        for op in &e.operands {
            if let Operand::IdRef(id) = op {
                used.insert(*id);
            }
        }
    }
    for f in &module.functions {
        for b in &f.blocks {
            for i in &b.instructions {
                for op in &i.operands {
                    if let Operand::IdRef(id) = op {
                        used.insert(*id);
                    }
                }
            }
        }
    }
    let dead: HashSet<Id> = module
        .types_global_values
        .iter()
        .filter(|i| i.class.opcode == Op::Variable)
        .filter_map(|i| i.result_id)
        .filter(|id| !used.contains(id))
        .collect();
    if dead.is_empty() {
        return;
    }
    // Debug info describing a dropped variable goes with it.
    module.types_global_values.retain(|i| {
        !i.result_id.is_some_and(|id| dead.contains(&id))
            && !i
                .operands
                .iter()
                .any(|o| matches!(o, Operand::IdRef(id) if dead.contains(id)))
    });
    let targets_dead = |i: &Instruction| matches!(i.operands.first(), Some(Operand::IdRef(id)) if dead.contains(id));
    module.debug_names.retain(|i| !targets_dead(i));
    module.annotations.retain(|i| !targets_dead(i));
    drop_unused_stage_pointers(module);
}

/// Pointer types of ray-tracing-only storage classes that nothing refers to
/// any more (their variable was dropped): they would need the ray-tracing
/// capability in, say, a compute module.
fn drop_unused_stage_pointers(module: &mut dr::Module) {
    let rt_class = |i: &Instruction| {
        i.class.opcode == Op::TypePointer
            && matches!(
                i.operands.first(),
                Some(Operand::StorageClass(
                    StorageClass::ShaderRecordBufferKHR
                        | StorageClass::RayPayloadKHR
                        | StorageClass::IncomingRayPayloadKHR
                        | StorageClass::HitAttributeKHR
                        | StorageClass::CallableDataKHR
                        | StorageClass::IncomingCallableDataKHR
                ))
            )
    };
    let mut used = HashSet::new();
    let mut note = |i: &Instruction| {
        used.extend(i.result_type);
        for op in &i.operands {
            if let Operand::IdRef(id) = op {
                used.insert(*id);
            }
        }
    };
    module.types_global_values.iter().for_each(&mut note);
    for f in &module.functions {
        f.def.iter().for_each(&mut note);
        f.parameters.iter().for_each(&mut note);
        for b in &f.blocks {
            b.instructions.iter().for_each(&mut note);
        }
    }
    module
        .types_global_values
        .retain(|i| !(rt_class(i) && i.result_id.is_some_and(|id| !used.contains(&id))));
}

/// Moves every function's `OpVariable`s to the top of its entry block, where
/// SPIR-V requires them (they are emitted where the declaration is met).
fn hoist_variables(module: &mut dr::Module) {
    for f in &mut module.functions {
        let mut vars = Vec::new();
        for b in &mut f.blocks {
            let (v, rest): (Vec<_>, Vec<_>) = b
                .instructions
                .drain(..)
                .partition(|i| i.class.opcode == Op::Variable);
            vars.extend(v);
            b.instructions = rest;
        }
        if let Some(first) = f.blocks.first_mut() {
            let rest = std::mem::take(&mut first.instructions);
            first.instructions = vars;
            first.instructions.extend(rest);
        }
    }
}

impl Lowerer<'_> {
    /// The function index of the entry point called `name`.
    pub fn entry_function(&self, name: &str) -> Option<usize> {
        self.funcs
            .iter()
            .position(|f| f.name == name && f.stage.is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spirv::ExecutionModel;

    #[test]
    fn swizzles_and_matrix_elements() {
        assert_eq!(swizzle_comps("xyzw"), Some(vec![0, 1, 2, 3]));
        assert_eq!(swizzle_comps("bgr"), Some(vec![2, 1, 0]));
        assert_eq!(swizzle_comps("xr"), None);
        assert_eq!(swizzle_comps("xyzwx"), None);
        assert_eq!(matrix_comps("_m01_m10"), Some(vec![(0, 1), (1, 0)]));
        assert_eq!(matrix_comps("_11_44"), Some(vec![(0, 0), (3, 3)]));
        assert_eq!(matrix_comps("_00"), None);
        assert_eq!(matrix_comps("m00"), None);
    }

    #[test]
    fn builtin_constants_and_stages_follow_dxc() {
        assert_eq!(
            builtin_constant("RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES"),
            Some(0x200)
        );
        assert_eq!(
            Stage::from_hlsl_name("intersection"),
            Some(Stage::Intersection)
        );
        assert_eq!(
            Stage::ClosestHit.model(),
            Some(ExecutionModel::ClosestHitKHR)
        );
    }

    #[test]
    fn constants_fold_through_conversions() {
        let items = Vec::new();
        let files = Vec::new();
        let mut l = Lowerer::new(&items, &files);
        let a = Val {
            id: l.const_i32(6),
            ty: Ty::ScalarKind(ScalarKind::Int),
        };
        let b = Val {
            id: l.const_u32(1),
            ty: Ty::ScalarKind(ScalarKind::Uint),
        };
        let v = l.binary(BinOp::BitOr, a, b, Pos::default()).unwrap();
        assert_eq!(v.ty, Ty::ScalarKind(ScalarKind::Uint));
        assert_eq!(l.known(&v), Some((ScalarKind::Uint, 7)));
        let f = l
            .convert(v, &Ty::ScalarKind(ScalarKind::Float), Pos::default(), false)
            .unwrap();
        assert_eq!(l.known(&f), Some((ScalarKind::Float, 7.0f32.to_bits())));
    }

    #[test]
    fn half_conversions_round_to_nearest_even() {
        use consts::{f16_to_f32, f32_to_f16};
        assert_eq!(f32_to_f16(1.0), 0x3c00);
        assert_eq!(f32_to_f16(-2.0), 0xc000);
        assert_eq!(f32_to_f16(0.1), 0x2e66);
        assert_eq!(f32_to_f16(65504.0), 0x7bff);
        // Past the largest half (and its rounding midpoint): infinity.
        assert_eq!(f32_to_f16(65520.0), 0x7c00);
        assert_eq!(f32_to_f16(f32::NEG_INFINITY), 0xfc00);
        assert_eq!(f32_to_f16(f32::NAN) & 0x7c00, 0x7c00);
        assert_ne!(f32_to_f16(f32::NAN) & 0x3ff, 0);
        // Ties go to the even mantissa: 2049 to 2048, 2051 to 2052.
        assert_eq!(f32_to_f16(2049.0), 0x6800);
        assert_eq!(f32_to_f16(2051.0), 0x6802);
        // Subnormals, the smallest one, and what rounds to zero.
        assert_eq!(f32_to_f16(2f32.powi(-24)), 0x0001);
        assert_eq!(f32_to_f16(2f32.powi(-15)), 0x0200);
        assert_eq!(f32_to_f16(2f32.powi(-26)), 0x0000);
        assert_eq!(f32_to_f16(-0.0), 0x8000);
        for h in [0x0001u16, 0x0200, 0x3c00, 0x2e66, 0x7bff, 0xc000, 0x8000] {
            assert_eq!(f32_to_f16(f16_to_f32(h)), h);
        }
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }
}
