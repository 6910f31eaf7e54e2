//! `rtlint stack --driver`: create a described pipeline on the device and ask
//! the driver for every shader's stack size, in the stack report's order.

use super::{
    Binding, BindingKind, Context, Group, RayTracingPipeline, RayTracingPipelineDesc, Result,
    ShaderStage, Stage,
};
use crate::pipeline::{HitGroupKind, Pipeline, Slot};
use crate::program::scalar::scalar_size;
use crate::program::Type;
use std::collections::BTreeMap;

/// Descriptor bindings (set 0) and push-constant bytes the pipeline's
/// shaders declare, so the layout matches them.
fn interface(pipeline: &Pipeline) -> (Vec<Binding>, u32) {
    use spirv::StorageClass as C;
    let mut bindings: BTreeMap<u32, BindingKind> = BTreeMap::new();
    let mut push = 0u32;
    for p in &pipeline.programs {
        for g in &p.globals {
            let kind = match (g.storage, p.ty(g.ty)) {
                (C::UniformConstant, Some(Type::AccelerationStructure)) => {
                    BindingKind::AccelerationStructure
                }
                (C::UniformConstant, Some(Type::Image)) => BindingKind::StorageImage,
                (C::StorageBuffer, _) => BindingKind::StorageBuffer,
                (C::Uniform, _) => {
                    if p.decoration(g.ty, spirv::Decoration::BufferBlock).is_some() {
                        BindingKind::StorageBuffer
                    } else {
                        BindingKind::UniformBuffer
                    }
                }
                (C::PushConstant, _) => {
                    let size = scalar_size(p, g.ty).unwrap_or(0);
                    push = push.max(size.next_multiple_of(4) as u32);
                    continue;
                }
                _ => continue,
            };
            if g.set.unwrap_or(0) == 0 {
                if let Some(b) = g.binding {
                    bindings.entry(b).or_insert(kind);
                }
            }
        }
    }
    (
        bindings
            .into_iter()
            .map(|(b, k)| Binding::new(b, k))
            .collect(),
        push,
    )
}

/// The driver's stack size for every shader of the pipeline, by its slot and
/// stage. The pipeline is created with its declared recursion depth, else
/// `depth` (the depth the caller found it needs). Comparing the numbers with
/// the model is the caller's business.
pub fn driver_stack_sizes<'p>(
    ctx: &Context,
    pipeline: &'p Pipeline,
    depth: Option<u32>,
) -> Result<BTreeMap<(Slot, Stage), u64>> {
    let mut stages: Vec<ShaderStage> = Vec::new();
    let mut stage_of = |sref: &'p crate::pipeline::ShaderRef| -> Option<u32> {
        let program = pipeline.program(sref)?;
        if !sref.stage.is_ray_tracing() {
            return None;
        }
        stages.push(ShaderStage {
            spirv: &program.words,
            entry_point: &sref.entry,
            stage: sref.stage,
        });
        Some(stages.len() as u32 - 1)
    };
    // Groups in SBT order: raygen, miss, hit groups, callables.
    let mut groups = Vec::new();
    let mut slot_group: BTreeMap<(u8, usize), u32> = BTreeMap::new();
    for (i, r) in pipeline.raygen.iter().enumerate() {
        if let Some(s) = stage_of(r) {
            slot_group.insert((0, i), groups.len() as u32);
            groups.push(Group::General(s));
        }
    }
    for (i, m) in pipeline.miss.iter().enumerate() {
        if let Some(s) = stage_of(m) {
            slot_group.insert((1, i), groups.len() as u32);
            groups.push(Group::General(s));
        }
    }
    for (i, h) in pipeline.hit_groups.iter().enumerate() {
        let closest_hit = h.closest_hit.as_ref().and_then(&mut stage_of);
        let any_hit = h.any_hit.as_ref().and_then(&mut stage_of);
        slot_group.insert((2, i), groups.len() as u32);
        groups.push(match h.kind {
            HitGroupKind::Triangles => Group::Triangles {
                closest_hit,
                any_hit,
            },
            HitGroupKind::Procedural => Group::Procedural {
                intersection: h.intersection.as_ref().and_then(&mut stage_of).unwrap_or(0),
                closest_hit,
                any_hit,
            },
        });
    }
    for (i, c) in pipeline.callable.iter().enumerate() {
        if let Some(s) = stage_of(c) {
            slot_group.insert((3, i), groups.len() as u32);
            groups.push(Group::General(s));
        }
    }
    let (bindings, push_constant_size) = interface(pipeline);
    let depth = pipeline
        .max_recursion_depth
        .or(depth)
        .unwrap_or(1)
        .min(ctx.limits().max_ray_recursion_depth);
    let rt = RayTracingPipeline::new(
        ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &groups,
            max_recursion_depth: depth,
            bindings: &bindings,
            push_constant_size,
            stack_size: None,
        },
    )?;
    let sizes = rt.group_stack_sizes();
    let mut out = BTreeMap::new();
    for (&(kind, i), &g) in &slot_group {
        let Some(g) = sizes.get(g as usize) else {
            continue;
        };
        let slot = match kind {
            0 => Slot::Raygen(i),
            1 => Slot::Miss(i),
            2 => Slot::HitGroup(i),
            _ => Slot::Callable(i),
        };
        let shaders = match slot {
            Slot::HitGroup(_) => vec![
                (Stage::ClosestHit, g.closest_hit),
                (Stage::AnyHit, g.any_hit),
                (Stage::Intersection, g.intersection),
            ],
            Slot::Raygen(_) => vec![(Stage::RayGeneration, g.general)],
            Slot::Miss(_) => vec![(Stage::Miss, g.general)],
            Slot::Callable(_) => vec![(Stage::Callable, g.general)],
        };
        for (stage, size) in shaders {
            if let Some(size) = size {
                out.insert((slot, stage), size);
            }
        }
    }
    Ok(out)
}
