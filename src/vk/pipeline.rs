//! Ray-tracing and compute pipelines, the shader binding table, dispatch.

use super::buffer::Buffer;
use super::context::{Context, Shared};
use super::descriptors::{Binding, Descriptors, Resource};
use super::error::{vk_err, Error, Result};
use ash::vk;
use std::ffi::CString;
use std::sync::Arc;
use std::time::Duration;

pub use crate::shader::Stage;

/// The Vulkan stage flag of a shader stage.
pub(crate) fn stage_flags(stage: Stage) -> vk::ShaderStageFlags {
    match stage {
        Stage::RayGeneration => vk::ShaderStageFlags::RAYGEN_KHR,
        Stage::Miss => vk::ShaderStageFlags::MISS_KHR,
        Stage::ClosestHit => vk::ShaderStageFlags::CLOSEST_HIT_KHR,
        Stage::AnyHit => vk::ShaderStageFlags::ANY_HIT_KHR,
        Stage::Intersection => vk::ShaderStageFlags::INTERSECTION_KHR,
        Stage::Callable => vk::ShaderStageFlags::CALLABLE_KHR,
        Stage::Compute => vk::ShaderStageFlags::COMPUTE,
        Stage::Vertex => vk::ShaderStageFlags::VERTEX,
        Stage::Fragment => vk::ShaderStageFlags::FRAGMENT,
        Stage::Other => vk::ShaderStageFlags::empty(),
    }
}

/// One shader stage: an entry point of a SPIR-V module. Stages that share a
/// module (the same slice) share one `VkShaderModule`.
#[derive(Clone, Copy, Debug)]
pub struct ShaderStage<'a> {
    pub spirv: &'a [u32],
    pub entry_point: &'a str,
    pub stage: Stage,
}

/// A shader group; numbers index the pipeline's stage list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// A ray generation, miss or callable stage.
    General(u32),
    Triangles {
        closest_hit: Option<u32>,
        any_hit: Option<u32>,
    },
    Procedural {
        intersection: u32,
        closest_hit: Option<u32>,
        any_hit: Option<u32>,
    },
}

/// Everything a ray-tracing pipeline is made of.
#[derive(Clone, Copy, Debug)]
pub struct RayTracingPipelineDesc<'a> {
    pub stages: &'a [ShaderStage<'a>],
    pub groups: &'a [Group],
    /// `maxPipelineRayRecursionDepth`.
    pub max_recursion_depth: u32,
    /// Descriptor set 0.
    pub bindings: &'a [Binding],
    /// Bytes of push constants the shaders read (0 for none).
    pub push_constant_size: u32,
    /// When set, the stack size is dynamic state and every trace sets this
    /// many bytes (`vkCmdSetRayTracingPipelineStackSizeKHR`) instead of the
    /// driver's default.
    pub stack_size: Option<u32>,
}

/// What `vkGetRayTracingShaderGroupStackSizeKHR` reports for one group, per
/// stage the group has (`None` where the group has no such stage).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GroupStackSizes {
    pub group: u32,
    pub general: Option<u64>,
    pub closest_hit: Option<u64>,
    pub any_hit: Option<u64>,
    pub intersection: Option<u64>,
}

/// One region of the shader binding table (an address range, like
/// `VkStridedDeviceAddressRegionKHR`), with the groups it holds in order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SbtRegion {
    pub address: u64,
    pub stride: u64,
    pub size: u64,
    pub groups: Vec<u32>,
}

impl SbtRegion {
    fn raw(&self) -> vk::StridedDeviceAddressRegionKHR {
        vk::StridedDeviceAddressRegionKHR {
            device_address: self.address,
            stride: self.stride,
            size: self.size,
        }
    }
}

/// The shader binding table: records are group handles only (no inline
/// data). Miss, hit and callable records are in pipeline group order within
/// their region, so an instance's SBT record offset counts hit groups.
#[derive(Debug)]
pub struct ShaderBindingTable {
    _buffer: Buffer,
    /// One region per ray generation group, since a raygen region holds one record.
    pub raygen: Vec<SbtRegion>,
    pub miss: SbtRegion,
    pub hit: SbtRegion,
    pub callable: SbtRegion,
}

