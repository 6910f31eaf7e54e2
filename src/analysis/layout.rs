//! Payload layouts: how big a struct is under the rules that matter for ray
//! tracing, and the member order that packs best.
//!
//! Three rules:
//! - **scalar**: how Vulkan sizes payload and attribute blocks for
//!   `maxPipelineRayPayloadSize` — every scalar aligned to the largest scalar
//!   alignment in the block — which is also DXC's payload size
//!   (`{float3 color; uint2 pos;}` = 20 bytes);
//! - **HLSL 16-byte packing** (the cbuffer rule): no scalar or vector crosses a
//!   16-byte row, structs, arrays, array elements and matrix vectors start a new
//!   row, and the trailing element is not padded (`uint A[256]` = 4084 bytes);
//! - **WGSL**: WGSL's own alignment and size rules, for WGSL sources.

use crate::program::{Id, Program, Type};

/// A type flattened to what layout needs; built once from the Program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Shape {
    /// A scalar of `bytes` bytes (bool counts as 4, as in HLSL and Vulkan).
    Scalar {
        bytes: u64,
    },
    Vector {
        scalar: u64,
        count: u64,
    },
    /// `vectors` vectors of `count` scalars each (SPIR-V columns by default).
    Matrix {
        scalar: u64,
        count: u64,
        vectors: u64,
    },
    Array {
        elem: Box<Shape>,
        len: u64,
    },
    Struct {
        members: Vec<Shape>,
    },
    /// Something with no defined size (runtime array, opaque handle).
    Opaque,
}

impl Shape {
    pub fn from_type(program: &Program, ty: Id) -> Shape {
        Self::build(program, ty, 0)
    }

    fn build(program: &Program, ty: Id, depth: u32) -> Shape {
        // Depth guard: SPIR-V types are acyclic, but a malformed module may not be.
        if depth > 64 {
            return Shape::Opaque;
        }
        let scalar_bytes = |t: Option<&Type>| match t {
            Some(Type::Bool) => Some(4),
            Some(Type::Int { width, .. }) | Some(Type::Float { width }) => {
                Some(u64::from(*width / 8))
            }
            _ => None,
        };
        match program.ty(ty) {
            Some(t @ (Type::Bool | Type::Int { .. } | Type::Float { .. })) => {
                match scalar_bytes(Some(t)) {
                    Some(bytes) if bytes > 0 => Shape::Scalar { bytes },
                    _ => Shape::Opaque,
                }
            }
            Some(Type::Vector { elem, count }) => match scalar_bytes(program.ty(*elem)) {
                Some(scalar) if scalar > 0 => Shape::Vector {
                    scalar,
                    count: u64::from(*count),
                },
                _ => Shape::Opaque,
            },
            Some(Type::Matrix { column, columns }) => match program.ty(*column) {
                Some(Type::Vector { elem, count }) => match scalar_bytes(program.ty(*elem)) {
                    Some(scalar) if scalar > 0 => Shape::Matrix {
                        scalar,
                        count: u64::from(*count),
                        vectors: u64::from(*columns),
                    },
                    _ => Shape::Opaque,
                },
                _ => Shape::Opaque,
            },
            Some(Type::Array { elem, len }) => match len.value() {
                Some(n) => Shape::Array {
                    elem: Box::new(Self::build(program, *elem, depth + 1)),
                    len: n,
                },
                None => Shape::Opaque,
            },
            Some(Type::Struct { members }) => Shape::Struct {
                members: members
                    .iter()
                    .map(|m| Self::build(program, *m, depth + 1))
                    .collect(),
            },
            _ => Shape::Opaque,
        }
    }

    /// Bytes of data, without any padding.
    pub fn data_bytes(&self) -> u64 {
        match self {
            Shape::Scalar { bytes } => *bytes,
            Shape::Vector { scalar, count } => scalar * count,
            Shape::Matrix {
                scalar,
                count,
                vectors,
            } => scalar * count * vectors,
            Shape::Array { elem, len } => elem.data_bytes() * len,
            Shape::Struct { members } => members.iter().map(Shape::data_bytes).sum(),
            Shape::Opaque => 0,
        }
    }

    pub fn is_sized(&self) -> bool {
        match self {
            Shape::Opaque => false,
            Shape::Array { elem, .. } => elem.is_sized(),
            Shape::Struct { members } => members.iter().all(Shape::is_sized),
            _ => true,
        }
    }

