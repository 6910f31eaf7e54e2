//! `rtlint tradeoff --quick` on the Vulkan device: the CSV parses, every
//! measured setting has a GPU time and an error, the Pareto front is
//! non-empty and truly non-dominated (recomputed here from the CSV), the
//! SVG is well-formed XML, the front's thumbnails exist, and the glossy
//! shader's error falls as its rays per pixel grow. Under the skip policy
//! (`common::device()`).

#![cfg(feature = "vulkan")]

mod common;

use std::collections::HashMap;

/// The CSV as maps from column to cell (fields have no quotes but the
/// result column's, which comes last).
fn parse_csv(text: &str) -> Vec<HashMap<String, String>> {
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .expect("a header")
        .split(',')
        .map(str::to_string)
        .collect();
    lines
        .map(|l| {
            let mut cells: Vec<String> = Vec::new();
            let (mut cell, mut quoted) = (String::new(), false);
            let mut chars = l.chars().peekable();
            while let Some(c) = chars.next() {
                match (c, quoted) {
                    ('"', true) if chars.peek() == Some(&'"') => {
                        chars.next();
                        cell.push('"');
                    }
                    ('"', _) => quoted = !quoted,
                    (',', false) => cells.push(std::mem::take(&mut cell)),
                    _ => cell.push(c),
                }
            }
            cells.push(cell);
            assert_eq!(cells.len(), header.len(), "row `{l}`");
            header.iter().cloned().zip(cells).collect()
        })
        .collect()
}

/// Checks that `text` is well-formed XML as the plot uses it: balanced
/// elements, quoted attributes, only the five predefined entities.
fn check_xml(text: &str) -> Result<(), String> {
    let mut stack: Vec<String> = Vec::new();
    let mut rest = text;
    let mut roots = 0;
    while let Some(at) = rest.find('<') {
        check_text(&rest[..at])?;
        let end = rest[at..].find('>').ok_or("a tag is not closed")? + at;
        let tag = &rest[at + 1..end];
        if let Some(name) = tag.strip_prefix('/') {
            match stack.pop() {
                Some(open) if open == name.trim() => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
        } else {
            let self_closing = tag.ends_with('/');
            let body = tag.trim_end_matches('/');
            let name: String = body.chars().take_while(|c| !c.is_whitespace()).collect();
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
                return Err(format!("bad element name in <{tag}>"));
            }
            // Attributes: name="value" pairs.
            let mut attrs = body[name.len()..].trim();
            while !attrs.is_empty() {
                let eq = attrs
                    .find("=\"")
                    .ok_or(format!("attribute without =\" in <{tag}>"))?;
                let key = attrs[..eq].trim();
                if key.is_empty() || key.contains(char::is_whitespace) {
                    return Err(format!("bad attribute `{key}` in <{tag}>"));
                }
                let close = attrs[eq + 2..]
                    .find('"')
                    .ok_or(format!("unterminated attribute in <{tag}>"))?;
                check_text(&attrs[eq + 2..eq + 2 + close])?;
                attrs = attrs[eq + 3 + close..].trim_start();
            }
            if stack.is_empty() {
                roots += 1;
            }
            if !self_closing {
                stack.push(name);
            }
        }
        rest = &rest[end + 1..];
    }
    check_text(rest)?;
    match (stack.is_empty(), roots) {
        (true, 1) => Ok(()),
        (false, _) => Err(format!("unclosed elements {stack:?}")),
        (_, n) => Err(format!("{n} root elements")),
    }
}

fn check_text(t: &str) -> Result<(), String> {
    let mut rest = t;
    while let Some(at) = rest.find('&') {
        let entity = &rest[at..rest[at..].find(';').map_or(rest.len(), |e| at + e + 1)];
        if !["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"].contains(&entity) {
            return Err(format!("bad entity `{entity}`"));
        }
        rest = &rest[at + 1..];
    }
    Ok(())
}

