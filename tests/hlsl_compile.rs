//! Compiles the HLSL test shaders under tests/hlsl/ and validates every module
//! with `spirv-val --target-env vulkan1.2`.

use rtlint::front::hlsl::{self, HlslOptions, Stage};
use std::path::{Path, PathBuf};
use std::process::Command;

fn shader(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/hlsl")
        .join(name)
}

/// Runs spirv-val on `words`; without spirv-val, fails in CI and skips elsewhere
/// (`rtlint_testkit::require`).
fn validate(words: &[u32], what: &str) {
    validate_with(words, what, &[]);
}

fn validate_with(words: &[u32], what: &str, extra: &[&str]) {
    let dir = std::env::temp_dir().join(format!("rtlint-hlsl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{}.spv", what.replace(['/', ':'], "_")));
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(&file, bytes).unwrap();
    let ran = Command::new("spirv-val")
        .args(["--target-env", "vulkan1.2"])
        .args(extra)
        .arg(&file)
        .output();
    let Some(out) = rtlint_testkit::require(&format!("spirv-val (validating {what})"), ran) else {
        return;
    };
    if !out.status.success() {
        let dis = Command::new("spirv-dis")
            .arg(&file)
            .output()
            .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
            .unwrap_or_default();
        panic!(
            "spirv-val rejected {what}:\n{}{}\n{dis}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Compiles `name` per entry point and as a whole file; validates all modules.
fn compile_all(name: &str) -> Vec<(String, Stage)> {
    let path = shader(name);
    let opts = HlslOptions::default();
    let entries = hlsl::compile(&path, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    for e in &entries {
        validate(&e.words, &format!("{name}-{}", e.name));
    }
    let whole = hlsl::compile_file(&path, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
    validate(&whole.words, &format!("{name}-all"));
    entries.into_iter().map(|e| (e.name, e.stage)).collect()
}

#[test]
fn pipeline_raygen_miss_closesthit() {
    let entries = compile_all("pipeline.hlsl");
    assert_eq!(
        entries,
        vec![
            ("RayGen".to_string(), Stage::RayGeneration),
            ("Miss".to_string(), Stage::Miss),
            ("ShadowMiss".to_string(), Stage::Miss),
            ("ClosestHit".to_string(), Stage::ClosestHit),
        ]
    );
}

/// `RTLINT_DUMP=path.hlsl cargo test --test hlsl_compile dump -- --nocapture`
/// writes the whole-file module to /tmp/rtlint-dump.spv for inspection.
#[test]
fn dump() {
    let Ok(p) = std::env::var("RTLINT_DUMP") else {
        return;
    };
    let m = hlsl::compile_file(Path::new(&p), &HlslOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let bytes: Vec<u8> = m.words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write("/tmp/rtlint-dump.spv", bytes).unwrap();
}

#[test]
fn anyhit_alpha_test() {
    let entries = compile_all("anyhit_alpha.hlsl");
    assert_eq!(entries[0], ("AlphaTest".to_string(), Stage::AnyHit));
    assert_eq!(entries[1], ("Shade".to_string(), Stage::ClosestHit));
}

#[test]
fn intersection_sphere_with_attributes() {
    let entries = compile_all("intersection_sphere.hlsl");
    assert_eq!(
        entries[0],
        ("SphereIntersection".to_string(), Stage::Intersection)
    );
    assert_eq!(entries[1], ("SphereHit".to_string(), Stage::ClosestHit));
}

#[test]
fn callable_shaders() {
    let entries = compile_all("callable.hlsl");
    assert_eq!(entries.len(), 4);
    assert_eq!(entries[1], ("Checker".to_string(), Stage::Callable));
}

#[test]
fn ray_query_in_compute() {
    let entries = compile_all("rayquery.hlsl");
    assert_eq!(
        entries,
        vec![("AmbientOcclusion".to_string(), Stage::Compute)]
    );
}

#[test]
fn language_features() {
    let entries = compile_all("language.hlsl");
    assert_eq!(entries, vec![("Main".to_string(), Stage::Compute)]);
}

#[test]
fn resources_bindless_images_records() {
    let entries = compile_all("resources.hlsl");
    assert_eq!(entries.len(), 3);
}

/// The module's instructions as (opcode, operand words); rspirv's loader
/// rejects module-scope `OpExtInst` (the debug info), so this reads words.
fn instructions(words: &[u32]) -> Vec<(u32, Vec<u32>)> {
    let mut out = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let n = (words[i] >> 16) as usize;
        out.push((words[i] & 0xffff, words[i + 1..i + n.max(1)].to_vec()));
        i += n.max(1);
    }
    out
}

fn string_at(ops: &[u32]) -> String {
    let bytes: Vec<u8> = ops.iter().flat_map(|w| w.to_le_bytes()).collect();
    let end = bytes.iter().position(|b| *b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// Ids named `name` by OpName.
fn named(words: &[u32], name: &str) -> Vec<u32> {
    instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == 5 && string_at(&ops[1..]) == name)
        .map(|(_, ops)| ops[0])
        .collect()
}

/// Offsets of a cbuffer's members as the module declares them.
fn member_offsets(words: &[u32], struct_name: &str) -> Vec<u32> {
    let id = named(words, struct_name)[0];
    // OpMemberDecorate (72) struct member Offset (35) value.
    let mut offsets: Vec<(u32, u32)> = instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == 72 && ops[0] == id && ops[2] == 35)
        .map(|(_, ops)| (ops[1], ops[3]))
        .collect();
    offsets.sort_unstable();
    offsets.into_iter().map(|(_, o)| o).collect()
}

#[test]
fn cbuffer_uses_hlsl_packing() {
    let path = shader("cbuffer_packing.hlsl");
    let m = hlsl::compile_file(&path, &HlslOptions::default()).unwrap();
    assert_eq!(
        member_offsets(&m.words, "type.Packed"),
        vec![0, 12, 16, 52, 56, 64, 108]
    );
    validate_with(&m.words, "cbuffer_packing", &["--scalar-block-layout"]);
}

/// `rtlint check` reads HLSL through `front::load`: declarations (struct
/// members included) must carry their own source lines.
#[test]
fn program_sees_hlsl_declaration_positions() {
    use rtlint::front::load;
    use rtlint::program::Decl;
    use rtlint::shader::Language;
    let path = shader("pipeline.hlsl");
    let program = load(&path, Language::Hlsl).unwrap();
    let id_named = |name: &str| {
        program
            .names
            .iter()
            .filter(|(_, n)| n.as_str() == name)
            .map(|(id, _)| *id)
            .min()
            .unwrap()
    };
    let payload = id_named("Payload");
    let at = |d: Decl| program.decl_location(d).map(|l| (l.line, l.column));
    assert_eq!(at(Decl::Type(payload)), Some((14, 21)));
    assert_eq!(at(Decl::Member(payload, 0)), Some((16, 12)));
    assert_eq!(at(Decl::Member(payload, 1)), Some((17, 10)));
    let sky = id_named("sky");
    let loc = program.decl_location(Decl::Func(sky)).unwrap();
    assert!(loc.path.ends_with("common.hlsli"), "{loc:?}");
    assert_eq!((loc.line, loc.column), (8, 8));
}

/// Every shader under tests/hlsl/ (the executed ones too) validates, per
/// entry point and as a whole file.
#[test]
fn every_test_shader_validates() {
    // HLSL cbuffer packing beyond std140 needs scalar block layout.
    const NEEDS_SCALAR: &[&str] = &[
        "cbuffer_packing.hlsl",
        "diff_cbuffer.hlsl",
        "exec_compute.hlsl",
    ];
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hlsl");
    let mut count = 0;
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".hlsl"))
        .collect();
    names.sort();
    for name in &names {
        let extra: &[&str] = if NEEDS_SCALAR.contains(&name.as_str()) {
            &["--scalar-block-layout"]
        } else {
            &[]
        };
        let path = shader(name);
        let opts = HlslOptions::default();
        for e in hlsl::compile(&path, &opts).unwrap_or_else(|e| panic!("{e}")) {
            validate_with(&e.words, &format!("{name}-{}", e.name), extra);
            count += 1;
        }
        let whole = hlsl::compile_file(&path, &opts).unwrap();
        validate_with(&whole.words, &format!("{name}-all"), extra);
        count += 1;
    }
    assert!(count >= 40, "only {count} modules validated");
    eprintln!(
        "{count} modules from {} shaders passed spirv-val",
        names.len()
    );
}

/// Per-entry modules declare only what their entry point uses.
#[test]
fn entry_modules_hold_only_their_globals() {
    let entries = hlsl::compile(&shader("pipeline.hlsl"), &HlslOptions::default()).unwrap();
    let globals = |words: &[u32]| -> Vec<String> {
        let insts = instructions(words);
        // OpVariable (59) at module scope: storage class is not Function (7).
        let vars: Vec<u32> = insts
            .iter()
            .filter(|(op, ops)| *op == 59 && ops[2] != 7)
            .map(|(_, ops)| ops[1])
            .collect();
        let mut names: Vec<String> = insts
            .iter()
            .filter(|(op, ops)| *op == 5 && vars.contains(&ops[0]))
            .map(|(_, ops)| string_at(&ops[1..]))
            .collect();
        names.sort();
        names
    };
    let miss = entries.iter().find(|e| e.name == "Miss").unwrap();
    assert_eq!(
        globals(&miss.words),
        vec!["WorldRayDirectionKHR", "incoming.payload"]
    );
    let gen = entries.iter().find(|e| e.name == "RayGen").unwrap();
    assert_eq!(
        globals(&gen.words),
        vec![
            "Camera",
            "LaunchIdKHR",
            "LaunchSizeKHR",
            "output",
            "payload",
            "scene"
        ]
    );
}

/// A module on its own (as `rtlint compile` writes it) carries declaration
/// positions in NonSemantic.Shader.DebugInfo.100.
#[test]
fn entry_modules_carry_debug_info() {
    use rtlint::program::Decl;
    use rtlint::shader::Language;
    let path = shader("pipeline.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap();
    let gen = entries.iter().find(|e| e.name == "RayGen").unwrap();
    let program = rtlint::program::parse(&gen.words, &path, Language::Hlsl).unwrap();
    let id = |name: &str| {
        program
            .names
            .iter()
            .filter(|(_, n)| n.as_str() == name)
            .map(|(id, _)| *id)
            .min()
            .unwrap()
    };
    let at = |d: Decl| program.decl_location(d).map(|l| (l.line, l.column));
    let payload = id("Payload");
    assert_eq!(at(Decl::Type(payload)), Some((14, 21)));
    assert_eq!(at(Decl::Member(payload, 1)), Some((17, 10)));
    assert_eq!(at(Decl::Var(id("Camera"))), Some((7, 9)));
    assert_eq!(at(Decl::Func(id("RayGen"))), Some((26, 6)));
    // Locals too (DebugLocalVariable + DebugDeclare).
    assert_eq!(at(Decl::Var(id("ray"))), Some((32, 13)));
}

/// The project's HLSL fixture gives the same findings on the same lines when
/// compiled by rtlint as when compiled by Slang (tests/slang.rs): for the
/// entry point's own module and for the whole file.
#[test]
fn payload_fixture_findings_match_slang_lines() {
    use rtlint::shader::Language;
    use std::collections::BTreeSet;
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/hlsl/payloads.hlsl");
    let expected = BTreeSet::from([(2, "RT001"), (2, "RT002"), (4, "RT003")]);
    let findings = |program: &rtlint::program::Program| -> BTreeSet<(u32, &'static str)> {
        rtlint::rules::check_program(program, &rtlint::config::Config::default())
            .iter()
            .map(|d| {
                let p = d.primary.as_ref().expect("positioned");
                assert_eq!(p.location.path.file_name().unwrap(), "payloads.hlsl");
                (p.location.line, d.code.unwrap())
            })
            .collect()
    };
    let entries = hlsl::compile(&src, &HlslOptions::default()).unwrap();
    let gen = entries.iter().find(|e| e.name == "RayGen").unwrap();
    validate(&gen.words, "payloads-RayGen");
    let program =
        rtlint::program::parse(&gen.words, Path::new("payloads.spv"), Language::Spirv).unwrap();
    assert_eq!(findings(&program), expected);
    let whole = rtlint::front::load(&src, Language::Hlsl).unwrap();
    assert_eq!(findings(&whole), expected);
}

/// `#line 200 "virtual.hlsl"` renumbers what follows in the module's debug
/// info: declarations (DebugInfo.100), instructions (OpLine) and so the
/// findings of `rtlint check` land on the renumbered lines of the named file.
#[test]
fn line_directive_renumbers_debug_info_and_findings() {
    use rtlint::program::Decl;
    use rtlint::shader::Language;
    use std::collections::BTreeSet;
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/hlsl/payloads.hlsl");
    let text = format!(
        "#line 200 \"virtual.hlsl\"\n{}",
        std::fs::read_to_string(&fixture).unwrap()
    );
    let mut loader = hlsl::pp::MemLoader::default();
    let path = Path::new("real.hlsl");
    let opts = HlslOptions::default();
    let entries = hlsl::compile_source(path, &text, &mut loader, &opts).unwrap();
    validate(&entries[0].words, "line-directive");
    let program =
        rtlint::program::parse(&entries[0].words, Path::new("out.spv"), Language::Spirv).unwrap();
    let id = |name: &str| {
        program
            .names
            .iter()
            .filter(|(_, n)| n.as_str() == name)
            .map(|(id, _)| *id)
            .min()
            .unwrap()
    };
    let at = |d: Decl| {
        program
            .decl_location(d)
            .map(|l| (l.path.display().to_string(), l.line, l.column))
    };
    let fat = id("SuboptimalPayload");
    // Fixture line 2 (struct) is line 201 after `#line 200` on line 1 of the text.
    assert_eq!(at(Decl::Type(fat)), Some(("virtual.hlsl".into(), 201, 8)));
    assert_eq!(
        at(Decl::Member(fat, 1)),
        Some(("virtual.hlsl".into(), 203, 12))
    );
    assert_eq!(
        at(Decl::Func(id("RayGen"))),
        Some(("virtual.hlsl".into(), 219, 6))
    );
    let findings = rtlint::rules::check_program(&program, &rtlint::config::Config::default());
    let primary: BTreeSet<(String, u32, &str)> = findings
        .iter()
        .map(|d| {
            let l = &d.primary.as_ref().expect("positioned").location;
            (l.path.display().to_string(), l.line, d.code.unwrap())
        })
        .collect();
    let v = |l, c| ("virtual.hlsl".to_string(), l, c);
    assert_eq!(
        primary,
        BTreeSet::from([v(201, "RT001"), v(201, "RT002"), v(203, "RT003")])
    );
    // The TraceRay call (fixture line 31) is evidence placed through OpLine.
    let secondary: BTreeSet<(String, u32)> = findings
        .iter()
        .flat_map(|d| d.secondary.iter())
        .map(|l| (l.location.path.display().to_string(), l.location.line))
        .collect();
    assert!(
        secondary.contains(&("virtual.hlsl".to_string(), 230)),
        "{secondary:?}"
    );
    // Whole-file modules (what `rtlint check` reads) agree.
    let whole = hlsl::compile_source_whole(path, &text, &mut loader, &opts).unwrap();
    assert!(whole
        .decls
        .iter()
        .any(|(_, l)| l.path == Path::new("virtual.hlsl") && l.line == 201));
}

/// Interface facts of one entry point: execution model and modes, and each
/// Input/Output variable as "class decoration, ..." (`BuiltIn`, `Location`,
/// `Flat`). Read from the words directly: rspirv's loader refuses the
/// NonSemantic debug instructions among the globals.
fn interface(words: &[u32], entry: &str) -> (String, Vec<String>, BTreeSet<String>) {
    use spirv::{BuiltIn, Decoration, ExecutionMode, ExecutionModel, StorageClass};
    let mut insts = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let n = (words[i] >> 16) as usize;
        insts.push((words[i] & 0xffff, &words[i + 1..i + n]));
        i += n;
    }
    let string = |w: &[u32]| {
        let bytes: Vec<u8> = w.iter().flat_map(|x| x.to_le_bytes()).collect();
        let end = bytes.iter().position(|b| *b == 0).unwrap();
        String::from_utf8(bytes[..end].to_vec()).unwrap()
    };
    // By name, or the only one (Slang names a lone entry point `main`).
    let eps: Vec<&[u32]> = insts
        .iter()
        .filter(|(op, _)| *op == 15)
        .map(|(_, o)| *o)
        .collect();
    let ep = match eps.iter().find(|o| string(&o[2..]) == entry) {
        Some(ep) => *ep,
        None if eps.len() == 1 => eps[0],
        None => panic!("no entry point {entry}"),
    };
    let model = format!("{:?}", ExecutionModel::from_u32(ep[0]).unwrap());
    let id = ep[1];
    let name_words = string(&ep[2..]).len() / 4 + 1;
    let globals = &ep[2 + name_words..];
    let mut modes: Vec<String> = insts
        .iter()
        .filter(|(op, o)| *op == 16 && o[0] == id)
        .map(|(_, o)| format!("{:?}", ExecutionMode::from_u32(o[1]).unwrap()))
        .collect();
    modes.sort();
    let mut io = BTreeSet::new();
    for (_, v) in insts
        .iter()
        .filter(|(op, o)| *op == 59 && globals.contains(&o[1]))
    {
        let class = StorageClass::from_u32(v[2]).unwrap();
        if !matches!(class, StorageClass::Input | StorageClass::Output) {
            continue;
        }
        let mut facts: Vec<String> = insts
            .iter()
            .filter(|(op, o)| *op == 71 && o[0] == v[1])
            .map(|(_, o)| match Decoration::from_u32(o[1]).unwrap() {
                Decoration::BuiltIn => format!("BuiltIn {:?}", BuiltIn::from_u32(o[2]).unwrap()),
                Decoration::Location => format!("Location {}", o[2]),
                d => format!("{d:?}"),
            })
            .collect();
        facts.sort();
        io.insert(format!("{class:?} {}", facts.join(", ")));
    }
    (model, modes, io)
}

/// Opcodes in `words`.
fn opcodes(words: &[u32]) -> Vec<u32> {
    let mut ops = Vec::new();
    let mut i = 5;
    while i < words.len() {
        ops.push(words[i] & 0xffff);
        i += (words[i] >> 16) as usize;
    }
    ops
}

use std::collections::BTreeSet;

/// A pixel shader with semantics (struct members flattened, SV_Position,
/// SV_IsFrontFace, SV_Target[n] from the return struct and an `out`
/// parameter) and every derivative intrinsic validates, and has the interface
/// Slang gives the same shader.
#[test]
fn pixel_shader_semantics_and_derivatives() {
    let entries = compile_all("pixel.hlsl");
    assert_eq!(
        entries,
        vec![
            ("Shade".to_string(), Stage::Fragment),
            ("Explicit".to_string(), Stage::Fragment)
        ]
    );
    let path = shader("pixel.hlsl");
    let ours = hlsl::compile(&path, &HlslOptions::default()).unwrap();
    let shade = interface(&ours[0].words, "Shade");
    let s = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
    assert_eq!(shade.0, "Fragment");
    assert_eq!(shade.1, vec!["OriginUpperLeft"]);
    assert_eq!(
        shade.2,
        s(&[
            "Input BuiltIn FragCoord",
            "Input BuiltIn FrontFacing",
            "Input Location 0",
            "Input Location 1",
            "Input Flat, Location 2",
            "Input Location 3",
            "Output Location 0",
            "Output Location 1",
            "Output Location 2",
        ])
    );
    let explicit = interface(&ours[1].words, "Explicit");
    assert_eq!(
        explicit.2,
        s(&["Input Location 1", "Input Location 3", "Output Location 0",])
    );
    use spirv::Op;
    let ops = opcodes(&ours[0].words);
    for op in [
        Op::DPdx,
        Op::DPdy,
        Op::DPdxFine,
        Op::DPdyFine,
        Op::DPdxCoarse,
        Op::DPdyCoarse,
        Op::Fwidth,
    ] {
        assert!(ops.contains(&(op as u32)), "{op:?} missing");
    }
    assert!(opcodes(&ours[1].words).contains(&(Op::ImageSampleImplicitLod as u32)));
    let kills = opcodes(&ours[0].words)
        .iter()
        .filter(|o| **o == Op::Kill as u32)
        .count();
    assert_eq!(kills, 2, "`discard` in the entry body and in the helper");
    // The fine and coarse forms need DerivativeControl; the plain ones do not.
    let caps = |w: &[u32]| {
        let mut caps = Vec::new();
        let mut i = 5;
        while i < w.len() {
            if w[i] & 0xffff == Op::Capability as u32 {
                caps.push(w[i + 1]);
            }
            i += (w[i] >> 16) as usize;
        }
        caps
    };
    let derivative_control = spirv::Capability::DerivativeControl as u32;
    assert!(caps(&ours[0].words).contains(&derivative_control));
    assert!(!caps(&ours[1].words).contains(&derivative_control));
    // Slang compiles the same file to the same interface.
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    for (k, name) in ["Shade", "Explicit"].iter().enumerate() {
        let theirs = slang.compile_hlsl(&path, name, "pixel", &[]).unwrap();
        let (model, modes, io) = interface(&theirs, name);
        let mine = interface(&ours[k].words, name);
        assert_eq!((model, modes, io), mine, "{name}: Slang vs rtlint");
    }
}
