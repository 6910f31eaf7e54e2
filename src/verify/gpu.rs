//! The GPU side of a verify case, run in the child process: the scene's
//! acceleration structures, the pipeline from its description, one trace,
//! the image read back.

use crate::pipeline::{HitGroupKind, Pipeline, ShaderRef};
use crate::reference::{Params, Scene};
use crate::vk::{
    raw, AccelerationStructure, Binding, BindingKind, Buffer, ComputePipeline, Context, Geometry,
    Group, Instance, RayTracingPipeline, RayTracingPipelineDesc, Resource, ShaderStage,
    StorageImage,
};
use std::time::{Duration, Instant};

/// The interface every reflection reference shader declares (set 0), and
/// the glossy shader's half-resolution buffer (the others leave it unused).
pub const BINDINGS: [Binding; 5] = [
    Binding::new(0, BindingKind::AccelerationStructure),
    Binding::new(1, BindingKind::StorageBuffer),
    Binding::new(2, BindingKind::StorageBuffer),
    Binding::new(3, BindingKind::UniformBuffer),
    Binding::new(HALF_RES_BINDING, BindingKind::StorageBuffer),
];

/// The binding of the glossy shader's half-resolution buffer (`rtlint
/// tradeoff`'s `half_res` knob): one `vec4<f32>` per 2×2 block.
pub const HALF_RES_BINDING: u32 = 8;

/// The half-resolution buffer for `params`' image.
pub fn half_res_buffer(ctx: &Context, params: &Params) -> crate::vk::Result<Buffer> {
    let blocks = u64::from(params.width.div_ceil(2)) * u64::from(params.height.div_ceil(2));
    Buffer::new(ctx, blocks * 16, raw::BufferUsageFlags::STORAGE_BUFFER, 1)
}

/// What a scene with alpha-tested cut-outs adds: the alpha texture (t4,
/// read with `Load`, one texel per test) and the per-triangle texture
/// coordinates (t5).
pub const CUTOUT_BINDINGS: [Binding; 2] = [
    Binding::new(4, BindingKind::SampledImage),
    Binding::new(5, BindingKind::StorageBuffer),
];

/// What multi-pass shaders (hybrid, adaptive) add: a count per pixel (u6:
/// the path each pixel's reflection took, or the paths it traced) and 64
/// bytes of state per pixel kept between passes (u7: the G-buffer, the
/// accumulator).
pub const SCRATCH_BINDINGS: [Binding; 2] = [
    Binding::new(6, BindingKind::StorageBuffer),
    Binding::new(7, BindingKind::StorageBuffer),
];

/// Bytes of [`SCRATCH_BINDINGS`]' state per pixel.
pub const SCRATCH_BYTES: u64 = 64;

/// The bindings a scene needs: [`BINDINGS`], and [`CUTOUT_BINDINGS`] only
/// when it has cut-outs.
pub fn bindings(scene: &Scene) -> Vec<Binding> {
    let mut b = BINDINGS.to_vec();
    if scene.has_cutouts() {
        b.extend(CUTOUT_BINDINGS);
    }
    b
}

/// How a pipeline runs: its ray generation shaders each in turn, `repeat`
/// times, with [`SCRATCH_BINDINGS`] when `scratch`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    pub repeat: u32,
    pub scratch: bool,
}

impl Passes {
    /// One trace from the first ray generation shader.
    pub const SINGLE: Passes = Passes {
        repeat: 1,
        scratch: false,
    };

    pub fn for_method(method: crate::reference::Method, params: &Params) -> Passes {
        Passes {
            repeat: method.passes(params),
            scratch: method.scratch(),
        }
    }
}

