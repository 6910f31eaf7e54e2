//! Lexer: source text → tokens, each with its file, line and column.
//!
//! The lexer runs before the preprocessor (as in C): directives are recognised
//! from `#` tokens that start a line, and macro expansion works on tokens, so
//! every token the parser sees still knows where it came from.

use super::error::{Error, Pos};
use std::rc::Rc;

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    Ident(Rc<str>),
    /// Integer literal: value and whether it had a `u`/`U` suffix.
    Int(u64, bool),
    /// An integer literal with an `l`/`ll` suffix: 64-bit (`1ull`).
    Long(u64, bool),
    /// Float literal: value (suffixes `f`, `h`, `l` are accepted and dropped).
    Float(f64),
    Str(Rc<str>),
    Punct(&'static str),
}

#[derive(Clone, Debug)]
pub struct Token {
    pub tok: Tok,
    pub pos: Pos,
    /// Whitespace came before it (for `#` stringification and
    /// function-like macro definitions).
    pub space: bool,
    /// First token on its (logical) line: starts a directive when it is `#`.
    pub bol: bool,
    /// Macros this token came out of, which must not expand it again.
    pub hide: Rc<Vec<Rc<str>>>,
}

impl Token {
    pub fn is(&self, p: &str) -> bool {
        matches!(&self.tok, Tok::Punct(q) if *q == p)
    }
    pub fn ident(&self) -> Option<&str> {
        match &self.tok {
            Tok::Ident(s) => Some(s),
            _ => None,
        }
    }
    /// The token's spelling, for stringification, pasting and messages.
    pub fn spelling(&self) -> String {
        match &self.tok {
            Tok::Ident(s) => s.to_string(),
            Tok::Int(v, u) => format!("{v}{}", if *u { "u" } else { "" }),
            Tok::Long(v, u) => format!("{v}{}ll", if *u { "u" } else { "" }),
            Tok::Float(f) => {
                let s = format!("{f:?}");
                s
            }
            Tok::Str(s) => format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"")),
            Tok::Punct(p) => p.to_string(),
        }
    }
}

const PUNCTS: &[&str] = &[
    "<<=", ">>=", "...", "::", "->", "++", "--", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||",
    "+=", "-=", "*=", "/=", "%=", "&=", "|=", "^=", "##", "[[", "]]", "{", "}", "(", ")", "[", "]",
    ";", ",", ".", "+", "-", "*", "/", "%", "<", ">", "=", "!", "~", "&", "|", "^", "?", ":", "#",
];

/// Lexes one file. `[[` and `]]` are not produced here (the parser pairs
/// brackets itself), so `a[b[c]]` stays ordinary indexing.
pub fn lex(src: &str, file: u32) -> Result<Vec<Token>, Error> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let (mut i, mut line, mut col) = (0usize, 1u32, 1u32);
    // Editors on Windows often start files with a byte-order mark.
    if src.starts_with('\u{feff}') {
        i = 3;
    }
    let mut bol = true;
    let mut space = false;
    let empty: Rc<Vec<Rc<str>>> = Rc::new(Vec::new());
    while i < b.len() {
        let c = b[i];
        // Line splice: backslash-newline joins lines without ending the directive.
        if c == b'\\' && (b.get(i + 1) == Some(&b'\n') || b.get(i + 1) == Some(&b'\r')) {
            i += 1;
            if b[i] == b'\r' && b.get(i + 1) == Some(&b'\n') {
                i += 1;
            }
            i += 1;
            line += 1;
            col = 1;
            space = true;
            continue;
        }
        if c == b'\n' {
            i += 1;
            line += 1;
            col = 1;
            bol = true;
            space = true;
            continue;
        }
        if c == b' ' || c == b'\t' || c == b'\r' || c == 0x0c || c == 0x0b {
            i += 1;
            col += 1;
            space = true;
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                // A spliced line comment continues on the next line.
                if b[i] == b'\\' && b.get(i + 1) == Some(&b'\n') {
                    i += 1;
                    line += 1;
                } else if b[i] == b'\\' && b[i + 1..].starts_with(b"\r\n") {
                    i += 2;
                    line += 1;
                }
                i += 1;
            }
            space = true;
            continue;
        }
        if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let start = Pos { file, line, col };
            i += 2;
            col += 2;
            loop {
                if i >= b.len() {
                    return Err(Error::new(start, "unterminated block comment"));
                }
                if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    i += 2;
                    col += 2;
                    break;
                }
                if b[i] == b'\n' {
                    line += 1;
                    col = 1;
                } else if b[i] & 0xc0 != 0x80 {
                    // Columns count characters: not UTF-8 continuation bytes.
                    col += 1;
                }
                i += 1;
            }
            space = true;
            continue;
        }
        let pos = Pos { file, line, col };
        let start = i;
        let tok = if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            Tok::Ident(Rc::from(&src[start..i]))
        } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let (tok, len) =
                lex_number(&b[i..]).ok_or_else(|| Error::new(pos, "malformed number literal"))?;
            i += len;
            tok
        } else if c == b'"' {
            i += 1;
            let mut s = String::new();
            loop {
                match b.get(i) {
                    None | Some(b'\n') => {
                        return Err(Error::new(pos, "unterminated string literal"));
                    }
                    Some(b'"') => {
                        i += 1;
                        break;
                    }
                    // `\"` and `\\` are escapes; any other backslash is kept, as
                    // in Windows include paths (`"util\Compat.h"`).
                    Some(b'\\') if matches!(b.get(i + 1), Some(b'"' | b'\\')) => {
                        s.push(b[i + 1] as char);
                        i += 2;
                    }
                    Some(_) => {
                        let ch = src[i..].chars().next().unwrap_or('?');
                        s.push(ch);
                        i += ch.len_utf8();
                    }
                }
            }
            Tok::Str(Rc::from(s.as_str()))
        } else if c == b'\'' {
            // Character literals are rare in shaders; read 'x' as its code.
            if b.get(i + 2) == Some(&b'\'') {
                i += 3;
                Tok::Int(b[start + 1] as u64, false)
            } else {
                // A lone apostrophe, as in `#error Can't ...` in a skipped
                // block: a token of its own, as clang lexes it; the parser
                // refuses it if it reaches code.
                i += 1;
                Tok::Punct("'")
            }
        } else {
            let rest = &src[i..];
            match PUNCTS
                .iter()
                .find(|p| rest.starts_with(**p) && **p != "[[" && **p != "]]")
            {
                Some(p) => {
                    i += p.len();
                    Tok::Punct(p)
                }
                None => {
                    let ch = rest.chars().next().unwrap_or('?');
                    return Err(Error::new(pos, format!("unexpected character `{ch}`")));
                }
            }
        };
        col += src[start..i].chars().count() as u32;
        out.push(Token {
            tok,
            pos,
            space,
            bol,
            hide: empty.clone(),
        });
        bol = false;
        space = false;
    }
    Ok(out)
}