    fn max_scalar(&self) -> u64 {
        match self {
            Shape::Scalar { bytes } => *bytes,
            Shape::Vector { scalar, .. } | Shape::Matrix { scalar, .. } => *scalar,
            Shape::Array { elem, .. } => elem.max_scalar(),
            Shape::Struct { members } => members.iter().map(Shape::max_scalar).max().unwrap_or(1),
            Shape::Opaque => 1,
        }
    }
}

fn round_up(x: u64, a: u64) -> u64 {
    if a <= 1 {
        x
    } else {
        x.div_ceil(a) * a
    }
}

// ---------------------------------------------------------------- scalar rule

/// Size under the payload rule: every scalar aligned to `align`, the block's
/// largest scalar alignment.
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

/// Member offsets and total size under the payload (scalar) rule.
pub fn scalar_layout(members: &[Shape]) -> (Vec<u64>, u64) {
    let align = members.iter().map(Shape::max_scalar).max().unwrap_or(4);
    let mut offsets = Vec::with_capacity(members.len());
    let mut at = 0;
    for m in members {
        offsets.push(at);
        at += scalar_size(m, align);
    }
    (offsets, at)
}

// ------------------------------------------------------------ HLSL 16-byte rule

const ROW: u64 = 16;

/// Size of a shape under 16-byte packing, when laid out from a row start.
pub fn packed_size(shape: &Shape) -> u64 {
    match shape {
        Shape::Scalar { bytes } => *bytes,
        Shape::Vector { scalar, count } => scalar * count,
        Shape::Matrix {
            scalar,
            count,
            vectors,
        } => {
            if *vectors == 0 {
                0
            } else {
                (vectors - 1) * ROW + scalar * count
            }
        }
        Shape::Array { elem, len } => {
            if *len == 0 {
                0
            } else {
                (len - 1) * round_up(packed_size(elem), ROW) + packed_size(elem)
            }
        }
        Shape::Struct { members } => packed_members(members).1,
        Shape::Opaque => 0,
    }
}

/// Where a member goes when the previous one ended at `at`.
pub fn packed_place(shape: &Shape, at: u64) -> u64 {
    match shape {
        Shape::Scalar { bytes } => round_up(at, *bytes),
        Shape::Vector { scalar, count } => {
            let o = round_up(at, *scalar);
            let size = scalar * count;
            if o % ROW + size > ROW {
                round_up(o, ROW)
            } else {
                o
            }
        }
        Shape::Matrix { .. } | Shape::Array { .. } | Shape::Struct { .. } => round_up(at, ROW),
        Shape::Opaque => at,
    }
}

/// Offsets and size of members laid out in the given order under 16-byte packing.
pub fn packed_members(members: &[Shape]) -> (Vec<u64>, u64) {
    let mut offsets = Vec::with_capacity(members.len());
    let mut at = 0;
    for m in members {
        let o = packed_place(m, at);
        offsets.push(o);
        at = o + packed_size(m);
    }
    (offsets, at)
}

// ------------------------------------------------------------------- WGSL rule

fn wgsl_align(shape: &Shape) -> u64 {
    match shape {
        Shape::Scalar { bytes } => *bytes,
        Shape::Vector { scalar, count } => scalar * if *count == 3 { 4 } else { *count },
        Shape::Matrix { scalar, count, .. } => scalar * if *count == 3 { 4 } else { *count },
        Shape::Array { elem, .. } => wgsl_align(elem),
        Shape::Struct { members } => members.iter().map(wgsl_align).max().unwrap_or(1),
        Shape::Opaque => 1,
    }
}

fn wgsl_size(shape: &Shape) -> u64 {
    match shape {
        Shape::Scalar { bytes } => *bytes,
        Shape::Vector { scalar, count } => scalar * count,
        Shape::Matrix { vectors, .. } => vectors * wgsl_align(shape),
        Shape::Array { elem, len } => len * round_up(wgsl_size(elem), wgsl_align(elem)),
        Shape::Struct { members } => wgsl_members(members).1,
        Shape::Opaque => 0,
    }
}

/// Offsets and size under WGSL's layout rules (struct size rounded to its alignment).
pub fn wgsl_members(members: &[Shape]) -> (Vec<u64>, u64) {
    let mut offsets = Vec::with_capacity(members.len());
    let mut at = 0;
    let mut align = 1;
    for m in members {
        let a = wgsl_align(m);
        align = align.max(a);
        let o = round_up(at, a);
        offsets.push(o);
        at = o + wgsl_size(m);
    }
    (offsets, round_up(at, align))
}

