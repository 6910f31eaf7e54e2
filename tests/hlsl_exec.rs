#![cfg(feature = "vulkan")]
//! Runs compiled HLSL compute shaders on a Vulkan driver (lavapipe in CI) and
//! checks the values they compute: spirv-val proves modules valid, this proves
//! them right. Skipped without a Vulkan driver unless CI=true.

use ash::vk;
use rtlint::front::hlsl::{self, HlslOptions};
use std::path::Path;

struct Gpu {
    _entry: ash::Entry,
    instance: ash::Instance,
    device: ash::Device,
    queue: vk::Queue,
    family: u32,
    memory: vk::PhysicalDeviceMemoryProperties,
    physical: vk::PhysicalDevice,
    /// Buffers get device addresses (ray tracing needs them).
    bda: bool,
    /// VK_KHR_ray_query is enabled.
    ray_query: bool,
}

impl Drop for Gpu {
    fn drop(&mut self) {
        unsafe {
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// A device; with `rt`, the ray-tracing extensions and buffer device addresses.
fn gpu(rt: bool) -> Option<Gpu> {
    // Like every driver test: no device is a failure, not a skip
    // (scripts/setup installs lavapipe).
    let fail = |what: String| -> Option<Gpu> {
        panic!("no usable Vulkan device (run scripts/setup): {what}")
    };
    unsafe {
        let entry = match ash::Entry::load() {
            Ok(e) => e,
            Err(e) => return fail(e.to_string()),
        };
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_2);
        let instance = match entry.create_instance(
            &vk::InstanceCreateInfo::default().application_info(&app),
            None,
        ) {
            Ok(i) => i,
            Err(e) => return fail(e.to_string()),
        };
        let pdevs = match instance.enumerate_physical_devices() {
            Ok(p) => p,
            Err(e) => return fail(e.to_string()),
        };
        let Some(&pd) = pdevs.first() else {
            instance.destroy_instance(None);
            return fail("no physical device".into());
        };
        let family = instance
            .get_physical_device_queue_family_properties(pd)
            .iter()
            .position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE))?
            as u32;
        let prio = [1.0];
        let qinfo = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(family)
            .queue_priorities(&prio)];
        // HLSL constant-buffer packing needs scalar block layout.
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default()
            .scalar_block_layout(true)
            .buffer_device_address(rt);
        let mut accel = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default()
            .acceleration_structure(true);
        let mut rtp =
            vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
        let mut exts = vec![
            ash::khr::acceleration_structure::NAME.as_ptr(),
            ash::khr::ray_tracing_pipeline::NAME.as_ptr(),
            ash::khr::deferred_host_operations::NAME.as_ptr(),
        ];
        let available = instance
            .enumerate_device_extension_properties(pd)
            .unwrap_or_default();
        let ray_query = rt
            && available
                .iter()
                .any(|e| e.extension_name_as_c_str() == Ok(ash::khr::ray_query::NAME));
        let mut rq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
        if ray_query {
            exts.push(ash::khr::ray_query::NAME.as_ptr());
        }
        // Storage images without a declared format (float3 texels, and Slang's
        // output) need these.
        let core = vk::PhysicalDeviceFeatures::default()
            .shader_storage_image_read_without_format(true)
            .shader_storage_image_write_without_format(true);
        let mut info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&qinfo)
            .enabled_features(&core)
            .push_next(&mut v12);
        if rt {
            info = info
                .enabled_extension_names(&exts)
                .push_next(&mut accel)
                .push_next(&mut rtp);
            if ray_query {
                info = info.push_next(&mut rq);
            }
        }
        let device = match instance.create_device(pd, &info, None) {
            Ok(d) => d,
            Err(e) => {
                instance.destroy_instance(None);
                return fail(format!("device: {e}"));
            }
        };
        let queue = device.get_device_queue(family, 0);
        let memory = instance.get_physical_device_memory_properties(pd);
        Some(Gpu {
            _entry: entry,
            instance,
            device,
            queue,
            family,
            memory,
            physical: pd,
            bda: rt,
            ray_query,
        })
    }
}

struct Buffer {
    buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    ptr: *mut u8,
}

