//! The resource interface of a described pipeline, reflected from its
//! SPIR-V so that the pipeline layout a driver gets matches the shaders:
//! every descriptor set and binding with its descriptor type and count
//! (arrays, runtime arrays), the stages that use it, the push-constant
//! range, and the shader-record bytes the shaders read.
//!
//! Pure: no Vulkan here; `descriptors.rs` turns it into layouts.

use crate::pipeline::{Pipeline, ShaderRef};
use crate::program::{Id, Program, Type};
use crate::shader::Stage;
use spirv::StorageClass as C;
use std::collections::{BTreeMap, BTreeSet, HashSet};

/// A Vulkan descriptor type, as the shaders declare it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum DescriptorKind {
    Sampler,
    CombinedImageSampler,
    SampledImage,
    StorageImage,
    UniformTexelBuffer,
    StorageTexelBuffer,
    UniformBuffer,
    StorageBuffer,
    AccelerationStructure,
}

/// How many descriptors a binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DescriptorCount {
    Fixed(u32),
    /// A runtime array (`T name[]`): the layout gives it a count of its own
    /// choosing, and the device needs `runtimeDescriptorArray`.
    Runtime,
}

impl std::fmt::Display for DescriptorCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DescriptorCount::Fixed(n) => write!(f, "{n}"),
            DescriptorCount::Runtime => f.write_str("a runtime array"),
        }
    }
}

/// One binding of the reflected layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LayoutBinding {
    pub set: u32,
    pub binding: u32,
    pub kind: DescriptorKind,
    pub count: DescriptorCount,
    /// Every stage whose entry point uses it.
    pub stages: BTreeSet<Stage>,
}

/// What the pipeline layout and shader binding table must provide.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PipelineInterface {
    /// Sorted by set, then binding.
    pub bindings: Vec<LayoutBinding>,
    /// Bytes of push constants read (0 for none), from offset 0.
    pub push_constant_size: u32,
    pub push_constant_stages: BTreeSet<Stage>,
    /// The largest shader-record block any shader reads, in bytes.
    pub shader_record_size: u32,
}

impl PipelineInterface {
    /// Whether some binding is a runtime array.
    pub fn has_runtime_array(&self) -> bool {
        self.bindings
            .iter()
            .any(|b| b.count == DescriptorCount::Runtime)
    }

    /// The number of descriptor sets the layout needs (highest set + 1).
    pub fn set_count(&self) -> u32 {
        self.bindings.iter().map(|b| b.set + 1).max().unwrap_or(0)
    }
}

/// The interface of every ray-tracing shader in the pipeline, merged the way
/// an application's pipeline layout serves all its stages: one binding per
/// set and binding, with the largest count any shader declares (a runtime
/// array wins: the layout gives it a count of its own), and the stages whose
/// entry points use it. A global an entry point lists in its interface but
/// never references (glslang lists every global of a shared header there,
/// SPIR-V 1.4 and later) does not constrain the binding's type; two shaders
/// that both use one binding as different descriptor types are an error: no
/// layout serves both.
pub fn reflect(pipeline: &Pipeline) -> Result<PipelineInterface, String> {
    let mut shaders: Vec<&ShaderRef> = Vec::new();
    shaders.extend(&pipeline.raygen);
    shaders.extend(&pipeline.miss);
    for h in &pipeline.hit_groups {
        shaders.extend(h.closest_hit.iter());
        shaders.extend(h.any_hit.iter());
        shaders.extend(h.intersection.iter());
    }
    shaders.extend(&pipeline.callable);
    let mut out = PipelineInterface::default();
    let mut declared: BTreeMap<(u32, u32), Vec<Declaration>> = BTreeMap::new();
    for s in shaders {
        let Some(program) = pipeline.program(s) else {
            continue;
        };
        let (referenced, listed) = used_globals(program, s);
        for g in program.globals.iter() {
            let used = referenced.contains(&g.id);
            if !used && !listed.contains(&g.id) {
                continue;
            }
            let who = format!("{} `{}` ({})", s.stage.as_str(), s.entry, s.file.display());
            match g.storage {
                C::PushConstant => {
                    let size = block_extent(program, g.ty).ok_or_else(|| {
                        format!(
                            "{who}: cannot size push-constant block `{}`",
                            program.display_name(g.id)
                        )
                    })?;
                    out.push_constant_size = out.push_constant_size.max(size.next_multiple_of(4));
                    out.push_constant_stages.insert(s.stage);
                    continue;
                }
                C::ShaderRecordBufferKHR => {
                    let size = block_extent(program, g.ty).unwrap_or(0);
                    out.shader_record_size = out.shader_record_size.max(size);
                    continue;
                }
                C::UniformConstant | C::Uniform | C::StorageBuffer => {}
                _ => continue,
            }
            let Some((kind, count)) = descriptor(program, g.storage, g.ty)? else {
                continue;
            };
            let (Some(set), Some(binding)) = (g.set, g.binding) else {
                return Err(format!(
                    "{who}: resource `{}` has no descriptor set or binding decoration",
                    program.display_name(g.id)
                ));
            };
            let hlsl = program.language == crate::shader::Language::Hlsl;
            declared
                .entry((set, binding))
                .or_default()
                .push(Declaration {
                    kind,
                    count,
                    used,
                    stage: s.stage,
                    who: format!("`{}` in {who}", program.display_name(g.id)),
                    hlsl,
                });
        }
    }
    for ((set, binding), decls) in declared {
        out.bindings.push(merge(set, binding, &decls)?);
    }
    Ok(out)
}

