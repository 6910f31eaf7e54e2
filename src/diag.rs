//! Diagnostics: what every front-end, analysis and rule hands to the report layer.
//!
//! Positions are 1-based line/column pairs in a named file, because that is what
//! SPIR-V debug info carries (`OpLine`, `DebugLine`). The report layer turns them
//! back into byte ranges when it can read the file.

use std::fmt;
use std::path::{Path, PathBuf};

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Note,
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

pub use crate::shader::Location;

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Label {
    pub location: Location,
    pub message: String,
}

impl Label {
    pub fn new(location: Location, message: impl Into<String>) -> Self {
        Label {
            location,
            message: message.into(),
        }
    }
}

/// A mechanical fix: the text that replaces the declaration at `location`
/// (so that a later `--fix` can apply it).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Fix {
    /// The declaration the replacement is for; `None` without debug info.
    pub location: Option<Location>,
    pub replacement: String,
}

/// One finding or one input error.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    /// `RT001` for rule findings; `None` for input errors.
    pub code: Option<&'static str>,
    /// The rule's kebab-case name, or the class of input error.
    pub name: &'static str,
    pub severity: Severity,
    /// One sentence: the fact, with the measured value and the limit.
    pub message: String,
    /// The file that was analysed (a `.spv` may point into its GLSL source).
    pub file: PathBuf,
    /// Where the claim is made; `None` when the module has no debug info.
    pub primary: Option<Label>,
    /// Evidence: declarations, call sites, config lines.
    pub secondary: Vec<Label>,
    /// Names the object when there is no source position (entry point, type, member).
    pub subject: Option<String>,
    pub notes: Vec<String>,
    pub help: Option<String>,
    /// A mechanical fix (e.g. a reordered struct).
    pub fix: Option<Fix>,
}

impl Diagnostic {
    /// An input error: no rule's finding, and not a note about an input
    /// (a header nothing includes).
    pub fn is_input_error(&self) -> bool {
        self.code.is_none() && self.severity != Severity::Note
    }

    pub fn new(
        severity: Severity,
        name: &'static str,
        file: &Path,
        message: impl Into<String>,
    ) -> Self {
        Diagnostic {
            code: None,
            name,
            severity,
            message: message.into(),
            file: file.to_path_buf(),
            primary: None,
            secondary: Vec::new(),
            subject: None,
            notes: Vec::new(),
            help: None,
            fix: None,
        }
    }

    pub fn with_code(mut self, code: &'static str) -> Self {
        self.code = Some(code);
        self
    }

    pub fn with_primary(mut self, location: Option<Location>, message: impl Into<String>) -> Self {
        self.primary = location.map(|l| Label::new(l, message));
        self
    }

    pub fn with_secondary(
        mut self,
        location: Option<Location>,
        message: impl Into<String>,
    ) -> Self {
        if let Some(l) = location {
            self.secondary.push(Label::new(l, message));
        }
        self
    }