impl Gpu {
    unsafe fn buffer(&self, size: usize, usage: vk::BufferUsageFlags) -> Buffer {
        let d = &self.device;
        let usage = if self.bda {
            usage | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
        } else {
            usage
        };
        let buffer = d
            .create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(size as u64)
                    .usage(usage),
                None,
            )
            .unwrap();
        let req = d.get_buffer_memory_requirements(buffer);
        let want = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let ty = (0..self.memory.memory_type_count)
            .find(|&i| {
                req.memory_type_bits & (1 << i) != 0
                    && self.memory.memory_types[i as usize]
                        .property_flags
                        .contains(want)
            })
            .unwrap();
        let mut flags =
            vk::MemoryAllocateFlagsInfo::default().flags(vk::MemoryAllocateFlags::DEVICE_ADDRESS);
        let mut info = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(ty);
        if self.bda {
            info = info.push_next(&mut flags);
        }
        let memory = d.allocate_memory(&info, None).unwrap();
        d.bind_buffer_memory(buffer, memory, 0).unwrap();
        let ptr = d
            .map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
            .unwrap() as *mut u8;
        std::ptr::write_bytes(ptr, 0, size);
        Buffer {
            buffer,
            memory,
            ptr,
        }
    }

    unsafe fn free(&self, b: Buffer) {
        self.device.unmap_memory(b.memory);
        self.device.destroy_buffer(b.buffer, None);
        self.device.free_memory(b.memory, None);
    }

    /// Runs `entry` once: binding 0 a storage buffer of `out_words`, binding 1
    /// a uniform buffer holding `uniform`. Returns the storage buffer.
    unsafe fn run(&self, words: &[u32], entry: &str, out_words: usize, uniform: &[u8]) -> Vec<u32> {
        let d = &self.device;
        let out = self.buffer(out_words * 4, vk::BufferUsageFlags::STORAGE_BUFFER);
        let ubo = self.buffer(uniform.len().max(16), vk::BufferUsageFlags::UNIFORM_BUFFER);
        std::ptr::copy_nonoverlapping(uniform.as_ptr(), ubo.ptr, uniform.len());
        let module = d
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)
            .unwrap();
        let bindings = [
            vk::DescriptorSetLayoutBinding::default()
                .binding(0)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
            vk::DescriptorSetLayoutBinding::default()
                .binding(1)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
        ];
        let set_layout = d
            .create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
            .unwrap();
        let layouts = [set_layout];
        let pipeline_layout = d
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts),
                None,
            )
            .unwrap();
        let name = std::ffi::CString::new(entry).unwrap();
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(&name);
        let pipeline = d
            .create_compute_pipelines(
                vk::PipelineCache::null(),
                &[vk::ComputePipelineCreateInfo::default()
                    .stage(stage)
                    .layout(pipeline_layout)],
                None,
            )
            .map_err(|e| e.1)
            .unwrap()[0];
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER,
                descriptor_count: 1,
            },
        ];
        let pool = d
            .create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(&sizes),
                None,
            )
            .unwrap();
        let set = d
            .allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
            .unwrap()[0];
        let oinfo = [vk::DescriptorBufferInfo {
            buffer: out.buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        let uinfo = [vk::DescriptorBufferInfo {
            buffer: ubo.buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        d.update_descriptor_sets(
            &[
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(0)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(&oinfo),
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(1)
                    .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                    .buffer_info(&uinfo),
            ],
            &[],
        );
        let cpool = d
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(self.family),
                None,
            )
            .unwrap();
        let cb = d
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(cpool)
                    .command_buffer_count(1),
            )
            .unwrap()[0];
        d.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())
            .unwrap();
        d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipeline);
        d.cmd_bind_descriptor_sets(
            cb,
            vk::PipelineBindPoint::COMPUTE,
            pipeline_layout,
            0,
            &[set],
            &[],
        );
        d.cmd_dispatch(cb, 1, 1, 1);
        d.end_command_buffer(cb).unwrap();
        let fence = d
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .unwrap();
        let cbs = [cb];
        d.queue_submit(
            self.queue,
            &[vk::SubmitInfo::default().command_buffers(&cbs)],
            fence,
        )
        .unwrap();
        d.wait_for_fences(&[fence], true, 10_000_000_000).unwrap();
        let mut result = vec![0u32; out_words];
        std::ptr::copy_nonoverlapping(out.ptr as *const u32, result.as_mut_ptr(), out_words);
        d.destroy_fence(fence, None);
        d.destroy_command_pool(cpool, None);
        d.destroy_descriptor_pool(pool, None);
        d.destroy_pipeline(pipeline, None);
        d.destroy_pipeline_layout(pipeline_layout, None);
        d.destroy_descriptor_set_layout(set_layout, None);
        d.destroy_shader_module(module, None);
        self.free(out);
        self.free(ubo);
        result
    }
}

#[derive(Debug, Clone, Copy)]
enum V {
    I(i32),
    U(u32),
    F(f32),
}

impl V {
    fn bits(self) -> u32 {
        match self {
            V::I(i) => i as u32,
            V::U(u) => u,
            V::F(f) => f.to_bits(),
        }
    }
}

/// The `Inputs` cbuffer of exec_compute.hlsl under HLSL packing.
fn inputs() -> Vec<u8> {
    let mut b = vec![0u8; 128];
    let mut put = |off: usize, v: f32| b[off..off + 4].copy_from_slice(&v.to_le_bytes());
    for (k, v) in [1.0, 2.0, 3.0].iter().enumerate() {
        put(k * 4, *v);
    }
    put(12, 4.0);
    put(16, 5.0);
    put(32, 6.0);
    put(48, 7.0);
    put(52, 8.0);
    put(56, 9.0);
    put(60, 10.0);
    // float3x3, column-major: HLSL column c at 64 + 16 c holds m[0..3][c].
    for col in 0..3 {
        for row in 0..3 {
            put(64 + 16 * col + 4 * row, (10 * row + col) as f32);
        }
    }
    put(108, 11.0);
    b[112] = 1;
    b
}

