//! Storage images that shaders write and the host reads back (or fills, to be
//! sampled), and samplers.

use super::buffer::Buffer;
use super::context::{Context, Shared};
use super::error::{vk_err, Error, Result};
use ash::vk;
use std::sync::Arc;

/// A 2D `R32G32B32A32_SFLOAT` image in `GENERAL` layout, cleared to zero, for
/// a `RWTexture2D<float4>` / `rgba32f` storage image binding, or, filled with
/// [`StorageImage::write`], for a sampled `Texture2D` binding.
pub struct StorageImage {
    shared: Arc<Shared>,
    image: vk::Image,
    memory: vk::DeviceMemory,
    view: vk::ImageView,
    width: u32,
    height: u32,
}

impl std::fmt::Debug for StorageImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StorageImage")
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

const FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

fn whole() -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(vk::ImageAspectFlags::COLOR)
        .level_count(1)
        .layer_count(1)
}

impl StorageImage {
    pub fn new(ctx: &Context, width: u32, height: u32) -> Result<StorageImage> {
        if width == 0 || height == 0 {
            return Err(Error::Invalid(format!(
                "a {width}×{height} image has no texels"
            )));
        }
        let shared = ctx.shared.clone();
        let device = &shared.device;
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(FORMAT)
            .extent(vk::Extent3D {
                width,
                height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // Each handle goes into `this` at once, so Drop frees it on a later error.
        let mut this = StorageImage {
            shared: shared.clone(),
            image: vk::Image::null(),
            memory: vk::DeviceMemory::null(),
            view: vk::ImageView::null(),
            width,
            height,
        };
        // SAFETY: valid device and create infos; objects are bound in order.
        unsafe {
            this.image = device
                .create_image(&info, None)
                .map_err(vk_err("vkCreateImage"))?;
            let req = device.get_image_memory_requirements(this.image);
            let type_index = shared
                .memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::DEVICE_LOCAL)
                .or_else(|| {
                    shared.memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::empty())
                })
                .ok_or_else(|| Error::Invalid("no memory type fits the image".into()))?;
            this.memory = device
                .allocate_memory(
                    &vk::MemoryAllocateInfo::default()
                        .allocation_size(req.size)
                        .memory_type_index(type_index),
                    None,
                )
                .map_err(vk_err("vkAllocateMemory"))?;
            device
                .bind_image_memory(this.image, this.memory, 0)
                .map_err(vk_err("vkBindImageMemory"))?;
            this.view = device
                .create_image_view(
                    &vk::ImageViewCreateInfo::default()
                        .image(this.image)
                        .view_type(vk::ImageViewType::TYPE_2D)
                        .format(FORMAT)
                        .subresource_range(whole()),
                    None,
                )
                .map_err(vk_err("vkCreateImageView"))?;
        }
        let image = this.image;
        shared.submit("image to GENERAL", |cmd| {
            let barrier = vk::ImageMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::empty())
                .dst_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::GENERAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image)
                .subresource_range(whole());
            // SAFETY: cmd is recording; the image is live and unused.
            unsafe {
                device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::TOP_OF_PIPE,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::DependencyFlags::empty(),
                    &[],
                    &[],
                    &[barrier],
                );
                device.cmd_clear_color_image(
                    cmd,
                    image,
                    vk::ImageLayout::GENERAL,
                    &vk::ClearColorValue::default(),
                    &[whole()],
                );
            }
        })?;
        Ok(this)
    }

    pub fn view(&self) -> vk::ImageView {
        self.view
    }

    pub fn raw(&self) -> vk::Image {
        self.image
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Replaces every texel, row by row; `texels` holds width × height of them.
    pub fn write(&self, ctx: &Context, texels: &[[f32; 4]]) -> Result<()> {
        let n = self.width as usize * self.height as usize;
        if texels.len() != n {
            return Err(Error::Invalid(format!(
                "a {}×{} image takes {n} texels, given {}",
                self.width,
                self.height,
                texels.len()
            )));
        }
        let staging = Buffer::from_data(ctx, vk::BufferUsageFlags::TRANSFER_SRC, texels)?;
        let device = &self.shared.device;
        let copy = vk::BufferImageCopy::default()
            .buffer_offset(staging.offset())
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: self.width,
                height: self.height,
                depth: 1,
            });
        self.shared.submit("image upload", |cmd| {
            // SAFETY: cmd is recording; image and buffer are live, and earlier
            // work on the image finished with its own submission.
            unsafe {
                device.cmd_copy_buffer_to_image(
                    cmd,
                    staging.raw(),
                    self.image,
                    vk::ImageLayout::GENERAL,
                    &[copy],
                )
            }
        })?;
        Ok(())
    }

    /// The texels, row by row. Call after the work that wrote them has
    /// finished (every harness submission waits on its fence).
    pub fn read(&self, ctx: &Context) -> Result<Vec<[f32; 4]>> {
        let n = u64::from(self.width) * u64::from(self.height);
        let staging = Buffer::new(ctx, n * 16, vk::BufferUsageFlags::TRANSFER_DST, 16)?;
        let device = &self.shared.device;
        let copy = vk::BufferImageCopy::default()
            .buffer_offset(staging.offset())
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .layer_count(1),
            )
            .image_extent(vk::Extent3D {
                width: self.width,
                height: self.height,
                depth: 1,
            });
        self.shared.submit("image readback", |cmd| {
            // SAFETY: cmd is recording; image and buffer are live, and the
            // image's earlier writes finished with their own submission.
            unsafe {
                device.cmd_copy_image_to_buffer(
                    cmd,
                    self.image,
                    vk::ImageLayout::GENERAL,
                    staging.raw(),
                    &[copy],
                )
            }
        })?;
        Ok(staging
            .read_f32()
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect())
    }
}

impl Drop for StorageImage {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: submissions are waited for, so nothing uses the image;
        // destroying null handles is allowed.
        unsafe {
            let d = &self.shared.device;
            d.destroy_image_view(self.view, None);
            d.destroy_image(self.image, None);
            d.free_memory(self.memory, None);
        }
    }
}

/// A sampler with nearest filtering and clamp-to-edge addressing, for a
/// `SamplerState` binding.
pub struct Sampler {
    shared: Arc<Shared>,
    sampler: vk::Sampler,
}

impl std::fmt::Debug for Sampler {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Sampler").finish_non_exhaustive()
    }
}

impl Sampler {
    pub fn nearest(ctx: &Context) -> Result<Sampler> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        // SAFETY: valid device and create info.
        let sampler = unsafe { ctx.shared.device.create_sampler(&info, None) }
            .map_err(vk_err("vkCreateSampler"))?;
        Ok(Sampler {
            shared: ctx.shared.clone(),
            sampler,
        })
    }

    pub fn raw(&self) -> vk::Sampler {
        self.sampler
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: submissions are waited for, so nothing uses the sampler.
        unsafe { self.shared.device.destroy_sampler(self.sampler, None) };
    }
}