/// Handle stride, region alignment and region sizes, with no Vulkan in it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SbtLayout {
    pub handle_size: u64,
    /// align(handle size, handle alignment).
    pub stride: u64,
    pub base_alignment: u64,
}

impl SbtLayout {
    pub fn new(limits: &super::RayTracingLimits) -> Self {
        let handle_size = u64::from(limits.shader_group_handle_size);
        SbtLayout {
            handle_size,
            stride: handle_size
                .next_multiple_of(u64::from(limits.shader_group_handle_alignment.max(1))),
            base_alignment: u64::from(limits.shader_group_base_alignment.max(1)),
        }
    }

    /// Records with `bytes` of shader-record data after each handle.
    pub fn with_record(self, bytes: u32, limits: &super::RayTracingLimits) -> Self {
        SbtLayout {
            stride: (self.handle_size + u64::from(bytes))
                .next_multiple_of(u64::from(limits.shader_group_handle_alignment.max(1))),
            ..self
        }
    }

    /// Offsets of the regions (raygen regions, then miss, hit, callable) for
    /// the given record counts, each on a base-alignment boundary, and the
    /// table's total size.
    pub fn offsets(
        &self,
        raygen: usize,
        miss: usize,
        hit: usize,
        callable: usize,
    ) -> (Vec<u64>, u64) {
        let mut offsets = Vec::new();
        let mut at = 0u64;
        let counts = std::iter::repeat_n(1usize, raygen).chain([miss, hit, callable]);
        for n in counts {
            offsets.push(at);
            at = (at + n as u64 * self.stride).next_multiple_of(self.base_alignment);
        }
        (offsets, at.max(self.base_alignment))
    }
}

pub struct RayTracingPipeline {
    shared: Arc<Shared>,
    pipeline: vk::Pipeline,
    descriptors: Descriptors,
    groups: Vec<Group>,
    stack_size: Option<u32>,
    sbt: ShaderBindingTable,
}

impl std::fmt::Debug for RayTracingPipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RayTracingPipeline")
            .field("groups", &self.groups)
            .field("sbt", &self.sbt)
            .finish_non_exhaustive()
    }
}

/// Shader modules created for one pipeline, destroyed once it exists.
struct Modules<'s> {
    shared: &'s Shared,
    modules: Vec<(*const u32, usize, vk::ShaderModule)>,
}

impl Modules<'_> {
    fn get(&mut self, spirv: &[u32]) -> Result<vk::ShaderModule> {
        let key = (spirv.as_ptr(), spirv.len());
        if let Some(m) = self.modules.iter().find(|m| (m.0, m.1) == key) {
            return Ok(m.2);
        }
        let info = vk::ShaderModuleCreateInfo::default().code(spirv);
        // SAFETY: valid device; the driver copies the code.
        let module = unsafe { self.shared.device.create_shader_module(&info, None) }
            .map_err(vk_err("vkCreateShaderModule"))?;
        self.modules.push((key.0, key.1, module));
        Ok(module)
    }
}

impl Drop for Modules<'_> {
    fn drop(&mut self) {
        for m in &self.modules {
            // SAFETY: modules are not needed after pipeline creation.
            unsafe { self.shared.device.destroy_shader_module(m.2, None) };
        }
    }
}

impl RayTracingPipeline {
    pub fn new(ctx: &Context, desc: &RayTracingPipelineDesc<'_>) -> Result<Self> {
        check_desc(ctx, desc)?;
        let descriptors = Descriptors::new(&ctx.shared, desc.bindings, desc.push_constant_size)?;
        Self::create(ctx, desc, descriptors, 0)
    }

