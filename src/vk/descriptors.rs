//! One descriptor set per pipeline, built from a plain binding list and
//! rewritten before each dispatch so its resources are borrowed for exactly
//! as long as the GPU uses them; or, for a pipeline that is only created
//! (the driver's stack sizes), every set a reflected interface names.

use super::accel::AccelerationStructure;
use super::buffer::Buffer;
use super::context::Shared;
use super::error::{vk_err, Error, Result};
use super::interface::{DescriptorCount, DescriptorKind, PipelineInterface};
use super::pipeline::stage_flags;
use ash::vk;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    AccelerationStructure,
    StorageBuffer,
    UniformBuffer,
    StorageImage,
    /// A `Texture2D` read through a separate sampler.
    SampledImage,
    /// A `SamplerState`.
    Sampler,
}

impl BindingKind {
    fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            BindingKind::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
            BindingKind::Sampler => vk::DescriptorType::SAMPLER,
        }
    }
}

fn descriptor_type(kind: DescriptorKind) -> vk::DescriptorType {
    use vk::DescriptorType as T;
    match kind {
        DescriptorKind::Sampler => T::SAMPLER,
        DescriptorKind::CombinedImageSampler => T::COMBINED_IMAGE_SAMPLER,
        DescriptorKind::SampledImage => T::SAMPLED_IMAGE,
        DescriptorKind::StorageImage => T::STORAGE_IMAGE,
        DescriptorKind::UniformTexelBuffer => T::UNIFORM_TEXEL_BUFFER,
        DescriptorKind::StorageTexelBuffer => T::STORAGE_TEXEL_BUFFER,
        DescriptorKind::UniformBuffer => T::UNIFORM_BUFFER,
        DescriptorKind::StorageBuffer => T::STORAGE_BUFFER,
        DescriptorKind::AccelerationStructure => T::ACCELERATION_STRUCTURE_KHR,
    }
}

/// One binding of descriptor set 0, visible to every stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Binding {
    pub binding: u32,
    pub kind: BindingKind,
}

impl Binding {
    pub const fn new(binding: u32, kind: BindingKind) -> Self {
        Binding { binding, kind }
    }
}

