//! rtlint against the tools users would otherwise run, on the same inputs in
//! the same run, and rtlint at scale: medians and ratios, printed as a table
//! and written to `target/bench/peers.csv`.
//!
//! - `rtlint check` (all rules) against `spirv-val` on SPIR-V modules: per
//!   file (rtlint in process, spirv-val one process per file, as a CI step
//!   runs it) and over the whole folder as users run each (`rtlint check
//!   DIR`; `spirv-val` per file, one after another and `xargs -P`).
//! - the WGSL path against naga's own parse + validate, with where rtlint's
//!   extra time goes (SPIR-V out, reading the module, rules).
//! - the static stack model against creating the pipeline and asking the
//!   driver (`vkGetRayTracingShaderGroupStackSizeKHR`), when a device is there,
//!   with the driver's shader caches off (`RTLINT_BENCH_DRIVER_CACHE=1`
//!   keeps them: a repeated creation is then a cache lookup).
//! - scaling: 1..10,000 files, one HLSL and one WGSL file growing 1×..64× (entry
//!   points, instructions, includes; functions, statements): wall time and peak memory (maxrss of
//!   the `rtlint` child).
//! - the result cache (cold against warm) and `--shard`.
//!
//! `cargo bench --bench peers` (set `RTLINT_BENCH_SPV=DIR` to add a folder of
//! SPIR-V modules, such as the public corpus compiled by
//! `scripts/corpus glsl`); `-- --quick` or `RTLINT_BENCH_QUICK=1` is the smoke
//! mode `scripts/test` runs.

use rtlint::config::Config;
use rtlint::lint::check_input;
use rtlint::shader::Language;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time<F: FnMut()>(iters: usize, mut f: F) -> Duration {
    f(); // warm
    median(
        (0..iters.max(1))
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed()
            })
            .collect(),
    )
}

/// The median time of `f` on a fresh `setup()` each time, neither the
/// setup nor dropping its result timed (subtracting a separately timed
/// setup left mostly noise when the setup takes ten times as long as `f`).
fn time_fresh<T, S: FnMut() -> T, F: FnMut(&T)>(iters: usize, mut setup: S, mut f: F) -> Duration {
    f(&setup()); // warm
    median(
        (0..iters.max(1))
            .map(|_| {
                let input = setup();
                let t = Instant::now();
                f(&input);
                let elapsed = t.elapsed();
                drop(input);
                elapsed
            })
            .collect(),
    )
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// One line of the table and the CSV.
struct Row {
    section: &'static str,
    case: String,
    ours_ms: f64,
    peer: String,
    peer_ms: Option<f64>,
    /// Peak memory of the rtlint child, KiB.
    rss_kib: Option<u64>,
}

impl Row {
    fn ratio(&self) -> Option<f64> {
        self.peer_ms.filter(|p| *p > 0.0).map(|p| self.ours_ms / p)
    }
}

#[derive(Default)]
struct Table(Vec<Row>);

impl Table {
    fn push(&mut self, row: Row) {
        println!(
            "{:<10} {:<46} {:>11.3} {:>24} {:>8} {:>10}",
            row.section,
            row.case,
            row.ours_ms,
            match row.peer_ms {
                Some(p) => format!("{p:.3} {}", row.peer),
                None => row.peer.clone(),
            },
            row.ratio().map_or("-".into(), |r| format!("{r:.3}")),
            row.rss_kib
                .map_or("-".into(), |k| format!("{:.1}", k as f64 / 1024.0)),
        );
        self.0.push(row);
    }

    fn csv(&self) -> String {
        let mut s = String::from("section,case,rtlint_ms,peer,peer_ms,ratio,rtlint_maxrss_kib\n");
        for r in &self.0 {
            let _ = writeln!(
                s,
                "{},\"{}\",{:.4},{},{},{},{}",
                r.section,
                r.case.replace('"', "'"),
                r.ours_ms,
                r.peer,
                r.peer_ms.map_or(String::new(), |p| format!("{p:.4}")),
                r.ratio().map_or(String::new(), |p| format!("{p:.4}")),
                r.rss_kib.map_or(String::new(), |k| k.to_string()),
            );
        }
        s
    }
}

/// Runs a command to its end: wall time and its peak memory (KiB), as GNU
/// time reports it. (A child's own `wait4` rusage will not do: std starts it
/// with `vfork`, so its maximum resident set starts at this process's.)
fn run_child(cmd: &mut Command) -> (Duration, u64) {
    let out = std::env::temp_dir().join(format!("rtlint-peers-rss-{}", std::process::id()));
    let time = Path::new("/usr/bin/time");
    let mut wrapped = if time.is_file() {
        let mut w = Command::new(time);
        w.args(["-f", "%M", "-o"]).arg(&out).arg(cmd.get_program());
        w
    } else {
        Command::new(cmd.get_program())
    };
    wrapped.args(cmd.get_args());
    for (k, v) in cmd.get_envs() {
        match v {
            Some(v) => wrapped.env(k, v),
            None => wrapped.env_remove(k),
        };
    }
    if let Some(d) = cmd.get_current_dir() {
        wrapped.current_dir(d);
    }
    wrapped
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    let t = Instant::now();
    wrapped.status().expect("start child");
    let elapsed = t.elapsed();
    let rss = std::fs::read_to_string(&out)
        .ok()
        .and_then(|s| s.lines().last().and_then(|l| l.trim().parse().ok()))
        .unwrap_or(0);
    let _ = std::fs::remove_file(&out);
    (elapsed, rss)
}

fn rtlint_bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rtlint"));
    c.env("NO_COLOR", "1");
    c
}

