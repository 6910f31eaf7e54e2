//! Instance, device selection, queue and one-shot command submission.

use super::error::{vk_err, Error, Result};
use super::validation::{Validation, ValidationLog, ValidationMessage, LAYER};
use ash::vk;
use std::ffi::CStr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Device extensions every ray-tracing pipeline needs.
const REQUIRED_EXTENSIONS: [&CStr; 3] = [
    vk::KHR_RAY_TRACING_PIPELINE_NAME,
    vk::KHR_ACCELERATION_STRUCTURE_NAME,
    vk::KHR_DEFERRED_HOST_OPERATIONS_NAME,
];

/// How [`Context::with_options`] picks and drives a device.
#[derive(Clone, Debug)]
pub struct ContextOptions {
    /// Only devices whose name contains this text are considered.
    pub device_name: Option<String>,
    /// Enable `VK_LAYER_KHRONOS_validation` when it is installed, collecting
    /// its messages (see [`Context::validation_messages`]). The default is
    /// on when the environment variable `RTLINT_VK_VALIDATION` is set to
    /// anything but `0`.
    pub validation: bool,
    /// How long a submission may run before [`Error::Timeout`]. A lost or hung
    /// device must end a test, not stall it. After a timeout the context
    /// leaks its objects instead of destroying what the GPU may still use.
    pub fence_timeout: Duration,
}

impl Default for ContextOptions {
    fn default() -> Self {
        ContextOptions {
            device_name: None,
            validation: std::env::var_os("RTLINT_VK_VALIDATION").is_some_and(|v| v != "0"),
            fence_timeout: Duration::from_secs(30),
        }
    }
}

/// Ray-tracing limits of the chosen device (`VkPhysicalDeviceRayTracingPipelinePropertiesKHR`
/// and the acceleration-structure scratch alignment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayTracingLimits {
    pub shader_group_handle_size: u32,
    pub shader_group_handle_alignment: u32,
    pub shader_group_base_alignment: u32,
    pub max_shader_group_stride: u32,
    pub max_ray_recursion_depth: u32,
    pub max_ray_dispatch_invocation_count: u32,
    pub max_ray_hit_attribute_size: u32,
    pub min_acceleration_structure_scratch_offset_alignment: u32,
}

/// What the harness learnt about the device it opened.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceInfo {
    pub name: String,
    /// Driver name and version text (`VkPhysicalDeviceDriverProperties`),
    /// e.g. "llvmpipe, Mesa 25.0.7-1~bpo12+1 (LLVM 15.0.6)".
    pub driver: String,
    /// `(major, minor, patch)` of the device's Vulkan version.
    pub api_version: (u32, u32, u32),
    pub driver_version: u32,
    pub vendor_id: u32,
    pub device_type: vk::PhysicalDeviceType,
    /// `VK_KHR_ray_query` was present and is enabled.
    pub ray_query: bool,
    /// `VK_KHR_ray_tracing_position_fetch` and its `rayTracingPositionFetch`
    /// feature were present and are enabled (not under a validation layer
    /// older than the extension).
    pub position_fetch: bool,
    /// `VK_NV_ray_tracing_invocation_reorder` (shader execution reordering,
    /// HLSL `dx::HitObject`) and its feature were present and are enabled.
    pub invocation_reorder: bool,
    /// Core features enabled because the device has them; naga's
    /// `primitive_index` needs `geometryShader`.
    pub geometry_shader: bool,
    pub shader_int64: bool,
    /// 16-bit arithmetic (`shaderFloat16` and `shaderInt16`), 16-bit wave
    /// operations (`shaderSubgroupExtendedTypes`) and 16-bit values in
    /// storage and uniform buffers, all enabled when present
    /// (HLSL compiled with `-enable-16bit-types`).
    pub sixteen_bit: bool,
    /// `shaderStorageImageReadWithoutFormat` and `…WriteWithoutFormat`,
    /// enabled when the device has both: storage images whose SPIR-V type
    /// names no format (HLSL `RWTexture2D<float3>`, Slang's images) need them.
    pub storage_image_without_format: bool,
    pub ray_tracing: RayTracingLimits,
    pub min_storage_buffer_offset_alignment: u64,
    pub min_uniform_buffer_offset_alignment: u64,
    /// `maxBoundDescriptorSets`.
    pub max_bound_descriptor_sets: u32,
    /// `maxPushConstantsSize`.
    pub max_push_constants_size: u32,
    /// `runtimeDescriptorArray` is present and enabled.
    pub runtime_descriptor_array: bool,
    /// `VK_KHR_shader_clock` with `shaderSubgroupClock` (SPIR-V
    /// `ShaderClockKHR`, GLSL `clockARB`) is present and enabled;
    /// `shader_device_clock` when `shaderDeviceClock` is too.
    pub shader_clock: bool,
    pub shader_device_clock: bool,
    /// `shaderFloat64` is present and enabled.
    pub shader_float64: bool,
}

