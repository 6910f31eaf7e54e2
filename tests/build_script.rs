//! The build-script API as a crate uses it: a scratch copy of
//! `examples/build-script` depends on this repository by path with
//! `default-features = false` and is built with `cargo build`. Checks that
//! the build script reruns on a shader edit and on an edit of an included file
//! (and not otherwise), that a finding appears as `cargo:warning`, that an
//! error finding and bad HLSL fail the build, that the generated types'
//! sizes are those `rtlint layout` reports, and that the types generated for
//! `tests/build_script/interfaces.hlsl` (padded arrays, matrices, nested
//! structs) compile with their size and offset assertions.
//!
//! The example's target folder is `target/build-script-example`, so reruns
//! reuse the build.
#![cfg(feature = "cli")]

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_name().unwrap();
        if name == "target" || name == "Cargo.lock" {
            continue;
        }
        if p.is_dir() {
            copy_dir(&p, &to.join(name));
        } else {
            std::fs::copy(&p, to.join(name)).unwrap();
        }
    }
}

struct Crate {
    dir: PathBuf,
    target: PathBuf,
    offline: bool,
}

struct Build {
    ok: bool,
    /// Standard error: cargo's progress, warnings, the failure.
    text: String,
}

impl Build {
    /// Whether cargo ran the example's build script (not only saw it fresh).
    fn ran_build_script(&self) -> bool {
        self.text.lines().any(|l| {
            l.contains("Running `")
                && l.contains("rtlint-build-example-")
                && l.contains("build-script-build")
        })
    }
}

impl Crate {
    /// A copy of the example whose rtlint dependency is this repository.
    fn new() -> Crate {
        let dir = std::env::temp_dir().join(format!("rtlint-build-script-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        copy_dir(&repo().join("examples/build-script"), &dir);
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
        let dep = format!(
            "rtlint = {{ path = {:?}, default-features = false }}",
            repo().display().to_string()
        );
        let manifest = manifest.replace(
            r#"rtlint = { path = "../..", default-features = false }"#,
            &dep,
        );
        assert!(manifest.contains(&dep), "the example names rtlint by path");
        std::fs::write(dir.join("Cargo.toml"), manifest).unwrap();
        // rtlint's own lock file: the same versions as the main build, which
        // an offline build finds on this machine.
        std::fs::copy(repo().join("Cargo.lock"), dir.join("Cargo.lock")).unwrap();
        let target = repo().join("target/build-script-example");
        let mut c = Crate {
            dir,
            target,
            offline: true,
        };
        // Offline when every dependency is already on this machine.
        c.offline = c.cargo(&["fetch", "--offline"]).status.success();
        c
    }

    fn cargo(&self, args: &[&str]) -> std::process::Output {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        Command::new(cargo)
            .args(args)
            .current_dir(&self.dir)
            .env("CARGO_TARGET_DIR", &self.target)
            .env_remove("RUSTFLAGS")
            .env("CARGO_TERM_COLOR", "never")
            .output()
            .unwrap()
    }

    fn build(&self) -> Build {
        let mut args = vec!["build", "-v"];
        if self.offline {
            args.push("--offline");
        }
        let out = self.cargo(&args);
        Build {
            ok: out.status.success(),
            text: String::from_utf8_lossy(&out.stderr).into_owned()
                + &String::from_utf8_lossy(&out.stdout),
        }
    }

    fn path(&self, rel: &str) -> PathBuf {
        self.dir.join(rel)
    }

    fn edit(&self, rel: &str, f: impl FnOnce(String) -> String) {
        let p = self.path(rel);
        let text = std::fs::read_to_string(&p).unwrap();
        // A later modification time than the last build's, whatever the
        // file system's clock resolution.
        std::thread::sleep(std::time::Duration::from_millis(1100));
        std::fs::write(&p, f(text)).unwrap();
    }

    /// The generated layouts of the last successful build.
    fn layouts(&self) -> String {
        let build = self.target.join("debug/build");
        let mut newest: Option<(std::time::SystemTime, PathBuf)> = None;
        for e in std::fs::read_dir(&build).unwrap() {
            let p = e.unwrap().path().join("out/layouts.rs");
            if let Ok(m) = std::fs::metadata(&p) {
                let t = m.modified().unwrap();
                if newest.as_ref().is_none_or(|(n, _)| t > *n) {
                    newest = Some((t, p));
                }
            }
        }
        std::fs::read_to_string(newest.expect("layouts.rs was generated").1).unwrap()
    }
}

impl Drop for Crate {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// `size_of::<Name>() == N` from the generated file.
fn generated_sizes(text: &str) -> Vec<(String, u64)> {
    text.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("const _: () = assert!(core::mem::size_of::<")?;
            let (name, rest) = rest.split_once(">() == ")?;
            let n = rest.trim_end_matches(");").parse().ok()?;
            Some((name.to_string(), n))
        })
        .collect()
}

/// Every payload, attribute and push-constant type `rtlint layout` reports
/// for the crate's shaders has a generated type of the reported size.
fn assert_sizes_match_rtlint_layout(c: &Crate) {
    let generated = generated_sizes(&c.layouts());
    let out = Command::new(env!("CARGO_BIN_EXE_rtlint"))
        .args(["layout", "--format", "json", "shaders"])
        .current_dir(&c.dir)
        .output()
        .unwrap();
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut compared = 0;
    for file in json["files"].as_array().unwrap() {
        for t in file["types"].as_array().unwrap() {
            let name = t["name"].as_str().unwrap().trim_start_matches("type.");
            let roles: Vec<&str> = t["roles"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r.as_str().unwrap())
                .collect();
            // Payloads and attributes follow the scalar rule; the push
            // constants' declared (std430) offsets give the same size here.
            let expected = t["scalar_size"].as_u64().unwrap();
            let got = generated
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("no generated type for `{name}` ({roles:?})"));
            assert_eq!(got.1, expected, "`{name}` ({roles:?})");
            compared += 1;
        }
    }
    assert!(compared >= 3, "{json}");
}

