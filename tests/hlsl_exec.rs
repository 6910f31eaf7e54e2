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
}

impl Drop for Gpu {
    fn drop(&mut self) {
        unsafe {
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

fn gpu() -> Option<Gpu> {
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
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default().scalar_block_layout(true);
        let device = instance
            .create_device(
                pd,
                &vk::DeviceCreateInfo::default()
                    .queue_create_infos(&qinfo)
                    .push_next(&mut v12),
                None,
            )
            .ok()?;
        let queue = device.get_device_queue(family, 0);
        let memory = instance.get_physical_device_memory_properties(pd);
        Some(Gpu {
            _entry: entry,
            instance,
            device,
            queue,
            family,
            memory,
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
        let memory = d
            .allocate_memory(
                &vk::MemoryAllocateInfo::default()
                    .allocation_size(req.size)
                    .memory_type_index(ty),
                None,
            )
            .unwrap();
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
    let Some(gpu) = gpu() else { return };
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