// ------------------------------------------------------------ optimal ordering

/// Members up to which the optimal order is found exactly (2^n × 16 states).
pub const EXACT_ORDER_LIMIT: usize = 16;

/// The member order with the smallest 16-byte-packed size (hence fewest rows);
/// among equally small orders, the one whose list of declared positions is
/// lexicographically smallest, so members move as little as possible.
///
/// Exact: where the next member lands depends only on the offset within the
/// current row, so the best size for the remaining members is a function of
/// (remaining set, offset mod 16) — a dynamic program over subsets. Beyond
/// [`EXACT_ORDER_LIMIT`] members, returns `None`.
pub fn optimal_order(members: &[Shape]) -> Option<Vec<usize>> {
    let n = members.len();
    if n > EXACT_ORDER_LIMIT {
        return None;
    }
    if n == 0 {
        return Some(Vec::new());
    }
    let sizes: Vec<u64> = members.iter().map(packed_size).collect();
    // Growth of the layout when member m is placed at phase p (offset mod 16).
    let step = |m: usize, phase: u64| -> (u64, u64) {
        let o = packed_place(&members[m], phase);
        let end = o + sizes[m];
        (end - phase, end % ROW)
    };
    let full = (1usize << n) - 1;
    // best[mask * 16 + phase]: smallest growth to place every member in `mask`.
    let mut best = vec![u64::MAX; (full + 1) * ROW as usize];
    best[..ROW as usize].fill(0);
    for mask in 1..=full {
        for phase in 0..ROW {
            let mut b = u64::MAX;
            let mut bits = mask;
            while bits != 0 {
                let m = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let (grow, next) = step(m, phase);
                let rest = best[(mask & !(1 << m)) * ROW as usize + next as usize];
                b = b.min(grow.saturating_add(rest));
            }
            best[mask * ROW as usize + phase as usize] = b;
        }
    }
    // Reconstruct: at each step the lowest declared position that stays optimal.
    let mut order = Vec::with_capacity(n);
    let mut mask = full;
    let mut phase = 0;
    while mask != 0 {
        let target = best[mask * ROW as usize + phase as usize];
        let m = (0..n).filter(|m| mask & (1 << m) != 0).find(|&m| {
            let (grow, next) = step(m, phase);
            grow.saturating_add(best[(mask & !(1 << m)) * ROW as usize + next as usize]) == target
        })?;
        let (_, next) = step(m, phase);
        order.push(m);
        mask &= !(1 << m);
        phase = next;
    }
    Some(order)
}

// ---------------------------------------------------------------- the report

#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    RayPayload,
    IncomingRayPayload,
    HitAttribute,
    CallableData,
    IncomingCallableData,
    ShaderRecord,
    PushConstant,
}

impl Role {
    pub fn from_storage(s: spirv::StorageClass) -> Option<Role> {
        use spirv::StorageClass as S;
        Some(match s {
            S::RayPayloadKHR => Role::RayPayload,
            S::IncomingRayPayloadKHR => Role::IncomingRayPayload,
            S::HitAttributeKHR => Role::HitAttribute,
            S::CallableDataKHR => Role::CallableData,
            S::IncomingCallableDataKHR => Role::IncomingCallableData,
            S::ShaderRecordBufferKHR => Role::ShaderRecord,
            S::PushConstant => Role::PushConstant,
            _ => return None,
        })
    }