/// What goes into a binding for one dispatch.
#[derive(Clone, Copy, Debug)]
pub enum Resource<'a> {
    AccelerationStructure(&'a AccelerationStructure),
    /// A storage or uniform buffer, whichever the binding says.
    Buffer(&'a Buffer),
    /// An image view in `GENERAL` layout ([`StorageImage::view`](super::StorageImage::view)).
    StorageImage(vk::ImageView),
    /// An image view in `GENERAL` layout, to be sampled.
    SampledImage(vk::ImageView),
    /// [`Sampler::raw`](super::Sampler::raw).
    Sampler(vk::Sampler),
}

/// Set layout, pool, the set itself and the pipeline layout over it.
pub(crate) struct Descriptors {
    shared: Arc<Shared>,
    bindings: Vec<Binding>,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    /// The set layouts of a reflected interface (set 0, 1, …); no sets are
    /// allocated for them.
    reflected: Vec<vk::DescriptorSetLayout>,
    pool: vk::DescriptorPool,
    pub(crate) set: vk::DescriptorSet,
    pub(crate) pipeline_layout: vk::PipelineLayout,
}

impl Descriptors {
    pub(crate) fn new(
        shared: &Arc<Shared>,
        bindings: &[Binding],
        push_constant_size: u32,
    ) -> Result<Self> {
        for (k, b) in bindings.iter().enumerate() {
            if bindings[..k].iter().any(|o| o.binding == b.binding) {
                return Err(Error::Invalid(format!(
                    "binding {} is listed twice",
                    b.binding
                )));
            }
        }
        let device = &shared.device;
        let mut this = Descriptors {
            shared: shared.clone(),
            bindings: bindings.to_vec(),
            set_layout: vk::DescriptorSetLayout::null(),
            reflected: Vec::new(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            pipeline_layout: vk::PipelineLayout::null(),
        };
        let layout_bindings: Vec<_> = bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.kind.descriptor_type())
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        // SAFETY: valid device; each handle is stored in `this` at once so
        // Drop releases it on any later error.
        unsafe {
            this.set_layout = device
                .create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                    None,
                )
                .map_err(vk_err("vkCreateDescriptorSetLayout"))?;
            let layouts = [this.set_layout];
            let ranges = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::ALL)
                .size(push_constant_size)];
            let ranges = if push_constant_size > 0 {
                &ranges[..]
            } else {
                &[]
            };
            this.pipeline_layout = device
                .create_pipeline_layout(
                    &vk::PipelineLayoutCreateInfo::default()
                        .set_layouts(&layouts)
                        .push_constant_ranges(ranges),
                    None,
                )
                .map_err(vk_err("vkCreatePipelineLayout"))?;
            if !bindings.is_empty() {
                let sizes: Vec<_> = bindings
                    .iter()
                    .map(|b| {
                        vk::DescriptorPoolSize::default()
                            .ty(b.kind.descriptor_type())
                            .descriptor_count(1)
                    })
                    .collect();
                this.pool = device
                    .create_descriptor_pool(
                        &vk::DescriptorPoolCreateInfo::default()
                            .max_sets(1)
                            .pool_sizes(&sizes),
                        None,
                    )
                    .map_err(vk_err("vkCreateDescriptorPool"))?;
                this.set = device
                    .allocate_descriptor_sets(
                        &vk::DescriptorSetAllocateInfo::default()
                            .descriptor_pool(this.pool)
                            .set_layouts(&layouts),
                    )
                    .map_err(vk_err("vkAllocateDescriptorSets"))?[0];
            }
        }
        Ok(this)
    }

    /// Set layouts and the pipeline layout for a reflected interface: every
    /// set up to the highest one used (empty where no shader uses a set),
    /// each binding with its descriptor type, count and stages, and the
    /// push-constant range. A runtime array gets `runtime_count`
    /// descriptors. Nothing is allocated: such a layout serves pipeline
    /// creation, not dispatch.
    pub(crate) fn from_interface(
        shared: &Arc<Shared>,
        interface: &PipelineInterface,
        runtime_count: u32,
    ) -> Result<Self> {
        let device = &shared.device;
        let mut this = Descriptors {
            shared: shared.clone(),
            bindings: Vec::new(),
            set_layout: vk::DescriptorSetLayout::null(),
            reflected: Vec::new(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            pipeline_layout: vk::PipelineLayout::null(),
        };
        let flags = |stages: &std::collections::BTreeSet<crate::shader::Stage>| {
            stages
                .iter()
                .fold(vk::ShaderStageFlags::empty(), |f, s| f | stage_flags(*s))
        };
        for set in 0..interface.set_count() {
            let layout_bindings: Vec<_> = interface
                .bindings
                .iter()
                .filter(|b| b.set == set)
                .map(|b| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.binding)
                        .descriptor_type(descriptor_type(b.kind))
                        .descriptor_count(match b.count {
                            DescriptorCount::Fixed(n) => n,
                            DescriptorCount::Runtime => runtime_count,
                        })
                        .stage_flags(flags(&b.stages))
                })
                .collect();
            // SAFETY: valid device; the handle is kept in `this` at once so
            // Drop releases it on any later error.
            let layout = unsafe {
                device.create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                    None,
                )
            }
            .map_err(vk_err("vkCreateDescriptorSetLayout"))?;
            this.reflected.push(layout);
        }
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(flags(&interface.push_constant_stages))
            .size(interface.push_constant_size)];
        let ranges = if interface.push_constant_size > 0 {
            &ranges[..]
        } else {
            &[]
        };
        // SAFETY: as above.
        this.pipeline_layout = unsafe {
            device.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&this.reflected)
                    .push_constant_ranges(ranges),
                None,
            )
        }
        .map_err(vk_err("vkCreatePipelineLayout"))?;
        Ok(this)
    }

    /// Points every binding at its resource; each binding needs exactly one.
    pub(crate) fn write(&self, resources: &[(u32, Resource<'_>)]) -> Result<()> {
        if !self.reflected.is_empty() {
            return Err(Error::Invalid(
                "a pipeline made from a reflected interface has no descriptor sets to write".into(),
            ));
        }
        for b in &self.bindings {
            let n = resources.iter().filter(|(k, _)| *k == b.binding).count();
            if n != 1 {
                return Err(Error::Invalid(format!(
                    "binding {} ({:?}) needs one resource, got {n}",
                    b.binding, b.kind
                )));
            }
        }
        // Collect the pointed-to infos first: writes hold pointers into them.
        let mut buffer_infos = Vec::new();
        let mut image_infos = Vec::new();
        let mut structures = Vec::new();
        for (binding, resource) in resources {
            let Some(b) = self.bindings.iter().find(|b| b.binding == *binding) else {
                return Err(Error::Invalid(format!(
                    "binding {binding} is not in the layout"
                )));
            };
            match (b.kind, resource) {
                (
                    BindingKind::StorageBuffer | BindingKind::UniformBuffer,
                    Resource::Buffer(buf),
                ) => buffer_infos.push((
                    *binding,
                    b.kind,
                    [vk::DescriptorBufferInfo::default()
                        .buffer(buf.raw())
                        .offset(buf.offset())
                        .range(buf.size())],
                )),
                (BindingKind::AccelerationStructure, Resource::AccelerationStructure(a)) => {
                    if !a.is_top_level() {
                        return Err(Error::Invalid(format!(
                            "binding {binding} needs a top-level acceleration structure"
                        )));
                    }
                    structures.push((*binding, [a.raw()]))
                }
                (BindingKind::StorageImage, Resource::StorageImage(view))
                | (BindingKind::SampledImage, Resource::SampledImage(view)) => image_infos.push((
                    *binding,
                    b.kind,
                    [vk::DescriptorImageInfo::default()
                        .image_view(*view)
                        .image_layout(vk::ImageLayout::GENERAL)],
                )),
                (BindingKind::Sampler, Resource::Sampler(sampler)) => image_infos.push((
                    *binding,
                    b.kind,
                    [vk::DescriptorImageInfo::default().sampler(*sampler)],
                )),
                (kind, r) => {
                    return Err(Error::Invalid(format!(
                        "binding {binding} is a {kind:?} binding, given {r:?}"
                    )))
                }
            }
        }
        let mut as_writes: Vec<_> = structures
            .iter()
            .map(|(_, s)| {
                vk::WriteDescriptorSetAccelerationStructureKHR::default().acceleration_structures(s)
            })
            .collect();
        let mut writes = Vec::new();
        for (binding, kind, info) in &buffer_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(*binding)
                    .descriptor_type(kind.descriptor_type())
                    .buffer_info(info),
            );
        }
        for (binding, kind, info) in &image_infos {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(*binding)
                    .descriptor_type(kind.descriptor_type())
                    .image_info(info),
            );
        }
        for ((binding, _), next) in structures.iter().zip(as_writes.iter_mut()) {
            // push_next does not set the count for acceleration structures.
            let mut w = vk::WriteDescriptorSet::default()
                .dst_set(self.set)
                .dst_binding(*binding)
                .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                .push_next(next);
            w.descriptor_count = 1;
            writes.push(w);
        }
        // SAFETY: every write points at live infos; no submission is using the
        // set (submissions are waited for).
        unsafe { self.shared.device.update_descriptor_sets(&writes, &[]) };
        Ok(())
    }
}

impl Drop for Descriptors {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: destroying null handles is allowed; nothing is in use.
        unsafe {
            let d = &self.shared.device;
            d.destroy_descriptor_pool(self.pool, None);
            d.destroy_pipeline_layout(self.pipeline_layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
            for l in &self.reflected {
                d.destroy_descriptor_set_layout(*l, None);
            }
        }
    }
}
