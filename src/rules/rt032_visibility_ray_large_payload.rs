use super::PipelineContext;
use crate::analysis::rays;
use crate::diag::Diagnostic;
use crate::program::scalar::scalar_size;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds visibility traces (see RT030) that pass a payload larger than 4
    /// bytes while the shaders they can run write at most one member of it,
    /// and whose payload type other traces of the pipeline use for more than
    /// a hit flag: the radiance payload reused to read back a single value. A
    /// payload of the visibility trace's own (which may carry inputs such as
    /// a random seed for an any-hit shader) is not reported.
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
    /// own location, and a miss shader that reads that payload type. (Not
    /// reported for WGSL: naga has one miss shader, whose payload type every
    /// trace shares.)
    "RT032" "visibility-ray-large-payload" {
        group: Perf,
        summary: "visibility trace with a payload larger than 4 bytes",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    let g = &ctx.recursion.graph;
    let visibility = rays::visibility_traces(ctx.pipeline, g);
    // Payload types (by the reach analysis's shape) that other traces use
    // for more than a hit flag.
    let shared: Vec<&crate::analysis::layout::Shape> = rays::trace_targets(g)
        .iter()
        .filter(|t| {
            !visibility
                .iter()
                .any(|v| v.program == t.program && v.inst == t.inst)
        })
        .filter_map(|t| g.payloads.traced_known(t.program, t.inst))
        .collect();
    for v in visibility {
        let Some(program) = ctx.pipeline.programs.get(v.program) else {
            continue;
        };
        // naga's WGSL has one miss shader (miss index 0) whose incoming
        // payload type is fixed: a visibility ray cannot have its own payload.
        if program.language == crate::shader::Language::Wgsl {
            continue;
        }
        let Some(ty) = v.payload_ty else { continue };
        let Some(size) = scalar_size(program, ty) else {
            continue;
        };
        if !g
            .payloads
            .traced_known(v.program, v.inst)
            .is_some_and(|s| shared.contains(&s))
        {
            continue;
        }
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
        .with_note(format!(
            "the shaders it can run write only {member}; other traces use the same payload type for more"
        ))
        .with_help("give visibility traces their own 4-byte payload (a `uint` or `bool`)");
        if reported.first(v.program, v.inst, &v.location) {
            out.push(d);
        }
    }
    out
}