/// Reads a number literal at the start of `b`: returns the token and its length.
fn lex_number(b: &[u8]) -> Option<(Tok, usize)> {
    let mut i = 0;
    // Binary literals (`0b0101u`), which DXC accepts as clang does.
    if b.len() > 2 && b[0] == b'0' && matches!(b[1], b'b' | b'B') && matches!(b[2], b'0' | b'1') {
        let mut j = 2;
        while j < b.len() && matches!(b[j], b'0' | b'1') {
            j += 1;
        }
        let v = u64::from_str_radix(std::str::from_utf8(&b[2..j]).ok()?, 2).ok()?;
        let (u, long, n) = int_suffix(&b[j..]);
        return Some((int_token(v, u, long), j + n));
    }
    if b.len() > 1 && b[0] == b'0' && (b[1] == b'x' || b[1] == b'X') {
        i = 2;
        let s = i;
        while i < b.len() && b[i].is_ascii_hexdigit() {
            i += 1;
        }
        let int_end = i;
        // A hexadecimal float (C99): `0x1.8p-3`, mantissa in hex, exponent of 2.
        let mut frac_digits = 0;
        if i < b.len() && b[i] == b'.' {
            let mut j = i + 1;
            while j < b.len() && b[j].is_ascii_hexdigit() {
                j += 1;
            }
            if j < b.len() && matches!(b[j], b'p' | b'P') {
                frac_digits = j - i - 1;
                i = j;
            }
        }
        if i < b.len() && matches!(b[i], b'p' | b'P') {
            let mut j = i + 1;
            let neg = j < b.len() && b[j] == b'-';
            if j < b.len() && matches!(b[j], b'+' | b'-') {
                j += 1;
            }
            let es = j;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if j > es {
                let mut mantissa = 0f64;
                for &d in b[s..int_end]
                    .iter()
                    .chain(&b[int_end + 1..int_end + 1 + frac_digits])
                {
                    mantissa = mantissa * 16.0 + (d as char).to_digit(16)? as f64;
                }
                let exp: i32 = std::str::from_utf8(&b[es..j]).ok()?.parse().ok()?;
                let exp = if neg { -exp } else { exp } - 4 * frac_digits as i32;
                let v = mantissa * 2f64.powi(exp);
                if j < b.len() && matches!(b[j], b'f' | b'F' | b'h' | b'H' | b'l' | b'L') {
                    j += 1;
                }
                return Some((Tok::Float(v), j));
            }
        }
        let i = int_end;
        let v = u64::from_str_radix(std::str::from_utf8(&b[s..i]).ok()?, 16).ok()?;
        let (u, long, n) = int_suffix(&b[i..]);
        return Some((int_token(v, u, long), i + n));
    }
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut float = false;
    if i < b.len() && b[i] == b'.' {
        float = true;
        i += 1;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        // MSVC's spelling of special values, which DXC accepts: `1.#INF`.
        for (spelling, v) in [
            (&b"#INF"[..], f64::INFINITY),
            (b"#IND", f64::NAN),
            (b"#QNAN", f64::NAN),
        ] {
            if b[i..].starts_with(spelling) {
                let mut j = i + spelling.len();
                if j < b.len() && matches!(b[j], b'f' | b'F') {
                    j += 1;
                }
                return Some((Tok::Float(v), j));
            }
        }
    }
    if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
        let mut j = i + 1;
        if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
            j += 1;
        }
        if j < b.len() && b[j].is_ascii_digit() {
            float = true;
            i = j;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
        }
    }
    let text = std::str::from_utf8(&b[..i]).ok()?;
    if float || (i < b.len() && matches!(b[i], b'f' | b'F' | b'h' | b'H')) {
        let v: f64 = text.parse().ok()?;
        if i < b.len() && matches!(b[i], b'f' | b'F' | b'h' | b'H' | b'l' | b'L') {
            i += 1;
        }
        return Some((Tok::Float(v), i));
    }
    // Octal literals (leading 0) as C reads them.
    let v = if text.len() > 1 && text.starts_with('0') {
        u64::from_str_radix(&text[1..], 8).ok()?
    } else {
        text.parse().ok()?
    };
    let (u, long, n) = int_suffix(&b[i..]);
    if i + n < b.len() && (b[i + n].is_ascii_alphanumeric() || b[i + n] == b'_') {
        return None;
    }
    Some((int_token(v, u, long), i + n))
}

