//! The linting driver shared by the CLI, the build-script API and editors:
//! find the inputs, pick each one's config, load each into a Program, run the
//! rules, apply suppressions. [`check_paths`] is the one entry point.

use crate::analysis::callgraph::Assumption;
use crate::config::Config;
use crate::diag::{Diagnostic, InputError, InputErrorKind, Severity};
use crate::front::hlsl::subobject::Subobjects;
use crate::front::{self, FrontOptions};
use crate::program::Program;
use crate::shader::{Language, Location};
use rayon::prelude::*;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Which `rtlint.toml` applies to a file.
#[derive(Clone, Debug, Default)]
pub enum ConfigChoice {
    /// The nearest `rtlint.toml` in the file's folder or above it.
    #[default]
    Nearest,
    /// This file, for every input.
    File(PathBuf),
    /// None: the defaults.
    Defaults,
}

/// What the command line adds on top of each config.
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub select: Option<Vec<String>>,
    pub extend_select: Vec<String>,
    pub ignore: Vec<String>,
    pub payload_budget: Option<u64>,
    pub deny_warnings: bool,
    /// `--analysis`: which rules run by what they need.
    pub analysis: Option<crate::config::AnalysisLevel>,
}

/// How to lint.
#[derive(Clone, Debug)]
pub struct Options {
    pub config: ConfigChoice,
    pub overrides: Overrides,
    /// Treat named files (and shader-like files in walked folders) as this.
    pub language: Option<Language>,
    /// Pipeline descriptions to apply besides those found in the walk.
    pub pipelines: Vec<PathBuf>,
    /// `-I`/`-D` for HLSL and GLSL, after the config's.
    pub front: FrontOptions,
    /// Skip what `.gitignore`, `.ignore` and `.git/info/exclude` ignore.
    pub respect_gitignore: bool,
    /// The contents of standard input, read when a path is `-`.
    pub stdin: Option<Vec<u8>>,
    /// The name standard input is linted under (`--stdin-filename`).
    pub stdin_filename: Option<PathBuf>,
    /// The result cache's folder; `None`: no cache.
    pub cache: Option<PathBuf>,
    /// Check only this part of the files (`--shard K/N`).
    pub shard: Option<Shard>,
}

/// Part `index` (1-based) of `count`: folders are dealt out whole, so the
/// shaders a loose pipeline groups together stay on one shard.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("`{s}` is not a shard: write K/N with 1 ≤ K ≤ N, e.g. 2/4");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            config: ConfigChoice::Nearest,
            overrides: Overrides::default(),
            language: None,
            pipelines: Vec::new(),
            front: FrontOptions::default(),
            respect_gitignore: true,
            stdin: None,
            stdin_filename: None,
            cache: None,
            shard: None,
        }
    }
}

/// The outcome of a run: findings and input errors in a stable order.
#[derive(Debug, Default)]
pub struct Report {
    /// Findings and input errors: inputs in walk order, each input's findings
    /// in rule order; duplicates (a header's struct seen by several modules)
    /// once.
    pub diagnostics: Vec<Diagnostic>,
    /// Shader files read.
    pub files: Vec<PathBuf>,
    /// Pipeline descriptions read.
    pub pipelines: Vec<PathBuf>,
    /// Files in walked folders that are not shaders on their own.
    pub skipped: Vec<PathBuf>,
    /// Source text the modules embed, for showing snippets of files that are
    /// not on disk.
    pub embedded: Vec<(PathBuf, String)>,
    /// Warnings fail the run (any config or the command line said so).
    pub deny_warnings: bool,
    /// Shader files and descriptions of the whole set, before `--shard`
    /// kept one part: an empty shard of a non-empty set is not an empty run.
    pub all_inputs: usize,
}

impl Report {
    /// 0 clean, 1 findings at the failing level, 2 input errors.
    pub fn exit_code(&self) -> u8 {
        if self.diagnostics.iter().any(Diagnostic::is_input_error) {
            2
        } else if self.diagnostics.iter().any(|d| {
            d.severity == Severity::Error || (self.deny_warnings && d.severity == Severity::Warning)
        }) {
            1
        } else {
            0
        }
    }

    /// Nothing was linted.
    pub fn is_empty(&self) -> bool {
        self.files.is_empty() && self.pipelines.is_empty()
    }

    /// Nothing was linted because the paths hold nothing to lint (not
    /// because this shard's part of a non-empty set is empty).
    pub fn found_nothing(&self) -> bool {
        self.is_empty() && self.all_inputs == 0
    }
}