#[test]
fn example_crate_builds_reruns_warns_and_fails() {
    let c = Crate::new();

    // Clean shaders: the crate builds and runs; no finding is reported.
    let b = c.build();
    assert!(b.ok, "{}", b.text);
    assert!(b.ran_build_script(), "{}", b.text);
    assert!(!b.text.contains(": RT0"), "{}", b.text);
    let generated = c.layouts();
    for ty in [
        "pub struct Payload",
        "pub struct Camera",
        "pub struct Push",
        "#[derive(bytemuck::Pod, bytemuck::Zeroable)]",
        "pub viewInverse: glam::Mat4,",
        "pub weights_last: f32,",
    ] {
        assert!(generated.contains(ty), "{ty} missing from\n{generated}");
    }
    assert_sizes_match_rtlint_layout(&c);
    let exe = c.target.join("debug/rtlint-build-example");
    let run = Command::new(&exe).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("Camera 192 bytes"), "{stdout}");
    assert!(stdout.contains("raygen: "), "{stdout}");

    // Nothing changed: the build script stays fresh.
    let b = c.build();
    assert!(b.ok && !b.ran_build_script(), "{}", b.text);

    // A shader edit reruns it.
    c.edit("shaders/raygen.hlsl", |t| t + "\n// edited\n");
    let b = c.build();
    assert!(b.ok && b.ran_build_script(), "{}", b.text);

    // So does an edit of a file a shader includes.
    c.edit("shaders/include/common.hlsli", |t| t + "\n// edited\n");
    let b = c.build();
    assert!(b.ok && b.ran_build_script(), "{}", b.text);

    // A warning: a 52-byte payload, over the 32-byte budget. It is reported
    // once as `cargo:warning`, the build goes on, and the generated type
    // follows the new layout.
    c.edit("shaders/include/common.hlsli", |t| {
        t.replace(
            "    uint depth;\n",
            "    uint depth;\n    float4 extra[2];\n",
        )
    });
    let b = c.build();
    assert!(b.ok, "{}", b.text);
    let rt001: Vec<&str> = b
        .text
        .lines()
        .filter(|l| l.contains("cargo:warning=") || l.starts_with("warning: rtlint-build-example"))
        .filter(|l| l.contains("RT001"))
        .collect();
    assert!(
        rt001.iter().any(|l| l.contains(
            "shaders/include/common.hlsli:4: RT001 ray payload `Payload` is 52 bytes, above the 32-byte budget"
        )),
        "{}",
        b.text
    );
    assert!(generated_sizes(&c.layouts()).contains(&("Payload".to_string(), 52)));
    assert_sizes_match_rtlint_layout(&c);

    // An error finding fails the build with the rendered diagnostic.
    let closest_hit = std::fs::read_to_string(c.path("shaders/closesthit.hlsl")).unwrap();
    c.edit("shaders/closesthit.hlsl", |t| {
        t.replace(
            "in BuiltInTriangleIntersectionAttributes attr)",
            "in Attributes attr)",
        )
        .replace(
            "[shader(\"closesthit\")]",
            "struct Attributes\n{\n    float2 barycentrics;\n    float4 a;\n    float4 b;\n    float c;\n};\n\n[shader(\"closesthit\")]",
        )
    });
    let b = c.build();
    assert!(!b.ok, "{}", b.text);
    assert!(
        b.text.contains(
            "error[RT004]: hit attributes `Attributes` are 44 bytes, above the 32-byte limit"
        ),
        "{}",
        b.text
    );
    assert!(b.text.contains("shaders/closesthit.hlsl:3:8"), "{}", b.text);

    // Bad HLSL fails it too, naming the file and position.
    c.edit("shaders/closesthit.hlsl", |_| {
        closest_hit.replace("p.hitT = RayTCurrent();", "p.hitT = RayTCurrent() +;")
    });
    let b = c.build();
    assert!(!b.ok, "{}", b.text);
    assert!(b.text.contains("shaders/closesthit.hlsl:8:"), "{}", b.text);
    assert!(!b.text.contains("panicked"), "{}", b.text);

    // Fixed again: it builds.
    c.edit("shaders/closesthit.hlsl", |_| closest_hit.clone());
    let b = c.build();
    assert!(b.ok, "{}", b.text);

    // Harder layouts: the crate compiles their generated types, so every
    // size and offset assertion holds, and the sizes are rtlint layout's.
    std::fs::copy(
        repo().join("tests/build_script/interfaces.hlsl"),
        c.path("shaders/interfaces.hlsl"),
    )
    .unwrap();
    let b = c.build();
    assert!(b.ok && b.ran_build_script(), "{}", b.text);
    let generated = c.layouts();
    for field in [
        "pub world: [[f32; 4]; 4],",
        "pub view: glam::Mat4,",
        "pub lights: [LightStride32; 2],",
        "pub lights_last: Light,",
        "pub counts_last: glam::IVec2,",
        "pub enabled: u32,",
        "pub inner: Inner,",
    ] {
        assert!(
            generated.contains(field),
            "{field} missing from\n{generated}"
        );
    }
    assert!(generated_sizes(&generated).contains(&("Scene".to_string(), 336)));
    assert_sizes_match_rtlint_layout(&c);
}
