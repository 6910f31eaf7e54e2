//! RT073 `ray-query-mega-shader`: material shading inside a ray query's
//! candidate loop.

use super::Context;
use crate::diag::Diagnostic;
use crate::program::cfg::natural_loops;
use crate::program::{Id, Program};
use rspirv::dr::Operand;
use spirv::Op;

/// Texture reads in the candidate loop at or above which it is shading, not
/// an alpha test. Instruction counts alone do not tell: an alpha test that
/// fetches the material and interpolates texture coordinates is several
/// hundred instructions of unoptimised SPIR-V (nvpro-samples' glTF path
/// tracer), and still one texture read.
const SAMPLES: usize = 2;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds the loop around each `RayQuery::Proceed` (`rayQueryProceedEXT`) — the
    /// candidate loop — and reports it when its body, with the functions it calls,
    /// reads two or more textures: material shading done for every candidate,
    /// rather than the one alpha lookup a candidate needs. The instruction count
    /// is reported but not judged: unoptimised compiler output inflates it, and a
    /// long alpha test (material fetch, texture-coordinate interpolation) is still
    /// an alpha test.
    ///
    /// This is advice (pedantic): the count of texture reads is a heuristic.
    ///
    /// ## Why is this bad?
    ///
    /// A ray query runs in the calling shader's own invocation: every lane of the
    /// wave waits while any lane is still in the candidate loop. Shading in the
    /// loop runs once per candidate instead of once per ray, keeps the registers of
    /// the shading code live across traversal, and lets divergent materials
    /// serialise the wave. Candidates should be accepted or rejected cheaply, and
    /// the committed hit shaded once after the loop.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// while (q.Proceed()) {
    ///     Material m = materials[q.CandidateInstanceID()];
    ///     float4 albedo = albedoTex.SampleLevel(s, uv, 0);
    ///     float3 n = normalTex.SampleLevel(s, uv, 0).xyz;
    ///     color += shade(m, albedo, n);          // shading per candidate
    ///     q.CommitNonOpaqueTriangleHit();
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// while (q.Proceed()) {
    ///     if (alphaTex.SampleLevel(s, uv, 0).a >= 0.5)
    ///         q.CommitNonOpaqueTriangleHit();
    /// }
    /// if (q.CommittedStatus() == COMMITTED_TRIANGLE_HIT)
    ///     color = shade(...);                     // once, for the hit
    /// ```
    ///
    /// ## How to fix
    ///
    /// Keep only the accept/reject test in the candidate loop and shade the
    /// committed hit after it.
    ///
    /// Fixtures: `fixtures/RT073/`.
    ///
    /// ## References
    ///
    /// - Microsoft, DirectX Raytracing functional spec, "Inline raytracing".
    /// - NVIDIA, "Best Practices for Using NVIDIA RTX Ray Tracing" (ray queries).
    "RT073" "ray-query-mega-shader" {
        group: Pedantic,
        summary: "material shading inside a ray query's candidate loop",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

/// The loops around instruction `inst`: the innermost loop of its function
/// holding it, else (a helper, as naga wraps every ray-query call) the loops
/// around the calls of its function, up to three calls out.
fn loops_around(program: &Program, inst: usize, depth: u32, out: &mut Vec<(usize, usize)>) {
    let Some(fi) = program.function_of(inst) else {
        return;
    };
    let f = &program.functions[fi];
    let Some(b) = f.block_of(inst) else { return };
    let inner = natural_loops(f)
        .into_iter()
        .filter(|(_, body)| body.contains(&b))
        .min_by_key(|(_, body)| body.len());
    match inner {
        Some((header, _)) if !out.contains(&(fi, header)) => out.push((fi, header)),
        Some(_) => {}
        None if depth < 3 => {
            for call in program.callers(f.id) {
                loops_around(program, call, depth + 1, out);
            }
        }
        None => {}
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let program = ctx.program;
    let mut out = Vec::new();
    let mut loops: Vec<(usize, usize)> = Vec::new();
    let mut first_proceed: Vec<usize> = Vec::new();
    for (i, inst) in program.insts.iter().enumerate() {
        if inst.class.opcode != Op::RayQueryProceedKHR {
            continue;
        }
        loops_around(program, i, 0, &mut loops);
        first_proceed.resize(loops.len(), i);
    }
    for (k, &(fi, header)) in loops.iter().enumerate() {
        let f = &program.functions[fi];
        let body = natural_loops(f)
            .into_iter()
            .find(|(h, _)| *h == header)
            .map(|(_, b)| b)
            .unwrap_or_default();
        let mut insts: Vec<usize> = Vec::new();
        for &bb in &body {
            let blk = &f.blocks[bb];
            insts.extend(blk.start..=blk.end);
        }
        let mut samples = 0;
        let mut count = 0;
        let mut callees: Vec<Id> = Vec::new();
        for &i in &insts {
            let inst = &program.insts[i];
            if program.is_debug_inst(inst) {
                continue;
            }
            count += 1;
            if crate::program::is_texture_read(inst.class.opcode) {
                samples += 1;
            }
            if inst.class.opcode == Op::FunctionCall {
                if let Some(Operand::IdRef(c)) = inst.operands.first() {
                    for g in program.reachable_functions(*c) {
                        if !callees.contains(&g) {
                            callees.push(g);
                        }
                    }
                }
            }
        }
        for g in callees.iter().filter_map(|g| program.function(*g)) {
            if g.id == f.id {
                continue;
            }
            for inst in &program.insts[g.start..=g.end] {
                if program.is_debug_inst(inst) {
                    continue;
                }
                count += 1;
                if crate::program::is_texture_read(inst.class.opcode) {
                    samples += 1;
                }
            }
        }
        if samples < SAMPLES {
            continue;
        }
        let p = first_proceed[k];
        // The call in the loop (naga's helper) or the proceed itself.
        let anchor = insts
            .iter()
            .copied()
            .find(|&i| i == p)
            .or_else(|| {
                insts.iter().copied().find(|&i| {
                    program.insts[i].class.opcode == Op::FunctionCall
                        && program.inst_location(i).is_some()
                        && matches!(program.insts[i].operands.first(),
                            Some(Operand::IdRef(c)) if program.reachable_functions(*c).iter().any(|g| {
                                program.function(*g).is_some_and(|g| g.start <= p && p <= g.end)
                            }))
                })
            })
            .unwrap_or(p);
        let at = program.site_location(anchor);
        out.push(
            ctx.diagnostic(
                &RULE,
                format!(
                    "ray query candidate loop reads {samples} texture{} in {count} instructions",
                    if samples == 1 { "" } else { "s" }
                ),
            )
            .with_primary(at, "candidate loop")
            .with_subject(format!(
                "candidate loop in `{}`",
                f.name.clone().unwrap_or_else(|| program.display_name(f.id))
            ))
            .with_note(format!(
                "reported at {SAMPLES} or more texture reads per candidate; an alpha test needs one"
            ))
            .with_help("keep only the accept/reject test in the loop and shade the committed hit after it"),
        );
    }
    out
}
