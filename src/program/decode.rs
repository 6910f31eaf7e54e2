//! A direct decoder for the instructions compilers commonly write, giving
//! the same `rspirv::dr::Instruction`s as rspirv's parser: rspirv searches
//! its grammar table linearly twice per instruction and allocates a vector
//! per operand, which made reading a module cost more than naga's own parse
//! of the WGSL it came from. Anything this decoder does not know exactly
//! (an operand kind, a decoration or mode with parameters it does not
//! list, a malformed instruction) makes it give up, and the caller parses
//! the whole module with rspirv, errors included.

use rspirv::dr::{Instruction, Operand};
use rspirv::grammar::{self, OperandKind as K, OperandQuantifier as Q};
use spirv::{Decoration, ExecutionMode, Op};
use std::sync::OnceLock;

type Grammar = &'static grammar::Instruction<'static>;

/// The grammar entry of each opcode: the first in rspirv's table, the one
/// its parser finds.
fn grammar_of(opcode: u32) -> Option<Grammar> {
    static TABLE: OnceLock<Vec<Option<Grammar>>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let max = grammar::INSTRUCTION_TABLE
            .iter()
            .map(|g| g.opcode as usize)
            .max()
            .unwrap_or(0);
        let mut t: Vec<Option<Grammar>> = vec![None; max + 1];
        for g in grammar::INSTRUCTION_TABLE.iter() {
            let slot = &mut t[g.opcode as usize];
            if slot.is_none() {
                *slot = Some(g);
            }
        }
        t
    });
    table.get(opcode as usize).copied().flatten()
}

/// Width class of a numeric type, as rspirv's type tracker sees it.
#[derive(Clone, Copy, PartialEq)]
enum Width {
    Unknown,
    W32,
    W64,
    /// A width rspirv refuses: the module goes to rspirv for its error.
    Unsupported,
}

struct Words<'a> {
    w: &'a [u32],
    at: usize,
}

impl Words<'_> {
    fn left(&self) -> bool {
        self.at < self.w.len()
    }
    fn word(&mut self) -> Option<u32> {
        let v = *self.w.get(self.at)?;
        self.at += 1;
        Some(v)
    }
    fn string(&mut self) -> Option<String> {
        // The terminating word found first, so the bytes are copied once
        // into a buffer of their size (an embedded source is tens of KB).
        let rest = &self.w[self.at..];
        let k = rest.iter().position(|&w| has_zero_byte(w))?;
        let last = rest[k].to_le_bytes();
        let z = last.iter().position(|&c| c == 0)?;
        let mut bytes = Vec::with_capacity(4 * k + z);
        for w in &rest[..k] {
            bytes.extend_from_slice(&w.to_le_bytes());
        }
        bytes.extend_from_slice(&last[..z]);
        self.at += k + 1;
        String::from_utf8(bytes).ok()
    }
}

/// Whether one of the word's four bytes is 0.
fn has_zero_byte(w: u32) -> bool {
    w.wrapping_sub(0x0101_0101) & !w & 0x8080_8080 != 0
}

/// Whether the `spirv` crate knows `opcode` (`Op::from_u32`, a long chain
/// of range tests that cost as much as decoding the instruction),
/// remembered per opcode for the process.
pub fn known_opcode(opcode: u16) -> bool {
    use std::sync::atomic::{AtomicU8, Ordering};
    // 0: not asked yet, 1: known, 2: unknown.
    static KNOWN: [AtomicU8; 1 << 16] = [const { AtomicU8::new(0) }; 1 << 16];
    let slot = &KNOWN[opcode as usize];
    match slot.load(Ordering::Relaxed) {
        1 => true,
        2 => false,
        _ => {
            let known = Op::from_u32(u32::from(opcode)).is_some();
            slot.store(if known { 1 } else { 2 }, Ordering::Relaxed);
            known
        }
    }
}

/// Every instruction of the module (`offsets` from the caller's own pass,
/// which checked word counts and opcodes), or `None` where rspirv must
/// decide.
pub fn decode(words: &[u32], offsets: &[u32]) -> Option<Vec<Instruction>> {
    // rspirv's type tracker: each id's numeric width, by id. A bound far
    // beyond the module's size is left to rspirv rather than allocated.
    let bound = *words.get(3)? as usize;
    if bound > 4 * words.len() + 64 {
        return None;
    }
    let mut widths = vec![Width::Unknown; bound];
    let mut out = Vec::with_capacity(offsets.len());
    for &at in offsets {
        let at = at as usize;
        let first = words[at];
        let count = (first >> 16) as usize;
        let g = grammar_of(first & 0xffff)?;
        let mut w = Words {
            w: words.get(at + 1..at + count)?,
            at: 0,
        };
        let inst = instruction(g, &mut w, &widths)?;
        if w.left() {
            return None;
        }
        track(&inst, &mut widths)?;
        out.push(inst);
    }
    Some(out)
}

