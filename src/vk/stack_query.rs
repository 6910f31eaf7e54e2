//! `rtlint stack --driver`: create a described pipeline on the device and ask
//! the driver for every shader's stack size, in the stack report's order.

use super::{
    Context, Error, Group, RayTracingPipeline, RayTracingPipelineDesc, Result, ShaderStage, Stage,
};
use crate::pipeline::{HitGroupKind, Pipeline, Slot};
use std::collections::BTreeMap;

/// The module with an `OpSource` language newer than SPIR-V 1.5's list
/// (WGSL is 10, Slang 11) set to 0, Unknown: it is debug information no
/// driver reads, and older validators reject the module for it.
fn known_source_language(words: &[u32]) -> Vec<u32> {
    let mut out = words.to_vec();
    let mut at = 5;
    while at < out.len() {
        let count = (out[at] >> 16) as usize;
        if count == 0 {
            break;
        }
        // OpSource (3): language, version, ...
        if out[at] & 0xffff == 3 && count >= 3 && out.get(at + 1).is_some_and(|&l| l > 9) {
            out[at + 1] = 0;
        }
        at += count;
    }
    out
}

/// The driver's stack size for every shader of the pipeline, by its slot and
/// stage. The pipeline is created with its declared recursion depth, else
/// `depth` (the depth the caller found it needs). Comparing the numbers with
/// the model is the caller's business. The pipeline layout is reflected
/// from the shaders (every set, descriptor type and push constant they use).
pub fn driver_stack_sizes<'p>(
    ctx: &Context,
    pipeline: &'p Pipeline,
    depth: Option<u32>,
) -> Result<BTreeMap<(Slot, Stage), u64>> {
    let needs = super::missing_requirements(pipeline, ctx.info());
    if !needs.is_empty() {
        return Err(Error::Unsupported(needs.join(", ")));
    }
    let modules: Vec<Vec<u32>> = pipeline
        .programs
        .iter()
        .map(|p| known_source_language(&p.words))
        .collect();
    let mut stages: Vec<ShaderStage> = Vec::new();
    let mut stage_of = |sref: &'p crate::pipeline::ShaderRef| -> Option<u32> {
        pipeline.program(sref)?;
        let words = modules.get(sref.program)?;
        if !sref.stage.is_ray_tracing() {
            return None;
        }
        stages.push(ShaderStage {
            spirv: words,
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
    let interface = super::interface::reflect(pipeline).map_err(Error::Invalid)?;
    let depth = pipeline
        .max_recursion_depth
        .or(depth)
        .unwrap_or(1)
        .min(ctx.limits().max_ray_recursion_depth);
    let rt = RayTracingPipeline::with_interface(
        ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &groups,
            max_recursion_depth: depth,
            bindings: &[],
            push_constant_size: 0,
            stack_size: None,
        },
        &interface,
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

#[cfg(test)]
mod tests {
    use super::known_source_language;

    #[test]
    fn newer_source_languages_become_unknown() {
        // Header, OpSource WGSL (10) version 1, OpCapability Shader.
        let words = [
            0x0723_0203,
            0x0001_0400,
            0,
            8,
            0,
            (3 << 16) | 3,
            10,
            1,
            (2 << 16) | 17,
            1,
        ];
        let out = known_source_language(&words);
        assert_eq!(out[6], 0);
        assert_eq!(out[..6], words[..6]);
        assert_eq!(out[7..], words[7..]);
        // GLSL (2) stays; a truncated module is left alone, not a panic.
        let glsl = [0x0723_0203, 0x0001_0400, 0, 8, 0, (3 << 16) | 3, 2, 460];
        assert_eq!(known_source_language(&glsl), glsl);
        let cut = [0x0723_0203, 0x0001_0400, 0, 8, 0, (9 << 16) | 3, 10];
        assert_eq!(known_source_language(&cut)[6], 0);
        assert!(known_source_language(&[0x0723_0203]).len() == 1);
    }
}
