use super::PipelineContext;
use crate::analysis::rays::{self, flags};
use crate::diag::Diagnostic;
use crate::shader::Language;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds visibility traces — every closest-hit, any-hit and miss shader the
    /// trace can run writes only constants to the payload (or nothing) and
    /// traces nothing, so the payload can only say "hit" or "missed" — whose
    /// ray flags lack `AcceptFirstHitAndEndSearch`
    /// (`gl_RayFlagsTerminateOnFirstHitEXT`, `RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH`, WGSL `RAY_FLAG_TERMINATE_ON_FIRST_HIT`, 0x4).
    /// Flags that are a choice between constants (a `?:`, or a variable
    /// assigned on branches) are judged by every choice: one without the
    /// flag is reported.
    ///
    /// Without a pipeline description every trace may reach every shader of
    /// its folder (or file) whose incoming payload has the trace's payload
    /// type (the reach analysis; `docs/pipeline.md`). A trace that may run a
    /// closest-hit shader but reaches none is judged only when the folder has
    /// closest-hit shaders and a miss shader that takes its payload (a shadow
    /// ray type whose hit group has no closest hit); otherwise its own closest
    /// hit may be missing from the folder.
    ///
    /// ## Why is this bad?
    ///
    /// A visibility test needs any hit, not the closest one. Without the flag
    /// traversal keeps searching for a closer intersection after the first,
    /// visiting more of the acceleration structure (and running any-hit shaders
    /// for every candidate) for an answer that was already known.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// shadowed = true;
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT | gl_RayFlagsSkipClosestHitShaderEXT,
    ///             0xFF, 0, 0, 1, p, 0.001, toLight, dist, 1);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// traceRayEXT(tlas, gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsOpaqueEXT
    ///             | gl_RayFlagsSkipClosestHitShaderEXT, 0xFF, 0, 0, 1, p, 0.001, toLight, dist, 1);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Add `AcceptFirstHitAndEndSearch` to the ray flags of the visibility trace.
    "RT030" "shadow-ray-without-accept-first-hit" {
        group: Perf,
        summary: "visibility trace without AcceptFirstHitAndEndSearch",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    for v in rays::visibility_traces(ctx.pipeline, &ctx.recursion.graph) {
        if v.flags & flags::TERMINATE_ON_FIRST_HIT != 0 {
            continue;
        }
        let Some(program) = ctx.pipeline.programs.get(v.program) else {
            continue;
        };
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            "visibility trace searches for the closest hit",
        )
        .with_code(CODE)
        .with_primary(
            v.location.clone(),
            if v.flag_choices.len() > 1 {
                "a choice of flags without `AcceptFirstHitAndEndSearch`"
            } else {
                "no `AcceptFirstHitAndEndSearch` flag"
            },
        )
        .with_note(match v.flag_choices.as_slice() {
            [_, _, ..] => format!(
                "its shaders only record whether the ray hit; ray flags are one of {}",
                v.flag_choices
                    .iter()
                    .map(|f| format!("{f:#x}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => format!(
                "its shaders only record whether the ray hit; ray flags are {:#x}",
                v.flags
            ),
        })
        .with_help(format!("add `{}` to the ray flags", flag_name(program.language)));
        if reported.first(v.program, v.inst, &v.location) {
            out.push(d);
        }
    }
    out
}

/// The flag as the shader's language spells it.
fn flag_name(language: Language) -> &'static str {
    match language {
        Language::Hlsl => "RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH",
        Language::Wgsl => "RAY_FLAG_TERMINATE_ON_FIRST_HIT",
        Language::Glsl => "gl_RayFlagsTerminateOnFirstHitEXT",
        Language::Spirv => "TerminateOnFirstHitKHR",
    }
}
