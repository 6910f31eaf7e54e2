//! The HLSL front-end: the `rtlint-hlsl` crate, its errors turned into
//! rtlint's [`InputError`]. Everything else is the crate's own (see
//! `crates/rtlint-hlsl` and `docs/hlsl.md`).

pub use rtlint_hlsl::*;

use crate::diag::InputError;
use std::path::{Path, PathBuf};

/// Compiles each entry point of `path` into its own module.
pub fn compile(path: &Path, options: &HlslOptions) -> Result<Vec<CompiledEntry>, InputError> {
    Ok(rtlint_hlsl::compile(path, options)?)
}

/// Compiles every entry point of `path` into one module (what `rtlint check` reads).
pub fn compile_file(path: &Path, options: &HlslOptions) -> Result<CompiledModule, InputError> {
    Ok(rtlint_hlsl::compile_file(path, options)?)
}

/// [`compile`] of `text`, the contents of `path`; includes come from `loader`.
pub fn compile_source(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<Vec<CompiledEntry>, InputError> {
    Ok(rtlint_hlsl::compile_source(path, text, loader, options)?)
}

/// [`compile_file`] of `text`, the contents of `path`.
pub fn compile_source_whole(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, InputError> {
    Ok(rtlint_hlsl::compile_source_whole(
        path, text, loader, options,
    )?)
}

/// Preprocesses and parses `text` (the contents of `path`).
pub fn parse_source(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<(Vec<ast::Item>, Vec<PathBuf>), InputError> {
    Ok(rtlint_hlsl::parse_source(path, text, loader, options)?)
}
