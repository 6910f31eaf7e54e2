//! Debug info never changes an answer. Every GLSL fixture is compiled by
//! glslang three ways (no debug info, `-g`, `-gV`); every HLSL fixture (and
//! the HLSL tests' shaders in `tests/hlsl`) goes through rtlint's compiler
//! with its `NonSemantic.Shader.DebugInfo.100` and with that stripped; every WGSL fixture and the shaders in `shaders/` go
//! through naga with and without line information. For each module the
//! layouts, live sets and bytes, rematerialisation, and findings must agree
//! apart from positions; for each folder of loose GLSL modules, each
//! multi-stage file, and each pipeline description, the recursion depth,
//! cycle guards, stack model and pipeline findings must agree too.
//!
//! Differences that come from the code a compiler generates, not from its
//! debug info, are named in [`KNOWN`]; a known difference that disappears
//! fails the test too, so the list stays true.

mod common;

use common::root;
use rtlint::analysis::layout::interface_layouts;
use rtlint::analysis::liveness::live_sites;
use rtlint::analysis::recursion::recursion_report;
use rtlint::analysis::stack::stack_report;
use rtlint::config::Config;
use rtlint::diag::Diagnostic;
use rtlint::pipeline::Pipeline;
use rtlint::program::Program;
use rtlint::shader::Language;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// (fixture, what differs and why) for differences between the ways of
/// compiling one shader that are not debug info. Empty: none is known.
const KNOWN: &[(&str, &str)] = &[];

/// The ways a shader is compiled; the first is the reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Mode {
    /// glslang without `-g`; HLSL and WGSL with debug info stripped.
    Plain,
    /// glslang `-g` (`OpLine`, `OpSource` text).
    G,
    /// glslang `-gV` (`NonSemantic.Shader.DebugInfo.100`); rtlint's HLSL and
    /// naga's WGSL as they come.
    GV,
}

const GLSL_STAGES: &[&str] = &["rgen", "rchit", "rmiss", "rahit", "rint", "rcall"];

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// HLSL test shaders these comparisons leave out: classic entry points
/// (tests/hlsl/classic) need their stage named on the command line and have
/// no ray-tracing stage; the DXC-suite shaders (tests/hlsl/dxc_suite) are
/// compiler checks that need their own flags, and some must be refused
/// (tests/hlsl_dxc_suite.rs judges them).
fn set_aside(p: &Path) -> bool {
    p.components()
        .any(|c| c.as_os_str() == "classic" || c.as_os_str() == "dxc_suite")
}

fn ext(p: &Path) -> &str {
    p.extension().and_then(|e| e.to_str()).unwrap_or("")
}

/// Drops what only describes the code: `OpLine`, `OpNoLine`, `OpSource`,
/// `OpSourceContinued`, `OpString`, `OpModuleProcessed`, and every
/// extended instruction of a `NonSemantic.*` set. Names stay.
fn strip_debug(words: &[u32]) -> Vec<u32> {
    let mut out = words[..5].to_vec();
    let mut sets = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let op = words[i] & 0xffff;
        let inst = &words[i..i + count];
        if op == 11 {
            let name: Vec<u8> = inst[2..].iter().flat_map(|w| w.to_le_bytes()).collect();
            if name.starts_with(b"NonSemantic.") {
                sets.push(inst[1]);
            }
        }
        let drop = matches!(op, 8 | 317 | 3 | 2 | 7 | 330) || (op == 12 && sets.contains(&inst[3]));
        if !drop {
            out.extend_from_slice(inst);
        }
        i += count;
    }
    out
}

fn parse(words: &[u32], path: &Path, language: Language) -> Program {
    rtlint::program::parse(words, path, language)
        .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()))
}

/// Replaces what may legitimately differ (positions, the folder a mode's
/// modules live in) so the rest can be compared.
fn scrub(v: &mut Value, roots: &[String]) {
    rtlint_testkit::gen_check::scrub_json(v, &|s| scrub_text(s, roots));
}

