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
/// `structs`: where the word `struct` stands in `s` (found once per text).
fn find_struct(s: &[u8], structs: &[usize], name: &str) -> Option<(usize, usize, usize)> {
    let mut found = None;
    for &at in structs {
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
    let mut texts: Vec<(u32, String)> = program
        .files
        .iter()
        .enumerate()
        .filter_map(|(i, f)| {
            f.text
                .clone()
                .or_else(|| crate::shader::read_source_text(&f.path))
                .map(|t| (i as u32, t))
        })
        .collect();
    add_included(program, &mut texts);
    drop_misplaced(program, &texts);
    let structs: Vec<(u32, Vec<u32>)> = program
        .types
        .iter()
        .filter_map(|(id, t)| match t {
            Type::Struct { members } => Some((*id, (0..members.len() as u32).collect())),
            _ => None,
        })
        .collect();
    // Each text without comments, and where `struct` stands in it: once,
    // not once per struct.
    let scanned: Vec<(u32, &String, Vec<u8>, Vec<usize>)> = texts
        .iter()
        .map(|(f, text)| {
            let s = strip_comments(text);
            let at = words(&s, 0, s.len(), "struct");
            (*f, text, s, at)
        })
        .collect();
    for (id, members) in structs {
        let Some(name) = program.names.get(&id).cloned() else {
            continue;
        };
        let hits: Vec<_> = scanned
            .iter()
            .filter_map(|(f, text, s, at)| find_struct(s, at, &name).map(|h| (*f, *text, s, h)))
            .collect();
        // One declaration; or copies of one header (the embedded text and
        // the same file found on disk elsewhere): the first, which debug
        // info named, stands for them.
        let same = |a: &(u32, &String, &Vec<u8>, (usize, usize, usize))| {
            a.1 == hits[0].1 && a.3 == hits[0].3
        };
        let Some(&(file, text, s, (at, body, end))) =
            hits.first().filter(|_| hits.iter().all(same))
        else {
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
            // Debug info placing the member inside this body is kept.
            if program.decl_pos.get(&Decl::Member(id, k)).is_some_and(|p| {
                p.file == file
                    && p.line >= line_col(text, body).0
                    && p.line <= line_col(text, end).0
            }) {
                continue;
            }
            let Some(m) = program.member_names.get(&(id, k)).cloned() else {
                continue;
            };
            // The member's name followed by `;`, `[`, `:` or `,` — a declarator.
            let decl = words(s, body, end, &m).into_iter().find(|&o| {
                let after = skip_ws(s, o + m.len());
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

/// Adds the files `#include`d by the sources (glslang 12 `-gV` names only the
/// main file), found beside the including file, transitively.
fn add_included(program: &mut Program, texts: &mut Vec<(u32, String)>) {
    let mut k = 0;
    while k < texts.len() && program.files.len() < 256 {
        let (file, text) = texts[k].clone();
        k += 1;
        let dir = program.files[file as usize]
            .path
            .parent()
            .map(std::path::Path::to_path_buf)
            .unwrap_or_default();
        for line in text.lines() {
            let Some(rest) = line.trim_start().strip_prefix('#') else {
                continue;
            };
            let Some(rest) = rest.trim_start().strip_prefix("include") else {
                continue;
            };
            let rest = rest.trim();
            let Some(name) = rest
                .strip_prefix('"')
                .and_then(|r| r.split('"').next())
                .or_else(|| rest.strip_prefix('<').and_then(|r| r.split('>').next()))
            else {
                continue;
            };
            let path = super::debug::normalize(&dir.join(name.replace('\\', "/")));
            if program.files.iter().any(|f| f.path == path) {
                continue;
            }
            let Some(included) = crate::shader::read_source_text(&path) else {
                continue;
            };
            program.files.push(super::SourceFile { path, text: None });
            texts.push(((program.files.len() - 1) as u32, included));
        }
    }
}

/// Drops struct and member positions whose line does not name the
/// declaration (glslang 12 `-gV` with `#include`: lines of the wrong file,
/// several members on one line).
fn drop_misplaced(program: &mut Program, texts: &[(u32, String)]) {
    let names_it = |pos: &SrcPos, name: &str| -> bool {
        let Some((_, text)) = texts.iter().find(|(f, _)| *f == pos.file) else {
            return true; // no text to check against
        };
        let Some(line) = text.lines().nth(pos.line.saturating_sub(1) as usize) else {
            return false;
        };
        !words(line.as_bytes(), 0, line.len(), name).is_empty()
    };
    let wrong: Vec<Decl> = program
        .decl_pos
        .iter()
        .filter(|(d, p)| {
            let name = match d {
                Decl::Type(id) => program.names.get(id),
                Decl::Member(id, k) => program.member_names.get(&(*id, *k)),
                _ => None,
            };
            name.is_some_and(|n| !n.is_empty() && !names_it(p, n))
        })
        .map(|(d, _)| *d)
        .collect();
    for d in wrong {
        program.decl_pos.remove(&d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_unique_struct_outside_comments() {
        let t = "// struct P { int x; };\nstruct P [raypayload] {\n  float3 c : read(caller) : write(closesthit);\n  uint d[2];\n};\nP p;";
        let s = strip_comments(t);
        let structs = |s: &[u8]| words(s, 0, s.len(), "struct");
        let (at, body, end) = find_struct(&s, &structs(&s), "P").unwrap();
        assert_eq!(line_col(t, at), (2, 8));
        assert!(t[body..end].contains("uint d[2]"));
        // A second definition makes it ambiguous.
        let t2 = format!("{t}\nstruct P {{ int y; }};");
        let s2 = strip_comments(&t2);
        assert_eq!(find_struct(&s2, &structs(&s2), "P"), None);
    }

    /// glslang 12 `-gV` with `#include` names only the main file and places
    /// the struct and its members on lines of it; `-g` names both files. Both
    /// end with the header's lines, one per member.
    #[test]
    fn included_struct_lands_in_the_header() {
        for v in ["g", "gV"] {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("fixtures/include/main.rgen.{v}.spv"));
            let p = crate::front::load(&path, crate::shader::Language::Spirv).unwrap();
            let ty = *p
                .names
                .iter()
                .find(|(id, n)| *n == "Payload" && matches!(p.ty(**id), Some(Type::Struct { .. })))
                .unwrap()
                .0;
            let at = |d: Decl| {
                let l = p.decl_location(d).unwrap();
                (
                    l.path.file_name().unwrap().to_str().unwrap().to_string(),
                    l.line,
                )
            };
            assert_eq!(at(Decl::Type(ty)), ("payload.glsl".to_string(), 2), "{v}");
            let lines: Vec<u32> = (0..5).map(|k| at(Decl::Member(ty, k)).1).collect();
            assert_eq!(lines, [3, 4, 5, 6, 7], "{v}");
        }
    }
}
