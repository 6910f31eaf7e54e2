//! Front-ends: every input language ends as SPIR-V words whose debug info
//! (`OpString`/`OpLine`, or `NonSemantic.Shader.DebugInfo.100`) leads back to the
//! original source.

pub mod hlsl;
pub mod wgsl;

use crate::diag::InputError;
pub use crate::diag::{io_error, read_text};
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
}

/// Reads and compiles one file to SPIR-V.
pub fn compile_path(path: &Path, language: Language) -> Result<Compiled, InputError> {
    match language {
        Language::Wgsl => {
            let text = read_text(path)?;
            let (module, info) = wgsl::parse(&text, path)?;
            let words = wgsl::write_spirv(&module, &info, &text, path)?;
            Ok(Compiled {
                path: path.to_path_buf(),
                language: Language::Wgsl,
                input_language: Language::Wgsl,
                words,
                decls: wgsl::declarations(&module, &text, path),
            })
        }
        Language::Spirv => {
            let bytes = std::fs::read(path).map_err(|e| io_error(path, &e))?;
            let words = crate::program::words_from_bytes(&bytes, path)?;
            Ok(Compiled {
                path: path.to_path_buf(),
                language: Language::Spirv,
                input_language: Language::Spirv,
                words,
                decls: Vec::new(),
            })
        }
        Language::Hlsl => {
            let m = hlsl::compile_file(path, &hlsl::HlslOptions::default())?;
            Ok(Compiled {
                path: path.to_path_buf(),
                language: Language::Hlsl,
                input_language: Language::Hlsl,
                words: m.words,
                decls: m.decls,
            })
        }
        Language::Glsl => Err(InputError::new(
            "unsupported-language",
            path,
            format!(
                "{} input is not supported by this build of rtlint",
                language.as_str()
            ),
        )),
    }
}

/// Compiles one file and builds its [`Program`](crate::program::Program).
pub fn load(path: &Path, language: Language) -> Result<crate::program::Program, InputError> {
    let c = compile_path(path, language)?;
    let mut program = crate::program::parse(&c.words, &c.path, c.language)?;
    program.attach_named_decls(&c.decls);
    Ok(program)
}
