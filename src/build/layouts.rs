//! Rust types for the host side of shader interfaces: ray payloads, hit
//! attributes, callable data, shader records, push constants and
//! constant/uniform buffers.
//!
//! Which layout a type follows depends on its role:
//! - payloads, hit attributes and callable data have no offsets in the module;
//!   they follow the scalar rule Vulkan and DXC size them by (every scalar
//!   aligned to the block's largest scalar), the `scalar` figure of
//!   `rtlint layout`;
//! - push constants, shader records and uniform/constant buffers follow the
//!   module's own `Offset`, `ArrayStride` and `MatrixStride` decorations, which
//!   are the truth for HLSL cbuffer packing, std140 and std430 alike.
//!
//! Every generated struct is `#[repr(C)]` with explicit `_padN` fields where
//! the next offset jumps, and is followed by `const` assertions of its size and
//! of each field's offset, so a layout the Rust compiler would place
//! differently fails to compile instead of corrupting data. glam types are
//! used only where both their size and their alignment fit the offset;
//! 16-byte-aligned ones (`Vec4`, `Mat4`, `Mat3A`, `Mat2`) only in top-level
//! types whose size is a multiple of 16, so nested types are the same
//! wherever they appear.

use crate::analysis::layout::{layout_type, scalar_layout, Shape};
use crate::diag::{Diagnostic, Severity};
use crate::program::{Decl, Id, Program, Type};
use crate::shader::Language;
use spirv::{Decoration, StorageClass};
use std::collections::HashMap;

pub struct Options {
    pub glam: bool,
    pub bytemuck: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    RayPayload,
    HitAttribute,
    CallableData,
    ShaderRecord,
    PushConstant,
    Uniform,
}

impl Kind {
    fn from_storage(s: StorageClass) -> Option<Kind> {
        use StorageClass as S;
        Some(match s {
            S::RayPayloadKHR | S::IncomingRayPayloadKHR => Kind::RayPayload,
            S::HitAttributeKHR => Kind::HitAttribute,
            S::CallableDataKHR | S::IncomingCallableDataKHR => Kind::CallableData,
            S::ShaderRecordBufferKHR => Kind::ShaderRecord,
            S::PushConstant => Kind::PushConstant,
            S::Uniform => Kind::Uniform,
            _ => return None,
        })
    }

    fn words(self) -> &'static str {
        match self {
            Kind::RayPayload => "ray payload",
            Kind::HitAttribute => "hit attributes",
            Kind::CallableData => "callable data",
            Kind::ShaderRecord => "shader record",
            Kind::PushConstant => "push constants",
            Kind::Uniform => "constant buffer",
        }
    }

    /// Types with no offsets in the module: laid out by the scalar rule.
    fn scalar_rule(self) -> bool {
        matches!(
            self,
            Kind::RayPayload | Kind::HitAttribute | Kind::CallableData
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum ScalarKind {
    F16,
    F32,
    F64,
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    /// 4 bytes, as HLSL and Vulkan store it.
    Bool,
}

impl ScalarKind {
    fn of(program: &Program, id: Id) -> Option<ScalarKind> {
        Some(match program.ty(id)? {
            Type::Bool => ScalarKind::Bool,
            Type::Float { width: 16 } => ScalarKind::F16,
            Type::Float { width: 32 } => ScalarKind::F32,
            Type::Float { width: 64 } => ScalarKind::F64,
            Type::Int { width, signed } => match (width, signed) {
                (8, true) => ScalarKind::I8,
                (8, false) => ScalarKind::U8,
                (16, true) => ScalarKind::I16,
                (16, false) => ScalarKind::U16,
                (32, true) => ScalarKind::I32,
                (32, false) => ScalarKind::U32,
                (64, true) => ScalarKind::I64,
                (64, false) => ScalarKind::U64,
                _ => return None,
            },
            _ => return None,
        })
    }

    fn bytes(self) -> u64 {
        match self {
            ScalarKind::I8 | ScalarKind::U8 => 1,
            ScalarKind::F16 | ScalarKind::I16 | ScalarKind::U16 => 2,
            ScalarKind::F32 | ScalarKind::I32 | ScalarKind::U32 | ScalarKind::Bool => 4,
            ScalarKind::F64 | ScalarKind::I64 | ScalarKind::U64 => 8,
        }
    }

    /// The Rust scalar (a half float is kept as its bits).
    fn rust(self) -> &'static str {
        match self {
            ScalarKind::F16 | ScalarKind::U16 => "u16",
            ScalarKind::F32 => "f32",
            ScalarKind::F64 => "f64",
            ScalarKind::I8 => "i8",
            ScalarKind::U8 => "u8",
            ScalarKind::I16 => "i16",
            ScalarKind::I32 => "i32",
            ScalarKind::U32 | ScalarKind::Bool => "u32",
            ScalarKind::I64 => "i64",
            ScalarKind::U64 => "u64",
        }
    }

    /// glam's vector family for this scalar, with its element alignment.
    fn glam_vector(self) -> Option<&'static str> {
        match self {
            ScalarKind::F32 => Some("Vec"),
            ScalarKind::I32 => Some("IVec"),
            ScalarKind::U32 => Some("UVec"),
            ScalarKind::F64 => Some("DVec"),
            _ => None,
        }
    }
}

