//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// The crate root: `CARGO_MANIFEST_DIR` as cargo sets it when it runs the
/// test, else where the crate was built. A test binary run by hand on another
/// machine (scripts/device-tests) is given the checkout's root that way.
pub fn root() -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")))
}

/// Runs `spirv-val --target-env vulkan1.2` on a module (see
/// [`rtlint_testkit::spirv_val`]); a test calls `rtlint_testkit::tool("spirv-val")`
/// first.
pub fn spirv_val(words: &[u32]) -> Result<(), String> {
    rtlint_testkit::spirv_val(words, &[])
}

/// [`spirv_val`] with further options (`--scalar-block-layout`).
pub fn spirv_val_with(words: &[u32], options: &[&str]) -> Result<(), String> {
    rtlint_testkit::spirv_val(words, options)
}

pub fn read_words(path: &Path) -> Vec<u32> {
    rtlint_testkit::words_of_bytes(&std::fs::read(path).unwrap())
}

/// Compares `actual` with the stored snapshot; `RTLINT_BLESS=1` rewrites it.
pub fn snapshot(name: &str, actual: &str) {
    let path = root().join("tests/snapshots").join(format!("{name}.txt"));
    if std::env::var_os("RTLINT_BLESS").is_some() {
        std::fs::write(&path, actual).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(&path).unwrap_or_else(|_| {
        panic!(
            "missing snapshot {}: run with RTLINT_BLESS=1 and review it",
            path.display()
        )
    });
    assert_eq!(
        expected, actual,
        "snapshot {name} differs (RTLINT_BLESS=1 rewrites it; review the diff)"
    );
}

/// The CLI, run in the checkout. Its result cache goes to a folder under
/// the system's temporary one, never into the checkout (a test that wants
/// the default folder removes `RTLINT_CACHE_DIR`).
pub fn rtlint() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtlint"));
    c.current_dir(root())
        .env("NO_COLOR", "1")
        .env("RTLINT_CACHE_DIR", test_cache_dir());
    c
}

/// The result cache of the tests' CLI runs, shared by every test process
/// (entries are keyed by the build and written whole, so runs never see
/// each other's half-written or stale results).
pub fn test_cache_dir() -> std::path::PathBuf {
    std::env::temp_dir().join("rtlint-test-cache")
}

/// The ray-tracing device, under the skip policy ([`rtlint_testkit::require`]):
/// a failure in CI without one, a `skipped:` line elsewhere.
#[cfg(feature = "vulkan")]
#[track_caller]
pub fn device() -> Option<rtlint::vk::Context> {
    rtlint_testkit::require(
        "a ray-tracing Vulkan device (lavapipe: scripts/setup)",
        rtlint::vk::Context::new(),
    )
}

/// Whether `ctx` has ray queries; without them (NVIDIA's driver) prints
/// [`rtlint_testkit::NO_RAY_QUERY`], which `scripts/device-tests` counts as
/// a skip, and the caller returns.
#[cfg(feature = "vulkan")]
pub fn has_ray_query(ctx: &rtlint::vk::Context) -> bool {
    if !ctx.info().ray_query {
        println!(
            "{} ({} lacks VK_KHR_ray_query)",
            rtlint_testkit::NO_RAY_QUERY,
            ctx.info().name
        );
    }
    ctx.info().ray_query
}
