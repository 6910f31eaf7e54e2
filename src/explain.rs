//! The words for analysis facts: reasons, chains, assumptions and suggested
//! declarations. Analyses return data; rule messages and reports (`report/`)
//! both say it in these words, so a fact reads the same everywhere.
//!
//! Layering: analyses → explain → rules → report.

use crate::analysis::callgraph::{Assumption, Node, OutOfRange};
use crate::analysis::layout::MemberLayout;
use crate::analysis::recursion::{
    BoundSource, ChainStep, NoGuard, NoLoopBound, UnknownBound, ValueKind,
};
use crate::shader::Language;
use std::fmt;

/// `closesthit `main` (hit group 0)`.
pub fn node(n: &Node) -> String {
    format!(
        "{} `{}` ({})",
        n.shader.stage.as_str(),
        n.shader.entry,
        n.slot
    )
}

/// `raygeneration `main` (raygen 0) at level 1 → closesthit `main` (hit group
/// 0) at levels 2–5`; `name` names a chain step's node.
pub fn chain(steps: &[ChainStep], name: impl Fn(usize) -> String) -> String {
    let parts: Vec<String> = steps
        .iter()
        .map(|s| {
            let name = name(s.node);
            if s.unbounded && s.level > 0 {
                format!("{name} at levels {} and deeper, without bound", s.level)
            } else if s.unbounded {
                format!("{name} at a level without bound")
            } else if s.repeat > 0 {
                format!("{name} at levels {}–{}", s.level, s.level as u64 + s.repeat)
            } else {
                format!("{name} at level {}", s.level)
            }
        })
        .collect();
    parts.join(" → ")
}

/// The chain of a recursion report, its nodes named by [`node`].
pub fn recursion_chain(rec: &crate::analysis::RecursionReport) -> String {
    chain(&rec.chain, |n| node(&rec.graph.nodes[n]))
}

/// The chain that needs a stack report's required depth, its shaders named
/// as [`node`] names them.
pub fn stack_chain(r: &crate::analysis::StackReport) -> String {
    chain(&r.depth_chain, |n| match r.shaders.get(n) {
        Some(sh) => format!("{} `{}` ({})", sh.stage.as_str(), sh.entry, sh.group),
        None => format!("shader {n}"),
    })
}

impl fmt::Display for ValueKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ValueKind::PushConstant => "push constant",
            ValueKind::Uniform => "uniform value",
            ValueKind::StorageBuffer => "storage buffer value",
            ValueKind::ShaderRecord => "shader record value",
        })
    }
}

impl fmt::Display for BoundSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BoundSource::Constant(v) => write!(f, "the constant {v}"),
            BoundSource::SpecConstant {
                name,
                value,
                described: true,
            } => write!(
                f,
                "specialization constant `{name}` = {value} from the description"
            ),
            BoundSource::SpecConstant {
                name,
                value,
                described: false,
            } => write!(f, "specialization constant `{name}` (default {value})"),
            BoundSource::Described { kind, key, value } => {
                write!(f, "{kind} `{key}` = {value} from the description")
            }
        }
    }
}

impl fmt::Display for UnknownBound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UnknownBound::UnknownValue => f.write_str("an unknown value"),
            UnknownBound::RuntimeValue => f.write_str("a value computed at run time"),
            UnknownBound::NotDescribed { kind, name } => write!(
                f,
                "{kind} `{name}`, which the pipeline description does not give"
            ),
        }
    }
}

impl fmt::Display for NoGuard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoGuard::ModuleMissing => f.write_str("the shader's module is missing"),
            NoGuard::TraceMissing => f.write_str("the trace is missing"),
            NoGuard::OutsideFunction => f.write_str("the trace is outside a function"),
            NoGuard::BoundUnknown { counter, bound } => {
                write!(f, "`{counter}` is compared with {bound}")
            }
            NoGuard::CounterDoesNotGrow { counter } => write!(
                f,
                "`{counter}` guards the trace but the traced payload's counter does not grow by a constant"
            ),
            NoGuard::NoComparison { counter: Some(c) } => write!(
                f,
                "no comparison of `{c}` with a known bound dominates the trace"
            ),
            NoGuard::NoComparison { counter: None } => {
                f.write_str("no depth counter comparison dominates the trace")
            }
        }
    }
}