/// A type as laid out in memory.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Lay {
    Scalar(ScalarKind),
    /// `n` contiguous scalars.
    Vector(ScalarKind, u64),
    /// `vectors` groups of `comps` scalars, `stride` bytes apart.
    /// `glam_order`: the groups are the columns of the source-language matrix.
    Matrix {
        sc: ScalarKind,
        vectors: u64,
        comps: u64,
        stride: u64,
        glam_order: bool,
    },
    Array {
        elem: Box<Lay>,
        len: u64,
        stride: u64,
    },
    Struct(Box<StructLay>),
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct StructLay {
    name: String,
    /// (name, offset, layout), in offset order.
    members: Vec<(String, u64, Lay)>,
    /// Where the last member ends.
    size: u64,
}

impl Lay {
    /// Bytes from the start of the value to the end of its last scalar.
    fn extent(&self) -> u64 {
        match self {
            Lay::Scalar(s) => s.bytes(),
            Lay::Vector(s, n) => s.bytes() * n,
            Lay::Matrix {
                sc,
                vectors,
                comps,
                stride,
                ..
            } => {
                if *vectors == 0 {
                    0
                } else {
                    (vectors - 1) * stride + comps * sc.bytes()
                }
            }
            Lay::Array { elem, len, stride } => {
                if *len == 0 {
                    0
                } else {
                    (len - 1) * stride + elem.extent()
                }
            }
            Lay::Struct(s) => s.size,
        }
    }
}

// ------------------------------------------------------- from the Program

/// A layout from the module's `Offset`/`ArrayStride`/`MatrixStride`.
fn explicit(p: &Program, ty: Id, member: Option<(Id, u32)>, depth: u32) -> Result<Lay, String> {
    if depth > 64 {
        return Err("types nest too deeply".into());
    }
    match p.ty(ty) {
        Some(Type::Bool | Type::Int { .. } | Type::Float { .. }) => ScalarKind::of(p, ty)
            .map(Lay::Scalar)
            .ok_or_else(|| format!("`{}` has no Rust equivalent", p.type_name(ty))),
        Some(Type::Vector { elem, count }) => ScalarKind::of(p, *elem)
            .map(|s| Lay::Vector(s, u64::from(*count)))
            .ok_or_else(|| format!("`{}` has no Rust equivalent", p.type_name(ty))),
        Some(Type::Matrix { column, columns }) => {
            let Some(Type::Vector { elem, count }) = p.ty(*column) else {
                return Err(format!("`{}` is a malformed matrix", p.type_name(ty)));
            };
            let sc = ScalarKind::of(p, *elem)
                .ok_or_else(|| format!("`{}` has no Rust equivalent", p.type_name(ty)))?;
            let (s, k) = member.ok_or("a matrix outside a struct member has no stride")?;
            let stride = p
                .member_decoration(s, k, Decoration::MatrixStride)
                .and_then(|v| v.first().copied())
                .ok_or_else(|| {
                    format!(
                        "member `{}` has no MatrixStride decoration",
                        p.member_name(s, k)
                    )
                })?;
            let row_major = p.member_decoration(s, k, Decoration::RowMajor).is_some();
            let (vectors, comps) = if row_major {
                (u64::from(*count), u64::from(*columns))
            } else {
                (u64::from(*columns), u64::from(*count))
            };
            Ok(Lay::Matrix {
                sc,
                vectors,
                comps,
                stride: u64::from(stride),
                // HLSL's rows are SPIR-V's columns: its column-major storage
                // is SPIR-V `RowMajor`.
                glam_order: (p.language == Language::Hlsl) == row_major,
            })
        }
        Some(Type::Array { elem, len }) => {
            let len = len.value().ok_or_else(|| {
                format!(
                    "`{}` has a specialization-constant length without a default",
                    p.type_name(ty)
                )
            })?;
            let stride = p
                .decoration(ty, Decoration::ArrayStride)
                .and_then(|v| v.first().copied())
                .ok_or_else(|| format!("`{}` has no ArrayStride decoration", p.type_name(ty)))?;
            Ok(Lay::Array {
                elem: Box::new(explicit(p, *elem, member, depth + 1)?),
                len,
                stride: u64::from(stride),
            })
        }
        Some(Type::Struct { members }) => {
            let mut out = Vec::new();
            for (k, m) in members.iter().enumerate() {
                let k = k as u32;
                let offset = p
                    .member_decoration(ty, k, Decoration::Offset)
                    .and_then(|v| v.first().copied())
                    .ok_or_else(|| {
                        format!(
                            "member `{}` of `{}` has no Offset decoration",
                            p.member_name(ty, k),
                            p.display_name(ty)
                        )
                    })?;
                let lay = explicit(p, *m, Some((ty, k)), depth + 1)?;
                out.push((p.member_name(ty, k), u64::from(offset), lay));
            }
            Ok(Lay::Struct(Box::new(struct_lay(p.display_name(ty), out))))
        }
        _ => Err(format!("`{}` has no size in memory", p.type_name(ty))),
    }
}