    pub fn is_payload(&self) -> bool {
        matches!(self, Role::RayPayload | Role::IncomingRayPayload)
    }
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct MemberLayout {
    pub name: String,
    pub ty: String,
    /// Bytes of data (no padding).
    pub size: u64,
    pub scalar_offset: u64,
    pub hlsl_packed_offset: u64,
    /// 16-byte row the member starts in under packing.
    pub row: u64,
    /// Crosses a 16-byte row where the declared order puts it (scalar
    /// placement), so 16-byte packing must push it to the next row.
    pub straddles: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wgsl_offset: Option<u64>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct TypeLayout {
    /// The struct type (or, for a non-struct payload, its variable).
    #[serde(skip)]
    pub id: Id,
    #[serde(skip)]
    pub is_struct: bool,
    pub name: String,
    pub roles: Vec<Role>,
    /// The variables declared with this type.
    pub variables: Vec<String>,
    #[serde(skip)]
    pub variable_ids: Vec<Id>,
    pub scalar_size: u64,
    pub hlsl_packed_size: u64,
    pub hlsl_rows: u64,
    pub hlsl_padding: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wgsl_size: Option<u64>,
    pub members: Vec<MemberLayout>,
    /// Member names in the optimal order; `None` past the exact limit.
    pub optimal_order: Option<Vec<String>>,
    #[serde(skip)]
    pub optimal_indices: Option<Vec<usize>>,
    pub optimal_hlsl_packed_size: Option<u64>,
    pub optimal_hlsl_rows: Option<u64>,
}

/// Lays out one struct (or a lone non-struct value named `var_name`).
pub fn layout_type(program: &Program, ty: Id, var_name: &str) -> Option<TypeLayout> {
    let (is_struct, members, names, member_types): (bool, Vec<Shape>, Vec<String>, Vec<Id>) =
        match program.ty(ty)? {
            Type::Struct { members } => (
                true,
                members
                    .iter()
                    .map(|m| Shape::from_type(program, *m))
                    .collect(),
                (0..members.len() as u32)
                    .map(|k| program.member_name(ty, k))
                    .collect(),
                members.clone(),
            ),
            _ => (
                false,
                vec![Shape::from_type(program, ty)],
                vec![var_name.to_string()],
                vec![ty],
            ),
        };
    if !members.iter().all(Shape::is_sized) {
        return None;
    }
    let (scalar_offsets, scalar_size) = scalar_layout(&members);
    let (packed_offsets, packed) = packed_members(&members);
    let wgsl = (program.language == crate::shader::Language::Wgsl).then(|| wgsl_members(&members));
    let member_layouts: Vec<MemberLayout> = members
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let size = m.data_bytes();
            let so = scalar_offsets[k];
            let small = matches!(m, Shape::Scalar { .. } | Shape::Vector { .. });
            MemberLayout {
                name: names[k].clone(),
                ty: program.type_name(member_types[k]),
                size,
                scalar_offset: so,
                hlsl_packed_offset: packed_offsets[k],
                row: packed_offsets[k] / ROW,
                straddles: small && size > 0 && so / ROW != (so + size - 1) / ROW,
                wgsl_offset: wgsl.as_ref().map(|(o, _)| o[k]),
            }
        })
        .collect();
    let order = if is_struct {
        optimal_order(&members)
    } else {
        Some(vec![0])
    };
    let optimal_size = order.as_ref().map(|o| {
        let reordered: Vec<Shape> = o.iter().map(|&k| members[k].clone()).collect();
        packed_members(&reordered).1
    });
    let name = if is_struct {
        program.display_name(ty)
    } else {
        var_name.to_string()
    };
    Some(TypeLayout {
        id: ty,
        is_struct,
        name,
        roles: Vec::new(),
        variables: Vec::new(),
        variable_ids: Vec::new(),
        scalar_size,
        hlsl_packed_size: packed,
        hlsl_rows: packed.div_ceil(ROW),
        hlsl_padding: packed - members.iter().map(Shape::data_bytes).sum::<u64>(),
        wgsl_size: wgsl.map(|(_, s)| s),
        optimal_order: order
            .as_ref()
            .map(|o| o.iter().map(|&k| names[k].clone()).collect()),
        optimal_indices: order,
        optimal_hlsl_packed_size: optimal_size,
        optimal_hlsl_rows: optimal_size.map(|s| s.div_ceil(ROW)),
        members: member_layouts,
    })
}

/// Every type used by a ray-tracing interface variable (payloads, hit
/// attributes, callable data, shader records, push constants), each once,
/// with all its roles and variables, in declaration order.
pub fn interface_layouts(program: &Program) -> Vec<TypeLayout> {
    let mut out: Vec<TypeLayout> = Vec::new();
    for g in &program.globals {
        let Some(role) = Role::from_storage(g.storage) else {
            continue;
        };
        let var_name = g.name.clone().unwrap_or_else(|| format!("%{}", g.id));
        let is_struct = matches!(program.ty(g.ty), Some(Type::Struct { .. }));
        // Structs are shared between variables; a lone value is its own entry.
        let existing = out
            .iter()
            .position(|t| t.is_struct && is_struct && t.id == g.ty);
        let idx = match existing {
            Some(i) => i,
            None => match layout_type(program, g.ty, &var_name) {
                Some(t) => {
                    out.push(t);
                    out.len() - 1
                }
                None => continue,
            },
        };
        let t = &mut out[idx];
        if !t.roles.contains(&role) {
            t.roles.push(role);
        }
        t.variables.push(var_name);
        t.variable_ids.push(g.id);
    }
    out
}

