//! HLSL front-end: preprocess → lex → parse → type-check and emit SPIR-V.
//!
//! The shape follows naga's WGSL front-end: stages pass plain data along, and
//! internal errors (a position and a message) become an [`InputError`] in one
//! place at this module's boundary. See `docs/hlsl.md` for what is supported.

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
    /// The stage of `entry` when it has no `[shader(...)]` (DXC's `-T`).
    pub stage: Option<Stage>,
    /// DXC's `-enable-16bit-types`: `half` and the `min16*` types are then
    /// 16-bit, which this compiler refuses rather than widen.
    pub enable_16bit_types: bool,
}

/// Reads a DXC target profile (`ps_6_5`, `cs_6_0`, `lib_6_3`) or a stage name
/// (`pixel`, `closesthit`, ...). `lib_*` gives `None`: stages come from the
/// `[shader(...)]` attributes.
pub fn parse_stage(s: &str) -> Result<Option<Stage>, String> {
    if let Some(stage) = Stage::from_hlsl_name(s) {
        return Ok(Some(stage));
    }
    let (kind, version) = s
        .split_once('_')
        .ok_or_else(|| format!("unknown profile or stage `{s}`"))?;
    let valid_version = version
        .split('_')
        .all(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_digit()));
    if !valid_version {
        return Err(format!("unknown profile `{s}`"));
    }
    match kind {
        "ps" => Ok(Some(Stage::Fragment)),
        "cs" => Ok(Some(Stage::Compute)),
        "lib" => Ok(None),
        "vs" | "gs" | "hs" | "ds" | "ms" | "as" => Err(format!(
            "not supported: {} shaders (`{s}`)",
            match kind {
                "vs" => "vertex",
                "gs" => "geometry",
                "hs" => "hull",
                "ds" => "domain",
                "ms" => "mesh",
                _ => "amplification",
            }
        )),
        _ => Err(format!("unknown profile `{s}`")),
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
) -> Result<Parsed, InputError> {
    let out = pp::preprocess(path, text, loader, &options.include_dirs, &options.defines)
        .map_err(|f| f.error.into_input_error(&f.files, path))?;
    let items = parse::parse(&out.tokens).map_err(|e| e.into_input_error(&out.files, path))?;
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
        return Err(match &options.entry {
            Some(name) => InputError::new(
                InputErrorKind::HlslError,
                path,
                format!("no entry point named `{name}`"),
            ),
            None => InputError::new(
                InputErrorKind::NoEntryPoint,
                path,
                "no entry points: mark one with [shader(\"...\")] or [numthreads(...)], or name it with its stage (-E main -T ps_6_5)",
            ),
        });
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
) -> Result<Vec<CompiledEntry>, InputError> {
    let (mut items, files, warnings) = parse_with_warnings(path, text, loader, options)?;
    instantiate_templates(&mut items, &files, options);
    let mut probe = lowerer(&items, &files, options);
    let picked = entry_indices(&mut probe, path, &files, options)?;
    let mut out = Vec::new();
    for (_, name, stage) in picked {
        // A fresh module per entry point, holding only what it reaches.
        let mut l = lowerer(&items, &files, options);
        l.declare().map_err(|e| e.into_input_error(&files, path))?;
        let k = l.entry_function(&name).ok_or_else(|| {
            InputError::new(InputErrorKind::HlslError, path, "entry point vanished")
        })?;
        let (words, _) = l
            .finish(&[k])
            .map_err(|e| e.into_input_error(&files, path))?;
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
) -> Result<CompiledModule, InputError> {
    with_stack(|| compile_source_whole_inner(path, text, loader, options))
}

fn compile_source_whole_inner(
    path: &Path,
    text: &str,
    loader: &mut dyn pp::FileLoader,
    options: &HlslOptions,
) -> Result<CompiledModule, InputError> {
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
        .map_err(|e| e.into_input_error(&files, path))?;
    Ok(CompiledModule {
        words,
        entries: picked.into_iter().map(|(_, n, s)| (n, s)).collect(),
        decls,
        subobjects,
        warnings,
    })
}
