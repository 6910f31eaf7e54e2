//! Wave intrinsics (SM 6.0) → SPIR-V group non-uniform instructions at
//! subgroup scope, as DXC maps them: the wave family of the intrinsic table.

use super::intrinsics::{any, Intrinsic, Lowering};
use super::*;

/// How a wave intrinsic is lowered.
#[derive(Clone, Copy)]
pub(super) enum Wave {
    /// A built-in input: `WaveGetLaneIndex`, `WaveGetLaneCount`.
    Lane(BuiltIn),
    /// `WaveIsFirstLane`: `OpGroupNonUniformElect`.
    Elect,
    /// `WaveActiveAnyTrue` / `AllTrue` on a `bool`.
    Vote(Op),
    /// `WaveActiveAllEqual` on a scalar.
    AllEqual,
    /// `WaveActiveBallot`: `uint4`.
    Ballot,
    /// `WaveReadLaneFirst`.
    First,
    /// `WaveReadLaneAt(value, lane)`.
    ReadAt,
    /// Reductions and prefix scans: (float op, signed op, unsigned op), group operation.
    Arith(Op, Op, Op, spirv::GroupOperation),
    /// Bitwise reductions on integers.
    Bits(Op),
    /// `WaveActiveCountBits` / `WavePrefixCountBits` of a `bool`.
    CountBits(spirv::GroupOperation),
}

/// The wave family of the intrinsic table.
pub(super) const WAVE: &[Intrinsic] = {
    use spirv::GroupOperation::{ExclusiveScan, Reduce};
    use Lowering::Wave as W;
    use Op::*;
    &[
        any(
            "WaveGetLaneIndex",
            0,
            W(Wave::Lane(BuiltIn::SubgroupLocalInvocationId)),
        ),
        any("WaveGetLaneCount", 0, W(Wave::Lane(BuiltIn::SubgroupSize))),
        any("WaveIsFirstLane", 0, W(Wave::Elect)),
        any("WaveActiveAnyTrue", 1, W(Wave::Vote(GroupNonUniformAny))),
        any("WaveActiveAllTrue", 1, W(Wave::Vote(GroupNonUniformAll))),
        any("WaveActiveAllEqual", 1, W(Wave::AllEqual)),
        any("WaveActiveBallot", 1, W(Wave::Ballot)),
        any("WaveReadLaneFirst", 1, W(Wave::First)),
        any("WaveReadLaneAt", 2, W(Wave::ReadAt)),
        any(
            "WaveActiveSum",
            1,
            W(Wave::Arith(
                GroupNonUniformFAdd,
                GroupNonUniformIAdd,
                GroupNonUniformIAdd,
                Reduce,
            )),
        ),
        any(
            "WaveActiveProduct",
            1,
            W(Wave::Arith(
                GroupNonUniformFMul,
                GroupNonUniformIMul,
                GroupNonUniformIMul,
                Reduce,
            )),
        ),
        any(
            "WaveActiveMin",
            1,
            W(Wave::Arith(
                GroupNonUniformFMin,
                GroupNonUniformSMin,
                GroupNonUniformUMin,
                Reduce,
            )),
        ),
        any(
            "WaveActiveMax",
            1,
            W(Wave::Arith(
                GroupNonUniformFMax,
                GroupNonUniformSMax,
                GroupNonUniformUMax,
                Reduce,
            )),
        ),
        any(
            "WavePrefixSum",
            1,
            W(Wave::Arith(
                GroupNonUniformFAdd,
                GroupNonUniformIAdd,
                GroupNonUniformIAdd,
                ExclusiveScan,
            )),
        ),
        any(
            "WavePrefixProduct",
            1,
            W(Wave::Arith(
                GroupNonUniformFMul,
                GroupNonUniformIMul,
                GroupNonUniformIMul,
                ExclusiveScan,
            )),
        ),
        any(
            "WaveActiveBitAnd",
            1,
            W(Wave::Bits(GroupNonUniformBitwiseAnd)),
        ),
        any(
            "WaveActiveBitOr",
            1,
            W(Wave::Bits(GroupNonUniformBitwiseOr)),
        ),
        any(
            "WaveActiveBitXor",
            1,
            W(Wave::Bits(GroupNonUniformBitwiseXor)),
        ),
        any("WaveActiveCountBits", 1, W(Wave::CountBits(Reduce))),
        any("WavePrefixCountBits", 1, W(Wave::CountBits(ExclusiveScan))),
    ]
};

