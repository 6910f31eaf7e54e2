use super::Context;
use crate::analysis::rays;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces and ray queries whose constant `tMin` or `tMax` is negative
    /// or not a number, or whose constant `tMin` is greater than its `tMax`.
    ///
    /// ## Why is this bad?
    ///
    /// The ray-tracing specifications require `tMin` to be non-negative and
    /// `tMin` ≤ `tMax`; anything else is undefined behaviour, and in practice the
    /// ray finds nothing (every shadow test passes, every radiance ray misses).
    /// A swapped pair of arguments is the usual cause: in GLSL `traceRayEXT`
    /// takes origin, `tMin`, direction, `tMax`, unlike HLSL's `RayDesc`.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// traceRayEXT(tlas, 0, 0xFF, 0, 0, 0, origin, 100.0, dir, 0.001, 0);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// traceRayEXT(tlas, 0, 0xFF, 0, 0, 0, origin, 0.001, dir, 100.0, 0);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Pass a non-negative `tMin` no greater than `tMax`.
    ///
    /// ## References
    ///
    /// - SPIR-V `OpTraceRayKHR` and `OpRayQueryInitializeKHR`: `Ray Tmin` and
    ///   `Ray Tmax` valid usage in the Vulkan specification.
    /// - DirectX Raytracing functional spec, `RayDesc`.
    "RT035" "invalid-ray-interval" {
        group: Correctness,
        summary: "constant ray interval with tMin > tMax or a negative bound",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for r in rays::rays(ctx.program).iter() {
        let problem = match (r.tmin, r.tmax) {
            (Some(a), _) if a.is_nan() => "`tMin` is not a number".to_string(),
            (_, Some(b)) if b.is_nan() => "`tMax` is not a number".to_string(),
            (Some(a), _) if a < 0.0 => format!("`tMin` is negative ({})", crate::explain::float(a)),
            (_, Some(b)) if b < 0.0 => format!("`tMax` is negative ({})", crate::explain::float(b)),
            (Some(a), Some(b)) if a > b => {
                format!("`tMin` ({}) is greater than `tMax` ({})", crate::explain::float(a), crate::explain::float(b))
            }
            _ => continue,
        };
        let what = if r.query { "ray query" } else { "ray" };
        out.push(
            ctx.diagnostic(&RULE, format!("{what} interval is invalid: {problem}"))
                .with_primary(r.location.clone(), "invalid interval")
                .with_help("pass a non-negative `tMin` no greater than `tMax`"),
        );
    }
    out
}
