use super::Context;
use crate::analysis::rayquery::{self, PathFact};
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a read of a ray query's committed intersection
    /// (`rayQueryGetIntersection*EXT(rq, true)`, `CommittedStatus()`,
    /// `CommittedRayT()`, `rayQueryGetCommittedIntersection`) reached on some
    /// path after the query's initialisation without any `Proceed` in between.
    /// A call that is passed the query counts as advancing it; queries that are
    /// function parameters are not judged.
    ///
    /// ## Why is this bad?
    ///
    /// Traversal happens inside `Proceed`. Before the first call the committed
    /// intersection is always "none": the read reports a miss whatever the scene
    /// holds, so shadows and occlusion silently vanish.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// rayQueryInitializeEXT(rq, tlas, gl_RayFlagsOpaqueEXT, 0xFF, o, 0.0, d, 1e4);
    /// bool hit = rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionNoneEXT;
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// rayQueryInitializeEXT(rq, tlas, gl_RayFlagsOpaqueEXT, 0xFF, o, 0.0, d, 1e4);
    /// while (rayQueryProceedEXT(rq)) { }
    /// bool hit = rayQueryGetIntersectionTypeEXT(rq, true) != gl_RayQueryCommittedIntersectionNoneEXT;
    /// ```
    ///
    /// ## How to fix
    ///
    /// Call `Proceed` (in a loop) before reading the committed intersection.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - `GL_EXT_ray_query`: `rayQueryProceedEXT`, `rayQueryGetIntersectionTypeEXT`.
    /// - DirectX Raytracing specification, `RayQuery::CommittedStatus`.
    "RT064" "committed-read-before-proceed" {
        group: Suspicious,
        summary: "committed intersection read before the query proceeds",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    for q in rayquery::queries(p).iter() {
        let misses = rayquery::reached_without(p, q, PathFact::Proceeded, &q.committed_reads);
        let Some(&first) = misses.first() else {
            continue;
        };
        let name = p.display_name(q.var);
        let mut d = ctx
            .diagnostic(
                &RULE,
                format!("ray query `{name}` reads its committed intersection before it proceeds"),
            )
            .with_primary(p.site_location(first), "committed intersection read here")
            .with_secondary(
                q.inits.first().and_then(|&k| p.site_location(k)),
                "initialised here",
            )
            .with_subject(format!("ray query `{name}`"))
            .with_help("call `Proceed` before reading the committed intersection");
        if misses.len() > 1 {
            d = d.with_note(format!(
                "{} more committed reads are reached the same way",
                misses.len() - 1
            ));
        }
        out.push(d);
    }
    out
}
