use super::Context;
use crate::analysis::rayquery::{self, FLAG_CULL_NO_OPAQUE, FLAG_OPAQUE, FLAG_SKIP_TRIANGLES};
use crate::diag::Diagnostic;
use crate::explain;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a ray query advanced by a single `Proceed` per initialisation (not
    /// in a loop, or in a loop that initialises the query again), when its
    /// constant ray flags let non-opaque triangles through (none of
    /// `gl_RayFlagsOpaqueEXT` / `RAY_FLAG_FORCE_OPAQUE`, `CullNoOpaque`,
    /// `SkipTriangles`). Queries whose flags are not known at compile time are not
    /// reported.
    ///
    /// ## Why is this bad?
    ///
    /// One `Proceed` runs traversal only up to the first candidate that needs the
    /// shader's decision. With opaque geometry only, it completes the traversal;
    /// as soon as a non-opaque triangle is met it returns `true` with that
    /// candidate pending, and the committed intersection read afterwards is not
    /// the closest hit (often no hit at all). The single-`Proceed` idiom is only
    /// correct with the opaque flag.
    ///
    /// The rule is pedantic (off unless selected): one `Proceed` is right as
    /// long as the geometry is built opaque, which the shader does not show.
    /// Every finding on public shaders was latent, the scene being built
    /// opaque (`docs/rules-precision.md`).
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// RayQuery<RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH> q;
    /// q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    /// q.Proceed();
    /// bool shadowed = q.CommittedStatus() == COMMITTED_TRIANGLE_HIT;
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// RayQuery<RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH> q;
    /// ```
    ///
    /// ## How to fix
    ///
    /// Add the opaque ray flag, or call `Proceed` in a loop that handles the
    /// candidates.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - DirectX Raytracing specification, "RayQuery", the single-`Proceed`
    ///   example with `RAY_FLAG_FORCE_OPAQUE`.
    /// - `GL_EXT_ray_query`: `rayQueryProceedEXT`.
    "RT062" "ray-query-single-proceed" {
        group: Pedantic,
        summary: "single Proceed per initialisation on a query that can meet non-opaque triangles",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    let opaque = FLAG_OPAQUE | FLAG_CULL_NO_OPAQUE | FLAG_SKIP_TRIANGLES;
    for q in rayquery::queries(p).iter() {
        if !q.flags_known() {
            continue;
        }
        let Some(init) = q.init_without(opaque) else {
            continue;
        };
        let flags = q.known_flags().find(|f| f & opaque == 0).unwrap_or(0);
        let name = p.display_name(q.var);
        for &proceed in q.proceeds.iter().filter(|&&i| !rayquery::in_loop(p, i, &q.inits)) {
            out.push(
                ctx.diagnostic(
                    &RULE,
                    format!("ray query `{name}` proceeds only once, but its flags let a non-opaque triangle stop traversal early"),
                )
                .with_primary(p.site_location(proceed), "single `Proceed` per initialisation")
                .with_secondary(p.site_location(init), "initialised without an opaque flag")
                .with_subject(format!("ray query `{name}`"))
                .with_note(format!("ray flags: {}", explain::ray_flags(flags, p.language)))
                .with_help("add the opaque ray flag, or call `Proceed` in a loop that handles the candidates"),
            );
        }
    }
    out
}