fn struct_lay(name: String, mut members: Vec<(String, u64, Lay)>) -> StructLay {
    members.sort_by_key(|m| m.1);
    let size = members
        .iter()
        .map(|(_, o, l)| o + l.extent())
        .max()
        .unwrap_or(0);
    StructLay {
        name,
        members,
        size,
    }
}

fn max_scalar(shape: &Shape) -> u64 {
    match shape {
        Shape::Scalar { bytes } => *bytes,
        Shape::Vector { scalar, .. } | Shape::Matrix { scalar, .. } => *scalar,
        Shape::Array { elem, .. } => max_scalar(elem),
        Shape::Struct { members } => members.iter().map(max_scalar).max().unwrap_or(1),
        Shape::Opaque => 1,
    }
}

/// Size under the scalar rule with every scalar taking `align` bytes (as
/// `analysis::layout` counts payloads).
fn scalar_size(shape: &Shape, align: u64) -> u64 {
    match shape {
        Shape::Scalar { .. } => align,
        Shape::Vector { count, .. } => align * count,
        Shape::Matrix { count, vectors, .. } => align * count * vectors,
        Shape::Array { elem, len } => scalar_size(elem, align) * len,
        Shape::Struct { members } => members.iter().map(|m| scalar_size(m, align)).sum(),
        Shape::Opaque => 0,
    }
}

/// A layout under the scalar rule, every scalar in `align` bytes.
fn scalar(p: &Program, ty: Id, align: u64, depth: u32) -> Result<Lay, String> {
    if depth > 64 {
        return Err("types nest too deeply".into());
    }
    let no_rust = || format!("`{}` has no Rust equivalent", p.type_name(ty));
    // A scalar narrower than the block's alignment takes `align` bytes.
    let spaced = |sc: ScalarKind, n: u64| {
        if sc.bytes() == align {
            Lay::Vector(sc, n)
        } else {
            Lay::Array {
                elem: Box::new(Lay::Scalar(sc)),
                len: n,
                stride: align,
            }
        }
    };
    match p.ty(ty) {
        Some(Type::Bool | Type::Int { .. } | Type::Float { .. }) => {
            ScalarKind::of(p, ty).map(Lay::Scalar).ok_or_else(no_rust)
        }
        Some(Type::Vector { elem, count }) => {
            let sc = ScalarKind::of(p, *elem).ok_or_else(no_rust)?;
            Ok(spaced(sc, u64::from(*count)))
        }
        Some(Type::Matrix { column, columns }) => {
            let Some(Type::Vector { elem, count }) = p.ty(*column) else {
                return Err(no_rust());
            };
            let sc = ScalarKind::of(p, *elem).ok_or_else(no_rust)?;
            let (columns, count) = (u64::from(*columns), u64::from(*count));
            if sc.bytes() == align {
                Ok(Lay::Matrix {
                    sc,
                    vectors: columns,
                    comps: count,
                    stride: align * count,
                    glam_order: p.language != Language::Hlsl,
                })
            } else {
                Ok(Lay::Array {
                    elem: Box::new(spaced(sc, count)),
                    len: columns,
                    stride: align * count,
                })
            }
        }
        Some(Type::Array { elem, len }) => {
            let len = len.value().ok_or_else(|| {
                format!(
                    "`{}` has a specialization-constant length without a default",
                    p.type_name(ty)
                )
            })?;
            Ok(Lay::Array {
                elem: Box::new(scalar(p, *elem, align, depth + 1)?),
                len,
                stride: scalar_size(&Shape::from_type(p, *elem), align),
            })
        }
        Some(Type::Struct { members }) => {
            let mut out = Vec::new();
            let mut at = 0;
            for (k, m) in members.iter().enumerate() {
                let lay = scalar(p, *m, align, depth + 1)?;
                out.push((p.member_name(ty, k as u32), at, lay));
                at += scalar_size(&Shape::from_type(p, *m), align);
            }
            let mut s = struct_lay(p.display_name(ty), out);
            s.size = at;
            Ok(Lay::Struct(Box::new(s)))
        }
        _ => Err(format!("`{}` has no size in memory", p.type_name(ty))),
    }
}

