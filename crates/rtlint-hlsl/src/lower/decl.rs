//! Declarations: structs, typedefs, enums, functions and methods, globals,
//! constant buffers and resource bindings.

use super::inline_spirv::no_ext_decorate;
use super::*;

impl<'a> Lowerer<'a> {
    /// Reads every declaration and function signature; returns the entry points.
    pub fn declare(&mut self) -> Result<Vec<EntryInfo>> {
        let items = self.items;
        for item in items {
            match item {
                // Scalar `static const`s are known in source order, so array
                // sizes in later structs and typedefs can use them.
                Item::Var(v) if v.mods.is_static && v.mods.is_const && v.dims.is_empty() => {
                    if let (Some(e), Ok(Ty::ScalarKind(s))) = (&v.init, self.resolve_ty(&v.ty, ""))
                    {
                        // Not constant (or not yet resolvable): declared later as usual.
                        let scope = v.name.rsplit_once("::").map(|(n, _)| format!("{n}::"));
                        let saved =
                            std::mem::replace(&mut self.f.cur_ns, scope.unwrap_or_default());
                        let c = self.const_eval(e);
                        self.f.cur_ns = saved;
                        if let Ok(Some(c)) = c {
                            let c = match (s, c) {
                                (s, c) if s.is_float() => ConstValue::F(c.as_f64()),
                                (_, ConstValue::F(f)) => ConstValue::I(f as i64),
                                (_, c) => c,
                            };
                            self.const_items.insert(v.name.clone(), c);
                        }
                    }
                }
                Item::Struct(s) if !s.tparams.is_empty() => {
                    self.struct_templates.insert(s.name.clone(), s);
                }
                // An instance declared already where it was first used.
                Item::Struct(s)
                    if self.struct_names.contains_key(&s.name) && s.name.contains('<') => {}
                Item::Struct(s) => match self.declare_struct(s) {
                    Ok(()) => {}
                    // A struct using something unsupported is refused where it is used.
                    Err(e) if e.is_unsupported() => {
                        self.unusable.entry(s.name.clone()).or_insert(e);
                    }
                    Err(e) => return Err(e),
                },
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
                            Ty::ScalarKind(s @ (ScalarKind::Int | ScalarKind::Uint)) => s,
                            _ => return Err(Error::new(t.pos, "enum type must be int or uint")),
                        },
                        None => ScalarKind::Int,
                    };
                    self.typedefs.insert(name.clone(), Ty::ScalarKind(sc));
                    let mut next = 0i64;
                    let ns = name
                        .rsplit_once("::")
                        .map(|(n, _)| format!("{n}::"))
                        .unwrap_or_default();
                    for (v, _, value) in variants {
                        if let Some(e) = value {
                            // Earlier variants are in scope by bare name.
                            let saved = std::mem::replace(&mut self.f.cur_ns, format!("{name}::"));
                            let r = self.const_int(e);
                            self.f.cur_ns = saved;
                            next = r?;
                        }
                        let id = self.const_scalar(sc, next as f64, next);
                        let c = Global::Const(Val {
                            id,
                            ty: Ty::ScalarKind(sc),
                        });
                        self.globals.insert(format!("{name}::{v}"), c.clone());
                        self.const_items
                            .insert(format!("{name}::{v}"), ConstValue::I(next));
                        if !scoped {
                            self.globals.insert(format!("{ns}{v}"), c);
                            self.const_items
                                .insert(format!("{ns}{v}"), ConstValue::I(next));
                        }
                        next += 1;
                    }
                }
                _ => {}
            }
        }
        self.declare_globals()?;
        let mut entries = Vec::new();
        let mut protos: Vec<&'a Function> = Vec::new();
        for item in items {
            if let Item::Struct(sd) = item {
                if sd.tparams.is_empty() {
                    self.declare_methods(sd)?;
                }
                continue;
            }
            let Item::Function(f) = item else { continue };
            if !f.tparams.is_empty() {
                self.fn_templates.entry(f.name.clone()).or_default().push(f);
                continue;
            }
            let mut stage = None;
            let mut numthreads = [1, 1, 1];
            let mut has_numthreads = false;
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
                        has_numthreads = true;
                        stage.get_or_insert(Stage::Compute);
                    }
                    _ => {}
                }
            }
            // A classic entry point (`float4 main(...) : SV_Target`): the stage
            // comes from the command line (`-E main -T ps_6_5`).
            if let Some((name, forced)) = &self.forced_entry {
                if *name == f.name {
                    match stage {
                        None => stage = Some(*forced),
                        Some(s) if s != *forced => {
                            return Err(Error::new(
                                f.pos,
                                format!(
                                    "`{}` is marked a {} shader; the command line asks for {}",
                                    f.name,
                                    s.hlsl_name(),
                                    forced.hlsl_name()
                                ),
                            )
                            .len(f.name.len() as u32))
                        }
                        Some(_) => {}
                    }
                }
            }
            let (ret, params) = match self.signature(f) {
                Ok(sig) => sig,
                // A helper using something unsupported in its signature is
                // refused where it is called; never called, it is not compiled.
                Err(e) if stage.is_none() && e.is_unsupported() => {
                    self.unusable.entry(f.name.clone()).or_insert(e);
                    continue;
                }
                Err(e) => return Err(e),
            };
            if let Some(a) = f.attrs.iter().find(|a| a.name == "vk::ext_instruction") {
                if f.body.is_some() {
                    return Err(Error::new(
                        a.pos,
                        "a `vk::ext_instruction` function is a declaration without a body",
                    ));
                }
                self.ext_insts.insert(f.name.clone(), f);
                continue;
            }
            let id = self.b.id();
            if f.body.is_none() {
                // A prototype: the definition carries the signature, the
                // prototype may carry the default values.
                protos.push(f);
                continue;
            }
            // DXC refuses a compute entry point without a workgroup size
            // rather than assume 1 x 1 x 1 (a prototype may leave it to the
            // definition).
            if stage == Some(Stage::Compute) && !has_numthreads {
                return Err(Error::new(
                    f.pos,
                    format!(
                        "compute entry point `{}` needs a [numthreads(X, Y, Z)] attribute",
                        f.name
                    ),
                )
                .len(f.name.len() as u32));
            }
            let proto = protos
                .iter()
                .rev()
                .find(|p| p.name == f.name && p.params.len() == f.params.len());
            let defaults = match defaults_of(f)? {
                d if d.is_empty() => match proto {
                    Some(p) => defaults_of(p)?,
                    None => d,
                },
                d => d,
            };
            let idx = self.funcs.len();
            let ret_slot = ret
                .is_opaque()
                .then(|| ret_slot_name(f))
                .flatten()
                .map(|n| (ret.clone(), n));
            let ret = if ret_slot.is_some() { Ty::Void } else { ret };
            self.funcs.push(FnSig {
                name: f.name.clone(),
                ret_slot,
                defaults,
                bound: Vec::new(),
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

    /// A function's return type and parameters.
    fn signature(&mut self, f: &Function) -> Result<(Ty, Vec<Param>)> {
        let ret = self.resolve_ty(&f.ret, &f.ns)?;
        if ret.is_opaque() && (ret == Ty::HitObject || ret_slot_name(f).is_none()) {
            // Opaque values cannot be copied out of a function; a ray query
            // returned as one named local is the caller's variable (`ret_slot`).
            return Err(unsupported(
                f.ret.pos,
                format!(
                    "functions returning a {} other than one local variable",
                    self.ty_name(&ret)
                ),
            ));
        }
        let mut params = Vec::new();
        for p in &f.params {
            let t = self.resolve_ty(&p.ty, &f.ns)?;
            let unsized_ok = t.is_resource(); // `Texture2D ts[]`, passed as its variable
            let t = self.apply_dims(t, &p.dims, p.pos, unsized_ok)?;
            if t.is_resource() && (bad_resource_array(&t) || p.mods.output) {
                return Err(unsupported(
                    p.pos,
                    "arrays of buffers, or `out` resources, as function parameters",
                ));
            }
            params.push(Param {
                ty: t,
                out: p.mods.output,
                input: p.mods.input || !p.mods.output,
            });
        }
        Ok((ret, params))
    }

    pub(super) fn declare_methods(&mut self, sd: &'a StructDecl) -> Result<()> {
        let Some(&k) = self.struct_names.get(&sd.name) else {
            return Ok(());
        };
        // Methods of the bases (transitively) that the struct does not redefine,
        // with the derived struct as `this` (its members start with the base's).
        let mut methods: Vec<&'a Function> = sd.methods.iter().collect();
        let mut bases: Vec<&TypeRef> = sd.bases.iter().collect();
        let mut seen = 0;
        while let Some(b) = bases.pop() {
            seen += 1;
            if seen > 64 {
                break;
            }
            let Ok(Ty::Struct(kb)) = self.resolve_ty(b, &format!("{}::", sd.name)) else {
                continue;
            };
            let base_name = self.structs[kb as usize].name.clone();
            let items = self.items;
            let Some(base) = items.iter().find_map(|i| match i {
                Item::Struct(s) if s.name == base_name => Some(s),
                _ => None,
            }) else {
                continue;
            };
            for m in &base.methods {
                let redefined = methods
                    .iter()
                    .any(|x| x.name == m.name && x.params.len() == m.params.len());
                if !redefined {
                    methods.push(m);
                }
            }
            bases.extend(base.bases.iter());
        }
        for f in methods {
            if f.body.is_none() {
                continue; // declared, never defined: a call finds no overload
            }
            if !f.tparams.is_empty() {
                self.method_templates
                    .entry(format!("{}::{}", sd.name, f.name))
                    .or_default()
                    .push(f);
                continue;
            }
            let ret = self.resolve_ty(&f.ret, &f.ns)?;
            let mut params = Vec::new();
            if !f.is_static {
                params.push(Param {
                    ty: Ty::Struct(k),
                    out: true,
                    input: true,
                });
            }
            for p in &f.params {
                let t = self.resolve_ty(&p.ty, &f.ns)?;
                let unsized_ok = t.is_resource(); // `Texture2D ts[]`, passed as its variable
                let t = self.apply_dims(t, &p.dims, p.pos, unsized_ok)?;
                if t.is_resource() && (bad_resource_array(&t) || p.mods.output) {
                    return Err(unsupported(
                        p.pos,
                        "arrays of buffers, or `out` resources, as function parameters",
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
            let ret_slot = ret
                .is_opaque()
                .then(|| ret_slot_name(f))
                .flatten()
                .map(|n| (ret.clone(), n));
            let ret = if ret_slot.is_some() { Ty::Void } else { ret };
            self.funcs.push(FnSig {
                name: name.clone(),
                ret_slot,
                defaults: defaults_of(f)?,
                bound: Vec::new(),
                params,
                ret,
                id,
                func: f,
                this: (!f.is_static).then_some(k),
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

    pub(super) fn declare_struct(&mut self, s: &StructDecl) -> Result<()> {
        // Names in the struct (array sizes, nested types) look in it first.
        let scope = format!("{}::", s.name);
        let saved = std::mem::replace(&mut self.f.cur_ns, scope.clone());
        let r = self.declare_struct_in(s, &scope);
        self.f.cur_ns = saved;
        r
    }

    fn declare_struct_in(&mut self, s: &StructDecl, scope: &str) -> Result<()> {
        let mut fields = Vec::new();
        let mut decorations = Vec::new();
        for b in &s.bases {
            // A base's members come first, as C++ lays them out.
            match self.resolve_ty(b, scope)? {
                Ty::Struct(k) => {
                    let at = fields.len() as u32;
                    for (i, d, ops) in self.member_decorations.get(&k).into_iter().flatten() {
                        decorations.push((at + i, *d, ops.clone()));
                    }
                    fields.extend(self.structs[k as usize].fields.iter().cloned())
                }
                _ => return Err(Error::new(b.pos, "a base must be a struct")),
            }
        }
        for f in &s.fields {
            if let Some((_, pos)) = f.bits {
                return Err(unsupported(pos, "bit fields"));
            }
            for a in f.attrs.iter().filter(|a| a.name == "vk::ext_decorate") {
                let (d, ops) = self.ext_decoration(a)?;
                decorations.push((fields.len() as u32, d, ops));
            }
            let t = self.resolve_ty(&f.ty, scope)?;
            let t = self.apply_dims(t, &f.dims, f.pos, false)?;
            if t.is_resource() || t.is_opaque() {
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
        if !decorations.is_empty() {
            self.member_decorations.insert(k, decorations);
        }
        self.struct_io.insert(
            k,
            s.fields
                .iter()
                .map(|f| (f.semantic.clone(), f.attrs.clone(), f.mods))
                .collect(),
        );
        self.struct_names.insert(s.name.clone(), k);
        Ok(())
    }

    pub(super) fn lookup_type_name(&self, name: &str, ns: &str) -> Option<Ty> {
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
                return self.usings.iter().find_map(|u| {
                    let q = format!("{u}{name}");
                    match self.struct_names.get(&q) {
                        Some(k) => Some(Ty::Struct(*k)),
                        None => self.typedefs.get(&q).cloned(),
                    }
                });
            }
            prefix.truncate(prefix.len() - 2);
            prefix = match prefix.rfind("::") {
                Some(k) => prefix[..k + 2].to_string(),
                None => String::new(),
            };
        }
    }

    pub(super) fn resolve_ty(&mut self, t: &TypeRef, ns: &str) -> Result<Ty> {
        let name = t.name.as_str();
        let targ_ty = |this: &mut Self, k: usize, default: Ty| -> Result<Ty> {
            match t.args.get(k) {
                Some(TArg::Type(a)) => this.resolve_ty(a, ns),
                Some(TArg::Expr(e)) => Err(Error::new(e.pos, "expected a type argument")),
                None => Ok(default),
            }
        };
        if let Some((base, a, b)) = split_numeric(name) {
            if !self.sixteen_bit_types && matches!(base, "float16_t" | "int16_t" | "uint16_t") {
                // DXC refuses these without the flag too.
                return Err(unsupported(
                    t.pos,
                    format!("16-bit type `{base}` (DXC needs -enable-16bit-types for it)"),
                )
                .len(base.len() as u32));
            }
            // With -enable-16bit-types DXC maps `half` and the min-precision
            // types to 16-bit ones; without it they are 32-bit.
            let sixteen = self.sixteen_bit_types;
            let sc = match base {
                "bool" => ScalarKind::Bool,
                "int16_t" => ScalarKind::Int16,
                "uint16_t" => ScalarKind::Uint16,
                "float16_t" => ScalarKind::Half,
                "min16int" | "min12int" if sixteen => ScalarKind::Int16,
                "min16uint" if sixteen => ScalarKind::Uint16,
                "half" | "min16float" | "min10float" if sixteen => ScalarKind::Half,
                "int" | "min16int" | "min12int" | "int32_t" => ScalarKind::Int,
                "uint" | "dword" | "min16uint" | "uint32_t" => ScalarKind::Uint,
                "int64_t" => ScalarKind::Int64,
                "uint64_t" => ScalarKind::Uint64,
                // Without 16-bit types enabled, DXC treats half as float.
                "float" | "half" | "min16float" | "min10float" | "float32_t" => ScalarKind::Float,
                other => {
                    return Err(unsupported(
                        t.pos,
                        format!("type `{other}` (only 32-bit floats, 32- and 64-bit integers)"),
                    )
                    .len(other.len() as u32))
                }
            };
            return self.numeric(sc, a, b, t.pos);
        }
        Ok(match name {
            "void" => Ty::Void,
            "vector" | "matrix" => {
                let sc = match targ_ty(self, 0, Ty::ScalarKind(ScalarKind::Float))? {
                    Ty::ScalarKind(s) => s,
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
            "SamplerComparisonState" => Ty::SamplerCmp,
            "HitObject" => Ty::HitObject,
            "ByteAddressBuffer" => Ty::ByteAddress(false),
            "RWByteAddressBuffer" => Ty::ByteAddress(true),
            "StructuredBuffer" | "RWStructuredBuffer" => {
                let e = targ_ty(self, 0, Ty::Void)?;
                if e == Ty::Void || e.is_resource() {
                    return Err(Error::new(t.pos, format!("{name} needs an element type")));
                }

                Ty::StructuredBuffer(Box::new(e), name.starts_with("RW"))
            }
            "ConstantBuffer" => match targ_ty(self, 0, Ty::Void)? {
                Ty::Struct(k) => Ty::ConstantBuffer(k),
                _ => return Err(Error::new(t.pos, "ConstantBuffer needs a struct type")),
            },
            "Texture1D" | "Texture2D" | "Texture3D" | "TextureCube" | "Texture2DArray"
            | "Texture1DArray" | "TextureCubeArray" | "RWTexture1D" | "RWTexture2D"
            | "RWTexture3D" | "RWTexture2DArray" | "RWTexture1DArray" | "Buffer" | "RWBuffer" => {
                let rw = name.starts_with("RW");
                let dim = match name.trim_start_matches("RW") {
                    "Texture1D" => Dim::D1,
                    "Texture2D" => Dim::D2,
                    "Texture3D" => Dim::D3,
                    "TextureCube" => Dim::Cube,
                    "Texture1DArray" => Dim::D1Array,
                    "TextureCubeArray" => Dim::CubeArray,
                    "Buffer" => Dim::Buffer,
                    _ => Dim::D2Array,
                };
                let (sc, n) = match targ_ty(self, 0, Ty::Vec(ScalarKind::Float, 4))? {
                    Ty::ScalarKind(s) if s != ScalarKind::Bool && !s.is_64() => (s, 1),
                    Ty::Vec(s, n) if s != ScalarKind::Bool && !s.is_64() => (s, n),
                    _ => {
                        return Err(Error::new(
                            t.pos,
                            "texture elements must be scalars or vectors",
                        ))
                    }
                };
                // DXC's rule for Vulkan: a texel buffer's elements are not
                // 16-bit floats (textures of them are read as 32-bit images).
                if dim == Dim::Buffer && sc == ScalarKind::Half {
                    return Err(Error::new(
                        t.pos,
                        format!(
                            "`{name}` of 16-bit floats: a Vulkan texel buffer's sampled type is at least 32 bits (use `float` elements)"
                        ),
                    )
                    .len(name.len() as u32));
                }
                Ty::Texture {
                    dim,
                    sc,
                    n,
                    rw,
                    fmt: None,
                }
            }
            "AppendStructuredBuffer"
            | "ConsumeStructuredBuffer"
            | "Texture2DMS"
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
            _ if !t.args.is_empty() && self.find_struct_template(name, ns).is_some() => {
                match self.find_struct_template(name, ns) {
                    Some(sd) => self.template_struct_ty(sd, t, ns)?,
                    None => return Err(Error::new(t.pos, format!("unknown type `{name}`"))),
                }
            }
            _ if !self.struct_names.contains_key(name)
                && self.instance_structs.contains_key(name) =>
            {
                if let Some(sd) = self.instance_structs.get(name).copied() {
                    self.declare_struct(sd)?;
                }
                match self.struct_names.get(name) {
                    Some(k) => Ty::Struct(*k),
                    None => return Err(Error::new(t.pos, format!("unknown type `{name}`"))),
                }
            }
            _ => match self.lookup_type_name(name, ns) {
                Some(t) => t,
                None if self.unusable.contains_key(name) => {
                    let mut e = self.unusable[name].clone();
                    e.secondary.push((t.pos, format!("`{name}` is used here")));
                    return Err(e);
                }
                None => {
                    return Err(
                        Error::new(t.pos, format!("unknown type `{name}`")).len(name.len() as u32)
                    )
                }
            },
        })
    }

    pub(super) fn numeric(&mut self, sc: ScalarKind, a: u8, b: u8, pos: Pos) -> Result<Ty> {
        Ok(match (a, b) {
            (0, _) | (1, 0) => Ty::ScalarKind(sc),
            (n, 0) => Ty::Vec(sc, n),
            (r, c) => {
                if !sc.is_float() {
                    return Err(unsupported(pos, "non-float matrices"));
                }
                if r < 2 || c < 2 {
                    return Err(unsupported(pos, "matrices with one row or column"));
                }
                Ty::Mat(sc, r, c)
            }
        })
    }

    pub(super) fn apply_dims(
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

    pub(super) fn declare_globals(&mut self) -> Result<()> {
        let items = self.items;
        // DXC's first two passes (`[[vk::binding]]`, then registers with the
        // options' mapping) before the third, so automatic ones avoid them.
        let mut used: HashSet<(u32, u32)> = HashSet::new();
        for item in items {
            let (attrs, reg) = match item {
                Item::Var(v) => (&v.attrs, &v.register),
                Item::CBuffer {
                    attrs, register, ..
                } => (attrs, register),
                _ => continue,
            };
            // Errors wait for the declaration: this one may not be a resource.
            if let Ok(Some(sb)) = self.explicit_binding(attrs, reg) {
                used.insert(sb);
            }
        }
        let mut globals_members: Vec<&VarDecl> = Vec::new();
        for item in items {
            // Extensions and capabilities a declaration names: an
            // `ext_builtin_input` adds them where it is used, others here.
            let attrs = match item {
                Item::Var(v) => &v.attrs,
                Item::CBuffer { attrs, .. } => attrs,
                _ => &Vec::new(),
            };
            if !attrs.iter().any(is_ext_builtin) {
                let req = self.ext_requirements(attrs)?;
                self.require(&req);
            }
            match item {
                Item::CBuffer {
                    attrs,
                    name,
                    pos,
                    register,
                    members,
                } => {
                    let binding = match self.explicit_binding(attrs, register)? {
                        Some(sb) => Some(sb),
                        None if attrs.iter().any(|a| a.name == "vk::push_constant") => None,
                        None => {
                            Some(self.implicit_binding(&mut used, register, Some('b'), *pos)?)
                        }
                    };
                    no_ext_decorate(attrs, "a `cbuffer`")?;
                    let members: Vec<&VarDecl> = members.iter().collect();
                    self.declare_cbuffer(attrs, name, *pos, binding, &members)?;
                }
                Item::Var(v) if v.attrs.iter().any(is_ext_builtin) => {
                    self.declare_ext_builtin(v)?;
                    self.ext_decorate_global(v)?;
                }
                Item::Var(v) if subobject::Kind::from_type_name(&v.ty.name).is_some() => {
                    no_ext_decorate(&v.attrs, "a subobject")?;
                    self.declare_subobject(v)?
                }
                Item::Var(v) if self.in_implicit_globals(v)? => {
                    no_ext_decorate(&v.attrs, "a member of `$Globals`")?;
                    globals_members.push(v)
                }
                Item::Var(v) => {
                    // A namespace's or struct's names are in scope in its initializers.
                    let scope = v.name.rsplit_once("::").map(|(n, _)| format!("{n}::"));
                    let saved = std::mem::replace(&mut self.f.cur_ns, scope.unwrap_or_default());
                    let r = self.declare_global_var(v, &mut used);
                    self.f.cur_ns = saved;
                    r?;
                    self.ext_decorate_global(v)?;
                }
                _ => {}
            }
        }
        if let Some(first) = globals_members.first() {
            // Plain globals live in the implicit `$Globals` constant buffer, as in DXC.
            let pos = first.pos;
            let b = &self.bindings;
            let binding = match b.bind_globals {
                // As in DXC: where it is told, shifted only as `-fvk-auto-shift-bindings`
                // shifts a `b` register, and not counted as used.
                Some((binding, set)) => {
                    let shift = if b.auto_shift { b.shift('b', set) } else { 0 };
                    (set, binding + shift)
                }
                None if !b.bind_register.is_empty() => return Err(Error::new(
                    pos,
                    "-fvk-bind-register requires Globals buffer to be bound with -fvk-bind-globals",
                )),
                None => self.implicit_binding(&mut used, &None, Some('b'), pos)?,
            };
            self.declare_cbuffer(&[], "$Globals", pos, Some(binding), &globals_members)?;
        }
        // The descriptor heaps' bindings (used only if the heaps are).
        let resources = next_binding(&mut used, 0, 0);
        let samplers = next_binding(&mut used, 0, 0);
        self.heap_bindings = (resources, samplers);
        Ok(())
    }

    /// `[[vk::ext_decorate]]` on a global: decorates its variable; a global
    /// that became a constant has none, and is refused.
    fn ext_decorate_global(&mut self, v: &VarDecl) -> Result<()> {
        if !v.attrs.iter().any(|a| a.name == "vk::ext_decorate") {
            return Ok(());
        }
        match self.globals.get(&v.name) {
            Some(Global::Place(Place::Ptr { ptr, .. })) => {
                let ptr = *ptr;
                self.ext_decorate(&v.attrs, ptr)
            }
            _ => no_ext_decorate(&v.attrs, "a constant"),
        }
    }

    /// A DXR subobject: its content is recorded, nothing is emitted.
    fn declare_subobject(&mut self, v: &VarDecl) -> Result<()> {
        let Some(kind) = subobject::Kind::from_type_name(&v.ty.name) else {
            return Ok(());
        };
        let Some(init) = &v.init else {
            return Err(Error::new(
                v.pos,
                format!("`{}` needs an initializer `{{ ... }}`", v.name),
            ));
        };
        let mut values = Vec::new();
        for e in subobject::fields(kind, init, v.pos)? {
            values.push(match &e.kind {
                ExprKind::Str(s) => subobject::Value::Str(s.clone()),
                _ => subobject::Value::Int(self.subobject_int(e)?),
            });
        }
        let location = self.loc(v.pos, v.name.len() as u32);
        subobject::record(&mut self.subobjects, kind, &v.name, values, location);
        Ok(())
    }

    /// An integer field of a subobject: a constant expression over numbers,
    /// `static const` values and the `RAYTRACING_PIPELINE_FLAG_*` /
    /// `STATE_OBJECT_FLAG*` names.
    fn subobject_int(&mut self, e: &Expr) -> Result<u32> {
        match &e.kind {
            ExprKind::Ident(n) if subobject::flag_constant(n).is_some() => {
                Ok(subobject::flag_constant(n).unwrap_or_default())
            }
            ExprKind::Binary(BinOp::BitOr, a, b) => {
                Ok(self.subobject_int(a)? | self.subobject_int(b)?)
            }
            _ => {
                let v = self.const_int(e)?;
                u32::try_from(v).map_err(|_| {
                    Error::new(e.pos, format!("{v} is out of range for a subobject field"))
                })
            }
        }
    }

    /// Whether a global belongs in `$Globals`: not static, groupshared, a
    /// resource, a push-constant block or a specialization constant.
    pub(super) fn in_implicit_globals(&mut self, v: &VarDecl) -> Result<bool> {
        if v.mods.is_static
            || v.mods.groupshared
            || v.attrs
                .iter()
                .any(|a| a.name == "vk::constant_id" || a.name == "vk::push_constant")
        {
            return Ok(false);
        }
        let t = self.resolve_ty(&v.ty, "")?;
        Ok(!t.is_resource() && !t.is_opaque() && !v.dims.iter().any(Option::is_none))
    }

    pub(super) fn declare_cbuffer(
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

    /// DXC's first two passes for one declaration: `[[vk::binding(b, s)]]`,
    /// else `register(xN, spaceM)` mapped by `-fvk-bind-register` or
    /// shifted by `-fvk-x-shift`. `None` for a binding the third pass picks.
    pub(super) fn explicit_binding(
        &mut self,
        attrs: &[Attr],
        reg: &Option<Register>,
    ) -> Result<Option<(u32, u32)>> {
        if let Some(a) = attrs.iter().find(|a| a.name == "vk::binding") {
            let b = a
                .args
                .first()
                .map(|e| self.const_int(e))
                .transpose()?
                .unwrap_or(0) as u32;
            let s = match a.args.get(1) {
                Some(e) => self.const_int(e)? as u32,
                None => self.bindings.default_space,
            };
            return Ok(Some((s, b)));
        }
        let Some(r) = reg else {
            return Ok(None);
        };
        // `register(cN)` places a constant in `$Globals`, not a resource.
        let Some(index) = r.index.filter(|_| r.class != 'c') else {
            return Ok(None);
        };
        let b = &self.bindings;
        if !b.bind_register.is_empty() {
            return match b.bound_register(r.class, index, r.space) {
                Some(sb) => Ok(Some(sb)),
                None => Err(Error::new(
                    r.pos,
                    format!(
                        "missing -fvk-bind-register for resource: register({}{index}, space{})",
                        r.class, r.space
                    ),
                )),
            };
        }
        Ok(Some((r.space, index + b.shift(r.class, r.space))))
    }

    /// DXC's third pass for one resource without a binding: the next free
    /// binding of its space (`register(spaceM)`) or of the default set,
    /// from the shift of `class` with `-fvk-auto-shift-bindings`.
    pub(super) fn implicit_binding(
        &mut self,
        used: &mut HashSet<(u32, u32)>,
        reg: &Option<Register>,
        class: Option<char>,
        pos: Pos,
    ) -> Result<(u32, u32)> {
        let b = &self.bindings;
        if !b.bind_register.is_empty() {
            return Err(Error::new(
                pos,
                "-fvk-bind-register requires register annotations on all resources",
            ));
        }
        let space = match reg {
            Some(r) => r.space,
            None => b.default_space,
        };
        let start = match class {
            Some(c) if b.auto_shift => b.shift(c, space),
            _ => 0,
        };
        Ok(next_binding(used, space, start))
    }

    /// Layout and storage class of a cbuffer / ConstantBuffer by its attributes.
    pub(super) fn cbuffer_class(&self, attrs: &[Attr]) -> (Layout, StorageClass) {
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
    pub(super) fn resource_var(
        &mut self,
        ty: &Ty,
        attrs: &[Attr],
        binding: Option<(u32, u32)>,
        name: &str,
    ) -> Result<Id> {
        let (tid, class) = self.descriptor_array_type(ty, attrs)?;
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

    /// The SPIR-V type of a descriptor variable of `ty` (a resource or an
    /// array of them, sized or not) and its storage class.
    pub(super) fn descriptor_array_type(
        &mut self,
        ty: &Ty,
        attrs: &[Attr],
    ) -> Result<(Id, StorageClass)> {
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
        Ok((tid, class))
    }

    /// The SPIR-V type of one descriptor (or push-constant / shader-record
    /// block) of `inner`, and its storage class; one id per kind, so arrays of
    /// resources and their elements agree.
    pub(super) fn descriptor_type(
        &mut self,
        inner: &Ty,
        attrs: &[Attr],
    ) -> Result<(Id, StorageClass)> {
        if let Ty::ConstantBuffer(k) = inner {
            let (layout, class) = self.cbuffer_class(attrs);
            return Ok((self.block_struct(*k, layout)?, class));
        }
        if let Ty::Accel | Ty::Sampler | Ty::SamplerCmp | Ty::Texture { .. } = inner {
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
                self.spv(&Ty::ScalarKind(ScalarKind::Uint), Layout::None)?,
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
        if let Ty::StructuredBuffer(e, _) = inner {
            if let Ty::Mat(..) = **e {
                // A buffer of matrices: the layout goes on the member holding them,
                // HLSL's default column-major packing (SPIR-V RowMajor).
                let (_, mstride, _) = matrix_layout(e, false, Layout::Std430);
                self.b.member_decorate(
                    st,
                    0,
                    Decoration::MatrixStride,
                    [Operand::LiteralBit32(mstride)],
                );
                self.b.member_decorate(st, 0, Decoration::RowMajor, []);
            }
        }
        self.b.name(st, name);
        self.ty_cache.insert(key, st);
        Ok((st, StorageClass::StorageBuffer))
    }

    /// A Block-decorated copy of struct `k` laid out for a buffer.
    pub(super) fn block_struct(&mut self, k: u32, layout: Layout) -> Result<Id> {
        let key = (Ty::Struct(k), layout, true);
        if let Some(id) = self.ty_cache.get(&key) {
            return Ok(*id);
        }
        let id = self.struct_type(k, layout, true)?;
        self.ty_cache.insert(key, id);
        Ok(id)
    }

    pub(super) fn declare_global_var(
        &mut self,
        v: &'a VarDecl,
        used: &mut HashSet<(u32, u32)>,
    ) -> Result<()> {
        let t = self.resolve_ty(&v.ty, "")?;
        // `[[vk::push_constant]] S pc;` is DXC's push-constant block, the
        // same as `[[vk::push_constant]] ConstantBuffer<S> pc;`.
        let t = match (t, v.attrs.iter().find(|a| a.name == "vk::push_constant")) {
            (Ty::Struct(k), Some(_)) if v.dims.is_empty() => Ty::ConstantBuffer(k),
            (t @ Ty::ConstantBuffer(_), _) | (t, None) => t,
            (_, Some(a)) => {
                return Err(Error::new(
                    a.pos,
                    "`[[vk::push_constant]]` applies to a variable of struct or `ConstantBuffer<T>` type",
                )
                .len(a.name.len() as u32))
            }
        };
        if let Ty::StructuredBuffer(e, _) = &t {
            if matches!(**e, Ty::Mat(..)) && v.mods.row_major {
                return Err(unsupported(
                    v.pos,
                    "a StructuredBuffer of row_major matrices (wrap the matrix in a struct)",
                ));
            }
        }
        let t = match v.attrs.iter().find(|a| a.name == "vk::image_format") {
            Some(a) => super::formats::with_image_format(t, a)?,
            None => t,
        };
        let res = t.is_resource();
        let t = match (&v.init, v.dims.first()) {
            // `static const float4 a[] = {...}`: sized by its initializer.
            (
                Some(Expr {
                    kind: ExprKind::InitList(items),
                    ..
                }),
                Some(None),
            ) if !res => {
                let inner = self.apply_dims(t, &v.dims[1..], v.pos, res)?;
                Ty::Array(Box::new(inner), items.len() as u32)
            }
            _ => self.apply_dims(t, &v.dims, v.pos, res)?,
        };
        self.decls.push((
            NamedDecl::Global(v.name.clone()),
            self.loc(v.pos, v.name.len() as u32),
        ));
        if t.is_resource() {
            let mut dims = 0;
            let mut inner = &t;
            while let Ty::Array(e, _) | Ty::RtArray(e) = inner {
                dims += 1;
                inner = e;
            }
            if dims > 1 {
                // Vulkan: a descriptor variable is one resource or a
                // one-dimensional array of them.
                return Err(unsupported(
                    v.pos,
                    "arrays of arrays of resources (a Vulkan descriptor array has one dimension: declare `a[N * M]` and index `a[i * M + j]`)",
                )
                .len(v.name.len() as u32));
            }
            let binding = match self.explicit_binding(&v.attrs, &v.register)? {
                Some(sb) => Some(sb),
                None if v.attrs.iter().any(|a| a.name == "vk::push_constant") => None,
                None => Some(self.implicit_binding(
                    used,
                    &v.register,
                    implicit_register_class(&t),
                    v.pos,
                )?),
            };
            let var = self.resource_var(&t, &v.attrs, binding, &v.name)?;
            // Writes are seen by every invocation of the dispatch, not only
            // the workgroup (GLSL450 memory model: the Coherent decoration).
            if v.mods.globally_coherent {
                self.b.decorate(var, Decoration::Coherent, []);
            }
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
        if t.is_opaque() {
            return Err(unsupported(
                v.pos,
                "global RayQuery or HitObject objects (declare them in the function)",
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
        if v.mods.is_const && matches!(t, Ty::ScalarKind(_) | Ty::Vec(..)) {
            if let (Ty::ScalarKind(s), Some(e)) = (&t, &v.init) {
                if let Some(c) = self.const_eval(e)? {
                    let c = match (s, c) {
                        (s, c) if s.is_float() => ConstValue::F(c.as_f64()),
                        (_, ConstValue::F(f)) => ConstValue::I(f as i64),
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
            let scope = v.name.rsplit_once("::").map(|(n, _)| format!("{n}::"));
            self.deferred_inits
                .push((var, t.clone(), e, scope.unwrap_or_default()));
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
    pub(super) fn spec_constant(&mut self, v: &VarDecl, a: &Attr, t: &Ty) -> Result<()> {
        let id_expr = a
            .args
            .first()
            .ok_or_else(|| Error::new(a.pos, "vk::constant_id needs an id"))?;
        let spec_id = self.const_int(id_expr)? as u32;
        let Ty::ScalarKind(s) = t else {
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
            ScalarKind::Bool if default.as_f64() != 0.0 => self.b.spec_constant_true(tid),
            ScalarKind::Bool => self.b.spec_constant_false(tid),
            ScalarKind::Float => self
                .b
                .spec_constant_bit32(tid, (default.as_f64() as f32).to_bits()),
            // A 16-bit literal is one word: the value in its low bits,
            // zero-extended (floats, unsigned) or sign-extended (signed).
            ScalarKind::Half => self.b.spec_constant_bit32(
                tid,
                super::consts::f32_to_f16(default.as_f64() as f32) as u32,
            ),
            _ => {
                let i = match default {
                    ConstValue::I(i) => i,
                    ConstValue::F(f) => f as i64,
                };
                if s.is_64() {
                    self.b.spec_constant_bit64(tid, i as u64)
                } else if *s == ScalarKind::Int16 {
                    self.b.spec_constant_bit32(tid, i as i16 as i32 as u32)
                } else if *s == ScalarKind::Uint16 {
                    self.b.spec_constant_bit32(tid, i as u16 as u32)
                } else {
                    self.b.spec_constant_bit32(tid, i as u32)
                }
            }
        };
        self.b
            .decorate(id, Decoration::SpecId, [Operand::LiteralBit32(spec_id)]);
        self.b.name(id, v.name.clone());
        self.globals
            .insert(v.name.clone(), Global::Const(Val { id, ty: t.clone() }));
        Ok(())
    }
}

/// The local a function returns in every `return` (`return q;`), if one.
pub(super) fn ret_slot_name(f: &Function) -> Option<String> {
    fn walk(s: &Stmt, out: &mut Vec<Option<String>>) {
        match &s.kind {
            StmtKind::Return(Some(Expr {
                kind: ExprKind::Ident(n),
                ..
            })) => out.push(Some(n.clone())),
            StmtKind::Return(_) => out.push(None),
            StmtKind::Block(b) => b.iter().for_each(|s| walk(s, out)),
            StmtKind::If(_, a, b) => {
                walk(a, out);
                if let Some(b) = b {
                    walk(b, out);
                }
            }
            StmtKind::For(i, _, _, b) => {
                if let Some(i) = i {
                    walk(i, out);
                }
                walk(b, out);
            }
            StmtKind::While(_, b) | StmtKind::DoWhile(b, _) => walk(b, out),
            StmtKind::Switch(_, cases) => cases
                .iter()
                .for_each(|c| c.body.iter().for_each(|s| walk(s, out))),
            _ => {}
        }
    }
    let mut out = Vec::new();
    f.body.as_ref()?.iter().for_each(|s| walk(s, &mut out));
    let first = out.first()?.clone()?;
    out.iter()
        .all(|n| n.as_deref() == Some(first.as_str()))
        .then_some(first)
}

/// The default values of `f`'s trailing parameters; every parameter after one
/// with a default value needs one too.
fn defaults_of(f: &Function) -> Result<Vec<&Expr>> {
    let Some(first) = f.params.iter().position(|p| p.init.is_some()) else {
        return Ok(Vec::new());
    };
    f.params[first..]
        .iter()
        .map(|p| {
            p.init.as_ref().ok_or_else(|| {
                Error::new(
                    p.pos,
                    format!(
                        "parameter `{}` follows one with a default value and needs one too",
                        p.name
                    ),
                )
            })
        })
        .collect()
}

/// Arrays of buffers cannot be function parameters (a function is copied per
/// buffer passed); arrays of textures, samplers and acceleration structures
/// are passed as their variable.
fn bad_resource_array(t: &Ty) -> bool {
    match t {
        Ty::Array(e, _) | Ty::RtArray(e) => !matches!(
            **e,
            Ty::Accel | Ty::Sampler | Ty::SamplerCmp | Ty::Texture { .. }
        ),
        _ => false,
    }
}

/// `vk::ext_builtin_input` or `vk::ext_builtin_output`: the variable is a
/// built-in, its extensions and capabilities needed only where it is used.
fn is_ext_builtin(a: &Attr) -> bool {
    matches!(
        a.name.as_str(),
        "vk::ext_builtin_input" | "vk::ext_builtin_output"
    )
}

/// The next free binding of `set` from `start` (DXC's "next available
/// binding number").
fn next_binding(used: &mut HashSet<(u32, u32)>, set: u32, start: u32) -> (u32, u32) {
    let mut b = start;
    while used.contains(&(set, b)) {
        b += 1;
    }
    used.insert((set, b));
    (set, b)
}

/// The register class DXC infers from a resource's type for
/// `-fvk-auto-shift-bindings`; none for an acceleration structure.
fn implicit_register_class(t: &Ty) -> Option<char> {
    match t {
        Ty::Array(e, _) | Ty::RtArray(e) => implicit_register_class(e),
        Ty::Texture { rw: true, .. } | Ty::StructuredBuffer(_, true) | Ty::ByteAddress(true) => {
            Some('u')
        }
        Ty::Texture { .. } | Ty::StructuredBuffer(..) | Ty::ByteAddress(_) => Some('t'),
        Ty::Sampler | Ty::SamplerCmp => Some('s'),
        Ty::ConstantBuffer(_) => Some('b'),
        _ => None,
    }
}
