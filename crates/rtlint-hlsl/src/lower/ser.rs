//! Shader Execution Reordering (SM 6.9): `dx::HitObject` and
//! `dx::MaybeReorderThread` → SPV_NV_shader_invocation_reorder.
//!
//! A hit object is opaque: it lives in a function variable that the
//! `OpHitObject*NV` instructions fill and read. So `HitObject::TraceRay`,
//! `MakeMiss` and `MakeNop` are lowered where they initialize or are assigned
//! to a variable, writing into it.

use super::*;

const RG_CH_MISS: &[Stage] = &[Stage::RayGeneration, Stage::ClosestHit, Stage::Miss];

impl<'a> Lowerer<'a> {
    pub(super) fn ser_caps(&mut self) {
        self.ray_tracing_caps();
        self.cap(Capability::ShaderInvocationReorderNV);
        self.ext("SPV_NV_shader_invocation_reorder");
    }

    /// Whether `e` makes a hit object (`HitObject::TraceRay(...)`, ...).
    pub(super) fn is_hit_object_maker(e: &Expr) -> bool {
        matches!(&e.kind, ExprKind::Call(n, _)
            if matches!(n.as_str(), "HitObject::TraceRay" | "HitObject::MakeMiss" | "HitObject::MakeNop"))
    }

    /// Fills the hit object at `dst` from `e`: a maker call, or a copy of another
    /// hit object variable (refused: hit objects cannot be copied in SPIR-V).
    pub(super) fn make_hit_object(&mut self, dst: Id, e: &'a Expr) -> Result<()> {
        self.ser_caps();
        let ExprKind::Call(name, args) = &e.kind else {
            return Err(unsupported(
                e.pos,
                "copying a HitObject; make it with HitObject::TraceRay, MakeMiss or MakeNop",
            ));
        };
        match name.as_str() {
            "HitObject::MakeNop" => {
                self.arity(name, args, 0, e.pos)?;
                self.inst(Op::HitObjectRecordEmptyNV, None, vec![Operand::IdRef(dst)])?;
            }
            "HitObject::MakeMiss" => {
                // SPV_NV_shader_invocation_reorder records a miss without ray flags.
                self.arity(name, args, 3, e.pos)?;
                let flags = self.expr_as(&args[0], &Ty::ScalarKind(ScalarKind::Uint))?;
                if self.known(&flags) != Some((ScalarKind::Uint, 0)) {
                    return Err(unsupported(
                        args[0].pos,
                        "ray flags other than 0 in HitObject::MakeMiss (SPV_NV_shader_invocation_reorder has none)",
                    ));
                }
                let miss = self.expr_as(&args[1], &Ty::ScalarKind(ScalarKind::Uint))?;
                let ray = self.ray_parts(&args[2])?;
                self.inst(
                    Op::HitObjectRecordMissNV,
                    None,
                    vec![
                        Operand::IdRef(dst),
                        Operand::IdRef(miss.id),
                        Operand::IdRef(ray[0]),
                        Operand::IdRef(ray[1]),
                        Operand::IdRef(ray[2]),
                        Operand::IdRef(ray[3]),
                    ],
                )?;
            }
            "HitObject::TraceRay" => {
                self.arity(name, args, 8, e.pos)?;
                self.stage_check(name, RG_CH_MISS, e.pos)?;
                let accel = self.expr(&args[0])?;
                if accel.ty != Ty::Accel {
                    return Err(Error::new(
                        args[0].pos,
                        "the first argument must be a RaytracingAccelerationStructure",
                    ));
                }
                let at = self.ty_id(&Ty::Accel)?;
                let mut ids = Vec::new();
                for a in &args[1..6] {
                    ids.push(self.expr_as(a, &Ty::ScalarKind(ScalarKind::Uint))?.id);
                }
                let ray = self.ray_parts(&args[6])?;
                let (var, p, t) = self.payload_in(&args[7])?;
                let a = self.b.load(at, None, accel.id, None, [])?;
                self.line(e.pos);
                let mut ops = vec![Operand::IdRef(dst), Operand::IdRef(a)];
                ops.extend(ids.iter().map(|i| Operand::IdRef(*i)));
                ops.extend(ray.iter().map(|i| Operand::IdRef(*i)));
                ops.push(Operand::IdRef(var));
                self.inst(Op::HitObjectTraceRayNV, None, ops)?;
                self.payload_out(var, &p, t, args[7].pos)?;
            }
            _ => {
                return Err(unsupported(
                    e.pos,
                    "copying a HitObject; make it with HitObject::TraceRay, MakeMiss or MakeNop",
                ))
            }
        }
        Ok(())
    }

