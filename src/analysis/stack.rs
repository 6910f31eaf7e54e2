//! The stack-size calculator.
//!
//! Each shader gets two figures:
//! - the **driver-comparable** size, from the payloads alone, in the shape
//!   the NVIDIA driver reports (`vkGetRayTracingShaderGroupStackSizeKHR`):
//!   ray generation 0 B for payloads up to 128 B, closest-hit 32 B minimum
//!   growing with the payload it passes on in 32-B steps, miss, any-hit and
//!   intersection 0 B. Drivers do not count live state there.
//! - the **model** size: the driver-comparable part plus the live state that
//!   cannot be recomputed after a trace (max over sites) and function-local
//!   arrays, which a driver must keep in memory somewhere.
//!
//! From these the pipeline stack follows by the Vulkan and DXR default
//! formulas (declared and required depth) and by the exact call-chain
//! maximum the Vulkan spec recommends setting explicitly. The assumptions
//! are in `docs/stack.md`.

use super::callgraph::{Assumption, EdgeKind};
use super::liveness::{shared_live_bytes, LiveSite};
use super::recursion::{recursion_report, ChainStep, NoGuard, RecursionReport};
use crate::pipeline::Pipeline;
use crate::pipeline::Slot;
use crate::program::scalar::scalar_size;
use crate::program::{Program, SiteKind, Type};
use crate::shader::Stage;
use spirv::StorageClass;
use std::collections::BTreeMap;

/// The largest pipeline stack measured to run on an NVIDIA H200 (driver
/// 580.159.04): 14,702 bytes per thread ran and 14,746 lost the device, at
/// 64×64, 512×512 and 2048×2048 alike (calibration/device-run.sh bisect).
pub const NVIDIA_KNOWN_SAFE_STACK_BYTES: u64 = 14_702;

/// Where the bytes of one shader's model come from.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Breakdown {
    /// Non-rematerializable live state, max over the shader's sites.
    pub live_state: u64,
    /// All live state, rematerializable values included, max over sites.
    pub live_state_total: u64,
    /// Non-rematerializable live state at sites inside a loop (carried
    /// around it across the call), max over such sites.
    pub loop_live_state: u64,
    /// The largest payload the shader traces with.
    pub outgoing_payload: u64,
    pub incoming_payload: u64,
    pub hit_attributes: u64,
    /// The largest callable data the shader passes on.
    pub callable_data: u64,
    pub incoming_callable_data: u64,
    /// Function-local arrays (kept in memory, not registers).
    pub local_arrays: u64,
    /// State kept across a call as a block of memory, max over sites:
    /// function-local arrays and structs in `live_state`, and the callable
    /// data of another call still needed after this one.
    pub live_blocks: u64,
    /// Trace and callable sites the entry point reaches.
    pub call_sites: u64,
    /// Bytes of outgoing ray payloads (globals) still needed after a later
    /// call, max over sites.
    pub outlived_payloads: u64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct ShaderStack {
    pub entry: String,
    pub stage: Stage,
    pub file: String,
    /// `raygen 0`, `miss 1`, `hit group 2`, `callable 0`.
    pub group: String,
    /// The full model: driver-comparable part + live state + local arrays.
    pub model_bytes: u64,
    /// The payload-driven part a driver reports.
    pub driver_model_bytes: u64,
    /// What the driver reported, when queried (`rtlint stack --driver`).
    pub driver_bytes: Option<u64>,
    pub breakdown: Breakdown,
}

/// The per-stage maxima the default formulas take.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct StageMax {
    pub raygen: u64,
    pub closest_hit: u64,
    pub miss: u64,
    pub intersection: u64,
    pub any_hit: u64,
    pub callable: u64,
}

/// The pipeline stack figures from one set of per-shader sizes.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Formulas {
    pub stage_max: StageMax,
    /// Vulkan default with the declared depth (what the driver uses).
    pub vulkan_default: Option<u64>,
    pub vulkan_default_required: Option<u64>,
    pub dxr_default: Option<u64>,
    pub dxr_default_required: Option<u64>,
    /// Max over all call chains of the sum of the shaders on the chain.
    pub exact_call_chain: Option<u64>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct StackReport {
    pub pipeline: Option<String>,
    pub required_depth: Option<u32>,
    pub declared_depth: Option<u32>,
    pub device_max_depth: u32,
    /// The chain that needs the required depth (nodes index `shaders`).
    #[serde(skip)]
    pub depth_chain: Vec<ChainStep>,
    pub shaders: Vec<ShaderStack>,
    pub vulkan_default: Option<u64>,
    pub vulkan_default_required: Option<u64>,
    pub dxr_default: Option<u64>,
    pub dxr_default_required: Option<u64>,
    pub exact_call_chain: Option<u64>,
    /// What to pass to `vkCmdSetRayTracingPipelineStackSizeKHR` /
    /// `SetPipelineStackSize`.
    pub recommended: Option<u64>,
    /// When no bound on the recursion is known at compile time: the depth
    /// the recommendation assumes (the declared depth, else the device's
    /// limit). The recommendation then holds only while the recursion stays
    /// within it.
    pub assumed_depth: Option<u32>,
    /// Full-model formulas (live state and arrays included).
    pub model: Formulas,
    /// The same formulas over the driver-comparable sizes.
    pub driver_comparable: Formulas,
    /// The same formulas over the driver's own numbers, when queried.
    pub driver: Option<Formulas>,
    /// What the model had to assume; reports put them in words.
    #[serde(skip)]
    pub assumptions: Vec<Assumption>,
}

/// Vulkan's default: `RG + min(1, D) × max(CH, MS, IS + AH) + max(0, D − 1)
/// × max(CH, MS) + 2 × CS`.
pub fn vulkan_default(m: &StageMax, depth: u32) -> u64 {
    let d = u64::from(depth);
    m.raygen
        + d.min(1) * m.closest_hit.max(m.miss).max(m.intersection + m.any_hit)
        + d.saturating_sub(1) * m.closest_hit.max(m.miss)
        + 2 * m.callable
}

/// DXR's default (the same shape as Vulkan's; the D3D12 spec states it with
/// `RGSMax`, `CHSMax`, `MSMax`, `ISMax + AHSMax`, `CSMax`).
pub fn dxr_default(m: &StageMax, depth: u32) -> u64 {
    let d = u64::from(depth);
    m.raygen
        + m.closest_hit.max(m.miss).max(m.intersection + m.any_hit) * d.min(1)
        + m.closest_hit.max(m.miss) * d.saturating_sub(1)
        + 2 * m.callable
}