fn scrub_text(s: &str, roots: &[String]) -> String {
    let mut s = s.to_string();
    for r in roots {
        s = s.replace(r.as_str(), "<root>");
    }
    // Names of SSA values come from source lines (WGSL `let`) when there
    // are any: `%12` without them.
    if s.starts_with("live values:") {
        let mut out = String::new();
        for (k, part) in s.split('`').enumerate() {
            out.push_str(if k % 2 == 1 { "_" } else { part });
        }
        s = out;
    }
    s
}

fn findings(d: &[Diagnostic], roots: &[String]) -> Vec<String> {
    rtlint_testkit::gen_check::findings_with(d, &|s| scrub_text(s, roots))
}

/// Everything the module-level analyses say, positions removed.
fn module_facts(p: &Program, roots: &[String]) -> Value {
    let mut layouts = serde_json::to_value(interface_layouts(p)).unwrap();
    scrub(&mut layouts, roots);
    let sites: Vec<Value> = live_sites(p)
        .iter()
        .map(|s| {
            let mut values: Vec<String> = s
                .values
                .iter()
                .map(rtlint_testkit::gen_check::value_line)
                .collect();
            values.sort();
            serde_json::json!({
                "entry": s.entry,
                "kind": s.kind.as_str(),
                "live": s.live_bytes,
                "remat": s.rematerializable_bytes,
                "payload": s.payload.as_ref().map(|p| p.size),
                "values": values,
            })
        })
        .collect();
    let config = Config::default();
    serde_json::json!({
        "layouts": layouts,
        "live": sites,
        "findings": findings(&rtlint::rules::check_program(p, &config), roots),
    })
}

/// Everything the pipeline-level analyses say, positions removed.
fn pipeline_facts(p: &Pipeline, roots: &[String]) -> Value {
    let rec = recursion_report(p);
    let cycles: Vec<String> = rec
        .cycles
        .iter()
        .flat_map(|c| c.sites.iter())
        .map(|s| match &s.guard {
            Ok(g) => format!(
                "{} {} {} step {} from {} ({}): {} traces",
                g.counter, g.op, g.bound, g.step, g.initial, g.initial_assumed, g.traces
            ),
            Err(e) => format!("no guard: {e:?}"),
        })
        .collect();
    let mut stack = serde_json::to_value(stack_report(p)).unwrap();
    scrub(&mut stack, roots);
    let config = Config::default();
    let ctx = rtlint::rules::PipelineContext::new(p, &config);
    serde_json::json!({
        "required_depth": rec.required_depth,
        "cycles": cycles,
        "chain": scrub_text(&rtlint::explain::recursion_chain(&rec), roots),
        "stack": stack,
        "findings": findings(&rtlint::rules::check_pipeline(&ctx), roots),
    })
}

/// Compiles every GLSL source under `fixtures/` into `out/<mode>/fixtures/…`
/// as `NAME.spv` (the name pipeline descriptions use), beside copies of the
/// descriptions and of the WGSL and header files they read.
fn compile_glsl_tree(out: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    files_under(&root().join("fixtures"), &mut files);
    let mut sources = Vec::new();
    for mode in ["plain", "g", "gV"] {
        for f in &files {
            let rel = f.strip_prefix(root()).unwrap();
            let dst = out.join(mode).join(rel);
            std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
            if ext(f) != "spv" {
                std::fs::copy(f, &dst).unwrap();
            }
        }
        for f in &files {
            if !GLSL_STAGES.contains(&ext(f)) {
                continue;
            }
            let rel = f.strip_prefix(root()).unwrap();
            let src = out.join(mode).join(rel);
            let spv = PathBuf::from(format!("{}.spv", src.display()));
            let mut cmd = Command::new("glslangValidator");
            cmd.args(["--target-env", "vulkan1.2", "-V"]);
            match mode {
                "g" => {
                    cmd.arg("-g");
                }
                "gV" => {
                    cmd.arg("-gV");
                }
                _ => {}
            }
            let status = cmd
                .arg(&src)
                .arg("-o")
                .arg(&spv)
                .output()
                .expect("glslangValidator is needed (scripts/setup installs glslang-tools)");
            assert!(
                status.status.success(),
                "glslang {mode} {}: {}",
                rel.display(),
                String::from_utf8_lossy(&status.stdout)
            );
            if mode == "plain" {
                sources.push(rel.to_path_buf());
            }
        }
    }
    sources
}