/// One shader's declaration of a set and binding.
struct Declaration {
    kind: DescriptorKind,
    count: DescriptorCount,
    /// Referenced by a function the entry point reaches, not only listed in
    /// its interface.
    used: bool,
    stage: Stage,
    /// The variable and the shader, for messages.
    who: String,
    /// Compiled from HLSL (registers t, s, u, b all map to bindings).
    hlsl: bool,
}

/// The layout binding that serves every declaration of one set and binding.
fn merge(set: u32, binding: u32, decls: &[Declaration]) -> Result<LayoutBinding, String> {
    // The type: what the shaders that use the binding say; only listed
    // declarations (unused) follow, and cannot veto it.
    let used: Vec<&Declaration> = decls.iter().filter(|d| d.used).collect();
    let decider = used.first().copied().unwrap_or(&decls[0]);
    if let Some(other) = used.iter().find(|d| d.kind != decider.kind) {
        let mut message = format!(
            "set {set}, binding {binding} is {} for {} but {} for {}: no pipeline layout serves both",
            decider.kind, decider.who, other.kind, other.who
        );
        if decider.hlsl || other.hlsl {
            message.push_str(&format!(
                "; HLSL registers t, s, u and b of one number share a binding when compiled for Vulkan (as DXC does): \
                 shift one register class into a range of its own ({} or {}) or declare `[[vk::binding(N, {set})]]`",
                decider.kind.shift_option(),
                other.kind.shift_option()
            ));
        }
        return Err(message);
    }
    let mut runtime = false;
    let mut fixed = 1;
    let mut stages = BTreeSet::new();
    for d in decls.iter().filter(|d| d.kind == decider.kind) {
        match d.count {
            DescriptorCount::Runtime => runtime = true,
            DescriptorCount::Fixed(n) => fixed = fixed.max(n),
        }
        if d.used || used.is_empty() {
            stages.insert(d.stage);
        }
    }
    // A runtime array takes whatever count the layout gives; the runtime
    // count the layout uses must still cover a larger fixed array elsewhere.
    let count = if runtime && fixed <= super::pipeline::RUNTIME_ARRAY_COUNT {
        DescriptorCount::Runtime
    } else {
        DescriptorCount::Fixed(fixed)
    };
    Ok(LayoutBinding {
        set,
        binding,
        kind: decider.kind,
        count,
        stages,
    })
}

impl DescriptorKind {
    /// DXC's register-shift option for the register class this descriptor
    /// type comes from in HLSL.
    fn shift_option(self) -> &'static str {
        use DescriptorKind::*;
        match self {
            Sampler => "`-fvk-s-shift N SET`",
            UniformBuffer => "`-fvk-b-shift N SET`",
            StorageImage | StorageTexelBuffer => "`-fvk-u-shift N SET`",
            // Read-only structured and byte-address buffers are t registers
            // too; a read-write one is u: name both.
            StorageBuffer => "`-fvk-t-shift N SET` / `-fvk-u-shift N SET`",
            CombinedImageSampler | SampledImage | UniformTexelBuffer | AccelerationStructure => {
                "`-fvk-t-shift N SET`"
            }
        }
    }
}

