//! DXC's register mapping options: one shader compiled with each, its
//! descriptor sets and bindings checked against the values DXC's SPIR-V
//! documentation ("HLSL register and Vulkan binding") gives for them.

use rtlint_hlsl::{compile_source_whole, parse_args, pp::MemLoader, HlslOptions};
use std::collections::BTreeMap;
use std::path::Path;

/// The example of DXC's documentation, plus a resource of each class, all
/// used by the entry point so that the module keeps them.
const SHADER: &str = r#"
struct S { float4 f; };
ConstantBuffer<S> cbuffer1 : register(b0);
ConstantBuffer<S> cbuffer2 : register(b0, space2);
Texture2D<float4> texture1 : register(t0);
Texture2D<float4> texture2 : register(t1, space1);
SamplerState sampler1;
[[vk::binding(3)]]
RWBuffer<float4> rwbuffer1 : register(u5, space2);
RWStructuredBuffer<float4> output : register(u0);
Texture2D<float4> unregistered;
float4 tint;

[numthreads(1, 1, 1)]
void main()
{
    float4 v = cbuffer1.f + cbuffer2.f + rwbuffer1[0] + tint;
    v += texture1.SampleLevel(sampler1, float2(0, 0), 0);
    v += texture2.SampleLevel(sampler1, float2(0, 0), 0);
    v += unregistered.SampleLevel(sampler1, float2(0, 0), 0);
    output[0] = v;
}
"#;

/// (set, binding) of each named variable, compiled with DXC's `args`.
fn bindings(args: &str, shader: &str) -> Result<BTreeMap<String, (u32, u32)>, String> {
    let args: Vec<String> = args.split_whitespace().map(String::from).collect();
    let mut options = HlslOptions::default();
    let rest = parse_args(&args, &mut options)?.rest;
    assert!(rest.is_empty(), "{rest:?}");
    let mut loader = MemLoader::default();
    let m = compile_source_whole(Path::new("b.hlsl"), shader, &mut loader, &options)
        .map_err(|e| e.to_string())?;
    // OpName (5) and OpDecorate (71) DescriptorSet (34) / Binding (33).
    let mut names = BTreeMap::new();
    let mut decorations = Vec::new();
    let mut at = 5;
    while at < m.words.len() {
        let (count, op) = ((m.words[at] >> 16) as usize, m.words[at] & 0xffff);
        let operands = &m.words[at + 1..at + count];
        match op {
            5 => {
                let bytes: Vec<u8> = operands[1..].iter().flat_map(|w| w.to_le_bytes()).collect();
                let name = bytes.split(|b| *b == 0).next().unwrap();
                names.insert(operands[0], String::from_utf8(name.to_vec()).unwrap());
            }
            71 if operands[1] == 34 || operands[1] == 33 => {
                decorations.push((operands[0], operands[1], operands[2]))
            }
            _ => {}
        }
        at += count.max(1);
    }
    let mut out: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for (id, d, v) in decorations {
        let Some(name) = names.get(&id) else { continue };
        let e = out.entry(name.clone()).or_default();
        if d == 34 {
            e.0 = v;
        } else {
            e.1 = v;
        }
    }
    Ok(out)
}

fn at(b: &BTreeMap<String, (u32, u32)>, name: &str) -> (u32, u32) {
    *b.get(name).unwrap_or_else(|| panic!("no {name} in {b:?}"))
}

#[test]
fn without_options_a_register_is_its_binding() {
    let b = bindings("", SHADER).unwrap();
    // vk::binding without a set: the default set, whatever the register says.
    assert_eq!(at(&b, "rwbuffer1"), (0, 3));
    assert_eq!(at(&b, "cbuffer1"), (0, 0));
    assert_eq!(at(&b, "cbuffer2"), (2, 0));
    assert_eq!(at(&b, "texture1"), (0, 0), "the register class is ignored");
    assert_eq!(at(&b, "texture2"), (1, 1));
    assert_eq!(at(&b, "output"), (0, 0));
    // The next free bindings of set 0, in declaration order.
    assert_eq!(at(&b, "sampler1"), (0, 1));
    assert_eq!(at(&b, "unregistered"), (0, 2));
}

