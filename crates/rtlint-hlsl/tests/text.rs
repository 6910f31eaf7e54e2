//! Source text as DXC reads it: any byte in comments and string literals,
//! Windows-1252 headers, byte-order marks, CRLF line ends and UTF-16, in the
//! main file and in included ones, with exact lines and columns after them.

use rtlint_hlsl::{compile_file, HlslOptions};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-hlsl-text-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `main.hlsl` (UTF-8 with a BOM and CRLF) including `header.hlsli`.
fn project(name: &str, header: &[u8]) -> PathBuf {
    let d = scratch(name);
    let main = "\u{feff}// caf\u{e9} \u{2019} in UTF-8\r\n#include \"header.hlsli\"\r\n\
                RWStructuredBuffer<float> output : register(u0);\r\n\
                [numthreads(1, 1, 1)]\r\nvoid main() { output[0] = Shade(); }\r\n";
    std::fs::write(d.join("main.hlsl"), main).unwrap();
    std::fs::write(d.join("header.hlsli"), header).unwrap();
    d.join("main.hlsl")
}

fn compile(path: &Path) -> Result<(), String> {
    compile_file(path, &HlslOptions::default())
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// A curly apostrophe (0x92) in a comment of an included Windows-1252
/// header, an `é` (0xE9) in a string literal, CRLF: it compiles.
#[test]
fn a_windows_1252_header_compiles() {
    let header = b"#pragma once\r\n// the shader\x92s colour \x96 see caf\xe9\r\n\
                   #define NAME \"caf\xe9\"\r\n/* \x93quoted\x94 */\r\n\
                   float Shade() { return 0.5; }\r\n";
    let main = project("cp1252", header);
    compile(&main).unwrap();
}

/// Errors after such bytes still have the right line and column: one
/// column per Windows-1252 byte, one per character in UTF-8 (a block
/// comment holding a three-byte character counts it once).
#[test]
fn positions_stay_exact_after_such_bytes() {
    let header = b"// \x92\r\n/* \x92\x92 */ float Shade() { return nope; }\r\n";
    let e = compile(&project("cp1252-error", header)).unwrap_err();
    assert!(e.contains("header.hlsli:2:33: "), "{e}");
    assert!(e.contains("nope"), "{e}");

    let header = "/* \u{2019}\u{2019} */ float Shade() { return nope; }\n";
    let e = compile(&project("utf8-error", header.as_bytes())).unwrap_err();
    assert!(e.contains("header.hlsli:1:33: "), "{e}");

    // A stray byte in code is an error at its line and column.
    let header = b"float Shade() { return 1.0; }\r\n  \x92\r\n";
    let e = compile(&project("stray", header)).unwrap_err();
    assert!(e.contains("header.hlsli:2:3: unexpected character"), "{e}");
}

/// A UTF-16 header with its byte-order mark (as some Windows editors save).
#[test]
fn a_utf16_header_compiles() {
    let text = "float Shade() { return 0.25; } // \u{2019}\r\n";
    let mut bytes = vec![0xff, 0xfe];
    bytes.extend(text.encode_utf16().flat_map(|u| u.to_le_bytes()));
    compile(&project("utf16", &bytes)).unwrap();
}

/// A line comment spliced with a backslash before CRLF continues on the
/// next line, as in C.
#[test]
fn a_spliced_comment_with_crlf() {
    let header =
        b"// not code \\\r\nfloat Shade() { return nope; }\r\nfloat Shade() { return 1.0; }\r\n";
    compile(&project("splice", header)).unwrap();
}

/// An apostrophe in the text of a skipped `#error` (`Can't`) is no
/// character literal: it compiles, as with DXC; one in code is an error at
/// its position.
#[test]
fn an_apostrophe_in_a_skipped_directive() {
    let header = b"#if 0\r\n#error Can't happen\r\n#endif\r\nfloat Shade() { return 1.0; }\r\n";
    compile(&project("apostrophe", header)).unwrap();
    let header = b"float Shade() { return 'ab'; }\r\n";
    let e = compile(&project("apostrophe-code", header)).unwrap_err();
    assert!(e.contains("header.hlsli:1:24: "), "{e}");
}