impl std::fmt::Display for DescriptorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use DescriptorKind::*;
        f.write_str(match self {
            Sampler => "a sampler",
            CombinedImageSampler => "a combined image sampler",
            SampledImage => "a sampled image",
            StorageImage => "a storage image",
            UniformTexelBuffer => "a uniform texel buffer",
            StorageTexelBuffer => "a storage texel buffer",
            UniformBuffer => "a uniform buffer",
            StorageBuffer => "a storage buffer",
            AccelerationStructure => "an acceleration structure",
        })
    }
}

/// The globals an entry point references from a function it reaches, and
/// those it only lists in its interface.
fn used_globals(program: &Program, s: &ShaderRef) -> (HashSet<Id>, HashSet<Id>) {
    let globals: HashSet<Id> = program.globals.iter().map(|g| g.id).collect();
    let mut listed = HashSet::new();
    if let Some(e) = program
        .entry_points
        .iter()
        .find(|e| e.name == s.entry && e.stage == s.stage)
    {
        listed.extend(e.interface.iter().copied().filter(|i| globals.contains(i)));
    }
    let mut used = HashSet::new();
    for f in program.reachable_functions(s.function) {
        let Some(f) = program.function(f) else {
            continue;
        };
        for inst in &program.insts[f.start..=f.end] {
            for op in &inst.operands {
                if let rspirv::dr::Operand::IdRef(id) = op {
                    if globals.contains(id) {
                        used.insert(*id);
                    }
                }
            }
        }
    }
    (used, listed)
}

/// The descriptor type and count of a resource variable of type `ty`;
/// `None` for variables that are no descriptor.
fn descriptor(
    program: &Program,
    storage: C,
    ty: Id,
) -> Result<Option<(DescriptorKind, DescriptorCount)>, String> {
    let (elem, count) = match program.ty(ty) {
        Some(Type::Array { elem, len }) => {
            let n = len
                .value()
                .and_then(|n| u32::try_from(n).ok())
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("a descriptor array of type %{ty} has no usable length"))?;
            (*elem, DescriptorCount::Fixed(n))
        }
        Some(Type::RuntimeArray { elem }) => (*elem, DescriptorCount::Runtime),
        _ => (ty, DescriptorCount::Fixed(1)),
    };
    let kind = match (storage, program.ty(elem)) {
        (C::UniformConstant, Some(Type::AccelerationStructure)) => {
            DescriptorKind::AccelerationStructure
        }
        (C::UniformConstant, Some(Type::Sampler)) => DescriptorKind::Sampler,
        (C::UniformConstant, Some(Type::SampledImage)) => {
            // glslang declares `samplerBuffer` as a sampled image of a
            // buffer image: Vulkan binds that as a uniform texel buffer.
            let image = program.def(elem).and_then(|i| match i.operands.first() {
                Some(rspirv::dr::Operand::IdRef(id)) => Some(*id),
                _ => None,
            });
            match image.map(|i| image_kind(program, i)).transpose()? {
                Some(DescriptorKind::UniformTexelBuffer) => DescriptorKind::UniformTexelBuffer,
                _ => DescriptorKind::CombinedImageSampler,
            }
        }
        (C::UniformConstant, Some(Type::Image)) => image_kind(program, elem)?,
        (C::UniformConstant, _) => return Ok(None),
        (C::StorageBuffer, _) => DescriptorKind::StorageBuffer,
        (C::Uniform, _) => {
            if program
                .decoration(elem, spirv::Decoration::BufferBlock)
                .is_some()
            {
                DescriptorKind::StorageBuffer
            } else {
                DescriptorKind::UniformBuffer
            }
        }
        _ => return Ok(None),
    };
    Ok(Some((kind, count)))
}

