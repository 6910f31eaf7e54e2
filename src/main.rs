//! The `rtlint` command line.

use clap::{Parser, Subcommand};
use codespan_reporting::term::termcolor::{self, ColorChoice, StandardStream, WriteColor};
use rtlint::diag::{Diagnostic, InputError};
use rtlint::lint;
use rtlint::report::{self, Sources, Summary};
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
    /// Shader files or directories (walked recursively); `-` reads standard input.
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Read this config for every file instead of each file's nearest rtlint.toml.
    #[arg(long, conflicts_with = "no_config")]
    config: Option<PathBuf>,
    /// Read no rtlint.toml: the defaults.
    #[arg(long)]
    no_config: bool,
    /// Treat every named file as this language.
    #[arg(long, value_enum)]
    lang: Option<LangArg>,
    /// The name standard input (`-`) is linted under; its extension picks the language.
    #[arg(long, value_name = "PATH")]
    stdin_filename: Option<PathBuf>,
    /// Walk into what .gitignore, .ignore and .git/info/exclude ignore.
    #[arg(long)]
    no_gitignore: bool,
    /// Also say which files were skipped.
    #[arg(short, long)]
    verbose: bool,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum LangArg {
    Hlsl,
    Wgsl,
    Spirv,
    Glsl,
}

impl LangArg {
    fn language(self) -> Language {
        match self {
            LangArg::Hlsl => Language::Hlsl,
            LangArg::Wgsl => Language::Wgsl,
            LangArg::Spirv => Language::Spirv,
            LangArg::Glsl => Language::Glsl,
        }
    }
}

/// Output formats of `check`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum CheckFormat {
    /// Findings with source snippets (codespan-reporting).
    #[value(alias = "full", alias = "text")]
    Human,
    /// One line per finding: `path:line:col: level[CODE] message`.
    Concise,
    Json,
    /// GitHub Actions workflow commands (annotations).
    Github,
    /// SARIF 2.1.0.
    Sarif,
}

/// Output formats of `layout`, `live` and `stack`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum ReportFormat {
    #[value(alias = "text")]
    Human,
    Json,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum ColorArg {
    Auto,
    Always,
    Never,
}

