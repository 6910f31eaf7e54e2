use super::Context;
use crate::analysis::rayquery::{self, FLAG_CULL_NO_OPAQUE, FLAG_OPAQUE, FLAG_SKIP_TRIANGLES};
use crate::diag::Diagnostic;
use crate::explain;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a ray query advanced in a loop (`while (rayQueryProceedEXT(rq))`,
    /// `while (q.Proceed())`) that never commits a candidate triangle
    /// (`rayQueryConfirmIntersectionEXT`, `CommitNonOpaqueTriangleHit`,
    /// `rayQueryConfirmIntersection`), although it is initialised with constant
    /// ray flags that let non-opaque triangles through: none of
    /// `gl_RayFlagsOpaqueEXT` / `RAY_FLAG_FORCE_OPAQUE`, `CullNoOpaque` or
    /// `SkipTriangles` (HLSL's `RayQuery<FLAGS>` template flags count). Queries
    /// whose flags are not known at compile time are not reported.
    ///
    /// ## Why is this bad?
    ///
    /// `Proceed` stops at every non-opaque triangle and leaves the decision to the
    /// shader; a candidate that is not committed is dropped. A loop that only
    /// spins `Proceed` therefore ignores all geometry not built with the opaque
    /// flag (alpha-tested foliage, decals): shadow rays pass through it and the
    /// committed hit is whatever opaque surface lies behind. The code is valid and
    /// works while every geometry happens to be opaque.
    ///
    /// The rule is pedantic (off unless selected): whether the loop is wrong
    /// depends on the geometry flags the application builds, which the shader
    /// does not show. Every finding on public shaders was latent, the scene
    /// being built opaque (`docs/rules-precision.md`).
    ///
    /// ## Example
    ///
    /// ```glsl
    /// rayQueryInitializeEXT(rq, tlas, gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, 0.0, d, 1e4);
    /// while (rayQueryProceedEXT(rq)) { }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// rayQueryInitializeEXT(rq, tlas, gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT, 0xFF, o, 0.0, d, 1e4);
    /// while (rayQueryProceedEXT(rq)) { }
    /// ```
    ///
    /// or commit the candidates that pass the alpha test:
    ///
    /// ```glsl
    /// while (rayQueryProceedEXT(rq)) {
    ///     if (rayQueryGetIntersectionTypeEXT(rq, false) == gl_RayQueryCandidateIntersectionTriangleEXT
    ///         && alphaTest(rq))
    ///         rayQueryConfirmIntersectionEXT(rq);
    /// }
    /// ```
    ///
    /// ## How to fix
    ///
    /// Add the opaque flag when all geometry is meant to be treated as opaque;
    /// otherwise commit the candidate triangles the shader accepts.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - `GL_EXT_ray_query`: `rayQueryProceedEXT`, `rayQueryConfirmIntersectionEXT`.
    /// - DirectX Raytracing specification, `RayQuery::Proceed`,
    ///   `CommitNonOpaqueTriangleHit`.
    "RT060" "ray-query-never-commits" {
        group: Pedantic,
        summary: "ray-query loop never commits non-opaque triangles",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    for q in rayquery::queries(p).iter() {
        if q.proceeds.is_empty() || !q.confirms.is_empty() || !q.flags_known() {
            continue;
        }
        let Some(init) = q.init_without(FLAG_OPAQUE | FLAG_CULL_NO_OPAQUE | FLAG_SKIP_TRIANGLES)
        else {
            continue;
        };
        let Some(&proceed) = q.proceeds.iter().find(|&&i| rayquery::in_loop(p, i, &q.inits)) else {
            continue;
        };
        let flags = q
            .known_flags()
            .find(|f| f & (FLAG_OPAQUE | FLAG_CULL_NO_OPAQUE | FLAG_SKIP_TRIANGLES) == 0)
            .unwrap_or(0);
        let name = p.display_name(q.var);
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("ray query `{name}` never commits a candidate, so non-opaque triangles are ignored"),
            )
            .with_primary(p.site_location(proceed), "proceeds here, and nothing commits a candidate")
            .with_secondary(p.site_location(init), "initialised without an opaque flag")
            .with_subject(format!("ray query `{name}`"))
            .with_note(format!("ray flags: {}", explain::ray_flags(flags, p.language)))
            .with_help("add the opaque ray flag, or commit the candidate triangles the shader accepts"),
        );
    }
    out
}