/// The top-level layout of a struct under the scalar rule, with the size
/// `rtlint layout` reports.
fn scalar_top(p: &Program, ty: Id) -> Result<StructLay, String> {
    let Some(Type::Struct { members }) = p.ty(ty) else {
        return Err("not a struct".into());
    };
    let shapes: Vec<Shape> = members.iter().map(|m| Shape::from_type(p, *m)).collect();
    let align = shapes.iter().map(max_scalar).max().unwrap_or(4);
    let (offsets, size) = scalar_layout(&shapes);
    let mut out = Vec::new();
    for (k, m) in members.iter().enumerate() {
        out.push((
            p.member_name(ty, k as u32),
            offsets[k],
            scalar(p, *m, align, 1)?,
        ));
    }
    let mut s = struct_lay(p.display_name(ty), out);
    s.size = size;
    Ok(s)
}

// ---------------------------------------------------------- to Rust

/// A Rust type with its size and alignment.
#[derive(Clone, Debug)]
struct RustTy {
    text: String,
    size: u64,
    align: u64,
}

struct Field {
    name: String,
    ty: RustTy,
    offset: u64,
    pad: bool,
    /// What the doc comment adds to the offset.
    note: String,
}

/// How a matrix's memory reads: its columns or its rows, in the source's terms.
fn matrix_note(lay: &Lay) -> String {
    match lay {
        Lay::Matrix {
            vectors,
            comps,
            stride,
            glam_order,
            ..
        } => format!(
            "; {vectors} {} of {comps}, {stride} bytes apart",
            if *glam_order { "columns" } else { "rows" }
        ),
        Lay::Array { elem, .. } => matrix_note(elem),
        _ => String::new(),
    }
}

struct Gen<'a> {
    options: &'a Options,
    /// Rendered items, nested types before their users.
    items: Vec<String>,
    /// Nested struct variants: (layout, slot size) → Rust name.
    nested: HashMap<(StructLay, u64), (String, u64)>,
    /// Every Rust type name in use.
    taken: HashMap<String, ()>,
}

/// Whether a field may be a 16-byte-aligned glam type.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Align16 {
    Allowed,
    No,
}

