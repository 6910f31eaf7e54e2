//! `rtlint stack` in words and as JSON.

use crate::analysis::stack::{vulkan_default, Formulas, StackReport, StageMax};
use crate::explain;

/// The depth the pipeline must declare when it declares less than its
/// deepest chain needs (RT021's error: the pipeline fails on the device).
pub fn raise_depth_to(r: &StackReport) -> Option<u32> {
    match (r.declared_depth, r.required_depth) {
        (Some(d), Some(req)) if d < req => Some(req),
        _ => None,
    }
}

/// Whether the shaders form a ray-tracing pipeline at all (compute shaders
/// with ray queries have no pipeline stack size to set).
fn has_pipeline_stages(r: &StackReport) -> bool {
    r.shaders.iter().any(|s| s.stage.is_ray_tracing())
}

/// The JSON form: the report's data with the chain and assumptions in words.
pub fn json(r: &StackReport) -> serde_json::Value {
    let mut v = serde_json::to_value(r).unwrap_or_default();
    if let Some(o) = v.as_object_mut() {
        o.insert("raise_depth_to".into(), raise_depth_to(r).into());
        if !has_pipeline_stages(r) {
            o.insert("recommended".into(), serde_json::Value::Null);
        }
        o.insert("depth_chain".into(), explain::stack_chain(r).into());
        o.insert(
            "assumptions".into(),
            r.assumptions.iter().map(|a| a.to_string()).collect(),
        );
    }
    v
}

/// What the table's columns mean, said once under it.
pub const COLUMNS: &str = "  bytes per thread, per shader:
    model     what rtlint reserves for it: every live value kept, plus a safety margin
    driver*   what the NVIDIA driver is modelled to report for it
    live      state kept across a trace or call that cannot be recomputed after it
    arrays    function-local arrays (kept in memory, not registers)
    payload   the largest ray payload the shader traces with (its outgoing payload)
    in        the payload it receives (hit and miss shaders)
    attrs     the hit attributes it reads or reports
    callable  the largest callable data it passes to a callable shader
    query     the driver's own figure, with --driver
";

fn formula_text(m: &StageMax, depth: u32) -> String {
    format!(
        "{} + min(1, {depth}) × max({}, {}, {} + {}) + max(0, {depth} − 1) × max({}, {}) + 2 × {} = {}",
        m.raygen,
        m.closest_hit,
        m.miss,
        m.intersection,
        m.any_hit,
        m.closest_hit,
        m.miss,
        m.callable,
        vulkan_default(m, depth)
    )
}

fn opt(v: Option<u64>) -> String {
    v.map_or("—".into(), |v| format!("{v} B"))
}

