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
    validate_by("spirv-val", words, what, extra)
}

/// Shaders using SPIR-V newer than Debian bookworm's spirv-val (2023.1)
/// knows: ray-tracing position fetch, shader invocation reorder.
const NEEDS_NEW_VALIDATOR: &[&str] = &[
    "position_fetch.hlsl",
    "exec_position_fetch.hlsl",
    "ser.hlsl",
    "exec_ser.hlsl",
];

/// Validates a module that needs a spirv-val of 2024 or later
/// (`rtlint_testkit::new_spirv_val`), under the skip policy.
fn validate_new(words: &[u32], what: &str) {
    let found = rtlint_testkit::new_spirv_val();
    if let Some(v) = rtlint_testkit::require(&format!("a new spirv-val (validating {what})"), found)
    {
        validate_by(&v, words, what, &[]);
    }
}

fn validate_by(validator: &str, words: &[u32], what: &str, extra: &[&str]) {
    let dir = std::env::temp_dir().join(format!("rtlint-hlsl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{}.spv", what.replace(['/', ':'], "_")));
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    std::fs::write(&file, bytes).unwrap();
    let ran = Command::new(validator)
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
    let m =
        hlsl::compile_file(&shader("cbuffer_struct_tail.hlsl"), &HlslOptions::default()).unwrap();
    assert_eq!(
        member_offsets(&m.words, "type.AfterStruct"),
        vec![0, 72, 76]
    );
    validate_with(&m.words, "cbuffer_struct_tail", &["--scalar-block-layout"]);
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

/// Shaders written for DXC's `-enable-16bit-types`.
const SIXTEEN_BIT: &[&str] = &[
    "half.hlsl",
    "exec_half.hlsl",
    "spec_half.hlsl",
    "bits_half.hlsl",
];

/// Every shader under tests/hlsl/ (the executed ones too) validates, per
/// entry point and as a whole file.
#[test]
fn every_test_shader_validates() {
    // HLSL cbuffer packing beyond std140 needs scalar block layout.
    const NEEDS_SCALAR: &[&str] = &[
        "cbuffer_packing.hlsl",
        "cbuffer_struct_tail.hlsl",
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
        let opts = HlslOptions {
            enable_16bit_types: SIXTEEN_BIT.contains(&name.as_str()),
            ..Default::default()
        };
        let check = |words: &[u32], what: &str| {
            if NEEDS_NEW_VALIDATOR.contains(&name.as_str()) {
                validate_new(words, what)
            } else {
                validate_with(words, what, extra)
            }
        };
        for e in hlsl::compile(&path, &opts).unwrap_or_else(|e| panic!("{e}")) {
            check(&e.words, &format!("{name}-{}", e.name));
            count += 1;
        }
        let whole = hlsl::compile_file(&path, &opts).unwrap();
        check(&whole.words, &format!("{name}-all"));
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
            // The payload variable is named after the variable traced.
            "p",
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

/// The operands of every `OpFunctionCall` (57) of the module: result type, id,
/// function, arguments.
fn calls(words: &[u32]) -> Vec<Vec<u32>> {
    instructions(words)
        .into_iter()
        .filter(|(op, _)| *op == 57)
        .map(|(_, ops)| ops)
        .collect()
}

#[test]
fn default_parameter_values_fill_left_out_arguments() {
    let entries = compile_all("default_params.hlsl");
    assert_eq!(entries, vec![("Main".to_string(), Stage::Compute)]);
    let m = hlsl::compile_file(&shader("default_params.hlsl"), &HlslOptions::default()).unwrap();
    let scaled = named(&m.words, "scaled")[0];
    let bump = named(&m.words, "Counter::bump")[0];
    let all = calls(&m.words);
    // Every call passes every parameter, whether written or defaulted.
    let to = |f: u32| -> Vec<usize> {
        all.iter()
            .filter(|c| c[2] == f)
            .map(|c| c.len() - 3)
            .collect()
    };
    assert_eq!(to(scaled), vec![3, 3, 3]);
    assert_eq!(to(bump), vec![2, 2]);
}

#[test]
fn forward_declarations_classes_static_and_out_of_line_methods() {
    let entries = compile_all("records.hlsl");
    assert_eq!(entries, vec![("Main".to_string(), Stage::Compute)]);
    let m = hlsl::compile_file(&shader("records.hlsl"), &HlslOptions::default()).unwrap();
    let all = calls(&m.words);
    let args_of = |name: &str| -> Vec<usize> {
        let f = named(&m.words, name)[0];
        all.iter()
            .filter(|c| c[2] == f)
            .map(|c| c.len() - 3)
            .collect()
    };
    // Static methods take no `this`; the out-of-line `pack` does.
    assert_eq!(args_of("GbufferData::make"), vec![2]);
    assert_eq!(args_of("GbufferData::channel"), vec![1, 1, 1]);
    assert_eq!(args_of("GbufferData::pack"), vec![1]);
    // `luminance` is found through `using namespace shading` (twice).
    assert_eq!(args_of("shading::luminance"), vec![1, 1]);
}

#[test]
fn subobjects_are_parsed_and_exposed() {
    let entries = compile_all("subobjects.hlsl");
    assert_eq!(entries.len(), 3);
    let m = hlsl::compile_file(&shader("subobjects.hlsl"), &HlslOptions::default()).unwrap();
    let s = &m.subobjects;
    assert_eq!(s.shader_configs.len(), 1);
    assert_eq!(s.shader_configs[0].name, "ShaderConfig");
    assert_eq!(s.shader_configs[0].max_payload_bytes, 16);
    assert_eq!(s.shader_configs[0].max_attribute_bytes, 8);
    assert_eq!(s.shader_configs[0].location.line, 19);
    assert_eq!(s.max_recursion_depth(), Some(3));
    assert_eq!(s.pipeline_configs[0].flags, 0x200);
    let groups: Vec<_> = s
        .hit_groups
        .iter()
        .map(|g| {
            (
                g.name.as_str(),
                g.procedural,
                g.any_hit.as_deref(),
                g.closest_hit.as_deref(),
                g.intersection.as_deref(),
            )
        })
        .collect();
    assert_eq!(
        groups,
        vec![
            ("Opaque", false, None, Some("ShadeHit"), None),
            (
                "Spheres",
                true,
                Some("SphereAny"),
                Some("ShadeHit"),
                Some("SphereHit")
            ),
        ]
    );
    assert_eq!(s.associations[0].subobject, "ShaderConfig");
    assert_eq!(
        s.associations[0].exports,
        vec!["Gen", "Background", "ShadeHit"]
    );
    assert_eq!(s.root_signatures.len(), 2);
    assert_eq!(
        s.root_signatures[0].text,
        "DescriptorTable(UAV(u0)), SRV(t0)"
    );
    assert!(s.root_signatures[1].local);
}

#[test]
fn helpers_returning_resources_are_inlined() {
    let entries = compile_all("resource_helpers.hlsl");
    assert_eq!(entries, vec![("Main".to_string(), Stage::Compute)]);
    let m = hlsl::compile_file(&shader("resource_helpers.hlsl"), &HlslOptions::default()).unwrap();
    // No function returns a resource: the helpers are not functions of the module.
    for helper in ["material", "palette", "raw", "defaultSampler"] {
        assert!(named(&m.words, helper).is_empty(), "{helper} was emitted");
    }
    assert!(calls(&m.words).is_empty());
}

#[test]
fn position_fetch_is_a_built_in_input_with_its_extension_and_capability() {
    let path = shader("position_fetch.hlsl");
    let opts = HlslOptions::default();
    let entries = hlsl::compile(&path, &opts).unwrap();
    for e in &entries {
        validate_new(&e.words, &format!("position_fetch-{}", e.name));
    }
    let hit = &entries[0];
    assert_eq!(hit.stage, Stage::ClosestHit);
    let var = named(&hit.words, "gl_HitTriangleVertexPositions")[0];
    let insts = instructions(&hit.words);
    // OpCapability (17) RayTracingPositionFetchKHR (5336).
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 5336));
    // OpExtension (10).
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 10 && string_at(ops) == "SPV_KHR_ray_tracing_position_fetch"));
    // OpDecorate (71) var BuiltIn (11) HitTriangleVertexPositionsKHR (5335).
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 71 && ops[..] == [var, 11, 5335]));
    // OpVariable (59) of storage class Input (1), never a null constant (46).
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 59 && ops[1] == var && ops[2] == 1));
    assert!(!insts.iter().any(|(op, _)| *op == 46));
    // The miss shader does not use it: no capability, no extension there.
    let miss = &entries[1];
    assert!(!instructions(&miss.words)
        .iter()
        .any(|(op, ops)| *op == 17 && ops[0] == 5336));
}

