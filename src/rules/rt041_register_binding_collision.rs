use super::Context;
use crate::diag::Diagnostic;
use crate::program::{Global, Program, Type};
use crate::shader::Language;
use rspirv::dr::Operand;
use spirv::{Decoration, Op, StorageClass};
use std::collections::BTreeMap;

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds two resources of different descriptor types bound to the same
    /// Vulkan descriptor set and binding: a texture and a UAV, a constant buffer
    /// and a structured buffer, an acceleration structure and anything else. A
    /// sampled image and a sampler may share a binding (a combined image
    /// sampler), and resources of one type may alias each other; neither is
    /// reported.
    ///
    /// ## Why is this bad?
    ///
    /// A binding of a descriptor set layout has one descriptor type. HLSL keeps a
    /// separate register space per class (`t0`, `u0`, `b0`, `s0` are four
    /// registers), but DXC, Slang and rtlint map `register(xN, spaceM)` to
    /// binding `N` of set `M` whatever the class unless told otherwise, so a
    /// shader ported from DXR puts its TLAS (`t0`) and its output UAV (`u0`) on
    /// the same binding. `spirv-val` accepts the module; pipeline creation fails
    /// validation, and without validation layers one of the two resources reads
    /// the other's descriptor.
    ///
    /// ## Example
    ///
    /// ```hlsl
    /// RaytracingAccelerationStructure scene : register(t0);
    /// RWTexture2D<float4> output : register(u0);      // binding 0 of set 0 as well
    /// ```
    ///
    /// Use instead:
    ///
    /// ```hlsl
    /// RaytracingAccelerationStructure scene : register(t0);
    /// [[vk::binding(1, 0)]] RWTexture2D<float4> output : register(u0);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Give one of the resources its own binding: `[[vk::binding(N, S)]]`,
    /// another register number, or a shift option of the compiler
    /// (`-fvk-u-shift`, `-fvk-t-shift`, …).
    ///
    /// ## When it runs on HLSL
    ///
    /// GLSL, WGSL and SPIR-V modules are Vulkan code, and every collision is
    /// reported. HLSL is also written for D3D12 alone, where registers of
    /// different classes never collide, so an HLSL source is checked only when
    /// it shows it is meant for Vulkan: a `vk::` attribute or intrinsic
    /// (`[[vk::binding]]`, `[[vk::push_constant]]`, `vk::RawBufferLoad`, …)
    /// in the file or its headers, a DXC command line that builds for Vulkan
    /// (`-spirv`, any `-fspv-*` or `-fvk-*` option, given to `rtlint` or in
    /// `[hlsl] args`), or the option `vulkan = true`. The build API
    /// (`rtlint::build`), whose output is SPIR-V for Vulkan, always checks. A
    /// SPIR-V module compiled from HLSL is a Vulkan build and always checked.
    /// The collision is judged after the command line's register mapping
    /// (`-fvk-t-shift 1000 all` separates `t0` from `u0`), since rtlint
    /// compiles with it. (Measured: all 47 findings on public HLSL without
    /// such a sign were D3D12-only code; `docs/rules-precision.md`.)
    ///
    /// ## Options
    ///
    /// - `vulkan` (default `false`): check HLSL sources that show no sign of
    ///   Vulkan too. Passing the build's DXC options (`-spirv`, its
    ///   `-fvk-*-shift`s) to `rtlint` or in `[hlsl] args` sets it.
    ///
    /// ## References
    ///
    /// - DXC, "SPIR-V codegen": HLSL register and Vulkan binding mapping,
    ///   `[[vk::binding]]`, `-fvk-*-shift`.
    /// - Vulkan specification, "Descriptor Set Layout" (one type per binding).
    "RT041" "register-binding-collision" {
        group: Suspicious,
        summary: "resources of different descriptor types share one set and binding",
        kind: super::Kind::Module(check),
        analysis: Fast,
        options: [super::RuleOption {
            name: "vulkan",
            default: "false",
            doc: "check HLSL sources without `vk::` attributes too (a build that compiles them with `-spirv`)",
        }],
    }
}

/// Whether the module is Vulkan code: not HLSL, a SPIR-V build of HLSL, an
/// HLSL source that uses `vk::`, or the option says so.
fn meant_for_vulkan(ctx: &Context) -> bool {
    let p = ctx.program;
    if p.language != Language::Hlsl || p.path.extension().is_some_and(|e| e == "spv") {
        return true;
    }
    let option = ctx
        .config
        .option(RULE.code, RULE.name, "vulkan")
        .and_then(|v| v.as_bool());
    if option == Some(true) {
        return true;
    }
    // The sources debug info names, and the input itself (a module without
    // debug info names none).
    let own = crate::shader::read_source_text(&p.path).unwrap_or_default();
    std::iter::once(own)
        .chain(p.files.iter().map(|f| match &f.text {
            Some(t) => t.clone(),
            None => crate::shader::read_source_text(&f.path).unwrap_or_default(),
        }))
        .any(|text| {
            // Code, not a comment that mentions Vulkan.
            text.lines()
                .any(|l| l.split("//").next().is_some_and(|code| code.contains("vk::")))
        })
}

/// A descriptor type, as far as a binding's compatibility goes.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Sampler,
    SampledImage,
    CombinedImageSampler,
    StorageImage,
    UniformTexelBuffer,
    StorageTexelBuffer,
    UniformBuffer,
    StorageBuffer,
    AccelerationStructure,
}

