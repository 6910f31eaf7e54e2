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
/// descriptions lint clean. The recursive reference exists to show recursion:
/// its RT020 is suppressed in the source with a reason, so the suppression
/// must be used (no RT000), and without suppressions the finding is there,
/// with the depth guard recognised (depth 5: three bounces and a shadow ray).
#[test]
fn main_job_is_clean_on_the_reference_shaders() {
    let o = common::rtlint()
        .args(["check", "--format", "json", "shaders/"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["diagnostics"], serde_json::json!([]), "{v}");
    assert_eq!(v["summary"]["files"], 22);
    // The same folder with the recursive reference's suppressions turned
    // into plain comments.
    let copy = std::env::temp_dir().join(format!("rtlint-shaders-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&copy);
    std::fs::create_dir_all(&copy).unwrap();
    for e in std::fs::read_dir(common::root().join("shaders")).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() {
            let mut text = std::fs::read_to_string(&p).unwrap();
            if p.file_stem().is_some_and(|s| s == "reflect_recursive") {
                text = text.replace("rtlint: allow(", "rtlint: noted(");
            }
            std::fs::write(copy.join(p.file_name().unwrap()), text).unwrap();
        }
    }
    let o = common::rtlint()
        .args(["check", "--format", "json"])
        .arg(&copy)
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let d = v["diagnostics"].as_array().unwrap();
    let found: Vec<(&str, String)> = d
        .iter()
        .map(|d| {
            let path = d["path"].as_str().unwrap();
            (
                d["code"].as_str().unwrap(),
                std::path::Path::new(path)
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned(),
            )
        })
        .collect();
    let _ = std::fs::remove_dir_all(&copy);
    assert_eq!(
        found,
        [
            ("RT020", "reflect_recursive.wgsl".to_string()),
            ("RT020", "reflect_recursive.hlsl".to_string()),
        ],
        "{v}"
    );
    for d in d {
        assert!(d["notes"][0]
            .as_str()
            .unwrap()
            .contains("needs recursion depth 5"));
    }
}
