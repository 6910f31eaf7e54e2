//! RT010 `live-state-over-budget`: more state kept alive across a trace
//! than the budget allows.

use crate::analysis::liveness::LiveSite;
use crate::diag::Diagnostic;
use crate::program::Program;

/// Sixteen 32-bit values: what fits in a closest-hit shader's 32-B stack
/// step twice over.
pub const DEFAULT_BUDGET_BYTES: u64 = 64;

/// One finding per trace or callable site whose state that cannot be
/// recomputed (live bytes minus rematerializable bytes) exceeds
/// `budget_bytes`. Ray-query loops are left out: an inline query is no shader
/// call, so its live values stay in registers rather than on a ray stack
/// (`rtlint live` still lists them).
pub fn check(program: &Program, sites: &[LiveSite], budget_bytes: u64) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for site in reported(program, sites) {
        let kept = site.live_bytes - site.rematerializable_bytes;
        if kept <= budget_bytes {
            continue;
        }
        let what = match site.kind {
            crate::analysis::liveness::LiveSiteKind::TraceRay => "the trace",
            crate::analysis::liveness::LiveSiteKind::ExecuteCallable => "the callable",
            crate::analysis::liveness::LiveSiteKind::RayQuery => "the ray-query loop",
        };
        let mut d = Diagnostic::new(
            LEVEL,
            NAME,
            &program.path,
            format!(
                "{kept} bytes of state are live across {what} in `{}`, above the {budget_bytes}-byte budget",
                site.entry
            ),
        )
        .with_code(CODE)
        .with_subject(site.entry.clone())
        .with_primary(site.location.clone(), format!("{kept} bytes kept across this call"));
        for v in site.values.iter().filter(|v| !v.rematerializable).take(4) {
            // Under the variable's name where the line has it.
            let def = v.def.as_ref().map(|at| {
                program
                    .name_location(at, &v.name)
                    .unwrap_or_else(|| at.clone())
            });
            d = d.with_secondary(
                def,
                format!("`{}` ({}, {} bytes) defined here", v.name, v.ty, v.size),
            );
        }
        let list: Vec<String> = site
            .values
            .iter()
            .map(|v| {
                format!(
                    "`{}` {} B{}",
                    v.name,
                    v.size,
                    if v.rematerializable {
                        " (recomputable)"
                    } else {
                        ""
                    }
                )
            })
            .collect();
        d = d.with_note(format!("live values: {}", list.join(", ")));
        if site.rematerializable_bytes > 0 {
            d = d.with_note(format!(
                "{} of the {} live bytes can be recomputed after the call and are not counted",
                site.rematerializable_bytes, site.live_bytes
            ));
        }
        out.push(d.with_help(
            "recompute values after the trace from builtins and buffers, or carry them in the payload",
        ));
    }
    out
}

super::declare_rule! {
    /// ## What it does
    ///
    /// Finds trace and callable sites across which a shader keeps more state
    /// than a budget (default 64 bytes). It counts the values that are defined
    /// before the call and used after it — SSA values and the live parts of
    /// local variables, through loops, phis and calls — whose value cannot be
    /// recomputed after the call. Each live value is listed with its size, and
    /// values that could be recomputed (see *Rematerialisation classes* in
    /// `docs/stack.md`: builtins, push constants, uniform, storage and
    /// `buffer_reference` loads, texture reads, constants) are marked and not
    /// counted. Ray-query loops are not reported: an inline query is no shader
    /// call, so its state stays in registers (`rtlint live` still lists them).
    /// The answer does not depend on the debug info the compiler emitted (none,
    /// `-g`, `-gV`).
    ///
    /// ## Why is this bad?
    ///
    /// A driver suspends the shader at every `TraceRay`/`traceRayEXT`/`traceRay`
    /// and `CallShader`/`executeCallableEXT`. Everything still needed afterwards is
    /// spilled to the ray stack and reloaded: more memory traffic per ray, a
    /// larger stack per thread, fewer threads in flight. NVIDIA keeps this state
    /// outside the stack size it reports, so the cost does not show up in
    /// `vkGetRayTracingShaderGroupStackSizeKHR` — only in performance.
    ///
    /// ## Example
    ///
    /// ```glsl
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, o, 0.001, d, 100.0, 0);
    /// mat4 frame = mat4(hit, hit.yzwx, hit.zwxy, hit.wxyz);   // 64 bytes
    /// vec4 tint = hit * 0.5;                                  // 16 bytes
    /// // ... more values derived from the first hit ...
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, o, 0.001, dir, 100.0, 0);
    /// vec4 c = frame * hit + tint + ...;
    /// ```
    ///
    /// ```
    /// warning[RT010]: 128 bytes of state are live across the trace in `main`, above the 64-byte budget
    /// ```
    ///
    /// Use instead: keep the one value everything derives from and compute the
    /// rest after the trace:
    ///
    /// ```glsl
    /// vec4 first = hit;                                       // 16 bytes
    /// traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, o, 0.001, dir, 100.0, 0);
    /// mat4 frame = mat4(first, first.yzwx, first.zwxy, first.wxyz);
    /// ```
    ///
    /// ## How to fix
    ///
    /// Recompute values after the trace from builtins and buffers; carry what the
    /// hit shader produces in the payload instead of keeping copies; move work
    /// that depends on the trace's result after it. `rtlint live FILE` lists every
    /// live value with its size and where it is defined and used.
    ///
    /// ## Options
    ///
    /// `budget` under `[rules.RT010]` in `rtlint.toml`, or the top-level
    /// `live-state-budget`: bytes that cannot be recomputed (default 64). There
    /// is no command-line flag for it.
    ///
    /// Fixtures: `fixtures/RT010/bad.rgen`, `fixtures/RT010/good.rgen`; the live
    /// sets behind it: `fixtures/live/`. Precision on public shaders:
    /// `docs/rules-precision.md`.
    "RT010" "live-state-over-budget" {
        group: Perf,
        summary: "state kept alive across a trace call above the budget",
        kind: super::Kind::Module(run),
        analysis: Full,
        options: [super::RuleOption {
            name: "budget",
            default: "64",
            doc: "bytes live across one call that cannot be recomputed (top-level `live-state-budget` too)",
        }],
    }
}