/// `rtlint check`.
#[derive(clap::Args, Clone)]
struct CheckArgs {
    #[command(flatten)]
    common: Common,
    #[arg(long, value_enum, default_value = "human")]
    format: CheckFormat,
    /// Run only these rules: codes, code prefixes, names, groups or ALL (comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "RULES")]
    select: Option<Vec<String>>,
    /// Run these rules too.
    #[arg(long, value_delimiter = ',', value_name = "RULES")]
    extend_select: Vec<String>,
    /// Do not run these rules.
    #[arg(long, value_delimiter = ',', value_name = "RULES")]
    ignore: Vec<String>,
    /// Ray payloads above this many bytes are reported (RT001).
    #[arg(long)]
    payload_budget: Option<u64>,
    /// Warnings fail the run (exit 1) too, and so does finding no file to
    /// lint (exit 2; an empty shard of a non-empty set is not that).
    #[arg(long)]
    deny_warnings: bool,
    /// Exit 0 even when findings fail the run (input errors still exit 2).
    #[arg(long)]
    exit_zero: bool,
    /// Count findings per rule instead of listing them, in the format's own
    /// shape (JSON `statistics`, SARIF run properties, a GitHub notice and
    /// job summary).
    #[arg(long)]
    statistics: bool,
    /// Print findings only: no summary line, no notes.
    #[arg(short, long)]
    quiet: bool,
    /// Colour: auto honours NO_COLOR, FORCE_COLOR and CLICOLOR_FORCE.
    #[arg(long, value_enum, default_value = "auto")]
    color: ColorArg,
    /// Write the report to this file instead of standard output.
    #[arg(long, short = 'o', value_name = "FILE")]
    output_file: Option<PathBuf>,
    /// Also apply this pipeline description (`*.pipeline.toml` files in
    /// the walked directories are applied too).
    #[arg(long)]
    pipeline: Vec<PathBuf>,
    /// `fast`: only the rules that need layouts, ray flags and constant
    /// operands; `full` (the default): dataflow too (liveness, recursion
    /// guards, uniformity, the stack model). Overrides `analysis` in
    /// rtlint.toml.
    #[arg(long, value_enum, value_name = "LEVEL")]
    analysis: Option<AnalysisArg>,
    /// Do not read or write the result cache.
    #[arg(long)]
    no_cache: bool,
    /// The result cache's folder [default: $RTLINT_CACHE_DIR, else
    /// .rtlint_cache in the working directory].
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Check only part K of N of the files (1-based): folders are dealt out
    /// whole and deterministically, so N runs with K = 1..N together report
    /// what one run does.
    #[arg(long, value_name = "K/N")]
    shard: Option<lint::Shard>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum AnalysisArg {
    Fast,
    Full,
}

/// `rtlint verify`.
#[derive(clap::Args, Clone)]
struct VerifyArgs {
    /// The folder holding `verify.toml`, the shaders and `scenes/`
    /// [default: the reference shaders built into rtlint].
    #[arg(long, value_name = "DIR")]
    shaders: Option<PathBuf>,
    /// Where the tables (CSV, Markdown) and the images go: each case's GPU
    /// image, multi-pass cases' path pictures, and for a failed case the CPU
    /// image and the difference.
    #[arg(long, default_value = "target/verify")]
    out: PathBuf,
    /// Use the first ray-tracing device whose name contains this text.
    #[arg(long, value_name = "NAME")]
    device: Option<String>,
    /// Run only the cases whose name (`shader/scene`) contains this text.
    #[arg(long, value_name = "NAME")]
    filter: Option<String>,
    /// Also run the numerical-extremes matrix.
    #[arg(long)]
    extremes: bool,
    /// Internal: run one case on the device and write its image (the child
    /// process `verify` starts for every GPU run).
    #[arg(long, hide = true, value_names = ["CASE", "IMAGE"], num_args = 2)]
    child: Option<Vec<String>>,
}

/// `rtlint tradeoff`.
#[derive(clap::Args, Clone)]
struct TradeoffArgs {
    /// The folder holding `verify.toml`, the shaders and `scenes/`
    /// [default: the reference shaders built into rtlint].
    #[arg(long, value_name = "DIR")]
    shaders: Option<PathBuf>,
    /// Where the CSV, Markdown table, SVG plot and PNGs go.
    #[arg(long, default_value = "target/tradeoff")]
    out: PathBuf,
    /// Use the first ray-tracing device whose name contains this text.
    #[arg(long, value_name = "NAME")]
    device: Option<String>,
    /// The scene (`scenes/NAME.toml`).
    #[arg(long, value_name = "NAME", default_value = "showcase")]
    scene: String,
    /// A small sweep (a few settings, 32×32 pixels).
    #[arg(long)]
    quick: bool,
    /// Internal: run one setting on the device, time it and write its image
    /// (the child process `tradeoff` starts for every GPU run).
    #[arg(long, hide = true, value_names = ["SETTING", "IMAGE"], num_args = 2)]
    child: Option<Vec<String>>,
}

#[derive(Subcommand)]
enum Command {
    /// Lint shaders and report best-practice violations.
    #[command(after_help = DXC_HELP)]
    Check(Box<CheckArgs>),
    /// Values kept alive across each trace, callable and ray-query site.
    #[command(after_help = DXC_HELP)]
    Live {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "human")]
        format: ReportFormat,
    },
    /// Recursion depth and stack size of a described pipeline (or of loose
    /// shaders, assuming every trace reaches every shader whose incoming
    /// payload matches its own).
    #[command(after_help = DXC_HELP)]
    Stack {
        #[command(flatten)]
        common: Common,
        /// Create the pipeline on the Vulkan device and show what the driver
        /// reports (`vkGetRayTracingShaderGroupStackSizeKHR`) beside the model.
        #[arg(long)]
        driver: bool,
        /// Take the driver's numbers from this CSV (as
        /// calibration/random/to_csv.py writes it: pipeline, group, stage,
        /// entry, driver_bytes, …) instead of a device; a row applies to a
        /// pipeline whose description path ends with its `pipeline`.
        #[arg(long, value_name = "CSV", conflicts_with = "driver")]
        driver_numbers: Option<PathBuf>,
        #[arg(long, value_enum, default_value = "human")]
        format: ReportFormat,
    },
    /// Print payload, attribute and shader-record layouts with the best member order.
    #[command(after_help = DXC_HELP)]
    Layout {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "human")]
        format: ReportFormat,
    },
    /// Compile HLSL to SPIR-V with rtlint's own compiler.
    #[command(after_help = DXC_HELP)]
    Compile {
        /// The HLSL file.
        file: PathBuf,
        /// Say which DXC options change nothing here.
        #[arg(short, long)]
        verbose: bool,
        /// Output: a `.spv` file (one entry point, or with --whole every entry
        /// point in one module), or a directory for one module per entry point
        /// (DXC's `-Fo FILE` too; `-o DIR/` is created when missing). Without
        /// it the file is compiled and nothing is written (a check).
        #[arg(short = 'o', long = "output")]
        output: Option<PathBuf>,
        /// One module holding every entry point.
        #[arg(long)]
        whole: bool,
    },
    /// Run the reference reflection shaders on the Vulkan device and
    /// compare each image with the CPU reference renderer.
    Verify(VerifyArgs),
    /// Sweep the reference shaders' knobs (bounces, spp, tmax, rough_cutoff,
    /// half_res, ssr, tolerance, min_paths, max_paths, origin; docs/tradeoff.md
    /// says what each sets) and measure GPU time against error.
    Tradeoff(TradeoffArgs),
    /// List every rule.
    Rules,
    /// (Internal) `stack --driver` runs this in a child process per
    /// pipeline, so that a driver crash cannot take rtlint down: creates the
    /// pipeline and prints the driver's stack sizes as JSON.
    #[command(hide = true, name = "driver-stack-sizes")]
    DriverStackSizes {
        /// The pipeline as the parent loaded it: a description naming the
        /// SPIR-V of every module (see `driver_description`).
        #[arg(long)]
        pipeline: PathBuf,
    },
    /// Print a rule's documentation.
    Rule {
        /// Code (RT001) or name (payload-over-budget).
        code: String,
    },
}

/// The DXC options the HLSL commands read (clap does not see them).
const DXC_HELP: &str = "\
HLSL: DXC's options, as a build passes them (docs/hlsl.md lists them all):
  -I DIR, -D NAME[=VALUE]   include folder, define (HLSL and GLSL)
  -E NAME (--entry)         only this entry point
  -T PROFILE (--stage)      ps_6_x, cs_6_x, lib_6_x or a stage name
  -HV 2016|2018|2021|202x   language version (__HLSL_VERSION)
  -enable-16bit-types       16-bit half and min16 types
  -Zpr, -Zpc                default matrix packing
  -fspv-target-env=ENV      target environment (__SPIRV_*_VERSION__)
  -fvk-{b,t,u,s}-shift N SPACE|all, -fvk-bind-register xN SPACE BINDING SET,
  -fvk-bind-globals BINDING SET, -fvk-auto-shift-bindings, -auto-binding-space N
                            register to descriptor set and binding, as DXC maps them
  -spirv, -O3, -Zi, ...     accepted without effect (-v lists them)";

/// DXC's options, read from the command line before clap reads the rest:
/// DXC spells them with one dash and some take two or four values
/// (`-fvk-t-shift 1000 all`), which clap cannot express.
struct Dxc {
    options: rtlint::front::hlsl::HlslOptions,
    notes: Vec<String>,
    /// `--stage`/`-T` given a GLSL stage name.
    glsl_stage: Option<String>,
}

static DXC: std::sync::OnceLock<Dxc> = std::sync::OnceLock::new();

fn dxc() -> &'static Dxc {
    DXC.get_or_init(|| Dxc {
        options: Default::default(),
        notes: Vec::new(),
        glsl_stage: None,
    })
}