/// What timestamp queries on the chosen queue measure: `timestampValidBits`
/// of its family and the device's `timestampPeriod` (nanoseconds per tick).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timestamps {
    /// 0: the queue cannot write timestamps.
    pub valid_bits: u32,
    pub period_ns: f32,
}

/// Everything the Vulkan objects need to destroy themselves; resources hold an
/// `Arc` to it, so the device outlives every buffer, structure and pipeline.
pub(crate) struct Shared {
    _entry: ash::Entry,
    instance: ash::Instance,
    validation: Option<Validation>,
    pub(crate) device: ash::Device,
    pub(crate) accel: ash::khr::acceleration_structure::Device,
    pub(crate) rt: ash::khr::ray_tracing_pipeline::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) command_pool: vk::CommandPool,
    pub(crate) memory: vk::PhysicalDeviceMemoryProperties,
    pub(crate) info: DeviceInfo,
    pub(crate) timestamps: Timestamps,
    pub(crate) fence_timeout: Duration,
    /// The command pool and queue need external synchronisation.
    pub(crate) submit_lock: Mutex<()>,
    /// A submission outlived its fence timeout and may still be running.
    timed_out: AtomicBool,
}

impl Drop for Shared {
    fn drop(&mut self) {
        if self.hung() {
            // Waiting for idle could block forever and destroying a busy
            // device is undefined; the process is expected to end soon.
            return;
        }
        // SAFETY: every other object holds an Arc<Shared>, so none is left.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some(v) = &self.validation {
                v.destroy();
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// An open ray-tracing device with one compute-capable queue.
#[derive(Clone)]
pub struct Context {
    pub(crate) shared: Arc<Shared>,
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Context")
            .field("device", &self.shared.info.name)
            .finish_non_exhaustive()
    }
}

/// A device that passed selection, with the features to enable.
struct Candidate {
    physical: vk::PhysicalDevice,
    queue_family: u32,
    info: DeviceInfo,
    timestamps: Timestamps,
    /// Shader features enabled where the device has them, so that shaders
    /// using descriptor indexing, format-less storage images, 16-bit
    /// integers or doubles can be created.
    optional: OptionalFeatures,
}

/// The optional features the device has (each enabled when present).
#[derive(Clone, Copy, Debug, Default)]
struct OptionalFeatures {
    core: vk::PhysicalDeviceFeatures,
    runtime_descriptor_array: bool,
    sampled_image_non_uniform: bool,
    storage_image_non_uniform: bool,
    storage_buffer_non_uniform: bool,
    uniform_buffer_non_uniform: bool,
    uniform_texel_non_uniform: bool,
    storage_texel_non_uniform: bool,
    partially_bound: bool,
    variable_count: bool,
    /// `shaderFloat16`, and the 16-bit storage features (Vulkan 1.1), for
    /// shaders compiled with 16-bit types.
    shader_float16: bool,
    storage16: [bool; 4],
    /// Group operations on 16-bit (and 8-bit, 64-bit) values.
    subgroup_extended_types: bool,
}

impl Context {
    /// Opens the first device (discrete GPUs first) with ray-tracing pipelines
    /// and acceleration structures.
    pub fn new() -> Result<Context> {
        Context::with_options(&ContextOptions::default())
    }