    /// A pipeline whose layout is the reflected `interface` (every set,
    /// descriptor type, count and stage the shaders use, and their push
    /// constants; `desc.bindings` and `desc.push_constant_size` are not
    /// read), with shader records long enough for the shader-record data
    /// the shaders read. Such a pipeline is for creation and its stack
    /// sizes: it has no descriptor sets to bind, so it cannot trace.
    pub fn with_interface(
        ctx: &Context,
        desc: &RayTracingPipelineDesc<'_>,
        interface: &super::interface::PipelineInterface,
    ) -> Result<Self> {
        check_desc(ctx, desc)?;
        let sets = interface.set_count();
        if sets > ctx.shared.info.max_bound_descriptor_sets {
            return Err(Error::Invalid(format!(
                "the shaders use {sets} descriptor sets; the device binds at most {}",
                ctx.shared.info.max_bound_descriptor_sets
            )));
        }
        if interface.push_constant_size > ctx.shared.info.max_push_constants_size {
            return Err(Error::Invalid(format!(
                "the shaders read {} bytes of push constants; the device has {}",
                interface.push_constant_size, ctx.shared.info.max_push_constants_size
            )));
        }
        if interface.has_runtime_array() && !ctx.shared.info.runtime_descriptor_array {
            return Err(Error::Invalid(
                "the shaders use a runtime descriptor array; the device lacks runtimeDescriptorArray"
                    .into(),
            ));
        }
        let descriptors = Descriptors::from_interface(&ctx.shared, interface, RUNTIME_ARRAY_COUNT)?;
        Self::create(ctx, desc, descriptors, interface.shader_record_size)
    }

