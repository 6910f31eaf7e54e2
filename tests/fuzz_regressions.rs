//! Replays the fuzz regression corpus (`fuzz/regressions/<target>/*`: inputs
//! that once crashed or hung a `cargo fuzz` target, minimised) through the
//! same calls as each target in `fuzz/fuzz_targets/`: each must end in a
//! result or an input error (`spirv_gen`: keep the generator's invariants),
//! without asking for more than [`MAX_ALLOCATION`] at once.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};

/// No single allocation over this while replaying: an input that once ran
/// the fuzzer out of memory fails here (the process aborts with
/// "memory allocation of N bytes failed") instead of passing on a machine
/// with enough of it.
const MAX_ALLOCATION: usize = 1 << 30;

struct Capped;

unsafe impl GlobalAlloc for Capped {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MAX_ALLOCATION {
            return std::ptr::null_mut();
        }
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MAX_ALLOCATION {
            return std::ptr::null_mut();
        }
        System.alloc_zeroed(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > MAX_ALLOCATION {
            return std::ptr::null_mut();
        }
        System.realloc(ptr, layout, new_size)
    }
}

#[global_allocator]
static ALLOCATOR: Capped = Capped;

use rtlint::config::Config;
use rtlint::front::hlsl::{compile_source_whole, parse_source, pp::MemLoader, HlslOptions};
use rtlint::shader::Language;
use std::path::Path;

fn run(target: &str, data: &[u8]) {
    let text = std::str::from_utf8(data).ok();
    let hlsl = Path::new("main.hlsl");
    match target {
        "hlsl_preprocess" | "hlsl_parse" => {
            if let Some(t) = text {
                let _ = parse_source(hlsl, t, &mut MemLoader::default(), &HlslOptions::default());
            }
        }
        "hlsl_compile" => {
            if let Some(t) = text {
                let _ = compile_source_whole(
                    hlsl,
                    t,
                    &mut MemLoader::default(),
                    &HlslOptions::default(),
                );
            }
        }
        "wgsl" => {
            let path = Path::new("fuzz.wgsl");
            if let Some(words) = text.and_then(|t| rtlint::front::wgsl::compile(t, path).ok()) {
                if let Ok(p) = rtlint::program::parse(&words, path, Language::Wgsl) {
                    let _ = rtlint::rules::check_program(&p, &Config::default());
                }
            }
        }
        "spirv" => {
            let path = Path::new("fuzz.spv");
            if let Ok(words) = rtlint::program::words_from_bytes(data, path) {
                if let Ok(p) = rtlint::program::parse(&words, path, Language::Spirv) {
                    let config = Config::default();
                    let _ = rtlint::rules::check_program(&p, &config);
                    let _ = rtlint::lint::check_loose(vec![(p, Default::default())], &[], &config);
                }
            }
        }
        "spirv_decode" => {
            if let Ok(words) = rtlint::program::words_from_bytes(data, Path::new("fuzz.spv")) {
                if let Err(e) = rtlint::program::decode::check_against_rspirv(&words) {
                    panic!("{e}");
                }
            }
        }
        "config" => {
            if let Some(Ok(c)) = text.map(|t| Config::parse(t, Path::new("rtlint.toml"))) {
                let _ = c.check_rule_names(rtlint::rules::is_selector);
                let _ = c.check_rule_options(rtlint::rules::has_option);
                let _ = c.excludes(Path::new("a/b.hlsl"));
                let _ = c.ignored_for(Path::new("a/b.hlsl"));
            }
        }
        "pipeline" => {
            if let Some(t) = text {
                let _ = rtlint::pipeline::parse(t, Path::new("fuzz.pipeline.toml"));
            }
        }
        "spirv_gen" => {
            use rtlint_testkit::gen::{module, Source};
            let plain = module(&mut Source::bytes(data), false);
            let debug = module(&mut Source::bytes(data), true);
            if let Err(e) = rtlint_testkit::gen_check::check_pair(&plain, &debug) {
                panic!("{e}");
            }
        }
        other => panic!("fuzz/regressions/{other}: no such fuzz target"),
    }
}

#[test]
fn fuzz_regressions_end_in_results_or_errors() {
    let dir = common::root().join("fuzz/regressions");
    let mut replayed = 0;
    let mut targets: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    targets.sort();
    for t in targets {
        let target = t.file_name().unwrap().to_string_lossy().into_owned();
        let mut inputs: Vec<_> = std::fs::read_dir(&t)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        inputs.sort();
        for input in inputs {
            let data = std::fs::read(&input).unwrap();
            let r = std::panic::catch_unwind(|| run(&target, &data));
            assert!(r.is_ok(), "{} panics", input.display());
            replayed += 1;
        }
    }
    assert!(replayed > 0, "no regression inputs under {}", dir.display());
}
