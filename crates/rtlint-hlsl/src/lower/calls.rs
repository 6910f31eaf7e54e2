//! Calls: user functions (overloads, `in`/`out`/`inout` by copy), intrinsics,
//! ray-tracing operations and methods of resources and ray queries.

use super::intrinsics::{Bit, FpClass, Math};
use super::*;
use spirv::GlslStd450Op as G;

/// A call argument: an expression, or a place already evaluated (`this`).
pub(super) enum Arg<'a> {
    Expr(&'a Expr),
    Place(Place, Pos),
    /// An argument already evaluated (for an `in` parameter).
    Value(Val, Pos),
}

impl Arg<'_> {
    fn pos(&self) -> Pos {
        match self {
            Arg::Expr(e) => e.pos,
            Arg::Place(_, p) | Arg::Value(_, p) => *p,
        }
    }
}

impl<'a> Lowerer<'a> {
    pub(super) fn call_expr(&mut self, e: &'a Expr) -> Result<Option<Val>> {
        self.line(e.pos);
        match &e.kind {
            ExprKind::Call(name, args) => self.call(name, args, e.pos),
            ExprKind::CallT(name, targs, args) => self.call_with_targs(name, targs, args, e.pos),
            ExprKind::MethodT(obj, name, targs, args) => {
                self.method_with_targs(obj, name, targs, args, e.pos)
            }
            ExprKind::Method(obj, name, args) => self.method(obj, name, args, e.pos),
            _ => Ok(Some(self.expr(e)?)),
        }
    }

    pub(super) fn stage_check(&mut self, name: &str, allowed: &[Stage], pos: Pos) -> Result<()> {
        match self.f.cur_stage {
            Some(s) if !allowed.contains(&s) => {
                return Err(Error::new(
                    pos,
                    format!("`{name}` is not available in {} shaders", s.hlsl_name()),
                )
                .len(name.len() as u32));
            }
            Some(_) => {}
            // In a helper: checked against every entry point that reaches it.
            None => self.fn_stage_uses.entry(self.f.cur_fn).or_default().push((
                name.to_string(),
                allowed.to_vec(),
                pos,
            )),
        }
        Ok(())
    }

