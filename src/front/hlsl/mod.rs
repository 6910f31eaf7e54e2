//! HLSL front-end: preprocess → lex → parse → type-check and emit SPIR-V.
//!
//! The shape follows naga's WGSL front-end: stages pass plain data along, and
//! internal errors (a position and a message) become an [`InputError`] in one
//! place at this module's boundary. See `docs/hlsl.md` for what is supported.

pub mod ast;
pub mod error;
pub mod lex;
mod lower;
pub mod parse;
pub mod pp;
pub mod types;

pub use crate::shader::Stage;

use crate::diag::{InputError, InputErrorKind};
use crate::program::NamedDecl;
use crate::shader::Location;
use std::path::{Path, PathBuf};

/// What `rtlint compile` and `rtlint check` pass to the compiler.
#[derive(Clone, Debug, Default)]
pub struct HlslOptions {
    /// `-I` directories, searched in order after the including file's folder.
    pub include_dirs: Vec<PathBuf>,
    /// `-D NAME[=VALUE]`; a define without a value is `1`.
    pub defines: Vec<(String, String)>,
    /// Compile only this entry point.
    pub entry: Option<String>,
}

/// One entry point compiled to its own SPIR-V module.
#[derive(Clone, Debug)]
pub struct CompiledEntry {
    pub name: String,
    pub stage: Stage,
    pub words: Vec<u32>,
}

/// A whole file compiled to one module holding every entry point.
#[derive(Clone, Debug)]
pub struct CompiledModule {
    pub words: Vec<u32>,
    pub entries: Vec<(String, Stage)>,
    /// Source positions of structs, members, globals and functions.
    pub decls: Vec<(NamedDecl, Location)>,
}

/// Compiles each entry point of `path` into its own module.
pub fn compile(path: &Path, options: &HlslOptions) -> Result<Vec<CompiledEntry>, InputError> {
    let text = crate::front::read_text(path)?;
    let mut loader = pp::FsLoader;
    compile_source(path, &text, &mut loader, options)
}

/// Compiles every entry point of `path` into one module (what `rtlint check` reads).
pub fn compile_file(path: &Path, options: &HlslOptions) -> Result<CompiledModule, InputError> {
    let text = crate::front::read_text(path)?;
    let mut loader = pp::FsLoader;
    compile_source_whole(path, &text, &mut loader, options)
}

/// Preprocesses and parses `text` (the contents of `path`).
pub fn parse_source(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<(Vec<ast::Item>, Vec<PathBuf>), InputError> {
    with_stack(|| parse_source_inner(path, text, loader, options))
}

fn parse_source_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<(Vec<ast::Item>, Vec<PathBuf>), InputError> {
    let out = pp::preprocess(path, text, loader, &options.include_dirs, &options.defines)
        .map_err(|f| f.error.into_input_error(&f.files, path))?;
    let items = parse::parse(&out.tokens).map_err(|e| e.into_input_error(&out.files, path))?;
    Ok((items, out.files))
}

fn entry_indices(
    lowerer: &mut lower::Lowerer,
    path: &Path,
    files: &[PathBuf],
    options: &HlslOptions,
) -> Result<Vec<(usize, String, Stage)>, InputError> {
    let entries = lowerer
        .declare()
        .map_err(|e| e.into_input_error(files, path))?;
    let all: Vec<(usize, String, Stage)> = entries
        .into_iter()
        .enumerate()
        .map(|(i, e)| (i, e.name, e.stage))
        .collect();
    let picked: Vec<_> = match &options.entry {
        Some(name) => all.into_iter().filter(|e| &e.1 == name).collect(),
        None => all,
    };
    if picked.is_empty() {
        let msg = match &options.entry {
            Some(name) => format!("no entry point named `{name}`"),
            None => {
                "no entry points: mark one with [shader(\"...\")] or [numthreads(...)]".to_string()
            }
        };
        return Err(InputError::new(InputErrorKind::HlslError, path, msg));
    }
    Ok(picked)
}

/// Runs `f` on a thread with a large stack: parsing and lowering recurse
/// over the syntax tree, whose depth the input controls (up to the parser's
/// nesting limit), and debug builds use big frames.
fn with_stack<T: Send>(f: impl FnOnce() -> Result<T, InputError> + Send) -> Result<T, InputError> {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, f)
            .map_err(|e| {
                InputError::new(
                    InputErrorKind::HlslError,
                    Path::new(""),
                    format!("cannot start the compiler thread: {e}"),
                )
            })?
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p))
    })
}

pub fn compile_source(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<Vec<CompiledEntry>, InputError> {
    with_stack(|| compile_source_inner(path, text, loader, options))
}

fn compile_source_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<Vec<CompiledEntry>, InputError> {
    let (items, files) = parse_source_inner(path, text, loader, options)?;
    let mut probe = lower::Lowerer::new(&items, &files);
    let picked = entry_indices(&mut probe, path, &files, options)?;
    let mut out = Vec::new();
    for (_, name, stage) in picked {
        // A fresh module per entry point, holding only what it reaches.
        let mut l = lower::Lowerer::new(&items, &files);
        l.declare().map_err(|e| e.into_input_error(&files, path))?;
        let k = l.entry_function(&name).ok_or_else(|| {
            InputError::new(InputErrorKind::HlslError, path, "entry point vanished")
        })?;
        let (words, _) = l
            .finish(&[k])
            .map_err(|e| e.into_input_error(&files, path))?;
        out.push(CompiledEntry { name, stage, words });
    }
    Ok(out)
}

pub fn compile_source_whole(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, InputError> {
    with_stack(|| compile_source_whole_inner(path, text, loader, options))
}

fn compile_source_whole_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, InputError> {
    let (items, files) = parse_source_inner(path, text, loader, options)?;
    let mut l = lower::Lowerer::new(&items, &files);
    let picked = entry_indices(&mut l, path, &files, options)?;
    let ks: Vec<usize> = picked
        .iter()
        .filter_map(|(_, name, _)| l.entry_function(name))
        .collect();
    let (words, decls) = l
        .finish(&ks)
        .map_err(|e| e.into_input_error(&files, path))?;
    Ok(CompiledModule {
        words,
        entries: picked.into_iter().map(|(_, n, s)| (n, s)).collect(),
        decls,
    })
}
