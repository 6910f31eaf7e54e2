//! Semantic types and memory layouts.
//!
//! Matrices follow DXC's mapping: HLSL `floatRxC` is a SPIR-V matrix of R
//! column vectors of C floats, so `m[i]` (HLSL row i) is SPIR-V column i and
//! `mul` swaps its operands.

use super::error::Pos;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ScalarKind {
    Bool,
    /// `int16_t`/`uint16_t` (and `min16int`/`min16uint` with
    /// -enable-16bit-types); ordered so that mixed arithmetic widens.
    Int16,
    Uint16,
    Int,
    Uint,
    /// `int64_t` and `uint64_t` (ordered so that mixed arithmetic widens).
    Int64,
    Uint64,
    /// `float16_t` (and `half`/`min16float` with -enable-16bit-types): any
    /// float wins over any integer, as in DXC (`half * int` is `half`).
    Half,
    Float,
}

impl ScalarKind {
    pub fn name(self) -> &'static str {
        match self {
            ScalarKind::Bool => "bool",
            ScalarKind::Int16 => "int16_t",
            ScalarKind::Uint16 => "uint16_t",
            ScalarKind::Half => "float16_t",
            ScalarKind::Int => "int",
            ScalarKind::Uint => "uint",
            ScalarKind::Int64 => "int64_t",
            ScalarKind::Uint64 => "uint64_t",
            ScalarKind::Float => "float",
        }
    }

    /// Bytes of one value in memory.
    pub fn size(self) -> u32 {
        match self {
            ScalarKind::Int64 | ScalarKind::Uint64 => 8,
            ScalarKind::Int16 | ScalarKind::Uint16 | ScalarKind::Half => 2,
            _ => 4,
        }
    }

    pub fn is_signed(self) -> bool {
        matches!(
            self,
            ScalarKind::Int | ScalarKind::Int64 | ScalarKind::Int16
        )
    }

    pub fn is_float(self) -> bool {
        matches!(self, ScalarKind::Float | ScalarKind::Half)
    }

    pub fn is_16(self) -> bool {
        matches!(
            self,
            ScalarKind::Int16 | ScalarKind::Uint16 | ScalarKind::Half
        )
    }

    /// The 32-bit type of the same kind: what an image of 16-bit texels
    /// holds (Vulkan images have 32-bit sampled types), as DXC does.
    pub fn wide(self) -> ScalarKind {
        match self {
            ScalarKind::Half => ScalarKind::Float,
            ScalarKind::Int16 => ScalarKind::Int,
            ScalarKind::Uint16 => ScalarKind::Uint,
            s => s,
        }
    }

    /// 32-bit (or `bool`): what textures, wave intrinsics and the like take.
    pub fn is_32(self) -> bool {
        !self.is_64() && !self.is_16()
    }

    pub fn is_64(self) -> bool {
        matches!(self, ScalarKind::Int64 | ScalarKind::Uint64)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dim {
    D1,
    D2,
    D3,
    Cube,
    D2Array,
    D1Array,
    CubeArray,
    /// `Buffer<T>` / `RWBuffer<T>`: texel buffers.
    Buffer,
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Ty {
    Void,
    ScalarKind(ScalarKind),
    Vec(ScalarKind, u8),
    /// HLSL rows, columns.
    Mat(ScalarKind, u8, u8),
    Array(Box<Ty>, u32),
    /// Unbounded arrays: resources only.
    RtArray(Box<Ty>),
    Struct(u32),
    Accel,
    RayQuery(u32),
    Sampler,
    /// `dx::HitObject` (shader execution reordering): opaque, like a ray query.
    HitObject,
    /// `SamplerComparisonState` (the same SPIR-V sampler; used with `SampleCmp*`).
    SamplerCmp,
    Texture {
        dim: Dim,
        sc: ScalarKind,
        n: u8,
        rw: bool,
        /// `[[vk::image_format("...")]]`; else derived from the element type.
        fmt: Option<spirv::ImageFormat>,
    },
    StructuredBuffer(Box<Ty>, bool),
    ByteAddress(bool),
    ConstantBuffer(u32),
}

impl Ty {
    /// Ray queries and hit objects: variables only, never copied or stored.
    pub fn is_opaque(&self) -> bool {
        matches!(self, Ty::RayQuery(_) | Ty::HitObject)
    }
    pub fn scalar(&self) -> Option<ScalarKind> {
        match self {
            Ty::ScalarKind(s) | Ty::Vec(s, _) | Ty::Mat(s, _, _) => Some(*s),
            _ => None,
        }
    }
    pub fn is_numeric(&self) -> bool {
        matches!(self, Ty::ScalarKind(_) | Ty::Vec(..) | Ty::Mat(..))
    }
    /// Components of a scalar or vector.
    pub fn width(&self) -> u8 {
        match self {
            Ty::Vec(_, n) => *n,
            _ => 1,
        }
    }
    pub fn with_scalar(&self, s: ScalarKind) -> Ty {
        match self {
            Ty::ScalarKind(_) => Ty::ScalarKind(s),
            Ty::Vec(_, n) => Ty::Vec(s, *n),
            Ty::Mat(_, r, c) => Ty::Mat(s, *r, *c),
            other => other.clone(),
        }
    }
    /// The scalar type of a numeric type's components.
    pub fn with_scalar_only(&self) -> Ty {
        Ty::ScalarKind(self.scalar().unwrap_or(ScalarKind::Float))
    }
    pub fn is_resource(&self) -> bool {
        match self {
            Ty::Accel
            | Ty::Sampler
            | Ty::SamplerCmp
            | Ty::Texture { .. }
            | Ty::StructuredBuffer(..)
            | Ty::ByteAddress(_)
            | Ty::ConstantBuffer(_) => true,
            Ty::Array(e, _) | Ty::RtArray(e) => e.is_resource(),
            _ => false,
        }
    }
    pub fn is_aggregate(&self) -> bool {
        matches!(self, Ty::Array(..) | Ty::Struct(_))
    }
}

#[derive(Clone, Debug)]
pub struct Field {
    pub name: String,
    pub ty: Ty,
    pub pos: Pos,
    pub row_major: bool,
}

#[derive(Clone, Debug)]
pub struct StructDef {
    pub name: String,
    pub fields: Vec<Field>,
    pub pos: Pos,
}

/// How a type is laid out in memory: not at all (function/private/payload
/// variables), HLSL constant-buffer packing, or DXC's default relaxed std430
/// for structured, push-constant and shader-record buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Layout {
    None,
    CBuffer,
    Std430,
}

fn round_up(x: u32, a: u32) -> u32 {
    x.div_ceil(a.max(1)) * a.max(1)
}

/// Size and alignment of `ty` under `layout` (scalars are 32-bit).
pub fn size_align(ty: &Ty, layout: Layout, structs: &[StructDef]) -> (u32, u32) {
    match (ty, layout) {
        (Ty::ScalarKind(s), _) => (s.size(), s.size()),
        (Ty::Vec(s, n), Layout::CBuffer) => (s.size() * *n as u32, s.size()),
        (Ty::Vec(s, n), _) => (s.size() * *n as u32, s.size() * if *n == 2 { 2 } else { 4 }),
        (Ty::Mat(..), _) => {
            let (count, stride, n) = matrix_layout(ty, false, layout);
            matrix_size_align(count, stride, n, ty, layout)
        }
        (Ty::Array(e, len), _) => {
            let stride = array_stride(e, layout, structs);
            let (esize, ealign) = size_align(e, layout, structs);
            if layout == Layout::CBuffer {
                // HLSL packing: the last element is not padded to a row.
                (stride * len.saturating_sub(1) + esize, 16)
            } else {
                (stride * len, ealign)
            }
        }
        (Ty::Struct(k), _) => {
            let offsets = struct_offsets(*k, layout, structs);
            let def = &structs[*k as usize];
            let mut end = 0;
            // A struct of 16-bit members is 2-aligned (DXC with 16-bit types).
            let mut align = if def.fields.is_empty() { 4 } else { 1 };
            for (f, off) in def.fields.iter().zip(&offsets) {
                let (s, a) = size_align(&f.ty, layout, structs);
                end = off + s;
                align = align.max(a);
            }
            if layout == Layout::CBuffer {
                // HLSL packing: a struct starts a row and is not padded at its end.
                (end, 16)
            } else {
                (round_up(end, align), align)
            }
        }
        _ => (0, 4),
    }
}

fn matrix_size_align(count: u32, stride: u32, n: u32, ty: &Ty, layout: Layout) -> (u32, u32) {
    let e = ty.scalar().map_or(4, ScalarKind::size);
    if layout == Layout::CBuffer {
        (stride * (count - 1) + e * n, 16)
    } else {
        (stride * count, stride.min(16))
    }
}

pub fn array_stride(elem: &Ty, layout: Layout, structs: &[StructDef]) -> u32 {
    let (s, a) = size_align(elem, layout, structs);
    match layout {
        Layout::CBuffer => round_up(s, 16),
        _ => round_up(s, a),
    }
}

/// A matrix in memory: (vector count, stride, vector length). Default HLSL
/// (column-major) packing stores HLSL columns; in SPIR-V terms that is RowMajor.
pub fn matrix_layout(ty: &Ty, row_major: bool, layout: Layout) -> (u32, u32, u32) {
    let Ty::Mat(s, r, c) = ty else {
        return (1, 16, 4);
    };
    // Vectors of 1, 2, or 3-4 components, aligned like vectors.
    let e = s.size();
    let (count, n) = if row_major {
        (*r as u32, *c as u32)
    } else {
        (*c as u32, *r as u32)
    };
    let stride = match layout {
        Layout::CBuffer => 16,
        _ => {
            if n == 2 {
                2 * e
            } else if n == 1 {
                e
            } else {
                4 * e
            }
        }
    };
    (count, stride, n)
}

/// Byte offsets of a struct's fields under `layout`.
pub fn struct_offsets(k: u32, layout: Layout, structs: &[StructDef]) -> Vec<u32> {
    let def = &structs[k as usize];
    let mut off = 0u32;
    let mut out = Vec::with_capacity(def.fields.len());
    for f in &def.fields {
        let (size, align) = if let Ty::Mat(..) = f.ty {
            let (count, stride, n) = matrix_layout(&f.ty, f.row_major, layout);
            matrix_size_align(count, stride, n, &f.ty, layout)
        } else {
            size_align(&f.ty, layout, structs)
        };
        off = match (layout, &f.ty) {
            // Vectors may sit at scalar alignment unless they would cross a
            // 16-byte row (HLSL packing, and DXC's relaxed std430).
            (_, Ty::Vec(s, _)) | (Layout::CBuffer, Ty::ScalarKind(s)) => {
                let o = round_up(off, s.size());
                if o % 16 + size > 16 {
                    round_up(o, 16)
                } else {
                    o
                }
            }
            _ => round_up(off, align),
        };
        out.push(off);
        off += size;
    }
    out
}

/// `sizeof(T)` as DXC computes it: 32-bit scalars packed without padding
/// (`float3` is 12 bytes, `struct { float a; float3 b; }` 16); `None` for
/// types with no size in memory (resources, ray queries).
pub fn packed_size(ty: &Ty, structs: &[StructDef]) -> Option<u32> {
    Some(match ty {
        Ty::ScalarKind(s) => s.size(),
        Ty::Vec(s, n) => s.size() * *n as u32,
        Ty::Mat(s, r, c) => s.size() * *r as u32 * *c as u32,
        Ty::Array(e, n) => packed_size(e, structs)? * n,
        Ty::Struct(k) => {
            let mut total = 0;
            for f in &structs.get(*k as usize)?.fields {
                total += packed_size(&f.ty, structs)?;
            }
            total
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn st(fields: Vec<Ty>) -> Vec<StructDef> {
        vec![StructDef {
            name: "S".into(),
            fields: fields
                .into_iter()
                .enumerate()
                .map(|(i, ty)| Field {
                    name: format!("f{i}"),
                    ty,
                    pos: Pos::default(),
                    row_major: false,
                })
                .collect(),
            pos: Pos::default(),
        }]
    }

    #[test]
    fn cbuffer_packing() {
        let f = Ty::ScalarKind(ScalarKind::Float);
        let f3 = Ty::Vec(ScalarKind::Float, 3);
        let f2 = Ty::Vec(ScalarKind::Float, 2);
        // float3 then float shares a row; float2 after float3 starts a new row.
        let s = st(vec![f3.clone(), f.clone(), f2.clone(), f3.clone()]);
        assert_eq!(struct_offsets(0, Layout::CBuffer, &s), vec![0, 12, 16, 32]);
        // Arrays start a row, stride 16, trailing element not padded.
        let s = st(vec![
            f.clone(),
            Ty::Array(Box::new(f.clone()), 3),
            f.clone(),
        ]);
        assert_eq!(struct_offsets(0, Layout::CBuffer, &s), vec![0, 16, 52]);
        assert_eq!(
            size_align(
                &Ty::Array(Box::new(Ty::ScalarKind(ScalarKind::Uint)), 256),
                Layout::CBuffer,
                &s
            )
            .0,
            4084
        );
        // float4x4 and float3x4 (HLSL columns are 3 long, 4 of them).
        let s = st(vec![f.clone(), Ty::Mat(ScalarKind::Float, 3, 4), f.clone()]);
        assert_eq!(struct_offsets(0, Layout::CBuffer, &s), vec![0, 16, 76]);
    }

    #[test]
    fn std430_relaxed() {
        let f = Ty::ScalarKind(ScalarKind::Float);
        let f3 = Ty::Vec(ScalarKind::Float, 3);
        let s = st(vec![f.clone(), f3.clone(), f.clone()]);
        assert_eq!(struct_offsets(0, Layout::Std430, &s), vec![0, 4, 16]);
        assert_eq!(size_align(&Ty::Struct(0), Layout::Std430, &s), (32, 16));
        let s = st(vec![f3.clone(), f.clone()]);
        assert_eq!(size_align(&Ty::Struct(0), Layout::Std430, &s), (16, 16));
        assert_eq!(array_stride(&f, Layout::Std430, &s), 4);
    }
}
