//! `rtlint.toml`: budgets, rule levels and language mappings.

use crate::diag::{InputError, InputErrorKind, Location, Severity};
use crate::shader::Language;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// `[hlsl]`: how sources that include other files are compiled.
#[derive(Clone, Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct SourceOptions {
    /// Searched after the including file's folder; relative to the config.
    #[serde(default)]
    pub include_dirs: Vec<PathBuf>,
    /// `NAME = "VALUE"`.
    #[serde(default)]
    pub defines: BTreeMap<String, String>,
    /// DXC's `-enable-16bit-types`.
    #[serde(default)]
    pub enable_16bit_types: bool,
    /// A DXC command line's options (`["-fvk-t-shift", "1000", "all"]`),
    /// read as `rtlint compile` reads them; checked when the config loads.
    #[serde(default)]
    pub args: Vec<String>,
}

impl SourceOptions {
    /// The HLSL options `enable-16bit-types` and `args` give (the include
    /// folders and defines are shared with GLSL and passed apart).
    pub fn hlsl_options(&self) -> rtlint_hlsl::HlslOptions {
        let mut o = rtlint_hlsl::HlslOptions {
            enable_16bit_types: self.enable_16bit_types,
            ..Default::default()
        };
        // Checked at load: an error here cannot happen.
        let _ = rtlint_hlsl::parse_args(&self.args, &mut o);
        o
    }
}

/// One rule's entry under `[rules]`.
#[derive(Clone, Debug, PartialEq)]
pub enum RuleSetting {
    Level(Level),
    Table {
        level: Option<Level>,
        /// The rule's own options; the rule says which it reads.
        options: BTreeMap<String, toml::Value>,
    },
}

/// By hand: serde's untagged enums answer a bad value with "did not match
/// any variant of untagged enum RuleSetting"; a user needs the levels.
impl<'de> serde::Deserialize<'de> for RuleSetting {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let level = |v: &toml::Value| -> Result<Level, D::Error> {
            match v.as_str() {
                Some("allow") => Ok(Level::Allow),
                Some("warn") => Ok(Level::Warn),
                Some("error") => Ok(Level::Error),
                Some(other) => Err(D::Error::custom(format!(
                    "unknown level `{other}`: expected \"allow\", \"warn\" or \"error\""
                ))),
                None => Err(D::Error::custom(
                    "a rule's level is \"allow\", \"warn\" or \"error\"",
                )),
            }
        };
        match toml::Value::deserialize(d)? {
            v @ toml::Value::String(_) => level(&v).map(RuleSetting::Level),
            toml::Value::Table(mut t) => {
                let level = t.remove("level").map(|v| level(&v)).transpose()?;
                Ok(RuleSetting::Table {
                    level,
                    options: t.into_iter().collect(),
                })
            }
            _ => Err(D::Error::custom(
                "expected a level (\"allow\", \"warn\" or \"error\") or a table of the rule's options",
            )),
        }
    }
}

impl RuleSetting {
    pub fn level(&self) -> Option<Level> {
        match self {
            RuleSetting::Level(l) => Some(*l),
            RuleSetting::Table { level, .. } => *level,
        }
    }

    pub fn options(&self) -> Option<&BTreeMap<String, toml::Value>> {
        match self {
            RuleSetting::Level(_) => None,
            RuleSetting::Table { options, .. } => Some(options),
        }
    }
}

/// A rule's configured level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    Allow,
    Warn,
    Error,
}

impl Level {
    pub fn severity(self) -> Option<Severity> {
        match self {
            Level::Allow => None,
            Level::Warn => Some(Severity::Warning),
            Level::Error => Some(Severity::Error),
        }
    }
}

/// How deep `rtlint check` looks (`analysis = "fast"` in `rtlint.toml`,
/// `--analysis` on the command line).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AnalysisLevel {
    /// Layouts, ray flags and constant operands: the rules that need no
    /// dataflow.
    Fast,
    /// Everything: liveness, recursion guards, uniformity, the stack model.
    #[default]
    Full,
}

impl AnalysisLevel {
    pub fn as_str(self) -> &'static str {
        match self {
            AnalysisLevel::Fast => "fast",
            AnalysisLevel::Full => "full",
        }
    }
}

