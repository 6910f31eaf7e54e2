#![no_main]
//! Structure-aware: the fuzzer's bytes are the generator's choices
//! (`rtlint_testkit::gen`), so every input is a valid ray-tracing module;
//! each must keep the invariants of `rtlint_testkit::gen_check`, with and
//! without its debug info.
use libfuzzer_sys::fuzz_target;
use rtlint_testkit::gen::{module, Source};

fuzz_target!(|data: &[u8]| {
    let plain = module(&mut Source::bytes(data), false);
    let debug = module(&mut Source::bytes(data), true);
    if let Err(e) = rtlint_testkit::gen_check::check_pair(&plain, &debug) {
        panic!("{e}");
    }
});