    fn create(
        ctx: &Context,
        desc: &RayTracingPipelineDesc<'_>,
        descriptors: Descriptors,
        shader_record_size: u32,
    ) -> Result<Self> {
        let shared = &ctx.shared;

        let mut modules = Modules {
            shared,
            modules: Vec::new(),
        };
        let names: Vec<CString> = desc
            .stages
            .iter()
            .map(|s| {
                CString::new(s.entry_point).map_err(|_| {
                    Error::Invalid(format!("entry point {:?} contains NUL", s.entry_point))
                })
            })
            .collect::<Result<_>>()?;
        let mut stages = Vec::with_capacity(desc.stages.len());
        for (s, name) in desc.stages.iter().zip(&names) {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(stage_flags(s.stage))
                    .module(modules.get(s.spirv)?)
                    .name(name),
            );
        }
        let unused = vk::SHADER_UNUSED_KHR;
        let groups: Vec<_> = desc
            .groups
            .iter()
            .map(|g| {
                let (ty, general, chit, ahit, isect) = match *g {
                    Group::General(s) => (
                        vk::RayTracingShaderGroupTypeKHR::GENERAL,
                        s,
                        unused,
                        unused,
                        unused,
                    ),
                    Group::Triangles {
                        closest_hit,
                        any_hit,
                    } => (
                        vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP,
                        unused,
                        closest_hit.unwrap_or(unused),
                        any_hit.unwrap_or(unused),
                        unused,
                    ),
                    Group::Procedural {
                        intersection,
                        closest_hit,
                        any_hit,
                    } => (
                        vk::RayTracingShaderGroupTypeKHR::PROCEDURAL_HIT_GROUP,
                        unused,
                        closest_hit.unwrap_or(unused),
                        any_hit.unwrap_or(unused),
                        intersection,
                    ),
                };
                vk::RayTracingShaderGroupCreateInfoKHR::default()
                    .ty(ty)
                    .general_shader(general)
                    .closest_hit_shader(chit)
                    .any_hit_shader(ahit)
                    .intersection_shader(isect)
            })
            .collect();
        let dynamic_states = [vk::DynamicState::RAY_TRACING_PIPELINE_STACK_SIZE_KHR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut create = vk::RayTracingPipelineCreateInfoKHR::default()
            .stages(&stages)
            .groups(&groups)
            .max_pipeline_ray_recursion_depth(desc.max_recursion_depth)
            .layout(descriptors.pipeline_layout);
        if desc.stack_size.is_some() {
            create = create.dynamic_state(&dynamic);
        }
        // SAFETY: the create info points at locals that outlive the call.
        let pipeline = match unsafe {
            shared.rt.create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                vk::PipelineCache::null(),
                &[create],
                None,
            )
        } {
            Ok(p) => p[0],
            Err((p, result)) => {
                for p in p.into_iter().filter(|p| *p != vk::Pipeline::null()) {
                    // SAFETY: a partially created pipeline is unused.
                    unsafe { shared.device.destroy_pipeline(p, None) };
                }
                return Err(Error::Vk {
                    call: "vkCreateRayTracingPipelinesKHR",
                    result,
                });
            }
        };
        drop(modules);
        let sbt = match build_sbt(ctx, pipeline, desc, shader_record_size) {
            Ok(sbt) => sbt,
            Err(e) => {
                // SAFETY: the pipeline is unused.
                unsafe { shared.device.destroy_pipeline(pipeline, None) };
                return Err(e);
            }
        };
        Ok(RayTracingPipeline {
            shared: shared.clone(),
            pipeline,
            descriptors,
            groups: desc.groups.to_vec(),
            stack_size: desc.stack_size,
            sbt,
        })
    }

    pub fn raw(&self) -> vk::Pipeline {
        self.pipeline
    }

    pub fn sbt(&self) -> &ShaderBindingTable {
        &self.sbt
    }

    /// `vkGetRayTracingShaderGroupStackSizeKHR` for every group and each
    /// stage it has.
    pub fn group_stack_sizes(&self) -> Vec<GroupStackSizes> {
        let query = |group: u32, which: vk::ShaderGroupShaderKHR| {
            // SAFETY: the group index is in range and the group has this stage.
            unsafe {
                self.shared
                    .rt
                    .get_ray_tracing_shader_group_stack_size(self.pipeline, group, which)
            }
        };
        self.groups
            .iter()
            .enumerate()
            .map(|(i, g)| {
                let i = i as u32;
                let mut s = GroupStackSizes {
                    group: i,
                    ..Default::default()
                };
                match *g {
                    Group::General(_) => {
                        s.general = Some(query(i, vk::ShaderGroupShaderKHR::GENERAL))
                    }
                    Group::Triangles {
                        closest_hit,
                        any_hit,
                    } => {
                        s.closest_hit =
                            closest_hit.map(|_| query(i, vk::ShaderGroupShaderKHR::CLOSEST_HIT));
                        s.any_hit = any_hit.map(|_| query(i, vk::ShaderGroupShaderKHR::ANY_HIT));
                    }
                    Group::Procedural {
                        closest_hit,
                        any_hit,
                        ..
                    } => {
                        s.intersection = Some(query(i, vk::ShaderGroupShaderKHR::INTERSECTION));
                        s.closest_hit =
                            closest_hit.map(|_| query(i, vk::ShaderGroupShaderKHR::CLOSEST_HIT));
                        s.any_hit = any_hit.map(|_| query(i, vk::ShaderGroupShaderKHR::ANY_HIT));
                    }
                }
                s
            })
            .collect()
    }

    /// Binds `resources`, traces `width × height × depth` rays from the first
    /// ray generation group, and waits. Returns the time from submission to
    /// completion (on lavapipe this includes the shader compile of a first
    /// dispatch).
    pub fn trace_rays(
        &self,
        resources: &[(u32, Resource<'_>)],
        width: u32,
        height: u32,
        depth: u32,
    ) -> Result<Duration> {
        self.trace_rays_from(0, resources, width, height, depth)
    }

    /// As [`trace_rays`](Self::trace_rays), from the `raygen`-th ray
    /// generation group (in group order).
    pub fn trace_rays_from(
        &self,
        raygen: usize,
        resources: &[(u32, Resource<'_>)],
        width: u32,
        height: u32,
        depth: u32,
    ) -> Result<Duration> {
        let limits = &self.shared.info.ray_tracing;
        let count = u64::from(width) * u64::from(height) * u64::from(depth);
        if count > u64::from(limits.max_ray_dispatch_invocation_count) {
            return Err(Error::Invalid(format!(
                "{count} rays exceed maxRayDispatchInvocationCount {}",
                limits.max_ray_dispatch_invocation_count
            )));
        }
        let Some(rg) = self.sbt.raygen.get(raygen) else {
            return Err(Error::Invalid(format!(
                "the pipeline has {} ray generation groups, not {}",
                self.sbt.raygen.len(),
                raygen + 1
            )));
        };
        self.descriptors.write(resources)?;
        let d = &self.shared.device;
        self.shared.submit("trace rays", |cmd| {
            // SAFETY: the pipeline, layout and set are live; the SBT buffer
            // outlives the submission.
            unsafe {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::RAY_TRACING_KHR, self.pipeline);
                bind_set(
                    d,
                    cmd,
                    vk::PipelineBindPoint::RAY_TRACING_KHR,
                    &self.descriptors,
                );
                if let Some(bytes) = self.stack_size {
                    self.shared
                        .rt
                        .cmd_set_ray_tracing_pipeline_stack_size(cmd, bytes);
                }
                self.shared.rt.cmd_trace_rays(
                    cmd,
                    &rg.raw(),
                    &self.sbt.miss.raw(),
                    &self.sbt.hit.raw(),
                    &self.sbt.callable.raw(),
                    width,
                    height,
                    depth,
                );
            }
        })
    }
}

impl RayTracingPipeline {
    /// Device time of `repeats` runs of `passes` (each a trace of `[width,
    /// height]` rays from the given ray generation group, in order, each
    /// seeing the writes of the one before), from timestamp queries, after
    /// `warmup` untimed runs (lavapipe compiles the pipeline at its first
    /// dispatch). The `clear` buffers (made with `TRANSFER_DST` usage) are
    /// zeroed before each timed run, outside its timestamps: state that
    /// passes accumulate starts afresh. Nanoseconds per run, in order.
    pub fn time_trace_rays(
        &self,
        resources: &[(u32, Resource<'_>)],
        passes: &[(usize, [u32; 2])],
        clear: &[&Buffer],
        warmup: u32,
        repeats: u32,
    ) -> Result<Vec<f64>> {
        for _ in 0..warmup {
            for &(raygen, [width, height]) in passes {
                self.trace_rays_from(raygen, resources, width, height, 1)?;
            }
        }
        if let Some(&(raygen, _)) = passes.iter().find(|p| p.0 >= self.sbt.raygen.len()) {
            return Err(Error::Invalid(format!(
                "the pipeline has {} ray generation groups, not {}",
                self.sbt.raygen.len(),
                raygen + 1
            )));
        }
        self.descriptors.write(resources)?;
        let d = &self.shared.device;
        super::timing::timed_dispatches(
            &self.shared,
            repeats,
            vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR,
            |cmd| {
                // SAFETY: cmd is recording; pipeline and set are live.
                unsafe {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::RAY_TRACING_KHR, self.pipeline);
                    bind_set(
                        d,
                        cmd,
                        vk::PipelineBindPoint::RAY_TRACING_KHR,
                        &self.descriptors,
                    );
                    if let Some(bytes) = self.stack_size {
                        self.shared
                            .rt
                            .cmd_set_ray_tracing_pipeline_stack_size(cmd, bytes);
                    }
                }
            },
            |cmd| {
                if clear.is_empty() {
                    return;
                }
                let rt = vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR;
                let transfer = vk::PipelineStageFlags::TRANSFER;
                let to_fill = vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE)
                    .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE);
                let to_shader = vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                    .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
                // SAFETY: cmd is recording; the buffers outlive the submission.
                unsafe {
                    d.cmd_pipeline_barrier(
                        cmd,
                        rt,
                        transfer,
                        vk::DependencyFlags::empty(),
                        &[to_fill],
                        &[],
                        &[],
                    );
                    for b in clear {
                        d.cmd_fill_buffer(cmd, b.raw(), b.offset(), b.size(), 0);
                    }
                    d.cmd_pipeline_barrier(
                        cmd,
                        transfer,
                        rt,
                        vk::DependencyFlags::empty(),
                        &[to_shader],
                        &[],
                        &[],
                    );
                }
            },
            |cmd| {
                let stage = vk::PipelineStageFlags::RAY_TRACING_SHADER_KHR;
                let barrier = vk::MemoryBarrier::default()
                    .src_access_mask(vk::AccessFlags::SHADER_WRITE)
                    .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
                for (k, &(raygen, [width, height])) in passes.iter().enumerate() {
                    // SAFETY: bound above; the SBT outlives the submission.
                    unsafe {
                        if k > 0 {
                            d.cmd_pipeline_barrier(
                                cmd,
                                stage,
                                stage,
                                vk::DependencyFlags::empty(),
                                &[barrier],
                                &[],
                                &[],
                            );
                        }
                        self.shared.rt.cmd_trace_rays(
                            cmd,
                            &self.sbt.raygen[raygen].raw(),
                            &self.sbt.miss.raw(),
                            &self.sbt.hit.raw(),
                            &self.sbt.callable.raw(),
                            width,
                            height,
                            1,
                        )
                    }
                }
            },
        )
    }
}

impl Drop for RayTracingPipeline {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: submissions are waited for, so the pipeline is idle.
        unsafe { self.shared.device.destroy_pipeline(self.pipeline, None) };
    }
}