#[derive(Clone, Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct Config {
    /// RT001: ray payloads above this many bytes (scalar size) are reported
    /// (the rule's default when unset; `[rules.RT001] budget` wins).
    #[serde(default)]
    pub payload_budget: Option<u64>,
    /// RT010: bytes of state live across one trace call (the rule's default
    /// when unset).
    #[serde(default)]
    pub live_state_budget: Option<u64>,
    /// RT025: the largest default pipeline stack (bytes per thread) a device
    /// is known to run (the rule's default when unset).
    #[serde(default)]
    pub stack_limit: Option<u64>,
    /// Warnings fail the run too.
    #[serde(default)]
    pub deny_warnings: bool,
    /// Which rules run by what they need: `fast` leaves out the dataflow
    /// rules.
    #[serde(default)]
    pub analysis: AnalysisLevel,
    /// Per rule, by code (`RT001`) or name (`payload-over-budget`): a level
    /// (`RT003 = "allow"`) or a table with a level and the rule's options
    /// (`[rules.RT001]` `level = "error"`, `budget = 48`).
    #[serde(default)]
    pub rules: BTreeMap<String, RuleSetting>,
    /// Languages for other file extensions: `rgen = "hlsl"`.
    #[serde(default)]
    pub languages: BTreeMap<String, String>,
    /// GLSL stages of files whose extension names none, by glob relative to
    /// this file's folder: `"shaders/*.glsl" = "rchit"` (glslang's stage
    /// names).
    #[serde(default)]
    pub stages: BTreeMap<String, String>,
    /// Rules to run instead of the default set: codes, names or groups.
    #[serde(default)]
    pub select: Option<Vec<String>>,
    /// Rules to run besides the selected ones.
    #[serde(default)]
    pub extend_select: Vec<String>,
    /// Rules not to run.
    #[serde(default)]
    pub ignore: Vec<String>,
    /// Globs (relative to this file's folder) of paths a directory walk skips.
    #[serde(default)]
    pub exclude: Vec<String>,
    /// Rules not to run on paths matching a glob: `"legacy/*.hlsl" = ["RT001"]`.
    #[serde(default)]
    pub per_file_ignores: BTreeMap<String, Vec<String>>,
    /// Include directories and defines for HLSL and GLSL sources.
    #[serde(default)]
    pub hlsl: SourceOptions,
    /// Where the config came from, for messages.
    #[serde(skip)]
    pub path: Option<PathBuf>,
    /// Where each key of `[rules]` stands, so whoever knows the rules can
    /// point at an unknown one.
    #[serde(skip)]
    rule_keys: Vec<(String, Option<Location>)>,
    /// The file's text, for pointing at what the rules reject.
    #[serde(skip)]
    text: Option<String>,
}

pub const FILE_NAME: &str = "rtlint.toml";

impl Config {
    pub fn parse(text: &str, path: &Path) -> Result<Config, InputError> {
        let mut config: Config = toml::from_str(text).map_err(|e| {
            let mut err = InputError::new(
                InputErrorKind::InvalidConfig,
                path,
                e.message().trim().to_string(),
            );
            if let Some(span) = e.span() {
                let at = |offset| crate::shader::line_col(text, offset);
                err = err.at(
                    Location::between(path, at(span.start), at(span.end)),
                    "here",
                );
            }
            err
        })?;
        let selectors = config
            .rules
            .keys()
            .chain(config.select.iter().flatten())
            .chain(&config.extend_select)
            .chain(&config.ignore)
            .chain(config.per_file_ignores.values().flatten());
        config.rule_keys = selectors
            .map(|k| (k.clone(), find_location(text, path, k)))
            .collect();
        for g in config
            .exclude
            .iter()
            .chain(config.per_file_ignores.keys())
            .chain(config.stages.keys())
        {
            if let Err(e) = globset::Glob::new(g) {
                return Err(config_error(
                    text,
                    path,
                    g,
                    format!("invalid glob `{g}`: {}", e.kind()),
                ));
            }
        }
        let mut scratch = rtlint_hlsl::HlslOptions::default();
        match rtlint_hlsl::parse_args(&config.hlsl.args, &mut scratch) {
            Ok(p) if p.rest.is_empty() => {}
            Ok(p) => {
                return Err(config_error(
                    text,
                    path,
                    "args",
                    format!("[hlsl] args: not a DXC option: `{}`", p.rest[0]),
                ))
            }
            Err(e) => {
                return Err(config_error(
                    text,
                    path,
                    "args",
                    format!("[hlsl] args: {e}"),
                ))
            }
        }
        if let Some(dir) = path.parent() {
            for d in &mut config.hlsl.include_dirs {
                if d.is_relative() {
                    *d = dir.join(&*d);
                }
            }
        }
        for (ext, lang) in &config.languages {
            if Language::parse(lang).is_none() {
                return Err(config_error(
                    text,
                    path,
                    lang,
                    format!("unknown language `{lang}` for extension `{ext}` (expected hlsl, wgsl, glsl or spirv)"),
                ));
            }
        }
        for (glob, stage) in &config.stages {
            if !crate::shader::GLSL_STAGES.contains(&stage.as_str()) {
                return Err(config_error(
                    text,
                    path,
                    stage,
                    format!(
                        "unknown GLSL stage `{stage}` for `{glob}` (expected one of {})",
                        crate::shader::GLSL_STAGES.join(", ")
                    ),
                ));
            }
        }
        config.path = Some(path.to_path_buf());
        config.text = Some(text.to_string());
        Ok(config)
    }