/// The stack to recommend from one set of formulas: the exact call chain
/// (else the default formula at the declared depth); with the recursion
/// unbounded at compile time, the default formula at the depth assumed,
/// never the declared-depth figure alone, which may be too small.
fn recommendation(f: &Formulas, assumed_depth: Option<u32>) -> Option<u64> {
    match assumed_depth {
        Some(d) => Some(vulkan_default(&f.stage_max, d)),
        None => f.exact_call_chain.or(f.vulkan_default),
    }
    .map(|v| align(v, 16))
}

fn align(v: u64, a: u64) -> u64 {
    v.div_ceil(a) * a
}

/// Payload bytes a driver keeps in registers; the rest of a larger payload
/// lives in the caller's stack frame.
const PAYLOAD_IN_REGISTERS: u64 = 128;

/// Bytes the driver adds to a frame holding part of a payload larger than
/// [`PAYLOAD_IN_REGISTERS`] (fitted: 8 or 16 fit equally well, 16 errs upwards).
const PAYLOAD_SPILL_EXTRA: u64 = 16;

/// Bytes for the few scalars a shader keeps across a call when the
/// compiler can fold the rest (a sum of values computed before the call).
const FOLDED_SCALARS: u64 = 8;

/// Bytes a miss shader that traces keeps beside its incoming payload even
/// with no live scalars (fitted: the driver reports `align(payload + 4, 32)`
/// for every such miss shader of the fitting seeds).
const MISS_KEPT: u64 = 4;

/// Live scalars above which a closest hit that calls twice keeps them all
/// and more: the driver spills them whole instead of folding (fitted).
const MANY_SCALARS: u64 = 16;

/// Bytes beyond its live scalars that such a closest hit keeps when both of
/// its calls are traces (a recursive ray and a shadow ray), or a trace and a
/// callable (fitted on the fitting seeds; the first held-out set had been
/// seen by then, so docs/stack.md judges this on the second one).
const TWO_TRACES_EXTRA: u64 = 32;
const TRACE_AND_CALL_EXTRA: u64 = 8;

/// The driver-comparable size of one shader: what the NVIDIA driver
/// (580.159.04 on Hopper) reports through
/// `vkGetRayTracingShaderGroupStackSizeKHR`. Fitted on the fitting seeds of
/// the random pipelines (calibration/random/, docs/stack.md) and judged on
/// the held-out seeds. The frame of a shader that calls (traces or executes
/// a callable) holds, rounded up to 32 bytes:
/// - the part of the outgoing payload beyond the first 128 bytes, plus 16;
/// - the incoming payload (callable data for a callable), up to 128 bytes,
///   which the shader must hand back after its calls;
/// - blocks live across a call: function-local arrays and structs, and
///   callable data of an earlier call still needed;
/// - scalars live across a call: in ray generation those a loop carries
///   across the trace, else none across a single call and at most 8 bytes
///   across several (the compiler folds the rest before the call; 8 too
///   when a payload outlives a later call); in a hit or miss shader 8
///   bytes across one call (4 in a miss shader with none), all of them
///   across several, and in a closest hit with more than 16 bytes of them
///   across several calls, 32 bytes more (8 when one call is a callable).
///
/// A shader that makes no call, and any-hit and intersection shaders,
/// report 0.
pub fn driver_model(stage: Stage, b: &Breakdown) -> u64 {
    let calls = b.call_sites > 0 || b.outgoing_payload > 0 || b.callable_data > 0;
    if !calls {
        return 0;
    }
    let incoming = match stage {
        Stage::ClosestHit | Stage::Miss => b.incoming_payload,
        Stage::Callable => b.incoming_callable_data,
        Stage::RayGeneration => 0,
        _ => return 0,
    }
    .min(PAYLOAD_IN_REGISTERS);
    let spilled_payload = if b.outgoing_payload > PAYLOAD_IN_REGISTERS {
        b.outgoing_payload - PAYLOAD_IN_REGISTERS + PAYLOAD_SPILL_EXTRA
    } else {
        0
    };
    let scalars = b.live_state.saturating_sub(b.live_blocks);
    let looped = b.loop_live_state.saturating_sub(b.live_blocks);
    let kept = match stage {
        Stage::RayGeneration if looped > 0 => looped,
        Stage::RayGeneration if b.call_sites > 1 => {
            let outlived = if b.outlived_payloads > 0 {
                FOLDED_SCALARS
            } else {
                0
            };
            scalars.min(FOLDED_SCALARS).max(outlived)
        }
        Stage::RayGeneration | Stage::Callable => 0,
        _ => {
            let folded = if scalars > 0 {
                FOLDED_SCALARS
            } else if stage == Stage::Miss {
                MISS_KEPT
            } else {
                0
            };
            if b.call_sites > 1 && stage == Stage::ClosestHit && scalars > MANY_SCALARS {
                scalars
                    + if b.callable_data == 0 {
                        TWO_TRACES_EXTRA
                    } else {
                        TRACE_AND_CALL_EXTRA
                    }
            } else if b.call_sites > 1 {
                folded.max(scalars)
            } else {
                folded
            }
        }
    };
    align(spilled_payload + incoming + b.live_blocks + kept, 32)
}

/// The full model of one shader: what a driver that keeps every live value
/// in its frame needs, never less than [`driver_model`]. A shader that
/// calls counts its spilled payload, its incoming payload and all its live
/// state (arrays and scalars, none folded, plus 8 bytes when there is any)
/// and a safety margin; one that does not counts its function-local arrays.
pub fn full_model(stage: Stage, b: &Breakdown) -> u64 {
    let driver = driver_model(stage, b);
    let calls = b.call_sites > 0 || b.outgoing_payload > 0 || b.callable_data > 0;
    if !calls || matches!(stage, Stage::AnyHit | Stage::Intersection) {
        return driver.max(b.local_arrays);
    }
    let incoming = match stage {
        Stage::ClosestHit | Stage::Miss => b.incoming_payload,
        Stage::Callable => b.incoming_callable_data,
        _ => 0,
    }
    .min(PAYLOAD_IN_REGISTERS);
    let spilled_payload = if b.outgoing_payload > PAYLOAD_IN_REGISTERS {
        b.outgoing_payload - PAYLOAD_IN_REGISTERS + PAYLOAD_SPILL_EXTRA
    } else {
        0
    };
    let scalars = if b.live_state > 0 { FOLDED_SCALARS } else { 0 };
    let everything = spilled_payload + incoming + b.live_state + scalars;
    // Margin, fitted on the fitting seeds so that no shader there needs
    // more than this: 32 bytes on every calling shader, and a ray
    // generation shader that makes several calls (or calls in a loop) with
    // a large payload its spilled payload twice more (such shaders
    // reported up to 2.3 times the model).
    let repeated = b.call_sites > 1 || b.loop_live_state > 0;
    let margin = SAFETY_MARGIN
        + if stage == Stage::RayGeneration && repeated {
            2 * spilled_payload
        } else {
            0
        };
    driver.max(align(everything, 32)) + margin
}