fn run(ctx: &super::Context) -> Vec<Diagnostic> {
    use crate::analysis::liveness::{shared_live_bytes, shared_live_sites};
    let budget = super::option_u64(ctx.config, &RULE, "budget", ctx.config.live_state_budget);
    // The bytes decide whether anything is reported; naming, typing and
    // placing each value (a third of the liveness time) only for a finding.
    let bytes = shared_live_bytes(ctx.program);
    if check_bytes(ctx.program, &bytes, budget) {
        check(ctx.program, &shared_live_sites(ctx.program), budget)
    } else {
        Vec::new()
    }
}

/// Whether [`check`] reports anything: the same sites, counted the same way.
fn check_bytes(program: &Program, sites: &[LiveSite], budget_bytes: u64) -> bool {
    reported(program, sites).any(|s| s.live_bytes - s.rematerializable_bytes > budget_bytes)
}

/// The sites [`check`] judges.
fn reported<'a>(program: &'a Program, sites: &'a [LiveSite]) -> impl Iterator<Item = &'a LiveSite> {
    sites.iter().filter(|s| {
        s.path == program.path && s.kind != crate::analysis::liveness::LiveSiteKind::RayQuery
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::liveness::live_sites;
    use crate::front::load;
    use crate::shader::Language;
    use std::path::Path;

    fn run(rel: &str, budget: u64) -> Vec<Diagnostic> {
        let p = load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join(rel),
            Language::Spirv,
        )
        .unwrap();
        check(&p, &live_sites(&p), budget)
    }

    /// The rule as `check` runs it (bytes first, descriptions only for a
    /// finding) reports what judging the described sites reports, at
    /// budgets on both sides of each site's count.
    #[test]
    fn run_reports_what_check_reports() {
        let mut judged = 0;
        for rel in [
            "fixtures/RT010/bad.rgen.spv",
            "fixtures/RT010/good.rgen.spv",
            "fixtures/live/seed.rchit.spv",
            "fixtures/live/classes.rgen.spv",
            "fixtures/live/classes.wgsl",
            "fixtures/live/classes.hlsl",
        ] {
            let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
            let p = load(&path, Language::from_path(&path).unwrap()).unwrap();
            let sites = live_sites(&p);
            for budget in [0, 4, 11, 12, 64, 1 << 20] {
                let mut config = crate::config::Config::default();
                config.live_state_budget = Some(budget);
                let fresh = load(&path, Language::from_path(&path).unwrap()).unwrap();
                let got: Vec<String> = crate::rules::check_program(&fresh, &config)
                    .into_iter()
                    .filter(|d| d.code == Some(CODE))
                    .map(|d| format!("{d:?}"))
                    .collect();
                let want: Vec<String> =
                    check(&p, &sites, budget).iter().map(|d| format!("{d:?}")).collect();
                judged += want.len();
                assert_eq!(got, want, "{rel} at budget {budget}");
            }
        }
        // Findings were compared, not only silences.
        assert!(judged > 0);
    }

    #[test]
    fn bad_and_good() {
        let d = run("fixtures/RT010/bad.rgen.spv", DEFAULT_BUDGET_BYTES);
        assert_eq!(d.len(), 1);
        assert_eq!(
            d[0].message,
            "128 bytes of state are live across the trace in `main`, above the 64-byte budget"
        );
        assert_eq!(d[0].primary.as_ref().unwrap().location.line, 19);
        assert!(run("fixtures/RT010/good.rgen.spv", DEFAULT_BUDGET_BYTES).is_empty());
        // The seed keeps 24 bytes, 12 of them recomputable (`directLight`).
        assert_eq!(run("fixtures/live/seed.rchit.spv", 11).len(), 1);
        assert!(run("fixtures/live/seed.rchit.spv", 12).is_empty());
    }
}