impl fmt::Display for NoLoopBound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            NoLoopBound::NotIncremented { counter } => write!(
                f,
                "`{counter}` is compared but not incremented by a constant in the loop"
            ),
            NoLoopBound::BoundUnknown { counter, bound } => {
                write!(f, "the loop runs while `{counter}` is below {bound}")
            }
            NoLoopBound::NoCounter => f.write_str("no exit compares a counter with a bound"),
        }
    }
}

impl fmt::Display for crate::analysis::reach::Ambiguity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use crate::analysis::reach::Ambiguity;
        f.write_str(match self {
            Ambiguity::TracedPayloadUnknown => "its payload is not a declared variable, so it is taken to reach every shader it can select",
            Ambiguity::TracedPayloadUnsized => "its payload type has no defined size, so it is taken to reach every shader it can select",
            Ambiguity::IncomingUnsized => "it is taken to reach a shader whose incoming payload type has no defined size",
            Ambiguity::NoMissTakesPayload => "no miss shader given takes its payload; its level is counted with the miss shaders it can select",
        })
    }
}

/// ` at file:line:col`, or nothing.
fn at(l: &Option<crate::shader::Location>) -> String {
    l.as_ref().map(|l| format!(" at {l}")).unwrap_or_default()
}

impl fmt::Display for Assumption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Assumption::Undescribed => f.write_str(
                "no pipeline description: every trace may reach every hit group and miss shader whose incoming payload matches its own",
            ),
            Assumption::FromSubobjects => f.write_str(
                "pipeline described by DXR subobjects, which do not give the shader table's order: every trace may reach every hit group and miss shader whose incoming payload matches its own",
            ),
            Assumption::PayloadUnmatched { at: l, why } => write!(f, "trace{}: {why}", at(l)),
            Assumption::DynamicSbtOffset { at: l } => write!(
                f,
                "trace{} has a SBT offset or stride unknown at compile time: it may reach every hit group",
                at(l)
            ),
            Assumption::DynamicMissIndex { at: l } => write!(
                f,
                "trace{} has a miss index unknown at compile time: it may reach every miss shader",
                at(l)
            ),
            Assumption::NoDeclaredDepth => {
                f.write_str("no declared depth: default formulas use the required depth only")
            }
            Assumption::UnboundedRecursion { why, at: l } => write!(
                f,
                "recursion is unbounded at compile time: the trace{} closes a cycle and {why}; no exact call-chain value",
                at(l)
            ),
            Assumption::InitialValueAssumed { counter } => write!(
                f,
                "no constant initial value of `{counter}` found: 0 assumed"
            ),
            Assumption::Driver { device, driver } => write!(f, "driver: {device} ({driver})"),
            Assumption::RecommendationRaised { from, to } => write!(
                f,
                "recommendation raised from {from} B to {to} B, what the driver's own numbers need"
            ),
        }
    }
}

impl fmt::Display for OutOfRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OutOfRange::HitGroup { index, count } => {
                write!(f, "selects hit group {index}, the pipeline has {count}")
            }
            OutOfRange::Miss { index, count } => {
                write!(f, "selects miss shader {index}, the pipeline has {count}")
            }
        }
    }
}

/// A struct declaration with members in `order`, in the source's language
/// (WGSL for WGSL, HLSL otherwise): the fix a layout finding offers.
pub fn struct_declaration(
    language: Language,
    name: &str,
    order: &[usize],
    members: &[MemberLayout],
) -> String {
    let wgsl = language == Language::Wgsl;
    let mut s = format!("struct {name} {{\n");
    for &k in order {
        let m = &members[k];
        if wgsl {
            s.push_str(&format!("    {}: {},\n", m.name, m.ty));
        } else {
            // HLSL puts array extents after the name.
            match m.ty.find('[') {
                Some(b) => s.push_str(&format!("    {} {}{};\n", &m.ty[..b], m.name, &m.ty[b..])),
                None => s.push_str(&format!("    {} {};\n", m.ty, m.name)),
            }
        }
    }
    s.push_str(if wgsl { "}" } else { "};" });
    s
}