/// Bytes added to the full model of every shader that calls (see
/// [`full_model`]): the driver reported up to 32 bytes more than the model
/// on the fitting seeds.
const SAFETY_MARGIN: u64 = 32;

fn global_size(program: &Program, id: u32) -> u64 {
    program
        .globals
        .iter()
        .find(|g| g.id == id)
        .and_then(|g| scalar_size(program, g.ty))
        .unwrap_or(0)
}

/// Breakdown of one entry point of a program.
pub fn breakdown(program: &Program, entry: &str) -> Breakdown {
    breakdown_with(program, entry, &shared_live_bytes(program))
}

/// [`breakdown`] with the program's live sites already computed.
pub fn breakdown_with(program: &Program, entry: &str, sites: &[LiveSite]) -> Breakdown {
    breakdown_in(program, entry, sites, &Loops::of(program))
}

/// [`breakdown_with`] with the program's [`Loops`] at hand (the stack
/// report asks once per program, not once per shader).
fn breakdown_in(program: &Program, entry: &str, sites: &[LiveSite], loops: &Loops) -> Breakdown {
    let mut b = Breakdown::default();
    let Some(e) = program.entry_points.iter().find(|e| e.name == entry) else {
        return b;
    };
    let reach = program.reached_functions(e.function);
    for site in &program.sites {
        if !reach.get(site.function).copied().unwrap_or(false) {
            continue;
        }
        let size = site.payload.map_or(0, |p| global_size(program, p));
        if matches!(site.kind, SiteKind::TraceRay | SiteKind::ExecuteCallable) {
            b.call_sites += 1;
        }
        match site.kind {
            SiteKind::TraceRay => b.outgoing_payload = b.outgoing_payload.max(size),
            SiteKind::ExecuteCallable => b.callable_data = b.callable_data.max(size),
            _ => {}
        }
    }
    // The stage's own inputs: the interface lists them from SPIR-V 1.4 on;
    // older modules get every global of the class.
    let in_interface = |id: u32| e.interface.is_empty() || e.interface.contains(&id);
    for g in &program.globals {
        // Only the classes counted here are looked up in the interface and
        // sized.
        if !matches!(
            g.storage,
            StorageClass::IncomingRayPayloadKHR
                | StorageClass::HitAttributeKHR
                | StorageClass::IncomingCallableDataKHR
        ) || (!in_interface(g.id) && program.version >= (1, 4))
        {
            continue;
        }
        let size = || scalar_size(program, g.ty).unwrap_or(0);
        match g.storage {
            StorageClass::IncomingRayPayloadKHR => {
                b.incoming_payload = b.incoming_payload.max(size())
            }
            StorageClass::HitAttributeKHR => b.hit_attributes = b.hit_attributes.max(size()),
            StorageClass::IncomingCallableDataKHR => {
                b.incoming_callable_data = b.incoming_callable_data.max(size())
            }
            _ => {}
        }
    }
    // Only the stages that receive them.
    if !matches!(
        e.stage,
        Stage::ClosestHit | Stage::Miss | Stage::AnyHit | Stage::Intersection
    ) {
        b.incoming_payload = 0;
    }
    if !matches!(
        e.stage,
        Stage::ClosestHit | Stage::AnyHit | Stage::Intersection
    ) {
        b.hit_attributes = 0;
    }
    // Once per function id, as the reached ids list them.
    for (fi, f) in program.functions.iter().enumerate() {
        if reach[fi] && program.function_index(f.id) == Some(fi) {
            b.local_arrays += loops.local_arrays(program, fi);
        }
    }
    // Shader calls only: an inline ray query keeps its state in registers.
    for site in sites
        .iter()
        .filter(|s| s.entry == entry && s.kind != crate::analysis::liveness::LiveSiteKind::RayQuery)
    {
        let (call_data, payload) = other_call_data_live(program, site.inst, loops);
        b.outlived_payloads = b.outlived_payloads.max(payload);
        let kept = site.live_bytes - site.rematerializable_bytes + call_data;
        let aggregates: u64 = site
            .values
            .iter()
            .filter(|v| !v.rematerializable && is_aggregate_variable(program, v.id))
            .map(|v| v.size)
            .sum();
        b.live_blocks = b.live_blocks.max(aggregates + call_data);
        b.live_state_total = b.live_state_total.max(site.live_bytes + call_data);
        b.live_state = b.live_state.max(kept);
        // Asked only when it could raise the maximum.
        if kept > b.loop_live_state
            && loops.contain(program, site.chain.first().copied().unwrap_or(site.inst))
        {
            b.loop_live_state = kept;
        }
    }
    b
}

/// Whether `id` is a function-local variable of array or struct type.
fn is_aggregate_variable(program: &Program, id: u32) -> bool {
    let Some(def) = program.def(id) else {
        return false;
    };
    if def.class.opcode != spirv::Op::Variable {
        return false;
    }
    matches!(
        def.result_type.and_then(|t| program.ty(t)),
        Some(Type::Pointer { pointee, .. })
            if matches!(program.ty(*pointee), Some(Type::Array { .. } | Type::Struct { .. }))
    )
}

/// Bytes of callable data and of ray payloads, other than what the call at
/// `inst` passes, written before the call (anywhere in a loop around it)
/// and read after it. The NVIDIA driver keeps such callable data in the
/// caller's frame; such a payload cost a few bytes whatever its size.
/// (GLSL declares both as globals, which live-state analysis does not
/// count; HLSL's locals are counted there.)
fn other_call_data_live(program: &Program, inst: usize, loops: &Loops) -> (u64, u64) {
    let Some(site) = program.sites.iter().find(|s| s.inst == inst) else {
        return (0, 0);
    };
    if !matches!(site.kind, SiteKind::TraceRay | SiteKind::ExecuteCallable) {
        return (0, 0);
    }
    // Only other blocks count: a shader with one payload has none to scan.
    let others = program.globals.iter().any(|g| {
        matches!(
            g.storage,
            StorageClass::CallableDataKHR | StorageClass::RayPayloadKHR
        ) && Some(g.id) != site.payload
    });
    if !others {
        return (0, 0);
    }
    let mut looped = None;
    let (mut callable, mut payload) = (0, 0);
    for u in loops.call_data(program, site.function) {
        if Some(u.global) == site.payload {
            continue;
        }
        let stored = u.first_store.is_some_and(|k| {
            k < inst || *looped.get_or_insert_with(|| loops.contain(program, inst))
        });
        let read = u.last_load.is_some_and(|k| k > inst);
        if stored && read {
            let size = scalar_size(program, u.ty).unwrap_or(0);
            if u.storage == StorageClass::CallableDataKHR {
                callable += size;
            } else {
                payload += size;
            }
        }
    }
    (callable, payload)
}