    pub fn with_options(options: &ContextOptions) -> Result<Context> {
        // SAFETY: loading the system's Vulkan loader runs its initialisers,
        // which is what any Vulkan program does.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| Error::Loader(e.to_string()))?;
        let (instance, layer_version) = create_instance(&entry, options.validation)?;
        let validating = layer_version.is_some();
        let validation = if validating {
            match Validation::new(&entry, &instance) {
                Ok(v) => Some(v),
                Err(e) => {
                    // SAFETY: nothing was created from the instance.
                    unsafe { instance.destroy_instance(None) };
                    return Err(e);
                }
            }
        } else {
            None
        };
        match open_device(&entry, &instance, options, layer_version) {
            Ok(mut shared) => {
                shared.validation = validation;
                Ok(Context {
                    shared: Arc::new(shared),
                })
            }
            Err(e) => {
                // SAFETY: nothing else created from the instance is left.
                unsafe {
                    if let Some(v) = &validation {
                        v.destroy();
                    }
                    instance.destroy_instance(None);
                }
                Err(e)
            }
        }
    }

    pub fn info(&self) -> &DeviceInfo {
        &self.shared.info
    }

    /// What timestamp queries measure on this device's queue.
    pub fn timestamps(&self) -> Timestamps {
        self.shared.timestamps
    }

    pub fn limits(&self) -> &RayTracingLimits {
        &self.shared.info.ray_tracing
    }

    /// The raw device, for work the harness does not wrap.
    pub fn device(&self) -> &ash::Device {
        &self.shared.device
    }

    pub fn fence_timeout(&self) -> Duration {
        self.shared.fence_timeout
    }

    /// Whether the validation layer is active (asked for and installed).
    pub fn validation_enabled(&self) -> bool {
        self.shared.validation.is_some()
    }

    /// The validation layer's messages, readable after the context is gone;
    /// `None` without validation.
    pub fn validation_log(&self) -> Option<ValidationLog> {
        self.shared.validation.as_ref().map(Validation::log)
    }

    /// Every validation error and warning so far (empty without validation).
    pub fn validation_messages(&self) -> Vec<ValidationMessage> {
        self.validation_log()
            .map(|l| l.messages())
            .unwrap_or_default()
    }

    /// The validation errors so far, as text.
    pub fn validation_errors(&self) -> Vec<String> {
        self.validation_log()
            .map(|l| l.errors())
            .unwrap_or_default()
    }
}

/// The instance, and whether the validation layer (with debug utils) is on.
/// Creates the instance; with `validation`, also the validation layer where
/// installed, whose spec version is returned.
fn create_instance(entry: &ash::Entry, validation: bool) -> Result<(ash::Instance, Option<u32>)> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"rtlint")
        .engine_name(c"rtlint")
        .api_version(vk::API_VERSION_1_3);
    let mut layers = Vec::new();
    let mut extensions = Vec::new();
    let mut layer_version = None;
    if validation {
        // SAFETY: plain query.
        let available = unsafe { entry.enumerate_instance_layer_properties() }
            .map_err(vk_err("vkEnumerateInstanceLayerProperties"))?;
        if let Some(layer) = available
            .iter()
            .find(|l| l.layer_name_as_c_str() == Ok(LAYER))
        {
            layers.push(LAYER.as_ptr());
            extensions.push(vk::EXT_DEBUG_UTILS_NAME.as_ptr());
            layer_version = Some(layer.spec_version);
        }
    }
    let create = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    // SAFETY: the create info points at locals that outlive the call.
    let instance =
        unsafe { entry.create_instance(&create, None) }.map_err(|result| match result {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => Error::NoDriver,
            result => Error::Vk {
                call: "vkCreateInstance",
                result,
            },
        })?;
    Ok((instance, layer_version))
}

