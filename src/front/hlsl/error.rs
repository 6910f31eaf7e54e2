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

#[derive(Clone, Debug)]
pub struct Error {
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
            pos,
            len: 1,
            message: message.into(),
            label: String::new(),
            secondary: Vec::new(),
            notes: Vec::new(),
        }
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
        let name = if self.message.starts_with("not supported") {
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