#[test]
fn ext_builtin_output_is_an_output_built_in_the_shader_writes() {
    let path = shader("ext_builtin_output.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap();
    for e in &entries {
        validate(&e.words, &format!("ext_builtin_output-{}", e.name));
    }
    let ps = entries.iter().find(|e| e.name == "Stencil").unwrap();
    let var = named(&ps.words, "gl_FragStencilRefARB")[0];
    let insts = instructions(&ps.words);
    // OpCapability (17) StencilExportEXT (5013), OpExtension (10).
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 5013));
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 10 && string_at(ops) == "SPV_EXT_shader_stencil_export"));
    // OpDecorate (71) var BuiltIn (11) FragStencilRefEXT (5014).
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 71 && ops[..] == [var, 11, 5014]));
    // OpVariable (59) of storage class Output (3), stored to (OpStore, 62),
    // and in the entry point's interface (OpEntryPoint, 15).
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 59 && ops[1] == var && ops[2] == 3));
    assert!(insts.iter().any(|(op, ops)| *op == 62 && ops[0] == var));
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 15 && ops[2..].contains(&var)));
    let plain = entries.iter().find(|e| e.name == "Plain").unwrap();
    assert!(named(&plain.words, "gl_FragStencilRefARB").is_empty());
    assert!(!instructions(&plain.words)
        .iter()
        .any(|(op, ops)| *op == 17 && ops[0] == 5013));
}

#[test]
fn ext_instruction_calls_are_the_instructions() {
    let path = shader("ext_instruction.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap();
    let m = &entries[0];
    validate(&m.words, "ext_instruction-main");
    let insts = instructions(&m.words);
    let result_of = |opcode: u32| -> Vec<Vec<u32>> {
        insts
            .iter()
            .filter(|(op, _)| *op == opcode)
            .map(|(_, ops)| ops.clone())
            .collect()
    };
    // OpExtInstImport (11) "GLSL.std.450"; OpExtInst (12) of it, Sin (13),
    // on `x` (loaded from its variable).
    let glsl = result_of(11)
        .into_iter()
        .find(|ops| string_at(&ops[1..]) == "GLSL.std.450")
        .unwrap()[0];
    let x = named(&m.words, "x")[0];
    let loads_of_x: Vec<u32> = result_of(61)
        .into_iter()
        .filter(|ops| ops[2] == x)
        .map(|ops| ops[1])
        .collect();
    assert!(result_of(12)
        .iter()
        .any(|ops| ops[2] == glsl && ops[3] == 13 && loads_of_x.contains(&ops[4])));
    // The void one: OpExtInst %void of "NonSemantic.rtlint.test", 7.
    let set = result_of(11)
        .into_iter()
        .find(|ops| string_at(&ops[1..]) == "NonSemantic.rtlint.test")
        .unwrap()[0];
    let void = result_of(19)[0][0];
    assert!(result_of(12)
        .iter()
        .any(|ops| ops[0] == void && ops[2] == set && ops[3] == 7 && ops.len() == 5));
    // OpReadClockKHR (5056) with its capability (5055) and extension.
    assert_eq!(result_of(5056).len(), 1);
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 5055));
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 10 && string_at(ops) == "SPV_KHR_shader_clock"));
    // OpCompositeExtract (81): type, result, vector, literal 2.
    assert!(result_of(81)
        .iter()
        .any(|ops| ops.len() == 4 && ops[3] == 2));
    // OpLoad (61) of `x`'s pointer: the `vk::ext_reference` operand.
    assert!(loads_of_x.len() >= 2, "{loads_of_x:?}");
    // OpMemoryBarrier (225): no result, two id operands.
    let barriers = result_of(225);
    assert_eq!(barriers.len(), 1);
    assert_eq!(barriers[0].len(), 2);
}

