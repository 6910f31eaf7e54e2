//! RT072 `incoherent-rays-without-reorder`: a bounce loop that shades with
//! several closest-hit shaders and never reorders threads.

use crate::analysis::callgraph::EdgeKind;
use crate::analysis::trace_sites::is_bounce_from;
use crate::diag::Diagnostic;
use crate::shader::Stage;

super::declare_rule! {
    /// ## What it does
    ///
    /// Reports a trace inside a loop of a ray generation shader whose origin or
    /// direction comes from a ray payload (a bounce loop, not a loop over
    /// samples) that can reach two or more different closest-hit shaders declared
    /// with its payload's layout — different material paths — when the ray
    /// generation shader uses no shader execution
    /// reordering (`MaybeReorderThread`, `reorderThreadNV`, hit objects).
    ///
    /// This is advice (pedantic), under an assumption the shaders cannot show:
    /// that the target supports shader execution reordering (NVIDIA Ada and later
    /// through `VK_NV_ray_tracing_invocation_reorder` or
    /// `VK_EXT_ray_tracing_invocation_reorder`, DXR 1.2). Elsewhere the call is
    /// accepted and does nothing; lavapipe has no reordering.
    ///
    /// ## Why is this bad?
    ///
    /// After the first bounce, neighbouring rays go in unrelated directions and hit
    /// unrelated materials. A wave whose lanes need different closest-hit shaders
    /// runs each of them with most lanes idle, and their memory accesses scatter.
    /// Reordering by hit shader (and a material key) before shading regroups the
    /// lanes so each wave runs one material path.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// for (uint bounce = 0; bounce < maxBounces; ++bounce) {
    ///     TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, payload);
    ///     ray = nextRay(payload);
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// for (uint bounce = 0; bounce < maxBounces; ++bounce) {
    ///     HitObject hit = HitObject::TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, payload);
    ///     MaybeReorderThread(hit);
    ///     HitObject::Invoke(hit, payload);
    ///     ray = nextRay(payload);
    /// }
    /// ```
    ///
    /// ## How to fix
    ///
    /// Trace into a hit object and reorder before invoking the hit shader, where
    /// the target supports it.
    ///
    /// Fixtures: `fixtures/RT072/`.
    ///
    /// ## References
    ///
    /// - Microsoft, DirectX Raytracing 1.2, "Shader execution reordering".
    /// - Vulkan, `VK_NV_ray_tracing_invocation_reorder`.
    "RT072" "incoherent-rays-without-reorder" {
        group: Pedantic,
        summary: "bounce loop over several closest-hit shaders without execution reordering",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

/// Whether the program uses shader execution reordering anywhere.
fn reorders(program: &crate::program::Program) -> bool {
    program.insts.iter().any(|i| {
        let name = format!("{:?}", i.class.opcode);
        name.contains("ReorderThread") || name.contains("HitObject")
    })
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    let pipeline = ctx.pipeline;
    let g = &ctx.recursion.graph;
    let mut out = Vec::new();
    // Per program and per trace, computed once: an undescribed pipeline has
    // an edge from every trace to every hit group that takes its payload.
    let reorder: Vec<bool> = pipeline.programs.iter().map(reorders).collect();
    let mut targets: std::collections::HashMap<(usize, usize), Vec<usize>> =
        std::collections::HashMap::new();
    for t in g.edges.iter().filter(|t| t.kind == EdgeKind::Trace) {
        targets.entry((t.program, t.inst)).or_default().push(t.to);
    }
    let mut seen: std::collections::HashSet<(usize, usize)> = std::collections::HashSet::new();
    let mut refused: std::collections::HashSet<(usize, usize, usize)> =
        std::collections::HashSet::new();
    for e in g.edges.iter().filter(|e| e.kind == EdgeKind::Trace) {
        if seen.contains(&(e.program, e.inst)) || !refused.insert((e.from, e.program, e.inst)) {
            continue;
        }
        let Some(from) = g.nodes.get(e.from) else {
            continue;
        };
        if from.shader.stage != Stage::RayGeneration {
            continue;
        }
        let Some(program) = pipeline.programs.get(e.program) else {
            continue;
        };
        if reorder[e.program] || !is_bounce_from(program, from.shader.function, e.inst) {
            continue;
        }
        // Distinct closest-hit shaders this trace can reach (the reach
        // analysis already left out those declared with another payload,
        // a shadow ray's).
        let mut hits: Vec<(usize, u32)> = Vec::new();
        for &to in targets.get(&(e.program, e.inst)).into_iter().flatten() {
            if let Some(n) = g.nodes.get(to) {
                let key = (n.shader.program, n.shader.function);
                if n.shader.stage == Stage::ClosestHit && !hits.contains(&key) {
                    hits.push(key);
                }
            }
        }
        seen.insert((e.program, e.inst));
        if hits.len() < 2 {
            continue;
        }
        out.push(
            Diagnostic::new(
                LEVEL,
                NAME,
                &program.path,
                format!(
                    "bounce loop traces rays that reach {} closest-hit shaders without reordering threads",
                    hits.len()
                ),
            )
            .with_code(CODE)
            .with_subject(format!("trace in `{}`", from.shader.entry))
            .with_primary(e.location.clone(), "traced in a loop")
            .with_note("assumes the target supports shader execution reordering (DXR 1.2, `VK_NV_ray_tracing_invocation_reorder`)")
            .with_help("trace into a hit object and reorder threads before invoking the hit shader"),
        );
    }
    out
}
