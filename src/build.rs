//! The build-script API: lint shaders from a cargo `build.rs`, write their
//! SPIR-V into `OUT_DIR`, and generate Rust types for their interfaces.
//!
//! ```no_run
//! // build.rs
//! fn main() -> Result<(), rtlint::build::Error> {
//!     rtlint::build::Builder::new()
//!         .shaders("shaders")
//!         .pipeline("shaders/main.pipeline.toml")
//!         .include_dir("shaders/include")
//!         .deny_warnings(false)
//!         .emit_spirv()
//!         .generate_layouts("layouts.rs")
//!         .run()
//! }
//! ```
//!
//! [`Builder::run`] prints `cargo:rerun-if-changed` for every shader and every
//! file it includes, one `cargo:warning` line per finding, and returns an
//! [`Error`] holding the rendered diagnostics when a finding is an error (or a
//! warning under `deny_warnings`) or an input cannot be read. See
//! `docs/build.md`.
//!
//! This module sits on top of the layers, beside the CLI: it drives the
//! front-ends, the rules and the human report.

mod layouts;

use crate::config::Config;
use crate::diag::{Diagnostic, InputError, InputErrorKind, Severity};
use crate::front::{self, hlsl};
use crate::lint;
use crate::program::Program;
use crate::report::{self, Sources};
use crate::shader::Language;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::io::Write;
use std::path::{Path, PathBuf};

/// File extensions of GLSL sources, which this build cannot compile.
const GLSL_EXTENSIONS: &[&str] = &[
    "glsl", "vert", "frag", "comp", "rgen", "rchit", "rmiss", "rahit", "rint", "rcall",
];

/// Configures one run over a crate's shaders.
#[derive(Clone, Debug, Default)]
pub struct Builder {
    shaders: Vec<PathBuf>,
    pipelines: Vec<PathBuf>,
    include_dirs: Vec<PathBuf>,
    defines: Vec<(String, String)>,
    config: Option<PathBuf>,
    deny_warnings: bool,
    emit_spirv: bool,
    layouts: Option<PathBuf>,
    no_glam: bool,
    bytemuck: bool,
    out_dir: Option<PathBuf>,
}

impl Builder {
    pub fn new() -> Self {
        Self::default()
    }

    /// A shader file or a folder searched recursively for `.hlsl`, `.wgsl`
    /// and `.spv` files (`.hlsli` headers are read through their includers).
    pub fn shaders(mut self, path: impl Into<PathBuf>) -> Self {
        self.shaders.push(path.into());
        self
    }

    /// A pipeline description (`*.pipeline.toml`) checked with the pipeline
    /// rules (recursion depth, stack size).
    pub fn pipeline(mut self, path: impl Into<PathBuf>) -> Self {
        self.pipelines.push(path.into());
        self
    }

    /// An `#include` folder for HLSL, searched after the including file's own.
    pub fn include_dir(mut self, path: impl Into<PathBuf>) -> Self {
        self.include_dirs.push(path.into());
        self
    }

    /// An HLSL `#define NAME VALUE`.
    pub fn define(mut self, name: impl Into<String>, value: impl Into<String>) -> Self {
        self.defines.push((name.into(), value.into()));
        self
    }

    /// The `rtlint.toml` to use; by default one is searched for upwards from
    /// the first shader path.
    pub fn config(mut self, path: impl Into<PathBuf>) -> Self {
        self.config = Some(path.into());
        self
    }

    /// Fail the build on warnings too (also settable in `rtlint.toml`).
    pub fn deny_warnings(mut self, deny: bool) -> Self {
        self.deny_warnings = deny;
        self
    }

    /// Writes one SPIR-V module per entry point into the output folder as
    /// `<file stem>.<entry>.spv`; a `.spv` input is copied as it is.
    pub fn emit_spirv(mut self) -> Self {
        self.emit_spirv = true;
        self
    }

