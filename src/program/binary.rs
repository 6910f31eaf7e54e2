//! SPIR-V binaries: bytes to words, with the endianness the magic number says.
//! Structural checks (opcodes, ids) happen when the Program is built.

use crate::diag::{InputError, InputErrorKind};
use std::path::Path;

pub const MAGIC: u32 = 0x0723_0203;

pub fn words_from_bytes(bytes: &[u8], path: &Path) -> Result<Vec<u32>, InputError> {
    if bytes.len() < 20 {
        return Err(InputError::new(
            InputErrorKind::InvalidSpirv,
            path,
            format!(
                "SPIR-V module is {} bytes, shorter than the 5-word header",
                bytes.len()
            ),
        ));
    }
    if bytes.len() % 4 != 0 {
        return Err(InputError::new(
            InputErrorKind::InvalidSpirv,
            path,
            format!(
                "SPIR-V module is {} bytes, not a whole number of 32-bit words (truncated at word {})",
                bytes.len(),
                bytes.len() / 4
            ),
        ));
    }
    let first = [bytes[0], bytes[1], bytes[2], bytes[3]];
    let from: fn([u8; 4]) -> u32 = if u32::from_le_bytes(first) == MAGIC {
        u32::from_le_bytes
    } else if u32::from_be_bytes(first) == MAGIC {
        u32::from_be_bytes
    } else {
        return Err(InputError::new(
            InputErrorKind::InvalidSpirv,
            path,
            format!(
                "not a SPIR-V module: word 0 is {:#010x}, expected the magic number {MAGIC:#010x}",
                u32::from_le_bytes(first)
            ),
        ));
    };
    Ok(bytes
        .chunks_exact(4)
        .map(|c| from([c[0], c[1], c[2], c[3]]))
        .collect())
}