#[test]
fn compute_semantics_on_the_driver() {
    let Some(gpu) = gpu(false) else { return };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl/exec_compute.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    use V::*;
    let expected = [
        I(3),
        I(-3),
        I(-1),
        U(1),
        F(3.0),
        F(-1.5),
        F(3.0),
        F(1.0),
        F(12.0),
        I(5),
        I(6),
        I(0),
        F(1.0),
        F(2.0),
        F(4.0),
        F(6.0),
        F(8.0),
        F(10.0),
        F(11.0),
        F(21.0),
        F(12.0),
        F(10.0),
        F(1.0),
        F(416.0),
        F(20.0),
        F(-2.0),
        F(3.0),
        I(23),
        I(5),
        I(12),
        F(4.0),
        F(3.0),
        I(10),
        F(6.0),
        U(4),
        U(8),
        U(8),
        U(0x8000_0000),
        I(-1),
        I(3),
        I(3),
        U(2),
        F(2.5),
        F(1.0),
        F(1.0),
        I(11),
        F(7.0),
        F(1.5),
        F(2.0),
        F(0.75),
        U(10),
        I(-2),
        U(3),
        F(-3.0),
        I(1),
        F(2.0),
        I(-4),
        U(1),
        I(6),
        F(8.0),
        I(1),
        F(0.8),
        F(8.0),
        F(1.0),
        F(2.5),
        U(4),
        F(4.0),
        U(0),
        F(0.5),
        F(2.0),
        F(-0.75),
        F(-2.0),
        F(12.0),
        I(45),
        I(-4),
        U(6),
        I(3),
        I(1),
        I(8),
    ];
    let got = unsafe { gpu.run(&entries[0].words, "Main", expected.len() + 4, &inputs()) };
    let mut wrong = Vec::new();
    for (k, want) in expected.iter().enumerate() {
        if got[k] != want.bits() {
            wrong.push(format!(
                "result {k}: got {:#x} (i32 {}, f32 {}), want {want:?}",
                got[k],
                got[k] as i32,
                f32::from_bits(got[k])
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert_eq!(got[expected.len()], 0, "more results than expected");
}

/// Front-end constructs of the DXR corpus (default arguments, templates,
/// classes, inheritance, static members, operator[], sizeof, functional casts,
/// buffers passed to functions) compute what HLSL says on the driver.
#[test]
fn front_end_constructs_on_the_driver() {
    let Some(gpu) = gpu(false) else { return };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl/exec_frontend.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let expected = [
        6.5f32, 2.5, 2.5, 8.0, 10.0, 3.5, 16.0, 7.0, 12.0, 56.0, 3.0, 4.0, 7.5, 7.0, 3.0, 4.5, 3.0,
    ];
    // `sky`: color (1, 2, 3), intensity 0.5.
    let sky: Vec<u8> = [1.0f32, 2.0, 3.0, 0.5]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let got = unsafe { gpu.run(&entries[0].words, "Main", expected.len() + 4, &sky) };
    let got: Vec<f32> = got.iter().map(|w| f32::from_bits(*w)).collect();
    assert_eq!(&got[..expected.len()], &expected[..]);
}

fn align_up(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
}

enum Bind<'b> {
    Accel(vk::AccelerationStructureKHR),
    Storage(&'b Buffer),
    StorageImage(vk::ImageView),
    SampledImage(vk::ImageView),
    Sampler(vk::Sampler),
}

/// Geometry of the one-instance test scenes.
enum Geom {
    /// A triangle in the z = 1 plane; its hypotenuse is x + y = 0.
    Triangle,
    /// The box around a sphere of radius 0.5 at (0, 0, 1).
    SphereBox,
}

struct Scene {
    tlas: vk::AccelerationStructureKHR,
    blas: vk::AccelerationStructureKHR,
    buffers: Vec<Buffer>,
}

impl Gpu {
    unsafe fn address(&self, b: &Buffer) -> u64 {
        self.device
            .get_buffer_device_address(&vk::BufferDeviceAddressInfo::default().buffer(b.buffer))
    }

    unsafe fn submit(&self, record: impl FnOnce(vk::CommandBuffer)) {
        let d = &self.device;
        let pool = d
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(self.family),
                None,
            )
            .unwrap();
        let cb = d
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .command_buffer_count(1),
            )
            .unwrap()[0];
        d.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())
            .unwrap();
        record(cb);
        d.end_command_buffer(cb).unwrap();
        let fence = d
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .unwrap();
        let cbs = [cb];
        d.queue_submit(
            self.queue,
            &[vk::SubmitInfo::default().command_buffers(&cbs)],
            fence,
        )
        .unwrap();
        d.wait_for_fences(&[fence], true, 10_000_000_000).unwrap();
        d.destroy_fence(fence, None);
        d.destroy_command_pool(pool, None);
    }

    fn accel_ext(&self) -> ash::khr::acceleration_structure::Device {
        ash::khr::acceleration_structure::Device::new(&self.instance, &self.device)
    }

    /// Builds an acceleration structure from one geometry; returns it and its buffer.
    unsafe fn build_as(
        &self,
        ty: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR,
    ) -> (vk::AccelerationStructureKHR, Buffer) {
        let ext = self.accel_ext();
        let geoms = [geometry];
        let mut info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(ty)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geoms);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        ext.get_acceleration_structure_build_sizes(
            vk::AccelerationStructureBuildTypeKHR::DEVICE,
            &info,
            &[1],
            &mut sizes,
        );
        let storage = self.buffer(
            sizes.acceleration_structure_size as usize,
            vk::BufferUsageFlags::ACCELERATION_STRUCTURE_STORAGE_KHR,
        );
        let accel = ext
            .create_acceleration_structure(
                &vk::AccelerationStructureCreateInfoKHR::default()
                    .buffer(storage.buffer)
                    .size(sizes.acceleration_structure_size)
                    .ty(ty),
                None,
            )
            .unwrap();
        let scratch = self.buffer(
            sizes.build_scratch_size as usize + 256,
            vk::BufferUsageFlags::STORAGE_BUFFER,
        );
        info = info
            .dst_acceleration_structure(accel)
            .scratch_data(vk::DeviceOrHostAddressKHR {
                device_address: align_up(self.address(&scratch), 256),
            });
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(1)];
        self.submit(|cb| ext.cmd_build_acceleration_structures(cb, &[info], &[&range]));
        self.free(scratch);
        (accel, storage)
    }

    /// One instance of one non-opaque geometry (any-hit shaders run).
    unsafe fn scene(&self, geom: Geom) -> Scene {
        let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;
        let data: Vec<f32> = match geom {
            Geom::Triangle => vec![-0.9, -0.9, 1.0, 0.9, -0.9, 1.0, -0.9, 0.9, 1.0],
            Geom::SphereBox => vec![-0.5, -0.5, 0.5, 0.5, 0.5, 1.5],
        };
        let vb = self.buffer(data.len() * 4, input);
        std::ptr::copy_nonoverlapping(data.as_ptr() as *const u8, vb.ptr, data.len() * 4);
        let addr = vk::DeviceOrHostAddressConstKHR {
            device_address: self.address(&vb),
        };
        let geometry = match geom {
            Geom::Triangle => vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
                .geometry(vk::AccelerationStructureGeometryDataKHR {
                    triangles: vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                        .vertex_format(vk::Format::R32G32B32_SFLOAT)
                        .vertex_data(addr)
                        .vertex_stride(12)
                        .max_vertex(2)
                        .index_type(vk::IndexType::NONE_KHR),
                }),
            Geom::SphereBox => vk::AccelerationStructureGeometryKHR::default()
                .geometry_type(vk::GeometryTypeKHR::AABBS)
                .geometry(vk::AccelerationStructureGeometryDataKHR {
                    aabbs: vk::AccelerationStructureGeometryAabbsDataKHR::default()
                        .data(addr)
                        .stride(24),
                }),
        };
        let (blas, blas_buf) =
            self.build_as(vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL, geometry);
        let blas_addr = self.accel_ext().get_acceleration_structure_device_address(
            &vk::AccelerationStructureDeviceAddressInfoKHR::default().acceleration_structure(blas),
        );
        let instance = vk::AccelerationStructureInstanceKHR {
            transform: vk::TransformMatrixKHR {
                matrix: [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            },
            instance_custom_index_and_mask: vk::Packed24_8::new(0, 0xFF),
            instance_shader_binding_table_record_offset_and_flags: vk::Packed24_8::new(0, 0),
            acceleration_structure_reference: vk::AccelerationStructureReferenceKHR {
                device_handle: blas_addr,
            },
        };
        let size = std::mem::size_of_val(&instance);
        let ib = self.buffer(size, input);
        std::ptr::copy_nonoverlapping(&instance as *const _ as *const u8, ib.ptr, size);
        let inst_geom = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::INSTANCES)
            .geometry(vk::AccelerationStructureGeometryDataKHR {
                instances: vk::AccelerationStructureGeometryInstancesDataKHR::default().data(
                    vk::DeviceOrHostAddressConstKHR {
                        device_address: self.address(&ib),
                    },
                ),
            });
        let (tlas, tlas_buf) =
            self.build_as(vk::AccelerationStructureTypeKHR::TOP_LEVEL, inst_geom);
        Scene {
            tlas,
            blas,
            buffers: vec![vb, blas_buf, ib, tlas_buf],
        }
    }

    unsafe fn drop_scene(&self, scene: Scene) {
        let ext = self.accel_ext();
        ext.destroy_acceleration_structure(scene.tlas, None);
        ext.destroy_acceleration_structure(scene.blas, None);
        for b in scene.buffers {
            self.free(b);
        }
    }

    /// A descriptor set (set 0) with `binds` at bindings 0, 1, ...
    unsafe fn descriptors(
        &self,
        binds: &[Bind],
        stages: vk::ShaderStageFlags,
    ) -> (
        vk::DescriptorSetLayout,
        vk::DescriptorPool,
        vk::DescriptorSet,
    ) {
        let d = &self.device;
        let ty = |b: &Bind| match b {
            Bind::Accel(_) => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            Bind::Storage(_) => vk::DescriptorType::STORAGE_BUFFER,
            Bind::StorageImage(_) => vk::DescriptorType::STORAGE_IMAGE,
            Bind::SampledImage(_) => vk::DescriptorType::SAMPLED_IMAGE,
            Bind::Sampler(_) => vk::DescriptorType::SAMPLER,
        };
        let bindings: Vec<_> = binds
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(ty(b))
                    .descriptor_count(1)
                    .stage_flags(stages)
            })
            .collect();
        let layout = d
            .create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
            .unwrap();
        let sizes: Vec<_> = binds
            .iter()
            .map(|b| vk::DescriptorPoolSize {
                ty: ty(b),
                descriptor_count: 1,
            })
            .collect();
        let pool = d
            .create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(&sizes),
                None,
            )
            .unwrap();
        let layouts = [layout];
        let set = d
            .allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
            .unwrap()[0];
        for (i, b) in binds.iter().enumerate() {
            let w = vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(i as u32)
                .descriptor_type(ty(b))
                .descriptor_count(1);
            match b {
                Bind::Accel(a) => {
                    let list = [*a];
                    let mut aw = vk::WriteDescriptorSetAccelerationStructureKHR::default()
                        .acceleration_structures(&list);
                    d.update_descriptor_sets(&[w.push_next(&mut aw)], &[]);
                }
                Bind::StorageImage(v) | Bind::SampledImage(v) => {
                    let info = [vk::DescriptorImageInfo::default()
                        .image_view(*v)
                        .image_layout(vk::ImageLayout::GENERAL)];
                    d.update_descriptor_sets(&[w.image_info(&info)], &[]);
                }
                Bind::Sampler(smp) => {
                    let info = [vk::DescriptorImageInfo::default().sampler(*smp)];
                    d.update_descriptor_sets(&[w.image_info(&info)], &[]);
                }
                Bind::Storage(buf) => {
                    let info = [vk::DescriptorBufferInfo {
                        buffer: buf.buffer,
                        offset: 0,
                        range: vk::WHOLE_SIZE,
                    }];
                    d.update_descriptor_sets(&[w.buffer_info(&info)], &[]);
                }
            }
        }
        (layout, pool, set)
    }

    /// Builds a ray-tracing pipeline from `module`'s entry points and traces
    /// a `w`×`h` launch. `tables` lists the group indices of the raygen, miss,
    /// hit and callable regions of the shader binding table.
    #[allow(clippy::too_many_arguments)]
    unsafe fn trace(
        &self,
        modules: &[&[u32]],
        stages: &[(&str, vk::ShaderStageFlags)],
        groups: &[vk::RayTracingShaderGroupCreateInfoKHR],
        tables: [&[u32]; 4],
        binds: &[Bind],
        w: u32,
        h: u32,
    ) {
        let d = &self.device;
        let rt_ext = ash::khr::ray_tracing_pipeline::Device::new(&self.instance, d);
        // One module for every stage, or one per stage (Slang's output).
        let shaders: Vec<vk::ShaderModule> = modules
            .iter()
            .map(|w| {
                d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(w), None)
                    .unwrap()
            })
            .collect();
        let names: Vec<std::ffi::CString> = stages
            .iter()
            .map(|(n, _)| std::ffi::CString::new(*n).unwrap())
            .collect();
        let infos: Vec<_> = names
            .iter()
            .zip(stages)
            .enumerate()
            .map(|(i, (n, (_, k)))| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(*k)
                    .module(shaders[i.min(shaders.len() - 1)])
                    .name(n)
            })
            .collect();
        let (set_layout, pool, set) = self.descriptors(binds, vk::ShaderStageFlags::ALL);
        let layouts = [set_layout];
        let pipeline_layout = d
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts),
                None,
            )
            .unwrap();
        let pipeline = rt_ext
            .create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                vk::PipelineCache::null(),
                &[vk::RayTracingPipelineCreateInfoKHR::default()
                    .stages(&infos)
                    .groups(groups)
                    .max_pipeline_ray_recursion_depth(1)
                    .layout(pipeline_layout)],
                None,
            )
            .map_err(|e| e.1)
            .unwrap()[0];
        // Shader binding table: one region per kind, each on the base alignment.
        let mut props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props);
        self.instance
            .get_physical_device_properties2(self.physical, &mut props2);
        let handle = props.shader_group_handle_size as usize;
        let stride = align_up(handle as u64, props.shader_group_handle_alignment as u64);
        let base = props.shader_group_base_alignment as u64;
        let handles = rt_ext
            .get_ray_tracing_shader_group_handles(
                pipeline,
                0,
                groups.len() as u32,
                groups.len() * handle,
            )
            .unwrap();
        let region_size = align_up(stride * 8, base);
        let sbt = self.buffer(
            (4 * region_size + base) as usize,
            vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR,
        );
        let sbt_addr = align_up(self.address(&sbt), base);
        let shift = (sbt_addr - self.address(&sbt)) as usize;
        let mut regions = [vk::StridedDeviceAddressRegionKHR::default(); 4];
        for (r, list) in tables.iter().enumerate() {
            let offset = r as u64 * region_size;
            for (k, g) in list.iter().enumerate() {
                let src = &handles[*g as usize * handle..(*g as usize + 1) * handle];
                let dst = sbt.ptr.add(shift + offset as usize + k * stride as usize);
                std::ptr::copy_nonoverlapping(src.as_ptr(), dst, handle);
            }
            if !list.is_empty() {
                regions[r] = vk::StridedDeviceAddressRegionKHR {
                    device_address: sbt_addr + offset,
                    stride,
                    size: stride * list.len() as u64,
                };
            }
        }
        self.submit(|cb| {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::RAY_TRACING_KHR, pipeline);
            d.cmd_bind_descriptor_sets(
                cb,
                vk::PipelineBindPoint::RAY_TRACING_KHR,
                pipeline_layout,
                0,
                &[set],
                &[],
            );
            rt_ext.cmd_trace_rays(
                cb,
                &regions[0],
                &regions[1],
                &regions[2],
                &regions[3],
                w,
                h,
                1,
            );
        });
        self.free(sbt);
        d.destroy_descriptor_pool(pool, None);
        d.destroy_pipeline(pipeline, None);
        d.destroy_pipeline_layout(pipeline_layout, None);
        d.destroy_descriptor_set_layout(set_layout, None);
        for m in shaders {
            d.destroy_shader_module(m, None);
        }
    }

    /// Runs compute entry `entry` with `binds`, `groups` workgroups along x.
    unsafe fn dispatch(&self, words: &[u32], entry: &str, binds: &[Bind], groups: u32) {
        let d = &self.device;
        let shader = d
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)
            .unwrap();
        let (set_layout, pool, set) = self.descriptors(binds, vk::ShaderStageFlags::COMPUTE);
        let layouts = [set_layout];
        let pipeline_layout = d
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts),
                None,
            )
            .unwrap();
        let name = std::ffi::CString::new(entry).unwrap();
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(shader)
            .name(&name);
        let pipeline = d
            .create_compute_pipelines(
                vk::PipelineCache::null(),
                &[vk::ComputePipelineCreateInfo::default()
                    .stage(stage)
                    .layout(pipeline_layout)],
                None,
            )
            .map_err(|e| e.1)
            .unwrap()[0];
        self.submit(|cb| {
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::COMPUTE, pipeline);
            d.cmd_bind_descriptor_sets(
                cb,
                vk::PipelineBindPoint::COMPUTE,
                pipeline_layout,
                0,
                &[set],
                &[],
            );
            d.cmd_dispatch(cb, groups, 1, 1);
        });
        d.destroy_descriptor_pool(pool, None);
        d.destroy_pipeline(pipeline, None);
        d.destroy_pipeline_layout(pipeline_layout, None);
        d.destroy_descriptor_set_layout(set_layout, None);
        d.destroy_shader_module(shader, None);
    }
}

