//! The invariants every generated module ([`crate::gen`]) must keep; shared
//! by `tests/spirv_gen.rs`, the `spirv_gen` fuzz target and the replay of
//! its regressions.
//!
//! 1. No panic: every rule (`select = ["ALL"]`) on the module, the pipeline
//!    rules, the recursion and stack reports, and the loose-pipeline check.
//! 2. Live bytes at each suspension site along each call chain are at most
//!    the **local bound**: the sum, over the functions on the chain (the
//!    site's and each caller's), of the scalar-layout sizes of their
//!    Function-storage variables and of every value they define
//!    (parameters and instruction results, pointers and void excepted).
//!    It holds because a live value is one of those, counted once (by id),
//!    and a variable counts at most its whole size.
//! 3. Recursion depth: the generator's entry points form a described
//!    pipeline (each hit shader a group of its own, in module order, one
//!    instance at SBT offset 0), and the generator knows each trace's SBT
//!    offset and miss index (or that they are dynamic). Over that graph,
//!    built here independently: when no cycle is reachable from a ray
//!    generation shader, the required depth is at most the longest chain of
//!    traces from one (its number of edges), and equal to it when every
//!    trace's operands are constants; with a cycle, a bounded depth needs a
//!    recognised guard on a cycle.
//! 4. Debug info changes nothing: live bytes and values per site, findings,
//!    recursion and stack figures agree (positions and SSA names aside)
//!    between the module and the same module with its debug info.

use crate::gen::{GenEntry, Generated};
use rtlint::analysis::liveness::{live_sites, LiveValue, Storage};
use rtlint::analysis::recursion::recursion_report;
use rtlint::analysis::stack::stack_report;
use rtlint::config::Config;
use rtlint::diag::Diagnostic;
use rtlint::pipeline::Pipeline;
use rtlint::program::scalar::scalar_size;
use rtlint::program::{Program, Type};
use rtlint::shader::{Language, Stage};
use serde_json::Value;
use spirv::{Op, StorageClass};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// Every rule on.
pub fn all_rules() -> Config {
    let mut c = Config::default();
    c.select = Some(vec!["ALL".to_string()]);
    c
}

/// The facts compared with and without debug info, positions removed.
pub fn facts(words: &[u32]) -> Result<Value, String> {
    let p = parse(words)?;
    let config = all_rules();
    let sites: Vec<String> = {
        let mut v: Vec<String> = live_sites(&p)
            .iter()
            .map(|s| {
                let mut values: Vec<String> = s.values.iter().map(value_line).collect();
                values.sort();
                format!(
                    "{} {} live {} remat {} payload {:?}: {}",
                    s.entry,
                    s.kind.as_str(),
                    s.live_bytes,
                    s.rematerializable_bytes,
                    s.payload.as_ref().map(|p| p.size),
                    values.join(", ")
                )
            })
            .collect();
        v.sort();
        v
    };
    let module_findings = findings_with(&rtlint::rules::check_program(&p, &config), &scrub_text);
    let loose = findings_with(
        &rtlint::lint::check_loose(vec![(parse(words)?, Default::default())], &[], &config),
        &scrub_text,
    );
    let pipeline = described(p);
    let rec = recursion_report(&pipeline);
    let mut stack = serde_json::to_value(stack_report(&pipeline)).unwrap();
    scrub_json(&mut stack, &scrub_text);
    let ctx = rtlint::rules::PipelineContext::new(&pipeline, &config);
    let pipeline_findings = findings_with(&rtlint::rules::check_pipeline(&ctx), &scrub_text);
    Ok(serde_json::json!({
        "live": sites,
        "findings": module_findings,
        "required_depth": rec.required_depth,
        "cycles": rec.cycles.iter().map(|c| c.extra_levels).collect::<Vec<_>>(),
        "stack": stack,
        "pipeline_findings": pipeline_findings,
        "loose_findings": loose,
    }))
}

fn parse(words: &[u32]) -> Result<Program, String> {
    rtlint::program::parse(words, Path::new("gen/generated.spv"), Language::Spirv)
        .map_err(|e| format!("generated module rejected: {e:?}"))
}

/// The pipeline the generator describes: every entry point, each hit
/// shader in a group of its own, in module order.
pub fn described(p: Program) -> Pipeline {
    let mut pipeline = Pipeline::from_programs(vec![p]);
    pipeline.path = Some(PathBuf::from("gen/generated.pipeline.toml"));
    pipeline
}

