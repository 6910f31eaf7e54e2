#![no_main]
//! Any text as `rtlint.toml`: a config or an error with a position, and a
//! config's rule names and options checked against the registry.
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Ok(c) = rtlint::config::Config::parse(text, Path::new("rtlint.toml")) {
        let _ = c.check_rule_names(rtlint::rules::is_selector);
        let _ = c.check_rule_options(rtlint::rules::has_option);
        let _ = c.excludes(Path::new("a/b.hlsl"));
        let _ = c.ignored_for(Path::new("a/b.hlsl"));
    }
});
