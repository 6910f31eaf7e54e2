//! A pure-Rust HLSL → SPIR-V compiler for ray-tracing shaders: DXR
//! libraries and subobjects, inline ray queries, compute and pixel shaders.
//! It follows DXC's documented HLSL → SPIR-V mapping for Vulkan, and writes
//! SPIR-V 1.4 with positions (`OpLine`) and
//! `NonSemantic.Shader.DebugInfo.100` declarations.
//!
//! ```no_run
//! use rtlint_hlsl::{compile_file, HlslOptions};
//!
//! let module = compile_file("rt.hlsl".as_ref(), &HlslOptions::default())?;
//! for (name, stage) in &module.entries {
//!     println!("{name}: {}", stage.as_str());
//! }
//! # Ok::<(), rtlint_hlsl::CompileError>(())
//! ```
//!
//! [`compile`] gives one module per entry point, [`compile_file`] one module
//! with all of them plus declaration positions and DXR subobjects;
//! [`compile_source`] and [`compile_source_whole`] take the text and a
//! [`pp::FileLoader`] for includes. [`HlslOptions`] is what a DXC command
//! line says. An error is a [`CompileError`] (kind, message, file, line and
//! column); HLSL outside the supported subset is refused with
//! `not supported: ...` at its position, never miscompiled.
//!
//! Stages: [`pp`] (preprocessor, on tokens) → [`lex`] → [`parse`] →
//! [`template`] (instances of the templates used) → lowering (type checking
//! and SPIR-V emission) → words. The stages pass plain data along, as in
//! naga's WGSL front-end; internal errors (a position and a message) become
//! a [`CompileError`] in one place at this crate's boundary.

pub mod ast;
pub mod attrs;
pub mod error;
pub mod lex;
mod lower;
pub mod parse;
pub mod pp;
pub mod subobject;
pub mod template;
pub mod types;

mod options;
mod text;
mod vocab;

pub use error::{CompileError, ErrorDetails, ErrorKind, Label};
pub use options::{
    parse_args, Bindings, HlslOptions, ParsedArgs, Profile, ProfileKind, RegisterBinding, Shift,
    TargetEnv,
};
pub use text::decode_source;
pub use vocab::{Location, NamedDecl, Stage};

use std::path::{Path, PathBuf};

/// Reads a DXC target profile (`ps_6_5`, `cs_6_0`, `lib_6_3`, `lib_6_x`) or
/// a stage name (`pixel`, `closesthit`, ...). `lib_*` gives `None`: stages
/// come from the `[shader(...)]` attributes.
pub fn parse_stage(s: &str) -> Result<Option<Stage>, String> {
    if let Some(stage) = Stage::from_hlsl_name(s) {
        return Ok(Some(stage));
    }
    let profile = Profile::parse(s).ok_or_else(|| match s.contains('_') {
        true => format!("unknown profile `{s}`"),
        false => format!("unknown profile or stage `{s}`"),
    })?;
    let unsupported = |what: &str| Err(format!("not supported: {what} shaders (`{s}`)"));
    match profile.kind {
        ProfileKind::Pixel => Ok(Some(Stage::Fragment)),
        ProfileKind::Compute => Ok(Some(Stage::Compute)),
        ProfileKind::Library => Ok(None),
        ProfileKind::Vertex => unsupported("vertex"),
        ProfileKind::Geometry => unsupported("geometry"),
        ProfileKind::Hull => unsupported("hull"),
        ProfileKind::Domain => unsupported("domain"),
        ProfileKind::Mesh => unsupported("mesh"),
        ProfileKind::Amplification => unsupported("amplification"),
    }
}

/// The lowerer for `items`, told about a command-line entry point's stage.
fn lowerer<'a>(
    items: &'a [ast::Item],
    files: &'a [PathBuf],
    options: &HlslOptions,
) -> lower::Lowerer<'a> {
    let mut l = lower::Lowerer::new(items, files);
    if let (Some(e), Some(s)) = (&options.entry, options.stage) {
        l.forced_entry = Some((e.clone(), s));
    }
    l.sixteen_bit_types = options.enable_16bit_types;
    l.bindings = options.bindings.clone();
    l
}