    /// Writes Rust types for ray payloads, hit attributes, callable data,
    /// shader records, push constants and constant/uniform buffers into this
    /// file of the output folder.
    pub fn generate_layouts(mut self, file: impl Into<PathBuf>) -> Self {
        self.layouts = Some(file.into());
        self
    }

    /// Use `glam` vector and matrix types where their size and alignment fit
    /// the layout (the default); `false` writes plain arrays only.
    pub fn glam(mut self, glam: bool) -> Self {
        self.no_glam = !glam;
        self
    }

    /// Derive `bytemuck::Pod` and `bytemuck::Zeroable` on the generated
    /// types (the crate then needs `bytemuck` with its `derive` feature, and
    /// `glam` with its `bytemuck` feature).
    pub fn bytemuck(mut self, derive: bool) -> Self {
        self.bytemuck = derive;
        self
    }

    /// Where SPIR-V and layouts go; by default the `OUT_DIR` cargo sets.
    pub fn out_dir(mut self, path: impl Into<PathBuf>) -> Self {
        self.out_dir = Some(path.into());
        self
    }

    /// Runs, printing cargo's instructions to standard output.
    pub fn run(self) -> Result<(), Error> {
        let stdout = std::io::stdout();
        let mut lock = stdout.lock();
        self.run_to(&mut lock)
    }

    /// Runs, writing cargo's instructions (`cargo:rerun-if-changed=…`,
    /// `cargo:warning=…`) to `out`.
    pub fn run_to(self, out: &mut dyn Write) -> Result<(), Error> {
        let outcome = self.execute();
        let mut lines = String::new();
        for p in &outcome.rerun {
            lines.push_str(&format!("cargo:rerun-if-changed={}\n", p.display()));
        }
        // A header's finding is found once per shader including it: say it once.
        let mut said = BTreeSet::new();
        for d in outcome.diagnostics.iter().filter(|d| d.code.is_some()) {
            let line = one_line(d);
            if said.insert(line.clone()) {
                lines.push_str(&format!("cargo:warning={line}\n"));
            }
        }
        out.write_all(lines.as_bytes())
            .and_then(|_| out.flush())
            .map_err(|e| {
                Error::new(
                    vec![Diagnostic::new(
                        Severity::Error,
                        "build-output",
                        Path::new("<stdout>"),
                        format!("cannot write cargo instructions: {e}"),
                    )],
                    &mut Sources::default(),
                )
            })?;
        let mut said_failing = BTreeSet::new();
        let failing: Vec<Diagnostic> = outcome
            .diagnostics
            .iter()
            .filter(|d| said_failing.insert(one_line(d)))
            .filter(|d| {
                d.code.is_none()
                    || d.severity == Severity::Error
                    || (outcome.deny_warnings && d.severity == Severity::Warning)
            })
            .cloned()
            .collect();
        if failing.is_empty() {
            Ok(())
        } else {
            let mut sources = outcome.sources;
            Err(Error::new(failing, &mut sources))
        }
    }

