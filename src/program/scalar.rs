//! Sizes of values as a driver keeps them: scalar layout, each member at its
//! own largest scalar's alignment, and descriptor handles as 8 bytes. Used
//! for live values and the stack model. Payload sizes as rules report them
//! come from `layout.rs`, whose rule aligns every scalar to the block's
//! largest (Vulkan's payload rule); the two agree unless a struct mixes
//! scalar widths.

use crate::program::{Id, Program, Type};

/// Bytes a value of type `ty` occupies under the scalar layout. `None` for
/// types without a size (runtime arrays, unknown array lengths, ray queries,
/// logical pointers).
pub fn scalar_size(program: &Program, ty: Id) -> Option<u64> {
    size_align(program, ty, 0).map(|(s, _)| s)
}

/// The scalar alignment of a type (its largest scalar).
pub fn scalar_align(program: &Program, ty: Id) -> Option<u64> {
    size_align(program, ty, 0).map(|(_, a)| a)
}

fn size_align(program: &Program, ty: Id, depth: u32) -> Option<(u64, u64)> {
    // Malformed modules could nest types without end; real ones stay shallow.
    if depth > 64 {
        return None;
    }
    let d = depth + 1;
    match program.ty(ty)? {
        // Booleans have no memory layout; drivers spill them as 32-bit values.
        Type::Bool => Some((4, 4)),
        Type::Int { width, .. } | Type::Float { width } => {
            let b = u64::from((*width).max(8) / 8);
            Some((b, b))
        }
        Type::Vector { elem, count } => {
            let (s, a) = size_align(program, *elem, d)?;
            Some((s * u64::from(*count), a))
        }
        Type::Matrix { column, columns } => {
            let (s, a) = size_align(program, *column, d)?;
            Some((s * u64::from(*columns), a))
        }
        Type::Array { elem, len } => {
            let (s, a) = size_align(program, *elem, d)?;
            Some((s.checked_mul(len.value()?)?, a))
        }
        Type::Struct { members } => {
            let mut offset = 0u64;
            let mut align = 1u64;
            for m in members {
                let (s, a) = size_align(program, *m, d)?;
                offset = offset.div_ceil(a) * a + s;
                align = align.max(a);
            }
            Some((offset.div_ceil(align) * align, align))
        }
        Type::Pointer { storage, .. } if *storage == spirv::StorageClass::PhysicalStorageBuffer => {
            Some((8, 8))
        }
        // Descriptor handles are 64-bit addresses or indices once compiled.
        Type::AccelerationStructure | Type::Image | Type::Sampler | Type::SampledImage => {
            Some((8, 8))
        }
        _ => None,
    }
}