fn spirv_valid(path: &Path) -> bool {
    Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .arg(path)
        .output()
        .expect("spirv-val is needed (scripts/setup installs spirv-tools)")
        .status
        .success()
}

fn load_spv(path: &Path) -> Program {
    rtlint::front::load(path, Language::Spirv).unwrap_or_else(|e| panic!("{e:?}"))
}

/// One comparison: the reference mode's facts against another mode's.
fn compare(what: &str, facts: &BTreeMap<Mode, Value>, differences: &mut Vec<(String, String)>) {
    let Some((first_mode, first)) = facts.iter().next() else {
        return;
    };
    for (mode, f) in facts {
        if f != first {
            differences.push((
                what.to_string(),
                format!(
                    "{first_mode:?} and {mode:?} differ:\n  {first_mode:?}: {first}\n  {mode:?}: {f}"
                ),
            ));
        }
    }
}

#[test]
fn analyses_do_not_depend_on_debug_info() {
    if !rtlint_testkit::tool("glslangValidator") || !rtlint_testkit::tool("spirv-val") {
        return;
    }
    let out = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("invariance");
    let _ = std::fs::remove_dir_all(&out);
    let glsl = compile_glsl_tree(&out);
    assert!(glsl.len() >= 30, "GLSL fixtures missing: {}", glsl.len());
    let roots: Vec<String> = ["plain", "g", "gV"]
        .iter()
        .map(|m| format!("{}/", out.join(m).display()))
        .chain([format!("{}/", root().display())])
        .collect();
    let mode_of = |m: &str| match m {
        "plain" => Mode::Plain,
        "g" => Mode::G,
        _ => Mode::GV,
    };
    let mut differences: Vec<(String, String)> = Vec::new();
    let mut compared = 0;
    let mut invalid = Vec::new();

    // GLSL modules, one by one.
    for rel in &glsl {
        let mut facts = BTreeMap::new();
        for m in ["plain", "g", "gV"] {
            let spv = PathBuf::from(format!("{}.spv", out.join(m).join(rel).display()));
            if !spirv_valid(&spv) {
                // glslang 12's `-gV` is invalid for buffer_reference types
                // (FIELD-NOTES); rtlint must refuse it too, clearly.
                let bytes = std::fs::read(&spv).unwrap();
                let words = rtlint::program::words_from_bytes(&bytes, &spv).unwrap();
                assert!(
                    rtlint::program::parse(&words, &spv, Language::Spirv).is_err(),
                    "{} ({m}): spirv-val rejects it, rtlint reads it",
                    rel.display()
                );
                invalid.push(format!("{} ({m})", rel.display()));
                continue;
            }
            facts.insert(mode_of(m), module_facts(&load_spv(&spv), &roots));
        }
        compared += 1;
        compare(&rel.display().to_string(), &facts, &mut differences);
    }

    // Loose GLSL modules, one pipeline per folder (of the modules every
    // mode gives valid).
    let mut folders: Vec<PathBuf> = glsl
        .iter()
        .map(|r| r.parent().unwrap().to_path_buf())
        .collect();
    folders.dedup();
    for folder in &folders {
        let mut facts = BTreeMap::new();
        for m in ["plain", "g", "gV"] {
            let programs: Vec<Program> = glsl
                .iter()
                .filter(|r| r.parent() == Some(folder.as_path()))
                .filter(|r| {
                    !invalid
                        .iter()
                        .any(|i| i.starts_with(&format!("{} (", r.display())))
                })
                .map(|r| PathBuf::from(format!("{}.spv", out.join(m).join(r).display())))
                .map(|p| load_spv(&p))
                .collect();
            facts.insert(
                mode_of(m),
                pipeline_facts(&Pipeline::from_programs(programs), &roots),
            );
        }
        compared += 1;
        compare(
            &format!("{}/ (loose)", folder.display()),
            &facts,
            &mut differences,
        );
    }

    // Pipeline descriptions whose shaders are all GLSL.
    let mut tomls = Vec::new();
    files_under(&out.join("plain").join("fixtures"), &mut tomls);
    tomls.retain(|p| rtlint::lint::is_pipeline(p));
    assert!(tomls.len() >= 15, "{tomls:?}");
    for toml in &tomls {
        let rel = toml.strip_prefix(out.join("plain")).unwrap();
        let mut facts = BTreeMap::new();
        for m in ["plain", "g", "gV"] {
            let p = rtlint::pipeline::load(&out.join(m).join(rel))
                .unwrap_or_else(|e| panic!("{}: {e:?}", rel.display()));
            facts.insert(mode_of(m), pipeline_facts(&p, &roots));
        }
        compared += 1;
        compare(&rel.display().to_string(), &facts, &mut differences);
    }

    // HLSL and WGSL: as compiled, and with the debug info stripped.
    let mut others = Vec::new();
    files_under(&root().join("fixtures"), &mut others);
    files_under(&root().join("shaders"), &mut others);
    files_under(&root().join("tests/hlsl"), &mut others);
    // Classic entry points (tests/hlsl/classic) need their stage named on the
    // command line; they have no ray-tracing stage to compare.
    others.retain(|p| matches!(ext(p), "hlsl" | "wgsl") && !set_aside(p));
    assert!(others.len() >= 10, "{others:?}");
    for path in &others {
        let language = Language::from_path(path).unwrap();
        // The 16-bit test shaders are written for -enable-16bit-types.
        let options = rtlint::front::FrontOptions {
            hlsl: rtlint::front::hlsl::HlslOptions {
                enable_16bit_types: path.to_string_lossy().ends_with("half.hlsl"),
                ..Default::default()
            },
            ..Default::default()
        };
        let c = rtlint::front::compile_input(path, None, language, &options)
            .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
        let mut with = parse(&c.words, path, c.language);
        with.attach_named_decls(&c.decls);
        let without = parse(&strip_debug(&c.words), path, c.language);
        assert!(
            without.locs.iter().all(Option::is_none),
            "{}: stripping left positions",
            path.display()
        );
        let mut facts = BTreeMap::new();
        facts.insert(Mode::Plain, module_facts(&without, &roots));
        facts.insert(Mode::GV, module_facts(&with, &roots));
        let rel = path.strip_prefix(root()).unwrap().display().to_string();
        compare(&rel, &facts, &mut differences);
        let mut facts = BTreeMap::new();
        facts.insert(
            Mode::Plain,
            pipeline_facts(&Pipeline::from_programs(vec![without]), &roots),
        );
        facts.insert(
            Mode::GV,
            pipeline_facts(&Pipeline::from_programs(vec![with]), &roots),
        );
        compare(&format!("{rel} (loose)"), &facts, &mut differences);
        compared += 2;
    }
    assert!(compared >= 80, "{compared}");
    // The only modules spirv-val rejects are glslang's -gV buffer_reference ones.
    assert!(
        invalid.iter().all(|i| i.contains("reference.rgen (gV)")),
        "{invalid:?}"
    );

    let mut unexplained = Vec::new();
    for (what, how) in &differences {
        if !KNOWN.iter().any(|(k, _)| what == k) {
            unexplained.push(format!("{what}: {how}"));
        }
    }
    for (k, why) in KNOWN {
        assert!(
            differences.iter().any(|(w, _)| w == k),
            "{k} no longer differs ({why}): remove it from KNOWN"
        );
    }
    assert!(
        unexplained.is_empty(),
        "{} of {compared} comparisons differ:\n{}",
        unexplained.len(),
        unexplained.join("\n")
    );
}

