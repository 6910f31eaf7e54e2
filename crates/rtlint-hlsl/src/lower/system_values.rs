//! The system-value table: one row per HLSL ray-tracing system value (name,
//! SPIR-V built-in, type, allowed stages), as DXC maps them. `call` looks a
//! name up once here; adding a system value is one row.

use super::*;

/// One system-value function (`DispatchRaysIndex()`, `RayTCurrent()`, ...).
pub(super) struct SystemValue {
    pub(super) name: &'static str,
    pub(super) builtin: BuiltIn,
    /// The built-in variable's type.
    pub(super) ty: Ty,
    pub(super) stages: &'static [Stage],
    /// The `3x4` forms return the transpose of the `float4x3` built-in.
    pub(super) transpose: bool,
}

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
const U: Ty = Ty::ScalarKind(ScalarKind::Uint);
const U3: Ty = Ty::Vec(ScalarKind::Uint, 3);
const F: Ty = Ty::ScalarKind(ScalarKind::Float);
const F3: Ty = Ty::Vec(ScalarKind::Float, 3);
// SPIR-V holds the transforms as 4 columns of float3, which is HLSL's float4x3.
const F4X3: Ty = Ty::Mat(ScalarKind::Float, 4, 3);

const fn sv(name: &'static str, builtin: BuiltIn, ty: Ty, stages: &'static [Stage]) -> SystemValue {
    SystemValue {
        name,
        builtin,
        ty,
        stages,
        transpose: false,
    }
}

const fn transposed(name: &'static str, builtin: BuiltIn) -> SystemValue {
    SystemValue {
        name,
        builtin,
        ty: F4X3,
        stages: HIT,
        transpose: true,
    }
}

pub(super) const SYSTEM_VALUES: &[SystemValue] = &[
    sv("DispatchRaysIndex", BuiltIn::LaunchIdKHR, U3, ALL),
    sv("DispatchRaysDimensions", BuiltIn::LaunchSizeKHR, U3, ALL),
    sv("WorldRayOrigin", BuiltIn::WorldRayOriginKHR, F3, RAY),
    sv("WorldRayDirection", BuiltIn::WorldRayDirectionKHR, F3, RAY),
    sv("ObjectRayOrigin", BuiltIn::ObjectRayOriginKHR, F3, HIT),
    sv(
        "ObjectRayDirection",
        BuiltIn::ObjectRayDirectionKHR,
        F3,
        HIT,
    ),
    sv("RayTMin", BuiltIn::RayTminKHR, F, RAY),
    sv("RayTCurrent", BuiltIn::RayTmaxKHR, F, RAY),
    sv("RayFlags", BuiltIn::IncomingRayFlagsKHR, U, RAY),
    sv("InstanceIndex", BuiltIn::InstanceId, U, HIT),
    sv("InstanceID", BuiltIn::InstanceCustomIndexKHR, U, HIT),
    sv("GeometryIndex", BuiltIn::RayGeometryIndexKHR, U, HIT),
    sv("PrimitiveIndex", BuiltIn::PrimitiveId, U, HIT),
    sv("HitKind", BuiltIn::HitKindKHR, U, &[ClosestHit, AnyHit]),
    sv("ObjectToWorld4x3", BuiltIn::ObjectToWorldKHR, F4X3, HIT),
    transposed("ObjectToWorld3x4", BuiltIn::ObjectToWorldKHR),
    transposed("ObjectToWorld", BuiltIn::ObjectToWorldKHR),
    sv("WorldToObject4x3", BuiltIn::WorldToObjectKHR, F4X3, HIT),
    transposed("WorldToObject3x4", BuiltIn::WorldToObjectKHR),
    transposed("WorldToObject", BuiltIn::WorldToObjectKHR),
];

/// A built-in variable of the module: which built-in, in which storage
/// class, whether it holds integers, and where the source declared it
/// (`vk::ext_builtin_*`; `None` when a system value or intrinsic reads it).
pub(super) struct BuiltinVar {
    pub(super) builtin: BuiltIn,
    pub(super) class: StorageClass,
    pub(super) integer: bool,
    pub(super) declared: Option<Pos>,
}

