//! GLSL through glslang: `glslangValidator` (on `PATH`, or the program named
//! by `RTLINT_GLSLANG`) compiles the file to SPIR-V with `-g`, whose
//! `OpLine`s and embedded source lead findings back to the GLSL lines. (`-gV`
//! is not used: glslang 12 records one source file for a whole `#include`
//! tree there, and writes invalid modules for `buffer_reference` types.)

use super::FrontOptions;
use crate::diag::{InputError, InputErrorKind};
use crate::shader::Location;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Extensions glslang maps to a ray-tracing stage by itself.
pub const RAY_TRACING_EXTENSIONS: &[&str] = &["rgen", "rchit", "rmiss", "rahit", "rint", "rcall"];

/// Extensions of other GLSL stages, linted when the file uses `rayQueryEXT`.
pub const RAY_QUERY_EXTENSIONS: &[&str] = &["comp", "frag", "vert", "mesh", "task"];

/// The stage extension of a GLSL file: `rgen` for `a.rgen` and for
/// `a.rgen.glsl` (glslang needs the stage, and tells it from the extension).
pub fn stage_extension(path: &Path) -> Option<&'static str> {
    let name = path.file_name()?.to_str()?.to_ascii_lowercase();
    let mut parts = name.rsplit('.');
    let last = parts.next()?;
    let ext = if last == "glsl" { parts.next()? } else { last };
    RAY_TRACING_EXTENSIONS
        .iter()
        .chain(RAY_QUERY_EXTENSIONS)
        .find(|e| **e == ext)
        .copied()
}

/// The glslang program to run.
pub fn glslang() -> PathBuf {
    std::env::var_os("RTLINT_GLSLANG")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("glslangValidator"))
}

/// What `glslang() --version` prints (empty when it does not run), asked
/// once per process: part of a GLSL input's cache key, since another
/// glslang writes other SPIR-V.
pub fn version() -> &'static str {
    static VERSION: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    VERSION.get_or_init(|| {
        Command::new(glslang())
            .arg("--version")
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
            .unwrap_or_default()
    })
}

/// Where compiled modules are kept between runs (`rtlint check`'s cache
/// folder sets it); `None`: nowhere.
static MODULE_CACHE: std::sync::RwLock<Option<PathBuf>> = std::sync::RwLock::new(None);

/// Keeps compiled GLSL modules in `dir` from now on (`None`: not at all).
/// A module is found again by its source's bytes, the files it included
/// (each checked by content), the glslang that wrote it and the options.
pub fn use_module_cache(dir: Option<PathBuf>) {
    if let Ok(mut c) = MODULE_CACHE.write() {
        *c = dir;
    }
}

/// Modules compiled in this process, by [`key`]: a shader that is an input
/// and named by a pipeline description is compiled once per run.
/// Each module with the scratch file its debug info names and the files it
/// included with their contents' hashes (checked on every use: a server
/// process outlives edits).
type Memo = std::collections::HashMap<u64, Entry>;

#[derive(Clone)]
struct Entry {
    words: Vec<u32>,
    scratch: PathBuf,
    deps: Vec<(u64, PathBuf)>,
}

impl Entry {
    /// Whether every included file still has the contents it had.
    fn fresh(&self) -> bool {
        self.deps
            .iter()
            .all(|(h, f)| std::fs::read(f).is_ok_and(|b| content_hash(&b) == *h))
    }

    /// `scratch PATH`, then `HASH PATH` per included file.
    fn deps_text(&self) -> String {
        let mut t = format!("scratch {}\n", self.scratch.display());
        for (h, f) in &self.deps {
            t.push_str(&format!("{h:016x} {}\n", f.display()));
        }
        t
    }
}
static MEMO: std::sync::Mutex<Option<Memo>> = std::sync::Mutex::new(None);

/// What a module depends on besides the files it includes: glslang, the
/// stage, where includes are searched, the defines, the source's bytes.
fn key(path: &Path, ext: &str, text: &[u8], options: &FrontOptions) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    version().hash(&mut h);
    ext.hash(&mut h);
    let canon = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    path.parent().map(canon).hash(&mut h);
    for d in &options.include_dirs {
        canon(d).hash(&mut h);
    }
    options.defines.hash(&mut h);
    text.hash(&mut h);
    h.finish()
}

fn content_hash(bytes: &[u8]) -> u64 {
    use std::hash::Hasher;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    h.write(bytes);
    h.finish()
}