/// (file, entry point, what differs and why) for HLSL compiled by rtlint and
/// by Slang: differences in the code the two compilers generate.
const KNOWN_ACROSS_COMPILERS: &[(&str, &str, &str, &str)] = &[
    (
        "fixtures/guards/fresh.hlsl",
        "Hit",
        "layouts",
        "rtlint declares the unused `attr` parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/live/classes.hlsl",
        "RayGen",
        "live bytes",
        "across the first trace rtlint keeps the whole `RayDesc` (32 B) in a local, Slang \
         only its origin (12 B); all recomputable, so the bytes that count agree",
    ),
    (
        "fixtures/RT030/bad_choice.hlsl",
        "ShadowHit",
        "layouts",
        "rtlint declares the unused `attr` parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/RT030/good_choice.hlsl",
        "ShadowHit",
        "layouts",
        "rtlint declares the unused `attr` parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/live/cbuffer_arg.hlsl",
        "RayGen",
        "live bytes",
        "rtlint passes `cam` to `Shade` through a temporary and counts it (recomputable: a \
         copy of the constant buffer); Slang inlines `Shade` and loads the buffer after the \
         trace; the kept bytes agree (0)",
    ),
    (
        "fixtures/live/cbuffer_arg_inline.hlsl",
        "RayGen",
        "live bytes",
        "rtlint keeps the constant `d` in a local (recomputable), Slang folds it; the kept \
         bytes agree (0)",
    ),
    (
        "fixtures/live/param_state.hlsl",
        "RayGen",
        "kept bytes",
        "rtlint passes `r` to `Trace` through a pointer and the analysis does not follow which \
         parts a callee writes through it, so `r.direction` (never written, recomputable) is \
         kept; Slang inlines `Trace` and sees it",
    ),
    (
        "fixtures/live/param_state.hlsl",
        "RayGen",
        "live bytes",
        "rtlint keeps `desc` (a `RayDesc`) and `r` in locals, Slang SSA values",
    ),
    (
        "fixtures/live/out_early.hlsl",
        "RayGen",
        "live bytes",
        "Slang carries the `out` values of `SampleLight`, unwritten when it returns early, \
         around the loop: `light.position` (12 B kept), `light.color` and `weight` (16 B \
         recomputable) are live across the trace; rtlint's `out` temporaries start undefined \
         at each call",
    ),
    (
        "fixtures/live/out_early.hlsl",
        "RayGen",
        "kept bytes",
        "as above: Slang keeps the stale `light.position` (12 B) across the trace",
    ),
    (
        "fixtures/hlsl/payloads.hlsl",
        "RayGen",
        "live bytes",
        "across the first trace rtlint keeps the whole `RayDesc` (32 B) and the zeroed `slim` \
         (16 B) in locals, Slang only the direction (12 B); all of it recomputable, so the \
         bytes that count (0 and 12) agree",
    ),
    (
        "fixtures/RT006/bad.hlsl",
        "(pipeline)",
        "depth and pipeline findings",
        "Slang copies the whole payload struct in and out of the payload variable, and a \
         whole-struct copy counts as reading and writing every member, so the members RT006 \
         reports look used in Slang's modules; rtlint's own output accesses members one by one",
    ),
    (
        "fixtures/RT008/bad.hlsl",
        "Sphere",
        "findings",
        "Slang stores the whole attribute struct (with `uv` undefined) into the hit-attribute \
         variable, which counts as writing every member; rtlint writes the members it assigns",
    ),
    (
        "fixtures/RT006/good.hlsl",
        "RayGen",
        "live bytes",
        "rtlint keeps the whole `RayDesc` in a local across the trace, Slang SSA values; all \
         recomputable, so the bytes that count agree",
    ),
    (
        "fixtures/RT006/good_shared_prefix.hlsl",
        "RayGen",
        "live bytes",
        "rtlint keeps the whole `RayDesc` in a local across the trace, Slang SSA values; all \
         recomputable, so the bytes that count agree",
    ),
    (
        "fixtures/RT006/good_shared_prefix.hlsl",
        "AlphaHash",
        "layouts",
        "rtlint declares the unused attribute parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/RT071/bad.hlsl",
        "AlphaTest",
        "layouts",
        "rtlint declares the unused incoming payload parameter; Slang drops it",
    ),
    (
        "fixtures/RT072/bad.hlsl",
        "Metal",
        "layouts",
        "rtlint declares the unused attribute parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/RT072/good_shadow_hit.hlsl",
        "Occluded",
        "layouts",
        "rtlint declares the unused attribute parameter as a hit-attribute variable; Slang drops it",
    ),
    (
        "fixtures/RT072/good_shadow_hit.hlsl",
        "RayGen",
        "live bytes",
        "the bounce loop's state sits in locals in rtlint's module and in loop phis in Slang's; \
         the analysis counts them differently (see below)",
    ),
    (
        "fixtures/RT072/good_shadow_hit.hlsl",
        "RayGen",
        "kept bytes",
        "per trace rtlint's module keeps 40 and 48 B, Slang's 28 and 64 B: the compilers keep \
         different parts of the loop state across each of the two traces; not yet explained \
         further (a known gap of the cross-compiler comparison)",
    ),

];