/// `--verbose`: the DXC options accepted without effect.
fn dxc_notes() {
    for n in &dxc().notes {
        eprintln!("note: {n}");
    }
}

/// The subcommands that compile HLSL read a DXC command line among their
/// arguments: `-T`, `-E`, `-I`, `-D`, `-HV`, `-fvk-*-shift`, ... (the
/// `rtlint_hlsl::parse_args` reader); what it does not know goes to clap.
/// `--entry`/`--stage` are rtlint's long names for `-E`/`-T`, and
/// `--enable-16bit-types` is taken for DXC's `-enable-16bit-types`.
fn take_dxc_args(argv: Vec<std::ffi::OsString>) -> Result<Vec<std::ffi::OsString>, String> {
    const HLSL_COMMANDS: &[&str] = &["check", "live", "stack", "layout", "compile"];
    let Some(sub) = argv
        .iter()
        .skip(1)
        .position(|a| !a.to_string_lossy().starts_with('-'))
        .map(|i| i + 1)
    else {
        return Ok(argv);
    };
    let command = argv[sub].to_string_lossy().into_owned();
    if !HLSL_COMMANDS.contains(&command.as_str()) {
        return Ok(argv);
    }
    // An argument that is not UTF-8 (a path) stands in as NUL and its
    // index (no argument can hold a NUL), and comes back unchanged.
    let mut args = Vec::new();
    // `--stage`/`-T` with a GLSL stage name (`rchit`) is the stage of GLSL
    // files whose extension names none, not a DXC profile.
    let mut glsl_stage = None;
    let mut skip = false;
    let rest = &argv[sub + 1..];
    for (i, a) in rest.iter().enumerate() {
        if std::mem::take(&mut skip) {
            continue;
        }
        let a = match a.to_str() {
            Some(s) => s.to_string(),
            None => format!("\0{i}"),
        };
        let next = rest.get(i + 1).and_then(|n| n.to_str());
        let attached = a.strip_prefix("--stage=").or_else(|| a.strip_prefix("-T"));
        match (a.as_str(), next, attached) {
            ("--stage" | "-T", Some(n), _) if is_glsl_stage(n) => {
                glsl_stage = Some(n.to_string());
                skip = true;
                continue;
            }
            (_, _, Some(v)) if is_glsl_stage(v) => {
                glsl_stage = Some(v.to_string());
                continue;
            }
            _ => {}
        }
        args.push(match a.as_str() {
            "--entry" => "-E".to_string(),
            "--stage" => "-T".to_string(),
            "--enable-16bit-types" => "-enable-16bit-types".to_string(),
            _ => match (a.strip_prefix("--entry="), a.strip_prefix("--stage=")) {
                (Some(e), _) => format!("-E{e}"),
                (_, Some(t)) => format!("-T{t}"),
                _ => a,
            },
        });
    }
    let mut options = rtlint::front::hlsl::HlslOptions::default();
    let parsed = rtlint::front::hlsl::parse_args(&args, &mut options)?;
    let mut out: Vec<std::ffi::OsString> = argv[..=sub].to_vec();
    for a in parsed.rest {
        match a.strip_prefix('\0').and_then(|i| i.parse::<usize>().ok()) {
            Some(i) => out.push(argv[sub + 1 + i].clone()),
            None => out.push(a.into()),
        }
    }
    let mut notes = parsed.notes;
    if let Some(o) = parsed.output {
        if command == "compile" {
            out.push("-o".into());
            out.push(o.into());
        } else {
            notes.push(format!(
                "-Fo {}: ignored by `rtlint {command}`",
                o.display()
            ));
        }
    }
    let _ = DXC.set(Dxc {
        options,
        notes,
        glsl_stage,
    });
    Ok(out)
}

fn main() -> ExitCode {
    let argv = match take_dxc_args(std::env::args_os().collect()) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let cli = match Cli::try_parse_from(argv) {
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
        Command::Check(args) => check(*args),
        Command::Live { common, format } => live(common, format),
        Command::Stack {
            common,
            driver,
            driver_numbers,
            format,
        } => stack(common, driver, driver_numbers, format),
        Command::Layout { common, format } => layout(common, format),
        Command::Compile {
            file,
            verbose,
            output,
            whole,
        } => {
            if verbose {
                dxc_notes();
            }
            // `-T lib_6_x` without `-E`, as DXC reads it: the whole library.
            let o = &dxc().options;
            let library = o
                .profile
                .is_some_and(|p| p.kind == rtlint::front::hlsl::ProfileKind::Library);
            let whole = whole || (library && o.entry.is_none());
            compile(file, o.clone(), output, whole)
        }
        Command::Verify(args) => verify(args),
        Command::Tradeoff(args) => tradeoff(args),
        Command::DriverStackSizes { pipeline } => driver_stack_sizes(pipeline),
        Command::Rules => {
            let mut out = std::io::stdout().lock();
            let level = |r: &rtlint::rules::Rule| {
                if r.group.on_by_default() {
                    r.level.as_str()
                } else {
                    "off"
                }
            };
            // Columns as wide as their longest entry: names grow.
            let rules = rtlint::rules::RULES;
            let width = |f: &dyn Fn(&rtlint::rules::Rule) -> usize| {
                rules.iter().map(|r| f(r)).max().unwrap_or(0)
            };
            let name_w = width(&|r| r.name.len());
            let level_w = width(&|r| level(r).len());
            let group_w = width(&|r| r.group.as_str().len());
            for r in rules {
                let _ = writeln!(
                    out,
                    "{}  {:<name_w$}  {:<level_w$}  {:<group_w$}  {}",
                    r.code,
                    r.name,
                    level(r),
                    r.group.as_str(),
                    r.summary
                );
            }
            Ok(0)
        }
        Command::Rule { code } => match rtlint::rules::find(&code) {
            Some(r) => {
                let _ = write!(std::io::stdout().lock(), "{}", r.page());
                Ok(0)
            }
            None => Err(format!("unknown rule `{code}` (`rtlint rules` lists them)")),
        },
    }
}

