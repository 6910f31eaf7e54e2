//! `rtlint stack` and `rtlint live` from the command line: every bundled and
//! test pipeline, with and without `--driver` (lavapipe here; the test fails
//! without a ray-tracing device), JSON contracts, and bad descriptions.

mod common;

use common::rtlint;
use std::path::PathBuf;

fn pipelines() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in ["shaders", "fixtures/pipelines", "calibration"] {
        let mut d: Vec<PathBuf> = std::fs::read_dir(common::root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| rtlint::lint::is_pipeline(p))
            .collect();
        d.sort();
        out.extend(d);
    }
    assert!(out.len() >= 30, "{out:?}");
    out
}

fn json(args: &[&str]) -> serde_json::Value {
    let o = rtlint().args(args).output().unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn stack_on_every_pipeline_with_and_without_the_driver() {
    let mut args: Vec<String> = vec![
        "stack".into(),
        "--driver".into(),
        "--format".into(),
        "json".into(),
    ];
    args.extend(pipelines().iter().map(|p| p.to_string_lossy().into_owned()));
    let with: Vec<&str> = args.iter().map(String::as_str).collect();
    let out = json(&with);
    assert_eq!(out["version"], 1);
    let reports = out["pipelines"]
        .as_array()
        .expect("one report per pipeline");
    assert_eq!(reports.len(), pipelines().len());
    let without: Vec<&str> = with.iter().copied().filter(|a| *a != "--driver").collect();
    let models = json(&without);
    for (r, m) in reports.iter().zip(models["pipelines"].as_array().unwrap()) {
        for key in [
            "required_depth",
            "declared_depth",
            "shaders",
            "vulkan_default",
            "dxr_default",
            "exact_call_chain",
            "recommended",
        ] {
            assert!(r.get(key).is_some(), "missing {key}");
        }
        // The model does not depend on the device.
        assert_eq!(
            r["shaders"].as_array().unwrap().len(),
            m["shaders"].as_array().unwrap().len()
        );
        for (s, t) in r["shaders"]
            .as_array()
            .unwrap()
            .iter()
            .zip(m["shaders"].as_array().unwrap())
        {
            for key in ["entry", "stage", "file", "model_bytes"] {
                assert!(s.get(key).is_some(), "missing shaders[].{key}");
            }
            assert_eq!(s["model_bytes"], t["model_bytes"]);
            assert!(t["driver_bytes"].is_null());
            // lavapipe inlines the whole pipeline and answers 4 for every
            // group and stage (FIELD-NOTES); a real driver answers per shader.
            let d = s["driver_bytes"]
                .as_u64()
                .expect("driver figure with --driver");
            if r["assumptions"].to_string().contains("llvmpipe") {
                assert_eq!(d, 4, "{}", r["pipeline"]);
            }
        }
        assert!(
            r["driver"].is_object(),
            "formulas from the driver's numbers"
        );
    }
}

#[test]
fn stack_numbers_for_the_reference_pipeline() {
    let out = json(&[
        "stack",
        "--format",
        "json",
        "shaders/reflect_iterative.pipeline.toml",
    ]);
    // One shape whatever the number of inputs.
    let r = &out["pipelines"][0];
    assert_eq!(out["pipelines"].as_array().unwrap().len(), 1);
    assert_eq!(r["required_depth"], 1);
    assert_eq!(r["declared_depth"], 1);
    let stages: Vec<(&str, u64)> = r["shaders"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            (
                s["stage"].as_str().unwrap(),
                s["driver_model_bytes"].as_u64().unwrap(),
            )
        })
        .collect();
    // As an NVIDIA H200 reported: raygen 64 (the bounce loop carries 60
    // bytes across the trace), miss 0, closest-hit 0 (it does not trace).
    assert_eq!(
        stages,
        [("ray_generation", 64), ("miss", 0), ("closest_hit", 0)]
    );
    let o = rtlint()
        .args(["stack", "shaders/reflect_iterative.pipeline.toml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("recommended: vkCmdSetRayTracingPipelineStackSizeKHR(cmd, "),
        "{text}"
    );
}

#[test]
fn live_report_keys_and_numbers() {
    let r = json(&["live", "--format", "json", "fixtures/live/seed.rchit.spv"]);
    let site = &r["sites"][0];
    for key in [
        "path",
        "line",
        "entry",
        "stage",
        "kind",
        "live_bytes",
        "rematerializable_bytes",
        "values",
    ] {
        assert!(site.get(key).is_some(), "missing sites[].{key}");
    }
    assert_eq!(site["kind"], "trace_ray");
    assert_eq!(site["live_bytes"], 24);
    let mut names: Vec<&str> = site["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["name"].as_str().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["directLight", "throughput"]);
    for v in site["values"].as_array().unwrap() {
        for key in [
            "name",
            "ty",
            "size",
            "rematerializable",
            "def_line",
            "use_line",
        ] {
            assert!(v.get(key).is_some(), "missing values[].{key}");
        }
    }
}

#[test]
fn bad_descriptions_point_into_the_toml() {
    let d = std::env::temp_dir().join(format!("rtlint-stack-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let shader = common::root().join("fixtures/pipelines/recursive/reflect.rgen.spv");
    let cases = [
        (
            "missing.pipeline.toml",
            "[[raygen]]\nfile = \"nope.spv\"\n",
            2,
        ),
        (
            "entry.pipeline.toml",
            &format!(
                "[[raygen]]\nfile = \"{}\"\nentry = \"nothere\"\n",
                shader.display()
            ),
            3,
        ),
        ("type.pipeline.toml", "max_recursion_depth = \"deep\"\n", 1),
        ("key.pipeline.toml", "max_recursion_depht = 2\n", 1),
    ];
    for (name, text, line) in cases {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        for cmd in ["stack", "check"] {
            let o = rtlint().args([cmd, p.to_str().unwrap()]).output().unwrap();
            let out = String::from_utf8_lossy(&o.stdout).into_owned()
                + &String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{cmd} {name}: {out}");
            assert!(
                out.contains(&format!("{name}:{line}:")),
                "{cmd} {name}: {out}"
            );
            assert!(!out.contains("panicked"), "{out}");
        }
    }
}

/// Every pipeline description in the repository, in every folder.
fn all_descriptions() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![
        common::root().join("shaders"),
        common::root().join("fixtures"),
        common::root().join("calibration"),
    ];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            // The generated random pipelines are not in the repository.
            if p.is_dir() && !p.ends_with("calibration/random") {
                dirs.push(p);
            } else if rtlint::lint::is_pipeline(&p) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn driver_creates_every_pipeline_without_a_validation_error() {
    // The Khronos validation layer must be there, or nothing is checked.
    let layer = std::fs::read_dir("/usr/share/vulkan/explicit_layer.d")
        .map(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().contains("validation"))
        })
        .unwrap_or(false);
    assert!(
        layer,
        "the Khronos validation layer is not installed (scripts/setup)"
    );
    let pipelines = all_descriptions();
    // Textures, samplers and bindless arrays in several sets, in HLSL and GLSL.
    for name in ["textured_hlsl.pipeline.toml", "bindless.pipeline.toml"] {
        assert!(
            pipelines.iter().any(|p| p.ends_with(name)),
            "{name} is missing"
        );
    }
    assert!(pipelines.len() >= 70, "{}", pipelines.len());
    let o = rtlint()
        .args(["stack", "--driver", "--format", "json"])
        .args(&pipelines)
        .env("RTLINT_VK_VALIDATION", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(!stderr.contains("validation"), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let reports = v["pipelines"].as_array().unwrap();
    // Exit 1 exactly when a pipeline declares too small a depth (the RT021
    // fixtures do on purpose).
    let shallow = reports.iter().any(|r| !r["raise_depth_to"].is_null());
    assert!(shallow);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert_eq!(reports.len(), pipelines.len());
    assert_eq!(v["errors"].as_array().map(Vec::len), Some(0));
    for r in reports {
        assert!(
            r["driver"].is_object(),
            "no driver figures: {}",
            r["pipeline"]
        );
    }
}

#[test]
fn a_driver_crash_is_an_error_for_that_pipeline_only() {
    // A child that dies of SIGSEGV, as lavapipe did on a mismatched layout.
    let dir = std::env::temp_dir().join(format!("rtlint-crash-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let child = dir.join("crash.sh");
    std::fs::write(&child, "#!/bin/sh\nkill -SEGV $$\n").unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&child, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let o = rtlint()
        .args([
            "stack",
            "--driver",
            "fixtures/pipelines/callable.pipeline.toml",
            "fixtures/pipelines/textured_hlsl.pipeline.toml",
        ])
        .env("RTLINT_DRIVER_CHILD", &child)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    // rtlint itself survives, reports both pipelines' models and an error
    // for each crashed creation.
    assert_eq!(o.status.code(), Some(2), "{stdout}{stderr}");
    assert_eq!(
        stdout.matches("pipeline fixtures/pipelines/").count(),
        2,
        "{stdout}"
    );
    assert_eq!(
        stdout
            .matches("the driver crashed while creating the pipeline (signal 11, SIGSEGV)")
            .count(),
        2,
        "{stdout}{stderr}"
    );
}

#[test]
fn json_with_several_inputs_still_reports_input_errors() {
    let o = rtlint()
        .args([
            "stack",
            "--format",
            "json",
            "fixtures/pipelines/callable.pipeline.toml",
            "fixtures/pipelines/procedural.pipeline.toml",
            "fixtures/pipelines/missing.pipeline.toml",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pipelines"].as_array().map(Vec::len), Some(2));
    let errors = v["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].to_string().contains("missing.pipeline.toml"),
        "{errors:?}"
    );
}

#[test]
fn driver_numbers_from_the_measurement_csv() {
    // What the H200 reported for the reference pipeline, kept in the
    // repository: raygen 64, miss 0, closest hit 0.
    let v = json(&[
        "stack",
        "--driver-numbers",
        "calibration/random/nvidia-h200.csv",
        "--format",
        "json",
        "shaders/reflect_iterative.pipeline.toml",
    ]);
    let r = &v["pipelines"][0];
    let measured: Vec<u64> = r["shaders"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["driver_bytes"].as_u64().unwrap())
        .collect();
    assert_eq!(measured, [64, 0, 0]);
    let chain = r["driver"]["exact_call_chain"].as_u64().unwrap();
    assert_eq!(chain, 64);
    assert!(r["recommended"].as_u64().unwrap() >= chain);
    // A malformed CSV is an input error with its line, not a panic.
    let dir = std::env::temp_dir().join(format!("rtlint-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.csv");
    std::fs::write(
        &bad,
        "pipeline,group,stage,entry,driver_bytes\nx,raygen 0,ray_generation,main,lots\n",
    )
    .unwrap();
    let o = rtlint()
        .args(["stack", "--driver-numbers"])
        .arg(&bad)
        .arg("shaders/reflect_iterative.pipeline.toml")
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("bad.csv:2: `lots` is not a byte count"),
        "{stderr}"
    );
}

/// An HLSL library that no description names is described by its DXR
/// subobjects: the depth of `RaytracingPipelineConfig`, its hit group, and
/// its own shaders; the driver's child process rebuilds it from the library.
#[test]
fn stack_of_a_library_described_by_its_subobjects() {
    let o = rtlint()
        .args([
            "stack",
            "--driver",
            "--format",
            "json",
            "fixtures/RT021/bad.hlsl",
        ])
        .output()
        .unwrap();
    // It declares depth 1 and needs 3: the run fails.
    assert_eq!(
        o.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let out: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let reports = out["pipelines"].as_array().unwrap();
    assert_eq!(reports.len(), 1, "{out}");
    let r = &reports[0];
    assert_eq!(r["pipeline"], "fixtures/RT021/bad.hlsl (DXR subobjects)");
    assert_eq!(r["declared_depth"], 1);
    assert_eq!(r["required_depth"], 3);
    assert_eq!(r["raise_depth_to"], 3);
    let shaders: Vec<(&str, &str)> = r["shaders"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| (s["stage"].as_str().unwrap(), s["entry"].as_str().unwrap()))
        .collect();
    assert_eq!(
        shaders,
        [
            ("ray_generation", "Gen"),
            ("miss", "Sky"),
            ("closest_hit", "MirrorHit")
        ]
    );
    assert!(r["driver"].is_object(), "no driver figures: {r}");
    let assumptions = r["assumptions"].to_string();
    assert!(assumptions.contains("DXR subobjects"), "{assumptions}");
}

/// A declared depth below the deepest chain: the report says to raise it
/// (and to what) beside the size, JSON says `raise_depth_to`, and the run
/// fails (exit 1) as RT021's error does; a sufficient depth passes.
#[test]
fn a_too_small_declared_depth_must_be_raised_and_fails_the_run() {
    let o = rtlint()
        .args(["stack", "fixtures/RT021/bad.pipeline.toml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{text}");
    assert!(
        text.contains("the declared depth 3 is too small: raise it to 5"),
        "{text}"
    );
    assert!(
        text.contains("once the declared depth is raised to 5: set both, the depth and this size"),
        "{text}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap_or_default();
    assert!(v.is_null(), "human output is not JSON");
    let o = rtlint()
        .args([
            "stack",
            "--format",
            "json",
            "fixtures/RT021/bad.pipeline.toml",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pipelines"][0]["raise_depth_to"], 5);
    let v = json(&[
        "stack",
        "--format",
        "json",
        "fixtures/RT021/good.pipeline.toml",
    ]);
    assert!(v["pipelines"][0]["raise_depth_to"].is_null());
}

/// Every column of the table is explained in words under it, once.
#[test]
fn the_stack_columns_are_explained() {
    let o = rtlint()
        .args(["stack", "fixtures/RT021/good.pipeline.toml"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    let header = text
        .lines()
        .find(|l| l.starts_with("shader "))
        .expect("a table header");
    let legend = rtlint::report::stack::COLUMNS;
    assert_eq!(text.matches(legend).count(), 1, "{text}");
    for column in header.split_whitespace().skip(2) {
        let column = column.trim_end_matches('*');
        assert!(
            legend
                .lines()
                .any(|l| l.trim_start().starts_with(&format!("{column} "))
                    || l.trim_start().starts_with(&format!("{column}* "))),
            "column `{column}` unexplained"
        );
    }
}

/// Compute shaders with ray queries have no pipeline stack to set.
#[test]
fn a_ray_query_compute_shader_gets_no_stack_size_call() {
    let o = rtlint()
        .args(["stack", "fixtures/RT062/good.comp"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{text}");
    assert!(
        !text.contains("vkCmdSetRayTracingPipelineStackSizeKHR"),
        "{text}"
    );
    assert!(text.contains("recommended: nothing to set"), "{text}");
    let v = json(&["stack", "--format", "json", "fixtures/RT062/good.comp"]);
    assert!(v["pipelines"][0]["recommended"].is_null(), "{v}");
}

/// `stack DIR`: shaders a description names are in its pipeline only, and
/// the others form one loose pipeline per folder, not one across folders.
#[test]
fn loose_pipelines_leave_out_described_shaders_and_keep_to_one_folder() {
    let v = json(&["stack", "--format", "json", "fixtures/pipelines"]);
    let list = v["pipelines"].as_array().unwrap();
    let files = |p: &serde_json::Value| -> Vec<PathBuf> {
        p["shaders"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| std::fs::canonicalize(s["file"].as_str().unwrap()).unwrap())
            .collect()
    };
    let described: Vec<PathBuf> = list
        .iter()
        .filter(|p| !p["pipeline"].is_null())
        .flat_map(files)
        .collect();
    let loose: Vec<&serde_json::Value> = list.iter().filter(|p| p["pipeline"].is_null()).collect();
    assert!(!loose.is_empty(), "{v}");
    for p in loose {
        let f = files(p);
        assert!(f.iter().all(|x| !described.contains(x)), "{f:?}");
        assert!(f.iter().all(|x| x.parent() == f[0].parent()), "{f:?}");
    }
}
