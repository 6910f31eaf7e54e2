//! The bundled reference shaders: valid SPIR-V, and clean under every rule.

mod common;

#[test]
fn bundled_wgsl_shaders_are_valid_and_clean() {
    let validate = rtlint_testkit::tool("spirv-val");
    let mut n = 0;
    for e in std::fs::read_dir(common::root().join("shaders")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "wgsl") {
            continue;
        }
        n += 1;
        let text = std::fs::read_to_string(&p).unwrap();
        let words = rtlint::front::wgsl::compile(&text, &p).unwrap();
        if validate {
            common::spirv_val(&words).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        }
        let program = rtlint::front::load(&p, rtlint::shader::Language::Wgsl).unwrap();
        let mut findings =
            rtlint::rules::check_program(&program, &rtlint::config::Config::default());
        // As `rtlint check` sees them: a finding the source suppresses on
        // its lines (e.g. `@diagnostic(off, rtlint.live_state_over_budget)`
        // on an entry point) does not count.
        let suppressions = rtlint::suppress::parse(&text);
        findings.retain(|d| {
            let line = d.primary.as_ref().map_or(0, |l| l.location.line);
            let rule = d.code.and_then(rtlint::rules::find);
            !suppressions.iter().any(|s| {
                (s.covers.0..=s.covers.1).contains(&line)
                    && rule.is_some_and(|r| {
                        s.selectors.iter().any(|sel| rtlint::rules::selects(sel, r))
                    })
            })
        });
        assert!(findings.is_empty(), "{}: {findings:?}", p.display());
    }
    assert!(n >= 3, "expected the reference shaders, found {n}");
}

/// The README's first command: the reference shaders and pipeline
/// descriptions lint with one finding per language, the recursion the
/// recursive reference exists to show (its depth guard recognised: depth 5,
/// three bounces and a shadow ray).
#[test]
fn main_job_reports_the_recursive_reference() {
    let o = common::rtlint()
        .args(["check", "--format", "json", "shaders/"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let diagnostics = v["diagnostics"].as_array().unwrap();
    let found: Vec<(&str, &str)> = diagnostics
        .iter()
        .map(|d| (d["code"].as_str().unwrap(), d["path"].as_str().unwrap()))
        .collect();
    assert_eq!(
        found,
        [
            ("RT020", "shaders/reflect_recursive.wgsl"),
            ("RT020", "shaders/reflect_recursive.hlsl"),
        ]
    );
    for d in diagnostics {
        assert!(d["notes"][0]
            .as_str()
            .unwrap()
            .contains("needs recursion depth 5"));
    }
    assert_eq!(v["summary"]["files"], 14);
}