/// The lint options every subcommand that reads shaders shares.
fn options(common: &Common) -> Result<lint::Options, String> {
    let config = match (&common.config, common.no_config) {
        (Some(f), _) => lint::ConfigChoice::File(f.clone()),
        (None, true) => lint::ConfigChoice::Defaults,
        (None, false) => lint::ConfigChoice::Nearest,
    };
    let stdin = if common.paths.iter().any(|p| p.as_os_str() == "-") {
        let mut bytes = Vec::new();
        std::io::Read::read_to_end(&mut std::io::stdin(), &mut bytes)
            .map_err(|e| format!("cannot read standard input: {e}"))?;
        Some(bytes)
    } else {
        None
    };
    Ok(lint::Options {
        config,
        language: common.lang.map(LangArg::language),
        front: {
            if common.verbose {
                dxc_notes();
            }
            // `-I`/`-D` are shared with GLSL; the rest is HLSL's alone.
            let mut hlsl = dxc().options.clone();
            rtlint::front::FrontOptions {
                include_dirs: std::mem::take(&mut hlsl.include_dirs),
                defines: std::mem::take(&mut hlsl.defines),
                hlsl,
                glsl_stage: dxc().glsl_stage.clone(),
            }
        },
        respect_gitignore: !common.no_gitignore,
        stdin,
        stdin_filename: common.stdin_filename.clone(),
        ..lint::Options::default()
    })
}

fn is_glsl_stage(s: &str) -> bool {
    rtlint::shader::GLSL_STAGES.contains(&s)
}

fn check(args: CheckArgs) -> Result<u8, String> {
    for list in [
        args.select.as_deref().unwrap_or(&[]),
        &args.extend_select,
        &args.ignore,
    ] {
        lint::check_selectors(list)?;
    }
    let mut options = options(&args.common)?;
    options.pipelines = args.pipeline.clone();
    options.overrides = lint::Overrides {
        select: args.select.clone(),
        extend_select: args.extend_select.clone(),
        ignore: args.ignore.clone(),
        payload_budget: args.payload_budget,
        deny_warnings: args.deny_warnings,
        analysis: args.analysis.map(|a| match a {
            AnalysisArg::Fast => rtlint::config::AnalysisLevel::Fast,
            AnalysisArg::Full => rtlint::config::AnalysisLevel::Full,
        }),
    };
    options.shard = args.shard;
    if !args.no_cache {
        options.cache = Some(
            args.cache_dir
                .clone()
                .or_else(|| std::env::var_os("RTLINT_CACHE_DIR").map(PathBuf::from))
                .unwrap_or_else(|| PathBuf::from(rtlint::cache::DEFAULT_DIR)),
        );
    }
    let report = lint::check_paths(&args.common.paths, &options);
    let mut sources = Sources::default();
    for (p, t) in &report.embedded {
        sources.add_embedded(p, t);
    }
    let summary = Summary::count(
        report.files.len() + report.pipelines.len(),
        &report.diagnostics,
    );
    let color = color_choice(args.color, args.output_file.is_some());
    let result = match &args.output_file {
        Some(path) => {
            let file = std::fs::File::create(path)
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            let mut w = std::io::BufWriter::new(file);
            if color == ColorChoice::Always {
                let mut out = termcolor::Ansi::new(&mut w);
                emit(&args, &report, &summary, &mut sources, &mut out)
            } else {
                let mut out = termcolor::NoColor::new(&mut w);
                emit(&args, &report, &summary, &mut sources, &mut out)
            }
            .and_then(|()| w.flush())
        }
        None => {
            let mut out = StandardStream::stdout(color);
            emit(&args, &report, &summary, &mut sources, &mut out).and_then(|()| out.flush())
        }
    };
    match result {
        Ok(()) => {}
        // A reader that stopped reading (`| head`) is not an error.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(0),
        Err(e) => return Err(format!("cannot write output: {e}")),
    }
    if report.found_nothing() {
        eprintln!("warning: no files to lint");
        if args.deny_warnings {
            return Ok(2);
        }
    } else if report.is_empty() && !args.quiet {
        // The other shards have the files: a small project on a wide CI
        // matrix is not an error.
        let n = report.all_inputs;
        eprintln!(
            "note: this shard got none of the {n} input{}; the other shards check {}",
            if n == 1 { "" } else { "s" },
            if n == 1 { "it" } else { "them" }
        );
    }
    let code = report.exit_code();
    Ok(if args.exit_zero && code == 1 { 0 } else { code })
}

fn emit(
    args: &CheckArgs,
    report: &lint::Report,
    summary: &Summary,
    sources: &mut Sources,
    out: &mut dyn WriteColor,
) -> std::io::Result<()> {
    let diagnostics = &report.diagnostics;
    if args.statistics {
        // Input errors are still shown in full: they are not statistics.
        let errors: Vec<Diagnostic> = diagnostics
            .iter()
            .filter(|d| d.code.is_none())
            .cloned()
            .collect();
        match args.format {
            CheckFormat::Human | CheckFormat::Concise => {
                write!(out, "{}", report::statistics(diagnostics))?;
                report::human::render(&errors, sources, out)?;
            }
            CheckFormat::Json => writeln!(
                out,
                "{}",
                report::json::render_statistics(diagnostics, summary)
            )?,
            CheckFormat::Sarif => {
                writeln!(out, "{}", report::sarif::render_statistics(diagnostics))?
            }
            CheckFormat::Github => {
                let (notice, table) = report::github_statistics(diagnostics);
                write!(out, "{notice}{}", report::github(&errors))?;
                // The job's summary page, when run as a GitHub step.
                if let Some(path) = std::env::var_os("GITHUB_STEP_SUMMARY") {
                    let mut f = std::fs::OpenOptions::new()
                        .create(true)
                        .append(true)
                        .open(path)?;
                    f.write_all(table.as_bytes())?;
                }
            }
        }
        return Ok(());
    }
    match args.format {
        CheckFormat::Human => {
            if args.common.verbose && !args.quiet {
                for p in &report.skipped {
                    writeln!(
                        out,
                        "note: skipped {} (not a shader on its own)",
                        p.display()
                    )?;
                }
            }
            report::human::render(diagnostics, sources, out)?;
            if !args.quiet {
                writeln!(out, "{}", report::human::summary_line(summary))?;
            }
        }
        CheckFormat::Concise => {
            write!(out, "{}", report::concise(diagnostics))?;
            if !args.quiet {
                writeln!(out, "{}", report::human::summary_line(summary))?;
            }
        }
        CheckFormat::Json => writeln!(out, "{}", report::json::render(diagnostics, summary))?,
        CheckFormat::Github => write!(out, "{}", report::github(diagnostics))?,
        CheckFormat::Sarif => writeln!(out, "{}", report::sarif::render(diagnostics))?,
    }
    Ok(())
}