    pub fn load(path: &Path) -> Result<Config, InputError> {
        let text = crate::diag::read_text(path)?;
        Config::parse(&text, path)
    }

    /// `rtlint.toml` in `start` or the nearest directory above it.
    pub fn discover(start: &Path) -> Option<PathBuf> {
        let start = std::fs::canonicalize(start).ok()?;
        let mut dir = if start.is_dir() {
            Some(start.as_path())
        } else {
            start.parent()
        };
        while let Some(d) = dir {
            let candidate = d.join(FILE_NAME);
            if candidate.is_file() {
                return Some(candidate);
            }
            dir = d.parent();
        }
        None
    }

    /// The folder the config's relative globs and paths start from.
    pub fn base_dir(&self) -> Option<&Path> {
        self.path.as_deref().and_then(Path::parent)
    }

    /// Whether a directory walk skips `path` under `exclude`.
    pub fn excludes(&self, path: &Path) -> bool {
        !self.exclude.is_empty()
            && glob_set(&self.exclude).is_some_and(|g| g.is_match(self.relative(path)))
    }

    /// The selectors `[per-file-ignores]` applies to `path`.
    pub fn ignored_for(&self, path: &Path) -> Vec<&str> {
        let rel = self.relative(path);
        self.per_file_ignores
            .iter()
            .filter(|(g, _)| {
                globset::Glob::new(g)
                    .map(|g| g.compile_matcher().is_match(&rel))
                    .unwrap_or(false)
            })
            .flat_map(|(_, rules)| rules.iter().map(String::as_str))
            .collect()
    }

    /// `path` relative to the config's folder (both made absolute first).
    fn relative(&self, path: &Path) -> PathBuf {
        let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        match self.base_dir() {
            Some(base) => {
                let (p, b) = (abs(path), abs(base));
                p.strip_prefix(&b).map(Path::to_path_buf).unwrap_or(p)
            }
            None => path.to_path_buf(),
        }
    }

    /// An error at the first key of `[rules]` that `known` does not accept.
    /// The config is data: the rule registry is consulted by its caller.
    pub fn check_rule_names(&self, known: impl Fn(&str) -> bool) -> Result<(), InputError> {
        let path = self.path.as_deref().unwrap_or(Path::new(FILE_NAME));
        match self.rule_keys.iter().find(|(k, _)| !known(k)) {
            None => Ok(()),
            Some((key, at)) => {
                let err = InputError::new(
                    InputErrorKind::InvalidConfig,
                    path,
                    format!("unknown rule `{key}`"),
                );
                Err(match at {
                    Some(l) => err.at(l.clone(), "here"),
                    None => err,
                })
            }
        }
    }

    /// The configured level of a rule, by code or by name.
    pub fn level(&self, code: &str, name: &str) -> Option<Level> {
        self.setting(code, name).and_then(RuleSetting::level)
    }