/// A scene on the device: one bottom-level structure per mesh, one instance
/// per scene instance with its transform and, as custom index, the index of
/// its first triangle in the `surfaces` buffer.
pub struct GpuScene {
    pub tlas: AccelerationStructure,
    pub surfaces: Buffer,
    /// The alpha texture and the `cutouts` buffer, when the scene has
    /// alpha-tested geometry.
    pub cutout: Option<(StorageImage, Buffer)>,
    /// What [`HALF_RES_BINDING`] gets unless the caller binds a buffer of
    /// its own: verify never turns half resolution on, so it is never read.
    pub half_res: Buffer,
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
                // Geometry is built opaque; a cut-out's instances are not,
                // so its candidates reach the any-hit shader or the ray
                // query's candidate loop.
                flags: if scene.materials[i.material].cutout {
                    raw::GeometryInstanceFlagsKHR::FORCE_NO_OPAQUE
                } else {
                    raw::GeometryInstanceFlagsKHR::empty()
                },
                ..Instance::identity(&blases[i.mesh])
            })
            .collect();
        let tlas = AccelerationStructure::top_level(ctx, &instances)?;
        let surfaces = Buffer::from_data(
            ctx,
            raw::BufferUsageFlags::STORAGE_BUFFER,
            &scene.surface_data(),
        )?;
        let cutout = match &scene.cutout {
            Some(c) if scene.has_cutouts() => {
                let texture = StorageImage::new(ctx, c.width, c.height)?;
                texture.write(ctx, &c.texels())?;
                let records = Buffer::from_data(
                    ctx,
                    raw::BufferUsageFlags::STORAGE_BUFFER,
                    &scene.cutout_data(),
                )?;
                Some((texture, records))
            }
            _ => None,
        };
        let half_res = Buffer::new(ctx, 16, raw::BufferUsageFlags::STORAGE_BUFFER, 1)?;
        Ok(GpuScene {
            tlas,
            surfaces,
            cutout,
            half_res,
        })
    }

    /// The scene's resources at their bindings (see [`bindings`]), with the
    /// image and the parameters.
    pub fn resources<'a>(
        &'a self,
        image: &'a Buffer,
        uniform: &'a Buffer,
    ) -> Vec<(u32, Resource<'a>)> {
        let mut r = vec![
            (0, Resource::AccelerationStructure(&self.tlas)),
            (1, Resource::Buffer(image)),
            (2, Resource::Buffer(&self.surfaces)),
            (3, Resource::Buffer(uniform)),
            (HALF_RES_BINDING, Resource::Buffer(&self.half_res)),
        ];
        if let Some((texture, records)) = &self.cutout {
            r.push((4, Resource::SampledImage(texture.view())));
            r.push((5, Resource::Buffer(records)));
        }
        r
    }
}

/// What one run measured.
pub struct Rendered {
    pub image: Vec<u32>,
    /// The per-pixel counts of multi-pass shaders ([`SCRATCH_BINDINGS`]).
    pub counts: Option<Vec<u32>>,
    /// Submission to fence of the trace (includes lavapipe's shader compile).
    pub trace: Duration,
    /// Everything on the device: structures, pipeline, trace, readback.
    pub total: Duration,
}

/// What the harness builds for a pipeline on a scene: the shader stages,
/// the groups over them, the bindings, and how many ray generation groups
/// run in turn.
pub struct Plan<'p> {
    pub stages: Vec<&'p ShaderRef>,
    pub groups: Vec<Group>,
    pub bindings: Vec<Binding>,
    pub raygens: usize,
}