/// `u`, `l`, `ul`, `ull`, ...: (unsigned, 64-bit, length).
fn int_suffix(b: &[u8]) -> (bool, bool, usize) {
    let mut u = false;
    let mut long = false;
    let mut n = 0;
    while n < b.len() && n < 3 && matches!(b[n], b'u' | b'U' | b'l' | b'L') {
        u |= matches!(b[n], b'u' | b'U');
        long |= matches!(b[n], b'l' | b'L');
        n += 1;
    }
    (u, long, n)
}

fn int_token(v: u64, u: bool, long: bool) -> Tok {
    if long {
        Tok::Long(v, u)
    } else {
        Tok::Int(v, u)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(s: &str) -> Vec<Tok> {
        lex(s, 0).unwrap().into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn hexadecimal_floats_and_msvc_infinity() {
        let toks =
            |s: &str| -> Vec<Tok> { lex(s, 0).unwrap().into_iter().map(|t| t.tok).collect() };
        assert!(matches!(toks("0x1.0p-24f")[..], [Tok::Float(v)] if v == 2f64.powi(-24)));
        assert!(matches!(toks("0x1.8p1")[..], [Tok::Float(v)] if v == 3.0));
        assert!(matches!(toks("0xAp0")[..], [Tok::Float(v)] if v == 10.0));
        assert!(matches!(toks("0x10")[..], [Tok::Int(16, false)]));
        assert!(matches!(toks("1.#INF")[..], [Tok::Float(v)] if v.is_infinite()));
    }

    #[test]
    fn numbers_and_puncts() {
        assert_eq!(
            kinds("a+=0x1Fu*1.5f>>=2e3"),
            vec![
                Tok::Ident("a".into()),
                Tok::Punct("+="),
                Tok::Int(31, true),
                Tok::Punct("*"),
                Tok::Float(1.5),
                Tok::Punct(">>="),
                Tok::Float(2000.0),
            ]
        );
        assert_eq!(
            kinds(".5 1. 3h"),
            vec![Tok::Float(0.5), Tok::Float(1.0), Tok::Float(3.0)]
        );
        assert_eq!(
            kinds("0b01u 0B110 0b1ll"),
            vec![Tok::Int(1, true), Tok::Int(6, false), Tok::Long(1, false)]
        );
    }

    #[test]
    fn positions_and_comments() {
        let t = lex("a /* x\n y */ b\n  // c\n\tc", 0).unwrap();
        let p: Vec<(u32, u32, bool)> = t.iter().map(|t| (t.pos.line, t.pos.col, t.bol)).collect();
        assert_eq!(p, vec![(1, 1, true), (2, 7, false), (4, 2, true)]);
    }

    #[test]
    fn splice_keeps_line_logical() {
        let t = lex("#define A \\\n 1\nB", 0).unwrap();
        let bols: Vec<bool> = t.iter().map(|t| t.bol).collect();
        assert_eq!(bols, vec![true, false, false, false, true]);
        assert_eq!(t[3].pos.line, 2);
    }

    #[test]
    fn byte_order_mark_and_crlf() {
        let t = lex("\u{feff}a\r\n  b", 0).unwrap();
        let p: Vec<(u32, u32)> = t.iter().map(|t| (t.pos.line, t.pos.col)).collect();
        assert_eq!(p, vec![(1, 1), (2, 3)]);
    }

    #[test]
    fn errors_have_positions() {
        let e = lex("x\n  @", 0).unwrap_err();
        assert_eq!((e.pos.line, e.pos.col), (2, 3));
        assert!(lex("/* open", 0).is_err());
        assert!(lex("\"open", 0).is_err());
    }
}
