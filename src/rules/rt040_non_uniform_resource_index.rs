use super::Context;
use crate::analysis::uniformity::{self, pointer_root};
use crate::diag::Diagnostic;
use crate::program::Type;
use crate::shader::Language;
use rspirv::dr::Operand;
use spirv::{Decoration, Op, StorageClass};

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds an array of descriptors (bindless textures, buffers, acceleration
    /// structures) indexed by a value that may differ between invocations, without
    /// the `NonUniform` decoration (`NonUniformResourceIndex` in HLSL,
    /// `nonuniformEXT` in GLSL). A value may differ when it derives from an
    /// invocation's builtins (`InstanceID()`, `gl_InstanceCustomIndexEXT`,
    /// `PrimitiveIndex()`, the launch or thread id), its payload, hit attributes
    /// or callable data, a ray query's results, or a buffer read at such an
    /// index; push constants, uniform-buffer reads at constant places,
    /// constants and `subgroupBroadcastFirst` / `WaveReadLaneFirst` are uniform.
    /// A value chosen under a varying branch is not followed (the analysis errs
    /// towards uniform). WGSL needs no marker: naga adds the decoration itself.
    ///
    /// ## Why is this bad?
    ///
    /// Without the decoration the driver may assume the index is the same for the
    /// whole wave and load one descriptor for all of it. In ray-tracing stages
    /// that is almost never true: one wave runs hits of many instances and
    /// materials. The result is the wrong texture or buffer on some GPUs (AMD in
    /// particular) and correct images on others, so the bug survives testing.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// layout(binding = 3) uniform sampler2D textures[];
    /// vec4 albedo = texture(textures[gl_InstanceCustomIndexEXT], uv);
    /// ```
    ///
    /// Use instead:
    ///
    /// ```glsl
    /// #extension GL_EXT_nonuniform_qualifier : require
    /// vec4 albedo = texture(textures[nonuniformEXT(gl_InstanceCustomIndexEXT)], uv);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Wrap the index in `NonUniformResourceIndex(...)` (HLSL) or
    /// `nonuniformEXT(...)` (GLSL).
    ///
    /// ## Options
    ///
    /// None.
    ///
    /// ## References
    ///
    /// - Vulkan specification, "Shader Resource Descriptor Indexing" (dynamically
    ///   uniform unless decorated `NonUniform`).
    /// - DirectX Raytracing specification: `NonUniformResourceIndex` for indices
    ///   that vary in ray-tracing shaders.
    /// - `GL_EXT_nonuniform_qualifier`.
    "RT040" "non-uniform-resource-index" {
        group: Suspicious,
        summary: "descriptor array indexed by a varying value without NonUniform",
        kind: super::Kind::Module(check),
        analysis: Full,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    let globals: Vec<_> = p
        .globals
        .iter()
        .filter(|g| {
            matches!(
                g.storage,
                StorageClass::UniformConstant | StorageClass::Uniform | StorageClass::StorageBuffer
            ) && matches!(p.ty(g.ty), Some(Type::Array { .. } | Type::RuntimeArray { .. }))
        })
        .collect();
    if globals.is_empty() {
        return Vec::new();
    }
    let varying = uniformity::varying(p);
    let non_uniform = |id: u32| p.decoration(id, Decoration::NonUniform).is_some();
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut users: std::collections::HashMap<u32, Vec<usize>> = std::collections::HashMap::new();
    for (i, inst) in p.insts.iter().enumerate() {
        if p.is_debug_inst(inst) || inst.class.opcode == Op::Name {
            continue;
        }
        for o in &inst.operands {
            if let Operand::IdRef(x) = o {
                users.entry(*x).or_default().push(i);
            }
        }
    }
    for (i, inst) in p.insts.iter().enumerate() {
        if !matches!(inst.class.opcode, Op::AccessChain | Op::InBoundsAccessChain) {
            continue;
        }
        let (Some(Operand::IdRef(base)), Some(Operand::IdRef(index))) =
            (inst.operands.first(), inst.operands.get(1))
        else {
            continue;
        };
        let Some(g) = globals.iter().find(|g| g.id == pointer_root(p, *base) && g.id == *base)
        else {
            continue;
        };
        if !varying.contains(*index) {
            continue;
        }
        let result = inst.result_id.unwrap_or(0);
        // The decoration may sit on the index, the pointer, or what the
        // access reads through it (Slang decorates the sampled image).
        let mut decorated = non_uniform(*index);
        let mut work = vec![result];
        let mut visited = 0;
        while let Some(id) = work.pop() {
            visited += 1;
            if non_uniform(id) {
                decorated = true;
                break;
            }
            if visited > 16 {
                break;
            }
            for &u in users.get(&id).map(Vec::as_slice).unwrap_or(&[]) {
                let ui = &p.insts[u];
                if matches!(
                    ui.class.opcode,
                    Op::Load
                        | Op::SampledImage
                        | Op::Image
                        | Op::CopyObject
                        | Op::AccessChain
                        | Op::InBoundsAccessChain
                ) {
                    work.extend(ui.result_id);
                }
            }
        }
        if decorated {
            continue;
        }
        // One finding per array and index value, whatever the debug info.
        if !seen.insert((g.id, *index)) {
            continue;
        }
        let loc = p.site_location(i);
        let name = p.display_name(g.id);
        let marker = match p.language {
            Language::Hlsl => "`NonUniformResourceIndex(...)`",
            _ => "`nonuniformEXT(...)`",
        };
        out.push(
            ctx.diagnostic(
                &RULE,
                format!("descriptor array `{name}` is indexed by a value that varies between invocations, without `NonUniform`"),
            )
            .with_primary(loc, "indexed here")
            .with_secondary(ctx.resource_location(g.id), "descriptor array declared here")
            .with_subject(format!("descriptor array `{name}`"))
            .with_note("the index derives from a per-invocation value (builtin, payload, attributes, ray query or a buffer read at such an index)")
            .with_help(format!("wrap the index in {marker}")),
        );
    }
    out
}