    fn execute(&self) -> Outcome {
        let mut run = Run::default();
        let config = self.load_config(&mut run);
        run.deny_warnings = self.deny_warnings || config.deny_warnings;
        let out_dir = self
            .out_dir
            .clone()
            .or_else(|| std::env::var_os("OUT_DIR").map(PathBuf::from));
        let needs_out = self.emit_spirv || self.layouts.is_some();
        if needs_out && out_dir.is_none() {
            run.error(
                Path::new("OUT_DIR"),
                "`OUT_DIR` is not set: run from a cargo build script or call `.out_dir(...)`",
            );
        }

        // Folders: a new file in them reruns the build script too.
        for p in &self.shaders {
            run.rerun(p);
        }
        let (glsl, paths): (Vec<PathBuf>, Vec<PathBuf>) =
            self.shaders.iter().cloned().partition(|p| is_glsl(p));
        for p in &glsl {
            run.diagnostics.push(glsl_error(p));
        }
        let inputs = lint::collect_inputs(&paths, &config, None);
        run.diagnostics
            .extend(inputs.errors.iter().map(|e| (*e.0).clone()));
        for p in &inputs.skipped {
            if is_glsl(p) {
                run.diagnostics.push(glsl_error(p));
            }
        }
        let options = hlsl::HlslOptions {
            include_dirs: self.include_dirs.clone(),
            defines: self.defines.clone(),
            entry: None,
        };
        let mut programs: Vec<Program> = Vec::new();
        let mut spirv_names: BTreeMap<String, PathBuf> = BTreeMap::new();
        for input in &inputs.files {
            run.rerun(&input.path);
            let program = match load(&input.path, input.language, &options) {
                Ok(p) => p,
                Err(e) => {
                    run.diagnostics.push(*e.0);
                    continue;
                }
            };
            run.rerun_files_of(&program);
            run.sources.add_program(&program);
            run.diagnostics
                .extend(crate::rules::check_program(&program, &config));
            if let (true, Some(dir)) = (self.emit_spirv, &out_dir) {
                if let Err(e) = emit_spirv(input, &options, dir, &mut spirv_names) {
                    run.diagnostics.push(*e.0);
                }
            }
            programs.push(program);
        }
        let mut pipelines = inputs.pipelines.clone();
        for p in &self.pipelines {
            if !pipelines.contains(p) {
                pipelines.push(p.clone());
            }
        }
        for p in &pipelines {
            run.rerun(p);
            match crate::pipeline::load(p) {
                Ok(pipeline) => {
                    for program in &pipeline.programs {
                        run.rerun(&program.path);
                        run.rerun_files_of(program);
                        run.sources.add_program(program);
                    }
                    let ctx = crate::rules::PipelineContext::new(&pipeline, &config);
                    run.diagnostics.extend(crate::rules::check_pipeline(&ctx));
                }
                Err(e) => run.diagnostics.push(*e.0),
            }
        }
        if let (Some(file), Some(dir)) = (&self.layouts, &out_dir) {
            let options = layouts::Options {
                glam: !self.no_glam,
                bytemuck: self.bytemuck,
            };
            let target = dir.join(file);
            match layouts::generate(&programs, &options) {
                Ok(text) => {
                    if let Err(e) = write_if_changed(&target, text.as_bytes()) {
                        run.diagnostics.push(*e.0);
                    }
                }
                Err(errors) => run.diagnostics.extend(errors),
            }
        }
        Outcome {
            rerun: run.rerun,
            diagnostics: run.diagnostics,
            sources: run.sources,
            deny_warnings: run.deny_warnings,
        }
    }

    fn load_config(&self, run: &mut Run) -> Config {
        let path = self
            .config
            .clone()
            .or_else(|| self.shaders.first().and_then(|p| Config::discover(p)));
        let Some(path) = path else {
            return Config::default();
        };
        run.rerun(&path);
        match lint::load_config(&path) {
            Ok(c) => c,
            Err(e) => {
                run.diagnostics.push(*e.0);
                Config::default()
            }
        }
    }
}

/// What one run found, before it is printed.
#[derive(Default)]
struct Run {
    /// Files and folders cargo watches, in the order first seen.
    rerun: Vec<PathBuf>,
    seen: BTreeSet<PathBuf>,
    diagnostics: Vec<Diagnostic>,
    sources: Sources,
    deny_warnings: bool,
}

struct Outcome {
    rerun: Vec<PathBuf>,
    diagnostics: Vec<Diagnostic>,
    sources: Sources,
    deny_warnings: bool,
}

impl Run {
    fn rerun(&mut self, p: &Path) {
        if self.seen.insert(p.to_path_buf()) {
            self.rerun.push(p.to_path_buf());
        }
    }

    /// Every source file the module's debug info names that exists here: for
    /// HLSL, the shader and each file it included.
    fn rerun_files_of(&mut self, program: &Program) {
        for f in &program.files {
            if f.path.is_file() {
                self.rerun(&f.path);
            }
        }
    }