    /// A `RayDesc` as (origin, tmin, direction, tmax).
    fn ray_parts(&mut self, e: &'a Expr) -> Result<[Id; 4]> {
        let ray = self.expr_as(e, &Ty::Struct(RAY_DESC))?;
        let mut parts = [0; 4];
        let tys = [
            Ty::Vec(ScalarKind::Float, 3),
            Ty::ScalarKind(ScalarKind::Float),
            Ty::Vec(ScalarKind::Float, 3),
            Ty::ScalarKind(ScalarKind::Float),
        ];
        for (i, t) in tys.iter().enumerate() {
            let tid = self.ty_id(t)?;
            parts[i] = self.inst(
                Op::CompositeExtract,
                Some(tid),
                vec![Operand::IdRef(ray.id), Operand::LiteralBit32(i as u32)],
            )?;
        }
        Ok(parts)
    }

    /// Copies a payload argument into its `RayPayloadKHR` variable.
    fn payload_in(&mut self, e: &'a Expr) -> Result<(Id, Place, Ty)> {
        let p = self.place(e)?;
        let t = p.ty().clone();
        if !matches!(t, Ty::Struct(_)) {
            return Err(Error::new(e.pos, "the ray payload must be a struct"));
        }
        let var = self.rt_var_named(StorageClass::RayPayloadKHR, &t, Some(e))?;
        let v = self.read(&p)?;
        self.b.store(var, v.id, None, [])?;
        Ok((var, p, t))
    }

    /// Copies the payload variable back to the argument.
    fn payload_out(&mut self, var: Id, p: &Place, t: Ty, pos: Pos) -> Result<()> {
        let tid = self.ty_id(&t)?;
        let back = self.b.load(tid, None, var, None, [])?;
        self.write(p, Val { id: back, ty: t }, pos)
    }

    /// The variable holding a hit object argument.
    fn hit_object_ptr(&mut self, e: &'a Expr) -> Result<Id> {
        match self.place(e)? {
            Place::Ptr {
                ptr,
                ty: Ty::HitObject,
                ..
            } => Ok(ptr),
            _ => Err(Error::new(e.pos, "expected a HitObject variable")),
        }
    }

