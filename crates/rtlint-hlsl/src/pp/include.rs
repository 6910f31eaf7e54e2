//! `#include`: where files are looked for (a loader, the include folders, a
//! case-insensitive match), include guards, and the include chain of errors.

use super::*;

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
        std::fs::read(path).ok().map(crate::decode_source)
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

impl Preprocessor<'_> {
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

    pub(super) fn include(&mut self, pos: Pos, rest: &[Token]) -> Result<()> {
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
}
