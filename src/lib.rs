//! rtlint: a toolkit and linter for ray-tracing shaders.
//!
//! Data flow: front-ends → SPIR-V → [`spirv::Program`] → analyses → rules →
//! [`diag::Diagnostic`]s → reports. See `docs/architecture.md`.

pub mod diag;
pub mod front;
pub mod reference;
pub mod spirv;
#[cfg(feature = "vulkan")]
pub mod vk;
