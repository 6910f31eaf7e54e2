//! Rules. (The registry goes here; these are the stack/recursion rules.)

pub mod rt010_live_state_over_budget;
pub mod rt020_recursive_trace;
pub mod rt021_depth_exceeds_declared;
pub mod rt022_depth_overdeclared;
pub mod rt023_depth_exceeds_device_limit;
pub mod rt024_unbounded_bounce_loop;
pub mod rt025_default_stack_unsafe;
