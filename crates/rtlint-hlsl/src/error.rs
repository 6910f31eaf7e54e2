//! Errors. Inside the compiler an error is a position in the file table and a
//! message ([`Error`]); it becomes the public [`CompileError`], whose
//! positions name files, in one place ([`Error::into_compile_error`]) at the
//! crate's boundary.

use crate::vocab::Location;
use std::fmt;
use std::path::{Path, PathBuf};

/// A position in one of the files read for a compile (index into the file table).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Pos {
    pub file: u32,
    pub line: u32,
    pub col: u32,
}

/// What an error says about the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kind {
    /// The input is wrong: a syntax, name or type error.
    Invalid,
    /// Valid HLSL this compiler does not handle (`not supported: ...`).
    Unsupported,
    /// A bug of the compiler (a builder error).
    Internal,
    /// The main file could not be read.
    Unreadable,
    /// The file declares no entry point (and none was named): a header, when
    /// another file includes it.
    NoEntryPoint,
}

/// The public name of [`Kind`].
pub use Kind as ErrorKind;

#[derive(Clone, Debug)]
pub struct Error {
    pub kind: Kind,
    pub pos: Pos,
    /// Columns the primary label covers (at least 1).
    pub len: u32,
    pub message: String,
    pub label: String,
    pub secondary: Vec<(Pos, String)>,
    pub notes: Vec<String>,
}

impl Error {
    pub fn new(pos: Pos, message: impl Into<String>) -> Self {
        Error {
            kind: Kind::Invalid,
            pos,
            len: 1,
            message: message.into(),
            label: String::new(),
            secondary: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// `not supported: <what>`: valid HLSL this compiler refuses.
    pub fn unsupported(pos: Pos, what: impl std::fmt::Display) -> Self {
        Error {
            kind: Kind::Unsupported,
            ..Error::new(pos, format!("not supported: {what}"))
        }
    }

    pub fn internal(message: impl std::fmt::Display) -> Self {
        Error {
            kind: Kind::Internal,
            ..Error::new(
                Pos::default(),
                format!("internal compiler error: {message}"),
            )
        }
    }

    pub fn is_unsupported(&self) -> bool {
        self.kind == Kind::Unsupported
    }

    pub fn len(mut self, len: u32) -> Self {
        self.len = len.max(1);
        self
    }

    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.notes.push(note.into());
        self
    }

    pub fn secondary(mut self, pos: Pos, label: impl Into<String>) -> Self {
        self.secondary.push((pos, label.into()));
        self
    }

    /// The public error, its positions naming files of `files` (`main` for
    /// a position outside the table).
    #[cold]
    pub fn into_compile_error(self, files: &[PathBuf], main: &Path) -> CompileError {
        let path = |p: Pos| {
            files
                .get(p.file as usize)
                .cloned()
                .unwrap_or_else(|| main.to_path_buf())
        };
        let label = if self.label.is_empty() {
            "here".to_string()
        } else {
            self.label.clone()
        };
        let primary = Label {
            location: Location::span(path(self.pos), self.pos.line, self.pos.col, self.len),
            message: label,
        };
        CompileError(Box::new(ErrorDetails {
            kind: self.kind,
            file: main.to_path_buf(),
            message: self.message,
            primary: Some(primary),
            secondary: self
                .secondary
                .into_iter()
                .map(|(p, l)| Label {
                    location: Location::point(path(p), p.line, p.col),
                    message: l,
                })
                .collect(),
            notes: self.notes,
        }))
    }
}

/// A place in the source and what it says about it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Label {
    pub location: Location,
    pub message: String,
}

/// Why a compile failed, rendered as `file:line:col: message` by `Display`;
/// a caller with a diagnostics renderer reads the [`ErrorDetails`] (through
/// `Deref`: `e.kind`, `e.primary`). Boxed, so that a `Result` stays small.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompileError(Box<ErrorDetails>);

/// What kind of failure, the message, where (the primary label: file, line,
/// column and the span's end), other places that explain it, and notes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ErrorDetails {
    pub kind: ErrorKind,
    /// The file that was compiled (an error in an included file names the
    /// included file in its label).
    pub file: PathBuf,
    pub message: String,
    /// Where; `None` for an error about the compile as a whole (no entry
    /// point, an unreadable file).
    pub primary: Option<Label>,
    pub secondary: Vec<Label>,
    pub notes: Vec<String>,
}

impl CompileError {
    /// An error about the compile as a whole, with no position.
    pub fn whole(kind: ErrorKind, file: &Path, message: impl Into<String>) -> Self {
        CompileError(Box::new(ErrorDetails {
            kind,
            file: file.to_path_buf(),
            message: message.into(),
            primary: None,
            secondary: Vec::new(),
            notes: Vec::new(),
        }))
    }

    /// The details, owned.
    pub fn into_details(self) -> ErrorDetails {
        *self.0
    }

    /// Valid HLSL this compiler does not handle (its message starts with
    /// `not supported:`).
    pub fn is_unsupported(&self) -> bool {
        self.kind == ErrorKind::Unsupported
    }
}

impl fmt::Display for CompileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.primary {
            Some(l) => write!(f, "{}: {}", l.location, self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl std::error::Error for CompileError {}

impl std::ops::Deref for CompileError {
    type Target = ErrorDetails;
    fn deref(&self) -> &ErrorDetails {
        &self.0
    }
}

pub type Result<T> = std::result::Result<T, Error>;
