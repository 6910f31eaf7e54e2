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

/// Compiles `path` (whose contents are `text`, from disk or standard
/// input) to SPIR-V; also returns the scratch file glslang read, which the
/// debug info names.
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
    let dir = tempdir(path)?;
    // glslang reads a file: the text goes into one named like the input, so
    // the stage still follows from the extension.
    let input = dir.join(format!("input.{ext}"));
    let output = dir.join("out.spv");
    std::fs::write(&input, text).map_err(|e| super::io_error(&input, &e))?;
    let mut cmd = Command::new(glslang());
    cmd.arg("-V")
        .arg("--target-env")
        .arg("vulkan1.2")
        .arg("-g")
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
    let _ = std::fs::remove_dir_all(&dir);
    result.map(|w| (w, Some(input)))
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
