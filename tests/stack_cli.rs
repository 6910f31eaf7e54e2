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
    // A header declaring a runtime array that one stage leaves unused, and a
    // module reading the shader clock (its extension must be enabled).
    for name in [
        "textured_hlsl.pipeline.toml",
        "bindless.pipeline.toml",
        "shared_header.pipeline.toml",
        "shader_clock.pipeline.toml",
    ] {
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

#[test]
fn driver_names_the_register_shift_for_an_hlsl_collision() {
    // t0, u0 and b0 on one binding: no layout serves them; the message says
    // which HLSL register classes collide and which option separates them,
    // in words (no Rust debug text).
    let o = rtlint()
        .args(["stack", "--driver"])
        .arg(common::root().join("tests/pipelines/registers.pipeline.toml"))
        .env("RTLINT_VK_VALIDATION", "1")
        .output()
        .unwrap();
    // The human report goes to stdout, its input errors after it.
    let stderr =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("set 0, binding 0 is an acceleration structure for `Scene`"),
        "{stderr}"
    );
    assert!(stderr.contains("a storage image for `Output`"), "{stderr}");
    // The user's file, not the copy the child process was given.
    assert!(
        stderr.contains("raygeneration `RayGen` (")
            && stderr.contains("tests/pipelines/registers.hlsl)"),
        "{stderr}"
    );
    assert!(!stderr.contains("m0.spv"), "{stderr}");
    assert!(stderr.contains("`-fvk-u-shift N SET`"), "{stderr}");
    assert!(stderr.contains("`-fvk-t-shift N SET`"), "{stderr}");
    let error = stderr
        .lines()
        .find(|l| l.contains("no pipeline layout"))
        .unwrap();
    for debug in ["Fixed(", "Runtime", "×", "StorageImage"] {
        assert!(!error.contains(debug), "{debug} in {error}");
    }
}

#[test]
fn a_device_without_the_shader_clock_skips_with_what_it_needs() {
    // The shader-clock fixture needs VK_KHR_shader_clock: with the device's
    // own answer it is satisfied, with the feature taken away it is named.
    let Some(ctx) =
        rtlint_testkit::require("a Vulkan ray-tracing device", rtlint::vk::Context::new())
    else {
        return;
    };
    let p = rtlint::pipeline::load(
        &common::root().join("fixtures/pipelines/shader_clock.pipeline.toml"),
    )
    .unwrap();
    let mut info = ctx.info().clone();
    assert!(info.shader_clock, "lavapipe has VK_KHR_shader_clock");
    assert_eq!(
        rtlint::vk::missing_requirements(&p, &info),
        Vec::<&str>::new()
    );
    info.shader_clock = false;
    assert_eq!(
        rtlint::vk::missing_requirements(&p, &info),
        ["VK_KHR_shader_clock (shaderSubgroupClock)"]
    );
    info.shader_int64 = false;
    assert_eq!(
        rtlint::vk::missing_requirements(&p, &info),
        // In the order the module declares them (Int64 first).
        ["shaderInt64", "VK_KHR_shader_clock (shaderSubgroupClock)"]
    );
}

#[test]
fn driver_takes_the_register_shifts_the_shaders_were_compiled_with() {
    // DXC's shifts on the command line reach the driver: the child process
    // gets the modules as `stack` compiled them. With u and b shifted the
    // pipeline is created with no validation error; with u alone the
    // collision that remains (t0 and b0) names the option that fixes it.
    let file = common::root().join("tests/pipelines/registers.hlsl");
    let run = |shifts: &[&str]| {
        let o = rtlint()
            .args(["stack", "--driver", "--format", "json"])
            .args(shifts)
            .arg(&file)
            .env("RTLINT_VK_VALIDATION", "1")
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
        let v: serde_json::Value =
            serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {stderr}"));
        (o.status.code(), v, stderr)
    };
    let (code, v, stderr) = run(&["-fvk-u-shift", "10", "all", "-fvk-b-shift", "20", "all"]);
    assert_eq!(code, Some(0), "{v}{stderr}");
    assert!(!stderr.contains("validation"), "{stderr}");
    assert_eq!(v["errors"].as_array().map(Vec::len), Some(0), "{v}");
    assert!(v["pipelines"][0]["driver"].is_object(), "{v}");

    let (code, v, _) = run(&["-fvk-u-shift", "10", "all"]);
    assert_eq!(code, Some(2), "{v}");
    let message = v["errors"][0]["message"].as_str().unwrap();
    assert!(
        message.contains("an acceleration structure for `Scene`")
            && message.contains("a uniform buffer for `Camera`"),
        "{message}"
    );
    assert!(message.contains("`-fvk-b-shift N SET`"), "{message}");
}

