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
//! This module sits on top of the layers, beside the CLI: findings come from
//! [`lint::check_paths`], the modules for includes, SPIR-V and layouts from
//! [`lint::load`], the rendered failure from the human report.

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

/// Configures one run over a crate's shaders.
#[derive(Clone, Debug, Default)]
pub struct Builder {
    shaders: Vec<PathBuf>,
    pipelines: Vec<PathBuf>,
    include_dirs: Vec<PathBuf>,
    defines: Vec<(String, String)>,
    /// DXC options besides `-I`/`-D` ([`Builder::dxc_args`]).
    hlsl: hlsl::HlslOptions,
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

    /// A shader file or a folder walked as `rtlint check` walks it: HLSL,
    /// WGSL, GLSL (through glslang) and SPIR-V; `.hlsli` headers are read
    /// through the shaders that include them.
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

    /// An `#include` folder for HLSL and GLSL, searched after the including
    /// file's own folder and the config's `[hlsl]` folders.
    pub fn include_dir(mut self, path: impl Into<PathBuf>) -> Self {
        self.include_dirs.push(path.into());
        self
    }

    /// A `#define NAME VALUE` for HLSL and GLSL.
    pub fn define(mut self, name: impl Into<String>, value: impl Into<String>) -> Self {
        self.defines.push((name.into(), value.into()));
        self
    }

    /// The project's DXC command line (`-fvk-t-shift 1000 all`,
    /// `-HV 2021`, `-I`, `-D`, ...), read as `rtlint compile` reads it. A bad
    /// or unknown option is an error naming it.
    pub fn dxc_args<S: AsRef<str>>(
        mut self,
        args: impl IntoIterator<Item = S>,
    ) -> Result<Self, String> {
        let args: Vec<String> = args.into_iter().map(|a| a.as_ref().to_string()).collect();
        let parsed = hlsl::parse_args(&args, &mut self.hlsl)?;
        match parsed.rest.first() {
            Some(a) => Err(format!("not a DXC option: `{a}`")),
            None => Ok(self),
        }
    }

