//! Bottom- and top-level acceleration structures.

use super::buffer::Buffer;
use super::context::{Context, Shared};
use super::error::{vk_err, Error, Result};
use ash::vk;
use std::sync::Arc;

/// One geometry of a bottom-level structure.
#[derive(Clone, Copy, Debug)]
pub enum Geometry<'a> {
    /// Indexed triangles: three indices per triangle into `positions`.
    Triangles {
        positions: &'a [[f32; 3]],
        indices: &'a [u32],
        opaque: bool,
    },
    /// Axis-aligned boxes for procedural geometry (an intersection shader
    /// decides what is inside).
    Aabbs { boxes: &'a [Aabb], opaque: bool },
}

/// Matches `VkAabbPositionsKHR`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Aabb {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// One instance of a bottom-level structure in a top-level one.
#[derive(Clone, Copy, Debug)]
pub struct Instance<'a> {
    pub blas: &'a AccelerationStructure,
    /// Row-major 3×4 object-to-world transform.
    pub transform: [[f32; 4]; 3],
    /// `InstanceCustomIndex` (24 bits).
    pub custom_index: u32,
    pub mask: u8,
    /// Offset into the hit region of the shader binding table (24 bits).
    pub sbt_record_offset: u32,
    pub flags: vk::GeometryInstanceFlagsKHR,
}

impl<'a> Instance<'a> {
    /// The identity transform, custom index 0, mask 0xFF, SBT offset 0, no flags.
    pub fn identity(blas: &'a AccelerationStructure) -> Self {
        Instance {
            blas,
            transform: IDENTITY,
            custom_index: 0,
            mask: 0xFF,
            sbt_record_offset: 0,
            flags: vk::GeometryInstanceFlagsKHR::empty(),
        }
    }
}

pub const IDENTITY: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

struct Inner {
    shared: Arc<Shared>,
    handle: vk::AccelerationStructureKHR,
    address: vk::DeviceAddress,
    level: vk::AccelerationStructureTypeKHR,
    _storage: Buffer,
    /// Bottom-level structures a top-level one references by address: they
    /// must live as long as it does.
    _children: Vec<AccelerationStructure>,
}

impl Drop for Inner {
    fn drop(&mut self) {
        if self.shared.hung() {
            return;
        }
        // SAFETY: submissions are waited for, so the structure is idle.
        unsafe {
            self.shared
                .accel
                .destroy_acceleration_structure(self.handle, None)
        };
    }
}

/// A built acceleration structure; clones share it.
#[derive(Clone)]
pub struct AccelerationStructure(Arc<Inner>);

impl std::fmt::Debug for AccelerationStructure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AccelerationStructure")
            .field("level", &self.0.level)
            .field("address", &format_args!("{:#x}", self.0.address))
            .finish()
    }
}

impl AccelerationStructure {
    pub fn raw(&self) -> vk::AccelerationStructureKHR {
        self.0.handle
    }

    pub fn address(&self) -> vk::DeviceAddress {
        self.0.address
    }

    pub fn is_top_level(&self) -> bool {
        self.0.level == vk::AccelerationStructureTypeKHR::TOP_LEVEL
    }