    fn error(&mut self, file: &Path, message: &str) {
        self.diagnostics.push(Diagnostic::new(
            Severity::Error,
            "build-error",
            file,
            message,
        ));
    }
}

/// `file:line: RTnnn message`, what a `cargo:warning` shows.
fn one_line(d: &Diagnostic) -> String {
    let (path, line, ..) = d.position();
    let at = if line > 0 {
        format!("{}:{line}", path.display())
    } else {
        path.display().to_string()
    };
    let mut message = d.message.clone();
    if let Some(s) = d.subject.as_ref().filter(|_| d.primary.is_none()) {
        message.push_str(&format!(" ({s})"));
    }
    let text = format!("{at}: {} {message}", d.code.unwrap_or(d.name));
    text.replace(['\n', '\r'], " ")
}

fn is_glsl(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| GLSL_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

fn glsl_error(p: &Path) -> Diagnostic {
    *InputError::new(
        InputErrorKind::UnsupportedLanguage,
        p,
        "GLSL input is not supported by rtlint::build yet",
    )
    .with_note("compile it to SPIR-V first (`glslangValidator -V --target-env vulkan1.2 -g`) and pass the `.spv`")
    .0
}

/// Compiles one input into a Program, HLSL with the builder's include
/// folders and defines.
fn load(
    path: &Path,
    language: Language,
    options: &hlsl::HlslOptions,
) -> Result<Program, InputError> {
    match language {
        Language::Hlsl => {
            let m = hlsl::compile_file(path, options)?;
            let mut program = crate::program::parse(&m.words, path, Language::Hlsl)?;
            program.attach_named_decls(&m.decls);
            Ok(program)
        }
        Language::Glsl => Err(InputError(Box::new(glsl_error(path)))),
        _ => front::load(path, language),
    }
}

/// Writes each entry point of `input` as its own module into `dir`.
fn emit_spirv(
    input: &lint::Input,
    options: &hlsl::HlslOptions,
    dir: &Path,
    names: &mut BTreeMap<String, PathBuf>,
) -> Result<(), InputError> {
    let path = &input.path;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let modules: Vec<(String, Vec<u32>)> = match input.language {
        Language::Hlsl => hlsl::compile(path, options)?
            .into_iter()
            .map(|e| (format!("{stem}.{}.spv", e.name), e.words))
            .collect(),
        Language::Wgsl => {
            let text = front::read_text(path)?;
            let (module, info) = front::wgsl::parse(&text, path)?;
            let mut out = Vec::new();
            for ep in &module.entry_points {
                let words = wgsl_entry(&module, &info, path, ep)?;
                out.push((format!("{stem}.{}.spv", ep.name), words));
            }
            out
        }
        Language::Spirv => {
            let bytes = std::fs::read(path).map_err(|e| front::io_error(path, &e))?;
            let name = path
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let target = dir.join(&name);
            claim(names, &name, path)?;
            return write_if_changed(&target, &bytes);
        }
        Language::Glsl => return Err(InputError(Box::new(glsl_error(path)))),
    };
    for (name, words) in modules {
        claim(names, &name, path)?;
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        write_if_changed(&dir.join(&name), &bytes)?;
    }
    Ok(())
}

/// One output name per source: two shaders writing `a.main.spv` is an error.
fn claim(names: &mut BTreeMap<String, PathBuf>, name: &str, path: &Path) -> Result<(), InputError> {
    match names.get(name) {
        Some(other) if other != path => Err(InputError::new(
            InputErrorKind::UnreadableFile,
            path,
            format!(
                "`{name}` would be written for both {} and {}",
                other.display(),
                path.display()
            ),
        )
        .with_note("give the shader files different names")),
        _ => {
            names.insert(name.to_string(), path.to_path_buf());
            Ok(())
        }
    }
}

fn wgsl_entry(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    path: &Path,
    ep: &naga::EntryPoint,
) -> Result<Vec<u32>, InputError> {
    use naga::back::spv;
    let options = spv::Options {
        lang_version: (1, 4),
        ..Default::default()
    };
    let pipeline = spv::PipelineOptions {
        shader_stage: ep.stage,
        entry_point: ep.name.clone(),
    };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        spv::write_vec(module, info, &options, Some(&pipeline))
    }))
    .map_err(|_| {
        InputError::new(
            InputErrorKind::WgslInternal,
            path,
            format!("naga failed to write SPIR-V for entry point `{}`", ep.name),
        )
    })?
    .map_err(|e| {
        InputError::new(
            InputErrorKind::WgslSpirvOut,
            path,
            format!(
                "naga could not write SPIR-V for entry point `{}`: {e}",
                ep.name
            ),
        )
    })
}