/// Only what the scene needs: no shadow miss shader without a light, no
/// any-hit shader and no texture binding without cut-outs, the scratch
/// bindings only for multi-pass shaders.
pub fn plan<'p>(pipeline: &'p Pipeline, scene: &Scene, passes: Passes) -> Result<Plan<'p>, String> {
    let mut stages: Vec<&'p ShaderRef> = Vec::new();
    let mut groups = Vec::new();
    let mut add = |s: &'p ShaderRef| {
        stages.push(s);
        stages.len() as u32 - 1
    };
    // Without a light no shadow ray is traced: the shadow miss shaders
    // (every miss after the first) are left out.
    let misses = if scene.light.is_some() {
        &pipeline.miss[..]
    } else {
        &pipeline.miss[..pipeline.miss.len().min(1)]
    };
    // Every ray generation shader when they run in turn; else the first.
    let raygens = if passes.repeat > 1 || passes.scratch {
        &pipeline.raygen[..]
    } else {
        &pipeline.raygen[..pipeline.raygen.len().min(1)]
    };
    for s in raygens.iter().chain(misses) {
        groups.push(Group::General(add(s)));
    }
    // Any-hit shaders only for alpha-tested geometry: without it every
    // instance is opaque and they would never run. A group left with no
    // shader keeps its place, so SBT offsets stay as the shaders trace them.
    let cutouts = scene.has_cutouts();
    for g in &pipeline.hit_groups {
        if g.kind != HitGroupKind::Triangles {
            return Err("verify builds triangle hit groups only".into());
        }
        let closest_hit = g.closest_hit.as_ref().map(&mut add);
        let any_hit = g.any_hit.as_ref().filter(|_| cutouts).map(&mut add);
        groups.push(Group::Triangles {
            closest_hit,
            any_hit,
        });
    }
    let mut bindings = bindings(scene);
    if passes.scratch {
        bindings.extend(SCRATCH_BINDINGS);
    }
    Ok(Plan {
        stages,
        groups,
        bindings,
        raygens: raygens.len(),
    })
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
    render_passes(ctx, pipeline, depth, scene, params, Passes::SINGLE)
}

/// The described pipeline on the device (with `depth` instead of its
/// declared recursion depth when given), with only what `scene` needs
/// ([`plan`]) for one trace from the first ray generation shader.
pub fn ray_tracing_pipeline(
    ctx: &Context,
    pipeline: &Pipeline,
    depth: Option<u32>,
    scene: &Scene,
) -> Result<RayTracingPipeline, String> {
    ray_tracing_pipeline_for(ctx, pipeline, depth, scene, Passes::SINGLE)
}

/// As [`ray_tracing_pipeline`], built to run as `passes` says.
pub fn ray_tracing_pipeline_for(
    ctx: &Context,
    pipeline: &Pipeline,
    depth: Option<u32>,
    scene: &Scene,
    passes: Passes,
) -> Result<RayTracingPipeline, String> {
    let plan = plan(pipeline, scene, passes)?;
    let mut stages = Vec::new();
    for s in &plan.stages {
        let program = pipeline
            .program(s)
            .ok_or_else(|| format!("{}: no program for `{}`", s.file.display(), s.entry))?;
        stages.push(ShaderStage {
            spirv: &program.words,
            entry_point: &s.entry,
            stage: s.stage,
        });
    }
    RayTracingPipeline::new(
        ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &plan.groups,
            max_recursion_depth: depth.or(pipeline.max_recursion_depth).unwrap_or(1),
            bindings: &plan.bindings,
            push_constant_size: 0,
            stack_size: None,
        },
    )
    .map_err(|e| e.to_string())
}