    /// Builds a bottom-level structure from one or more geometries.
    pub fn bottom_level(ctx: &Context, geometries: &[Geometry<'_>]) -> Result<Self> {
        Self::bottom_level_with(
            ctx,
            geometries,
            vk::BuildAccelerationStructureFlagsKHR::empty(),
        )
    }

    /// Builds a bottom-level structure whose triangles' vertex positions hit
    /// shaders may read (`ALLOW_DATA_ACCESS`, for ray-tracing position fetch).
    /// Fails on a device without `VK_KHR_ray_tracing_position_fetch`, where
    /// the flag is invalid.
    pub fn bottom_level_readable(ctx: &Context, geometries: &[Geometry<'_>]) -> Result<Self> {
        if !ctx.info().position_fetch {
            return Err(Error::Invalid(format!(
                "{} lacks VK_KHR_ray_tracing_position_fetch",
                ctx.info().name
            )));
        }
        Self::bottom_level_with(
            ctx,
            geometries,
            vk::BuildAccelerationStructureFlagsKHR::ALLOW_DATA_ACCESS,
        )
    }

    fn bottom_level_with(
        ctx: &Context,
        geometries: &[Geometry<'_>],
        flags: vk::BuildAccelerationStructureFlagsKHR,
    ) -> Result<Self> {
        if geometries.is_empty() {
            return Err(Error::Invalid(
                "a bottom-level structure needs a geometry".into(),
            ));
        }
        let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;
        // Inputs stay alive until the build's fence has signalled.
        let mut inputs = Vec::new();
        let mut vk_geometries = Vec::new();
        let mut ranges = Vec::new();
        for g in geometries {
            match *g {
                Geometry::Triangles {
                    positions,
                    indices,
                    opaque,
                } => {
                    if indices.len() % 3 != 0 || positions.is_empty() {
                        return Err(Error::Invalid(format!(
                            "triangle geometry needs whole triangles ({} indices, {} positions)",
                            indices.len(),
                            positions.len()
                        )));
                    }
                    if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
                        return Err(Error::Invalid(format!(
                            "index {i} is past the {} positions",
                            positions.len()
                        )));
                    }
                    let vertices = Buffer::from_data_aligned(ctx, input, positions, 16)?;
                    let index_buf = Buffer::from_data_aligned(ctx, input, indices, 16)?;
                    let triangles = vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                        .vertex_format(vk::Format::R32G32B32_SFLOAT)
                        .vertex_data(vk::DeviceOrHostAddressConstKHR {
                            device_address: vertices.address(),
                        })
                        .vertex_stride(12)
                        .max_vertex(positions.len() as u32 - 1)
                        .index_type(vk::IndexType::UINT32)
                        .index_data(vk::DeviceOrHostAddressConstKHR {
                            device_address: index_buf.address(),
                        });
                    vk_geometries.push(
                        vk::AccelerationStructureGeometryKHR::default()
                            .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                            .geometry(vk::AccelerationStructureGeometryDataKHR { triangles })
                            .flags(geometry_flags(opaque)),
                    );
                    ranges.push((indices.len() / 3) as u32);
                    inputs.push(vertices);
                    inputs.push(index_buf);
                }
                Geometry::Aabbs { boxes, opaque } => {
                    if boxes.is_empty() {
                        return Err(Error::Invalid("AABB geometry has no boxes".into()));
                    }
                    let flat: Vec<[f32; 6]> = boxes
                        .iter()
                        .map(|b| [b.min[0], b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]])
                        .collect();
                    let data = Buffer::from_data_aligned(ctx, input, &flat, 16)?;
                    let aabbs = vk::AccelerationStructureGeometryAabbsDataKHR::default()
                        .data(vk::DeviceOrHostAddressConstKHR {
                            device_address: data.address(),
                        })
                        .stride(24);
                    vk_geometries.push(
                        vk::AccelerationStructureGeometryKHR::default()
                            .geometry_type(vk::GeometryTypeKHR::AABBS)
                            .geometry(vk::AccelerationStructureGeometryDataKHR { aabbs })
                            .flags(geometry_flags(opaque)),
                    );
                    ranges.push(boxes.len() as u32);
                    inputs.push(data);
                }
            }
        }
        build(
            ctx,
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            &vk_geometries,
            &ranges,
            Vec::new(),
            flags,
        )
    }

    /// Builds a top-level structure over instances of bottom-level ones.
    pub fn top_level(ctx: &Context, instances: &[Instance<'_>]) -> Result<Self> {
        if instances.is_empty() {
            return Err(Error::Invalid(
                "a top-level structure needs an instance".into(),
            ));
        }
        let mut raw = Vec::with_capacity(instances.len());
        for i in instances {
            if i.blas.is_top_level() {
                return Err(Error::Invalid(
                    "an instance must reference a bottom-level structure".into(),
                ));
            }
            if i.custom_index >= 1 << 24 || i.sbt_record_offset >= 1 << 24 {
                return Err(Error::Invalid(format!(
                    "instance custom index {} or SBT offset {} does not fit in 24 bits",
                    i.custom_index, i.sbt_record_offset
                )));
            }
            let mut matrix = [0.0f32; 12];
            for (r, row) in i.transform.iter().enumerate() {
                matrix[r * 4..r * 4 + 4].copy_from_slice(row);
            }
            raw.push(RawInstance {
                transform: matrix,
                custom_index_and_mask: (i.custom_index & 0xFF_FFFF) | (u32::from(i.mask) << 24),
                // Instance flags are 8 bits in the packed record.
                sbt_offset_and_flags: (i.sbt_record_offset & 0xFF_FFFF)
                    | ((i.flags.as_raw() & 0xFF) << 24),
                blas_address: i.blas.address(),
            });
        }
        let words: Vec<u32> = raw.iter().flat_map(RawInstance::words).collect();
        // Instance data must be 16-byte aligned.
        let data = Buffer::from_data_aligned(
            ctx,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR,
            &words,
            16,
        )?;
        let geometry = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::INSTANCES)
            .geometry(vk::AccelerationStructureGeometryDataKHR {
                instances: vk::AccelerationStructureGeometryInstancesDataKHR::default()
                    .array_of_pointers(false)
                    .data(vk::DeviceOrHostAddressConstKHR {
                        device_address: data.address(),
                    }),
            });
        let children = instances.iter().map(|i| i.blas.clone()).collect();
        let built = build(
            ctx,
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            &[geometry],
            &[instances.len() as u32],
            children,
            vk::BuildAccelerationStructureFlagsKHR::empty(),
        );
        drop(data);
        built
    }
}

/// `VkAccelerationStructureInstanceKHR`, written out word by word so its
/// layout (64 bytes) does not depend on Rust's.
struct RawInstance {
    transform: [f32; 12],
    custom_index_and_mask: u32,
    sbt_offset_and_flags: u32,
    blas_address: u64,
}

impl RawInstance {
    fn words(&self) -> impl Iterator<Item = u32> + '_ {
        self.transform.iter().map(|f| f.to_bits()).chain([
            self.custom_index_and_mask,
            self.sbt_offset_and_flags,
            self.blas_address as u32,
            (self.blas_address >> 32) as u32,
        ])
    }
}