/// Lints `paths` (files, folders, or `-` for standard input).
pub fn check_paths(paths: &[PathBuf], options: &Options) -> Report {
    // Compiled GLSL is kept beside the results: a description's shaders
    // are compiled again each run otherwise (its pipeline is not cached).
    front::glsl::use_module_cache(options.cache.as_ref().map(|c| c.join("modules")));
    let mut configs = Configs::new(options);
    let mut inputs = collect(paths, options, &mut configs);
    // Shaders a description uses are checked with it (on the description's
    // shard), never as loose shaders: on every shard.
    let descriptions: Vec<Vec<PathBuf>> = inputs
        .pipelines
        .iter()
        .map(|(p, config)| described_shaders(p, config, options))
        .collect();
    let all_inputs = inputs.files.len() + inputs.pipelines.len();
    if let Some(shard) = options.shard {
        keep_shard(&mut inputs, &descriptions, shard);
    }
    let described: HashSet<PathBuf> = descriptions.into_iter().flatten().collect();
    let cache = options.cache.as_deref().and_then(crate::cache::Cache::open);
    let mut report = Report {
        files: inputs.files.iter().map(|i| i.path.clone()).collect(),
        pipelines: inputs.pipelines.iter().map(|(p, _)| p.clone()).collect(),
        skipped: inputs.skipped.clone(),
        all_inputs,
        ..Report::default()
    };
    // A config that cannot be read is reported once, by the first shard.
    if options.shard.is_some_and(|s| s.index != 1) {
        configs.errors.clear();
    }
    let mut diagnostics: Vec<Diagnostic> = configs.errors.clone();
    diagnostics.extend(inputs.errors.iter().map(|e| (*e.0).clone()));
    // Sets: a header or embedded source shared by many inputs is kept once.
    // (Hashed while collecting, sorted once at the end: a BTreeSet compares
    // paths component by component on every insert.)
    let mut owned: HashSet<PathBuf> = HashSet::new();
    let mut embedded: HashSet<PathBuf> = HashSet::new();
    let mut own_text = HashMap::new();
    // The loose pipelines: each group's members (input indices) and, once
    // checked, its findings. A folder's group is checked as soon as its last
    // input is, and its Programs dropped: memory follows the largest folder,
    // not the tree.
    let mut groups: Vec<(PathBuf, Vec<usize>, Option<Vec<Diagnostic>>)> = Vec::new();
    let mut group_of: HashMap<PathBuf, usize> = HashMap::new();
    // Groups not yet checked: looked at after each chunk (all groups would
    // make the run quadratic in the number of files).
    let mut pending: Vec<usize> = Vec::new();
    let folder = |p: &Path| p.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut last_in: HashMap<PathBuf, usize> = HashMap::new();
    for (i, input) in inputs.files.iter().enumerate() {
        last_in.insert(folder(&input.path), i);
    }
    let mut outcomes: Vec<Outcome> = Vec::with_capacity(inputs.files.len());
    const CHUNK: usize = 512;
    for (ci, chunk) in inputs.files.chunks(CHUNK).enumerate() {
        // Files in parallel; collected in input order, so output is the
        // same whatever the thread count.
        let checked: Vec<Outcome> = chunk
            .par_iter()
            .map(|input| check_cached(input, options, cache.as_ref()))
            .collect();
        for (k, mut c) in checked.into_iter().enumerate() {
            let i = ci * CHUNK + k;
            if c.analysed {
                for (path, text) in std::mem::take(&mut c.files) {
                    if let Some(t) = text {
                        if embedded.insert(path.clone()) {
                            report.embedded.push((path.clone(), t));
                        }
                    }
                    owned.insert(path);
                }
                // Suppressions are judged only in inputs that were analysed.
                owned.insert(inputs.files[i].path.clone());
                if let Some(found) = c.suppressions.take() {
                    own_text.insert(inputs.files[i].path.clone(), found);
                }
            }
            diagnostics.extend(std::mem::take(&mut c.diagnostics));
            if let Some(g) = &c.group {
                match group_of.get(g) {
                    Some(&k) => groups[k].1.push(i),
                    None => {
                        group_of.insert(g.clone(), groups.len());
                        pending.push(groups.len());
                        groups.push((g.clone(), vec![i], None));
                    }
                }
            }
            outcomes.push(c);
        }
        let done = ci * CHUNK + chunk.len();
        let Some(first) = inputs.files.first() else {
            continue;
        };
        let mut waiting = Vec::with_capacity(pending.len());
        for k in pending.drain(..) {
            let (dir, members, found) = &mut groups[k];
            // A group named by a file (a whole pipeline in one module) is
            // complete at once; a folder's after its last input.
            if last_in.get(dir.as_path()).is_some_and(|&l| l >= done) {
                waiting.push(k);
                continue;
            }
            let members: Vec<usize> = members
                .iter()
                .copied()
                .filter(|&i| {
                    described.is_empty() || !described.contains(&canonical(&inputs.files[i].path))
                })
                .collect();
            *found = Some(if members.is_empty() {
                Vec::new()
            } else {
                check_group_cached(
                    dir,
                    &folder(&inputs.files[members[0]].path),
                    &members,
                    &inputs.files,
                    &mut outcomes,
                    &first.config,
                    options,
                    cache.as_ref(),
                )
            });
        }
        pending = waiting;
        // Folders checked whole (their groups too): their cache packs are
        // written now, not held to the end of the run.
        if let Some(cache) = &cache {
            for (k, input) in chunk.iter().enumerate() {
                let dir = folder(&input.path);
                if last_in.get(&dir) == Some(&(ci * CHUNK + k)) {
                    cache.flush(&dir);
                }
            }
        }
    }
    settle_headers(&mut diagnostics, owned.iter());
    let pipelines: Vec<Checked> = inputs
        .pipelines
        .par_iter()
        .map(|(p, config)| check_pipeline(p, config, options))
        .collect();
    for c in pipelines {
        diagnostics.extend(c.diagnostics);
    }
    // Shaders no description uses still get the pipeline rules, under the
    // assumption that every trace reaches every shader that takes its
    // payload.
    for (_, _, found) in groups {
        diagnostics.extend(found.into_iter().flatten());
    }
    report.deny_warnings = options.overrides.deny_warnings
        || inputs.files.iter().any(|i| i.config.deny_warnings)
        || inputs.pipelines.iter().any(|(_, c)| c.deny_warnings);
    // The same finding from several modules (a struct or a trace in a
    // shared header) once, with the evidence of each: the secondary labels
    // (each includer's trace) of the copies are added to the one kept. A
    // finding without a position belongs to its own input, and two alike
    // there are two places (two traces of a module without debug info): the
    // n-th of them is told from the (n+1)-th.
    type Same = (
        Option<&'static str>,
        &'static str,
        String,
        Option<crate::shader::Location>,
        Option<PathBuf>,
        Option<String>,
        usize,
    );
    let mut kept_at: HashMap<Same, usize> = HashMap::new();
    // (code, name, message, input, subject) → how many seen so far.
    type Alike<'a> = (Option<&'a str>, &'a str, String, PathBuf, Option<String>);
    let mut alike: HashMap<Alike, usize> = HashMap::new();
    let mut merged: Vec<Diagnostic> = Vec::with_capacity(diagnostics.len());
    for d in diagnostics {
        let nth = if d.primary.is_none() {
            let n = alike
                .entry((
                    d.code,
                    d.name,
                    d.message.clone(),
                    d.file.clone(),
                    d.subject.clone(),
                ))
                .or_insert(0);
            *n += 1;
            *n
        } else {
            0
        };
        let key = (
            d.code,
            d.name,
            d.message.clone(),
            d.primary.as_ref().map(|l| l.location.clone()),
            d.primary.is_none().then(|| d.file.clone()),
            d.subject.clone(),
            nth,
        );
        match kept_at.get(&key) {
            Some(&k) => {
                for l in d.secondary {
                    if !merged[k].secondary.contains(&l) {
                        merged[k].secondary.push(l);
                    }
                }
            }
            None => {
                kept_at.insert(key, merged.len());
                merged.push(d);
            }
        }
    }
    let diagnostics = merged;
    let mut owned: Vec<PathBuf> = owned.into_iter().collect();
    owned.sort();
    let owned: Vec<(PathBuf, Arc<Config>)> = owned
        .into_iter()
        .map(|p| {
            let c = configs.for_file(&p);
            (p, c)
        })
        .collect();
    report.diagnostics = apply_suppressions(diagnostics, &owned, &report.embedded, &own_text);
    if let Some(cache) = &cache {
        cache.flush_all();
        cache.prune();
    }
    report
}