/// A live value as two builds of one shader must agree on: variables by
/// name, SSA values (named only with debug info) by type and size alone;
/// shared with tests/invariance.rs.
pub fn value_line(v: &LiveValue) -> String {
    let name = match v.storage {
        Storage::Variable => v.name.as_str(),
        Storage::Ssa => "_",
    };
    format!("{name} {} {} {}", v.ty, v.size, v.rematerializable)
}

/// Removes from analysis output what may legitimately differ between two
/// builds of one shader (positions, paths) and passes every string through
/// `text`; shared with tests/invariance.rs.
pub fn scrub_json(v: &mut Value, text: &dyn Fn(&str) -> String) {
    match v {
        Value::Object(m) => {
            for k in [
                "line",
                "column",
                "end_line",
                "end_column",
                "path",
                "file",
                "def_line",
                "use_line",
                "location",
                "pipeline",
            ] {
                m.remove(k);
            }
            m.values_mut().for_each(|x| scrub_json(x, text));
        }
        Value::Array(a) => a.iter_mut().for_each(|x| scrub_json(x, text)),
        Value::String(s) => *s = text(s),
        _ => {}
    }
}

fn scrub_text(s: &str) -> String {
    let mut out = String::new();
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        out.push(c);
        if c == '%' {
            while chars.peek().is_some_and(|d| d.is_ascii_digit()) {
                chars.next();
            }
        }
    }
    out
}

/// Each finding as one sortable line (code, severity, message, notes,
/// help), its texts passed through `text`; shared with tests/invariance.rs.
pub fn findings_with(d: &[Diagnostic], text: &dyn Fn(&str) -> String) -> Vec<String> {
    let mut v: Vec<String> = d
        .iter()
        .map(|d| {
            let notes: Vec<String> = d.notes.iter().map(|n| text(n)).collect();
            format!(
                "{} {:?} {} | {} | {}",
                d.code.unwrap_or("-"),
                d.severity,
                text(&d.message),
                notes.join(" / "),
                d.help.as_deref().map(text).unwrap_or_default()
            )
        })
        .collect();
    v.sort();
    v
}

/// The local bound of function `f` (see the module docs).
pub fn local_bytes(p: &Program, f: usize) -> u64 {
    let func = &p.functions[f];
    let mut sum = 0;
    for inst in &p.insts[func.start..=func.end] {
        let (Some(_), Some(ty)) = (inst.result_id, inst.result_type) else {
            continue;
        };
        if p.is_debug_inst(inst) {
            continue;
        }
        let size = match p.ty(ty) {
            Some(Type::Pointer { pointee, storage }) => {
                if inst.class.opcode == Op::Variable && *storage == StorageClass::Function {
                    scalar_size(p, *pointee).unwrap_or(0)
                } else {
                    0
                }
            }
            _ => scalar_size(p, ty).unwrap_or(0),
        };
        sum += size;
    }
    sum
}

/// Checks invariants 1–3 on `words`, generated with `entries`.
pub fn check_module(words: &[u32], entries: &[GenEntry]) -> Result<(), String> {
    let p = parse(words)?;
    let config = all_rules();
    let _ = rtlint::rules::check_program(&p, &config);
    // Invariant 2.
    for s in live_sites(&p) {
        let mut funcs: Vec<usize> = std::iter::once(s.inst)
            .chain(s.chain.iter().copied())
            .filter_map(|i| p.function_of(i))
            .collect();
        funcs.sort_unstable();
        funcs.dedup();
        let bound: u64 = funcs.iter().map(|&f| local_bytes(&p, f)).sum();
        if s.live_bytes > bound {
            return Err(format!(
                "{} {}: {} live bytes above the local bound {bound} ({:?})",
                s.entry,
                s.kind.as_str(),
                s.live_bytes,
                s.values
                    .iter()
                    .map(|v| format!("{} {}", v.name, v.size))
                    .collect::<Vec<_>>()
            ));
        }
    }
    // Invariant 3.
    let _ = rtlint::lint::check_loose(vec![(parse(words)?, Default::default())], &[], &config);
    let pipeline = described(p);
    let rec = recursion_report(&pipeline);
    let _ = stack_report(&pipeline);
    let ctx = rtlint::rules::PipelineContext::new(&pipeline, &config);
    let _ = rtlint::rules::check_pipeline(&ctx);
    // Over the generator's graph with every dynamic operand reaching every
    // shader (upper) and none (lower): the analysis may fold a dynamic
    // operand to a constant, so its graph lies between the two.
    let upper = depth_bound(entries, true);
    let lower = depth_bound(entries, false);
    let got = rec.required_depth;
    if let (DepthBound::Acyclic(up), None) = (&upper, got) {
        return Err(format!(
            "no cycle, but the required depth is unbounded (longest chain {up})"
        ));
    }
    if let (DepthBound::Acyclic(up), Some(d)) = (&upper, got) {
        let exact = entries
            .iter()
            .flat_map(|e| &e.traces)
            .all(|t| t.sbt_offset.is_some() && t.miss_index.is_some());
        if d > *up || (exact && d != *up) {
            return Err(format!(
                "required depth {d}, longest chain of traces {up} (all operands constant: {exact})"
            ));
        }
    }
    if let (DepthBound::Acyclic(low), Some(d)) = (&lower, got) {
        if d < *low {
            return Err(format!(
                "required depth {d}, below the longest chain of constant traces {low}"
            ));
        }
    }
    if let (DepthBound::Cyclic, Some(d)) = (&lower, got) {
        if rec.cycles.is_empty() || rec.cycles.iter().any(|c| c.extra_levels.is_none()) {
            return Err(format!(
                "a cycle of constant traces is reachable, but the required depth is {d} without a guard on it"
            ));
        }
    }
    Ok(())
}