fn geometry_flags(opaque: bool) -> vk::GeometryFlagsKHR {
    if opaque {
        vk::GeometryFlagsKHR::OPAQUE
    } else {
        vk::GeometryFlagsKHR::empty()
    }
}

fn build(
    ctx: &Context,
    level: vk::AccelerationStructureTypeKHR,
    geometries: &[vk::AccelerationStructureGeometryKHR<'_>],
    primitive_counts: &[u32],
    children: Vec<AccelerationStructure>,
    flags: vk::BuildAccelerationStructureFlagsKHR,
) -> Result<AccelerationStructure> {
    let shared = &ctx.shared;
    let mut info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
        .ty(level)
        .flags(vk::BuildAccelerationStructureFlagsKHR::PREFER_FAST_TRACE | flags)
        .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
        .geometries(geometries);
    let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
    // SAFETY: the build info describes valid geometries.
    unsafe {
        shared.accel.get_acceleration_structure_build_sizes(
            vk::AccelerationStructureBuildTypeKHR::DEVICE,
            &info,
            primitive_counts,
            &mut sizes,
        )
    };
    let storage = Buffer::new(
        ctx,
        sizes.acceleration_structure_size,
        vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR,
        // Alignment 1 keeps the region at offset 0 of the Vulkan buffer: the
        // structure's offset must be a multiple of 256, its address need not.
        1,
    )?;
    let scratch_align = u64::from(
        shared
            .info
            .ray_tracing
            .min_acceleration_structure_scratch_offset_alignment
            .max(1),
    );
    let scratch = Buffer::new(
        ctx,
        sizes.build_scratch_size,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        scratch_align,
    )?;
    let create = vk::AccelerationStructureCreateInfoKHR::default()
        .buffer(storage.raw())
        .offset(storage.offset())
        .size(sizes.acceleration_structure_size)
        .ty(level);
    // SAFETY: the storage buffer is large enough and has the right usage.
    let handle = unsafe { shared.accel.create_acceleration_structure(&create, None) }
        .map_err(vk_err("vkCreateAccelerationStructureKHR"))?;
    // From here the handle is owned by `inner`, so any error path destroys it.
    let mut inner = Inner {
        shared: shared.clone(),
        handle,
        address: 0,
        level,
        _storage: storage,
        _children: children,
    };
    info = info
        .dst_acceleration_structure(handle)
        .scratch_data(vk::DeviceOrHostAddressKHR {
            device_address: scratch.address(),
        });
    let ranges: Vec<vk::AccelerationStructureBuildRangeInfoKHR> = primitive_counts
        .iter()
        .map(|&n| vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(n))
        .collect();
    shared.submit("acceleration structure build", |cmd| {
        // SAFETY: every address in `info` refers to a live buffer.
        unsafe {
            shared
                .accel
                .cmd_build_acceleration_structures(cmd, &[info], &[&ranges])
        };
    })?;
    drop(scratch);
    // SAFETY: the structure is built.
    inner.address = unsafe {
        shared.accel.get_acceleration_structure_device_address(
            &vk::AccelerationStructureDeviceAddressInfoKHR::default()
                .acceleration_structure(handle),
        )
    };
    Ok(AccelerationStructure(Arc::new(inner)))
}