fn general(i: u32) -> vk::RayTracingShaderGroupCreateInfoKHR<'static> {
    vk::RayTracingShaderGroupCreateInfoKHR::default()
        .ty(vk::RayTracingShaderGroupTypeKHR::GENERAL)
        .general_shader(i)
        .closest_hit_shader(vk::SHADER_UNUSED_KHR)
        .any_hit_shader(vk::SHADER_UNUSED_KHR)
        .intersection_shader(vk::SHADER_UNUSED_KHR)
}

fn hit_group(
    ty: vk::RayTracingShaderGroupTypeKHR,
    closest: u32,
    any: u32,
    intersection: u32,
) -> vk::RayTracingShaderGroupCreateInfoKHR<'static> {
    vk::RayTracingShaderGroupCreateInfoKHR::default()
        .ty(ty)
        .general_shader(vk::SHADER_UNUSED_KHR)
        .closest_hit_shader(closest)
        .any_hit_shader(any)
        .intersection_shader(intersection)
}

/// Pixel centers of the 4×4 launches, shifted so none lies on an edge.
fn pixel(x: u32, y: u32) -> (f32, f32) {
    (
        (x as f32 + 0.5) / 4.0 * 2.0 - 1.0 + 0.1,
        (y as f32 + 0.5) / 4.0 * 2.0 - 1.0,
    )
}