impl Gen<'_> {
    fn glam(&self, name: &str, size: u64, align: u64) -> RustTy {
        RustTy {
            text: format!("glam::{name}"),
            size,
            align,
        }
    }

    fn array(elem: &RustTy, n: u64) -> RustTy {
        RustTy {
            text: format!("[{}; {n}]", elem.text),
            size: elem.size * n,
            align: elem.align,
        }
    }

    fn scalar(sc: ScalarKind) -> RustTy {
        RustTy {
            text: sc.rust().to_string(),
            size: sc.bytes(),
            align: sc.bytes(),
        }
    }

    /// The natural Rust type of `lay` placed at `offset` with `room` bytes
    /// before the next field. Padded arrays and matrices may be larger than
    /// the extent; the caller splits them.
    fn ty(&mut self, lay: &Lay, offset: u64, room: u64, a16: Align16) -> Result<RustTy, String> {
        let wide = a16 == Align16::Allowed && offset % 16 == 0;
        match lay {
            Lay::Scalar(sc) => Ok(Self::scalar(*sc)),
            Lay::Vector(sc, n) => {
                if let (true, Some(family), 2..=4) = (self.options.glam, sc.glam_vector(), *n) {
                    let b = sc.bytes();
                    let size = b * n;
                    // glam's Vec4 is 16-byte aligned; the integer and f64
                    // vectors keep their scalar's alignment.
                    let align = if *sc == ScalarKind::F32 && *n == 4 {
                        16
                    } else {
                        b
                    };
                    if align < 16 || wide {
                        return Ok(self.glam(&format!("{family}{n}"), size, align));
                    }
                }
                Ok(Self::array(&Self::scalar(*sc), *n))
            }
            Lay::Matrix {
                sc,
                vectors,
                comps,
                stride,
                glam_order,
            } => {
                let b = sc.bytes();
                if self.options.glam && *sc == ScalarKind::F32 && *glam_order && vectors == comps {
                    let pick = match (*vectors, *stride) {
                        (2, 8) if wide => Some(("Mat2", 16, 16)),
                        (3, 12) => Some(("Mat3", 36, 4)),
                        (3, 16) if wide && room >= 48 => Some(("Mat3A", 48, 16)),
                        (4, 16) if wide => Some(("Mat4", 64, 16)),
                        _ => None,
                    };
                    if let Some((name, size, align)) = pick {
                        return Ok(self.glam(name, size, align));
                    }
                }
                if stride % b != 0 || *stride < comps * b {
                    return Err(format!(
                        "a matrix stride of {stride} bytes does not fit {comps} scalars of {b} bytes"
                    ));
                }
                let column = Self::array(&Self::scalar(*sc), stride / b);
                Ok(Self::array(&column, *vectors))
            }
            Lay::Array { elem, len, stride } => {
                let e = self.element(elem, *stride)?;
                Ok(Self::array(&e, *len))
            }
            Lay::Struct(s) => self.nested(s, s.size),
        }
    }

    /// A type exactly `stride` bytes long holding `lay`: an array element.
    fn element(&mut self, lay: &Lay, stride: u64) -> Result<RustTy, String> {
        let t = self.ty(lay, 0, stride, Align16::No)?;
        if t.size == stride {
            return Ok(t);
        }
        if t.size < stride {
            match lay {
                Lay::Scalar(sc) | Lay::Vector(sc, _) if stride % sc.bytes() == 0 => {
                    return Ok(Self::array(&Self::scalar(*sc), stride / sc.bytes()));
                }
                Lay::Struct(s) => return self.nested(s, stride),
                _ => {}
            }
        }
        Err(format!(
            "an array element of {} bytes with a stride of {stride} bytes has no Rust equivalent",
            lay.extent()
        ))
    }

    /// A nested struct type of `slot` bytes (its own size, or an array stride).
    fn nested(&mut self, s: &StructLay, slot: u64) -> Result<RustTy, String> {
        let key = (s.clone(), slot);
        if let Some((name, align)) = self.nested.get(&key) {
            return Ok(RustTy {
                text: name.clone(),
                size: slot,
                align: *align,
            });
        }
        let base = if slot == s.size {
            rust_type_name(&s.name)
        } else {
            format!("{}Stride{slot}", rust_type_name(&s.name))
        };
        let name = self.fresh(&base);
        let (text, align) = self.render(&name, s, slot, Align16::No, "")?;
        self.items.push(text);
        self.nested.insert(key, (name.clone(), align));
        Ok(RustTy {
            text: name,
            size: slot,
            align,
        })
    }

    fn fresh(&mut self, base: &str) -> String {
        let mut name = base.to_string();
        let mut n = 2;
        while self.taken.contains_key(&name) {
            name = format!("{base}{n}");
            n += 1;
        }
        self.taken.insert(name.clone(), ());
        name
    }

    /// The fields of `s` in a struct of `slot` bytes, with explicit padding.
    fn fields(&mut self, s: &StructLay, slot: u64, a16: Align16) -> Result<Vec<Field>, String> {
        let mut out: Vec<Field> = Vec::new();
        let mut at = 0;
        let mut pads = 0;
        let pad = |out: &mut Vec<Field>, pads: &mut u32, from: u64, to: u64| {
            out.push(Field {
                name: format!("_pad{pads}"),
                ty: RustTy {
                    text: format!("[u8; {}]", to - from),
                    size: to - from,
                    align: 1,
                },
                offset: from,
                pad: true,
                note: String::new(),
            });
            *pads += 1;
        };
        for (k, (name, offset, lay)) in s.members.iter().enumerate() {
            let offset = *offset;
            if offset < at {
                return Err(format!(
                    "member `{name}` at offset {offset} overlaps the member before it (which ends at {at})"
                ));
            }
            if offset > at {
                pad(&mut out, &mut pads, at, offset);
            }
            let end = s.members.get(k + 1).map(|m| m.1).unwrap_or(slot);
            let room = end.saturating_sub(offset);
            let t = self.ty(lay, offset, room, a16)?;
            let field = rust_field_name(name);
            if t.size <= room {
                at = offset + t.size;
                out.push(Field {
                    name: field,
                    ty: t,
                    offset,
                    pad: false,
                    note: matrix_note(lay),
                });
                continue;
            }
            // A padded array or matrix whose last element's padding holds
            // the next member (HLSL packing): the last element on its own.
            let (head, last) = match lay {
                Lay::Array { elem, len, stride } if *len > 0 => {
                    let e = self.element(elem, *stride)?;
                    let last = self.ty(elem, 0, elem.extent(), Align16::No)?;
                    (Self::array(&e, len - 1), last)
                }
                Lay::Matrix {
                    sc,
                    vectors,
                    comps,
                    stride,
                    ..
                } if *vectors > 0 && stride % sc.bytes() == 0 => {
                    let column = Self::array(&Self::scalar(*sc), stride / sc.bytes());
                    (
                        Self::array(&column, vectors - 1),
                        Self::array(&Self::scalar(*sc), *comps),
                    )
                }
                _ => {
                    return Err(format!(
                    "member `{name}` needs {} bytes but only {room} are free at offset {offset}",
                    t.size
                ))
                }
            };
            if head.size + last.size > room {
                return Err(format!(
                    "member `{name}` needs {} bytes but only {room} are free at offset {offset}",
                    head.size + last.size
                ));
            }
            let last_offset = offset + head.size;
            let (what, n) = match lay {
                Lay::Matrix {
                    glam_order,
                    vectors,
                    ..
                } => (if *glam_order { "columns" } else { "rows" }, *vectors),
                Lay::Array { len, .. } => ("elements", *len),
                _ => ("elements", 0),
            };
            let note = matrix_note(lay);
            out.push(Field {
                name: field.clone(),
                ty: head,
                offset,
                pad: false,
                note: format!(
                    "{note}; {what} 0..{} with their padding",
                    n.saturating_sub(1)
                ),
            });
            at = last_offset + last.size;
            out.push(Field {
                name: format!("{}_last", field.trim_start_matches("r#")),
                ty: last,
                offset: last_offset,
                pad: false,
                note: format!(
                    "; `{name}` {} {}, which the next member packs after",
                    what.trim_end_matches('s'),
                    n.saturating_sub(1)
                ),
            });
        }
        if at < slot {
            pad(&mut out, &mut pads, at, slot);
        } else if at > slot {
            return Err(format!(
                "its members end at {at} bytes, past its size of {slot}"
            ));
        }
        for f in &out {
            if f.offset % f.ty.align != 0 {
                return Err(format!(
                    "`{}` ({}) at offset {} is not aligned to {} bytes",
                    f.name, f.ty.text, f.offset, f.ty.align
                ));
            }
        }
        Ok(out)
    }

    /// A struct item and its assertions; the struct's alignment.
    fn render(
        &mut self,
        name: &str,
        s: &StructLay,
        slot: u64,
        a16: Align16,
        doc: &str,
    ) -> Result<(String, u64), String> {
        let mut fields = self.fields(s, slot, a16)?;
        let mut align = fields.iter().map(|f| f.ty.align).max().unwrap_or(1);
        if slot % align != 0 {
            if a16 == Align16::No {
                return Err(format!(
                    "its size of {slot} bytes is not a multiple of its alignment ({align})"
                ));
            }
            fields = self.fields(s, slot, Align16::No)?;
            align = fields.iter().map(|f| f.ty.align).max().unwrap_or(1);
            if slot % align != 0 {
                return Err(format!(
                    "its size of {slot} bytes is not a multiple of its alignment ({align})"
                ));
            }
        }
        let mut t = String::new();
        if doc.is_empty() {
            t.push_str(&format!("/// `{}`, {slot} bytes.\n", s.name));
        } else {
            t.push_str(doc);
        }
        t.push_str("#[repr(C)]\n");
        t.push_str("#[derive(Clone, Copy, Debug, PartialEq)]\n");
        if self.options.bytemuck {
            t.push_str("#[derive(bytemuck::Pod, bytemuck::Zeroable)]\n");
        }
        t.push_str("#[allow(non_snake_case, non_camel_case_types, dead_code)]\n");
        t.push_str(&format!("pub struct {name} {{\n"));
        for f in &fields {
            if !f.pad {
                t.push_str(&format!("    /// offset {}{}\n", f.offset, f.note));
            }
            t.push_str(&format!("    pub {}: {},\n", f.name, f.ty.text));
        }
        t.push_str("}\n");
        t.push_str(&format!(
            "const _: () = assert!(core::mem::size_of::<{name}>() == {slot});\n"
        ));
        for f in fields.iter().filter(|f| !f.pad) {
            t.push_str(&format!(
                "const _: () = assert!(core::mem::offset_of!({name}, {}) == {});\n",
                f.name, f.offset
            ));
        }
        Ok((t, align))
    }
}

