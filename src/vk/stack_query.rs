//! `rtlint stack --driver`: create a described pipeline on the device and ask
//! the driver for every shader's stack size, in the stack report's order.

use super::{
    Binding, BindingKind, Context, Group, RayTracingPipeline, RayTracingPipelineDesc, Result,
    ShaderStage, Stage,
};
use crate::analysis::callgraph::Slot;
use crate::analysis::recursion;
use crate::pipeline::{HitGroupKind, Pipeline};
use crate::spirv::{self, Type};
use spirv::Stage as S;
use std::collections::BTreeMap;

fn vk_stage(s: S) -> Option<Stage> {
    Some(match s {
        S::RayGeneration => Stage::RayGeneration,
        S::Miss => Stage::Miss,
        S::ClosestHit => Stage::ClosestHit,
        S::AnyHit => Stage::AnyHit,
        S::Intersection => Stage::Intersection,
        S::Callable => Stage::Callable,
        _ => return None,
    })
}

/// Descriptor bindings (set 0) and push-constant bytes the pipeline's
/// shaders declare, so the layout matches them.
fn interface(pipeline: &Pipeline) -> (Vec<Binding>, u32) {
    use ::spirv::StorageClass as C;
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
                    if p.decoration(g.ty, ::spirv::Decoration::BufferBlock)
                        .is_some()
                    {
                        BindingKind::StorageBuffer
                    } else {
                        BindingKind::UniformBuffer
                    }
                }
                (C::PushConstant, _) => {
                    let size = crate::analysis::scalar::scalar_size(p, g.ty).unwrap_or(0);
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

/// The driver's stack size for each shader of `recursion(pipeline).graph.nodes`
/// (the order of `StackReport::shaders`).
pub fn driver_stack_sizes<'p>(ctx: &Context, pipeline: &'p Pipeline) -> Result<Vec<Option<u64>>> {
    let rec = recursion(pipeline);
    let mut stages: Vec<ShaderStage> = Vec::new();
    let mut stage_of = |sref: &'p crate::pipeline::ShaderRef| -> Option<u32> {
        let program = pipeline.program(sref)?;
        stages.push(ShaderStage {
            spirv: &program.words,
            entry_point: &sref.entry,
            stage: vk_stage(sref.stage)?,
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
        .or(rec.required_depth)
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
    Ok(rec
        .graph
        .nodes
        .iter()
        .map(|n| {
            let key = match n.slot {
                Slot::Raygen(i) => (0, i),
                Slot::Miss(i) => (1, i),
                Slot::HitGroup(i) => (2, i),
                Slot::Callable(i) => (3, i),
            };
            let g = sizes.get(*slot_group.get(&key)? as usize)?;
            match n.shader.stage {
                S::ClosestHit => g.closest_hit,
                S::AnyHit => g.any_hit,
                S::Intersection => g.intersection,
                _ => g.general,
            }
        })
        .collect())
}
