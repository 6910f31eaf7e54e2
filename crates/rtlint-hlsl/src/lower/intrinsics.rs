//! The intrinsic table: one row per HLSL intrinsic function (name, arity,
//! allowed stages, lowering), split by family. `call` looks a name up once
//! here; adding an intrinsic is one row (and, for a new kind, its lowering).

use super::wave::WAVE;
use super::*;
use spirv::GlslStd450Op as G;

/// One intrinsic function.
pub(super) struct Intrinsic {
    pub(super) name: &'static str,
    pub(super) arity: usize,
    /// The stages that may call it; `None`: any (derivatives check their own).
    pub(super) stages: Option<&'static [Stage]>,
    pub(super) lower: Lowering,
}

/// How an intrinsic is lowered.
#[derive(Clone, Copy)]
pub(super) enum Lowering {
    /// A GLSL.std.450 instruction on one float scalar or vector.
    Glsl(G),
    /// The arguments first (literals beside 16-bit ones adapted), then
    /// `intrinsic`.
    Eval(Math),
    /// `ddx` and its kin: the instruction; pixel shaders only.
    Derivative(Op),
    /// A wave intrinsic (`lower/wave.rs`).
    Wave(super::wave::Wave),
    /// One with a lowering of its own.
    Special(Special),
    /// Not lowered: pixel shaders only, which rtlint does not compile.
    PixelOnly,
}

/// The intrinsics `intrinsic` lowers from evaluated arguments.
#[derive(Clone, Copy)]
pub(super) enum Math {
    Dot,
    Cross,
    Length,
    Distance,
    Reflect,
    FaceForward,
    Refract,
    /// A GLSL.std.450 instruction on float arguments of one type.
    Glsl(G),
    Mad,
    Saturate,
    /// `min`, `max`, `clamp`: the float, signed and unsigned instructions.
    MinMax(G, G, G),
    Abs,
    Sign,
    Fmod,
    Rcp,
    Log10,
    Mul,
    Transpose,
    Determinant,
    /// `any` (`OpAny`) and `all` (`OpAll`).
    AnyAll(Op),
    /// `asuint16`, `asint16`, `asfloat16`: the result's scalar.
    As16(ScalarKind),
    /// `asuint`, `asint`, `asfloat`: the result's scalar.
    As32(ScalarKind),
    /// `f32tof16` (true) and `f16tof32`.
    F16(bool),
    Bits(Bit),
    Class(FpClass),
}

/// `countbits`, `reversebits`, `firstbithigh`, `firstbitlow`.
#[derive(Clone, Copy)]
pub(super) enum Bit {
    Count,
    Reverse,
    High,
    Low,
}

/// `isnan`, `isinf`, `isfinite`.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum FpClass {
    Nan,
    Inf,
    Finite,
}

/// The intrinsics lowered by their own code in `special`.
#[derive(Clone, Copy)]
pub(super) enum Special {
    TraceRay,
    CallShader,
    ReportHit,
    /// `IgnoreHit` and `AcceptHitAndEndSearch`.
    EndHit,
    NonUniformIndex,
    /// The six memory barriers.
    Barrier,
    /// `and` and `or`.
    Logic,
    Select,
    Sincos,
    Modf,
    Ldexp,
}

/// A row for any stage.
pub(super) const fn any(name: &'static str, arity: usize, lower: Lowering) -> Intrinsic {
    Intrinsic {
        name,
        arity,
        stages: None,
        lower,
    }
}

/// A row for some stages only.
const fn only(
    name: &'static str,
    arity: usize,
    stages: &'static [Stage],
    lower: Lowering,
) -> Intrinsic {
    Intrinsic {
        name,
        arity,
        stages: Some(stages),
        lower,
    }
}

const RG_CH_MISS: &[Stage] = &[Stage::RayGeneration, Stage::ClosestHit, Stage::Miss];

