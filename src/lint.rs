//! The linting driver shared by the CLI and the build-script API: find the
//! inputs, load each into a Program, run the rules.

use crate::config::Config;
use crate::diag::{Diagnostic, InputError, InputErrorKind};
use crate::front;
use crate::program::Program;
use crate::shader::Language;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Input {
    pub path: PathBuf,
    pub language: Language,
}

/// Loads `rtlint.toml` and checks its rule names against the registry.
pub fn load_config(path: &Path) -> Result<Config, InputError> {
    let config = Config::load(path)?;
    config.check_rule_names(|k| crate::rules::find(k).is_some())?;
    Ok(config)
}

/// What walking the paths found.
#[derive(Debug, Default)]
pub struct Inputs {
    pub files: Vec<Input>,
    /// Pipeline descriptions (`*.pipeline.toml`).
    pub pipelines: Vec<PathBuf>,
    /// Paths that could not be used (missing, unknown language when named).
    pub errors: Vec<InputError>,
    /// Files skipped inside directories, for `--verbose`.
    pub skipped: Vec<PathBuf>,
}

/// Walks `paths`: files are taken as named, directories recursively (sorted,
/// so output is stable), picking files by extension.
pub fn collect_inputs(paths: &[PathBuf], config: &Config, forced: Option<Language>) -> Inputs {
    let mut inputs = Inputs::default();
    for p in paths {
        let meta = match std::fs::metadata(p) {
            Ok(m) => m,
            Err(e) => {
                inputs.errors.push(front::io_error(p, &e));
                continue;
            }
        };
        if meta.is_dir() {
            walk(p, config, forced, &mut inputs);
        } else if is_pipeline(p) {
            inputs.pipelines.push(p.clone());
        } else {
            match language_of(p, config, forced) {
                Some(language) => inputs.files.push(Input {
                    path: p.clone(),
                    language,
                }),
                None => inputs.errors.push(InputError::new(
                    InputErrorKind::UnknownLanguage,
                    p,
                    "cannot tell the shader language from the file extension; pass --lang or map the extension under [languages] in rtlint.toml",
                )),
            }
        }
    }
    inputs
}

fn walk(dir: &Path, config: &Config, forced: Option<Language>, inputs: &mut Inputs) {
    let mut entries: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(rd) => rd.filter_map(|e| e.ok().map(|e| e.path())).collect(),
        Err(e) => {
            inputs.errors.push(front::io_error(dir, &e));
            return;
        }
    };
    entries.sort();
    for p in entries {
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if p.is_dir() {
            walk(&p, config, forced, inputs);
        } else if is_pipeline(&p) {
            inputs.pipelines.push(p);
        } else if p
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("hlsli"))
        {
            // A header: analysed through the shaders that include it.
            inputs.skipped.push(p);
        } else if let Some(language) =
            language_of(&p, config, None).or(forced.filter(|_| is_shader_like(&p)))
        {
            inputs.files.push(Input { path: p, language });
        } else {
            inputs.skipped.push(p);
        }
    }
}

pub fn is_pipeline(p: &Path) -> bool {
    p.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.ends_with(".pipeline.toml"))
}

/// `--lang` applies to named files; inside directories only to files that are
/// not obviously something else.
fn is_shader_like(p: &Path) -> bool {
    !matches!(
        p.extension().and_then(|e| e.to_str()),
        Some("md" | "toml" | "txt" | "json" | "sh" | "py" | "rs" | "png" | "ppm")
    ) && p.extension().is_some()
}

fn language_of(p: &Path, config: &Config, forced: Option<Language>) -> Option<Language> {
    forced
        .or_else(|| config.language_for(p))
        .or_else(|| Language::from_path(p))
}