/// One input file and the config that applies to it.
#[derive(Clone, Debug)]
pub struct Input {
    pub path: PathBuf,
    pub language: Language,
    pub config: Arc<Config>,
    /// Standard input's contents, for the input named `-`.
    pub contents: Option<Arc<Vec<u8>>>,
}

/// What walking the paths found.
#[derive(Debug, Default)]
pub struct Inputs {
    pub files: Vec<Input>,
    /// Pipeline descriptions (`*.pipeline.toml`) with their configs.
    pub pipelines: Vec<(PathBuf, Arc<Config>)>,
    /// Paths that could not be used, and configs that could not be read.
    pub errors: Vec<InputError>,
    /// Files in walked folders that are not shaders on their own.
    pub skipped: Vec<PathBuf>,
}

/// Walks `paths` as [`check_paths`] does, without linting: what the other
/// commands (`layout`, `live`, `stack`) read.
pub fn inputs(paths: &[PathBuf], options: &Options) -> Inputs {
    let mut configs = Configs::new(options);
    let mut inputs = collect(paths, options, &mut configs);
    let mut errors: Vec<InputError> = configs
        .errors
        .into_iter()
        .map(|d| InputError(Box::new(d)))
        .collect();
    errors.append(&mut inputs.errors);
    inputs.errors = errors;
    inputs
}

/// Loads one input into a Program, with the config's and the options'
/// include directories and defines.
pub fn load(input: &Input, options: &Options) -> Result<Program, InputError> {
    load_library(input, options).map(|(program, _)| program)
}

/// [`load`], also giving the DXR subobjects an HLSL library declares.
pub fn load_library(input: &Input, options: &Options) -> Result<(Program, Subobjects), InputError> {
    let front_options = input_options(input, options);
    let contents = input.contents.as_deref().map(|v| v.as_slice());
    front::load_library(&input.path, contents, input.language, &front_options)
}

/// The front-end options `input` is compiled with: its config's `[hlsl]`,
/// then `options`', and the GLSL stage `[stages]` gives its path.
pub fn front_options_for(input: &Input, options: &Options) -> FrontOptions {
    input_options(input, options)
}

/// An HLSL file without an entry point is a header: when a file another
/// input read (`included`) is one, its error goes (its contents were linted
/// through its includers); otherwise the error becomes a note, since a
/// header nothing includes is no input error.
pub fn settle_headers<'a>(
    diagnostics: &mut Vec<Diagnostic>,
    included: impl Iterator<Item = &'a PathBuf>,
) {
    let no_entry = InputErrorKind::NoEntryPoint.as_str();
    if !diagnostics.iter().any(|d| d.name == no_entry) {
        return;
    }
    let included: HashSet<PathBuf> = included.map(|p| canonical(p)).collect();
    diagnostics.retain_mut(|d| {
        if d.name != no_entry || d.code.is_some() {
            return true;
        }
        if included.contains(&canonical(&d.file)) {
            return false;
        }
        d.severity = Severity::Note;
        d.message = "no entry point, and no linted file includes it: nothing to lint".into();
        d.help = Some(
            "mark an entry point with [shader(\"...\")] or [numthreads(...)], name one with its stage (-E main -T ps_6_5), or lint the shaders that include it".into(),
        );
        true
    });
}

/// Loads a pipeline description, compiling the shaders it names with the
/// same include directories and defines as every other input.
pub fn load_pipeline(
    path: &Path,
    config: &Config,
    options: &Options,
) -> Result<crate::pipeline::Pipeline, InputError> {
    let mut front = front_options(config, options);
    // The description names each entry point and its stage itself.
    front.hlsl.entry = None;
    front.hlsl.stage = None;
    front.glsl_stage = None;
    crate::pipeline::load_with(path, &front)
}

/// [`front_options`] for one input, with the GLSL stage `[stages]` gives
/// its path when the command line gives none.
fn input_options(input: &Input, options: &Options) -> FrontOptions {
    let mut front = front_options(&input.config, options);
    if front.glsl_stage.is_none() {
        front.glsl_stage = input.config.stage_for(&input.path).map(str::to_string);
    }
    front
}

/// The one set of compile options of an input: the config's `[hlsl]`
/// include directories and defines, then the command line's (or the build
/// API's).
pub fn front_options(config: &Config, options: &Options) -> FrontOptions {
    let mut hlsl = config.hlsl.hlsl_options();
    hlsl.merge(&options.front.hlsl);
    let mut front_options = FrontOptions {
        include_dirs: config.hlsl.include_dirs.clone(),
        defines: config
            .hlsl
            .defines
            .iter()
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect(),
        hlsl,
        glsl_stage: options.front.glsl_stage.clone(),
    };
    front_options
        .include_dirs
        .extend(options.front.include_dirs.iter().cloned());
    front_options
        .defines
        .extend(options.front.defines.iter().cloned());
    front_options
}

/// Configs by folder, loaded once each.
struct Configs {
    choice: ConfigChoice,
    overrides: Overrides,
    /// The command line's HLSL options build for Vulkan.
    vulkan_hlsl: bool,
    by_file: HashMap<PathBuf, Arc<Config>>,
    by_dir: HashMap<PathBuf, Arc<Config>>,
    /// [`Configs::for_file`]'s answers by the folder as written: a walk
    /// asks once per file, and resolving each path costs system calls.
    by_parent: HashMap<PathBuf, Arc<Config>>,
    errors: Vec<Diagnostic>,
}

impl Configs {
    fn new(options: &Options) -> Self {
        Configs {
            choice: options.config.clone(),
            overrides: options.overrides.clone(),
            vulkan_hlsl: options.front.hlsl.spirv,
            by_file: HashMap::new(),
            by_dir: HashMap::new(),
            by_parent: HashMap::new(),
            errors: Vec::new(),
        }
    }

    /// The config for a path known to be a file (not a folder).
    fn for_file(&mut self, path: &Path) -> Arc<Config> {
        let parent = path.parent().unwrap_or(Path::new(""));
        if let Some(c) = self.by_parent.get(parent) {
            return c.clone();
        }
        let c = self.for_path(path);
        self.by_parent.insert(parent.to_path_buf(), c.clone());
        c
    }

