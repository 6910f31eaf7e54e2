use super::PipelineContext;
use crate::analysis::rays;
use crate::diag::Diagnostic;
use crate::program::scalar::scalar_size;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds a trace whose payload differs in type or size from the incoming
    /// payload of a hit or miss shader that a pipeline description connects
    /// to it (the hit groups and miss shaders its SBT operands can select).
    ///
    /// Without a description the rule does not judge: a folder's shaders
    /// are paired with a trace only when their payload type matches, and
    /// the GLSL `layout(location)` that pairs them in a project is not in
    /// the SPIR-V (a module without debug info would answer differently).
    ///
    /// ## Why is this bad?
    ///
    /// The shader reads and writes the caller's payload memory through its
    /// own declaration. A miss shader whose payload is 64 bytes writing into
    /// a 60-byte raygen payload writes past it; a closest hit whose payload
    /// is 56 bytes leaves the caller's last member as it was, or reads
    /// members at other offsets. The Vulkan specification requires the
    /// types to match; drivers do not check. A warning: a description may
    /// connect shaders the application never pairs at run time.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// // raygen
    /// struct Payload { vec3 radiance; vec3 throughput; uint depth; };
    /// layout(location = 0) rayPayloadEXT Payload payload;
    /// // miss
    /// struct Payload { vec3 radiance; vec3 throughput; uint depth; uint seed; };
    /// layout(location = 0) rayPayloadInEXT Payload payload;
    /// ```
    ///
    /// Use instead: one declaration of the payload in a header every stage
    /// includes.
    ///
    /// ## How to fix
    ///
    /// Declare each payload struct once, in a shared header, and include it
    /// from the ray generation, hit and miss shaders.
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Vulkan specification, "Ray Tracing": the payload of a trace and the
    ///   incoming payload of the shaders it invokes must match.
    "RT009" "payload-mismatch" {
        group: Suspicious,
        summary: "trace payload and a reached shader's incoming payload differ",
        kind: super::Kind::Pipeline(check),
        analysis: Full,
    }
}

fn check(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = Vec::new();
    let mut reported = super::Reported::default();
    let graph = &ctx.recursion.graph;
    // The reach analysis keeps the shaders a trace's SBT operands select
    // but whose payload has another shape: those are the mismatches.
    for ((site_program, inst, location), targets) in rays::mismatched_targets(ctx.pipeline, graph)
    {
        let Some(program) = ctx.pipeline.programs.get(site_program) else {
            continue;
        };
        let Some(ty) = rays::trace_payload_ty(program, inst) else {
            continue;
        };
        let size = scalar_size(program, ty);
        let mut differ: Vec<String> = Vec::new();
        for n in targets {
            let shader = &graph.nodes[n].shader;
            let Some(callee) = ctx.pipeline.program(shader) else {
                continue;
            };
            let Some(var) = rays::incoming_payload_var(callee, shader.function) else {
                continue;
            };
            let Some(their) = callee
                .def(var)
                .and_then(|d| d.result_type)
                .and_then(|p| match callee.ty(p) {
                    Some(crate::program::Type::Pointer { pointee, .. }) => Some(*pointee),
                    _ => None,
                })
            else {
                continue;
            };
            let their_size = scalar_size(callee, their);
            let file = shader
                .file
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
                .unwrap_or_default();
            let what = format!(
                "{} `{}` in {} takes `{}` ({})",
                shader.stage.as_str(),
                shader.entry,
                file,
                callee.type_name(their),
                bytes(their_size)
            );
            if !differ.contains(&what) {
                differ.push(what);
            }
        }
        if differ.is_empty() {
            continue;
        }
        let d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            format!(
                "trace payload `{}` ({}) differs from the incoming payload of {} shader{}",
                program.type_name(ty),
                bytes(size),
                differ.len(),
                if differ.len() == 1 { "" } else { "s" }
            ),
        )
        .with_code(CODE)
        .with_primary(location.clone(), "traced with this payload")
        .with_note(differ.join("; "))
        .with_help("declare the payload once in a header every stage includes");
        if reported.first(site_program, inst, &location) {
            out.push(d);
        }
    }
    out
}

fn bytes(size: Option<u64>) -> String {
    size.map_or("size unknown".into(), |s| format!("{s} bytes"))
}