/// Layout facts without names (Slang suffixes its identifiers with `_0`).
fn layout_shapes(p: &Program) -> Vec<String> {
    let mut v: Vec<String> = interface_layouts(p)
        .iter()
        .map(|t| {
            let members: Vec<String> = t
                .members
                .iter()
                .map(|m| {
                    format!(
                        "{}@{}/{}{}",
                        m.size,
                        m.scalar_offset,
                        m.hlsl_packed_offset,
                        if m.straddles { "!" } else { "" }
                    )
                })
                .collect();
            format!(
                "{:?} {} B, packed {} B in {} rows, best {:?}: {}",
                t.roles,
                t.scalar_size,
                t.hlsl_packed_size,
                t.hlsl_rows,
                t.optimal_hlsl_packed_size,
                members.join(" ")
            )
        })
        .collect();
    v.sort();
    v
}

/// Finding codes with the line they point at.
fn coded_lines(d: &[Diagnostic]) -> Vec<String> {
    let mut v: Vec<String> = d
        .iter()
        .map(|d| {
            format!(
                "{} line {:?}",
                d.code.unwrap_or("-"),
                d.primary.as_ref().map(|p| p.location.line)
            )
        })
        .collect();
    v.sort();
    v
}

/// Whether an HLSL file declares DXR subobjects (Slang has none: such a
/// fixture, a pipeline described by its subobjects, is not compared).
fn declares_subobjects(file: &Path) -> bool {
    rtlint::front::hlsl::compile_file(file, &Default::default())
        .is_ok_and(|m| !m.subobjects.is_empty())
}