    /// The config for a file or folder.
    fn for_path(&mut self, path: &Path) -> Arc<Config> {
        let file = match &self.choice {
            ConfigChoice::Defaults => None,
            ConfigChoice::File(f) => Some(f.clone()),
            ConfigChoice::Nearest => {
                let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
                let dir = if abs.is_dir() {
                    abs.clone()
                } else {
                    abs.parent().map(Path::to_path_buf).unwrap_or_default()
                };
                if let Some(c) = self.by_dir.get(&dir) {
                    return c.clone();
                }
                let found = Config::discover(&dir);
                let c = self.load(found);
                self.by_dir.insert(dir, c.clone());
                return c;
            }
        };
        self.load(file)
    }

    fn load(&mut self, file: Option<PathBuf>) -> Arc<Config> {
        let key = file.clone().unwrap_or_default();
        if let Some(c) = self.by_file.get(&key) {
            return c.clone();
        }
        let mut config = match &file {
            Some(f) => match load_config(f) {
                Ok(c) => c,
                Err(e) => {
                    self.errors.push(*e.0);
                    Config::default()
                }
            },
            None => Config::default(),
        };
        let o = &self.overrides;
        if o.select.is_some() {
            config.select = o.select.clone();
        }
        config.extend_select.extend(o.extend_select.iter().cloned());
        config.ignore.extend(o.ignore.iter().cloned());
        if let Some(b) = o.payload_budget {
            config.set_option("RT001", "budget", toml::Value::Integer(b as i64));
        }
        config.deny_warnings |= o.deny_warnings;
        if let Some(a) = o.analysis {
            config.analysis = a;
        }
        // A DXC command line that builds for Vulkan (`-spirv`, `-fvk-*`, in
        // `[hlsl] args` or on the command line) says what RT041's option says.
        if self.vulkan_hlsl || config.hlsl.hlsl_options().spirv {
            config.set_option("RT041", "vulkan", toml::Value::Boolean(true));
        }
        let c = Arc::new(config);
        self.by_file.insert(key, c.clone());
        c
    }
}

/// Loads `rtlint.toml` and checks the rules and selectors it names against
/// the registry.
pub fn load_config(path: &Path) -> Result<Config, InputError> {
    let config = Config::load(path)?;
    config.check_rule_names(crate::rules::is_selector)?;
    config.check_rule_options(crate::rules::has_option)?;
    Ok(config)
}

/// Checks selectors given on the command line.
pub fn check_selectors(selectors: &[String]) -> Result<(), String> {
    match selectors.iter().find(|s| !crate::rules::is_selector(s)) {
        Some(s) => Err(format!(
            "unknown rule or group `{s}` (`rtlint rules` lists them)"
        )),
        None => Ok(()),
    }
}

/// Walks `paths`: files as named, folders recursively in sorted order,
/// following links once (a link back up the tree is not walked again) and
/// skipping what `.gitignore` and the config's `exclude` say.
fn collect(paths: &[PathBuf], options: &Options, configs: &mut Configs) -> Inputs {
    let mut inputs = Inputs::default();
    let mut seen: HashSet<PathBuf> = HashSet::new();
    let add_pipeline = |p: PathBuf, inputs: &mut Inputs, configs: &mut Configs| {
        let key = std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone());
        if !inputs
            .pipelines
            .iter()
            .any(|(q, _)| std::fs::canonicalize(q).unwrap_or_else(|_| q.clone()) == key)
        {
            let c = configs.for_path(&p);
            inputs.pipelines.push((p, c));
        }
    };
    for p in paths {
        if p.as_os_str() == "-" {
            let name = options
                .stdin_filename
                .clone()
                .unwrap_or_else(|| PathBuf::from("-"));
            let config = configs.for_path(&name);
            match options
                .language
                .or_else(|| config.language_for(&name))
                .or_else(|| language_from_name(&name))
            {
                Some(language) => inputs.files.push(Input {
                    path: name,
                    language,
                    config,
                    contents: Some(Arc::new(options.stdin.clone().unwrap_or_default())),
                }),
                None => inputs.errors.push(InputError::new(
                    InputErrorKind::UnknownLanguage,
                    &name,
                    "cannot tell the language of standard input: pass --stdin-filename with a shader extension, or --lang",
                )),
            }
            continue;
        }
        let meta = match std::fs::metadata(p) {
            Ok(m) => m,
            Err(e) => {
                inputs.errors.push(front::io_error(p, &e));
                continue;
            }
        };
        if meta.is_dir() {
            walk(p, options, configs, &mut inputs, &mut seen);
            continue;
        }
        if is_pipeline(p) {
            add_pipeline(p.clone(), &mut inputs, configs);
            continue;
        }
        let p = &tidy(p);
        let key = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
        if !seen.insert(key) {
            continue;
        }
        let config = configs.for_path(p);
        match options
            .language
            .or_else(|| config.language_for(p))
            .or_else(|| language_from_name(p))
            .or_else(|| glsl_by_stage(p, &config, options.front.glsl_stage.is_some()))
            .or_else(|| ray_query_glsl(p, &config, options))
        {
            Some(language) => inputs.files.push(Input {
                path: p.clone(),
                language,
                config,
                contents: None,
            }),
            None => inputs.errors.push(InputError::new(
                InputErrorKind::UnknownLanguage,
                p,
                "cannot tell the shader language from the file extension; pass --lang (and --stage for GLSL) or map the extension under [languages] in rtlint.toml",
            )),
        }
    }
    for p in &options.pipelines {
        add_pipeline(p.clone(), &mut inputs, configs);
    }
    inputs
}