impl Kind {
    fn as_str(self) -> &'static str {
        match self {
            Kind::Sampler => "sampler",
            Kind::SampledImage => "sampled image",
            Kind::CombinedImageSampler => "combined image sampler",
            Kind::StorageImage => "storage image",
            Kind::UniformTexelBuffer => "uniform texel buffer",
            Kind::StorageTexelBuffer => "storage texel buffer",
            Kind::UniformBuffer => "uniform buffer",
            Kind::StorageBuffer => "storage buffer",
            Kind::AccelerationStructure => "acceleration structure",
        }
    }

    /// Whether two kinds can live on one binding.
    fn compatible(self, other: Kind) -> bool {
        use Kind::*;
        self == other
            || matches!(
                (self, other),
                (Sampler, SampledImage)
                    | (SampledImage, Sampler)
                    | (Sampler, CombinedImageSampler)
                    | (CombinedImageSampler, Sampler)
                    | (SampledImage, CombinedImageSampler)
                    | (CombinedImageSampler, SampledImage)
            )
    }
}

fn kind(p: &Program, g: &Global) -> Option<Kind> {
    let mut ty = g.ty;
    for _ in 0..4 {
        match p.ty(ty)? {
            Type::Array { elem, .. } | Type::RuntimeArray { elem } => ty = *elem,
            _ => break,
        }
    }
    match (g.storage, p.ty(ty)?) {
        (StorageClass::StorageBuffer, _) => Some(Kind::StorageBuffer),
        (StorageClass::Uniform, _) if p.decoration(ty, Decoration::BufferBlock).is_some() => {
            Some(Kind::StorageBuffer)
        }
        (StorageClass::Uniform, _) => Some(Kind::UniformBuffer),
        (StorageClass::UniformConstant, Type::AccelerationStructure) => {
            Some(Kind::AccelerationStructure)
        }
        (StorageClass::UniformConstant, Type::Sampler) => Some(Kind::Sampler),
        (StorageClass::UniformConstant, Type::SampledImage) => Some(Kind::CombinedImageSampler),
        (StorageClass::UniformConstant, Type::Image) => {
            let inst = p.def(ty)?;
            if inst.class.opcode != Op::TypeImage {
                return None;
            }
            // Sampled Type, Dim, Depth, Arrayed, MS, Sampled, Format.
            let buffer = matches!(inst.operands.get(1), Some(Operand::Dim(spirv::Dim::DimBuffer)));
            let storage = matches!(inst.operands.get(5), Some(Operand::LiteralBit32(2)));
            Some(match (buffer, storage) {
                (true, true) => Kind::StorageTexelBuffer,
                (true, false) => Kind::UniformTexelBuffer,
                (false, true) => Kind::StorageImage,
                (false, false) => Kind::SampledImage,
            })
        }
        _ => None,
    }
}

fn check(ctx: &Context) -> Vec<Diagnostic> {
    let p = ctx.program;
    if !meant_for_vulkan(ctx) {
        return Vec::new();
    }
    let mut by_slot: BTreeMap<(u32, u32), Vec<(&Global, Kind)>> = BTreeMap::new();
    for g in &p.globals {
        let (Some(set), Some(binding)) = (g.set, g.binding) else {
            continue;
        };
        if let Some(k) = kind(p, g) {
            by_slot.entry((set, binding)).or_default().push((g, k));
        }
    }
    let mut out = Vec::new();
    for ((set, binding), mut vars) in by_slot {
        // By name: compilers order their globals differently.
        vars.sort_by_key(|(g, _)| (p.display_name(g.id), g.id));
        let Some(&(first, k0)) = vars.first() else {
            continue;
        };
        let Some(&(other, k1)) = vars.iter().skip(1).find(|(_, k)| !k.compatible(k0)) else {
            continue;
        };
        let (a, b) = (p.display_name(first.id), p.display_name(other.id));
        let mut d = ctx
            .diagnostic(
                &RULE,
                format!(
                    "`{b}` ({}) and `{a}` ({}) share descriptor set {set} binding {binding}",
                    k1.as_str(),
                    k0.as_str()
                ),
            )
            .with_primary(ctx.resource_location(other.id), "bound here")
            .with_secondary(ctx.resource_location(first.id), "same set and binding as this")
            .with_subject(format!("`{a}` and `{b}`"));
        if p.language == Language::Hlsl {
            d = d.with_note("HLSL register classes (`t`, `u`, `b`, `s`) map to the same Vulkan binding number without `[[vk::binding]]` or a shift option");
        }
        out.push(d.with_help("give one of them its own binding"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use std::path::Path;

    /// D3D12-only HLSL is checked when the configuration says the build
    /// targets Vulkan.
    #[test]
    fn the_vulkan_option_checks_hlsl_without_vk_attributes() {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/RT041/good_d3d12_only.hlsl");
        let p = crate::front::load(&path, Language::Hlsl).unwrap();
        let mut config = Config::default();
        assert!(check(&Context::new(&p, &config)).is_empty());
        config.set_option("RT041", "vulkan", toml::Value::Boolean(true));
        let lines: Vec<u32> = check(&Context::new(&p, &config))
            .iter()
            .map(|d| d.primary.as_ref().unwrap().location.line)
            .collect();
        assert_eq!(lines, [8, 13]);
    }
}