/// (set, binding) of the variable named `name`.
fn binding_of(words: &[u32], name: &str) -> (u32, u32) {
    let id = named(words, name)[0];
    let deco = |d: u32| {
        instructions(words)
            .into_iter()
            .find(|(op, ops)| *op == 71 && ops[0] == id && ops[1] == d)
            .map(|(_, ops)| ops[2])
            .unwrap()
    };
    (deco(34), deco(33))
}

#[test]
fn space_only_registers_and_static_const_array_sizes() {
    compile_all("bindings_and_sizes.hlsl");
    let m =
        hlsl::compile_file(&shader("bindings_and_sizes.hlsl"), &HlslOptions::default()).unwrap();
    assert_eq!(binding_of(&m.words, "bindlessTextures"), (99, 0));
    assert_eq!(binding_of(&m.words, "bindlessBuffers"), (98, 0));
    assert_eq!(binding_of(&m.words, "Extra"), (7, 0));
    assert_eq!(binding_of(&m.words, "output"), (0, 0));
    assert_eq!(binding_of(&m.words, "Params"), (0, 0));
}

#[test]
fn windows_include_paths_and_case_mismatches() {
    compile_all("windows_includes.hlsl");
    let m = hlsl::compile_file(&shader("windows_includes.hlsl"), &HlslOptions::default()).unwrap();
    // One warning: the include whose case differs (the second matches exactly).
    assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
    assert!(m.warnings[0].contains(
        "windows_includes.hlsl:4:2: warning: include `include/util/hlslcompat.hlsli` matched"
    ));
    assert!(m.warnings[0].ends_with("include/Util/HlslCompat.hlsli` only when ignoring case"));
    assert_eq!(named(&m.words, "srgbToLinear").len(), 1);
}

#[test]
fn classic_entry_points_take_their_stage_from_the_command_line() {
    let path = shader("classic/pixel_rayquery.hlsl");
    let opts = HlslOptions {
        entry: Some("main".into()),
        stage: hlsl::parse_stage("ps_6_5").unwrap(),
        ..Default::default()
    };
    let entries = hlsl::compile(&path, &opts).unwrap();
    assert_eq!(entries.len(), 1);
    assert_eq!(
        (entries[0].name.as_str(), entries[0].stage),
        ("main", Stage::Fragment)
    );
    validate(&entries[0].words, "classic-pixel");
    let whole = hlsl::compile_file(&path, &opts).unwrap();
    validate(&whole.words, "classic-pixel-all");
    // Without the stage there is no entry point.
    let e = hlsl::compile(&path, &HlslOptions::default()).unwrap_err();
    assert!(e.to_string().contains("-E main -T ps_6_5"), "{e}");
    // Profiles and names.
    assert_eq!(hlsl::parse_stage("cs_6_0"), Ok(Some(Stage::Compute)));
    assert_eq!(hlsl::parse_stage("lib_6_3"), Ok(None));
    assert_eq!(hlsl::parse_stage("closesthit"), Ok(Some(Stage::ClosestHit)));
    assert!(hlsl::parse_stage("vs_6_0")
        .unwrap_err()
        .starts_with("not supported: vertex"));
    assert!(hlsl::parse_stage("ps_x").is_err());
}

/// `OpMemberDecorate` (72) of `struct_name`: (member, decoration) pairs.
fn member_decorations(words: &[u32], struct_name: &str) -> Vec<(u32, u32)> {
    let id = named(words, struct_name)[0];
    instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == 72 && ops[0] == id)
        .map(|(_, ops)| (ops[1], ops[2]))
        .collect()
}

#[test]
fn pack_matrix_pragma_sets_the_default_matrix_layout() {
    compile_all("pack_matrix.hlsl");
    let m = hlsl::compile_file(&shader("pack_matrix.hlsl"), &HlslOptions::default()).unwrap();
    // HLSL row major is SPIR-V ColMajor (5), HLSL column major RowMajor (4).
    let majors = |s: &str| -> Vec<(u32, u32)> {
        member_decorations(&m.words, s)
            .into_iter()
            .filter(|(_, d)| *d == 4 || *d == 5)
            .collect()
    };
    assert_eq!(majors("type.Camera"), vec![(0, 5), (1, 4)]);
    assert_eq!(majors("Instance"), vec![(0, 5)]);
    assert_eq!(majors("type.Later"), vec![(0, 4)]);
    // A buffer of matrices: the layout is on the block's member.
    let ids = named(&m.words, "type.StructuredBuffer");
    let decorated = |d: u32| {
        instructions(&m.words)
            .iter()
            .any(|(op, ops)| *op == 72 && ids.contains(&ops[0]) && ops[1] == 0 && ops[2] == d)
    };
    // RowMajor (4) and MatrixStride (7).
    assert!(decorated(4) && decorated(7));
}

/// Member names of the struct named `name`, by `OpMemberName` (6).
fn member_names(words: &[u32], name: &str) -> Vec<String> {
    let id = named(words, name)[0];
    instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == 6 && ops[0] == id)
        .map(|(_, ops)| string_at(&ops[2..]))
        .collect()
}

#[test]
fn static_members_nested_structs_and_inheritance() {
    compile_all("nested_records.hlsl");
    let m = hlsl::compile_file(&shader("nested_records.hlsl"), &HlslOptions::default()).unwrap();
    assert_eq!(
        member_names(&m.words, "BrdfSample"),
        vec!["value", "pdf", "direction"]
    );
    assert_eq!(member_names(&m.words, "L1::Packed"), vec!["c"]);
    // The inherited method runs on the derived struct.
    assert_eq!(named(&m.words, "BrdfSample::valueOverPdf").len(), 1);
    assert_eq!(named(&m.words, "L1::Packed::Unpack").len(), 1);
}

/// Values of the 32-bit `OpConstant`s (43) of the module.
fn constants(words: &[u32]) -> Vec<u32> {
    instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == 43 && ops.len() == 3)
        .map(|(_, ops)| ops[2])
        .collect()
}

