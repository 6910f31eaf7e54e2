use super::Context;
use crate::analysis::rays;
use crate::diag::Diagnostic;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds traces and ray queries whose direction is a constant that is zero,
    /// not finite, or not of unit length.
    ///
    /// ## Why is this bad?
    ///
    /// A zero direction finds nothing, and a direction with an infinite or NaN
    /// component is undefined behaviour. A constant direction that is not
    /// normalised is valid but scales the ray interval: `tMin`, `tMax` and the hit
    /// distance are measured in multiples of its length, so an epsilon or a light
    /// distance chosen in world units is wrong by that factor.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// ray.Direction = float3(1, 1, 0);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// ray.Direction = normalize(float3(1, 1, 0));
    /// ```
    ///
    /// ## How to fix
    ///
    /// Normalise constant directions.
    "RT036" "degenerate-ray-direction" {
        group: Suspicious,
        summary: "constant ray direction that is zero or not normalised",
        kind: super::Kind::Module(check),
        analysis: Fast,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for r in rays::rays(ctx.program).iter() {
        let Some(d) = r.direction.as_ref().filter(|d| d.len() == 3) else {
            continue;
        };
        let len = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let what = if r.query { "ray query" } else { "ray" };
        let (message, help) = if d.iter().any(|x| !x.is_finite()) {
            (
                format!("{what} direction is not finite"),
                "give the ray a finite direction",
            )
        } else if len == 0.0 {
            (format!("{what} direction is zero"), "give the ray a non-zero direction")
        } else if (len - 1.0).abs() > 1e-3 {
            (
                format!(
                    "{what} direction is not normalised (length {})",
                    crate::explain::float((len * 1e4).round() / 1e4)
                ),
                "normalise the direction, or scale `tMin` and `tMax` by its length",
            )
        } else {
            continue;
        };
        out.push(
            ctx.diagnostic(&RULE, message)
                .with_primary(r.location.clone(), "constant direction")
                .with_help(help),
        );
    }
    out
}