/// Writes `bytes` unless the file already holds them, so an unchanged output
/// keeps its timestamp and does not rebuild what depends on it.
fn write_if_changed(path: &Path, bytes: &[u8]) -> Result<(), InputError> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(());
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| front::io_error(dir, &e))?;
    }
    std::fs::write(path, bytes).map_err(|e| {
        InputError::new(
            InputErrorKind::UnreadableFile,
            path,
            format!("cannot write {}: {e}", path.display()),
        )
    })
}

/// Why the build failed: the diagnostics, rendered as `rtlint check` prints
/// them. `fn main() -> Result<(), Error>` shows the rendered text.
pub struct Error {
    diagnostics: Vec<Diagnostic>,
    rendered: String,
}

impl Error {
    fn new(diagnostics: Vec<Diagnostic>, sources: &mut Sources) -> Self {
        let mut buf = codespan_reporting::term::termcolor::NoColor::new(Vec::new());
        let rendered = match report::human::render(&diagnostics, sources, &mut buf) {
            Ok(()) => String::from_utf8_lossy(&buf.into_inner()).into_owned(),
            Err(_) => diagnostics
                .iter()
                .map(|d| format!("{}\n", one_line(d)))
                .collect(),
        };
        Error {
            diagnostics,
            rendered,
        }
    }

    /// The errors (and, under `deny_warnings`, warnings) that failed the build.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.diagnostics.len();
        writeln!(
            f,
            "rtlint: {n} problem{} in the shaders",
            if n == 1 { "" } else { "s" }
        )?;
        write!(f, "{}", self.rendered)
    }
}