    /// `ddx`, `ddy`, their `_fine`/`_coarse` forms and `fwidth` → `OpDPdx`... on
    /// float scalars and vectors (integers convert, as in DXC).
    pub(super) fn derivative(
        &mut self,
        op: Op,
        name: &'static str,
        arity: usize,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Val> {
        let len = name.len() as u32;
        match self.f.cur_stage {
            Some(Stage::Fragment) => {}
            Some(s) => {
                return Err(Error::new(
                    pos,
                    format!(
                        "`{name}` is only available in pixel shaders, not {} shaders",
                        s.hlsl_name()
                    ),
                )
                .len(len))
            }
            // In a helper: checked against the entry points that reach it.
            None => {
                self.fn_derivs.entry(self.f.cur_fn).or_insert((name, pos));
            }
        }
        self.arity(name, args, arity, pos)?;
        let v = self.expr(&args[0])?;
        // Vulkan's derivatives are 32-bit: a 16-bit float is widened for the
        // instruction and the result narrowed back to its type, as DXC does.
        let narrow_to = match v.ty.scalar() {
            Some(ScalarKind::Half) => Some(v.ty.clone()),
            Some(s) if s.is_16() => {
                return Err(unsupported(pos, format!("`{name}` of 16-bit integers")).len(len))
            }
            _ => None,
        };
        let ty = match v.ty {
            Ty::ScalarKind(_) => Ty::ScalarKind(ScalarKind::Float),
            Ty::Vec(_, n) => Ty::Vec(ScalarKind::Float, n),
            _ => {
                return Err(Error::new(
                    args[0].pos,
                    format!(
                        "`{name}` takes a scalar or vector, not `{}`",
                        self.ty_name(&v.ty)
                    ),
                ))
            }
        };
        let v = self.convert(v, &ty, args[0].pos, false)?;
        if !matches!(op, Op::DPdx | Op::DPdy | Op::Fwidth) {
            self.cap(Capability::DerivativeControl);
        }
        let tid = self.ty_id(&ty)?;
        let id = self.inst(op, Some(tid), vec![Operand::IdRef(v.id)])?;
        match narrow_to {
            Some(t) => self.convert(Val { id, ty }, &t, pos, true),
            None => Ok(Val { id, ty }),
        }
    }

    pub(super) fn glsl(&mut self, inst: G, ty: &Ty, args: &[Id]) -> Result<Val> {
        let tid = self.ty_id(ty)?;
        let mut ops = vec![
            Operand::IdRef(self.glsl),
            Operand::LiteralExtInstInteger(inst as u32),
        ];
        ops.extend(args.iter().map(|a| Operand::IdRef(*a)));
        let id = self.inst(Op::ExtInst, Some(tid), ops)?;
        Ok(Val { id, ty: ty.clone() })
    }

    pub(super) fn args(&mut self, args: &'a [Expr]) -> Result<Vec<Val>> {
        args.iter().map(|a| self.expr(a)).collect()
    }

    /// Literal arguments beside a 16-bit one take its type (`clamp(h, 0.0,
    /// 1.0)` stays `half`), as in binary operators.
    pub(super) fn adapt_literal_args(
        &mut self,
        args: &[Expr],
        vals: Vec<Val>,
        pos: Pos,
    ) -> Result<Vec<Val>> {
        let Some(other) = vals
            .iter()
            .find(|v| v.ty.scalar().is_some_and(ScalarKind::is_16))
            .map(|v| v.ty.clone())
        else {
            return Ok(vals);
        };
        args.iter()
            .zip(vals)
            .map(|(e, v)| self.adapt_literal(e, v, &other, pos))
            .collect()
    }

    pub(super) fn arity(&self, name: &str, args: &[Expr], n: usize, pos: Pos) -> Result<()> {
        if args.len() != n {
            return Err(Error::new(
                pos,
                format!("`{name}` takes {n} argument(s), {} given", args.len()),
            )
            .len(name.len() as u32));
        }
        Ok(())
    }

    /// Arguments converted to one common type (`float_only` forces float).
    pub(super) fn unify(
        &mut self,
        vals: Vec<Val>,
        float_only: bool,
        pos: Pos,
    ) -> Result<(Ty, Vec<Id>)> {
        let mut t = vals
            .first()
            .map(|v| v.ty.clone())
            .ok_or_else(|| Error::new(pos, "missing arguments"))?;
        for v in &vals[1..] {
            t = self.common(&t, &v.ty, pos)?;
        }
        if float_only || t.scalar() == Some(ScalarKind::Bool) {
            // GLSL.std.450 works on 16-bit floats: `half` stays `half`.
            t = t.with_scalar(if float_only && t.scalar() == Some(ScalarKind::Half) {
                ScalarKind::Half
            } else if float_only {
                ScalarKind::Float
            } else {
                ScalarKind::Int
            });
        }
        if !t.is_numeric() {
            return Err(Error::new(
                pos,
                format!("expected numbers, found `{}`", self.ty_name(&t)),
            ));
        }
        if let Ty::Mat(..) = t {
            // GLSL.std.450 works on scalars and vectors only.
            return Err(unsupported(pos, "matrix arguments to this intrinsic"));
        }
        let mut ids = Vec::new();
        for v in vals {
            ids.push(self.convert(v, &t, pos, false)?.id);
        }
        Ok((t, ids))
    }

    /// Writes `v` to an `out` argument, converting to its type.
    pub(super) fn store_out(&mut self, a: &'a Expr, v: Val) -> Result<()> {
        let p = self.place(a)?;
        let t = p.ty().clone();
        let v = self.convert(v, &t, a.pos, true)?;
        self.write(&p, v, a.pos)
    }

    pub(super) fn find_user(&self, name: &str) -> Option<Vec<usize>> {
        self.scoped_names(name)
            .iter()
            .find_map(|n| self.fn_by_name.get(n))
            .cloned()
    }

    fn call(&mut self, name: &str, args: &'a [Expr], pos: Pos) -> Result<Option<Val>> {
        if let Some(this) = self.f.this_place.clone() {
            if let Ty::Struct(k) = this.ty() {
                // `S::m(...)` inside a method of `S` is `m(...)` (on `this`
                // when `m` is not static), as in C++.
                let own = format!("{}::", self.structs[*k as usize].name);
                let name = name.strip_prefix(own.as_str()).unwrap_or(name);
                let qualified = format!("{}::{name}", self.structs[*k as usize].name);
                if let Some(c) = self.fn_by_name.get(&qualified).cloned() {
                    if c.iter().all(|k| self.funcs[*k].this.is_none()) {
                        let args = args.iter().map(Arg::Expr).collect();
                        return self.call_user(name, c, args, pos);
                    }
                    let mut all = vec![Arg::Place(this, pos)];
                    all.extend(args.iter().map(Arg::Expr));
                    return self.call_user(name, c, all, pos);
                }
            }
        }
        if let Some(this) = self.f.this_place.clone() {
            if let Ty::Struct(k) = this.ty() {
                let key = format!("{}::{name}", self.structs[*k as usize].name);
                if let Some(ts) = self.method_templates.get(&key).cloned() {
                    return self.template_call(name, ts, &[], args, Some(this), pos);
                }
            }
        }
        if let Some(r) = self.ser_call(name, args, pos)? {
            return Ok(r);
        }
        if let Some(r) = self.ext_instruction_call(name, args, pos)? {
            return Ok(r);
        }
        if name == "vk::RawBufferLoad" {
            return self.raw_buffer_load(None, args, pos).map(Some);
        }
        let user_fits = self.find_user(name).is_some_and(|c| {
            c.iter().any(|k| {
                let f = &self.funcs[*k];
                (f.params.len() - f.defaults.len()..=f.params.len()).contains(&args.len())
            })
        });
        if !user_fits {
            // A template takes the call when one fits the arguments (a user
            // template may share an intrinsic's or an overload's name).
            if let Some(ts) = self.find_fn_template(name) {
                let fits = ts.iter().any(|f| {
                    let required = f.params.iter().take_while(|p| p.init.is_none()).count();
                    (required..=f.params.len()).contains(&args.len())
                });
                if fits {
                    return self.template_call(name, ts, &[], args, None, pos);
                }
            }
            let ns = self.f.cur_ns.clone();
            let refused = self
                .unusable
                .get(&format!("{ns}{name}"))
                .or_else(|| self.unusable.get(name));
            if let Some(e) = refused {
                let mut e = e.clone();
                e.secondary.push((pos, format!("`{name}` is called here")));
                return Err(e);
            }
        }
        if self.returns_resource(name) {
            let p = self.resource_call(name, args, pos)?;
            return self.read(&p).map(Some);
        }
        if let Some(c) = self.find_user(name) {
            return self.call_user(name, c, args.iter().map(Arg::Expr).collect(), pos);
        }
        if let Some(sv) = system_value(name) {
            self.arity(name, args, 0, pos)?;
            if self.f.cur_stage == Some(Stage::Compute) {
                return Err(Error::new(
                    pos,
                    format!("`{name}` is not available in compute shaders"),
                )
                .len(name.len() as u32));
            }
            self.stage_check(name, sv.stages, pos)?;
            self.ray_tracing_caps();
            let v = self.read_builtin(sv.builtin, &sv.ty)?;
            if sv.transpose {
                let t = Ty::Mat(ScalarKind::Float, 3, 4);
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::Transpose, tid, &[v.id])?;
                return Ok(Some(Val { id, ty: t }));
            }
            return Ok(Some(v));
        }
        if let Some(row) = intrinsics::lookup(name) {
            return self.lower_intrinsic(row, args, pos);
        }
        if name.starts_with("Interlocked") {
            return self.interlocked(name, args, pos);
        }
        if name.starts_with("Wave") || name.starts_with("Quad") {
            return Err(unsupported(pos, format!("wave intrinsic `{name}`")).len(name.len() as u32));
        }
        Err(Error::new(pos, format!("unknown function `{name}`")).len(name.len() as u32))
    }

