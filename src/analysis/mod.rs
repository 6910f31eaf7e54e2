//! Analyses: pure functions over a [`Program`](crate::spirv::Program).

pub mod layout;