/// `--color`, with `auto` honouring NO_COLOR, then FORCE_COLOR and
/// CLICOLOR_FORCE, then whether the output is a terminal.
fn color_choice(arg: ColorArg, to_file: bool) -> ColorChoice {
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty() && v != "0");
    match arg {
        ColorArg::Always => ColorChoice::Always,
        ColorArg::Never => ColorChoice::Never,
        ColorArg::Auto if std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty()) => {
            ColorChoice::Never
        }
        ColorArg::Auto if set("FORCE_COLOR") || set("CLICOLOR_FORCE") => ColorChoice::Always,
        ColorArg::Auto if to_file || !std::io::IsTerminal::is_terminal(&std::io::stdout()) => {
            ColorChoice::Never
        }
        ColorArg::Auto => ColorChoice::Auto,
    }
}

/// What `layout`, `live` and `stack` read: loaded Programs, the pipeline
/// descriptions found, and input errors.
struct Loaded {
    programs: Vec<rtlint::program::Program>,
    /// The DXR subobjects of each program (empty but for HLSL libraries).
    subobjects: Vec<rtlint::front::hlsl::subobject::Subobjects>,
    /// Each description with its config.
    pipelines: Vec<(PathBuf, std::sync::Arc<rtlint::config::Config>)>,
    problems: Vec<Diagnostic>,
    /// How the inputs were read: descriptions compile their shaders alike.
    options: lint::Options,
}

fn load(common: &Common) -> Result<Loaded, String> {
    let options = options(common)?;
    let inputs = lint::inputs(&common.paths, &options);
    let mut problems: Vec<Diagnostic> = inputs.errors.iter().map(|e| (*e.0).clone()).collect();
    let mut programs = Vec::new();
    let mut subobjects = Vec::new();
    for input in &inputs.files {
        match lint::load_library(input, &options) {
            Ok((p, s)) => {
                programs.push(p);
                subobjects.push(s);
            }
            Err(InputError(d)) => problems.push(*d),
        }
    }
    lint::settle_headers(
        &mut problems,
        programs
            .iter()
            .flat_map(|p| p.files.iter().map(|f| &f.path)),
    );
    Ok(Loaded {
        programs,
        subobjects,
        pipelines: inputs.pipelines,
        problems,
        options,
    })
}

fn layout(common: Common, format: ReportFormat) -> Result<u8, String> {
    let Loaded {
        programs, problems, ..
    } = load(&common)?;
    let files: Vec<_> = programs
        .iter()
        .map(rtlint::analysis::layout::FileLayouts::new)
        .collect();
    let json = || {
        let files: Vec<_> = files.iter().map(report::layout::json).collect();
        serde_json::json!({ "version": 1, "files": files })
    };
    let human = || files.iter().map(report::layout::human).collect::<String>();
    print_report(format, json, human, &problems)
}

fn live(common: Common, format: ReportFormat) -> Result<u8, String> {
    let Loaded {
        programs, problems, ..
    } = load(&common)?;
    let report = rtlint::analysis::live_report(&programs);
    let json = || {
        let mut v = serde_json::to_value(&report).unwrap_or_default();
        if let Some(o) = v.as_object_mut() {
            o.insert("version".into(), 1.into());
        }
        v
    };
    print_report(format, json, || report::live::human(&report), &problems)
}

