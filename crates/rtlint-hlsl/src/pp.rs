//! Preprocessor: directives, includes and macro expansion over tokens.
//!
//! Every output token keeps a position in a real file: source tokens their
//! own, tokens produced by a macro the position of the macro's name at the
//! invocation (that is where a user looks when a diagnostic points there).

mod cond;
mod include;
mod macros;

pub use include::{FileLoader, FsLoader, MemLoader};

use super::error::{Error, Pos, Result};
use super::lex::{lex, Tok, Token};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;

#[derive(Clone, Debug)]
struct Macro {
    params: Option<Vec<Rc<str>>>,
    variadic: bool,
    body: Vec<Token>,
}

/// The preprocessed token stream and the file table its positions index.
pub struct Output {
    pub tokens: Vec<Token>,
    pub files: Vec<PathBuf>,
    pub warnings: Vec<Error>,
}

struct Cond {
    /// This group is being emitted.
    active: bool,
    /// Some earlier group of this `#if` was taken.
    taken: bool,
    /// Enclosing groups are all active.
    parent: bool,
    seen_else: bool,
    pos: Pos,
}

pub struct Preprocessor<'a> {
    loader: &'a mut dyn FileLoader,
    include_dirs: Vec<PathBuf>,
    macros: HashMap<Rc<str>, Macro>,
    pub files: Vec<PathBuf>,
    once: HashSet<PathBuf>,
    /// (file index, position of the `#include` that opened it).
    stack: Vec<(u32, Option<Pos>)>,
    out: Vec<Token>,
    /// Expansion work done so far; bounds runaway macros.
    budget: usize,
    /// Warnings (positions and messages), rendered by the caller.
    pub warnings: Vec<Error>,
}

const MAX_INCLUDE_DEPTH: usize = 64;

/// Marker tokens for `#pragma pack_matrix(...)`, read by the parser.
pub const PACK_ROW_MAJOR: &str = "#pragma pack_matrix(row_major)";
pub const PACK_COLUMN_MAJOR: &str = "#pragma pack_matrix(column_major)";
/// Tokens macro expansions may produce in one file.
const EXPANSION_BUDGET: usize = 2_000_000;

impl<'a> Preprocessor<'a> {
    pub fn new(loader: &'a mut dyn FileLoader, setup: &Setup) -> Result<Self> {
        let (include_dirs, defines) = (setup.include_dirs, setup.defines);
        let mut pp = Preprocessor {
            loader,
            include_dirs: include_dirs.to_vec(),
            macros: HashMap::new(),
            files: Vec::new(),
            once: HashSet::new(),
            stack: Vec::new(),
            out: Vec::new(),
            budget: 0,
            warnings: Vec::new(),
        };
        // What DXC defines when it compiles for Vulkan (`-spirv`), before the
        // user's `-D`s (which may replace them).
        for (name, value) in setup.predefined {
            let name = *name;
            // Plain numbers: no file of their own (nothing in them can fail).
            let body = lex(value, 0)?
                .into_iter()
                .map(|mut t| {
                    t.bol = false;
                    t
                })
                .collect();
            pp.macros.insert(
                Rc::from(name),
                Macro {
                    params: None,
                    variadic: false,
                    body,
                },
            );
        }
        // `-D` values are lexed as a file of their own, so errors point somewhere.
        for (name, value) in defines {
            let file = pp.files.len() as u32;
            pp.files
                .push(PathBuf::from(format!("<command line -D{name}>")));
            if name.contains('(') {
                // `-D NAME(x)=body`: a function-like macro, read as `#define` reads it.
                let line = lex(&format!("{name} {value}"), file)?;
                let pos = line.first().map(|t| t.pos).unwrap_or_default();
                pp.define(pos, &line)?;
                continue;
            }
            let body = lex(value, file)?
                .into_iter()
                .map(|mut t| {
                    t.bol = false;
                    t
                })
                .collect();
            pp.macros.insert(
                Rc::from(name.as_str()),
                Macro {
                    params: None,
                    variadic: false,
                    body,
                },
            );
        }
        Ok(pp)
    }

    /// Preprocesses a file whose text is already read.
    pub fn run(mut self, path: &Path, text: &str) -> Result<Output> {
        self.file(path, text, None)?;
        Ok(Output {
            tokens: self.out,
            files: self.files,
            warnings: self.warnings,
        })
    }

