//! Debug-info helpers: resolving source paths and naming types.

use super::{Id, Program, Type};
use crate::shader::Language;
use std::path::{Path, PathBuf};

/// Where a path named by debug info lives on this machine: as written if it
/// exists, else beside the module, else its file name beside the module, else
/// as written (the report then shows no snippet).
pub fn resolve_path(named: &str, module_path: &Path) -> PathBuf {
    normalize(&resolve_unnormalized(named, module_path))
}

/// Removes `.` and `name/..` lexically, so messages show `a/c` for `a/b/../c`.
pub fn normalize(p: &Path) -> PathBuf {
    use std::path::Component;
    let mut out: Vec<Component> = Vec::new();
    for c in p.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        return PathBuf::from(".");
    }
    out.iter().collect()
}

fn resolve_unnormalized(named: &str, module_path: &Path) -> PathBuf {
    let p = Path::new(named);
    if p.is_absolute() && p.exists() {
        return p.to_path_buf();
    }
    let dir = module_path.parent().unwrap_or_else(|| Path::new(""));
    let beside = dir.join(p);
    if beside.exists() {
        return beside;
    }
    if let Some(file) = p.file_name() {
        let b = dir.join(file);
        if b.exists() {
            return b;
        }
    }
    p.to_path_buf()
}

/// The name of a type in the source language's spelling.
pub fn type_name(program: &Program, id: Id, lang: Language) -> String {
    name_at(program, id, lang, 0)
}

/// Nesting past which a name is cut short: forward-declared pointers let
/// a type contain itself (a valid `buffer_reference` list, or a fuzzed
/// module), so the walk through pointees must end.
const MAX_NAME_DEPTH: u32 = 8;

fn name_at(program: &Program, id: Id, lang: Language, depth: u32) -> String {
    if depth > MAX_NAME_DEPTH {
        return "…".into();
    }
    let wgsl = lang == Language::Wgsl;
    if lang == Language::Glsl {
        return glsl_type_name(program, id);
    }
    let scalar = |t: &Type| -> String {
        match (t, wgsl) {
            (Type::Bool, _) => "bool".into(),
            (
                Type::Int {
                    width: 32,
                    signed: true,
                },
                true,
            ) => "i32".into(),
            (
                Type::Int {
                    width: 32,
                    signed: false,
                },
                true,
            ) => "u32".into(),
            (Type::Float { width: 32 }, true) => "f32".into(),
            (Type::Float { width: 16 }, true) => "f16".into(),
            (Type::Int { width, signed }, true) => {
                format!("{}{width}", if *signed { "i" } else { "u" })
            }
            (Type::Float { width }, true) => format!("f{width}"),
            (
                Type::Int {
                    width: 32,
                    signed: true,
                },
                false,
            ) => "int".into(),
            (
                Type::Int {
                    width: 32,
                    signed: false,
                },
                false,
            ) => "uint".into(),
            (
                Type::Int {
                    width: 16,
                    signed: true,
                },
                false,
            ) => "int16_t".into(),
            (
                Type::Int {
                    width: 16,
                    signed: false,
                },
                false,
            ) => "uint16_t".into(),
            (
                Type::Int {
                    width: 64,
                    signed: true,
                },
                false,
            ) => "int64_t".into(),
            (
                Type::Int {
                    width: 64,
                    signed: false,
                },
                false,
            ) => "uint64_t".into(),
            (Type::Int { width, signed }, false) => {
                format!("{}int{width}_t", if *signed { "" } else { "u" })
            }
            (Type::Float { width: 32 }, false) => "float".into(),
            (Type::Float { width: 16 }, false) => "half".into(),
            (Type::Float { width: 64 }, false) => "double".into(),
            (Type::Float { width }, false) => format!("float{width}_t"),
            _ => "?".into(),
        }
    };
    match program.ty(id) {
        None => format!("%{id}"),
        Some(t) => match t {
            Type::Void => "void".into(),
            Type::Bool | Type::Int { .. } | Type::Float { .. } => scalar(t),
            Type::Vector { elem, count } => {
                let e = program.ty(*elem).map(scalar).unwrap_or_else(|| "?".into());
                if wgsl {
                    format!("vec{count}<{e}>")
                } else {
                    format!("{e}{count}")
                }
            }
            Type::Matrix { column, columns } => {
                let (e, rows) = match program.ty(*column) {
                    Some(Type::Vector { elem, count }) => (
                        program.ty(*elem).map(scalar).unwrap_or_else(|| "?".into()),
                        *count,
                    ),
                    _ => ("?".into(), 0),
                };
                if wgsl {
                    format!("mat{columns}x{rows}<{e}>")
                } else {
                    // HLSL names rows×columns; SPIR-V from HLSL is transposed, so a
                    // SPIR-V matrix of C columns of R-vectors is HLSL's CxR.
                    format!("{e}{columns}x{rows}")
                }
            }
            Type::Array { elem, len } => {
                let n = len
                    .value()
                    .map(|v| v.to_string())
                    .unwrap_or_else(|| "N".into());
                if wgsl {
                    format!("array<{}, {n}>", name_at(program, *elem, lang, depth + 1))
                } else {
                    format!("{}[{n}]", name_at(program, *elem, lang, depth + 1))
                }
            }
            Type::RuntimeArray { elem } => {
                if wgsl {
                    format!("array<{}>", name_at(program, *elem, lang, depth + 1))
                } else {
                    format!("{}[]", name_at(program, *elem, lang, depth + 1))
                }
            }
            Type::Struct { .. } => program.display_name(id),
            Type::Pointer { pointee, .. } => {
                format!("ptr<{}>", name_at(program, *pointee, lang, depth + 1))
            }
            Type::AccelerationStructure => {
                if wgsl {
                    "acceleration_structure".into()
                } else {
                    "RaytracingAccelerationStructure".into()
                }
            }
            Type::RayQuery => {
                if wgsl {
                    "ray_query".into()
                } else {
                    "RayQuery".into()
                }
            }
            Type::Image => "image".into(),
            Type::Sampler => "sampler".into(),
            Type::SampledImage => "sampled_image".into(),
            Type::Function { .. } => "function".into(),
            Type::Other(op) => (*op).into(),
        },
    }
}