#[test]
fn the_xml_checker_rejects_broken_documents() {
    assert!(check_xml(r#"<svg a="1"><g><text>x &amp; y</text></g><rect/></svg>"#).is_ok());
    for bad in [
        "<svg><g></svg>",
        "<svg>a & b</svg>",
        "<svg a=1></svg>",
        "<svg></svg><svg></svg>",
        "<svg><text>",
    ] {
        assert!(check_xml(bad).is_err(), "{bad}");
    }
}

#[test]
fn bad_input_exits_2_naming_the_file() {
    let o = common::rtlint()
        .current_dir(common::root())
        .args(["tradeoff", "--quick", "--scene", "no-such-scene", "--out"])
        .arg(std::env::temp_dir().join(format!("rtlint-tradeoff-bad-{}", std::process::id())))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no-such-scene.toml"), "{stderr}");
}

fn number(row: &HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} of {}: `{}`", row["setting"], row[key]))
}

#[test]
fn quick_sweep_writes_a_true_front_and_error_falls_with_rays_per_pixel() {
    let Some(ctx) = common::device() else {
        return;
    };
    drop(ctx);
    let out = std::env::temp_dir().join(format!("rtlint-tradeoff-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    // From a folder with no `shaders/`, as an installed binary runs: the
    // reference shaders come from the binary.
    let elsewhere =
        std::env::temp_dir().join(format!("rtlint-tradeoff-cwd-{}", std::process::id()));
    std::fs::create_dir_all(&elsewhere).unwrap();
    let o = common::rtlint()
        .current_dir(&elsewhere)
        .args(["tradeoff", "--quick", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let rows = parse_csv(&std::fs::read_to_string(out.join("tradeoff.csv")).unwrap());
    let measured: Vec<&HashMap<String, String>> =
        rows.iter().filter(|r| r["result"] == "measured").collect();
    assert!(measured.len() >= 8, "{stdout}");
    for r in &measured {
        assert!(number(r, "gpu_ms") > 0.0, "{r:?}");
        assert!(number(r, "gpu_ms_min") <= number(r, "gpu_ms"));
        assert!(number(r, "gpu_ms") <= number(r, "gpu_ms_max"));
        let rmse = number(r, "rmse");
        assert!((0.0..1.0).contains(&rmse), "{r:?}");
        assert!(number(r, "max_error") >= rmse);
        assert!(
            number(r, "rays") >= 32.0 * 32.0,
            "a primary ray per pixel at least"
        );
        // The GPU follows the CPU reference of the same setting.
        assert!(number(r, "cpu_diff") <= 1.0, "{r:?}");
    }
    // The front, recomputed: every front row is dominated by none, every
    // other row by some row.
    let point = |r: &HashMap<String, String>| (number(r, "gpu_ms"), number(r, "rmse"));
    let dominated = |p: (f64, f64)| {
        measured.iter().any(|q| {
            let q = point(q);
            q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1)
        })
    };
    let front: Vec<&&HashMap<String, String>> =
        measured.iter().filter(|r| r["front"] == "yes").collect();
    assert!(!front.is_empty(), "{stdout}");
    for r in &measured {
        assert_eq!(
            r["front"] == "yes",
            !dominated(point(r)),
            "{}: {:?}",
            r["setting"],
            point(r)
        );
        if r["front"] == "yes" {
            let png = out.join(format!(
                "front-{}.png",
                r["setting"].replace(' ', "_").replace('=', "-")
            ));
            assert!(png.is_file(), "{}", png.display());
        }
    }
    // A thumbnail for each front setting and for nothing else.
    let thumbnails = std::fs::read_dir(&out)
        .unwrap()
        .filter(|e| {
            let name = e.as_ref().unwrap().file_name();
            let name = name.to_string_lossy();
            name.starts_with("front-") && name.ends_with(".png")
        })
        .count();
    assert_eq!(thumbnails, front.len());
    // Rays per pixel 1, 4 (the default), 16: each more rays, less error.
    let glossy = |spp: &str| {
        let name = if spp == "4" {
            "glossy".to_string()
        } else {
            format!("glossy spp={spp}")
        };
        let r = measured
            .iter()
            .find(|r| r["setting"] == name)
            .unwrap_or_else(|| panic!("no row `{name}`: {stdout}"));
        (number(r, "rmse"), number(r, "rays"))
    };
    let (e1, r1) = glossy("1");
    let (e4, r4) = glossy("4");
    let (e16, r16) = glossy("16");
    assert!(r1 < r4 && r4 < r16, "rays {r1} {r4} {r16}");
    assert!(e1 > e4 && e4 > e16, "rmse {e1} {e4} {e16}");
    // The adaptive shader's fewest and most paths are uniforms the GPU
    // follows (each row matched its own CPU reference above): fewer paths
    // at either bound, fewer rays.
    let rays = |name: &str| {
        let r = measured
            .iter()
            .find(|r| r["setting"] == name)
            .unwrap_or_else(|| panic!("no row `{name}`: {stdout}"));
        number(r, "rays")
    };
    let adaptive = rays("adaptive");
    assert!(rays("adaptive min_paths=1") < adaptive, "{stdout}");
    assert!(rays("adaptive max_paths=8") < adaptive, "{stdout}");
    let svg = std::fs::read_to_string(out.join("tradeoff.svg")).unwrap();
    check_xml(&svg).unwrap();
    assert!(svg.contains("on the Pareto front"));
    for r in &front {
        assert!(
            svg.contains(&format!(">{}</text>", r["setting"])),
            "{} is not labelled",
            r["setting"]
        );
    }
    assert!(std::fs::read_to_string(out.join("tradeoff.md"))
        .unwrap()
        .contains("Pareto front"));
    assert!(out.join("reference.png").is_file());
    let _ = std::fs::remove_dir_all(&out);
}

/// The docs and `--help` follow the knob table: the quick sweep's number of
/// settings in docs/tradeoff.md is the one the code builds, `--help` names
/// every knob, and the progress bar counts to settings × rounds (children
/// that fail at once stand in for the device here).
#[test]
fn docs_help_and_the_bar_follow_the_knob_table() {
    let shaders = common::root().join("shaders");
    let manifest = rtlint::verify::Manifest::load(&shaders).unwrap();
    let quick = rtlint::tradeoff::settings(&manifest, &shaders, "showcase", true)
        .unwrap()
        .len();
    let docs = std::fs::read_to_string(common::root().join("docs/tradeoff.md")).unwrap();
    assert!(
        docs.contains(&format!("`--quick`: {quick} settings")),
        "docs/tradeoff.md should say {quick} quick settings"
    );
    let help = common::rtlint()
        .args(["tradeoff", "--help"])
        .output()
        .unwrap();
    let help = String::from_utf8_lossy(&help.stdout);
    for k in rtlint::tradeoff::KNOBS {
        assert!(help.contains(k.name), "`tradeoff --help` omits {}", k.name);
    }
    let out = std::env::temp_dir().join(format!("rtlint-tradeoff-bar-{}", std::process::id()));
    let fail = |_: &str, _: &std::path::Path| std::process::Command::new("false");
    let options = rtlint::tradeoff::Options {
        shaders: shaders.clone(),
        out,
        scene: "showcase".into(),
        quick: true,
        child: &fail,
    };
    let mut seen = Vec::new();
    let report =
        rtlint::tradeoff::run(&options, |done, total, _| seen.push((done, total))).unwrap();
    assert_eq!(report.rows.len(), quick);
    assert!(seen.iter().all(|&(d, t)| t == quick && d <= t), "{seen:?}");
    assert_eq!(seen.last(), Some(&(quick, quick)));
}
