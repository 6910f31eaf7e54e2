//! Source bytes as DXC reads them. DXC (clang) takes the bytes of a file as
//! they are: a comment or string literal may hold any byte, and files
//! written on Windows are often Windows-1252 (a curly apostrophe `0x92` in
//! a comment). Here a file becomes text once, before lexing: a UTF-8 or
//! UTF-16 byte-order mark is honoured and removed, valid UTF-8 is kept, and
//! anything else is read as Windows-1252, one character per byte, so
//! that line and column numbers still count what an editor shows.

/// The text of a source file's bytes.
pub fn decode_source(bytes: Vec<u8>) -> String {
    if let Some(rest) = bytes.strip_prefix(&[0xef, 0xbb, 0xbf]) {
        return decode_source(rest.to_vec());
    }
    let utf16 = |le: bool, b: &[u8]| {
        let units = b.chunks(2).map(|c| match (c, le) {
            ([lo, hi], true) => u16::from_le_bytes([*lo, *hi]),
            ([hi, lo], false) => u16::from_le_bytes([*lo, *hi]),
            // An odd last byte: a unit no decoder can complete.
            _ => 0xfffd,
        });
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect()
    };
    match bytes.as_slice() {
        [0xff, 0xfe, rest @ ..] => return utf16(true, rest),
        [0xfe, 0xff, rest @ ..] => return utf16(false, rest),
        _ => {}
    }
    match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.into_bytes().into_iter().map(windows_1252).collect(),
    }
}

/// One Windows-1252 byte as a character. The five bytes the code page
/// leaves undefined (0x81, 0x8D, 0x8F, 0x90, 0x9D) are read as the Latin-1
/// control characters of the same value, as Windows does.
fn windows_1252(b: u8) -> char {
    const HIGH: [char; 32] = [
        '\u{20ac}', '\u{81}', '\u{201a}', '\u{192}', '\u{201e}', '\u{2026}', '\u{2020}',
        '\u{2021}', '\u{2c6}', '\u{2030}', '\u{160}', '\u{2039}', '\u{152}', '\u{8d}', '\u{17d}',
        '\u{8f}', '\u{90}', '\u{2018}', '\u{2019}', '\u{201c}', '\u{201d}', '\u{2022}', '\u{2013}',
        '\u{2014}', '\u{2dc}', '\u{2122}', '\u{161}', '\u{203a}', '\u{153}', '\u{9d}', '\u{17e}',
        '\u{178}',
    ];
    match b {
        0x80..=0x9f => HIGH[(b - 0x80) as usize],
        _ => b as char,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_as_dxc_reads() {
        // UTF-8 stays, with or without a BOM.
        assert_eq!(decode_source("a’b".into()), "a’b");
        assert_eq!(decode_source(b"\xef\xbb\xbfint".to_vec()), "int");
        // Windows-1252: a curly apostrophe and a Latin-1 letter.
        assert_eq!(
            decode_source(b"// don\x92t \xe9\n".to_vec()),
            "// don’t é\n"
        );
        assert_eq!(decode_source(vec![0x81, 0x9f]), "\u{81}Ÿ");
        // UTF-16 with its byte-order mark.
        assert_eq!(
            decode_source(b"\xff\xfea\x00\r\x00\n\x00".to_vec()),
            "a\r\n"
        );
        assert_eq!(decode_source(b"\xfe\xff\x00a".to_vec()), "a");
    }
}