/// Expected triangle result: barycentrics and t where the (any-hit filtered)
/// triangle is hit, else the miss value.
fn triangle_expectation(x: u32, y: u32, hit_w: f32, miss: [f32; 4]) -> [f32; 4] {
    let (px, py) = pixel(x, y);
    let (u, v) = ((px + 0.9) / 1.8, (py + 0.9) / 1.8);
    if px + py < 0.0 && u <= 0.5 {
        [u, v, 2.0, hit_w]
    } else {
        miss
    }
}

fn compare(got: &[[f32; 4]], want: impl Fn(u32, u32) -> [f32; 4]) {
    let mut wrong = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            let g = got[(y * 4 + x) as usize];
            let w = want(x, y);
            if g.iter().zip(w).any(|(a, b)| (a - b).abs() > 1e-4) {
                wrong.push(format!("pixel ({x}, {y}): got {g:?}, want {w:?}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

unsafe fn read4(b: &Buffer, n: usize) -> Vec<[f32; 4]> {
    let mut got = vec![[0f32; 4]; n];
    std::ptr::copy_nonoverlapping(b.ptr as *const [f32; 4], got.as_mut_ptr(), n);
    got
}

fn compile_whole(name: &str) -> Vec<u32> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/hlsl")
        .join(name);
    hlsl::compile_file(&path, &HlslOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .words
}

#[test]
fn ray_tracing_pipeline_on_the_driver() {
    let Some(gpu) = gpu(true) else { return };
    let words = compile_whole("exec_pipeline.hlsl");
    unsafe {
        let scene = gpu.scene(Geom::Triangle);
        let out = gpu.buffer(16 * 16, vk::BufferUsageFlags::STORAGE_BUFFER);
        use vk::ShaderStageFlags as S;
        gpu.trace(
            &[&words],
            &[
                ("RG", S::RAYGEN_KHR),
                ("MissColor", S::MISS_KHR),
                ("MissProbe", S::MISS_KHR),
                ("Hit", S::CLOSEST_HIT_KHR),
                ("Filter", S::ANY_HIT_KHR),
            ],
            &[
                general(0),
                general(1),
                general(2),
                hit_group(
                    vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP,
                    3,
                    4,
                    vk::SHADER_UNUSED_KHR,
                ),
            ],
            [&[0], &[1, 2], &[3], &[]],
            &[Bind::Accel(scene.tlas), Bind::Storage(&out)],
            4,
            4,
        );
        let got = read4(&out, 16);
        // The any-hit shader ignores hits with u > 0.5; the second ray always
        // reaches miss shader 1, which adds 10.
        compare(&got, |x, y| {
            triangle_expectation(x, y, 11.0, [0.0, 0.0, 1.0, 10.0])
        });
        assert!(got.iter().any(|g| g[3] == 11.0) && got.iter().any(|g| g[3] == 10.0));
        gpu.free(out);
        gpu.drop_scene(scene);
    }
}

#[test]
fn intersection_and_callable_on_the_driver() {
    let Some(gpu) = gpu(true) else { return };
    let words = compile_whole("exec_procedural.hlsl");
    unsafe {
        let scene = gpu.scene(Geom::SphereBox);
        let out = gpu.buffer(16 * 16, vk::BufferUsageFlags::STORAGE_BUFFER);
        use vk::ShaderStageFlags as S;
        gpu.trace(
            &[&words],
            &[
                ("Gen", S::RAYGEN_KHR),
                ("Miss", S::MISS_KHR),
                ("SphereHit", S::CLOSEST_HIT_KHR),
                ("Sphere", S::INTERSECTION_KHR),
                ("Twice", S::CALLABLE_KHR),
            ],
            &[
                general(0),
                general(1),
                hit_group(
                    vk::RayTracingShaderGroupTypeKHR::PROCEDURAL_HIT_GROUP,
                    2,
                    vk::SHADER_UNUSED_KHR,
                    3,
                ),
                general(4),
            ],
            [&[0], &[1], &[2], &[3]],
            &[Bind::Accel(scene.tlas), Bind::Storage(&out)],
            4,
            4,
        );
        let got = read4(&out, 16);
        compare(&got, |x, y| {
            let (px, py) = pixel(x, y);
            let called = 2.0 * x as f32 + 1.0;
            let disc = 0.25 - (px * px + py * py);
            if disc > 0.0 {
                let s = disc.sqrt();
                [-2.0 * s, 2.0 - s, 7.0, called]
            } else {
                [0.0, 0.0, 0.0, 100.0 + called]
            }
        });
        assert!(got.iter().any(|g| g[2] == 7.0), "no sphere hits: {got:?}");
        gpu.free(out);
        gpu.drop_scene(scene);
    }
}

#[test]
fn ray_query_on_the_driver() {
    let Some(gpu) = gpu(true) else { return };
    if !gpu.ray_query {
        eprintln!("no VK_KHR_ray_query; skipping");
        return;
    }
    let words = compile_whole("exec_rayquery.hlsl");
    unsafe {
        let scene = gpu.scene(Geom::Triangle);
        let out = gpu.buffer(16 * 16, vk::BufferUsageFlags::STORAGE_BUFFER);
        gpu.dispatch(
            &words,
            "Query",
            &[Bind::Accel(scene.tlas), Bind::Storage(&out)],
            1,
        );
        let got = read4(&out, 16);
        compare(&got, |x, y| {
            triangle_expectation(x, y, 1.0, [0.0, 0.0, 1.0, 0.0])
        });
        gpu.free(out);
        gpu.drop_scene(scene);
    }
}

#[test]
fn groupshared_atomics_and_byte_address_buffers_on_the_driver() {
    let Some(gpu) = gpu(false) else { return };
    let words = compile_whole("exec_memory.hlsl");
    unsafe {
        let raw = gpu.buffer(1024, vk::BufferUsageFlags::STORAGE_BUFFER);
        let init: Vec<u32> = (0..64).map(|i| 1000 + i).collect();
        std::ptr::copy_nonoverlapping(init.as_ptr() as *const u8, raw.ptr, 256);
        let counts = gpu.buffer(16, vk::BufferUsageFlags::STORAGE_BUFFER);
        gpu.dispatch(
            &words,
            "Main",
            &[Bind::Storage(&raw), Bind::Storage(&counts)],
            1,
        );
        let mut r = vec![0u32; 256];
        std::ptr::copy_nonoverlapping(raw.ptr as *const u32, r.as_mut_ptr(), 256);
        for i in 0..64u32 {
            assert_eq!(
                r[64 + i as usize],
                1000 + i + 2 * (63 - i),
                "word {}",
                64 + i
            );
        }
        assert_eq!(&r[128..130], &[2016, 7]);
        assert_eq!(&r[132..136], &[1003, 1002, 1001, 1000]);
        let mut c = [0u32; 4];
        std::ptr::copy_nonoverlapping(counts.ptr as *const u32, c.as_mut_ptr(), 4);
        assert_eq!(&c[..3], &[63, 64, u32::MAX]);
        assert!((1..=64).contains(&c[3]), "compare-exchange stored {}", c[3]);
        assert_eq!(&r[192..194], &[128, 189]);
        gpu.free(raw);
        gpu.free(counts);
    }
}

struct Image {
    image: vk::Image,
    memory: vk::DeviceMemory,
    view: vk::ImageView,
}

impl Gpu {
    /// A linear, host-visible RGBA32F image in GENERAL layout, filled with `texels`.
    unsafe fn image(
        &self,
        w: u32,
        h: u32,
        usage: vk::ImageUsageFlags,
        texels: &[[f32; 4]],
    ) -> Image {
        let d = &self.device;
        let format = vk::Format::R32G32B32A32_SFLOAT;
        let image = d
            .create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width: w,
                        height: h,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::LINEAR)
                    .usage(usage)
                    .initial_layout(vk::ImageLayout::PREINITIALIZED),
                None,
            )
            .unwrap();
        let req = d.get_image_memory_requirements(image);
        let want = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let ty = (0..self.memory.memory_type_count)
            .find(|&i| {
                req.memory_type_bits & (1 << i) != 0
                    && self.memory.memory_types[i as usize]
                        .property_flags
                        .contains(want)
            })
            .unwrap();
        let memory = d
            .allocate_memory(
                &vk::MemoryAllocateInfo::default()
                    .allocation_size(req.size)
                    .memory_type_index(ty),
                None,
            )
            .unwrap();
        d.bind_image_memory(image, memory, 0).unwrap();
        let layout = d.get_image_subresource_layout(
            image,
            vk::ImageSubresource {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                array_layer: 0,
            },
        );
        let ptr = d
            .map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
            .unwrap() as *mut u8;
        for y in 0..h as usize {
            for x in 0..w as usize {
                if let Some(t) = texels.get(y * w as usize + x) {
                    let at =
                        ptr.add(layout.offset as usize + y * layout.row_pitch as usize + x * 16);
                    std::ptr::copy_nonoverlapping(t.as_ptr() as *const u8, at, 16);
                }
            }
        }
        d.unmap_memory(memory);
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        self.submit(|cb| {
            let barrier = vk::ImageMemoryBarrier::default()
                .old_layout(vk::ImageLayout::PREINITIALIZED)
                .new_layout(vk::ImageLayout::GENERAL)
                .src_access_mask(vk::AccessFlags::HOST_WRITE)
                .dst_access_mask(vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE)
                .image(image)
                .subresource_range(range);
            d.cmd_pipeline_barrier(
                cb,
                vk::PipelineStageFlags::HOST,
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            );
        });
        let view = d
            .create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(range),
                None,
            )
            .unwrap();
        Image {
            image,
            memory,
            view,
        }
    }

    unsafe fn free_image(&self, i: Image) {
        self.device.destroy_image_view(i.view, None);
        self.device.destroy_image(i.image, None);
        self.device.free_memory(i.memory, None);
    }
}

#[test]
fn textures_and_storage_images_on_the_driver() {
    let Some(gpu) = gpu(false) else { return };
    let words = compile_whole("exec_textures.hlsl");
    unsafe {
        let d = &gpu.device;
        let texels = [
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 2.0, 0.0, 1.0],
            [0.0, 0.0, 3.0, 1.0],
            [4.0, 4.0, 4.0, 1.0],
        ];
        let tex = gpu.image(2, 2, vk::ImageUsageFlags::SAMPLED, &texels);
        let img = gpu.image(4, 4, vk::ImageUsageFlags::STORAGE, &[]);
        let sampler = d
            .create_sampler(
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::NEAREST)
                    .min_filter(vk::Filter::NEAREST)
                    .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE),
                None,
            )
            .unwrap();
        let out = gpu.buffer(16 * 16, vk::BufferUsageFlags::STORAGE_BUFFER);
        gpu.dispatch(
            &words,
            "Main",
            &[
                Bind::SampledImage(tex.view),
                Bind::Sampler(sampler),
                Bind::StorageImage(img.view),
                Bind::Storage(&out),
            ],
            1,
        );
        let got = read4(&out, 16);
        for (i, g) in got.iter().enumerate() {
            let (x, y) = (i % 4, i / 4);
            // Nearest sampling of the 2x2 texture at the 4x4 pixel centers,
            // plus a texel fetch, plus what the storage image read back.
            let sampled = texels[(y / 2) * 2 + x / 2];
            let fetched = texels[(y % 2) * 2 + x % 2];
            let stored = [x as f32, y as f32, 0.5, 1.0];
            let want: Vec<f32> = (0..4)
                .map(|c| sampled[c] + 10.0 * fetched[c] + 100.0 * stored[c])
                .collect();
            assert_eq!(g.to_vec(), want, "pixel {i}");
        }
        d.destroy_sampler(sampler, None);
        gpu.free(out);
        gpu.free_image(tex);
        gpu.free_image(img);
    }
}

