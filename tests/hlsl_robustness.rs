//! A quick in-tree stand-in for the fuzzers (which need nightly): random and
//! mutated inputs through preprocess, parse and the whole compiler must give
//! `Ok` or an error, never a panic.

use rtlint::front::hlsl::{compile_source_whole, parse_source, pp::MemLoader, HlslOptions};
use std::path::{Path, PathBuf};

/// xorshift64*: deterministic, so a failure reproduces from its seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const PIECES: &[&str] = &[
    "(",
    ")",
    "{",
    "}",
    "[",
    "]",
    ";",
    ",",
    ".",
    "#",
    "##",
    "\n#define A(x) x##x\n",
    "\n#if 1\n",
    "\n#endif\n",
    "\n#include \"common.hlsli\"\n",
    "\n#include \"main.hlsl\"\n",
    "\n#else\n",
    "float3",
    "RayDesc",
    "TraceRay",
    "struct",
    "return",
    "for (;;)",
    "if",
    "else",
    "switch",
    "case 1:",
    "break;",
    "x.xyzw",
    "1e9",
    "0x",
    "\"",
    "/*",
    "*/",
    "//",
    "\\\n",
    "__VA_ARGS__",
    "...",
    "<",
    ">",
    ">>=",
    "?",
    ":",
    "::",
    "=",
    "++",
    "inout",
    "[shader(\"miss\")]",
    "[numthreads(1,1,1)]",
    "RayQuery<0>",
    "cbuffer",
    "register(b0)",
    "mul(",
    "_m00",
    "static const",
    "[]",
    "-",
    "!",
    "~",
    "out",
    "void",
    "uint",
    "\u{e9}",
];

fn shaders() -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl");
    let mut out: Vec<(String, String)> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            let name = p.file_name()?.to_str()?.to_string();
            Some((name, std::fs::read_to_string(&p).ok()?))
        })
        .collect();
    out.sort();
    out
}

fn mutate(rng: &mut Rng, src: &str) -> String {
    let mut s: Vec<char> = src.chars().collect();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(s.len() + 1);
        match rng.below(4) {
            0 if !s.is_empty() => {
                let end = (at + rng.below(40)).min(s.len());
                s.drain(at.min(end)..end);
            }
            1 => {
                let piece = PIECES[rng.below(PIECES.len())];
                for (k, c) in piece.chars().enumerate() {
                    s.insert(at + k, c);
                }
            }
            2 if !s.is_empty() => {
                let from = rng.below(s.len());
                let end = (from + rng.below(60)).min(s.len());
                let chunk: Vec<char> = s[from..end].to_vec();
                for (k, c) in chunk.into_iter().enumerate() {
                    s.insert(at.min(s.len()) + k, c);
                }
            }
            _ => {
                let b = (rng.next() % 95 + 32) as u8 as char;
                s.insert(at, b);
            }
        }
    }
    s.into_iter().collect()
}

/// The 16-bit shaders are written for -enable-16bit-types (and mutated under it).
fn options_for(name: &str) -> HlslOptions {
    HlslOptions {
        enable_16bit_types: name.ends_with("half.hlsl"),
        ..Default::default()
    }
}

fn run(name: &str, text: &str, files: &[(String, String)]) {
    let mut loader = MemLoader(
        files
            .iter()
            .map(|(n, t)| (PathBuf::from(n), t.clone()))
            .chain([(PathBuf::from(name), text.to_string())])
            .collect(),
    );
    let opts = options_for(name);
    let _ = parse_source(Path::new(name), text, &mut loader, &opts);
    let _ = compile_source_whole(Path::new(name), text, &mut loader, &opts);
}