/// rspirv's `TypeTracker::track`; `None` for a result id beyond the bound,
/// which rspirv would track and the caller rejects.
fn track(inst: &Instruction, widths: &mut [Width]) -> Option<()> {
    let Some(r) = inst.result_id else {
        return Some(());
    };
    widths.get(r as usize)?;
    let width = if inst.class.opcode.is_type() {
        match (inst.class.opcode, inst.operands.first()) {
            (Op::TypeInt, Some(Operand::LiteralBit32(bits))) => match bits {
                8 | 16 | 32 => Width::W32,
                64 => Width::W64,
                _ => Width::Unsupported,
            },
            (Op::TypeFloat, Some(Operand::LiteralBit32(bits))) => match bits {
                16 | 32 => Width::W32,
                64 => Width::W64,
                _ => Width::Unsupported,
            },
            _ => return Some(()),
        }
    } else {
        match inst.result_type.map(|t| width_of(widths, t)) {
            Some(w) if w != Width::Unknown => w,
            _ => return Some(()),
        }
    };
    widths[r as usize] = width;
    Some(())
}

fn literal(w: &mut Words, width: Width) -> Option<Operand> {
    match width {
        Width::Unknown | Width::W32 => Some(Operand::LiteralBit32(w.word()?)),
        Width::W64 => {
            let low = u64::from(w.word()?);
            let high = u64::from(w.word()?);
            Some(Operand::LiteralBit64((high << 32) | low))
        }
        Width::Unsupported => None,
    }
}

fn width_of(widths: &[Width], id: u32) -> Width {
    widths.get(id as usize).copied().unwrap_or(Width::Unknown)
}

/// rspirv's `Parser::parse_operands`.
fn instruction(g: Grammar, w: &mut Words, widths: &[Width]) -> Option<Instruction> {
    let mut result_type = None;
    let mut result_id = None;
    // At most one operand per word after the result type and id, and
    // rarely more than 16 (a string of many words, such as the embedded
    // source, is one operand).
    let results = g
        .operands
        .iter()
        .take(2)
        .filter(|o| matches!(o.kind, K::IdResultType | K::IdResult))
        .count();
    let mut operands = Vec::with_capacity(w.w.len().saturating_sub(results).min(16));
    let mut k = 0;
    while k < g.operands.len() {
        let lop = &g.operands[k];
        if !w.left() {
            match lop.quantifier {
                Q::One => return None,
                Q::ZeroOrOne | Q::ZeroOrMore => break,
            }
        }
        match lop.kind {
            K::IdResultType => result_type = Some(w.word()?),
            K::IdResult => result_id = Some(w.word()?),
            K::LiteralContextDependentNumber => {
                if !matches!(g.opcode, Op::Constant | Op::SpecConstant) {
                    return None;
                }
                operands.push(literal(w, width_of(widths, result_type?))?);
            }
            K::PairLiteralIntegerIdRef => {
                let Some(Operand::IdRef(selector)) = operands.first() else {
                    return None;
                };
                if g.opcode != Op::Switch {
                    return None;
                }
                let width = width_of(widths, *selector);
                operands.push(literal(w, width)?);
                operands.push(Operand::IdRef(w.word()?));
            }
            kind => operand(kind, w, &mut operands)?,
        }
        match lop.quantifier {
            Q::One | Q::ZeroOrOne => k += 1,
            Q::ZeroOrMore => {}
        }
    }
    Some(Instruction {
        class: g,
        result_type,
        result_id,
        operands,
    })
}