/// # Safety
/// `cmd` is recording and the descriptors are live.
unsafe fn bind_set(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    point: vk::PipelineBindPoint,
    ds: &Descriptors,
) {
    if ds.set != vk::DescriptorSet::null() {
        d.cmd_bind_descriptor_sets(cmd, point, ds.pipeline_layout, 0, &[ds.set], &[]);
    }
}

/// Descriptors a runtime array gets in a reflected layout.
pub(crate) const RUNTIME_ARRAY_COUNT: u32 = 16;

fn check_desc(ctx: &Context, desc: &RayTracingPipelineDesc<'_>) -> Result<()> {
    let limits = ctx.shared.info.ray_tracing;
    if desc.max_recursion_depth > limits.max_ray_recursion_depth {
        return Err(Error::Invalid(format!(
            "recursion depth {} is above the device's maximum of {}",
            desc.max_recursion_depth, limits.max_ray_recursion_depth
        )));
    }
    check_groups(desc)
}

fn check_groups(desc: &RayTracingPipelineDesc<'_>) -> Result<()> {
    let stage_of = |i: u32, what: &str, allowed: &[Stage]| -> Result<()> {
        match desc.stages.get(i as usize) {
            Some(s) if allowed.contains(&s.stage) => Ok(()),
            Some(s) => Err(Error::Invalid(format!(
                "{what} refers to stage {i}, a {} stage",
                s.stage.as_str()
            ))),
            None => Err(Error::Invalid(format!(
                "{what} refers to stage {i}, but there are {} stages",
                desc.stages.len()
            ))),
        }
    };
    for (k, g) in desc.groups.iter().enumerate() {
        let what = format!("group {k}");
        match *g {
            Group::General(s) => stage_of(
                s,
                &what,
                &[Stage::RayGeneration, Stage::Miss, Stage::Callable],
            )?,
            Group::Triangles {
                closest_hit,
                any_hit,
            } => {
                if let Some(s) = closest_hit {
                    stage_of(s, &what, &[Stage::ClosestHit])?;
                }
                if let Some(s) = any_hit {
                    stage_of(s, &what, &[Stage::AnyHit])?;
                }
            }
            Group::Procedural {
                intersection,
                closest_hit,
                any_hit,
            } => {
                stage_of(intersection, &what, &[Stage::Intersection])?;
                if let Some(s) = closest_hit {
                    stage_of(s, &what, &[Stage::ClosestHit])?;
                }
                if let Some(s) = any_hit {
                    stage_of(s, &what, &[Stage::AnyHit])?;
                }
            }
        }
    }
    Ok(())
}

