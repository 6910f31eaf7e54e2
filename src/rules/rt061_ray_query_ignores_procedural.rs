use super::Context;
use crate::analysis::rayquery::{self, FLAG_SKIP_AABBS};
use crate::diag::Diagnostic;
use crate::explain;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a ray query whose loop commits candidate triangles
    /// (`rayQueryConfirmIntersectionEXT`, `CommitNonOpaqueTriangleHit`) but never
    /// commits a procedural primitive (`rayQueryGenerateIntersectionEXT`,
    /// `CommitProceduralPrimitiveHit`), and whose constant ray flags do not skip
    /// AABBs (`gl_RayFlagsSkipAABBEXT`, `RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES`).
    ///
    /// ## Why is this bad?
    ///
    /// A ray query never intersects an AABB by itself: `Proceed` returns each AABB
    /// as a candidate, opaque or not, and only the shader can report a hit in it.
    /// A loop written for triangles silently misses every procedural primitive in
    /// the acceleration structure. It is harmless when the scene has no AABBs,
    /// which a shader cannot know: the rule is pedantic.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// RayQuery<RAY_FLAG_NONE> q;
    /// q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    /// while (q.Proceed()) {
    ///     if (AlphaTest(q)) q.CommitNonOpaqueTriangleHit();
    /// }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// RayQuery<RAY_FLAG_SKIP_PROCEDURAL_PRIMITIVES> q;
    /// ```
    ///
    /// or handle `CANDIDATE_PROCEDURAL_PRIMITIVE` with `CommitProceduralPrimitiveHit(t)`.
    ///
    /// ## How to fix
    ///
    /// Skip procedural primitives in the ray flags, or intersect candidate AABBs
    /// and commit the hits.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - `GL_EXT_ray_query`: `rayQueryGenerateIntersectionEXT`,
    ///   `gl_RayQueryCandidateIntersectionAABBEXT`.
    /// - DirectX Raytracing specification, `RayQuery::CommitProceduralPrimitiveHit`.
    "RT061" "ray-query-ignores-procedural" {
        group: Pedantic,
        summary: "ray-query loop commits triangles but never procedural primitives",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    for q in rayquery::queries(p).iter() {
        if q.confirms.is_empty() || !q.generates.is_empty() || !q.flags_known() {
            continue;
        }
        let Some(init) = q.init_without(FLAG_SKIP_AABBS) else {
            continue;
        };
        let flags = q
            .known_flags()
            .find(|f| f & FLAG_SKIP_AABBS == 0)
            .unwrap_or(0);
        let name = p.display_name(q.var);
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("ray query `{name}` commits triangles but never a procedural primitive, so AABBs are ignored"),
            )
            .with_primary(p.site_location(q.confirms[0]), "commits candidate triangles only")
            .with_secondary(p.site_location(init), "initialised without skipping AABBs")
            .with_subject(format!("ray query `{name}`"))
            .with_note(format!("ray flags: {}", explain::ray_flags(flags, p.language)))
            .with_help("skip procedural primitives in the ray flags, or commit candidate AABB hits"),
        );
    }
    out
}
