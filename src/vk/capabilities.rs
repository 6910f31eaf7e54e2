//! What a pipeline's modules need from the device: each `OpCapability` the
//! Vulkan environment ties to an extension or a feature, checked against
//! what the context enabled, so that a device lacking one skips the
//! pipeline with a message instead of failing under the validation layer.

use super::DeviceInfo;
use crate::pipeline::Pipeline;
use spirv::Capability as Cap;

/// The requirement a capability carries, or `None` for one every
/// ray-tracing device has (Shader, RayTracingKHR, Int8 storage…) or one the
/// context always enables.
fn requirement(cap: Cap, info: &DeviceInfo) -> Option<(&'static str, bool)> {
    Some(match cap {
        Cap::ShaderClockKHR => (
            "VK_KHR_shader_clock (shaderSubgroupClock)",
            info.shader_clock,
        ),
        Cap::Int64 => ("shaderInt64", info.shader_int64),
        Cap::Float64 => ("shaderFloat64", info.shader_float64),
        Cap::Int16
        | Cap::Float16
        | Cap::StorageBuffer16BitAccess
        | Cap::UniformAndStorageBuffer16BitAccess
        | Cap::StoragePushConstant16
        | Cap::StorageInputOutput16 => (
            "16-bit types (shaderFloat16, shaderInt16, storageBuffer16BitAccess)",
            info.sixteen_bit,
        ),
        Cap::RuntimeDescriptorArray => ("runtimeDescriptorArray", info.runtime_descriptor_array),
        Cap::RayQueryKHR => ("VK_KHR_ray_query", info.ray_query),
        Cap::RayTracingPositionFetchKHR => (
            "VK_KHR_ray_tracing_position_fetch (enabled only under a validation layer of 1.3.250 or later)",
            info.position_fetch,
        ),
        Cap::ShaderInvocationReorderNV => (
            "VK_NV_ray_tracing_invocation_reorder",
            info.invocation_reorder,
        ),
        Cap::Geometry => ("geometryShader", info.geometry_shader),
        Cap::StorageImageReadWithoutFormat | Cap::StorageImageWriteWithoutFormat => (
            "shaderStorageImageReadWithoutFormat and shaderStorageImageWriteWithoutFormat",
            info.storage_image_without_format,
        ),
        _ => return None,
    })
}

/// The capabilities a module declares (`OpCapability`, opcode 17).
fn capabilities(words: &[u32]) -> Vec<Cap> {
    let mut out = Vec::new();
    let mut at = 5;
    while at < words.len() {
        let count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        if count == 0 {
            break;
        }
        match opcode {
            17 => {
                if let Some(c) = words.get(at + 1).and_then(|&c| Cap::from_u32(c)) {
                    out.push(c);
                }
            }
            // OpCapability leads the module; past the memory model
            // (opcode 14) none can follow.
            14 => break,
            _ => {}
        }
        at += count;
    }
    out
}

/// What the pipeline's modules need that this device lacks (or that was
/// left disabled), one entry per requirement, in a stable order.
pub fn missing(pipeline: &Pipeline, info: &DeviceInfo) -> Vec<&'static str> {
    let mut out: Vec<&'static str> = Vec::new();
    for program in &pipeline.programs {
        for cap in capabilities(&program.words) {
            if let Some((what, have)) = requirement(cap, info) {
                if !have && !out.contains(&what) {
                    out.push(what);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_capabilities_before_the_memory_model() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures/pipelines/shader_clock/heat.rgen.spv");
        let bytes = std::fs::read(path).unwrap();
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let caps = capabilities(&words);
        assert!(caps.contains(&Cap::ShaderClockKHR), "{caps:?}");
        assert!(caps.contains(&Cap::Int64), "{caps:?}");
        assert!(caps.contains(&Cap::RayTracingKHR), "{caps:?}");
    }
}