fn walk(
    dir: &Path,
    options: &Options,
    configs: &mut Configs,
    inputs: &mut Inputs,
    seen: &mut HashSet<PathBuf>,
) {
    let respect = options.respect_gitignore;
    let walker = ignore::WalkBuilder::new(dir)
        .follow_links(true)
        .hidden(true)
        .ignore(respect)
        .git_ignore(respect)
        .git_exclude(respect)
        .git_global(false)
        .parents(respect)
        .require_git(false)
        .sort_by_file_path(|a, b| a.cmp(b))
        .filter_entry(|e| e.file_name() != "target")
        .build();
    let mut found: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut canonical_dirs: HashMap<PathBuf, Option<PathBuf>> = HashMap::new();
    for entry in walker {
        let entry = match entry {
            Ok(e) => e,
            // A link that leads back up the tree: already walked.
            Err(e) if is_loop(&e) => continue,
            Err(e) => {
                inputs.errors.push(InputError::new(
                    InputErrorKind::UnreadableFile,
                    dir,
                    format!("cannot walk the folder: {e}"),
                ));
                continue;
            }
        };
        if !entry.file_type().is_some_and(|t| t.is_file()) {
            continue;
        }
        let p = tidy(entry.path());
        // A file that is no link resolves as its folder does: one
        // `canonicalize` per folder, not one per file (each costs a system
        // call per path component).
        let key = match (entry.path_is_symlink(), p.parent(), p.file_name()) {
            (false, Some(parent), Some(name)) => {
                let dir = canonical_dirs
                    .entry(parent.to_path_buf())
                    .or_insert_with(|| {
                        let parent = if parent.as_os_str().is_empty() {
                            Path::new(".")
                        } else {
                            parent
                        };
                        std::fs::canonicalize(parent).ok()
                    });
                dir.as_ref().map(|d| d.join(name))
            }
            _ => None,
        }
        .unwrap_or_else(|| std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone()));
        found.push((p, key));
    }
    // A file reached through a link and by its own path is read once, under
    // the path without links when there is one.
    let direct = |p: &Path, key: &Path| {
        std::path::absolute(p).is_ok_and(|a| crate::program::debug::normalize(&a) == key)
    };
    let mut chosen: HashMap<PathBuf, PathBuf> = HashMap::new();
    for (p, key) in &found {
        match chosen.get(key) {
            Some(q) if direct(q, key) || !direct(p, key) => {}
            _ => {
                chosen.insert(key.clone(), p.clone());
            }
        }
    }
    for (p, key) in found {
        if chosen.get(&key) != Some(&p) || !seen.insert(key) {
            continue;
        }
        let config = configs.for_file(&p);
        if config.excludes(&p) {
            continue;
        }
        if is_pipeline(&p) {
            if !inputs.pipelines.iter().any(|(q, _)| *q == p) {
                inputs.pipelines.push((p, config));
            }
        } else if let Some(language) = glsl_by_stage(&p, &config, false) {
            inputs.files.push(Input {
                path: p,
                language,
                config,
                contents: None,
            });
        } else if p
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("hlsli"))
            || (p
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("glsl"))
                && front::glsl::stage_extension(&p).is_none())
        {
            // A header: analysed through the shaders that include it.
            inputs.skipped.push(p);
        } else if let Some(language) = config
            .language_for(&p)
            .or_else(|| language_from_name(&p))
            .or_else(|| options.language.filter(|_| is_shader_like(&p)))
            .or_else(|| ray_query_glsl(&p, &config, options))
        {
            inputs.files.push(Input {
                path: p,
                language,
                config,
                contents: None,
            });
        } else {
            inputs.skipped.push(p);
        }
    }
}

/// A path without `.` components: `./a/b` is `a/b`, as debug info names it.
fn tidy(p: &Path) -> PathBuf {
    let t: PathBuf = p
        .components()
        .filter(|c| !matches!(c, std::path::Component::CurDir))
        .collect();
    if t.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        t
    }
}

fn is_loop(e: &ignore::Error) -> bool {
    match e {
        ignore::Error::Loop { .. } => true,
        ignore::Error::WithPath { err, .. } | ignore::Error::WithDepth { err, .. } => is_loop(err),
        _ => false,
    }
}

/// The language a file's name says: `.hlsl`, `.wgsl`, `.spv`, and GLSL's
/// ray-tracing stage extensions (also as `name.rgen.glsl`).
fn language_from_name(p: &Path) -> Option<Language> {
    Language::from_path(p).or_else(|| {
        front::glsl::stage_extension(p)
            .filter(|e| front::glsl::RAY_TRACING_EXTENSIONS.contains(e))
            .map(|_| Language::Glsl)
    })
}

/// GLSL, for a file given a stage: by `[stages]` in its config, or by
/// `--stage` (`named`: the user named the file).
fn glsl_by_stage(p: &Path, config: &Config, named: bool) -> Option<Language> {
    (named || config.stage_for(p).is_some()).then_some(Language::Glsl)
}

/// A GLSL compute, fragment or other stage that uses ray queries, in its
/// own text or in a file it includes (searched as glslang does: the
/// including file's folder, then the include directories).
fn ray_query_glsl(p: &Path, config: &Config, options: &Options) -> Option<Language> {
    let ext = front::glsl::stage_extension(p)?;
    if !front::glsl::RAY_QUERY_EXTENSIONS.contains(&ext) {
        return None;
    }
    let dirs: Vec<PathBuf> = front_options(config, options).include_dirs;
    let mut seen = HashSet::new();
    mentions_ray_query(p, &dirs, &mut seen).then_some(Language::Glsl)
}

fn mentions_ray_query(p: &Path, dirs: &[PathBuf], seen: &mut HashSet<PathBuf>) -> bool {
    // A header included twice (or in a cycle) is read once.
    if seen.len() > 256 || !seen.insert(canonical(p)) {
        return false;
    }
    let Ok(text) = std::fs::read(p) else {
        return false;
    };
    let needle = b"rayQueryEXT";
    if text.windows(needle.len()).any(|w| w == needle) {
        return true;
    }
    let own = p.parent().unwrap_or(Path::new(""));
    String::from_utf8_lossy(&text).lines().any(|line| {
        let Some(rest) = line.trim_start().strip_prefix('#') else {
            return false;
        };
        let Some(rest) = rest.trim_start().strip_prefix("include") else {
            return false;
        };
        let rest = rest.trim();
        let name = match rest.chars().next() {
            Some('"') => rest[1..].split('"').next(),
            Some('<') => rest[1..].split('>').next(),
            _ => None,
        };
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            return false;
        };
        std::iter::once(own)
            .chain(dirs.iter().map(PathBuf::as_path))
            .map(|d| d.join(name))
            .find(|c| c.is_file())
            .is_some_and(|c| mentions_ray_query(&c, dirs, seen))
    })
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
        Some("md" | "toml" | "txt" | "json" | "sh" | "py" | "rs" | "png" | "ppm" | "yml" | "yaml")
    ) && p.extension().is_some()
}

/// One input's outcome.
#[derive(Debug)]
pub struct Checked {
    pub path: PathBuf,
    pub program: Option<Program>,
    /// DXR subobjects the input declares (HLSL).
    pub subobjects: Subobjects,
    pub diagnostics: Vec<Diagnostic>,
}

/// Loads and checks one file with `config`; a bad input becomes one error
/// diagnostic.
pub fn check_input(path: &Path, language: Language, config: &Config) -> Checked {
    let input = Input {
        path: path.to_path_buf(),
        language,
        config: Arc::new(config.clone()),
        contents: None,
    };
    check_input_with(&input, config, &Options::default())
}

