//! The result cache, `--shard` and `--analysis`, through the CLI.

mod common;

use common::{root, rtlint};
use std::path::{Path, PathBuf};
use std::process::Output;

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-cache-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
}

fn check(dir: &Path, args: &[&str]) -> Output {
    let mut c = rtlint();
    c.current_dir(dir)
        .args(["check", "--format", "concise", "--quiet"])
        .args(args);
    c.output().unwrap()
}

/// Cache entries written so far (one per input, one per loose pipeline).
fn entries(cache: &Path) -> usize {
    ["files", "groups"]
        .iter()
        .map(|k| {
            std::fs::read_dir(cache.join(k))
                .map(|d| d.count())
                .unwrap_or(0)
        })
        .sum()
}

const PAYLOAD: &str = "struct Fat {\n    float4 a;\n    float4 b;\n};\n";

fn shader() -> String {
    "#include \"payload.hlsli\"\nRaytracingAccelerationStructure tlas : register(t0);\nRWTexture2D<float4> image : register(u1);\n[shader(\"raygeneration\")]\nvoid Gen()\n{\n    RayDesc ray;\n    ray.Origin = float3(0.0, 0.0, 0.0);\n    ray.Direction = float3(0.0, 0.0, 1.0);\n    ray.TMin = 0.001;\n    ray.TMax = 10.0;\n    Fat p = (Fat)0;\n    TraceRay(tlas, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 1, 0, ray, p);\n    image[DispatchRaysIndex().xy] = p.a;\n}\n".to_string()
}

/// A warm run answers as the cold one; editing an included file, the config
/// or the command line's rule options invalidates what they touch.
#[test]
fn the_cache_is_never_stale() {
    let d = scratch("stale");
    std::fs::write(d.join("payload.hlsli"), PAYLOAD).unwrap();
    std::fs::write(d.join("gen.hlsl"), shader()).unwrap();
    let cache = d.join("c");
    let cache_arg = ["--cache-dir", cache.to_str().unwrap()];
    let run = |extra: &[&str]| {
        let mut args: Vec<&str> = cache_arg.to_vec();
        args.extend_from_slice(extra);
        args.push(".");
        check(&d, &args)
    };
    // 32 bytes: within the default budget.
    let cold = run(&[]);
    assert_eq!(cold.status.code(), Some(0), "{}", text(&cold));
    assert!(entries(&cache) > 0, "no cache entries written");
    let n = entries(&cache);
    let warm = run(&[]);
    assert_eq!(text(&warm), text(&cold));
    assert_eq!(entries(&cache), n, "a warm run wrote new entries");
    // The header grows to 48 bytes: RT001 now.
    std::fs::write(
        d.join("payload.hlsli"),
        "struct Fat {\n    float4 a;\n    float4 b;\n    float4 c;\n};\n",
    )
    .unwrap();
    let o = run(&[]);
    assert!(
        text(&o).contains("payload.hlsli:1:8: warning[RT001]"),
        "{}",
        text(&o)
    );
    // The config raises the budget: clean again.
    std::fs::write(d.join("rtlint.toml"), "[rules.RT001]\nbudget = 64\n").unwrap();
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(!text(&o).contains("RT001"), "{}", text(&o));
    // The command line lowers it again.
    let o = run(&["--payload-budget", "16"]);
    assert!(text(&o).contains("RT001"), "{}", text(&o));
    // Without the cache: the same answers, nothing written.
    let uncached = scratch("stale-uncached");
    let before = entries(&cache);
    let o = check(&d, &["--no-cache", "--payload-budget", "16", "."]);
    assert!(text(&o).contains("RT001"), "{}", text(&o));
    assert_eq!(entries(&cache), before);
    assert!(!uncached.join(".rtlint_cache").exists());
    // The default folder is in the working directory and ignores itself.
    let o = check(&d, &["."]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let ignore = std::fs::read_to_string(d.join(".rtlint_cache/.gitignore")).unwrap();
    assert!(ignore.lines().any(|l| l == "*"), "{ignore}");
}

/// A shader without a cache entry whose folder's other shaders are cached:
/// the loose pipeline rules still see the whole folder.
#[test]
fn a_partly_cached_folder_still_forms_one_pipeline() {
    let d = scratch("partial");
    let src = root().join("fixtures/pipelines/recursive");
    for e in std::fs::read_dir(&src).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "spv") {
            std::fs::copy(&p, d.join(p.file_name().unwrap())).unwrap();
        }
    }
    let whole = check(&d, &["--no-cache", "."]);
    assert!(!whole.stdout.is_empty(), "{}", text(&whole));
    let cache = d.join("c");
    let args = ["--cache-dir", cache.to_str().unwrap(), "."];
    assert_eq!(text(&check(&d, &args)), text(&whole));
    // Forget one input's entry: it is compiled again, the others are not.
    let first = std::fs::read_dir(cache.join("files"))
        .unwrap()
        .next()
        .unwrap()
        .unwrap()
        .path();
    std::fs::remove_file(first).unwrap();
    for e in std::fs::read_dir(cache.join("groups")).unwrap() {
        std::fs::remove_file(e.unwrap().path()).unwrap();
    }
    assert_eq!(text(&check(&d, &args)), text(&whole));
    assert_eq!(text(&check(&d, &args)), text(&whole));
}