    fn file(&mut self, path: &Path, text: &str, from: Option<Pos>) -> Result<()> {
        let file = self.files.len() as u32;
        self.files.push(path.to_path_buf());
        self.stack.push((file, from));
        let tokens = lex(text, file)?;
        self.lines(tokens)?;
        self.stack.pop();
        Ok(())
    }

    fn lines(&mut self, mut tokens: Vec<Token>) -> Result<()> {
        let mut conds: Vec<Cond> = Vec::new();
        let mut pending: Vec<Token> = Vec::new();
        let mut i = 0;
        while i < tokens.len() {
            let t = &tokens[i];
            if !(t.bol && t.is("#")) {
                if conds.last().is_none_or(|c| c.active) {
                    pending.push(t.clone());
                }
                i += 1;
                continue;
            }
            // A directive: `#` at the start of a line up to the next line start.
            let hash = t.pos;
            let mut j = i + 1;
            while j < tokens.len() && !tokens[j].bol {
                j += 1;
            }
            let line = &tokens[i + 1..j];
            i = j;
            let active = conds.last().is_none_or(|c| c.active);
            let Some(name_tok) = line.first() else {
                continue; // null directive
            };
            let name = name_tok.ident().unwrap_or("");
            match name {
                "if" | "ifdef" | "ifndef" => {
                    let value = if !active {
                        false
                    } else if name == "if" {
                        self.eval_if(&line[1..], name_tok.pos)? != 0
                    } else {
                        let id = line.get(1).and_then(Token::ident).ok_or_else(|| {
                            Error::new(name_tok.pos, format!("#{name} needs a macro name"))
                        })?;
                        self.macros.contains_key(id) == (name == "ifdef")
                    };
                    conds.push(Cond {
                        active: active && value,
                        taken: value,
                        parent: active,
                        seen_else: false,
                        pos: hash,
                    });
                }
                "elif" | "else" => {
                    let Some(c) = conds.last_mut() else {
                        return Err(Error::new(name_tok.pos, format!("#{name} without #if")));
                    };
                    if c.seen_else {
                        return Err(Error::new(name_tok.pos, format!("#{name} after #else")));
                    }
                    let (parent, taken) = (c.parent, c.taken);
                    let value = if name == "else" {
                        true
                    } else if parent && !taken {
                        self.eval_if(&line[1..], name_tok.pos)? != 0
                    } else {
                        false
                    };
                    let c = conds.last_mut().unwrap_or_else(|| unreachable!());
                    c.seen_else = name == "else";
                    c.active = parent && !taken && value;
                    c.taken |= value;
                }
                "endif" => {
                    if conds.pop().is_none() {
                        return Err(Error::new(name_tok.pos, "#endif without #if"));
                    }
                }
                _ if !active => {}
                "line" => {
                    self.flush(&mut pending)?;
                    let (number, file) = self.line_directive(name_tok, &line[1..])?;
                    // The line after the directive becomes `number`; later
                    // lines follow on. Positions seen so far (possibly already
                    // renumbered) are shifted, so several `#line`s compose.
                    let next = hash.line.saturating_add(1);
                    for t in &mut tokens[j..] {
                        t.pos.line = number.saturating_add(t.pos.line.saturating_sub(next));
                        if let Some(f) = file {
                            t.pos.file = f;
                        }
                    }
                }
                _ => {
                    // Text before a directive is expanded first: a macro
                    // defined or undefined by the directive affects only what follows.
                    self.flush(&mut pending)?;
                    self.directive(name_tok, &line[1..])?;
                }
            }
        }
        if let Some(c) = conds.last() {
            return Err(Error::new(c.pos, "unterminated conditional directive")
                .label("this #if has no #endif"));
        }
        self.flush(&mut pending)
    }

    fn flush(&mut self, pending: &mut Vec<Token>) -> Result<()> {
        if pending.is_empty() {
            return Ok(());
        }
        let toks = std::mem::take(pending);
        let expanded = self.expand(toks)?;
        self.out.extend(expanded);
        Ok(())
    }