/// A Rust type name from a SPIR-V name: `type.Camera` → `Camera`,
/// `type.ConstantBuffer.Params` → `Params`, `$Globals` → `Globals`.
pub(super) fn rust_type_name(name: &str) -> String {
    let last = name.rsplit('.').next().unwrap_or(name);
    let mut out: String = last
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect::<String>()
        .trim_start_matches('_')
        .to_string();
    if out.is_empty() {
        out = "Type".into();
    }
    if out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'T');
    }
    let mut chars = out.chars();
    match chars.next() {
        Some(c) => c.to_uppercase().chain(chars).collect(),
        None => out,
    }
}

const KEYWORDS: &[&str] = &[
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn", "for",
    "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref", "return",
    "static", "struct", "trait", "true", "type", "unsafe", "use", "where", "while", "async",
    "await", "dyn", "abstract", "become", "box", "do", "final", "macro", "override", "priv",
    "typeof", "unsized", "virtual", "yield", "try", "gen",
];

fn rust_field_name(name: &str) -> String {
    let mut out: String = name
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, 'm');
    }
    // `_padN` names the generated padding.
    if out
        .strip_prefix("_pad")
        .is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()))
    {
        out.insert(0, 'm');
    }
    match out.as_str() {
        "self" | "Self" | "super" | "crate" | "_" => format!("{out}_"),
        k if KEYWORDS.contains(&k) => format!("r#{k}"),
        _ => out,
    }
}