/// Component-wise float math → GLSL.std.450.
const GLSL_UNARY: &[Intrinsic] = {
    use Lowering::Glsl;
    &[
        any("sin", 1, Glsl(G::Sin)),
        any("cos", 1, Glsl(G::Cos)),
        any("tan", 1, Glsl(G::Tan)),
        any("asin", 1, Glsl(G::Asin)),
        any("acos", 1, Glsl(G::Acos)),
        any("atan", 1, Glsl(G::Atan)),
        any("sinh", 1, Glsl(G::Sinh)),
        any("cosh", 1, Glsl(G::Cosh)),
        any("tanh", 1, Glsl(G::Tanh)),
        any("exp", 1, Glsl(G::Exp)),
        any("log", 1, Glsl(G::Log)),
        any("exp2", 1, Glsl(G::Exp2)),
        any("log2", 1, Glsl(G::Log2)),
        any("sqrt", 1, Glsl(G::Sqrt)),
        any("rsqrt", 1, Glsl(G::InverseSqrt)),
        any("floor", 1, Glsl(G::Floor)),
        any("ceil", 1, Glsl(G::Ceil)),
        any("frac", 1, Glsl(G::Fract)),
        any("trunc", 1, Glsl(G::Trunc)),
        any("round", 1, Glsl(G::RoundEven)),
        any("radians", 1, Glsl(G::Radians)),
        any("degrees", 1, Glsl(G::Degrees)),
        any("normalize", 1, Glsl(G::Normalize)),
    ]
};

/// Other scalar math.
const MATH: &[Intrinsic] = {
    use Lowering::{Eval, Special as S};
    &[
        any("lerp", 3, Eval(Math::Glsl(G::FMix))),
        any("saturate", 1, Eval(Math::Saturate)),
        any(
            "clamp",
            3,
            Eval(Math::MinMax(G::FClamp, G::SClamp, G::UClamp)),
        ),
        any("min", 2, Eval(Math::MinMax(G::FMin, G::SMin, G::UMin))),
        any("max", 2, Eval(Math::MinMax(G::FMax, G::SMax, G::UMax))),
        any("abs", 1, Eval(Math::Abs)),
        any("sign", 1, Eval(Math::Sign)),
        any("pow", 2, Eval(Math::Glsl(G::Pow))),
        any("atan2", 2, Eval(Math::Glsl(G::Atan2))),
        any("step", 2, Eval(Math::Glsl(G::Step))),
        any("smoothstep", 3, Eval(Math::Glsl(G::SmoothStep))),
        any("fmod", 2, Eval(Math::Fmod)),
        any("mad", 3, Eval(Math::Mad)),
        any("fma", 3, Eval(Math::Glsl(G::Fma))),
        any("rcp", 1, Eval(Math::Rcp)),
        any("log10", 1, Eval(Math::Log10)),
        any("isnan", 1, Eval(Math::Class(FpClass::Nan))),
        any("isinf", 1, Eval(Math::Class(FpClass::Inf))),
        any("isfinite", 1, Eval(Math::Class(FpClass::Finite))),
        any("sincos", 3, S(Special::Sincos)),
        any("modf", 2, S(Special::Modf)),
        any("ldexp", 2, S(Special::Ldexp)),
    ]
};

/// Vectors, matrices and component-wise logic.
const VECTOR: &[Intrinsic] = {
    use Lowering::{Eval, Special as S};
    &[
        any("dot", 2, Eval(Math::Dot)),
        any("cross", 2, Eval(Math::Cross)),
        any("length", 1, Eval(Math::Length)),
        any("distance", 2, Eval(Math::Distance)),
        any("reflect", 2, Eval(Math::Reflect)),
        any("refract", 3, Eval(Math::Refract)),
        any("faceforward", 3, Eval(Math::FaceForward)),
        any("mul", 2, Eval(Math::Mul)),
        any("transpose", 1, Eval(Math::Transpose)),
        any("determinant", 1, Eval(Math::Determinant)),
        any("any", 1, Eval(Math::AnyAll(Op::Any))),
        any("all", 1, Eval(Math::AnyAll(Op::All))),
        any("and", 2, S(Special::Logic)),
        any("or", 2, S(Special::Logic)),
        any("select", 3, S(Special::Select)),
    ]
};

