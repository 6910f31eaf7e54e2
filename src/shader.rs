//! The vocabulary every layer shares: a shader's source language, its stage,
//! and positions in its source. A leaf: it imports nothing from the crate, so
//! front-ends, the Program, analyses, rules and reports may all use it.

use std::fmt;
use std::path::{Path, PathBuf};

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

/// A shader stage. One enum for every layer: the HLSL compiler, the Program,
/// pipeline descriptions and the Vulkan harness.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    RayGeneration,
    Intersection,
    AnyHit,
    ClosestHit,
    Miss,
    Callable,
    Compute,
    Vertex,
    Fragment,
    Other,
}

impl Stage {
    pub fn from_model(model: spirv::ExecutionModel) -> Stage {
        use spirv::ExecutionModel as M;
        match model {
            M::RayGenerationKHR => Stage::RayGeneration,
            M::IntersectionKHR => Stage::Intersection,
            M::AnyHitKHR => Stage::AnyHit,
            M::ClosestHitKHR => Stage::ClosestHit,
            M::MissKHR => Stage::Miss,
            M::CallableKHR => Stage::Callable,
            M::GLCompute => Stage::Compute,
            M::Vertex => Stage::Vertex,
            M::Fragment => Stage::Fragment,
            _ => Stage::Other,
        }
    }

    /// The SPIR-V execution model; `None` for [`Stage::Other`].
    pub fn model(self) -> Option<spirv::ExecutionModel> {
        use spirv::ExecutionModel as M;
        Some(match self {
            Stage::RayGeneration => M::RayGenerationKHR,
            Stage::Intersection => M::IntersectionKHR,
            Stage::AnyHit => M::AnyHitKHR,
            Stage::ClosestHit => M::ClosestHitKHR,
            Stage::Miss => M::MissKHR,
            Stage::Callable => M::CallableKHR,
            Stage::Compute => M::GLCompute,
            Stage::Vertex => M::Vertex,
            Stage::Fragment => M::Fragment,
            Stage::Other => return None,
        })
    }

    pub fn as_str(self) -> &'static str {
        match self {
            Stage::RayGeneration => "raygeneration",
            Stage::Intersection => "intersection",
            Stage::AnyHit => "anyhit",
            Stage::ClosestHit => "closesthit",
            Stage::Miss => "miss",
            Stage::Callable => "callable",
            Stage::Compute => "compute",
            Stage::Vertex => "vertex",
            Stage::Fragment => "fragment",
            Stage::Other => "other",
        }
    }

    /// The name HLSL's `[shader("...")]` attribute uses (`pixel` for fragment).
    pub fn hlsl_name(self) -> &'static str {
        match self {
            Stage::Fragment => "pixel",
            s => s.as_str(),
        }
    }

    /// The stage an HLSL `[shader("...")]` attribute names (of those the HLSL
    /// compiler lowers).
    pub fn from_hlsl_name(name: &str) -> Option<Stage> {
        Some(match name {
            "raygeneration" => Stage::RayGeneration,
            "closesthit" => Stage::ClosestHit,
            "anyhit" => Stage::AnyHit,
            "miss" => Stage::Miss,
            "intersection" => Stage::Intersection,
            "callable" => Stage::Callable,
            "compute" => Stage::Compute,
            "pixel" => Stage::Fragment,
            _ => return None,
        })
    }

    pub fn is_ray_tracing(self) -> bool {
        matches!(
            self,
            Stage::RayGeneration
                | Stage::Intersection
                | Stage::AnyHit
                | Stage::ClosestHit
                | Stage::Miss
                | Stage::Callable
        )
    }
}

/// A place in a source file. Lines and columns are 1-based; a column of 0 means
/// "the whole line" (debug info without columns).
#[derive(
    Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub struct Location {
    pub path: PathBuf,
    pub line: u32,
    pub column: u32,
    pub end_line: u32,
    pub end_column: u32,
}

impl Location {
    pub fn point(path: impl Into<PathBuf>, line: u32, column: u32) -> Self {
        Location {
            path: path.into(),
            line,
            column,
            end_line: line,
            end_column: column,
        }
    }

    /// A location from one (line, column) to another.
    pub fn between(path: impl Into<PathBuf>, start: (u32, u32), end: (u32, u32)) -> Self {
        Location {
            path: path.into(),
            line: start.0,
            column: start.1,
            end_line: end.0,
            end_column: end.1,
        }
    }

    /// A location spanning `len` columns from `column` on one line.
    pub fn span(path: impl Into<PathBuf>, line: u32, column: u32, len: u32) -> Self {
        Location {
            path: path.into(),
            line,
            column,
            end_line: line,
            end_column: column + len,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.column > 0 {
            write!(f, "{}:{}:{}", self.path.display(), self.line, self.column)
        } else {
            write!(f, "{}:{}", self.path.display(), self.line)
        }
    }
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