    fn directive(&mut self, name_tok: &Token, rest: &[Token]) -> Result<()> {
        let pos = name_tok.pos;
        match name_tok.ident().unwrap_or("") {
            "define" => self.define(pos, rest),
            "undef" => {
                let id = rest
                    .first()
                    .and_then(Token::ident)
                    .ok_or_else(|| Error::new(pos, "#undef needs a macro name"))?;
                self.macros.remove(id);
                Ok(())
            }
            "include" => self.include(pos, rest),
            "pragma" => {
                if rest.first().and_then(Token::ident) == Some("pack_matrix") {
                    // The default packing of the matrices declared after it: a
                    // marker token the parser reads (and removes).
                    let arg = rest.get(2).and_then(Token::ident).unwrap_or("");
                    let marker = match arg {
                        "row_major" => PACK_ROW_MAJOR,
                        "column_major" => PACK_COLUMN_MAJOR,
                        _ => {
                            return Err(Error::new(
                                pos,
                                format!(
                                "#pragma pack_matrix needs row_major or column_major, not `{arg}`"
                            ),
                            ))
                        }
                    };
                    let mut t = rest[0].clone();
                    t.tok = Tok::Punct(marker);
                    t.bol = false;
                    self.out.push(t);
                }
                if rest.first().and_then(Token::ident) == Some("once") {
                    let file = self.stack.last().map(|s| s.0).unwrap_or(0);
                    let path = self.files[file as usize].clone();
                    self.once.insert(path);
                }
                // Other pragmas (pack_matrix, warning, ...) do not change code we accept.
                Ok(())
            }
            "error" => {
                // The message as written: spaces only where the source had them.
                let mut msg = String::new();
                for (n, t) in rest.iter().enumerate() {
                    if n > 0 && t.space {
                        msg.push(' ');
                    }
                    msg.push_str(&t.spelling());
                }
                Err(Error::new(pos, format!("#error {msg}")).len(5))
            }
            "warning" => Ok(()),
            other => {
                Err(Error::new(pos, format!("unknown directive `#{other}`"))
                    .len(other.len() as u32))
            }
        }
    }

    /// Checks `#line N ["file"]` (macros in it expanded, as C allows) and
    /// gives the new number and, when a file is named, its file-table index.
    fn line_directive(&mut self, name_tok: &Token, rest: &[Token]) -> Result<(u32, Option<u32>)> {
        let pos = name_tok.pos;
        let expanded;
        let rest = if rest.iter().any(|t| t.ident().is_some()) {
            expanded = self.expand(rest.to_vec())?;
            &expanded[..]
        } else {
            rest
        };
        let number = match rest.first() {
            // C's limit is 2147483647; 0 cannot name a line.
            Some(Token {
                tok: Tok::Int(n, _),
                ..
            }) if (1..=2_147_483_647).contains(n) => *n as u32,
            Some(t) => {
                return Err(
                    Error::new(t.pos, "#line needs a line number from 1 to 2147483647")
                        .len(t.spelling().len() as u32),
                )
            }
            None => return Err(Error::new(pos, "#line needs a line number").len(4)),
        };
        let file = match rest.get(1) {
            None => None,
            Some(Token {
                tok: Tok::Str(s), ..
            }) => {
                let path = PathBuf::from(&**s);
                // One file-table entry per name, so debug info has one source per name.
                let k = match self.files.iter().position(|f| *f == path) {
                    Some(k) => k,
                    None => {
                        self.files.push(path);
                        self.files.len() - 1
                    }
                };
                Some(k as u32)
            }
            Some(t) => {
                return Err(
                    Error::new(t.pos, "#line takes a file name in double quotes")
                        .len(t.spelling().len() as u32),
                )
            }
        };
        if let Some(t) = rest.get(2) {
            return Err(
                Error::new(t.pos, "unexpected token after #line").len(t.spelling().len() as u32)
            );
        }
        Ok((number, file))
    }

    fn define(&mut self, pos: Pos, rest: &[Token]) -> Result<()> {
        let Some(name) = rest.first().and_then(Token::ident) else {
            return Err(Error::new(pos, "#define needs a macro name"));
        };
        if name == "defined" {
            return Err(Error::new(rest[0].pos, "`defined` cannot be a macro name"));
        }
        let mut body_start = 1;
        let mut params = None;
        let mut variadic = false;
        // Function-like only when `(` follows the name with no space between.
        if rest.get(1).is_some_and(|t| t.is("(") && !t.space) {
            let mut ps = Vec::new();
            let mut k = 2;
            loop {
                let t = rest
                    .get(k)
                    .ok_or_else(|| Error::new(pos, "unterminated macro parameter list"))?;
                if t.is(")") {
                    k += 1;
                    break;
                }
                if t.is("...") {
                    variadic = true;
                    ps.push(Rc::from("__VA_ARGS__"));
                } else if let Some(p) = t.ident() {
                    ps.push(Rc::from(p));
                } else {
                    return Err(Error::new(t.pos, "expected a macro parameter name"));
                }
                k += 1;
                match rest.get(k) {
                    Some(t) if t.is(",") => k += 1,
                    Some(t) if t.is(")") => {}
                    _ => return Err(Error::new(t.pos, "expected `,` or `)` in macro parameters")),
                }
            }
            body_start = k;
            params = Some(ps);
        }
        let body = rest[body_start..].to_vec();
        if body.first().is_some_and(|t| t.is("##")) || body.last().is_some_and(|t| t.is("##")) {
            return Err(Error::new(pos, "`##` cannot start or end a macro body"));
        }
        self.macros.insert(
            Rc::from(name),
            Macro {
                params,
                variadic,
                body,
            },
        );
        Ok(())
    }
}

