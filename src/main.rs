//! The `rtlint` command line.

use clap::{Parser, Subcommand};
use codespan_reporting::term::termcolor::{ColorChoice, StandardStream};
use rtlint::config::Config;
use rtlint::diag::{Diagnostic, InputError, Severity};
use rtlint::front::Language;
use rtlint::lint;
use rtlint::report::{self, Format, Sources, Summary};
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
    },
    /// Print payload, attribute and shader-record layouts with the best member order.
    Layout {
        #[command(flatten)]
        common: Common,
    },
    /// List every rule.
    Rules,
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
        } => check(common, payload_budget, deny_warnings),
        Command::Layout { common } => layout(common),
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
        Some(p) => match Config::load(&p) {
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

fn check(common: Common, payload_budget: Option<u64>, deny_warnings: bool) -> Result<u8, String> {
    let Setup {
        format,
        mut config,
        inputs,
        errors,
    } = setup(&common)?;
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
    let summary = Summary::count(inputs.files.len(), &diagnostics);
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
                        "note: skipped {} (not a shader extension)",
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
    for input in &inputs.files {
        match rtlint::front::load(&input.path, input.language) {
            Ok(p) => files.push(rtlint::analysis::layout::FileLayouts::new(&p)),
            Err(InputError(d)) => problems.push(*d),
        }
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
