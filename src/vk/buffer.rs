//! Host-visible buffers with device addresses.

use super::context::{Context, Shared};
use super::error::{vk_err, Error, Result};
use ash::vk;
use std::sync::Arc;

/// Plain data that can be copied to and from a buffer byte for byte.
///
/// # Safety
/// The type must have no padding and every bit pattern must be valid.
pub unsafe trait Pod: Copy + 'static {}

// SAFETY: primitive numbers and arrays of them have no padding and no invalid
// bit patterns.
unsafe impl Pod for u8 {}
unsafe impl Pod for u32 {}
unsafe impl Pod for i32 {}
unsafe impl Pod for u64 {}
unsafe impl Pod for f32 {}
unsafe impl<T: Pod, const N: usize> Pod for [T; N] {}

/// The bytes of a slice of plain data.
pub fn bytes_of<T: Pod>(data: &[T]) -> &[u8] {
    // SAFETY: Pod types have no padding, so every byte is initialised.
    unsafe { std::slice::from_raw_parts(data.as_ptr().cast(), std::mem::size_of_val(data)) }
}

/// A buffer in host-visible, coherent memory, mapped for its whole life.
///
/// Its usable region starts `offset` bytes into the Vulkan buffer, chosen so
/// that [`Buffer::address`] is a multiple of the alignment asked for: Vulkan
/// does not align buffer device addresses beyond the memory requirements, and
/// scratch memory and shader binding tables need more.
pub struct Buffer {
    shared: Arc<Shared>,
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    mapped: *mut u8,
    offset: u64,
    size: u64,
    address: vk::DeviceAddress,
}

// SAFETY: the mapping is plain memory owned by this buffer; access goes
// through &self/&mut self.
unsafe impl Send for Buffer {}
unsafe impl Sync for Buffer {}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Buffer")
            .field("size", &self.size)
            .field("address", &format_args!("{:#x}", self.address))
            .finish()
    }
}