#[test]
fn sizeof_msvc_spellings_and_functional_struct_casts() {
    compile_all("sizeof_and_casts.hlsl");
    let m = hlsl::compile_file(&shader("sizeof_and_casts.hlsl"), &HlslOptions::default()).unwrap();
    let c = constants(&m.words);
    // sizeof(float3) + sizeof(Mixed) * 100 + sizeof(float4x4) * 10000, folded.
    assert!(c.contains(&(12 + 32 * 100 + 64 * 10000)), "{c:?}");
    // META_COUNT: 3 * sizeof(uint).
    assert!(c.contains(&12));
    // 1.#INF.
    assert!(c.contains(&f32::INFINITY.to_bits()));
}

#[test]
fn functions_are_specialized_on_their_buffer_arguments() {
    compile_all("buffer_params.hlsl");
    let m = hlsl::compile_file(&shader("buffer_params.hlsl"), &HlslOptions::default()).unwrap();
    // One copy per distinct buffer: indicesA and indicesB.
    assert_eq!(named(&m.words, "centroid").len(), 2);
    assert_eq!(named(&m.words, "loadTriangle").len(), 2);
    // Textures and samplers stay parameters: one `shade`, with 3 parameters.
    assert_eq!(named(&m.words, "shade").len(), 1);
    let insts = instructions(&m.words);
    // No OpFunctionParameter (55) is a StorageBuffer (12) pointer (32).
    let sb_ptrs: Vec<u32> = insts
        .iter()
        .filter(|(op, ops)| *op == 32 && ops[1] == 12)
        .map(|(_, ops)| ops[0])
        .collect();
    assert!(!insts
        .iter()
        .any(|(op, ops)| *op == 55 && sb_ptrs.contains(&ops[0])));
}

#[test]
fn templates_are_instantiated_per_argument_list() {
    compile_all("templates.hlsl");
    let m = hlsl::compile_file(&shader("templates.hlsl"), &HlslOptions::default()).unwrap();
    for name in [
        "interpolate<float3>",
        "interpolate<float2>",
        "sumFirst<float,3>",
        "sumFirst<uint,2>",
        "average<4>",
        "average<8>",
        "Pair<float3>",
        "Pair<uint>",
        "Pair<float3>::sum",
        "Sampler::next<2>",
        "Sampler::next<3>",
    ] {
        assert_eq!(named(&m.words, name).len(), 1, "{name}");
    }
    // The templates themselves are not functions of the module.
    assert!(named(&m.words, "interpolate").is_empty());
    assert!(named(&m.words, "anyHit").is_empty());
    assert_eq!(
        member_names(&m.words, "Pair<uint>"),
        vec!["first", "second"]
    );
}

#[test]
fn local_resource_names_cube_arrays_and_function_like_defines() {
    compile_all("resource_locals.hlsl");
    let m = hlsl::compile_file(&shader("resource_locals.hlsl"), &HlslOptions::default()).unwrap();
    let insts = instructions(&m.words);
    // OpCapability (17) SampledCubeArray (45).
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 45));
    // No function variable holds a resource: `albedo` and `s` are names only.
    assert!(named(&m.words, "albedo").is_empty());
    // 0x1.0p-10 and 0x1.8p4 are exact.
    let c = constants(&m.words);
    assert!(c.contains(&(2f32.powi(-10)).to_bits()));
    assert!(c.contains(&24f32.to_bits()));

    // `-D NAME(x)=...` defines a function-like macro.
    let mut loader = rtlint::front::hlsl::pp::MemLoader::default();
    let src = "VK_IMAGE_FORMAT(\"rgba8\") RWTexture2D<float4> img;\n[numthreads(1,1,1)] void m() { img[uint2(0, 0)] = 1; }";
    let opts = HlslOptions {
        defines: vec![(
            "VK_IMAGE_FORMAT(x)".into(),
            "[[vk::image_format(x)]]".into(),
        )],
        ..Default::default()
    };
    let m = hlsl::compile_source_whole(Path::new("d.hlsl"), src, &mut loader, &opts).unwrap();
    validate(&m.words, "function-like-define");
    // OpTypeImage (25) ... format Rgba8 (4).
    assert!(instructions(&m.words)
        .iter()
        .any(|(op, ops)| *op == 25 && ops[7] == 4));
}

#[test]
fn hlsl_2021_operators_local_structs_and_sizeof_of_names() {
    compile_all("hlsl2021.hlsl");
    let m = hlsl::compile_file(&shader("hlsl2021.hlsl"), &HlslOptions::default()).unwrap();
    assert_eq!(named(&m.words, "LinearDepth::operator[]").len(), 1);
    assert_eq!(
        member_names(&m.words, "Sample"),
        vec!["direction", "weight"]
    );
    let c = constants(&m.words);
    // arraysize(directions) = 72 / 12 = 6, folded; sizeof(best) = 16.
    assert!(c.contains(&6) && c.contains(&16), "{c:?}");
}

#[test]
fn wave_intrinsics_are_group_non_uniform_instructions() {
    let entries = compile_all("wave.hlsl");
    assert_eq!(entries.len(), 2);
    let m = hlsl::compile_file(&shader("wave.hlsl"), &HlslOptions::default()).unwrap();
    let ops: std::collections::BTreeSet<u32> = instructions(&m.words)
        .into_iter()
        .map(|(op, _)| op)
        .filter(|op| (333..=366).contains(op))
        .collect();
    // Elect 333, All 334, Any 335, AllEqual 336, BroadcastFirst 338, Ballot 339,
    // BallotBitCount 342, Shuffle 345, FAdd 350, IMul 351, UMin 354, FMax 358,
    // BitwiseAnd/Or/Xor 359-361.
    for op in [
        333, 334, 335, 336, 338, 339, 342, 345, 350, 351, 354, 358, 359, 360, 361,
    ] {
        assert!(ops.contains(&op), "missing opcode {op}: {ops:?}");
    }
    // Subgroup scope (3) on every instruction: checked by spirv-val; the lane
    // index is the SubgroupLocalInvocationId (41) built-in.
    assert!(instructions(&m.words)
        .iter()
        .any(|(op, ops)| *op == 71 && ops[1] == 11 && ops[2] == 41));
}

#[test]
fn comparison_samplers_sample_with_a_depth_reference() {
    compile_all("shadow_compare.hlsl");
    let m = hlsl::compile_file(&shader("shadow_compare.hlsl"), &HlslOptions::default()).unwrap();
    let ops: Vec<u32> = instructions(&m.words)
        .into_iter()
        .map(|(op, _)| op)
        .collect();
    // OpImageSampleDrefImplicitLod (89) once, OpImageSampleDrefExplicitLod (90) twice.
    assert_eq!(ops.iter().filter(|o| **o == 89).count(), 1);
    assert_eq!(ops.iter().filter(|o| **o == 90).count(), 2);
}

