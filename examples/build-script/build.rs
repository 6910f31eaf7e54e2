fn main() -> Result<(), rtlint::build::Error> {
    rtlint::build::Builder::new()
        .shaders("shaders")
        .pipeline("shaders/main.pipeline.toml")
        .include_dir("shaders/include")
        .deny_warnings(false)
        .emit_spirv()
        .generate_layouts("layouts.rs")
        .bytemuck(true)
        .run()
}
