//! Generates the rule registry: one module per `src/rules/rt*.rs` file and
//! `RULES` in code order, so that adding a rule is adding its file.

use std::path::Path;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/rules");
    println!("cargo:rerun-if-changed={}", dir.display());
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