/// rspirv's `Parser::parse_operand` for the kinds compilers commonly write.
fn operand(kind: K, w: &mut Words, out: &mut Vec<Operand>) -> Option<()> {
    let o = match kind {
        K::IdRef => Operand::IdRef(w.word()?),
        K::IdScope => Operand::IdScope(w.word()?),
        K::IdMemorySemantics => Operand::IdMemorySemantics(w.word()?),
        K::LiteralInteger | K::LiteralFloat => Operand::LiteralBit32(w.word()?),
        K::LiteralString => Operand::LiteralString(w.string()?),
        K::LiteralExtInstInteger => Operand::LiteralExtInstInteger(w.word()?),
        K::PairIdRefLiteralInteger => {
            out.push(Operand::IdRef(w.word()?));
            Operand::LiteralBit32(w.word()?)
        }
        K::PairIdRefIdRef => {
            out.push(Operand::IdRef(w.word()?));
            Operand::IdRef(w.word()?)
        }
        K::StorageClass => Operand::StorageClass(spirv::StorageClass::from_u32(w.word()?)?),
        K::SourceLanguage => Operand::SourceLanguage(spirv::SourceLanguage::from_u32(w.word()?)?),
        K::ExecutionModel => Operand::ExecutionModel(spirv::ExecutionModel::from_u32(w.word()?)?),
        K::AddressingModel => {
            Operand::AddressingModel(spirv::AddressingModel::from_u32(w.word()?)?)
        }
        K::MemoryModel => Operand::MemoryModel(spirv::MemoryModel::from_u32(w.word()?)?),
        K::Capability => Operand::Capability(spirv::Capability::from_u32(w.word()?)?),
        K::Dim => Operand::Dim(spirv::Dim::from_u32(w.word()?)?),
        K::ImageFormat => Operand::ImageFormat(spirv::ImageFormat::from_u32(w.word()?)?),
        K::AccessQualifier => {
            Operand::AccessQualifier(spirv::AccessQualifier::from_u32(w.word()?)?)
        }
        K::BuiltIn => Operand::BuiltIn(spirv::BuiltIn::from_u32(w.word()?)?),
        K::Scope => Operand::Scope(spirv::Scope::from_u32(w.word()?)?),
        K::GroupOperation => Operand::GroupOperation(spirv::GroupOperation::from_u32(w.word()?)?),
        K::FunctionControl => {
            Operand::FunctionControl(spirv::FunctionControl::from_bits(w.word()?)?)
        }
        K::SelectionControl => {
            Operand::SelectionControl(spirv::SelectionControl::from_bits(w.word()?)?)
        }
        K::MemorySemantics => {
            Operand::MemorySemantics(spirv::MemorySemantics::from_bits(w.word()?)?)
        }
        K::LoopControl => {
            let v = spirv::LoopControl::from_bits(w.word()?)?;
            // Every parameter-carrying bit is left to rspirv.
            let plain = spirv::LoopControl::UNROLL
                | spirv::LoopControl::DONT_UNROLL
                | spirv::LoopControl::DEPENDENCY_INFINITE;
            if !plain.contains(v) {
                return None;
            }
            Operand::LoopControl(v)
        }
        K::MemoryAccess => {
            let v = spirv::MemoryAccess::from_bits(w.word()?)?;
            let plain = spirv::MemoryAccess::VOLATILE
                | spirv::MemoryAccess::ALIGNED
                | spirv::MemoryAccess::NONTEMPORAL;
            if !plain.contains(v) {
                return None;
            }
            out.push(Operand::MemoryAccess(v));
            if v.contains(spirv::MemoryAccess::ALIGNED) {
                out.push(Operand::LiteralBit32(w.word()?));
            }
            return Some(());
        }
        K::ImageOperands => {
            let v = spirv::ImageOperands::from_bits(w.word()?)?;
            out.push(Operand::ImageOperands(v));
            // Each of these bits takes one id, in this order (GRAD two).
            use spirv::ImageOperands as I;
            let ids = [
                (I::BIAS, 1),
                (I::LOD, 1),
                (I::GRAD, 2),
                (I::CONST_OFFSET, 1),
                (I::OFFSET, 1),
                (I::CONST_OFFSETS, 1),
                (I::SAMPLE, 1),
                (I::MIN_LOD, 1),
            ];
            let known = ids.iter().fold(I::NONE, |a, (b, _)| a | *b)
                | I::NON_PRIVATE_TEXEL
                | I::VOLATILE_TEXEL
                | I::SIGN_EXTEND
                | I::ZERO_EXTEND
                | I::NONTEMPORAL;
            if !known.contains(v) {
                return None;
            }
            for (bit, n) in ids {
                if v.contains(bit) {
                    for _ in 0..n {
                        out.push(Operand::IdRef(w.word()?));
                    }
                }
            }
            return Some(());
        }
        K::Decoration => {
            let d = Decoration::from_u32(w.word()?)?;
            out.push(Operand::Decoration(d));
            match decoration_params(d)? {
                Params::None => {}
                Params::Literal => out.push(Operand::LiteralBit32(w.word()?)),
                Params::BuiltIn => out.push(Operand::BuiltIn(spirv::BuiltIn::from_u32(w.word()?)?)),
            }
            return Some(());
        }
        K::ExecutionMode => {
            let m = ExecutionMode::from_u32(w.word()?)?;
            out.push(Operand::ExecutionMode(m));
            match m {
                ExecutionMode::LocalSize | ExecutionMode::LocalSizeHint => {
                    for _ in 0..3 {
                        out.push(Operand::LiteralBit32(w.word()?));
                    }
                }
                ExecutionMode::OriginUpperLeft
                | ExecutionMode::OriginLowerLeft
                | ExecutionMode::EarlyFragmentTests
                | ExecutionMode::DepthReplacing
                | ExecutionMode::DepthGreater
                | ExecutionMode::DepthLess
                | ExecutionMode::DepthUnchanged => {}
                _ => return None,
            }
            return Some(());
        }
        _ => return None,
    };
    out.push(o);
    Some(())
}