#[test]
fn shader_execution_reordering_uses_nv_invocation_reorder() {
    let path = shader("ser.hlsl");
    let opts = HlslOptions::default();
    let entries = hlsl::compile(&path, &opts).unwrap();
    for e in &entries {
        validate_new(&e.words, &format!("ser-{}", e.name));
    }
    let gen = &entries[0];
    assert_eq!(gen.stage, Stage::RayGeneration);
    let insts = instructions(&gen.words);
    let count = |op: u32| insts.iter().filter(|(o, _)| *o == op).count();
    // OpCapability ShaderInvocationReorderNV (5383), OpTypeHitObjectNV (5281),
    // OpHitObjectTraceRayNV (5260), OpHitObjectRecordMissNV (5263),
    // OpHitObjectRecordEmptyNV (5259), OpHitObjectExecuteShaderNV (5264),
    // OpReorderThreadWithHitObjectNV (5279), OpReorderThreadWithHintNV (5280).
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 5383));
    assert_eq!(count(5281), 1);
    assert_eq!(count(5260), 1);
    assert_eq!(count(5263), 1);
    assert_eq!(count(5264), 2);
    assert_eq!(count(5279), 2);
    assert_eq!(count(5280), 1);
    assert!(count(5259) >= 1);
    // `materialOf(hit)` is given the hit object's variable itself.
    let hit = named(&gen.words, "hit")[0];
    let helper = named(&gen.words, "materialOf")[0];
    assert!(calls(&gen.words)
        .iter()
        .any(|c| c[2] == helper && c[3] == hit));
    // The hit shaders do not reorder.
    assert!(!instructions(&entries[1].words)
        .iter()
        .any(|(op, ops)| *op == 17 && ops[0] == 5383));
}

#[test]
fn int64_types_layouts_literals_and_conversions() {
    compile_all("int64.hlsl");
    let m = hlsl::compile_file(&shader("int64.hlsl"), &HlslOptions::default()).unwrap();
    let insts = instructions(&m.words);
    // OpCapability Int64 (11).
    assert!(insts.iter().any(|(op, ops)| *op == 17 && ops[0] == 11));
    // 8-byte members: offsets 0, 8, 16.
    assert_eq!(member_offsets(&m.words, "Range"), vec![0, 8, 16]);
    // 64-bit constants (OpConstant with two value words): 5000000000 and -7 sign-extended.
    let wide: Vec<u64> = insts
        .iter()
        .filter(|(op, ops)| *op == 43 && ops.len() == 4)
        .map(|(_, ops)| ops[2] as u64 | (ops[3] as u64) << 32)
        .collect();
    assert!(wide.contains(&5_000_000_000), "{wide:?}");
    assert!(wide.contains(&(-7i64 as u64)), "{wide:?}");
    // Width changes: OpUConvert (113) and OpSConvert (114).
    assert!(insts.iter().any(|(op, _)| *op == 113));
    assert!(insts.iter().any(|(op, _)| *op == 114));
}

#[test]
fn ray_queries_are_passed_to_helpers_as_their_variable() {
    compile_all("rayquery_params.hlsl");
    let m = hlsl::compile_file(&shader("rayquery_params.hlsl"), &HlslOptions::default()).unwrap();
    let insts = instructions(&m.words);
    // OpTypeRayQueryKHR (4472), a Function (7) pointer (32) to it, and a
    // parameter (55) of that pointer type in both helpers.
    let rq = insts
        .iter()
        .find(|(op, _)| *op == 4472)
        .map(|(_, o)| o[0])
        .unwrap();
    let ptr = insts
        .iter()
        .find(|(op, o)| *op == 32 && o[1] == 7 && o[2] == rq)
        .map(|(_, o)| o[0])
        .unwrap();
    assert_eq!(
        insts
            .iter()
            .filter(|(op, o)| *op == 55 && o[0] == ptr)
            .count(),
        2
    );
    assert_eq!(named(&m.words, "committed<1>").len(), 1);
}

/// `rtlint check` and `rtlint compile` take the entry point and its stage.
#[test]
fn cli_names_a_classic_entry_point_with_its_stage() {
    let file = shader("classic/pixel_rayquery.hlsl");
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_rtlint"))
            .args(args)
            .arg(&file)
            .env("NO_COLOR", "1")
            .env(
                "RTLINT_CACHE_DIR",
                std::env::temp_dir().join("rtlint-test-cache"),
            )
            .output()
            .unwrap()
    };
    let ok = run(&["check", "-E", "main", "-T", "ps_6_5"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stdout)
    );
    // Without -E it has no entry point: a header nothing includes, a note
    // that says how to name it.
    let none = run(&["check"]);
    assert_eq!(none.status.code(), Some(0));
    let said = String::from_utf8_lossy(&none.stdout);
    assert!(
        said.contains("note: no entry point") && said.contains("-E main -T ps_6_5"),
        "{said}"
    );
    let bad = run(&["check", "-E", "main", "-T", "vs_6_0"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("not supported: vertex shaders"));
    let out = std::env::temp_dir().join(format!("rtlint-classic-{}.spv", std::process::id()));
    let compiled = Command::new(env!("CARGO_BIN_EXE_rtlint"))
        .args(["compile", "-E", "main", "-T", "ps_6_5", "-o"])
        .arg(&out)
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        compiled.status.success(),
        "{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    let bytes = std::fs::read(&out).unwrap();
    let words: Vec<u32> = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    // OpEntryPoint (15) Fragment (4) named main.
    assert!(instructions(&words)
        .iter()
        .any(|(op, ops)| *op == 15 && ops[0] == 4 && string_at(&ops[2..]) == "main"));
    let _ = std::fs::remove_file(&out);
}

