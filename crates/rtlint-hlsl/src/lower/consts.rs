//! SPIR-V types and constants: type ids, layouts, constant folding and
//! evaluation of constant expressions.

use super::inline_spirv::decoration_operands;
use super::*;

impl<'a> Lowerer<'a> {
    pub(super) fn sc_id(&mut self, s: ScalarKind) -> Id {
        match s {
            ScalarKind::Bool => self.b.type_bool(),
            ScalarKind::Int => self.b.type_int(32, 1),
            ScalarKind::Uint => self.b.type_int(32, 0),
            ScalarKind::Int64 => {
                self.cap(Capability::Int64);
                self.b.type_int(64, 1)
            }
            ScalarKind::Uint64 => {
                self.cap(Capability::Int64);
                self.b.type_int(64, 0)
            }
            ScalarKind::Float => self.b.type_float(32, None),
            ScalarKind::Int16 => {
                self.cap(Capability::Int16);
                self.b.type_int(16, 1)
            }
            ScalarKind::Uint16 => {
                self.cap(Capability::Int16);
                self.b.type_int(16, 0)
            }
            ScalarKind::Half => {
                self.cap(Capability::Float16);
                self.b.type_float(16, None)
            }
        }
    }

    pub(super) fn ty_id(&mut self, t: &Ty) -> Result<Id> {
        self.spv(t, Layout::None)
    }

    /// An `OpUndef` of type `t` (one per type, at module scope, where
    /// `Builder::undef` would not put it while a block is selected).
    pub(super) fn undef(&mut self, t: &Ty) -> Result<Id> {
        let tid = self.ty_id(t)?;
        if let Some(&id) = self.undefs.get(&tid) {
            return Ok(id);
        }
        let id = self.b.id();
        self.b.insert_types_global_values(
            InsertPoint::End,
            Instruction::new(Op::Undef, Some(tid), Some(id), vec![]),
        );
        self.undefs.insert(tid, id);
        Ok(id)
    }

