//! Analyses: pure functions over a [`Program`](crate::program::Program) (and a
//! [`Pipeline`](crate::pipeline::Pipeline) where the scene matters).

pub(crate) mod bitset;
pub mod callgraph;
pub mod layout;
pub mod liveness;
pub mod payload_use;
pub mod rayquery;
pub mod rays;
pub mod reach;
pub mod recursion;
pub mod stack;
pub mod trace_sites;
pub mod uniformity;

pub use liveness::{live_report, LiveReport};
pub use recursion::{recursion_report, RecursionReport};
pub use stack::{stack_report, StackReport};
