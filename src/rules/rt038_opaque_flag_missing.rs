use super::PipelineContext;
use crate::analysis::rays::{self, flags};
use crate::diag::Diagnostic;
use crate::shader::Stage;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces whose constant ray flags set neither `Opaque` nor `NoOpaque`
    /// although no hit group they can reach has an any-hit shader, in a
    /// pipeline whose description does not say all geometry is opaque.
    ///
    /// ## Why is this bad?
    ///
    /// When the ray is not opaque, geometry built without the opaque flag makes
    /// traversal stop at every candidate to look for an any-hit shader. `Opaque`
    /// on the ray states what the pipeline already guarantees and lets the
    /// hardware skip that path. The check is pedantic: the instance and geometry
    /// flags the application uses are not visible to it, and without a pipeline
    /// description an any-hit shader elsewhere is unknown.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// traceRayEXT(tlas, gl_RayFlagsNoneEXT, 0xFF, 0, 0, 0, o, 0.001, d, 1e4, 0);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, o, 0.001, d, 1e4, 0);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Add `Opaque` to the ray flags, or build the geometry opaque and say so with
    /// `all_geometry_opaque = true` in the pipeline description.
    "RT038" "opaque-flag-missing" {
        group: Pedantic,
        summary: "trace without Opaque where no reachable hit group has an any-hit shader",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let p = ctx.pipeline;
    let g = &ctx.recursion.graph;
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    if p.all_geometry_opaque {
        return out;
    }
    for t in rays::trace_targets(g) {
        let Some(f) = rays::trace_flags(p, g, &t) else {
            continue;
        };
        if f & (flags::OPAQUE | flags::NO_OPAQUE) != 0 {
            continue;
        }
        let groups = rays::reached_groups(g, &t);
        let any_hit = t
            .targets
            .iter()
            .any(|&n| g.nodes[n].shader.stage == Stage::AnyHit)
            || groups
                .iter()
                .any(|&gi| p.hit_groups.get(gi).is_some_and(|h| h.any_hit.is_some()));
        if groups.is_empty() || any_hit {
            continue;
        }
        let Some(program) = p.programs.get(t.program) else {
            continue;
        };
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            "trace without `Opaque` reaches no any-hit shader",
        )
        .with_code(CODE)
        .with_primary(t.location.clone(), "ray flags without `Opaque`")
        .with_help("add `Opaque` to the ray flags");
        if reported.first(t.program, t.inst, &t.location) {
            out.push(d);
        }
    }
    out
}
