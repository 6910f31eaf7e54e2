//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// True when running in CI, where every external tool must be present.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// Runs `spirv-val --target-env vulkan1.2` on a module. Debian's SPIRV-Tools
/// 2023.1 does not know the WGSL source language (10), so OpSource's language
/// is set to Unknown on a copy first. Panics when spirv-val is missing: the
/// setup script installs it, and a validation test must not pass silently.
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

pub fn spirv_val(words: &[u32]) -> Result<(), String> {
    spirv_val_with(words, &[])
}

/// [`spirv_val`] with further options (`--scalar-block-layout`).
pub fn spirv_val_with(words: &[u32], options: &[&str]) -> Result<(), String> {
    let mut w = words.to_vec();
    unknown_source_language(&mut w);
    let dir = std::env::temp_dir().join(format!("rtlint-val-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{:x}.spv", hash(&w)));
    std::fs::write(
        &file,
        w.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
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

pub fn read_words(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap();
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
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

pub fn rtlint() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtlint"));
    c.current_dir(root()).env("NO_COLOR", "1");
    c
}