fn check_input_with(input: &Input, config: &Config, options: &Options) -> Checked {
    match load_library(input, options) {
        Ok((program, subobjects)) => {
            let ignored = config.ignored_for(&input.path);
            let mut diagnostics = crate::rules::check_program(&program, config);
            drop_ignored(&mut diagnostics, &ignored);
            Checked {
                path: input.path.clone(),
                program: Some(program),
                subobjects,
                diagnostics,
            }
        }
        Err(e) => Checked {
            path: input.path.clone(),
            program: None,
            subobjects: Subobjects::default(),
            diagnostics: vec![*e.0],
        },
    }
}

/// Removes findings of rules that `[per-file-ignores]` turns off.
fn drop_ignored(diagnostics: &mut Vec<Diagnostic>, ignored: &[&str]) {
    if ignored.is_empty() {
        return;
    }
    diagnostics.retain(|d| {
        let Some(rule) = d.code.and_then(crate::rules::find) else {
            return true;
        };
        !ignored.iter().any(|s| crate::rules::selects(s, rule))
    });
}

/// Loads a pipeline description and runs the pipeline rules on it.
pub fn check_pipeline(path: &Path, config: &Config, options: &Options) -> Checked {
    match load_pipeline(path, config, options) {
        Ok(pipeline) => {
            let ctx = crate::rules::PipelineContext::new(&pipeline, config);
            let mut diagnostics = crate::rules::check_pipeline(&ctx);
            drop_ignored(&mut diagnostics, &config.ignored_for(path));
            Checked {
                path: path.to_path_buf(),
                program: None,
                subobjects: Subobjects::default(),
                diagnostics,
            }
        }
        Err(e) => Checked {
            path: path.to_path_buf(),
            program: None,
            subobjects: Subobjects::default(),
            diagnostics: vec![*e.0],
        },
    }
}

