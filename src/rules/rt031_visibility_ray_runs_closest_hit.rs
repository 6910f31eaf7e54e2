use super::PipelineContext;
use crate::analysis::rays;
use crate::diag::Diagnostic;
use crate::shader::Language;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds visibility traces (see RT030: every shader the trace can run
    /// writes only constants to the payload and traces nothing) that run a
    /// closest-hit shader only to record that the ray hit, without
    /// `SkipClosestHitShader` (`gl_RayFlagsSkipClosestHitShaderEXT`, 0x8).
    ///
    /// ## Why is this bad?
    ///
    /// Invoking a closest-hit shader is a shader call: the payload is written
    /// out, the shader is scheduled, and the payload read back. When the only
    /// thing it does is store "hit", initialising the payload to "hit" before
    /// the trace and letting the miss shader store "missed" gives the same answer
    /// with no closest-hit invocation.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// // closest hit of the shadow group
    /// void main() { shadowed = true; }
    /// ```
    ///
    /// Use instead: `shadowed = true;` before `traceRayEXT(tlas,
    /// gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT, …)`
    /// and a miss shader that stores `shadowed = false`.
    ///
    /// ## How to fix
    ///
    /// Set `SkipClosestHitShader` on the trace, initialise the payload to the
    /// "hit" value and write "missed" in the miss shader.
    "RT031" "visibility-ray-runs-closest-hit" {
        group: Perf,
        summary: "visibility trace runs a closest-hit shader that only records a hit",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    for v in rays::visibility_traces(ctx.pipeline, &ctx.recursion.graph) {
        if v.recording_closest_hits == 0 {
            continue;
        }
        let Some(program) = ctx.pipeline.programs.get(v.program) else {
            continue;
        };
        let names = v
            .closest_hits
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            "visibility trace runs a closest-hit shader that only records the hit",
        )
        .with_code(CODE)
        .with_primary(v.location.clone(), "no `SkipClosestHitShader` flag")
        .with_note(format!("closest-hit shaders it runs: {names}; each only stores constants in the payload"))
        .with_help(format!(
            "set `{}`, initialise the payload to the hit value and store the miss value in the miss shader",
            flag_name(program.language)
        ));
        if reported.first(v.program, v.inst, &v.location) {
            out.push(d);
        }
    }
    out
}

/// The flag as the shader's language spells it.
fn flag_name(language: Language) -> &'static str {
    match language {
        Language::Hlsl => "RAY_FLAG_SKIP_CLOSEST_HIT_SHADER",
        Language::Wgsl => "RAY_FLAG_SKIP_CLOSEST_HIT_SHADER",
        Language::Glsl => "gl_RayFlagsSkipClosestHitShaderEXT",
        Language::Spirv => "SkipClosestHitShaderKHR",
    }
}