impl Buffer {
    /// A zeroed buffer of `size` bytes whose device address is a multiple of
    /// `align` (a power of two; 1 for "any"). `SHADER_DEVICE_ADDRESS` usage
    /// is always added.
    pub fn new(
        ctx: &Context,
        size: u64,
        usage: vk::BufferUsageFlags,
        align: u64,
    ) -> Result<Buffer> {
        if !align.is_power_of_two() {
            return Err(Error::Invalid(format!(
                "buffer alignment {align} is not a power of two"
            )));
        }
        let shared = ctx.shared.clone();
        let device = &shared.device;
        let padded = size.max(1) + align - 1;
        let info = vk::BufferCreateInfo::default()
            .size(padded)
            .usage(usage | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create info.
        let buffer =
            unsafe { device.create_buffer(&info, None) }.map_err(vk_err("vkCreateBuffer"))?;
        let destroy_buffer = |e| {
            // SAFETY: the buffer is unused.
            unsafe { device.destroy_buffer(buffer, None) };
            e
        };
        // SAFETY: valid buffer.
        let req = unsafe { device.get_buffer_memory_requirements(buffer) };
        let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        // Device-local and host-visible where the device has it (lavapipe: all
        // memory; NVIDIA: the BAR heap), else plain host memory.
        let type_index = shared
            .memory_type(
                req.memory_type_bits,
                host | vk::MemoryPropertyFlags::DEVICE_LOCAL,
            )
            .or_else(|| shared.memory_type(req.memory_type_bits, host))
            .ok_or_else(|| {
                destroy_buffer(Error::Invalid(
                    "no host-visible coherent memory type fits this buffer".into(),
                ))
            })?;
        let mut flags =
            vk::MemoryAllocateFlagsInfo::default().flags(vk::MemoryAllocateFlags::DEVICE_ADDRESS);
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(type_index)
            .push_next(&mut flags);
        // SAFETY: valid device and allocate info.
        let memory = unsafe { device.allocate_memory(&alloc, None) }
            .map_err(|e| destroy_buffer(vk_err("vkAllocateMemory")(e)))?;
        let release = |e| {
            // SAFETY: neither object is in use.
            unsafe {
                device.destroy_buffer(buffer, None);
                device.free_memory(memory, None);
            }
            e
        };
        // SAFETY: fresh buffer and memory of a fitting type and size.
        unsafe { device.bind_buffer_memory(buffer, memory, 0) }
            .map_err(|e| release(vk_err("vkBindBufferMemory")(e)))?;
        // SAFETY: host-visible memory, mapped once, whole range.
        let mapped =
            unsafe { device.map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty()) }
                .map_err(|e| release(vk_err("vkMapMemory")(e)))?
                .cast::<u8>();
        // SAFETY: the mapping covers req.size >= padded bytes; zeroing makes
        // the contents defined.
        unsafe { std::ptr::write_bytes(mapped, 0, padded as usize) };
        // SAFETY: the buffer has SHADER_DEVICE_ADDRESS usage and bound memory.
        let base = unsafe {
            device.get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(buffer))
        };
        let address = base.next_multiple_of(align);
        Ok(Buffer {
            shared: shared.clone(),
            buffer,
            memory,
            mapped,
            offset: address - base,
            size,
            address,
        })
    }

    /// A buffer holding `data`, with any device address alignment.
    pub fn from_data<T: Pod>(
        ctx: &Context,
        usage: vk::BufferUsageFlags,
        data: &[T],
    ) -> Result<Buffer> {
        Buffer::from_data_aligned(ctx, usage, data, 1)
    }

    pub fn from_data_aligned<T: Pod>(
        ctx: &Context,
        usage: vk::BufferUsageFlags,
        data: &[T],
        align: u64,
    ) -> Result<Buffer> {
        let bytes = bytes_of(data);
        let mut buffer = Buffer::new(ctx, bytes.len() as u64, usage, align)?;
        buffer.write(0, bytes)?;
        Ok(buffer)
    }

    /// Copies `bytes` into the buffer at `offset` (relative to its region).
    pub fn write(&mut self, offset: u64, bytes: &[u8]) -> Result<()> {
        let end = offset.checked_add(bytes.len() as u64);
        if end.is_none_or(|end| end > self.size) {
            return Err(Error::Invalid(format!(
                "write of {} bytes at {offset} overruns a {}-byte buffer",
                bytes.len(),
                self.size
            )));
        }
        // SAFETY: bounds checked above; the mapping is exclusively ours (&mut).
        unsafe {
            std::ptr::copy_nonoverlapping(
                bytes.as_ptr(),
                self.mapped.add((self.offset + offset) as usize),
                bytes.len(),
            )
        };
        Ok(())
    }

    /// The buffer's contents. Call after the work that wrote it has finished
    /// (every harness submission waits on its fence).
    pub fn read(&self) -> Vec<u8> {
        // SAFETY: the region lies inside the mapping; coherent memory needs no
        // invalidation.
        unsafe {
            std::slice::from_raw_parts(self.mapped.add(self.offset as usize), self.size as usize)
        }
        .to_vec()
    }

    /// The contents as little-endian `u32`s (a trailing partial word is dropped).
    pub fn read_u32(&self) -> Vec<u32> {
        self.read()
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    pub fn read_f32(&self) -> Vec<f32> {
        self.read_u32().into_iter().map(f32::from_bits).collect()
    }

    /// Device address of the usable region.
    pub fn address(&self) -> vk::DeviceAddress {
        self.address
    }

    /// Size of the usable region in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    pub fn raw(&self) -> vk::Buffer {
        self.buffer
    }

    /// Offset of the usable region inside [`Buffer::raw`].
    pub fn offset(&self) -> u64 {
        self.offset
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: every harness submission waits for completion, so the
        // buffer is idle; unmapping happens with the free.
        unsafe {
            self.shared.device.destroy_buffer(self.buffer, None);
            self.shared.device.free_memory(self.memory, None);
        }
    }
}