/// One entry point compiled to its own SPIR-V module.
#[derive(Clone, Debug)]
pub struct CompiledEntry {
    pub name: String,
    pub stage: Stage,
    pub words: Vec<u32>,
    /// `file:line:col: warning: message` (e.g. an include matched ignoring case).
    pub warnings: Vec<String>,
}

/// A whole file compiled to one module holding every entry point.
#[derive(Clone, Debug)]
pub struct CompiledModule {
    pub words: Vec<u32>,
    pub entries: Vec<(String, Stage)>,
    /// Source positions of structs, members, globals and functions.
    pub decls: Vec<(NamedDecl, Location)>,
    /// DXR subobjects (shader and pipeline configs, hit groups, associations).
    pub subobjects: subobject::Subobjects,
    /// `file:line:col: warning: message` (e.g. an include matched ignoring case).
    pub warnings: Vec<String>,
}

/// Compiles each entry point of `path` into its own module.
pub fn compile(path: &Path, options: &HlslOptions) -> Result<Vec<CompiledEntry>, CompileError> {
    let text = read_source(path)?;
    let mut loader = pp::FsLoader;
    compile_source(path, &text, &mut loader, options)
}

/// Compiles every entry point of `path` into one module (what `rtlint check` reads).
pub fn compile_file(path: &Path, options: &HlslOptions) -> Result<CompiledModule, CompileError> {
    let text = read_source(path)?;
    let mut loader = pp::FsLoader;
    compile_source_whole(path, &text, &mut loader, options)
}

