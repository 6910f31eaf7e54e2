//! The GPU side of a verify case, run in the child process: the scene's
//! acceleration structures, the pipeline from its description, one trace,
//! the image read back.

use crate::pipeline::{HitGroupKind, Pipeline};
use crate::reference::{Params, Scene};
use crate::vk::{
    raw, AccelerationStructure, Binding, BindingKind, Buffer, ComputePipeline, Context, Geometry,
    Group, Instance, RayTracingPipeline, RayTracingPipelineDesc, Resource, ShaderStage,
};
use std::time::{Duration, Instant};

/// The interface every reflection reference shader declares (set 0), and
/// the glossy shader's half-resolution buffer (binding 8; the others leave
/// it unused).
pub const BINDINGS: [Binding; 5] = [
    Binding::new(0, BindingKind::AccelerationStructure),
    Binding::new(1, BindingKind::StorageBuffer),
    Binding::new(2, BindingKind::StorageBuffer),
    Binding::new(3, BindingKind::UniformBuffer),
    Binding::new(HALF_RES_BINDING, BindingKind::StorageBuffer),
];

/// The binding of the glossy shader's half-resolution buffer.
pub const HALF_RES_BINDING: u32 = 8;

/// The glossy shader's half-resolution buffer for `params`' image: one
/// `vec4<f32>` per 2×2 block.
pub fn half_res_buffer(ctx: &Context, params: &Params) -> crate::vk::Result<Buffer> {
    let blocks = u64::from(params.width.div_ceil(2)) * u64::from(params.height.div_ceil(2));
    Buffer::new(ctx, blocks * 16, raw::BufferUsageFlags::STORAGE_BUFFER, 1)
}

/// A scene on the device: one bottom-level structure per mesh, one instance
/// per scene instance with its transform and, as custom index, the index of
/// its first triangle in the `surfaces` buffer.
pub struct GpuScene {
    pub tlas: AccelerationStructure,
    pub surfaces: Buffer,
}

impl GpuScene {
    pub fn new(ctx: &Context, scene: &Scene) -> crate::vk::Result<GpuScene> {
        let mut blases = Vec::new();
        for m in &scene.meshes {
            let positions = m.positions_f32();
            blases.push(AccelerationStructure::bottom_level(
                ctx,
                &[Geometry::Triangles {
                    positions: &positions,
                    indices: &m.indices,
                    opaque: true,
                }],
            )?);
        }
        let instances: Vec<Instance> = scene
            .instances
            .iter()
            .map(|i| Instance {
                transform: i.rows(),
                custom_index: i.first_triangle,
                ..Instance::identity(&blases[i.mesh])
            })
            .collect();
        let tlas = AccelerationStructure::top_level(ctx, &instances)?;
        let surfaces = Buffer::from_data(
            ctx,
            raw::BufferUsageFlags::STORAGE_BUFFER,
            &scene.surface_data(),
        )?;
        Ok(GpuScene { tlas, surfaces })
    }
}

/// What one run measured.
pub struct Rendered {
    pub image: Vec<u32>,
    /// Submission to fence of the trace (includes lavapipe's shader compile).
    pub trace: Duration,
    /// Everything on the device: structures, pipeline, trace, readback.
    pub total: Duration,
}

/// Creates the described pipeline (with `depth` instead of its declared
/// recursion depth when given) and traces `params`' image of `scene`.
pub fn render(
    ctx: &Context,
    pipeline: &Pipeline,
    depth: Option<u32>,
    scene: &Scene,
    params: &Params,
) -> Result<Rendered, String> {
    let start = Instant::now();
    let vk = |e: crate::vk::Error| e.to_string();
    let gpu_scene = GpuScene::new(ctx, scene).map_err(vk)?;
    let rt = ray_tracing_pipeline(ctx, pipeline, depth, scene)?;
    let pixels = u64::from(params.width) * u64::from(params.height);
    let image =
        Buffer::new(ctx, pixels * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).map_err(vk)?;
    let uniform = Buffer::from_data(
        ctx,
        raw::BufferUsageFlags::UNIFORM_BUFFER,
        &params.to_words(),
    )
    .map_err(vk)?;
    let half = half_res_buffer(ctx, params).map_err(vk)?;
    let resources = [
        (0, Resource::AccelerationStructure(&gpu_scene.tlas)),
        (1, Resource::Buffer(&image)),
        (2, Resource::Buffer(&gpu_scene.surfaces)),
        (3, Resource::Buffer(&uniform)),
        (HALF_RES_BINDING, Resource::Buffer(&half)),
    ];
    let trace = rt
        .trace_rays(&resources, params.width, params.height, 1)
        .map_err(vk)?;
    Ok(Rendered {
        image: image.read_u32(),
        trace,
        total: start.elapsed(),
    })
}