/// A module kept in the cache folder (`KEY.spv`, and `KEY.deps` as
/// [`Entry::deps_text`] writes it), when its included files are unchanged.
fn cached(dir: &Path, key: u64) -> Option<Entry> {
    let deps = std::fs::read_to_string(dir.join(format!("{key:016x}.deps"))).ok()?;
    let mut lines = deps.lines();
    let scratch = PathBuf::from(lines.next()?.strip_prefix("scratch ")?);
    let mut list = Vec::new();
    for line in lines {
        let (hash, file) = line.split_once(' ')?;
        list.push((u64::from_str_radix(hash, 16).ok()?, PathBuf::from(file)));
    }
    let bytes = std::fs::read(dir.join(format!("{key:016x}.spv"))).ok()?;
    let words = crate::program::words_from_bytes(&bytes, dir).ok()?;
    let e = Entry {
        words,
        scratch,
        deps: list,
    };
    e.fresh().then_some(e)
}

/// The files a compilation included (from glslang's depfile; the scratch
/// copy of the input is not one of them), with their contents' hashes;
/// `None` when one cannot be read back.
fn included(depfile: &str, scratch: &Path) -> Option<Vec<(u64, PathBuf)>> {
    let mut out = Vec::new();
    for file in depfile_paths(depfile) {
        if Path::new(&file) == scratch {
            continue;
        }
        let bytes = std::fs::read(&file).ok()?;
        let file = std::fs::canonicalize(&file).unwrap_or_else(|_| PathBuf::from(&file));
        out.push((content_hash(&bytes), file));
    }
    Some(out)
}

/// Keeps a module in the cache folder. Written to temporary names and
/// renamed, the module last, so a concurrent run never reads half an entry.
fn keep(dir: &Path, key: u64, e: &Entry) {
    if std::fs::create_dir_all(dir).is_err() {
        return;
    }
    let bytes: Vec<u8> = e.words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let deps = e.deps_text();
    let tmp = |ext: &str| dir.join(format!("{key:016x}.{ext}.{}", std::process::id()));
    for (ext, data) in [("deps", deps.as_bytes()), ("spv", bytes.as_slice())] {
        let t = tmp(ext);
        if std::fs::write(&t, data).is_err()
            || std::fs::rename(&t, dir.join(format!("{key:016x}.{ext}"))).is_err()
        {
            let _ = std::fs::remove_file(&t);
            return;
        }
    }
}