/// Runs `entry` of `file` once and returns every output buffer's bytes;
/// `setup` makes the bindings, `run` dispatches.
unsafe fn run_compute_case(gpu: &Gpu, words: &[u32], entry: &str, file: &str) -> Vec<Vec<u8>> {
    let read = |b: &Buffer, n: usize| std::slice::from_raw_parts(b.ptr, n).to_vec();
    match file {
        "exec_memory.hlsl" => {
            let raw = gpu.buffer(1024, vk::BufferUsageFlags::STORAGE_BUFFER);
            let init: Vec<u32> = (0..64).map(|i| 1000 + i).collect();
            std::ptr::copy_nonoverlapping(init.as_ptr() as *const u8, raw.ptr, 256);
            let counts = gpu.buffer(16, vk::BufferUsageFlags::STORAGE_BUFFER);
            gpu.dispatch(
                words,
                entry,
                &[Bind::Storage(&raw), Bind::Storage(&counts)],
                1,
            );
            // Word 195 onward and the compare-exchange winner depend on scheduling.
            let mut r = read(&raw, 772);
            r.truncate(768);
            let mut c = read(&counts, 12);
            c.truncate(12);
            gpu.free(raw);
            gpu.free(counts);
            vec![r, c]
        }
        "exec_textures.hlsl" => {
            let texels = [
                [1.0f32, 0.0, 0.0, 1.0],
                [0.0, 2.0, 0.0, 1.0],
                [0.0, 0.0, 3.0, 1.0],
                [4.0, 4.0, 4.0, 1.0],
            ];
            let tex = gpu.image(2, 2, vk::ImageUsageFlags::SAMPLED, &texels);
            let img = gpu.image(4, 4, vk::ImageUsageFlags::STORAGE, &[]);
            let sampler = gpu
                .device
                .create_sampler(
                    &vk::SamplerCreateInfo::default()
                        .mag_filter(vk::Filter::NEAREST)
                        .min_filter(vk::Filter::NEAREST),
                    None,
                )
                .unwrap();
            let out = gpu.buffer(256, vk::BufferUsageFlags::STORAGE_BUFFER);
            gpu.dispatch(
                words,
                entry,
                &[
                    Bind::SampledImage(tex.view),
                    Bind::Sampler(sampler),
                    Bind::StorageImage(img.view),
                    Bind::Storage(&out),
                ],
                1,
            );
            let r = read(&out, 256);
            gpu.device.destroy_sampler(sampler, None);
            gpu.free(out);
            gpu.free_image(tex);
            gpu.free_image(img);
            vec![r]
        }
        _ => unreachable!("no setup for {file}"),
    }
}

