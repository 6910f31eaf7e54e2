//! Type checking and SPIR-V emission in one walk over the AST.
//!
//! Follows DXC's HLSL→SPIR-V mapping for Vulkan: ray-tracing payloads become
//! `RayPayloadKHR`/`IncomingRayPayloadKHR` variables, hit attributes a
//! `HitAttributeKHR` variable, system values `BuiltIn` inputs, resources
//! descriptor-set variables with `Binding`/`DescriptorSet`.

mod calls;
mod debug;
mod methods;
mod pixel;

use super::ast::*;
use super::error::{Error, Pos, Result};
use super::parse::split_numeric;
use super::types::*;
use crate::diag::Location;
use crate::program::NamedDecl;
pub use crate::shader::Stage;
use rspirv::dr::{self, Builder, InsertPoint, Instruction, Operand};
use spirv::{BuiltIn, Capability, Decoration, Op, StorageClass, Word as Id};
use std::collections::{BTreeSet, HashMap, HashSet};
use std::path::PathBuf;

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
    ty_cache: HashMap<(Ty, Layout, bool), Id>,
    consts: HashMap<(Id, u32), Id>,
    glsl: Id,
    caps: HashSet<Capability>,
    exts: HashSet<&'static str>,
    builtins: HashMap<BuiltIn, Id>,
    rt_vars: HashMap<(StorageClass, Ty), Id>,
    next_location: HashMap<StorageClass, u32>,
    fn_used: HashMap<usize, BTreeSet<Id>>,
    fn_calls: HashMap<usize, BTreeSet<usize>>,
    pending: Vec<usize>,
    lowered: HashSet<usize>,
    pub decls: Vec<(NamedDecl, Location)>,
    // Per-function state.
    cur_fn: usize,
    cur_ns: String,
    cur_stage: Option<Stage>,
    cur_label: Id,
    ret_ty: Ty,
    scopes: Vec<HashMap<String, Place>>,
    flow: Vec<Flow>,
    term: bool,
    /// `NonUniformResourceIndex` results, decorated when they index resources.
    nonuniform: HashSet<Id>,
    /// cbuffer member name → (variable, type, index, layout, storage class).
    cbuffer_members: HashMap<String, (Id, Ty, u32, Layout, StorageClass)>,
    /// Scalar constants known at compile time (enums, `static const`), for array sizes.
    const_items: HashMap<String, CVal>,
    /// Scalar constant id → its bits.
    const_ids: HashMap<Id, u32>,
    /// Static globals whose initializers run at the start of each entry point.
    deferred_inits: Vec<(Id, Ty, &'a Expr)>,
    /// Pointers into resource arrays indexed with `NonUniformResourceIndex`.
    nonuniform_ptrs: HashSet<Id>,
    /// `this` of the method being lowered; its members resolve by bare name.
    this_place: Option<Place>,
    /// Globals with source positions, for debug info: (variable, name, type, position).
    global_decls: Vec<(Id, String, Ty, Pos)>,
    /// Locals and parameters for debug info: (function, variable, name, type, position).
    local_decls: Vec<(usize, Id, String, Ty, Pos)>,
    /// Descriptor variables (what a resource parameter may be given).
    resource_vars: HashSet<Id>,
    /// Per user struct, each member's semantic and attributes (pixel-shader I/O).
    struct_io: HashMap<u32, Vec<MemberIo>>,
    /// Functions outside an entry body that use derivatives: (name, position),
    /// checked against the entry points that reach them.
    fn_derivs: HashMap<usize, (&'static str, Pos)>,
}

/// A struct member's semantic and attributes.
type MemberIo = (Option<(String, Pos)>, Vec<Attr>);

/// Source positions of named declarations (the side table `Program` reads).
pub type Decls = Vec<(NamedDecl, Location)>;

const RAY_DESC: u32 = 0;
const TRI_ATTRS: u32 = 1;

fn unsupported(pos: Pos, what: impl std::fmt::Display) -> Error {
    Error::new(pos, format!("not supported: {what}"))
}

impl From<dr::Error> for Error {
    fn from(e: dr::Error) -> Self {
        Error::new(Pos::default(), format!("internal compiler error: {e}"))
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

/// System-value intrinsics: builtin, type, stages that may read it.
fn system_value(name: &str) -> Option<(BuiltIn, Ty, &'static [Stage])> {
    use Stage::*;
    const ALL: &[Stage] = &[
        RayGeneration,
        ClosestHit,
        AnyHit,
        Miss,
        Intersection,
        Callable,
    ];
    const RAY: &[Stage] = &[ClosestHit, AnyHit, Miss, Intersection];
    const HIT: &[Stage] = &[ClosestHit, AnyHit, Intersection];
    let f3 = Ty::Vec(Sc::Float, 3);
    let u = Ty::Sc(Sc::Uint);
    let f = Ty::Sc(Sc::Float);
    Some(match name {
        "DispatchRaysIndex" => (BuiltIn::LaunchIdKHR, Ty::Vec(Sc::Uint, 3), ALL),
        "DispatchRaysDimensions" => (BuiltIn::LaunchSizeKHR, Ty::Vec(Sc::Uint, 3), ALL),
        "WorldRayOrigin" => (BuiltIn::WorldRayOriginKHR, f3, RAY),
        "WorldRayDirection" => (BuiltIn::WorldRayDirectionKHR, f3, RAY),
        "ObjectRayOrigin" => (BuiltIn::ObjectRayOriginKHR, f3, HIT),
        "ObjectRayDirection" => (BuiltIn::ObjectRayDirectionKHR, f3, HIT),
        "RayTMin" => (BuiltIn::RayTminKHR, f, RAY),
        "RayTCurrent" => (BuiltIn::RayTmaxKHR, f, RAY),
        "RayFlags" => (BuiltIn::IncomingRayFlagsKHR, u, RAY),
        "InstanceIndex" => (BuiltIn::InstanceId, u, HIT),
        "InstanceID" => (BuiltIn::InstanceCustomIndexKHR, u, HIT),
        "GeometryIndex" => (BuiltIn::RayGeometryIndexKHR, u, HIT),
        "PrimitiveIndex" => (BuiltIn::PrimitiveId, u, HIT),
        "HitKind" => (BuiltIn::HitKindKHR, u, &[ClosestHit, AnyHit]),
        // SPIR-V holds these as 4 columns of float3, which is HLSL's float4x3.
        "ObjectToWorld4x3" | "ObjectToWorld3x4" | "ObjectToWorld" => {
            (BuiltIn::ObjectToWorldKHR, Ty::Mat(Sc::Float, 4, 3), HIT)
        }
        "WorldToObject4x3" | "WorldToObject3x4" | "WorldToObject" => {
            (BuiltIn::WorldToObjectKHR, Ty::Mat(Sc::Float, 4, 3), HIT)
        }
        _ => return None,
    })
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
        let f = Ty::Sc(Sc::Float);
        let f3 = Ty::Vec(Sc::Float, 3);
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
                fields: vec![field("barycentrics", &Ty::Vec(Sc::Float, 2))],
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
            ty_cache: HashMap::new(),
            consts: HashMap::new(),
            glsl,
            caps,
            exts: HashSet::new(),
            builtins: HashMap::new(),
            rt_vars: HashMap::new(),
            next_location: HashMap::new(),
            fn_used: HashMap::new(),
            fn_calls: HashMap::new(),
            pending: Vec::new(),
            lowered: HashSet::new(),
            decls: Vec::new(),
            cur_fn: usize::MAX,
            cur_ns: String::new(),
            cur_stage: None,
            cur_label: 0,
            struct_io: HashMap::new(),
            fn_derivs: HashMap::new(),
            ret_ty: Ty::Void,
            scopes: Vec::new(),
            flow: Vec::new(),
            term: false,
            nonuniform: HashSet::new(),
            cbuffer_members: HashMap::new(),
            const_items: HashMap::new(),
            const_ids: HashMap::new(),
            deferred_inits: Vec::new(),
            nonuniform_ptrs: HashSet::new(),
            this_place: None,
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

    fn ext(&mut self, e: &'static str) {
        if self.exts.insert(e) {
            self.b.extension(e);
        }
    }

    // ---- declarations --------------------------------------------------

    /// Reads every declaration and function signature; returns the entry points.
    pub fn declare(&mut self) -> Result<Vec<EntryInfo>> {
        let items = self.items;
        for item in items {
            match item {
                Item::Struct(s) => self.declare_struct(s)?,
                Item::Typedef {
                    ty,
                    dims,
                    name,
                    pos,
                } => {
                    let t = self.resolve_ty(ty, "")?;
                    let t = self.apply_dims(t, dims, *pos, false)?;
                    self.typedefs.insert(name.clone(), t);
                }
                Item::Enum {
                    name,
                    scoped,
                    underlying,
                    variants,
                    ..
                } => {
                    let sc = match underlying {
                        Some(t) => match self.resolve_ty(t, "")? {
                            Ty::Sc(s @ (Sc::Int | Sc::Uint)) => s,
                            _ => return Err(Error::new(t.pos, "enum type must be int or uint")),
                        },
                        None => Sc::Int,
                    };
                    self.typedefs.insert(name.clone(), Ty::Sc(sc));
                    let mut next = 0i64;
                    let ns = name
                        .rsplit_once("::")
                        .map(|(n, _)| format!("{n}::"))
                        .unwrap_or_default();
                    for (v, _, value) in variants {
                        if let Some(e) = value {
                            next = self.const_int(e)?;
                        }
                        let id = self.const_scalar(sc, next as f64, next);
                        let c = Global::Const(Val { id, ty: Ty::Sc(sc) });
                        self.globals.insert(format!("{name}::{v}"), c.clone());
                        self.const_items
                            .insert(format!("{name}::{v}"), CVal::I(next));
                        if !scoped {
                            self.globals.insert(format!("{ns}{v}"), c);
                            self.const_items.insert(format!("{ns}{v}"), CVal::I(next));
                        }
                        next += 1;
                    }
                }
                _ => {}
            }
        }
        self.declare_globals()?;
        let mut entries = Vec::new();
        for item in items {
            if let Item::Struct(sd) = item {
                self.declare_methods(sd)?;
                continue;
            }
            let Item::Function(f) = item else { continue };
            let mut stage = None;
            let mut numthreads = [1, 1, 1];
            for a in &f.attrs {
                match a.name.as_str() {
                    "shader" => {
                        let s = attr_str(a)
                            .ok_or_else(|| Error::new(a.pos, "expected [shader(\"stage\")]"))?;
                        stage =
                            Some(Stage::from_hlsl_name(s).ok_or_else(|| {
                                unsupported(a.pos, format!("shader stage \"{s}\""))
                            })?);
                    }
                    "numthreads" => {
                        if a.args.len() != 3 {
                            return Err(Error::new(a.pos, "[numthreads] needs three sizes"));
                        }
                        for (n, e) in a.args.iter().enumerate() {
                            numthreads[n] = self.const_int(e)? as u32;
                        }
                        stage.get_or_insert(Stage::Compute);
                    }
                    _ => {}
                }
            }
            let ret = self.resolve_ty(&f.ret, &f.ns)?;
            let mut params = Vec::new();
            for p in &f.params {
                let t = self.resolve_ty(&p.ty, &f.ns)?;
                let t = self.apply_dims(t, &p.dims, p.pos, false)?;
                if t.is_resource() && (matches!(t, Ty::Array(..) | Ty::RtArray(_)) || p.mods.output)
                {
                    return Err(unsupported(
                        p.pos,
                        "arrays of resources, or `out` resources, as function parameters",
                    ));
                }
                params.push(Param {
                    ty: t,
                    out: p.mods.output,
                    input: p.mods.input || !p.mods.output,
                });
            }
            let id = self.b.id();
            if f.body.is_none() {
                continue; // a prototype: the definition carries the signature
            }
            let idx = self.funcs.len();
            self.funcs.push(FnSig {
                name: f.name.clone(),
                params,
                ret,
                id,
                func: f,
                this: None,
                stage,
                numthreads,
            });
            self.fn_by_name.entry(f.name.clone()).or_default().push(idx);
            self.decls.push((
                NamedDecl::Function(f.name.clone()),
                self.loc(f.pos, f.name.len() as u32),
            ));
            if let Some(s) = stage {
                entries.push(EntryInfo {
                    name: f.name.clone(),
                    stage: s,
                });
            }
        }
        Ok(entries)
    }

    fn declare_methods(&mut self, sd: &'a StructDecl) -> Result<()> {
        let Some(&k) = self.struct_names.get(&sd.name) else {
            return Ok(());
        };
        for f in &sd.methods {
            let ret = self.resolve_ty(&f.ret, &f.ns)?;
            let mut params = vec![Param {
                ty: Ty::Struct(k),
                out: true,
                input: true,
            }];
            for p in &f.params {
                let t = self.resolve_ty(&p.ty, &f.ns)?;
                let t = self.apply_dims(t, &p.dims, p.pos, false)?;
                if t.is_resource() && (matches!(t, Ty::Array(..) | Ty::RtArray(_)) || p.mods.output)
                {
                    return Err(unsupported(
                        p.pos,
                        "arrays of resources, or `out` resources, as function parameters",
                    ));
                }
                params.push(Param {
                    ty: t,
                    out: p.mods.output,
                    input: p.mods.input || !p.mods.output,
                });
            }
            let name = format!("{}::{}", sd.name, f.name);
            let idx = self.funcs.len();
            let id = self.b.id();
            self.funcs.push(FnSig {
                name: name.clone(),
                params,
                ret,
                id,
                func: f,
                this: Some(k),
                stage: None,
                numthreads: [1, 1, 1],
            });
            self.fn_by_name.entry(name.clone()).or_default().push(idx);
            self.decls.push((
                NamedDecl::Function(name),
                self.loc(f.pos, f.name.len() as u32),
            ));
        }
        Ok(())
    }

    fn declare_struct(&mut self, s: &StructDecl) -> Result<()> {
        let mut fields = Vec::new();
        for f in &s.fields {
            let t = self.resolve_ty(&f.ty, "")?;
            let t = self.apply_dims(t, &f.dims, f.pos, false)?;
            if t.is_resource() || matches!(t, Ty::RayQuery(_)) {
                return Err(unsupported(f.pos, "resources inside structs"));
            }
            if fields.iter().any(|x: &Field| x.name == f.name) {
                return Err(Error::new(f.pos, format!("duplicate member `{}`", f.name)));
            }
            fields.push(Field {
                name: f.name.clone(),
                ty: t,
                pos: f.pos,
                row_major: f.mods.row_major,
            });
        }
        if self.struct_names.contains_key(&s.name) {
            return Err(Error::new(
                s.pos,
                format!("`{}` is already defined", s.name),
            ));
        }
        let k = self.structs.len() as u32;
        self.decls.push((
            NamedDecl::Type(s.name.clone()),
            self.loc(s.pos, s.name.len() as u32),
        ));
        for (i, f) in fields.iter().enumerate() {
            self.decls.push((
                NamedDecl::Member(s.name.clone(), i as u32),
                self.loc(f.pos, f.name.len() as u32),
            ));
        }
        self.structs.push(StructDef {
            name: s.name.clone(),
            fields,
            pos: s.pos,
        });
        self.struct_io.insert(
            k,
            s.fields
                .iter()
                .map(|f| (f.semantic.clone(), f.attrs.clone()))
                .collect(),
        );
        self.struct_names.insert(s.name.clone(), k);
        Ok(())
    }

    fn lookup_type_name(&self, name: &str, ns: &str) -> Option<Ty> {
        let mut prefix = ns.to_string();
        loop {
            let q = format!("{prefix}{name}");
            if let Some(k) = self.struct_names.get(&q) {
                return Some(Ty::Struct(*k));
            }
            if let Some(t) = self.typedefs.get(&q) {
                return Some(t.clone());
            }
            if prefix.is_empty() {
                return None;
            }
            prefix.truncate(prefix.len() - 2);
            prefix = match prefix.rfind("::") {
                Some(k) => prefix[..k + 2].to_string(),
                None => String::new(),
            };
        }
    }

    fn resolve_ty(&mut self, t: &TypeRef, ns: &str) -> Result<Ty> {
        let name = t.name.as_str();
        let targ_ty = |this: &mut Self, k: usize, default: Ty| -> Result<Ty> {
            match t.args.get(k) {
                Some(TArg::Type(a)) => this.resolve_ty(a, ns),
                Some(TArg::Expr(e)) => Err(Error::new(e.pos, "expected a type argument")),
                None => Ok(default),
            }
        };
        if let Some((base, a, b)) = split_numeric(name) {
            let sc = match base {
                "bool" => Sc::Bool,
                "int" | "min16int" | "min12int" | "int32_t" => Sc::Int,
                "uint" | "dword" | "min16uint" | "uint32_t" => Sc::Uint,
                // Without 16-bit types enabled, DXC treats half as float.
                "float" | "half" | "min16float" | "min10float" | "float32_t" => Sc::Float,
                other => {
                    return Err(
                        unsupported(t.pos, format!("type `{other}` (only 32-bit types)"))
                            .len(other.len() as u32),
                    )
                }
            };
            return self.numeric(sc, a, b, t.pos);
        }
        Ok(match name {
            "void" => Ty::Void,
            "vector" | "matrix" => {
                let sc = match targ_ty(self, 0, Ty::Sc(Sc::Float))? {
                    Ty::Sc(s) => s,
                    _ => {
                        return Err(Error::new(
                            t.pos,
                            "vector and matrix elements must be scalars",
                        ))
                    }
                };
                let dim = |this: &mut Self, k: usize| -> Result<u8> {
                    match t.args.get(k) {
                        Some(TArg::Expr(e)) => Ok(this.const_int(e)?.clamp(0, 255) as u8),
                        Some(TArg::Type(a)) => Err(Error::new(a.pos, "expected a size")),
                        None => Ok(4),
                    }
                };
                let a = dim(self, 1)?;
                let b = if name == "matrix" { dim(self, 2)? } else { 0 };
                if a == 0 || a > 4 || (name == "matrix" && (b == 0 || b > 4)) {
                    return Err(Error::new(t.pos, "vector and matrix sizes are 1 to 4"));
                }
                return self.numeric(sc, a, b, t.pos);
            }
            "RaytracingAccelerationStructure" => Ty::Accel,
            "RayQuery" => {
                let flags = match t.args.first() {
                    Some(TArg::Expr(e)) => self.const_int(e)? as u32,
                    _ => {
                        return Err(Error::new(
                            t.pos,
                            "RayQuery needs its flags: RayQuery<RAY_FLAG_NONE>",
                        ))
                    }
                };
                Ty::RayQuery(flags)
            }
            "SamplerState" => Ty::Sampler,
            "ByteAddressBuffer" => Ty::ByteAddress(false),
            "RWByteAddressBuffer" => Ty::ByteAddress(true),
            "StructuredBuffer" | "RWStructuredBuffer" => {
                let e = targ_ty(self, 0, Ty::Void)?;
                if e == Ty::Void || e.is_resource() {
                    return Err(Error::new(t.pos, format!("{name} needs an element type")));
                }
                if let Ty::Mat(..) = e {
                    return Err(unsupported(
                        t.pos,
                        format!("{name} of a matrix; wrap the matrix in a struct"),
                    ));
                }
                Ty::StructuredBuffer(Box::new(e), name.starts_with("RW"))
            }
            "ConstantBuffer" => match targ_ty(self, 0, Ty::Void)? {
                Ty::Struct(k) => Ty::ConstantBuffer(k),
                _ => return Err(Error::new(t.pos, "ConstantBuffer needs a struct type")),
            },
            "Texture1D" | "Texture2D" | "Texture3D" | "TextureCube" | "Texture2DArray"
            | "RWTexture1D" | "RWTexture2D" | "RWTexture3D" | "RWTexture2DArray" => {
                let rw = name.starts_with("RW");
                let dim = match name.trim_start_matches("RW") {
                    "Texture1D" => Dim::D1,
                    "Texture2D" => Dim::D2,
                    "Texture3D" => Dim::D3,
                    "TextureCube" => Dim::Cube,
                    _ => Dim::D2Array,
                };
                let (sc, n) = match targ_ty(self, 0, Ty::Vec(Sc::Float, 4))? {
                    Ty::Sc(s) if s != Sc::Bool => (s, 1),
                    Ty::Vec(s, n) if s != Sc::Bool => (s, n),
                    _ => {
                        return Err(Error::new(
                            t.pos,
                            "texture elements must be scalars or vectors",
                        ))
                    }
                };
                Ty::Texture { dim, sc, n, rw }
            }
            "SamplerComparisonState"
            | "Buffer"
            | "RWBuffer"
            | "AppendStructuredBuffer"
            | "ConsumeStructuredBuffer"
            | "Texture2DMS"
            | "HitObject"
            | "string"
            | "TriangleHitGroup"
            | "ProceduralPrimitiveHitGroup"
            | "RaytracingShaderConfig"
            | "RaytracingPipelineConfig"
            | "RaytracingPipelineConfig1"
            | "GlobalRootSignature"
            | "LocalRootSignature"
            | "StateObjectConfig"
            | "SubobjectToExportsAssociation" => {
                return Err(unsupported(t.pos, format!("`{name}`")).len(name.len() as u32));
            }
            _ => match self.lookup_type_name(name, ns) {
                Some(t) => t,
                None => {
                    return Err(
                        Error::new(t.pos, format!("unknown type `{name}`")).len(name.len() as u32)
                    )
                }
            },
        })
    }

    fn numeric(&mut self, sc: Sc, a: u8, b: u8, pos: Pos) -> Result<Ty> {
        Ok(match (a, b) {
            (0, _) | (1, 0) => Ty::Sc(sc),
            (n, 0) => Ty::Vec(sc, n),
            (r, c) => {
                if sc != Sc::Float {
                    return Err(unsupported(pos, "non-float matrices"));
                }
                if r < 2 || c < 2 {
                    return Err(unsupported(pos, "matrices with one row or column"));
                }
                Ty::Mat(sc, r, c)
            }
        })
    }

    fn apply_dims(
        &mut self,
        mut t: Ty,
        dims: &[Option<Expr>],
        pos: Pos,
        unbounded_ok: bool,
    ) -> Result<Ty> {
        for d in dims.iter().rev() {
            t = match d {
                Some(e) => {
                    let n = self.const_int(e)?;
                    if n <= 0 {
                        return Err(Error::new(e.pos, "array size must be positive"));
                    }
                    Ty::Array(Box::new(t), n as u32)
                }
                None if unbounded_ok => Ty::RtArray(Box::new(t)),
                None => return Err(Error::new(pos, "array size missing")),
            };
        }
        Ok(t)
    }

    fn declare_globals(&mut self) -> Result<()> {
        let items = self.items;
        // Explicit bindings first, so automatic ones avoid them.
        let mut used: HashSet<(u32, u32)> = HashSet::new();
        let explicit = |attrs: &[Attr],
                        reg: &Option<Register>,
                        this: &mut Self|
         -> Result<Option<(u32, u32)>> {
            for a in attrs {
                if a.name == "vk::binding" {
                    let b = a
                        .args
                        .first()
                        .map(|e| this.const_int(e))
                        .transpose()?
                        .unwrap_or(0) as u32;
                    let s = a
                        .args
                        .get(1)
                        .map(|e| this.const_int(e))
                        .transpose()?
                        .unwrap_or(0) as u32;
                    return Ok(Some((s, b)));
                }
            }
            Ok(reg.as_ref().map(|r| (r.space, r.index)))
        };
        for item in items {
            let (attrs, reg) = match item {
                Item::Var(v) => (&v.attrs, &v.register),
                Item::CBuffer {
                    attrs, register, ..
                } => (attrs, register),
                _ => continue,
            };
            if let Some(sb) = explicit(attrs, reg, self)? {
                used.insert(sb);
            }
        }
        let mut next_auto = 0u32;
        let mut globals_members: Vec<&VarDecl> = Vec::new();
        for item in items {
            match item {
                Item::CBuffer {
                    attrs,
                    name,
                    pos,
                    register,
                    members,
                } => {
                    let binding = match explicit(attrs, register, self)? {
                        Some(sb) => Some(sb),
                        None if attrs.iter().any(|a| a.name == "vk::push_constant") => None,
                        None => Some(self.auto_binding(&mut used, &mut next_auto)),
                    };
                    let members: Vec<&VarDecl> = members.iter().collect();
                    self.declare_cbuffer(attrs, name, *pos, binding, &members)?;
                }
                Item::Var(v) if self.in_implicit_globals(v)? => globals_members.push(v),
                Item::Var(v) => self.declare_global_var(v, &mut used, &mut next_auto)?,
                _ => {}
            }
        }
        if let Some(first) = globals_members.first() {
            // Plain globals live in the implicit `$Globals` constant buffer, as in DXC.
            let pos = first.pos;
            let binding = self.auto_binding(&mut used, &mut next_auto);
            self.declare_cbuffer(&[], "$Globals", pos, Some(binding), &globals_members)?;
        }
        Ok(())
    }

    /// Whether a global belongs in `$Globals`: not static, groupshared, a
    /// resource or a specialization constant.
    fn in_implicit_globals(&mut self, v: &VarDecl) -> Result<bool> {
        if v.mods.is_static
            || v.mods.groupshared
            || v.attrs.iter().any(|a| a.name == "vk::constant_id")
        {
            return Ok(false);
        }
        let t = self.resolve_ty(&v.ty, "")?;
        Ok(
            !t.is_resource()
                && !matches!(t, Ty::RayQuery(_))
                && !v.dims.iter().any(Option::is_none),
        )
    }

    fn declare_cbuffer(
        &mut self,
        attrs: &[Attr],
        name: &str,
        pos: Pos,
        binding: Option<(u32, u32)>,
        members: &[&VarDecl],
    ) -> Result<()> {
        let mut fields = Vec::new();
        for m in members {
            if let Some(init) = &m.init {
                return Err(unsupported(
                    init.pos,
                    "initializers of constant-buffer members (declare the global `static const`)",
                ));
            }
            let t = self.resolve_ty(&m.ty, "")?;
            let t = self.apply_dims(t, &m.dims, m.pos, false)?;
            if t.is_resource() {
                return Err(unsupported(m.pos, "resources inside cbuffer"));
            }
            fields.push(Field {
                name: m.name.clone(),
                ty: t,
                pos: m.pos,
                row_major: m.mods.row_major,
            });
        }
        let k = self.structs.len() as u32;
        self.structs.push(StructDef {
            name: format!("type.{name}"),
            fields: fields.clone(),
            pos,
        });
        self.decls.push((
            NamedDecl::Type(format!("type.{name}")),
            self.loc(pos, name.len() as u32),
        ));
        for (i, f) in fields.iter().enumerate() {
            self.decls.push((
                NamedDecl::Member(format!("type.{name}"), i as u32),
                self.loc(f.pos, f.name.len() as u32),
            ));
        }
        let var = self.resource_var(&Ty::ConstantBuffer(k), attrs, binding, name)?;
        self.global_decls
            .push((var, name.to_string(), Ty::Struct(k), pos));
        self.decls.push((
            NamedDecl::Global(name.to_string()),
            self.loc(pos, name.len() as u32),
        ));
        let (layout, class) = self.cbuffer_class(attrs);
        for (i, f) in fields.iter().enumerate() {
            self.cbuffer_members
                .insert(f.name.clone(), (var, f.ty.clone(), i as u32, layout, class));
        }
        Ok(())
    }

    fn auto_binding(&mut self, used: &mut HashSet<(u32, u32)>, next: &mut u32) -> (u32, u32) {
        while used.contains(&(0, *next)) {
            *next += 1;
        }
        used.insert((0, *next));
        (0, *next)
    }

    /// Layout and storage class of a cbuffer / ConstantBuffer by its attributes.
    fn cbuffer_class(&self, attrs: &[Attr]) -> (Layout, StorageClass) {
        if attrs.iter().any(|a| a.name == "vk::push_constant") {
            (Layout::Std430, StorageClass::PushConstant)
        } else if attrs
            .iter()
            .any(|a| a.name == "vk::shader_record_ext" || a.name == "vk::shader_record_nv")
        {
            (Layout::Std430, StorageClass::ShaderRecordBufferKHR)
        } else {
            (Layout::CBuffer, StorageClass::Uniform)
        }
    }

    /// Declares a descriptor (or push-constant / shader-record) variable.
    fn resource_var(
        &mut self,
        ty: &Ty,
        attrs: &[Attr],
        binding: Option<(u32, u32)>,
        name: &str,
    ) -> Result<Id> {
        let (inner, arrays) = {
            let mut t = ty;
            let mut arrays = Vec::new();
            loop {
                match t {
                    Ty::Array(e, n) => {
                        arrays.push(Some(*n));
                        t = e;
                    }
                    Ty::RtArray(e) => {
                        arrays.push(None);
                        t = e;
                    }
                    _ => break,
                }
            }
            (t.clone(), arrays)
        };
        let (mut tid, class) = self.descriptor_type(&inner, attrs)?;
        for n in arrays.iter().rev() {
            tid = match n {
                Some(n) => {
                    let len = self.const_u32(*n);
                    self.b.type_array(tid, len)
                }
                None => {
                    self.cap(Capability::RuntimeDescriptorArray);
                    self.ext("SPV_EXT_descriptor_indexing");
                    self.b.type_runtime_array(tid)
                }
            };
        }
        let pty = self.b.type_pointer(None, class, tid);
        let var = self.global_var(pty, class, None);
        self.b.name(var, name);
        self.resource_vars.insert(var);
        if let Some((set, binding)) = binding {
            if matches!(
                class,
                StorageClass::Uniform | StorageClass::StorageBuffer | StorageClass::UniformConstant
            ) {
                self.b
                    .decorate(var, Decoration::DescriptorSet, [Operand::LiteralBit32(set)]);
                self.b
                    .decorate(var, Decoration::Binding, [Operand::LiteralBit32(binding)]);
            }
        }
        Ok(var)
    }

    /// The SPIR-V type of one descriptor (or push-constant / shader-record
    /// block) of `inner`, and its storage class; one id per kind, so arrays of
    /// resources and their elements agree.
    fn descriptor_type(&mut self, inner: &Ty, attrs: &[Attr]) -> Result<(Id, StorageClass)> {
        if let Ty::ConstantBuffer(k) = inner {
            let (layout, class) = self.cbuffer_class(attrs);
            return Ok((self.block_struct(*k, layout)?, class));
        }
        if let Ty::Accel | Ty::Sampler | Ty::Texture { .. } = inner {
            return Ok((
                self.spv(inner, Layout::None)?,
                StorageClass::UniformConstant,
            ));
        }
        let key = (inner.clone(), Layout::Std430, true);
        if let Some(id) = self.ty_cache.get(&key) {
            return Ok((*id, StorageClass::StorageBuffer));
        }
        let (elem, stride, rw, name) = match inner {
            Ty::StructuredBuffer(e, rw) => (
                self.spv(e, Layout::Std430)?,
                array_stride(e, Layout::Std430, &self.structs),
                *rw,
                if *rw {
                    "type.RWStructuredBuffer"
                } else {
                    "type.StructuredBuffer"
                },
            ),
            Ty::ByteAddress(rw) => (
                self.spv(&Ty::Sc(Sc::Uint), Layout::None)?,
                4,
                *rw,
                if *rw {
                    "type.RWByteAddressBuffer"
                } else {
                    "type.ByteAddressBuffer"
                },
            ),
            other => {
                return Err(Error::new(
                    Pos::default(),
                    format!(
                        "internal compiler error: `{}` is not a descriptor",
                        self.ty_name(other)
                    ),
                ))
            }
        };
        let rt = self.b.id();
        self.b.type_runtime_array_id(Some(rt), elem);
        self.b
            .decorate(rt, Decoration::ArrayStride, [Operand::LiteralBit32(stride)]);
        let st = self.b.id();
        self.b.type_struct_id(Some(st), [rt]);
        self.b.decorate(st, Decoration::Block, []);
        self.b
            .member_decorate(st, 0, Decoration::Offset, [Operand::LiteralBit32(0)]);
        if !rw {
            self.b.member_decorate(st, 0, Decoration::NonWritable, []);
        }
        self.b.name(st, name);
        self.ty_cache.insert(key, st);
        Ok((st, StorageClass::StorageBuffer))
    }

    /// A Block-decorated copy of struct `k` laid out for a buffer.
    fn block_struct(&mut self, k: u32, layout: Layout) -> Result<Id> {
        let key = (Ty::Struct(k), layout, true);
        if let Some(id) = self.ty_cache.get(&key) {
            return Ok(*id);
        }
        let id = self.struct_type(k, layout, true)?;
        self.ty_cache.insert(key, id);
        Ok(id)
    }

    fn declare_global_var(
        &mut self,
        v: &'a VarDecl,
        used: &mut HashSet<(u32, u32)>,
        next: &mut u32,
    ) -> Result<()> {
        let t = self.resolve_ty(&v.ty, "")?;
        let res = t.is_resource();
        let t = self.apply_dims(t, &v.dims, v.pos, res)?;
        self.decls.push((
            NamedDecl::Global(v.name.clone()),
            self.loc(v.pos, v.name.len() as u32),
        ));
        if t.is_resource() {
            let binding = match v.attrs.iter().find(|a| a.name == "vk::binding") {
                Some(a) => {
                    let b = a
                        .args
                        .first()
                        .map(|e| self.const_int(e))
                        .transpose()?
                        .unwrap_or(0) as u32;
                    let s = a
                        .args
                        .get(1)
                        .map(|e| self.const_int(e))
                        .transpose()?
                        .unwrap_or(0) as u32;
                    Some((s, b))
                }
                None => match &v.register {
                    Some(r) => Some((r.space, r.index)),
                    None if v.attrs.iter().any(|a| a.name == "vk::push_constant") => None,
                    None => Some(self.auto_binding(used, next)),
                },
            };
            let var = self.resource_var(&t, &v.attrs, binding, &v.name)?;
            let shown = match &t {
                Ty::ConstantBuffer(k) => Ty::Struct(*k),
                other => other.clone(),
            };
            self.global_decls.push((var, v.name.clone(), shown, v.pos));
            let (layout, class) = match &t {
                Ty::ConstantBuffer(_) => self.cbuffer_class(&v.attrs),
                Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => {
                    (Layout::Std430, StorageClass::StorageBuffer)
                }
                _ => {
                    let mut inner = &t;
                    while let Ty::Array(e, _) | Ty::RtArray(e) = inner {
                        inner = e;
                    }
                    match inner {
                        Ty::ConstantBuffer(_) => self.cbuffer_class(&v.attrs),
                        Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => {
                            (Layout::Std430, StorageClass::StorageBuffer)
                        }
                        _ => (Layout::None, StorageClass::UniformConstant),
                    }
                }
            };
            self.globals.insert(
                v.name.clone(),
                Global::Place(Place::Ptr {
                    ptr: var,
                    ty: t,
                    layout,
                    class,
                }),
            );
            return Ok(());
        }
        if matches!(t, Ty::RayQuery(_)) {
            return Err(unsupported(
                v.pos,
                "global RayQuery objects (declare them in the function)",
            ));
        }
        if v.mods.groupshared {
            let tid = self.spv(&t, Layout::None)?;
            let pty = self.b.type_pointer(None, StorageClass::Workgroup, tid);
            let var = self.global_var(pty, StorageClass::Workgroup, None);
            self.b.name(var, &v.name);
            self.global_decls
                .push((var, v.name.clone(), t.clone(), v.pos));
            if v.init.is_some() {
                return Err(Error::new(
                    v.pos,
                    "groupshared variables cannot have initializers",
                ));
            }
            self.globals.insert(
                v.name.clone(),
                Global::Place(Place::Ptr {
                    ptr: var,
                    ty: t,
                    layout: Layout::None,
                    class: StorageClass::Workgroup,
                }),
            );
            return Ok(());
        }
        if let Some(a) = v.attrs.iter().find(|a| a.name == "vk::constant_id") {
            return self.spec_constant(v, a, &t);
        }
        if !v.mods.is_static {
            return Err(unsupported(
                v.pos,
                "global variables outside a cbuffer (the implicit $Globals buffer); declare it `static` or put it in a cbuffer",
            )
            .len(v.name.len() as u32));
        }
        let mut deferred = None;
        let init = match &v.init {
            Some(e) => {
                let c = self.const_value(e, &t)?;
                if c.is_none() {
                    // Computed at the start of every entry point, as DXC does.
                    deferred = Some(e);
                }
                c
            }
            None => None,
        };
        // Scalars and vectors that never change are used as constants directly.
        if v.mods.is_const && matches!(t, Ty::Sc(_) | Ty::Vec(..)) {
            if let (Ty::Sc(s), Some(e)) = (&t, &v.init) {
                if let Some(c) = self.const_eval(e)? {
                    let c = match (s, c) {
                        (Sc::Float, c) => CVal::F(c.as_f64()),
                        (_, CVal::F(f)) => CVal::I(f as i64),
                        (_, c) => c,
                    };
                    self.const_items.insert(v.name.clone(), c);
                }
            }
            if let Some(id) = init {
                self.globals
                    .insert(v.name.clone(), Global::Const(Val { id, ty: t }));
                return Ok(());
            }
        }
        let tid = self.spv(&t, Layout::None)?;
        let pty = self.b.type_pointer(None, StorageClass::Private, tid);
        let init = match init {
            Some(i) => i,
            None => self.b.constant_null(tid),
        };
        let var = self.global_var(pty, StorageClass::Private, Some(init));
        self.b.name(var, &v.name);
        self.global_decls
            .push((var, v.name.clone(), t.clone(), v.pos));
        if let Some(e) = deferred {
            self.deferred_inits.push((var, t.clone(), e));
        }
        self.globals.insert(
            v.name.clone(),
            Global::Place(Place::Ptr {
                ptr: var,
                ty: t,
                layout: Layout::None,
                class: StorageClass::Private,
            }),
        );
        Ok(())
    }

    /// `[[vk::constant_id(N)]] const T name = default;`: a specialization constant.
    fn spec_constant(&mut self, v: &VarDecl, a: &Attr, t: &Ty) -> Result<()> {
        let id_expr = a
            .args
            .first()
            .ok_or_else(|| Error::new(a.pos, "vk::constant_id needs an id"))?;
        let spec_id = self.const_int(id_expr)? as u32;
        let Ty::Sc(s) = t else {
            return Err(unsupported(
                v.pos,
                "specialization constants that are not scalars",
            ));
        };
        let default = match &v.init {
            Some(e) => self.const_eval(e)?.ok_or_else(|| {
                Error::new(e.pos, "a specialization constant needs a constant default")
            })?,
            None => {
                return Err(Error::new(
                    v.pos,
                    "a specialization constant needs a default value",
                ))
            }
        };
        let tid = self.sc_id(*s);
        let id = match s {
            Sc::Bool => {
                let on = default.as_f64() != 0.0;
                let id = self.b.id();
                let op = if on {
                    Op::SpecConstantTrue
                } else {
                    Op::SpecConstantFalse
                };
                self.b.insert_types_global_values(
                    InsertPoint::End,
                    Instruction::new(op, Some(tid), Some(id), vec![]),
                );
                id
            }
            Sc::Float => self
                .b
                .spec_constant_bit32(tid, (default.as_f64() as f32).to_bits()),
            _ => {
                let i = match default {
                    CVal::I(i) => i,
                    CVal::F(f) => f as i64,
                };
                self.b.spec_constant_bit32(tid, i as u32)
            }
        };
        self.b
            .decorate(id, Decoration::SpecId, [Operand::LiteralBit32(spec_id)]);
        self.b.name(id, v.name.clone());
        self.globals
            .insert(v.name.clone(), Global::Const(Val { id, ty: t.clone() }));
        Ok(())
    }

    // ---- types and constants -------------------------------------------

    fn sc_id(&mut self, s: Sc) -> Id {
        match s {
            Sc::Bool => self.b.type_bool(),
            Sc::Int => self.b.type_int(32, 1),
            Sc::Uint => self.b.type_int(32, 0),
            Sc::Float => self.b.type_float(32, None),
        }
    }

    fn ty_id(&mut self, t: &Ty) -> Result<Id> {
        self.spv(t, Layout::None)
    }

    /// The SPIR-V type of `t` laid out per `layout`.
    fn spv(&mut self, t: &Ty, layout: Layout) -> Result<Id> {
        let layout = match t {
            Ty::Struct(_) | Ty::Array(..) => layout,
            // Buffers hold no bools (Vulkan forbids them there); DXC stores uints.
            Ty::Sc(Sc::Bool) | Ty::Vec(Sc::Bool, _) if layout != Layout::None => {
                return self.spv(&t.with_scalar(Sc::Uint), Layout::None);
            }
            _ => Layout::None,
        };
        let key = (t.clone(), layout, false);
        if let Some(id) = self.ty_cache.get(&key) {
            return Ok(*id);
        }
        let id = match t {
            Ty::Void => self.b.type_void(),
            Ty::Sc(s) => self.sc_id(*s),
            Ty::Vec(s, n) => {
                let e = self.sc_id(*s);
                self.b.type_vector(e, *n as u32)
            }
            Ty::Mat(s, r, c) => {
                let e = self.sc_id(*s);
                let col = self.b.type_vector(e, *c as u32);
                self.b.type_matrix(col, *r as u32)
            }
            Ty::Array(e, n) => {
                let eid = self.spv(e, layout)?;
                let len = self.const_u32(*n);
                let id = self.b.id();
                self.b.type_array_id(Some(id), eid, len);
                if layout != Layout::None {
                    let stride = array_stride(e, layout, &self.structs);
                    self.b
                        .decorate(id, Decoration::ArrayStride, [Operand::LiteralBit32(stride)]);
                }
                id
            }
            Ty::RtArray(e) => {
                let eid = self.spv(e, layout)?;
                self.b.type_runtime_array(eid)
            }
            Ty::Struct(k) => self.struct_type(*k, layout, false)?,
            Ty::Accel => {
                self.ray_tracing_caps();
                self.b.type_acceleration_structure_khr()
            }
            Ty::RayQuery(_) => {
                self.cap(Capability::RayQueryKHR);
                self.ext("SPV_KHR_ray_query");
                self.b.type_ray_query_khr()
            }
            Ty::Sampler => self.b.type_sampler(),
            Ty::Texture { dim, sc, n, rw } => {
                let st = self.sc_id(if *sc == Sc::Bool { Sc::Uint } else { *sc });
                let (d, arrayed) = match dim {
                    Dim::D1 => (spirv::Dim::Dim1D, 0),
                    Dim::D2 => (spirv::Dim::Dim2D, 0),
                    Dim::D3 => (spirv::Dim::Dim3D, 0),
                    Dim::Cube => (spirv::Dim::DimCube, 0),
                    Dim::D2Array => (spirv::Dim::Dim2D, 1),
                };
                if *dim == Dim::D1 {
                    self.cap(if *rw {
                        Capability::Image1D
                    } else {
                        Capability::Sampled1D
                    });
                }
                let format = if *rw {
                    self.image_format(*sc, *n)
                } else {
                    spirv::ImageFormat::Unknown
                };
                if *rw && *n == 2 {
                    self.cap(Capability::StorageImageExtendedFormats);
                }
                if *rw && format == spirv::ImageFormat::Unknown {
                    self.cap(Capability::StorageImageReadWithoutFormat);
                    self.cap(Capability::StorageImageWriteWithoutFormat);
                }
                self.b
                    .type_image(st, d, 0, arrayed, 0, if *rw { 2 } else { 1 }, format, None)
            }
            Ty::StructuredBuffer(..) | Ty::ByteAddress(_) | Ty::ConstantBuffer(_) => {
                return Ok(self.descriptor_type(t, &[])?.0);
            }
        };
        self.ty_cache.insert(key, id);
        Ok(id)
    }

    fn image_format(&self, sc: Sc, n: u8) -> spirv::ImageFormat {
        use spirv::ImageFormat as F;
        match (sc, n) {
            (Sc::Float, 1) => F::R32f,
            (Sc::Float, 2) => F::Rg32f,
            (Sc::Float, 4) => F::Rgba32f,
            (Sc::Uint, 1) => F::R32ui,
            (Sc::Uint, 2) => F::Rg32ui,
            (Sc::Uint, 4) => F::Rgba32ui,
            (Sc::Int, 1) => F::R32i,
            (Sc::Int, 2) => F::Rg32i,
            (Sc::Int, 4) => F::Rgba32i,
            _ => F::Unknown,
        }
    }

    fn ray_tracing_caps(&mut self) {
        self.cap(Capability::RayTracingKHR);
        self.ext("SPV_KHR_ray_tracing");
    }

    fn struct_type(&mut self, k: u32, layout: Layout, block: bool) -> Result<Id> {
        let def = self.structs[k as usize].clone();
        let mut members = Vec::new();
        for f in &def.fields {
            members.push(self.spv(&f.ty, layout)?);
        }
        let id = self.b.id();
        self.b.type_struct_id(Some(id), members);
        let name = if block {
            format!("type.{}", def.name.trim_start_matches("type."))
        } else {
            def.name.clone()
        };
        self.b.name(id, name);
        for (i, f) in def.fields.iter().enumerate() {
            self.b.member_name(id, i as u32, f.name.clone());
        }
        if block {
            self.b.decorate(id, Decoration::Block, []);
        }
        if layout != Layout::None {
            let offsets = struct_offsets(k, layout, &self.structs);
            for (i, (f, off)) in def.fields.iter().zip(offsets).enumerate() {
                let i = i as u32;
                self.b
                    .member_decorate(id, i, Decoration::Offset, [Operand::LiteralBit32(off)]);
                let mut inner = &f.ty;
                while let Ty::Array(e, _) = inner {
                    inner = e;
                }
                if let Ty::Mat(..) = inner {
                    let (_, stride, _) = matrix_layout(inner, f.row_major, layout);
                    self.b.member_decorate(
                        id,
                        i,
                        Decoration::MatrixStride,
                        [Operand::LiteralBit32(stride)],
                    );
                    // HLSL column-major storage is SPIR-V RowMajor (see the module doc).
                    let d = if f.row_major {
                        Decoration::ColMajor
                    } else {
                        Decoration::RowMajor
                    };
                    self.b.member_decorate(id, i, d, []);
                }
            }
        }
        Ok(id)
    }

    fn const_bits(&mut self, ty: Id, bits: u32) -> Id {
        if let Some(id) = self.consts.get(&(ty, bits)) {
            return *id;
        }
        let id = self.b.constant_bit32(ty, bits);
        self.consts.insert((ty, bits), id);
        self.const_ids.insert(id, bits);
        id
    }

    /// The value of a scalar constant made by this lowerer, as (scalar, bits).
    fn known(&self, v: &Val) -> Option<(Sc, u32)> {
        match v.ty {
            Ty::Sc(s @ (Sc::Int | Sc::Uint | Sc::Float)) => {
                self.const_ids.get(&v.id).map(|b| (s, *b))
            }
            _ => None,
        }
    }

    /// Folds an operator on two scalar constants, so trace operands, flags and
    /// SBT indices written as expressions stay constants in the module.
    fn fold(&mut self, op: BinOp, a: (Sc, u32), b: (Sc, u32)) -> Option<Val> {
        use BinOp::*;
        let (s, x, y) = (a.0, a.1, b.1);
        if s != b.0 {
            return None;
        }
        let v = match s {
            Sc::Float => {
                let (x, y) = (f32::from_bits(x), f32::from_bits(y));
                let r = match op {
                    Add => x + y,
                    Sub => x - y,
                    Mul => x * y,
                    Div => x / y,
                    _ => return None,
                };
                return Some(Val {
                    id: self.const_f32(r),
                    ty: Ty::Sc(Sc::Float),
                });
            }
            _ => match op {
                Add => x.wrapping_add(y),
                Sub => x.wrapping_sub(y),
                Mul => x.wrapping_mul(y),
                BitAnd => x & y,
                BitOr => x | y,
                BitXor => x ^ y,
                Shl if y < 32 => x << y,
                Shr if y < 32 && s == Sc::Uint => x >> y,
                Shr if y < 32 => ((x as i32) >> y) as u32,
                _ => return None,
            },
        };
        let t = self.sc_id(s);
        Some(Val {
            id: self.const_bits(t, v),
            ty: Ty::Sc(s),
        })
    }

    fn const_u32(&mut self, v: u32) -> Id {
        let t = self.sc_id(Sc::Uint);
        self.const_bits(t, v)
    }

    fn const_i32(&mut self, v: i32) -> Id {
        let t = self.sc_id(Sc::Int);
        self.const_bits(t, v as u32)
    }

    fn const_f32(&mut self, v: f32) -> Id {
        let t = self.sc_id(Sc::Float);
        self.const_bits(t, v.to_bits())
    }

    fn const_bool(&mut self, v: bool) -> Id {
        let t = self.sc_id(Sc::Bool);
        let key = (t, v as u32);
        if let Some(id) = self.consts.get(&key) {
            return *id;
        }
        let id = if v {
            self.b.constant_true(t)
        } else {
            self.b.constant_false(t)
        };
        self.consts.insert(key, id);
        id
    }

    fn const_scalar(&mut self, s: Sc, f: f64, i: i64) -> Id {
        match s {
            Sc::Bool => self.const_bool(i != 0 || f != 0.0),
            Sc::Int => self.const_i32(i as i32),
            Sc::Uint => self.const_u32(i as u32),
            Sc::Float => self.const_f32(f as f32),
        }
    }

    /// A constant of numeric type `t` with every component `v`.
    fn const_splat(&mut self, t: &Ty, v: f64) -> Result<Id> {
        let s = t.scalar().unwrap_or(Sc::Float);
        let c = self.const_scalar(s, v, v as i64);
        Ok(match t {
            Ty::Sc(_) => c,
            Ty::Vec(_, n) => {
                let tid = self.ty_id(t)?;
                self.b.constant_composite(tid, vec![c; *n as usize])
            }
            Ty::Mat(s, r, cols) => {
                let row = Ty::Vec(*s, *cols);
                let rid = self.const_splat(&row, v)?;
                let tid = self.ty_id(t)?;
                self.b.constant_composite(tid, vec![rid; *r as usize])
            }
            _ => c,
        })
    }

    /// Evaluates an integer constant expression (array sizes, attributes, enums).
    fn const_int(&mut self, e: &Expr) -> Result<i64> {
        match self.const_eval(e)? {
            Some(CVal::I(v)) => Ok(v),
            Some(CVal::F(f)) => Ok(f as i64),
            _ => Err(Error::new(e.pos, "expected an integer constant")),
        }
    }

    fn const_eval(&mut self, e: &Expr) -> Result<Option<CVal>> {
        Ok(match &e.kind {
            ExprKind::Int(v, _) => Some(CVal::I(*v as i64)),
            ExprKind::Float(f) => Some(CVal::F(*f)),
            ExprKind::Bool(b) => Some(CVal::I(*b as i64)),
            ExprKind::Ident(n) => {
                if let Some(v) = builtin_constant(n) {
                    return Ok(Some(CVal::I(v as i64)));
                }
                self.enum_value(n)
            }
            ExprKind::Unary(op, a) => {
                let Some(a) = self.const_eval(a)? else {
                    return Ok(None);
                };
                match (op, a) {
                    (UnOp::Neg, CVal::I(v)) => Some(CVal::I(v.wrapping_neg())),
                    (UnOp::Neg, CVal::F(v)) => Some(CVal::F(-v)),
                    (UnOp::Plus, v) => Some(v),
                    (UnOp::BitNot, CVal::I(v)) => Some(CVal::I(!v & 0xffff_ffff)),
                    (UnOp::Not, CVal::I(v)) => Some(CVal::I((v == 0) as i64)),
                    _ => None,
                }
            }
            ExprKind::Binary(op, a, b) => {
                let (Some(a), Some(b)) = (self.const_eval(a)?, self.const_eval(b)?) else {
                    return Ok(None);
                };
                match (a, b) {
                    (CVal::I(a), CVal::I(b)) => {
                        let v = match op {
                            BinOp::Add => a.wrapping_add(b),
                            BinOp::Sub => a.wrapping_sub(b),
                            BinOp::Mul => a.wrapping_mul(b),
                            BinOp::Div | BinOp::Rem if b == 0 => {
                                return Err(Error::new(e.pos, "division by zero in a constant"))
                            }
                            BinOp::Div => a.wrapping_div(b),
                            BinOp::Rem => a.wrapping_rem(b),
                            BinOp::Shl => a.wrapping_shl(b as u32),
                            BinOp::Shr => a.wrapping_shr(b as u32),
                            BinOp::BitAnd => a & b,
                            BinOp::BitOr => a | b,
                            BinOp::BitXor => a ^ b,
                            BinOp::And => (a != 0 && b != 0) as i64,
                            BinOp::Or => (a != 0 || b != 0) as i64,
                            BinOp::Eq => (a == b) as i64,
                            BinOp::Ne => (a != b) as i64,
                            BinOp::Lt => (a < b) as i64,
                            BinOp::Le => (a <= b) as i64,
                            BinOp::Gt => (a > b) as i64,
                            BinOp::Ge => (a >= b) as i64,
                        };
                        Some(CVal::I(v))
                    }
                    (a, b) => {
                        let (a, b) = (a.as_f64(), b.as_f64());
                        match op {
                            BinOp::Add => Some(CVal::F(a + b)),
                            BinOp::Sub => Some(CVal::F(a - b)),
                            BinOp::Mul => Some(CVal::F(a * b)),
                            BinOp::Div => Some(CVal::F(a / b)),
                            _ => None,
                        }
                    }
                }
            }
            ExprKind::Cast(t, a) => {
                let Some(v) = self.const_eval(a)? else {
                    return Ok(None);
                };
                match split_numeric(&t.name) {
                    Some(("float" | "half", 0, 0)) => Some(CVal::F(v.as_f64())),
                    Some(("int" | "uint" | "dword", 0, 0)) => Some(CVal::I(v.as_f64() as i64)),
                    _ => None,
                }
            }
            ExprKind::Ternary(c, a, b) => match self.const_eval(c)? {
                Some(CVal::I(c)) => {
                    if c != 0 {
                        self.const_eval(a)?
                    } else {
                        self.const_eval(b)?
                    }
                }
                _ => None,
            },
            _ => None,
        })
    }

    fn enum_value(&self, n: &str) -> Option<CVal> {
        if !self.cur_ns.is_empty() {
            if let Some(c) = self.const_items.get(&format!("{}{n}", self.cur_ns)) {
                return Some(c.clone());
            }
        }
        self.const_items.get(n).cloned()
    }

    /// A constant of type `t` from an initializer, or `None` when it is not constant.
    fn const_value(&mut self, e: &Expr, t: &Ty) -> Result<Option<Id>> {
        let mut flat = Vec::new();
        if !self.const_flatten(e, &mut flat)? {
            return Ok(None);
        }
        // A single scalar initializes every component (`float3 v = 0`).
        if flat.len() == 1 && t.is_numeric() {
            return Ok(Some(self.const_splat(t, flat[0].as_f64())?));
        }
        let mut it = flat.into_iter();
        let id = self.const_build(t, &mut it, e.pos)?;
        if it.next().is_some() {
            return Err(Error::new(e.pos, "too many initializers"));
        }
        Ok(Some(id))
    }

    fn const_flatten(&mut self, e: &Expr, out: &mut Vec<CVal>) -> Result<bool> {
        match &e.kind {
            ExprKind::InitList(items) | ExprKind::Construct(_, items) => {
                for i in items {
                    if !self.const_flatten(i, out)? {
                        return Ok(false);
                    }
                }
                Ok(true)
            }
            _ => match self.const_eval(e)? {
                Some(v) => {
                    out.push(v);
                    Ok(true)
                }
                None => Ok(false),
            },
        }
    }

    fn const_build(&mut self, t: &Ty, it: &mut std::vec::IntoIter<CVal>, pos: Pos) -> Result<Id> {
        let mut next = |this: &mut Self, s: Sc| -> Result<Id> {
            let v = it
                .next()
                .ok_or_else(|| Error::new(pos, "too few initializers"))?;
            let f = v.as_f64();
            let i = match v {
                CVal::I(i) => i,
                CVal::F(f) => f as i64,
            };
            Ok(this.const_scalar(s, f, i))
        };
        match t {
            Ty::Sc(s) => next(self, *s),
            Ty::Vec(s, n) => {
                let mut c = Vec::new();
                for _ in 0..*n {
                    c.push(next(self, *s)?);
                }
                let tid = self.ty_id(t)?;
                Ok(self.b.constant_composite(tid, c))
            }
            Ty::Mat(s, r, cols) => {
                let mut rows = Vec::new();
                for _ in 0..*r {
                    let mut c = Vec::new();
                    for _ in 0..*cols {
                        c.push(next(self, *s)?);
                    }
                    let rt = self.ty_id(&Ty::Vec(*s, *cols))?;
                    rows.push(self.b.constant_composite(rt, c));
                }
                let tid = self.ty_id(t)?;
                Ok(self.b.constant_composite(tid, rows))
            }
            Ty::Array(e, n) => {
                let mut c = Vec::new();
                for _ in 0..*n {
                    c.push(self.const_build(e, it, pos)?);
                }
                let tid = self.ty_id(t)?;
                Ok(self.b.constant_composite(tid, c))
            }
            Ty::Struct(k) => {
                let fields = self.structs[*k as usize].fields.clone();
                let mut c = Vec::new();
                for f in &fields {
                    c.push(self.const_build(&f.ty, it, pos)?);
                }
                let tid = self.ty_id(t)?;
                Ok(self.b.constant_composite(tid, c))
            }
            _ => Err(Error::new(pos, "this type has no constant initializer")),
        }
    }

    // ---- functions -----------------------------------------------------

    /// Lowers the given entry points and everything they call; returns the module.
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
            let mut entry_id = sig.id;
            if let Some((w, io)) = wrappers.get(&e) {
                entry_id = *w;
                vars.extend(io.iter().copied());
            }
            let vars: Vec<Id> = vars.into_iter().collect();
            self.b.entry_point(
                stage.model().expect("HLSL stages have an execution model"),
                entry_id,
                sig.name.clone(),
                vars,
            );
            if stage == Stage::Compute {
                self.b
                    .execution_mode(sig.id, spirv::ExecutionMode::LocalSize, sig.numthreads);
            } else if stage == Stage::Fragment {
                // Vulkan requires it; HLSL's SV_Position has its origin at the top left.
                self.b
                    .execution_mode(entry_id, spirv::ExecutionMode::OriginUpperLeft, []);
            } else {
                self.ray_tracing_caps();
            }
        }
        let debug = self.emit_debug_info();
        let mut module = self.b.module();
        hoist_variables(&mut module);
        if let Some(d) = &debug {
            Self::place_definitions(&mut module, d);
        }
        drop_unused_globals(&mut module);
        use rspirv::binary::Assemble;
        Ok((module.assemble(), self.decls))
    }

    fn check_recursion(&self) -> Result<()> {
        // Depth-first search for a cycle in the call graph.
        fn visit(
            k: usize,
            calls: &HashMap<usize, BTreeSet<usize>>,
            state: &mut HashMap<usize, u8>,
        ) -> Option<usize> {
            match state.get(&k) {
                Some(1) => return Some(k),
                Some(2) => return None,
                _ => {}
            }
            state.insert(k, 1);
            for c in calls.get(&k).into_iter().flatten() {
                if let Some(r) = visit(*c, calls, state) {
                    return Some(r);
                }
            }
            state.insert(k, 2);
            None
        }
        let mut state = HashMap::new();
        let mut keys: Vec<usize> = self.fn_calls.keys().copied().collect();
        keys.sort_unstable();
        for k in keys {
            if let Some(r) = visit(k, &self.fn_calls, &mut state) {
                let f = self.funcs[r].func;
                return Err(Error::new(
                    f.pos,
                    format!(
                        "function `{}` is recursive; HLSL does not allow recursion",
                        f.name
                    ),
                )
                .len(f.name.len() as u32));
            }
        }
        Ok(())
    }

    fn lower_function(&mut self, k: usize) -> Result<()> {
        let sig = self.funcs[k].clone();
        let f = sig.func;
        self.cur_fn = k;
        self.cur_ns = f.ns.clone();
        self.cur_stage = sig.stage;
        self.ret_ty = sig.ret.clone();
        self.scopes = vec![HashMap::new()];
        self.flow.clear();
        self.term = false;
        let ret_id = self.ty_id(&sig.ret)?;
        // A pixel entry point is lowered as an ordinary function (`src.NAME`,
        // as DXC names it) that a wrapper calls; see `pixel_wrapper`.
        if let Some(stage) = sig.stage.filter(|s| *s != Stage::Fragment) {
            if sig.ret != Ty::Void {
                return Err(unsupported(
                    f.ret.pos,
                    format!("{} entry points returning a value", stage.hlsl_name()),
                ));
            }
            let fty = self.b.type_function(ret_id, []);
            self.b
                .begin_function(ret_id, Some(sig.id), spirv::FunctionControl::NONE, fty)?;
            self.b.name(sig.id, f.name.clone());
            self.start_block(None)?;
            self.line(f.pos);
            self.this_place = None;
            self.bind_entry_params(f, &sig, stage)?;
            for (var, t, e) in self.deferred_inits.clone() {
                self.line(e.pos);
                let v = self.expr_as(e, &t)?;
                self.use_global(var);
                if self.term {
                    self.start_block(None)?;
                }
                self.b.store(var, v.id, None, [])?;
            }
        } else {
            let mut ptys = Vec::new();
            for p in &sig.params {
                if matches!(p.ty, Ty::RayQuery(_)) {
                    return Err(unsupported(f.pos, "RayQuery function parameters"));
                }
                let (class, _) = self.param_class(&p.ty);
                let t = if p.ty.is_resource() {
                    self.descriptor_type(&p.ty, &[])?.0
                } else {
                    self.ty_id(&p.ty)?
                };
                ptys.push(self.b.type_pointer(None, class, t));
            }
            let fty = self.b.type_function(ret_id, ptys.clone());
            self.b
                .begin_function(ret_id, Some(sig.id), spirv::FunctionControl::NONE, fty)?;
            if sig.stage == Some(Stage::Fragment) {
                self.b.name(sig.id, format!("src.{}", sig.name));
            } else {
                self.b.name(sig.id, sig.name.clone());
            }
            let mut ptys = ptys.into_iter();
            let mut params = sig.params.iter();
            if let Some(k) = sig.this {
                // `this`, and each member by its bare name.
                let pty = ptys.next().unwrap_or_default();
                let p = params.next().map(|p| p.ty.clone()).unwrap_or(Ty::Struct(k));
                let id = self.b.function_parameter(pty)?;
                self.b.name(id, "this");
                let this = Place::Ptr {
                    ptr: id,
                    ty: p,
                    layout: Layout::None,
                    class: StorageClass::Function,
                };
                self.scopes[0].insert("this".to_string(), this.clone());
                self.this_place = Some(this);
            } else {
                self.this_place = None;
            }
            for ((p, decl), pty) in params.zip(&f.params).zip(ptys) {
                let id = self.b.function_parameter(pty)?;
                self.b.name(id, decl.name.clone());
                self.local_decls
                    .push((self.cur_fn, id, decl.name.clone(), p.ty.clone(), decl.pos));
                let (class, layout) = self.param_class(&p.ty);
                self.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: id,
                        ty: p.ty.clone(),
                        layout,
                        class,
                    },
                );
            }
            self.start_block(None)?;
        }
        let body = f.body.as_deref().unwrap_or(&[]);
        self.block(body)?;
        if !self.term {
            if sig.ret == Ty::Void {
                self.b.ret()?;
            } else {
                self.b.unreachable()?;
            }
        }
        self.b.end_function()?;
        Ok(())
    }

    /// How a parameter is passed: values by a Function-storage pointer (the
    /// caller's copy); resources by a pointer to the resource variable itself.
    fn param_class(&self, t: &Ty) -> (StorageClass, Layout) {
        match t {
            Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => {
                (StorageClass::StorageBuffer, Layout::Std430)
            }
            Ty::ConstantBuffer(_) => (StorageClass::Uniform, Layout::CBuffer),
            Ty::Accel | Ty::Sampler | Ty::Texture { .. } => {
                (StorageClass::UniformConstant, Layout::None)
            }
            _ => (StorageClass::Function, Layout::None),
        }
    }

    fn bind_entry_params(&mut self, f: &'a Function, sig: &FnSig, stage: Stage) -> Result<()> {
        for (i, (p, decl)) in sig.params.iter().zip(&f.params).enumerate() {
            let is_struct = matches!(p.ty, Ty::Struct(_));
            // DXR fixes the parameters by position: payload (or callable data)
            // first, `inout`; hit attributes second, `in`.
            let class = match (stage, i) {
                (Stage::ClosestHit | Stage::AnyHit | Stage::Miss, 0)
                    if is_struct && p.out && p.input =>
                {
                    Some(StorageClass::IncomingRayPayloadKHR)
                }
                (Stage::ClosestHit | Stage::AnyHit, 1) if is_struct && !p.out => {
                    Some(StorageClass::HitAttributeKHR)
                }
                (Stage::Callable, 0) if is_struct && p.out && p.input => {
                    Some(StorageClass::IncomingCallableDataKHR)
                }
                _ => None,
            };
            if let Some(class) = class {
                let var = self.rt_var(class, &p.ty)?;
                self.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: var,
                        ty: p.ty.clone(),
                        layout: Layout::None,
                        class,
                    },
                );
                continue;
            }
            if stage == Stage::Compute && !p.out {
                let Some((sem, spos)) = &decl.semantic else {
                    return Err(Error::new(
                        decl.pos,
                        "compute entry point parameters need a system-value semantic",
                    ));
                };
                let (bi, bty) = match sem.to_ascii_uppercase().as_str() {
                    "SV_DISPATCHTHREADID" => (BuiltIn::GlobalInvocationId, Ty::Vec(Sc::Uint, 3)),
                    "SV_GROUPTHREADID" => (BuiltIn::LocalInvocationId, Ty::Vec(Sc::Uint, 3)),
                    "SV_GROUPID" => (BuiltIn::WorkgroupId, Ty::Vec(Sc::Uint, 3)),
                    "SV_GROUPINDEX" => (BuiltIn::LocalInvocationIndex, Ty::Sc(Sc::Uint)),
                    _ => {
                        return Err(unsupported(
                            *spos,
                            format!("semantic `{sem}` on a compute parameter"),
                        ))
                    }
                };
                let v = self.read_builtin(bi, &bty)?;
                let v = self.convert(v, &p.ty, decl.pos, true)?;
                let var = self.local_var(&p.ty, &decl.name)?;
                self.b.store(var, v.id, None, [])?;
                self.scopes[0].insert(
                    decl.name.clone(),
                    Place::Ptr {
                        ptr: var,
                        ty: p.ty.clone(),
                        layout: Layout::None,
                        class: StorageClass::Function,
                    },
                );
                continue;
            }
            return Err(unsupported(
                decl.pos,
                format!("this parameter in a {} entry point", stage.hlsl_name()),
            )
            .len(decl.name.len() as u32)
            .note("ray-tracing entry points take `inout` payload / callable data and `in` hit attributes (structs)"));
        }
        Ok(())
    }

    /// The ray-tracing interface variable of `class` for type `t` (one per type).
    fn rt_var(&mut self, class: StorageClass, t: &Ty) -> Result<Id> {
        self.ray_tracing_caps();
        let key = (class, t.clone());
        let var = match self.rt_vars.get(&key) {
            Some(v) => *v,
            None => {
                let tid = self.ty_id(t)?;
                let pty = self.b.type_pointer(None, class, tid);
                let var = self.global_var(pty, class, None);
                let name = match class {
                    StorageClass::RayPayloadKHR => "payload",
                    StorageClass::IncomingRayPayloadKHR => "incoming.payload",
                    StorageClass::HitAttributeKHR => "hit.attributes",
                    StorageClass::CallableDataKHR => "callable.data",
                    _ => "incoming.callable.data",
                };
                self.b.name(var, name);
                if matches!(
                    class,
                    StorageClass::RayPayloadKHR | StorageClass::CallableDataKHR
                ) {
                    let n = self.next_location.entry(class).or_insert(0);
                    let loc = *n;
                    *n += 1;
                    self.b
                        .decorate(var, Decoration::Location, [Operand::LiteralBit32(loc)]);
                }
                self.rt_vars.insert(key, var);
                var
            }
        };
        self.use_global(var);
        Ok(var)
    }

    /// A module-scope variable, even while a function is being emitted.
    fn global_var(&mut self, pty: Id, class: StorageClass, init: Option<Id>) -> Id {
        let id = self.b.id();
        let mut ops = vec![Operand::StorageClass(class)];
        ops.extend(init.map(Operand::IdRef));
        self.b.insert_types_global_values(
            InsertPoint::End,
            Instruction::new(Op::Variable, Some(pty), Some(id), ops),
        );
        id
    }

    fn use_global(&mut self, id: Id) {
        self.fn_used.entry(self.cur_fn).or_default().insert(id);
    }

    fn read_builtin(&mut self, bi: BuiltIn, t: &Ty) -> Result<Val> {
        let var = match self.builtins.get(&bi) {
            Some(v) => *v,
            None => {
                let tid = self.ty_id(t)?;
                let pty = self.b.type_pointer(None, StorageClass::Input, tid);
                let var = self.global_var(pty, StorageClass::Input, None);
                self.b
                    .decorate(var, Decoration::BuiltIn, [Operand::BuiltIn(bi)]);
                self.b.name(var, format!("{bi:?}"));
                self.builtins.insert(bi, var);
                var
            }
        };
        self.use_global(var);
        let tid = self.ty_id(t)?;
        let id = self.b.load(tid, None, var, None, [])?;
        Ok(Val { id, ty: t.clone() })
    }

    fn start_block(&mut self, label: Option<Id>) -> Result<Id> {
        let l = self.b.begin_block(label)?;
        self.cur_label = l;
        self.term = false;
        Ok(l)
    }

    fn line(&mut self, pos: Pos) {
        if self.term || self.b.selected_block().is_none() {
            return;
        }
        if let Some(f) = self.file_ids.get(pos.file as usize) {
            let f = *f;
            self.b.line(f, pos.line, pos.col);
        }
    }

    /// Emits one instruction with a result; starts a dead block after a terminator.
    fn op(&mut self, op: Op, ty: Id, args: &[Id]) -> Result<Id> {
        self.inst(
            op,
            Some(ty),
            args.iter().map(|a| Operand::IdRef(*a)).collect(),
        )
    }

    fn inst(&mut self, op: Op, ty: Option<Id>, operands: Vec<Operand>) -> Result<Id> {
        if self.term {
            self.start_block(None)?;
        }
        let id = self.b.id();
        // Pointers reached through a NonUniformResourceIndex stay NonUniform.
        let nonuniform = op == Op::AccessChain
            && operands.iter().enumerate().any(|(i, o)| {
                matches!(o, Operand::IdRef(x)
                    if (i == 0 && self.nonuniform_ptrs.contains(x)) || (i > 0 && self.nonuniform.contains(x)))
            });
        let inst = Instruction::new(op, ty, ty.map(|_| id), operands);
        self.b.insert_into_block(InsertPoint::End, inst)?;
        if nonuniform {
            self.b.decorate(id, Decoration::NonUniform, []);
            self.nonuniform_ptrs.insert(id);
        }
        Ok(id)
    }

    fn local_var(&mut self, t: &Ty, name: &str) -> Result<Id> {
        let tid = self.ty_id(t)?;
        let pty = self.b.type_pointer(None, StorageClass::Function, tid);
        if self.term {
            self.start_block(None)?;
        }
        // Placed here, hoisted to the entry block when the module is finished.
        let id = self.b.variable(pty, None, StorageClass::Function, None);
        if !name.is_empty() {
            self.b.name(id, name);
        }
        Ok(id)
    }

    // ---- statements ----------------------------------------------------

    fn block(&mut self, stmts: &'a [Stmt]) -> Result<()> {
        self.scopes.push(HashMap::new());
        for s in stmts {
            if self.term {
                break; // the rest is unreachable
            }
            self.stmt(s)?;
        }
        self.scopes.pop();
        Ok(())
    }

    fn cond(&mut self, e: &'a Expr) -> Result<Id> {
        let v = self.expr(e)?;
        if !matches!(v.ty, Ty::Sc(_)) {
            return Err(Error::new(
                e.pos,
                format!(
                    "condition must be a scalar, found `{}`",
                    self.ty_name(&v.ty)
                ),
            ));
        }
        Ok(self.convert(v, &Ty::Sc(Sc::Bool), e.pos, false)?.id)
    }

    fn branch(&mut self, to: Id) -> Result<()> {
        if !self.term {
            self.b.branch(to)?;
            self.term = true;
        }
        Ok(())
    }

    fn stmt(&mut self, s: &'a Stmt) -> Result<()> {
        self.line(s.pos);
        match &s.kind {
            StmtKind::Empty => {}
            StmtKind::Block(b) => self.block(b)?,
            StmtKind::Expr(e) => {
                self.expr_void(e)?;
            }
            StmtKind::Decl(vars) => {
                for v in vars {
                    self.local_decl(v)?;
                }
            }
            StmtKind::If(c, then, els) => {
                let c = self.cond(c)?;
                let (lt, lm) = (self.b.id(), self.b.id());
                let le = if els.is_some() { self.b.id() } else { lm };
                self.b.selection_merge(lm, spirv::SelectionControl::NONE)?;
                self.b.branch_conditional(c, lt, le, [])?;
                self.start_block(Some(lt))?;
                self.scoped(then)?;
                self.branch(lm)?;
                if let Some(e) = els {
                    self.start_block(Some(le))?;
                    self.scoped(e)?;
                    self.branch(lm)?;
                }
                self.start_block(Some(lm))?;
            }
            StmtKind::While(c, body) => self.lower_loop(Some(c), None, body, false)?,
            StmtKind::DoWhile(body, c) => self.lower_loop(Some(c), None, body, true)?,
            StmtKind::For(init, c, step, body) => {
                self.scopes.push(HashMap::new());
                if let Some(i) = init {
                    self.stmt(i)?;
                }
                self.lower_loop(c.as_ref(), step.as_ref(), body, false)?;
                self.scopes.pop();
            }
            StmtKind::Break => {
                let Some(f) = self.flow.last() else {
                    return Err(Error::new(s.pos, "`break` outside a loop or switch").len(5));
                };
                let to = f.brk;
                self.b.branch(to)?;
                self.term = true;
            }
            StmtKind::Continue => {
                let Some(to) = self.flow.iter().rev().find_map(|f| f.cont) else {
                    return Err(Error::new(s.pos, "`continue` outside a loop").len(8));
                };
                self.b.branch(to)?;
                self.term = true;
            }
            StmtKind::Return(v) => {
                let ret = self.ret_ty.clone();
                match (v, ret == Ty::Void) {
                    (None, true) => self.b.ret()?,
                    (Some(e), false) => {
                        let v = self.expr(e)?;
                        let v = self.convert(v, &ret, e.pos, false)?;
                        if self.term {
                            self.start_block(None)?;
                        }
                        self.b.ret_value(v.id)?;
                    }
                    (Some(e), true) => return Err(Error::new(e.pos, "this function returns void")),
                    (None, false) => return Err(Error::new(s.pos, "missing return value").len(6)),
                }
                self.term = true;
            }
            StmtKind::Discard => {
                match self.cur_stage {
                    Some(Stage::Fragment) => {}
                    Some(st) => {
                        return Err(Error::new(
                            s.pos,
                            format!(
                                "`discard` is only available in pixel shaders, not {} shaders",
                                st.hlsl_name()
                            ),
                        )
                        .len(7))
                    }
                    None => {
                        self.fn_derivs
                            .entry(self.cur_fn)
                            .or_insert(("discard", s.pos));
                    }
                }
                if self.term {
                    self.start_block(None)?;
                }
                // OpKill: SPIR-V 1.4 without SPV_KHR_terminate_invocation, as Vulkan 1.2 accepts.
                self.b.kill()?;
                self.term = true;
            }
            StmtKind::Switch(sel, cases) => self.lower_switch(sel, cases)?,
        }
        Ok(())
    }

    fn scoped(&mut self, s: &'a Stmt) -> Result<()> {
        self.scopes.push(HashMap::new());
        let r = self.stmt(s);
        self.scopes.pop();
        r
    }

    fn lower_loop(
        &mut self,
        cond: Option<&'a Expr>,
        step: Option<&'a Expr>,
        body: &'a Stmt,
        do_while: bool,
    ) -> Result<()> {
        let (header, body_l, cont, merge) = (self.b.id(), self.b.id(), self.b.id(), self.b.id());
        self.branch(header)?;
        self.start_block(Some(header))?;
        self.b
            .loop_merge(merge, cont, spirv::LoopControl::NONE, [])?;
        if do_while {
            self.b.branch(body_l)?;
        } else {
            let check = self.b.id();
            self.b.branch(check)?;
            self.start_block(Some(check))?;
            match cond {
                Some(c) => {
                    let c = self.cond(c)?;
                    self.b.branch_conditional(c, body_l, merge, [])?;
                }
                None => self.b.branch(body_l)?,
            }
        }
        self.start_block(Some(body_l))?;
        self.flow.push(Flow {
            brk: merge,
            cont: Some(cont),
        });
        let r = self.scoped(body);
        self.flow.pop();
        r?;
        self.branch(cont)?;
        self.start_block(Some(cont))?;
        if do_while {
            let c = match cond {
                Some(c) => self.cond(c)?,
                None => self.const_bool(true),
            };
            self.b.branch_conditional(c, header, merge, [])?;
        } else {
            if let Some(s) = step {
                self.expr_void(s)?;
            }
            self.b.branch(header)?;
        }
        self.term = true;
        self.start_block(Some(merge))?;
        Ok(())
    }

    fn lower_switch(&mut self, sel: &'a Expr, cases: &'a [Case]) -> Result<()> {
        let v = self.expr(sel)?;
        let v = match v.ty {
            Ty::Sc(Sc::Int) | Ty::Sc(Sc::Uint) => v,
            Ty::Sc(Sc::Bool) => self.convert(v, &Ty::Sc(Sc::Int), sel.pos, false)?,
            _ => return Err(Error::new(sel.pos, "switch needs an integer scalar")),
        };
        let merge = self.b.id();
        let labels: Vec<Id> = cases.iter().map(|_| self.b.id()).collect();
        let mut default = merge;
        let mut targets = Vec::new();
        let mut seen = HashSet::new();
        for (c, l) in cases.iter().zip(&labels) {
            for lab in &c.labels {
                match lab {
                    None => default = *l,
                    Some(e) => {
                        let n = self.const_int(e)? as u32;
                        if !seen.insert(n) {
                            return Err(Error::new(e.pos, format!("duplicate case {n}")));
                        }
                        targets.push((Operand::LiteralBit32(n), *l));
                    }
                }
            }
        }
        self.b
            .selection_merge(merge, spirv::SelectionControl::NONE)?;
        self.b.switch(v.id, default, targets)?;
        self.flow.push(Flow {
            brk: merge,
            cont: None,
        });
        for (i, (c, l)) in cases.iter().zip(&labels).enumerate() {
            self.start_block(Some(*l))?;
            self.scopes.push(HashMap::new());
            let mut r = Ok(());
            for s in &c.body {
                if self.term {
                    break;
                }
                r = self.stmt(s);
                if r.is_err() {
                    break;
                }
            }
            self.scopes.pop();
            if let Err(e) = r {
                self.flow.pop();
                return Err(e);
            }
            // Falling through to the next case is allowed in SPIR-V too.
            let next = labels.get(i + 1).copied().unwrap_or(merge);
            self.branch(next)?;
        }
        self.flow.pop();
        self.start_block(Some(merge))?;
        Ok(())
    }

    fn local_decl(&mut self, v: &'a VarDecl) -> Result<()> {
        let ns = self.cur_ns.clone();
        let base = self.resolve_ty(&v.ty, &ns)?;
        // `float a[] = {...}` takes its size from the initializer.
        let t = if v.dims.first().is_some_and(|d| d.is_none()) {
            let n = match &v.init {
                Some(Expr {
                    kind: ExprKind::InitList(items),
                    ..
                }) => items.len() as u32,
                _ => return Err(Error::new(v.pos, "array size missing")),
            };
            let inner = self.apply_dims(base, &v.dims[1..], v.pos, false)?;
            Ty::Array(Box::new(inner), n)
        } else {
            self.apply_dims(base, &v.dims, v.pos, false)?
        };
        if t.is_resource() {
            return Err(unsupported(v.pos, "local resource variables").len(v.name.len() as u32));
        }
        if v.mods.is_static {
            let init = match &v.init {
                Some(e) => Some(self.const_value(e, &t)?.ok_or_else(|| {
                    unsupported(e.pos, "non-constant initializer of a static local")
                })?),
                None => None,
            };
            let tid = self.ty_id(&t)?;
            let init = match init {
                Some(i) => i,
                None => self.b.constant_null(tid),
            };
            let pty = self.b.type_pointer(None, StorageClass::Private, tid);
            let b = &mut self.b;
            // Private variables live at module scope even when declared in a function.
            let var = b.id();
            b.insert_types_global_values(
                InsertPoint::End,
                Instruction::new(
                    Op::Variable,
                    Some(pty),
                    Some(var),
                    vec![
                        Operand::StorageClass(StorageClass::Private),
                        Operand::IdRef(init),
                    ],
                ),
            );
            b.name(var, v.name.clone());
            self.use_global(var);
            self.bind(
                &v.name,
                Place::Ptr {
                    ptr: var,
                    ty: t,
                    layout: Layout::None,
                    class: StorageClass::Private,
                },
            );
            return Ok(());
        }
        let var = self.local_var(&t, &v.name)?;
        self.local_decls
            .push((self.cur_fn, var, v.name.clone(), t.clone(), v.pos));
        if let Some(init) = &v.init {
            let val = self.expr_as(init, &t)?;
            if self.term {
                self.start_block(None)?;
            }
            self.b.store(var, val.id, None, [])?;
        }
        self.bind(
            &v.name,
            Place::Ptr {
                ptr: var,
                ty: t,
                layout: Layout::None,
                class: StorageClass::Function,
            },
        );
        Ok(())
    }

    fn bind(&mut self, name: &str, p: Place) {
        if let Some(s) = self.scopes.last_mut() {
            s.insert(name.to_string(), p);
        }
    }

    // ---- places --------------------------------------------------------

    fn lookup(&mut self, name: &str, pos: Pos) -> Result<Place> {
        for s in self.scopes.iter().rev() {
            if let Some(p) = s.get(name) {
                return Ok(p.clone());
            }
        }
        if let Some(this) = self.this_place.clone() {
            if let Ty::Struct(k) = this.ty() {
                if self.structs[*k as usize]
                    .fields
                    .iter()
                    .any(|f| f.name == name)
                {
                    return self.member(this, name, pos);
                }
            }
        }
        let candidates = if self.cur_ns.is_empty() {
            vec![name.to_string()]
        } else {
            vec![format!("{}{name}", self.cur_ns), name.to_string()]
        };
        for c in &candidates {
            if let Some(g) = self.globals.get(c).cloned() {
                return Ok(match g {
                    Global::Const(v) => Place::Value(v),
                    Global::Place(p) => {
                        if let Place::Ptr { ptr, .. } = &p {
                            self.use_global(*ptr);
                        }
                        p
                    }
                });
            }
            if let Some((var, ty, idx, layout, class)) = self.cbuffer_members.get(c).cloned() {
                self.use_global(var);
                let t = self.spv(&ty, layout)?;
                let pty = self.b.type_pointer(None, class, t);
                let i = self.const_u32(idx);
                let ptr = self.inst(
                    Op::AccessChain,
                    Some(pty),
                    vec![Operand::IdRef(var), Operand::IdRef(i)],
                )?;
                return Ok(Place::Ptr {
                    ptr,
                    ty,
                    layout,
                    class,
                });
            }
        }
        if let Some(v) = builtin_constant(name) {
            let id = self.const_u32(v);
            return Ok(Place::Value(Val {
                id,
                ty: Ty::Sc(Sc::Uint),
            }));
        }
        if self.fn_by_name.contains_key(name) || system_value(name).is_some() {
            return Err(
                Error::new(pos, format!("`{name}` is a function; call it with `()`"))
                    .len(name.len() as u32),
            );
        }
        Err(Error::new(pos, format!("unknown name `{name}`")).len(name.len() as u32))
    }

    /// A pointer to element/member `index` of a place.
    fn sub_place(
        &mut self,
        p: Place,
        index: Id,
        const_index: Option<u32>,
        elem: Ty,
        pos: Pos,
    ) -> Result<Place> {
        match p {
            Place::Ptr {
                ptr, layout, class, ..
            } => {
                let t = self.spv(&elem, layout)?;
                let pty = self.b.type_pointer(None, class, t);
                let ptr = self.inst(
                    Op::AccessChain,
                    Some(pty),
                    vec![Operand::IdRef(ptr), Operand::IdRef(index)],
                )?;
                if self.nonuniform_ptrs.contains(&ptr) {
                    let cap = match &elem {
                        Ty::Texture { rw: false, .. } => {
                            Some(Capability::SampledImageArrayNonUniformIndexing)
                        }
                        Ty::Texture { rw: true, .. } => {
                            Some(Capability::StorageImageArrayNonUniformIndexing)
                        }
                        Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => {
                            Some(Capability::StorageBufferArrayNonUniformIndexing)
                        }
                        Ty::ConstantBuffer(_) => {
                            Some(Capability::UniformBufferArrayNonUniformIndexing)
                        }
                        _ => None,
                    };
                    if let Some(c) = cap {
                        self.cap(c);
                    }
                }
                Ok(Place::Ptr {
                    ptr,
                    ty: elem,
                    layout,
                    class,
                })
            }
            Place::Swizzle { base, comps, .. } => match const_index {
                Some(k) if (k as usize) < comps.len() => Ok(Place::Swizzle {
                    base,
                    comps: vec![comps[k as usize]],
                    ty: elem,
                }),
                _ => {
                    let v = self.read(&Place::Swizzle {
                        ty: Ty::Vec(elem.scalar().unwrap_or(Sc::Float), comps.len() as u8),
                        base,
                        comps,
                    })?;
                    self.extract_dynamic(v, index, const_index, elem, pos)
                }
            },
            // A component of a storage-image texel stays writable.
            texel @ Place::Texel { .. }
                if const_index.is_some() && matches!(texel.ty(), Ty::Vec(..)) =>
            {
                let k = const_index.unwrap_or_default();
                Ok(Place::Swizzle {
                    base: Box::new(texel),
                    comps: vec![k],
                    ty: elem,
                })
            }
            other => {
                let v = self.read(&other)?;
                self.extract_dynamic(v, index, const_index, elem, pos)
            }
        }
    }

    fn extract_dynamic(
        &mut self,
        v: Val,
        index: Id,
        const_index: Option<u32>,
        elem: Ty,
        _pos: Pos,
    ) -> Result<Place> {
        let et = self.ty_id(&elem)?;
        if let Some(k) = const_index {
            let id = self.inst(
                Op::CompositeExtract,
                Some(et),
                vec![Operand::IdRef(v.id), Operand::LiteralBit32(k)],
            )?;
            return Ok(Place::Value(Val { id, ty: elem }));
        }
        if let Ty::Vec(..) = v.ty {
            let id = self.op(Op::VectorExtractDynamic, et, &[v.id, index])?;
            return Ok(Place::Value(Val { id, ty: elem }));
        }
        // Dynamic indexing of an array or matrix value goes through memory.
        let tmp = self.local_var(&v.ty, "")?;
        self.b.store(tmp, v.id, None, [])?;
        let p = Place::Ptr {
            ptr: tmp,
            ty: v.ty.clone(),
            layout: Layout::None,
            class: StorageClass::Function,
        };
        self.sub_place(p, index, None, elem, _pos)
    }

    fn place(&mut self, e: &'a Expr) -> Result<Place> {
        match &e.kind {
            ExprKind::Ident(n) => self.lookup(n, e.pos),
            ExprKind::Member(base, name) => {
                let bp = self.place(base)?;
                self.member(bp, name, e.pos)
            }
            ExprKind::Index(base, idx) => {
                let bp = self.place(base)?;
                let iv = self.expr(idx)?;
                if !matches!(iv.ty, Ty::Sc(_) | Ty::Vec(..)) {
                    return Err(Error::new(idx.pos, "index must be an integer"));
                }
                self.index(bp, iv, idx, e.pos)
            }
            _ => Ok(Place::Value(self.expr(e)?)),
        }
    }

    fn member(&mut self, bp: Place, name: &str, pos: Pos) -> Result<Place> {
        let t = bp.ty().clone();
        match &t {
            Ty::Struct(k) | Ty::ConstantBuffer(k) => {
                let def = &self.structs[*k as usize];
                let Some(i) = def.fields.iter().position(|f| f.name == name) else {
                    return Err(
                        Error::new(pos, format!("`{}` has no member `{name}`", def.name))
                            .len(name.len() as u32 + 1),
                    );
                };
                let ft = def.fields[i].ty.clone();
                let c = self.const_u32(i as u32);
                self.sub_place(bp, c, Some(i as u32), ft, pos)
            }
            Ty::Sc(s) | Ty::Vec(s, _) => {
                let Some(comps) = swizzle_comps(name) else {
                    return Err(Error::new(
                        pos,
                        format!("`{}` has no member `{name}`", self.ty_name(&t)),
                    ));
                };
                let n = t.width() as u32;
                if comps.iter().any(|c| *c >= n) {
                    return Err(Error::new(
                        pos,
                        format!("swizzle `{name}` reaches past a {}", self.ty_name(&t)),
                    ));
                }
                if let Ty::Sc(_) = t {
                    // `x.xxx` on a scalar: a splat, read-only.
                    let v = self.read(&bp)?;
                    if comps.len() == 1 {
                        return Ok(Place::Value(v));
                    }
                    let to = Ty::Vec(*s, comps.len() as u8);
                    return Ok(Place::Value(self.convert(v, &to, pos, false)?));
                }
                if comps.len() == 1 {
                    let c = self.const_u32(comps[0]);
                    return self.sub_place(bp, c, Some(comps[0]), Ty::Sc(*s), pos);
                }
                // Swizzles of swizzles compose.
                let (base, comps) = match bp {
                    Place::Swizzle {
                        base, comps: inner, ..
                    } => (base, comps.iter().map(|c| inner[*c as usize]).collect()),
                    other => (Box::new(other), comps),
                };
                Ok(Place::Swizzle {
                    base,
                    ty: Ty::Vec(*s, comps.len() as u8),
                    comps,
                })
            }
            Ty::Mat(s, r, c) => {
                let Some(els) = matrix_comps(name) else {
                    return Err(Error::new(
                        pos,
                        format!("`{}` has no member `{name}`", self.ty_name(&t)),
                    ));
                };
                if els.iter().any(|(i, j)| *i >= *r as u32 || *j >= *c as u32) {
                    return Err(Error::new(
                        pos,
                        format!("`{name}` is outside a {}", self.ty_name(&t)),
                    ));
                }
                if els.len() == 1 {
                    let (i, j) = els[0];
                    let ci = self.const_u32(i);
                    let row = self.sub_place(bp, ci, Some(i), Ty::Vec(*s, *c), pos)?;
                    let cj = self.const_u32(j);
                    return self.sub_place(row, cj, Some(j), Ty::Sc(*s), pos);
                }
                let m = self.read(&bp)?;
                let st = self.sc_id(*s);
                let mut ids = Vec::new();
                for (i, j) in els.iter() {
                    ids.push(self.inst(
                        Op::CompositeExtract,
                        Some(st),
                        vec![
                            Operand::IdRef(m.id),
                            Operand::LiteralBit32(*i),
                            Operand::LiteralBit32(*j),
                        ],
                    )?);
                }
                let vt = Ty::Vec(*s, ids.len() as u8);
                let vid = self.ty_id(&vt)?;
                let id = self.op(Op::CompositeConstruct, vid, &ids)?;
                Ok(Place::Value(Val { id, ty: vt }))
            }
            _ => Err(Error::new(
                pos,
                format!("`{}` has no member `{name}`", self.ty_name(&t)),
            )
            .len(name.len() as u32 + 1)),
        }
    }

    fn index(&mut self, bp: Place, iv: Val, idx: &'a Expr, pos: Pos) -> Result<Place> {
        let t = bp.ty().clone();
        let const_index = match self.const_eval(idx)? {
            Some(CVal::I(v)) if v >= 0 => Some(v as u32),
            _ => None,
        };
        let scalar_index = |this: &mut Self, iv: Val| -> Result<Id> {
            let nu = this.nonuniform.contains(&iv.id);
            let v = match iv.ty {
                Ty::Sc(Sc::Int) | Ty::Sc(Sc::Uint) => iv,
                _ => this.convert(iv, &Ty::Sc(Sc::Uint), idx.pos, false)?,
            };
            if nu {
                this.nonuniform.insert(v.id);
            }
            Ok(v.id)
        };
        match &t {
            Ty::Array(e, n) => {
                if let Some(k) = const_index {
                    if k >= *n {
                        return Err(Error::new(
                            idx.pos,
                            format!("index {k} is out of bounds for an array of {n}"),
                        ));
                    }
                }
                let i = scalar_index(self, iv)?;
                self.sub_place(bp, i, const_index, (**e).clone(), pos)
            }
            Ty::RtArray(e) => {
                let i = scalar_index(self, iv)?;
                self.sub_place(bp, i, const_index, (**e).clone(), pos)
            }
            Ty::Vec(s, _) => {
                let i = scalar_index(self, iv)?;
                self.sub_place(bp, i, const_index, Ty::Sc(*s), pos)
            }
            Ty::Mat(s, _, c) => {
                let i = scalar_index(self, iv)?;
                self.sub_place(bp, i, const_index, Ty::Vec(*s, *c), pos)
            }
            Ty::StructuredBuffer(e, _) => {
                let i = scalar_index(self, iv)?;
                let Place::Ptr { ptr, class, .. } = bp else {
                    unreachable!("buffers are variables")
                };
                let et = self.spv(e, Layout::Std430)?;
                let pty = self.b.type_pointer(None, class, et);
                let zero = self.const_u32(0);
                let ptr = self.inst(
                    Op::AccessChain,
                    Some(pty),
                    vec![Operand::IdRef(ptr), Operand::IdRef(zero), Operand::IdRef(i)],
                )?;
                Ok(Place::Ptr {
                    ptr,
                    ty: (**e).clone(),
                    layout: Layout::Std430,
                    class,
                })
            }
            Ty::Texture { dim: Dim::Cube, .. } => Err(Error::new(
                pos,
                "a TextureCube cannot be indexed; use SampleLevel",
            )),
            Ty::Texture { rw, sc, n, dim } => {
                let Place::Ptr { ptr, .. } = bp else {
                    unreachable!("textures are variables")
                };
                let cn = self.coord_size(*dim, false);
                let ct = if cn == 1 {
                    Ty::Sc(Sc::Int)
                } else {
                    Ty::Vec(Sc::Int, cn)
                };
                let coord = self.convert(iv, &ct, idx.pos, false)?;
                let texel = if *n == 1 {
                    Ty::Sc(*sc)
                } else {
                    Ty::Vec(*sc, *n)
                };
                if *rw {
                    Ok(Place::Texel {
                        image: ptr,
                        img: t.clone(),
                        coord: coord.id,
                        ty: texel,
                    })
                } else {
                    let v = self.fetch(ptr, &t, coord.id, None)?;
                    Ok(Place::Value(v))
                }
            }
            _ => Err(Error::new(
                pos,
                format!("`{}` cannot be indexed", self.ty_name(&t)),
            )),
        }
    }

    fn coord_size(&self, dim: Dim, sampling: bool) -> u8 {
        match dim {
            Dim::D1 => 1,
            Dim::D2 => 2,
            Dim::D3 | Dim::D2Array => 3,
            Dim::Cube => {
                if sampling {
                    3
                } else {
                    2
                }
            }
        }
    }

    fn read(&mut self, p: &Place) -> Result<Val> {
        match p {
            Place::Ptr {
                ptr,
                ty,
                layout,
                class,
            } => {
                if ty.is_resource() || matches!(ty, Ty::RayQuery(_)) {
                    return Ok(Val {
                        id: *ptr,
                        ty: ty.clone(),
                    });
                }
                if *layout != Layout::None && self.has_bool(ty) {
                    return self.load_bools(*ptr, ty, *layout, *class);
                }
                let tid = self.spv(ty, *layout)?;
                if self.term {
                    self.start_block(None)?;
                }
                let mut id = self.b.load(tid, None, *ptr, None, [])?;
                if self.nonuniform_ptrs.contains(ptr) {
                    self.b.decorate(id, Decoration::NonUniform, []);
                }
                if *layout != Layout::None && ty.is_aggregate() {
                    let plain = self.ty_id(ty)?;
                    id = self.op(Op::CopyLogical, plain, &[id])?;
                }
                Ok(Val { id, ty: ty.clone() })
            }
            Place::Swizzle { base, comps, ty } => {
                let v = self.read(base)?;
                let tid = self.ty_id(ty)?;
                let id = if comps.len() == 1 {
                    self.inst(
                        Op::CompositeExtract,
                        Some(tid),
                        vec![Operand::IdRef(v.id), Operand::LiteralBit32(comps[0])],
                    )?
                } else {
                    let mut ops = vec![Operand::IdRef(v.id), Operand::IdRef(v.id)];
                    ops.extend(comps.iter().map(|c| Operand::LiteralBit32(*c)));
                    self.inst(Op::VectorShuffle, Some(tid), ops)?
                };
                Ok(Val { id, ty: ty.clone() })
            }
            Place::Texel {
                image,
                img,
                coord,
                ty,
            } => {
                let it = self.ty_id(img)?;
                let im = self.b.load(it, None, *image, None, [])?;
                let s = ty.scalar().unwrap_or(Sc::Float);
                let v4 = self.ty_id(&Ty::Vec(s, 4))?;
                let id = self.op(Op::ImageRead, v4, &[im, *coord])?;
                self.shrink(
                    Val {
                        id,
                        ty: Ty::Vec(s, 4),
                    },
                    ty,
                )
            }
            Place::Value(v) => Ok(v.clone()),
        }
    }

    fn has_bool(&self, t: &Ty) -> bool {
        match t {
            Ty::Sc(Sc::Bool) | Ty::Vec(Sc::Bool, _) => true,
            Ty::Array(e, _) | Ty::RtArray(e) => self.has_bool(e),
            Ty::Struct(k) => self.structs[*k as usize]
                .fields
                .iter()
                .any(|f| self.has_bool(&f.ty)),
            _ => false,
        }
    }

    /// Parts of an aggregate with their indices and types.
    fn parts(&self, t: &Ty) -> Vec<(u32, Ty)> {
        match t {
            Ty::Struct(k) => self.structs[*k as usize]
                .fields
                .iter()
                .enumerate()
                .map(|(i, f)| (i as u32, f.ty.clone()))
                .collect(),
            Ty::Array(e, n) => (0..*n).map(|i| (i, (**e).clone())).collect(),
            _ => Vec::new(),
        }
    }

    /// Loads a value holding bools from a buffer, where they are stored as uints.
    fn load_bools(&mut self, ptr: Id, t: &Ty, layout: Layout, class: StorageClass) -> Result<Val> {
        if let Ty::Sc(_) | Ty::Vec(..) = t {
            let ut = self.spv(t, layout)?;
            let raw = self.b.load(ut, None, ptr, None, [])?;
            return self.convert_scalar(raw, Sc::Uint, Sc::Bool, t);
        }
        let mut ids = Vec::new();
        for (i, pt) in self.parts(t) {
            let c = self.const_u32(i);
            let et = self.spv(&pt, layout)?;
            let pty = self.b.type_pointer(None, class, et);
            let p = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![Operand::IdRef(ptr), Operand::IdRef(c)],
            )?;
            let v = if self.has_bool(&pt) {
                self.load_bools(p, &pt, layout, class)?
            } else {
                self.read(&Place::Ptr {
                    ptr: p,
                    ty: pt.clone(),
                    layout,
                    class,
                })?
            };
            ids.push(v.id);
        }
        let tid = self.ty_id(t)?;
        let id = self.op(Op::CompositeConstruct, tid, &ids)?;
        Ok(Val { id, ty: t.clone() })
    }

    fn store_bools(&mut self, ptr: Id, v: Val, layout: Layout, class: StorageClass) -> Result<()> {
        if let Ty::Sc(_) | Ty::Vec(..) = v.ty {
            let ut = v.ty.with_scalar(Sc::Uint);
            let raw = self.convert_scalar(v.id, Sc::Bool, Sc::Uint, &ut)?;
            self.b.store(ptr, raw.id, None, [])?;
            return Ok(());
        }
        for (i, pt) in self.parts(&v.ty) {
            let c = self.const_u32(i);
            let et = self.spv(&pt, layout)?;
            let pty = self.b.type_pointer(None, class, et);
            let p = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![Operand::IdRef(ptr), Operand::IdRef(c)],
            )?;
            let ptid = self.ty_id(&pt)?;
            let part = self.inst(
                Op::CompositeExtract,
                Some(ptid),
                vec![Operand::IdRef(v.id), Operand::LiteralBit32(i)],
            )?;
            let pv = Val {
                id: part,
                ty: pt.clone(),
            };
            self.write(
                &Place::Ptr {
                    ptr: p,
                    ty: pt,
                    layout,
                    class,
                },
                pv,
                Pos::default(),
            )?;
        }
        Ok(())
    }

    /// A 4-vector cut down to `to` (scalar or narrower vector).
    fn shrink(&mut self, v: Val, to: &Ty) -> Result<Val> {
        if &v.ty == to {
            return Ok(v);
        }
        let tid = self.ty_id(to)?;
        let id = match to {
            Ty::Sc(_) => self.inst(
                Op::CompositeExtract,
                Some(tid),
                vec![Operand::IdRef(v.id), Operand::LiteralBit32(0)],
            )?,
            _ => {
                let mut ops = vec![Operand::IdRef(v.id), Operand::IdRef(v.id)];
                ops.extend((0..to.width() as u32).map(Operand::LiteralBit32));
                self.inst(Op::VectorShuffle, Some(tid), ops)?
            }
        };
        Ok(Val { id, ty: to.clone() })
    }

    fn write(&mut self, p: &Place, v: Val, pos: Pos) -> Result<()> {
        match p {
            Place::Ptr {
                ptr,
                ty,
                layout,
                class,
            } => {
                if ty.is_resource() || matches!(ty, Ty::RayQuery(_)) {
                    return Err(unsupported(pos, "assigning resources or ray queries"));
                }
                if matches!(
                    class,
                    StorageClass::Uniform
                        | StorageClass::PushConstant
                        | StorageClass::ShaderRecordBufferKHR
                        | StorageClass::Input
                ) {
                    return Err(Error::new(
                        pos,
                        "cannot assign to a read-only value (constant buffer or input)",
                    ));
                }
                if *layout != Layout::None && self.has_bool(ty) {
                    return self.store_bools(*ptr, v, *layout, *class);
                }
                let mut id = v.id;
                if *layout != Layout::None && ty.is_aggregate() {
                    let lt = self.spv(ty, *layout)?;
                    id = self.op(Op::CopyLogical, lt, &[id])?;
                }
                if self.term {
                    self.start_block(None)?;
                }
                self.b.store(*ptr, id, None, [])?;
                Ok(())
            }
            Place::Swizzle { base, comps, .. } => {
                let mut sorted = comps.clone();
                sorted.sort_unstable();
                sorted.dedup();
                if sorted.len() != comps.len() {
                    return Err(Error::new(
                        pos,
                        "a swizzle with repeated components cannot be assigned",
                    ));
                }
                let b = self.read(base)?;
                let bt = self.ty_id(&b.ty)?;
                let id = if comps.len() == 1 {
                    self.inst(
                        Op::CompositeInsert,
                        Some(bt),
                        vec![
                            Operand::IdRef(v.id),
                            Operand::IdRef(b.id),
                            Operand::LiteralBit32(comps[0]),
                        ],
                    )?
                } else {
                    let n = b.ty.width() as u32;
                    let mut ops = vec![Operand::IdRef(b.id), Operand::IdRef(v.id)];
                    for i in 0..n {
                        let sel = comps
                            .iter()
                            .position(|c| *c == i)
                            .map(|j| n + j as u32)
                            .unwrap_or(i);
                        ops.push(Operand::LiteralBit32(sel));
                    }
                    self.inst(Op::VectorShuffle, Some(bt), ops)?
                };
                self.write(
                    base,
                    Val {
                        id,
                        ty: b.ty.clone(),
                    },
                    pos,
                )
            }
            Place::Texel {
                image,
                img,
                coord,
                ty,
            } => {
                let Ty::Texture { rw: true, .. } = img else {
                    return Err(Error::new(pos, "cannot write to a read-only texture"));
                };
                let s = ty.scalar().unwrap_or(Sc::Float);
                let v4 = self.widen4(v, s)?;
                let it = self.ty_id(img)?;
                let im = self.b.load(it, None, *image, None, [])?;
                self.b.image_write(im, *coord, v4, None, [])?;
                Ok(())
            }
            Place::Value(_) => Err(Error::new(pos, "cannot assign to this expression")),
        }
    }

    /// Pads a scalar or vector to 4 components with zeros (image writes).
    fn widen4(&mut self, v: Val, s: Sc) -> Result<Id> {
        let n = v.ty.width() as u32;
        if n == 4 {
            return Ok(v.id);
        }
        let mut parts = Vec::new();
        let st = self.sc_id(s);
        if n == 1 {
            parts.push(v.id);
        } else {
            for i in 0..n {
                parts.push(self.inst(
                    Op::CompositeExtract,
                    Some(st),
                    vec![Operand::IdRef(v.id), Operand::LiteralBit32(i)],
                )?);
            }
        }
        let zero = self.const_scalar(s, 0.0, 0);
        while parts.len() < 4 {
            parts.push(zero);
        }
        let t4 = self.ty_id(&Ty::Vec(s, 4))?;
        self.op(Op::CompositeConstruct, t4, &parts)
    }

    pub fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Void => "void".into(),
            Ty::Sc(s) => s.name().into(),
            Ty::Vec(s, n) => format!("{}{n}", s.name()),
            Ty::Mat(s, r, c) => format!("{}{r}x{c}", s.name()),
            Ty::Array(e, n) => format!("{}[{n}]", self.ty_name(e)),
            Ty::RtArray(e) => format!("{}[]", self.ty_name(e)),
            Ty::Struct(k) => self.structs[*k as usize].name.clone(),
            Ty::Accel => "RaytracingAccelerationStructure".into(),
            Ty::RayQuery(_) => "RayQuery".into(),
            Ty::Sampler => "SamplerState".into(),
            Ty::Texture { rw, .. } => {
                if *rw {
                    "RWTexture".into()
                } else {
                    "Texture".into()
                }
            }
            Ty::StructuredBuffer(_, rw) => {
                if *rw {
                    "RWStructuredBuffer".into()
                } else {
                    "StructuredBuffer".into()
                }
            }
            Ty::ByteAddress(rw) => {
                if *rw {
                    "RWByteAddressBuffer".into()
                } else {
                    "ByteAddressBuffer".into()
                }
            }
            Ty::ConstantBuffer(k) => format!("ConstantBuffer<{}>", self.structs[*k as usize].name),
        }
    }

    // ---- expressions ---------------------------------------------------

    fn expr_void(&mut self, e: &'a Expr) -> Result<()> {
        match &e.kind {
            // Calls of void functions have no value to produce.
            ExprKind::Call(..) | ExprKind::Method(..) => {
                self.call_expr(e)?;
            }
            _ => {
                self.expr(e)?;
            }
        }
        Ok(())
    }

    fn expr(&mut self, e: &'a Expr) -> Result<Val> {
        let v = match &e.kind {
            ExprKind::Int(v, u) => {
                if *u || *v > i32::MAX as u64 {
                    if *v > u32::MAX as u64 {
                        return Err(unsupported(e.pos, "64-bit integer literals"));
                    }
                    Val {
                        id: self.const_u32(*v as u32),
                        ty: Ty::Sc(Sc::Uint),
                    }
                } else {
                    Val {
                        id: self.const_i32(*v as i32),
                        ty: Ty::Sc(Sc::Int),
                    }
                }
            }
            ExprKind::Float(f) => Val {
                id: self.const_f32(*f as f32),
                ty: Ty::Sc(Sc::Float),
            },
            ExprKind::Bool(b) => Val {
                id: self.const_bool(*b),
                ty: Ty::Sc(Sc::Bool),
            },
            ExprKind::Str(_) => {
                return Err(unsupported(e.pos, "string literals outside attributes"))
            }
            ExprKind::Ident(_) | ExprKind::Member(..) | ExprKind::Index(..) => {
                let p = self.place(e)?;
                self.read(&p)?
            }
            ExprKind::Unary(op, a) => self.unary(*op, a, e.pos)?,
            ExprKind::Binary(op, a, b) => {
                if matches!(op, BinOp::And | BinOp::Or) {
                    return self.logical(*op, a, b, e.pos);
                }
                let a = self.expr(a)?;
                let b = self.expr(b)?;
                self.binary(*op, a, b, e.pos)?
            }
            ExprKind::Assign(op, lhs, rhs) => {
                let p = self.place(lhs)?;
                let t = p.ty().clone();
                let v = match op {
                    None => self.expr_as(rhs, &t)?,
                    Some(op) => {
                        let cur = self.read(&p)?;
                        let r = self.expr(rhs)?;
                        let v = self.binary(*op, cur, r, e.pos)?;
                        self.convert(v, &t, e.pos, true)?
                    }
                };
                self.write(&p, v.clone(), lhs.pos)?;
                v
            }
            ExprKind::Ternary(c, a, b) => self.ternary(c, a, b, e.pos)?,
            ExprKind::Call(..) | ExprKind::Method(..) => match self.call_expr(e)? {
                Some(v) => v,
                None => {
                    return Err(Error::new(
                        e.pos,
                        "this call has no value (it returns void)",
                    ))
                }
            },
            ExprKind::Construct(t, args) => {
                let ns = self.cur_ns.clone();
                let ty = self.resolve_ty(t, &ns)?;
                self.construct(&ty, args, e.pos)?
            }
            ExprKind::Cast(t, a) => {
                let ns = self.cur_ns.clone();
                let ty = self.resolve_ty(t, &ns)?;
                if let Ty::Struct(_) = ty {
                    // `(S)0` zero-initializes; a same-typed value passes through.
                    if let Some(CVal::I(0)) = self.const_eval(a)? {
                        let tid = self.ty_id(&ty)?;
                        let id = self.b.constant_null(tid);
                        return Ok(Val { id, ty });
                    }
                }
                let v = self.expr(a)?;
                self.convert(v, &ty, e.pos, true)?
            }
            ExprKind::InitList(_) => {
                return Err(Error::new(
                    e.pos,
                    "an initializer list needs a declared type",
                ))
            }
            ExprKind::Comma(a, b) => {
                self.expr_void(a)?;
                self.expr(b)?
            }
        };
        Ok(v)
    }

    /// An expression converted to `t`; initializer lists are built for it.
    fn expr_as(&mut self, e: &'a Expr, t: &Ty) -> Result<Val> {
        if let ExprKind::InitList(items) = &e.kind {
            let mut flat = Vec::new();
            for i in items {
                let v = self.expr_init(i, t)?;
                self.flatten(v, &mut flat)?;
            }
            if flat.len() == 1 && t.is_numeric() {
                let v = flat.pop().unwrap_or_else(|| unreachable!());
                return self.convert(v, t, e.pos, false);
            }
            let mut it = flat.into_iter();
            let v = self.build(t, &mut it, e.pos)?;
            if it.next().is_some() {
                return Err(Error::new(
                    e.pos,
                    format!("too many initializers for `{}`", self.ty_name(t)),
                ));
            }
            return Ok(v);
        }
        let v = self.expr(e)?;
        self.convert(v, t, e.pos, false)
    }

    fn expr_init(&mut self, e: &'a Expr, t: &Ty) -> Result<Val> {
        if let ExprKind::InitList(_) = e.kind {
            // Nested braces: the element type is unknown here, so flatten freely.
            let inner = match t {
                Ty::Array(el, _) => (**el).clone(),
                other => other.clone(),
            };
            return self.expr_as(e, &inner);
        }
        self.expr(e)
    }

    /// Splits a value into its scalar components, in memory order.
    fn flatten(&mut self, v: Val, out: &mut Vec<Val>) -> Result<()> {
        let parts: Vec<Ty> = match &v.ty {
            Ty::Sc(_) => {
                out.push(v);
                return Ok(());
            }
            Ty::Vec(s, n) => vec![Ty::Sc(*s); *n as usize],
            Ty::Mat(s, r, c) => vec![Ty::Vec(*s, *c); *r as usize],
            Ty::Array(e, n) => vec![(**e).clone(); *n as usize],
            Ty::Struct(k) => self.structs[*k as usize]
                .fields
                .iter()
                .map(|f| f.ty.clone())
                .collect(),
            other => {
                return Err(Error::new(
                    Pos::default(),
                    format!("cannot take apart a `{}`", self.ty_name(other)),
                ))
            }
        };
        for (i, pt) in parts.into_iter().enumerate() {
            let tid = self.ty_id(&pt)?;
            let id = self.inst(
                Op::CompositeExtract,
                Some(tid),
                vec![Operand::IdRef(v.id), Operand::LiteralBit32(i as u32)],
            )?;
            self.flatten(Val { id, ty: pt }, out)?;
        }
        Ok(())
    }

    /// Builds a value of `t` from scalar components.
    fn build(&mut self, t: &Ty, it: &mut std::vec::IntoIter<Val>, pos: Pos) -> Result<Val> {
        let parts: Vec<Ty> = match t {
            Ty::Sc(_) => {
                let v = it.next().ok_or_else(|| {
                    Error::new(
                        pos,
                        format!("too few initializers for `{}`", self.ty_name(t)),
                    )
                })?;
                return self.convert(v, t, pos, false);
            }
            Ty::Vec(s, n) => vec![Ty::Sc(*s); *n as usize],
            Ty::Mat(s, r, c) => vec![Ty::Vec(*s, *c); *r as usize],
            Ty::Array(e, n) => vec![(**e).clone(); *n as usize],
            Ty::Struct(k) => self.structs[*k as usize]
                .fields
                .iter()
                .map(|f| f.ty.clone())
                .collect(),
            other => {
                return Err(Error::new(
                    pos,
                    format!("cannot initialize a `{}`", self.ty_name(other)),
                ))
            }
        };
        let mut ids = Vec::new();
        for pt in parts {
            ids.push(self.build(&pt, it, pos)?.id);
        }
        let tid = self.ty_id(t)?;
        let id = self.op(Op::CompositeConstruct, tid, &ids)?;
        Ok(Val { id, ty: t.clone() })
    }

    fn construct(&mut self, ty: &Ty, args: &'a [Expr], pos: Pos) -> Result<Val> {
        if !ty.is_numeric() {
            return Err(unsupported(
                pos,
                format!("constructing a `{}` with `()`", self.ty_name(ty)),
            ));
        }
        let mut vals = Vec::new();
        for a in args {
            vals.push(self.expr(a)?);
        }
        if vals.len() == 1 && matches!(vals[0].ty, Ty::Sc(_)) {
            let v = vals.pop().unwrap_or_else(|| unreachable!());
            return self.convert(v, ty, pos, false);
        }
        let mut flat = Vec::new();
        for v in vals {
            if !v.ty.is_numeric() {
                return Err(Error::new(
                    pos,
                    format!(
                        "cannot build a `{}` from a `{}`",
                        self.ty_name(ty),
                        self.ty_name(&v.ty)
                    ),
                ));
            }
            self.flatten(v, &mut flat)?;
        }
        let want = match ty {
            Ty::Vec(_, n) => *n as usize,
            Ty::Mat(_, r, c) => (*r as usize) * (*c as usize),
            _ => 1,
        };
        if flat.len() != want {
            return Err(Error::new(
                pos,
                format!(
                    "`{}` needs {want} components, {} given",
                    self.ty_name(ty),
                    flat.len()
                ),
            ));
        }
        let mut it = flat.into_iter();
        self.build(ty, &mut it, pos)
    }

    /// Converts `v` to `to` with HLSL's implicit rules (`explicit` also allows
    /// what only casts allow).
    fn convert(&mut self, v: Val, to: &Ty, pos: Pos, explicit: bool) -> Result<Val> {
        if &v.ty == to {
            return Ok(v);
        }
        let bad = |this: &Self| {
            Error::new(
                pos,
                format!(
                    "cannot convert `{}` to `{}`",
                    this.ty_name(&v.ty),
                    this.ty_name(to)
                ),
            )
            .label(format!("this is a `{}`", this.ty_name(&v.ty)))
        };
        match (&v.ty, to) {
            (Ty::Sc(a), Ty::Sc(b)) => self.convert_scalar(v.id, *a, *b, to),
            (Ty::Sc(_), Ty::Vec(s, n)) => {
                let c = self.convert(v, &Ty::Sc(*s), pos, explicit)?;
                let tid = self.ty_id(to)?;
                let id = self.op(Op::CompositeConstruct, tid, &vec![c.id; *n as usize])?;
                Ok(Val { id, ty: to.clone() })
            }
            (Ty::Sc(_), Ty::Mat(s, r, c)) => {
                let row = self.convert(v, &Ty::Vec(*s, *c), pos, explicit)?;
                let tid = self.ty_id(to)?;
                let id = self.op(Op::CompositeConstruct, tid, &vec![row.id; *r as usize])?;
                Ok(Val { id, ty: to.clone() })
            }
            (Ty::Vec(a, n), Ty::Vec(b, m)) if m <= n => {
                let v = if m < n {
                    self.shrink(v.clone(), &Ty::Vec(*a, *m))?
                } else {
                    v.clone()
                };
                self.convert_scalar(v.id, *a, *b, to)
            }
            (Ty::Vec(a, _), Ty::Sc(b)) => {
                // Truncation to the first component (DXC warns; so would we).
                let s = self.shrink(v.clone(), &Ty::Sc(*a))?;
                self.convert_scalar(s.id, *a, *b, to)
            }
            (Ty::Mat(a, r, c), Ty::Mat(b, r2, c2)) if a == b && r2 <= r && c2 <= c && explicit => {
                let st = self.ty_id(&Ty::Vec(*a, *c2))?;
                let mut rows = Vec::new();
                for i in 0..*r2 {
                    let rowt = self.ty_id(&Ty::Vec(*a, *c))?;
                    let row = self.inst(
                        Op::CompositeExtract,
                        Some(rowt),
                        vec![Operand::IdRef(v.id), Operand::LiteralBit32(i as u32)],
                    )?;
                    let mut ops = vec![Operand::IdRef(row), Operand::IdRef(row)];
                    ops.extend((0..*c2 as u32).map(Operand::LiteralBit32));
                    rows.push(self.inst(Op::VectorShuffle, Some(st), ops)?);
                }
                let tid = self.ty_id(to)?;
                let id = self.op(Op::CompositeConstruct, tid, &rows)?;
                Ok(Val { id, ty: to.clone() })
            }
            _ => Err(bad(self)),
        }
    }

    fn convert_scalar(&mut self, id: Id, from: Sc, to: Sc, to_ty: &Ty) -> Result<Val> {
        if let (Ty::Sc(_), Some(bits)) = (to_ty, self.const_ids.get(&id).copied()) {
            if from != Sc::Bool && to != Sc::Bool && from != to {
                let (f, i) = match from {
                    Sc::Float => (f32::from_bits(bits) as f64, f32::from_bits(bits) as i64),
                    Sc::Int => (bits as i32 as f64, bits as i32 as i64),
                    _ => (bits as f64, bits as i64),
                };
                // Int <-> uint keeps the bits; float conversions convert the value.
                let i = if from != Sc::Float && to != Sc::Float {
                    bits as i64
                } else {
                    i
                };
                return Ok(Val {
                    id: self.const_scalar(to, f, i),
                    ty: to_ty.clone(),
                });
            }
        }
        let tid = self.ty_id(to_ty)?;
        let from_ty = to_ty.with_scalar(from);
        let id = match (from, to) {
            _ if from == to => id,
            (Sc::Bool, _) => {
                let one = self.const_splat(to_ty, 1.0)?;
                let zero = self.const_splat(to_ty, 0.0)?;
                self.op(Op::Select, tid, &[id, one, zero])?
            }
            (_, Sc::Bool) => {
                let zero = self.const_splat(&from_ty, 0.0)?;
                let op = if from == Sc::Float {
                    Op::FUnordNotEqual
                } else {
                    Op::INotEqual
                };
                self.op(op, tid, &[id, zero])?
            }
            (Sc::Int, Sc::Float) => self.op(Op::ConvertSToF, tid, &[id])?,
            (Sc::Uint, Sc::Float) => self.op(Op::ConvertUToF, tid, &[id])?,
            (Sc::Float, Sc::Int) => self.op(Op::ConvertFToS, tid, &[id])?,
            (Sc::Float, Sc::Uint) => self.op(Op::ConvertFToU, tid, &[id])?,
            _ => self.op(Op::Bitcast, tid, &[id])?,
        };
        Ok(Val {
            id,
            ty: to_ty.clone(),
        })
    }

    /// The type both operands of an arithmetic operator convert to.
    fn common(&self, a: &Ty, b: &Ty, pos: Pos) -> Result<Ty> {
        let (Some(sa), Some(sb)) = (a.scalar(), b.scalar()) else {
            return Err(Error::new(
                pos,
                format!(
                    "operator needs numbers, found `{}` and `{}`",
                    self.ty_name(a),
                    self.ty_name(b)
                ),
            ));
        };
        let s = sa.max(sb);
        Ok(match (a, b) {
            (Ty::Sc(_), x) | (x, Ty::Sc(_)) => x.with_scalar(s),
            (Ty::Vec(_, n), Ty::Vec(_, m)) => Ty::Vec(s, (*n).min(*m)),
            (Ty::Mat(_, r, c), Ty::Mat(_, r2, c2)) => Ty::Mat(s, (*r).min(*r2), (*c).min(*c2)),
            _ => {
                return Err(Error::new(
                    pos,
                    format!(
                        "cannot combine `{}` and `{}`",
                        self.ty_name(a),
                        self.ty_name(b)
                    ),
                ))
            }
        })
    }

    fn binary(&mut self, op: BinOp, a: Val, b: Val, pos: Pos) -> Result<Val> {
        use BinOp::*;
        let mut ct = self.common(&a.ty, &b.ty, pos)?;
        let cmp = matches!(op, Eq | Ne | Lt | Le | Gt | Ge);
        let bits = matches!(op, Shl | Shr | BitAnd | BitOr | BitXor);
        if ct.scalar() == Some(Sc::Bool) && !(cmp && matches!(op, Eq | Ne)) {
            ct = ct.with_scalar(Sc::Int);
        }
        if matches!(op, Shl | Shr) {
            // A shift has its left operand's type (HLSL, like C).
            let ls = match a.ty.scalar() {
                Some(Sc::Bool) | None => Sc::Int,
                Some(s) => s,
            };
            ct = ct.with_scalar(ls);
        }
        if bits && ct.scalar() == Some(Sc::Float) {
            return Err(Error::new(
                pos,
                format!("`{}` needs integer operands", op.as_str()),
            ));
        }
        let a = self.convert(a, &ct, pos, true)?;
        let b = self.convert(b, &ct, pos, true)?;
        if let (Some(x), Some(y)) = (self.known(&a), self.known(&b)) {
            if let Some(v) = self.fold(op, x, y) {
                return Ok(v);
            }
        }
        if let (Ty::Mat(..), true) = (&ct, cmp) {
            return Err(unsupported(pos, "comparing matrices"));
        }
        if let Ty::Mat(s, r, c) = ct {
            // Matrix operators are component-wise: one row at a time.
            let row = Ty::Vec(s, c);
            let rt = self.ty_id(&row)?;
            let mut rows = Vec::new();
            for i in 0..r as u32 {
                let x = self.inst(
                    Op::CompositeExtract,
                    Some(rt),
                    vec![Operand::IdRef(a.id), Operand::LiteralBit32(i)],
                )?;
                let y = self.inst(
                    Op::CompositeExtract,
                    Some(rt),
                    vec![Operand::IdRef(b.id), Operand::LiteralBit32(i)],
                )?;
                rows.push(self.binary(
                    op,
                    Val {
                        id: x,
                        ty: row.clone(),
                    },
                    Val {
                        id: y,
                        ty: row.clone(),
                    },
                    pos,
                )?);
            }
            let mt = Ty::Mat(s, r, c);
            let tid = self.ty_id(&mt)?;
            let ids: Vec<Id> = rows.iter().map(|v| v.id).collect();
            let id = self.op(Op::CompositeConstruct, tid, &ids)?;
            return Ok(Val { id, ty: mt });
        }
        let s = ct.scalar().unwrap_or(Sc::Float);
        let f = s == Sc::Float;
        let signed = s == Sc::Int;
        let opcode = match op {
            Add => {
                if f {
                    Op::FAdd
                } else {
                    Op::IAdd
                }
            }
            Sub => {
                if f {
                    Op::FSub
                } else {
                    Op::ISub
                }
            }
            Mul => {
                if f {
                    Op::FMul
                } else {
                    Op::IMul
                }
            }
            Div => {
                if f {
                    Op::FDiv
                } else if signed {
                    Op::SDiv
                } else {
                    Op::UDiv
                }
            }
            Rem => {
                if f {
                    Op::FRem
                } else if signed {
                    Op::SRem
                } else {
                    Op::UMod
                }
            }
            Shl => Op::ShiftLeftLogical,
            Shr => {
                if signed {
                    Op::ShiftRightArithmetic
                } else {
                    Op::ShiftRightLogical
                }
            }
            BitAnd => Op::BitwiseAnd,
            BitOr => Op::BitwiseOr,
            BitXor => Op::BitwiseXor,
            Eq => {
                if f {
                    Op::FOrdEqual
                } else if s == Sc::Bool {
                    Op::LogicalEqual
                } else {
                    Op::IEqual
                }
            }
            Ne => {
                if f {
                    Op::FUnordNotEqual
                } else if s == Sc::Bool {
                    Op::LogicalNotEqual
                } else {
                    Op::INotEqual
                }
            }
            Lt => {
                if f {
                    Op::FOrdLessThan
                } else if signed {
                    Op::SLessThan
                } else {
                    Op::ULessThan
                }
            }
            Le => {
                if f {
                    Op::FOrdLessThanEqual
                } else if signed {
                    Op::SLessThanEqual
                } else {
                    Op::ULessThanEqual
                }
            }
            Gt => {
                if f {
                    Op::FOrdGreaterThan
                } else if signed {
                    Op::SGreaterThan
                } else {
                    Op::UGreaterThan
                }
            }
            Ge => {
                if f {
                    Op::FOrdGreaterThanEqual
                } else if signed {
                    Op::SGreaterThanEqual
                } else {
                    Op::UGreaterThanEqual
                }
            }
            And | Or => unreachable!("handled by logical"),
        };
        let rt = if cmp { ct.with_scalar(Sc::Bool) } else { ct };
        let tid = self.ty_id(&rt)?;
        let id = self.op(opcode, tid, &[a.id, b.id])?;
        Ok(Val { id, ty: rt })
    }

    /// `&&` and `||`: short-circuit on scalars (HLSL 2021), component-wise on vectors.
    fn logical(&mut self, op: BinOp, a: &'a Expr, b: &'a Expr, pos: Pos) -> Result<Val> {
        let av = self.expr(a)?;
        if let Ty::Vec(_, n) = av.ty {
            let bv = self.expr(b)?;
            let t = Ty::Vec(
                Sc::Bool,
                n.min(
                    bv.ty
                        .width()
                        .max(if matches!(bv.ty, Ty::Sc(_)) { n } else { 0 }),
                ),
            );
            let x = self.convert(av, &t, pos, false)?;
            let y = self.convert(bv, &t, pos, false)?;
            let tid = self.ty_id(&t)?;
            let id = self.op(
                if op == BinOp::And {
                    Op::LogicalAnd
                } else {
                    Op::LogicalOr
                },
                tid,
                &[x.id, y.id],
            )?;
            return Ok(Val { id, ty: t });
        }
        let bool_t = Ty::Sc(Sc::Bool);
        let x = self.convert(av, &bool_t, a.pos, false)?;
        let from = self.cur_label;
        let (rhs_l, merge) = (self.b.id(), self.b.id());
        self.b
            .selection_merge(merge, spirv::SelectionControl::NONE)?;
        if op == BinOp::And {
            self.b.branch_conditional(x.id, rhs_l, merge, [])?;
        } else {
            self.b.branch_conditional(x.id, merge, rhs_l, [])?;
        }
        self.start_block(Some(rhs_l))?;
        let bv = self.expr(b)?;
        let y = self.convert(bv, &bool_t, b.pos, false)?;
        let rhs_end = self.cur_label;
        self.branch(merge)?;
        self.start_block(Some(merge))?;
        let tid = self.ty_id(&bool_t)?;
        let id = self.inst(
            Op::Phi,
            Some(tid),
            vec![
                Operand::IdRef(x.id),
                Operand::IdRef(from),
                Operand::IdRef(y.id),
                Operand::IdRef(rhs_end),
            ],
        )?;
        Ok(Val { id, ty: bool_t })
    }

    fn ternary(&mut self, c: &'a Expr, a: &'a Expr, b: &'a Expr, pos: Pos) -> Result<Val> {
        let cv = self.expr(c)?;
        if let Ty::Vec(_, n) = cv.ty {
            // Vector conditions select per component; both sides are evaluated.
            let av = self.expr(a)?;
            let bv = self.expr(b)?;
            let t = self.common(&av.ty, &bv.ty, pos)?;
            let t = match t {
                Ty::Sc(s) => Ty::Vec(s, n),
                other => other,
            };
            let x = self.convert(av, &t, pos, false)?;
            let y = self.convert(bv, &t, pos, false)?;
            let cb = self.convert(cv, &Ty::Vec(Sc::Bool, t.width()), c.pos, false)?;
            let tid = self.ty_id(&t)?;
            let id = self.op(Op::Select, tid, &[cb.id, x.id, y.id])?;
            return Ok(Val { id, ty: t });
        }
        let cb = self.convert(cv, &Ty::Sc(Sc::Bool), c.pos, false)?;
        // Only the chosen side runs. Each side leaves its value in a temporary
        // of its own type; the result, in the common type of both, is selected
        // after the merge (the unchosen temporary is never observed).
        let (la, lb, merge) = (self.b.id(), self.b.id(), self.b.id());
        self.b
            .selection_merge(merge, spirv::SelectionControl::NONE)?;
        self.b.branch_conditional(cb.id, la, lb, [])?;
        let side = |this: &mut Self, label: Id, e: &'a Expr| -> Result<(Id, Ty)> {
            this.start_block(Some(label))?;
            let v = this.expr(e)?;
            let tmp = this.local_var(&v.ty, "")?;
            if this.term {
                this.start_block(None)?;
            }
            this.b.store(tmp, v.id, None, [])?;
            this.branch(merge)?;
            Ok((tmp, v.ty))
        };
        let (ta, tya) = side(self, la, a)?;
        let (tb, tyb) = side(self, lb, b)?;
        self.start_block(Some(merge))?;
        let t = if tya == tyb {
            tya.clone()
        } else {
            self.common(&tya, &tyb, pos)?
        };
        let load = |this: &mut Self, tmp: Id, ty: &Ty, at: Pos| -> Result<Val> {
            let tid = this.ty_id(ty)?;
            let id = this.b.load(tid, None, tmp, None, [])?;
            this.convert(Val { id, ty: ty.clone() }, &t, at, false)
        };
        let x = load(self, ta, &tya, a.pos)?;
        let y = load(self, tb, &tyb, b.pos)?;
        let tid = self.ty_id(&t)?;
        let id = self.op(Op::Select, tid, &[cb.id, x.id, y.id])?;
        Ok(Val { id, ty: t })
    }

    fn unary(&mut self, op: UnOp, a: &'a Expr, pos: Pos) -> Result<Val> {
        match op {
            UnOp::Plus => self.expr(a),
            UnOp::Neg => {
                let v = self.expr(a)?;
                let v = if v.ty.scalar() == Some(Sc::Bool) {
                    self.convert(v.clone(), &v.ty.with_scalar(Sc::Int), pos, false)?
                } else {
                    v
                };
                let zero = Val {
                    id: self.const_splat(&v.ty, 0.0)?,
                    ty: v.ty.clone(),
                };
                if v.ty.scalar().is_none() {
                    return Err(Error::new(
                        pos,
                        format!("cannot negate a `{}`", self.ty_name(&v.ty)),
                    ));
                }
                self.binary(BinOp::Sub, zero, v, pos)
            }
            UnOp::Not => {
                let v = self.expr(a)?;
                if let Ty::Mat(..) = v.ty {
                    return Err(unsupported(pos, "`!` on a matrix"));
                }
                let t = v.ty.with_scalar(Sc::Bool);
                let b = self.convert(v, &t, pos, false)?;
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::LogicalNot, tid, &[b.id])?;
                Ok(Val { id, ty: t })
            }
            UnOp::BitNot => {
                let v = self.expr(a)?;
                if !matches!(v.ty.scalar(), Some(Sc::Int | Sc::Uint)) {
                    return Err(Error::new(pos, "`~` needs an integer"));
                }
                let tid = self.ty_id(&v.ty)?;
                let id = self.op(Op::Not, tid, &[v.id])?;
                Ok(Val { id, ty: v.ty })
            }
            UnOp::PreInc | UnOp::PreDec | UnOp::PostInc | UnOp::PostDec => {
                let p = self.place(a)?;
                let old = self.read(&p)?;
                let one = Val {
                    id: self.const_splat(&old.ty, 1.0)?,
                    ty: old.ty.clone(),
                };
                let bop = if matches!(op, UnOp::PreInc | UnOp::PostInc) {
                    BinOp::Add
                } else {
                    BinOp::Sub
                };
                let new = self.binary(bop, old.clone(), one, pos)?;
                let new = self.convert(new, &old.ty, pos, true)?;
                self.write(&p, new.clone(), pos)?;
                Ok(if matches!(op, UnOp::PreInc | UnOp::PreDec) {
                    new
                } else {
                    old
                })
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum CVal {
    I(i64),
    F(f64),
}

impl CVal {
    fn as_f64(&self) -> f64 {
        match self {
            CVal::I(i) => *i as f64,
            CVal::F(f) => *f,
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
    fn system_values_follow_dxc() {
        let (b, t, stages) = system_value("RayTCurrent").unwrap();
        assert_eq!((b, t), (BuiltIn::RayTmaxKHR, Ty::Sc(Sc::Float)));
        assert!(!stages.contains(&Stage::RayGeneration));
        assert_eq!(
            system_value("InstanceIndex").unwrap().0,
            BuiltIn::InstanceId
        );
        assert_eq!(
            system_value("InstanceID").unwrap().0,
            BuiltIn::InstanceCustomIndexKHR
        );
        assert_eq!(
            system_value("ObjectToWorld4x3").unwrap().1,
            Ty::Mat(Sc::Float, 4, 3)
        );
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
            ty: Ty::Sc(Sc::Int),
        };
        let b = Val {
            id: l.const_u32(1),
            ty: Ty::Sc(Sc::Uint),
        };
        let v = l.binary(BinOp::BitOr, a, b, Pos::default()).unwrap();
        assert_eq!(v.ty, Ty::Sc(Sc::Uint));
        assert_eq!(l.known(&v), Some((Sc::Uint, 7)));
        let f = l
            .convert(v, &Ty::Sc(Sc::Float), Pos::default(), false)
            .unwrap();
        assert_eq!(l.known(&f), Some((Sc::Float, 7.0f32.to_bits())));
    }
}
