//! The result cache, `--shard` and `--analysis`, through the CLI.

mod common;

use common::{root, rtlint};
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, SystemTime};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rtlint-cache-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A scratch folder holding the test shader and the header it includes.
fn shader_folder(name: &str) -> PathBuf {
    let d = scratch(name);
    std::fs::write(d.join("payload.hlsli"), PAYLOAD).unwrap();
    std::fs::write(d.join("gen.hlsl"), shader()).unwrap();
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

/// The cache's pack files (one per folder and scope).
fn packs(cache: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(cache.join("packs"))
        .map(|d| {
            d.map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// A pack's entries by slot name (an input's file name, or `group PATH`).
fn slots(pack: &Path) -> serde_json::Map<String, serde_json::Value> {
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(pack).unwrap()).unwrap();
    v["slots"].as_object().unwrap().clone()
}

/// Cache entries written so far (one per input, one per loose pipeline).
fn entries(cache: &Path) -> usize {
    packs(cache).iter().map(|p| slots(p).len()).sum()
}

/// Entries of inputs (not of loose pipelines).
fn input_entries(cache: &Path) -> usize {
    packs(cache)
        .iter()
        .map(|p| slots(p).keys().filter(|k| !k.starts_with("group ")).count())
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
    let d = shader_folder("stale");
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
    let o = rtlint()
        .current_dir(&d)
        .env_remove("RTLINT_CACHE_DIR")
        .args(["check", "--format", "concise", "--quiet", "."])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let ignore = std::fs::read_to_string(d.join(".rtlint_cache/.gitignore")).unwrap();
    assert!(ignore.lines().any(|l| l == "*"), "{ignore}");
}

/// Suppressions are judged the same on a warm run: in the input (read once
/// for its key there) and in a header, and an edit to either counts.
#[test]
fn suppressions_hold_on_a_warm_run() {
    let d = scratch("suppress");
    let fat =
        "// rtlint: allow(RT001)\nstruct Fat {\n    float4 a;\n    float4 b;\n    float4 c;\n};\n";
    std::fs::write(d.join("payload.hlsli"), fat).unwrap();
    let unused = format!("// rtlint: allow(RT002)\n{}", shader());
    std::fs::write(d.join("gen.hlsl"), &unused).unwrap();
    let cache = d.join("c");
    let run = || check(&d, &["--cache-dir", cache.to_str().unwrap(), "."]);
    let cold = run();
    let n = entries(&cache);
    let warm = run();
    assert_eq!(text(&warm), text(&cold));
    assert_eq!(entries(&cache), n, "a warm run wrote new entries");
    // The header's suppression allows RT001; the input's allows nothing.
    assert!(!text(&warm).contains("RT001"), "{}", text(&warm));
    assert!(
        text(&warm).contains("gen.hlsl:1:4: warning[RT000]"),
        "{}",
        text(&warm)
    );
    // Without the unused one in the input: nothing left.
    std::fs::write(d.join("gen.hlsl"), shader()).unwrap();
    let o = run();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(!text(&o).contains("RT0"), "{}", text(&o));
    // Without the header's: RT001 comes back (the header is a dependency
    // of the input's entry, so the input is analysed again).
    std::fs::write(
        d.join("payload.hlsli"),
        fat.replace("// rtlint: allow(RT001)\n", ""),
    )
    .unwrap();
    let o = run();
    assert!(
        text(&o).contains("payload.hlsli:1:8: warning[RT001]"),
        "{}",
        text(&o)
    );
}

fn set_age(path: &Path, days: u64) {
    let t = SystemTime::now() - Duration::from_secs(days * 24 * 60 * 60);
    std::fs::File::options()
        .write(true)
        .open(path)
        .unwrap()
        .set_modified(t)
        .unwrap();
}

fn age_days(path: &Path) -> u64 {
    let m = std::fs::metadata(path).unwrap().modified().unwrap();
    SystemTime::now().duration_since(m).unwrap().as_secs() / (24 * 60 * 60)
}

/// Entries unused for 30 days go, once a day; a hit counts as a use, so
/// what this run (or another shard) used stays.
#[test]
fn old_unused_entries_are_pruned_and_used_ones_kept() {
    let d = shader_folder("prune");
    let cache = d.join("c");
    let args = ["--cache-dir", cache.to_str().unwrap(), "."];
    let cold = check(&d, &args);
    // One pack for the input, one for its loose pipeline.
    let used = packs(&cache);
    assert_eq!(used.len(), 2, "{used:?}");
    // A pack of a folder long gone, a temporary file of a run that died, and
    // the used packs made old as well.
    let stale = cache.join("packs/00000000000000000000000000000000.json");
    let tmp = cache.join("packs/00000000000000000000000000000001.4242.ThreadId(2).tmp");
    std::fs::copy(&used[0], &stale).unwrap();
    std::fs::write(&tmp, "{").unwrap();
    for p in [&stale, &tmp, &used[0], &used[1]] {
        set_age(p, 40);
    }
    // Pruned less than a day ago: nothing goes yet.
    assert_eq!(text(&check(&d, &args)), text(&cold));
    assert!(stale.exists() && tmp.exists());
    for p in &used {
        assert_eq!(age_days(p), 0, "a read did not refresh {}", p.display());
    }
    for p in &used {
        set_age(p, 40);
    }
    set_age(&cache.join("last-prune"), 2);
    let warm = check(&d, &args);
    assert_eq!(text(&warm), text(&cold));
    assert!(!stale.exists(), "an unused old pack is left");
    assert!(!tmp.exists(), "a dead run's temporary file is left");
    assert_eq!(age_days(&cache.join("last-prune")), 0);
}

/// An entry whose input is gone leaves its pack when the pack is written
/// again; the other inputs' entries stay.
#[test]
fn entries_of_deleted_inputs_leave_their_pack() {
    let d = shader_folder("gone");
    std::fs::write(d.join("other.hlsl"), shader().replace("Gen", "Other")).unwrap();
    let cache = d.join("c");
    let args = ["--cache-dir", cache.to_str().unwrap(), "."];
    check(&d, &args);
    assert_eq!(input_entries(&cache), 2);
    std::fs::remove_file(d.join("other.hlsl")).unwrap();
    // A run over one file keeps its folder's other entries.
    std::fs::write(d.join("third.hlsl"), shader().replace("Gen", "Third")).unwrap();
    check(&d, &["--cache-dir", cache.to_str().unwrap(), "third.hlsl"]);
    let names: Vec<String> = packs(&cache)
        .iter()
        .flat_map(|p| slots(p).keys().cloned().collect::<Vec<_>>())
        .filter(|k| !k.starts_with("group "))
        .collect();
    assert!(names.contains(&"gen.hlsl".to_string()), "{names:?}");
    assert!(names.contains(&"third.hlsl".to_string()), "{names:?}");
    assert!(!names.contains(&"other.hlsl".to_string()), "{names:?}");
}

/// A pack that is not what rtlint wrote (cut short, or garbage) is a miss:
/// the run answers as without the cache and writes the pack again.
#[test]
fn a_damaged_pack_is_a_miss() {
    let d = shader_folder("damaged");
    let cache = d.join("c");
    let args = ["--cache-dir", cache.to_str().unwrap(), "."];
    let uncached = check(&d, &["--no-cache", "."]);
    check(&d, &args);
    let n = entries(&cache);
    for (k, pack) in packs(&cache).iter().enumerate() {
        let bytes = std::fs::read(pack).unwrap();
        let damaged = if k % 2 == 0 {
            bytes[..bytes.len() / 2].to_vec()
        } else {
            b"\x00\xffnot json".to_vec()
        };
        std::fs::write(pack, damaged).unwrap();
    }
    let o = check(&d, &args);
    assert_eq!(o.status.code(), uncached.status.code(), "{}", text(&o));
    assert_eq!(text(&o), text(&uncached));
    assert_eq!(
        entries(&cache),
        n,
        "the damaged packs were not written again"
    );
}

/// A GLSL input's key holds what `glslangValidator --version` says: another
/// glslang misses the cache. (Other languages never run it.)
#[test]
fn another_glslang_misses_the_cache() {
    if !rtlint_testkit::tool("glslangValidator") {
        return;
    }
    let d = scratch("glslang");
    std::fs::copy(
        root().join("fixtures/RT034/good.rchit"),
        d.join("hit.rchit"),
    )
    .unwrap();
    // A glslang that says the version it is told and compiles as the real one.
    let fake = d.join("glslang.sh");
    std::fs::write(
        &fake,
        "#!/bin/sh\nif [ \"$1\" = --version ]; then echo \"Glslang Version: $FAKE_GLSLANG\"; exit 0; fi\nexec glslangValidator \"$@\"\n",
    )
    .unwrap();
    std::process::Command::new("chmod")
        .arg("+x")
        .arg(&fake)
        .status()
        .unwrap();
    let cache = d.join("c");
    let run = |version: &str| {
        let o = rtlint()
            .current_dir(&d)
            .env("RTLINT_GLSLANG", &fake)
            .env("FAKE_GLSLANG", version)
            .args(["check", "--format", "concise", "--quiet", "--cache-dir"])
            .arg(&cache)
            .arg(".")
            .output()
            .unwrap();
        assert_ne!(o.status.code(), Some(2), "{}", text(&o));
        input_entries(&cache)
    };
    assert_eq!(run("11:12.0.0"), 1);
    assert_eq!(run("11:12.0.0"), 1, "the same glslang reads its entry");
    assert_eq!(
        run("11:15.1.0"),
        2,
        "another glslang wrote no entry of its own"
    );
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
    // Forget one input's entry and the pipeline's: the input is compiled
    // again, the others are not.
    for pack in packs(&cache) {
        let mut kept = slots(&pack);
        let first_input = kept.keys().find(|k| !k.starts_with("group ")).cloned();
        kept.retain(|k, _| !k.starts_with("group ") && Some(k) != first_input.as_ref());
        let v = serde_json::json!({ "slots": kept });
        std::fs::write(&pack, serde_json::to_vec(&v).unwrap()).unwrap();
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
    // Fast never needs a pipeline's recursion or stack analysis: a fast
    // pipeline rule over its fixtures' descriptions leaves both uncomputed.
    let mut fast_pipeline_findings = 0;
    for r in RULES {
        let (AnalysisLevel::Fast, Kind::Pipeline(run)) = (r.analysis, r.kind) else {
            continue;
        };
        let dir = root().join("fixtures").join(r.code);
        for e in std::fs::read_dir(&dir).unwrap() {
            let path = e.unwrap().path();
            if !path.to_string_lossy().ends_with(".pipeline.toml") {
                continue;
            }
            let pipeline = rtlint::pipeline::load(&path).unwrap();
            let config = rtlint::config::Config::default();
            let ctx = rtlint::rules::PipelineContext::new(&pipeline, &config);
            fast_pipeline_findings += run(&ctx).len();
            assert!(
                !ctx.recursion.is_computed() && !ctx.stack.is_computed(),
                "{} is fast but analysed {}",
                r.code,
                path.display()
            );
        }
    }
    assert!(
        fast_pipeline_findings > 0,
        "no fast pipeline rule found anything"
    );
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

/// A project with one folder on a four-shard CI matrix: the shards without
/// files succeed, also under `--deny-warnings`; paths with nothing to lint
/// still fail it.
#[test]
fn an_empty_shard_of_a_non_empty_set_succeeds() {
    let d = scratch("empty-shard");
    std::fs::create_dir_all(d.join("s")).unwrap();
    std::fs::write(
        d.join("s/gen.rgen"),
        "#version 460\n#extension GL_EXT_ray_tracing : require\nvoid main() {}\n",
    )
    .unwrap();
    std::fs::create_dir_all(d.join("nothing")).unwrap();
    let mut empty = 0;
    for k in 1..=4 {
        let shard = format!("{k}/4");
        let o = rtlint()
            .current_dir(&d)
            .args([
                "check",
                "--no-cache",
                "--deny-warnings",
                "--shard",
                &shard,
                "s",
            ])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{shard}: {}", text(&o));
        if text(&o).contains("this shard got none of the 1 input;") {
            empty += 1;
        }
    }
    assert_eq!(empty, 3);
    let o = check(
        &d,
        &["--no-cache", "--deny-warnings", "--shard", "2/4", "nothing"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("no files to lint"), "{}", text(&o));
}

/// A folder whose description names GLSL shaders: cold, glslang compiles
/// each shader once (it was three times: as an input, to find what the
/// description names, for the pipeline); warm, not at all; editing the
/// shared header compiles both again. Counted through a wrapper named by
/// RTLINT_GLSLANG.
#[test]
fn compiled_glsl_is_cached_by_content_and_includes() {
    if std::process::Command::new("glslangValidator")
        .arg("--version")
        .output()
        .is_err()
    {
        rtlint_testkit::require("glslangValidator", Err::<(), _>("not on PATH"));
        return;
    }
    let d = scratch("glsl-modules");
    let s = d.join("s");
    std::fs::create_dir_all(&s).unwrap();
    std::fs::write(
        s.join("payload.glsl"),
        "struct Payload {\n    vec4 color;\n};\n",
    )
    .unwrap();
    let head = "#version 460\n#extension GL_EXT_ray_tracing : require\n#extension GL_GOOGLE_include_directive : require\n#include \"payload.glsl\"\n";
    std::fs::write(
        s.join("raytrace.rgen"),
        format!("{head}layout(location = 0) rayPayloadEXT Payload p;\nlayout(binding = 0) uniform accelerationStructureEXT tlas;\nlayout(binding = 1, rgba8) uniform image2D img;\nvoid main() {{\n    traceRayEXT(tlas, 0, 0xFF, 0, 1, 0, vec3(0.0), 0.001, vec3(0.0, 0.0, 1.0), 100.0, 0);\n    imageStore(img, ivec2(gl_LaunchIDEXT.xy), p.color);\n}}\n"),
    )
    .unwrap();
    std::fs::write(
        s.join("raytrace.rmiss"),
        format!("{head}layout(location = 0) rayPayloadInEXT Payload p;\nvoid main() {{ p.color = vec4(1.0); }}\n"),
    )
    .unwrap();
    std::fs::write(
        s.join("scene.pipeline.toml"),
        "max_recursion_depth = 1\n\n[[raygen]]\nfile = \"raytrace.rgen\"\nentry = \"main\"\n\n[[miss]]\nfile = \"raytrace.rmiss\"\nentry = \"main\"\n",
    )
    .unwrap();
    let log = d.join("calls.log");
    let wrapper = d.join("glslang.sh");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\ncase \"$1\" in --version) ;; *) echo \"$*\" >> '{}' ;; esac\nexec glslangValidator \"$@\"\n",
            log.display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    let calls = || {
        std::fs::read_to_string(&log)
            .unwrap_or_default()
            .lines()
            .count()
    };
    let run = || {
        let o = rtlint()
            .current_dir(&d)
            .args(["check", "--format", "concise", "--cache-dir", "c", "s"])
            .env("RTLINT_GLSLANG", &wrapper)
            .output()
            .unwrap();
        assert_ne!(o.status.code(), Some(2), "{}", text(&o));
        sorted_lines(&o)
    };
    let cold = run();
    assert_eq!(calls(), 2, "cold: each shader once");
    let warm = run();
    assert_eq!(calls(), 2, "warm: glslang not run");
    assert_eq!(cold, warm);
    std::fs::write(
        s.join("payload.glsl"),
        "struct Payload {\n    vec4 color;\n    vec4 extra;\n};\n",
    )
    .unwrap();
    run();
    assert_eq!(calls(), 4, "the header changed: both again");
}