#[test]
fn descriptor_heaps_are_typed_arrays_sharing_a_binding() {
    compile_all("descriptor_heaps.hlsl");
    let m = hlsl::compile_file(&shader("descriptor_heaps.hlsl"), &HlslOptions::default()).unwrap();
    let heaps = named(&m.words, "ResourceDescriptorHeap");
    // One array per element type (a texture and a structured buffer).
    assert_eq!(heaps.len(), 2);
    let insts = instructions(&m.words);
    let binding = |id: u32| {
        insts
            .iter()
            .find(|(op, ops)| *op == 71 && ops[0] == id && ops[1] == 33)
            .map(|(_, ops)| ops[2])
            .unwrap()
    };
    // After `material` (0) and `output` (1): resources at 2, samplers at 3.
    assert_eq!(binding(heaps[0]), 2);
    assert_eq!(binding(heaps[1]), 2);
    assert_eq!(binding(named(&m.words, "SamplerDescriptorHeap")[0]), 3);
}

#[test]
fn typed_buffers_are_texel_buffers() {
    compile_all("texel_buffers.hlsl");
    let m = hlsl::compile_file(&shader("texel_buffers.hlsl"), &HlslOptions::default()).unwrap();
    let insts = instructions(&m.words);
    // OpTypeImage (25) with Dim Buffer (5): sampled 1 (Buffer) and 2 (RWBuffer).
    let images: Vec<(u32, u32)> = insts
        .iter()
        .filter(|(op, ops)| *op == 25 && ops[2] == 5)
        .map(|(_, ops)| (ops[6], ops[7]))
        .collect();
    assert!(images.contains(&(1, 0)));
    // RWBuffer<float> → R32f (3), RWBuffer<uint2> → Rg32ui (35).
    assert!(
        images.contains(&(2, 3)) && images.contains(&(2, 35)),
        "{images:?}"
    );
    // OpImageFetch (95) without image operands (no mip level in a texel buffer).
    assert!(insts.iter().any(|(op, ops)| *op == 95 && ops.len() == 4));
}

#[test]
fn a_returned_ray_query_is_the_callers_variable() {
    compile_all("rayquery_return.hlsl");
    let m = hlsl::compile_file(&shader("rayquery_return.hlsl"), &HlslOptions::default()).unwrap();
    let insts = instructions(&m.words);
    // No OpReturnValue (254): the function returns void and makes the query
    // in its last parameter, a Function pointer to the ray query type.
    assert!(!insts.iter().any(|(op, _)| *op == 254));
    let f = named(&m.words, "traceScene<RayQuery<1>>")[0];
    let at = insts
        .iter()
        .position(|(op, ops)| *op == 54 && ops[1] == f)
        .unwrap();
    let params: Vec<_> = insts[at + 1..]
        .iter()
        .take_while(|(op, _)| *op == 55)
        .collect();
    assert_eq!(params.len(), 2);
}

/// The constructs public shaders failed on (tests/hlsl/corpus_constructs.hlsl).
#[test]
fn constructs_from_the_public_corpus() {
    let entries = compile_all("corpus_constructs.hlsl");
    assert_eq!(
        entries,
        [
            ("Main".to_string(), Stage::Compute),
            ("Shade".to_string(), Stage::Fragment)
        ]
    );
    let m = hlsl::compile(&shader("corpus_constructs.hlsl"), &HlslOptions::default()).unwrap();
    let (main, shade) = (&m[0].words, &m[1].words);
    let insts = instructions(main);
    // Texture arrays are passed as their variables: `pick(gTextures, ...)`
    // and `pickAny(gBindless, ...)` take the descriptor variables themselves,
    // and `occluded` hands its acceleration-structure parameter on.
    let textures = named(main, "gTextures")[0];
    let bindless = named(main, "gBindless")[0];
    let all_calls = calls(main);
    assert!(all_calls.iter().any(|c| c[3..].contains(&textures)));
    assert!(all_calls.iter().any(|c| c[3..].contains(&bindless)));
    let scene_param = named(main, "scene");
    assert!(all_calls
        .iter()
        .any(|c| c[3..].iter().any(|a| scene_param.contains(a))));
    // Atomics on texels: OpImageTexelPointer (60) then OpAtomicOr (241) and
    // OpAtomicUMin (237) on it.
    let texel_ptrs: Vec<u32> = insts
        .iter()
        .filter(|(op, _)| *op == 60)
        .map(|(_, ops)| ops[1])
        .collect();
    assert_eq!(texel_ptrs.len(), 2);
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 241 && texel_ptrs.contains(&ops[2])));
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 237 && texel_ptrs.contains(&ops[2])));
    // vk::RawBufferLoad: OpConvertUToPtr (120) and an Aligned (2) load of 4,
    // then of 16; the addressing model is PhysicalStorageBuffer64 (5348).
    assert_eq!(insts.iter().filter(|(op, _)| *op == 120).count(), 2);
    let aligned: Vec<u32> = insts
        .iter()
        .filter(|(op, ops)| *op == 61 && ops.len() == 5 && ops[3] == 2)
        .map(|(_, ops)| ops[4])
        .collect();
    assert_eq!(aligned, [4, 16]);
    assert!(insts.iter().any(|(op, ops)| *op == 14 && ops[0] == 5348));
    // [[vk::ext_decorate(0)]]: member 0 of `Material` is RelaxedPrecision (0).
    assert!(member_decorations(main, "Material").contains(&(0, 0)));
    // The pixel shader: EarlyFragmentTests (9), and each input's interpolation.
    let pixel = instructions(shade);
    assert!(pixel.iter().any(|(op, ops)| *op == 16 && ops[1] == 9));
    let decorated = |name: &str, decoration: u32| {
        let var = named(shade, name)[0];
        pixel
            .iter()
            .any(|(op, ops)| *op == 71 && ops[0] == var && ops[1] == decoration)
    };
    // Centroid (16), Flat (14), NoPerspective (13), Sample (17).
    assert!(decorated("in.var.TEXCOORD0", 16));
    assert!(decorated("in.var.TEXCOORD1", 14));
    assert!(decorated("in.var.TEXCOORD2", 13));
    assert!(decorated("in.var.TEXCOORD3", 17));
    assert!(!decorated("in.var.TEXCOORD0", 14));
}