/// Bits and reinterpretations.
const BITS: &[Intrinsic] = {
    use Lowering::Eval;
    &[
        any("asuint", 1, Eval(Math::As32(ScalarKind::Uint))),
        any("asint", 1, Eval(Math::As32(ScalarKind::Int))),
        any("asfloat", 1, Eval(Math::As32(ScalarKind::Float))),
        any("asuint16", 1, Eval(Math::As16(ScalarKind::Uint16))),
        any("asint16", 1, Eval(Math::As16(ScalarKind::Int16))),
        any("asfloat16", 1, Eval(Math::As16(ScalarKind::Half))),
        any("f32tof16", 1, Eval(Math::F16(true))),
        any("f16tof32", 1, Eval(Math::F16(false))),
        any("countbits", 1, Eval(Math::Bits(Bit::Count))),
        any("firstbithigh", 1, Eval(Math::Bits(Bit::High))),
        any("firstbitlow", 1, Eval(Math::Bits(Bit::Low))),
        any("reversebits", 1, Eval(Math::Bits(Bit::Reverse))),
    ]
};

/// Ray-tracing calls (system values are the table in `lower/system_values.rs`).
const RAY_TRACING: &[Intrinsic] = {
    use Lowering::Special as S;
    use Stage::*;
    &[
        only("TraceRay", 8, RG_CH_MISS, S(Special::TraceRay)),
        only(
            "CallShader",
            2,
            &[RayGeneration, ClosestHit, Miss, Callable],
            S(Special::CallShader),
        ),
        only("ReportHit", 3, &[Intersection], S(Special::ReportHit)),
        only("IgnoreHit", 0, &[AnyHit], S(Special::EndHit)),
        only("AcceptHitAndEndSearch", 0, &[AnyHit], S(Special::EndHit)),
    ]
};

/// Barriers and resource indexing.
const SYNC: &[Intrinsic] = {
    use Lowering::Special as S;
    &[
        any("GroupMemoryBarrierWithGroupSync", 0, S(Special::Barrier)),
        any("GroupMemoryBarrier", 0, S(Special::Barrier)),
        any("AllMemoryBarrierWithGroupSync", 0, S(Special::Barrier)),
        any("DeviceMemoryBarrierWithGroupSync", 0, S(Special::Barrier)),
        any("AllMemoryBarrier", 0, S(Special::Barrier)),
        any("DeviceMemoryBarrier", 0, S(Special::Barrier)),
        any("NonUniformResourceIndex", 1, S(Special::NonUniformIndex)),
    ]
};

/// Derivatives (and `clip`): pixel shaders.
const PIXEL: &[Intrinsic] = {
    use Lowering::{Derivative as D, PixelOnly};
    &[
        any("ddx", 1, D(Op::DPdx)),
        any("ddy", 1, D(Op::DPdy)),
        any("ddx_fine", 1, D(Op::DPdxFine)),
        any("ddy_fine", 1, D(Op::DPdyFine)),
        any("ddx_coarse", 1, D(Op::DPdxCoarse)),
        any("ddy_coarse", 1, D(Op::DPdyCoarse)),
        any("fwidth", 1, D(Op::Fwidth)),
        any("clip", 1, PixelOnly),
    ]
};

const FAMILIES: &[&[Intrinsic]] = &[
    GLSL_UNARY,
    MATH,
    VECTOR,
    BITS,
    RAY_TRACING,
    SYNC,
    PIXEL,
    WAVE,
];

/// The row of the intrinsic `name`.
pub(super) fn lookup(name: &str) -> Option<&'static Intrinsic> {
    FAMILIES
        .iter()
        .flat_map(|f| f.iter())
        .find(|r| r.name == name)
}