/// `rtlint check --format concise` lines (`path:line: level[CODE] …`).
fn concise(args: &[&str]) -> Vec<String> {
    let o = rtlint()
        .args(["check", "--format", "concise"])
        .args(args)
        .output()
        .unwrap();
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| l.contains("[RT"))
        .map(str::to_owned)
        .collect()
}

/// Issue 26: a closest hit that reflects while `payload.depth < 3` and
/// traces an unflagged shadow ray with its own payload. A trace reaches only
/// the shaders whose incoming payload matches its own, so the shadow ray
/// does not close a cycle through the radiance closest hit: the loose
/// folder, the DXR subobjects and the description all need depth 5 (hits at
/// levels 1–4, the deepest one's shadow miss at 5), and the loose and
/// subobject forms never recommend less than the description.
#[test]
fn reach_by_payload_gives_one_depth_in_every_form() {
    let glsl: Vec<String> = ["camera.rgen", "radiance.rchit", "sky.rmiss", "shadow.rmiss"]
        .iter()
        .map(|f| format!("fixtures/reach/glsl/{f}.spv"))
        .collect();
    let glsl: Vec<&str> = glsl.iter().map(String::as_str).collect();
    let described = |p: &str| json(&["stack", "--format", "json", p])["pipelines"][0].clone();
    for (forms, description) in [
        (
            vec![
                vec!["fixtures/reach/loose.hlsl"],
                vec!["fixtures/reach/library.hlsl"],
            ],
            "fixtures/reach/scene.pipeline.toml",
        ),
        (vec![glsl.clone()], "fixtures/reach/glsl.pipeline.toml"),
    ] {
        let d = described(description);
        assert_eq!(d["required_depth"], 5, "{description}");
        assert_eq!(d["declared_depth"], 5, "{description}");
        let floor = d["recommended"].as_u64().unwrap();
        for inputs in forms {
            let mut args = vec!["stack", "--format", "json"];
            args.extend(&inputs);
            let r = json(&args)["pipelines"][0].clone();
            assert_eq!(r["required_depth"], 5, "{inputs:?}");
            assert!(r["assumed_depth"].is_null(), "{inputs:?}");
            let rec = r["recommended"].as_u64().unwrap();
            assert!(rec >= floor, "{inputs:?}: {rec} < {floor}");
            let chain = r["depth_chain"].as_str().unwrap();
            assert!(chain.ends_with("at level 5"), "{chain}");
        }
    }
    // The findings: RT020 on the reflection only, RT030 on the shadow ray
    // (it only records hit or miss and lacks AcceptFirstHit), RT021 where a
    // description declares less than 5.
    for (inputs, reflection, shadow) in [
        (
            vec!["fixtures/reach/loose.hlsl"],
            "scene.hlsli:37",
            "scene.hlsli:31",
        ),
        (glsl.clone(), "radiance.rchit:21", "radiance.rchit:16"),
    ] {
        let mut args = vec!["--select", "RT020,RT021,RT030"];
        args.extend(&inputs);
        let lines = concise(&args);
        let at = |code: &str, place: &str| {
            lines
                .iter()
                .filter(|l| l.contains(code) && l.contains(place))
                .count()
        };
        assert_eq!(at("[RT020]", reflection), 1, "{lines:#?}");
        assert_eq!(at("[RT020]", shadow), 0, "{lines:#?}");
        assert_eq!(at("[RT030]", shadow), 1, "{lines:#?}");
        assert_eq!(at("[RT021]", ""), 0, "no declared depth: {lines:#?}");
    }
    let lines = concise(&["--select", "RT021", "fixtures/reach/shallow.pipeline.toml"]);
    assert_eq!(lines.len(), 1, "{lines:#?}");
    assert!(
        lines[0].contains("needs recursion depth 5, above the declared 3"),
        "{lines:#?}"
    );
}