    /// The SPIR-V type of `t` laid out per `layout`.
    pub(super) fn spv(&mut self, t: &Ty, layout: Layout) -> Result<Id> {
        let layout = match t {
            Ty::Struct(_) | Ty::Array(..) => layout,
            // Buffers hold no bools (Vulkan forbids them there); DXC stores uints.
            Ty::ScalarKind(ScalarKind::Bool) | Ty::Vec(ScalarKind::Bool, _)
                if layout != Layout::None =>
            {
                return self.spv(&t.with_scalar(ScalarKind::Uint), Layout::None);
            }
            _ => Layout::None,
        };
        let key = (t.clone(), layout, false);
        if let Some(id) = self.ty_cache.get(&key) {
            return Ok(*id);
        }
        let id = match t {
            Ty::Void => self.b.type_void(),
            Ty::ScalarKind(s) => self.sc_id(*s),
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
            // Its capability is chosen once the stages are known
            // (`acceleration_structure_caps`).
            Ty::Accel => self.b.type_acceleration_structure_khr(),
            Ty::RayQuery(_) => {
                self.cap(Capability::RayQueryKHR);
                self.ext("SPV_KHR_ray_query");
                self.b.type_ray_query_khr()
            }
            Ty::Sampler | Ty::SamplerCmp => self.b.type_sampler(),
            Ty::HitObject => {
                self.ser_caps();
                self.b.type_hit_object_nv()
            }
            Ty::Texture {
                dim,
                sc,
                n,
                rw,
                fmt,
            } => {
                let st = self.sc_id(if *sc == ScalarKind::Bool {
                    ScalarKind::Uint
                } else {
                    sc.wide()
                });
                let (d, arrayed) = match dim {
                    Dim::D1 => (spirv::Dim::Dim1D, 0),
                    Dim::D2 => (spirv::Dim::Dim2D, 0),
                    Dim::D3 => (spirv::Dim::Dim3D, 0),
                    Dim::Cube => (spirv::Dim::DimCube, 0),
                    Dim::D2Array => (spirv::Dim::Dim2D, 1),
                    Dim::D1Array => (spirv::Dim::Dim1D, 1),
                    Dim::CubeArray => (spirv::Dim::DimCube, 1),
                    Dim::Buffer => (spirv::Dim::DimBuffer, 0),
                };
                if *dim == Dim::Buffer {
                    self.cap(if *rw {
                        Capability::ImageBuffer
                    } else {
                        Capability::SampledBuffer
                    });
                }
                if *dim == Dim::CubeArray {
                    self.cap(if *rw {
                        Capability::ImageCubeArray
                    } else {
                        Capability::SampledCubeArray
                    });
                }
                if matches!(dim, Dim::D1 | Dim::D1Array) {
                    self.cap(if *rw {
                        Capability::Image1D
                    } else {
                        Capability::Sampled1D
                    });
                }
                let format = if *rw {
                    fmt.unwrap_or_else(|| self.image_format(*sc, *n))
                } else {
                    spirv::ImageFormat::Unknown
                };
                if *rw && extended_format(format) {
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

    pub(super) fn image_format(&self, sc: ScalarKind, n: u8) -> spirv::ImageFormat {
        use spirv::ImageFormat as F;
        match (sc, n) {
            (ScalarKind::Float, 1) => F::R32f,
            (ScalarKind::Float, 2) => F::Rg32f,
            (ScalarKind::Float, 4) => F::Rgba32f,
            (ScalarKind::Uint, 1) => F::R32ui,
            (ScalarKind::Uint, 2) => F::Rg32ui,
            (ScalarKind::Uint, 4) => F::Rgba32ui,
            (ScalarKind::Int, 1) => F::R32i,
            (ScalarKind::Int, 2) => F::Rg32i,
            (ScalarKind::Int, 4) => F::Rgba32i,
            // 16-bit texels: 16-bit formats, as DXC derives them.
            (ScalarKind::Half, 1) => F::R16f,
            (ScalarKind::Half, 2) => F::Rg16f,
            (ScalarKind::Half, 4) => F::Rgba16f,
            (ScalarKind::Uint16, 1) => F::R16ui,
            (ScalarKind::Uint16, 2) => F::Rg16ui,
            (ScalarKind::Uint16, 4) => F::Rgba16ui,
            (ScalarKind::Int16, 1) => F::R16i,
            (ScalarKind::Int16, 2) => F::Rg16i,
            (ScalarKind::Int16, 4) => F::Rgba16i,
            _ => F::Unknown,
        }
    }

    pub(super) fn ray_tracing_caps(&mut self) {
        self.cap(Capability::RayTracingKHR);
        self.ext("SPV_KHR_ray_tracing");
    }

    /// An acceleration structure type needs ray-tracing pipelines or ray
    /// queries: in a module without ray-tracing stages that is ray queries,
    /// so that a device with only VK_KHR_ray_query runs it (as DXC chooses).
    pub(super) fn acceleration_structure_caps(&mut self) {
        let has_type = self
            .b
            .module_ref()
            .types_global_values
            .iter()
            .any(|i| i.class.opcode == Op::TypeAccelerationStructureKHR);
        let covered = [Capability::RayTracingKHR, Capability::RayQueryKHR]
            .iter()
            .any(|c| self.caps.contains(c));
        if has_type && !covered {
            self.cap(Capability::RayQueryKHR);
            self.ext("SPV_KHR_ray_query");
        }
    }

    pub(super) fn struct_type(&mut self, k: u32, layout: Layout, block: bool) -> Result<Id> {
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
        for (i, d, ops) in self.member_decorations.get(&k).cloned().unwrap_or_default() {
            self.b
                .member_decorate(id, i, d, decoration_operands(d, ops));
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

    pub(super) fn const_bits(&mut self, ty: Id, bits: u32) -> Id {
        if let Some(id) = self.consts.get(&(ty, bits)) {
            return *id;
        }
        let id = self.b.constant_bit32(ty, bits);
        self.consts.insert((ty, bits), id);
        self.const_ids.insert(id, bits);
        id
    }

    /// The value of a scalar constant made by this lowerer, as (scalar, bits).
    pub(super) fn known(&self, v: &Val) -> Option<(ScalarKind, u32)> {
        match v.ty {
            Ty::ScalarKind(s @ (ScalarKind::Int | ScalarKind::Uint | ScalarKind::Float)) => {
                self.const_ids.get(&v.id).map(|b| (s, *b))
            }
            _ => None,
        }
    }

    /// Folds an operator on two scalar constants, so trace operands, flags and
    /// SBT indices written as expressions stay constants in the module.
    pub(super) fn fold(
        &mut self,
        op: BinOp,
        a: (ScalarKind, u32),
        b: (ScalarKind, u32),
    ) -> Option<Val> {
        use BinOp::*;
        let (s, x, y) = (a.0, a.1, b.1);
        if s != b.0 {
            return None;
        }
        let v = match s {
            ScalarKind::Float => {
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
                    ty: Ty::ScalarKind(ScalarKind::Float),
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
                Shr if y < 32 && s == ScalarKind::Uint => x >> y,
                Shr if y < 32 => ((x as i32) >> y) as u32,
                _ => return None,
            },
        };
        let t = self.sc_id(s);
        Some(Val {
            id: self.const_bits(t, v),
            ty: Ty::ScalarKind(s),
        })
    }

    pub(super) fn const_u32(&mut self, v: u32) -> Id {
        let t = self.sc_id(ScalarKind::Uint);
        self.const_bits(t, v)
    }

    pub(super) fn const_i32(&mut self, v: i32) -> Id {
        let t = self.sc_id(ScalarKind::Int);
        self.const_bits(t, v as u32)
    }

    pub(super) fn const_f32(&mut self, v: f32) -> Id {
        let t = self.sc_id(ScalarKind::Float);
        self.const_bits(t, v.to_bits())
    }

    pub(super) fn const_bool(&mut self, v: bool) -> Id {
        let t = self.sc_id(ScalarKind::Bool);
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

    pub(super) fn const_scalar(&mut self, s: ScalarKind, f: f64, i: i64) -> Id {
        match s {
            ScalarKind::Bool => self.const_bool(i != 0 || f != 0.0),
            ScalarKind::Int => self.const_i32(i as i32),
            ScalarKind::Uint => self.const_u32(i as u32),
            ScalarKind::Int64 | ScalarKind::Uint64 => {
                let t = self.sc_id(s);
                self.b.constant_bit64(t, i as u64)
            }
            ScalarKind::Float => self.const_f32(f as f32),
            // One word: zero-extended, or sign-extended for signed types
            // (SPIR-V's rule for literals narrower than 32 bits).
            ScalarKind::Int16 => {
                let t = self.sc_id(s);
                self.const_bits(t, i as i16 as i32 as u32)
            }
            ScalarKind::Uint16 => {
                let t = self.sc_id(s);
                self.const_bits(t, i as u16 as u32)
            }
            ScalarKind::Half => {
                let t = self.sc_id(s);
                self.const_bits(t, f32_to_f16(f as f32) as u32)
            }
        }
    }

    /// A constant of numeric type `t` with every component `v`.
    pub(super) fn const_splat(&mut self, t: &Ty, v: f64) -> Result<Id> {
        let s = t.scalar().unwrap_or(ScalarKind::Float);
        let c = self.const_scalar(s, v, v as i64);
        Ok(match t {
            Ty::ScalarKind(_) => c,
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
    pub(super) fn const_int(&mut self, e: &Expr) -> Result<i64> {
        match self.const_eval(e)? {
            Some(ConstValue::I(v)) => Ok(v),
            Some(ConstValue::F(f)) => Ok(f as i64),
            _ => Err(Error::new(e.pos, "expected an integer constant")),
        }
    }

    pub(super) fn const_eval(&mut self, e: &Expr) -> Result<Option<ConstValue>> {
        Ok(match &e.kind {
            ExprKind::Int(v, _) | ExprKind::Int64(v, _) => Some(ConstValue::I(*v as i64)),
            ExprKind::Float(f) => Some(ConstValue::F(*f)),
            ExprKind::Bool(b) => Some(ConstValue::I(*b as i64)),
            ExprKind::SizeOf(t, dims) => Some(ConstValue::I(self.size_of(t, dims, e.pos)? as i64)),
            ExprKind::SizeOfExpr(x) => {
                let t = self.type_of_name(x)?;
                let n = packed_size(&t, &self.structs).ok_or_else(|| {
                    Error::new(
                        e.pos,
                        format!("`{}` has no size in memory", self.ty_name(&t)),
                    )
                })?;
                Some(ConstValue::I(n as i64))
            }
            ExprKind::Ident(n) => {
                // A local shadows every global: constant only when it is one.
                if let Some(p) = self.f.scopes.iter().rev().find_map(|s| s.get(n.as_str())) {
                    return Ok(match p {
                        Place::Value(v) => match self.known(v) {
                            Some((ScalarKind::Float, b)) => {
                                Some(ConstValue::F(f32::from_bits(b) as f64))
                            }
                            Some((ScalarKind::Int, b)) => Some(ConstValue::I(b as i32 as i64)),
                            Some((_, b)) => Some(ConstValue::I(b as i64)),
                            None => None,
                        },
                        _ => None,
                    });
                }
                if let Some(v) = builtin_constant(n) {
                    return Ok(Some(ConstValue::I(v as i64)));
                }
                self.enum_value(n)
            }
            ExprKind::Unary(op, a) => {
                let Some(a) = self.const_eval(a)? else {
                    return Ok(None);
                };
                match (op, a) {
                    (UnOp::Neg, ConstValue::I(v)) => Some(ConstValue::I(v.wrapping_neg())),
                    (UnOp::Neg, ConstValue::F(v)) => Some(ConstValue::F(-v)),
                    (UnOp::Plus, v) => Some(v),
                    (UnOp::BitNot, ConstValue::I(v)) => Some(ConstValue::I(!v & 0xffff_ffff)),
                    (UnOp::Not, ConstValue::I(v)) => Some(ConstValue::I((v == 0) as i64)),
                    _ => None,
                }
            }
            ExprKind::Binary(op, a, b) => {
                let (Some(a), Some(b)) = (self.const_eval(a)?, self.const_eval(b)?) else {
                    return Ok(None);
                };
                match (a, b) {
                    (ConstValue::I(a), ConstValue::I(b)) => {
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
                        Some(ConstValue::I(v))
                    }
                    (a, b) => {
                        let (a, b) = (a.as_f64(), b.as_f64());
                        match op {
                            BinOp::Add => Some(ConstValue::F(a + b)),
                            BinOp::Sub => Some(ConstValue::F(a - b)),
                            BinOp::Mul => Some(ConstValue::F(a * b)),
                            BinOp::Div => Some(ConstValue::F(a / b)),
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
                    Some(("float" | "half", 0, 0)) => Some(ConstValue::F(v.as_f64())),
                    Some(("int" | "uint" | "dword", 0, 0)) => {
                        Some(ConstValue::I(v.as_f64() as i64))
                    }
                    _ => None,
                }
            }
            ExprKind::Ternary(c, a, b) => match self.const_eval(c)? {
                Some(ConstValue::I(c)) => {
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

    /// A named constant: looked up in the current namespace (or struct),
    /// then each enclosing one, then the `using` namespaces.
    pub(super) fn enum_value(&self, n: &str) -> Option<ConstValue> {
        self.scoped_names(n)
            .iter()
            .find_map(|k| self.const_items.get(k))
            .cloned()
    }

    /// A constant of type `t` from an initializer, or `None` when it is not constant.
    pub(super) fn const_value(&mut self, e: &Expr, t: &Ty) -> Result<Option<Id>> {
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

    pub(super) fn const_flatten(&mut self, e: &Expr, out: &mut Vec<ConstValue>) -> Result<bool> {
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

    pub(super) fn const_build(
        &mut self,
        t: &Ty,
        it: &mut std::vec::IntoIter<ConstValue>,
        pos: Pos,
    ) -> Result<Id> {
        let mut next = |this: &mut Self, s: ScalarKind| -> Result<Id> {
            let v = it
                .next()
                .ok_or_else(|| Error::new(pos, "too few initializers"))?;
            let f = v.as_f64();
            let i = match v {
                ConstValue::I(i) => i,
                ConstValue::F(f) => f as i64,
            };
            Ok(this.const_scalar(s, f, i))
        };
        match t {
            Ty::ScalarKind(s) => next(self, *s),
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
}

/// Storage-image formats that need `StorageImageExtendedFormats`.
fn extended_format(f: spirv::ImageFormat) -> bool {
    use spirv::ImageFormat as F;
    !matches!(
        f,
        F::Unknown
            | F::Rgba32f
            | F::Rgba16f
            | F::R32f
            | F::Rgba8
            | F::Rgba8Snorm
            | F::Rgba32i
            | F::Rgba16i
            | F::Rgba8i
            | F::R32i
            | F::Rgba32ui
            | F::Rgba16ui
            | F::Rgba8ui
            | F::R32ui
    )
}

impl Lowerer<'_> {
    /// `sizeof(T)` in bytes.
    pub(super) fn size_of(&mut self, t: &TypeRef, dims: &[Option<Expr>], pos: Pos) -> Result<u32> {
        let ns = self.f.cur_ns.clone();
        let ty = self.resolve_ty(t, &ns)?;
        let ty = self.apply_dims(ty, dims, pos, false)?;
        packed_size(&ty, &self.structs).ok_or_else(|| {
            Error::new(
                pos,
                format!("`{}` has no size in memory", self.ty_name(&ty)),
            )
        })
    }

    /// The type of a name, member or element, without evaluating anything
    /// (for `sizeof(expression)`).
    pub(super) fn type_of_name(&mut self, e: &Expr) -> Result<Ty> {
        let refuse = || {
            unsupported(
                e.pos,
                "`sizeof` of an expression other than a name, member or element",
            )
        };
        match &e.kind {
            ExprKind::Ident(n) => {
                for s in self.f.scopes.iter().rev() {
                    if let Some(p) = s.get(n.as_str()) {
                        return Ok(p.ty().clone());
                    }
                }
                let ns = self.f.cur_ns.clone();
                let names = [format!("{ns}{n}"), n.clone()];
                for c in &names {
                    match self.globals.get(c) {
                        Some(Global::Const(v)) => return Ok(v.ty.clone()),
                        Some(Global::Place(p)) => return Ok(p.ty().clone()),
                        None => {}
                    }
                    if let Some((_, t, ..)) = self.cbuffer_members.get(c) {
                        return Ok(t.clone());
                    }
                }
                Err(Error::new(e.pos, format!("unknown name `{n}`")))
            }
            ExprKind::Index(b, _) => match self.type_of_name(b)? {
                Ty::Array(t, _) | Ty::RtArray(t) => Ok(*t),
                Ty::Vec(s, _) => Ok(Ty::ScalarKind(s)),
                Ty::Mat(s, _, c) => Ok(Ty::Vec(s, c)),
                _ => Err(refuse()),
            },
            ExprKind::Member(b, m) => match self.type_of_name(b)? {
                Ty::Struct(k) => self.structs[k as usize]
                    .fields
                    .iter()
                    .find(|f| f.name == *m)
                    .map(|f| f.ty.clone())
                    .ok_or_else(refuse),
                _ => Err(refuse()),
            },
            _ => Err(refuse()),
        }
    }
}

/// IEEE binary16 bits of `x`, rounded to nearest even (as DXC folds
/// `(half)x`): overflow gives infinity, tiny values subnormals or zero.
pub(super) fn f32_to_f16(x: f32) -> u16 {
    let b = x.to_bits();
    let sign = ((b >> 16) & 0x8000) as u16;
    let exp = ((b >> 23) & 0xff) as i32;
    let man = b & 0x7f_ffff;
    if exp == 0xff {
        // Infinity stays infinity; NaN stays a (quiet) NaN.
        return sign | 0x7c00 | if man != 0 { 0x200 } else { 0 };
    }
    let e = exp - 127 + 15;
    if e >= 0x1f {
        return sign | 0x7c00;
    }
    if e <= 0 {
        if e < -10 {
            return sign;
        }
        // Subnormal: the implicit bit joins the mantissa, shifted into place.
        let m = man | 0x80_0000;
        let shift = (14 - e) as u32;
        let half = 1u32 << (shift - 1);
        let rest = m & ((1 << shift) - 1);
        let mut r = m >> shift;
        if rest > half || (rest == half && r & 1 == 1) {
            r += 1;
        }
        return sign | r as u16;
    }
    let rest = man & 0x1fff;
    let mut r = ((e as u32) << 10) | (man >> 13);
    if rest > 0x1000 || (rest == 0x1000 && r & 1 == 1) {
        // A carry into the exponent is right (up to infinity).
        r += 1;
    }
    sign | r as u16
}

/// The value of IEEE binary16 bits.
pub(super) fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = ((h >> 10) & 0x1f) as i32;
    let man = (h & 0x3ff) as f32;
    sign * match exp {
        0 => man * (-24f32).exp2(),
        0x1f if man == 0.0 => f32::INFINITY,
        0x1f => f32::NAN,
        _ => (1.0 + man / 1024.0) * ((exp - 15) as f32).exp2(),
    }
}