/// Drops findings that a suppression allows, and reports every suppression
/// in the linted sources that allowed nothing (RT000).
fn apply_suppressions(
    diagnostics: Vec<Diagnostic>,
    owned: &[(PathBuf, Arc<Config>)],
    embedded: &[(PathBuf, String)],
    // Inputs' suppressions already parsed (`None`: the input is not text).
    known: &HashMap<PathBuf, Option<Vec<crate::suppress::Suppression>>>,
) -> Vec<Diagnostic> {
    let embedded: HashMap<&Path, &str> = embedded
        .iter()
        .map(|(p, t)| (p.as_path(), t.as_str()))
        .collect();
    // Each suppression with, per selector, whether it allowed a finding:
    // every file a finding points into or this run linted, read and parsed
    // up front in parallel (10,000 files read one after another were a
    // sixth of a warm cached run).
    let mut paths: Vec<&Path> = diagnostics
        .iter()
        .filter(|d| d.code.is_some())
        .filter_map(|d| d.primary.as_ref().map(|p| p.location.path.as_path()))
        .chain(owned.iter().map(|(p, _)| p.as_path()))
        .collect();
    paths.sort_unstable();
    paths.dedup();
    type Found = Vec<(crate::suppress::Suppression, Vec<bool>)>;
    let parsed: Vec<Found> = paths
        .par_iter()
        .map(|path| {
            let parsed = match known.get(*path) {
                Some(Some(list)) => Some(list.clone()),
                Some(None) => embedded.get(*path).map(|t| crate::suppress::parse(t)),
                None => crate::shader::read_source_text(path)
                    .as_deref()
                    .or_else(|| embedded.get(*path).copied())
                    .map(crate::suppress::parse),
            };
            parsed
                .map(|list| {
                    list.into_iter()
                        .map(|s| {
                            let n = s.selectors.len();
                            (s, vec![false; n])
                        })
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let mut files: HashMap<PathBuf, Found> = paths
        .into_iter()
        .map(Path::to_path_buf)
        .zip(parsed)
        .collect();
    let mut kept = Vec::new();
    for d in diagnostics {
        let (Some(code), Some(primary)) = (d.code, &d.primary) else {
            kept.push(d);
            continue;
        };
        let Some(rule) = crate::rules::find(code) else {
            kept.push(d);
            continue;
        };
        let at = &primary.location;
        let mut allowed = false;
        if let Some(list) = files.get_mut(&at.path) {
            for (s, used) in list.iter_mut() {
                if at.line < s.covers.0 || at.line > s.covers.1 {
                    continue;
                }
                for (k, sel) in s.selectors.iter().enumerate() {
                    if crate::rules::selects(sel, rule) {
                        used[k] = true;
                        allowed = true;
                    }
                }
            }
        }
        if !allowed {
            kept.push(d);
        }
    }
    // Selectors that name nothing, in the files this run linted: input
    // errors, as unknown selectors in rtlint.toml are.
    for (path, _) in owned {
        for (s, _) in files.get(path.as_path()).into_iter().flatten() {
            for (sel, &(column, len)) in s.selectors.iter().zip(&s.spans) {
                if !crate::rules::is_selector(sel) {
                    let e = InputError::new(
                        InputErrorKind::InvalidSuppression,
                        path,
                        format!("suppression names unknown rule or group `{sel}`"),
                    )
                    .at(
                        Location::span(path, s.line, column, len),
                        "not a rule code, name or group",
                    )
                    .with_note("`rtlint rules` lists the codes, names and groups");
                    kept.push(*e.0);
                }
            }
        }
    }
    // Unused suppressions, in the files this run linted.
    let rule = &crate::rules::rt000_unused_suppression::RULE;
    for (path, config) in owned {
        let Some(severity) = crate::rules::configured(rule, config) else {
            continue;
        };
        for (s, used) in files.get(path.as_path()).into_iter().flatten() {
            // A selector is judged only when a rule it names ran on the file.
            let ran = |sel: &str| {
                crate::rules::RULES.iter().any(|r| {
                    crate::rules::selects(sel, r) && crate::rules::configured(r, config).is_some()
                })
            };
            let unused: Vec<&str> = s
                .selectors
                .iter()
                .zip(used)
                .filter(|(sel, u)| !**u && ran(sel))
                .map(|(sel, _)| sel.as_str())
                .collect();
            if !unused.is_empty() {
                kept.push(crate::rules::rt000_unused_suppression::finding(
                    path, s, &unused, severity,
                ));
            }
        }
    }
    kept
}

/// The shader files a pipeline description uses (nothing when it cannot be
/// read: `check_pipeline` reports that).
pub fn described_shaders(path: &Path, config: &Config, options: &Options) -> Vec<PathBuf> {
    load_pipeline(path, config, options)
        .map(|p| p.programs.iter().map(|p| canonical(&p.path)).collect())
        .unwrap_or_default()
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

/// Runs the pipeline rules (RT020–RT025) on shaders no description uses:
/// an HLSL library that declares DXR subobjects is the pipeline they
/// describe; otherwise the shaders of each folder form one pipeline in which
/// every trace may reach every hit group and miss shader. Each finding says
/// what was assumed.
pub fn check_loose(
    programs: Vec<(Program, Subobjects)>,
    described: &[PathBuf],
    config: &Config,
) -> Vec<Diagnostic> {
    let mut groups: Vec<(PathBuf, Vec<(Program, Subobjects)>)> = Vec::new();
    for (p, subobjects) in programs {
        if described.contains(&canonical(&p.path)) {
            continue;
        }
        let Some(dir) = loose_group(&p, &subobjects) else {
            continue;
        };
        match groups.iter_mut().find(|(d, _)| *d == dir) {
            Some((_, g)) => g.push((p, subobjects)),
            None => groups.push((dir, vec![(p, subobjects)])),
        }
    }
    let mut out = Vec::new();
    for (_, programs) in groups {
        out.extend(check_group(programs, config));
    }
    out
}

/// The loose pipeline a module belongs to: an HLSL library whose DXR
/// subobjects describe a pipeline, or a file holding a ray generation shader
/// and others (WGSL, HLSL), is a pipeline of its own; one-stage modules
/// pipeline with their folder. `None` without ray-tracing stages.
fn loose_group(p: &Program, subobjects: &Subobjects) -> Option<PathBuf> {
    if crate::pipeline::Pipeline::subobjects_describe(p, subobjects) {
        return Some(p.path.clone());
    }
    if !p.entry_points.iter().any(|e| e.stage.is_ray_tracing()) {
        return None;
    }
    let has_raygen = p
        .entry_points
        .iter()
        .any(|e| e.stage == crate::shader::Stage::RayGeneration);
    Some(if has_raygen && p.entry_points.len() > 1 {
        p.path.clone()
    } else {
        p.path.parent().map(Path::to_path_buf).unwrap_or_default()
    })
}

/// The pipeline rules over one loose group, each finding noting what was
/// assumed: the pipeline a library's subobjects describe, else every trace
/// reaching every shader.
fn check_group(mut programs: Vec<(Program, Subobjects)>, config: &Config) -> Vec<Diagnostic> {
    let run = |pipeline: &crate::pipeline::Pipeline, note: String| -> Vec<Diagnostic> {
        let ctx = crate::rules::PipelineContext::new(pipeline, config);
        crate::rules::check_pipeline(&ctx)
            .into_iter()
            .map(|d| d.with_note(note.clone()))
            .collect()
    };
    if programs.len() == 1 {
        let (p, subobjects) = programs.remove(0);
        return match crate::pipeline::Pipeline::from_subobjects(p, &subobjects) {
            Ok(pipeline) => run(&pipeline, Assumption::FromSubobjects.to_string()),
            Err(p) => run(
                &crate::pipeline::Pipeline::from_programs(vec![*p]),
                Assumption::Undescribed.to_string(),
            ),
        };
    }
    let pipeline =
        crate::pipeline::Pipeline::from_programs(programs.into_iter().map(|(p, _)| p).collect());
    run(&pipeline, Assumption::Undescribed.to_string())
}

/// One input's outcome in [`check_paths`]: computed, or read from the cache
/// (then without a Program, which a loose pipeline group loads only when its
/// own entry misses).
struct Outcome {
    /// Loaded and analysed (suppressions in its files are judged).
    analysed: bool,
    /// Boxed: a Program is large, and every input keeps its outcome until
    /// the end of the run (unboxed, about 1 KiB per file at 100,000 files).
    program: Option<Box<(Program, Subobjects)>>,
    diagnostics: Vec<Diagnostic>,
    /// The module's source files and the text it embeds.
    files: Vec<(PathBuf, Option<String>)>,
    /// Its loose pipeline group.
    group: Option<PathBuf>,
    /// Its cache key, when the cache is on and the input could be read.
    key: Option<crate::cache::Key>,
    /// The suppressions in the input's own bytes, parsed when they were read
    /// for the key (`Some(None)`: not text), so that a cached run reads each
    /// input once.
    suppressions: Option<Option<Vec<crate::suppress::Suppression>>>,
}

/// The cache keys of an input under its config and the options: its pack's
/// scope (everything but the input itself) and its own key.
/// `read`: the file's bytes, when it is not standard input.
fn input_keys(
    input: &Input,
    options: &Options,
    read: Option<&[u8]>,
) -> Option<(crate::cache::Key, crate::cache::Key)> {
    let bytes = match &input.contents {
        Some(c) => c.as_slice(),
        None => read?,
    };
    let front = input_options(input, options);
    let mut k = crate::cache::base_key();
    k.add(format!("{:?}", input.config))
        .add(format!("{front:?}"));
    // Only GLSL inputs run glslang, so only they ask which one it is.
    if input.language == Language::Glsl {
        k.add(front::glsl::version());
    }
    let scope = k.finish();
    k.add(&input.path)
        .add(format!("{:?}", input.language))
        .add_bytes(bytes);
    Some((scope, k.finish()))
}

fn check_cached(input: &Input, options: &Options, cache: Option<&crate::cache::Cache>) -> Outcome {
    let read = cache
        .filter(|_| input.contents.is_none())
        .and_then(|_| std::fs::read(&input.path).ok());
    let keys = cache.and_then(|_| input_keys(input, options, read.as_deref()));
    let key = keys.map(|(_, k)| k);
    let suppressions = read
        .as_deref()
        .map(|b| std::str::from_utf8(b).ok().map(crate::suppress::parse));
    if let (Some(cache), Some((scope, key))) = (cache, keys) {
        if let Some(entry) = cache.get(scope, &input.path, key) {
            if let Some(diagnostics) = crate::cache::load_all(entry.diagnostics) {
                return Outcome {
                    suppressions,
                    analysed: true,
                    program: None,
                    diagnostics,
                    files: entry.files,
                    group: entry.group,
                    key: Some(key),
                };
            }
        }
    }
    let c = check_input_with(input, &input.config, options);
    // Reports and suppressions read a file from disk before its embedded
    // text: only texts of files not on disk are kept, so neither the run's
    // memory nor the cache entries grow by every input's source.
    let files: Vec<(PathBuf, Option<String>)> = c
        .program
        .iter()
        .flat_map(|p| {
            p.files.iter().map(|f| {
                let text = f
                    .text
                    .as_ref()
                    .filter(|_| std::fs::File::open(&f.path).is_err());
                (f.path.clone(), text.cloned())
            })
        })
        .collect();
    let group = c
        .program
        .as_ref()
        .and_then(|p| loose_group(p, &c.subobjects));
    if let (Some(cache), Some((scope, key)), Some(_)) = (cache, keys, &c.program) {
        if let Some(diagnostics) = crate::cache::store_all(&c.diagnostics) {
            // Everything the module names besides the input itself: includes,
            // and sources debug info points at (rules read their text).
            let deps: Vec<_> = files
                .iter()
                .map(|(p, _)| p)
                .filter(|p| **p != input.path)
                .map(|p| (p.clone(), cache.dep_hash(p)))
                .collect();
            cache.put(
                scope,
                &input.path,
                key,
                &crate::cache::Entry {
                    deps,
                    files: files.clone(),
                    diagnostics,
                    group: group.clone(),
                },
            );
        }
    }
    Outcome {
        suppressions,
        analysed: c.program.is_some(),
        // Only modules with ray-tracing stages join a loose pipeline.
        program: c
            .program
            .filter(|_| group.is_some())
            .map(|p| Box::new((p, c.subobjects))),
        diagnostics: c.diagnostics,
        files,
        group,
        key,
    }
}

/// The pipeline rules over one loose group (`members`: indices into
/// `inputs`), from the cache when every member and the group are cached.
#[allow(clippy::too_many_arguments)]
fn check_group_cached(
    group: &Path,
    folder: &Path,
    members: &[usize],
    inputs: &[Input],
    outcomes: &mut [Outcome],
    config: &Config,
    options: &Options,
    cache: Option<&crate::cache::Cache>,
) -> Vec<Diagnostic> {
    let keys = cache.and_then(|_| {
        let mut k = crate::cache::base_key();
        k.add("group").add(format!("{config:?}"));
        let scope = k.finish();
        for &i in members {
            k.add(&inputs[i].path).add(outcomes[i].key?);
        }
        Some((scope, k.finish()))
    });
    if let (Some(cache), Some((scope, key))) = (cache, keys) {
        if let Some(d) = cache
            .get_group(scope, folder, group, key)
            .and_then(|g| crate::cache::load_all(g.diagnostics))
        {
            return d;
        }
    }
    let mut programs = Vec::with_capacity(members.len());
    for &i in members {
        match outcomes[i].program.take() {
            Some(p) => programs.push(*p),
            // Read from the cache: load it again for the pipeline.
            None => match load_library(&inputs[i], options) {
                Ok(p) => programs.push(p),
                Err(_) => continue,
            },
        }
    }
    let out = check_group(programs, config);
    if let (Some(cache), Some((scope, key)), Some(diagnostics)) =
        (cache, keys, crate::cache::store_all(&out))
    {
        cache.put_group(
            scope,
            folder,
            group,
            key,
            &crate::cache::GroupEntry { diagnostics },
        );
    }
    out
}

/// Keeps the files (and pipeline descriptions) of one shard. Folders are
/// dealt out whole, in path order, each to the shard with the fewest files
/// so far; a description's folder and the folders of the shaders it uses
/// count as one, so that each finding comes from one shard.
fn keep_shard(inputs: &mut Inputs, descriptions: &[Vec<PathBuf>], shard: Shard) {
    let folder = |p: &Path| {
        canonical(p)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    };
    // Union-find over folders.
    let mut index: BTreeMap<PathBuf, usize> = BTreeMap::new();
    for p in inputs
        .files
        .iter()
        .map(|i| &i.path)
        .chain(inputs.pipelines.iter().map(|(p, _)| p))
    {
        let n = index.len();
        index.entry(folder(p)).or_insert(n);
    }
    for shaders in descriptions {
        for s in shaders {
            let n = index.len();
            index.entry(folder(s)).or_insert(n);
        }
    }
    let mut parent: Vec<usize> = (0..index.len()).collect();
    fn root(parent: &mut [usize], mut v: usize) -> usize {
        while parent[v] != v {
            parent[v] = parent[parent[v]];
            v = parent[v];
        }
        v
    }
    for ((p, _), shaders) in inputs.pipelines.iter().zip(descriptions) {
        let a = index[&folder(p)];
        for s in shaders {
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, index[&folder(s)]));
            // The smaller index stays the root: the result is independent of
            // the order of the unions.
            parent[ra.max(rb)] = ra.min(rb);
        }
    }
    let mut sizes: BTreeMap<usize, usize> = BTreeMap::new();
    for i in &inputs.files {
        let r = root(&mut parent, index[&folder(&i.path)]);
        *sizes.entry(r).or_default() += 1;
    }
    for (p, _) in &inputs.pipelines {
        let r = root(&mut parent, index[&folder(p)]);
        sizes.entry(r).or_default();
    }
    // Components in the order of their first folder by path.
    let mut order: Vec<usize> = Vec::new();
    let mut placed = HashSet::new();
    for &i in index.values() {
        let r = root(&mut parent, i);
        if sizes.contains_key(&r) && placed.insert(r) {
            order.push(r);
        }
    }
    let mut load = vec![0usize; shard.count as usize];
    let mut owner: HashMap<usize, usize> = HashMap::new();
    for r in order {
        let k = (0..load.len()).min_by_key(|&k| (load[k], k)).unwrap_or(0);
        load[k] += sizes[&r];
        owner.insert(r, k);
    }
    let me = shard.index as usize - 1;
    let mut mine = |p: &Path| {
        let r = root(&mut parent, index[&folder(p)]);
        owner.get(&r) == Some(&me)
    };
    inputs.files.retain(|i| mine(&i.path));
    inputs.pipelines.retain(|(p, _)| mine(p));
    // Paths that could not be used belong to no folder: the first shard
    // reports them.
    if shard.index != 1 {
        inputs.errors.clear();
    }
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
        let d = check_loose(vec![(p, Subobjects::default())], &[], &Config::default());
        let rt020: Vec<_> = d.iter().filter(|d| d.code == Some("RT020")).collect();
        assert_eq!(rt020.len(), 1, "{d:?}");
        assert_eq!(rt020[0].primary.as_ref().unwrap().location.line, 42);
        assert!(rt020[0]
            .notes
            .iter()
            .any(|n| n.contains("every trace may reach every hit group and miss shader")));
        // A shader a description uses is checked with that description only.
        let p = front::load(&path, Language::Wgsl).unwrap();
        let p = vec![(p, Subobjects::default())];
        assert!(check_loose(p, &[canonical(&path)], &Config::default()).is_empty());
    }
}