fn build_sbt(
    ctx: &Context,
    pipeline: vk::Pipeline,
    desc: &RayTracingPipelineDesc<'_>,
    shader_record_size: u32,
) -> Result<ShaderBindingTable> {
    let shared = &ctx.shared;
    let limits = &shared.info.ray_tracing;
    let layout = SbtLayout::new(limits).with_record(shader_record_size, limits);
    if layout.stride > u64::from(limits.max_shader_group_stride) {
        return Err(Error::Invalid(format!(
            "shader records of {shader_record_size} bytes make a stride of {} bytes; the device allows {}",
            layout.stride, limits.max_shader_group_stride
        )));
    }
    let (mut raygen, mut miss, mut hit, mut callable) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (k, g) in desc.groups.iter().enumerate() {
        let k = k as u32;
        match *g {
            Group::General(s) => match desc.stages[s as usize].stage {
                Stage::RayGeneration => raygen.push(k),
                Stage::Miss => miss.push(k),
                _ => callable.push(k),
            },
            Group::Triangles { .. } | Group::Procedural { .. } => hit.push(k),
        }
    }
    if raygen.is_empty() {
        return Err(Error::Invalid(
            "the pipeline has no ray generation group".into(),
        ));
    }
    let n = desc.groups.len();
    let hs = layout.handle_size as usize;
    // SAFETY: the pipeline has `n` groups.
    let handles = unsafe {
        shared
            .rt
            .get_ray_tracing_shader_group_handles(pipeline, 0, n as u32, n * hs)
    }
    .map_err(vk_err("vkGetRayTracingShaderGroupHandlesKHR"))?;
    let (offsets, total) = layout.offsets(raygen.len(), miss.len(), hit.len(), callable.len());
    let mut buffer = Buffer::new(
        ctx,
        total,
        vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR,
        layout.base_alignment,
    )?;
    let lists: Vec<Vec<u32>> = raygen
        .iter()
        .map(|&g| vec![g])
        .chain([miss, hit, callable])
        .collect();
    let mut regions = Vec::new();
    for (list, &offset) in lists.iter().zip(&offsets) {
        for (r, &g) in list.iter().enumerate() {
            let at = offset + r as u64 * layout.stride;
            buffer.write(at, &handles[g as usize * hs..(g as usize + 1) * hs])?;
        }
        let empty = list.is_empty();
        regions.push(SbtRegion {
            // An empty region must have address 0 (and so stride and size 0).
            address: if empty { 0 } else { buffer.address() + offset },
            stride: if empty { 0 } else { layout.stride },
            // For the raygen region size equals stride, as the spec requires.
            size: list.len() as u64 * layout.stride,
            groups: list.clone(),
        });
    }
    let callable = regions.pop().unwrap_or_default();
    let hit = regions.pop().unwrap_or_default();
    let miss = regions.pop().unwrap_or_default();
    Ok(ShaderBindingTable {
        _buffer: buffer,
        raygen: regions,
        miss,
        hit,
        callable,
    })
}

