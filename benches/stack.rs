//! The static stack model against a driver query, on the same pipelines in
//! the same run: `rtlint::analysis::stack_report` (recursion + liveness +
//! stack model) versus creating the pipeline on the Vulkan device and asking
//! `vkGetRayTracingShaderGroupStackSizeKHR` for every group (what `--driver`
//! does; the device is opened once, outside the timing).
//! `cargo bench --bench stack [-- PIPELINE.toml...]`

use std::path::PathBuf;
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(iters: usize, mut f: F) -> Duration {
    f();
    median(
        (0..iters)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed()
            })
            .collect(),
    )
}

fn main() {
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let caches_off = rtlint_testkit::driver_caches_off();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(&root).unwrap();
    let mut paths: Vec<PathBuf> = std::env::args()
        .skip(1)
        .filter(|a| a.ends_with(".pipeline.toml"))
        .map(PathBuf::from)
        .collect();
    if paths.is_empty() {
        for dir in ["shaders", "fixtures/pipelines", "calibration"] {
            let mut d: Vec<PathBuf> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| rtlint::lint::is_pipeline(p))
                .collect();
            d.sort();
            paths.extend(d);
        }
    }
    let ctx = match rtlint::vk::Context::new() {
        Ok(c) => Some(c),
        Err(e) => {
            println!("no device ({e}); timing the model only");
            None
        }
    };
    if let Some(c) = &ctx {
        println!(
            "device: {} ({}), driver shader caches {}",
            c.info().name,
            c.info().driver,
            if caches_off { "off" } else { "on" }
        );
    }
    println!(
        "{:<48} {:>10} {:>12} {:>9}",
        "pipeline", "model ms", "driver ms", "ratio"
    );
    let (mut tm, mut td) = (Duration::ZERO, Duration::ZERO);
    for p in &paths {
        let pipeline = rtlint::pipeline::load(p).unwrap_or_else(|e| panic!("{e}"));
        let model = time(20, || {
            std::hint::black_box(rtlint::analysis::stack_report(&pipeline));
        });
        let depth = rtlint::analysis::recursion_report(&pipeline).required_depth;
        let driver = ctx.as_ref().map(|c| {
            time(5, || {
                rtlint::vk::driver_stack_sizes(c, &pipeline, depth).expect("driver query");
            })
        });
        tm += model;
        td += driver.unwrap_or_default();
        println!(
            "{:<48} {:>10.3} {:>12} {:>9}",
            p.display(),
            model.as_secs_f64() * 1e3,
            driver.map_or("-".into(), |d| format!("{:.3}", d.as_secs_f64() * 1e3)),
            driver.map_or("-".into(), |d| format!(
                "{:.1}x",
                d.as_secs_f64() / model.as_secs_f64()
            ))
        );
    }
    if ctx.is_some() {
        println!(
            "{:<48} {:>10.3} {:>12.3} {:>8.1}x",
            "total",
            tm.as_secs_f64() * 1e3,
            td.as_secs_f64() * 1e3,
            td.as_secs_f64() / tm.as_secs_f64()
        );
        println!("ratio = driver query (pipeline creation + group queries) / static model");
    }
}
