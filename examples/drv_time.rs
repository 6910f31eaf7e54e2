//! Times creating each pipeline on the driver and querying its stack sizes:
//! the first creation in this process, then four repeats (a driver may keep
//! what it compiled, in memory or on disk).
//!
//! `cargo run --release --features vulkan --example drv_time -- PIPELINE.toml...`
fn main() {
    let ctx = rtlint::vk::Context::new().expect("a Vulkan device");
    let (mut first_total, mut repeat_total) = (0.0, 0.0);
    for f in std::env::args().skip(1) {
        let p = rtlint::pipeline::load(std::path::Path::new(&f)).expect("pipeline");
        let depth = rtlint::analysis::recursion_report(&p).required_depth;
        let mut ms = Vec::new();
        for _ in 0..5 {
            let t = std::time::Instant::now();
            if rtlint::vk::driver_stack_sizes(&ctx, &p, depth).is_err() {
                break;
            }
            ms.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let Some((&first, rest)) = ms.split_first() else {
            println!("{f}: not created");
            continue;
        };
        let mut rest = rest.to_vec();
        rest.sort_by(f64::total_cmp);
        let median = rest[rest.len() / 2];
        println!("{f}: first {first:.2} ms, repeats {rest:.2?} (median {median:.2})");
        first_total += first;
        repeat_total += median;
    }
    println!("total: first {first_total:.2} ms, repeated (median) {repeat_total:.2} ms");
}