fn round_up(x: u64, a: u64) -> u64 {
    x.div_ceil(a) * a
}

/// One interface type of one module, ready to render.
struct Top {
    name: String,
    kinds: Vec<Kind>,
    lay: StructLay,
    size: u64,
    rule: &'static str,
    location: String,
}

fn tops(p: &Program) -> Result<Vec<Top>, (Id, String)> {
    let mut out: Vec<(Id, Top)> = Vec::new();
    for g in &p.globals {
        let Some(kind) = Kind::from_storage(g.storage) else {
            continue;
        };
        let var = g.name.clone().unwrap_or_else(|| format!("v{}", g.id));
        let is_struct = matches!(p.ty(g.ty), Some(Type::Struct { .. }));
        if kind == Kind::Uniform && (!is_struct || p.decoration(g.ty, Decoration::Block).is_none())
        {
            continue;
        }
        if let Some((_, t)) = out.iter_mut().find(|(id, _)| is_struct && *id == g.ty) {
            if !t.kinds.contains(&kind) {
                t.kinds.push(kind);
            }
            continue;
        }
        let location = p
            .decl_location(Decl::Type(g.ty))
            .or_else(|| p.var_location(g.id))
            .map(|l| l.to_string())
            .unwrap_or_else(|| p.path.display().to_string());
        let fail = |e: String| (g.ty, e);
        let (lay, size, rule) = if !is_struct {
            // A lone value (WGSL allows `var<ray_payload> p: vec4<f32>`).
            let shape = Shape::from_type(p, g.ty);
            let align = max_scalar(&shape);
            let lay = scalar(p, g.ty, align, 1).map_err(fail)?;
            let s = struct_lay(var.clone(), vec![("value".into(), 0, lay)]);
            let size = scalar_size(&shape, align);
            (s, size, "scalar layout")
        } else if kind.scalar_rule() || !has_offsets(p, g.ty) {
            let s = scalar_top(p, g.ty).map_err(fail)?;
            let size = s.size;
            (s, size, "scalar layout")
        } else {
            let Lay::Struct(mut s) = explicit(p, g.ty, None, 0).map_err(fail)? else {
                continue;
            };
            // naga wraps a uniform in an unnamed block around the declared
            // struct: the declared struct is the type to generate.
            if p.name(g.ty).is_none() {
                if let [(_, 0, Lay::Struct(inner))] = s.members.as_slice() {
                    s = inner.clone();
                }
            }
            let size = match kind {
                Kind::Uniform if p.language == Language::Wgsl => layout_type(p, g.ty, &var)
                    .and_then(|t| t.wgsl_size)
                    .unwrap_or(round_up(s.size, 16)),
                // A constant buffer occupies whole 16-byte rows.
                Kind::Uniform => round_up(s.size, 16),
                _ => s.size,
            };
            (*s, size, "offsets as the module declares them")
        };
        let name = if is_struct && !lay.name.starts_with('%') {
            rust_type_name(&lay.name)
        } else {
            rust_type_name(&var)
        };
        out.push((
            g.ty,
            Top {
                name,
                kinds: vec![kind],
                lay,
                size,
                rule,
                location,
            },
        ));
    }
    Ok(out.into_iter().map(|(_, t)| t).collect())
}