/// A preprocessing error and the file table its position indexes.
pub struct Failure {
    pub error: Error,
    pub files: Vec<PathBuf>,
}

/// Preprocesses `text` (the contents of `path`).
/// What the preprocessor starts from.
pub struct Setup<'o> {
    /// `-I`, searched after the including file's folder.
    pub include_dirs: &'o [PathBuf],
    /// The compiler's own macros (`__spirv__`, ...), before `defines`.
    pub predefined: &'o [(&'o str, String)],
    /// `-D NAME=VALUE`.
    pub defines: &'o [(String, String)],
    /// `-Zpr`: matrices are row-major until a `#pragma pack_matrix` says otherwise.
    pub row_major: bool,
}

/// Preprocesses `text` with DXC's predefined macros for a library target
/// and the given `-I` and `-D`.
pub fn preprocess(
    path: &Path,
    text: &str,
    loader: &mut dyn FileLoader,
    include_dirs: &[PathBuf],
    defines: &[(String, String)],
) -> std::result::Result<Output, Box<Failure>> {
    let predefined = crate::HlslOptions::default().predefined_macros();
    let setup = Setup {
        include_dirs,
        predefined: &predefined,
        defines,
        row_major: false,
    };
    preprocess_with(path, text, loader, &setup)
}

/// Preprocesses `text` as `setup` says.
pub fn preprocess_with(
    path: &Path,
    text: &str,
    loader: &mut dyn FileLoader,
    setup: &Setup,
) -> std::result::Result<Output, Box<Failure>> {
    let pp = match Preprocessor::new(loader, setup) {
        Ok(p) => p,
        Err(error) => {
            return Err(Box::new(Failure {
                error,
                files: Vec::new(),
            }))
        }
    };
    // The file table is needed to render an error, so keep it on failure.
    let mut pp = pp;
    match pp.file(path, text, None) {
        Ok(()) if setup.row_major && !pp.out.is_empty() => {
            // `-Zpr` is a `#pragma pack_matrix(row_major)` before the first token.
            let mut t = pp.out[0].clone();
            t.tok = Tok::Punct(PACK_ROW_MAJOR);
            pp.out.insert(0, t);
            Ok(Output {
                tokens: pp.out,
                files: pp.files,
                warnings: pp.warnings,
            })
        }
        Ok(()) => Ok(Output {
            tokens: pp.out,
            files: pp.files,
            warnings: pp.warnings,
        }),
        Err(error) => Err(Box::new(Failure {
            error,
            files: pp.files,
        })),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pp_with(
        files: &[(&str, &str)],
        defines: &[(&str, &str)],
    ) -> std::result::Result<String, String> {
        let mut loader = MemLoader(
            files
                .iter()
                .map(|(p, t)| (PathBuf::from(p), t.to_string()))
                .collect(),
        );
        let defs: Vec<(String, String)> = defines
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        let main = files[0];
        match preprocess(
            Path::new(main.0),
            main.1,
            &mut loader,
            &[PathBuf::from("inc")],
            &defs,
        ) {
            Ok(o) => Ok(o
                .tokens
                .iter()
                .map(Token::spelling)
                .collect::<Vec<_>>()
                .join(" ")),
            Err(f) => Err(format!(
                "{}:{}: {} | {}",
                f.error.pos.line,
                f.error.pos.col,
                f.error.message,
                f.error.notes.join(" | ")
            )),
        }
    }

    fn pp(s: &str) -> String {
        pp_with(&[("main.hlsl", s)], &[]).unwrap()
    }

    #[test]
    fn object_and_function_macros() {
        assert_eq!(pp("#define N 4\nfloat a[N];"), "float a [ 4 ] ;");
        assert_eq!(
            pp("#define SQ(x) ((x)*(x))\nSQ(a+1)"),
            "( ( a + 1 ) * ( a + 1 ) )"
        );
        assert_eq!(pp("#define F (x)\nF"), "( x )");
        assert_eq!(pp("#define S(x) #x\nS(a  +  b)"), "\"a + b\"");
        assert_eq!(pp("#define CAT(a,b) a##b\nCAT(foo,3) CAT(,x)"), "foo3 x");
        assert_eq!(
            pp("#define V(f, ...) f(__VA_ARGS__)\nV(g, 1, 2) V(h)"),
            "g ( 1 , 2 ) h ( )"
        );
        // Self-reference does not loop.
        assert_eq!(pp("#define A A+1\nA"), "A + 1");
        assert_eq!(pp("#define A B\n#define B A\nA"), "A");
        // Arguments are expanded before substitution.
        assert_eq!(pp("#define ONE 1\n#define ID(x) x\nID(ONE)"), "1");
        assert_eq!(pp("#define A 1\n#undef A\nA"), "A");
    }

    /// The expansion budget counts what macros produce, not the file's own
    /// tokens: a file of more plain tokens than the budget preprocesses.
    #[test]
    fn big_files_are_not_macro_bombs() {
        let text = "a ".repeat(EXPANSION_BUDGET + 10);
        let out = pp_with(&[("main.hlsl", &text)], &[]).unwrap();
        assert_eq!(out.len(), text.len() - 1);
        let bomb = "#define A0 x\n".to_string()
            + &(1..30)
                .map(|i| format!("#define A{i} A{p} A{p}\n", p = i - 1))
                .collect::<String>()
            + "A29\n";
        let e = pp_with(&[("main.hlsl", &bomb)], &[]).unwrap_err();
        assert!(e.contains("macro expansion does not terminate"), "{e}");
    }

    #[test]
    fn conditionals() {
        let s = "#define X 2\n#if X > 1 && defined(X)\na\n#elif 1\nb\n#else\nc\n#endif\n#ifdef Y\nd\n#endif\n#ifndef Y\ne\n#endif";
        assert_eq!(pp(s), "a e");
        assert_eq!(
            pp("#if 0\n#if 1\na\n#else\nb\n#endif\n#elif (3 % 2) == 1 ? 1 : 0\nc\n#endif"),
            "c"
        );
        assert_eq!(pp("#if UNDEFINED_NAME\na\n#else\nb\n#endif"), "b");
        assert!(pp_with(&[("m", "#if 1/0\n#endif")], &[])
            .unwrap_err()
            .contains("division by zero"));
        assert!(pp_with(&[("m", "#if 1\n")], &[])
            .unwrap_err()
            .contains("unterminated"));
        assert!(pp_with(&[("m", "#endif")], &[])
            .unwrap_err()
            .contains("without #if"));
    }

    #[test]
    fn command_line_defines() {
        assert_eq!(
            pp_with(
                &[("m", "#if FOO == 3\nBAR\n#endif")],
                &[("FOO", "3"), ("BAR", "x y")]
            )
            .unwrap(),
            "x y"
        );
    }

    #[test]
    fn includes_once_guards_and_errors() {
        let files = [
            ("dir/main.hlsl", "#include \"a.hlsli\"\n#include \"a.hlsli\"\n#include <b.hlsli>\n#include \"b.hlsli\"\nend"),
            ("dir/a.hlsli", "#pragma once\nA"),
            ("inc/b.hlsli", "#ifndef B_H\n#define B_H\nB\n#endif"),
        ];
        assert_eq!(pp_with(&files, &[]).unwrap(), "A B end");
        let missing = pp_with(&[("main.hlsl", "#include \"nope.h\"")], &[]).unwrap_err();
        assert!(
            missing.starts_with("1:2: cannot find include file `nope.h`"),
            "{missing}"
        );
        let cyc = pp_with(
            &[
                ("main.hlsl", "#include \"x.h\""),
                ("x.h", "\n#include \"y.h\""),
                ("y.h", "#include \"x.h\""),
            ],
            &[],
        )
        .unwrap_err();
        assert!(cyc.contains("include cycle"), "{cyc}");
        assert!(cyc.contains("`y.h` included from x.h:2"), "{cyc}");
        assert!(cyc.contains("`x.h` included from main.hlsl:1"), "{cyc}");
    }

    #[test]
    fn error_directive_and_positions() {
        let e = pp_with(&[("m", "\n  #error stop here")], &[]).unwrap_err();
        assert!(e.starts_with("2:4: #error stop here"), "{e}");
        let mut loader = MemLoader::default();
        let o = preprocess(
            Path::new("m"),
            "#define P(x) x + 1\n\n  P(y)",
            &mut loader,
            &[],
            &[],
        )
        .ok()
        .unwrap();
        let p: Vec<(u32, u32)> = o.tokens.iter().map(|t| (t.pos.line, t.pos.col)).collect();
        assert_eq!(p, vec![(3, 5), (3, 3), (3, 3)]);
    }

    /// (file name, line, column) of every output token.
    fn positions(files: &[(&str, &str)]) -> Vec<(String, u32, u32)> {
        let mut loader = MemLoader(
            files
                .iter()
                .map(|(p, t)| (PathBuf::from(p), t.to_string()))
                .collect(),
        );
        let o = preprocess(Path::new(files[0].0), files[0].1, &mut loader, &[], &[])
            .ok()
            .unwrap();
        o.tokens
            .iter()
            .map(|t| {
                let f = o.files[t.pos.file as usize].display().to_string();
                (f, t.pos.line, t.pos.col)
            })
            .collect()
    }

    #[test]
    fn line_directive_renumbers_what_follows() {
        let p = positions(&[(
            "m.hlsl",
            "a\n#line 100 \"virtual.hlsl\"\nb\n\n  c\n#line 7\nd",
        )]);
        let want = [
            ("m.hlsl", 1, 1),
            ("virtual.hlsl", 100, 1),
            ("virtual.hlsl", 102, 3),
            ("virtual.hlsl", 7, 1),
        ];
        let want: Vec<(String, u32, u32)> = want
            .iter()
            .map(|(f, l, c)| (f.to_string(), *l, *c))
            .collect();
        assert_eq!(p, want);
        // `__LINE__` and errors see the new numbers.
        assert_eq!(pp("#line 41\n__LINE__"), "41");
        let e = pp_with(&[("m", "#line 9 \"v.h\"\n\n#error here")], &[]).unwrap_err();
        assert!(e.starts_with("10:2: #error here"), "{e}");
        // Macros in the arguments are expanded; a macro body lands where it is used.
        let p = positions(&[(
            "m",
            "#define N 50\n#define F \"f.h\"\n#define M x y\n#line N F\n M",
        )]);
        assert_eq!(p, vec![("f.h".into(), 50, 2), ("f.h".into(), 50, 2)]);
    }

    #[test]
    fn line_directive_in_includes_and_skipped_groups() {
        // The renumbering stays in its file: the includer keeps counting after the include.
        let p = positions(&[
            ("main.hlsl", "#include \"a.h\"\nz"),
            ("a.h", "#line 20 \"gen.h\"\ny"),
        ]);
        assert_eq!(p, vec![("gen.h".into(), 20, 1), ("main.hlsl".into(), 2, 1)]);
        // Includes after `#line "x"` still resolve next to the real file.
        let p = positions(&[
            (
                "dir/main.hlsl",
                "#line 5 \"elsewhere/v.hlsl\"\n#include \"b.h\"\nw",
            ),
            ("dir/b.h", "q"),
        ]);
        assert_eq!(
            p,
            vec![("dir/b.h".into(), 1, 1), ("elsewhere/v.hlsl".into(), 6, 1)]
        );
        // Inside a group not taken it is not even checked, as in C.
        assert_eq!(pp("#if 0\n#line x\n#endif\nv"), "v");
    }

    #[test]
    fn line_directive_errors_at_their_arguments() {
        let err = |s: &str| pp_with(&[("m", s)], &[]).unwrap_err();
        let e = err("\n#line");
        assert!(e.starts_with("2:2: #line needs a line number"), "{e}");
        let e = err("#line x");
        assert!(
            e.starts_with("1:7: #line needs a line number from 1 to 2147483647"),
            "{e}"
        );
        let e = err("#line 0");
        assert!(
            e.starts_with("1:7: #line needs a line number from 1"),
            "{e}"
        );
        let e = err("#line 4294967296");
        assert!(
            e.starts_with("1:7: #line needs a line number from 1"),
            "{e}"
        );
        let e = err("#line 3 file");
        assert!(
            e.starts_with("1:9: #line takes a file name in double quotes"),
            "{e}"
        );
        let e = err("#line 3 \"f\" 4");
        assert!(e.starts_with("1:13: unexpected token after #line"), "{e}");
    }
}
