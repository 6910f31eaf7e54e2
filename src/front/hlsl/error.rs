//! Internal errors: a position and a message; they become an [`InputError`] in
//! one place, [`Error::into_input_error`], at the front-end's boundary.

use crate::diag::{InputError, InputErrorKind, Label, Location};
use std::path::{Path, PathBuf};

/// A position in one of the files read for a compile (index into the file table).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Pos {
    pub file: u32,
    pub line: u32,
    pub col: u32,
}

/// What an error says about the input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The input is wrong: a syntax, name or type error.
    Invalid,
    /// Valid HLSL this compiler does not handle (`not supported: ...`).
    Unsupported,
    /// A bug of the compiler (a builder error).
    Internal,
}

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

    #[cold]
    pub fn into_input_error(self, files: &[PathBuf], main: &Path) -> InputError {
        let path = |p: Pos| {
            files
                .get(p.file as usize)
                .cloned()
                .unwrap_or_else(|| main.to_path_buf())
        };
        let name = if self.kind == Kind::Unsupported {
            InputErrorKind::HlslUnsupported
        } else {
            InputErrorKind::HlslError
        };
        let label = if self.label.is_empty() {
            "here".to_string()
        } else {
            self.label.clone()
        };
        let mut e = InputError::new(name, main, self.message).at(
            Location::span(path(self.pos), self.pos.line, self.pos.col, self.len),
            label,
        );
        for (p, l) in self.secondary {
            e.0.secondary
                .push(Label::new(Location::point(path(p), p.line, p.col), l));
        }
        for n in self.notes {
            e = e.with_note(n);
        }
        e
    }
}

pub type Result<T> = std::result::Result<T, Error>;