/// The documentation's example: `-fvk-t-shift 10 0 -fvk-t-shift 20 1`.
#[test]
fn t_shift_per_space() {
    let b = bindings("-fvk-t-shift 10 0 -fvk-t-shift 20 1", SHADER).unwrap();
    assert_eq!(at(&b, "rwbuffer1"), (0, 3), "vk::binding is not shifted");
    assert_eq!(at(&b, "cbuffer1"), (0, 0));
    assert_eq!(at(&b, "texture1"), (0, 10));
    assert_eq!(at(&b, "texture2"), (1, 21));
    assert_eq!(at(&b, "sampler1"), (0, 1));
}

#[test]
fn shifts_for_all_spaces() {
    let b = bindings(
        "-fvk-b-shift 1000 all -fvk-t-shift 2000 all -fvk-s-shift 3000 all -fvk-u-shift 4000 all",
        SHADER,
    )
    .unwrap();
    assert_eq!(at(&b, "cbuffer1"), (0, 1000));
    assert_eq!(at(&b, "cbuffer2"), (2, 1000));
    assert_eq!(at(&b, "texture1"), (0, 2000));
    assert_eq!(at(&b, "texture2"), (1, 2001));
    assert_eq!(at(&b, "output"), (0, 4000));
    assert_eq!(at(&b, "rwbuffer1"), (0, 3));
    // Without -fvk-auto-shift-bindings, unregistered resources are not shifted.
    assert_eq!(at(&b, "sampler1"), (0, 0));
}

#[test]
fn auto_shift_bindings_shift_by_the_type_s_class() {
    let b = bindings(
        "-fvk-auto-shift-bindings -fvk-t-shift 100 0 -fvk-s-shift 200 0 -fvk-b-shift 300 0",
        SHADER,
    )
    .unwrap();
    assert_eq!(at(&b, "sampler1"), (0, 200));
    assert_eq!(
        at(&b, "unregistered"),
        (0, 101),
        "t0 is taken: texture1 is t0 + 100"
    );
    assert_eq!(at(&b, "texture1"), (0, 100));
}

#[test]
fn bind_register_and_bind_globals() {
    let shader = r#"
Texture2D<float4> tex : register(t0);
SamplerState smp : register(s0, space1);
RWStructuredBuffer<float4> output : register(u3);
float4 tint;
[numthreads(1, 1, 1)]
void main() { output[0] = tex.SampleLevel(smp, float2(0, 0), 0) + tint; }
"#;
    let b = bindings(
        "-fvk-bind-register t0 0 7 3 -vkbr s0 1 2 4 -fvk-bind-register u3 0 0 0 -fvk-bind-globals 2 1",
        shader,
    )
    .unwrap();
    assert_eq!(at(&b, "tex"), (3, 7));
    assert_eq!(at(&b, "smp"), (4, 2));
    assert_eq!(at(&b, "output"), (0, 0));
    assert_eq!(at(&b, "$Globals"), (1, 2));

    // DXC's errors: a register not listed, a resource without a register,
    // `$Globals` without -fvk-bind-globals.
    let e = bindings(
        "-vkbr t0 0 7 3 -vkbr s0 1 2 4 -fvk-bind-globals 2 1",
        shader,
    )
    .unwrap_err();
    assert!(
        e.starts_with("b.hlsl:4:") && e.contains("missing -fvk-bind-register for resource"),
        "{e}"
    );
    let e = bindings("-vkbr t0 0 7 3 -vkbr s0 1 2 4 -vkbr u3 0 0 0", shader).unwrap_err();
    assert!(e.contains("requires Globals buffer to be bound"), "{e}");
    let e = bindings("-vkbr t0 0 7 3", SHADER).unwrap_err();
    assert!(e.contains("missing -fvk-bind-register"), "{e}");
}

