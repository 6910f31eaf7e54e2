//! A small Vulkan harness (ash) for running ray-tracing shaders on a real
//! driver: device selection, buffers with device addresses, acceleration
//! structures, ray-tracing and compute pipelines, the shader binding table,
//! dispatch with a bounded wait, readback of buffers and storage images, and
//! the driver's per-group stack sizes.
//!
//! Every object holds a reference to the device it was made on, so drop order
//! does not matter; every submission waits on a fence with a finite timeout,
//! so a resource is never freed while the GPU uses it.
//!
//! Set `RTLINT_VK_VALIDATION=1` to run under the Khronos validation layer
//! (when installed); [`Context::validation_errors`] then lists what it
//! reported. Work that may crash the process (lavapipe dies on recursion past
//! the declared depth) belongs in a child process: see [`run_in_child`].
//!
//! ```no_run
//! use rtlint::vk::*;
//! let ctx = Context::new()?;
//! println!("{}: max recursion {}", ctx.info().name, ctx.limits().max_ray_recursion_depth);
//! # Ok::<(), rtlint::vk::Error>(())
//! ```

mod accel;
mod buffer;
mod capabilities;
mod child;
mod context;
mod descriptors;
mod error;
mod image;
mod interface;
mod pipeline;
mod stack_query;
mod timing;
mod validation;

pub use accel::{Aabb, AccelerationStructure, Geometry, Instance, IDENTITY};
pub use buffer::{bytes_of, Buffer, Pod};
pub use capabilities::missing as missing_requirements;
pub use child::{
    run_command, run_in_child, run_in_child_with_timeout, spawn_command, ChildOutcome,
    RunningChild, CHILD_ENV, DEFAULT_CHILD_TIMEOUT,
};
pub use context::{Context, ContextOptions, DeviceInfo, RayTracingLimits, Timestamps};
pub use descriptors::{Binding, BindingKind, Resource};
pub use error::{Error, Result};
pub use image::{Sampler, StorageImage};
pub use interface::{
    reflect as reflect_interface, DescriptorCount, DescriptorKind, LayoutBinding, PipelineInterface,
};
pub use pipeline::{
    ComputePipeline, Group, GroupStackSizes, RayTracingPipeline, RayTracingPipelineDesc, SbtLayout,
    SbtRegion, ShaderBindingTable, ShaderStage, Stage,
};
pub use stack_query::driver_stack_sizes;
pub use validation::{ValidationLog, ValidationMessage};

/// The raw Vulkan types (`ash::vk`), for flags and handles the harness passes through.
pub use ash::vk as raw;