    /// The same bits as another scalar kind (`asuint`, `asfloat16`, ...).
    fn reinterpret(&mut self, v: Val, s: ScalarKind) -> Result<Val> {
        let t = v.ty.with_scalar(s);
        if t == v.ty {
            return Ok(v);
        }
        let tid = self.ty_id(&t)?;
        let id = self.op(Op::Bitcast, tid, &[v.id])?;
        Ok(Val { id, ty: t })
    }

    pub(super) fn intrinsic(
        &mut self,
        m: Math,
        name: &str,
        vals: Vec<Val>,
        pos: Pos,
    ) -> Result<Val> {
        let f = Ty::ScalarKind(ScalarKind::Float);
        // 64-bit integers: the min/max/clamp/abs family only.
        if vals
            .iter()
            .any(|v| v.ty.scalar().is_some_and(ScalarKind::is_64))
            && !matches!(m, Math::MinMax(..) | Math::Abs)
        {
            return Err(
                unsupported(pos, format!("`{name}` of 64-bit integers")).len(name.len() as u32)
            );
        }
        // 16-bit values: the arithmetic families, which keep their width
        // (`f32tof16`/`f16tof32` take them exactly as `float`/`uint`), and
        // `countbits` of 16-bit integers, widened below as DXC does.
        if vals
            .iter()
            .any(|v| v.ty.scalar().is_some_and(ScalarKind::is_16))
            && matches!(m, Math::As32(_) | Math::Bits(_))
            && !matches!(m, Math::Bits(Bit::Count))
        {
            return Err(
                unsupported(pos, format!("`{name}` of 16-bit values")).len(name.len() as u32)
            );
        }
        match m {
            Math::Dot => {
                let (t, ids) = self.unify(vals, false, pos)?;
                let s = t.scalar().unwrap_or(ScalarKind::Float);
                let st = Ty::ScalarKind(s);
                if let Ty::ScalarKind(_) = t {
                    return self.binary(
                        BinOp::Mul,
                        Val {
                            id: ids[0],
                            ty: t.clone(),
                        },
                        Val { id: ids[1], ty: t },
                        pos,
                    );
                }
                if s.is_float() {
                    let tid = self.ty_id(&st)?;
                    let id = self.op(Op::Dot, tid, &ids)?;
                    return Ok(Val { id, ty: st });
                }
                // Integer dot products: multiply, then add the components.
                let prod = self.binary(
                    BinOp::Mul,
                    Val {
                        id: ids[0],
                        ty: t.clone(),
                    },
                    Val {
                        id: ids[1],
                        ty: t.clone(),
                    },
                    pos,
                )?;
                let mut parts = Vec::new();
                self.flatten(prod, &mut parts)?;
                let mut acc = parts[0].clone();
                for p in &parts[1..] {
                    acc = self.binary(BinOp::Add, acc, p.clone(), pos)?;
                }
                Ok(acc)
            }
            Math::Cross => {
                let (t, ids) = self.unify(vals, true, pos)?;
                if !matches!(t, Ty::Vec(s, 3) if s.is_float()) {
                    return Err(Error::new(pos, "`cross` needs float3 arguments"));
                }
                self.glsl(G::Cross, &t, &ids)
            }
            Math::Length => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.glsl(G::Length, &t.with_scalar_only(), &ids)
            }
            Math::Distance => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.glsl(G::Distance, &t.with_scalar_only(), &ids)
            }
            Math::Reflect => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.glsl(G::Reflect, &t, &ids)
            }
            Math::FaceForward => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.glsl(G::FaceForward, &t, &ids)
            }
            Math::Refract => {
                let mut vals = vals;
                let eta = vals.pop().unwrap_or_else(|| unreachable!());
                let (t, mut ids) = self.unify(vals, true, pos)?;
                let eta = self.convert(eta, &t.with_scalar_only(), pos, false)?;
                ids.push(eta.id);
                self.glsl(G::Refract, &t, &ids)
            }
            Math::Glsl(inst) => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.glsl(inst, &t, &ids)
            }
            Math::Mad => {
                let mut it = vals.into_iter();
                let (a, b, c) = (
                    it.next().unwrap_or_else(|| unreachable!()),
                    it.next().unwrap_or_else(|| unreachable!()),
                    it.next().unwrap_or_else(|| unreachable!()),
                );
                let ab = self.binary(BinOp::Mul, a, b, pos)?;
                self.binary(BinOp::Add, ab, c, pos)
            }
            Math::Saturate => {
                let (t, ids) = self.unify(vals, true, pos)?;
                let zero = self.const_splat(&t, 0.0)?;
                let one = self.const_splat(&t, 1.0)?;
                self.glsl(G::FClamp, &t, &[ids[0], zero, one])
            }
            Math::MinMax(fi, si, ui) => {
                let (t, ids) = self.unify(vals, false, pos)?;
                let s = t.scalar().unwrap_or(ScalarKind::Float);
                let inst = if s.is_float() {
                    fi
                } else if s.is_signed() {
                    si
                } else {
                    ui
                };
                self.glsl(inst, &t, &ids)
            }
            Math::Abs => {
                let (t, ids) = self.unify(vals, false, pos)?;
                match t.scalar() {
                    Some(s) if s.is_float() => self.glsl(G::FAbs, &t, &ids),
                    Some(s) if s.is_signed() => self.glsl(G::SAbs, &t, &ids),
                    _ => Ok(Val { id: ids[0], ty: t }),
                }
            }
            Math::Sign => {
                // HLSL's sign returns int components.
                let (t, ids) = self.unify(vals, false, pos)?;
                let it = t.with_scalar(ScalarKind::Int);
                match t.scalar() {
                    Some(s) if s.is_float() => {
                        let v = self.glsl(G::FSign, &t, &ids)?;
                        self.convert(v, &it, pos, true)
                    }
                    Some(ScalarKind::Int) => self.glsl(G::SSign, &t, &ids),
                    Some(ScalarKind::Int16) => {
                        let v = self.glsl(G::SSign, &t, &ids)?;
                        self.convert(v, &it, pos, true)
                    }
                    _ => {
                        let v = Val {
                            id: ids[0],
                            ty: t.clone(),
                        };
                        let b = self.convert(v, &t.with_scalar(ScalarKind::Bool), pos, true)?;
                        self.convert(b, &it, pos, true)
                    }
                }
            }
            Math::Fmod => {
                let (t, ids) = self.unify(vals, true, pos)?;
                self.binary(
                    BinOp::Rem,
                    Val {
                        id: ids[0],
                        ty: t.clone(),
                    },
                    Val { id: ids[1], ty: t },
                    pos,
                )
            }
            Math::Rcp => {
                let (t, ids) = self.unify(vals, true, pos)?;
                let one = Val {
                    id: self.const_splat(&t, 1.0)?,
                    ty: t.clone(),
                };
                self.binary(BinOp::Div, one, Val { id: ids[0], ty: t }, pos)
            }
            Math::Log10 => {
                let (t, ids) = self.unify(vals, true, pos)?;
                let l = self.glsl(G::Log2, &t, &ids)?;
                let k = Val {
                    id: self.const_splat(&t, std::f64::consts::LOG10_2)?,
                    ty: t,
                };
                self.binary(BinOp::Mul, l, k, pos)
            }
            Math::Mul => self.mul(vals, pos),
            Math::Transpose => {
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                let Ty::Mat(s, r, c) = v.ty else {
                    return Err(Error::new(pos, "`transpose` needs a matrix"));
                };
                let t = Ty::Mat(s, c, r);
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::Transpose, tid, &[v.id])?;
                Ok(Val { id, ty: t })
            }
            Math::Determinant => {
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                match v.ty {
                    Ty::Mat(s, r, c) if r == c => {
                        self.glsl(G::Determinant, &Ty::ScalarKind(s), &[v.id])
                    }
                    _ => Err(Error::new(pos, "`determinant` needs a square matrix")),
                }
            }
            Math::AnyAll(op) => {
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                let bt = Ty::ScalarKind(ScalarKind::Bool);
                match v.ty.clone() {
                    Ty::ScalarKind(_) => self.convert(v, &bt, pos, false),
                    Ty::Vec(_, n) => {
                        let b = self.convert(v, &Ty::Vec(ScalarKind::Bool, n), pos, false)?;
                        let tid = self.ty_id(&bt)?;
                        let id = self.op(op, tid, &[b.id])?;
                        Ok(Val { id, ty: bt })
                    }
                    other => Err(Error::new(
                        pos,
                        format!(
                            "`{name}` needs a scalar or vector, found `{}`",
                            self.ty_name(&other)
                        ),
                    )),
                }
            }
            Math::As16(s) => {
                // DXC's 16-bit reinterpretations: the same bits, another type.
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                if !matches!(v.ty, Ty::ScalarKind(_) | Ty::Vec(..))
                    || !v.ty.scalar().is_some_and(ScalarKind::is_16)
                {
                    return Err(Error::new(
                        pos,
                        format!("`{name}` needs a 16-bit scalar or vector"),
                    ));
                }
                self.reinterpret(v, s)
            }
            Math::As32(s) => {
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                if !matches!(v.ty, Ty::ScalarKind(_) | Ty::Vec(..))
                    || v.ty.scalar() == Some(ScalarKind::Bool)
                {
                    return Err(Error::new(
                        pos,
                        format!("`{name}` needs a 32-bit scalar or vector"),
                    ));
                }
                self.reinterpret(v, s)
            }
            Math::F16(to_half) => {
                let v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                let src = v.ty.with_scalar(if to_half {
                    ScalarKind::Float
                } else {
                    ScalarKind::Uint
                });
                let v = self.convert(v, &src, pos, false)?;
                let mut comps = Vec::new();
                self.flatten(v, &mut comps)?;
                let mut out = Vec::new();
                for c in comps {
                    if to_half {
                        let zero = self.const_f32(0.0);
                        let v2 = self.ty_id(&Ty::Vec(ScalarKind::Float, 2))?;
                        let pair = self.op(Op::CompositeConstruct, v2, &[c.id, zero])?;
                        out.push(self.glsl(
                            G::PackHalf2x16,
                            &Ty::ScalarKind(ScalarKind::Uint),
                            &[pair],
                        )?);
                    } else {
                        let pair =
                            self.glsl(G::UnpackHalf2x16, &Ty::Vec(ScalarKind::Float, 2), &[c.id])?;
                        let ft = self.ty_id(&f)?;
                        let id = self.inst(
                            Op::CompositeExtract,
                            Some(ft),
                            vec![Operand::IdRef(pair.id), Operand::LiteralBit32(0)],
                        )?;
                        out.push(Val { id, ty: f.clone() });
                    }
                }
                let t = src.with_scalar(if to_half {
                    ScalarKind::Uint
                } else {
                    ScalarKind::Float
                });
                if out.len() == 1 {
                    return Ok(out.pop().unwrap_or_else(|| unreachable!()));
                }
                let mut it = out.into_iter();
                self.build(&t, &mut it, pos)
            }
            Math::Bits(bit) => {
                let mut v = vals.into_iter().next().unwrap_or_else(|| unreachable!());
                if matches!(v.ty.scalar(), Some(ScalarKind::Int16 | ScalarKind::Uint16))
                    && matches!(v.ty, Ty::ScalarKind(_) | Ty::Vec(..))
                {
                    // Vulkan's OpBitCount is 32-bit: zero-extended first
                    // (`OpUConvert`, whatever the signedness), as DXC does.
                    let t = v.ty.with_scalar(ScalarKind::Uint);
                    let tid = self.ty_id(&t)?;
                    let id = self.op(Op::UConvert, tid, &[v.id])?;
                    v = Val { id, ty: t };
                }
                let s = v.ty.scalar();
                if !matches!(s, Some(ScalarKind::Int | ScalarKind::Uint))
                    || matches!(v.ty, Ty::Mat(..))
                {
                    return Err(Error::new(
                        pos,
                        format!("`{name}` needs an integer scalar or vector"),
                    ));
                }
                let t = v.ty.clone();
                let r = match bit {
                    Bit::Count => {
                        let tid = self.ty_id(&t)?;
                        Val {
                            id: self.op(Op::BitCount, tid, &[v.id])?,
                            ty: t.clone(),
                        }
                    }
                    Bit::Reverse => {
                        let tid = self.ty_id(&t)?;
                        Val {
                            id: self.op(Op::BitReverse, tid, &[v.id])?,
                            ty: t.clone(),
                        }
                    }
                    Bit::High => self.glsl(
                        if s == Some(ScalarKind::Int) {
                            G::FindSMsb
                        } else {
                            G::FindUMsb
                        },
                        &t,
                        &[v.id],
                    )?,
                    Bit::Low => self.glsl(G::FindILsb, &t, &[v.id])?,
                };
                // HLSL returns uint components for all four.
                self.convert(r, &t.with_scalar(ScalarKind::Uint), pos, true)
            }
            Math::Class(class) => {
                let (t, ids) = self.unify(vals, true, pos)?;
                let bt = t.with_scalar(ScalarKind::Bool);
                let tid = self.ty_id(&bt)?;
                if class == FpClass::Finite {
                    let a = self.op(Op::IsNan, tid, &ids)?;
                    let b = self.op(Op::IsInf, tid, &ids)?;
                    let o = self.op(Op::LogicalOr, tid, &[a, b])?;
                    let id = self.op(Op::LogicalNot, tid, &[o])?;
                    return Ok(Val { id, ty: bt });
                }
                let id = self.op(
                    if class == FpClass::Nan {
                        Op::IsNan
                    } else {
                        Op::IsInf
                    },
                    tid,
                    &ids,
                )?;
                Ok(Val { id, ty: bt })
            }
        }
    }

    /// `mul` in all its shapes (see the matrix note in `types`).
    fn mul(&mut self, vals: Vec<Val>, pos: Pos) -> Result<Val> {
        let mut it = vals.into_iter();
        let (a, b) = (
            it.next().unwrap_or_else(|| unreachable!()),
            it.next().unwrap_or_else(|| unreachable!()),
        );
        let (at, bt) = (a.ty.clone(), b.ty.clone());
        // Matrices are float or half: the wider of the two (any integer
        // vector joins the matrix's kind).
        let s = match (at.scalar(), bt.scalar()) {
            (Some(x), Some(y)) if x.max(y).is_float() => x.max(y),
            _ => ScalarKind::Float,
        };
        match (&at, &bt) {
            (Ty::ScalarKind(_), _) | (_, Ty::ScalarKind(_)) => self.binary(BinOp::Mul, a, b, pos),
            (Ty::Vec(..), Ty::Vec(..)) => self.intrinsic(Math::Dot, "dot", vec![a, b], pos),
            (Ty::Mat(_, r, c), Ty::Vec(_, n)) => {
                if n != c {
                    return Err(Error::new(
                        pos,
                        format!("`mul` of a {r}x{c} matrix needs a {c}-vector, found a {n}-vector"),
                    ));
                }
                let (r, c) = (*r, *c);
                let m = self.convert(a, &Ty::Mat(s, r, c), pos, false)?;
                let v = self.convert(b, &Ty::Vec(s, c), pos, false)?;
                let t = Ty::Vec(s, r);
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::VectorTimesMatrix, tid, &[v.id, m.id])?;
                Ok(Val { id, ty: t })
            }
            (Ty::Vec(_, n), Ty::Mat(_, r, c)) => {
                if n != r {
                    return Err(Error::new(
                        pos,
                        format!(
                            "`mul` of a {n}-vector needs a matrix with {n} rows, found {r}x{c}"
                        ),
                    ));
                }
                let (r, c) = (*r, *c);
                let m = self.convert(b, &Ty::Mat(s, r, c), pos, false)?;
                let v = self.convert(a, &Ty::Vec(s, *n), pos, false)?;
                let t = Ty::Vec(s, c);
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::MatrixTimesVector, tid, &[m.id, v.id])?;
                Ok(Val { id, ty: t })
            }
            (Ty::Mat(_, r, k), Ty::Mat(_, k2, c)) => {
                if k != k2 {
                    return Err(Error::new(
                        pos,
                        format!("`mul` of {r}x{k} and {k2}x{c} matrices"),
                    ));
                }
                let (r, k, c) = (*r, *k, *c);
                let x = self.convert(a, &Ty::Mat(s, r, k), pos, false)?;
                let y = self.convert(b, &Ty::Mat(s, k, c), pos, false)?;
                let t = Ty::Mat(s, r, c);
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::MatrixTimesMatrix, tid, &[y.id, x.id])?;
                Ok(Val { id, ty: t })
            }
            _ => Err(Error::new(
                pos,
                format!(
                    "`mul` of `{}` and `{}`",
                    self.ty_name(&a.ty),
                    self.ty_name(&b.ty)
                ),
            )),
        }
    }

    fn interlocked(&mut self, name: &str, args: &'a [Expr], pos: Pos) -> Result<Option<Val>> {
        let Some(first) = args.first() else {
            return Err(Error::new(pos, format!("`{name}` needs a destination")));
        };
        let dest = self.place(first)?;
        self.atomic(name, dest, first.pos, &args[1..], pos)
    }

    /// An atomic on `dest` (an int or uint in a buffer or groupshared memory);
    /// `rest` are the operands after the destination, an `out` original last.
    pub(super) fn atomic(
        &mut self,
        name: &str,
        dest: Place,
        dest_pos: Pos,
        rest: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let bad = || {
            Error::new(
                dest_pos,
                format!("`{name}` needs an int or uint in a buffer, a storage image or groupshared memory"),
            )
        };
        let (ptr, s, class) = match dest {
            Place::Ptr {
                ptr,
                ty: Ty::ScalarKind(s @ (ScalarKind::Int | ScalarKind::Uint)),
                class: class @ (StorageClass::StorageBuffer | StorageClass::Workgroup),
                ..
            } => (ptr, s, class),
            // `img[coord]` of a `RWTexture*<uint>` or `RWBuffer<uint>`: a texel pointer.
            Place::Texel {
                image,
                coord,
                ty: Ty::ScalarKind(s @ (ScalarKind::Int | ScalarKind::Uint)),
                ..
            } => {
                let st = self.ty_id(&Ty::ScalarKind(s))?;
                let pty = self.b.type_pointer(None, StorageClass::Image, st);
                let sample = self.const_u32(0);
                let ptr = self.op(Op::ImageTexelPointer, pty, &[image, coord, sample])?;
                (ptr, s, StorageClass::Image)
            }
            _ => return Err(bad()),
        };
        let op = match (name.trim_start_matches("Interlocked"), s) {
            ("Add", _) => Op::AtomicIAdd,
            ("And", _) => Op::AtomicAnd,
            ("Or", _) => Op::AtomicOr,
            ("Xor", _) => Op::AtomicXor,
            ("Exchange", _) => Op::AtomicExchange,
            ("Min", ScalarKind::Int) => Op::AtomicSMin,
            ("Min", _) => Op::AtomicUMin,
            ("Max", ScalarKind::Int) => Op::AtomicSMax,
            ("Max", _) => Op::AtomicUMax,
            ("CompareExchange" | "CompareStore", _) => Op::AtomicCompareExchange,
            _ => return Err(unsupported(pos, format!("`{name}`")).len(name.len() as u32)),
        };
        let cmp = op == Op::AtomicCompareExchange;
        let (min, max) = match name {
            "InterlockedCompareExchange" => (3, 3),
            "InterlockedCompareStore" => (2, 2),
            _ => (1, 2),
        };
        if rest.len() < min || rest.len() > max {
            return Err(Error::new(
                pos,
                format!("`{name}` takes {} to {} arguments", min + 1, max + 1),
            ));
        }
        let t = Ty::ScalarKind(s);
        let mut vals = Vec::new();
        for e in &rest[..if cmp { 2 } else { 1 }] {
            let v = self.expr(e)?;
            vals.push(self.convert(v, &t, e.pos, false)?.id);
        }
        let scope = self.const_u32(if class == StorageClass::Workgroup {
            2
        } else {
            1
        });
        let relaxed = self.const_u32(0);
        let tid = self.ty_id(&t)?;
        let old = if cmp {
            // HLSL gives (compare, value); SPIR-V takes (value, comparator).
            self.op(op, tid, &[ptr, scope, relaxed, relaxed, vals[1], vals[0]])?
        } else {
            self.op(op, tid, &[ptr, scope, relaxed, vals[0]])?
        };
        let out_at = if cmp { 2 } else { 1 };
        if let Some(o) = rest.get(out_at) {
            let p = self.place(o)?;
            let ot = p.ty().clone();
            let ov = self.convert(Val { id: old, ty: t }, &ot, o.pos, true)?;
            self.write(&p, ov, o.pos)?;
        }
        Ok(None)
    }

    pub(super) fn trace_ray(&mut self, args: &'a [Expr], pos: Pos) -> Result<()> {
        let accel = self.expr(&args[0])?;
        if accel.ty != Ty::Accel {
            return Err(Error::new(
                args[0].pos,
                "TraceRay's first argument must be a RaytracingAccelerationStructure",
            ));
        }
        let at = self.ty_id(&Ty::Accel)?;
        let mut ids = Vec::new();
        for a in &args[1..6] {
            let v = self.expr(a)?;
            ids.push(
                self.convert(v, &Ty::ScalarKind(ScalarKind::Uint), a.pos, false)?
                    .id,
            );
        }
        let ray = self.expr_as(&args[6], &Ty::Struct(RAY_DESC))?;
        let mut parts = Vec::new();
        for (i, t) in [
            Ty::Vec(ScalarKind::Float, 3),
            Ty::ScalarKind(ScalarKind::Float),
            Ty::Vec(ScalarKind::Float, 3),
            Ty::ScalarKind(ScalarKind::Float),
        ]
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
        let p = self.place(&args[7])?;
        let t = p.ty().clone();
        if !matches!(t, Ty::Struct(_)) {
            return Err(Error::new(args[7].pos, "the ray payload must be a struct"));
        }
        let var = self.rt_var_named(StorageClass::RayPayloadKHR, &t, Some(&args[7]))?;
        let v = self.read(&p)?;
        self.b.store(var, v.id, None, [])?;
        let a = self.b.load(at, None, accel.id, None, [])?;
        self.line(pos);
        self.b.trace_ray_khr(
            a, ids[0], ids[1], ids[2], ids[3], ids[4], parts[0], parts[1], parts[2], parts[3], var,
        )?;
        let tid = self.ty_id(&t)?;
        let back = self.b.load(tid, None, var, None, [])?;
        self.write(&p, Val { id: back, ty: t }, args[7].pos)
    }

    pub(super) fn call_user(
        &mut self,
        name: &str,
        cands: Vec<usize>,
        args: Vec<Arg<'a>>,
        pos: Pos,
    ) -> Result<Option<Val>> {
        // Trailing parameters with default values may be left out.
        let cands: Vec<usize> = cands
            .into_iter()
            .filter(|k| {
                let f = &self.funcs[*k];
                (f.params.len() - f.defaults.len()..=f.params.len()).contains(&args.len())
            })
            .collect();
        if cands.is_empty() {
            return Err(Error::new(
                pos,
                format!("no overload of `{name}` takes {} argument(s)", args.len()),
            )
            .len(name.len() as u32));
        }
        // Arguments for `out` parameters are places; the rest are values.
        let mut argv: Vec<(Option<Place>, Val)> = Vec::new();
        for (i, a) in args.iter().enumerate() {
            let is_out = cands.iter().any(|k| self.funcs[*k].params[i].out);
            if let Arg::Place(p, _) = a {
                let v = Val {
                    id: 0,
                    ty: p.ty().clone(),
                };
                argv.push((Some(p.clone()), v));
                continue;
            }
            if let Arg::Value(v, _) = a {
                argv.push((None, v.clone()));
                continue;
            }
            let Arg::Expr(a) = *a else { unreachable!() };
            if is_out {
                let p = self.place(a)?;
                if matches!(p, Place::Value(_)) {
                    return Err(Error::new(a.pos, "an `out` argument must be assignable"));
                }
                let v = Val {
                    id: 0,
                    ty: p.ty().clone(),
                };
                argv.push((Some(p), v));
            } else {
                let mut v = self.expr(a)?;
                if let Ty::ConstantBuffer(k) = v.ty {
                    // A `ConstantBuffer<S>` passed for an `S`: its contents.
                    let wants_buffer = cands
                        .iter()
                        .any(|c| matches!(self.funcs[*c].params[i].ty, Ty::ConstantBuffer(_)));
                    if !wants_buffer {
                        let p = self.place(a)?;
                        v = self.struct_of(p, k, a.pos)?;
                    }
                }
                argv.push((None, v));
            }
        }
        let cost = |from: &Ty, to: &Ty| -> Option<u32> {
            if from == to {
                return Some(0);
            }
            match (from, to) {
                (Ty::ScalarKind(_), Ty::ScalarKind(_)) => Some(1),
                (Ty::Vec(_, n), Ty::Vec(_, m)) if n == m => Some(1),
                (Ty::ScalarKind(_), Ty::Vec(..) | Ty::Mat(..)) => Some(2),
                (Ty::Vec(_, n), Ty::Vec(_, m)) if m < n => Some(3),
                (Ty::Vec(..), Ty::ScalarKind(_)) => Some(3),
                _ => None,
            }
        };
        let mut best: Option<(u32, usize)> = None;
        for &k in &cands {
            let mut total = 0;
            let mut ok = true;
            for (p, (_, v)) in self.funcs[k].params.iter().zip(&argv) {
                match cost(&v.ty, &p.ty) {
                    Some(c) => total += c,
                    None => ok = false,
                }
            }
            if ok && best.is_none_or(|(c, _)| total < c) {
                best = Some((total, k));
            }
        }
        let Some((_, k)) = best else {
            let tys: Vec<String> = argv.iter().map(|(_, v)| self.ty_name(&v.ty)).collect();
            return Err(Error::new(
                pos,
                format!("no overload of `{name}` takes ({})", tys.join(", ")),
            )
            .len(name.len() as u32));
        };
        let sig = self.funcs[k].clone();
        if sig.stage.is_some() {
            return Err(unsupported(pos, "calling an entry point function"));
        }
        let mut args = args;
        let first_default = sig.params.len() - sig.defaults.len();
        for i in args.len()..sig.params.len() {
            // Evaluated at the call, as C++ and DXC do.
            let e = sig.defaults[i - first_default];
            argv.push((None, self.expr(e)?));
            args.push(Arg::Expr(e));
        }
        let mut temps = Vec::new();
        // Buffers (storage-buffer pointers) cannot be function arguments
        // without variable pointers: the function is specialized on them.
        let mut bound = Vec::new();
        for (i, ((p, (place, v)), a)) in sig.params.iter().zip(&argv).zip(&args).enumerate() {
            if let Ty::RayQuery(_) | Ty::HitObject = p.ty {
                // A ray query or hit object is passed as its variable (it
                // cannot be copied).
                if p.out || v.ty != p.ty {
                    return Err(Error::new(
                        a.pos(),
                        format!(
                            "expected a `{}` variable (passed `in`)",
                            self.ty_name(&p.ty)
                        ),
                    ));
                }
                temps.push(v.id);
                continue;
            }
            if p.ty.is_resource() {
                // Passed as the resource variable itself, which SPIR-V's
                // logical addressing allows for whole variables and, for
                // images and samplers, for elements of arrays of them.
                let element_ok = matches!(p.ty, Ty::Texture { .. } | Ty::Sampler | Ty::SamplerCmp);
                if !element_ok && !self.resource_vars.contains(&v.id) {
                    return Err(unsupported(
                        a.pos(),
                        "passing an element of a resource array to a function",
                    ));
                }
                if self.param_class(&p.ty).0 != StorageClass::UniformConstant {
                    bound.push((i, v.id));
                }
                temps.push(v.id);
                continue;
            }
            let tmp = self.local_var(&p.ty, "")?;
            if p.input {
                let val = match place {
                    Some(pl) => self.read(pl)?,
                    None => v.clone(),
                };
                let val = self.convert(val, &p.ty, a.pos(), false)?;
                self.b.store(tmp, val.id, None, [])?;
            } else {
                // A pure `out` temporary starts undefined at each call: a
                // callee that returns without writing it leaves no value of
                // an earlier call to be copied out (and kept alive).
                let undef = self.undef(&p.ty)?;
                if self.f.term {
                    self.start_block(None)?;
                }
                self.b.store(tmp, undef, None, [])?;
            }
            temps.push(tmp);
        }
        let (k, sig) = if bound.is_empty() {
            (k, sig)
        } else {
            let k = self.specialize(k, &bound);
            (k, self.funcs[k].clone())
        };
        let mut passed: Vec<Id> = temps
            .iter()
            .enumerate()
            .filter(|(i, _)| !sig.bound.iter().any(|(b, _)| b == i))
            .map(|(_, t)| *t)
            .collect();
        if let Some((t, _)) = &sig.ret_slot {
            match self.f.ret_dest.take() {
                Some((var, dt)) if dt == *t => passed.push(var),
                _ => {
                    return Err(unsupported(
                        pos,
                        format!(
                        "`{name}` returns a {}: call it only to initialize a variable of that type",
                        self.ty_name(t)
                    ),
                    )
                    .len(name.len() as u32))
                }
            }
        }
        let rt = self.ty_id(&sig.ret)?;
        if self.f.term {
            self.start_block(None)?;
        }
        let id = self.b.function_call(rt, None, sig.id, passed)?;
        self.fn_calls.entry(self.f.cur_fn).or_default().insert(k);
        if !self.lowered.contains(&k) && !self.pending.contains(&k) {
            self.pending.push(k);
        }
        for ((p, (place, _)), (tmp, a)) in sig.params.iter().zip(&argv).zip(temps.iter().zip(&args))
        {
            if p.out {
                let tid = self.ty_id(&p.ty)?;
                let back = self.b.load(tid, None, *tmp, None, [])?;
                let pl = place.as_ref().unwrap_or_else(|| unreachable!());
                let want = pl.ty().clone();
                let v = self.convert(
                    Val {
                        id: back,
                        ty: p.ty.clone(),
                    },
                    &want,
                    a.pos(),
                    true,
                )?;
                self.write(pl, v, a.pos())?;
            }
        }
        Ok(if sig.ret == Ty::Void {
            None
        } else {
            Some(Val { id, ty: sig.ret })
        })
    }

    /// Function `k` with the buffer parameters `bound` (parameter index,
    /// variable) replaced by those variables: one copy per combination.
    fn specialize(&mut self, k: usize, bound: &[(usize, Id)]) -> usize {
        let key = (k, bound.to_vec());
        if let Some(&s) = self.specialized.get(&key) {
            return s;
        }
        let mut sig = self.funcs[k].clone();
        sig.id = self.b.id();
        sig.bound = bound
            .iter()
            .map(|&(i, var)| {
                let ty = sig.params[i].ty.clone();
                let (class, layout) = self.param_class(&ty);
                (
                    i,
                    Place::Ptr {
                        ptr: var,
                        ty,
                        layout,
                        class,
                    },
                )
            })
            .collect();
        let s = self.funcs.len();
        self.funcs.push(sig);
        self.specialized.insert(key, s);
        s
    }

    /// The value of a struct place read member by member (a constant buffer's
    /// contents as an `S`).
    pub(super) fn struct_of(&mut self, p: Place, k: u32, pos: Pos) -> Result<Val> {
        let names: Vec<String> = self.structs[k as usize]
            .fields
            .iter()
            .map(|f| f.name.clone())
            .collect();
        let mut ids = Vec::new();
        for n in &names {
            let m = self.member(p.clone(), n, pos)?;
            ids.push(self.read(&m)?.id);
        }
        let t = Ty::Struct(k);
        let tid = self.ty_id(&t)?;
        let id = self.op(Op::CompositeConstruct, tid, &ids)?;
        Ok(Val { id, ty: t })
    }
}
