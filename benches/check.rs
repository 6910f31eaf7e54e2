//! How long `rtlint check` takes per file, next to peers run on the same input
//! in the same process run: naga alone (parse + validate + SPIR-V out) for
//! WGSL, and `spirv-val` (the validator a CI would run anyway) for SPIR-V.
//! Prints a table; `cargo bench --bench check`.

use rtlint::config::Config;
use rtlint::lint::check_input;
use rtlint::shader::Language;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(iters: usize, mut f: F) -> Duration {
    f(); // warm
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

fn ms(d: Duration) -> String {
    format!("{:.3}", d.as_secs_f64() * 1e3)
}

fn main() {
    // `cargo test --all-targets` runs bench binaries too; time only under `cargo bench`.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(&root).unwrap();
    let mut files: Vec<PathBuf> = Vec::new();
    for dir in [
        "shaders",
        "fixtures/RT001",
        "fixtures/RT005",
        "fixtures/glsl",
    ] {
        let mut d: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        d.sort();
        files.extend(d.into_iter().filter(|p| {
            let n = p.to_string_lossy();
            n.ends_with(".wgsl") || n.ends_with(".gV.spv")
        }));
    }
    let config = Config::default();
    let spirv_val = which("spirv-val");
    println!(
        "{:<44} {:>9} {:>12} {:>12} {:>8}",
        "file", "words", "rtlint ms", "peer ms", "ratio"
    );
    let (mut total_ours, mut total_peer) = (Duration::ZERO, Duration::ZERO);
    for f in &files {
        let language = Language::from_path(f).unwrap();
        let words = rtlint::front::compile_path(f, language).unwrap().words;
        let ours = time(30, || {
            let c = check_input(f, language, &config);
            assert!(c.program.is_some());
        });
        let (peer_name, peer) = if language == Language::Wgsl {
            let text = std::fs::read_to_string(f).unwrap();
            (
                "naga",
                time(30, || {
                    rtlint::front::wgsl::compile(&text, f).unwrap();
                }),
            )
        } else {
            match &spirv_val {
                Some(val) => (
                    "spirv-val",
                    time(10, || {
                        let ok = std::process::Command::new(val)
                            .args(["--target-env", "vulkan1.2"])
                            .arg(f)
                            .output()
                            .unwrap()
                            .status
                            .success();
                        assert!(ok);
                    }),
                ),
                None => ("-", Duration::ZERO),
            }
        };
        total_ours += ours;
        total_peer += peer;
        println!(
            "{:<44} {:>9} {:>12} {:>12} {:>8}",
            f.display(),
            words.len(),
            ms(ours),
            format!("{} {}", ms(peer), peer_name),
            if peer.is_zero() {
                "-".into()
            } else {
                format!("{:.2}", ours.as_secs_f64() / peer.as_secs_f64())
            }
        );
    }
    println!(
        "{:<44} {:>9} {:>12} {:>12} {:>8.2}",
        "total",
        "",
        ms(total_ours),
        ms(total_peer),
        total_ours.as_secs_f64() / total_peer.as_secs_f64()
    );
    println!("ratio = rtlint check (read, compile, analyse, all rules) / peer; below 1 is faster than the peer");
    println!("naga: parse + validate + SPIR-V out in process; spirv-val: one process per file, start-up included");
}

fn which(tool: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(tool))
        .find(|p| p.is_file())
}
