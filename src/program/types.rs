//! The neutral type tree: what the analyses need to know about SPIR-V types.

use super::Id;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ArrayLen {
    Const(u64),
    /// A specialization constant (its default value when known).
    Spec(Id, Option<u64>),
}

impl ArrayLen {
    pub fn value(&self) -> Option<u64> {
        match self {
            ArrayLen::Const(n) => Some(*n),
            ArrayLen::Spec(_, v) => *v,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Type {
    Void,
    Bool,
    Int {
        width: u32,
        signed: bool,
    },
    Float {
        width: u32,
    },
    Vector {
        elem: Id,
        count: u32,
    },
    /// Column-major as SPIR-V has it: `columns` vectors of type `column`.
    Matrix {
        column: Id,
        columns: u32,
    },
    Array {
        elem: Id,
        len: ArrayLen,
    },
    RuntimeArray {
        elem: Id,
    },
    Struct {
        members: Vec<Id>,
    },
    Pointer {
        storage: spirv::StorageClass,
        pointee: Id,
    },
    AccelerationStructure,
    RayQuery,
    Image,
    Sampler,
    SampledImage,
    Function {
        ret: Id,
        params: Vec<Id>,
    },
    /// Any type rtlint has no use for, by opcode name.
    Other(&'static str),
}

impl Type {
    pub fn is_scalar(&self) -> bool {
        matches!(self, Type::Bool | Type::Int { .. } | Type::Float { .. })
    }
}
