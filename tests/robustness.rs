//! Mutation fuzzing of the parsers, run in every test pass: mutated SPIR-V and
//! WGSL must give a result or an input error, never a panic. (`fuzz/` holds the
//! cargo-fuzz targets for longer, coverage-guided runs.)

mod common;

use rtlint::config::Config;
use rtlint::shader::Language;
use std::path::Path;

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn seeds() -> Vec<Vec<u32>> {
    let mut out = Vec::new();
    for dir in ["fixtures/glsl", "fixtures/RT001", "fixtures/RT004"] {
        let mut files: Vec<_> = std::fs::read_dir(common::root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for p in files {
            if p.extension().is_some_and(|x| x == "spv") {
                out.push(common::read_words(&p));
            }
        }
    }
    let wgsl = common::root().join("shaders/reflect_iterative.wgsl");
    out.push(
        rtlint::front::wgsl::compile(&std::fs::read_to_string(&wgsl).unwrap(), &wgsl).unwrap(),
    );
    out
}

fn mutate_words(rng: &mut Rng, w: &mut Vec<u32>) {
    for _ in 0..1 + rng.below(4) {
        let i = 5 + rng.below(w.len().saturating_sub(5));
        match rng.below(6) {
            0 => w[i] ^= 1 << rng.below(32),
            1 => w[i] = rng.next() as u32,
            2 => w[i] = (w[i] & 0xffff_0000) | rng.below(0x1200) as u32,
            3 => w[i] = (rng.below(8) as u32) << 16 | (w[i] & 0xffff),
            4 => {
                let n = rng.below(w.len() - i).min(8);
                w.drain(i..i + n);
            }
            _ => w.truncate(i),
        }
        if w.len() <= 5 {
            break;
        }
    }
}

#[test]
fn mutated_spirv_never_panics() {
    let config = Config::default();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut rejected = 0;
    let mut accepted = 0;
    for seed in seeds() {
        for _ in 0..400 {
            let mut w = seed.clone();
            mutate_words(&mut rng, &mut w);
            let r = std::panic::catch_unwind(|| {
                match rtlint::program::parse(&w, Path::new("m.spv"), Language::Spirv) {
                    Ok(p) => {
                        let _ = rtlint::rules::check_program(&p, &config);
                        let _ = rtlint::report::layout::human(
                            &rtlint::analysis::layout::FileLayouts::new(&p),
                        );
                        true
                    }
                    Err(e) => {
                        assert!(!e.diagnostic().message.is_empty());
                        false
                    }
                }
            });
            match r {
                Ok(true) => accepted += 1,
                Ok(false) => rejected += 1,
                Err(_) => panic!(
                    "panic on mutated module (seed words {}): {:?}",
                    seed.len(),
                    &w[..w.len().min(64)]
                ),
            }
        }
    }
    // Both paths were exercised.
    assert!(
        rejected > 100 && accepted > 100,
        "rejected {rejected}, accepted {accepted}"
    );
}

#[test]
fn mutated_wgsl_never_panics() {
    let text =
        std::fs::read_to_string(common::root().join("shaders/reflect_iterative.wgsl")).unwrap();
    let bytes = text.as_bytes();
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let alphabet = b"{}()<>;:,.=+-*/&|!@ \n0123456789abcfnuvxyz_";
    for _ in 0..300 {
        let mut b = bytes.to_vec();
        for _ in 0..1 + rng.below(3) {
            let i = rng.below(b.len());
            match rng.below(3) {
                0 => {
                    b.remove(i);
                }
                1 => b.insert(i, alphabet[rng.below(alphabet.len())]),
                _ => b[i] = alphabet[rng.below(alphabet.len())],
            }
        }
        let Ok(src) = String::from_utf8(b) else {
            continue;
        };
        let r = std::panic::catch_unwind(|| {
            if let Ok(words) = rtlint::front::wgsl::compile(&src, Path::new("m.wgsl")) {
                let p = rtlint::program::parse(&words, Path::new("m.wgsl"), Language::Wgsl)
                    .expect("naga output parses");
                let _ = rtlint::rules::check_program(&p, &Config::default());
            }
        });
        assert!(r.is_ok(), "panic on mutated WGSL:\n{src}");
    }
}

/// WGSL nested as deep as the limits, in one folder run (inputs checked on
/// worker threads): an operator chain of the deepest accepted length
/// compiles, one level more is an error at its place, brackets past naga's
/// parser limit are an error at the deepest bracket, and a long flat list
/// is not mistaken for nesting. Before, 5,000 unary minuses in one file
/// overflowed a worker's stack and aborted the whole run.
#[test]
fn wgsl_nesting_is_handled_or_refused_at_its_place() {
    use rtlint::front::wgsl::MAX_EXPRESSION_DEPTH;
    let d = std::env::temp_dir().join(format!("rtlint-wgsl-nesting-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let head = "@compute @workgroup_size(1) fn main() { var x: f32 = ";
    // `=` is one level, each `-` one more.
    let minus = |n: usize| format!("{head}{}1.0; }}\n", "- ".repeat(n));
    std::fs::write(d.join("deepest.wgsl"), minus(MAX_EXPRESSION_DEPTH - 1)).unwrap();
    std::fs::write(d.join("too_deep.wgsl"), minus(MAX_EXPRESSION_DEPTH)).unwrap();
    std::fs::write(
        d.join("brackets.wgsl"),
        format!("{head}{}1.0{}; }}\n", "(".repeat(200), ")".repeat(200)),
    )
    .unwrap();
    let list: Vec<String> = (0..30_000).map(|i| format!("-{i}.5e-3")).collect();
    std::fs::write(
        d.join("flat.wgsl"),
        format!(
            "const T = array<f32, 30000>({});\n@compute @workgroup_size(1) fn main() {{ var x: f32 = T[3]; }}\n",
            list.join(", ")
        ),
    )
    .unwrap();
    let o = common::rtlint()
        .args(["check", "--no-cache", "--format", "concise"])
        .arg(&d)
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{out}");
    let errors: Vec<&str> = out.lines().filter(|l| l.contains("error")).collect();
    // Two errors, each at its place: at the operator that passes the limit
    // (the `=` is the first level), and at the deepest bracket, the 200th
    // (the first is in column 54).
    let col = head.len() + 2 * (MAX_EXPRESSION_DEPTH - 1) + 1;
    assert!(
        errors.iter().any(|l| l.contains(&format!("too_deep.wgsl:1:{col}"))
            && l.contains("nested too deep")),
        "{out}"
    );
    assert!(
        errors
            .iter()
            .any(|l| l.contains("brackets.wgsl:1:253") && l.contains("brackets nested too deep")),
        "{out}"
    );
    assert!(!out.contains("deepest.wgsl"), "{out}");
    assert!(!out.contains("flat.wgsl"), "{out}");
    assert!(out.contains("in 4 files"), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}