/// The same text as `Display`: `main` returning `Err` prints `Debug`.
impl fmt::Debug for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::layout::layout_type;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("rtlint-build-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Runs a builder; the cargo instructions it printed and its result.
    fn run(b: Builder) -> (String, Result<(), Error>) {
        let mut out = Vec::new();
        let r = b.run_to(&mut out);
        (String::from_utf8(out).unwrap(), r)
    }

    /// `size_of::<Name>() == N` lines of a generated file.
    fn size_of(text: &str, name: &str) -> Option<u64> {
        let key = format!("size_of::<{name}>() == ");
        let at = text.find(&key)? + key.len();
        text[at..].split(')').next()?.parse().ok()
    }

    fn struct_body<'a>(text: &'a str, name: &str) -> &'a str {
        let start = text.find(&format!("pub struct {name} {{")).unwrap();
        let end = start + text[start..].find("\n}").unwrap();
        &text[start..end]
    }

    #[test]
    fn example_shaders_rerun_on_includes_and_write_one_module_per_entry_point() {
        let out = scratch("example");
        let (lines, r) = run(Builder::new()
            .shaders("examples/build-script/shaders")
            .pipeline("examples/build-script/shaders/main.pipeline.toml")
            .emit_spirv()
            .generate_layouts("layouts.rs")
            .out_dir(&out));
        r.unwrap();
        for f in [
            "shaders",
            "shaders/raygen.hlsl",
            "shaders/miss.hlsl",
            "shaders/closesthit.hlsl",
            "shaders/include/common.hlsli",
            "shaders/main.pipeline.toml",
        ] {
            let line = format!("cargo:rerun-if-changed=examples/build-script/{f}\n");
            assert_eq!(lines.matches(&line).count(), 1, "{f}: {lines}");
        }
        assert!(!lines.contains("cargo:warning"), "{lines}");
        let mut written: Vec<String> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        written.sort();
        assert_eq!(
            written,
            [
                "closesthit.ClosestHit.spv",
                "layouts.rs",
                "miss.Miss.spv",
                "raygen.RayGen.spv"
            ]
        );
        let spv = std::fs::read(out.join("miss.Miss.spv")).unwrap();
        let words = crate::program::words_from_bytes(&spv, Path::new("miss.Miss.spv")).unwrap();
        let program = crate::program::parse(&words, Path::new("miss"), Language::Hlsl).unwrap();
        assert_eq!(program.entry_points.len(), 1);
        assert_eq!(program.entry_points[0].name, "Miss");
        let _ = std::fs::remove_dir_all(&out);
    }

    /// The cbuffer rule at its trickiest: a float after an array shares the
    /// array's last row, and so does one after a float3x3.
    #[test]
    fn cbuffer_follows_declared_offsets_with_split_last_elements() {
        let out = scratch("cbuffer");
        let (_, r) = run(Builder::new()
            .shaders("tests/hlsl/cbuffer_packing.hlsl")
            .generate_layouts("layouts.rs")
            .out_dir(&out));
        r.unwrap();
        let text = std::fs::read_to_string(out.join("layouts.rs")).unwrap();
        let packed = struct_body(&text, "Packed");
        for field in [
            "/// offset 0\n    pub a: glam::Vec3,",
            "/// offset 12\n    pub b: f32,",
            "/// offset 16\n    pub c: [[f32; 4]; 2],",
            "/// offset 48\n    pub c_last: f32,",
            "/// offset 52\n    pub d: f32,",
            "/// offset 56\n    pub e: glam::Vec2,",
            "/// offset 64\n    pub m: [[f32; 4]; 2],",
            "/// offset 96\n    pub m_last: [f32; 3],",
            "/// offset 108\n    pub tail: f32,",
        ] {
            assert!(packed.contains(field), "{field} in\n{packed}");
        }
        // The size: whole 16-byte rows, as the layout analysis counts them.
        let program =
            front::load(Path::new("tests/hlsl/cbuffer_packing.hlsl"), Language::Hlsl).unwrap();
        for (var, name) in [("Packed", "Packed"), ("$Globals", "Globals")] {
            let g = program
                .globals
                .iter()
                .find(|g| g.name.as_deref() == Some(var))
                .unwrap();
            let t = layout_type(&program, g.ty, var).unwrap();
            assert_eq!(size_of(&text, name), Some(t.hlsl_rows * 16), "{name}");
        }
        assert_eq!(size_of(&text, "Packed"), Some(112));
        assert!(
            text.contains("const _: () = assert!(core::mem::offset_of!(Packed, m_last) == 96);")
        );
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn wgsl_payload_and_uniform_sizes_are_the_layout_analysis_sizes() {
        let out = scratch("wgsl");
        let (_, r) = run(Builder::new()
            .shaders("shaders/reflect_recursive.wgsl")
            .glam(false)
            .bytemuck(true)
            .generate_layouts("layouts.rs")
            .out_dir(&out));
        r.unwrap();
        let text = std::fs::read_to_string(out.join("layouts.rs")).unwrap();
        assert!(!text.contains("glam::"), "{text}");
        assert!(text.contains("#[derive(bytemuck::Pod, bytemuck::Zeroable)]\n"));
        let program =
            front::load(Path::new("shaders/reflect_recursive.wgsl"), Language::Wgsl).unwrap();
        let params = program
            .globals
            .iter()
            .find(|g| g.name.as_deref() == Some("params"))
            .unwrap();
        let t = layout_type(&program, params.ty, "params").unwrap();
        assert_eq!(size_of(&text, "Params"), t.wgsl_size);
        let ray = program
            .globals
            .iter()
            .find(|g| g.name.as_deref() == Some("ray"))
            .unwrap();
        let t = layout_type(&program, ray.ty, "ray").unwrap();
        assert_eq!(size_of(&text, "Radiance"), Some(t.scalar_size));
        assert!(
            struct_body(&text, "Radiance").contains("pub color: [f32; 3],"),
            "{text}"
        );
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn bad_hlsl_fails_with_file_and_position() {
        let dir = scratch("bad");
        std::fs::write(
            dir.join("bad.hlsl"),
            "[shader(\"miss\")]\nvoid Miss(inout float4 p)\n{\n    p = ;\n}\n",
        )
        .unwrap();
        let (lines, r) = run(Builder::new().shaders(&dir).out_dir(&dir));
        let e = r.unwrap_err();
        let text = e.to_string();
        let at = format!("{}:4:", dir.join("bad.hlsl").display());
        assert!(text.contains(&at), "{text}");
        assert!(
            format!("{e:?}").contains(&at),
            "Debug is what `main` prints"
        );
        assert!(lines.contains(&format!("cargo:rerun-if-changed={}", dir.display())));
        assert_eq!(e.diagnostics().len(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn glsl_is_refused_with_a_way_out() {
        let dir = scratch("glsl");
        std::fs::write(dir.join("a.rgen"), "#version 460\nvoid main() {}\n").unwrap();
        let (_, r) = run(Builder::new().shaders(&dir).out_dir(&dir));
        let text = r.unwrap_err().to_string();
        assert!(
            text.contains("GLSL input is not supported by rtlint::build yet"),
            "{text}"
        );
        assert!(text.contains("glslangValidator"), "{text}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn warnings_fail_only_when_denied_and_two_layouts_under_one_name_fail() {
        let dir = scratch("warn");
        let shader = |payload: &str| {
            format!(
                "struct Payload {{ {payload} }};\nRaytracingAccelerationStructure s : register(t0);\n\
                 [shader(\"raygeneration\")]\nvoid R()\n{{\n    RayDesc r;\n    r.Origin = 0; r.Direction = float3(0, 0, 1); r.TMin = 0; r.TMax = 1;\n    Payload p = (Payload)0;\n    TraceRay(s, 0, 0xFF, 0, 1, 0, r, p);\n}}\n"
            )
        };
        std::fs::write(dir.join("a.hlsl"), shader("float4 a; float4 b; float4 c;")).unwrap();
        let (lines, r) = run(Builder::new().shaders(dir.join("a.hlsl")).out_dir(&dir));
        r.unwrap();
        let warning = format!(
            "cargo:warning={}:1: RT001 ray payload `Payload` is 48 bytes, above the 32-byte budget\n",
            dir.join("a.hlsl").display()
        );
        assert!(lines.contains(&warning), "{lines}");
        let (_, r) = run(Builder::new()
            .shaders(dir.join("a.hlsl"))
            .deny_warnings(true)
            .out_dir(&dir));
        assert!(r.unwrap_err().to_string().contains("warning[RT001]"));

        std::fs::write(dir.join("b.hlsl"), shader("float a;")).unwrap();
        let (_, r) = run(Builder::new()
            .shaders(&dir)
            .generate_layouts("layouts.rs")
            .out_dir(&dir));
        let text = r.unwrap_err().to_string();
        assert!(text.contains("`Payload` at"), "{text}");
        assert!(text.contains("rename one"), "{text}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn rust_names() {
        assert_eq!(layouts_names("type.Camera"), "Camera");
        assert_eq!(layouts_names("type.$Globals"), "Globals");
        assert_eq!(layouts_names("type.ConstantBuffer.params"), "Params");
    }

    fn layouts_names(s: &str) -> String {
        layouts::rust_type_name(s)
    }
}