    /// The `rtlint.toml` for every input; by default each file's nearest.
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
    /// `<file stem>.<entry>.spv` (HLSL, WGSL), a GLSL shader as `<file
    /// name>.spv` (`shadow.rmiss.spv`); a `.spv` input is copied as it is.
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
                d.is_input_error()
                    || d.severity == Severity::Error
                    || (outcome.deny_warnings && d.severity == Severity::Warning)
            })
            .cloned()
            .collect();
        if failing.is_empty() {
            Ok(())
        } else {
            // The other shaders' findings go with the failure too: cargo
            // shows a failed script's output as a block, and a reader of
            // the error should not have to dig the warnings out of it.
            let also: Vec<String> = outcome
                .diagnostics
                .iter()
                .filter(|d| d.code.is_some() && !failing.contains(d))
                .map(one_line)
                .collect::<BTreeSet<_>>()
                .into_iter()
                .collect();
            let mut sources = outcome.sources;
            let mut e = Error::new(failing, &mut sources);
            if !also.is_empty() {
                e.rendered.push_str("also found (not failing the build):\n");
                for l in also {
                    e.rendered.push_str(&format!("  {l}\n"));
                }
            }
            Err(e)
        }
    }

    fn options(&self) -> lint::Options {
        lint::Options {
            config: match &self.config {
                Some(f) => lint::ConfigChoice::File(f.clone()),
                None => lint::ConfigChoice::Nearest,
            },
            overrides: lint::Overrides {
                deny_warnings: self.deny_warnings,
                ..lint::Overrides::default()
            },
            pipelines: self.pipelines.clone(),
            front: front::FrontOptions {
                include_dirs: self.include_dirs.clone(),
                defines: self.defines.clone(),
                hlsl: self.vulkan_hlsl(),
                glsl_stage: None,
            },
            ..lint::Options::default()
        }
    }

    /// The HLSL options: always a Vulkan build, since the output is SPIR-V
    /// for Vulkan (so RT041 judges register collisions after the shifts).
    fn vulkan_hlsl(&self) -> hlsl::HlslOptions {
        let mut o = self.hlsl.clone();
        o.spirv = true;
        o
    }

    fn execute(&self) -> Run {
        let mut run = Run::default();
        let options = self.options();
        // Findings as `rtlint check` reports them: per-file configs,
        // suppressions, each finding once.
        let report = lint::check_paths(&self.shaders, &options);
        run.diagnostics = report.diagnostics;
        run.deny_warnings = report.deny_warnings;
        for (path, text) in &report.embedded {
            run.sources.add_embedded(path, text);
        }
        // Folders too: a new file in them reruns the build script.
        for p in self.shaders.iter().chain(&report.files) {
            run.rerun(p);
        }
        match &self.config {
            Some(c) => run.rerun(c),
            None => {
                for f in &report.files {
                    if let Some(c) = Config::discover(f) {
                        run.rerun(&relative(&c));
                    }
                }
            }
        }
        let out_dir = self
            .out_dir
            .clone()
            .or_else(|| std::env::var_os("OUT_DIR").map(PathBuf::from));
        if (self.emit_spirv || self.layouts.is_some()) && out_dir.is_none() {
            run.error(
                Path::new("OUT_DIR"),
                "`OUT_DIR` is not set: run from a cargo build script or call `.out_dir(...)`",
            );
        }

        // The modules again, for what the report does not carry: the files
        // each shader included, SPIR-V per entry point, layouts. Inputs that
        // failed to load are already reported.
        let inputs = lint::inputs(&self.shaders, &options);
        let mut programs: Vec<Program> = Vec::new();
        let mut spirv_names: BTreeMap<String, PathBuf> = BTreeMap::new();
        for input in &inputs.files {
            let Ok(program) = lint::load(input, &options) else {
                continue;
            };
            run.rerun_files_of(&program);
            if let (true, Some(dir)) = (self.emit_spirv, &out_dir) {
                // The config's `[hlsl]` folders and defines first, as `check` has them.
                let front = lint::front_options_for(input, &options);
                let hlsl_options = front.hlsl_options();
                if let Err(e) = emit_spirv(input, &program, &hlsl_options, dir, &mut spirv_names) {
                    run.diagnostics.push(*e.0);
                }
            }
            programs.push(program);
        }
        for (p, config) in &inputs.pipelines {
            run.rerun(p);
            // The shaders a description names, wherever they are.
            if let Ok(pipeline) = lint::load_pipeline(p, config, &options) {
                for program in &pipeline.programs {
                    run.rerun(&program.path);
                    run.rerun_files_of(program);
                }
            }
        }
        let mut written: BTreeSet<PathBuf> = spirv_names.keys().map(PathBuf::from).collect();
        if let Some(file) = &self.layouts {
            written.insert(file.clone());
        }
        if let Some(dir) = &out_dir {
            if let Err(e) = forget_old_outputs(dir, &written) {
                run.diagnostics.push(*e.0);
            }
        }
        if let (Some(file), Some(dir)) = (&self.layouts, &out_dir) {
            let options = layouts::Options {
                glam: !self.no_glam,
                bytemuck: self.bytemuck,
            };
            match layouts::generate(&programs, &options) {
                Ok(text) => {
                    if let Err(e) = write_if_changed(&dir.join(file), text.as_bytes()) {
                        run.diagnostics.push(*e.0);
                    }
                }
                Err(errors) => run.diagnostics.extend(errors),
            }
        }
        run
    }
}

/// The list of files rtlint wrote into the output folder, one per line.
const OUTPUTS: &str = "rtlint-outputs.txt";

