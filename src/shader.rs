//! The vocabulary every layer shares: a shader's source language, its stage,
//! and positions in its source. A leaf: it imports nothing from the crate, so
//! front-ends, the Program, analyses, rules and reports may all use it.
//! [`Stage`] and [`Location`] are the HLSL compiler's (`rtlint-hlsl`), shared.

use std::path::Path;

/// The language a shader was written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Language {
    Wgsl,
    Spirv,
    Hlsl,
    Glsl,
}

impl Language {
    pub fn as_str(self) -> &'static str {
        match self {
            Language::Wgsl => "wgsl",
            Language::Spirv => "spirv",
            Language::Hlsl => "hlsl",
            Language::Glsl => "glsl",
        }
    }

    /// The language a file holds, judged by its extension.
    pub fn from_path(path: &Path) -> Option<Language> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "wgsl" => Some(Language::Wgsl),
            "spv" | "spirv" => Some(Language::Spirv),
            "hlsl" | "hlsli" => Some(Language::Hlsl),
            "rgen" | "rchit" | "rmiss" | "rahit" | "rint" | "rcall" => Some(Language::Glsl),
            _ => None,
        }
    }

    pub fn parse(name: &str) -> Option<Language> {
        match name.to_ascii_lowercase().as_str() {
            "wgsl" => Some(Language::Wgsl),
            "spirv" | "spv" => Some(Language::Spirv),
            "hlsl" => Some(Language::Hlsl),
            "glsl" => Some(Language::Glsl),
            _ => None,
        }
    }
}

/// The GLSL stages glslang knows by name (its `-S` values and the file
/// extensions it reads them from) that rtlint lints: the ray-tracing stages,
/// and the others when they use ray queries.
pub const GLSL_STAGES: &[&str] = &[
    "rgen", "rchit", "rmiss", "rahit", "rint", "rcall", "comp", "frag", "vert", "mesh", "task",
];

pub use rtlint_hlsl::{Location, Stage};

/// A source file's text for what reads it after the compile (snippets,
/// suppression comments, declarations): any bytes, read as the HLSL
/// compiler reads them (a header may be Windows-1252); `None` when it
/// cannot be read.
pub fn read_source_text(path: &Path) -> Option<String> {
    std::fs::read(path).ok().map(rtlint_hlsl::decode_source)
}

/// The 1-based line and column (in characters) of a byte offset in `source`.
pub fn line_col(source: &str, offset: usize) -> (u32, u32) {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = before.matches('\n').count() as u32 + 1;
    let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
    let column = source[line_start..offset].chars().count() as u32 + 1;
    (line, column)
}