    pub fn with_subject(mut self, subject: impl Into<String>) -> Self {
        self.subject = Some(subject.into());
        self
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// A fix: `replacement` for the declaration at `location`.
    pub fn with_fix(mut self, location: Option<Location>, replacement: impl Into<String>) -> Self {
        self.fix = Some(Fix {
            location,
            replacement: replacement.into(),
        });
        self
    }

    /// The position reported in one-line formats: the primary label, else the file.
    pub fn position(&self) -> (&Path, u32, u32, u32, u32) {
        match &self.primary {
            Some(l) => (
                &l.location.path,
                l.location.line,
                l.location.column,
                l.location.end_line,
                l.location.end_column,
            ),
            None => (&self.file, 0, 0, 0, 0),
        }
    }
}

/// The classes of bad input, each with a stable kebab-case name (the
/// diagnostic's `name` in every output format).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InputErrorKind {
    /// a file or folder could not be read.
    UnreadableFile,
    /// a text input is not valid UTF-8.
    InvalidUtf8,
    /// the language of a file cannot be told from its name.
    UnknownLanguage,
    /// this build cannot read the file's language.
    UnsupportedLanguage,
    /// `rtlint.toml` is malformed or names something unknown.
    InvalidConfig,
    /// a `*.pipeline.toml` description is malformed or names something missing.
    InvalidPipeline,
    /// a SPIR-V module is malformed.
    InvalidSpirv,
    /// naga cannot parse the WGSL.
    WgslParse,
    /// naga's validator rejects the WGSL.
    WgslValidation,
    /// naga cannot write the module as SPIR-V.
    WgslSpirvOut,
    /// naga panicked on the input.
    WgslInternal,
    /// the HLSL is malformed or ill-typed.
    HlslError,
    /// the HLSL uses a construct rtlint's compiler does not support.
    HlslUnsupported,
    /// glslang rejects the GLSL.
    GlslError,
    /// an HLSL file declares no entry point: a header when another linted
    /// file includes it (then dropped), else reported as a note.
    NoEntryPoint,
    /// a suppression in a shader names no rule, code or group.
    InvalidSuppression,
    /// `stack --driver`: the device could not create the pipeline (the
    /// driver failed or crashed, or the validation layer objected).
    DriverFailed,
}

impl InputErrorKind {
    pub const ALL: &'static [InputErrorKind] = &[
        InputErrorKind::UnreadableFile,
        InputErrorKind::InvalidUtf8,
        InputErrorKind::UnknownLanguage,
        InputErrorKind::UnsupportedLanguage,
        InputErrorKind::InvalidConfig,
        InputErrorKind::InvalidPipeline,
        InputErrorKind::InvalidSpirv,
        InputErrorKind::WgslParse,
        InputErrorKind::WgslValidation,
        InputErrorKind::WgslSpirvOut,
        InputErrorKind::WgslInternal,
        InputErrorKind::HlslError,
        InputErrorKind::HlslUnsupported,
        InputErrorKind::GlslError,
        InputErrorKind::DriverFailed,
        InputErrorKind::NoEntryPoint,
        InputErrorKind::InvalidSuppression,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            InputErrorKind::UnreadableFile => "unreadable-file",
            InputErrorKind::InvalidUtf8 => "invalid-utf8",
            InputErrorKind::UnknownLanguage => "unknown-language",
            InputErrorKind::UnsupportedLanguage => "unsupported-language",
            InputErrorKind::InvalidConfig => "invalid-config",
            InputErrorKind::InvalidPipeline => "invalid-pipeline",
            InputErrorKind::InvalidSpirv => "invalid-spirv",
            InputErrorKind::WgslParse => "wgsl-parse",
            InputErrorKind::WgslValidation => "wgsl-validation",
            InputErrorKind::WgslSpirvOut => "wgsl-spirv-out",
            InputErrorKind::WgslInternal => "wgsl-internal",
            InputErrorKind::HlslError => "hlsl-error",
            InputErrorKind::HlslUnsupported => "hlsl-unsupported",
            InputErrorKind::GlslError => "glsl-error",
            InputErrorKind::DriverFailed => "driver-failed",
            InputErrorKind::NoEntryPoint => "no-entry-point",
            InputErrorKind::InvalidSuppression => "invalid-suppression",
        }
    }
}

/// Bad input: an unreadable file, invalid SPIR-V, source a front-end rejects.
/// Always exit code 2; carries a diagnostic that names the file and position.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputError(pub Box<Diagnostic>);

impl InputError {
    pub fn new(kind: InputErrorKind, file: &Path, message: impl Into<String>) -> Self {
        InputError(Box::new(Diagnostic::new(
            Severity::Error,
            kind.as_str(),
            file,
            message,
        )))
    }

    pub fn at(mut self, location: Location, label: impl Into<String>) -> Self {
        self.0.primary = Some(Label::new(location, label));
        self
    }

