//! The `rtlint` command line.

use clap::{Parser, Subcommand};
use codespan_reporting::term::termcolor::{ColorChoice, StandardStream};
use rtlint::config::Config;
use rtlint::diag::{Diagnostic, InputError, Severity};
use rtlint::lint;
use rtlint::report::{self, Format, Sources, Summary};
use rtlint::shader::Language;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "rtlint",
    version,
    about = "Linter and toolkit for ray-tracing shaders (HLSL, WGSL, SPIR-V)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct Common {
    /// Shader files or directories (walked recursively).
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Output format: human, json, github or sarif.
    #[arg(long, default_value = "human")]
    format: String,
    /// Read this config instead of the nearest rtlint.toml.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Treat every named file as this language (hlsl, wgsl, spirv).
    #[arg(long)]
    lang: Option<String>,
    /// Also say which files were skipped.
    #[arg(short, long)]
    verbose: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Lint shaders and report best-practice violations.
    Check {
        #[command(flatten)]
        common: Common,
        /// Ray payloads above this many bytes are reported (RT001).
        #[arg(long)]
        payload_budget: Option<u64>,
        /// Warnings fail the run (exit 1) too.
        #[arg(long)]
        deny_warnings: bool,
        /// Also apply this pipeline description (`*.pipeline.toml` files in
        /// the walked directories are applied too).
        #[arg(long)]
        pipeline: Vec<PathBuf>,
    },
    /// Values kept alive across each trace, callable and ray-query site.
    Live {
        #[command(flatten)]
        common: Common,
    },
    /// Recursion depth and stack size of a described pipeline (or of loose
    /// shaders, assuming every trace reaches every shader).
    Stack {
        #[command(flatten)]
        common: Common,
        /// Create the pipeline on the Vulkan device and show what the driver
        /// reports (`vkGetRayTracingShaderGroupStackSizeKHR`) beside the model.
        #[arg(long)]
        driver: bool,
    },
    /// Print payload, attribute and shader-record layouts with the best member order.
    Layout {
        #[command(flatten)]
        common: Common,
    },
    /// Compile HLSL to SPIR-V with rtlint's own compiler.
    Compile {
        /// The HLSL file.
        file: PathBuf,
        /// Compile only this entry point.
        #[arg(short = 'E', long = "entry")]
        entry: Option<String>,
        /// Include directory (searched after the including file's folder).
        #[arg(short = 'I', value_name = "DIR")]
        include: Vec<PathBuf>,
        /// Define a macro: NAME or NAME=VALUE.
        #[arg(short = 'D', value_name = "NAME[=VALUE]")]
        define: Vec<String>,
        /// Output: a `.spv` file (one entry point, or with --whole every entry
        /// point in one module), or a directory for one module per entry point.
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// One module holding every entry point.
        #[arg(long)]
        whole: bool,
    },
    /// List every rule.
    Rules,
    /// (Internal) `stack --driver` runs this in a child process per
    /// pipeline, so that a driver crash cannot take rtlint down: creates the
    /// pipeline and prints the driver's stack sizes as JSON.
    #[command(hide = true, name = "driver-stack-sizes")]
    DriverStackSizes {
        /// A pipeline description.
        #[arg(long)]
        pipeline: Option<PathBuf>,
        /// Loose shaders, as `LANG:PATH`.
        #[arg(long)]
        shader: Vec<String>,
    },
    /// Print a rule's documentation.
    Rule {
        /// Code (RT001) or name (payload-over-budget).
        code: String,
    },
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    match run(cli) {
        Ok(code) => ExitCode::from(code),
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<u8, String> {
    match cli.command {
        Command::Check {
            common,
            payload_budget,
            deny_warnings,
            pipeline,
        } => check(common, payload_budget, deny_warnings, pipeline),
        Command::Live { common } => live(common),
        Command::Stack { common, driver } => stack(common, driver),
        Command::Layout { common } => layout(common),
        Command::Compile {
            file,
            entry,
            include,
            define,
            output,
            whole,
        } => compile(file, entry, include, define, output, whole),
        Command::DriverStackSizes { pipeline, shader } => driver_stack_sizes(pipeline, shader),
        Command::Rules => {
            let mut out = std::io::stdout().lock();
            for r in rtlint::rules::RULES {
                let _ = writeln!(
                    out,
                    "{}  {:<28} {:<8} {}",
                    r.code,
                    r.name,
                    r.level.as_str(),
                    r.summary
                );
            }
            Ok(0)
        }
        Command::Rule { code } => match rtlint::rules::find(&code) {
            Some(r) => {
                print!("{}", r.doc);
                Ok(0)
            }
            None => Err(format!("unknown rule `{code}` (`rtlint rules` lists them)")),
        },
    }
}

/// Settings shared by every subcommand that reads shaders.
struct Setup {
    format: Format,
    config: Config,
    inputs: lint::Inputs,
    /// Input errors found before any file was read (bad config).
    errors: Vec<Diagnostic>,
}

fn setup(common: &Common) -> Result<Setup, String> {
    let format = Format::parse(&common.format).ok_or_else(|| {
        format!(
            "unknown format `{}` (expected human, json, github or sarif)",
            common.format
        )
    })?;
    let forced = match &common.lang {
        Some(l) => Some(
            Language::parse(l)
                .ok_or_else(|| format!("unknown language `{l}` (expected hlsl, wgsl or spirv)"))?,
        ),
        None => None,
    };
    let mut errors = Vec::new();
    let config_path = common
        .config
        .clone()
        .or_else(|| common.paths.first().and_then(|p| Config::discover(p)));
    let config = match config_path {
        Some(p) => match lint::load_config(&p) {
            Ok(c) => c,
            Err(e) => {
                errors.push(*e.0);
                Config::default()
            }
        },
        None => Config::default(),
    };
    let inputs = lint::collect_inputs(&common.paths, &config, forced);
    Ok(Setup {
        format,
        config,
        inputs,
        errors,
    })
}

fn check(
    common: Common,
    payload_budget: Option<u64>,
    deny_warnings: bool,
    pipelines: Vec<PathBuf>,
) -> Result<u8, String> {
    let Setup {
        format,
        mut config,
        mut inputs,
        errors,
    } = setup(&common)?;
    inputs.pipelines.extend(pipelines);
    if let Some(b) = payload_budget {
        config.payload_budget = b;
    }
    config.deny_warnings |= deny_warnings;
    let mut diagnostics = errors;
    diagnostics.extend(inputs.errors.iter().map(|e| (*e.0).clone()));
    let mut sources = Sources::default();
    for input in &inputs.files {
        let checked = lint::check_input(input, &config);
        if let Some(p) = &checked.program {
            sources.add_program(p);
        }
        diagnostics.extend(checked.diagnostics);
    }
    for p in &inputs.pipelines {
        diagnostics.extend(lint::check_pipeline(p, &config).diagnostics);
    }
    let summary = Summary::count(inputs.files.len() + inputs.pipelines.len(), &diagnostics);
    emit(
        format,
        &diagnostics,
        &summary,
        &mut sources,
        common.verbose.then_some(&inputs.skipped),
    )?;
    Ok(exit_code(&diagnostics, &config))
}

fn exit_code(diagnostics: &[Diagnostic], config: &Config) -> u8 {
    if diagnostics.iter().any(|d| d.code.is_none()) {
        2
    } else if diagnostics.iter().any(|d| {
        d.severity == Severity::Error || (config.deny_warnings && d.severity == Severity::Warning)
    }) {
        1
    } else {
        0
    }
}

fn emit(
    format: Format,
    diagnostics: &[Diagnostic],
    summary: &Summary,
    sources: &mut Sources,
    skipped: Option<&Vec<PathBuf>>,
) -> Result<(), String> {
    let io = |e: std::io::Error| format!("cannot write output: {e}");
    match format {
        Format::Human => {
            let mut out = StandardStream::stdout(color_choice());
            if let Some(skipped) = skipped {
                for p in skipped {
                    writeln!(
                        out,
                        "note: skipped {} (not a shader on its own)",
                        p.display()
                    )
                    .map_err(io)?;
                }
            }
            report::human::render(diagnostics, sources, &mut out).map_err(io)?;
            writeln!(out, "{}", report::human::summary_line(summary)).map_err(io)?;
        }
        Format::Json => println!("{}", report::json::render(diagnostics, summary)),
        Format::Github => print!("{}", report::github(diagnostics)),
        Format::Sarif => println!("{}", report::sarif::render(diagnostics)),
    }
    Ok(())
}

fn color_choice() -> ColorChoice {
    if std::env::var_os("NO_COLOR").is_some()
        || !std::io::IsTerminal::is_terminal(&std::io::stdout())
    {
        ColorChoice::Never
    } else {
        ColorChoice::Auto
    }
}

fn layout(common: Common) -> Result<u8, String> {
    let Setup {
        format,
        inputs,
        errors,
        ..
    } = setup(&common)?;
    if matches!(format, Format::Github | Format::Sarif) {
        return Err("`rtlint layout` prints human or json".into());
    }
    let mut problems: Vec<Diagnostic> = errors;
    problems.extend(inputs.errors.iter().map(|e| (*e.0).clone()));
    let mut files = Vec::new();
    for p in load_programs(&inputs, &mut problems) {
        files.push(rtlint::analysis::layout::FileLayouts::new(&p));
    }
    match format {
        Format::Json => {
            let errors: Vec<_> = problems.iter().map(report::json::diagnostic).collect();
            let v = serde_json::json!({ "files": files, "errors": errors });
            println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        }
        _ => {
            let mut out = StandardStream::stdout(color_choice());
            for f in &files {
                write!(out, "{}", f.render_human()).map_err(|e| e.to_string())?;
            }
            let mut sources = Sources::default();
            report::human::render(&problems, &mut sources, &mut out).map_err(|e| e.to_string())?;
        }
    }
    Ok(if problems.is_empty() { 0 } else { 2 })
}

fn live(common: Common) -> Result<u8, String> {
    let Setup {
        format,
        inputs,
        errors,
        ..
    } = setup(&common)?;
    let mut problems: Vec<Diagnostic> = errors;
    problems.extend(inputs.errors.iter().map(|e| (*e.0).clone()));
    let programs = load_programs(&inputs, &mut problems);
    let report = rtlint::analysis::live_report(&programs);
    print_report(
        format,
        &report,
        rtlint::analysis::liveness::render_human(&report),
        &problems,
    )
}

fn stack(common: Common, driver: bool) -> Result<u8, String> {
    let Setup {
        format,
        inputs,
        errors,
        ..
    } = setup(&common)?;
    let mut problems: Vec<Diagnostic> = errors;
    problems.extend(inputs.errors.iter().map(|e| (*e.0).clone()));
    let mut pipelines = Vec::new();
    for p in &inputs.pipelines {
        match rtlint::pipeline::load(p) {
            Ok(p) => pipelines.push(p),
            Err(InputError(d)) => problems.push(*d),
        }
    }
    // Loose shaders: one conservative pipeline over all of them.
    if !inputs.files.is_empty() {
        let programs = load_programs(&inputs, &mut problems);
        if !programs.is_empty() {
            pipelines.push(rtlint::pipeline::Pipeline::from_programs(programs));
        }
    }
    #[cfg(not(feature = "vulkan"))]
    if driver {
        return Err("--driver needs rtlint built with the `vulkan` feature".into());
    }
    #[cfg_attr(not(feature = "vulkan"), allow(unused_variables))]
    let loose: Vec<String> = inputs
        .files
        .iter()
        .map(|f| format!("{}:{}", f.language.as_str(), f.path.display()))
        .collect();
    let mut reports = Vec::new();
    for p in &pipelines {
        #[allow(unused_mut)]
        let mut r = rtlint::analysis::stack_report(p);
        #[cfg(feature = "vulkan")]
        if driver {
            match driver_in_child(p, &loose) {
                Ok(d) => {
                    let sizes = d
                        .sizes
                        .iter()
                        .map(|&(slot, stage, b)| ((slot, stage), b))
                        .collect();
                    rtlint::analysis::stack::attach_driver(&mut r, p, &sizes);
                    r.assumptions
                        .push(format!("driver: {} ({})", d.device, d.driver));
                }
                Err(message) => problems.push(
                    *rtlint::diag::InputError::new(
                        "driver",
                        &p.path
                            .clone()
                            .or_else(|| p.programs.first().map(|q| q.path.clone()))
                            .unwrap_or_default(),
                        format!("--driver: {message}"),
                    )
                    .0,
                ),
            }
        }
        reports.push(r);
    }
    let human: String = reports
        .iter()
        .map(rtlint::analysis::stack::render_human)
        .collect::<Vec<_>>()
        .join("\n");
    let value = if reports.len() == 1 {
        serde_json::to_value(&reports[0])
    } else {
        serde_json::to_value(&reports)
    }
    .map_err(|e| e.to_string())?;
    print_report(format, &value, human, &problems)
}

/// Loads every input into a Program; the ones that fail become input errors.
fn load_programs(
    inputs: &lint::Inputs,
    problems: &mut Vec<Diagnostic>,
) -> Vec<rtlint::program::Program> {
    let mut programs = Vec::new();
    for input in &inputs.files {
        match rtlint::front::load(&input.path, input.language) {
            Ok(p) => programs.push(p),
            Err(InputError(d)) => problems.push(*d),
        }
    }
    programs
}

/// Prints a report as JSON or text, then any input errors; exit 2 on errors.
fn print_report<T: serde::Serialize>(
    format: Format,
    value: &T,
    human: String,
    problems: &[Diagnostic],
) -> Result<u8, String> {
    match format {
        Format::Json => {
            let mut v = serde_json::to_value(value).map_err(|e| e.to_string())?;
            if !v.is_object() && !problems.is_empty() {
                // Several reports print as an array, which has no room for
                // the errors: they go to stderr, in text.
                let mut err = StandardStream::stderr(color_choice());
                report::human::render(problems, &mut Sources::default(), &mut err)
                    .map_err(|e| e.to_string())?;
            }
            if let Some(obj) = v.as_object_mut() {
                obj.insert(
                    "errors".into(),
                    serde_json::to_value(
                        problems
                            .iter()
                            .map(report::json::diagnostic)
                            .collect::<Vec<_>>(),
                    )
                    .map_err(|e| e.to_string())?,
                );
            }
            println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        }
        Format::Human => {
            let mut out = StandardStream::stdout(color_choice());
            write!(out, "{human}").map_err(|e| e.to_string())?;
            report::human::render(problems, &mut Sources::default(), &mut out)
                .map_err(|e| e.to_string())?;
        }
        _ => return Err("this command prints human or json".into()),
    }
    Ok(if problems.is_empty() { 0 } else { 2 })
}

fn compile(
    file: PathBuf,
    entry: Option<String>,
    include: Vec<PathBuf>,
    define: Vec<String>,
    output: PathBuf,
    whole: bool,
) -> Result<u8, String> {
    use rtlint::front::hlsl;
    let options = hlsl::HlslOptions {
        include_dirs: include,
        defines: define
            .iter()
            .map(|d| match d.split_once('=') {
                Some((n, v)) => (n.to_string(), v.to_string()),
                None => (d.clone(), "1".to_string()),
            })
            .collect(),
        entry,
    };
    let write = |path: &std::path::Path, words: &[u32]| -> Result<(), String> {
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    let report = |e: InputError| -> Result<u8, String> {
        let mut out = StandardStream::stderr(color_choice());
        let mut sources = Sources::default();
        report::human::render(&[*e.0], &mut sources, &mut out).map_err(|e| e.to_string())?;
        Ok(2)
    };
    if whole {
        return match hlsl::compile_file(&file, &options) {
            Ok(m) => {
                write(&output, &m.words)?;
                eprintln!("{}: {} entry points", output.display(), m.entries.len());
                Ok(0)
            }
            Err(e) => report(e),
        };
    }
    let entries = match hlsl::compile(&file, &options) {
        Ok(e) => e,
        Err(e) => return report(e),
    };
    if entries.is_empty() {
        return Err(format!("{}: no entry point to compile", file.display()));
    }
    if output.is_dir() {
        for e in &entries {
            let path = output.join(format!("{}.spv", e.name));
            write(&path, &e.words)?;
            eprintln!("{}", path.display());
        }
    } else if let [only] = entries.as_slice() {
        write(&output, &only.words)?;
    } else {
        let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        return Err(format!(
            "{} has {} entry points ({}): pick one with -E, write them to a directory, or use --whole",
            file.display(),
            entries.len(),
            names.join(", ")
        ));
    }
    Ok(0)
}

/// What the child process of `stack --driver` reports for one pipeline.
#[derive(serde::Serialize, serde::Deserialize)]
struct DriverSizes {
    device: String,
    driver: String,
    sizes: Vec<(rtlint::pipeline::Slot, rtlint::shader::Stage, u64)>,
    validation_errors: Vec<String>,
}

/// How long one pipeline's creation may take in the child.
const DRIVER_CHILD_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(120);

#[cfg(feature = "vulkan")]
/// Runs `driver-stack-sizes` for one pipeline in a child process: a driver
/// that crashes or hangs costs that pipeline its driver figures, with a
/// message, and nothing else. Validation errors (`RTLINT_VK_VALIDATION=1`)
/// are errors too: the layout rtlint built does not match the shaders.
fn driver_in_child(
    p: &rtlint::pipeline::Pipeline,
    loose: &[String],
) -> Result<DriverSizes, String> {
    // RTLINT_DRIVER_CHILD names another program to run as the child (the
    // tests use it to stand in for a driver that crashes).
    let exe = match std::env::var_os("RTLINT_DRIVER_CHILD") {
        Some(p) => PathBuf::from(p),
        None => std::env::current_exe().map_err(|e| format!("cannot find rtlint itself: {e}"))?,
    };
    let mut command = std::process::Command::new(exe);
    command.arg("driver-stack-sizes");
    match &p.path {
        Some(path) => {
            command.arg("--pipeline").arg(path);
        }
        None => {
            for s in loose {
                command.arg("--shader").arg(s);
            }
        }
    }
    let o = rtlint::vk::run_command(command, DRIVER_CHILD_TIMEOUT)
        .map_err(|e| format!("cannot start a child process: {e}"))?;
    let last_line = |t: &str| {
        t.lines()
            .rev()
            .find(|l| l.starts_with("error: "))
            .map(|l| l.trim_start_matches("error: ").to_string())
            .unwrap_or_else(|| t.lines().last().unwrap_or("").to_string())
    };
    if o.timed_out {
        return Err(format!(
            "creating the pipeline on the device took over {} s; the child was killed",
            DRIVER_CHILD_TIMEOUT.as_secs()
        ));
    }
    if let Some(sig) = o.signal {
        return Err(format!(
            "the driver crashed while creating the pipeline (signal {sig}{})",
            match sig {
                11 => ", SIGSEGV",
                7 => ", SIGBUS",
                6 => ", SIGABRT",
                _ => "",
            }
        ));
    }
    if !o.success() {
        return Err(last_line(&o.stderr));
    }
    let d: DriverSizes = serde_json::from_str(&o.stdout)
        .map_err(|e| format!("unreadable answer from the child process: {e}"))?;
    if let Some(first) = d.validation_errors.first() {
        return Err(format!(
            "the validation layer reported {} error(s) on this pipeline; the first: {first}",
            d.validation_errors.len()
        ));
    }
    Ok(d)
}

/// The child's side of [`driver_in_child`].
fn driver_stack_sizes(pipeline: Option<PathBuf>, shaders: Vec<String>) -> Result<u8, String> {
    let p = match pipeline {
        Some(path) => rtlint::pipeline::load(&path).map_err(|e| e.0.message.clone())?,
        None => {
            let mut programs = Vec::new();
            for s in &shaders {
                let (lang, path) = s
                    .split_once(':')
                    .ok_or_else(|| format!("`{s}` is not LANG:PATH"))?;
                let lang =
                    Language::parse(lang).ok_or_else(|| format!("unknown language `{lang}`"))?;
                programs.push(
                    rtlint::front::load(std::path::Path::new(path), lang)
                        .map_err(|e| e.0.message.clone())?,
                );
            }
            rtlint::pipeline::Pipeline::from_programs(programs)
        }
    };
    driver_stack_sizes_of(&p)
}

#[cfg(feature = "vulkan")]
fn driver_stack_sizes_of(p: &rtlint::pipeline::Pipeline) -> Result<u8, String> {
    let ctx = rtlint::vk::Context::new().map_err(|e| e.to_string())?;
    let depth = rtlint::analysis::recursion_report(p).required_depth;
    let sizes = rtlint::vk::driver_stack_sizes(&ctx, p, depth)
        .map_err(|e| format!("creating the pipeline on {} failed: {e}", ctx.info().name))?;
    let d = DriverSizes {
        device: ctx.info().name.clone(),
        driver: ctx.info().driver.clone(),
        sizes: sizes
            .into_iter()
            .map(|((slot, stage), b)| (slot, stage, b))
            .collect(),
        validation_errors: ctx.validation_errors(),
    };
    drop(ctx);
    println!("{}", serde_json::to_string(&d).map_err(|e| e.to_string())?);
    Ok(0)
}

#[cfg(not(feature = "vulkan"))]
fn driver_stack_sizes_of(_: &rtlint::pipeline::Pipeline) -> Result<u8, String> {
    Err("--driver needs rtlint built with the `vulkan` feature".into())
}
