//! The reference shaders and scenes (`shaders/` of the repository) built
//! into the binary, so that `rtlint verify` and `rtlint tradeoff` work from
//! an installed binary in any folder. They are written out once per content
//! hash (the front-ends, glslang and the pipeline descriptions read files
//! and includes from disk) and checked byte for byte on every use.

use super::MANIFEST;
use std::path::{Path, PathBuf};

mod files {
    include!(concat!(env!("OUT_DIR"), "/reference_shaders.rs"));
}

/// Every bundled file: its path under the shaders folder and its bytes.
pub fn files() -> &'static [(&'static str, &'static [u8])] {
    files::FILES
}

/// A folder holding exactly the bundled files: `rtlint/shaders-HASH` in the
/// user's cache folder (`$XDG_CACHE_HOME`, else `~/.cache`, else the
/// temporary folder), written when missing or not what this binary carries.
pub fn folder() -> Result<PathBuf, String> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir)
        .join("rtlint");
    folder_in(&base)
}

/// [`folder`] under `base` instead of the user's cache folder.
pub fn folder_in(base: &Path) -> Result<PathBuf, String> {
    if files::FILES.is_empty() {
        return Err(
            "this rtlint was built without its reference shaders: give --shaders DIR".into(),
        );
    }
    let dir = base.join(format!("shaders-{}", files::HASH));
    if holds_exactly(&dir) {
        return Ok(dir);
    }
    // Written beside it and renamed into place: a reader never sees half
    // a folder, and two runs racing both end with a complete one.
    let fresh = base.join(format!("shaders-{}.{}", files::HASH, std::process::id()));
    let _ = std::fs::remove_dir_all(&fresh);
    let write = |rel: &str, bytes: &[u8]| -> std::io::Result<()> {
        let path = fresh.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(path, bytes)
    };
    for (rel, bytes) in files::FILES {
        write(rel, bytes).map_err(|e| {
            format!(
                "cannot write the reference shaders to {}: {e} (or give --shaders DIR)",
                fresh.display()
            )
        })?;
    }
    let _ = std::fs::remove_dir_all(&dir);
    match std::fs::rename(&fresh, &dir) {
        Ok(()) => Ok(dir),
        // Another run put its copy there first.
        Err(_) if holds_exactly(&dir) => {
            let _ = std::fs::remove_dir_all(&fresh);
            Ok(dir)
        }
        Err(_) => Ok(fresh),
    }
}

fn holds_exactly(dir: &Path) -> bool {
    dir.join(MANIFEST).is_file()
        && files::FILES
            .iter()
            .all(|(rel, bytes)| std::fs::read(dir.join(rel)).is_ok_and(|b| b == *bytes))
}