fn stack(
    common: Common,
    driver: bool,
    driver_numbers: Option<PathBuf>,
    format: ReportFormat,
) -> Result<u8, String> {
    let measured = match &driver_numbers {
        Some(path) => read_driver_numbers(path)?,
        None => Vec::new(),
    };
    let Loaded {
        programs,
        subobjects,
        pipelines: descriptions,
        mut problems,
        options,
    } = load(&common)?;
    let mut pipelines = Vec::new();
    let mut described = Vec::new();
    for (p, config) in &descriptions {
        match lint::load_pipeline(p, config, &options) {
            Ok(p) => {
                described.extend(p.programs.iter().map(|q| canonical(&q.path)));
                pipelines.push(p)
            }
            Err(InputError(d)) => problems.push(*d),
        }
    }
    // An HLSL library no description names, declaring DXR subobjects, is
    // the pipeline they describe.
    let mut loose_programs = Vec::new();
    for (program, s) in programs.into_iter().zip(subobjects) {
        // Its description's pipeline already has it.
        if described.contains(&canonical(&program.path)) {
            continue;
        }
        match rtlint::pipeline::Pipeline::from_subobjects(program, &s) {
            Ok(p) => pipelines.push(p),
            Err(program) => loose_programs.push(*program),
        }
    }
    // Loose shaders: one conservative pipeline per folder, as `check`
    // groups them (shaders in different folders are not one pipeline).
    let mut folders: Vec<(PathBuf, Vec<rtlint::program::Program>)> = Vec::new();
    for program in loose_programs {
        let dir = program.path.parent().map(canonical).unwrap_or_default();
        match folders.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, list)) => list.push(program),
            None => folders.push((dir, vec![program])),
        }
    }
    for (_, programs) in folders {
        pipelines.push(rtlint::pipeline::Pipeline::from_programs(programs));
    }
    #[cfg(not(feature = "vulkan"))]
    if driver {
        return Err("--driver needs rtlint built with the `vulkan` feature".into());
    }
    let mut reports = Vec::new();
    for p in &pipelines {
        #[allow(unused_mut)]
        let mut r = rtlint::analysis::stack_report(p);
        #[cfg(feature = "vulkan")]
        if driver {
            match driver_in_child(p) {
                Ok(d) => {
                    let sizes = d
                        .sizes
                        .iter()
                        .map(|&(slot, stage, b)| ((slot, stage), b))
                        .collect();
                    rtlint::analysis::stack::attach_driver(&mut r, p, &sizes);
                    r.assumptions
                        .push(rtlint::analysis::callgraph::Assumption::Driver {
                            device: d.device,
                            driver: d.driver,
                        });
                }
                Err(message) => problems.push(
                    *rtlint::diag::InputError::new(
                        rtlint::diag::InputErrorKind::DriverFailed,
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
        if driver_numbers.is_some() {
            let sizes = measured_for(&measured, p);
            if sizes.is_empty() {
                problems.push(
                    *InputError::new(
                        rtlint::diag::InputErrorKind::DriverFailed,
                        &p.file(),
                        "--driver-numbers: no row of the CSV names this pipeline",
                    )
                    .0,
                );
            } else {
                rtlint::analysis::stack::attach_driver(&mut r, p, &sizes);
            }
        }
        reports.push(r);
    }
    // One shape whatever the number of inputs: a list of pipeline reports.
    let json = || {
        let list: Vec<_> = reports.iter().map(report::stack::json).collect();
        serde_json::json!({ "version": 1, "pipelines": list })
    };
    let human = || {
        reports
            .iter()
            .map(report::stack::human)
            .collect::<Vec<_>>()
            .join("\n")
    };
    // A declared depth below the deepest chain fails on the device (RT021
    // is an error): CI should fail too.
    let too_shallow = reports
        .iter()
        .any(|r| report::stack::raise_depth_to(r).is_some());
    Ok(match print_report(format, json, human, &problems)? {
        0 if too_shallow => 1,
        code => code,
    })
}

/// Prints a report as JSON (with the input errors under `errors`) or text
/// followed by the input errors; exit 2 on input errors.
fn print_report(
    format: ReportFormat,
    json: impl FnOnce() -> serde_json::Value,
    human: impl FnOnce() -> String,
    problems: &[Diagnostic],
) -> Result<u8, String> {
    let result = match format {
        ReportFormat::Json => {
            let mut v = json();
            if let Some(obj) = v.as_object_mut() {
                obj.insert(
                    "errors".into(),
                    problems
                        .iter()
                        .map(|d| {
                            serde_json::to_value(report::json::diagnostic(d)).unwrap_or_default()
                        })
                        .collect(),
                );
            }
            let mut out = std::io::stdout().lock();
            writeln!(
                out,
                "{}",
                serde_json::to_string_pretty(&v).unwrap_or_default()
            )
        }
        ReportFormat::Human => {
            let mut out = StandardStream::stdout(color_choice(ColorArg::Auto, false));
            write!(out, "{}", human())
                .and_then(|()| report::human::render(problems, &mut Sources::default(), &mut out))
        }
    };
    match result {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(0),
        Err(e) => return Err(format!("cannot write output: {e}")),
    }
    Ok(if problems.iter().any(Diagnostic::is_input_error) {
        2
    } else {
        0
    })
}

fn compile(
    file: PathBuf,
    options: rtlint::front::hlsl::HlslOptions,
    output: Option<PathBuf>,
    whole: bool,
) -> Result<u8, String> {
    use rtlint::front::hlsl;
    let write = |path: &std::path::Path, words: &[u32]| -> Result<(), String> {
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    let report = |e: InputError| -> Result<u8, String> {
        let mut out = StandardStream::stderr(color_choice(ColorArg::Auto, false));
        let mut sources = Sources::default();
        report::human::render(&[*e.0], &mut sources, &mut out).map_err(|e| e.to_string())?;
        Ok(2)
    };
    if whole {
        return match hlsl::compile_file(&file, &options) {
            Ok(m) => {
                for w in &m.warnings {
                    eprintln!("{w}");
                }
                match &output {
                    Some(output) => {
                        write(output, &m.words)?;
                        eprintln!("{}: {} entry points", output.display(), m.entries.len());
                    }
                    None => eprintln!(
                        "{}: {} entry points compiled (no -o: nothing written)",
                        file.display(),
                        m.entries.len()
                    ),
                }
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
    for w in &entries[0].warnings {
        eprintln!("{w}");
    }
    let Some(output) = output else {
        let names: Vec<&str> = entries.iter().map(|e| e.name.as_str()).collect();
        eprintln!(
            "{}: {} compiled (no -o: nothing written)",
            file.display(),
            names.join(", ")
        );
        return Ok(0);
    };
    // `-o dir/` names a folder, which is created when missing.
    let folder = output.is_dir() || output.as_os_str().to_string_lossy().ends_with(['/', '\\']);
    if folder {
        std::fs::create_dir_all(&output)
            .map_err(|e| format!("cannot create {}: {e}", output.display()))?;
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

#[cfg(not(feature = "vulkan"))]
fn tradeoff(_: TradeoffArgs) -> Result<u8, String> {
    Err("tradeoff needs rtlint built with the `vulkan` feature".into())
}

/// `rtlint tradeoff`: every GPU run in a child process (this executable
/// with `tradeoff --child SETTING IMAGE`), a progress bar, the table and
/// the files; exit 1 when a setting failed.
#[cfg(feature = "vulkan")]
fn tradeoff(args: TradeoffArgs) -> Result<u8, String> {
    use rtlint::{tradeoff, verify};
    let shaders = match &args.shaders {
        Some(dir) => dir.clone(),
        None => verify::bundled::folder()?,
    };
    if let Some(child) = &args.child {
        let [setting, image] = child.as_slice() else {
            return Err("--child takes a setting and an image path".into());
        };
        return match tradeoff::child_main(
            &shaders,
            &args.scene,
            args.quick,
            setting,
            std::path::Path::new(image),
            args.device.as_deref(),
        ) {
            Ok(()) => Ok(0),
            Err(e) if e == verify::SKIP => Ok(verify::SKIP_CODE as u8),
            Err(e) => Err(e),
        };
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot find rtlint itself: {e}"))?;
    let make_child = |setting: &str, image: &std::path::Path| {
        let mut c = std::process::Command::new(&exe);
        c.arg("tradeoff")
            .arg("--shaders")
            .arg(&shaders)
            .arg("--scene")
            .arg(&args.scene)
            .arg("--child")
            .arg(setting)
            .arg(image);
        if args.quick {
            c.arg("--quick");
        }
        if let Some(d) = &args.device {
            c.arg("--device").arg(d);
        }
        c
    };
    let options = tradeoff::Options {
        shaders: shaders.clone(),
        out: args.out.clone(),
        scene: args.scene.clone(),
        quick: args.quick,
        child: &make_child,
    };
    let bar = progress_bar();
    let report = tradeoff::run(&options, |done, total, name| {
        advance(&bar, done, total, name)
    });
    bar.finish_and_clear();
    let report = report?;
    report.write(&args.out)?;
    let mut out = std::io::stdout().lock();
    let _ = write!(out, "{}", report.text());
    let failed = report
        .rows
        .iter()
        .filter(|r| matches!(r.outcome, tradeoff::Outcome::Failed(_)))
        .count();
    let front: Vec<String> = report.front().iter().map(|r| r.setting.name()).collect();
    let _ = writeln!(
        out,
        "{} settings, {} failed; Pareto front: {}; files in {}",
        report.rows.len(),
        failed,
        front.join(", "),
        args.out.display()
    );
    Ok(if failed == 0 { 0 } else { 1 })
}

#[cfg(not(feature = "vulkan"))]
fn verify(_: VerifyArgs) -> Result<u8, String> {
    Err("verify needs rtlint built with the `vulkan` feature".into())
}

/// `rtlint verify`: every GPU run in a child process (this executable with
/// `verify --child CASE IMAGE`), a progress bar, the table, exit 1 on a
/// failed case.
#[cfg(feature = "vulkan")]
fn verify(args: VerifyArgs) -> Result<u8, String> {
    use rtlint::verify;
    let shaders = match &args.shaders {
        Some(dir) => dir.clone(),
        None => verify::bundled::folder()?,
    };
    if let Some(child) = &args.child {
        let [case, image] = child.as_slice() else {
            return Err("--child takes a case and an image path".into());
        };
        return match verify::child_main(
            &shaders,
            case,
            std::path::Path::new(image),
            args.device.as_deref(),
        ) {
            Ok(()) => Ok(0),
            Err(e) if e == verify::SKIP => Ok(verify::SKIP_CODE as u8),
            Err(e) => Err(e),
        };
    }
    let exe = std::env::current_exe().map_err(|e| format!("cannot find rtlint itself: {e}"))?;
    let make_child = |case: &str, image: &std::path::Path| {
        let mut c = std::process::Command::new(&exe);
        c.arg("verify")
            .arg("--shaders")
            .arg(&shaders)
            .arg("--child")
            .arg(case)
            .arg(image);
        if let Some(d) = &args.device {
            c.arg("--device").arg(d);
        }
        c
    };
    let options = verify::Options {
        shaders: shaders.clone(),
        out: args.out.clone(),
        filter: args.filter.clone(),
        extremes: args.extremes,
        child: &make_child,
    };
    let bar = progress_bar();
    let report = verify::run(&options, |done, total, name| {
        advance(&bar, done, total, name)
    });
    bar.finish_and_clear();
    let report = report?;
    let mut out = std::io::stdout().lock();
    let device = report.device.as_deref().unwrap_or("no device answered");
    let _ = writeln!(out, "device: {device}");
    let _ = write!(out, "{}", report.text());
    let mut files = vec![
        ("verify.csv", report.csv()),
        ("verify.md", report.markdown()),
    ];
    if args.extremes {
        let matrix = verify::Report {
            device: report.device.clone(),
            rows: report
                .rows
                .iter()
                .filter(|r| r.case.name.starts_with("extremes/"))
                .cloned()
                .collect(),
        };
        files.push(("extremes.csv", matrix.csv()));
        files.push(("extremes.md", matrix.markdown()));
    }
    for (name, text) in files {
        let path = args.out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    }
    let failed = report.rows.iter().filter(|r| !r.passed()).count();
    let _ = writeln!(
        out,
        "{} cases, {} failed; tables in {}",
        report.rows.len(),
        failed,
        args.out.display()
    );
    Ok(if failed == 0 { 0 } else { 1 })
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
fn driver_in_child(p: &rtlint::pipeline::Pipeline) -> Result<DriverSizes, String> {
    // RTLINT_DRIVER_CHILD names another program to run as the child (the
    // tests use it to stand in for a driver that crashes).
    let exe = match std::env::var_os("RTLINT_DRIVER_CHILD") {
        Some(p) => PathBuf::from(p),
        None => std::env::current_exe().map_err(|e| format!("cannot find rtlint itself: {e}"))?,
    };
    // The child gets the modules as this process compiled them, whatever
    // options (includes, defines, register shifts) that took.
    static RUN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "rtlint-driver-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
    ));
    let description = driver_description(p, &dir)
        .map_err(|e| format!("cannot write the pipeline for the child process: {e}"))?;
    let mut command = std::process::Command::new(exe);
    command
        .arg("driver-stack-sizes")
        .arg("--pipeline")
        .arg(&description);
    let o = rtlint::vk::run_command(command, DRIVER_CHILD_TIMEOUT);
    let _ = std::fs::remove_dir_all(&dir);
    let o = o.map_err(|e| format!("cannot start a child process: {e}"))?;
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
        // The child names the modules it was given; say the user's files.
        let mut message = last_line(&o.stderr);
        for (i, program) in p.programs.iter().enumerate().rev() {
            let given = dir.join(format!("m{i}.spv"));
            message = message.replace(
                &given.display().to_string(),
                &program.path.display().to_string(),
            );
        }
        return Err(message);
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

/// Writes the pipeline as a description in `dir`: every module's SPIR-V
/// (`mN.spv`, as loaded, so the child compiles nothing again), the groups in
/// their slots' order, and the recursion depth the driver gets (the
/// declared one, else the one the shaders need).
fn driver_description(
    p: &rtlint::pipeline::Pipeline,
    dir: &std::path::Path,
) -> std::io::Result<PathBuf> {
    use std::fmt::Write as _;
    std::fs::create_dir_all(dir)?;
    for (i, program) in p.programs.iter().enumerate() {
        let bytes: Vec<u8> = program.words.iter().flat_map(|w| w.to_le_bytes()).collect();
        std::fs::write(dir.join(format!("m{i}.spv")), bytes)?;
    }
    let shader = |s: &rtlint::pipeline::ShaderRef| {
        format!(
            "file = \"m{}.spv\", entry = {}",
            s.program,
            toml_string(&s.entry)
        )
    };
    let mut t = String::new();
    let depth = p
        .max_recursion_depth
        .or_else(|| rtlint::analysis::recursion_report(p).required_depth);
    if let Some(d) = depth {
        let _ = writeln!(t, "max_recursion_depth = {d}");
    }
    for (table, list) in [("raygen", &p.raygen), ("miss", &p.miss)] {
        for s in list {
            let _ = writeln!(t, "[[{table}]]\n{}", shader(s).replace(", ", "\n"));
        }
    }
    for g in &p.hit_groups {
        let kind = match g.kind {
            rtlint::pipeline::HitGroupKind::Triangles => "triangles",
            rtlint::pipeline::HitGroupKind::Procedural => "procedural",
        };
        let _ = writeln!(t, "[[hit_group]]\ntype = \"{kind}\"");
        for (key, s) in [
            ("closest_hit", &g.closest_hit),
            ("any_hit", &g.any_hit),
            ("intersection", &g.intersection),
        ] {
            if let Some(s) = s {
                let _ = writeln!(t, "{key} = {{ {} }}", shader(s));
            }
        }
    }
    for s in &p.callable {
        let _ = writeln!(t, "[[callable]]\n{}", shader(s).replace(", ", "\n"));
    }
    let path = dir.join("driver.pipeline.toml");
    std::fs::write(&path, t)?;
    Ok(path)
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The child's side of [`driver_in_child`].
fn driver_stack_sizes(pipeline: PathBuf) -> Result<u8, String> {
    let p = rtlint::pipeline::load(&pipeline).map_err(|e| e.0.message.clone())?;
    driver_stack_sizes_of(&p)
}

#[cfg(feature = "vulkan")]
fn driver_stack_sizes_of(p: &rtlint::pipeline::Pipeline) -> Result<u8, String> {
    let ctx = rtlint::vk::Context::new().map_err(|e| e.to_string())?;
    let depth = rtlint::analysis::recursion_report(p).required_depth;
    let sizes = rtlint::vk::driver_stack_sizes(&ctx, p, depth).map_err(|e| match e {
        rtlint::vk::Error::Unsupported(needs) => {
            format!("skipped: needs {needs}, which {} lacks", ctx.info().name)
        }
        e => format!("creating the pipeline on {} failed: {e}", ctx.info().name),
    })?;
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

/// One row of a driver-numbers CSV: pipeline key, slot, stage, bytes.
type MeasuredRow = (String, rtlint::pipeline::Slot, rtlint::shader::Stage, u64);

/// Reads the CSV `--driver-numbers` names (header first; columns pipeline,
/// group, stage, entry, driver_bytes, …). A malformed row is an error.
fn read_driver_numbers(path: &std::path::Path) -> Result<Vec<MeasuredRow>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let bad = |what: &str| format!("{}:{}: {what}", path.display(), n + 1);
        let cols: Vec<&str> = line.split(',').collect();
        let [pipeline, group, stage, _entry, bytes, ..] = cols[..] else {
            return Err(bad("expected pipeline,group,stage,entry,driver_bytes"));
        };
        let slot = parse_slot(group).ok_or_else(|| bad(&format!("unknown group `{group}`")))?;
        let stage: rtlint::shader::Stage =
            serde_json::from_value(serde_json::Value::String(stage.to_string()))
                .map_err(|_| bad(&format!("unknown stage `{stage}`")))?;
        let bytes: u64 = bytes
            .parse()
            .map_err(|_| bad(&format!("`{bytes}` is not a byte count")))?;
        rows.push((pipeline.to_string(), slot, stage, bytes));
    }
    Ok(rows)
}

/// `raygen 0`, `miss 1`, `hit group 2`, `callable 0` (as reports print slots).
fn parse_slot(text: &str) -> Option<rtlint::pipeline::Slot> {
    use rtlint::pipeline::Slot;
    let (kind, index) = text.rsplit_once(' ')?;
    let i: usize = index.parse().ok()?;
    Some(match kind {
        "raygen" => Slot::Raygen(i),
        "miss" => Slot::Miss(i),
        "hit group" => Slot::HitGroup(i),
        "callable" => Slot::Callable(i),
        _ => return None,
    })
}

/// The rows of `measured` for pipeline `p`: those whose key its
/// description's path ends with.
fn measured_for(
    measured: &[MeasuredRow],
    p: &rtlint::pipeline::Pipeline,
) -> std::collections::BTreeMap<(rtlint::pipeline::Slot, rtlint::shader::Stage), u64> {
    let Some(path) = &p.path else {
        return Default::default();
    };
    let path = path.to_string_lossy().replace('\\', "/");
    measured
        .iter()
        .filter(|(key, ..)| path == *key || path.ends_with(&format!("/{key}")))
        .map(|(_, slot, stage, b)| ((*slot, *stage), *b))
        .collect()
}

fn canonical(p: &std::path::Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// The progress bar `verify` and `tradeoff` draw while their cases run.
#[cfg(feature = "vulkan")]
fn progress_bar() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Moves the bar to case `done` of `total`, named `name`.
#[cfg(feature = "vulkan")]
fn advance(bar: &indicatif::ProgressBar, done: usize, total: usize, name: &str) {
    bar.set_length(total as u64);
    bar.set_position(done as u64);
    bar.set_message(name.to_string());
}