#[derive(Debug)]
enum DepthBound {
    /// The longest chain of traces from a ray generation shader (edges).
    Acyclic(u32),
    Cyclic,
}

/// The depth bound over the generator's own graph; a dynamic SBT offset or
/// miss index reaches every shader of its kind with `dynamic_all`, else none.
fn depth_bound(entries: &[GenEntry], dynamic_all: bool) -> DepthBound {
    let groups: Vec<usize> = (0..entries.len())
        .filter(|&k| {
            matches!(
                entries[k].stage,
                Stage::ClosestHit | Stage::AnyHit | Stage::Intersection
            )
        })
        .collect();
    let misses: Vec<usize> = (0..entries.len())
        .filter(|&k| entries[k].stage == Stage::Miss)
        .collect();
    let all = |v: &Vec<usize>| if dynamic_all { v.clone() } else { Vec::new() };
    let adj: Vec<Vec<usize>> = entries
        .iter()
        .map(|e| {
            let mut to = Vec::new();
            for t in &e.traces {
                let hit: Vec<usize> = match t.sbt_offset {
                    Some(o) => groups.get(o as usize).copied().into_iter().collect(),
                    None => all(&groups),
                };
                let miss: Vec<usize> = match t.miss_index {
                    Some(m) => misses.get(m as usize).copied().into_iter().collect(),
                    None => all(&misses),
                };
                for n in hit.into_iter().chain(miss) {
                    // An opaque ray runs no any-hit shader.
                    if t.opaque && entries[n].stage == Stage::AnyHit {
                        continue;
                    }
                    if !to.contains(&n) {
                        to.push(n);
                    }
                }
            }
            to
        })
        .collect();
    // Longest path by depth-first search; a node on the stack again is a cycle.
    fn longest(
        n: usize,
        adj: &[Vec<usize>],
        on_stack: &mut HashSet<usize>,
        memo: &mut Vec<Option<u32>>,
    ) -> Option<u32> {
        if let Some(l) = memo[n] {
            return Some(l);
        }
        if !on_stack.insert(n) {
            return None;
        }
        let mut best = 0;
        for &m in &adj[n] {
            best = best.max(1 + longest(m, adj, on_stack, memo)?);
        }
        on_stack.remove(&n);
        memo[n] = Some(best);
        Some(best)
    }
    let mut memo = vec![None; entries.len()];
    let mut deepest = 0;
    for (k, e) in entries.iter().enumerate() {
        if e.stage != Stage::RayGeneration {
            continue;
        }
        match longest(k, &adj, &mut HashSet::new(), &mut memo) {
            Some(l) => deepest = deepest.max(l),
            None => return DepthBound::Cyclic,
        }
    }
    DepthBound::Acyclic(deepest)
}

/// Every invariant for one generated pair (the same choices without and
/// with debug info).
pub fn check_pair(plain: &Generated, debug: &Generated) -> Result<(), String> {
    check_module(&plain.words, &plain.entries).map_err(|e| format!("without debug info: {e}"))?;
    check_module(&debug.words, &debug.entries).map_err(|e| format!("with debug info: {e}"))?;
    let a = facts(&plain.words)?;
    let b = facts(&debug.words)?;
    if a != b {
        return Err(format!(
            "debug info changes the results:\n  without: {a}\n  with:    {b}"
        ));
    }
    Ok(())
}
