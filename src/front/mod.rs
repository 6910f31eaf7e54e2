//! Front-ends: every input language ends as SPIR-V words whose debug info
//! (`OpString`/`OpLine`, or `NonSemantic.Shader.DebugInfo.100`) leads back to the
//! original source.

#[cfg(feature = "naga-oil")]
pub mod compose;
pub mod glsl;
pub mod hlsl;
pub mod wgsl;

use crate::diag::InputError;
pub use crate::diag::{io_error, read_text, InputErrorKind};
use crate::program::NamedDecl;
use crate::shader::{Language, Location};
use std::path::{Path, PathBuf};

/// One SPIR-V module produced from one input file.
#[derive(Clone, Debug)]
pub struct Compiled {
    /// The input file as the user named it.
    pub path: PathBuf,
    /// The language the module was written in (for a `.spv`, the language its
    /// `OpSource` names, when it names one we know).
    pub language: Language,
    /// The language of the input file itself.
    pub input_language: Language,
    pub words: Vec<u32>,
    /// Declaration positions the SPIR-V's own debug info lacks.
    pub decls: Vec<(NamedDecl, Location)>,
    /// The scratch file an external compiler read instead of `path`.
    pub scratch_source: Option<PathBuf>,
    /// DXR subobjects an HLSL file declares (empty for other languages).
    pub subobjects: hlsl::subobject::Subobjects,
}

/// Options for front-ends that read more than one file.
#[derive(Clone, Debug, Default)]
pub struct FrontOptions {
    /// `-I` directories (HLSL and GLSL), after the including file's folder.
    pub include_dirs: Vec<PathBuf>,
    /// `-D NAME=VALUE` (HLSL and GLSL).
    pub defines: Vec<(String, String)>,
    /// The rest of a DXC command line (`-E`, `-T`, register shifts, ...):
    /// the one HLSL options type, whose own `-I`/`-D` lists come after the
    /// shared ones above. [`FrontOptions::hlsl_options`] puts them together.
    pub hlsl: hlsl::HlslOptions,
    /// GLSL: the stage (glslang's name, `rchit`) of a file whose extension
    /// names none (`--stage`, or `[stages]` in rtlint.toml).
    pub glsl_stage: Option<String>,
}

impl FrontOptions {
    /// What the HLSL compiler is given: the shared `-I`/`-D`, then the rest.
    pub fn hlsl_options(&self) -> hlsl::HlslOptions {
        let mut o = hlsl::HlslOptions {
            include_dirs: self.include_dirs.clone(),
            defines: self.defines.clone(),
            ..hlsl::HlslOptions::default()
        };
        o.merge(&self.hlsl);
        o
    }
}

/// Reads and compiles one file to SPIR-V.
pub fn compile_path(path: &Path, language: Language) -> Result<Compiled, InputError> {
    compile_input(path, None, language, &FrontOptions::default())
}

/// Compiles one input to SPIR-V: the file at `path`, or `contents` (standard
/// input) under that name.
pub fn compile_input(
    path: &Path,
    contents: Option<&[u8]>,
    language: Language,
    options: &FrontOptions,
) -> Result<Compiled, InputError> {
    let text = || -> Result<String, InputError> {
        match contents {
            Some(bytes) => crate::diag::text_from_bytes(bytes, path),
            None => read_text(path),
        }
    };
    let compiled = |language, words, decls| Compiled {
        path: path.to_path_buf(),
        language,
        input_language: language,
        words,
        decls,
        scratch_source: None,
        subobjects: Default::default(),
    };
    match language {
        Language::Wgsl => {
            let text = text()?;
            let (mut module, mut info) =
                wgsl::parse_composed(&text, path, &options.include_dirs, &options.defines)?;
            if let Some((m, i)) =
                wgsl::apply_overrides(&module, &info, &text, &options.defines, path)?
            {
                (module, info) = (m, i);
            }
            let words = wgsl::write_spirv(&mut module, &info, &text, path)?;
            Ok(compiled(
                Language::Wgsl,
                words,
                wgsl::declarations(&module, &text, path),
            ))
        }
        Language::Spirv => {
            let bytes = match contents {
                Some(b) => b.to_vec(),
                None => std::fs::read(path).map_err(|e| io_error(path, &e))?,
            };
            let words = crate::program::words_from_bytes(&bytes, path)?;
            Ok(compiled(Language::Spirv, words, Vec::new()))
        }
        Language::Hlsl => {
            // Any bytes, as DXC reads them (Windows-1252, a BOM, UTF-16).
            let text = match contents {
                Some(bytes) => hlsl::decode_source(bytes.to_vec()),
                None => hlsl::read_source(path)?,
            };
            let hlsl_options = options.hlsl_options();
            let m =
                hlsl::compile_source_whole(path, &text, &mut hlsl::pp::FsLoader, &hlsl_options)?;
            let mut c = compiled(Language::Hlsl, m.words, m.decls);
            c.subobjects = m.subobjects;
            Ok(c)
        }
        Language::Glsl => {
            // glslang takes bytes: a Latin-1 comment is no reason to refuse.
            let bytes = match contents {
                Some(b) => b.to_vec(),
                None => std::fs::read(path).map_err(|e| io_error(path, &e))?,
            };
            let (words, scratch) = glsl::compile(path, &bytes, options)?;
            let mut c = compiled(Language::Glsl, words, Vec::new());
            c.scratch_source = scratch;
            Ok(c)
        }
    }
}

/// Compiles one file and builds its [`Program`](crate::program::Program).
pub fn load(path: &Path, language: Language) -> Result<crate::program::Program, InputError> {
    load_input(path, None, language, &FrontOptions::default())
}

/// Compiles one input and builds its Program; debug info that names the
/// front-end's scratch copy names the input instead.
pub fn load_input(
    path: &Path,
    contents: Option<&[u8]>,
    language: Language,
    options: &FrontOptions,
) -> Result<crate::program::Program, InputError> {
    load_library(path, contents, language, options).map(|(program, _)| program)
}

/// [`load_input`], also giving the DXR subobjects an HLSL library declares
/// (a pipeline description when no `*.pipeline.toml` names the file).
pub fn load_library(
    path: &Path,
    contents: Option<&[u8]>,
    language: Language,
    options: &FrontOptions,
) -> Result<(crate::program::Program, hlsl::subobject::Subobjects), InputError> {
    let mut c = compile_input(path, contents, language, options)?;
    let words = std::mem::take(&mut c.words);
    let mut program = crate::program::parse_owned(words, &c.path, c.language)?;
    program.attach_named_decls(&c.decls);
    if let Some(scratch) = &c.scratch_source {
        for f in &mut program.files {
            if f.path == *scratch {
                f.path = path.to_path_buf();
            }
        }
    }
    Ok((program, c.subobjects))
}
