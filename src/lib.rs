//! rtlint: a toolkit and linter for ray-tracing shaders.
//!
//! Data flow: front-ends → SPIR-V → [`program::Program`] → analyses → rules →
//! [`diag::Diagnostic`]s → reports. See `docs/architecture.md`.

pub mod analysis;
pub mod build;
pub mod cache;
pub mod config;
pub mod diag;
pub mod explain;
pub mod front;
pub mod lint;
pub mod pipeline;
pub mod program;
#[cfg(feature = "vulkan")]
pub mod reference;
pub mod report;
pub mod rules;
pub mod shader;
pub mod suppress;
#[cfg(feature = "vulkan")]
pub mod tradeoff;
#[cfg(feature = "vulkan")]
pub mod verify;
#[cfg(feature = "vulkan")]
pub mod vk;
