//! Running GPU work in a child process: lavapipe kills the whole process
//! (SIGSEGV/SIGBUS) when a shader recurses deeper than the pipeline declared,
//! and a test must observe that rather than die of it.
//!
//! The child is the current test binary re-run on one test:
//!
//! ```text
//! #[test]
//! fn deep_recursion() {
//!     if let Some(outcome) = rtlint::vk::run_in_child("deep_recursion") {
//!         assert!(outcome.signal.is_some(), "{outcome:?}");
//!         return;
//!     }
//!     // Only the child gets here: do the GPU work.
//! }
//! ```

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Set in the child's environment; its presence means "do the work here".
pub const CHILD_ENV: &str = "RTLINT_VK_CHILD";

/// How long [`run_in_child`] lets a child run.
pub const DEFAULT_CHILD_TIMEOUT: Duration = Duration::from_secs(300);

/// How the child process ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChildOutcome {
    /// Exit code, when it exited normally.
    pub code: Option<i32>,
    /// The signal that ended it (Unix), e.g. 11 for SIGSEGV.
    pub signal: Option<i32>,
    /// It outran its time and was killed (then `signal` is SIGKILL's 9).
    pub timed_out: bool,
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
    run_in_child_with_timeout(test_name, DEFAULT_CHILD_TIMEOUT)
}

/// As [`run_in_child`], killing the child after `timeout`: a hung GPU must
/// not hang the test run.
pub fn run_in_child_with_timeout(test_name: &str, timeout: Duration) -> Option<ChildOutcome> {
    if std::env::var_os(CHILD_ENV).is_some() {
        return None;
    }
    let exe = std::env::current_exe().expect("the test binary's path is known");
    let mut command = Command::new(exe);
    command
        .args([test_name, "--exact", "--nocapture", "--test-threads=1"])
        .env(CHILD_ENV, "1");
    Some(run_command(command, timeout).expect("the test binary can be re-run as a child"))
}

/// Runs `command` with piped output, killing it after `timeout`, and says
/// how it ended: a crash (a signal) or a hang is an outcome, not an error.
/// Only a failure to start or wait for it is an error.
pub fn run_command(command: Command, timeout: Duration) -> std::io::Result<ChildOutcome> {
    spawn_command(command)?.wait(timeout)
}

/// A child started by [`spawn_command`], its output being drained.
pub struct RunningChild {
    child: std::process::Child,
    out: std::thread::JoinHandle<String>,
    err: std::thread::JoinHandle<String>,
    start: Instant,
}

/// Starts `command` with piped output, so the caller can work while it runs
/// and [`RunningChild::wait`] for it afterwards.
pub fn spawn_command(mut command: Command) -> std::io::Result<RunningChild> {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()?;
    // Drain both pipes while it runs, so a chatty child cannot block on a
    // full pipe.
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut text = Vec::new();
            if let Some(mut p) = pipe {
                let _ = p.read_to_end(&mut text);
            }
            String::from_utf8_lossy(&text).into_owned()
        })
    };
    let out = drain(child.stdout.take().map(|p| Box::new(p) as _));
    let err = drain(child.stderr.take().map(|p| Box::new(p) as _));
    Ok(RunningChild {
        child,
        out,
        err,
        start: Instant::now(),
    })
}

impl RunningChild {
    /// Waits for the child, killing it once `timeout` has passed since it
    /// started.
    pub fn wait(mut self, timeout: Duration) -> std::io::Result<ChildOutcome> {
        let mut timed_out = false;
        let status = loop {
            if let Some(status) = self.child.try_wait()? {
                break status;
            }
            if self.start.elapsed() > timeout {
                timed_out = true;
                let _ = self.child.kill();
                break self.child.wait()?;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        #[cfg(unix)]
        let signal = std::os::unix::process::ExitStatusExt::signal(&status);
        #[cfg(not(unix))]
        let signal = None;
        Ok(ChildOutcome {
            code: status.code(),
            signal,
            timed_out,
            stdout: self.out.join().unwrap_or_default(),
            stderr: self.err.join().unwrap_or_default(),
        })
    }
}
