//! Expressions: operators, conversions, constructors.

use super::*;

/// Opcodes of the binary operators by operand class: float, signed,
/// unsigned, bool (`&&`/`||` are lowered by `logical`).
const BINARY_OPS: &[(BinOp, [Op; 4])] = {
    use BinOp::*;
    use Op::*;
    &[
        (Add, [FAdd, IAdd, IAdd, IAdd]),
        (Sub, [FSub, ISub, ISub, ISub]),
        (Mul, [FMul, IMul, IMul, IMul]),
        (Div, [FDiv, SDiv, UDiv, UDiv]),
        (Rem, [FRem, SRem, UMod, UMod]),
        (Shl, [ShiftLeftLogical; 4]),
        (
            Shr,
            [
                ShiftRightLogical,
                ShiftRightArithmetic,
                ShiftRightLogical,
                ShiftRightLogical,
            ],
        ),
        (BitAnd, [BitwiseAnd; 4]),
        (BitOr, [BitwiseOr; 4]),
        (BitXor, [BitwiseXor; 4]),
        (Eq, [FOrdEqual, IEqual, IEqual, LogicalEqual]),
        (Ne, [FUnordNotEqual, INotEqual, INotEqual, LogicalNotEqual]),
        (Lt, [FOrdLessThan, SLessThan, ULessThan, ULessThan]),
        (
            Le,
            [
                FOrdLessThanEqual,
                SLessThanEqual,
                ULessThanEqual,
                ULessThanEqual,
            ],
        ),
        (
            Gt,
            [FOrdGreaterThan, SGreaterThan, UGreaterThan, UGreaterThan],
        ),
        (
            Ge,
            [
                FOrdGreaterThanEqual,
                SGreaterThanEqual,
                UGreaterThanEqual,
                UGreaterThanEqual,
            ],
        ),
    ]
};

