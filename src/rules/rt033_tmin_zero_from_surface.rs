use super::Context;
use crate::analysis::rays::{self, Origin};
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces and ray queries whose `tMin` is the constant 0 while the
    /// origin is exactly a hit point: `origin + direction × t` with `t` the hit
    /// distance (`gl_HitTEXT`, `RayTCurrent()`, a distance read back from the
    /// payload), or a vertex position transformed by `ObjectToWorld`, with no
    /// offset added.
    ///
    /// ## Why is this bad?
    ///
    /// A hit point computed in floating point lies a little above or below the
    /// surface it was computed from. With `tMin` 0 the new ray can hit that same
    /// surface at a distance of almost nothing: shadow rays report the surface as
    /// its own occluder ("shadow acne"), and reflection rays bounce back into the
    /// surface.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    /// traceRayEXT(tlas, flags, 0xFF, 0, 0, 1, p, 0.0, toLight, dist, 1);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    /// traceRayEXT(tlas, flags, 0xFF, 0, 0, 1, offsetRay(p, n), 0.0, toLight, dist, 1);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Offset the origin along the geometric normal, ideally with a robust
    /// origin function (Wächter and Binder's `offset_ray`), or give `tMin` a small
    /// positive value scaled to the scene. An origin with any offset added, or
    /// passed through a function, is not reported.
    ///
    /// ## References
    ///
    /// - Carsten Wächter and Nikolaus Binder, "A Fast and Robust Method for
    ///   Avoiding Self-Intersection", Ray Tracing Gems, chapter 6.
    "RT033" "tmin-zero-from-surface" {
        group: Suspicious,
        summary: "ray from a hit point with tMin 0 and no origin offset",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for r in rays::rays(ctx.program).iter() {
        if r.origin != Origin::HitPoint || r.tmin != Some(0.0) {
            continue;
        }
        let what = if r.query { "ray query" } else { "ray" };
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("{what} starts exactly at a hit point with `tMin` 0"),
            )
            .with_primary(r.location.clone(), "origin on the surface, `tMin` 0")
            .with_note(
                "the origin is the hit point with no offset; rounding leaves it on either side of the surface, so the ray can hit the surface it starts on",
            )
            .with_help("offset the origin along the surface normal or give `tMin` a small positive value"),
        );
    }
    out
}