/// Opens the device; on error everything it made is destroyed, and the
/// caller destroys the instance.
fn open_device(
    entry: &ash::Entry,
    instance: &ash::Instance,
    options: &ContextOptions,
    layer_version: Option<u32>,
) -> Result<Shared> {
    let mut candidate = select_device(instance, options)?;
    // A validation layer older than an optional extension rejects its
    // structures at device creation (Debian bookworm's 1.3.239 layer and
    // position fetch, which came with the 1.3.250 headers): leave it off.
    // Invocation reorder came with the 1.3.235 headers.
    if layer_version.is_some_and(|v| v < vk::make_api_version(0, 1, 3, 250)) {
        candidate.info.position_fetch = false;
    }
    if layer_version.is_some_and(|v| v < vk::make_api_version(0, 1, 3, 235)) {
        candidate.info.invocation_reorder = false;
    }
    let device = create_device(instance, &candidate)?;
    // SAFETY: queue family and index were requested at device creation.
    let queue = unsafe { device.get_device_queue(candidate.queue_family, 0) };
    let pool_info = vk::CommandPoolCreateInfo::default()
        .queue_family_index(candidate.queue_family)
        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
    // SAFETY: valid device.
    let command_pool = match unsafe { device.create_command_pool(&pool_info, None) } {
        Ok(pool) => pool,
        Err(e) => {
            // SAFETY: the device has no objects yet.
            unsafe { device.destroy_device(None) };
            return Err(vk_err("vkCreateCommandPool")(e));
        }
    };
    // SAFETY: valid physical device.
    let memory = unsafe { instance.get_physical_device_memory_properties(candidate.physical) };
    Ok(Shared {
        _entry: entry.clone(),
        accel: ash::khr::acceleration_structure::Device::new(instance, &device),
        rt: ash::khr::ray_tracing_pipeline::Device::new(instance, &device),
        instance: instance.clone(),
        validation: None,
        device,
        queue,
        command_pool,
        memory,
        info: candidate.info,
        timestamps: candidate.timestamps,
        fence_timeout: options.fence_timeout,
        submit_lock: Mutex::new(()),
        timed_out: AtomicBool::new(false),
    })
}

fn select_device(instance: &ash::Instance, options: &ContextOptions) -> Result<Candidate> {
    // SAFETY: plain queries on a valid instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }
        .map_err(vk_err("vkEnumeratePhysicalDevices"))?;
    let mut reasons = Vec::new();
    let mut found = Vec::new();
    for physical in physicals {
        match examine(instance, physical) {
            Ok(c) => {
                if let Some(want) = &options.device_name {
                    if !c.info.name.contains(want.as_str()) {
                        reasons.push(format!("{}: name does not contain {want:?}", c.info.name));
                        continue;
                    }
                }
                found.push(c);
            }
            Err(reason) => reasons.push(reason),
        }
    }
    // Real GPUs before CPU drivers, so a machine with both tests the GPU.
    let rank = |t: vk::PhysicalDeviceType| match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        _ => 3,
    };
    found.sort_by_key(|c| rank(c.info.device_type));
    found.into_iter().next().ok_or(Error::NoDevice(reasons))
}