/// The prerequisites of a Make-style depfile (`out: a b\ c`), with `\ `
/// read as a space.
fn depfile_paths(text: &str) -> Vec<String> {
    let body = text.split_once(": ").map_or(text, |(_, b)| b);
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut chars = body.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&' ') => {
                cur.push(' ');
                chars.next();
            }
            '\\' if chars.peek() == Some(&'\n') => {
                chars.next();
            }
            c if c.is_whitespace() => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            c => cur.push(c),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Compiles `path` (whose contents are `text`, from disk or standard
/// input) to SPIR-V; also returns the scratch file glslang read, which the
/// debug info names. A module compiled before with the same key (this run,
/// or an earlier one through [`use_module_cache`]) is not compiled again.
pub fn compile(
    path: &Path,
    text: &[u8],
    options: &FrontOptions,
) -> Result<(Vec<u32>, Option<PathBuf>), InputError> {
    let ext = match options.glsl_stage.as_deref().or_else(|| stage_extension(path)) {
        Some(ext) => ext,
        // glslang would print its usage text.
        None => {
            return Err(InputError::new(
                InputErrorKind::UnknownLanguage,
                path,
                format!(
                    "cannot tell the GLSL stage of `{}`: name it with a stage extension (`.rchit`, or `name.rchit.glsl`), pass --stage, or give it under [stages] in rtlint.toml (one of {})",
                    path.display(),
                    crate::shader::GLSL_STAGES.join(", ")
                ),
            ))
        }
    };
    let key = key(path, ext, text, options);
    let memo = MEMO
        .lock()
        .ok()
        .and_then(|m| m.as_ref().and_then(|m| m.get(&key).cloned()))
        .filter(Entry::fresh);
    if let Some(e) = memo {
        return Ok((e.words, Some(e.scratch)));
    }
    let store = MODULE_CACHE.read().ok().and_then(|c| c.clone());
    if let Some(e) = store.as_deref().and_then(|d| cached(d, key)) {
        remember(key, &e);
        return Ok((e.words, Some(e.scratch)));
    }
    let (words, scratch, depfile) = run_glslang(path, ext, text, options)?;
    // Without a readable list of its includes a module is not kept: it
    // could not be checked later.
    if let Some(deps) = included(&depfile, &scratch).filter(|_| !depfile.is_empty()) {
        let e = Entry {
            words,
            scratch,
            deps,
        };
        if let Some(d) = &store {
            keep(d, key, &e);
        }
        remember(key, &e);
        return Ok((e.words, Some(e.scratch)));
    }
    Ok((words, Some(scratch)))
}

fn remember(key: u64, e: &Entry) {
    if let Ok(mut m) = MEMO.lock() {
        m.get_or_insert_with(Memo::new).insert(key, e.clone());
    }
}

/// Runs glslang on a scratch copy of the input: the module, the scratch
/// file's path and glslang's depfile.
fn run_glslang(
    path: &Path,
    ext: &str,
    text: &[u8],
    options: &FrontOptions,
) -> Result<(Vec<u32>, PathBuf, String), InputError> {
    let dir = tempdir(path)?;
    // glslang reads a file: the text goes into one named like the input, so
    // the stage still follows from the extension.
    let input = dir.join(format!("input.{ext}"));
    let output = dir.join("out.spv");
    let depfile = dir.join("out.d");
    std::fs::write(&input, text).map_err(|e| super::io_error(&input, &e))?;
    let mut cmd = Command::new(glslang());
    cmd.arg("-V")
        .arg("--target-env")
        .arg("vulkan1.2")
        .arg("-g")
        .arg("--depfile")
        .arg(&depfile)
        .arg("-o")
        .arg(&output);
    // glslang looks beside the file it reads (the scratch copy), so the
    // shader's own folder is named first, absolute: `a.rchit`, `./a.rchit`
    // and standard input under `--stdin-filename a.rchit` have the current
    // folder as theirs.
    cmd.arg(format!("-I{}", own_folder(path).display()));
    for d in &options.include_dirs {
        cmd.arg(format!("-I{}", d.display()));
    }
    for (n, v) in &options.defines {
        cmd.arg(format!("-D{n}={v}"));
    }
    cmd.arg(&input);
    let out = cmd.output();
    let result = match out {
        Err(e) => Err(InputError::new(
            InputErrorKind::UnsupportedLanguage,
            path,
            format!(
                "cannot run `{}` to compile GLSL ({e}); install glslang (glslangValidator) or set RTLINT_GLSLANG",
                glslang().display()
            ),
        )),
        Ok(o) if !o.status.success() => Err(glslang_error(path, &input, &o.stdout, &o.stderr)),
        Ok(_) => std::fs::read(&output)
            .map_err(|e| super::io_error(&output, &e))
            .and_then(|bytes| crate::program::words_from_bytes(&bytes, path)),
    };
    let deps = std::fs::read_to_string(&depfile).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&dir);
    result.map(|w| (w, input, deps))
}

/// The folder `path` is in, absolute (the current folder for a bare name).
fn own_folder(path: &Path) -> PathBuf {
    let parent = path.parent().unwrap_or(Path::new(""));
    let parent = if parent.as_os_str().is_empty() {
        Path::new(".")
    } else {
        parent
    };
    std::path::absolute(parent).unwrap_or_else(|_| parent.to_path_buf())
}

/// A private scratch folder for one compilation.
fn tempdir(path: &Path) -> Result<PathBuf, InputError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let dir = std::env::temp_dir().join(format!(
        "rtlint-glsl-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).map_err(|e| super::io_error(path, &e))?;
    Ok(dir)
}

/// glslang's first `ERROR: file:line: message` as an input error at that line.
fn glslang_error(path: &Path, input: &Path, stdout: &[u8], stderr: &[u8]) -> InputError {
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(stdout),
        String::from_utf8_lossy(stderr)
    );
    let input_name = input.display().to_string();
    for line in text.lines() {
        let Some(rest) = line.trim().strip_prefix("ERROR: ") else {
            continue;
        };
        // `FILE:LINE: message`, FILE being the scratch copy or an include.
        let (file, rest) = match rest.strip_prefix(&input_name) {
            Some(r) => (path.to_path_buf(), r),
            None => match rest.find(':') {
                Some(i) => (PathBuf::from(&rest[..i]), &rest[i..]),
                None => (path.to_path_buf(), rest),
            },
        };
        let mut parts = rest.trim_start_matches(':').splitn(2, ':');
        let line_no = parts.next().and_then(|l| l.trim().parse::<u32>().ok());
        let message = parts.next().unwrap_or(rest).trim().to_string();
        let err = InputError::new(
            InputErrorKind::GlslError,
            path,
            format!("glslang: {message}"),
        );
        return match line_no {
            Some(l) if l > 0 => err.at(Location::point(file, l, 0), "here"),
            _ => err,
        };
    }
    let first = text
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("failed");
    InputError::new(
        InputErrorKind::GlslError,
        path,
        format!("glslang: {}", first.trim()),
    )
}