/// The same HLSL through rtlint's compiler and through Slang (`-g`), every
/// ray-tracing entry point of the HLSL fixtures and of `tests/hlsl`:
/// recursion depth, findings and the live bytes that cannot be recomputed
/// agree, and for the fixtures layouts and all live bytes too, except where
/// [`KNOWN_ACROSS_COMPILERS`] names the difference.
#[test]
fn hlsl_compilers_agree() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    let mut files = Vec::new();
    files_under(&root().join("fixtures"), &mut files);
    files_under(&root().join("tests/hlsl"), &mut files);
    files.retain(|p| ext(p) == "hlsl" && !set_aside(p));
    assert!(files.len() >= 3, "{files:?}");
    let config = Config::default();
    let mut differences: Vec<(String, String, String)> = Vec::new();
    let mut entries_compared = 0;
    for file in &files {
        let rel = file.strip_prefix(root()).unwrap().display().to_string();
        // The HLSL tests' shaders (tests/hlsl) declare resources Slang drops
        // as unused: only findings, depth and kept bytes are compared there.
        let all_facts = rel.starts_with("fixtures/");
        let options = rtlint::front::hlsl::HlslOptions {
            enable_16bit_types: rel.ends_with("half.hlsl"),
            ..Default::default()
        };
        let entries =
            rtlint::front::hlsl::compile(file, &options).unwrap_or_else(|e| panic!("{rel}: {e:?}"));
        let mut ours = Vec::new();
        let mut theirs = Vec::new();
        for e in entries.iter().filter(|e| e.stage.is_ray_tracing()) {
            let words =
                match slang.compile_hlsl(file, &e.name, e.stage.hlsl_name(), &["-g".to_string()]) {
                    Ok(w) => w,
                    // The HLSL tests exercise constructs Slang lacks (vk::ext_*
                    // attributes, SER, subobjects): nothing to compare there.
                    Err(err) if !all_facts || declares_subobjects(file) => {
                        eprintln!("{rel} {}: not compared, Slang refuses it: {err}", e.name);
                        continue;
                    }
                    Err(err) => panic!("{rel} {}: Slang: {err}", e.name),
                };
            let a = parse(&e.words, file, Language::Hlsl);
            let b = parse(&words, file, Language::Hlsl);
            let mut note = |what: &str, x: String, y: String| {
                if x != y && (all_facts || what == "findings") {
                    differences.push((
                        rel.clone(),
                        e.name.clone(),
                        format!("{what}: rtlint {x}, Slang {y}"),
                    ));
                }
            };
            note(
                "layouts",
                format!("{:?}", layout_shapes(&a)),
                format!("{:?}", layout_shapes(&b)),
            );
            note(
                "findings",
                format!(
                    "{:?}",
                    coded_lines(&rtlint::rules::check_program(&a, &config))
                ),
                format!(
                    "{:?}",
                    coded_lines(&rtlint::rules::check_program(&b, &config))
                ),
            );
            let bytes = |p: &Program| {
                let mut v: Vec<(u64, u64)> = live_sites(p)
                    .iter()
                    .map(|s| (s.live_bytes, s.live_bytes - s.rematerializable_bytes))
                    .collect();
                v.sort();
                format!("{v:?}")
            };
            note("live bytes (all, kept)", bytes(&a), bytes(&b));
            // What RT010 counts, compared for every entry point.
            let kept = |p: &Program| {
                let mut v: Vec<u64> = live_sites(p)
                    .iter()
                    .map(|s| s.live_bytes - s.rematerializable_bytes)
                    .collect();
                v.sort();
                format!("{v:?}")
            };
            let (ka, kb) = (kept(&a), kept(&b));
            if ka != kb {
                differences.push((
                    rel.clone(),
                    e.name.clone(),
                    format!("kept bytes: rtlint {ka}, Slang {kb}"),
                ));
            }
            ours.push(a);
            theirs.push(b);
            entries_compared += 1;
        }
        let depth = |programs: Vec<Program>| {
            let p = Pipeline::from_programs(programs);
            let r = recursion_report(&p);
            let ctx = rtlint::rules::PipelineContext::new(&p, &config);
            format!(
                "{:?} {:?}",
                r.required_depth,
                coded_lines(&rtlint::rules::check_pipeline(&ctx))
            )
        };
        let (x, y) = (depth(ours), depth(theirs));
        if x != y {
            differences.push((
                rel.clone(),
                "(pipeline)".into(),
                format!("depth and pipeline findings: rtlint {x}, Slang {y}"),
            ));
        }
    }
    assert!(entries_compared >= 6, "{entries_compared}");
    let unexplained: Vec<String> = differences
        .iter()
        .filter(|(f, e, how)| {
            !KNOWN_ACROSS_COMPILERS
                .iter()
                .any(|(kf, ke, kw, _)| kf == f && ke == e && how.starts_with(kw))
        })
        .map(|(f, e, how)| format!("{f} `{e}`: {how}"))
        .collect();
    for (f, e, what, why) in KNOWN_ACROSS_COMPILERS {
        assert!(
            differences
                .iter()
                .any(|(df, de, how)| df == f && de == e && how.starts_with(what)),
            "{f} `{e}` no longer differs ({why}): remove it"
        );
    }
    assert!(unexplained.is_empty(), "{}", unexplained.join("\n"));
}