/// Checks one device; `Err` says what it lacks.
fn examine(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
) -> std::result::Result<Candidate, String> {
    // SAFETY: plain queries on a valid physical device.
    let props = unsafe { instance.get_physical_device_properties(physical) };
    let name = props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "<unnamed device>".into());
    let api = props.api_version;
    if api < vk::API_VERSION_1_3 {
        return Err(format!(
            "{name}: Vulkan {}.{} (1.3 needed)",
            vk::api_version_major(api),
            vk::api_version_minor(api)
        ));
    }
    // SAFETY: as above.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }
        .map_err(|e| format!("{name}: cannot list extensions: {e}"))?;
    let has = |ext: &CStr| {
        extensions
            .iter()
            .any(|p| p.extension_name_as_c_str() == Ok(ext))
    };
    let missing: Vec<String> = REQUIRED_EXTENSIONS
        .iter()
        .filter(|e| !has(e))
        .map(|e| e.to_string_lossy().into_owned())
        .collect();
    if !missing.is_empty() {
        return Err(format!("{name}: lacks {}", missing.join(", ")));
    }
    let ray_query = has(vk::KHR_RAY_QUERY_NAME);

    let mut f11 = vk::PhysicalDeviceVulkan11Features::default();
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut fas = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
    let mut frt = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default();
    let mut fpf = vk::PhysicalDeviceRayTracingPositionFetchFeaturesKHR::default();
    let has_position_fetch = has(vk::KHR_RAY_TRACING_POSITION_FETCH_NAME);
    let mut fir = vk::PhysicalDeviceRayTracingInvocationReorderFeaturesNV::default();
    let has_reorder = has(vk::NV_RAY_TRACING_INVOCATION_REORDER_NAME);
    let mut fclock = vk::PhysicalDeviceShaderClockFeaturesKHR::default();
    let has_clock = has(vk::KHR_SHADER_CLOCK_NAME);
    let mut features = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f11)
        .push_next(&mut f12)
        .push_next(&mut f13)
        .push_next(&mut fas)
        .push_next(&mut frt);
    if has_position_fetch {
        features = features.push_next(&mut fpf);
    }
    if has_reorder {
        features = features.push_next(&mut fir);
    }
    if has_clock {
        features = features.push_next(&mut fclock);
    }
    // SAFETY: the chain holds only structures of this device's version and extensions.
    unsafe { instance.get_physical_device_features2(physical, &mut features) };
    let core = features.features;
    let required = [
        ("bufferDeviceAddress", f12.buffer_device_address),
        ("descriptorIndexing", f12.descriptor_indexing),
        ("scalarBlockLayout", f12.scalar_block_layout),
        ("synchronization2", f13.synchronization2),
        ("maintenance4", f13.maintenance4),
        ("accelerationStructure", fas.acceleration_structure),
        ("rayTracingPipeline", frt.ray_tracing_pipeline),
    ];
    let lacking: Vec<&str> = required
        .iter()
        .filter(|(_, v)| *v == vk::FALSE)
        .map(|(n, _)| *n)
        .collect();
    if !lacking.is_empty() {
        return Err(format!("{name}: lacks features {}", lacking.join(", ")));
    }

    let mut rt_props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
    let mut as_props = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
    let mut driver_props = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut rt_props)
        .push_next(&mut as_props)
        .push_next(&mut driver_props);
    // SAFETY: as above.
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };

    // SAFETY: as above.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let queue_family = families
        .iter()
        .position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE))
        .ok_or_else(|| format!("{name}: no compute queue"))? as u32;
    let timestamps = Timestamps {
        valid_bits: families[queue_family as usize].timestamp_valid_bits,
        period_ns: props.limits.timestamp_period,
    };

    Ok(Candidate {
        physical,
        queue_family,
        timestamps,
        info: DeviceInfo {
            name,
            driver: format!(
                "{}, {}",
                c_text(driver_props.driver_name_as_c_str()),
                c_text(driver_props.driver_info_as_c_str())
            ),
            api_version: (
                vk::api_version_major(api),
                vk::api_version_minor(api),
                vk::api_version_patch(api),
            ),
            driver_version: props.driver_version,
            vendor_id: props.vendor_id,
            device_type: props.device_type,
            ray_query,
            position_fetch: has_position_fetch && fpf.ray_tracing_position_fetch == vk::TRUE,
            invocation_reorder: has_reorder && fir.ray_tracing_invocation_reorder == vk::TRUE,
            geometry_shader: core.geometry_shader == vk::TRUE,
            shader_int64: core.shader_int64 == vk::TRUE,
            sixteen_bit: f12.shader_float16 == vk::TRUE
                && core.shader_int16 == vk::TRUE
                && f12.shader_subgroup_extended_types == vk::TRUE
                && f11.storage_buffer16_bit_access == vk::TRUE
                && f11.uniform_and_storage_buffer16_bit_access == vk::TRUE,
            storage_image_without_format: core.shader_storage_image_read_without_format == vk::TRUE
                && core.shader_storage_image_write_without_format == vk::TRUE,
            ray_tracing: RayTracingLimits {
                shader_group_handle_size: rt_props.shader_group_handle_size,
                shader_group_handle_alignment: rt_props.shader_group_handle_alignment,
                shader_group_base_alignment: rt_props.shader_group_base_alignment,
                max_shader_group_stride: rt_props.max_shader_group_stride,
                max_ray_recursion_depth: rt_props.max_ray_recursion_depth,
                max_ray_dispatch_invocation_count: rt_props.max_ray_dispatch_invocation_count,
                max_ray_hit_attribute_size: rt_props.max_ray_hit_attribute_size,
                min_acceleration_structure_scratch_offset_alignment: as_props
                    .min_acceleration_structure_scratch_offset_alignment,
            },
            min_storage_buffer_offset_alignment: props.limits.min_storage_buffer_offset_alignment,
            min_uniform_buffer_offset_alignment: props.limits.min_uniform_buffer_offset_alignment,
            max_bound_descriptor_sets: props.limits.max_bound_descriptor_sets,
            max_push_constants_size: props.limits.max_push_constants_size,
            runtime_descriptor_array: f12.runtime_descriptor_array == vk::TRUE,
            shader_clock: has_clock && fclock.shader_subgroup_clock == vk::TRUE,
            shader_device_clock: has_clock && fclock.shader_device_clock == vk::TRUE,
            shader_float64: core.shader_float64 == vk::TRUE,
        },
        optional: OptionalFeatures {
            core: vk::PhysicalDeviceFeatures {
                shader_storage_image_read_without_format: core
                    .shader_storage_image_read_without_format,
                shader_storage_image_write_without_format: core
                    .shader_storage_image_write_without_format,
                shader_sampled_image_array_dynamic_indexing: core
                    .shader_sampled_image_array_dynamic_indexing,
                shader_storage_image_array_dynamic_indexing: core
                    .shader_storage_image_array_dynamic_indexing,
                shader_storage_buffer_array_dynamic_indexing: core
                    .shader_storage_buffer_array_dynamic_indexing,
                shader_uniform_buffer_array_dynamic_indexing: core
                    .shader_uniform_buffer_array_dynamic_indexing,
                shader_int16: core.shader_int16,
                shader_float64: core.shader_float64,
                shader_image_gather_extended: core.shader_image_gather_extended,
                ..Default::default()
            },
            runtime_descriptor_array: f12.runtime_descriptor_array == vk::TRUE,
            sampled_image_non_uniform: f12.shader_sampled_image_array_non_uniform_indexing
                == vk::TRUE,
            storage_image_non_uniform: f12.shader_storage_image_array_non_uniform_indexing
                == vk::TRUE,
            storage_buffer_non_uniform: f12.shader_storage_buffer_array_non_uniform_indexing
                == vk::TRUE,
            uniform_buffer_non_uniform: f12.shader_uniform_buffer_array_non_uniform_indexing
                == vk::TRUE,
            uniform_texel_non_uniform: f12.shader_uniform_texel_buffer_array_non_uniform_indexing
                == vk::TRUE,
            storage_texel_non_uniform: f12.shader_storage_texel_buffer_array_non_uniform_indexing
                == vk::TRUE,
            partially_bound: f12.descriptor_binding_partially_bound == vk::TRUE,
            variable_count: f12.descriptor_binding_variable_descriptor_count == vk::TRUE,
            shader_float16: f12.shader_float16 == vk::TRUE,
            subgroup_extended_types: f12.shader_subgroup_extended_types == vk::TRUE,
            storage16: [
                f11.storage_buffer16_bit_access == vk::TRUE,
                f11.uniform_and_storage_buffer16_bit_access == vk::TRUE,
                f11.storage_push_constant16 == vk::TRUE,
                f11.storage_input_output16 == vk::TRUE,
            ],
        },
    })
}