/// Sampled or storage image, uniform or storage texel buffer, from the
/// `OpTypeImage` operands (Dim, Sampled).
fn image_kind(program: &Program, ty: Id) -> Result<DescriptorKind, String> {
    use rspirv::dr::Operand as O;
    let inst = program
        .def(ty)
        .ok_or_else(|| format!("image type %{ty} has no definition"))?;
    let dim = inst.operands.iter().find_map(|o| match o {
        O::Dim(d) => Some(*d),
        _ => None,
    });
    // Operands: sampled type, Dim, Depth, Arrayed, MS, Sampled, format.
    let sampled = match inst.operands.get(5) {
        Some(O::LiteralBit32(v)) => *v,
        _ => 0,
    };
    Ok(match (dim, sampled) {
        (Some(spirv::Dim::DimBuffer), 2) => DescriptorKind::StorageTexelBuffer,
        (Some(spirv::Dim::DimBuffer), _) => DescriptorKind::UniformTexelBuffer,
        (Some(spirv::Dim::DimSubpassData), _) => {
            return Err("a subpass input has no place in a ray-tracing pipeline".into())
        }
        (_, 2) => DescriptorKind::StorageImage,
        _ => DescriptorKind::SampledImage,
    })
}

/// The bytes a block (push constants, shader record) spans: the end of its
/// last member by its `Offset` decoration, else its scalar size.
fn block_extent(program: &Program, ty: Id) -> Option<u32> {
    let size = match program.ty(ty)? {
        Type::Struct { members } => {
            let mut end = 0u64;
            for (i, &m) in members.iter().enumerate() {
                let offset = program
                    .member_decoration(ty, i as u32, spirv::Decoration::Offset)
                    .and_then(|v| v.first().copied())
                    .map(u64::from);
                let offset = match offset {
                    Some(o) => o,
                    None => {
                        return crate::program::scalar::scalar_size(program, ty)
                            .and_then(|s| u32::try_from(s).ok())
                    }
                };
                end = end.max(offset + member_size(program, ty, i as u32, m)?);
            }
            end
        }
        _ => crate::program::scalar::scalar_size(program, ty)?,
    };
    u32::try_from(size).ok()
}

