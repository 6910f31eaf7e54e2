//! Methods of resources and ray queries.

use super::*;

impl<'a> Lowerer<'a> {
    pub(super) fn method(
        &mut self,
        obj: &'a Expr,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let p = self.place(obj)?;
        self.method_at(p, obj, name, args, pos)
    }

    /// A method of the object at `p` (the place of `obj`).
    pub(super) fn method_at(
        &mut self,
        p: Place,
        obj: &'a Expr,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        if let Some(c) = self.resource_method(&p, name) {
            let r = self.inline_resource_call(name, c, Some(p), args, pos)?;
            return self.read(&r).map(Some);
        }
        if let Ty::ConstantBuffer(k) = *p.ty() {
            // `cb.m()` of a `ConstantBuffer<S>`: `S::m` on a copy of its contents.
            let v = self.struct_of(p, k, obj.pos)?;
            return self.method_at(Place::Value(v), obj, name, args, pos);
        }
        let t = p.ty().clone();
        match &t {
            Ty::Struct(k) => {
                let qualified = format!("{}::{name}", self.structs[*k as usize].name);
                let Some(c) = self.fn_by_name.get(&qualified).cloned() else {
                    return Err(Error::new(
                        pos,
                        format!("`{}` has no method `{name}`", self.ty_name(&t)),
                    )
                    .len(name.len() as u32));
                };
                // A method of an rvalue, or of a constant buffer member or a
                // stage input (which a method must not change), works on a copy.
                let p = match p {
                    Place::Ptr { class, .. } if read_only(class) => Place::Value(self.read(&p)?),
                    other => other,
                };
                let this = match p {
                    Place::Value(v) => {
                        let tmp = self.local_var(&v.ty, "")?;
                        self.b.store(tmp, v.id, None, [])?;
                        Place::Ptr {
                            ptr: tmp,
                            ty: v.ty,
                            layout: Layout::None,
                            class: StorageClass::Function,
                        }
                    }
                    other => other,
                };
                let mut all = vec![super::calls::Arg::Place(this, obj.pos)];
                all.extend(args.iter().map(super::calls::Arg::Expr));
                self.call_user(name, c, all, pos)
            }
            Ty::HitObject => {
                let Place::Ptr { ptr, .. } = p else {
                    return Err(Error::new(obj.pos, "a HitObject must be a local variable"));
                };
                self.hit_object_method(ptr, name, args, pos)
            }
            Ty::RayQuery(flags) => {
                let Place::Ptr { ptr, .. } = p else {
                    return Err(Error::new(obj.pos, "a RayQuery must be a local variable"));
                };
                self.ray_query(ptr, *flags, name, args, pos)
            }
            Ty::Texture { .. } => {
                let Place::Ptr { ptr, .. } = p else {
                    return Err(not_a_variable(pos));
                };
                self.texture(ptr, &t, name, args, pos)
            }
            Ty::StructuredBuffer(e, _) => {
                let Place::Ptr { ptr, .. } = p.clone() else {
                    return Err(not_a_variable(pos));
                };
                match name {
                    "Load" => {
                        self.arity(name, args, 1, pos)?;
                        let i = self.expr(&args[0])?;
                        let el = self.index(p, i, &args[0], pos)?;
                        Ok(Some(self.read(&el)?))
                    }
                    "GetDimensions" => {
                        self.arity(name, args, 2, pos)?;
                        let ut = self.ty_id(&Ty::ScalarKind(ScalarKind::Uint))?;
                        let n = self.inst(
                            Op::ArrayLength,
                            Some(ut),
                            vec![Operand::IdRef(ptr), Operand::LiteralBit32(0)],
                        )?;
                        let stride = array_stride(e, Layout::Std430, &self.structs);
                        let s = self.const_u32(stride);
                        self.out_arg(
                            &args[0],
                            Val {
                                id: n,
                                ty: Ty::ScalarKind(ScalarKind::Uint),
                            },
                        )?;
                        self.out_arg(
                            &args[1],
                            Val {
                                id: s,
                                ty: Ty::ScalarKind(ScalarKind::Uint),
                            },
                        )?;
                        Ok(None)
                    }
                    _ => Err(Error::new(
                        pos,
                        format!("{} has no method `{name}`", self.ty_name(&t)),
                    )),
                }
            }
            Ty::ByteAddress(rw) => {
                let Place::Ptr { ptr, .. } = p else {
                    return Err(not_a_variable(pos));
                };
                self.byte_address(ptr, *rw, name, args, pos)
            }
            _ => Err(Error::new(
                pos,
                format!("`{}` has no method `{name}`", self.ty_name(&t)),
            )
            .len(name.len() as u32)),
        }
    }

    fn out_arg(&mut self, a: &'a Expr, v: Val) -> Result<()> {
        let p = self.place(a)?;
        let t = p.ty().clone();
        let v = self.convert(v, &t, a.pos, true)?;
        self.write(&p, v, a.pos)
    }

    pub(super) fn byte_address(
        &mut self,
        var: Id,
        rw: bool,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let ut = self.ty_id(&u)?;
        let pty = self.b.type_pointer(None, StorageClass::StorageBuffer, ut);
        if let Some(op) = name.strip_prefix("Interlocked") {
            if !rw {
                return Err(Error::new(
                    pos,
                    "a ByteAddressBuffer is read-only; use RWByteAddressBuffer",
                ));
            }
            let Some(addr) = args.first() else {
                return Err(Error::new(pos, format!("`{name}` needs a byte address")));
            };
            let a = self.expr(addr)?;
            let a = self.convert(a, &u, addr.pos, false)?;
            let two = Val {
                id: self.const_u32(2),
                ty: u.clone(),
            };
            let word = self.binary(BinOp::Shr, a, two, pos)?;
            let zero = self.const_u32(0);
            let ptr = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![
                    Operand::IdRef(var),
                    Operand::IdRef(zero),
                    Operand::IdRef(word.id),
                ],
            )?;
            let dest = Place::Ptr {
                ptr,
                ty: u,
                layout: Layout::Std430,
                class: StorageClass::StorageBuffer,
            };
            return self.atomic(&format!("Interlocked{op}"), dest, addr.pos, &args[1..], pos);
        }
        let n = match name {
            "Load" | "Store" => 1,
            "Load2" | "Store2" => 2,
            "Load3" | "Store3" => 3,
            "Load4" | "Store4" => 4,
            "GetDimensions" => {
                self.arity(name, args, 1, pos)?;
                let len = self.inst(
                    Op::ArrayLength,
                    Some(ut),
                    vec![Operand::IdRef(var), Operand::LiteralBit32(0)],
                )?;
                let four = Val {
                    id: self.const_u32(4),
                    ty: u.clone(),
                };
                let bytes = self.binary(
                    BinOp::Mul,
                    Val {
                        id: len,
                        ty: u.clone(),
                    },
                    four,
                    pos,
                )?;
                self.out_arg(&args[0], bytes)?;
                return Ok(None);
            }
            _ => {
                return Err(
                    Error::new(pos, format!("ByteAddressBuffer has no method `{name}`"))
                        .len(name.len() as u32),
                )
            }
        };
        let store = name.starts_with("Store");
        if store && !rw {
            return Err(Error::new(
                pos,
                "a ByteAddressBuffer is read-only; use RWByteAddressBuffer",
            ));
        }
        self.arity(name, args, if store { 2 } else { 1 }, pos)?;
        let addr = self.expr(&args[0])?;
        let addr = self.convert(addr, &u, args[0].pos, false)?;
        let two = Val {
            id: self.const_u32(2),
            ty: u.clone(),
        };
        let word = self.binary(BinOp::Shr, addr, two, pos)?;
        let zero = self.const_u32(0);
        let vt = if n == 1 {
            u.clone()
        } else {
            Ty::Vec(ScalarKind::Uint, n)
        };
        let value = if store {
            let v = self.expr(&args[1])?;
            let v = self.convert(v, &vt, args[1].pos, false)?;
            let mut comps = Vec::new();
            self.flatten(v, &mut comps)?;
            Some(comps)
        } else {
            None
        };
        let mut loaded = Vec::new();
        for i in 0..n as u32 {
            let off = Val {
                id: self.const_u32(i),
                ty: u.clone(),
            };
            let w = self.binary(BinOp::Add, word.clone(), off, pos)?;
            let ptr = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![
                    Operand::IdRef(var),
                    Operand::IdRef(zero),
                    Operand::IdRef(w.id),
                ],
            )?;
            match &value {
                Some(comps) => self.b.store(ptr, comps[i as usize].id, None, [])?,
                None => loaded.push(Val {
                    id: self.b.load(ut, None, ptr, None, [])?,
                    ty: u.clone(),
                }),
            }
        }
        if store {
            return Ok(None);
        }
        if n == 1 {
            return Ok(loaded.pop());
        }
        let mut it = loaded.into_iter();
        Ok(Some(self.build(&vt, &mut it, pos)?))
    }

    /// Loads an image handle from its variable (or array element pointer).
    fn image(&mut self, ptr: Id, t: &Ty) -> Result<Id> {
        let it = self.ty_id(t)?;
        let id = self.b.load(it, None, ptr, None, [])?;
        if self.nonuniform_ptr(ptr) {
            self.b.decorate(id, Decoration::NonUniform, []);
        }
        Ok(id)
    }

    fn nonuniform_ptr(&self, ptr: Id) -> bool {
        self.nonuniform_ptrs.contains(&ptr)
    }

    pub(super) fn fetch(&mut self, ptr: Id, t: &Ty, coord: Id, lod: Option<Id>) -> Result<Val> {
        let Ty::Texture { sc, n, .. } = t else {
            unreachable!("fetch on a texture")
        };
        let im = self.image(ptr, t)?;
        let v4 = Ty::Vec(sc.wide(), 4);
        let vt = self.ty_id(&v4)?;
        let mut ops = vec![Operand::IdRef(im), Operand::IdRef(coord)];
        // Texel buffers have no mip levels.
        if !matches!(
            t,
            Ty::Texture {
                dim: Dim::Buffer,
                ..
            }
        ) {
            let lod = match lod {
                Some(l) => l,
                None => self.const_i32(0),
            };
            ops.push(Operand::ImageOperands(spirv::ImageOperands::LOD));
            ops.push(Operand::IdRef(lod));
        }
        let id = self.inst(Op::ImageFetch, Some(vt), ops)?;
        let texel = if *n == 1 {
            Ty::ScalarKind(*sc)
        } else {
            Ty::Vec(*sc, *n)
        };
        self.shrink(Val { id, ty: v4 }, &texel)
    }

    fn texture(
        &mut self,
        ptr: Id,
        t: &Ty,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let Ty::Texture { dim, sc, n, rw, .. } = t.clone() else {
            unreachable!("texture method")
        };
        let texel = if n == 1 {
            Ty::ScalarKind(sc)
        } else {
            Ty::Vec(sc, n)
        };
        let cn = self.coord_size(dim, true);
        let float_coord = if cn == 1 {
            Ty::ScalarKind(ScalarKind::Float)
        } else {
            Ty::Vec(ScalarKind::Float, cn)
        };
        match name {
            _ if dim == Dim::Buffer && name.starts_with("Sample") => Err(Error::new(
                pos,
                format!("a Buffer has no `{name}`; use Load or []"),
            )),
            "Sample" if self.f.cur_stage.is_some_and(|s| s != Stage::Fragment) => Err(unsupported(
                pos,
                "`Sample` (implicit level of detail) outside pixel shaders; use `SampleLevel`",
            )
            .len(6)),
            "SampleCmp" | "SampleCmpLevelZero" | "SampleCmpLevel" => self
                .sample_cmp(ptr, t, float_coord, name, args, pos)
                .map(Some),
            "Sample" | "SampleLevel" | "SampleGrad" => {
                if rw {
                    return Err(Error::new(pos, format!("RWTexture has no method `{name}`")));
                }
                if name == "Sample" && self.f.cur_stage.is_none() {
                    // Implicit LOD takes derivatives: checked against the reaching entry points.
                    self.fn_derivs
                        .entry(self.f.cur_fn)
                        .or_insert(("Sample", pos));
                }
                let want = match name {
                    "Sample" => 2,
                    "SampleLevel" => 3,
                    _ => 4,
                };
                self.arity(name, args, want, pos)?;
                let s = self.expr(&args[0])?;
                if s.ty != Ty::Sampler {
                    return Err(Error::new(args[0].pos, "expected a SamplerState"));
                }
                let uv = self.expr(&args[1])?;
                let uv = self.convert(uv, &float_coord, args[1].pos, false)?;
                let im = self.image(ptr, t)?;
                let st = self.ty_id(&Ty::Sampler)?;
                let sm = self.b.load(st, None, s.id, None, [])?;
                let it = self.ty_id(t)?;
                let sit = self.b.type_sampled_image(it);
                let si = self.op(Op::SampledImage, sit, &[im, sm])?;
                let v4 = Ty::Vec(sc.wide(), 4);
                let vt = self.ty_id(&v4)?;
                let mut ops = vec![Operand::IdRef(si), Operand::IdRef(uv.id)];
                if name == "Sample" {
                    let id = self.inst(Op::ImageSampleImplicitLod, Some(vt), ops)?;
                    return Ok(Some(self.shrink(Val { id, ty: v4 }, &texel)?));
                } else if name == "SampleLevel" {
                    let lod = self.expr(&args[2])?;
                    let lod =
                        self.convert(lod, &Ty::ScalarKind(ScalarKind::Float), args[2].pos, false)?;
                    ops.push(Operand::ImageOperands(spirv::ImageOperands::LOD));
                    ops.push(Operand::IdRef(lod.id));
                } else {
                    let gt = if matches!(dim, Dim::Cube | Dim::CubeArray | Dim::D3) {
                        Ty::Vec(ScalarKind::Float, 3)
                    } else if matches!(dim, Dim::D1 | Dim::D1Array) {
                        Ty::ScalarKind(ScalarKind::Float)
                    } else {
                        Ty::Vec(ScalarKind::Float, 2)
                    };
                    let dx = self.expr(&args[2])?;
                    let dx = self.convert(dx, &gt, args[2].pos, false)?;
                    let dy = self.expr(&args[3])?;
                    let dy = self.convert(dy, &gt, args[3].pos, false)?;
                    ops.push(Operand::ImageOperands(spirv::ImageOperands::GRAD));
                    ops.push(Operand::IdRef(dx.id));
                    ops.push(Operand::IdRef(dy.id));
                }
                let id = self.inst(Op::ImageSampleExplicitLod, Some(vt), ops)?;
                Ok(Some(self.shrink(Val { id, ty: v4 }, &texel)?))
            }
            "Load" if dim == Dim::Buffer && !rw => {
                self.arity(name, args, 1, pos)?;
                let c = self.expr_as(&args[0], &Ty::ScalarKind(ScalarKind::Int))?;
                Ok(Some(self.fetch(ptr, t, c.id, None)?))
            }
            "Load" if matches!(dim, Dim::Cube | Dim::CubeArray) => Err(Error::new(
                pos,
                "a TextureCube has no `Load`; use SampleLevel",
            )),
            "Load" => {
                self.arity(name, args, 1, pos)?;
                let c = self.expr(&args[0])?;
                let icn = self.coord_size(dim, false);
                if rw {
                    let ct = if icn == 1 {
                        Ty::ScalarKind(ScalarKind::Int)
                    } else {
                        Ty::Vec(ScalarKind::Int, icn)
                    };
                    let coord = self.convert(c, &ct, args[0].pos, false)?;
                    let pl = Place::Texel {
                        image: ptr,
                        img: t.clone(),
                        coord: coord.id,
                        ty: texel,
                    };
                    return Ok(Some(self.read(&pl)?));
                }
                // Sampled textures: the last component is the mip level.
                let full = Ty::Vec(ScalarKind::Int, icn + 1);
                let c = self.convert(c, &full, args[0].pos, false)?;
                let ct = if icn == 1 {
                    Ty::ScalarKind(ScalarKind::Int)
                } else {
                    Ty::Vec(ScalarKind::Int, icn)
                };
                let ctid = self.ty_id(&ct)?;
                let coord = if icn == 1 {
                    self.inst(
                        Op::CompositeExtract,
                        Some(ctid),
                        vec![Operand::IdRef(c.id), Operand::LiteralBit32(0)],
                    )?
                } else {
                    let mut ops = vec![Operand::IdRef(c.id), Operand::IdRef(c.id)];
                    ops.extend((0..icn as u32).map(Operand::LiteralBit32));
                    self.inst(Op::VectorShuffle, Some(ctid), ops)?
                };
                let it = self.ty_id(&Ty::ScalarKind(ScalarKind::Int))?;
                let lod = self.inst(
                    Op::CompositeExtract,
                    Some(it),
                    vec![Operand::IdRef(c.id), Operand::LiteralBit32(icn as u32)],
                )?;
                Ok(Some(self.fetch(ptr, t, coord, Some(lod))?))
            }
            "GetDimensions" => {
                self.cap(Capability::ImageQuery);
                let icn = self.coord_size(dim, false);
                let (mip, outs) = match args.len() {
                    k if k == icn as usize => (None, args),
                    k if k == icn as usize + 2 && !rw => (Some(&args[0]), &args[1..]),
                    _ => return Err(Error::new(pos, format!("`GetDimensions` takes {icn} out arguments (or a mip level, {icn} sizes and a level count)"))),
                };
                let qt = if icn == 1 {
                    Ty::ScalarKind(ScalarKind::Uint)
                } else {
                    Ty::Vec(ScalarKind::Uint, icn)
                };
                let qtid = self.ty_id(&qt)?;
                let im = self.image(ptr, t)?;
                let size = if rw || dim == Dim::Buffer {
                    self.op(Op::ImageQuerySize, qtid, &[im])?
                } else {
                    let lod = match mip {
                        Some(m) => {
                            let v = self.expr(m)?;
                            self.convert(v, &Ty::ScalarKind(ScalarKind::Uint), m.pos, false)?
                                .id
                        }
                        None => self.const_u32(0),
                    };
                    self.op(Op::ImageQuerySizeLod, qtid, &[im, lod])?
                };
                let mut comps = Vec::new();
                self.flatten(Val { id: size, ty: qt }, &mut comps)?;
                for (a, c) in outs.iter().zip(comps) {
                    self.out_arg(a, c)?;
                }
                if mip.is_some() {
                    let ut = self.ty_id(&Ty::ScalarKind(ScalarKind::Uint))?;
                    let levels = self.op(Op::ImageQueryLevels, ut, &[im])?;
                    self.out_arg(
                        &outs[icn as usize],
                        Val {
                            id: levels,
                            ty: Ty::ScalarKind(ScalarKind::Uint),
                        },
                    )?;
                }
                Ok(None)
            }
            _ => Err(
                Error::new(pos, format!("{} has no method `{name}`", self.ty_name(t)))
                    .len(name.len() as u32),
            ),
        }
    }

    fn ray_query(
        &mut self,
        q: Id,
        flags: u32,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let f = Ty::ScalarKind(ScalarKind::Float);
        let b = Ty::ScalarKind(ScalarKind::Bool);
        let f3 = Ty::Vec(ScalarKind::Float, 3);
        match name {
            "TraceRayInline" => {
                self.arity(name, args, 4, pos)?;
                let accel = self.expr(&args[0])?;
                if accel.ty != Ty::Accel {
                    return Err(Error::new(
                        args[0].pos,
                        "expected a RaytracingAccelerationStructure",
                    ));
                }
                let at = self.ty_id(&Ty::Accel)?;
                let a = self.b.load(at, None, accel.id, None, [])?;
                let fl = self.expr(&args[1])?;
                let mut fl = self.convert(fl, &u, args[1].pos, false)?;
                if flags != 0 {
                    let k = Val {
                        id: self.const_u32(flags),
                        ty: u.clone(),
                    };
                    fl = self.binary(BinOp::BitOr, fl, k, pos)?;
                }
                let mask = self.expr(&args[2])?;
                let mask = self.convert(mask, &u, args[2].pos, false)?;
                let ray = self.expr_as(&args[3], &Ty::Struct(RAY_DESC))?;
                let mut parts = Vec::new();
                for (i, t) in [f3.clone(), f.clone(), f3.clone(), f.clone()]
                    .iter()
                    .enumerate()
                {
                    let tid = self.ty_id(t)?;
                    parts.push(self.inst(
                        Op::CompositeExtract,
                        Some(tid),
                        vec![Operand::IdRef(ray.id), Operand::LiteralBit32(i as u32)],
                    )?);
                }
                let mut ops = vec![q, a, fl.id, mask.id];
                ops.extend(parts);
                self.inst(
                    Op::RayQueryInitializeKHR,
                    None,
                    ops.into_iter().map(Operand::IdRef).collect(),
                )?;
                return Ok(None);
            }
            "Proceed" => {
                self.arity(name, args, 0, pos)?;
                let bt = self.ty_id(&b)?;
                let id = self.op(Op::RayQueryProceedKHR, bt, &[q])?;
                return Ok(Some(Val { id, ty: b }));
            }
            "Abort" | "CommitNonOpaqueTriangleHit" => {
                self.arity(name, args, 0, pos)?;
                let op = if name == "Abort" {
                    Op::RayQueryTerminateKHR
                } else {
                    Op::RayQueryConfirmIntersectionKHR
                };
                self.inst(op, None, vec![Operand::IdRef(q)])?;
                return Ok(None);
            }
            "CommitProceduralPrimitiveHit" => {
                self.arity(name, args, 1, pos)?;
                let t = self.expr(&args[0])?;
                let t = self.convert(t, &f, args[0].pos, false)?;
                self.inst(
                    Op::RayQueryGenerateIntersectionKHR,
                    None,
                    vec![Operand::IdRef(q), Operand::IdRef(t.id)],
                )?;
                return Ok(None);
            }
            _ => {}
        }
        self.arity(name, args, 0, pos)?;
        let simple = match name {
            "WorldRayOrigin" => Some((Op::RayQueryGetWorldRayOriginKHR, f3.clone())),
            "WorldRayDirection" => Some((Op::RayQueryGetWorldRayDirectionKHR, f3.clone())),
            "RayTMin" => Some((Op::RayQueryGetRayTMinKHR, f.clone())),
            "RayFlags" => Some((Op::RayQueryGetRayFlagsKHR, u.clone())),
            _ => None,
        };
        if let Some((op, t)) = simple {
            let tid = self.ty_id(&t)?;
            let id = self.op(op, tid, &[q])?;
            return Ok(Some(Val { id, ty: t }));
        }
        let (which, rest) = if let Some(r) = name.strip_prefix("Candidate") {
            (0u32, r)
        } else if let Some(r) = name.strip_prefix("Committed") {
            (1u32, r)
        } else {
            return Err(
                Error::new(pos, format!("RayQuery has no method `{name}`")).len(name.len() as u32)
            );
        };
        let k = self.const_u32(which);
        let m43 = Ty::Mat(ScalarKind::Float, 4, 3);
        let (op, t, transpose) = match (which, rest) {
            (0, "Type") | (1, "Status") => (Op::RayQueryGetIntersectionTypeKHR, u.clone(), false),
            (0, "TriangleRayT") | (1, "RayT") => {
                (Op::RayQueryGetIntersectionTKHR, f.clone(), false)
            }
            (_, "InstanceIndex") => (Op::RayQueryGetIntersectionInstanceIdKHR, u.clone(), false),
            (_, "InstanceID") => (
                Op::RayQueryGetIntersectionInstanceCustomIndexKHR,
                u.clone(),
                false,
            ),
            (_, "InstanceContributionToHitGroupIndex") => (
                Op::RayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetKHR,
                u.clone(),
                false,
            ),
            (_, "GeometryIndex") => (
                Op::RayQueryGetIntersectionGeometryIndexKHR,
                u.clone(),
                false,
            ),
            (_, "PrimitiveIndex") => (
                Op::RayQueryGetIntersectionPrimitiveIndexKHR,
                u.clone(),
                false,
            ),
            (_, "TriangleBarycentrics") => (
                Op::RayQueryGetIntersectionBarycentricsKHR,
                Ty::Vec(ScalarKind::Float, 2),
                false,
            ),
            (_, "TriangleFrontFace") => (Op::RayQueryGetIntersectionFrontFaceKHR, b.clone(), false),
            (_, "ObjectRayOrigin") => (
                Op::RayQueryGetIntersectionObjectRayOriginKHR,
                f3.clone(),
                false,
            ),
            (_, "ObjectRayDirection") => (
                Op::RayQueryGetIntersectionObjectRayDirectionKHR,
                f3.clone(),
                false,
            ),
            (_, "ObjectToWorld4x3") => (
                Op::RayQueryGetIntersectionObjectToWorldKHR,
                m43.clone(),
                false,
            ),
            (_, "ObjectToWorld3x4") => (
                Op::RayQueryGetIntersectionObjectToWorldKHR,
                m43.clone(),
                true,
            ),
            (_, "WorldToObject4x3") => (
                Op::RayQueryGetIntersectionWorldToObjectKHR,
                m43.clone(),
                false,
            ),
            (_, "WorldToObject3x4") => (
                Op::RayQueryGetIntersectionWorldToObjectKHR,
                m43.clone(),
                true,
            ),
            (0, "ProceduralPrimitiveNonOpaque") => {
                let bt = self.ty_id(&b)?;
                let opaque =
                    self.op(Op::RayQueryGetIntersectionCandidateAABBOpaqueKHR, bt, &[q])?;
                let id = self.op(Op::LogicalNot, bt, &[opaque])?;
                return Ok(Some(Val { id, ty: b }));
            }
            _ => {
                return Err(Error::new(pos, format!("RayQuery has no method `{name}`"))
                    .len(name.len() as u32))
            }
        };
        let tid = self.ty_id(&t)?;
        let id = self.op(op, tid, &[q, k])?;
        if transpose {
            let t34 = Ty::Mat(ScalarKind::Float, 3, 4);
            let tid = self.ty_id(&t34)?;
            let id = self.op(Op::Transpose, tid, &[id])?;
            return Ok(Some(Val { id, ty: t34 }));
        }
        Ok(Some(Val { id, ty: t }))
    }

    /// `buffer.Load<T>(address)` for 32-bit scalars and vectors: the words
    /// `LoadN` reads, reinterpreted as `T`.
    pub(super) fn typed_load(
        &mut self,
        p: Place,
        name: &str,
        targs: &'a [TArg],
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let (Place::Ptr { ptr, .. }, Ty::ByteAddress(rw)) = (&p, p.ty()) else {
            return Err(not_a_variable(pos));
        };
        let ns = self.f.cur_ns.clone();
        let t = match (name, targs) {
            ("Load", [TArg::Type(t)]) => self.resolve_ty(t, &ns)?,
            _ => {
                return Err(unsupported(pos, format!("templated method `{name}<...>`"))
                    .len(name.len() as u32))
            }
        };
        let (sc, n) = match t {
            Ty::ScalarKind(s) if s != ScalarKind::Bool && s.is_32() => (s, 1),
            Ty::Vec(s, n) if s != ScalarKind::Bool && s.is_32() => (s, n),
            Ty::ScalarKind(s) | Ty::Vec(s, _) if s.is_16() => {
                return self.load_16(*ptr, &t, s, args, pos).map(Some);
            }
            Ty::Struct(_) | Ty::Array(..) => {
                return self.load_packed(*ptr, &t, args, pos).map(Some);
            }
            _ => {
                return Err(unsupported(
                    pos,
                    format!(
                        "`Load<{}>` (only 32-bit scalars, vectors, and structs and arrays of them)",
                        self.ty_name(&t)
                    ),
                ))
            }
        };
        let method = match n {
            1 => "Load",
            2 => "Load2",
            3 => "Load3",
            _ => "Load4",
        };
        let Some(words) = self.byte_address(*ptr, *rw, method, args, pos)? else {
            return Err(Error::new(pos, "`Load` gave no value"));
        };
        if sc == ScalarKind::Uint {
            return Ok(Some(words));
        }
        let tid = self.ty_id(&t)?;
        let id = self.op(Op::Bitcast, tid, &[words.id])?;
        Ok(Some(Val { id, ty: t }))
    }

    /// `Load<T>` of 16-bit scalars and vectors: each component is the low or
    /// high half of the word holding its byte address, as DXC loads them.
    fn load_16(
        &mut self,
        var: Id,
        t: &Ty,
        sc: ScalarKind,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Val> {
        self.arity("Load", args, 1, pos)?;
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let a = self.expr(&args[0])?;
        let a = self.convert(a, &u, args[0].pos, false)?;
        let ut = self.ty_id(&u)?;
        let pty = self.b.type_pointer(None, StorageClass::StorageBuffer, ut);
        let st = self.sc_id(sc);
        let ust = self.sc_id(ScalarKind::Uint16);
        let (zero, two, three) = (self.const_u32(0), self.const_u32(2), self.const_u32(3));
        let mut comps = Vec::new();
        for k in 0..t.width() as u32 {
            let off = self.const_u32(2 * k);
            let at = self.op(Op::IAdd, ut, &[a.id, off])?;
            let word = self.op(Op::ShiftRightLogical, ut, &[at, two])?;
            let ptr = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![
                    Operand::IdRef(var),
                    Operand::IdRef(zero),
                    Operand::IdRef(word),
                ],
            )?;
            let w = self.b.load(ut, None, ptr, None, [])?;
            // Bit 1 of the address picks the half: a shift of 0 or 16.
            let half = self.op(Op::BitwiseAnd, ut, &[at, two])?;
            let shift = self.op(Op::ShiftLeftLogical, ut, &[half, three])?;
            let bits = self.op(Op::ShiftRightLogical, ut, &[w, shift])?;
            let low = self.op(Op::UConvert, ust, &[bits])?;
            comps.push(if sc == ScalarKind::Uint16 {
                low
            } else {
                self.op(Op::Bitcast, st, &[low])?
            });
        }
        if comps.len() == 1 {
            return Ok(Val {
                id: comps[0],
                ty: t.clone(),
            });
        }
        let tid = self.ty_id(t)?;
        let id = self.op(Op::CompositeConstruct, tid, &comps)?;
        Ok(Val { id, ty: t.clone() })
    }

    /// `SampleCmp`, `SampleCmpLevelZero`, `SampleCmpLevel`: depth-comparison
    /// sampling with a `SamplerComparisonState` (`OpImageSampleDref*`).
    fn sample_cmp(
        &mut self,
        ptr: Id,
        t: &Ty,
        coord: Ty,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Val> {
        let Ty::Texture { rw: false, sc, .. } = t else {
            return Err(Error::new(pos, format!("RWTexture has no method `{name}`")));
        };
        let implicit = name == "SampleCmp";
        if implicit {
            if self.f.cur_stage.is_some_and(|s| s != Stage::Fragment) {
                return Err(unsupported(
                    pos,
                    "`SampleCmp` (implicit level of detail) outside pixel shaders; use `SampleCmpLevelZero`",
                ));
            }
            if self.f.cur_stage.is_none() {
                self.fn_derivs
                    .entry(self.f.cur_fn)
                    .or_insert(("SampleCmp", pos));
            }
        }
        let want = if name == "SampleCmpLevel" { 4 } else { 3 };
        self.arity(name, args, want, pos)?;
        let s = self.expr(&args[0])?;
        if s.ty != Ty::SamplerCmp {
            return Err(Error::new(args[0].pos, "expected a SamplerComparisonState"));
        }
        let uv = self.expr(&args[1])?;
        let uv = self.convert(uv, &coord, args[1].pos, false)?;
        let reference = self.expr(&args[2])?;
        let reference = self.convert(
            reference,
            &Ty::ScalarKind(ScalarKind::Float),
            args[2].pos,
            false,
        )?;
        let im = self.image(ptr, t)?;
        let st = self.ty_id(&Ty::SamplerCmp)?;
        let sm = self.b.load(st, None, s.id, None, [])?;
        let it = self.ty_id(t)?;
        let sit = self.b.type_sampled_image(it);
        let si = self.op(Op::SampledImage, sit, &[im, sm])?;
        let rt = Ty::ScalarKind(sc.wide());
        let rid = self.ty_id(&rt)?;
        let mut ops = vec![
            Operand::IdRef(si),
            Operand::IdRef(uv.id),
            Operand::IdRef(reference.id),
        ];
        let op = if implicit {
            Op::ImageSampleDrefImplicitLod
        } else {
            let lod = if name == "SampleCmpLevel" {
                let l = self.expr(&args[3])?;
                self.convert(l, &Ty::ScalarKind(ScalarKind::Float), args[3].pos, false)?
                    .id
            } else {
                self.const_f32(0.0)
            };
            ops.push(Operand::ImageOperands(spirv::ImageOperands::LOD));
            ops.push(Operand::IdRef(lod));
            Op::ImageSampleDrefExplicitLod
        };
        let id = self.inst(op, Some(rid), ops)?;
        self.convert_scalar(id, sc.wide(), *sc, &Ty::ScalarKind(*sc))
    }

    /// `Load<S>` of a struct or array: its 32-bit leaves packed one word each,
    /// in declaration order (the layout `sizeof` gives), then put together.
    fn load_packed(&mut self, var: Id, t: &Ty, args: &'a [Expr], pos: Pos) -> Result<Val> {
        fn leaves(t: &Ty, structs: &[StructDef], out: &mut Vec<ScalarKind>) -> bool {
            match t {
                Ty::ScalarKind(s) if *s != ScalarKind::Bool && s.is_32() => out.push(*s),
                Ty::Vec(s, n) if *s != ScalarKind::Bool && s.is_32() => {
                    out.extend(std::iter::repeat_n(*s, *n as usize))
                }
                Ty::Array(e, n) => {
                    for _ in 0..*n {
                        if !leaves(e, structs, out) {
                            return false;
                        }
                    }
                }
                Ty::Struct(k) => {
                    for f in &structs[*k as usize].fields {
                        if !leaves(&f.ty, structs, out) {
                            return false;
                        }
                    }
                }
                _ => return false,
            }
            true
        }
        let mut scalars = Vec::new();
        if !leaves(t, &self.structs, &mut scalars) {
            return Err(unsupported(
                pos,
                format!(
                    "`Load<{}>`: members other than 32-bit scalars, vectors, structs and arrays",
                    self.ty_name(t)
                ),
            ));
        }
        self.arity("Load", args, 1, pos)?;
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let ut = self.ty_id(&u)?;
        let pty = self.b.type_pointer(None, StorageClass::StorageBuffer, ut);
        let addr = self.expr_as(&args[0], &u)?;
        let two = Val {
            id: self.const_u32(2),
            ty: u.clone(),
        };
        let word = self.binary(BinOp::Shr, addr, two, pos)?;
        let zero = self.const_u32(0);
        let mut vals = Vec::new();
        for (i, s) in scalars.iter().enumerate() {
            let off = Val {
                id: self.const_u32(i as u32),
                ty: u.clone(),
            };
            let w = self.binary(BinOp::Add, word.clone(), off, pos)?;
            let ptr = self.inst(
                Op::AccessChain,
                Some(pty),
                vec![
                    Operand::IdRef(var),
                    Operand::IdRef(zero),
                    Operand::IdRef(w.id),
                ],
            )?;
            let id = self.b.load(ut, None, ptr, None, [])?;
            let st = Ty::ScalarKind(*s);
            let id = if *s == ScalarKind::Uint {
                id
            } else {
                let sid = self.ty_id(&st)?;
                self.op(Op::Bitcast, sid, &[id])?
            };
            vals.push(Val { id, ty: st });
        }
        let mut it = vals.into_iter();
        self.build(t, &mut it, pos)
    }
}