/// Where one function writes and reads a ray payload or callable data
/// global (through access chains into it): the first store and the last
/// load, by instruction index.
struct CallDataUse {
    global: u32,
    ty: u32,
    storage: StorageClass,
    first_store: Option<usize>,
    last_load: Option<usize>,
}

fn call_data_uses(program: &Program, f: &crate::program::Function) -> Vec<CallDataUse> {
    use spirv::Op;
    let mut out: Vec<CallDataUse> = program
        .globals
        .iter()
        .filter(|g| {
            matches!(
                g.storage,
                StorageClass::CallableDataKHR | StorageClass::RayPayloadKHR
            )
        })
        .map(|g| CallDataUse {
            global: g.id,
            ty: g.ty,
            storage: g.storage,
            first_store: None,
            last_load: None,
        })
        .collect();
    if out.is_empty() {
        return out;
    }
    // Each pointer into one of these globals within this function, with the
    // global's place in `out`, found in one pass for all of them: ids are
    // defined once, so a pointer leads back to one global.
    let mut into: rustc_hash::FxHashMap<u32, usize> =
        out.iter().enumerate().map(|(n, u)| (u.global, n)).collect();
    for (k, i) in (f.start..).zip(&program.insts[f.start..=f.end]) {
        if !matches!(
            i.class.opcode,
            Op::AccessChain | Op::InBoundsAccessChain | Op::Store | Op::Load
        ) {
            continue;
        }
        let Some(first) = i.operands.iter().find_map(|o| match o {
            rspirv::dr::Operand::IdRef(id) => Some(*id),
            _ => None,
        }) else {
            continue;
        };
        let Some(&n) = into.get(&first) else {
            continue;
        };
        match i.class.opcode {
            Op::AccessChain | Op::InBoundsAccessChain => {
                if let Some(r) = i.result_id {
                    into.insert(r, n);
                }
            }
            Op::Store => {
                out[n].first_store.get_or_insert(k);
            }
            _ => out[n].last_load = Some(k),
        }
    }
    out
}

/// Per function of a program, worked out once and asked per site and per
/// entry point: which blocks lie in a loop (natural loops need the
/// dominator tree: the Program's memo, which the depth guards share), the
/// bytes of its function-local arrays, and where it uses payload and
/// callable-data globals (kept for one report: a memo of them cost more
/// than it saved).
struct Loops {
    cfgs: std::sync::Arc<crate::program::cfg::FunctionCfgs>,
    facts: Vec<FunctionFacts>,
}

#[derive(Default)]
struct FunctionFacts {
    local_arrays: std::cell::OnceCell<u64>,
    call_data: std::cell::OnceCell<Vec<CallDataUse>>,
}

impl Loops {
    fn of(program: &Program) -> Self {
        Loops {
            cfgs: crate::program::cfg::function_cfgs(program),
            facts: program
                .functions
                .iter()
                .map(|_| FunctionFacts::default())
                .collect(),
        }
    }

    /// Whether instruction `inst` lies in a loop of its function.
    fn contain(&self, program: &Program, inst: usize) -> bool {
        let Some(fi) = program.function_of(inst) else {
            return false;
        };
        let Some(f) = program.functions.get(fi) else {
            return false;
        };
        let Some(block) = f.block_of(inst) else {
            return false;
        };
        self.cfgs
            .looped(program, fi)
            .get(block)
            .copied()
            .unwrap_or(false)
    }

    /// Bytes of the function-local arrays function `fi` declares.
    fn local_arrays(&self, program: &Program, fi: usize) -> u64 {
        let (Some(facts), Some(f)) = (self.facts.get(fi), program.functions.get(fi)) else {
            return 0;
        };
        *facts.local_arrays.get_or_init(|| {
            let mut bytes = 0;
            for inst in &program.insts[f.start..=f.end] {
                if inst.class.opcode != spirv::Op::Variable {
                    continue;
                }
                let Some(Type::Pointer {
                    storage: StorageClass::Function,
                    pointee,
                }) = inst.result_type.and_then(|t| program.ty(t))
                else {
                    continue;
                };
                if matches!(program.ty(*pointee), Some(Type::Array { .. })) {
                    bytes += scalar_size(program, *pointee).unwrap_or(0);
                }
            }
            bytes
        })
    }

    /// [`call_data_uses`] of function `fi`.
    fn call_data(&self, program: &Program, fi: usize) -> &[CallDataUse] {
        match (self.facts.get(fi), program.functions.get(fi)) {
            (Some(facts), Some(f)) => facts.call_data.get_or_init(|| call_data_uses(program, f)),
            _ => &[],
        }
    }
}

fn stage_max_of(shaders: impl Iterator<Item = (Stage, u64)>) -> StageMax {
    let mut m = StageMax::default();
    for (stage, v) in shaders {
        let slot = match stage {
            Stage::RayGeneration => &mut m.raygen,
            Stage::ClosestHit => &mut m.closest_hit,
            Stage::Miss => &mut m.miss,
            Stage::Intersection => &mut m.intersection,
            Stage::AnyHit => &mut m.any_hit,
            Stage::Callable => &mut m.callable,
            _ => continue,
        };
        *slot = (*slot).max(v);
    }
    m
}

/// The formulas over per-node sizes (indexed like the trace graph's nodes).
pub fn formulas(pipeline: &Pipeline, rec: &RecursionReport, sizes: &[u64]) -> Formulas {
    formulas_with(pipeline, rec, &ChainShape::of(rec), sizes)
}

/// [`formulas`] with the graph's shape worked out once for several sets of
/// sizes (the model's and the driver-comparable ones).
fn formulas_with(
    pipeline: &Pipeline,
    rec: &RecursionReport,
    shape: &ChainShape,
    sizes: &[u64],
) -> Formulas {
    let m = stage_max_of(
        rec.graph
            .nodes
            .iter()
            .zip(sizes)
            .map(|(n, &s)| (n.shader.stage, s)),
    );
    Formulas {
        stage_max: m,
        vulkan_default: pipeline.max_recursion_depth.map(|d| vulkan_default(&m, d)),
        vulkan_default_required: rec.required_depth.map(|d| vulkan_default(&m, d)),
        dxr_default: pipeline.max_recursion_depth.map(|d| dxr_default(&m, d)),
        dxr_default_required: rec.required_depth.map(|d| dxr_default(&m, d)),
        exact_call_chain: shape.exact_call_chain(rec, sizes),
    }
}

