//! Generates the rule registry: one module per `src/rules/rt*.rs` file and
//! `RULES` in code order, so that adding a rule is adding its file.

use std::path::Path;

fn main() {
    // The manifest directory at run time, not when the script was compiled:
    // worktrees sharing one target directory share this script's binary.
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR");
    let dir = Path::new(&manifest).join("src/rules");
    println!("cargo:rerun-if-changed={}", dir.display());
    // Cargo keeps one output of this script per target directory, whatever
    // checkout it came from: run again when cargo runs in another directory.
    println!("cargo:rerun-if-env-changed=PWD");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .expect("src/rules")
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            let stem = name.strip_suffix(".rs")?;
            let code = stem.split('_').next()?;
            (code.len() == 5
                && code.starts_with("rt")
                && code[2..].bytes().all(|b| b.is_ascii_digit()))
            .then(|| stem.to_string())
        })
        .collect();
    files.sort();
    let mut out = String::new();
    for f in &files {
        out.push_str(&format!(
            "#[path = {:?}]\npub mod {f};\n",
            dir.join(format!("{f}.rs")).display().to_string()
        ));
    }
    out.push_str("/// Every rule, in code order.\npub static RULES: &[&Rule] = &[\n");
    for f in &files {
        out.push_str(&format!("    &{f}::RULE,\n"));
    }
    out.push_str("];\n");
    let dest = Path::new(&std::env::var("OUT_DIR").unwrap()).join("rules_registry.rs");
    std::fs::write(dest, out).unwrap();
    reference_shaders(Path::new(&manifest));
}

/// `rtlint verify` and `rtlint tradeoff` carry the reference shaders and
/// scenes (`shaders/`, 30 small files) so that an installed binary runs
/// them from any folder: every file's path and bytes, and a hash of them all
/// that names the folder they are written to.
fn reference_shaders(manifest: &Path) {
    let root = manifest.join("shaders");
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for e in entries.flatten() {
            let path = e.path();
            if path.is_dir() {
                stack.push(path);
            } else if let Ok(rel) = path.strip_prefix(&root) {
                files.push((rel.to_string_lossy().replace('\\', "/"), path.clone()));
            }
        }
    }
    files.sort();
    // FNV-1a over names and contents: a new build with other shaders
    // writes a new folder rather than reusing a stale one.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut out = String::from("/// The reference shaders: path under `shaders/`, bytes.\npub static FILES: &[(&str, &[u8])] = &[\n");
    for (rel, path) in &files {
        let bytes = std::fs::read(path).unwrap_or_default();
        for b in rel.bytes().chain([0]).chain(bytes) {
            hash = (hash ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
        }
        out.push_str(&format!(
            "    ({rel:?}, include_bytes!({:?})),\n",
            path.display().to_string()
        ));
    }
    out.push_str(&format!(
        "];\n/// A hash of every path and byte above.\npub const HASH: &str = \"{hash:016x}\";\n"
    ));
    let dest = Path::new(&std::env::var("OUT_DIR").unwrap()).join("reference_shaders.rs");
    std::fs::write(dest, out).unwrap();
}