#[test]
fn mutated_shaders_never_panic() {
    // Shaders using SPIR-V newer than Debian's validator knows need a newer
    // one (`rtlint_testkit::new_spirv_val`); without it they are left out here.
    let validator = rtlint_testkit::new_spirv_val().ok();
    let files: Vec<_> = shaders()
        .into_iter()
        .filter(|(n, _)| {
            validator.is_some()
                || !["position_fetch.hlsl", "ser.hlsl"]
                    .iter()
                    .any(|x| n.ends_with(x))
        })
        .collect();
    let iterations: usize = std::env::var("RTLINT_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100);
    for (i, (name, text)) in files.iter().enumerate() {
        for k in 0..iterations {
            let seed = 0x9E37_79B9_7F4A_7C15 ^ ((i as u64) << 32 | k as u64);
            let mut rng = Rng(seed | 1);
            let input = mutate(&mut rng, text);
            let r = std::panic::catch_unwind(|| run(name, &input, &files));
            assert!(
                r.is_ok(),
                "panic on mutation seed {seed:#x} of {name}:\n{input}"
            );
        }
    }
}

#[test]
fn random_token_soup_never_panics() {
    let files = shaders();
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    for _ in 0..2000 {
        let mut s = String::new();
        for _ in 0..rng.below(60) {
            s.push_str(PIECES[rng.below(PIECES.len())]);
            s.push(' ');
        }
        let r = std::panic::catch_unwind(|| run("main.hlsl", &s, &files));
        assert!(r.is_ok(), "panic on:\n{s}");
    }
}

#[test]
fn deep_nesting_and_macro_bombs_end_in_errors() {
    let files = shaders();
    let deep = format!(
        "[numthreads(1,1,1)] void m() {{ float x = {}1{}; }}",
        "(".repeat(5000),
        ")".repeat(5000)
    );
    run("main.hlsl", &deep, &files);
    let blocks = format!(
        "[numthreads(1,1,1)] void m() {}{}",
        "{".repeat(5000),
        "}".repeat(5000)
    );
    run("main.hlsl", &blocks, &files);
    // Each level doubles the expansion: the budget stops it.
    let mut bomb = String::from("#define A0 x\n");
    for i in 1..40 {
        bomb.push_str(&format!("#define A{i} A{p} A{p}\n", p = i - 1));
    }
    bomb.push_str("A39\n");
    let mut loader = MemLoader::default();
    let e = parse_source(
        Path::new("b.hlsl"),
        &bomb,
        &mut loader,
        &HlslOptions::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("macro expansion does not terminate"),
        "{e}"
    );
}

/// Mutated shaders the compiler accepts must give valid SPIR-V: an accepted
/// input never becomes an invalid module. Needs spirv-val (the skip policy
/// of `rtlint_testkit::require`).
#[test]
fn accepted_mutations_validate() {
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    // Shaders using SPIR-V newer than Debian's validator knows need a newer
    // one (`rtlint_testkit::new_spirv_val`); without it they are left out here.
    let validator = rtlint_testkit::new_spirv_val().ok();
    let files: Vec<_> = shaders()
        .into_iter()
        .filter(|(n, _)| {
            validator.is_some()
                || !["position_fetch.hlsl", "ser.hlsl"]
                    .iter()
                    .any(|x| n.ends_with(x))
        })
        .collect();
    let iterations: usize = std::env::var("RTLINT_FUZZ_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(100)
        / 4;
    let dir = std::env::temp_dir().join(format!("rtlint-mut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut checked = 0;
    for (i, (name, text)) in files.iter().enumerate() {
        for k in 0..iterations {
            let seed = 0xA076_1D64_78BD_642F ^ ((i as u64) << 32 | k as u64);
            let mut rng = Rng(seed | 1);
            let input = mutate(&mut rng, text);
            let mut loader = MemLoader(
                files
                    .iter()
                    .map(|(n, t)| (PathBuf::from(n), t.clone()))
                    .collect(),
            );
            let Ok(m) =
                compile_source_whole(Path::new(name), &input, &mut loader, &options_for(name))
            else {
                continue;
            };
            let file = dir.join("m.spv");
            let bytes: Vec<u8> = m.words.iter().flat_map(|w| w.to_le_bytes()).collect();
            std::fs::write(&file, bytes).unwrap();
            let out = std::process::Command::new(validator.as_deref().unwrap_or("spirv-val"))
                .args(["--target-env", "vulkan1.2", "--scalar-block-layout"])
                .arg(&file)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "seed {seed:#x} of {name} compiled to invalid SPIR-V: {}\n{input}",
                String::from_utf8_lossy(&out.stderr)
            );
            checked += 1;
        }
    }
    eprintln!("{checked} accepted mutations validated");
    assert!(checked > 0);
}

/// Compiles one shader alone: `Ok` or the error's text.
fn compile_alone(text: &str) -> Result<(), String> {
    let mut loader = MemLoader::default();
    compile_source_whole(
        Path::new("main.hlsl"),
        text,
        &mut loader,
        &HlslOptions::default(),
    )
    .map(|_| ())
    .map_err(|e| e.to_string())
}

/// DXC (clang) accepts 256 nested brackets: so does rtlint, and twice that,
/// in every nesting shape, on the compiler thread's stack in a debug build;
/// deeper ends in an error naming the position.
#[test]
fn nesting_as_deep_as_dxc_accepts_compiles() {
    let shader = |body: String| {
        format!("RWStructuredBuffer<float> o : register(u0);\n[numthreads(1,1,1)] void m() {{ float x = 1.0; {body} o[0] = x; }}\n")
    };
    let parens = |n: usize| shader(format!("x = {}x{};", "(".repeat(n), ")".repeat(n)));
    for n in [48, 256, 500] {
        assert_eq!(compile_alone(&parens(n)), Ok(()), "{n} parentheses");
    }
    let e = compile_alone(&parens(600)).unwrap_err();
    assert!(e.contains("nesting too deep"), "{e}");
    let shapes = [
        (
            "blocks",
            shader(format!("{}x += 1.0;{}", "{".repeat(500), "}".repeat(500))),
        ),
        (
            "ifs",
            shader(format!(
                "{}x += 1.0;{}",
                "if (x > 0.0) { ".repeat(300),
                "}".repeat(300)
            )),
        ),
        ("negations", shader(format!("x = {}x;", "- ".repeat(500)))),
        (
            "ternaries",
            shader(format!(
                "x = {}x{};",
                "x > 0.0 ? (".repeat(250),
                ") : x".repeat(250)
            )),
        ),
        (
            "calls",
            shader(format!("x = {}x{};", "abs(".repeat(256), ")".repeat(256))),
        ),
        ("sum", shader(format!("x = x{};", " + x".repeat(1000)))),
    ];
    for (name, text) in shapes {
        assert_eq!(compile_alone(&text), Ok(()), "{name}");
    }
    // A longer chain is a tree as deep: an error, not a stack overflow.
    let e = compile_alone(&shader(format!("x = x{};", " + x".repeat(20_000)))).unwrap_err();
    assert!(e.contains("nesting too deep"), "{e}");
}
