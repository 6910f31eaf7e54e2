//! Struct declarations found in C-like source text (GLSL, HLSL).
//!
//! `glslang -g` and `dxc -fspv-debug=line` give instruction positions but none
//! for types, and glslang 12's `-gV` gives a struct the line of its first use.
//! The source text is usually embedded (or on disk), and a struct declaration
//! is easy to find exactly: `struct Name {` once, outside comments. Only a
//! unique match is used.

use super::{Decl, Program, SrcPos, Type};

/// Blanks comments (keeping offsets and newlines) so matches in them are ignored.
fn strip_comments(text: &str) -> Vec<u8> {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                out[i] = b' ';
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] != b'\n' {
                    out[i] = b' ';
                }
                i += 1;
            }
            let close = (i + 2).min(b.len());
            out[i..close].fill(b' ');
            i += 2;
        } else {
            i += 1;
        }
    }
    out
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// Offsets of `name` as a whole word in `s[from..to]`.
fn words(s: &[u8], from: usize, to: usize, name: &str) -> Vec<usize> {
    let n = name.as_bytes();
    let mut out = Vec::new();
    if n.is_empty() {
        return out;
    }
    let mut i = from;
    while i + n.len() <= to {
        if &s[i..i + n.len()] == n
            && (i == 0 || !is_ident(s[i - 1]))
            && (i + n.len() >= s.len() || !is_ident(s[i + n.len()]))
        {
            out.push(i);
            i += n.len();
        } else {
            i += 1;
        }
    }
    out
}

fn skip_ws(s: &[u8], mut i: usize) -> usize {
    while i < s.len() && s[i].is_ascii_whitespace() {
        i += 1;
    }
    i
}

/// The struct `name`: offset of the name and the body's byte range.
fn find_struct(s: &[u8], name: &str) -> Option<(usize, usize, usize)> {
    let mut found = None;
    for at in words(s, 0, s.len(), "struct") {
        let n = skip_ws(s, at + 6);
        if !s[n..].starts_with(name.as_bytes())
            || s.get(n + name.len()).is_some_and(|c| is_ident(*c))
        {
            continue;
        }
        // HLSL may put `[raypayload]` between the name and the body.
        let mut b = skip_ws(s, n + name.len());
        if s.get(b) == Some(&b'[') {
            while b < s.len() && s[b] != b']' {
                b += 1;
            }
            b = skip_ws(s, b + 1);
        }
        if s.get(b) != Some(&b'{') {
            continue; // a forward declaration or a use
        }
        let mut depth = 0;
        let mut end = b;
        while end < s.len() {
            match s[end] {
                b'{' => depth += 1,
                b'}' => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            end += 1;
        }
        if found.is_some() {
            return None; // ambiguous: trust nothing
        }
        found = Some((n, b + 1, end));
    }
    found
}

fn line_col(text: &str, offset: usize) -> (u32, u32) {
    crate::shader::line_col(text, offset)
}

/// Fills struct and member positions from the source text where debug info
/// has none or (glslang's composite bug) places the struct at a use.
pub fn fill(program: &mut Program) {
    if !matches!(
        program.language,
        crate::shader::Language::Glsl | crate::shader::Language::Hlsl
    ) {
        return;
    }
    let texts: Vec<(u32, String)> = program
        .files
        .iter()
        .enumerate()
        .filter_map(|(i, f)| {
            f.text
                .clone()
                .or_else(|| std::fs::read_to_string(&f.path).ok())
                .map(|t| (i as u32, t))
        })
        .collect();
    let structs: Vec<(u32, Vec<u32>)> = program
        .types
        .iter()
        .filter_map(|(id, t)| match t {
            Type::Struct { members } => Some((*id, (0..members.len() as u32).collect())),
            _ => None,
        })
        .collect();
    for (id, members) in structs {
        let Some(name) = program.names.get(&id).cloned() else {
            continue;
        };
        let mut hits = texts.iter().filter_map(|(f, text)| {
            let s = strip_comments(text);
            find_struct(&s, &name).map(|h| (*f, text, s, h))
        });
        let (Some((file, text, s, (at, body, end))), None) = (hits.next(), hits.next()) else {
            continue;
        };
        let pos = |offset: usize, len: usize| {
            let (line, column) = line_col(text, offset);
            let (end_line, end_column) = line_col(text, offset + len);
            SrcPos {
                file,
                line,
                column,
                end_line,
                end_column,
            }
        };
        program.decl_pos.insert(Decl::Type(id), pos(at, name.len()));
        for k in members {
            if program.decl_pos.contains_key(&Decl::Member(id, k)) {
                continue;
            }
            let Some(m) = program.member_names.get(&(id, k)).cloned() else {
                continue;
            };
            // The member's name followed by `;`, `[`, `:` or `,` — a declarator.
            let decl = words(&s, body, end, &m).into_iter().find(|&o| {
                let after = skip_ws(&s, o + m.len());
                matches!(s.get(after), Some(b';' | b'[' | b':' | b','))
            });
            if let Some(o) = decl {
                program
                    .decl_pos
                    .insert(Decl::Member(id, k), pos(o, m.len()));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_unique_struct_outside_comments() {
        let t = "// struct P { int x; };\nstruct P [raypayload] {\n  float3 c : read(caller) : write(closesthit);\n  uint d[2];\n};\nP p;";
        let s = strip_comments(t);
        let (at, body, end) = find_struct(&s, "P").unwrap();
        assert_eq!(line_col(t, at), (2, 8));
        assert!(t[body..end].contains("uint d[2]"));
        // A second definition makes it ambiguous.
        let t2 = format!("{t}\nstruct P {{ int y; }};");
        assert_eq!(find_struct(&strip_comments(&t2), "P"), None);
    }
}
