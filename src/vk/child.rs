//! Running GPU work in a child process: lavapipe kills the whole process
//! (SIGSEGV/SIGBUS) when a shader recurses deeper than the pipeline declared,
//! and a test must observe that rather than die of it.
//!
//! The child is the current test binary re-run on one test:
//!
//! ```ignore
//! #[test]
//! fn deep_recursion() {
//!     if let Some(outcome) = rtlint::vk::run_in_child("deep_recursion") {
//!         assert!(outcome.signal.is_some(), "{outcome:?}");
//!         return;
//!     }
//!     // Only the child gets here: do the GPU work.
//! }
//! ```

use std::process::Command;

/// Set in the child's environment; its presence means "do the work here".
pub const CHILD_ENV: &str = "RTLINT_VK_CHILD";

/// How the child process ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChildOutcome {
    /// Exit code, when it exited normally.
    pub code: Option<i32>,
    /// The signal that ended it (Unix), e.g. 11 for SIGSEGV.
    pub signal: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl ChildOutcome {
    pub fn success(&self) -> bool {
        self.code == Some(0)
    }
}

/// In the parent, re-runs the test named `test_name` of the current test
/// binary in a child process and returns how it ended; in that child
/// (where [`CHILD_ENV`] is set) returns `None`, so the caller does the work.
/// A failure to start the child is reported as a panic: a test cannot go on.
pub fn run_in_child(test_name: &str) -> Option<ChildOutcome> {
    if std::env::var_os(CHILD_ENV).is_some() {
        return None;
    }
    let exe = std::env::current_exe().expect("the test binary's path is known");
    let out = Command::new(exe)
        .args([test_name, "--exact", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, "1")
        .output()
        .expect("the test binary can be re-run as a child");
    #[cfg(unix)]
    let signal = std::os::unix::process::ExitStatusExt::signal(&out.status);
    #[cfg(not(unix))]
    let signal = None;
    Some(ChildOutcome {
        code: out.status.code(),
        signal,
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    })
}
