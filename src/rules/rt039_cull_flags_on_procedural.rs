use super::PipelineContext;
use crate::analysis::rays::{self, flags};
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces with a face-culling flag (`CullBackFacingTriangles`,
    /// `CullFrontFacingTriangles`) that can reach only procedural (AABB) hit
    /// groups, or that also set `SkipTriangles`.
    ///
    /// ## Why is this bad?
    ///
    /// Facing is a property of triangles: procedural primitives have no winding,
    /// so the flag does nothing for them and whatever culling it was meant to do
    /// must happen in the intersection shader. A face-culling flag together
    /// with `SkipTriangles` is not allowed at all: DXR's `RAY_FLAG` reference
    /// makes `SkipTriangles` mutually exclusive with both culling flags.

    ///
    /// ## Example
    ///
    /// ```glsl
    /// // every hit group is procedural (spheres)
    /// traceRayEXT(tlas, gl_RayFlagsCullBackFacingTrianglesEXT, 0xFF, 0, 0, 0, o, 0.001, d, 1e4, 0);
    /// ```
    ///
    /// Use instead: no culling flag, and back faces rejected in the
    /// intersection shader if that is wanted.
    ///
    /// ## How to fix
    ///
    /// Drop the culling flag, or cull in the intersection shader.
    ///
    /// ## References
    ///
    /// - DirectX Raytracing, `RAY_FLAG` enumeration (`RAY_FLAG_SKIP_TRIANGLES`).
    "RT039" "cull-flags-on-procedural" {
        group: Suspicious,
        summary: "face-culling ray flags on a trace that reaches only procedural geometry",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let p = ctx.pipeline;
    let g = &ctx.recursion.graph;
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    let cull = flags::CULL_BACK_FACING | flags::CULL_FRONT_FACING;
    // Culling with SkipTriangles, whatever the pipeline.
    for (pi, program) in p.programs.iter().enumerate() {
        for r in rays::rays(program).iter() {
            let Some(f) = r.flags else { continue };
            if f & cull == 0 || f & flags::SKIP_TRIANGLES == 0 {
                continue;
            }
            let inst = program.sites[r.site].inst;
            push(
                &mut out,
                (&mut reported, pi, inst),
                Diagnostic::new(
                    LEVEL,
                    NAME,
                    &program.path,
                    "trace combines a face-culling flag with `SkipTriangles`",
                )
                .with_code(CODE)
                .with_primary(r.location.clone(), "face-culling ray flag")
                .with_note("`SkipTriangles` is mutually exclusive with `CullBackFacingTriangles` and `CullFrontFacingTriangles`")
                .with_help("drop the culling flag"),
            );
        }
    }
    for t in rays::trace_targets(g) {
        let Some(f) = rays::trace_flags(p, g, &t) else {
            continue;
        };
        if f & cull == 0 || f & flags::SKIP_TRIANGLES != 0 {
            continue;
        }
        let groups = rays::reached_groups(g, &t);
        if !rays::all_procedural(p, &groups) {
            continue;
        }
        // A triangles group whose every shader the flags skip (a shadow ray's
        // `SkipClosestHit` on a closest-hit-only group) has no edge, yet its
        // triangles are traversed and culled all the same.
        let runs = |stage: crate::shader::Stage| match stage {
            crate::shader::Stage::ClosestHit => f & flags::SKIP_CLOSEST_HIT == 0,
            crate::shader::Stage::AnyHit => f & flags::OPAQUE == 0,
            _ => true,
        };
        let unseen_triangles = p.hit_groups.iter().any(|h| {
            h.kind == crate::pipeline::HitGroupKind::Triangles && !h.shaders().any(|s| runs(s.stage))
        });
        if unseen_triangles {
            continue;
        }
        let Some(program) = p.programs.get(t.program) else {
            continue;
        };
        let list = groups
            .iter()
            .map(|g| g.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        push(
            &mut out,
            (&mut reported, t.program, t.inst),
            Diagnostic::new(
                LEVEL,
                NAME,
                &program.path,
                "face-culling flag on a trace that reaches only procedural geometry",
            )
            .with_code(CODE)
            .with_primary(t.location.clone(), "face-culling ray flag")
            .with_note(format!("hit groups it can reach, all procedural: {list}"))
            .with_help("drop the culling flag; cull in the intersection shader if needed"),
        );
    }
    out
}

fn push(
    out: &mut Vec<Diagnostic>,
    (reported, program, inst): (&mut super::Reported, usize, usize),
    d: Diagnostic,
) {
    let at = d.primary.as_ref().map(|l| l.location.clone());
    if reported.first(program, inst, &at) {
        out.push(d);
    }
}
