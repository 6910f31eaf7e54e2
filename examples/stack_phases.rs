//! Times the phases of the stack model on freshly loaded pipelines:
//! `cargo run --release --example stack_phases -- [ITERS] [PIPELINE.toml...]`
//! (default: the repository's pipelines); `STATS=1` prints each program's size instead.
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let iters: usize = args
        .first()
        .and_then(|a| a.parse().ok())
        .inspect(|_| {
            args.remove(0);
        })
        .unwrap_or(20);
    let mut files: Vec<PathBuf> = args.iter().map(PathBuf::from).collect();
    if files.is_empty() {
        for dir in ["shaders", "fixtures/pipelines"] {
            let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
                .unwrap()
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.to_string_lossy().ends_with(".pipeline.toml"))
                .collect();
            v.sort();
            files.extend(v);
        }
    }
    if std::env::var_os("STATS").is_some() {
        for f in &files {
            let p = rtlint::pipeline::load(f).unwrap();
            for prog in &p.programs {
                let blocks: usize = prog.functions.iter().map(|f| f.blocks.len()).sum();
                println!(
                    "{} {}: insts {} functions {} blocks {} sites {} live sites {} values {}",
                    f.display(),
                    prog.path.display(),
                    prog.insts.len(),
                    prog.functions.len(),
                    blocks,
                    prog.sites.len(),
                    rtlint::analysis::liveness::live_sites(prog).len(),
                    rtlint::analysis::liveness::live_sites(prog)
                        .iter()
                        .map(|s| s.values.len())
                        .sum::<usize>()
                );
            }
        }
        return;
    }
    let mut total = [Duration::ZERO; 4];
    for f in &files {
        let mut t = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..iters {
            let a = Instant::now();
            let p = rtlint::pipeline::load(f).unwrap();
            let b = Instant::now();
            let rec = rtlint::analysis::recursion_report(&p);
            let c = Instant::now();
            for prog in &p.programs {
                std::hint::black_box(rtlint::analysis::liveness::live_sites(prog));
            }
            let d = Instant::now();
            std::hint::black_box(rtlint::analysis::stack::stack_report_with(&p, &rec));
            let e = Instant::now();
            for (k, x) in [b - a, c - b, d - c, e - d].into_iter().enumerate() {
                t[k].push(x);
            }
        }
        let med: Vec<Duration> = t
            .iter_mut()
            .map(|v| {
                v.sort();
                v[v.len() / 2]
            })
            .collect();
        for k in 0..4 {
            total[k] += med[k];
        }
        println!(
            "{:<50} load {:>8.3} rec {:>8.3} live {:>8.3} rest {:>8.3} ms",
            f.display(),
            med[0].as_secs_f64() * 1e3,
            med[1].as_secs_f64() * 1e3,
            med[2].as_secs_f64() * 1e3,
            med[3].as_secs_f64() * 1e3
        );
    }
    println!(
        "{:<50} load {:>8.3} rec {:>8.3} live {:>8.3} rest {:>8.3} ms",
        "TOTAL",
        total[0].as_secs_f64() * 1e3,
        total[1].as_secs_f64() * 1e3,
        total[2].as_secs_f64() * 1e3,
        total[3].as_secs_f64() * 1e3
    );
}