/// A shadow ray guarded by the reflection's own depth counter, in helpers
/// that return early at the maximum (as Microsoft's procedural-geometry
/// sample writes it): the deepest hit traces nothing, so the declared 3 is
/// enough and RT021 stays silent.
#[test]
fn shadow_ray_guarded_by_the_reflection_counter() {
    let r = json(&[
        "stack",
        "--format",
        "json",
        "fixtures/guards/shared_counter.hlsl",
    ])["pipelines"][0]
        .clone();
    assert_eq!(r["declared_depth"], 3);
    assert_eq!(r["required_depth"], 3);
    assert!(concise(&["--select", "RT021", "fixtures/guards/shared_counter.hlsl"]).is_empty());
}

/// Recursion without a bound known at compile time: the recommendation is
/// conditional on the depth it assumes (the declared one, else the device's
/// limit) and never the smaller figure alone; the note and RT024 name the
/// trace that closes the cycle.
#[test]
fn unbounded_recursion_gives_a_conditional_recommendation() {
    let r = json(&[
        "stack",
        "--format",
        "json",
        "fixtures/RT024/bad.pipeline.toml",
    ])["pipelines"][0]
        .clone();
    assert!(r["required_depth"].is_null());
    assert_eq!(r["assumed_depth"], 5);
    assert_eq!(r["recommended"], r["model"]["vulkan_default"]);
    let text = |args: &[&str]| {
        let o = rtlint().args(args).output().unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let t = text(&["stack", "fixtures/RT024/bad.pipeline.toml"]);
    assert!(t.contains("recommended (conditional): "), "{t}");
    assert!(
        t.contains("assumes the recursion stops within depth 5 (the declared depth)"),
        "{t}"
    );
    assert!(
        t.contains("the trace at fixtures/pipelines/recursive/reflect.rchit:25:9 closes a cycle"),
        "{t}"
    );
    // No declared depth: the device's limit (31) is assumed, and the
    // recommendation covers it.
    let r = json(&[
        "stack",
        "--format",
        "json",
        "fixtures/guards/two_calls.wgsl",
    ])["pipelines"][0]
        .clone();
    assert!(r["required_depth"].is_null());
    assert_eq!(r["assumed_depth"], 31);
    let m = &r["model"]["stage_max"];
    let at31 = m["raygen"].as_u64().unwrap()
        + m["closest_hit"]
            .as_u64()
            .unwrap()
            .max(m["miss"].as_u64().unwrap())
            .max(m["intersection"].as_u64().unwrap() + m["any_hit"].as_u64().unwrap())
        + 30 * m["closest_hit"]
            .as_u64()
            .unwrap()
            .max(m["miss"].as_u64().unwrap())
        + 2 * m["callable"].as_u64().unwrap();
    assert!(r["recommended"].as_u64().unwrap() >= at31, "{r}");
    let t = text(&["stack", "fixtures/guards/two_calls.wgsl"]);
    assert!(
        t.contains("assumes the recursion stops within depth 31 (the device's limit)"),
        "{t}"
    );
    let lines = concise(&["--select", "RT024", "fixtures/RT024/bad.pipeline.toml"]);
    assert!(
        lines.iter().any(|l| l.contains(
            "is unbounded at compile time: the trace in closesthit `main` (hit group 0) has no depth bound"
        )),
        "{lines:#?}"
    );
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

/// A closest hit the description selects with a constant SBT offset runs
/// even when its payload differs from the trace's (a public sample ships
/// this): its level counts, so the depth is never under-stated, and RT009
/// reports the mismatch.
#[test]
fn a_selected_shader_with_another_payload_still_counts_its_level() {
    let p = "tests/pipelines/payload_mismatch.pipeline.toml";
    let r = json(&["stack", "--format", "json", p])["pipelines"][0].clone();
    assert_eq!(r["required_depth"], 2, "{r}");
    let lines = concise(&["--select", "RT009,RT021", p]);
    assert_eq!(lines.len(), 1, "{lines:#?}");
    assert!(lines[0].contains("[RT009]"), "{lines:#?}");
}