/// A member's size, honouring matrix and array strides.
fn member_size(program: &Program, parent: Id, index: u32, ty: Id) -> Option<u64> {
    let scalar = crate::program::scalar::scalar_size;
    match program.ty(ty)? {
        Type::Matrix { columns, column } => {
            match program
                .member_decoration(parent, index, spirv::Decoration::MatrixStride)
                .and_then(|v| v.first().copied())
            {
                Some(stride) => {
                    let col = scalar(program, *column)?;
                    let row_major = program
                        .member_decoration(parent, index, spirv::Decoration::RowMajor)
                        .is_some();
                    if row_major {
                        // Rows of `columns` elements, one per column component.
                        let rows = match program.ty(*column)? {
                            Type::Vector { count, .. } => u64::from(*count),
                            _ => 1,
                        };
                        let elem = col / rows.max(1);
                        Some((rows - 1) * u64::from(stride) + u64::from(*columns) * elem)
                    } else {
                        Some(u64::from(*columns - 1) * u64::from(stride) + col)
                    }
                }
                None => scalar(program, ty),
            }
        }
        Type::Array { elem, len } => match program
            .decoration(ty, spirv::Decoration::ArrayStride)
            .and_then(|v| v.first().copied())
        {
            Some(stride) => {
                let n = len.value()?;
                Some(n.saturating_sub(1) * u64::from(stride) + scalar(program, *elem)?)
            }
            None => scalar(program, ty),
        },
        _ => scalar(program, ty),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn load(rel: &str) -> Pipeline {
        crate::pipeline::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
    }

    /// A user reads the conflict in words, not Rust's debug text.
    #[test]
    fn conflicting_bindings_are_told_without_debug_text() {
        let dir = std::env::temp_dir().join(format!("rtlint-iface-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let gen = dir.join("gen.hlsl");
        let hit = dir.join("hit.hlsl");
        std::fs::write(
            &gen,
            "RaytracingAccelerationStructure s : register(t0, space1);\nRWTexture2D<float4> img : register(u0);\nstruct P { float4 c; };\n[shader(\"raygeneration\")] void G() { RayDesc r = { float3(0,0,0), 0, float3(0,0,1), 1 }; P p = { float4(0,0,0,0) }; TraceRay(s, 0, 0xFF, 0, 1, 0, r, p); img[uint2(0,0)] = p.c; }\n",
        )
        .unwrap();
        std::fs::write(
            &hit,
            "RWStructuredBuffer<float4> buf[] : register(u0);\nstruct P { float4 c; };\n[shader(\"closesthit\")] void H(inout P p, BuiltInTriangleIntersectionAttributes a) { p.c = buf[0][0]; }\n",
        )
        .unwrap();
        let programs = [&gen, &hit]
            .iter()
            .map(|p| crate::front::load(p, crate::shader::Language::Hlsl).unwrap())
            .collect();
        let e = reflect(&Pipeline::from_programs(programs)).unwrap_err();
        let _ = std::fs::remove_dir_all(&dir);
        assert!(e.contains("binding 0"), "{e}");
        assert!(
            e.contains("a storage image for `img`") && e.contains("a storage buffer for `buf`"),
            "{e}"
        );
        assert!(!e.contains("Fixed") && !e.contains("Runtime"), "{e}");
    }

    #[test]
    fn hlsl_texture_in_space1_and_bindless_array_in_space2() {
        let i = reflect(&load("fixtures/pipelines/textured_hlsl.pipeline.toml")).unwrap();
        let got: Vec<(u32, u32, DescriptorKind, DescriptorCount, Vec<Stage>)> = i
            .bindings
            .iter()
            .map(|b| {
                (
                    b.set,
                    b.binding,
                    b.kind,
                    b.count,
                    b.stages.iter().copied().collect(),
                )
            })
            .collect();
        use DescriptorCount::*;
        use DescriptorKind::*;
        assert_eq!(
            got,
            [
                (
                    0,
                    0,
                    AccelerationStructure,
                    Fixed(1),
                    vec![Stage::RayGeneration]
                ),
                (0, 1, StorageImage, Fixed(1), vec![Stage::RayGeneration]),
                (0, 2, UniformBuffer, Fixed(1), vec![Stage::RayGeneration]),
                (1, 0, SampledImage, Fixed(1), vec![Stage::ClosestHit]),
                (1, 1, Sampler, Fixed(1), vec![Stage::ClosestHit]),
                (2, 0, StorageBuffer, Runtime, vec![Stage::ClosestHit]),
            ]
        );
        assert_eq!(i.set_count(), 3);
        assert!(i.has_runtime_array());
        assert_eq!(i.push_constant_size, 0);
    }

    #[test]
    fn glsl_bindless_arrays_in_four_sets() {
        let i = reflect(&load("fixtures/pipelines/bindless.pipeline.toml")).unwrap();
        use DescriptorCount::*;
        use DescriptorKind::*;
        let got: Vec<(u32, u32, DescriptorKind, DescriptorCount)> = i
            .bindings
            .iter()
            .map(|b| (b.set, b.binding, b.kind, b.count))
            .collect();
        assert_eq!(
            got,
            [
                (0, 0, AccelerationStructure, Fixed(1)),
                (0, 1, StorageImage, Fixed(1)),
                (0, 2, UniformBuffer, Fixed(1)),
                (1, 0, SampledImage, Runtime),
                (1, 1, Sampler, Fixed(1)),
                (2, 0, StorageBuffer, Runtime),
                (2, 1, UniformTexelBuffer, Fixed(1)),
                (2, 2, StorageTexelBuffer, Fixed(1)),
                (2, 3, CombinedImageSampler, Fixed(4)),
                (3, 0, CombinedImageSampler, Fixed(1)),
            ]
        );
        // Push constants in ray generation and closest hit, 8 bytes; the
        // shader record (two uints) read by the closest hit.
        assert_eq!(i.push_constant_size, 8);
        assert_eq!(
            i.push_constant_stages.iter().copied().collect::<Vec<_>>(),
            [Stage::RayGeneration, Stage::ClosestHit]
        );
        assert_eq!(i.shader_record_size, 8);
        let env = &i.bindings.last().unwrap().stages;
        assert_eq!(env.iter().copied().collect::<Vec<_>>(), [Stage::Miss]);
    }

    #[test]
    fn an_unused_header_array_takes_the_runtime_array_of_the_stage_that_uses_it() {
        // The raygen lists `indices` (an array of one) without using it; the
        // closest hit indexes it as a runtime array: one runtime binding,
        // used by the closest hit only.
        let i = reflect(&load("fixtures/pipelines/shared_header.pipeline.toml")).unwrap();
        let b = i.bindings.iter().find(|b| b.binding == 2).unwrap();
        assert_eq!(b.kind, DescriptorKind::StorageBuffer);
        assert_eq!(b.count, DescriptorCount::Runtime);
        assert_eq!(
            b.stages.iter().copied().collect::<Vec<_>>(),
            [Stage::ClosestHit]
        );
        // The image: used by the raygen, listed by the closest hit.
        let image = i.bindings.iter().find(|b| b.binding == 1).unwrap();
        assert_eq!(
            image.stages.iter().copied().collect::<Vec<_>>(),
            [Stage::RayGeneration]
        );
    }

    fn decl(kind: DescriptorKind, count: DescriptorCount, used: bool, stage: Stage) -> Declaration {
        Declaration {
            kind,
            count,
            used,
            stage,
            who: "`x` in a shader".into(),
            hlsl: false,
        }
    }

    #[test]
    fn the_largest_count_serves_every_declaration() {
        use DescriptorCount::*;
        use DescriptorKind::*;
        let m = |d: &[Declaration]| merge(0, 3, d).unwrap();
        // Fixed arrays: the largest.
        let b = m(&[
            decl(SampledImage, Fixed(4), true, Stage::RayGeneration),
            decl(SampledImage, Fixed(8), true, Stage::ClosestHit),
        ]);
        assert_eq!(b.count, Fixed(8));
        // A runtime array with a small fixed one: a runtime count.
        let b = m(&[
            decl(SampledImage, Fixed(4), true, Stage::RayGeneration),
            decl(SampledImage, Runtime, true, Stage::ClosestHit),
        ]);
        assert_eq!(b.count, Runtime);
        // With a fixed array larger than the runtime count: that many.
        let b = m(&[
            decl(SampledImage, Fixed(64), true, Stage::RayGeneration),
            decl(SampledImage, Runtime, true, Stage::ClosestHit),
        ]);
        assert_eq!(b.count, Fixed(64));
        // An unused declaration of another type neither decides the type nor
        // adds its stage; one of the same type still counts.
        let b = m(&[
            decl(UniformBuffer, Fixed(1), false, Stage::Miss),
            decl(StorageBuffer, Fixed(2), false, Stage::RayGeneration),
            decl(StorageBuffer, Fixed(1), true, Stage::ClosestHit),
        ]);
        assert_eq!((b.kind, b.count), (StorageBuffer, Fixed(2)));
        assert_eq!(
            b.stages.iter().copied().collect::<Vec<_>>(),
            [Stage::ClosestHit]
        );
        // Two uses of different types: an error in words.
        let e = merge(
            1,
            0,
            &[
                decl(StorageImage, Fixed(1), true, Stage::RayGeneration),
                decl(UniformBuffer, Fixed(1), true, Stage::ClosestHit),
            ],
        )
        .unwrap_err();
        assert!(
            e.starts_with("set 1, binding 0 is a storage image for"),
            "{e}"
        );
        assert!(e.contains("but a uniform buffer for"), "{e}");
        assert!(!e.contains("-fvk-"), "not HLSL: {e}");
    }

    #[test]
    fn conflicting_declarations_are_an_error() {
        // The same set and binding as a storage image in one shader and a
        // uniform buffer in another: no layout serves both.
        let mut p = load("fixtures/pipelines/bindless.pipeline.toml");
        let rgen = p.raygen[0].program;
        let g = p.programs[rgen]
            .globals
            .iter_mut()
            .find(|g| g.binding == Some(1) && g.set == Some(0))
            .unwrap();
        g.set = Some(3);
        g.binding = Some(0);
        let e = reflect(&p).unwrap_err();
        assert!(e.contains("set 3, binding 0"), "{e}");
        assert!(e.contains("no pipeline layout serves both"), "{e}");
    }
}