/// Removes what an earlier run wrote into `dir` and this run does not (the
/// SPIR-V of a deleted shader), then records this run's files. Only files
/// rtlint listed are ever removed: the folder is shared with the rest of the
/// build script.
fn forget_old_outputs(dir: &Path, written: &BTreeSet<PathBuf>) -> Result<(), InputError> {
    let list = dir.join(OUTPUTS);
    if let Ok(old) = std::fs::read_to_string(&list) {
        for name in old.lines().map(Path::new) {
            // Names rtlint wrote are plain relative paths; anything else in
            // the list was not written by it.
            let plain = name
                .components()
                .all(|c| matches!(c, std::path::Component::Normal(_)));
            if plain && !name.as_os_str().is_empty() && !written.contains(name) {
                let _ = std::fs::remove_file(dir.join(name));
            }
        }
    }
    let text: String = written
        .iter()
        .map(|p| format!("{}\n", p.display()))
        .collect();
    write_if_changed(&list, text.as_bytes())
}

/// `path` relative to the current folder when it is inside it: cargo runs
/// build scripts in the package folder, and relative lines read better.
fn relative(path: &Path) -> PathBuf {
    std::env::current_dir()
        .ok()
        .and_then(|cwd| {
            let cwd = std::fs::canonicalize(cwd).ok()?;
            path.strip_prefix(&cwd).ok().map(Path::to_path_buf)
        })
        .unwrap_or_else(|| path.to_path_buf())
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

/// Writes each entry point of `input` as its own module into `dir`.
fn emit_spirv(
    input: &lint::Input,
    program: &Program,
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
        // glslang writes one entry point per file, always `main`: the file
        // name with its stage extension tells the modules apart
        // (`shadow.rmiss` and `shadow.rahit` → `shadow.rmiss.spv`,
        // `shadow.rahit.spv`).
        Language::Glsl => {
            let name = path
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            vec![(format!("{name}.spv"), program.words.clone())]
        }
        // A module as it is, under its own name.
        Language::Spirv => {
            let name = path
                .file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            vec![(name, program.words.clone())]
        }
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
                "raygen.RayGen.spv",
                OUTPUTS,
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
    /// The build's output is Vulkan: RT041 checks D3D12-style registers
    /// without any `vk::` sign, and judges them after `dxc_args`' shifts.
    #[test]
    fn hlsl_is_a_vulkan_build_with_the_dxc_shifts() {
        let shader = "fixtures/RT041/good_d3d12_only.hlsl";
        let dir = scratch("vk");
        let config = dir.join("rtlint.toml");
        std::fs::write(&config, "select = [\"RT041\"]\n").unwrap();
        let rt041 = |lines: &str| {
            lines
                .lines()
                .filter(|l| l.starts_with("cargo:warning=") && l.contains("RT041"))
                .count()
        };
        let (lines, _) = run(Builder::new().shaders(shader).config(&config).out_dir(&dir));
        assert_eq!(rt041(&lines), 2, "{lines}");
        let shifted = Builder::new()
            .shaders(shader)
            .config(&config)
            .dxc_args(["-fvk-t-shift", "100", "all", "-fvk-u-shift", "200", "all"])
            .unwrap()
            .out_dir(scratch("vk-shifted"));
        let (lines, _) = run(shifted);
        assert_eq!(rt041(&lines), 0, "{lines}");
        let bad = Builder::new().dxc_args(["-fvk-t-shift", "x", "all"]);
        assert!(bad.unwrap_err().contains("-fvk-t-shift"));
        assert!(Builder::new().dxc_args(["shader.hlsl"]).is_err());
    }

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
            "/// offset 16; elements 0..2 with their padding\n    pub c: [[f32; 4]; 2],",
            "/// offset 48; `c` element 2, which the next member packs after\n    pub c_last: f32,",
            "/// offset 52\n    pub d: f32,",
            "/// offset 56\n    pub e: glam::Vec2,",
            "/// offset 64; 3 columns of 3, 16 bytes apart; columns 0..2 with their padding\n    pub m: [[f32; 4]; 2],",
            "/// offset 96; `m` column 2, which the next member packs after\n    pub m_last: [f32; 3],",
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

    /// `.include_dir()` and `.define()` reach the shaders a pipeline
    /// description names, as they reach every other input.
    #[test]
    fn include_dirs_and_defines_reach_described_shaders() {
        let dir = scratch("described");
        std::fs::create_dir_all(dir.join("inc")).unwrap();
        std::fs::create_dir_all(dir.join("shaders")).unwrap();
        std::fs::write(
            dir.join("inc/common.hlsli"),
            "struct Payload { float4 color; };\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("shaders/gen.hlsl"),
            "#include \"common.hlsli\"\n#ifndef COLOR\n#error COLOR is not defined\n#endif\nRaytracingAccelerationStructure scene : register(t0);\n[shader(\"raygeneration\")]\nvoid Gen() {\n    RayDesc ray = { float3(0, 0, 0), 0.0, float3(0, 0, 1), 100.0 };\n    Payload p = { float4(0, 0, 0, COLOR) };\n    TraceRay(scene, 0, 0xFF, 0, 1, 0, ray, p);\n}\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("shaders/scene.pipeline.toml"),
            "max_recursion_depth = 1\n[[raygen]]\nfile = \"gen.hlsl\"\nentry = \"Gen\"\n",
        )
        .unwrap();
        let (_, r) = run(Builder::new()
            .shaders(dir.join("shaders"))
            .include_dir(dir.join("inc"))
            .define("COLOR", "1")
            .out_dir(&dir));
        r.unwrap();
        // Without them the description's shader fails: the test is not empty.
        let (_, r) = run(Builder::new().shaders(dir.join("shaders")).out_dir(&dir));
        assert!(r.is_err());
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
    fn glsl_goes_through_glslang() {
        if !rtlint_testkit::tool(&front::glsl::glslang().to_string_lossy()) {
            return;
        }
        let dir = scratch("glsl");
        std::fs::create_dir_all(dir.join("include")).unwrap();
        std::fs::write(
            dir.join("include/payload.glsl"),
            "struct Payload { vec3 color; uint depth; mat4 m; };\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("trace.rgen"),
            "#version 460\n#extension GL_EXT_ray_tracing : require\n\
             #extension GL_GOOGLE_include_directive : require\n\
             #include \"include/payload.glsl\"\n\
             layout(location = 0) rayPayloadEXT Payload p;\n\
             layout(binding = 0) uniform accelerationStructureEXT tlas;\n\
             layout(binding = 1, std140) uniform Params { vec3 tint; float scale; mat4 view; } params;\n\
             void main() {\n    p.depth = 0u;\n    p.color = params.tint * params.scale;\n\
             traceRayEXT(tlas, 0u, 0xFFu, 0u, 1u, 0u, vec3(0.0), 0.0, vec3(0.0, 0.0, 1.0), 1.0, 0);\n}\n",
        )
        .unwrap();
        let (lines, r) = run(Builder::new()
            .shaders(&dir)
            .emit_spirv()
            .generate_layouts("layouts.rs")
            .out_dir(&dir));
        r.unwrap();
        assert!(lines.contains("trace.rgen\n"), "{lines}");
        // The included file too, as glslang's debug info names it.
        assert!(lines.contains("payload.glsl\n"), "{lines}");
        let spv = std::fs::read(dir.join("trace.rgen.spv")).unwrap();
        assert_eq!(&spv[..4], &crate::program::MAGIC.to_le_bytes());
        let text = std::fs::read_to_string(dir.join("layouts.rs")).unwrap();
        // std140: the vec3 and the float share a row, the mat4 is a glam Mat4.
        let params = struct_body(&text, "Params");
        assert!(params.contains("pub tint: glam::Vec3,"), "{text}");
        assert!(
            params.contains(
                "/// offset 16; 4 columns of 4, 16 bytes apart\n    pub view: glam::Mat4,"
            ),
            "{text}"
        );
        assert_eq!(size_of(&text, "Params"), Some(80));
        // The payload's scalar size: 12 + 4 + 64; its mat4 sits at 16 in an
        // 80-byte type, so glam's 16-byte-aligned Mat4 fits.
        assert_eq!(size_of(&text, "Payload"), Some(80));
        assert!(
            struct_body(&text, "Payload").contains("pub m: glam::Mat4,"),
            "{text}"
        );
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