impl<'a> Lowerer<'a> {
    /// A wave intrinsic of the kind `kind` (arity already checked).
    pub(super) fn wave(&mut self, kind: Wave, name: &str, args: &'a [Expr]) -> Result<Val> {
        self.cap(Capability::GroupNonUniform);
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let b = Ty::ScalarKind(ScalarKind::Bool);
        let scope = self.const_u32(spirv::Scope::Subgroup as u32);
        let group_op = |this: &mut Self, op: Op, ty: &Ty, rest: Vec<Operand>| -> Result<Val> {
            let tid = this.ty_id(ty)?;
            let mut ops = vec![Operand::IdRef(scope)];
            ops.extend(rest);
            let id = this.inst(op, Some(tid), ops)?;
            Ok(Val { id, ty: ty.clone() })
        };
        let v = match kind {
            Wave::Lane(bi) => self.read_builtin(bi, &u)?,
            Wave::Elect => group_op(self, Op::GroupNonUniformElect, &b, vec![])?,
            Wave::Vote(op) => {
                self.cap(Capability::GroupNonUniformVote);
                let c = self.expr_as(&args[0], &b)?;
                group_op(self, op, &b, vec![Operand::IdRef(c.id)])?
            }
            Wave::AllEqual => {
                self.cap(Capability::GroupNonUniformVote);
                let x = self.expr(&args[0])?;
                if !matches!(x.ty, Ty::ScalarKind(_)) {
                    return Err(unsupported(
                        args[0].pos,
                        format!("`{name}` of a `{}` (scalars only)", self.ty_name(&x.ty)),
                    ));
                }
                group_op(
                    self,
                    Op::GroupNonUniformAllEqual,
                    &b,
                    vec![Operand::IdRef(x.id)],
                )?
            }
            Wave::Ballot => {
                self.cap(Capability::GroupNonUniformBallot);
                let c = self.expr_as(&args[0], &b)?;
                let u4 = Ty::Vec(ScalarKind::Uint, 4);
                group_op(
                    self,
                    Op::GroupNonUniformBallot,
                    &u4,
                    vec![Operand::IdRef(c.id)],
                )?
            }
            Wave::First | Wave::ReadAt => {
                let x = self.wave_value(name, &args[0])?;
                if let Wave::First = kind {
                    self.cap(Capability::GroupNonUniformBallot);
                    group_op(
                        self,
                        Op::GroupNonUniformBroadcastFirst,
                        &x.ty.clone(),
                        vec![Operand::IdRef(x.id)],
                    )?
                } else {
                    self.cap(Capability::GroupNonUniformShuffle);
                    let lane = self.expr_as(&args[1], &u)?;
                    group_op(
                        self,
                        Op::GroupNonUniformShuffle,
                        &x.ty.clone(),
                        vec![Operand::IdRef(x.id), Operand::IdRef(lane.id)],
                    )?
                }
            }
            Wave::Arith(fop, sop, uop, gop) => {
                self.cap(Capability::GroupNonUniformArithmetic);
                let x = self.wave_value(name, &args[0])?;
                let op = match x.ty.scalar() {
                    Some(s) if s.is_float() => fop,
                    Some(s) if s.is_signed() => sop,
                    _ => uop,
                };
                group_op(
                    self,
                    op,
                    &x.ty.clone(),
                    vec![Operand::GroupOperation(gop), Operand::IdRef(x.id)],
                )?
            }
            Wave::Bits(op) => {
                self.cap(Capability::GroupNonUniformArithmetic);
                let x = self.wave_value(name, &args[0])?;
                if !matches!(
                    x.ty.scalar(),
                    Some(
                        ScalarKind::Int | ScalarKind::Uint | ScalarKind::Int16 | ScalarKind::Uint16
                    )
                ) {
                    return Err(Error::new(
                        args[0].pos,
                        format!("`{name}` needs an integer, not a `{}`", self.ty_name(&x.ty)),
                    ));
                }
                group_op(
                    self,
                    op,
                    &x.ty.clone(),
                    vec![
                        Operand::GroupOperation(spirv::GroupOperation::Reduce),
                        Operand::IdRef(x.id),
                    ],
                )?
            }
            Wave::CountBits(gop) => {
                self.cap(Capability::GroupNonUniformBallot);
                let c = self.expr_as(&args[0], &b)?;
                let u4 = Ty::Vec(ScalarKind::Uint, 4);
                let ballot = group_op(
                    self,
                    Op::GroupNonUniformBallot,
                    &u4,
                    vec![Operand::IdRef(c.id)],
                )?;
                group_op(
                    self,
                    Op::GroupNonUniformBallotBitCount,
                    &u,
                    vec![Operand::GroupOperation(gop), Operand::IdRef(ballot.id)],
                )?
            }
        };
        Ok(v)
    }

    /// A numeric scalar or vector argument of a wave intrinsic.
    fn wave_value(&mut self, name: &str, e: &'a Expr) -> Result<Val> {
        let x = self.expr(e)?;
        match x.ty {
            // 16-bit values need the device's shaderSubgroupExtendedTypes.
            Ty::ScalarKind(s) | Ty::Vec(s, _) if s != ScalarKind::Bool && !s.is_64() => Ok(x),
            _ => Err(unsupported(
                e.pos,
                format!("`{name}` of a `{}`", self.ty_name(&x.ty)),
            )),
        }
    }
}
