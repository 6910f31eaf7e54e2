//! Rules: one file per rule, one registry table. Rules read the Program and
//! analysis facts and return typed [`Diagnostic`]s; the report layer makes text.

pub mod rt000_unused_suppression;
mod rt001_payload_over_budget;
mod rt002_payload_packing_waste;
mod rt003_member_straddles_row;
mod rt004_hit_attributes_over_limit;
mod rt005_ray_query_null_constant;
pub mod rt010_live_state_over_budget;
pub mod rt020_recursive_trace;
pub mod rt021_depth_exceeds_declared;
pub mod rt022_depth_overdeclared;
pub mod rt023_depth_exceeds_device_limit;
pub mod rt024_unbounded_bounce_loop;
pub mod rt025_default_stack_unsafe;

use crate::analysis::layout::{self, TypeLayout};
use crate::config::Config;
use crate::diag::{Diagnostic, Location, Severity};
use crate::program::{Decl, Id, Program, SiteKind};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Group {
    /// Guaranteed failure: invalid modules, limits exceeded.
    Correctness,
    /// Costs the GPU time or memory.
    Perf,
}

/// What a rule reads.
#[derive(Clone, Copy)]
pub enum Kind {
    /// One module at a time.
    Module(fn(&Context) -> Vec<Diagnostic>),
    /// A whole described pipeline (recursion depth, stack size).
    Pipeline(fn(&PipelineContext) -> Vec<Diagnostic>),
    /// Reported by the lint driver itself (suppressions).
    Driver,
}

pub struct Rule {
    pub code: &'static str,
    pub name: &'static str,
    pub group: Group,
    pub level: Severity,
    /// One line, for `rtlint rules`.
    pub summary: &'static str,
    /// The rule's page under `rules/`: the single source of its documentation.
    pub doc: &'static str,
    pub kind: Kind,
}

/// Every rule, in code order.
pub static RULES: &[&Rule] = &[
    &rt000_unused_suppression::RULE,
    &rt001_payload_over_budget::RULE,
    &rt002_payload_packing_waste::RULE,
    &rt003_member_straddles_row::RULE,
    &rt004_hit_attributes_over_limit::RULE,
    &rt005_ray_query_null_constant::RULE,
    &rt010_live_state_over_budget::RULE,
    &rt020_recursive_trace::RULE,
    &rt021_depth_exceeds_declared::RULE,
    &rt022_depth_overdeclared::RULE,
    &rt023_depth_exceeds_device_limit::RULE,
    &rt024_unbounded_bounce_loop::RULE,
    &rt025_default_stack_unsafe::RULE,
];

/// A rule by code (`RT001`, any case) or name.
pub fn find(key: &str) -> Option<&'static Rule> {
    RULES
        .iter()
        .copied()
        .find(|r| r.code.eq_ignore_ascii_case(key) || r.name == key)
}

/// What module rules read: the Program and the facts computed once for it.
pub struct Context<'a> {
    pub program: &'a Program,
    pub config: &'a Config,
    pub layouts: Vec<TypeLayout>,
}

impl<'a> Context<'a> {
    pub fn new(program: &'a Program, config: &'a Config) -> Self {
        Context {
            program,
            config,
            layouts: layout::interface_layouts(program),
        }
    }

    /// Where a type is declared, if debug info says.
    pub fn type_location(&self, t: &TypeLayout) -> Option<Location> {
        if t.is_struct {
            self.program.decl_location(Decl::Type(t.id))
        } else {
            t.variable_ids
                .iter()
                .find_map(|v| self.program.var_location(*v))
        }
    }

    pub fn member_location(&self, t: &TypeLayout, k: usize) -> Option<Location> {
        if t.is_struct {
            self.program.decl_location(Decl::Member(t.id, k as u32))
        } else {
            self.type_location(t)
        }
    }

    /// Trace (or callable) sites that pass one of these variables.
    pub fn sites_using(&self, vars: &[Id]) -> Vec<Location> {
        self.program
            .sites
            .iter()
            .filter(|s| matches!(s.kind, SiteKind::TraceRay | SiteKind::ExecuteCallable))
            .filter(|s| s.payload.is_some_and(|p| vars.contains(&p)))
            .filter_map(|s| self.program.site_location(s.inst))
            .collect()
    }

    /// Names the object when there is no source position.
    pub fn subject(&self, t: &TypeLayout) -> String {
        let vars = t.variables.join("`, `");
        if t.is_struct {
            format!("type `{}` (variable `{vars}`)", t.name)
        } else {
            format!("variable `{vars}`")
        }
    }

    pub fn diagnostic(&self, rule: &'static Rule, message: impl Into<String>) -> Diagnostic {
        Diagnostic::new(rule.level, rule.name, &self.program.path, message).with_code(rule.code)
    }
}

/// What pipeline rules read: the description and the analyses of it,
/// computed once.
pub struct PipelineContext<'a> {
    pub pipeline: &'a crate::pipeline::Pipeline,
    pub config: &'a Config,
    pub recursion: crate::analysis::RecursionReport,
    pub stack: crate::analysis::StackReport,
}

