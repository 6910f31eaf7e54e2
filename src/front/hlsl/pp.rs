//! Preprocessor: directives, includes and macro expansion over tokens.
//!
//! Every output token keeps a position in a real file: source tokens their
//! own, tokens produced by a macro the position of the macro's name at the
//! invocation (that is where a user looks when a diagnostic points there).

use super::error::{Error, Pos, Result};
use super::lex::{lex, Tok, Token};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Where `#include` looks for files; tests and fuzzers read from memory.
pub trait FileLoader: Send {
    fn read(&mut self, path: &Path) -> Option<String>;
    /// The names in a folder (files and folders), for matching an include
    /// whose case differs from the file's.
    fn list(&mut self, _dir: &Path) -> Vec<String> {
        Vec::new()
    }
}

pub struct FsLoader;

impl FileLoader for FsLoader {
    fn read(&mut self, path: &Path) -> Option<String> {
        std::fs::read_to_string(path).ok()
    }

    fn list(&mut self, dir: &Path) -> Vec<String> {
        let dir = if dir.as_os_str().is_empty() {
            Path::new(".")
        } else {
            dir
        };
        std::fs::read_dir(dir)
            .map(|r| {
                r.filter_map(|e| e.ok()?.file_name().into_string().ok())
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// Files from a map; anything else is missing.
#[derive(Default)]
pub struct MemLoader(pub HashMap<PathBuf, String>);

impl FileLoader for MemLoader {
    fn read(&mut self, path: &Path) -> Option<String> {
        self.0.get(path).cloned()
    }

    fn list(&mut self, dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = self
            .0
            .keys()
            .filter_map(|p| p.strip_prefix(dir).ok()?.components().next())
            .filter_map(|c| c.as_os_str().to_str().map(String::from))
            .collect();
        names.sort();
        names.dedup();
        names
    }
}

/// `path` with each component matched without regard to case where the exact
/// name is missing (Windows file systems ignore case; DXR code relies on it).
fn case_insensitive_match(loader: &mut dyn FileLoader, path: &Path) -> Option<PathBuf> {
    use std::path::Component;
    let mut out = PathBuf::new();
    let mut changed = false;
    for c in path.components() {
        match c {
            Component::Normal(name) => {
                let name = name.to_str()?;
                let names = loader.list(&out);
                if names.iter().any(|n| n == name) {
                    out.push(name);
                } else {
                    let m = names.iter().find(|n| n.eq_ignore_ascii_case(name))?;
                    out.push(m);
                    changed = true;
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    changed.then_some(out)
}

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
    pub fn new(
        loader: &'a mut dyn FileLoader,
        include_dirs: &[PathBuf],
        defines: &[(String, String)],
    ) -> Result<Self> {
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
        // user's `-D`s (which may replace them). Shader model 6.5: what this
        // compiler implements.
        let predefined = [
            ("__spirv__", "1"),
            ("__hlsl_dx_compiler", "1"),
            ("__HLSL_VERSION", "2021"),
            ("__SHADER_TARGET_MAJOR", "6"),
            ("__SHADER_TARGET_MINOR", "5"),
        ];
        for (name, value) in predefined {
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

    fn include_chain(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for (file, from) in self.stack.iter().rev() {
            let p = self.files[*file as usize].display();
            match from {
                Some(at) => notes.push(format!(
                    "`{p}` included from {}:{}",
                    self.files[at.file as usize].display(),
                    at.line
                )),
                None => notes.push(format!("`{p}` is the file being compiled")),
            }
        }
        notes
    }

    fn include(&mut self, pos: Pos, rest: &[Token]) -> Result<()> {
        let expanded;
        let rest = if rest.first().is_some_and(|t| t.ident().is_some()) {
            expanded = self.expand(rest.to_vec())?;
            &expanded[..]
        } else {
            rest
        };
        let (name, quoted) = match rest.first().map(|t| &t.tok) {
            Some(Tok::Str(s)) => (s.to_string(), true),
            Some(Tok::Punct("<")) => {
                let mut s = String::new();
                let mut k = 1;
                loop {
                    match rest.get(k) {
                        Some(t) if t.is(">") => break,
                        Some(t) => {
                            if t.space && !s.is_empty() {
                                s.push(' ');
                            }
                            s.push_str(&t.spelling());
                        }
                        None => return Err(Error::new(pos, "unterminated `<file>` in #include")),
                    }
                    k += 1;
                }
                (s, false)
            }
            _ => return Err(Error::new(pos, "#include needs \"file\" or <file>")),
        };
        // Windows separators: `#include "util\Compat.h"`.
        let name = name.replace('\\', "/");
        let current = self.stack.last().map(|s| s.0).unwrap_or(0);
        let mut candidates = Vec::new();
        if quoted {
            let dir = self.files[current as usize]
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default();
            candidates.push(dir.join(&name));
        }
        for d in &self.include_dirs {
            candidates.push(d.join(&name));
        }
        let mut found = None;
        for c in &candidates {
            if let Some(text) = self.loader.read(c) {
                found = Some((c.clone(), text));
                break;
            }
        }
        if found.is_none() {
            // Windows ignores case: take a file whose name differs only in case, and say so.
            for c in &candidates {
                let Some(m) = case_insensitive_match(self.loader, c) else {
                    continue;
                };
                if let Some(text) = self.loader.read(&m) {
                    self.warnings.push(Error::new(
                        pos,
                        format!(
                            "include `{name}` matched `{}` only when ignoring case",
                            m.display()
                        ),
                    ));
                    found = Some((m, text));
                    break;
                }
            }
        }
        let Some((path, text)) = found else {
            let mut e = Error::new(pos, format!("cannot find include file `{name}`"))
                .label("included here");
            for n in self.include_chain() {
                e = e.note(n);
            }
            return Err(e.note(if self.include_dirs.is_empty() {
                "no include directories were given (-I)".to_string()
            } else {
                format!(
                    "searched: {}",
                    self.include_dirs
                        .iter()
                        .map(|d| d.display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }));
        };
        let path = normalize(&path);
        if self.once.contains(&path) {
            return Ok(());
        }
        if self
            .stack
            .iter()
            .any(|(f, _)| normalize(&self.files[*f as usize]) == path)
        {
            // Re-entering a guarded header is harmless; anything else loops forever.
            if let Some(guard) = include_guard(&text) {
                if self.macros.contains_key(guard.as_str()) {
                    return Ok(());
                }
            }
            let mut e = Error::new(pos, format!("include cycle: `{name}` includes itself"))
                .label("this #include re-enters a file being included");
            for n in self.include_chain() {
                e = e.note(n);
            }
            return Err(e);
        }
        if self.stack.len() >= MAX_INCLUDE_DEPTH {
            return Err(Error::new(pos, "includes nested too deeply"));
        }
        self.file(&path, &text, Some(pos))
    }

    /// Evaluates the condition of `#if`/`#elif`.
    fn eval_if(&mut self, line: &[Token], pos: Pos) -> Result<i64> {
        // `defined X` / `defined(X)` is resolved before expansion.
        let mut toks = Vec::new();
        let mut k = 0;
        while k < line.len() {
            let t = &line[k];
            if t.ident() == Some("defined") {
                let (name, next) = if line.get(k + 1).is_some_and(|t| t.is("(")) {
                    let n = line.get(k + 2).and_then(Token::ident);
                    if !line.get(k + 3).is_some_and(|t| t.is(")")) {
                        return Err(Error::new(t.pos, "expected `defined(NAME)`"));
                    }
                    (n, k + 4)
                } else {
                    (line.get(k + 1).and_then(Token::ident), k + 2)
                };
                let name = name.ok_or_else(|| Error::new(t.pos, "`defined` needs a name"))?;
                let mut d = t.clone();
                d.tok = Tok::Int(self.macros.contains_key(name) as u64, false);
                toks.push(d);
                k = next;
            } else {
                toks.push(t.clone());
                k += 1;
            }
        }
        let toks = self.expand(toks)?;
        if toks.is_empty() {
            return Err(Error::new(pos, "#if needs an expression"));
        }
        let mut e = CondExpr { t: &toks, i: 0 };
        let v = e.ternary()?;
        if let Some(t) = toks.get(e.i) {
            return Err(Error::new(
                t.pos,
                format!("unexpected `{}` in #if expression", t.spelling()),
            ));
        }
        Ok(v)
    }

    /// Expands macros in `input` (rescanning results together with what follows).
    fn expand(&mut self, input: Vec<Token>) -> Result<Vec<Token>> {
        let mut queue: std::collections::VecDeque<Token> = input.into();
        let mut out = Vec::new();
        while let Some(t) = queue.pop_front() {
            let Some(name) = t.ident() else {
                out.push(t);
                continue;
            };
            if name == "__LINE__" {
                let mut n = t.clone();
                n.tok = Tok::Int(t.pos.line as u64, false);
                out.push(n);
                continue;
            }
            let Some(m) = self.macros.get(name) else {
                out.push(t);
                continue;
            };
            if t.hide.iter().any(|h| &**h == name) {
                out.push(t);
                continue;
            }
            let m = m.clone();
            let mut hide = (*t.hide).clone();
            hide.push(Rc::from(name));
            let hide = Rc::new(hide);
            let result = match &m.params {
                None => self.substitute(&m, &[], &t, &hide)?,
                Some(params) => {
                    if !queue.front().is_some_and(|n| n.is("(")) {
                        out.push(t);
                        continue;
                    }
                    queue.pop_front();
                    let args = collect_args(&mut queue, &t)?;
                    let args = if params.is_empty() && args.len() == 1 && args[0].is_empty() {
                        Vec::new()
                    } else {
                        args
                    };
                    let args = if m.variadic {
                        fold_variadic(args, params.len())
                    } else {
                        args
                    };
                    if args.len() != params.len() && !(m.variadic && args.len() + 1 == params.len())
                    {
                        return Err(Error::new(
                            t.pos,
                            format!(
                                "macro `{name}` takes {} argument(s), {} given",
                                params.len(),
                                args.len()
                            ),
                        )
                        .len(name.len() as u32));
                    }
                    let mut args = args;
                    while args.len() < params.len() {
                        args.push(Vec::new());
                    }
                    self.substitute(&m, &args, &t, &hide)?
                }
            };
            // Only what macros produce counts: a big file of plain code is
            // not an expansion that does not terminate.
            self.budget += result.len().max(1);
            if self.budget > EXPANSION_BUDGET {
                return Err(Error::new(t.pos, "macro expansion does not terminate"));
            }
            for r in result.into_iter().rev() {
                queue.push_front(r);
            }
        }
        Ok(out)
    }

    /// The macro body with parameters replaced, `#` and `##` applied; every
    /// token takes the invocation's position.
    fn substitute(
        &mut self,
        m: &Macro,
        args: &[Vec<Token>],
        at: &Token,
        hide: &Rc<Vec<Rc<str>>>,
    ) -> Result<Vec<Token>> {
        let params = m.params.as_deref().unwrap_or(&[]);
        let param = |t: &Token| -> Option<usize> {
            let id = t.ident()?;
            params.iter().position(|p| &**p == id)
        };
        let body = &m.body;
        // Pieces: Some(tokens) for real tokens; pasting works on the spelling.
        let mut out: Vec<Token> = Vec::new();
        let mut k = 0;
        // Whether the last pushed piece may be the left side of `##` (a placemarker
        // is represented by pushing nothing and remembering it).
        let mut last_was_empty_arg = false;
        while k < body.len() {
            let t = &body[k];
            if t.is("#") && m.params.is_some() {
                let idx = body.get(k + 1).and_then(&param).ok_or_else(|| {
                    Error::new(at.pos, "`#` must be followed by a macro parameter")
                })?;
                let mut s = String::new();
                for (n, a) in args[idx].iter().enumerate() {
                    if n > 0 && a.space {
                        s.push(' ');
                    }
                    s.push_str(&a.spelling());
                }
                let mut st = at.clone();
                st.tok = Tok::Str(Rc::from(s.as_str()));
                st.hide = hide.clone();
                out.push(st);
                k += 2;
                last_was_empty_arg = false;
                continue;
            }
            if t.is("##") {
                k += 1;
                let Some(rhs) = body.get(k) else { break };
                let rhs_toks: Vec<Token> = match param(rhs) {
                    Some(idx) => args[idx].clone(),
                    None => vec![rhs.clone()],
                };
                k += 1;
                if last_was_empty_arg || out.is_empty() {
                    out.extend(rhs_toks.into_iter().map(|mut r| {
                        r.pos = at.pos;
                        r.hide = hide.clone();
                        r
                    }));
                    last_was_empty_arg = false;
                    continue;
                }
                let mut rest = rhs_toks.into_iter();
                if let Some(first) = rest.next() {
                    let left = out.pop().unwrap_or_else(|| unreachable!());
                    let text = format!("{}{}", left.spelling(), first.spelling());
                    let pasted = lex(&text, at.pos.file).ok().filter(|v| v.len() == 1);
                    let Some(mut p) = pasted.and_then(|mut v| v.pop()) else {
                        return Err(Error::new(
                            at.pos,
                            format!(
                                "pasting `{}` and `{}` does not give one token",
                                left.spelling(),
                                first.spelling()
                            ),
                        ));
                    };
                    p.pos = at.pos;
                    p.space = left.space;
                    p.bol = false;
                    p.hide = hide.clone();
                    out.push(p);
                }
                out.extend(rest.map(|mut r| {
                    r.pos = at.pos;
                    r.hide = hide.clone();
                    r
                }));
                continue;
            }
            if let Some(idx) = param(t) {
                let next_is_paste = body.get(k + 1).is_some_and(|n| n.is("##"));
                let toks = if next_is_paste {
                    args[idx].clone()
                } else {
                    self.expand(args[idx].clone())?
                };
                last_was_empty_arg = toks.is_empty();
                let first = out.len();
                // Argument tokens keep their own (real) positions.
                out.extend(toks.into_iter().map(|mut r| {
                    r.bol = false;
                    r
                }));
                if let Some(f) = out.get_mut(first) {
                    f.space = t.space;
                }
                k += 1;
                continue;
            }
            let mut c = t.clone();
            c.pos = at.pos;
            c.bol = false;
            c.hide = hide.clone();
            out.push(c);
            last_was_empty_arg = false;
            k += 1;
        }
        if let Some(f) = out.first_mut() {
            f.space = at.space;
            f.bol = at.bol;
        }
        Ok(out)
    }
}

/// Reads a macro's arguments after its `(`: top-level commas split them.
fn collect_args(
    queue: &mut std::collections::VecDeque<Token>,
    at: &Token,
) -> Result<Vec<Vec<Token>>> {
    let mut args = vec![Vec::new()];
    let mut depth = 0usize;
    loop {
        let Some(t) = queue.pop_front() else {
            return Err(Error::new(at.pos, "unterminated macro invocation")
                .label("this macro's `(` is never closed"));
        };
        if t.is("(") {
            depth += 1;
        } else if t.is(")") {
            if depth == 0 {
                break;
            }
            depth -= 1;
        } else if t.is(",") && depth == 0 {
            args.push(Vec::new());
            continue;
        }
        args.last_mut().unwrap_or_else(|| unreachable!()).push(t);
    }
    Ok(args)
}

/// Joins the arguments past the named ones into `__VA_ARGS__`, commas kept.
fn fold_variadic(mut args: Vec<Vec<Token>>, nparams: usize) -> Vec<Vec<Token>> {
    if args.len() <= nparams {
        return args;
    }
    let extra = args.split_off(nparams - 1);
    let mut va = Vec::new();
    for (n, a) in extra.into_iter().enumerate() {
        if n > 0 {
            let mut comma = a.first().cloned().unwrap_or_else(|| va_comma(&va));
            comma.tok = Tok::Punct(",");
            va.push(comma);
        }
        va.extend(a);
    }
    args.push(va);
    args
}

fn va_comma(prev: &[Token]) -> Token {
    let mut t = prev.last().cloned().unwrap_or(Token {
        tok: Tok::Punct(","),
        pos: Pos::default(),
        space: false,
        bol: false,
        hide: Rc::new(Vec::new()),
    });
    t.tok = Tok::Punct(",");
    t
}

/// The guard macro of a header written `#ifndef X` / `#define X` ... `#endif`.
fn include_guard(text: &str) -> Option<String> {
    let toks = lex(text, 0).ok()?;
    let is = |k: usize, p: &str| toks.get(k).is_some_and(|t| t.is(p) || t.ident() == Some(p));
    if is(0, "#") && toks[0].bol && is(1, "ifndef") && is(3, "#") && toks[3].bol && is(4, "define")
    {
        let a = toks.get(2)?.ident()?;
        let b = toks.get(5)?.ident()?;
        if a == b {
            return Some(a.to_string());
        }
    }
    None
}

fn normalize(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir
                if matches!(
                    out.components().next_back(),
                    Some(std::path::Component::Normal(_))
                ) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// Integer expressions of `#if`, with C's precedence.
struct CondExpr<'t> {
    t: &'t [Token],
    i: usize,
}

impl CondExpr<'_> {
    fn peek(&self, p: &str) -> bool {
        self.t.get(self.i).is_some_and(|t| t.is(p))
    }
    fn pos(&self) -> Pos {
        self.t
            .get(self.i)
            .or_else(|| self.t.last())
            .map(|t| t.pos)
            .unwrap_or_default()
    }
    fn ternary(&mut self) -> Result<i64> {
        let c = self.binary(0)?;
        if self.peek("?") {
            self.i += 1;
            let a = self.ternary()?;
            if !self.peek(":") {
                return Err(Error::new(self.pos(), "expected `:` in #if expression"));
            }
            self.i += 1;
            let b = self.ternary()?;
            return Ok(if c != 0 { a } else { b });
        }
        Ok(c)
    }
    fn binary(&mut self, min: u8) -> Result<i64> {
        let mut lhs = self.unary()?;
        while let Some(Tok::Punct(op)) = self.t.get(self.i).map(|t| &t.tok) {
            let prec = match *op {
                "||" => 1,
                "&&" => 2,
                "|" => 3,
                "^" => 4,
                "&" => 5,
                "==" | "!=" => 6,
                "<" | ">" | "<=" | ">=" => 7,
                "<<" | ">>" => 8,
                "+" | "-" => 9,
                "*" | "/" | "%" => 10,
                _ => break,
            };
            if prec <= min && min > 0 || prec < min {
                break;
            }
            let op = *op;
            let at = self.pos();
            self.i += 1;
            let rhs = self.binary(prec)?;
            lhs = match op {
                "||" => ((lhs != 0) || (rhs != 0)) as i64,
                "&&" => ((lhs != 0) && (rhs != 0)) as i64,
                "|" => lhs | rhs,
                "^" => lhs ^ rhs,
                "&" => lhs & rhs,
                "==" => (lhs == rhs) as i64,
                "!=" => (lhs != rhs) as i64,
                "<" => (lhs < rhs) as i64,
                ">" => (lhs > rhs) as i64,
                "<=" => (lhs <= rhs) as i64,
                ">=" => (lhs >= rhs) as i64,
                "<<" => lhs.wrapping_shl(rhs as u32),
                ">>" => lhs.wrapping_shr(rhs as u32),
                "+" => lhs.wrapping_add(rhs),
                "-" => lhs.wrapping_sub(rhs),
                "*" => lhs.wrapping_mul(rhs),
                "/" | "%" => {
                    if rhs == 0 {
                        return Err(Error::new(at, "division by zero in #if expression"));
                    }
                    if op == "/" {
                        lhs.wrapping_div(rhs)
                    } else {
                        lhs.wrapping_rem(rhs)
                    }
                }
                _ => unreachable!(),
            };
        }
        Ok(lhs)
    }
    fn unary(&mut self) -> Result<i64> {
        let Some(t) = self.t.get(self.i) else {
            return Err(Error::new(self.pos(), "#if expression ends early"));
        };
        self.i += 1;
        match &t.tok {
            Tok::Int(v, _) | Tok::Long(v, _) => Ok(*v as i64),
            // Identifiers left after expansion are 0, as in C.
            Tok::Ident(_) => Ok(0),
            Tok::Punct("!") => Ok((self.unary()? == 0) as i64),
            Tok::Punct("~") => Ok(!self.unary()?),
            Tok::Punct("-") => Ok(self.unary()?.wrapping_neg()),
            Tok::Punct("+") => self.unary(),
            Tok::Punct("(") => {
                let v = self.ternary()?;
                if !self.peek(")") {
                    return Err(Error::new(self.pos(), "expected `)` in #if expression"));
                }
                self.i += 1;
                Ok(v)
            }
            _ => Err(Error::new(
                t.pos,
                format!("unexpected `{}` in #if expression", t.spelling()),
            )),
        }
    }
}

/// A preprocessing error and the file table its position indexes.
pub struct Failure {
    pub error: Error,
    pub files: Vec<PathBuf>,
}

/// Preprocesses `text` (the contents of `path`).
pub fn preprocess(
    path: &Path,
    text: &str,
    loader: &mut dyn FileLoader,
    include_dirs: &[PathBuf],
    defines: &[(String, String)],
) -> std::result::Result<Output, Box<Failure>> {
    let pp = match Preprocessor::new(loader, include_dirs, defines) {
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