impl<'a> Lowerer<'a> {
    pub fn ty_name(&self, t: &Ty) -> String {
        match t {
            Ty::Void => "void".into(),
            Ty::ScalarKind(s) => s.name().into(),
            Ty::Vec(s, n) => format!("{}{n}", s.name()),
            Ty::Mat(s, r, c) => format!("{}{r}x{c}", s.name()),
            Ty::Array(e, n) => format!("{}[{n}]", self.ty_name(e)),
            Ty::RtArray(e) => format!("{}[]", self.ty_name(e)),
            Ty::Struct(k) => self.structs[*k as usize].name.clone(),
            Ty::Accel => "RaytracingAccelerationStructure".into(),
            Ty::RayQuery(_) => "RayQuery".into(),
            Ty::Sampler => "SamplerState".into(),
            Ty::SamplerCmp => "SamplerComparisonState".into(),
            Ty::HitObject => "HitObject".into(),
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

    pub(super) fn expr_void(&mut self, e: &'a Expr) -> Result<()> {
        match &e.kind {
            // `h = HitObject::TraceRay(...)`: the hit object is made in `h`.
            ExprKind::Assign(None, lhs, rhs) if Self::is_hit_object_maker(rhs) => {
                match self.place(lhs)? {
                    Place::Ptr {
                        ptr,
                        ty: Ty::HitObject,
                        ..
                    } => self.make_hit_object(ptr, rhs)?,
                    _ => return Err(Error::new(lhs.pos, "expected a HitObject variable")),
                }
            }
            // Calls of void functions have no value to produce.
            ExprKind::Call(..)
            | ExprKind::Method(..)
            | ExprKind::CallT(..)
            | ExprKind::MethodT(..) => {
                self.call_expr(e)?;
            }
            _ => {
                self.expr(e)?;
            }
        }
        Ok(())
    }

    pub(super) fn expr(&mut self, e: &'a Expr) -> Result<Val> {
        let v = match &e.kind {
            // `sizeof` is a `uint` constant, as in DXC.
            ExprKind::SizeOfExpr(_) => {
                let n = match self.const_eval(e)? {
                    Some(ConstValue::I(n)) => n as u32,
                    _ => return Err(Error::new(e.pos, "`sizeof` needs a name")),
                };
                Val {
                    id: self.const_u32(n),
                    ty: Ty::ScalarKind(ScalarKind::Uint),
                }
            }
            ExprKind::SizeOf(t, dims) => {
                let n = self.size_of(t, dims, e.pos)?;
                Val {
                    id: self.const_u32(n),
                    ty: Ty::ScalarKind(ScalarKind::Uint),
                }
            }
            ExprKind::Int64(v, u) => {
                // `uint64_t` with a `u` suffix or above `int64_t`'s range, as in C.
                let s = if *u || *v > i64::MAX as u64 {
                    ScalarKind::Uint64
                } else {
                    ScalarKind::Int64
                };
                Val {
                    id: self.const_scalar(s, *v as f64, *v as i64),
                    ty: Ty::ScalarKind(s),
                }
            }
            ExprKind::Int(v, u) => {
                if *u || *v > i32::MAX as u64 {
                    Val {
                        id: self.const_u32(*v as u32),
                        ty: Ty::ScalarKind(ScalarKind::Uint),
                    }
                } else {
                    Val {
                        id: self.const_i32(*v as i32),
                        ty: Ty::ScalarKind(ScalarKind::Int),
                    }
                }
            }
            ExprKind::Float(f) => Val {
                id: self.const_f32(*f as f32),
                ty: Ty::ScalarKind(ScalarKind::Float),
            },
            ExprKind::Bool(b) => Val {
                id: self.const_bool(*b),
                ty: Ty::ScalarKind(ScalarKind::Bool),
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
                let av = self.expr(a)?;
                let bv = self.expr(b)?;
                let av = self.adapt_literal(a, av, &bv.ty, e.pos)?;
                let bv = self.adapt_literal(b, bv, &av.ty, e.pos)?;
                self.binary(*op, av, bv, e.pos)?
            }
            ExprKind::Assign(op, lhs, rhs) => {
                let p = self.place(lhs)?;
                let t = p.ty().clone();
                if t == Ty::HitObject {
                    return Err(unsupported(e.pos, "a HitObject assignment used as a value"));
                }
                let v = match op {
                    None => self.expr_as(rhs, &t)?,
                    Some(op) => {
                        let cur = self.read(&p)?;
                        let r = self.expr(rhs)?;
                        let r = self.adapt_literal(rhs, r, &cur.ty, e.pos)?;
                        let v = self.binary(*op, cur, r, e.pos)?;
                        self.convert(v, &t, e.pos, true)?
                    }
                };
                self.write(&p, v.clone(), lhs.pos)?;
                v
            }
            ExprKind::Ternary(c, a, b) => self.ternary(c, a, b, e.pos)?,
            ExprKind::Call(..)
            | ExprKind::Method(..)
            | ExprKind::CallT(..)
            | ExprKind::MethodT(..) => match self.call_expr(e)? {
                Some(v) => v,
                None => {
                    return Err(Error::new(
                        e.pos,
                        "this call has no value (it returns void)",
                    ))
                }
            },
            ExprKind::Construct(t, args) => {
                let ns = self.f.cur_ns.clone();
                let ty = self.resolve_ty(t, &ns)?;
                self.construct(&ty, args, e.pos)?
            }
            ExprKind::Cast(t, a) => {
                let ns = self.f.cur_ns.clone();
                let ty = self.resolve_ty(t, &ns)?;
                if let Ty::Struct(_) = ty {
                    // `(S)0` zero-initializes; a same-typed value passes through.
                    if let Some(ConstValue::I(0)) = self.const_eval(a)? {
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
    pub(super) fn expr_as(&mut self, e: &'a Expr, t: &Ty) -> Result<Val> {
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

    pub(super) fn expr_init(&mut self, e: &'a Expr, t: &Ty) -> Result<Val> {
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
    pub(super) fn flatten(&mut self, v: Val, out: &mut Vec<Val>) -> Result<()> {
        let parts: Vec<Ty> = match &v.ty {
            Ty::ScalarKind(_) => {
                out.push(v);
                return Ok(());
            }
            Ty::Vec(s, n) => vec![Ty::ScalarKind(*s); *n as usize],
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
    pub(super) fn build(
        &mut self,
        t: &Ty,
        it: &mut std::vec::IntoIter<Val>,
        pos: Pos,
    ) -> Result<Val> {
        let parts: Vec<Ty> = match t {
            Ty::ScalarKind(_) => {
                let v = it.next().ok_or_else(|| {
                    Error::new(
                        pos,
                        format!("too few initializers for `{}`", self.ty_name(t)),
                    )
                })?;
                return self.convert(v, t, pos, false);
            }
            Ty::Vec(s, n) => vec![Ty::ScalarKind(*s); *n as usize],
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

    pub(super) fn construct(&mut self, ty: &Ty, args: &'a [Expr], pos: Pos) -> Result<Val> {
        if let Ty::Struct(_) = ty {
            // `S(a, b)`: a functional cast, component by component (as `(S)v` or `{a, b}`).
            if let [one] = args {
                if let ExprKind::Int(0, _) = one.kind {
                    let v = self.expr(one)?;
                    return self.convert(v, ty, pos, true);
                }
            }
            let mut flat = Vec::new();
            for a in args {
                let v = self.expr(a)?;
                self.flatten(v, &mut flat)?;
            }
            let n = flat.len();
            let mut it = flat.into_iter();
            let v = self.build(ty, &mut it, pos)?;
            if it.next().is_some() {
                return Err(Error::new(
                    pos,
                    format!("too many components ({n}) for a `{}`", self.ty_name(ty)),
                ));
            }
            return Ok(v);
        }
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
        if vals.len() == 1 && matches!(vals[0].ty, Ty::ScalarKind(_)) {
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
    pub(super) fn convert(&mut self, v: Val, to: &Ty, pos: Pos, explicit: bool) -> Result<Val> {
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
            (Ty::ScalarKind(a), Ty::ScalarKind(b)) => self.convert_scalar(v.id, *a, *b, to),
            (Ty::ScalarKind(_), Ty::Vec(s, n)) => {
                let c = self.convert(v, &Ty::ScalarKind(*s), pos, explicit)?;
                let tid = self.ty_id(to)?;
                let id = self.op(Op::CompositeConstruct, tid, &vec![c.id; *n as usize])?;
                Ok(Val { id, ty: to.clone() })
            }
            (Ty::ScalarKind(_), Ty::Mat(s, r, c)) => {
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
            (Ty::Vec(a, _), Ty::ScalarKind(b)) => {
                // Truncation to the first component (DXC warns; so would we).
                let s = self.shrink(v.clone(), &Ty::ScalarKind(*a))?;
                self.convert_scalar(s.id, *a, *b, to)
            }
            // half and float matrices: row by row (OpFConvert takes no matrices).
            (Ty::Mat(a, r, c), Ty::Mat(b, r2, c2))
                if a != b && ((r2 <= r && c2 <= c && explicit) || (r2 == r && c2 == c)) =>
            {
                let same = self.convert(v.clone(), &Ty::Mat(*a, *r2, *c2), pos, explicit)?;
                let rowt = self.ty_id(&Ty::Vec(*a, *c2))?;
                let mut rows = Vec::new();
                for i in 0..*r2 {
                    let row = self.inst(
                        Op::CompositeExtract,
                        Some(rowt),
                        vec![Operand::IdRef(same.id), Operand::LiteralBit32(i as u32)],
                    )?;
                    rows.push(self.convert_scalar(row, *a, *b, &Ty::Vec(*b, *c2))?.id);
                }
                let tid = self.ty_id(to)?;
                let id = self.op(Op::CompositeConstruct, tid, &rows)?;
                Ok(Val { id, ty: to.clone() })
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

    pub(super) fn convert_scalar(
        &mut self,
        id: Id,
        from: ScalarKind,
        to: ScalarKind,
        to_ty: &Ty,
    ) -> Result<Val> {
        if let (Ty::ScalarKind(_), Some(bits)) = (to_ty, self.const_ids.get(&id).copied()) {
            if from != ScalarKind::Bool && to != ScalarKind::Bool && from != to {
                let (f, i) = match from {
                    ScalarKind::Float => (f32::from_bits(bits) as f64, f32::from_bits(bits) as i64),
                    ScalarKind::Half => {
                        let v = consts::f16_to_f32(bits as u16);
                        (v as f64, v as i64)
                    }
                    // 16-bit signed constants are stored sign-extended.
                    ScalarKind::Int | ScalarKind::Int16 => (bits as i32 as f64, bits as i32 as i64),
                    _ => (bits as f64, bits as i64),
                };
                // Between integers the value is sign- or zero-extended from its
                // own type (then wraps to the target); float conversions convert.
                let i = if !from.is_float() && !to.is_float() {
                    if from.is_signed() {
                        bits as i32 as i64
                    } else {
                        bits as i64
                    }
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
            (ScalarKind::Bool, _) => {
                let one = self.const_splat(to_ty, 1.0)?;
                let zero = self.const_splat(to_ty, 0.0)?;
                self.op(Op::Select, tid, &[id, one, zero])?
            }
            (_, ScalarKind::Bool) => {
                let zero = self.const_splat(&from_ty, 0.0)?;
                let op = if from.is_float() {
                    Op::FUnordNotEqual
                } else {
                    Op::INotEqual
                };
                self.op(op, tid, &[id, zero])?
            }
            (s, t) if s.is_float() && t.is_float() => self.op(Op::FConvert, tid, &[id])?,
            (s, t) if t.is_float() && s.is_signed() => self.op(Op::ConvertSToF, tid, &[id])?,
            (_, t) if t.is_float() => self.op(Op::ConvertUToF, tid, &[id])?,
            (s, t) if s.is_float() && t.is_signed() => self.op(Op::ConvertFToS, tid, &[id])?,
            (s, _) if s.is_float() => self.op(Op::ConvertFToU, tid, &[id])?,
            // Integers of another width: extended by the source's signedness,
            // or truncated (the result type's signedness is its own).
            (s, t) if s.size() != t.size() && s.is_signed() => self.op(Op::SConvert, tid, &[id])?,
            (s, t) if s.size() != t.size() && t.is_signed() => {
                // OpUConvert makes an unsigned result: then reinterpret it.
                let u = match t {
                    ScalarKind::Int16 => ScalarKind::Uint16,
                    ScalarKind::Int64 => ScalarKind::Uint64,
                    _ => ScalarKind::Uint,
                };
                let ut = self.ty_id(&to_ty.with_scalar(u))?;
                let w = self.op(Op::UConvert, ut, &[id])?;
                self.op(Op::Bitcast, tid, &[w])?
            }
            (s, t) if s.size() != t.size() => self.op(Op::UConvert, tid, &[id])?,
            _ => self.op(Op::Bitcast, tid, &[id])?,
        };
        Ok(Val {
            id,
            ty: to_ty.clone(),
        })
    }

    /// A literal beside a 16-bit operand takes its type, as DXC's untyped
    /// literals do: `h * 2.0` is `half` arithmetic, `i16 + 1` is `int16_t`
    /// (a float literal beside a 16-bit integer stays `float`).
    pub(super) fn adapt_literal(&mut self, e: &Expr, v: Val, other: &Ty, pos: Pos) -> Result<Val> {
        let t = literal_ty(e, &v.ty, other);
        self.convert(v, &t, pos, true)
    }

    /// The type both operands of an arithmetic operator convert to.
    pub(super) fn common(&self, a: &Ty, b: &Ty, pos: Pos) -> Result<Ty> {
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
            (Ty::ScalarKind(_), x) | (x, Ty::ScalarKind(_)) => x.with_scalar(s),
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

    pub(super) fn binary(&mut self, op: BinOp, a: Val, b: Val, pos: Pos) -> Result<Val> {
        use BinOp::*;
        let mut ct = self.common(&a.ty, &b.ty, pos)?;
        let cmp = matches!(op, Eq | Ne | Lt | Le | Gt | Ge);
        let bits = matches!(op, Shl | Shr | BitAnd | BitOr | BitXor);
        if ct.scalar() == Some(ScalarKind::Bool) && !(cmp && matches!(op, Eq | Ne)) {
            ct = ct.with_scalar(ScalarKind::Int);
        }
        if matches!(op, Shl | Shr) {
            // A shift has its left operand's type (HLSL, like C).
            let ls = match a.ty.scalar() {
                Some(ScalarKind::Bool) | None => ScalarKind::Int,
                Some(s) => s,
            };
            ct = ct.with_scalar(ls);
        }
        if bits && ct.scalar().is_some_and(ScalarKind::is_float) {
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
        let s = ct.scalar().unwrap_or(ScalarKind::Float);
        let f = s.is_float();
        let signed = s.is_signed();
        let class = if f {
            0
        } else if signed {
            1
        } else if s == ScalarKind::Bool {
            3
        } else {
            2
        };
        let Some(opcode) = BINARY_OPS
            .iter()
            .find(|(o, _)| *o == op)
            .map(|(_, ops)| ops[class])
        else {
            return Err(Error::new(
                pos,
                format!("`{}` is not an arithmetic operator", op.as_str()),
            ));
        };
        let rt = if cmp {
            ct.with_scalar(ScalarKind::Bool)
        } else {
            ct
        };
        let tid = self.ty_id(&rt)?;
        let id = self.op(opcode, tid, &[a.id, b.id])?;
        Ok(Val { id, ty: rt })
    }

    /// `&&` and `||`: short-circuit on scalars (HLSL 2021), component-wise on vectors.
    pub(super) fn logical(&mut self, op: BinOp, a: &'a Expr, b: &'a Expr, pos: Pos) -> Result<Val> {
        let av = self.expr(a)?;
        if let Ty::Vec(_, n) = av.ty {
            let bv = self.expr(b)?;
            let t = Ty::Vec(
                ScalarKind::Bool,
                n.min(bv.ty.width().max(if matches!(bv.ty, Ty::ScalarKind(_)) {
                    n
                } else {
                    0
                })),
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
        let bool_t = Ty::ScalarKind(ScalarKind::Bool);
        let x = self.convert(av, &bool_t, a.pos, false)?;
        let from = self.f.cur_label;
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
        let rhs_end = self.f.cur_label;
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

    /// The type of `?:`: a literal side takes a 16-bit other side's type.
    fn ternary_ty(&self, a: &Expr, at: &Ty, b: &Expr, bt: &Ty, pos: Pos) -> Result<Ty> {
        let (at, bt) = (literal_ty(a, at, bt), literal_ty(b, bt, at));
        if at == bt {
            Ok(at)
        } else {
            self.common(&at, &bt, pos)
        }
    }

    pub(super) fn ternary(
        &mut self,
        c: &'a Expr,
        a: &'a Expr,
        b: &'a Expr,
        pos: Pos,
    ) -> Result<Val> {
        let cv = self.expr(c)?;
        let vector = matches!(cv.ty, Ty::Vec(..));
        if vector || (cheap_and_pure(a) && cheap_and_pure(b)) {
            // Vector conditions select per component, both sides evaluated
            // (as DXC); a scalar one may too when neither side can be
            // observed running, which leaves no temporary behind.
            let av = self.expr(a)?;
            let bv = self.expr(b)?;
            let t = self.ternary_ty(a, &av.ty, b, &bv.ty, pos)?;
            let t = match (t, &cv.ty) {
                (Ty::ScalarKind(s), Ty::Vec(_, n)) => Ty::Vec(s, *n),
                (other, _) => other,
            };
            if t.is_resource() || t.is_opaque() {
                return Err(unsupported(pos, "choosing a resource with `?:`"));
            }
            let x = self.convert(av, &t, pos, false)?;
            let y = self.convert(bv, &t, pos, false)?;
            let cond_ty = match cv.ty {
                Ty::Vec(..) => Ty::Vec(ScalarKind::Bool, t.width()),
                _ => Ty::ScalarKind(ScalarKind::Bool),
            };
            let cb = self.convert(cv, &cond_ty, c.pos, false)?;
            let tid = self.ty_id(&t)?;
            let id = self.op(Op::Select, tid, &[cb.id, x.id, y.id])?;
            return Ok(Val { id, ty: t });
        }
        let cb = self.convert(cv, &Ty::ScalarKind(ScalarKind::Bool), c.pos, false)?;
        // Only the chosen side runs, and its value reaches the merge through
        // an OpPhi: no variable, so nothing of the unchosen side is read. The
        // first side's value goes through a block of its own where it is
        // converted to the common type, known once the second side is.
        let (la, lb, a_conv, merge) = (self.b.id(), self.b.id(), self.b.id(), self.b.id());
        self.b
            .selection_merge(merge, spirv::SelectionControl::NONE)?;
        self.b.branch_conditional(cb.id, la, lb, [])?;
        let side = |this: &mut Self, label: Id, e: &'a Expr| -> Result<Val> {
            this.start_block(Some(label))?;
            let v = this.expr(e)?;
            if v.ty.is_resource() || v.ty.is_opaque() {
                // Vulkan has no function variables of resource types.
                return Err(unsupported(pos, "choosing a resource with `?:`"));
            }
            if this.f.term {
                this.start_block(None)?;
            }
            Ok(v)
        };
        let av = side(self, la, a)?;
        self.branch(a_conv)?;
        let bv = side(self, lb, b)?;
        let t = self.ternary_ty(a, &av.ty, b, &bv.ty, pos)?;
        let y = self.convert(bv, &t, b.pos, false)?;
        let from_b = self.f.cur_label;
        self.branch(merge)?;
        self.start_block(Some(a_conv))?;
        let x = self.convert(av, &t, a.pos, false)?;
        let from_a = self.f.cur_label;
        self.branch(merge)?;
        self.start_block(Some(merge))?;
        let tid = self.ty_id(&t)?;
        let id = self.inst(
            Op::Phi,
            Some(tid),
            vec![
                Operand::IdRef(x.id),
                Operand::IdRef(from_a),
                Operand::IdRef(y.id),
                Operand::IdRef(from_b),
            ],
        )?;
        Ok(Val { id, ty: t })
    }

    pub(super) fn unary(&mut self, op: UnOp, a: &'a Expr, pos: Pos) -> Result<Val> {
        match op {
            UnOp::Plus => self.expr(a),
            UnOp::Neg => {
                let v = self.expr(a)?;
                let v = if v.ty.scalar() == Some(ScalarKind::Bool) {
                    self.convert(v.clone(), &v.ty.with_scalar(ScalarKind::Int), pos, false)?
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
                let t = v.ty.with_scalar(ScalarKind::Bool);
                let b = self.convert(v, &t, pos, false)?;
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::LogicalNot, tid, &[b.id])?;
                Ok(Val { id, ty: t })
            }
            UnOp::BitNot => {
                let v = self.expr(a)?;
                if !v
                    .ty
                    .scalar()
                    .is_some_and(|s| s != ScalarKind::Bool && !s.is_float())
                {
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

/// Whether evaluating `e` can have no effect the program could observe
/// (no call, store, division or indexing that could be out of bounds) and
/// costs a few instructions: `c ? a : b` may then evaluate both sides.
fn cheap_and_pure(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Int(..)
        | ExprKind::Int64(..)
        | ExprKind::Float(_)
        | ExprKind::Bool(_)
        | ExprKind::Ident(_) => true,
        ExprKind::Member(base, _) => cheap_and_pure(base),
        ExprKind::Unary(op, x) => {
            matches!(op, UnOp::Neg | UnOp::Plus | UnOp::Not | UnOp::BitNot) && cheap_and_pure(x)
        }
        ExprKind::Binary(op, x, y) => {
            !matches!(op, BinOp::Div | BinOp::Rem) && cheap_and_pure(x) && cheap_and_pure(y)
        }
        ExprKind::Ternary(c, x, y) => cheap_and_pure(c) && cheap_and_pure(x) && cheap_and_pure(y),
        ExprKind::Cast(_, x) => cheap_and_pure(x),
        ExprKind::Construct(_, args) => args.iter().all(cheap_and_pure),
        _ => false,
    }
}

/// `ty` (the type of `e`), or, when `e` is an untyped literal beside a
/// 16-bit `other`, the same shape of `other`'s scalar: `h * 2.0` is `half`
/// as in DXC; a float literal beside a 16-bit integer stays `float`.
fn literal_ty(e: &Expr, ty: &Ty, other: &Ty) -> Ty {
    let lit = match &e.kind {
        ExprKind::Unary(UnOp::Neg, x) => &x.kind,
        k => k,
    };
    match (lit, other.scalar()) {
        (ExprKind::Float(_), Some(ScalarKind::Half)) => ty.with_scalar(ScalarKind::Half),
        (ExprKind::Int(..), Some(o)) if o.is_16() => ty.with_scalar(o),
        _ => ty.clone(),
    }
}
