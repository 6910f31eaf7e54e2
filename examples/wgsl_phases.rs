//! Where the WGSL path's time goes, as in the `wgsl` section of
//! `benches/peers.rs` without the rest of that benchmark, plus each rule's
//! share: `cargo run --release --example wgsl_phases -- [ITERS] [FILE.wgsl...]`
//! (default: every WGSL file under shaders/ and fixtures/ that loads).
//! `LOOP=parse|load|rules|check` repeats one phase ITERS times over the
//! files instead, for a profiler; `STEPS=1` times the steps of reading;
//! `SEQ=1` times the steps of one `check_input` one after the other inside
//! each run (each step as cold as `check_input` finds it), so they add up.
use rtlint::config::Config;
use rtlint::shader::Language;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, out);
        } else if p.extension().is_some_and(|e| e == "wgsl") {
            out.push(p);
        }
    }
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

fn time(iters: usize, mut f: impl FnMut()) -> Duration {
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

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let iters: usize = match args.first().and_then(|a| a.parse().ok()) {
        Some(n) => {
            args.remove(0);
            n
        }
        None => 20,
    };
    let mut files: Vec<PathBuf> = args.iter().map(PathBuf::from).collect();
    if files.is_empty() {
        files_under(Path::new("shaders"), &mut files);
        files_under(Path::new("fixtures"), &mut files);
    }
    let mut config = Config::default();
    config.select = Some(vec!["ALL".to_string()]);
    files.retain(|f| rtlint::front::load(f, Language::Wgsl).is_ok());

    if let Ok(phase) = std::env::var("LOOP") {
        let words: Vec<Vec<u32>> = files
            .iter()
            .map(|f| {
                let text = std::fs::read_to_string(f).unwrap();
                rtlint::front::wgsl::compile(&text, f).unwrap()
            })
            .collect();
        for _ in 0..iters {
            if phase == "parse" {
                for (f, w) in files.iter().zip(&words) {
                    std::hint::black_box(rtlint::program::parse(w, f, Language::Wgsl).unwrap());
                }
                continue;
            }
            for f in &files {
                match phase.as_str() {
                    "load" => {
                        std::hint::black_box(rtlint::front::load(f, Language::Wgsl).unwrap());
                    }
                    "rules" => {
                        let p = rtlint::front::load(f, Language::Wgsl).unwrap();
                        std::hint::black_box(rtlint::rules::check_program(&p, &config));
                    }
                    _ => {
                        std::hint::black_box(rtlint::lint::check_input(f, Language::Wgsl, &config));
                    }
                }
            }
        }
        return;
    }

    if std::env::var_os("SEQ").is_some() {
        in_sequence(iters, &files, &config);
        return;
    }

    if std::env::var_os("STEPS").is_some() {
        steps(iters, &files);
        return;
    }

    let mut parts = [Duration::ZERO; 5];
    let mut per_rule: Vec<(&'static str, Duration)> = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
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
        // Each rule on a fresh Program: a Program keeps what analyses computed.
        let mut rules = Duration::ZERO;
        let programs: Vec<_> = (0..=iters)
            .map(|_| rtlint::front::load(f, Language::Wgsl).unwrap())
            .collect();
        let mut runs: Vec<Vec<Duration>> = Vec::new();
        for p in &programs {
            let t = Instant::now();
            let ctx = rtlint::rules::Context::new(p, &config);
            let mut row = vec![t.elapsed()];
            for rule in rtlint::rules::RULES {
                if let rtlint::rules::Kind::Module(check) = rule.kind {
                    let t = Instant::now();
                    std::hint::black_box(check(&ctx));
                    row.push(t.elapsed());
                }
            }
            runs.push(row);
        }
        let names: Vec<&str> = std::iter::once("context (layouts)")
            .chain(
                rtlint::rules::RULES
                    .iter()
                    .filter(|r| matches!(r.kind, rtlint::rules::Kind::Module(_)))
                    .map(|r| r.code),
            )
            .collect();
        if per_rule.is_empty() {
            per_rule = names.iter().map(|n| (*n, Duration::ZERO)).collect();
        }
        for (k, slot) in per_rule.iter_mut().enumerate() {
            // The first program is the warm-up.
            let d = median(runs[1..].iter().map(|r| r[k]).collect());
            slot.1 += d;
            rules += d;
        }
        let check = time(iters, || {
            std::hint::black_box(rtlint::lint::check_input(f, Language::Wgsl, &config));
        });
        for (k, d) in [check, naga_floor, compiled, loaded, rules]
            .into_iter()
            .enumerate()
        {
            parts[k] += d;
        }
    }
    let [check, naga_floor, compiled, loaded, rules] = parts;
    println!(
        "{} files: rtlint check {:.3} ms, naga parse+validate {:.3} ms ({:.2}x)",
        files.len(),
        ms(check),
        ms(naga_floor),
        ms(check) / ms(naga_floor)
    );
    println!(
        "  + SPIR-V out {:.3} ms, + reading the module {:.3} ms, rules {:.3} ms (sum of per-rule medians)",
        ms(compiled.saturating_sub(naga_floor)),
        ms(loaded.saturating_sub(compiled)),
        ms(rules)
    );
    per_rule.sort_by_key(|r| std::cmp::Reverse(r.1));
    for (code, d) in per_rule.iter().take(12) {
        println!("    {code} {:.3} ms", ms(*d));
    }
}