fn create_device(instance: &ash::Instance, c: &Candidate) -> Result<ash::Device> {
    let mut extensions: Vec<*const std::ffi::c_char> =
        REQUIRED_EXTENSIONS.iter().map(|e| e.as_ptr()).collect();
    // Only where present: NVIDIA's driver has no ray query, and asking for it
    // fails device creation.
    if c.info.ray_query {
        extensions.push(vk::KHR_RAY_QUERY_NAME.as_ptr());
    }
    if c.info.position_fetch {
        extensions.push(vk::KHR_RAY_TRACING_POSITION_FETCH_NAME.as_ptr());
    }
    if c.info.invocation_reorder {
        extensions.push(vk::NV_RAY_TRACING_INVOCATION_REORDER_NAME.as_ptr());
    }
    // Old enough (Vulkan 1.1 era) for every validation layer to know it.
    if c.info.shader_clock {
        extensions.push(vk::KHR_SHADER_CLOCK_NAME.as_ptr());
    }
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(c.queue_family)
        .queue_priorities(&priorities)];
    let o = &c.optional;
    let core = o
        .core
        .geometry_shader(c.info.geometry_shader)
        .shader_int64(c.info.shader_int64)
        .shader_storage_image_read_without_format(c.info.storage_image_without_format)
        .shader_storage_image_write_without_format(c.info.storage_image_without_format);
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
        .buffer_device_address(true)
        .descriptor_indexing(true)
        .scalar_block_layout(true)
        .runtime_descriptor_array(o.runtime_descriptor_array)
        .shader_sampled_image_array_non_uniform_indexing(o.sampled_image_non_uniform)
        .shader_storage_image_array_non_uniform_indexing(o.storage_image_non_uniform)
        .shader_storage_buffer_array_non_uniform_indexing(o.storage_buffer_non_uniform)
        .shader_uniform_buffer_array_non_uniform_indexing(o.uniform_buffer_non_uniform)
        .shader_uniform_texel_buffer_array_non_uniform_indexing(o.uniform_texel_non_uniform)
        .shader_storage_texel_buffer_array_non_uniform_indexing(o.storage_texel_non_uniform)
        .descriptor_binding_partially_bound(o.partially_bound)
        .descriptor_binding_variable_descriptor_count(o.variable_count)
        .shader_float16(o.shader_float16)
        .shader_subgroup_extended_types(o.subgroup_extended_types);
    let mut f11 = vk::PhysicalDeviceVulkan11Features::default()
        .storage_buffer16_bit_access(o.storage16[0])
        .uniform_and_storage_buffer16_bit_access(o.storage16[1])
        .storage_push_constant16(o.storage16[2])
        .storage_input_output16(o.storage16[3]);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .maintenance4(true);
    let mut fas =
        vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
    let mut frt =
        vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
    let mut frq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
    let mut features = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut f11)
        .push_next(&mut f12)
        .push_next(&mut f13)
        .push_next(&mut fas)
        .push_next(&mut frt);
    if c.info.ray_query {
        features = features.push_next(&mut frq);
    }
    let mut fpf = vk::PhysicalDeviceRayTracingPositionFetchFeaturesKHR::default()
        .ray_tracing_position_fetch(true);
    if c.info.position_fetch {
        features = features.push_next(&mut fpf);
    }
    let mut fir = vk::PhysicalDeviceRayTracingInvocationReorderFeaturesNV::default()
        .ray_tracing_invocation_reorder(true);
    if c.info.invocation_reorder {
        features = features.push_next(&mut fir);
    }
    let mut fclock = vk::PhysicalDeviceShaderClockFeaturesKHR::default()
        .shader_subgroup_clock(true)
        .shader_device_clock(c.info.shader_device_clock);
    if c.info.shader_clock {
        features = features.push_next(&mut fclock);
    }
    let create = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&extensions)
        .push_next(&mut features);
    // SAFETY: every pointer in the create info refers to a local that outlives the call.
    unsafe { instance.create_device(c.physical, &create, None) }.map_err(vk_err("vkCreateDevice"))
}