/// A float constant as messages write it: `0.001`, `100`, `1e30`, `inf`.
/// Values that a 32-bit float holds exactly are written as the shortest
/// 32-bit decimal (`0.001`, not `0.0010000000474974513`).
pub fn float(v: f64) -> String {
    let narrow = v as f32;
    if f64::from(narrow) == v {
        if narrow.is_finite() && narrow != 0.0 && (narrow.abs() >= 1e4 || narrow.abs() < 1e-3) {
            format!("{narrow:e}")
        } else {
            format!("{narrow}")
        }
    } else if v.is_finite() && v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-3) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Ray flags as the source language spells them (`gl_RayFlagsOpaqueEXT |
/// gl_RayFlagsTerminateOnFirstHitEXT`, `RAY_FLAG_FORCE_OPAQUE`), `none` for 0.
pub fn ray_flags(flags: u64, language: Language) -> String {
    const NAMES: [(&str, &str, &str); 10] = [
        (
            "gl_RayFlagsOpaqueEXT",
            "RAY_FLAG_FORCE_OPAQUE",
            "RAY_FLAG_FORCE_OPAQUE",
        ),
        (
            "gl_RayFlagsNoOpaqueEXT",
            "RAY_FLAG_FORCE_NON_OPAQUE",
            "RAY_FLAG_FORCE_NO_OPAQUE",
        ),
        (
            "gl_RayFlagsTerminateOnFirstHitEXT",
            "RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH",
            "RAY_FLAG_TERMINATE_ON_FIRST_HIT",
        ),
        (
            "gl_RayFlagsSkipClosestHitShaderEXT",
            "RAY_FLAG_SKIP_CLOSEST_HIT_SHADER",
            "RAY_FLAG_SKIP_CLOSEST_HIT_SHADER",
        ),
        (
            "gl_RayFlagsCullBackFacingTrianglesEXT",
            "RAY_FLAG_CULL_BACK_FACING_TRIANGLES",
            "RAY_FLAG_CULL_BACK_FACING",
        ),
        (
            "gl_RayFlagsCullFrontFacingTrianglesEXT",
            "RAY_FLAG_CULL_FRONT_FACING_TRIANGLES",
            "RAY_FLAG_CULL_FRONT_FACING",
        ),
        (
            "gl_RayFlagsCullOpaqueEXT",
            "RAY_FLAG_CULL_OPAQUE",
            "RAY_FLAG_CULL_OPAQUE",
        ),
        (
            "gl_RayFlagsCullNoOpaqueEXT",
            "RAY_FLAG_CULL_NON_OPAQUE",
            "RAY_FLAG_CULL_NO_OPAQUE",
        ),
        (
            "gl_RayFlagsSkipTrianglesEXT",
            "RAY_FLAG_SKIP_TRIANGLES",
            "RAY_FLAG_SKIP_TRIANGLES",
        ),
        (
            "gl_RayFlagsSkipAABBEXT",
            "RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES",
            "RAY_FLAG_SKIP_AABBS",
        ),
    ];
    let mut parts = Vec::new();
    for (bit, (glsl, hlsl, wgsl)) in NAMES.iter().enumerate() {
        if flags & (1 << bit) != 0 {
            parts.push(match language {
                Language::Hlsl => *hlsl,
                Language::Wgsl => *wgsl,
                _ => *glsl,
            });
        }
    }
    let rest = flags & !0x3ff;
    let mut s = if parts.is_empty() && rest == 0 {
        "none".to_string()
    } else {
        parts
            .iter()
            .map(|p| format!("`{p}`"))
            .collect::<Vec<_>>()
            .join(" | ")
    };
    if rest != 0 {
        if !parts.is_empty() {
            s.push_str(" | ");
        }
        s.push_str(&format!("{rest:#x}"));
    }
    s
}
