//! The harness's error type: every failure is a value with a readable message,
//! so a machine without a ray-tracing driver gets an explanation, not a panic.

use ash::vk;
use std::fmt;

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Error {
    /// The Vulkan loader library could not be opened.
    Loader(String),
    /// The loader found no driver, or none for Vulkan 1.3.
    NoDriver,
    /// No physical device has what the harness needs; one line per device
    /// says what it lacks.
    NoDevice(Vec<String>),
    /// A Vulkan call failed.
    Vk {
        call: &'static str,
        result: vk::Result,
    },
    /// A submission did not finish within the fence timeout.
    Timeout { what: &'static str, millis: u128 },
    /// The caller asked for something the harness or the device cannot do.
    Invalid(String),
    /// The shaders need a device extension or feature this device lacks
    /// (the text names them).
    Unsupported(String),
}

pub type Result<T> = std::result::Result<T, Error>;

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Loader(msg) => write!(f, "cannot load the Vulkan loader: {msg}"),
            Error::NoDriver => {
                f.write_str("no Vulkan driver is installed, or none supports Vulkan 1.3")
            }
            Error::NoDevice(reasons) if reasons.is_empty() => {
                f.write_str("no Vulkan physical device found")
            }
            Error::NoDevice(reasons) => {
                f.write_str("no Vulkan device supports ray tracing pipelines:")?;
                for r in reasons {
                    write!(f, "\n  {r}")?;
                }
                Ok(())
            }
            Error::Vk { call, result } => write!(f, "{call} failed: {result}"),
            Error::Timeout { what, millis } => {
                write!(f, "{what} did not finish within {millis} ms")
            }
            Error::Invalid(msg) => f.write_str(msg),
            Error::Unsupported(needs) => write!(f, "skipped: needs {needs}"),
        }
    }
}

impl std::error::Error for Error {}

/// Maps a `vk::Result` error to [`Error::Vk`] naming the call.
pub(crate) fn vk_err(call: &'static str) -> impl FnOnce(vk::Result) -> Error {
    move |result| Error::Vk { call, result }
}
