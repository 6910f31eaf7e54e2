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
    let fail = |what: String| -> Option<Gpu> {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "Vulkan is required in CI: {what}"
        );
        eprintln!("no Vulkan driver ({what}); skipping");
        None
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
        let pdevs = instance.enumerate_physical_devices().ok()?;
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
        let exts = [
            ash::khr::acceleration_structure::NAME.as_ptr(),
            ash::khr::ray_tracing_pipeline::NAME.as_ptr(),
            ash::khr::deferred_host_operations::NAME.as_ptr(),
        ];
        let mut info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&qinfo)
            .push_next(&mut v12);
        if rt {
            info = info
                .enabled_extension_names(&exts)
                .push_next(&mut accel)
                .push_next(&mut rtp);
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

fn align_up(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
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

    /// Builds an acceleration structure from one geometry; returns it and its buffer.
    unsafe fn build_as(
        &self,
        ext: &ash::khr::acceleration_structure::Device,
        ty: vk::AccelerationStructureTypeKHR,
        geometry: vk::AccelerationStructureGeometryKHR,
        count: u32,
    ) -> (vk::AccelerationStructureKHR, Buffer) {
        let geoms = [geometry];
        let mut info = vk::AccelerationStructureBuildGeometryInfoKHR::default()
            .ty(ty)
            .mode(vk::BuildAccelerationStructureModeKHR::BUILD)
            .geometries(&geoms);
        let mut sizes = vk::AccelerationStructureBuildSizesInfoKHR::default();
        ext.get_acceleration_structure_build_sizes(
            vk::AccelerationStructureBuildTypeKHR::DEVICE,
            &info,
            &[count],
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
        let range = [vk::AccelerationStructureBuildRangeInfoKHR::default().primitive_count(count)];
        self.submit(|cb| ext.cmd_build_acceleration_structures(cb, &[info], &[&range]));
        self.free(scratch);
        (accel, storage)
    }
}

#[test]
fn ray_tracing_pipeline_on_the_driver() {
    let Some(gpu) = gpu(true) else { return };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl/exec_pipeline.hlsl");
    let module =
        hlsl::compile_file(&path, &HlslOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    unsafe {
        let d = &gpu.device;
        let accel_ext = ash::khr::acceleration_structure::Device::new(&gpu.instance, d);
        let rt_ext = ash::khr::ray_tracing_pipeline::Device::new(&gpu.instance, d);
        let input = vk::BufferUsageFlags::ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_KHR;

        // One triangle in the z = 1 plane; its hypotenuse is x + y = 0.
        let verts: [f32; 9] = [-0.9, -0.9, 1.0, 0.9, -0.9, 1.0, -0.9, 0.9, 1.0];
        let vb = gpu.buffer(36, input);
        std::ptr::copy_nonoverlapping(verts.as_ptr() as *const u8, vb.ptr, 36);
        let tri = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::TRIANGLES)
            .geometry(vk::AccelerationStructureGeometryDataKHR {
                triangles: vk::AccelerationStructureGeometryTrianglesDataKHR::default()
                    .vertex_format(vk::Format::R32G32B32_SFLOAT)
                    .vertex_data(vk::DeviceOrHostAddressConstKHR {
                        device_address: gpu.address(&vb),
                    })
                    .vertex_stride(12)
                    .max_vertex(2)
                    .index_type(vk::IndexType::NONE_KHR),
            });
        let (blas, blas_buf) = gpu.build_as(
            &accel_ext,
            vk::AccelerationStructureTypeKHR::BOTTOM_LEVEL,
            tri,
            1,
        );
        let blas_addr = accel_ext.get_acceleration_structure_device_address(
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
        let ib = gpu.buffer(std::mem::size_of_val(&instance), input);
        std::ptr::copy_nonoverlapping(
            &instance as *const _ as *const u8,
            ib.ptr,
            std::mem::size_of_val(&instance),
        );
        let inst_geom = vk::AccelerationStructureGeometryKHR::default()
            .geometry_type(vk::GeometryTypeKHR::INSTANCES)
            .geometry(vk::AccelerationStructureGeometryDataKHR {
                instances: vk::AccelerationStructureGeometryInstancesDataKHR::default().data(
                    vk::DeviceOrHostAddressConstKHR {
                        device_address: gpu.address(&ib),
                    },
                ),
            });
        let (tlas, tlas_buf) = gpu.build_as(
            &accel_ext,
            vk::AccelerationStructureTypeKHR::TOP_LEVEL,
            inst_geom,
            1,
        );

        // Pipeline: raygen, miss 0, miss 1, hit group (closest hit + any hit).
        let shader = d
            .create_shader_module(
                &vk::ShaderModuleCreateInfo::default().code(&module.words),
                None,
            )
            .unwrap();
        let names: Vec<std::ffi::CString> = ["RG", "MissColor", "MissProbe", "Hit", "Filter"]
            .iter()
            .map(|n| std::ffi::CString::new(*n).unwrap())
            .collect();
        let kinds = [
            vk::ShaderStageFlags::RAYGEN_KHR,
            vk::ShaderStageFlags::MISS_KHR,
            vk::ShaderStageFlags::MISS_KHR,
            vk::ShaderStageFlags::CLOSEST_HIT_KHR,
            vk::ShaderStageFlags::ANY_HIT_KHR,
        ];
        let stages: Vec<_> = names
            .iter()
            .zip(kinds)
            .map(|(n, k)| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(k)
                    .module(shader)
                    .name(n)
            })
            .collect();
        let general = |i: u32| {
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::GENERAL)
                .general_shader(i)
                .closest_hit_shader(vk::SHADER_UNUSED_KHR)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR)
        };
        let groups = [
            general(0),
            general(1),
            general(2),
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::TRIANGLES_HIT_GROUP)
                .general_shader(vk::SHADER_UNUSED_KHR)
                .closest_hit_shader(3)
                .any_hit_shader(4)
                .intersection_shader(vk::SHADER_UNUSED_KHR),
        ];
        let bindings = [
            vk::DescriptorSetLayoutBinding::default()
                .binding(0)
                .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::RAYGEN_KHR),
            vk::DescriptorSetLayoutBinding::default()
                .binding(1)
                .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::RAYGEN_KHR),
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
        let pipeline = rt_ext
            .create_ray_tracing_pipelines(
                vk::DeferredOperationKHR::null(),
                vk::PipelineCache::null(),
                &[vk::RayTracingPipelineCreateInfoKHR::default()
                    .stages(&stages)
                    .groups(&groups)
                    .max_pipeline_ray_recursion_depth(1)
                    .layout(pipeline_layout)],
                None,
            )
            .map_err(|e| e.1)
            .unwrap()[0];

        // Shader binding table: one region per kind, each on the base alignment.
        let mut props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props);
        gpu.instance
            .get_physical_device_properties2(gpu.physical, &mut props2);
        let handle = props.shader_group_handle_size as usize;
        let stride = align_up(handle as u64, props.shader_group_handle_alignment as u64);
        let base = props.shader_group_base_alignment as u64;
        let handles = rt_ext
            .get_ray_tracing_shader_group_handles(pipeline, 0, 4, 4 * handle)
            .unwrap();
        let regions = [
            (0u64, 1usize, 0usize),
            (base, 2, 1),
            (2 * base + align_up(2 * stride, base), 1, 3),
        ];
        let sbt = gpu.buffer(
            8 * base as usize,
            vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR,
        );
        let sbt_addr = align_up(gpu.address(&sbt), base);
        let shift = (sbt_addr - gpu.address(&sbt)) as usize;
        for (offset, count, first) in regions {
            for k in 0..count {
                let src = &handles[(first + k) * handle..(first + k + 1) * handle];
                let dst = sbt.ptr.add(shift + offset as usize + k * stride as usize);
                std::ptr::copy_nonoverlapping(src.as_ptr(), dst, handle);
            }
        }
        let region = |(offset, count, _): (u64, usize, usize), raygen: bool| {
            vk::StridedDeviceAddressRegionKHR {
                device_address: sbt_addr + offset,
                stride,
                size: if raygen {
                    stride
                } else {
                    stride * count as u64
                },
            }
        };

        let (w, h) = (4u32, 4u32);
        let out = gpu.buffer((w * h * 16) as usize, vk::BufferUsageFlags::STORAGE_BUFFER);
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
                descriptor_count: 1,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_BUFFER,
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
        let tlases = [tlas];
        let mut as_write = vk::WriteDescriptorSetAccelerationStructureKHR::default()
            .acceleration_structures(&tlases);
        let oinfo = [vk::DescriptorBufferInfo {
            buffer: out.buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        }];
        d.update_descriptor_sets(
            &[
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(0)
                    .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                    .descriptor_count(1)
                    .push_next(&mut as_write),
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(1)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(&oinfo),
            ],
            &[],
        );
        gpu.submit(|cb| {
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
                &region(regions[0], true),
                &region(regions[1], false),
                &region(regions[2], false),
                &vk::StridedDeviceAddressRegionKHR::default(),
                w,
                h,
                1,
            );
        });
        let mut got = vec![[0f32; 4]; (w * h) as usize];
        std::ptr::copy_nonoverlapping(out.ptr as *const [f32; 4], got.as_mut_ptr(), got.len());

        let mut wrong = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let px = (x as f32 + 0.5) / w as f32 * 2.0 - 1.0 + 0.1;
                let py = (y as f32 + 0.5) / h as f32 * 2.0 - 1.0;
                let (u, v) = ((px + 0.9) / 1.8, (py + 0.9) / 1.8);
                let inside = px + py < 0.0;
                // The any-hit shader ignores hits with u > 0.5; the second ray
                // always reaches miss shader 1, which adds 10.
                let want = if inside && u <= 0.5 {
                    [u, v, 2.0, 11.0]
                } else {
                    [0.0, 0.0, 1.0, 10.0]
                };
                let g = got[(y * w + x) as usize];
                if g.iter().zip(want).any(|(a, b)| (a - b).abs() > 1e-4) {
                    wrong.push(format!("pixel ({x}, {y}): got {g:?}, want {want:?}"));
                }
            }
        }
        assert!(wrong.is_empty(), "{}", wrong.join("\n"));
        // Both outcomes occur, and both hit filters matter.
        assert!(got.iter().any(|g| g[3] == 11.0) && got.iter().any(|g| g[3] == 10.0));

        d.destroy_descriptor_pool(pool, None);
        d.destroy_pipeline(pipeline, None);
        d.destroy_pipeline_layout(pipeline_layout, None);
        d.destroy_descriptor_set_layout(set_layout, None);
        d.destroy_shader_module(shader, None);
        accel_ext.destroy_acceleration_structure(tlas, None);
        accel_ext.destroy_acceleration_structure(blas, None);
        for b in [out, sbt, ib, vb, tlas_buf, blas_buf] {
            gpu.free(b);
        }
    }
}
