use super::PipelineContext;
use crate::analysis::rays;
use crate::diag::Diagnostic;
use crate::program::scalar::scalar_size;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds visibility traces (see RT030) that pass a payload larger than 4
    /// bytes while the shaders they can run write at most one member of it:
    /// typically the radiance payload reused to read back a single hit flag.
    ///
    /// ## Why is this bad?
    ///
    /// The whole payload is copied to every shader the ray runs and kept on
    /// the ray stack; the pipeline's stack is sized for its largest payload. A
    /// visibility answer fits in one `uint` (or `bool`), so the extra bytes are
    /// moved for nothing on what is usually the most frequent ray.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// layout(location = 0) rayPayloadEXT HitInfo prd;   // 32 bytes
    /// prd.missed = false;
    /// traceRayEXT(tlas, shadowFlags, 0xFF, 0, 0, 1, p, 0.001, l, d, 0);
    /// if (prd.missed) { ... }
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// layout(location = 1) rayPayloadEXT bool shadowed;
    /// ```
    ///
    /// ## How to fix
    ///
    /// Give visibility traces their own payload of one `uint` or `bool`, at its
    /// own location, and a miss shader that reads that payload type.
    "RT032" "visibility-ray-large-payload" {
        group: Perf,
        summary: "visibility trace with a payload larger than 4 bytes",
        kind: super::Kind::Pipeline(check),
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::new();
    for v in rays::visibility_traces(ctx.pipeline, &ctx.recursion.graph) {
        let Some(program) = ctx.pipeline.programs.get(v.program) else {
            continue;
        };
        let Some(ty) = v.payload_ty else { continue };
        let Some(size) = scalar_size(program, ty) else {
            continue;
        };
        // At most one member written, and not the whole payload.
        if size <= 4 || v.written.len() > 1 || v.written.iter().any(|p| p.is_empty()) {
            continue;
        }
        let member = match v.written.iter().next().and_then(|p| p.first()) {
            Some(&k) if k != u32::MAX => format!("`{}`", program.member_name(ty, k)),
            _ => "one member".to_string(),
        };
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            format!(
                "visibility trace carries payload `{}` of {size} bytes to return one value",
                program.type_name(ty)
            ),
        )
        .with_code(CODE)
        .with_primary(v.location.clone(), "visibility trace")
        .with_note(format!("the shaders it can run write only {member}"))
        .with_help("give visibility traces their own 4-byte payload (a `uint` or `bool`)");
        if !out.iter().any(|o| o.primary == d.primary) {
            out.push(d);
        }
    }
    out
}