impl<'a> Lowerer<'a> {
    /// A call of the intrinsic `row`: arity and stage from the row, then its lowering.
    pub(super) fn lower_intrinsic(
        &mut self,
        row: &'static Intrinsic,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let name = row.name;
        match row.lower {
            // The arguments' own errors come before an arity error.
            Lowering::Eval(m) => {
                let vals = self.args(args)?;
                let vals = self.adapt_literal_args(args, vals, pos)?;
                self.arity(name, args, row.arity, pos)?;
                self.intrinsic(m, name, vals, pos).map(Some)
            }
            // The stage rule (deferred in helpers) comes before the arity.
            Lowering::Derivative(op) => self.derivative(op, name, row.arity, args, pos).map(Some),
            Lowering::PixelOnly => {
                Err(unsupported(pos, format!("`{name}` (pixel shaders only)"))
                    .len(name.len() as u32))
            }
            Lowering::Glsl(inst) => {
                self.checks(row, args, pos)?;
                let vals = self.args(args)?;
                let (t, ids) = self.unify(vals, true, pos)?;
                Ok(Some(self.glsl(inst, &t, &ids)?))
            }
            Lowering::Wave(kind) => {
                self.checks(row, args, pos)?;
                self.wave(kind, name, args).map(Some)
            }
            Lowering::Special(s) => {
                self.checks(row, args, pos)?;
                self.special(s, name, args, pos)
            }
        }
    }

    fn checks(&mut self, row: &Intrinsic, args: &[Expr], pos: Pos) -> Result<()> {
        self.arity(row.name, args, row.arity, pos)?;
        if let Some(stages) = row.stages {
            self.stage_check(row.name, stages, pos)?;
        }
        Ok(())
    }