fn which(tool: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(tool))
        .find(|p| p.is_file())
}

fn files_under(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, ext, out);
        } else if p.to_string_lossy().ends_with(ext) {
            out.push(p);
        }
    }
}

fn all_rules() -> Config {
    let mut c = Config::default();
    c.select = Some(vec!["ALL".to_string()]);
    c
}

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("target/bench/scratch")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn main() {
    // `cargo test --all-targets` runs bench binaries too: time only under
    // `cargo bench` (or when asked for the smoke run).
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick")
        || std::env::var_os("RTLINT_BENCH_QUICK").is_some_and(|v| v != "0");
    if !quick && !args.iter().any(|a| a == "--bench") {
        return;
    }
    let caches_off = rtlint_testkit::driver_caches_off();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(&root).unwrap();
    let iters = if quick { 3 } else { 15 };
    let mut table = Table::default();
    println!(
        "{:<10} {:<46} {:>11} {:>24} {:>8} {:>10}",
        "section", "case", "rtlint ms", "peer ms", "ratio", "rss MiB"
    );

    // SPIR-V: rtlint check (all rules) against spirv-val.
    let mut spv: Vec<PathBuf> = Vec::new();
    files_under(&root.join("fixtures"), ".spv", &mut spv);
    if let Some(d) = std::env::var_os("RTLINT_BENCH_SPV") {
        files_under(Path::new(&d), ".spv", &mut spv);
    }
    if quick {
        spv.truncate(8);
    }
    let spirv_val = which("spirv-val");
    let config = all_rules();
    let (mut ours_total, mut peer_total) = (Duration::ZERO, Duration::ZERO);
    let mut ratios = Vec::new();
    let mut used: Vec<PathBuf> = Vec::new();
    for f in &spv {
        // Modules rtlint rejects (invalid on purpose) are left out of the
        // comparison: neither tool does the same work on them.
        if check_input(f, Language::Spirv, &config).program.is_none() {
            continue;
        }
        let ours = time(iters, || {
            std::hint::black_box(check_input(f, Language::Spirv, &config));
        });
        let peer = spirv_val.as_ref().map(|val| {
            time(iters.min(5), || {
                let _ = Command::new(val)
                    .args(["--target-env", "vulkan1.2"])
                    .arg(f)
                    .output()
                    .unwrap();
            })
        });
        ours_total += ours;
        if let Some(p) = peer {
            peer_total += p;
            ratios.push(ours.as_secs_f64() / p.as_secs_f64());
        }
        used.push(f.clone());
    }
    ratios.sort_by(f64::total_cmp);
    table.push(Row {
        section: "spirv",
        case: format!("{} modules, per file (sum of medians)", used.len()),
        ours_ms: ms(ours_total),
        peer: "spirv-val".into(),
        peer_ms: spirv_val.as_ref().map(|_| ms(peer_total)),
        rss_kib: None,
    });
    if let Some(m) = ratios.get(ratios.len() / 2) {
        println!(
            "           median per-file ratio {m:.3} over {} modules",
            ratios.len()
        );
    }
    // The whole folder, as each is run.
    let folder = scratch("spirv");
    for (i, f) in used.iter().enumerate() {
        std::fs::copy(
            f,
            folder.join(format!(
                "{i:05}.{}",
                f.file_name().unwrap().to_string_lossy()
            )),
        )
        .unwrap();
    }
    let whole = median(
        (0..iters.min(5))
            .map(|_| {
                run_child(
                    rtlint_bin()
                        .args(["check", "--no-cache", "--select", "ALL", "--exit-zero"])
                        .arg(&folder),
                )
                .0
            })
            .collect(),
    );
    if let Some(val) = &spirv_val {
        let list: Vec<PathBuf> = used
            .iter()
            .enumerate()
            .map(|(i, f)| {
                folder.join(format!(
                    "{i:05}.{}",
                    f.file_name().unwrap().to_string_lossy()
                ))
            })
            .collect();
        let seq = time(iters.min(3), || {
            for f in &list {
                let _ = Command::new(val)
                    .args(["--target-env", "vulkan1.2"])
                    .arg(f)
                    .output();
            }
        });
        let jobs = std::thread::available_parallelism().map_or(2, |n| n.get());
        let par = time(iters.min(3), || {
            let _ = Command::new("sh")
                .arg("-c")
                .arg(format!(
                    "ls {}/*.spv | xargs -n1 -P{jobs} {} --target-env vulkan1.2 >/dev/null 2>&1",
                    folder.display(),
                    val.display()
                ))
                .status();
        });
        for (how, t) in [("one after another", seq), ("xargs -P", par)] {
            table.push(Row {
                section: "spirv",
                case: format!("whole folder ({} files), spirv-val {how}", list.len()),
                ours_ms: ms(whole),
                peer: "spirv-val".into(),
                peer_ms: Some(ms(t)),
                rss_kib: None,
            });
        }
    }

    // WGSL: rtlint check against naga's parse + validate.
    let mut wgsl: Vec<PathBuf> = Vec::new();
    files_under(&root.join("shaders"), ".wgsl", &mut wgsl);
    files_under(&root.join("fixtures"), ".wgsl", &mut wgsl);
    wgsl.retain(|f| check_input(f, Language::Wgsl, &config).program.is_some());
    if quick {
        wgsl.truncate(4);
    }
    let mut parts = [Duration::ZERO; 5];
    for f in &wgsl {
        let text = std::fs::read_to_string(f).unwrap();
        let ours = time(iters, || {
            std::hint::black_box(check_input(f, Language::Wgsl, &config));
        });
        let naga_floor = time(iters, || {
            let module = naga::front::wgsl::parse_str(&text).unwrap();
            let mut v = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            );
            std::hint::black_box(v.validate(&module).unwrap());
        });
        let compiled = time(iters, || {
            std::hint::black_box(rtlint::front::wgsl::compile(&text, f).unwrap());
        });
        let loaded = time(iters, || {
            std::hint::black_box(rtlint::front::load(f, Language::Wgsl).unwrap());
        });
        // On a fresh Program each time: a Program keeps what its analyses
        // computed (live sites), so a second run of the rules is cheaper.
        let rules = time_fresh(
            iters,
            || rtlint::front::load(f, Language::Wgsl).unwrap(),
            |program| {
                std::hint::black_box(rtlint::rules::check_program(program, &config));
            },
        );
        for (k, d) in [ours, naga_floor, compiled, loaded, rules]
            .into_iter()
            .enumerate()
        {
            parts[k] += d;
        }
    }
    let [ours, naga_floor, compiled, loaded, rules] = parts;
    table.push(Row {
        section: "wgsl",
        case: format!("{} files, rtlint check (all rules)", wgsl.len()),
        ours_ms: ms(ours),
        peer: "naga".into(),
        peer_ms: Some(ms(naga_floor)),
        rss_kib: None,
    });
    // What the one-IR design costs before any rule runs: naga's own SPIR-V
    // writer (with the debug info that carries positions) on top of naga.
    table.push(Row {
        section: "wgsl",
        case: "  of which the front-end alone (naga + its SPIR-V writer)".into(),
        ours_ms: ms(compiled),
        peer: "naga".into(),
        peer_ms: Some(ms(naga_floor)),
        rss_kib: None,
    });
    println!(
        "           where the time goes: naga parse+validate {:.3} ms, + SPIR-V out {:.3}, + reading the module {:.3}, rules {:.3}",
        ms(naga_floor),
        ms(compiled.saturating_sub(naga_floor)),
        ms(loaded.saturating_sub(compiled)),
        ms(rules)
    );

    // The stack model against the driver.
    let mut pipelines: Vec<PathBuf> = Vec::new();
    for dir in ["shaders", "fixtures/pipelines"] {
        files_under(&root.join(dir), ".pipeline.toml", &mut pipelines);
    }
    // The smoke run leaves the device out unless asked
    // (`RTLINT_BENCH_DRIVER=1`: every pipeline, model and driver).
    let driver = !quick || std::env::var_os("RTLINT_BENCH_DRIVER").is_some();
    if !driver {
        pipelines.truncate(2);
    }
    #[cfg(feature = "vulkan")]
    let ctx = if driver {
        rtlint::vk::Context::new().ok()
    } else {
        None
    };
    let (mut model_total, mut driver_total, mut driver_n) = (Duration::ZERO, Duration::ZERO, 0);
    let mut model_each = Vec::new();
    for p in &pipelines {
        let Ok(pipeline) = rtlint::pipeline::load(p) else {
            continue;
        };
        // On freshly loaded Programs: a Program keeps its live sites once
        // computed, so a second stack report of the same one costs less.
        let model = time_fresh(
            iters * 2,
            || rtlint::pipeline::load(p).unwrap(),
            |fresh| {
                std::hint::black_box(rtlint::analysis::stack_report(fresh));
            },
        );
        model_total += model;
        model_each.push(ms(model));
        #[cfg(feature = "vulkan")]
        if let Some(c) = &ctx {
            let depth = rtlint::analysis::recursion_report(&pipeline).required_depth;
            if rtlint::vk::driver_stack_sizes(c, &pipeline, depth).is_ok() {
                driver_total += time(iters.min(5), || {
                    let _ = rtlint::vk::driver_stack_sizes(c, &pipeline, depth);
                });
                driver_n += 1;
            }
        }
    }
    model_each.sort_by(f64::total_cmp);
    table.push(Row {
        section: "stack",
        case: format!(
            "{} pipelines, model (per pipeline {:.3}..{:.3} ms)",
            model_each.len(),
            model_each.first().copied().unwrap_or(0.0),
            model_each.last().copied().unwrap_or(0.0)
        ),
        ours_ms: ms(model_total),
        peer: if driver_n > 0 {
            let cache = if caches_off { "compiling" } else { "cache on" };
            format!("driver({driver_n}, {cache})")
        } else {
            "no device".into()
        },
        peer_ms: (driver_n > 0).then(|| ms(driver_total)),
        rss_kib: None,
    });

    // Scaling in the number of files: copies of the repository's shaders,
    // 25 to a folder (shards deal out folders whole).
    let mut seeds: Vec<PathBuf> = used.clone();
    seeds.extend(wgsl.iter().cloned());
    let counts: &[usize] = if quick {
        &[1, 10, 50]
    } else {
        &[1, 10, 100, 1000, 10_000]
    };
    let mut biggest = PathBuf::new();
    for &n in counts {
        let dir = scratch(&format!("files-{n}"));
        for i in 0..n {
            let seed = &seeds[i % seeds.len()];
            let sub = dir.join(format!("d{:03}", i / 25));
            std::fs::create_dir_all(&sub).unwrap();
            let name = seed.file_name().unwrap().to_string_lossy();
            std::fs::copy(seed, sub.join(format!("{i:05}.{name}"))).unwrap();
        }
        let runs: Vec<(Duration, u64)> = (0..if n >= 1000 || quick { 1 } else { 3 })
            .map(|_| {
                run_child(
                    rtlint_bin()
                        .args(["check", "--no-cache", "--select", "ALL", "--exit-zero"])
                        .arg(&dir),
                )
            })
            .collect();
        let t = median(runs.iter().map(|r| r.0).collect());
        let rss = runs.iter().map(|r| r.1).max().unwrap_or(0);
        table.push(Row {
            section: "files",
            case: format!("{n} files ({:.3} ms per file)", ms(t) / n as f64),
            ours_ms: ms(t),
            peer: "-".into(),
            peer_ms: None,
            rss_kib: Some(rss),
        });
        biggest = dir;
    }

    // One HLSL file growing: entry points, instructions, includes; one WGSL
    // file growing in functions and in statements (naga's writer made WGSL
    // quadratic in the file's length once: docs/performance.md).
    let factors: &[usize] = if quick {
        &[1, 4]
    } else {
        &[1, 2, 4, 8, 16, 32, 64]
    };
    let shapes = [
        "entry points",
        "instructions",
        "includes",
        "wgsl functions",
        "wgsl statements",
    ];
    for shape in shapes {
        for &k in factors {
            let dir = scratch(&format!("grow-{}-{k}", shape.replace(' ', "-")));
            let (text, file) = match shape.strip_prefix("wgsl ") {
                Some(wgsl_shape) => (grown_wgsl(&root, wgsl_shape, k), dir.join("grown.wgsl")),
                None => (grown_hlsl(shape, k, &dir), dir.join("grown.hlsl")),
            };
            std::fs::write(&file, text).unwrap();
            let runs: Vec<(Duration, u64)> = (0..3)
                .map(|_| {
                    run_child(
                        rtlint_bin()
                            .args(["check", "--no-cache", "--select", "ALL", "--exit-zero"])
                            .arg(&file),
                    )
                })
                .collect();
            let t = median(runs.iter().map(|r| r.0).collect());
            table.push(Row {
                section: "grow",
                case: format!("{shape} ×{k}"),
                ours_ms: ms(t),
                peer: "-".into(),
                peer_ms: None,
                rss_kib: runs.iter().map(|r| r.1).max(),
            });
        }
    }

    // The cache: the biggest tree cold, then warm; then shards.
    let cache = scratch("cache");
    let check_cached = |extra: &[&str]| {
        run_child(
            rtlint_bin()
                .args(["check", "--select", "ALL", "--exit-zero", "--cache-dir"])
                .arg(&cache)
                .args(extra)
                .arg(&biggest),
        )
    };
    let n = counts.last().copied().unwrap_or(0);
    // Cold: the median of three runs, each from an empty cache (one run
    // swung between 3.4 and 7.8 s with the disk's mood while it writes
    // 10,000 entries); the last one leaves the cache warm.
    let colds: Vec<(Duration, u64)> = (0..3)
        .map(|_| {
            let _ = std::fs::remove_dir_all(&cache);
            check_cached(&[])
        })
        .collect();
    let cold = median(colds.iter().map(|r| r.0).collect());
    let cold_rss = colds.iter().map(|r| r.1).max().unwrap_or(0);
    let warm = median((0..3).map(|_| check_cached(&[]).0).collect());
    table.push(Row {
        section: "cache",
        case: format!("{n} files, warm (peer: cold)"),
        ours_ms: ms(warm),
        peer: "cold".into(),
        peer_ms: Some(ms(cold)),
        rss_kib: Some(cold_rss),
    });
    let shards = 4;
    let mut slowest = Duration::ZERO;
    let mut sum = Duration::ZERO;
    for k in 1..=shards {
        let (t, _) = run_child(
            rtlint_bin()
                .args([
                    "check",
                    "--no-cache",
                    "--select",
                    "ALL",
                    "--exit-zero",
                    "--shard",
                ])
                .arg(format!("{k}/{shards}"))
                .arg(&biggest),
        );
        slowest = slowest.max(t);
        sum += t;
    }
    let (whole, _) = run_child(
        rtlint_bin()
            .args(["check", "--no-cache", "--select", "ALL", "--exit-zero"])
            .arg(&biggest),
    );
    table.push(Row {
        section: "shard",
        case: format!(
            "{n} files, slowest of {shards} shards (sum {:.0} ms)",
            ms(sum)
        ),
        ours_ms: ms(slowest),
        peer: "whole".into(),
        peer_ms: Some(ms(whole)),
        rss_kib: None,
    });

    let out = root.join("target/bench");
    std::fs::create_dir_all(&out).unwrap();
    let csv = out.join(if quick {
        "peers-quick.csv"
    } else {
        "peers.csv"
    });
    std::fs::write(&csv, table.csv()).unwrap();
    let _ = std::fs::remove_dir_all(out.join("scratch"));
    println!(
        "ratio = rtlint / peer (below 1: rtlint is faster); wrote {}",
        csv.display()
    );
}