/// A compute pipeline (for ray-query shaders) over the same descriptor code.
pub struct ComputePipeline {
    shared: Arc<Shared>,
    pipeline: vk::Pipeline,
    descriptors: Descriptors,
}

impl std::fmt::Debug for ComputePipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ComputePipeline").finish_non_exhaustive()
    }
}

impl ComputePipeline {
    pub fn new(
        ctx: &Context,
        spirv: &[u32],
        entry_point: &str,
        bindings: &[Binding],
    ) -> Result<Self> {
        let shared = &ctx.shared;
        let descriptors = Descriptors::new(shared, bindings, 0)?;
        let mut modules = Modules {
            shared,
            modules: Vec::new(),
        };
        let name = CString::new(entry_point)
            .map_err(|_| Error::Invalid(format!("entry point {entry_point:?} contains NUL")))?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(modules.get(spirv)?)
            .name(&name);
        let create = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(descriptors.pipeline_layout);
        // SAFETY: the create info points at live locals.
        let pipeline = unsafe {
            shared
                .device
                .create_compute_pipelines(vk::PipelineCache::null(), &[create], None)
        }
        .map_err(|(p, result)| {
            for p in p.into_iter().filter(|p| *p != vk::Pipeline::null()) {
                // SAFETY: unused.
                unsafe { shared.device.destroy_pipeline(p, None) };
            }
            Error::Vk {
                call: "vkCreateComputePipelines",
                result,
            }
        })?[0];
        Ok(ComputePipeline {
            shared: shared.clone(),
            pipeline,
            descriptors,
        })
    }

    pub fn raw(&self) -> vk::Pipeline {
        self.pipeline
    }

