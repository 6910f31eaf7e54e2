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