/// One input's outcome.
#[derive(Debug)]
pub struct Checked {
    pub path: PathBuf,
    pub program: Option<Program>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Loads and checks one input; a bad input becomes one error diagnostic.
pub fn check_input(input: &Input, config: &Config) -> Checked {
    match front::load(&input.path, input.language) {
        Ok(program) => {
            let diagnostics = crate::rules::check_program(&program, config);
            Checked {
                path: input.path.clone(),
                program: Some(program),
                diagnostics,
            }
        }
        Err(e) => Checked {
            path: input.path.clone(),
            program: None,
            diagnostics: vec![*e.0],
        },
    }
}

/// Loads a pipeline description and runs the pipeline rules on it.
pub fn check_pipeline(path: &Path, config: &Config) -> Checked {
    match crate::pipeline::load(path) {
        Ok(pipeline) => {
            let ctx = crate::rules::PipelineContext::new(&pipeline, config);
            Checked {
                path: path.to_path_buf(),
                program: None,
                diagnostics: crate::rules::check_pipeline(&ctx),
            }
        }
        Err(e) => Checked {
            path: path.to_path_buf(),
            program: None,
            diagnostics: vec![*e.0],
        },
    }
}

/// The shader files a pipeline description uses (nothing when it cannot be
/// read: `check_pipeline` reports that).
pub fn described_shaders(path: &Path) -> Vec<PathBuf> {
    crate::pipeline::load(path)
        .map(|p| p.programs.iter().map(|p| canonical(&p.path)).collect())
        .unwrap_or_default()
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Runs the pipeline rules (RT020–RT025) on shaders no description uses:
/// the shaders of each folder form one pipeline in which every trace may
/// reach every hit group and miss shader, and each finding says so.
pub fn check_loose(
    programs: Vec<Program>,
    described: &[PathBuf],
    config: &Config,
) -> Vec<Diagnostic> {
    let mut groups: Vec<(PathBuf, Vec<Program>)> = Vec::new();
    for p in programs {
        if described.contains(&canonical(&p.path)) {
            continue;
        }
        let has_rt = p.entry_points.iter().any(|e| e.stage.is_ray_tracing());
        if !has_rt {
            continue;
        }
        // A file holding a ray generation shader and others (WGSL, HLSL) is
        // a pipeline of its own; one-stage modules pipeline with their folder.
        let whole = p
            .entry_points
            .iter()
            .any(|e| e.stage == crate::shader::Stage::RayGeneration)
            && p.entry_points.len() > 1;
        let dir = if whole {
            p.path.clone()
        } else {
            p.path.parent().map(Path::to_path_buf).unwrap_or_default()
        };
        match groups.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, g)) => g.push(p),
            None => groups.push((dir, vec![p])),
        }
    }
    let mut out = Vec::new();
    for (_, programs) in groups {
        let pipeline = crate::pipeline::Pipeline::from_programs(programs);
        let ctx = crate::rules::PipelineContext::new(&pipeline, config);
        let note = crate::analysis::callgraph::Assumption::Undescribed.to_string();
        out.extend(
            crate::rules::check_pipeline(&ctx)
                .into_iter()
                .map(|d| d.with_note(note.clone())),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without a description every trace may reach every shader: RT020–RT025
    /// still run, and each finding says what was assumed.
    #[test]
    fn loose_shaders_get_pipeline_rules_with_the_assumption() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/guards/constructed.wgsl");
        let p = front::load(&path, Language::Wgsl).unwrap();
        let d = check_loose(vec![p], &[], &Config::default());
        let rt020: Vec<_> = d.iter().filter(|d| d.code == Some("RT020")).collect();
        assert_eq!(rt020.len(), 1, "{d:?}");
        assert_eq!(rt020[0].primary.as_ref().unwrap().location.line, 38);
        assert!(rt020[0]
            .notes
            .iter()
            .any(|n| n.contains("every trace may reach every hit group and miss shader")));
        // A shader a description uses is checked with that description only.
        let p = front::load(&path, Language::Wgsl).unwrap();
        assert!(check_loose(vec![p], &[canonical(&path)], &Config::default()).is_empty());
    }
}