    fn setting(&self, code: &str, name: &str) -> Option<&RuleSetting> {
        self.rules
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(code))
            .or_else(|| self.rules.iter().find(|(k, _)| *k == name))
            .map(|(_, v)| v)
    }

    /// A rule's option from its `[rules.CODE]` (or `[rules.name]`) table.
    pub fn option(&self, code: &str, name: &str, key: &str) -> Option<&toml::Value> {
        self.setting(code, name)?.options()?.get(key)
    }

    /// Sets a rule's option (the command line's overrides).
    pub fn set_option(&mut self, code: &str, key: &str, value: toml::Value) {
        let entry = self
            .rules
            .entry(code.to_string())
            .or_insert(RuleSetting::Table {
                level: None,
                options: BTreeMap::new(),
            });
        if let RuleSetting::Level(l) = entry {
            *entry = RuleSetting::Table {
                level: Some(*l),
                options: BTreeMap::new(),
            };
        }
        if let RuleSetting::Table { options, .. } = entry {
            options.insert(key.to_string(), value);
        }
    }

    /// An error at the first option of a `[rules.X]` table that `known`
    /// (rule key, option) does not accept.
    pub fn check_rule_options(&self, known: impl Fn(&str, &str) -> bool) -> Result<(), InputError> {
        let path = self.path.as_deref().unwrap_or(Path::new(FILE_NAME));
        for (rule, setting) in &self.rules {
            for key in setting.options().into_iter().flat_map(|o| o.keys()) {
                if !known(rule, key) {
                    let err = InputError::new(
                        InputErrorKind::InvalidConfig,
                        path,
                        format!("rule `{rule}` has no option `{key}`"),
                    );
                    return Err(
                        match self
                            .text
                            .as_deref()
                            .and_then(|t| find_location(t, path, key))
                        {
                            Some(l) => err.at(l, "here"),
                            None => err,
                        },
                    );
                }
            }
        }
        Ok(())
    }

    /// The GLSL stage `[stages]` gives `path` (glslang's name: `rchit`).
    pub fn stage_for(&self, path: &Path) -> Option<&str> {
        if self.stages.is_empty() {
            return None;
        }
        let rel = self.relative(path);
        self.stages
            .iter()
            .find(|(g, _)| {
                globset::Glob::new(g)
                    .map(|g| g.compile_matcher().is_match(&rel))
                    .unwrap_or(false)
            })
            .map(|(_, s)| s.as_str())
    }

    /// The language configured for a path's extension.
    pub fn language_for(&self, path: &Path) -> Option<Language> {
        let ext = path.extension()?.to_str()?;
        let ext = ext.trim_start_matches('.');
        self.languages
            .iter()
            .find(|(k, _)| k.trim_start_matches('.').eq_ignore_ascii_case(ext))
            .and_then(|(_, v)| Language::parse(v))
    }
}

fn glob_set(globs: &[String]) -> Option<globset::GlobSet> {
    let mut b = globset::GlobSetBuilder::new();
    for g in globs {
        b.add(globset::Glob::new(g).ok()?);
        // `dir` also excludes what is inside it.
        b.add(globset::Glob::new(&format!("{}/**", g.trim_end_matches('/'))).ok()?);
    }
    b.build().ok()
}

/// The first occurrence of `needle` in the config text.
fn find_location(text: &str, path: &Path, needle: &str) -> Option<Location> {
    let at = text.find(needle)?;
    let (line, column) = crate::shader::line_col(text, at);
    Some(Location::span(
        path,
        line,
        column,
        needle.chars().count() as u32,
    ))
}

/// An error pointing at the first occurrence of `needle` in the config text.
fn config_error(text: &str, path: &Path, needle: &str, message: String) -> InputError {
    let err = InputError::new(InputErrorKind::InvalidConfig, path, message);
    match find_location(text, path, needle) {
        Some(l) => err.at(l, "here"),
        None => err,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_levels_budgets_and_languages() {
        let c = Config::parse(
            "payload-budget = 48\n[rules]\nRT003 = \"allow\"\npayload-packing-waste = \"error\"\n[languages]\nrgen = \"hlsl\"\n",
            Path::new("rtlint.toml"),
        )
        .unwrap();
        assert_eq!(c.payload_budget, Some(48));
        assert_eq!(c.level("RT003", "member-straddles-row"), Some(Level::Allow));
        assert_eq!(
            c.level("RT002", "payload-packing-waste"),
            Some(Level::Error)
        );
        assert_eq!(c.level("RT001", "payload-over-budget"), None);
        assert_eq!(c.language_for(Path::new("a/b.rgen")), Some(Language::Hlsl));
    }

    #[test]
    fn bad_config_names_the_position() {
        let e = Config::parse(
            "payload-budget = 32\nbogus = 1\n",
            Path::new("x/rtlint.toml"),
        )
        .unwrap_err();
        let l = &e.diagnostic().primary.as_ref().unwrap().location;
        assert_eq!((l.line, l.column), (2, 1));
        assert!(
            e.diagnostic().message.contains("bogus"),
            "{}",
            e.diagnostic().message
        );

        let e = Config::parse("[rules]\nRT999 = \"warn\"\n", Path::new("rtlint.toml"))
            .unwrap()
            .check_rule_names(|k| k == "RT001")
            .unwrap_err();
        assert_eq!(e.diagnostic().message, "unknown rule `RT999`");
        assert_eq!(e.diagnostic().primary.as_ref().unwrap().location.line, 2);

        let e = Config::parse("payload-budget = \"big\"\n", Path::new("rtlint.toml")).unwrap_err();
        assert_eq!(e.diagnostic().primary.as_ref().unwrap().location.line, 1);
    }
}