/// Preprocesses and parses `text` (the contents of `path`).
pub fn parse_source(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<(Vec<ast::Item>, Vec<PathBuf>), CompileError> {
    with_stack(|| parse_source_inner(path, text, loader, options))
}

fn parse_source_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<(Vec<ast::Item>, Vec<PathBuf>), CompileError> {
    parse_with_warnings(path, text, loader, options).map(|(items, files, _)| (items, files))
}

/// Items, the file table, and warnings.
type Parsed = (Vec<ast::Item>, Vec<PathBuf>, Vec<String>);

/// Preprocesses and parses; also gives the warnings, rendered
/// `file:line:col: warning: message`.
fn parse_with_warnings(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<Parsed, CompileError> {
    let predefined = options.predefined_macros();
    let out = pp::preprocess_with(
        path,
        text,
        loader,
        &pp::Setup {
            include_dirs: &options.include_dirs,
            predefined: &predefined,
            defines: &options.defines,
            row_major: options.row_major,
        },
    )
    .map_err(|f| f.error.into_compile_error(&f.files, path))?;
    let items = parse::parse(&out.tokens).map_err(|e| e.into_compile_error(&out.files, path))?;
    let warnings = out
        .warnings
        .iter()
        .map(|w| {
            let file = out
                .files
                .get(w.pos.file as usize)
                .map(|f| f.display().to_string())
                .unwrap_or_default();
            format!(
                "{file}:{}:{}: warning: {}",
                w.pos.line, w.pos.col, w.message
            )
        })
        .collect();
    Ok((items, out.files, warnings))
}

fn entry_indices(
    lowerer: &mut lower::Lowerer,
    path: &Path,
    files: &[PathBuf],
    options: &HlslOptions,
) -> Result<Vec<(usize, String, Stage)>, CompileError> {
    let entries = lowerer
        .declare()
        .map_err(|e| e.into_compile_error(files, path))?;
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
        let (kind, msg) = match &options.entry {
            Some(name) => (ErrorKind::Invalid, format!("no entry point named `{name}`")),
            None => (
                ErrorKind::NoEntryPoint,
                "no entry points: mark one with [shader(\"...\")] or [numthreads(...)], or name it with its stage (-E main -T ps_6_5)".to_string(),
            ),
        };
        return Err(CompileError::whole(kind, path, msg));
    }
    Ok(picked)
}

/// Runs `f` on a thread with a large stack: parsing and lowering recurse
/// over the syntax tree, whose depth the input controls (up to the parser's
/// nesting limit), and debug builds use big frames.
fn with_stack<T: Send>(
    f: impl FnOnce() -> Result<T, CompileError> + Send,
) -> Result<T, CompileError> {
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .stack_size(64 << 20)
            .spawn_scoped(s, f)
            .map_err(|e| {
                CompileError::whole(
                    ErrorKind::Invalid,
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
) -> Result<Vec<CompiledEntry>, CompileError> {
    with_stack(|| compile_source_inner(path, text, loader, options))
}

/// Template instances: lowering finds the ones missing, they are added to
/// the syntax tree, and lowering runs again until none is missing.
fn instantiate_templates(items: &mut Vec<ast::Item>, files: &[PathBuf], options: &HlslOptions) {
    const MAX_ROUNDS: usize = 64;
    const MAX_INSTANCES: usize = 512;
    let has_templates = items.iter().any(|i| match i {
        ast::Item::Function(f) => !f.tparams.is_empty(),
        ast::Item::Struct(s) => {
            !s.tparams.is_empty() || s.methods.iter().any(|m| !m.tparams.is_empty())
        }
        _ => false,
    });
    if !has_templates {
        return;
    }
    let mut made = std::collections::HashSet::new();
    for _ in 0..MAX_ROUNDS {
        let needed = {
            let mut l = lowerer(items, files, options);
            let entries = l.declare().map(|e| {
                e.iter()
                    .filter(|e| options.entry.as_ref().is_none_or(|n| *n == e.name))
                    .filter_map(|e| l.entry_function(&e.name))
                    .collect::<Vec<_>>()
            });
            if let Ok(ks) = entries {
                let _ = l.lower_reached(&ks);
            }
            std::mem::take(&mut l.needed)
        };
        if needed.is_empty() {
            return;
        }
        for inst in &needed {
            // A failure here (or an instance asked for twice) leaves the
            // instance missing: the compile then reports the use that needed it.
            if !made.insert((inst.name.clone(), inst.template))
                || made.len() > MAX_INSTANCES
                || template::instantiate(items, inst).is_err()
            {
                return;
            }
        }
    }
}

fn compile_source_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<Vec<CompiledEntry>, CompileError> {
    let (mut items, files, warnings) = parse_with_warnings(path, text, loader, options)?;
    instantiate_templates(&mut items, &files, options);
    let mut probe = lowerer(&items, &files, options);
    let picked = entry_indices(&mut probe, path, &files, options)?;
    let mut out = Vec::new();
    for (_, name, stage) in picked {
        // A fresh module per entry point, holding only what it reaches.
        let mut l = lowerer(&items, &files, options);
        l.declare()
            .map_err(|e| e.into_compile_error(&files, path))?;
        let k = l
            .entry_function(&name)
            .ok_or_else(|| CompileError::whole(ErrorKind::Invalid, path, "entry point vanished"))?;
        let (words, _) = l
            .finish(&[k])
            .map_err(|e| e.into_compile_error(&files, path))?;
        out.push(CompiledEntry {
            name,
            stage,
            words,
            warnings: warnings.clone(),
        });
    }
    Ok(out)
}

pub fn compile_source_whole(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, CompileError> {
    with_stack(|| compile_source_whole_inner(path, text, loader, options))
}

fn compile_source_whole_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, CompileError> {
    let (mut items, files, warnings) = parse_with_warnings(path, text, loader, options)?;
    instantiate_templates(&mut items, &files, options);
    let mut l = lowerer(&items, &files, options);
    let picked = entry_indices(&mut l, path, &files, options)?;
    let ks: Vec<usize> = picked
        .iter()
        .filter_map(|(_, name, _)| l.entry_function(name))
        .collect();
    let subobjects = std::mem::take(&mut l.subobjects);
    let (words, decls) = l
        .finish(&ks)
        .map_err(|e| e.into_compile_error(&files, path))?;
    Ok(CompiledModule {
        words,
        entries: picked.into_iter().map(|(_, n, s)| (n, s)).collect(),
        decls,
        subobjects,
        warnings,
    })
}

/// Reads a source file as DXC reads it: any bytes (see [`decode_source`]).
pub fn read_source(path: &Path) -> Result<String, CompileError> {
    let bytes = std::fs::read(path).map_err(|e| {
        CompileError::whole(
            ErrorKind::Unreadable,
            path,
            format!("cannot read file: {e}"),
        )
    })?;
    Ok(decode_source(bytes))
}