    /// `HitObject::Invoke(h, payload)`, `MaybeReorderThread(...)`; `None` for other names.
    pub(super) fn ser_call(
        &mut self,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Option<Val>>> {
        match name {
            "HitObject::Invoke" => {
                self.ser_caps();
                self.arity(name, args, 2, pos)?;
                self.stage_check(name, RG_CH_MISS, pos)?;
                let h = self.hit_object_ptr(&args[0])?;
                let (var, p, t) = self.payload_in(&args[1])?;
                self.inst(
                    Op::HitObjectExecuteShaderNV,
                    None,
                    vec![Operand::IdRef(h), Operand::IdRef(var)],
                )?;
                self.payload_out(var, &p, t, args[1].pos)?;
                Ok(Some(None))
            }
            "MaybeReorderThread" => {
                self.ser_caps();
                self.stage_check(name, &[Stage::RayGeneration], pos)?;
                let u = Ty::ScalarKind(ScalarKind::Uint);
                match args.len() {
                    1 | 3 => {
                        let h = self.hit_object_ptr(&args[0])?;
                        let mut ops = vec![Operand::IdRef(h)];
                        for a in &args[1..] {
                            ops.push(Operand::IdRef(self.expr_as(a, &u)?.id));
                        }
                        self.inst(Op::ReorderThreadWithHitObjectNV, None, ops)?;
                    }
                    2 => {
                        let hint = self.expr_as(&args[0], &u)?;
                        let bits = self.expr_as(&args[1], &u)?;
                        self.inst(
                            Op::ReorderThreadWithHintNV,
                            None,
                            vec![Operand::IdRef(hint.id), Operand::IdRef(bits.id)],
                        )?;
                    }
                    n => {
                        return Err(Error::new(
                            pos,
                            format!("`MaybeReorderThread` takes 1, 2 or 3 arguments, {n} given"),
                        ))
                    }
                }
                Ok(Some(None))
            }
            "HitObject::TraceRay" | "HitObject::MakeMiss" | "HitObject::MakeNop" => {
                Err(unsupported(
                    pos,
                    format!("`{name}` other than as a HitObject variable's initializer or assigned value"),
                ))
            }
            _ => Ok(None),
        }
    }

    /// Methods of a hit object variable.
    pub(super) fn hit_object_method(
        &mut self,
        h: Id,
        name: &str,
        args: &'a [Expr],
        pos: Pos,
    ) -> Result<Option<Val>> {
        self.ser_caps();
        let f = Ty::ScalarKind(ScalarKind::Float);
        let f3 = Ty::Vec(ScalarKind::Float, 3);
        let u = Ty::ScalarKind(ScalarKind::Uint);
        let b = Ty::ScalarKind(ScalarKind::Bool);
        let (op, ty) = match name {
            "IsMiss" => (Op::HitObjectIsMissNV, b),
            "IsHit" => (Op::HitObjectIsHitNV, b),
            "IsNop" => (Op::HitObjectIsEmptyNV, b),
            "GetRayTMin" => (Op::HitObjectGetRayTMinNV, f),
            "GetRayTCurrent" => (Op::HitObjectGetRayTMaxNV, f),
            "GetWorldRayOrigin" => (Op::HitObjectGetWorldRayOriginNV, f3),
            "GetWorldRayDirection" => (Op::HitObjectGetWorldRayDirectionNV, f3),
            "GetObjectRayOrigin" => (Op::HitObjectGetObjectRayOriginNV, f3),
            "GetObjectRayDirection" => (Op::HitObjectGetObjectRayDirectionNV, f3),
            "GetInstanceIndex" => (Op::HitObjectGetInstanceIdNV, u),
            "GetInstanceID" => (Op::HitObjectGetInstanceCustomIndexNV, u),
            "GetGeometryIndex" => (Op::HitObjectGetGeometryIndexNV, u),
            "GetPrimitiveIndex" => (Op::HitObjectGetPrimitiveIndexNV, u),
            "GetHitKind" => (Op::HitObjectGetHitKindNV, u),
            "GetShaderTableIndex" => (Op::HitObjectGetShaderBindingTableRecordIndexNV, u),
            "GetObjectToWorld3x4" | "GetObjectToWorld4x3" => (
                Op::HitObjectGetObjectToWorldNV,
                Ty::Mat(ScalarKind::Float, 4, 3),
            ),
            "GetWorldToObject3x4" | "GetWorldToObject4x3" => (
                Op::HitObjectGetWorldToObjectNV,
                Ty::Mat(ScalarKind::Float, 4, 3),
            ),
            _ => {
                return Err(
                    unsupported(pos, format!("HitObject method `{name}`")).len(name.len() as u32)
                )
            }
        };
        self.arity(name, args, 0, pos)?;
        let tid = self.ty_id(&ty)?;
        let id = self.inst(op, Some(tid), vec![Operand::IdRef(h)])?;
        if name.ends_with("3x4") {
            let t = Ty::Mat(ScalarKind::Float, 3, 4);
            let tt = self.ty_id(&t)?;
            let id = self.op(Op::Transpose, tt, &[id])?;
            return Ok(Some(Val { id, ty: t }));
        }
        Ok(Some(Val { id, ty }))
    }
}