/// The human form of `rtlint stack`.
pub fn human(r: &StackReport) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    if let Some(p) = &r.pipeline {
        let _ = writeln!(s, "pipeline {p}");
    } else {
        let _ = writeln!(
            s,
            "no pipeline description: every shader given is assumed reachable"
        );
    }
    let depth = |d: Option<u32>| d.map_or("unbounded at compile time".into(), |d| d.to_string());
    let _ = writeln!(
        s,
        "recursion depth: required {}, declared {}, device limit {}",
        depth(r.required_depth),
        r.declared_depth
            .map_or("not given".into(), |d| d.to_string()),
        r.device_max_depth
    );
    let chain = explain::stack_chain(r);
    if !chain.is_empty() {
        let _ = writeln!(s, "  deepest chain: {chain}");
    }
    if let (Some(req), Some(d)) = (raise_depth_to(r), r.declared_depth) {
        let _ = writeln!(
            s,
            "  error: the declared depth {d} is too small: raise it to {req} \
             (maxPipelineRayRecursionDepth / MaxTraceRecursionDepth); a trace \
             beyond the declared depth fails on the device (RT021)"
        );
    }
    let _ = writeln!(s);
    let names: Vec<String> = r
        .shaders
        .iter()
        .map(|sh| {
            let file = std::path::Path::new(&sh.file)
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            format!("{} `{}` {}", sh.stage.as_str(), sh.entry, file)
        })
        .collect();
    let w = names
        .iter()
        .map(|n| n.chars().count())
        .max()
        .unwrap_or(6)
        .max(6);
    let _ = writeln!(
        s,
        "{:<w$}  {:<12} {:>6} {:>7} {:>5} {:>6} {:>7} {:>4} {:>5} {:>8} {:>6}",
        "shader",
        "group",
        "model",
        "driver*",
        "live",
        "arrays",
        "payload",
        "in",
        "attrs",
        "callable",
        "query"
    );
    for (sh, name) in r.shaders.iter().zip(&names) {
        let b = &sh.breakdown;
        let _ = writeln!(
            s,
            "{:<w$}  {:<12} {:>6} {:>7} {:>5} {:>6} {:>7} {:>4} {:>5} {:>8} {:>6}",
            name,
            sh.group,
            sh.model_bytes,
            sh.driver_model_bytes,
            b.live_state,
            b.local_arrays,
            b.outgoing_payload,
            b.incoming_payload,
            b.hit_attributes,
            b.callable_data,
            sh.driver_bytes.map_or("—".into(), |d| d.to_string()),
        );
    }
    let _ = write!(s, "{COLUMNS}");
    let _ = writeln!(s);
    let mut block = |title: &str, f: &Formulas| {
        let _ = writeln!(s, "{title}:");
        if let Some(d) = r.declared_depth {
            let _ = writeln!(
                s,
                "  Vulkan/DXR default, declared depth {d}: {}",
                formula_text(&f.stage_max, d)
            );
        }
        if let Some(d) = r.required_depth {
            let _ = writeln!(
                s,
                "  Vulkan/DXR default, required depth {d}: {}",
                formula_text(&f.stage_max, d)
            );
        }
        if let Some(d) = r.assumed_depth.filter(|&d| r.declared_depth != Some(d)) {
            let _ = writeln!(
                s,
                "  Vulkan/DXR default, assumed depth {d}: {}",
                formula_text(&f.stage_max, d)
            );
        }
        let _ = writeln!(s, "  exact call-chain maximum: {}", opt(f.exact_call_chain));
    };
    block("full model", &r.model);
    block("driver-comparable part", &r.driver_comparable);
    if let Some(d) = &r.driver {
        block("driver's own numbers", d);
    }
    let _ = writeln!(s);
    match r.recommended {
        _ if !has_pipeline_stages(r) => {
            let _ = writeln!(
                s,
                "recommended: nothing to set (no ray-tracing pipeline: ray queries in compute shaders use no pipeline stack)"
            );
        }
        Some(v) if r.assumed_depth.is_some() => {
            let d = r.assumed_depth.unwrap_or_default();
            let whose = if r.declared_depth == Some(d) {
                "the declared depth"
            } else {
                "the device's limit"
            };
            let _ = writeln!(
                s,
                "recommended (conditional): vkCmdSetRayTracingPipelineStackSizeKHR(cmd, {v}) / SetPipelineStackSize({v})"
            );
            let _ = writeln!(
                s,
                "  assumes the recursion stops within depth {d} ({whose}): no bound is known at compile time, so a deeper recursion needs more"
            );
        }
        Some(v) => {
            let _ = writeln!(
                s,
                "recommended: vkCmdSetRayTracingPipelineStackSizeKHR(cmd, {v}) / SetPipelineStackSize({v})"
            );
            if let Some(req) = raise_depth_to(r) {
                let _ = writeln!(
                    s,
                    "  once the declared depth is raised to {req}: set both, the depth and this size"
                );
            }
            if let Some(d) = r.vulkan_default {
                if d > v {
                    let _ = writeln!(
                        s,
                        "  {} B ({:.0} %) below the default of {d} B",
                        d - v,
                        100.0 * (d - v) as f64 / d as f64
                    );
                }
            }
        }
        None => {
            let _ = writeln!(s, "recommended: none (recursion unbounded at compile time)");
        }
    }
    for a in &r.assumptions {
        let _ = writeln!(s, "note: {a}");
    }
    s
}