fn sorted_lines(o: &Output) -> Vec<String> {
    let mut v: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    v.sort();
    v
}

/// The union of the shards is the whole run, byte for byte after sorting;
/// every file is in exactly one shard.
#[test]
fn shards_add_up_to_the_whole_run() {
    let paths = [
        "shaders",
        "fixtures/pipelines",
        "fixtures/RT000",
        "fixtures/RT003",
        "fixtures/RT020",
        "fixtures/RT041",
        "fixtures/RT006",
        // Missing: reported once, by the first shard.
        "fixtures/no-such-folder",
    ];
    let run = |extra: &[&str]| {
        let mut args = vec!["--no-cache"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&paths);
        check(&root(), &args)
    };
    let whole = run(&[]);
    assert!(whole.stdout.len() > 100, "{}", text(&whole));
    let n = 3;
    let mut union = Vec::new();
    let mut counted = 0usize;
    for k in 1..=n {
        let shard = format!("{k}/{n}");
        let o = run(&["--shard", &shard]);
        union.extend(sorted_lines(&o));
        // The summary line (not quiet) says how many files the shard read.
        let mut c = rtlint();
        c.args([
            "check",
            "--no-cache",
            "--format",
            "concise",
            "--shard",
            &shard,
        ])
        .args(paths);
        let s = text(&c.output().unwrap());
        let line = s.lines().last().unwrap_or_default().to_string();
        let read: usize = line
            .split(" in ")
            .nth(1)
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no file count in `{line}`"));
        counted += read;
    }
    union.sort();
    assert_eq!(union, sorted_lines(&whole));
    let mut c = rtlint();
    c.args(["check", "--no-cache", "--format", "concise"])
        .args(paths);
    let s = text(&c.output().unwrap());
    let line = s.lines().last().unwrap().to_string();
    assert!(line.contains(&format!(" in {counted} files")), "{line}");
    // Not a shard.
    for bad in ["0/3", "4/3", "1", "a/b"] {
        let o = check(&root(), &["--shard", bad, "shaders"]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", text(&o));
    }
}

/// `--analysis fast` runs only the rules that say they need no dataflow; the
/// config's `analysis` key does the same, and the flag wins over it.
#[test]
fn fast_analysis_leaves_out_the_dataflow_rules() {
    use rtlint::config::AnalysisLevel;
    use rtlint::rules::{Kind, RULES};
    // Fast never needs a pipeline's recursion or stack analysis.
    for r in RULES {
        if r.analysis == AnalysisLevel::Fast {
            assert!(
                !matches!(r.kind, Kind::Pipeline(_)),
                "{} is fast but a pipeline rule",
                r.code
            );
        }
    }
    let full = check(
        &root(),
        &["--no-cache", "--select", "RT010", "fixtures/RT010"],
    );
    assert!(text(&full).contains("[RT010]"), "{}", text(&full));
    let fast = check(
        &root(),
        &[
            "--no-cache",
            "--select",
            "RT010",
            "--analysis",
            "fast",
            "fixtures/RT010",
        ],
    );
    assert!(!text(&fast).contains("[RT010]"), "{}", text(&fast));
    // The config says fast; the command line says full.
    let d = scratch("fast");
    std::fs::copy(
        root().join("fixtures/RT010/bad.rgen.spv"),
        d.join("bad.rgen.spv"),
    )
    .unwrap();
    std::fs::write(d.join("rtlint.toml"), "analysis = \"fast\"\n").unwrap();
    let o = check(&d, &["--no-cache", "--select", "RT010", "."]);
    assert!(!text(&o).contains("[RT010]"), "{}", text(&o));
    let o = check(
        &d,
        &["--no-cache", "--select", "RT010", "--analysis", "full", "."],
    );
    assert!(text(&o).contains("[RT010]"), "{}", text(&o));
    std::fs::write(d.join("rtlint.toml"), "analysis = \"quick\"\n").unwrap();
    let o = check(&d, &["--no-cache", "."]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("rtlint.toml:1"), "{}", text(&o));
}