fn has_offsets(p: &Program, ty: Id) -> bool {
    match p.ty(ty) {
        Some(Type::Struct { members }) => (0..members.len() as u32)
            .all(|k| p.member_decoration(ty, k, Decoration::Offset).is_some()),
        _ => false,
    }
}

/// The generated file for every interface type of `programs`; a type that
/// cannot be expressed, or two different types under one name, is an error.
pub fn generate(programs: &[Program], options: &Options) -> Result<String, Vec<Diagnostic>> {
    let mut gen = Gen {
        options,
        items: Vec::new(),
        nested: HashMap::new(),
        taken: HashMap::new(),
    };
    let mut errors = Vec::new();
    // Top-level name → (layout, size, where first seen).
    let mut seen: HashMap<String, (StructLay, u64, String)> = HashMap::new();
    let error = |p: &Program, ty: Option<Id>, message: String| {
        let mut d = Diagnostic::new(Severity::Error, "layout-generation", &p.path, message);
        if let Some(loc) = ty.and_then(|t| p.decl_location(Decl::Type(t))) {
            d = d.with_primary(Some(loc), "declared here");
        }
        d
    };
    // First every top-level type, so their names are reserved before any
    // nested type is named.
    let mut unique: Vec<(&Program, Top)> = Vec::new();
    for p in programs {
        let tops = match tops(p) {
            Ok(t) => t,
            Err((ty, e)) => {
                errors.push(error(
                    p,
                    Some(ty),
                    format!(
                        "cannot generate a Rust type for `{}`: {e}",
                        p.display_name(ty)
                    ),
                ));
                continue;
            }
        };
        for t in tops {
            if let Some((lay, size, first)) = seen.get(&t.name) {
                if *lay != t.lay || *size != t.size {
                    errors.push(error(
                        p,
                        None,
                        format!(
                            "`{}` at {} ({} bytes) differs from `{}` at {first} ({size} bytes): one Rust type cannot stand for both; rename one",
                            t.name, t.location, t.size, t.name
                        ),
                    ));
                }
                continue;
            }
            seen.insert(t.name.clone(), (t.lay.clone(), t.size, t.location.clone()));
            gen.taken.insert(t.name.clone(), ());
            unique.push((p, t));
        }
    }
    for (p, t) in unique {
        let roles: Vec<&str> = t.kinds.iter().map(|k| k.words()).collect();
        let doc = format!(
            "/// {} `{}` ({}): {}, {} bytes.\n",
            capitalize(&roles.join(", ")),
            t.lay.name.trim_start_matches("type."),
            t.location,
            t.rule,
            t.size
        );
        match gen.render(&t.name, &t.lay, t.size, Align16::Allowed, &doc) {
            Ok((text, _)) => gen.items.push(text),
            Err(e) => errors.push(error(
                p,
                None,
                format!(
                    "cannot generate a Rust type for `{}` at {}: {e}",
                    t.name, t.location
                ),
            )),
        }
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    let mut out = String::from(
        "// Generated by rtlint::build from the shaders' SPIR-V; do not edit.\n\
         // Payloads, hit attributes and callable data follow the scalar rule (the\n\
         // `scalar` size of `rtlint layout`); push constants, shader records and\n\
         // constant buffers the offsets the module declares. Each size and field\n\
         // offset is asserted below its type.\n\n",
    );
    for item in gen.items {
        out.push_str(&item);
        out.push('\n');
    }
    Ok(out)
}

fn capitalize(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}
