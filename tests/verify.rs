//! `rtlint verify` on the Vulkan device: the reference shaders (WGSL, and
//! HLSL through rtlint's compiler) match the CPU reference, recursive and
//! iterative images and both languages' images are identical, the pipeline
//! declared too shallow crashes its child and passes as an expected failure,
//! and a shader that disagrees with the reference fails with images. Under
//! the skip policy (`common::device()`): without a ray-tracing device these
//! fail in CI.

#![cfg(feature = "vulkan")]

mod common;

use std::path::{Path, PathBuf};

fn out_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rtlint-verify-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The table's rows: (shader, scene, result) by the first, second and last cell.
fn rows(stdout: &str) -> Vec<(String, String, String)> {
    stdout
        .lines()
        .skip_while(|l| !l.starts_with("shader "))
        .skip(1)
        .take_while(|l| !l.starts_with("FAIL") && !l.starts_with("expected failure"))
        .filter(|l| !l.contains(" cases, "))
        .map(|l| {
            let cells: Vec<&str> = l
                .split("  ")
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .collect();
            (
                cells[0].to_string(),
                cells[1].to_string(),
                cells.last().unwrap().to_string(),
            )
        })
        .collect()
}

#[test]
fn reference_shaders_pass_and_the_shallow_pipeline_fails_as_expected() {
    let Some(ctx) = common::device() else {
        return;
    };
    // Ray-query cases are skipped, and say so, where the device has none.
    let query = if ctx.info().ray_query {
        "pass"
    } else {
        "skipped"
    };
    drop(ctx);
    let out = out_dir("bundled");
    // As an installed binary runs: from a folder with no `shaders/`, the
    // reference shaders taken from the binary (written to a fresh cache).
    let elsewhere = out_dir("elsewhere");
    std::fs::create_dir_all(&elsewhere).unwrap();
    let o = common::rtlint()
        .current_dir(&elsewhere)
        .env("XDG_CACHE_HOME", elsewhere.join("cache"))
        .args(["verify", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    eprintln!("{stdout}{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{stdout}");
    let row = |s: &str, c: &str, r: &str| (s.to_string(), c.to_string(), r.to_string());
    let mut expected = Vec::new();
    // The cut-out scene: HLSL pipelines (any-hit) and ray queries only.
    for (shader, result, cutout) in [
        ("iterative", "pass", false),
        ("recursive", "pass", false),
        ("iterative-hlsl", "pass", true),
        ("recursive-hlsl", "pass", true),
        ("rayquery", query, true),
        ("rayquery-hlsl", query, true),
        ("glossy", "pass", false),
        ("glossy-hlsl", "pass", true),
        ("hybrid", "pass", false),
        ("hybrid-hlsl", "pass", true),
        ("adaptive", "pass", false),
        ("adaptive-hlsl", "pass", false),
    ] {
        for scene in ["mirror", "showcase", "cutout"] {
            if scene != "cutout" || cutout {
                expected.push(row(shader, scene, result));
            }
        }
    }
    // Identity cases, on the scenes both shaders render.
    for (pair, result, cutout) in [
        ("recursive = iterative", "pass", false),
        ("iterative-hlsl = iterative", "pass", false),
        ("recursive-hlsl = recursive", "pass", false),
        ("recursive-hlsl = iterative-hlsl", "pass", true),
        ("rayquery = iterative", query, false),
        ("rayquery = iterative-hlsl", query, true),
        ("rayquery-hlsl = iterative", query, false),
        ("rayquery-hlsl = rayquery", query, true),
        ("glossy-hlsl = glossy", "pass", false),
        ("hybrid-hlsl = hybrid", "pass", false),
        ("adaptive-hlsl = adaptive", "pass", false),
    ] {
        for scene in ["mirror", "showcase", "cutout"] {
            if scene != "cutout" || cutout {
                expected.push(row(pair, scene, result));
            }
        }
    }
    expected.push(row(
        "recursive-depth-1",
        "showcase",
        "pass (expected failure)",
    ));
    assert_eq!(rows(&stdout), expected);
    // The crash was caught and named.
    assert!(
        stdout.contains(
            "expected failure recursive-depth-1/showcase: caught: the child was killed by signal"
        ),
        "{stdout}"
    );
    // The multi-pass shaders say what they measured, and the hybrid one
    // draws the path each pixel took.
    for (shader, scene) in [
        ("hybrid", "mirror"),
        ("hybrid", "showcase"),
        ("hybrid-hlsl", "cutout"),
    ] {
        let note = format!("{shader}/{scene}: ");
        let line = stdout.lines().find(|l| l.starts_with(&note));
        assert!(
            line.is_some_and(|l| l.contains("reflecting pixels traced a ray")
                && l.contains("paths differ from the CPU's on 0 (")
                && l.ends_with(&format!("({})", rtlint::verify::measure::HYBRID_LEGEND))),
            "{stdout}"
        );
        assert!(out.join(format!("{shader}_{scene}-paths.png")).is_file());
    }
    assert!(
        // Without rough surfaces every pixel stops at the minimum, 4 of 16.
        stdout.contains("adaptive/mirror: 16384 paths instead of 65536 for 16 fixed passes"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(out.join("verify.csv")).unwrap();
    assert_eq!(csv.lines().count(), expected.len() + 1, "{csv}");
    assert!(csv.starts_with("shader,case,pixels,max diff"), "{csv}");
    let md = std::fs::read_to_string(out.join("verify.md")).unwrap();
    assert!(md.contains("| recursive | mirror | 4096 |"), "{md}");
    assert!(out.join("iterative_mirror-gpu.png").is_file());
    std::fs::remove_dir_all(&out).unwrap();
}

/// The pipeline `verify` runs as its expected failure, the recursive
/// reference declared with depth 1, is an error for `rtlint check` too.
#[test]
fn check_flags_the_shallow_pipeline_statically() {
    let dir = out_dir("shallow");
    std::fs::create_dir_all(&dir).unwrap();
    let shaders = common::root().join("shaders");
    let text = std::fs::read_to_string(shaders.join("reflect_recursive.pipeline.toml")).unwrap();
    let wgsl = shaders.join("reflect_recursive.wgsl");
    let shallow = text
        .replace("max_recursion_depth = 5", "max_recursion_depth = 1")
        .replace(
            "\"reflect_recursive.wgsl\"",
            &format!("{:?}", wgsl.display().to_string()),
        );
    assert_ne!(text, shallow);
    let toml = dir.join("shallow.pipeline.toml");
    std::fs::write(&toml, shallow).unwrap();
    let o = common::rtlint()
        .args(["check", "--format", "concise"])
        .arg(&toml)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("error[RT021]"), "{stdout}");
    assert!(stdout.contains("needs recursion depth 5"), "{stdout}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Copies the bundled shaders folder with the iterative shader's sky made a
/// little less blue, and a manifest that verifies only that shader.
fn broken_copy(dir: &Path) {
    let root = common::root().join("shaders");
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    let pipeline = "reflect_iterative.pipeline.toml";
    std::fs::copy(root.join(pipeline), dir.join(pipeline)).unwrap();
    for f in ["mirror.toml", "showcase.toml"] {
        std::fs::copy(root.join("scenes").join(f), dir.join("scenes").join(f)).unwrap();
    }
    let wgsl = std::fs::read_to_string(root.join("reflect_iterative.wgsl")).unwrap();
    let changed = wgsl.replace("vec3<f32>(0.5, 0.7, 1.0)", "vec3<f32>(0.5, 0.7, 0.9)");
    assert_ne!(wgsl, changed);
    std::fs::write(dir.join("reflect_iterative.wgsl"), changed).unwrap();
    std::fs::write(
        dir.join("verify.toml"),
        "width = 32\nheight = 32\n[[shader]]\nname = \"iterative\"\n\
         pipeline = \"reflect_iterative.pipeline.toml\"\nreference = \"iterative\"\n\
         scenes = [\"mirror\"]\n",
    )
    .unwrap();
}

#[test]
fn a_shader_that_disagrees_fails_with_images() {
    if common::device().is_none() {
        return;
    }
    let dir = out_dir("broken-shaders");
    broken_copy(&dir);
    let out = dir.join("out");
    let o = common::rtlint()
        .args(["verify", "--shaders"])
        .arg(&dir)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert_eq!(
        rows(&stdout),
        [("iterative".into(), "mirror".into(), "FAIL".into())]
    );
    assert!(stdout.contains("FAIL iterative/mirror: "), "{stdout}");
    for suffix in ["gpu", "cpu", "diff"] {
        let png = out.join(format!("iterative_mirror-{suffix}.png"));
        assert!(png.is_file(), "{} missing", png.display());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn usage_errors_exit_2() {
    let missing = out_dir("missing");
    for args in [
        vec!["verify", "--shaders", missing.to_str().unwrap()],
        vec!["verify", "--filter", "no-such-case"],
        vec!["verify", "--no-such-flag"],
    ] {
        let o = common::rtlint().args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    // A scene that does not parse is a usage error before any GPU work.
    let dir = out_dir("bad-scene");
    broken_copy(&dir);
    std::fs::write(dir.join("scenes/mirror.toml"), "[camera]\nposition = 3\n").unwrap();
    let o = common::rtlint()
        .args(["verify", "--shaders"])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("scenes/mirror.toml"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The whole extremes matrix: every cell passes (no NaN or infinity on
/// either side, robust origins below 0.1 % self-intersections); far from
/// the origin the fixed epsilon, below the coordinates' ulp at 1e5, makes
/// most rays hit the triangle they leave, the robust origin none.
#[test]
fn extremes_matrix() {
    if common::device().is_none() {
        return;
    }
    let out = out_dir("extremes");
    let o = common::rtlint()
        .args(["verify", "--extremes", "--filter", "extremes/", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{stdout}");
    let cells = |mode: &str, variant: &str| -> Vec<String> {
        let line = stdout
            .lines()
            .find(|l| l.contains(&format!(" {mode} ")) && l.contains(&format!(" {variant} ")))
            .unwrap_or_else(|| panic!("no {mode} {variant} row: {stdout}"));
        line.split("  ")
            .map(str::trim)
            .filter(|c| !c.is_empty())
            .map(str::to_string)
            .collect()
    };
    for variant in rtlint::verify::EXTREMES {
        for mode in ["robust", "epsilon"] {
            let row = cells(mode, variant);
            // shader, case, pixels, max, mean, above, PSNR, NaN, self-hit %, time, result
            assert_eq!(
                (row[7].as_str(), row.last().unwrap().as_str()),
                ("0", "pass"),
                "{row:?}"
            );
            if mode == "robust" {
                assert_eq!(row[8], "0.000", "{row:?}");
            }
        }
    }
    let self_hit: f64 = cells("epsilon", "translate=1e5")[8].parse().unwrap();
    assert!(self_hit > 50.0, "{stdout}");
    let md = std::fs::read_to_string(out.join("extremes.md")).unwrap();
    assert_eq!(
        md.lines().count(),
        2 + 2 * rtlint::verify::EXTREMES.len(),
        "{md}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// The shaders built into the binary are the repository's `shaders/`, file
/// for file and byte for byte, and the folder they are written to holds
/// exactly them (a changed file there is put back).
#[test]
fn the_bundled_shaders_are_the_shaders_folder() {
    let root = common::root().join("shaders");
    let mut on_disk = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p
                    .strip_prefix(&root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                on_disk.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    on_disk.sort();
    let mut bundled: Vec<(String, Vec<u8>)> = rtlint::verify::bundled::files()
        .iter()
        .map(|(r, b)| (r.to_string(), b.to_vec()))
        .collect();
    bundled.sort();
    assert_eq!(
        bundled.iter().map(|f| &f.0).collect::<Vec<_>>(),
        on_disk.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert!(bundled == on_disk, "a bundled file differs from shaders/");
    let base = out_dir("bundled-cache");
    let dir = rtlint::verify::bundled::folder_in(&base).unwrap();
    std::fs::write(dir.join("verify.toml"), "tampered").unwrap();
    let again = rtlint::verify::bundled::folder_in(&base).unwrap();
    let manifest = std::fs::read(again.join("verify.toml")).unwrap();
    assert_eq!(manifest, std::fs::read(root.join("verify.toml")).unwrap());
    assert!(rtlint::verify::Manifest::load(&again).is_ok());
}