/// Built-ins whose value can change when a ray-tracing invocation is
/// resumed on another subgroup or SM after a trace or call: Vulkan wants
/// them `Volatile` in ray-generation, intersection, any-hit, closest-hit,
/// miss and callable shaders (SPIRV-Tools' spread-volatile-semantics pass
/// applies the same list).
const RESCHEDULED: &[BuiltIn] = &[
    BuiltIn::SubgroupSize,
    BuiltIn::SubgroupLocalInvocationId,
    BuiltIn::SubgroupEqMask,
    BuiltIn::SubgroupGeMask,
    BuiltIn::SubgroupGtMask,
    BuiltIn::SubgroupLeMask,
    BuiltIn::SubgroupLtMask,
    BuiltIn::SMIDNV,
    BuiltIn::WarpIDNV,
];

/// Whether a value of `t` is integer (or holds integers): a pixel-shader
/// input of it is not interpolated.
pub(super) fn integer_ty(t: &Ty) -> bool {
    use ScalarKind::*;
    match t {
        Ty::ScalarKind(s) | Ty::Vec(s, _) | Ty::Mat(s, ..) => {
            matches!(s, Int16 | Uint16 | Int | Uint | Int64 | Uint64)
        }
        Ty::Array(e, _) => integer_ty(e),
        _ => false,
    }
}

impl Lowerer<'_> {
    /// The decorations Vulkan asks of the built-in inputs an entry point of
    /// `stage` reads (`interface`): `Flat` on integer inputs of a pixel
    /// shader (VUID-StandaloneSpirv-Flat-04744), `Volatile` on
    /// `RESCHEDULED` ones in the ray-tracing stages. `done` holds what
    /// earlier entry points of the module already decorated.
    pub(super) fn decorate_builtin_inputs(
        &mut self,
        stage: Stage,
        interface: &BTreeSet<Id>,
        done: &mut HashSet<(Id, u32)>,
    ) {
        let mut vars: Vec<(Id, Decoration)> = Vec::new();
        for (&var, b) in &self.builtin_vars {
            if b.class != StorageClass::Input || !interface.contains(&var) {
                continue;
            }
            if stage == Stage::Fragment && b.integer {
                vars.push((var, Decoration::Flat));
            } else if stage.is_ray_tracing() && RESCHEDULED.contains(&b.builtin) {
                vars.push((var, Decoration::Volatile));
            }
        }
        vars.sort_by_key(|(v, d)| (*v, *d as u32));
        for (var, d) in vars {
            // `[[vk::ext_decorate]]` may have written it already: a second
            // one is invalid.
            let written = self.b.module_ref().annotations.iter().any(|i| {
                i.class.opcode == Op::Decorate
                    && i.operands.first() == Some(&Operand::IdRef(var))
                    && i.operands.get(1) == Some(&Operand::Decoration(d))
            });
            if done.insert((var, d as u32)) && !written {
                self.b.decorate(var, d, []);
            }
        }
    }
}

pub(super) fn system_value(name: &str) -> Option<&'static SystemValue> {
    SYSTEM_VALUES.iter().find(|s| s.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_system_value_has_one_row() {
        let mut seen = HashSet::new();
        for s in SYSTEM_VALUES {
            assert!(seen.insert(s.name), "`{}` has two rows", s.name);
            // A system value is not also an intrinsic: `call` would pick one.
            assert!(
                super::super::intrinsics::lookup(s.name).is_none(),
                "`{}` is also an intrinsic",
                s.name
            );
        }
    }

    #[test]
    fn system_values_follow_dxc() {
        let t = system_value("RayTCurrent").unwrap();
        assert_eq!(
            (t.builtin, &t.ty),
            (BuiltIn::RayTmaxKHR, &Ty::ScalarKind(ScalarKind::Float))
        );
        assert!(!t.stages.contains(&Stage::RayGeneration));
        assert_eq!(
            system_value("InstanceIndex").unwrap().builtin,
            BuiltIn::InstanceId
        );
        assert_eq!(
            system_value("InstanceID").unwrap().builtin,
            BuiltIn::InstanceCustomIndexKHR
        );
        let m = system_value("ObjectToWorld4x3").unwrap();
        assert_eq!(
            (&m.ty, m.transpose),
            (&Ty::Mat(ScalarKind::Float, 4, 3), false)
        );
        let m = system_value("WorldToObject3x4").unwrap();
        assert_eq!((m.builtin, m.transpose), (BuiltIn::WorldToObjectKHR, true));
        assert!(system_value("RayTMax").is_none());
    }
}
