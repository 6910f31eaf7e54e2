//! RT020 `recursive-trace`: a closest-hit or miss shader traces a ray that
//! can invoke a closest-hit shader again, so the stack grows per bounce.

use crate::analysis::callgraph::EdgeKind;
use crate::analysis::recursion::RecursionReport;
use crate::diag::Diagnostic;
use crate::pipeline::Pipeline;
use crate::shader::Stage;


/// One finding per trace site in a closest-hit or miss shader whose ray can
/// reach a closest-hit shader. Shadow rays that skip closest-hit shaders
/// (or reach only miss shaders) add one fixed level and are not reported.
pub fn check(pipeline: &Pipeline, rec: &RecursionReport) -> Vec<Diagnostic> {
    let g = &rec.graph;
    let mut out = Vec::new();
    for site in &rec.recursive_sites {
        let reaches_hit = g.edges.iter().any(|e| {
            e.kind == EdgeKind::Trace
                && e.program == site.program
                && e.inst == site.inst
                && g.nodes[e.to].shader.stage == Stage::ClosestHit
        });
        if !reaches_hit {
            continue;
        }
        let node = &g.nodes[site.node];
        let file = pipeline
            .programs
            .get(site.program)
            .map(|p| p.path.clone())
            .unwrap_or_else(|| node.shader.file.clone());
        let stage = match node.shader.stage {
            Stage::Miss => "miss",
            _ => "closest-hit",
        };
        let mut d = Diagnostic::new(
            LEVEL,
            NAME,
            &file,
            format!(
                "{stage} shader `{}` traces a ray that can invoke a closest-hit shader again",
                node.shader.entry
            ),
        )
        .with_code(CODE)
        .with_subject(node.shader.entry.clone())
        .with_primary(site.location.clone(), "recursive trace");
        match rec.required_depth {
            Some(depth) => {
                d = d.with_note(format!(
                    "the pipeline needs recursion depth {depth}: {}",
                    crate::explain::recursion_chain(rec)
                ))
            }
            None => d = d.with_note("the recursion depth is unbounded at compile time"),
        }
        out.push(d.with_help(
            "loop over bounces in the ray generation shader and return the hit in the payload",
        ));
    }
    out
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces in closest-hit or miss shaders that can invoke a closest-hit
    /// shader again, making every bounce one more level of recursion. Shadow rays
    /// that skip closest-hit shaders (`SkipClosestHitShader`), or that can reach
    /// only miss shaders, add one fixed level and are not reported.
    ///
    /// ## Why is this bad?
    ///
    /// Every recursion level keeps the calling shader's state and payload on the
    /// stack, and the pipeline must declare `maxPipelineRayRecursionDepth` for the
    /// deepest chain — the default stack grows with the declared depth. The same
    /// image can be rendered with a loop in the ray generation shader at depth 1
    /// (2 with shadow rays from the hit): rtlint's recursive and iterative
    /// reference pipelines give bit-identical images on lavapipe and NVIDIA.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// // closest hit
    /// if (payload.depth < pushConst.maxDepth) {
    ///     reflected.depth = payload.depth + 1u;
    ///     traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, hitPos, 0.001,
    ///                 reflect(gl_WorldRayDirectionEXT, normal), 100.0, 1);
    ///     color += 0.5 * reflected.color;
    /// }
    /// ```
    ///
    /// ```
    /// warning[RT020]: closest-hit shader `main` traces a ray that can invoke a closest-hit shader again
    ///   = note: the pipeline needs recursion depth 5: raygeneration `main` (raygen 0) at level 0 → closesthit `main` (hit group 0) at levels 1–4 → miss `main` (miss 1) at level 5
    /// ```
    ///
    /// Use instead: the closest-hit shader returns the surface (normal, distance,
    /// reflectivity) in the payload and the ray generation shader loops over
    /// bounces (`fixtures/pipelines/iterative/`).
    ///
    /// ## How to fix
    ///
    /// Loop over bounces in the ray generation shader and return the hit in the
    /// payload; keep only fixed-depth traces (shadow rays) in hit shaders.
    ///
    /// Fixtures: `fixtures/RT020/bad.pipeline.toml`, `fixtures/RT020/good.pipeline.toml`.
    "RT020" "recursive-trace" {
        group: Perf,
        summary: "trace call from a closest-hit or miss shader",
        kind: super::Kind::Pipeline(run),
        analysis: Full,
    }
}

fn run(ctx: &super::PipelineContext) -> Vec<Diagnostic> {
    check(ctx.pipeline, &ctx.recursion)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::recursion::recursion_report;
    use crate::pipeline::load;
    use std::path::Path;

    fn run(rel: &str) -> Vec<Diagnostic> {
        let p = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap();
        check(&p, &recursion_report(&p))
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT020/bad.pipeline.toml");
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(
            d[0].message,
            "closest-hit shader `main` traces a ray that can invoke a closest-hit shader again"
        );
        // The trace starts on line 25 and ends on 26.
        assert_eq!(d[0].primary.as_ref().unwrap().location.line, 25);
        assert!(d[0].notes[0].starts_with("the pipeline needs recursion depth 5"));
        // The iterative pipeline's closest-hit shader traces only a shadow ray.
        assert!(run("fixtures/RT020/good.pipeline.toml").is_empty());
    }

    /// naga calls one trace helper per payload from every shader: the finding
    /// points at the closest hit's own call, not the raygen's.
    #[test]
    fn wgsl_finding_at_the_closest_hits_call() {
        let d = run("shaders/reflect_recursive.pipeline.toml");
        assert_eq!(d.len(), 1, "{d:?}");
        let l = &d[0].primary.as_ref().unwrap().location;
        assert_eq!((l.line, l.column), (136, 9));
    }
}