    fn special(
        &mut self,
        s: Special,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        let f = Ty::ScalarKind(ScalarKind::Float);
        match s {
            Special::TraceRay => self.trace_ray(args, pos).map(|_| None),
            Special::CallShader => {
                let idx = self.expr(&args[0])?;
                let idx =
                    self.convert(idx, &Ty::ScalarKind(ScalarKind::Uint), args[0].pos, false)?;
                let p = self.place(&args[1])?;
                let t = p.ty().clone();
                if !matches!(t, Ty::Struct(_)) {
                    return Err(Error::new(args[1].pos, "callable data must be a struct"));
                }
                let var = self.rt_var(StorageClass::CallableDataKHR, &t)?;
                let v = self.read(&p)?;
                self.b.store(var, v.id, None, [])?;
                self.inst(
                    Op::ExecuteCallableKHR,
                    None,
                    vec![Operand::IdRef(idx.id), Operand::IdRef(var)],
                )?;
                let tid = self.ty_id(&t)?;
                let back = self.b.load(tid, None, var, None, [])?;
                self.write(&p, Val { id: back, ty: t }, args[1].pos)?;
                Ok(None)
            }
            Special::ReportHit => {
                let t = self.expr(&args[0])?;
                let t = self.convert(t, &f, args[0].pos, false)?;
                let k = self.expr(&args[1])?;
                let k = self.convert(k, &Ty::ScalarKind(ScalarKind::Uint), args[1].pos, false)?;
                let a = self.expr(&args[2])?;
                if !matches!(a.ty, Ty::Struct(_)) {
                    return Err(Error::new(args[2].pos, "hit attributes must be a struct"));
                }
                let var = self.rt_var(StorageClass::HitAttributeKHR, &a.ty)?;
                self.b.store(var, a.id, None, [])?;
                let bt = self.ty_id(&Ty::ScalarKind(ScalarKind::Bool))?;
                let id = self.op(Op::ReportIntersectionKHR, bt, &[t.id, k.id])?;
                Ok(Some(Val {
                    id,
                    ty: Ty::ScalarKind(ScalarKind::Bool),
                }))
            }
            Special::EndHit => {
                self.ray_tracing_caps();
                if self.f.term {
                    self.start_block(None)?;
                }
                if name == "IgnoreHit" {
                    self.b.ignore_intersection_khr()?;
                } else {
                    self.b.terminate_ray_khr()?;
                }
                self.f.term = true;
                Ok(None)
            }
            Special::NonUniformIndex => {
                let v = self.expr(&args[0])?;
                self.cap(Capability::ShaderNonUniform);
                self.ext("SPV_EXT_descriptor_indexing");
                self.nonuniform.insert(v.id);
                Ok(Some(v))
            }
            Special::Barrier => {
                let group = name.starts_with("Group");
                let mem = self.const_u32(if group { 2 } else { 1 });
                // AcquireRelease | WorkgroupMemory (| UniformMemory | ImageMemory).
                let sem = self.const_u32(if group {
                    0x108
                } else {
                    0x8 | 0x40 | 0x100 | 0x800
                });
                if name.ends_with("WithGroupSync") {
                    let wg = self.const_u32(2);
                    self.inst(
                        Op::ControlBarrier,
                        None,
                        vec![Operand::IdRef(wg), Operand::IdRef(mem), Operand::IdRef(sem)],
                    )?;
                } else {
                    self.inst(
                        Op::MemoryBarrier,
                        None,
                        vec![Operand::IdRef(mem), Operand::IdRef(sem)],
                    )?;
                }
                Ok(None)
            }
            Special::Logic => {
                // HLSL 2021's component-wise logic (`&&` no longer is on vectors).
                let a = self.expr(&args[0])?;
                let b = self.expr(&args[1])?;
                let t = self
                    .common(&a.ty, &b.ty, pos)?
                    .with_scalar(ScalarKind::Bool);
                if let Ty::Mat(..) = t {
                    return Err(unsupported(pos, format!("matrix arguments to `{name}`")));
                }
                let x = self.convert(a, &t, pos, false)?;
                let y = self.convert(b, &t, pos, false)?;
                let tid = self.ty_id(&t)?;
                let op = if name == "and" {
                    Op::LogicalAnd
                } else {
                    Op::LogicalOr
                };
                let id = self.op(op, tid, &[x.id, y.id])?;
                Ok(Some(Val { id, ty: t }))
            }
            Special::Select => {
                let c = self.expr(&args[0])?;
                let a = self.expr(&args[1])?;
                let b = self.expr(&args[2])?;
                let mut t = self.common(&a.ty, &b.ty, pos)?;
                if let (Ty::Vec(_, n), Ty::ScalarKind(s)) = (&c.ty, &t) {
                    t = Ty::Vec(*s, *n);
                }
                if let Ty::Mat(..) = t {
                    return Err(unsupported(pos, "matrix arguments to `select`"));
                }
                let ct = t.with_scalar(ScalarKind::Bool);
                let cb = self.convert(c, &ct, args[0].pos, false)?;
                let x = self.convert(a, &t, args[1].pos, false)?;
                let y = self.convert(b, &t, args[2].pos, false)?;
                let tid = self.ty_id(&t)?;
                let id = self.op(Op::Select, tid, &[cb.id, x.id, y.id])?;
                Ok(Some(Val { id, ty: t }))
            }
            Special::Sincos => {
                let x = self.expr(&args[0])?;
                let (t, ids) = self.unify(vec![x], true, pos)?;
                let sn = self.glsl(G::Sin, &t, &ids)?;
                let cs = self.glsl(G::Cos, &t, &ids)?;
                self.store_out(&args[1], sn)?;
                self.store_out(&args[2], cs)?;
                Ok(None)
            }
            Special::Modf => {
                // modf(x, out ip): the integer part truncates toward zero.
                let x = self.expr(&args[0])?;
                let (t, ids) = self.unify(vec![x], true, pos)?;
                let ip = self.glsl(G::Trunc, &t, &ids)?;
                let frac = self.binary(
                    BinOp::Sub,
                    Val {
                        id: ids[0],
                        ty: t.clone(),
                    },
                    ip.clone(),
                    pos,
                )?;
                self.store_out(&args[1], ip)?;
                Ok(Some(frac))
            }
            Special::Ldexp => {
                let vals = self.args(args)?;
                let (t, ids) = self.unify(vals, true, pos)?;
                let p = self.glsl(G::Exp2, &t, &ids[1..])?;
                self.binary(BinOp::Mul, Val { id: ids[0], ty: t }, p, pos)
                    .map(Some)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_intrinsic_has_one_row() {
        // `lookup` takes the first row of a name: a second would be dead.
        let mut seen = HashSet::new();
        for r in FAMILIES.iter().flat_map(|f| f.iter()) {
            assert!(seen.insert(r.name), "`{}` has two rows", r.name);
        }
        assert_eq!(lookup("WaveActiveSum").map(|r| r.arity), Some(1));
        assert_eq!(lookup("TraceRay").map(|r| r.arity), Some(8));
        assert!(lookup("InterlockedAdd").is_none());
    }
}
