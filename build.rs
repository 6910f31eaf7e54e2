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
}