#[test]
fn auto_binding_space_and_globals_alone() {
    let b = bindings("-auto-binding-space 5 -fvk-bind-globals 9 0", SHADER).unwrap();
    assert_eq!(at(&b, "sampler1"), (5, 0));
    assert_eq!(at(&b, "unregistered"), (5, 1));
    assert_eq!(at(&b, "rwbuffer1"), (5, 3), "vk::binding without a set");
    assert_eq!(at(&b, "$Globals"), (0, 9));
}

/// A collision that remains after the shifts is kept, as DXC keeps it (its
/// optimizer may yet remove one of the two); rtlint's RT041 reports it.
#[test]
fn a_remaining_collision_is_kept() {
    let b = bindings("-fvk-t-shift 0 0", SHADER).unwrap();
    assert_eq!(at(&b, "texture1"), at(&b, "cbuffer1"));
}

/// DXC's predefined macros follow `-T`, `-HV`, `-fspv-target-env` and
/// `-enable-16bit-types`; `-Zpr` makes matrices row-major by default. Each
/// value is checked by a `#error` that fires when it is wrong.
#[test]
fn predefined_macros_and_matrix_packing() {
    let shader = r#"
#if __SHADER_TARGET_STAGE != __SHADER_STAGE_COMPUTE || __SHADER_STAGE_COMPUTE != 5
#error stage
#endif
#if __SHADER_TARGET_MAJOR != 6 || __SHADER_TARGET_MINOR != 2
#error target
#endif
#if __HLSL_VERSION != 2018 || !defined(__spirv__) || !defined(__hlsl_dx_compiler)
#error version
#endif
#if __SPIRV_MAJOR_VERSION__ != 1 || __SPIRV_MINOR_VERSION__ != 5
#error spirv
#endif
#if __DXC_VERSION_MAJOR != 1 || __SHADER_STAGE_LIBRARY != 6 || __SHADER_STAGE_PIXEL != 0
#error dxc
#endif
#ifdef __HLSL_ENABLE_16_BIT
#error sixteen
#endif
cbuffer C : register(b0) { float4x4 m; };
RWStructuredBuffer<float4> output : register(u0);
[numthreads(1, 1, 1)]
void main() { output[0] = mul(m, float4(1, 2, 3, 4)); }
"#;
    let line = "-T cs_6_2 -E main -HV 2018 -fspv-target-env=vulkan1.2";
    bindings(line, shader).unwrap();
    let e = bindings(&format!("{line} -enable-16bit-types"), shader).unwrap_err();
    assert!(e.contains("sixteen"), "{e}");
    let e = bindings(
        "-T cs_6_2 -E main -HV 2021 -fspv-target-env=vulkan1.2",
        shader,
    )
    .unwrap_err();
    assert!(e.contains("version"), "{e}");
    let e = bindings("-T lib_6_x -fspv-target-env=vulkan1.2 -HV 2018", shader).unwrap_err();
    assert!(e.contains("stage"), "{e}");

    // -Zpr: the cbuffer's matrix is HLSL row-major, which SPIR-V calls ColMajor
    // (OpMemberDecorate ... 5); without it HLSL column-major, SPIR-V RowMajor (4).
    let decorations = |args: &str| {
        let mut options = HlslOptions::default();
        let args: Vec<String> = args.split_whitespace().map(String::from).collect();
        parse_args(&args, &mut options).unwrap();
        let mut loader = MemLoader::default();
        let m = compile_source_whole(Path::new("b.hlsl"), shader, &mut loader, &options).unwrap();
        let mut found = Vec::new();
        let mut at = 5;
        while at < m.words.len() {
            let (count, op) = ((m.words[at] >> 16) as usize, m.words[at] & 0xffff);
            if op == 72 && matches!(m.words[at + 3], 4 | 5) {
                found.push(m.words[at + 3]);
            }
            at += count.max(1);
        }
        found
    };
    assert_eq!(decorations(&format!("{line} -Zpr")), [5]);
    assert_eq!(decorations(line), [4]);
}