/// The layouts of one file, as `rtlint layout` prints them.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FileLayouts {
    pub path: String,
    pub language: crate::shader::Language,
    pub types: Vec<TypeLayout>,
}

impl FileLayouts {
    pub fn new(program: &Program) -> Self {
        FileLayouts {
            path: program.path.display().to_string(),
            language: program.language,
            types: interface_layouts(program),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const F: Shape = Shape::Scalar { bytes: 4 };
    const H: Shape = Shape::Scalar { bytes: 2 };
    fn v(n: u64) -> Shape {
        Shape::Vector {
            scalar: 4,
            count: n,
        }
    }

    #[test]
    fn color_uv_distance_table() {
        // {float3 color; float2 uv; float distance;}
        let m = [v(3), v(2), F];
        assert_eq!(scalar_layout(&m), (vec![0, 12, 20], 24));
        assert_eq!(packed_members(&m), (vec![0, 16, 24], 28));
        assert_eq!(optimal_order(&m), Some(vec![0, 2, 1]));
        let best: Vec<Shape> = [0, 2, 1].iter().map(|&k| m[k].clone()).collect();
        assert_eq!(packed_members(&best), (vec![0, 12, 16], 24));
    }

    #[test]
    fn dxc_payload_size_example() {
        // DXC's own test: {float3 color; uint2 pos;} is 20 bytes.
        assert_eq!(scalar_layout(&[v(3), v(2)]).1, 20);
    }

    #[test]
    fn arrays_start_rows_and_last_element_is_not_padded() {
        let a = Shape::Array {
            elem: Box::new(v(2)),
            len: 3,
        };
        assert_eq!(packed_size(&a), 40);
        let u = Shape::Array {
            elem: Box::new(F),
            len: 256,
        };
        assert_eq!(packed_size(&u), 4084);
        // A float after a float array packs into the array's last row.
        assert_eq!(packed_members(&[u.clone(), F]), (vec![0, 4084], 4088));
        // A scalar before an array: the array starts the next row.
        assert_eq!(packed_members(&[F, a]).0, vec![0, 16]);
        assert_eq!(scalar_layout(&[F, u]).1, 4 + 1024);
    }

    #[test]
    fn nested_structs_start_a_row() {
        let inner = Shape::Struct {
            members: vec![v(3), F, F],
        };
        // inner: float3 at 0, float at 12, float at 16 → 20 bytes.
        assert_eq!(packed_size(&inner), 20);
        let outer = [F, inner.clone(), F];
        // F at 0; struct at 16 (20 bytes → ends 36); F at 36.
        assert_eq!(packed_members(&outer), (vec![0, 16, 36], 40));
        // Best: struct first, then the two floats pack into its last row.
        assert_eq!(optimal_order(&outer), Some(vec![1, 0, 2]));
        let best: Vec<Shape> = [1, 0, 2].iter().map(|&k| outer[k].clone()).collect();
        assert_eq!(packed_members(&best).1, 28);
    }

    #[test]
    fn matrices() {
        // float4x4: four rows of four.
        let m44 = Shape::Matrix {
            scalar: 4,
            count: 4,
            vectors: 4,
        };
        assert_eq!(packed_size(&m44), 64);
        // GLSL mat4x3 = 4 columns of vec3: 3 rows × 16 + 12.
        let m43 = Shape::Matrix {
            scalar: 4,
            count: 3,
            vectors: 4,
        };
        assert_eq!(packed_size(&m43), 60);
        assert_eq!(scalar_layout(std::slice::from_ref(&m43)).1, 48);
        // A float after it fills the last row.
        assert_eq!(packed_members(&[m43, F]).1, 64);
        // A matrix starts a new row.
        assert_eq!(packed_members(&[F, m44]).0, vec![0, 16]);
    }

    #[test]
    fn bool_is_four_bytes() {
        let b = Shape::Scalar { bytes: 4 };
        assert_eq!(packed_members(&[b.clone(), v(3)]), (vec![0, 4], 16));
        assert_eq!(scalar_layout(&[b, v(3)]).1, 16);
    }

    #[test]
    fn sixteen_bit_types() {
        let h3 = Shape::Vector {
            scalar: 2,
            count: 3,
        };
        // half3 at 0 (6 bytes), half at 6, float at 8 → 12.
        assert_eq!(packed_members(&[h3.clone(), H, F]), (vec![0, 6, 8], 12));
        // Payload rule: each scalar aligned to the block's largest (4).
        assert_eq!(scalar_layout(&[h3.clone(), H, F]).1, 12 + 4 + 4);
        // Only 16-bit: aligned to 2.
        assert_eq!(scalar_layout(&[h3, H]).1, 8);
        // A half4 at offset 10 would cross the row: moved to 16.
        let h4 = Shape::Vector {
            scalar: 2,
            count: 4,
        };
        assert_eq!(packed_members(&[v(2), H, h4]).0, vec![0, 8, 16]);
    }

    #[test]
    fn wgsl_rules() {
        // struct {f32, vec3<f32>} is 32 bytes in WGSL (offsets 0/16), 16 scalar.
        assert_eq!(wgsl_members(&[F, v(3)]), (vec![0, 16], 32));
        assert_eq!(scalar_layout(&[F, v(3)]).1, 16);
        assert_eq!(wgsl_members(&[v(3), F]), (vec![0, 12], 16));
        let a = Shape::Array {
            elem: Box::new(v(3)),
            len: 2,
        };
        assert_eq!(wgsl_members(&[a]).1, 32);
    }

    #[test]
    fn optimal_order_prefers_declared_order_on_ties() {
        // Already optimal: stays as declared.
        assert_eq!(optimal_order(&[v(4), v(3), F]), Some(vec![0, 1, 2]));
        assert_eq!(optimal_order(&[F, F, F]), Some(vec![0, 1, 2]));
        // float, float3, float, float3: 2 rows at best (float3+float twice).
        let m = [F, v(3), F, v(3)];
        let o = optimal_order(&m).unwrap();
        let r: Vec<Shape> = o.iter().map(|&k| m[k].clone()).collect();
        assert_eq!(packed_members(&r).1, 32);
        assert_eq!(o, vec![0, 1, 2, 3]);
        // float, float4, float: the float4 moves first (36 → 24 bytes).
        assert_eq!(optimal_order(&[F, v(4), F]), Some(vec![1, 0, 2]));
    }

    /// Brute force over all permutations agrees with the dynamic program,
    /// including its tie-break, on every small mix of member shapes.
    #[test]
    fn optimal_order_matches_brute_force() {
        let pool = [
            F,
            H,
            v(2),
            v(3),
            v(4),
            Shape::Vector {
                scalar: 2,
                count: 3,
            },
            Shape::Array {
                elem: Box::new(F),
                len: 2,
            },
            Shape::Struct {
                members: vec![v(3)],
            },
        ];
        let mut seed = 0x1234_5678u64;
        for _ in 0..300 {
            let n = 1 + (next(&mut seed) % 6) as usize;
            let m: Vec<Shape> = (0..n)
                .map(|_| pool[(next(&mut seed) % pool.len() as u64) as usize].clone())
                .collect();
            let mut best: Option<(u64, Vec<usize>)> = None;
            permute(&mut (0..n).collect::<Vec<_>>(), 0, &mut |p| {
                let r: Vec<Shape> = p.iter().map(|&k| m[k].clone()).collect();
                let s = packed_members(&r).1;
                let better = match &best {
                    None => true,
                    Some((bs, bp)) => s < *bs || (s == *bs && p < bp.as_slice()),
                };
                if better {
                    best = Some((s, p.to_vec()));
                }
            });
            assert_eq!(optimal_order(&m), best.map(|b| b.1), "members {m:?}");
        }
    }

    fn next(s: &mut u64) -> u64 {
        *s ^= *s << 13;
        *s ^= *s >> 7;
        *s ^= *s << 17;
        *s
    }

    fn permute(p: &mut Vec<usize>, k: usize, f: &mut dyn FnMut(&[usize])) {
        if k == p.len() {
            f(p);
            return;
        }
        for i in k..p.len() {
            p.swap(k, i);
            permute(p, k + 1, f);
            p.swap(k, i);
        }
    }
}