/// An HLSL shader `k` times as big in one way: `k` entry points with a
/// helper each, one entry point with `k` times the statements, or `k`
/// included headers (written into `dir`).
/// The glossy reference shader with `k` × 64 small functions, or with one
/// function of `k` × 64 statements.
fn grown_wgsl(root: &Path, shape: &str, k: usize) -> String {
    let mut s = std::fs::read_to_string(root.join("shaders/reflect_glossy.wgsl")).unwrap();
    if shape == "functions" {
        for i in 0..64 * k {
            let _ = write!(
                s,
                "\nfn grown{i}(x: f32) -> f32 {{\n    var y = x;\n    if y > 4.0 {{ y = y * 0.5; }}\n    return y + {i}.0;\n}}\n"
            );
        }
    } else {
        s.push_str("\nfn grown(x: f32) -> f32 {\n    var y = x;\n");
        for i in 0..64 * k {
            let _ = writeln!(s, "    y = y * 0.5 + {i}.0;");
        }
        s.push_str("    return y;\n}\n");
    }
    s
}

fn grown_hlsl(shape: &str, k: usize, dir: &Path) -> String {
    let mut s = String::from(
        "RaytracingAccelerationStructure tlas : register(t0);\nRWTexture2D<float4> image : register(u1);\nstruct Payload { float4 color; };\n",
    );
    let entry = |s: &mut String, i: usize, body: &str| {
        let _ = write!(
            s,
            "[shader(\"raygeneration\")]\nvoid Gen{i}()\n{{\n    float3 a = float3(0.0, 0.0, 0.0);\n{body}    RayDesc ray;\n    ray.Origin = a;\n    ray.Direction = float3(0.0, 0.0, 1.0);\n    ray.TMin = 0.001;\n    ray.TMax = 100.0;\n    Payload p = (Payload)0;\n    TraceRay(tlas, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, ray, p);\n    image[DispatchRaysIndex().xy] = p.color + float4(a, 1.0);\n}}\n"
        );
    };
    let step = |i: usize| format!("    a = a * 0.5 + float3({i}.0, 1.0, 2.0);\n");
    match shape {
        "entry points" => {
            for i in 0..k {
                let _ = write!(
                    s,
                    "float3 helper{i}(float3 x)\n{{\n    for (int j = 0; j < 4; j++) {{ x = x * 0.5 + float3(j, {i}, 1); }}\n    return x;\n}}\n"
                );
                entry(&mut s, i, &format!("    a = helper{i}(a);\n"));
            }
        }
        "instructions" => {
            let body: String = (0..32 * k).map(step).collect();
            entry(&mut s, 0, &body);
        }
        _ => {
            let mut body = String::new();
            for i in 0..k {
                std::fs::write(
                    dir.join(format!("inc{i}.hlsli")),
                    format!(
                        "float3 inc{i}(float3 x)\n{{\n{}    return x;\n}}\n",
                        (0..8)
                            .map(|j| format!("    x = x * 0.5 + float3({j}.0, {i}.0, 1.0);\n"))
                            .collect::<String>()
                    ),
                )
                .unwrap();
                let _ = writeln!(s, "#include \"inc{i}.hlsli\"");
                body.push_str(&format!("    a = inc{i}(a);\n"));
            }
            entry(&mut s, 0, &body);
        }
    }
    s
}