fn glsl_scalar(t: Option<&Type>) -> (&'static str, String) {
    // (vector prefix, scalar name)
    match t {
        Some(Type::Bool) => ("b", "bool".into()),
        Some(Type::Int {
            width: 32,
            signed: true,
        }) => ("i", "int".into()),
        Some(Type::Int {
            width: 32,
            signed: false,
        }) => ("u", "uint".into()),
        Some(Type::Int {
            width,
            signed: true,
        }) => ("i", format!("int{width}_t")),
        Some(Type::Int {
            width,
            signed: false,
        }) => ("u", format!("uint{width}_t")),
        Some(Type::Float { width: 32 }) => ("", "float".into()),
        Some(Type::Float { width: 64 }) => ("d", "double".into()),
        Some(Type::Float { width }) => ("", format!("float{width}_t")),
        _ => ("", "?".into()),
    }
}

fn glsl_type_name(program: &Program, id: Id) -> String {
    match program.ty(id) {
        Some(t @ (Type::Bool | Type::Int { .. } | Type::Float { .. })) => glsl_scalar(Some(t)).1,
        Some(Type::Vector { elem, count }) => match program.ty(*elem) {
            Some(Type::Float { width: 16 }) => format!("f16vec{count}"),
            Some(Type::Int { width: 16, signed }) => {
                format!("{}16vec{count}", if *signed { "i" } else { "u" })
            }
            e => format!("{}vec{count}", glsl_scalar(e).0),
        },
        Some(Type::Matrix { column, columns }) => {
            let (prefix, rows) = match program.ty(*column) {
                Some(Type::Vector { elem, count }) => (glsl_scalar(program.ty(*elem)).0, *count),
                _ => ("", 0),
            };
            if rows == *columns {
                format!("{prefix}mat{columns}")
            } else {
                format!("{prefix}mat{columns}x{rows}")
            }
        }
        Some(Type::Array { elem, len }) => {
            let n = len.value().map(|v| v.to_string()).unwrap_or_default();
            format!("{}[{n}]", glsl_type_name(program, *elem))
        }
        Some(Type::RuntimeArray { elem }) => format!("{}[]", glsl_type_name(program, *elem)),
        Some(Type::AccelerationStructure) => "accelerationStructureEXT".into(),
        Some(Type::RayQuery) => "rayQueryEXT".into(),
        _ => type_name(program, id, Language::Hlsl),
    }
}