/// The maximum over call chains of the sum of the shaders on the chain.
/// Any-hit and intersection shaders of one group run together on top of
/// the tracing shader; callables stack on their caller; a bounded cycle
/// repeats its largest shader once per level it adds.
pub fn exact_call_chain(rec: &RecursionReport, sizes: &[u64]) -> Option<u64> {
    ChainShape::of(rec).exact_call_chain(rec, sizes)
}

/// The items of node `v` in `(node, item)` pairs sorted by node.
fn of_node(pairs: &[(usize, usize)], v: usize) -> &[(usize, usize)] {
    let from = pairs.partition_point(|&(u, _)| u < v);
    let to = from + pairs[from..].partition_point(|&(u, _)| u == v);
    &pairs[from..to]
}

/// What [`exact_call_chain`] needs of the trace graph, independent of the
/// sizes: worked out once per report, not once per set of sizes, and each
/// list gathered once (not a scan of every edge or cycle per node: a loose
/// pipeline has edges from every trace to every shader). Lists are
/// `(node, item)` pairs sorted by node, in edge order per node: most are
/// empty, so they cost no allocation.
struct ChainShape {
    /// `(caller, callable)` of each callable edge.
    callables: Vec<(usize, usize)>,
    /// `(any-hit, intersection)` nodes of one hit group.
    intersections: Vec<(usize, usize)>,
    /// Nodes by level: levels order the acyclic part.
    order: Vec<usize>,
    /// The first cycle through each node.
    cycle_of: Vec<Option<usize>>,
    /// `(target, source)` of each trace edge, but those within a cycle.
    into: Vec<(usize, usize)>,
    /// A node lies on a cycle with no bound.
    unbounded: bool,
}

impl ChainShape {
    fn of(rec: &RecursionReport) -> ChainShape {
        let g = &rec.graph;
        let n = g.nodes.len();
        let mut callables: Vec<(usize, usize)> = g
            .edges
            .iter()
            .filter(|e| e.kind == EdgeKind::Callable)
            .map(|e| (e.from, e.to))
            .collect();
        // Stable: each node's edges stay in edge order.
        callables.sort_by_key(|&(v, _)| v);
        let mut intersections = Vec::new();
        for v in 0..n {
            let (Stage::AnyHit, Slot::HitGroup(gi)) = (g.nodes[v].shader.stage, g.nodes[v].slot)
            else {
                continue;
            };
            for (u, node) in g.nodes.iter().enumerate() {
                if node.slot == Slot::HitGroup(gi) && node.shader.stage == Stage::Intersection {
                    intersections.push((v, u));
                }
            }
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&v| rec.node_level[v].unwrap_or(u32::MAX));
        let mut cycle_of: Vec<Option<usize>> = vec![None; n];
        for (k, c) in rec.cycles.iter().enumerate() {
            for &v in &c.nodes {
                if let Some(slot) = cycle_of.get_mut(v) {
                    slot.get_or_insert(k);
                }
            }
        }
        let mut into: Vec<(usize, usize)> = g
            .traces()
            .filter(|e| match (cycle_of[e.from], cycle_of[e.to]) {
                (Some(a), Some(b)) => a != b,
                _ => true,
            })
            .map(|e| (e.to, e.from))
            .collect();
        into.sort_by_key(|&(v, _)| v);
        let unbounded = cycle_of
            .iter()
            .flatten()
            .any(|&k| rec.cycles[k].extra_levels.is_none());
        ChainShape {
            callables,
            intersections,
            order,
            cycle_of,
            into,
            unbounded,
        }
    }

    fn exact_call_chain(&self, rec: &RecursionReport, sizes: &[u64]) -> Option<u64> {
        let g = &rec.graph;
        let n = g.nodes.len();
        if self.unbounded {
            return None;
        }
        // Callable chains on top of each node.
        fn with_callables(
            callables: &[(usize, usize)],
            n: usize,
            sizes: &[u64],
            v: usize,
            memo: &mut [Option<u64>],
            depth: usize,
        ) -> u64 {
            if let Some(x) = memo[v] {
                return x;
            }
            let own = sizes.get(v).copied().unwrap_or(0);
            if depth > n {
                return own;
            }
            let above = of_node(callables, v)
                .iter()
                .map(|&(_, to)| with_callables(callables, n, sizes, to, memo, depth + 1))
                .max()
                .unwrap_or(0);
            memo[v] = Some(own + above);
            own + above
        }
        let mut memo = vec![None; n];
        let mut w: Vec<u64> = (0..n)
            .map(|v| with_callables(&self.callables, n, sizes, v, &mut memo, 0))
            .collect();
        // Intersection and any-hit of a procedural group are active together
        // (intersection nodes are not any-hit nodes: their weights are final).
        for &(v, u) in &self.intersections {
            w[v] += w[u];
        }
        // Longest weighted path over trace edges, cycles by their bound (the
        // memo's vector reused).
        let best = &mut memo;
        best.fill(None);
        for _ in 0..2 {
            for &v in &self.order {
                let own = match self.cycle_of[v] {
                    Some(k) => {
                        let c = &rec.cycles[k];
                        let x = c.extra_levels?;
                        let max_w = c.nodes.iter().map(|&u| w[u]).max().unwrap_or(0);
                        (x + 1) * max_w
                    }
                    None => w[v],
                };
                let entered = if g.nodes[v].shader.stage == Stage::RayGeneration {
                    Some(0)
                } else {
                    of_node(&self.into, v)
                        .iter()
                        .filter_map(|&(_, from)| best[from])
                        .max()
                };
                if let Some(base) = entered {
                    best[v] = Some(best[v].unwrap_or(0).max(base + own));
                }
            }
        }
        Some(best.iter().flatten().copied().max().unwrap_or(0))
    }
}

/// `raygen 0`, `miss 1`, `hit group 2`, `callable 0`: [`Slot`]'s `Display`
/// without the formatter (a string per shader per report).
fn slot_name(slot: Slot) -> String {
    let (kind, mut i) = match slot {
        Slot::Raygen(i) => ("raygen ", i),
        Slot::Miss(i) => ("miss ", i),
        Slot::HitGroup(i) => ("hit group ", i),
        Slot::Callable(i) => ("callable ", i),
    };
    let mut digits = [0u8; 20];
    let mut k = digits.len();
    loop {
        k -= 1;
        digits[k] = b'0' + (i % 10) as u8;
        i /= 10;
        if i == 0 {
            break;
        }
    }
    let mut s = String::with_capacity(kind.len() + digits.len() - k);
    s.push_str(kind);
    s.extend(digits[k..].iter().map(|&d| d as char));
    s
}

/// `rtlint stack`: the stack figures of a described (or assumed) pipeline.
pub fn stack_report(pipeline: &Pipeline) -> StackReport {
    stack_report_with(pipeline, &recursion_report(pipeline))
}

