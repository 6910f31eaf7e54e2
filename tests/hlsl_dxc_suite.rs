//! What DXC's SPIR-V test suite (`scripts/dxc-suite`) found wrong in the
//! HLSL compiler, each as a shader of ours under tests/hlsl/dxc_suite/ or a
//! few lines here: modules that were invalid but compiled without a word
//! (the 2025 spirv-val or an assertion on the module's decorations and
//! capabilities catches each), and source errors DXC reports that rtlint
//! compiled anyway (each now an error at the construct).

use rtlint::front::hlsl::{self, parse_stage, pp::MemLoader, HlslOptions};
use spirv::{BuiltIn, Capability, Decoration, Op};
use std::path::{Path, PathBuf};
use std::process::Command;

fn shader(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/hlsl/dxc_suite")
        .join(name)
}

/// `-E entry -T profile` (or the whole file when `entry` is `None`).
fn options(entry: Option<&str>, profile: Option<&str>, sixteen: bool) -> HlslOptions {
    HlslOptions {
        entry: entry.map(str::to_string),
        stage: profile.and_then(|p| parse_stage(p).unwrap()),
        enable_16bit_types: sixteen,
        ..Default::default()
    }
}

/// The module of one entry point (`entry` given) or of the whole file.
fn compile(name: &str, entry: Option<&str>, profile: Option<&str>, sixteen: bool) -> Vec<u32> {
    let path = shader(name);
    let opts = options(entry, profile, sixteen);
    if entry.is_some() {
        let mut e = hlsl::compile(&path, &opts).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(e.len(), 1, "{name}: one entry point");
        e.remove(0).words
    } else {
        hlsl::compile_file(&path, &opts)
            .unwrap_or_else(|e| panic!("{name}: {e}"))
            .words
    }
}