/// The described pipeline on the device (with `depth` instead of its
/// declared recursion depth when given), with only the groups `scene` needs.
pub fn ray_tracing_pipeline<'p>(
    ctx: &Context,
    pipeline: &'p Pipeline,
    depth: Option<u32>,
    scene: &Scene,
) -> Result<RayTracingPipeline, String> {
    let vk = |e: crate::vk::Error| e.to_string();
    let mut stages: Vec<ShaderStage<'p>> = Vec::new();
    let mut groups = Vec::new();
    let mut add = |s: &'p crate::pipeline::ShaderRef| -> Result<u32, String> {
        let program = pipeline
            .program(s)
            .ok_or_else(|| format!("{}: no program for `{}`", s.file.display(), s.entry))?;
        stages.push(ShaderStage {
            spirv: &program.words,
            entry_point: &s.entry,
            stage: s.stage,
        });
        Ok(stages.len() as u32 - 1)
    };
    // Only what the scene needs: without a light no shadow ray is traced, so
    // the shadow miss shaders (every miss after the first) are left out.
    let misses = if scene.light.is_some() {
        &pipeline.miss[..]
    } else {
        &pipeline.miss[..pipeline.miss.len().min(1)]
    };
    for s in pipeline.raygen.iter().chain(misses) {
        groups.push(Group::General(add(s)?));
    }
    for g in &pipeline.hit_groups {
        if g.kind != HitGroupKind::Triangles {
            return Err("verify builds triangle hit groups only".into());
        }
        let closest_hit = g.closest_hit.as_ref().map(&mut add).transpose()?;
        let any_hit = g.any_hit.as_ref().map(&mut add).transpose()?;
        groups.push(Group::Triangles {
            closest_hit,
            any_hit,
        });
    }
    RayTracingPipeline::new(
        ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &groups,
            max_recursion_depth: depth.or(pipeline.max_recursion_depth).unwrap_or(1),
            bindings: &BINDINGS,
            push_constant_size: 0,
            stack_size: None,
        },
    )
    .map_err(vk)
}

/// Dispatches the compute shader `entry` (8 × 8 workgroups, one invocation
/// per pixel) over `params`' image of `scene`.
pub fn render_compute(
    ctx: &Context,
    words: &[u32],
    entry: &str,
    scene: &Scene,
    params: &Params,
) -> Result<Rendered, String> {
    let start = Instant::now();
    let vk = |e: crate::vk::Error| e.to_string();
    let gpu_scene = GpuScene::new(ctx, scene).map_err(vk)?;
    let pipeline = ComputePipeline::new(ctx, words, entry, &BINDINGS).map_err(vk)?;
    let pixels = u64::from(params.width) * u64::from(params.height);
    let image =
        Buffer::new(ctx, pixels * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).map_err(vk)?;
    let uniform = Buffer::from_data(
        ctx,
        raw::BufferUsageFlags::UNIFORM_BUFFER,
        &params.to_words(),
    )
    .map_err(vk)?;
    let half = half_res_buffer(ctx, params).map_err(vk)?;
    let resources = [
        (0, Resource::AccelerationStructure(&gpu_scene.tlas)),
        (1, Resource::Buffer(&image)),
        (2, Resource::Buffer(&gpu_scene.surfaces)),
        (3, Resource::Buffer(&uniform)),
        (HALF_RES_BINDING, Resource::Buffer(&half)),
    ];
    let trace = pipeline
        .dispatch(
            &resources,
            params.width.div_ceil(8),
            params.height.div_ceil(8),
            1,
        )
        .map_err(vk)?;
    Ok(Rendered {
        image: image.read_u32(),
        trace,
        total: start.elapsed(),
    })
}