/// Sets `OpSource`'s language to Unknown: Slang writes a code (11) that older
/// SPIR-V consumers reject.
fn unknown_source_language(words: &mut [u32]) {
    let mut i = 5;
    while i < words.len() {
        let n = (words[i] >> 16) as usize;
        if words[i] & 0xffff == 3 && n > 1 {
            words[i + 1] = 0;
        }
        i += n.max(1);
    }
}

/// The same HLSL compiled by Slang and by rtlint computes the same bytes on
/// the driver. Skipped when Slang is missing, unless CI=true.
#[test]
fn differential_against_slang_on_the_driver() {
    let slang = match rtlint::front::slang::Slang::find() {
        Ok(s) => s,
        Err(e) => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "Slang is required in CI: {e}"
            );
            eprintln!("no Slang ({e}); skipping");
            return;
        }
    };
    let Some(gpu) = gpu(false) else { return };
    let mut compared = 0;
    for file in ["exec_memory.hlsl", "exec_textures.hlsl"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/hlsl")
            .join(file);
        let ours = compile_whole(file);
        let mut theirs = slang.compile_hlsl(&path, "Main", "compute", &[]).unwrap();
        unknown_source_language(&mut theirs);
        // Compare only where Slang's module is valid: for `img[p].z *= 2.0`
        // Slang 2026.12 emits an OpImageTexelPointer to a vector, which
        // spirv-val and lavapipe reject.
        if let Some(why) = invalid_spirv(&theirs) {
            eprintln!("{file}: Slang's module is invalid, not compared: {why}");
            continue;
        }
        compared += 1;
        unsafe {
            let a = run_compute_case(&gpu, &ours, "Main", file);
            // Slang names every entry point `main`.
            let b = run_compute_case(&gpu, &theirs, "main", file);
            assert_eq!(a, b, "{file}: rtlint and Slang disagree");
        }
    }
    assert!(compared >= 1, "nothing was compared");
    drop(gpu);
    // Inline ray tracing, where the driver has ray queries.
    let Some(rt) = self::gpu(true) else { return };
    if !rt.ray_query {
        return;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl/exec_rayquery.hlsl");
    let ours = compile_whole("exec_rayquery.hlsl");
    let mut theirs = slang.compile_hlsl(&path, "Query", "compute", &[]).unwrap();
    unknown_source_language(&mut theirs);
    assert_eq!(invalid_spirv(&theirs), None);
    let run = |words: &[u32], entry: &str| unsafe {
        let scene = rt.scene(Geom::Triangle);
        let out = rt.buffer(256, vk::BufferUsageFlags::STORAGE_BUFFER);
        rt.dispatch(
            words,
            entry,
            &[Bind::Accel(scene.tlas), Bind::Storage(&out)],
            1,
        );
        let bytes = std::slice::from_raw_parts(out.ptr, 256).to_vec();
        rt.free(out);
        rt.drop_scene(scene);
        bytes
    };
    assert_eq!(
        run(&ours, "Query"),
        run(&theirs, "main"),
        "ray query: rtlint and Slang disagree"
    );
}