/// [`stack_report`] over a recursion analysis the caller already has.
pub fn stack_report_with(pipeline: &Pipeline, rec: &RecursionReport) -> StackReport {
    let mut cache: rustc_hash::FxHashMap<(usize, &str), Breakdown> =
        rustc_hash::FxHashMap::with_capacity_and_hasher(rec.graph.nodes.len(), Default::default());
    let sites: Vec<_> = pipeline.programs.iter().map(shared_live_bytes).collect();
    let mut loops: Vec<Option<Loops>> = pipeline.programs.iter().map(|_| None).collect();
    let mut shaders = Vec::with_capacity(rec.graph.nodes.len());
    for node in &rec.graph.nodes {
        let s = &node.shader;
        let b = cache
            .entry((s.program, s.entry.as_str()))
            .or_insert_with(|| match (pipeline.program(s), sites.get(s.program)) {
                (Some(p), Some(sites)) => {
                    let loops = loops[s.program].get_or_insert_with(|| Loops::of(p));
                    breakdown_in(p, &s.entry, sites, loops)
                }
                _ => Breakdown::default(),
            })
            .clone();
        let driver_model_bytes = driver_model(s.stage, &b);
        let group = slot_name(node.slot);
        shaders.push(ShaderStack {
            entry: s.entry.clone(),
            stage: s.stage,
            // As `display()` writes it; a UTF-8 path without the formatter.
            file: match s.file.to_str() {
                Some(f) => f.to_owned(),
                None => s.file.display().to_string(),
            },
            group,
            model_bytes: full_model(s.stage, &b),
            driver_model_bytes,
            driver_bytes: None,
            breakdown: b,
        });
    }
    let model_sizes: Vec<u64> = shaders.iter().map(|s| s.model_bytes).collect();
    let driver_sizes: Vec<u64> = shaders.iter().map(|s| s.driver_model_bytes).collect();
    let shape = ChainShape::of(rec);
    let model = formulas_with(pipeline, rec, &shape, &model_sizes);
    let driver_comparable = formulas_with(pipeline, rec, &shape, &driver_sizes);
    let assumed_depth = match rec.required_depth {
        Some(_) => None,
        None => Some(
            pipeline
                .max_recursion_depth
                .unwrap_or(pipeline.device_max_recursion_depth),
        ),
    };
    let recommended = recommendation(&model, assumed_depth);
    let mut assumptions = rec.graph.assumptions.clone();
    if pipeline.max_recursion_depth.is_none() {
        assumptions.push(Assumption::NoDeclaredDepth);
    }
    if let Some(c) = rec.unbounded_cycle() {
        let site = c.sites.iter().find(|s| s.guard.is_err());
        let why = site
            .and_then(|s| s.guard.as_ref().err())
            .cloned()
            .unwrap_or(NoGuard::NoComparison { counter: None });
        assumptions.push(Assumption::UnboundedRecursion {
            why,
            at: site.and_then(|s| s.location.clone()),
        });
    }
    for c in &rec.cycles {
        for s in &c.sites {
            if let Ok(g) = &s.guard {
                if g.initial_assumed {
                    assumptions.push(Assumption::InitialValueAssumed {
                        counter: g.counter.clone(),
                    });
                }
            }
        }
    }
    StackReport {
        pipeline: pipeline
            .path
            .as_ref()
            // As `display()` writes it; a UTF-8 path without the formatter.
            .map(|p| match p.to_str() {
                Some(p) => p.to_owned(),
                None => p.display().to_string(),
            })
            .or_else(|| {
                let lib = pipeline.subobject_library.as_ref()?;
                Some(format!("{} (DXR subobjects)", lib.display()))
            }),
        required_depth: rec.required_depth,
        declared_depth: pipeline.max_recursion_depth,
        device_max_depth: pipeline.device_max_recursion_depth,
        depth_chain: rec.chain.clone(),
        shaders,
        vulkan_default: model.vulkan_default,
        vulkan_default_required: model.vulkan_default_required,
        dxr_default: model.dxr_default,
        dxr_default_required: model.dxr_default_required,
        exact_call_chain: model.exact_call_chain,
        recommended,
        assumed_depth,
        model,
        driver_comparable,
        driver: None,
        assumptions,
    }
}