enum Params {
    None,
    Literal,
    BuiltIn,
}

/// The parameters of the decorations compilers commonly write (rspirv's
/// `parse_decoration_arguments`); `None` for any other.
fn decoration_params(d: Decoration) -> Option<Params> {
    use Decoration as D;
    Some(match d {
        D::RelaxedPrecision
        | D::Block
        | D::BufferBlock
        | D::RowMajor
        | D::ColMajor
        | D::GLSLShared
        | D::GLSLPacked
        | D::NoPerspective
        | D::Flat
        | D::Patch
        | D::Centroid
        | D::Sample
        | D::Invariant
        | D::Restrict
        | D::Aliased
        | D::Volatile
        | D::Coherent
        | D::NonWritable
        | D::NonReadable
        | D::NoContraction
        | D::NonUniform
        | D::RestrictPointer
        | D::AliasedPointer
        | D::PerPrimitiveEXT
        | D::PerVertexKHR => Params::None,
        D::SpecId
        | D::ArrayStride
        | D::MatrixStride
        | D::Stream
        | D::Location
        | D::Component
        | D::Index
        | D::Binding
        | D::DescriptorSet
        | D::Offset
        | D::XfbBuffer
        | D::XfbStride
        | D::InputAttachmentIndex
        | D::Alignment
        | D::MaxByteOffset => Params::Literal,
        D::BuiltIn => Params::BuiltIn,
        _ => return None,
    })
}

/// The decoder against rspirv's parser on any words (unit tests and the
/// fuzz target `spirv_decode`): where the decoder gives instructions,
/// rspirv must parse the module and give the same ones. `Err` says where
/// they differ.
pub fn check_against_rspirv(words: &[u32]) -> Result<(), String> {
    // What `build::parse` checks before it asks the decoder.
    if words.len() < 5 || words[0] != super::binary::MAGIC {
        return Ok(());
    }
    let Some(offsets) = checked_offsets(words) else {
        return Ok(());
    };
    if offsets
        .iter()
        .any(|&at| Op::from_u32(words[at as usize] & 0xffff).is_none())
    {
        return Ok(());
    }
    let Some(got) = decode(words, &offsets) else {
        return Ok(());
    };
    match rspirv_insts(words) {
        None => Err("decoded a module rspirv refuses".into()),
        Some(expected) => match expected.iter().zip(&got).position(|(a, b)| a != b) {
            Some(k) => Err(format!(
                "instruction {k}: rspirv {:?}, decoded {:?}",
                expected[k], got[k]
            )),
            None if expected.len() != got.len() => Err(format!(
                "rspirv {} instructions, decoded {}",
                expected.len(),
                got.len()
            )),
            None => Ok(()),
        },
    }
}

/// Offsets as `build::parse` checks them first: `None` where a word
/// count is 0 or runs past the end.
pub fn checked_offsets(words: &[u32]) -> Option<Vec<u32>> {
    let mut out = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        if count == 0 || i + count > words.len() {
            return None;
        }
        out.push(i as u32);
        i += count;
    }
    Some(out)
}