/// spirv-val's complaint about `words`, if any (None also when spirv-val is missing).
fn invalid_spirv(words: &[u32]) -> Option<String> {
    let file = std::env::temp_dir().join(format!("rtlint-diff-{}.spv", std::process::id()));
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(&file, bytes).ok()?;
    let out = std::process::Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .arg(&file)
        .output()
        .ok()?;
    let _ = std::fs::remove_file(&file);
    (!out.status.success()).then(|| {
        String::from_utf8_lossy(&out.stderr)
            .lines()
            .next()
            .unwrap_or("")
            .to_string()
    })
}

/// The ray-tracing pipeline and the procedural/callable pipeline compiled by
/// Slang (one module per entry point) and by rtlint give the same bytes.
#[test]
fn ray_tracing_differential_against_slang_on_the_driver() {
    let slang = match rtlint::front::slang::Slang::find() {
        Ok(s) => s,
        Err(e) => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "Slang is required in CI: {e}"
            );
            eprintln!("no Slang ({e}); skipping");
            return;
        }
    };
    let Some(gpu) = gpu(true) else { return };
    use vk::ShaderStageFlags as S;
    let tri = vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP;
    let proc_ = vk::RayTracingShaderGroupTypeKHR::PROCEDURAL_HIT_GROUP;
    let none = vk::SHADER_UNUSED_KHR;
    type Case<'c> = (
        &'c str,
        Geom,
        Vec<(&'c str, S, &'c str)>,
        Vec<vk::RayTracingShaderGroupCreateInfoKHR<'static>>,
        [&'c [u32]; 4],
    );
    let cases: Vec<Case> = vec![
        (
            "exec_pipeline.hlsl",
            Geom::Triangle,
            vec![
                ("RG", S::RAYGEN_KHR, "raygeneration"),
                ("MissColor", S::MISS_KHR, "miss"),
                ("MissProbe", S::MISS_KHR, "miss"),
                ("Hit", S::CLOSEST_HIT_KHR, "closesthit"),
                ("Filter", S::ANY_HIT_KHR, "anyhit"),
            ],
            vec![
                general(0),
                general(1),
                general(2),
                hit_group(tri, 3, 4, none),
            ],
            [&[0], &[1, 2], &[3], &[]],
        ),
        (
            "exec_procedural.hlsl",
            Geom::SphereBox,
            vec![
                ("Gen", S::RAYGEN_KHR, "raygeneration"),
                ("Miss", S::MISS_KHR, "miss"),
                ("SphereHit", S::CLOSEST_HIT_KHR, "closesthit"),
                ("Sphere", S::INTERSECTION_KHR, "intersection"),
                ("Twice", S::CALLABLE_KHR, "callable"),
            ],
            vec![
                general(0),
                general(1),
                hit_group(proc_, 2, none, 3),
                general(4),
            ],
            [&[0], &[1], &[2], &[3]],
        ),
    ];
    let mut compared = 0;
    for (file, geom, stages, groups, tables) in cases {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/hlsl")
            .join(file);
        let ours = compile_whole(file);
        let mut theirs = Vec::new();
        for (entry, _, stage) in &stages {
            let mut w = slang
                .compile_hlsl(&path, entry, stage, &[])
                .unwrap_or_else(|e| panic!("{e}"));
            unknown_source_language(&mut w);
            if let Some(why) = invalid_spirv(&w) {
                panic!("{file}: Slang's {entry} is invalid: {why}");
            }
            theirs.push(w);
        }
        let run = |modules: &[&[u32]], names: &[&str]| unsafe {
            let scene = gpu.scene(match geom {
                Geom::Triangle => Geom::Triangle,
                Geom::SphereBox => Geom::SphereBox,
            });
            let out = gpu.buffer(16 * 16, vk::BufferUsageFlags::STORAGE_BUFFER);
            let st: Vec<(&str, S)> = names
                .iter()
                .zip(&stages)
                .map(|(n, (_, k, _))| (*n, *k))
                .collect();
            gpu.trace(
                modules,
                &st,
                &groups,
                tables,
                &[Bind::Accel(scene.tlas), Bind::Storage(&out)],
                4,
                4,
            );
            let bytes = std::slice::from_raw_parts(out.ptr, 256).to_vec();
            gpu.free(out);
            gpu.drop_scene(scene);
            bytes
        };
        let our_names: Vec<&str> = stages.iter().map(|(n, _, _)| *n).collect();
        let a = run(&[&ours], &our_names);
        let slang_modules: Vec<&[u32]> = theirs.iter().map(|w| w.as_slice()).collect();
        let b = run(&slang_modules, &vec!["main"; stages.len()]);
        assert_eq!(a, b, "{file}: rtlint and Slang disagree");
        compared += 1;
    }
    assert_eq!(compared, 2);
}