    /// Binds `resources`, dispatches `x × y × z` workgroups and waits.
    pub fn dispatch(
        &self,
        resources: &[(u32, Resource<'_>)],
        x: u32,
        y: u32,
        z: u32,
    ) -> Result<Duration> {
        self.descriptors.write(resources)?;
        let d = &self.shared.device;
        self.shared.submit("compute dispatch", |cmd| {
            // SAFETY: the pipeline, layout and set are live.
            unsafe {
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
                bind_set(d, cmd, vk::PipelineBindPoint::COMPUTE, &self.descriptors);
                d.cmd_dispatch(cmd, x, y, z);
            }
        })
    }
}

impl ComputePipeline {
    /// As [`RayTracingPipeline::time_trace_rays`] for `x × y × z`
    /// workgroups: nanoseconds per timed dispatch.
    pub fn time_dispatch(
        &self,
        resources: &[(u32, Resource<'_>)],
        groups: [u32; 3],
        warmup: u32,
        repeats: u32,
    ) -> Result<Vec<f64>> {
        let [x, y, z] = groups;
        for _ in 0..warmup {
            self.dispatch(resources, x, y, z)?;
        }
        self.descriptors.write(resources)?;
        let d = &self.shared.device;
        super::timing::timed_dispatches(
            &self.shared,
            repeats,
            vk::PipelineStageFlags::COMPUTE_SHADER,
            |cmd| {
                // SAFETY: cmd is recording; pipeline and set are live.
                unsafe {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
                    bind_set(d, cmd, vk::PipelineBindPoint::COMPUTE, &self.descriptors);
                }
            },
            |_| {},
            // SAFETY: bound above.
            |cmd| unsafe { d.cmd_dispatch(cmd, x, y, z) },
        )
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: submissions are waited for, so the pipeline is idle.
        unsafe { self.shared.device.destroy_pipeline(self.pipeline, None) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vk::RayTracingLimits;

    fn limits(handle: u32, handle_align: u32, base: u32) -> RayTracingLimits {
        RayTracingLimits {
            shader_group_handle_size: handle,
            shader_group_handle_alignment: handle_align,
            shader_group_base_alignment: base,
            max_shader_group_stride: 4096,
            max_ray_recursion_depth: 31,
            max_ray_dispatch_invocation_count: 1 << 30,
            max_ray_hit_attribute_size: 32,
            min_acceleration_structure_scratch_offset_alignment: 128,
        }
    }

    #[test]
    fn lavapipe_layout_packs_regions_on_32_bytes() {
        // lavapipe: handle 32, handle alignment 16, base alignment 32.
        let l = SbtLayout::new(&limits(32, 16, 32));
        assert_eq!((l.stride, l.base_alignment), (32, 32));
        assert_eq!(l.offsets(1, 1, 1, 0), (vec![0, 32, 64, 96], 96));
    }

    #[test]
    fn nvidia_layout_starts_each_region_on_64_bytes() {
        // NVIDIA H100: handle 32, handle alignment 32, base alignment 64.
        let l = SbtLayout::new(&limits(32, 32, 64));
        assert_eq!(l.stride, 32);
        // Two miss records share one 64-byte region; three hit records need 96.
        assert_eq!(l.offsets(1, 2, 3, 0), (vec![0, 64, 128, 256], 256));
        assert_eq!(l.offsets(2, 1, 1, 1), (vec![0, 64, 128, 192, 256], 320));
    }

    #[test]
    fn shader_records_widen_the_stride() {
        // NVIDIA: a 32-byte handle and 8 bytes of shader record round up
        // to the 32-byte handle alignment: 64.
        let l = SbtLayout::new(&limits(32, 32, 64)).with_record(8, &limits(32, 32, 64));
        assert_eq!(l.stride, 64);
        assert_eq!(l.offsets(1, 1, 2, 0), (vec![0, 64, 128, 256], 256));
        // No record: the handle alone.
        let l = SbtLayout::new(&limits(32, 16, 32)).with_record(0, &limits(32, 16, 32));
        assert_eq!(l.stride, 32);
    }

    #[test]
    fn stride_rounds_handle_size_up_to_handle_alignment() {
        let l = SbtLayout::new(&limits(24, 16, 64));
        assert_eq!(l.stride, 32);
        // An empty table still has one aligned block (buffers cannot be empty).
        assert_eq!(l.offsets(0, 0, 0, 0), (vec![0, 0, 0], 64));
    }
}
