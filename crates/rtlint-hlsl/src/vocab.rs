//! The crate's vocabulary: a shader stage, a place in a source file, and a
//! named declaration. Small value types a caller keeps using after the
//! compile (rtlint shares them with its other front-ends).

use std::fmt;
use std::path::PathBuf;

/// A shader stage. It names every stage a SPIR-V module may hold, not only
/// those this compiler emits, so that a caller can use one enum for all its
/// front-ends.
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

/// A declaration named in source, matched to SPIR-V ids through `OpName`: how
/// the compiler hands over declaration positions the module's own debug info
/// does not carry (struct members, globals, functions).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NamedDecl {
    /// A struct type, by name.
    Type(String),
    /// A member of a struct type: the struct's name and the member's index.
    Member(String, u32),
    /// A module-scope variable (resources, groupshared, static).
    Global(String),
    /// A function, by name.
    Function(String),
}