/// As [`render`], running the pipeline's ray generation shaders as `passes` says.
pub fn render_passes(
    ctx: &Context,
    pipeline: &Pipeline,
    depth: Option<u32>,
    scene: &Scene,
    params: &Params,
    passes: Passes,
) -> Result<Rendered, String> {
    let start = Instant::now();
    let vk = |e: crate::vk::Error| e.to_string();
    let gpu_scene = GpuScene::new(ctx, scene).map_err(vk)?;
    let rt = ray_tracing_pipeline_for(ctx, pipeline, depth, scene, passes)?;
    let raygens = plan(pipeline, scene, passes)?.raygens;
    let pixels = u64::from(params.width) * u64::from(params.height);
    let image =
        Buffer::new(ctx, pixels * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).map_err(vk)?;
    let uniform = Buffer::from_data(
        ctx,
        raw::BufferUsageFlags::UNIFORM_BUFFER,
        &params.to_words(),
    )
    .map_err(vk)?;
    let mut resources = gpu_scene.resources(&image, &uniform);
    let scratch = if passes.scratch {
        let counts =
            Buffer::new(ctx, pixels * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).map_err(vk)?;
        let state = Buffer::new(
            ctx,
            pixels * SCRATCH_BYTES,
            raw::BufferUsageFlags::STORAGE_BUFFER,
            1,
        )
        .map_err(vk)?;
        Some((counts, state))
    } else {
        None
    };
    if let Some((counts, state)) = &scratch {
        resources.push((6, Resource::Buffer(counts)));
        resources.push((7, Resource::Buffer(state)));
    }
    // Each trace waits for the one before: a pass reads what the last wrote.
    let mut trace = Duration::ZERO;
    for _ in 0..passes.repeat {
        for r in 0..raygens {
            trace += rt
                .trace_rays_from(r, &resources, params.width, params.height, 1)
                .map_err(vk)?;
        }
    }
    Ok(Rendered {
        image: image.read_u32(),
        counts: scratch.map(|(c, _)| c.read_u32()),
        trace,
        total: start.elapsed(),
    })
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
    let pipeline = ComputePipeline::new(ctx, words, entry, &bindings(scene)).map_err(vk)?;
    let pixels = u64::from(params.width) * u64::from(params.height);
    let image =
        Buffer::new(ctx, pixels * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).map_err(vk)?;
    let uniform = Buffer::from_data(
        ctx,
        raw::BufferUsageFlags::UNIFORM_BUFFER,
        &params.to_words(),
    )
    .map_err(vk)?;
    let resources = gpu_scene.resources(&image, &uniform);
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
        counts: None,
        trace,
        total: start.elapsed(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::Method;
    use std::path::Path;

    fn load(pipeline: &str, scene: &str) -> (Pipeline, Scene) {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        (
            crate::pipeline::load(&dir.join(pipeline)).unwrap(),
            Scene::load(&dir.join("scenes").join(format!("{scene}.toml"))).unwrap(),
        )
    }

    fn any_hits(plan: &Plan) -> usize {
        plan.stages
            .iter()
            .filter(|s| s.stage == crate::shader::Stage::AnyHit)
            .count()
    }

    #[test]
    fn only_what_the_scene_needs_is_built() {
        // Showcase: a light (shadow miss), no cut-outs (no any-hit, no texture).
        let (p, s) = load("reflect_iterative_hlsl.pipeline.toml", "showcase");
        let built = plan(&p, &s, Passes::SINGLE).unwrap();
        assert_eq!(any_hits(&built), 0);
        assert_eq!(built.bindings, BINDINGS);
        // raygen, miss, shadow miss, the primary and the shadow hit group.
        assert_eq!(built.groups.len(), 5);
        assert!(matches!(
            built.groups[4],
            Group::Triangles {
                closest_hit: None,
                any_hit: None
            }
        ));
        // Mirror: no light, so no shadow miss either.
        let (p, s) = load("reflect_iterative_hlsl.pipeline.toml", "mirror");
        let built = plan(&p, &s, Passes::SINGLE).unwrap();
        assert_eq!(built.groups.len(), 4);
        // Cut-outs: both any-hit shaders, the texture and the coordinates.
        let (p, s) = load("reflect_iterative_hlsl.pipeline.toml", "cutout");
        let built = plan(&p, &s, Passes::SINGLE).unwrap();
        assert_eq!(any_hits(&built), 2);
        assert_eq!(built.bindings[BINDINGS.len()..], CUTOUT_BINDINGS);
        // The hybrid shader's two passes, with their scratch buffers.
        let (p, s) = load("reflect_hybrid_hlsl.pipeline.toml", "showcase");
        let built = plan(
            &p,
            &s,
            Passes::for_method(Method::Hybrid, &Params::for_scene(&s, 8, 8, 1)),
        )
        .unwrap();
        assert_eq!(built.raygens, 2);
        assert_eq!(built.bindings[BINDINGS.len()..], SCRATCH_BINDINGS);
    }
}
