use super::Context;
use crate::analysis::rayquery::{self, PathFact};
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a `Proceed` (`rayQueryProceedEXT`, `RayQuery::Proceed`,
    /// `rayQueryProceed`) reached on some path of its function before the query
    /// is initialised (`rayQueryInitializeEXT`, `TraceRayInline`,
    /// `rayQueryInitialize`). A call that is passed the query counts as
    /// initialising it; queries that are function parameters are not judged.
    ///
    /// ## Why is this bad?
    ///
    /// Proceeding an uninitialised ray query is undefined behaviour in SPIR-V: the
    /// query has no acceleration structure and no ray. Drivers may hang, crash or
    /// return garbage; the validator cannot see it.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// rayQueryEXT rq;
    /// if (castShadow)
    ///     rayQueryInitializeEXT(rq, tlas, gl_RayFlagsOpaqueEXT, 0xFF, o, 0.0, d, 1e4);
    /// while (rayQueryProceedEXT(rq)) { }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// if (castShadow) {
    ///     rayQueryInitializeEXT(rq, tlas, gl_RayFlagsOpaqueEXT, 0xFF, o, 0.0, d, 1e4);
    ///     while (rayQueryProceedEXT(rq)) { }
    /// }
    /// ```
    ///
    /// ## How to fix
    ///
    /// Initialise the query on every path that reaches `Proceed`.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - SPIR-V specification, `OpRayQueryProceedKHR` ("Ray Query must have been
    ///   initialized").
    "RT063" "ray-query-not-initialised" {
        group: Correctness,
        summary: "Proceed on a ray query not initialised on every path",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let mut out = Vec::new();
    for q in rayquery::queries(p).iter() {
        let name = p.display_name(q.var);
        for i in rayquery::reached_without(p, q, PathFact::Initialised, &q.proceeds) {
            let never = q.inits.is_empty();
            out.push(
                ctx.diagnostic(
                    &RULE,
                    if never {
                        format!("ray query `{name}` proceeds but is never initialised")
                    } else {
                        format!("ray query `{name}` can proceed before it is initialised")
                    },
                )
                .with_primary(p.site_location(i), "proceeds here")
                .with_secondary(
                    q.inits.first().and_then(|&k| p.site_location(k)),
                    "initialised here, not on every path",
                )
                .with_secondary(p.var_location(q.var).filter(|_| never), "declared here")
                .with_subject(format!("ray query `{name}`"))
                .with_help("initialise the query on every path that reaches `Proceed`"),
            );
        }
    }
    out
}