impl<'a> PipelineContext<'a> {
    pub fn new(pipeline: &'a crate::pipeline::Pipeline, config: &'a Config) -> Self {
        let recursion = crate::analysis::recursion_report(pipeline);
        let stack = crate::analysis::stack::stack_report_with(pipeline, &recursion);
        PipelineContext {
            pipeline,
            config,
            recursion,
            stack,
        }
    }
}

impl Group {
    pub fn as_str(self) -> &'static str {
        match self {
            Group::Correctness => "correctness",
            Group::Perf => "perf",
        }
    }
}

/// Whether a selector (`ALL`, a code, a code prefix such as `RT02`, a name
/// or a group) picks `rule`.
pub fn selects(selector: &str, rule: &Rule) -> bool {
    let s = selector.trim();
    s.eq_ignore_ascii_case("ALL")
        || s == rule.name
        || s.eq_ignore_ascii_case(rule.group.as_str())
        || (s.len() >= 3
            && s.len() <= rule.code.len()
            && rule.code[..s.len()].eq_ignore_ascii_case(s))
}

/// Whether a selector picks any rule (for checking configs and flags).
pub fn is_selector(selector: &str) -> bool {
    RULES.iter().any(|r| selects(selector, r))
}

/// Whether `rule` runs under `config`'s selection (`select`, then
/// `extend-select`, then `ignore`).
pub fn enabled(rule: &Rule, config: &Config) -> bool {
    let any = |list: &[String]| list.iter().any(|s| selects(s, rule));
    let mut on = match &config.select {
        Some(list) => any(list),
        None => true,
    };
    on |= any(&config.extend_select);
    on && !any(&config.ignore)
}

/// The severity a rule reports at under `config`, or `None` when it does not
/// run.
pub fn configured(rule: &Rule, config: &Config) -> Option<Severity> {
    if !enabled(rule, config) {
        return None;
    }
    match config.level(rule.code, rule.name) {
        Some(l) => l.severity(),
        None => Some(rule.level),
    }
}

/// Runs every module rule on one Program and applies the configured levels.
pub fn check_program(program: &Program, config: &Config) -> Vec<Diagnostic> {
    let ctx = Context::new(program, config);
    let mut out = Vec::new();
    for rule in RULES {
        let (Kind::Module(check), Some(severity)) = (rule.kind, configured(rule, config)) else {
            continue;
        };
        for mut d in check(&ctx) {
            d.severity = severity;
            out.push(d);
        }
    }
    out
}

/// Runs every pipeline rule on a described pipeline.
pub fn check_pipeline(ctx: &PipelineContext) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for rule in RULES {
        let (Kind::Pipeline(check), Some(severity)) = (rule.kind, configured(rule, ctx.config))
        else {
            continue;
        };
        for mut d in check(ctx) {
            d.severity = severity;
            out.push(d);
        }
    }
    out
}

/// Renders the struct in the help text's indentation.
pub(crate) fn indent(text: &str) -> String {
    text.lines()
        .map(|l| format!("    {l}"))
        .collect::<Vec<_>>()
        .join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_is_documented() {
        for r in RULES {
            assert!(
                r.doc.starts_with(&format!("# {} `{}`", r.code, r.name)),
                "{}: page must start with its code and name",
                r.code
            );
            for section in [
                "## What it does",
                "## Why is this bad?",
                "## Example",
                "## How to fix",
            ] {
                assert!(
                    r.doc.contains(section),
                    "{}: page lacks `{section}`",
                    r.code
                );
            }
            assert!(
                r.doc
                    .contains(&format!("Default level: {}.", r.level.as_str())),
                "{}: page must state the default level",
                r.code
            );
        }
    }

    /// Codes never change silently: this list is the contract.
    #[test]
    fn code_list() {
        let list: Vec<String> = RULES
            .iter()
            .map(|r| format!("{} {}", r.code, r.name))
            .collect();
        assert_eq!(
            list,
            [
                "RT000 unused-suppression",
                "RT001 payload-over-budget",
                "RT002 payload-packing-waste",
                "RT003 member-straddles-row",
                "RT004 hit-attributes-over-limit",
                "RT005 ray-query-null-constant",
                "RT010 live-state-over-budget",
                "RT020 recursive-trace",
                "RT021 depth-exceeds-declared",
                "RT022 depth-overdeclared",
                "RT023 depth-exceeds-device-limit",
                "RT024 unbounded-bounce-loop",
                "RT025 default-stack-unsafe",
            ]
        );
    }

    #[test]
    fn codes_and_names_are_unique_and_well_formed() {
        for (i, a) in RULES.iter().enumerate() {
            assert!(a.code.len() == 5 && a.code.starts_with("RT"), "{}", a.code);
            assert!(
                a.name.chars().all(|c| c.is_ascii_lowercase() || c == '-'),
                "{} is not kebab-case",
                a.name
            );
            for b in &RULES[i + 1..] {
                assert!(a.code != b.code && a.name != b.name);
            }
        }
    }
}
