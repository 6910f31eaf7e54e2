//! Places: names, members, indices, and reading and writing through them.

use super::*;

impl<'a> Lowerer<'a> {
    pub(super) fn bind(&mut self, name: &str, p: Place) {
        if let Some(s) = self.f.scopes.last_mut() {
            s.insert(name.to_string(), p);
        }
    }

    // ---- places --------------------------------------------------------

    pub(super) fn lookup(&mut self, name: &str, pos: Pos) -> Result<Place> {
        for s in self.f.scopes.iter().rev() {
            if let Some(p) = s.get(name) {
                return Ok(p.clone());
            }
        }
        if let Some(this) = self.f.this_place.clone() {
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
        let candidates = self.scoped_names(name);
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
                ty: Ty::ScalarKind(ScalarKind::Uint),
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
    pub(super) fn sub_place(
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
                        ty: Ty::Vec(
                            elem.scalar().unwrap_or(ScalarKind::Float),
                            comps.len() as u8,
                        ),
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

    pub(super) fn extract_dynamic(
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

    pub(super) fn place(&mut self, e: &'a Expr) -> Result<Place> {
        match &e.kind {
            ExprKind::Ident(n) => self.lookup(n, e.pos),
            ExprKind::Member(base, name) => {
                let bp = self.place(base)?;
                self.member(bp, name, e.pos)
            }
            ExprKind::Index(base, idx) => {
                let bp = self.place(base)?;
                let iv = self.expr(idx)?;
                if !matches!(iv.ty, Ty::ScalarKind(_) | Ty::Vec(..)) {
                    return Err(Error::new(idx.pos, "index must be an integer"));
                }
                self.index(bp, iv, idx, e.pos)
            }
            ExprKind::Call(name, args) if self.returns_resource(name) => {
                self.resource_call(name, args, e.pos)
            }
            // A method returning a resource, called in another method.
            ExprKind::Call(name, args)
                if self
                    .f
                    .this_place
                    .as_ref()
                    .is_some_and(|t| self.resource_method(t, name).is_some()) =>
            {
                let this = self.f.this_place.clone().unwrap_or(Place::Value(Val {
                    id: 0,
                    ty: Ty::Void,
                }));
                let c = self.resource_method(&this, name).unwrap_or_default();
                self.inline_resource_call(name, c, Some(this), args, e.pos)
            }
            // `obj.m(...)`: a method returning a resource names it.
            ExprKind::Method(obj, name, args) => {
                self.line(e.pos);
                let this = self.place(obj)?;
                if let Some(c) = self.resource_method(&this, name) {
                    return self.inline_resource_call(name, c, Some(this), args, e.pos);
                }
                match self.method_at(this, obj, name, args, e.pos)? {
                    Some(v) => Ok(Place::Value(v)),
                    None => Err(Error::new(
                        e.pos,
                        "this call has no value (it returns void)",
                    )),
                }
            }
            // `(Texture2D<float4>)ResourceDescriptorHeap[i]`.
            ExprKind::Cast(tref, inner) if Self::heap_index(inner).is_some() => {
                let ns = self.f.cur_ns.clone();
                let t = self.resolve_ty(tref, &ns)?;
                match Self::heap_index(inner) {
                    Some((sampler, idx)) => self.heap_place(sampler, idx, &t, e.pos),
                    None => Err(Error::new(e.pos, "expected a descriptor heap element")),
                }
            }
            _ => Ok(Place::Value(self.expr(e)?)),
        }
    }

    pub(super) fn member(&mut self, bp: Place, name: &str, pos: Pos) -> Result<Place> {
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
            Ty::ScalarKind(s) | Ty::Vec(s, _) => {
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
                if let Ty::ScalarKind(_) = t {
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
                    return self.sub_place(bp, c, Some(comps[0]), Ty::ScalarKind(*s), pos);
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
                    return self.sub_place(row, cj, Some(j), Ty::ScalarKind(*s), pos);
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

    pub(super) fn index(&mut self, bp: Place, iv: Val, idx: &'a Expr, pos: Pos) -> Result<Place> {
        let t = bp.ty().clone();
        if let Ty::Struct(k) = &t {
            // `s[i]` of a struct with `operator[]`: a call (its result is read-only).
            let key = format!("{}::operator[]", self.structs[*k as usize].name);
            if let Some(c) = self.fn_by_name.get(&key).cloned() {
                let args = vec![
                    super::calls::Arg::Place(bp, pos),
                    super::calls::Arg::Value(iv, idx.pos),
                ];
                return match self.call_user("operator[]", c, args, pos)? {
                    Some(v) => Ok(Place::Value(v)),
                    None => Err(Error::new(pos, "`operator[]` returns nothing")),
                };
            }
        }
        let const_index = match self.const_eval(idx)? {
            Some(ConstValue::I(v)) if v >= 0 => Some(v as u32),
            _ => None,
        };
        let scalar_index = |this: &mut Self, iv: Val| -> Result<Id> {
            let nu = this.nonuniform.contains(&iv.id);
            let v = match iv.ty {
                Ty::ScalarKind(ScalarKind::Int) | Ty::ScalarKind(ScalarKind::Uint) => iv,
                _ => this.convert(iv, &Ty::ScalarKind(ScalarKind::Uint), idx.pos, false)?,
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
                self.sub_place(bp, i, const_index, Ty::ScalarKind(*s), pos)
            }
            Ty::Mat(s, _, c) => {
                let i = scalar_index(self, iv)?;
                self.sub_place(bp, i, const_index, Ty::Vec(*s, *c), pos)
            }
            Ty::StructuredBuffer(e, _) => {
                let i = scalar_index(self, iv)?;
                let Place::Ptr { ptr, class, .. } = bp else {
                    return Err(not_a_variable(pos));
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
            Ty::Texture {
                dim: Dim::Cube | Dim::CubeArray,
                ..
            } => Err(Error::new(
                pos,
                "a TextureCube cannot be indexed; use SampleLevel",
            )),
            Ty::Texture { rw, sc, n, dim, .. } => {
                let Place::Ptr { ptr, .. } = bp else {
                    return Err(not_a_variable(pos));
                };
                let cn = self.coord_size(*dim, false);
                let ct = if cn == 1 {
                    Ty::ScalarKind(ScalarKind::Int)
                } else {
                    Ty::Vec(ScalarKind::Int, cn)
                };
                let coord = self.convert(iv, &ct, idx.pos, false)?;
                let texel = if *n == 1 {
                    Ty::ScalarKind(*sc)
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

    pub(super) fn coord_size(&self, dim: Dim, sampling: bool) -> u8 {
        match dim {
            Dim::D1 | Dim::Buffer => 1,
            Dim::D2 | Dim::D1Array => 2,
            Dim::D3 | Dim::D2Array => 3,
            Dim::Cube => {
                if sampling {
                    3
                } else {
                    2
                }
            }
            Dim::CubeArray => {
                if sampling {
                    4
                } else {
                    3
                }
            }
        }
    }

    pub(super) fn read(&mut self, p: &Place) -> Result<Val> {
        match p {
            Place::Ptr {
                ptr,
                ty,
                layout,
                class,
            } => {
                if ty.is_resource() || ty.is_opaque() {
                    return Ok(Val {
                        id: *ptr,
                        ty: ty.clone(),
                    });
                }
                if *layout != Layout::None && self.has_bool(ty) {
                    return self.load_bools(*ptr, ty, *layout, *class);
                }
                let tid = self.spv(ty, *layout)?;
                if self.f.term {
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
                let s = ty.scalar().unwrap_or(ScalarKind::Float).wide();
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

    pub(super) fn has_bool(&self, t: &Ty) -> bool {
        match t {
            Ty::ScalarKind(ScalarKind::Bool) | Ty::Vec(ScalarKind::Bool, _) => true,
            Ty::Array(e, _) | Ty::RtArray(e) => self.has_bool(e),
            Ty::Struct(k) => self.structs[*k as usize]
                .fields
                .iter()
                .any(|f| self.has_bool(&f.ty)),
            _ => false,
        }
    }

    /// Parts of an aggregate with their indices and types.
    pub(super) fn parts(&self, t: &Ty) -> Vec<(u32, Ty)> {
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
    pub(super) fn load_bools(
        &mut self,
        ptr: Id,
        t: &Ty,
        layout: Layout,
        class: StorageClass,
    ) -> Result<Val> {
        if let Ty::ScalarKind(_) | Ty::Vec(..) = t {
            let ut = self.spv(t, layout)?;
            let raw = self.b.load(ut, None, ptr, None, [])?;
            return self.convert_scalar(raw, ScalarKind::Uint, ScalarKind::Bool, t);
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

    pub(super) fn store_bools(
        &mut self,
        ptr: Id,
        v: Val,
        layout: Layout,
        class: StorageClass,
    ) -> Result<()> {
        if let Ty::ScalarKind(_) | Ty::Vec(..) = v.ty {
            let ut = v.ty.with_scalar(ScalarKind::Uint);
            let raw = self.convert_scalar(v.id, ScalarKind::Bool, ScalarKind::Uint, &ut)?;
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
    pub(super) fn shrink(&mut self, v: Val, to: &Ty) -> Result<Val> {
        if &v.ty == to {
            return Ok(v);
        }
        // A 16-bit texel read as its 32-bit kind: narrowed after shrinking.
        if let (Some(from), Some(s)) = (v.ty.scalar(), to.scalar()) {
            if from != s {
                let wide = self.shrink(v, &to.with_scalar(from))?;
                return self.convert_scalar(wide.id, from, s, to);
            }
        }
        let tid = self.ty_id(to)?;
        let id = match to {
            Ty::ScalarKind(_) => self.inst(
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

    pub(super) fn write(&mut self, p: &Place, v: Val, pos: Pos) -> Result<()> {
        match p {
            Place::Ptr {
                ptr,
                ty,
                layout,
                class,
            } => {
                if ty.is_resource() || ty.is_opaque() {
                    return Err(unsupported(pos, "assigning resources or ray queries"));
                }
                if read_only(*class) {
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
                if self.f.term {
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
                // 16-bit texels are stored as their 32-bit kind.
                let s = ty.scalar().unwrap_or(ScalarKind::Float).wide();
                let v = self.convert(v, &ty.with_scalar(s), pos, true)?;
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
    pub(super) fn widen4(&mut self, v: Val, s: ScalarKind) -> Result<Id> {
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
}