/// Every instruction as rspirv's parser reads them (`None`: it refuses).
fn rspirv_insts(words: &[u32]) -> Option<Vec<Instruction>> {
    struct All(Vec<Instruction>);
    impl rspirv::binary::Consumer for All {
        fn initialize(&mut self) -> rspirv::binary::ParseAction {
            rspirv::binary::ParseAction::Continue
        }
        fn finalize(&mut self) -> rspirv::binary::ParseAction {
            rspirv::binary::ParseAction::Continue
        }
        fn consume_header(&mut self, _: rspirv::dr::ModuleHeader) -> rspirv::binary::ParseAction {
            rspirv::binary::ParseAction::Continue
        }
        fn consume_instruction(&mut self, i: Instruction) -> rspirv::binary::ParseAction {
            self.0.push(i);
            rspirv::binary::ParseAction::Continue
        }
    }
    let mut all = All(Vec::new());
    rspirv::binary::parse_words(words, &mut all).ok()?;
    Some(all.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    fn files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                files(&p, out);
            } else {
                out.push(p);
            }
        }
    }

    fn offsets(words: &[u32]) -> Vec<u32> {
        let mut out = Vec::new();
        let mut i = 5;
        while i < words.len() {
            out.push(i as u32);
            i += (words[i] >> 16).max(1) as usize;
        }
        out
    }

    /// The per-opcode table answers as `Op::from_u32` does, asked twice
    /// (the second answer comes from the table).
    #[test]
    fn known_opcode_is_from_u32() {
        for _ in 0..2 {
            for w in 0..=u16::MAX {
                assert_eq!(known_opcode(w), Op::from_u32(u32::from(w)).is_some(), "{w}");
            }
        }
    }

    /// The zero-byte test against the bytes themselves.
    #[test]
    fn zero_byte_found_in_any_position() {
        for w in [
            0u32,
            0x0000_0001,
            0x6162_6300,
            0x0061_6263,
            0x6100_6263,
            0x6162_0063,
            0x8080_8080,
            0xffff_ffff,
            0x0101_0101,
            0x6162_6364,
        ] {
            assert_eq!(has_zero_byte(w), w.to_le_bytes().contains(&0), "{w:#x}");
        }
    }

    /// Damaged modules: wherever the decoder gives instructions, rspirv
    /// parses the module too and gives the same ones.
    #[test]
    fn damaged_modules_decode_as_rspirv_or_not_at_all() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut all = Vec::new();
        files(&root.join("fixtures"), &mut all);
        all.retain(|f| f.extension().is_some_and(|e| e == "spv"));
        all.sort();
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (mut decoded, mut tried) = (0, 0);
        for f in &all {
            let bytes = std::fs::read(f).unwrap();
            let Ok(words) = crate::program::words_from_bytes(&bytes, f) else {
                continue;
            };
            for _ in 0..40 {
                let mut w = words.clone();
                let at = 5 + (next() as usize) % (w.len() - 5);
                // A small value, a flipped bit or an opcode-sized change.
                w[at] = match next() % 3 {
                    0 => (next() % 8) as u32,
                    1 => w[at] ^ (1 << (next() % 32)),
                    _ => w[at].wrapping_add((next() % 5) as u32).wrapping_sub(2),
                };
                let Some(offs) = checked_offsets(&w) else {
                    continue;
                };
                tried += 1;
                if let Some(got) = decode(&w, &offs) {
                    let expected = rspirv_insts(&w);
                    assert!(
                        expected.as_ref() == Some(&got),
                        "{} with word {at} damaged",
                        f.display()
                    );
                    decoded += 1;
                }
            }
        }
        assert!(tried > 500 && decoded > 100, "{decoded} of {tried}");
    }

    /// On every module of the repository (SPIR-V files, and the WGSL and
    /// HLSL sources compiled), the decoder gives rspirv's instructions or
    /// leaves the module to rspirv; every WGSL module it decodes itself.
    #[test]
    fn same_instructions_as_rspirv() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut all = Vec::new();
        files(&root.join("shaders"), &mut all);
        files(&root.join("fixtures"), &mut all);
        all.sort();
        let (mut decoded, mut wgsl) = (0, 0);
        for f in &all {
            let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("");
            let words = match ext {
                "spv" => {
                    let bytes = std::fs::read(f).unwrap();
                    match crate::program::words_from_bytes(&bytes, f) {
                        Ok(w) => w,
                        Err(_) => continue,
                    }
                }
                "wgsl" => match crate::front::compile_path(f, crate::shader::Language::Wgsl) {
                    Ok(c) => c.words,
                    Err(_) => continue,
                },
                "hlsl" => match crate::front::compile_path(f, crate::shader::Language::Hlsl) {
                    Ok(c) => c.words,
                    Err(_) => continue,
                },
                _ => continue,
            };
            let Some(expected) = rspirv_insts(&words) else {
                continue;
            };
            let got = decode(&words, &offsets(&words));
            if ext == "wgsl" {
                assert!(got.is_some(), "{} left to rspirv", f.display());
                wgsl += 1;
            }
            if let Some(got) = got {
                assert!(got == expected, "{}", f.display());
                decoded += 1;
            }
        }
        assert!(
            wgsl >= 40 && decoded >= wgsl + 50,
            "{decoded} decoded, {wgsl} WGSL"
        );
    }
}