/// With -enable-16bit-types `half`, `min16float`, `float16_t`, `int16_t`,
/// `uint16_t` and `min16int` are 16-bit: their SPIR-V types, the capabilities
/// for 16-bit arithmetic and for 16-bit values in storage and uniform
/// buffers, 2-byte layouts, and arithmetic that stays 16-bit.
#[test]
fn sixteen_bit_types_with_the_flag() {
    let opts = HlslOptions {
        enable_16bit_types: true,
        ..Default::default()
    };
    let path = shader("half.hlsl");
    let m = hlsl::compile_file(&path, &opts).unwrap_or_else(|e| panic!("{e}"));
    validate(&m.words, "half.hlsl-flag");
    let insts = instructions(&m.words);
    let caps = |words: &[u32]| -> Vec<u32> {
        instructions(words)
            .iter()
            .filter(|(op, _)| *op == 17)
            .map(|(_, o)| o[0])
            .collect()
    };
    // Float16 (9), Int16 (22), StorageBuffer16BitAccess (4433),
    // UniformAndStorageBuffer16BitAccess (4434), StoragePushConstant16 (4435),
    // StorageInputOutput16 (4436): each where its storage class holds 16-bit values.
    let entries = hlsl::compile(&path, &opts).unwrap_or_else(|e| panic!("{e}"));
    let of = |name: &str| caps(&entries.iter().find(|e| e.name == name).unwrap().words);
    let (cs, ps, hit) = (of("cs"), of("ps"), of("hit"));
    for c in [9, 22, 4433, 4434, 4435] {
        assert!(cs.contains(&c), "cs: capability {c} missing: {cs:?}");
    }
    assert!(!cs.contains(&4436), "{cs:?}");
    assert!(ps.contains(&4436) && !ps.contains(&4433), "{ps:?}");
    // ddx and fwidth of half values: OpDPdx (207) and OpFwidth (209) take an
    // OpFConvert (115) of the value and their result is converted back.
    let ps_words = &entries.iter().find(|e| e.name == "ps").unwrap().words;
    let ps_insts = instructions(ps_words);
    let fconverts: Vec<&Vec<u32>> = ps_insts
        .iter()
        .filter(|(op, _)| *op == 115)
        .map(|(_, ops)| ops)
        .collect();
    let derivatives: Vec<&Vec<u32>> = ps_insts
        .iter()
        .filter(|(op, _)| *op == 207 || *op == 209)
        .map(|(_, ops)| ops)
        .collect();
    assert_eq!(derivatives.len(), 2);
    for d in derivatives {
        assert!(
            fconverts.iter().any(|c| c[1] == d[2]),
            "operand not widened"
        );
        assert!(
            fconverts.iter().any(|c| c[2] == d[1]),
            "result not narrowed"
        );
    }
    // A payload needs no storage capability.
    assert!(
        hit.contains(&9) && !hit.iter().any(|c| (4433..=4436).contains(c)),
        "{hit:?}"
    );
    // OpExtension (10).
    assert!(insts
        .iter()
        .any(|(op, o)| *op == 10 && string_at(o) == "SPV_KHR_16bit_storage"));
    // OpTypeFloat (22) 16, OpTypeInt (21) 16 signed and unsigned.
    let half = insts
        .iter()
        .find(|(op, o)| *op == 22 && o[1] == 16)
        .map(|(_, o)| o[0])
        .expect("OpTypeFloat 16");
    let short = insts
        .iter()
        .find(|(op, o)| *op == 21 && o[1] == 16 && o[2] == 1)
        .map(|(_, o)| o[0])
        .expect("OpTypeInt 16 1");
    assert!(insts
        .iter()
        .any(|(op, o)| *op == 21 && o[1] == 16 && o[2] == 0));
    // 2-byte members: half a, half2 b (relaxed: at 2), float c, int16_t d, uint16_t e.
    // half3x3: three half3 columns 8 bytes apart.
    assert_eq!(
        member_offsets(&m.words, "Packed"),
        vec![0, 2, 8, 12, 14, 16]
    );
    assert_eq!(member_offsets(&m.words, "type.Params"), vec![0, 2, 4]);
    // `h * 2.0 + scale` is half arithmetic (OpFMul 133, OpFAdd 129), the
    // literal taking the type of the half beside it; int16 arithmetic (OpIMul 132).
    assert!(insts.iter().any(|(op, o)| *op == 133 && o[0] == half));
    assert!(insts.iter().any(|(op, o)| *op == 129 && o[0] == half));
    assert!(insts.iter().any(|(op, o)| *op == 132 && o[0] == short));
    // GLSL.std.450 on halves (OpExtInst 12 with a half result: Sqrt, Length, FClamp, FMix).
    let glsl: Vec<u32> = insts
        .iter()
        .filter(|(op, o)| *op == 12 && o[0] == half && o.len() > 3)
        .map(|(_, o)| o[3])
        .collect();
    for inst in [31, 66, 43, 46] {
        assert!(
            glsl.contains(&inst),
            "GLSL.std.450 {inst} on half: {glsl:?}"
        );
    }
    // 16-bit texels live in 32-bit images (OpTypeImage 25, sampled type
    // float); the storage image's format is Rgba16f (2).
    let float = insts
        .iter()
        .find(|(op, o)| *op == 22 && o[1] == 32)
        .map(|(_, o)| o[0])
        .unwrap();
    let images: Vec<&Vec<u32>> = insts
        .iter()
        .filter(|(op, _)| *op == 25)
        .map(|(_, o)| o)
        .collect();
    assert!(images.iter().all(|o| o[1] != half), "{images:?}");
    assert!(images
        .iter()
        .any(|o| o[1] == float && o[6] == 2 && o[7] == 2));
    // Wave reductions keep 16 bits: OpGroupNonUniformFAdd (350) of half,
    // OpGroupNonUniformSMin (353) of int16_t.
    assert!(insts.iter().any(|(op, o)| *op == 350 && o[0] == half));
    assert!(insts.iter().any(|(op, o)| *op == 353 && o[0] == short));
    // half + float is float: OpFConvert (115) widens.
    assert!(insts.iter().any(|(op, _)| *op == 115));

    // Literals beside halves in `?:` and intrinsics stay half: no float
    // arithmetic, no conversion (OpFConvert 115) at all.
    let lits = "RWStructuredBuffer<half> o;\n[numthreads(1,1,1)]\nvoid m(uint3 id : SV_DispatchThreadID) { half h = (half)id.x; o[0] = h > 1 ? h : 0.5; o[1] = id.y > 0 ? o[2] + h : -1.0; o[3] = max(h, 0.25) * 2; }";
    let m = hlsl::compile_source_whole(
        Path::new("main.hlsl"),
        lits,
        &mut hlsl::pp::MemLoader::default(),
        &opts,
    )
    .unwrap();
    validate(&m.words, "half-literals");
    let insts = instructions(&m.words);
    assert!(!insts.iter().any(|(op, _)| *op == 115));
    // OpSelect (169) and OpPhi (245) of half.
    let half = insts
        .iter()
        .find(|(op, o)| *op == 22 && o[1] == 16)
        .map(|(_, o)| o[0])
        .unwrap();
    assert!(insts.iter().any(|(op, o)| *op == 169 && o[0] == half));
    assert!(insts.iter().any(|(op, o)| *op == 245 && o[0] == half));

    // Without the flag `half` and `min16*` are 32-bit: no 16-bit type at all.
    let plain = "RWStructuredBuffer<float> o;\n[numthreads(1,1,1)]\nvoid m() { half h = 1.5; min16float g = h; min16int i = 2; o[0] = g * i; }";
    let m = hlsl::compile_source_whole(
        Path::new("main.hlsl"),
        plain,
        &mut hlsl::pp::MemLoader::default(),
        &HlslOptions::default(),
    )
    .unwrap();
    validate(&m.words, "half-no-flag");
    assert!(!instructions(&m.words)
        .iter()
        .any(|(op, o)| (*op == 21 || *op == 22) && o[1] == 16));
}

