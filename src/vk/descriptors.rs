//! One descriptor set per pipeline, built from a plain binding list and
//! rewritten before each dispatch so its resources are borrowed for exactly
//! as long as the GPU uses them.

use super::accel::AccelerationStructure;
use super::buffer::Buffer;
use super::context::Shared;
use super::error::{vk_err, Error, Result};
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

    /// Points every binding at its resource; each binding needs exactly one.
    pub(crate) fn write(&self, resources: &[(u32, Resource<'_>)]) -> Result<()> {
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
        }
    }
}