/// Validates with a spirv-val of 2024 or later for Vulkan 1.2 (Debian's
/// 2023.1 misses some of these rules); fails in CI and skips elsewhere
/// without one.
fn validate(words: &[u32], what: &str) {
    let Some(val) = rtlint_testkit::require(
        &format!("a new spirv-val (validating {what})"),
        rtlint_testkit::new_spirv_val(),
    ) else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("rtlint-dxc-suite-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join(format!("{what}.spv"));
    std::fs::write(&file, rtlint_testkit::bytes_of_words(words)).unwrap();
    let out = Command::new(&val)
        .args(["--target-env", "vulkan1.2"])
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "spirv-val rejected {what}:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// (opcode, operands) of each instruction.
fn instructions(words: &[u32]) -> Vec<(u32, Vec<u32>)> {
    let mut out = Vec::new();
    let mut i = 5;
    while i < words.len() {
        let n = ((words[i] >> 16) as usize).max(1);
        out.push((words[i] & 0xffff, words[i + 1..i + n].to_vec()));
        i += n;
    }
    out
}

fn string_at(ops: &[u32]) -> String {
    let bytes: Vec<u8> = ops.iter().flat_map(|w| w.to_le_bytes()).collect();
    let end = bytes.iter().position(|b| *b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

/// The id OpName calls `name`.
fn named(words: &[u32], name: &str) -> u32 {
    instructions(words)
        .into_iter()
        .find(|(op, ops)| *op == Op::Name as u32 && string_at(&ops[1..]) == name)
        .unwrap_or_else(|| panic!("no OpName `{name}`"))
        .1[0]
}

/// The variable decorated `BuiltIn bi`.
fn builtin_var(words: &[u32], bi: BuiltIn) -> u32 {
    instructions(words)
        .into_iter()
        .find(|(op, ops)| {
            *op == Op::Decorate as u32
                && ops[1] == Decoration::BuiltIn as u32
                && ops[2] == bi as u32
        })
        .unwrap_or_else(|| panic!("no variable is BuiltIn {bi:?}"))
        .1[0]
}

/// The decorations without operands of `id`.
fn decorations(words: &[u32], id: u32) -> Vec<u32> {
    instructions(words)
        .into_iter()
        .filter(|(op, ops)| *op == Op::Decorate as u32 && ops[0] == id)
        .map(|(_, ops)| ops[1])
        .collect()
}

fn capabilities(words: &[u32]) -> Vec<u32> {
    instructions(words)
        .into_iter()
        .filter(|(op, _)| *op == Op::Capability as u32)
        .map(|(_, ops)| ops[0])
        .collect()
}

fn extensions(words: &[u32]) -> Vec<String> {
    instructions(words)
        .into_iter()
        .filter(|(op, _)| *op == Op::Extension as u32)
        .map(|(_, ops)| string_at(&ops))
        .collect()
}

#[test]
fn integer_pixel_inputs_are_flat_at_every_width() {
    let w = compile(
        "pixel_integer_inputs.hlsl",
        Some("main"),
        Some("ps_6_2"),
        true,
    );
    validate(&w, "pixel_integer_inputs");
    let flat = Decoration::Flat as u32;
    for name in ["in.var.A", "in.var.B", "in.var.C"] {
        assert!(
            decorations(&w, named(&w, name)).contains(&flat),
            "`{name}` is an integer input without Flat"
        );
    }
    assert!(!decorations(&w, named(&w, "in.var.D")).contains(&flat));
    for bi in [BuiltIn::SubgroupSize, BuiltIn::SubgroupLocalInvocationId] {
        assert!(
            decorations(&w, builtin_var(&w, bi)).contains(&flat),
            "{bi:?} read by a pixel shader without Flat"
        );
    }
}

#[test]
fn inline_spirv_built_ins_declare_their_capabilities() {
    let w = compile("inline_builtins.hlsl", Some("main"), Some("ps_6_0"), false);
    validate(&w, "inline_builtins");
    let caps = capabilities(&w);
    assert!(caps.contains(&(Capability::SampleRateShading as u32)));
    assert!(caps.contains(&(Capability::StencilExportEXT as u32)));
    assert!(extensions(&w).contains(&"SPV_EXT_shader_stencil_export".to_string()));
    let sample_id = builtin_var(&w, BuiltIn::SampleId);
    assert!(decorations(&w, sample_id).contains(&(Decoration::Flat as u32)));
    // Flat written by the source too: once.
    let src = "[[vk::ext_decorate(/* Flat */ 14)]]\n[[vk::ext_builtin_input(18)]]\n\
               static const int sample_id;\n\
               float4 main() : SV_Target { return float4(sample_id, 0, 0, 1); }\n";
    let mut loader = MemLoader([(PathBuf::from("main.hlsl"), src.to_string())].into());
    let e = hlsl::compile_source(
        Path::new("main.hlsl"),
        src,
        &mut loader,
        &options(Some("main"), Some("ps_6_0"), false),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let w = &e[0].words;
    validate(w, "inline_builtins_flat_twice");
    let flats = decorations(w, builtin_var(w, BuiltIn::SampleId))
        .into_iter()
        .filter(|d| *d == Decoration::Flat as u32)
        .count();
    assert_eq!(flats, 1);
}

#[test]
fn ray_tracing_stages_read_subgroup_built_ins_as_volatile() {
    // spirv-val does not check this rule: the assertion does.
    let w = compile("raygen_subgroup.hlsl", None, None, false);
    validate(&w, "raygen_subgroup");
    let volatile = Decoration::Volatile as u32;
    for bi in [BuiltIn::SubgroupSize, BuiltIn::SubgroupLocalInvocationId] {
        assert!(
            decorations(&w, builtin_var(&w, bi)).contains(&volatile),
            "{bi:?} read by a ray-generation shader without Volatile"
        );
    }
    // The miss shader alone: SubgroupSize only, Volatile too.
    let miss = compile("raygen_subgroup.hlsl", Some("Miss"), None, false);
    let v = builtin_var(&miss, BuiltIn::SubgroupSize);
    assert_eq!(
        decorations(&miss, v),
        vec![Decoration::BuiltIn as u32, volatile]
    );
}

#[test]
fn compute_with_an_acceleration_structure_needs_ray_queries_only() {
    let w = compile(
        "compute_acceleration_structure.hlsl",
        Some("main"),
        Some("cs_6_5"),
        false,
    );
    validate(&w, "compute_acceleration_structure");
    let caps = capabilities(&w);
    assert!(caps.contains(&(Capability::RayQueryKHR as u32)));
    assert!(
        !caps.contains(&(Capability::RayTracingKHR as u32)),
        "a compute shader declares RayTracingKHR"
    );
    assert!(!extensions(&w).contains(&"SPV_KHR_ray_tracing".to_string()));
    // A ray-tracing stage keeps RayTracingKHR.
    let rg = compile("raygen_subgroup.hlsl", Some("RayGen"), None, false);
    assert!(capabilities(&rg).contains(&(Capability::RayTracingKHR as u32)));
}

/// "line:col: message" of compiling `src` as main.hlsl, with the position of
/// each secondary label appended.
fn error(src: &str, profile: Option<&str>, sixteen: bool) -> String {
    let mut loader = MemLoader([(PathBuf::from("main.hlsl"), src.to_string())].into());
    let opts = options(profile.map(|_| "main"), profile, sixteen);
    let e = hlsl::compile_source(Path::new("main.hlsl"), src, &mut loader, &opts)
        .err()
        .unwrap_or_else(|| panic!("expected an error for:\n{src}"));
    let d = e.diagnostic();
    let l = &d.primary.as_ref().expect("error has a position").location;
    let mut s = format!("{}:{}: {}", l.line, l.column, d.message);
    for label in &d.secondary {
        s.push_str(&format!(
            "\n  {}:{}: {}",
            label.location.line, label.location.column, label.message
        ));
    }
    s
}

#[test]
fn arrays_of_arrays_of_resources_are_refused_at_the_declaration() {
    let path = shader("constant_buffer_2d.hlsl");
    let Err(e) = hlsl::compile(&path, &options(Some("main"), Some("ps_6_0"), false)) else {
        panic!("a two-dimensional descriptor array compiles");
    };
    let d = e.diagnostic();
    let l = &d.primary.as_ref().unwrap().location;
    assert_eq!((l.line, l.column), (10, 23));
    assert!(
        d.message
            .starts_with("not supported: arrays of arrays of resources"),
        "{}",
        d.message
    );
    assert_eq!(
        error(
            "Texture2D t[2][3];\nSamplerState s;\nfloat4 main(float2 uv : UV) : SV_Target { return t[1][2].Sample(s, uv); }\n",
            Some("ps_6_0"),
            false
        )
        .lines()
        .next()
        .unwrap(),
        "1:11: not supported: arrays of arrays of resources (a Vulkan descriptor array has one dimension: declare `a[N * M]` and index `a[i * M + j]`)"
    );
}

#[test]
fn compute_entry_points_need_numthreads() {
    assert_eq!(
        error(
            "RWBuffer<uint> b;\nvoid main() { b[0] = 1; }\n",
            Some("cs_6_0"),
            false
        ),
        "2:6: compute entry point `main` needs a [numthreads(X, Y, Z)] attribute"
    );
    assert_eq!(
        error(
            "RWBuffer<uint> b;\n[shader(\"compute\")]\nvoid main() { b[0] = 1; }\n",
            None,
            false
        ),
        "3:6: compute entry point `main` needs a [numthreads(X, Y, Z)] attribute"
    );
    // A prototype leaves the attribute to the definition.
    let src = "void main();\n[numthreads(4, 1, 1)]\nvoid main() {}\n";
    let mut loader = MemLoader([(PathBuf::from("main.hlsl"), src.to_string())].into());
    hlsl::compile_source(
        Path::new("main.hlsl"),
        src,
        &mut loader,
        &options(Some("main"), Some("cs_6_0"), false),
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_built_in_input_cannot_be_redefined_as_an_output() {
    let src = "[[vk::ext_builtin_input(24)]]\nstatic const uint3 groups;\n\
               [[vk::ext_builtin_output(24)]]\nstatic uint3 again;\n\
               float4 main() : SV_Target { return float4(groups, 1); }\n";
    assert_eq!(
        error(src, Some("ps_6_0"), false),
        "4:14: built-in `NumWorkgroups` (24) is already declared as an input; it cannot be redefined as an output\n  2:20: first declared here"
    );
}

#[test]
fn texel_buffers_of_16_bit_floats_are_refused() {
    let src = "Buffer<half4> b;\nfloat4 main() : SV_Target { return b[0]; }\n";
    assert_eq!(
        error(src, Some("ps_6_2"), true),
        "1:1: `Buffer` of 16-bit floats: a Vulkan texel buffer's sampled type is at least 32 bits (use `float` elements)"
    );
    let rw = "RWBuffer<float16_t> b;\nfloat4 main() : SV_Target { return b[0]; }\n";
    assert!(error(rw, Some("ps_6_2"), true).starts_with("1:1: `RWBuffer` of 16-bit floats"));
    // Without -enable-16bit-types `half` is a 32-bit float.
    let mut loader = MemLoader([(PathBuf::from("main.hlsl"), src.to_string())].into());
    hlsl::compile_source(
        Path::new("main.hlsl"),
        src,
        &mut loader,
        &options(Some("main"), Some("ps_6_0"), false),
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn a_pixel_input_semantic_is_used_once() {
    let src = "struct In {\n    float4 a : SV_Position;\n    float4 b : SV_Position;\n};\n\
               float4 main(In i) : SV_Target { return i.a + i.b; }\n";
    assert_eq!(
        error(src, Some("ps_6_0"), false),
        "3:16: input semantic `SV_Position` used more than once\n  2:16: first used here"
    );
}

/// Offsets of a struct's members, by member index.
fn member_offsets(words: &[u32], struct_name: &str) -> Vec<u32> {
    let id = named(words, struct_name);
    let mut offsets: Vec<(u32, u32)> = instructions(words)
        .into_iter()
        .filter(|(op, ops)| {
            *op == Op::MemberDecorate as u32 && ops[0] == id && ops[2] == Decoration::Offset as u32
        })
        .map(|(_, ops)| (ops[1], ops[3]))
        .collect();
    offsets.sort_unstable();
    offsets.into_iter().map(|(_, o)| o).collect()
}

#[test]
fn push_constant_structs_are_push_constant_blocks() {
    let w = compile(
        "push_constant_struct.hlsl",
        Some("main"),
        Some("ps_6_2"),
        true,
    );
    validate(&w, "push_constant_struct");
    // The variable is in PushConstant storage, and nothing is in $Globals.
    let push = named(&w, "push");
    let class = instructions(&w)
        .into_iter()
        .find(|(op, ops)| *op == Op::Variable as u32 && ops[1] == push)
        .map(|(_, ops)| ops[2]);
    assert_eq!(class, Some(spirv::StorageClass::PushConstant as u32));
    assert!(!instructions(&w)
        .iter()
        .any(|(op, ops)| *op == Op::Name as u32 && string_at(&ops[1..]) == "type.$Globals"));
    // Laid out as a push-constant block (as DXC lays it out): the 16-bit
    // members packed, the float4 after the 32-byte nested struct.
    assert_eq!(member_offsets(&w, "Light"), vec![0, 2, 8]);
    assert_eq!(member_offsets(&w, "type.Push"), vec![0, 32]);
    assert!(capabilities(&w).contains(&(Capability::StoragePushConstant16 as u32)));
    // Other types cannot be push constants.
    assert_eq!(
        error(
            "[[vk::push_constant]]\nfloat4 tint;\nfloat4 main() : SV_Target { return tint; }\n",
            Some("ps_6_0"),
            false
        ),
        "1:3: `[[vk::push_constant]]` applies to a variable of struct or `ConstantBuffer<T>` type"
    );
}

#[test]
fn globally_coherent_resources_are_coherent() {
    let w = compile(
        "globally_coherent.hlsl",
        Some("main"),
        Some("cs_6_0"),
        false,
    );
    validate(&w, "globally_coherent");
    let coherent = Decoration::Coherent as u32;
    for name in ["counters", "flags", "image"] {
        assert!(
            decorations(&w, named(&w, name)).contains(&coherent),
            "`{name}` is globallycoherent but not Coherent"
        );
    }
    assert!(!decorations(&w, named(&w, "results")).contains(&coherent));
}