/// Reading the module, step by step (`STEPS=1`).
fn steps(iters: usize, files: &[PathBuf]) {
    let names = [
        "naga parse+validate",
        "naga SPIR-V out",
        "declarations",
        "rspirv parse_words",
        "program::parse",
        "attach_named_decls",
        "drop Program",
        "read the file",
    ];
    let mut sums = [Duration::ZERO; 8];
    for f in files {
        let text = std::fs::read_to_string(f).unwrap();
        let (mut module, info) = rtlint::front::wgsl::parse(&text, f).unwrap();
        let words = rtlint::front::wgsl::write_spirv(&mut module, &info, &text, f).unwrap();
        let decls = rtlint::front::wgsl::declarations(&module, &text, f);
        let d = [
            time(iters, || {
                std::hint::black_box(rtlint::front::wgsl::parse(&text, f).unwrap());
            }),
            time(iters, || {
                std::hint::black_box(
                    rtlint::front::wgsl::write_spirv(&mut module, &info, &text, f).unwrap(),
                );
            }),
            time(iters, || {
                std::hint::black_box(rtlint::front::wgsl::declarations(&module, &text, f));
            }),
            time(iters, || {
                struct Sink(usize);
                impl rspirv::binary::Consumer for Sink {
                    fn initialize(&mut self) -> rspirv::binary::ParseAction {
                        rspirv::binary::ParseAction::Continue
                    }
                    fn finalize(&mut self) -> rspirv::binary::ParseAction {
                        rspirv::binary::ParseAction::Continue
                    }
                    fn consume_header(
                        &mut self,
                        _: rspirv::dr::ModuleHeader,
                    ) -> rspirv::binary::ParseAction {
                        rspirv::binary::ParseAction::Continue
                    }
                    fn consume_instruction(
                        &mut self,
                        i: rspirv::dr::Instruction,
                    ) -> rspirv::binary::ParseAction {
                        self.0 += i.operands.len();
                        rspirv::binary::ParseAction::Continue
                    }
                }
                let mut s = Sink(0);
                rspirv::binary::parse_words(&words, &mut s).unwrap();
                std::hint::black_box(s.0);
            }),
            time(iters, || {
                std::hint::black_box(rtlint::program::parse(&words, f, Language::Wgsl).unwrap());
            }),
            {
                let mut total = Vec::new();
                for _ in 0..iters {
                    let mut p = rtlint::program::parse(&words, f, Language::Wgsl).unwrap();
                    let t = Instant::now();
                    p.attach_named_decls(&decls);
                    total.push(t.elapsed());
                }
                median(total)
            },
            {
                let mut total = Vec::new();
                for _ in 0..iters {
                    let p = rtlint::front::load(f, Language::Wgsl).unwrap();
                    let t = Instant::now();
                    drop(p);
                    total.push(t.elapsed());
                }
                median(total)
            },
            time(iters, || {
                std::hint::black_box(rtlint::front::read_text(f).unwrap());
            }),
        ];
        for k in 0..8 {
            sums[k] += d[k];
        }
    }
    for (n, d) in names.iter().zip(sums) {
        println!("{n:>22} {:.3} ms", ms(d));
    }
}

/// The steps of `check_input` on WGSL, timed in turn within each run
/// (`SEQ=1`): the per-phase figures above each repeat one phase while it
/// is hot in the caches, so they sum to less than a check.
fn in_sequence(iters: usize, files: &[PathBuf], config: &Config) {
    let names = [
        "read the file",
        "naga parse+validate",
        "naga SPIR-V out (ours around it)",
        "declarations",
        "program::parse",
        "attach_named_decls",
        "rules",
        "drop",
    ];
    let mut sums = [Duration::ZERO; 8];
    let mut whole = Duration::ZERO;
    for f in files {
        let mut runs: Vec<[Duration; 8]> = Vec::new();
        for _ in 0..=iters {
            let mut d = [Duration::ZERO; 8];
            let mut t = Instant::now();
            let mut lap = |k: usize, d: &mut [Duration; 8]| {
                d[k] = t.elapsed();
                t = Instant::now();
            };
            let text = rtlint::front::read_text(f).unwrap();
            lap(0, &mut d);
            let (mut module, info) = rtlint::front::wgsl::parse(&text, f).unwrap();
            lap(1, &mut d);
            let words = rtlint::front::wgsl::write_spirv(&mut module, &info, &text, f).unwrap();
            lap(2, &mut d);
            let decls = rtlint::front::wgsl::declarations(&module, &text, f);
            drop((module, info, text));
            lap(3, &mut d);
            let mut p = rtlint::program::parse_owned(words, f, Language::Wgsl).unwrap();
            lap(4, &mut d);
            p.attach_named_decls(&decls);
            lap(5, &mut d);
            std::hint::black_box(rtlint::rules::check_program(&p, config));
            lap(6, &mut d);
            drop(p);
            lap(7, &mut d);
            runs.push(d);
        }
        // The first run is the warm-up.
        let runs = &runs[1..];
        for (k, sum) in sums.iter_mut().enumerate() {
            *sum += median(runs.iter().map(|r| r[k]).collect());
        }
        whole += median(runs.iter().map(|r| r.iter().sum()).collect());
    }
    for (n, d) in names.iter().zip(sums) {
        println!("{n:>33} {:.3} ms", ms(d));
    }
    println!(
        "{:>33} {:.3} ms (median of the runs' sums)",
        "one check",
        ms(whole)
    );
}