/// `[[vk::ext_decorate]]` on a resource, a `static` global, a `groupshared`
/// array and a parameter: each one's variable or `OpFunctionParameter` has
/// the decoration (tests/hlsl/ext_decorate.hlsl).
#[test]
fn ext_decorate_on_variables_and_parameters() {
    compile_all("ext_decorate.hlsl");
    let m = hlsl::compile(&shader("ext_decorate.hlsl"), &HlslOptions::default()).unwrap();
    let words = &m[0].words;
    let insts = instructions(words);
    // OpDecorate (71) target decoration.
    let decorations = |name: &str| -> Vec<u32> {
        let ids = named(words, name);
        insts
            .iter()
            .filter(|(op, ops)| *op == 71 && ids.contains(&ops[0]))
            .map(|(_, ops)| ops[1])
            .collect()
    };
    // Restrict (19) beside the binding's DescriptorSet (34) and Binding (33).
    let mut results = decorations("gResults");
    results.sort_unstable();
    assert_eq!(results, [19, 33, 34]);
    // RelaxedPrecision (0).
    assert_eq!(decorations("gScale"), [0]);
    assert_eq!(decorations("gShared"), [0]);
    // The parameter `x` is an OpFunctionParameter (55) with the decoration.
    let x = named(words, "x");
    assert!(insts
        .iter()
        .any(|(op, ops)| *op == 55 && x.contains(&ops[1])));
    assert_eq!(decorations("x"), [0]);
}

/// 16-bit specialization constants: `OpSpecConstant` (50) of `half` and of
/// 16-bit integers, the default's bits in the low half of the literal word
/// (sign-extended for `int16_t`), each with its `SpecId` (1).
#[test]
fn sixteen_bit_specialization_constants() {
    let opts = HlslOptions {
        enable_16bit_types: true,
        ..Default::default()
    };
    let m = hlsl::compile(&shader("spec_half.hlsl"), &opts).unwrap_or_else(|e| panic!("{e}"));
    let words = &m[0].words;
    validate(words, "spec_half.hlsl-Main");
    let insts = instructions(words);
    let spec = |name: &str| -> (u32, u32) {
        let id = named(words, name)[0];
        let value = insts
            .iter()
            .find(|(op, ops)| *op == 50 && ops[1] == id)
            .map(|(_, ops)| ops[2])
            .unwrap();
        let spec_id = insts
            .iter()
            .find(|(op, ops)| *op == 71 && ops[0] == id && ops[1] == 1)
            .map(|(_, ops)| ops[2])
            .unwrap();
        (spec_id, value)
    };
    // 1.5 as a half is 0x3e00.
    assert_eq!(spec("kGain"), (7, 0x3e00));
    assert_eq!(spec("kBias"), (8, 0xffff_fffe));
    assert_eq!(spec("kCount"), (9, 40000));
    // The constants' types are 16 bits wide: OpTypeFloat (22) 16 and
    // OpTypeInt (21) 16, signed and unsigned.
    let type_of = |name: &str| {
        let id = named(words, name)[0];
        let t = insts
            .iter()
            .find(|(op, ops)| *op == 50 && ops[1] == id)
            .map(|(_, ops)| ops[0])
            .unwrap();
        insts
            .iter()
            .find(|(op, ops)| (*op == 21 || *op == 22) && ops[0] == t)
            .map(|(op, ops)| (*op, ops[1..].to_vec()))
            .unwrap()
    };
    assert_eq!(type_of("kGain"), (22, vec![16]));
    assert_eq!(type_of("kBias"), (21, vec![16, 1]));
    assert_eq!(type_of("kCount"), (21, vec![16, 0]));
}

/// `countbits` of 16-bit integers: `OpBitCount` (205) of an `OpUConvert`
/// (113) to 32 bits (zero-extended, also for `int16_t`), as DXC lowers it,
/// never of the 16-bit value itself (tests/hlsl/bits_half.hlsl).
#[test]
fn countbits_of_sixteen_bit_integers_counts_the_zero_extended_value() {
    let opts = HlslOptions {
        enable_16bit_types: true,
        ..Default::default()
    };
    let m = hlsl::compile(&shader("bits_half.hlsl"), &opts).unwrap_or_else(|e| panic!("{e}"));
    let words = &m[0].words;
    validate(words, "bits_half.hlsl-Main");
    let insts = instructions(words);
    let uconverts: Vec<u32> = insts
        .iter()
        .filter(|(op, _)| *op == 113)
        .map(|(_, ops)| ops[1])
        .collect();
    let counts: Vec<&Vec<u32>> = insts
        .iter()
        .filter(|(op, _)| *op == 205)
        .map(|(_, ops)| ops)
        .collect();
    assert_eq!(counts.len(), 2);
    for c in counts {
        assert!(
            uconverts.contains(&c[2]),
            "OpBitCount of a value not widened"
        );
    }
}