impl Shared {
    /// Records commands into a fresh command buffer, submits them, and waits
    /// on a fence for at most the context's timeout. Returns the time from
    /// submission to the fence signalling.
    pub(crate) fn submit(
        &self,
        what: &'static str,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<Duration> {
        let _guard = self.submit_lock.lock().unwrap_or_else(|p| p.into_inner());
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device; the lock serialises its use.
        let cmd = unsafe { self.device.allocate_command_buffers(&alloc) }
            .map_err(vk_err("vkAllocateCommandBuffers"))?[0];
        let free =
            |this: &Self| unsafe { this.device.free_command_buffers(this.command_pool, &[cmd]) };
        let begin = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        // SAFETY: cmd was just allocated.
        if let Err(e) = unsafe { self.device.begin_command_buffer(cmd, &begin) } {
            free(self);
            return Err(vk_err("vkBeginCommandBuffer")(e));
        }
        record(cmd);
        // Make the submission's writes visible to the host (readback) and to
        // later submissions, which only a fence wait separates.
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::MEMORY_WRITE)
            .dst_access_mask(vk::AccessFlags::MEMORY_READ | vk::AccessFlags::HOST_READ);
        // SAFETY: cmd is recording.
        unsafe {
            self.device.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::ALL_COMMANDS,
                vk::PipelineStageFlags::ALL_COMMANDS | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            )
        };
        // SAFETY: as above.
        if let Err(e) = unsafe { self.device.end_command_buffer(cmd) } {
            free(self);
            return Err(vk_err("vkEndCommandBuffer")(e));
        }
        // SAFETY: valid device.
        let fence = match unsafe {
            self.device
                .create_fence(&vk::FenceCreateInfo::default(), None)
        } {
            Ok(f) => f,
            Err(e) => {
                free(self);
                return Err(vk_err("vkCreateFence")(e));
            }
        };
        let cmds = [cmd];
        let submit = vk::SubmitInfo::default().command_buffers(&cmds);
        let start = Instant::now();
        // SAFETY: the command buffer is recorded and the fence unsignalled.
        let result = unsafe { self.device.queue_submit(self.queue, &[submit], fence) }
            .map_err(vk_err("vkQueueSubmit"))
            .and_then(|()| {
                let nanos = self.fence_timeout.as_nanos().min(u64::MAX as u128) as u64;
                // SAFETY: the fence was submitted above.
                match unsafe { self.device.wait_for_fences(&[fence], true, nanos) } {
                    Ok(()) => Ok(start.elapsed()),
                    Err(vk::Result::TIMEOUT) => Err(Error::Timeout {
                        what,
                        millis: self.fence_timeout.as_millis(),
                    }),
                    Err(e) => Err(vk_err("vkWaitForFences")(e)),
                }
            });
        match result {
            // A timed-out submission may still be running: leak its command
            // buffer and fence, and from now on every object, rather than
            // free what the GPU may use.
            Err(Error::Timeout { .. }) => self.timed_out.store(true, Ordering::SeqCst),
            _ => unsafe {
                // SAFETY: the submission finished (or never started).
                self.device.destroy_fence(fence, None);
                free(self);
            },
        }
        result
    }

    /// Whether a submission timed out; objects then leak instead of being
    /// destroyed under the GPU.
    pub(crate) fn hung(&self) -> bool {
        self.timed_out.load(Ordering::SeqCst)
    }

    /// A memory type with all of `flags` among `type_bits`.
    pub(crate) fn memory_type(
        &self,
        type_bits: u32,
        flags: vk::MemoryPropertyFlags,
    ) -> Option<u32> {
        (0..self.memory.memory_type_count).find(|&i| {
            type_bits & (1 << i) != 0
                && self.memory.memory_types[i as usize]
                    .property_flags
                    .contains(flags)
        })
    }
}

fn c_text(s: std::result::Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    s.map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}