/// Adds a driver's own per-shader sizes (`vkGetRayTracingShaderGroupStackSizeKHR`,
/// one per entry of `report.shaders`, in the same order) and the formulas
/// computed from them. Sizes beyond `report.shaders` are ignored; missing
/// ones leave the shader without a driver figure and count as 0.
/// Puts the driver's per-shader stack sizes (by pipeline slot and stage)
/// beside the model's, and applies the formulas to the driver's numbers.
pub fn attach_driver(
    report: &mut StackReport,
    pipeline: &Pipeline,
    driver: &BTreeMap<(Slot, Stage), u64>,
) {
    let rec = recursion_report(pipeline);
    for (s, n) in report.shaders.iter_mut().zip(&rec.graph.nodes) {
        s.driver_bytes = driver.get(&(n.slot, n.shader.stage)).copied();
    }
    let sizes: Vec<u64> = report
        .shaders
        .iter()
        .map(|s| s.driver_bytes.unwrap_or(0))
        .collect();
    if sizes.len() == rec.graph.nodes.len() {
        let f = formulas(pipeline, &rec, &sizes);
        // Never recommend less than the driver's own numbers require: an
        // explicit stack below the real call chain hangs the GPU.
        if let Some(needed) = recommendation(&f, report.assumed_depth) {
            if report.recommended.is_some_and(|r| r < needed) {
                report.assumptions.push(Assumption::RecommendationRaised {
                    from: report.recommended.unwrap_or(0),
                    to: needed,
                });
                report.recommended = Some(needed);
            }
        }
        report.driver = Some(f);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::load;
    use std::path::Path;

    fn report(rel: &str) -> StackReport {
        stack_report(&load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap())
    }

    #[test]
    fn slot_names_as_display_writes_them() {
        for i in [0, 1, 9, 10, 99, 100, 12_345, usize::MAX] {
            for slot in [
                Slot::Raygen(i),
                Slot::Miss(i),
                Slot::HitGroup(i),
                Slot::Callable(i),
            ] {
                assert_eq!(slot_name(slot), slot.to_string());
            }
        }
    }

    #[test]
    fn formulas_and_the_calibrated_driver_model() {
        // FIELD-NOTES' H100 figures for a 256-byte payload: raygen 160,
        // closest-hit 544; the formulas on them.
        let m = StageMax {
            raygen: 160,
            closest_hit: 544,
            ..Default::default()
        };
        assert_eq!(vulkan_default(&m, 29), 15_936);
        assert_eq!(vulkan_default(&m, 31), 17_024);
        assert_eq!(vulkan_default(&m, 8), 4_512);
        assert_eq!(dxr_default(&m, 31), 17_024);
        // A shader that traces once, passing `p` bytes on and (a closest
        // hit) receiving as many: calibration/p*.pass, p*.rgen.
        let b = |p, incoming| Breakdown {
            outgoing_payload: p,
            incoming_payload: incoming,
            call_sites: 1,
            ..Default::default()
        };
        // What an NVIDIA H200 (driver 580.159.04) reported for a closest-hit
        // passing each payload size on (calibration/, docs/stack.md).
        for (p, ch) in [
            (4, 32),
            (16, 32),
            (32, 32),
            (48, 64),
            (64, 64),
            (96, 96),
            (128, 128),
            (160, 192),
            (192, 224),
            (224, 256),
            (256, 288),
        ] {
            assert_eq!(driver_model(Stage::ClosestHit, &b(p, p)), ch, "payload {p}");
        }
        // Ray generation keeps what exceeds 128 bytes, plus 16.
        for (p, rg) in [
            (64, 0),
            (128, 0),
            (160, 64),
            (192, 96),
            (224, 128),
            (256, 160),
        ] {
            assert_eq!(
                driver_model(Stage::RayGeneration, &b(p, 0)),
                rg,
                "payload {p}"
            );
        }
        // Live state across calls in ray generation: folded away across a
        // single trace, 8 bytes across several, all of it (rounded up to
        // 32) when a loop carries it across the trace.
        let live = |sites, straight, looped| Breakdown {
            outgoing_payload: 16,
            call_sites: sites,
            live_state: straight,
            loop_live_state: looped,
            ..Default::default()
        };
        for (sites, straight, looped, rg) in [
            (1, 4, 0, 0),
            (1, 128, 0, 0),
            (2, 4, 0, 32),
            (2, 128, 0, 32),
            (1, 28, 28, 32),
            (1, 40, 40, 64),
            (1, 68, 68, 96),
            (1, 132, 132, 160),
        ] {
            assert_eq!(
                driver_model(Stage::RayGeneration, &live(sites, straight, looped)),
                rg
            );
        }
        // A closest hit holding a 24-float array across a shadow trace (the
        // issue's class): its 16-byte payload, the 96-byte array and a few
        // folded scalars, 128 as the driver reported; the array counted
        // once.
        let array = Breakdown {
            outgoing_payload: 4,
            incoming_payload: 16,
            call_sites: 1,
            live_state: 104,
            live_blocks: 96,
            local_arrays: 96,
            ..Default::default()
        };
        assert_eq!(driver_model(Stage::ClosestHit, &array), 128);
        assert_eq!(full_model(Stage::ClosestHit, &array), 128 + SAFETY_MARGIN);
        // Several calls in a closest hit: every scalar counts, and more than
        // 16 bytes of them cost 32 bytes more across two traces (8 across a
        // trace and a callable); a few stay as they are.
        let two = Breakdown {
            outgoing_payload: 16,
            incoming_payload: 16,
            call_sites: 2,
            live_state: 40,
            ..Default::default()
        };
        assert_eq!(driver_model(Stage::ClosestHit, &two), 96);
        let trace_and_call = Breakdown {
            callable_data: 16,
            ..two
        };
        assert_eq!(driver_model(Stage::ClosestHit, &trace_and_call), 64);
        let few = Breakdown {
            live_state: 12,
            ..two
        };
        assert_eq!(driver_model(Stage::ClosestHit, &few), 32);
        // A miss shader that traces keeps 4 bytes beside its payload: 92
        // bytes fit in 96, 96 need 128, as the driver reported.
        let miss = |p| Breakdown {
            outgoing_payload: 4,
            incoming_payload: p,
            call_sites: 1,
            ..Default::default()
        };
        assert_eq!(driver_model(Stage::Miss, &miss(92)), 96);
        assert_eq!(driver_model(Stage::Miss, &miss(96)), 128);
        assert_eq!(driver_model(Stage::Miss, &miss(240)), 160);
        // The full model is never below the driver-comparable one.
        for p in [4, 64, 128, 256, 512] {
            for st in [Stage::RayGeneration, Stage::ClosestHit, Stage::Miss] {
                let x = b(p, p);
                assert!(full_model(st, &x) >= driver_model(st, &x));
            }
        }
        // No call, no stack: a closest-hit or miss that does not trace.
        let none = Breakdown {
            incoming_payload: 64,
            ..Default::default()
        };
        assert_eq!(driver_model(Stage::Miss, &none), 0);
        assert_eq!(driver_model(Stage::ClosestHit, &none), 0);
    }

    #[test]
    fn recursive_pipeline() {
        let r = report("fixtures/pipelines/reflect_recursive.pipeline.toml");
        assert_eq!((r.required_depth, r.declared_depth), (Some(5), Some(5)));
        let ch = r
            .shaders
            .iter()
            .find(|s| s.stage == Stage::ClosestHit)
            .unwrap();
        // Payload {vec3, uint} = 16 B out, 16 B in; shadow payload 4 B.
        assert_eq!(ch.breakdown.outgoing_payload, 16);
        assert_eq!(ch.breakdown.incoming_payload, 16);
        assert_eq!(ch.driver_model_bytes, 32);
        // Across the shadow ray only recomputable values (hitPos from
        // builtins, constant vectors); across the reflection `color` (12 B).
        assert_eq!(
            (ch.breakdown.live_state, ch.breakdown.live_state_total),
            (12, 36)
        );
        // Full: 16 + 12 + 8 → 64, plus the margin.
        assert_eq!(ch.model_bytes, 64 + SAFETY_MARGIN);
        let rg = r
            .shaders
            .iter()
            .find(|s| s.stage == Stage::RayGeneration)
            .unwrap();
        assert_eq!(rg.driver_model_bytes, 0);
        // Driver-comparable: 0 + 1 × 32 + 4 × 32 = 160; exact chain: raygen
        // + 4 closest-hits + miss = 128.
        assert_eq!(r.driver_comparable.vulkan_default, Some(160));
        assert_eq!(r.driver_comparable.exact_call_chain, Some(128));
        assert_eq!(rg.model_bytes, SAFETY_MARGIN);
        assert_eq!(r.vulkan_default, Some(32 + 5 * 96));
        assert_eq!(r.exact_call_chain, Some(32 + 4 * 96));
        assert_eq!(r.recommended, r.exact_call_chain.map(|v| align(v, 16)));
        let json = serde_json::to_value(&r).unwrap();
        for k in [
            "required_depth",
            "declared_depth",
            "shaders",
            "vulkan_default",
            "dxr_default",
            "exact_call_chain",
            "recommended",
        ] {
            assert!(json.get(k).is_some(), "{k}");
        }
        assert_eq!(json["shaders"][0]["stage"], "ray_generation");
        assert!(json["shaders"][0]["driver_bytes"].is_null());
        let text = crate::report::stack::human(&r);
        assert!(text.contains("required 5, declared 5"), "{text}");
        assert!(
            text.contains(
                "0 + min(1, 5) × max(32, 0, 0 + 0) + max(0, 5 − 1) × max(32, 0) + 2 × 0 = 160"
            ),
            "{text}"
        );
    }

    #[test]
    fn iterative_pipeline_needs_less() {
        let r = report("fixtures/pipelines/reflect_iterative.pipeline.toml");
        assert_eq!(r.required_depth, Some(2));
        // As the driver reported: raygen 64 (a bounce loop carrying 52
        // bytes across the trace), closest-hit 32, misses 0.
        assert_eq!(r.driver_comparable.vulkan_default, Some(128));
        // raygen 64 + closest-hit 32 + shadow miss 0.
        assert_eq!(r.driver_comparable.exact_call_chain, Some(96));
        let rg = r
            .shaders
            .iter()
            .find(|s| s.stage == Stage::RayGeneration)
            .unwrap();
        // origin, dir, color, throughput (4 × 12) + bounce (4).
        assert_eq!(rg.breakdown.live_state, 52);
        assert_eq!(rg.breakdown.outgoing_payload, 32);
    }

    #[test]
    fn reference_wgsl_pipeline() {
        let r = report("shaders/reflect_iterative.pipeline.toml");
        assert_eq!(r.required_depth, Some(1));
        let rg = &r.shaders[0];
        assert_eq!(
            (rg.breakdown.live_state, rg.breakdown.live_state_total),
            (64, 84)
        );
        assert!(r.assumptions.is_empty(), "{:?}", r.assumptions);
    }

    #[test]
    fn big_payload_pipeline() {
        let r = report("fixtures/RT025/bad.pipeline.toml");
        assert_eq!(r.required_depth, Some(31));
        let sizes: Vec<(Stage, u64, u64)> = r
            .shaders
            .iter()
            .map(|s| (s.stage, s.driver_model_bytes, s.model_bytes))
            .collect();
        assert_eq!(
            sizes,
            [
                (Stage::RayGeneration, 416, 416 + SAFETY_MARGIN),
                (Stage::Miss, 0, 0),
                (Stage::ClosestHit, 544, 544 + SAFETY_MARGIN)
            ]
        );
        // A 512-byte payload, driver-comparable: 416 + 31 × 544 (NVIDIA
        // reported 512 for the closest hit, +6 %).
        assert_eq!(r.driver_comparable.exact_call_chain, Some(17_280));
        // Full model, with the margin on each shader: 448 + 31 × 576.
        assert_eq!(r.vulkan_default, Some(18_304));
        assert_eq!(r.exact_call_chain, Some(18_304));
        let good = report("fixtures/RT025/good.pipeline.toml");
        assert_eq!(good.driver_comparable.vulkan_default, Some(4_768));
    }

    #[test]
    fn no_description_and_no_panics() {
        // Every shader module in the repository, as one conservative pipeline
        // each, through every analysis.
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        let mut dirs = vec![root.join("fixtures"), root.join("shaders")];
        while let Some(d) = dirs.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    dirs.push(p);
                } else if matches!(p.extension().and_then(|x| x.to_str()), Some("spv" | "wgsl")) {
                    files.push(p);
                }
            }
        }
        assert!(files.len() >= 20, "{}", files.len());
        for f in &files {
            let lang = crate::shader::Language::from_path(f).unwrap();
            let program = crate::front::load(f, lang).unwrap();
            let p = Pipeline::from_programs(vec![program]);
            let r = stack_report(&p);
            assert!(crate::report::stack::human(&r).contains("no pipeline description"));
            let _ = super::super::liveness::live_report(&p.programs);
        }
    }

    #[test]
    fn callables_stack_on_their_caller() {
        let r = report("fixtures/pipelines/callable.pipeline.toml");
        let sizes: Vec<(&str, u64)> = r
            .shaders
            .iter()
            .map(|s| (s.group.as_str(), s.model_bytes))
            .collect();
        // raygen: `weight` (4 B) across the callable: 32 (what the driver
        // reported) plus the margin; flat.rcall: a local float[16] (64 B).
        assert_eq!(r.shaders[0].driver_model_bytes, 32);
        assert_eq!(
            sizes,
            [
                ("raygen 0", 32 + SAFETY_MARGIN),
                ("miss 0", 0),
                ("callable 0", 0),
                ("callable 1", 64)
            ]
        );
        // 64 + 1 × max(0, 0, 0) + 0 + 2 × 64.
        assert_eq!(r.vulkan_default, Some(192));
        // The raygen calls SBT index 1 only: 64 + 64.
        assert_eq!(r.exact_call_chain, Some(128));
        assert_eq!(r.recommended, Some(128));
    }

    #[test]
    fn procedural_group_attributes() {
        let r = report("fixtures/pipelines/procedural.pipeline.toml");
        let attrs: Vec<(Stage, u64)> = r
            .shaders
            .iter()
            .map(|s| (s.stage, s.breakdown.hit_attributes))
            .collect();
        assert_eq!(
            attrs,
            [
                (Stage::RayGeneration, 0),
                (Stage::Miss, 0),
                (Stage::ClosestHit, 8),
                (Stage::ClosestHit, 16),
                (Stage::AnyHit, 16),
                (Stage::Intersection, 16)
            ]
        );
        // No shader traces from a hit group, and the driver reported 0 for
        // each; the raygen keeps nothing across its trace: 0, and the
        // margin in the full model.
        assert_eq!(r.driver_comparable.exact_call_chain, Some(0));
        assert_eq!(r.exact_call_chain, Some(SAFETY_MARGIN));
    }

    #[test]
    fn driver_numbers_beside_the_model() {
        let p = load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("fixtures/pipelines/reflect_iterative.pipeline.toml"),
        )
        .unwrap();
        let mut r = stack_report(&p);
        // lavapipe answers 4 for every group and stage.
        let driver: BTreeMap<_, _> = recursion_report(&p)
            .graph
            .nodes
            .iter()
            .map(|n| ((n.slot, n.shader.stage), 4))
            .collect();
        attach_driver(&mut r, &p, &driver);
        let d = r.driver.as_ref().unwrap();
        assert_eq!(d.vulkan_default, Some(4 + 4 + 4));
        assert_eq!(d.exact_call_chain, Some(12));
        assert!(crate::report::stack::human(&r).contains("driver's own numbers"));
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["shaders"][0]["driver_bytes"], 4);
    }
}
