//! The bundled reference shaders: valid SPIR-V, and clean under every rule.

mod common;

#[test]
fn bundled_wgsl_shaders_are_valid_and_clean() {
    let mut n = 0;
    for e in std::fs::read_dir(common::root().join("shaders")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "wgsl") {
            continue;
        }
        n += 1;
        let text = std::fs::read_to_string(&p).unwrap();
        let words = rtlint::front::wgsl::compile(&text, &p).unwrap();
        common::spirv_val(&words).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        let program = rtlint::front::load(&p, rtlint::front::Language::Wgsl).unwrap();
        let findings = rtlint::rules::check_program(&program, &rtlint::config::Config::default());
        assert!(findings.is_empty(), "{}: {findings:?}", p.display());
    }
    assert!(n >= 3, "expected the reference shaders, found {n}");
}

#[test]
fn main_job_runs_clean() {
    let o = common::rtlint()
        .args(["check", "shaders/"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(text.contains("0 errors, 0 warnings in"), "{text}");
}
