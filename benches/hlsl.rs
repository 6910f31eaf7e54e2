//! Compile time per HLSL entry point: rtlint's own compiler against Slang, on
//! the same files in the same run. Each side compiles one entry point from
//! the file on disk (read, preprocess, parse, emit); Slang's global session
//! is created once, before any timing. Prints a table and the overall ratio;
//! `cargo bench --bench hlsl`.

use rtlint::front::hlsl::{self, HlslOptions};
use rtlint_testkit::Slang;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Timed runs per entry point and compiler; the median is reported.
const RUNS: usize = 15;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(mut f: F) -> Duration {
    f(); // warm caches and lazy initialisation outside the timing
    median(
        (0..RUNS)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed()
            })
            .collect(),
    )
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    // `cargo test --all-targets` runs bench binaries too; time only under `cargo bench`.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let slang = Slang::find().expect("Slang is required (scripts/setup installs slangpy)");
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("tests/hlsl"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "hlsl"))
        .collect();
    files.sort();

    println!(
        "{:<26} {:<20} {:<14} {:>10} {:>10} {:>8}",
        "file", "entry", "stage", "rtlint ms", "slang ms", "ratio"
    );
    let (mut ours_total, mut theirs_total) = (Duration::ZERO, Duration::ZERO);
    let mut ratios = Vec::new();
    let mut left_out = Vec::new();
    for file in &files {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let entries = match hlsl::compile(file, &HlslOptions::default()) {
            Ok(e) => e,
            Err(e) => {
                left_out.push(format!("{name}: rtlint: {e}"));
                continue;
            }
        };
        for entry in entries {
            let stage = rtlint_testkit::stage_name(entry.stage);
            if let Err(e) = slang.compile_hlsl(file, &entry.name, stage, &[]) {
                let first = e.lines().next().unwrap_or("").to_string();
                left_out.push(format!("{name}:{}: Slang: {first}", entry.name));
                continue;
            }
            let options = HlslOptions {
                entry: Some(entry.name.clone()),
                ..HlslOptions::default()
            };
            let ours = time(|| {
                let m = hlsl::compile(file, &options).unwrap();
                assert_eq!(m.len(), 1);
            });
            let theirs = time(|| {
                slang.compile_hlsl(file, &entry.name, stage, &[]).unwrap();
            });
            ours_total += ours;
            theirs_total += theirs;
            let ratio = theirs.as_secs_f64() / ours.as_secs_f64();
            ratios.push(ratio);
            println!(
                "{:<26} {:<20} {:<14} {:>10.3} {:>10.3} {:>7.1}x",
                name,
                entry.name,
                stage,
                ms(ours),
                ms(theirs),
                ratio
            );
        }
    }
    ratios.sort_by(f64::total_cmp);
    println!(
        "{:<62} {:>10.3} {:>10.3} {:>7.1}x",
        format!("total ({} entry points)", ratios.len()),
        ms(ours_total),
        ms(theirs_total),
        theirs_total.as_secs_f64() / ours_total.as_secs_f64()
    );
    println!(
        "per-entry ratio: min {:.1}x, median {:.1}x, max {:.1}x",
        ratios[0],
        ratios[ratios.len() / 2],
        ratios[ratios.len() - 1]
    );
    println!(
        "ratio = Slang time / rtlint time (above 1: rtlint is faster); median of {RUNS} runs each"
    );
    for l in &left_out {
        println!("not timed: {l}");
    }
}
