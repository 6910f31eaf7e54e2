//! Compiles one HLSL entry point with Slang and writes the SPIR-V.
//! `cargo run --example slang_probe -- FILE ENTRY STAGE OUT.spv`
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let s = rtlint_testkit::Slang::find().unwrap();
    let w = s
        .compile_hlsl(std::path::Path::new(&a[1]), &a[2], &a[3], &a[5..])
        .unwrap();
    std::fs::write(
        &a[4],
        w.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
}