    pub fn with_note(mut self, note: impl Into<String>) -> Self {
        self.0.notes.push(note.into());
        self
    }

    pub fn diagnostic(&self) -> &Diagnostic {
        &self.0
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = &self.0;
        match &d.primary {
            Some(l) => write!(f, "{}: {}", l.location, d.message),
            None => write!(f, "{}: {}", d.file.display(), d.message),
        }
    }
}

impl std::error::Error for InputError {}

/// The HLSL compiler's error as rtlint's: the kind picks the name, labels and
/// notes carry over.
impl From<rtlint_hlsl::CompileError> for InputError {
    #[cold]
    fn from(e: rtlint_hlsl::CompileError) -> Self {
        use rtlint_hlsl::ErrorKind as K;
        let e = e.into_details();
        let kind = match e.kind {
            K::Invalid | K::Internal => InputErrorKind::HlslError,
            K::Unsupported => InputErrorKind::HlslUnsupported,
            K::Unreadable => InputErrorKind::UnreadableFile,
            K::NoEntryPoint => InputErrorKind::NoEntryPoint,
        };
        let mut d = Diagnostic::new(Severity::Error, kind.as_str(), &e.file, e.message);
        d.primary = e.primary.map(|l| Label::new(l.location, l.message));
        d.secondary = e
            .secondary
            .into_iter()
            .map(|l| Label::new(l.location, l.message))
            .collect();
        d.notes = e.notes;
        InputError(Box::new(d))
    }
}

/// Reads a UTF-8 text input; an unreadable or non-UTF-8 file is an input error.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    let bytes = std::fs::read(path).map_err(|e| io_error(path, &e))?;
    // The bytes become the text, not a copy of them.
    String::from_utf8(bytes).map_err(|e| not_utf8(path, e.as_bytes(), e.utf8_error()))
}

/// Input bytes as UTF-8 text; anything else is an input error.
pub fn text_from_bytes(bytes: &[u8], path: &Path) -> Result<String, InputError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.to_string()),
        Err(e) => Err(not_utf8(path, bytes, e)),
    }
}

/// Where the first byte that is not UTF-8 is, as an editor counts: line and
/// column (in characters) of the valid text before it.
fn not_utf8(path: &Path, bytes: &[u8], e: std::str::Utf8Error) -> InputError {
    let offset = e.valid_up_to();
    let valid = std::str::from_utf8(&bytes[..offset]).unwrap_or_default();
    let (line, column) = crate::shader::line_col(valid, offset);
    let byte = bytes.get(offset).copied().unwrap_or_default();
    InputError::new(
        InputErrorKind::InvalidUtf8,
        path,
        format!("file is not valid UTF-8: byte 0x{byte:02x} at line {line}, column {column}"),
    )
    .at(Location::point(path, line, column), "not UTF-8")
}

pub fn io_error(path: &Path, e: &std::io::Error) -> InputError {
    InputError::new(
        InputErrorKind::UnreadableFile,
        path,
        format!("cannot read file: {e}"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names are a contract with every consumer of the JSON, SARIF and
    /// GitHub output: they never change silently.
    #[test]
    fn input_error_kinds_snapshot() {
        let names: Vec<&str> = InputErrorKind::ALL.iter().map(|k| k.as_str()).collect();
        assert_eq!(
            names,
            [
                "unreadable-file",
                "invalid-utf8",
                "unknown-language",
                "unsupported-language",
                "invalid-config",
                "invalid-pipeline",
                "invalid-spirv",
                "wgsl-parse",
                "wgsl-validation",
                "wgsl-spirv-out",
                "wgsl-internal",
                "hlsl-error",
                "hlsl-unsupported",
                "glsl-error",
                "driver-failed",
                "no-entry-point",
                "invalid-suppression",
            ]
        );
        for (i, a) in names.iter().enumerate() {
            assert!(a
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'));
            assert!(!names[i + 1..].contains(a), "{a} twice");
        }
    }
}
