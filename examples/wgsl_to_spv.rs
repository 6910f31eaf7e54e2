//! Writes the SPIR-V rtlint analyses for a WGSL file: `wgsl_to_spv IN.wgsl OUT.spv`.
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(&a[1]);
    let text = std::fs::read_to_string(path).unwrap();
    let words = rtlint::front::wgsl::compile(&text, path).unwrap_or_else(|e| panic!("{e}"));
    std::fs::write(
        &a[2],
        words
            .iter()
            .flat_map(|w| w.to_le_bytes())
            .collect::<Vec<u8>>(),
    )
    .unwrap();
}
