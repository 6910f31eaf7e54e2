use super::Context;
use crate::analysis::rays;
use crate::diag::Diagnostic;

/// `tMax` at or above this counts as unbounded.
const UNBOUNDED: f64 = 1e4;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces and ray queries toward a point at a known distance — the
    /// direction is `normalize(v)` (or `v / length(v)`) and `length(v)` or
    /// `distance(a, b)` of the same vector is computed beside it — whose `tMax`
    /// is a constant of 10⁴ or more, or infinite.
    ///
    /// ## Why is this bad?
    ///
    /// A shadow ray toward a point light or an area-light sample must stop at the
    /// light: geometry behind the light does not shadow the point, yet an
    /// unbounded ray finds it and reports an occluder. Traversal also visits
    /// every node the longer ray crosses, so unbounded rays cost more. The
    /// distance that bounds the ray is already computed.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// vec3 toLight = light.position - p;
    /// float dist = length(toLight);
    /// traceRayEXT(tlas, flags, 0xFF, 0, 0, 1, p, 0.001, normalize(toLight), 1e30, 1);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// traceRayEXT(tlas, flags, 0xFF, 0, 0, 1, p, 0.001, normalize(toLight), dist - 0.001, 1);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Pass the computed distance (less a small epsilon, so the light's own
    /// geometry is not hit) as `tMax`.
    "RT034" "unbounded-secondary-tmax" {
        group: Suspicious,
        summary: "unbounded tMax on a ray whose target distance is computed",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for r in rays::rays(ctx.program).iter() {
        let (Some(bound), Some(tmax)) = (&r.bound, r.tmax) else {
            continue;
        };
        if tmax < UNBOUNDED {
            continue;
        }
        let what = if r.query { "ray query" } else { "ray" };
        out.push(
            ctx.diagnostic(
                &RULE,
                format!(
                    "{what} toward a point at a computed distance has `tMax` {}",
                    crate::explain::float(tmax)
                ),
            )
            .with_primary(r.location.clone(), "unbounded `tMax`")
            .with_secondary(bound.location.clone(), "distance to the target computed here")
            .with_help("pass the computed distance, less a small epsilon, as `tMax`"),
        );
    }
    out
}
