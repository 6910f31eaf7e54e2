#![cfg(feature = "vulkan")]
//! Runs compiled HLSL shaders on a Vulkan driver (lavapipe in CI) through
//! `rtlint::vk` and checks the values they compute: spirv-val proves modules
//! valid, this proves them right. Needs a ray-tracing device (the skip policy
//! of `rtlint_testkit::require`: a failure in CI, a `skipped:` line
//! elsewhere); the Slang differentials also need Slang and spirv-val.

mod common;

use rtlint::front::hlsl::{self, HlslOptions};
use rtlint::vk::{
    raw, Aabb, AccelerationStructure, Binding, BindingKind, Buffer, ComputePipeline, Context,
    Geometry, Group, Instance, RayTracingPipeline, RayTracingPipelineDesc, Resource, Sampler,
    ShaderStage, Stage, StorageImage,
};
use std::path::PathBuf;

const STORAGE: raw::BufferUsageFlags = raw::BufferUsageFlags::STORAGE_BUFFER;

/// A zeroed storage buffer of `bytes` bytes.
fn storage(ctx: &Context, bytes: u64) -> Buffer {
    Buffer::new(ctx, bytes, STORAGE, 1).unwrap()
}

/// Binds `list[i]` at binding `i` of set 0, each binding of the kind given.
fn bindings<'r>(list: &[(BindingKind, Resource<'r>)]) -> (Vec<Binding>, Vec<(u32, Resource<'r>)>) {
    list.iter()
        .enumerate()
        .map(|(i, (kind, r))| (Binding::new(i as u32, *kind), (i as u32, *r)))
        .unzip()
}

/// Runs compute entry `entry` as one workgroup with `list` bound.
fn dispatch(ctx: &Context, words: &[u32], entry: &str, list: &[(BindingKind, Resource<'_>)]) {
    let (layout, resources) = bindings(list);
    ComputePipeline::new(ctx, words, entry, &layout)
        .unwrap_or_else(|e| panic!("{entry}: {e}"))
        .dispatch(&resources, 1, 1, 1)
        .unwrap_or_else(|e| panic!("{entry}: {e}"));
}

#[derive(Debug, Clone, Copy)]
enum V {
    I(i32),
    U(u32),
    F(f32),
}

impl V {
    fn bits(self) -> u32 {
        match self {
            V::I(i) => i as u32,
            V::U(u) => u,
            V::F(f) => f.to_bits(),
        }
    }
}

/// The `Inputs` cbuffer of exec_compute.hlsl under HLSL packing.
fn inputs() -> Vec<u8> {
    let mut b = vec![0u8; 128];
    let mut put = |off: usize, v: f32| b[off..off + 4].copy_from_slice(&v.to_le_bytes());
    for (k, v) in [1.0, 2.0, 3.0].iter().enumerate() {
        put(k * 4, *v);
    }
    put(12, 4.0);
    put(16, 5.0);
    put(32, 6.0);
    put(48, 7.0);
    put(52, 8.0);
    put(56, 9.0);
    put(60, 10.0);
    // float3x3, column-major: HLSL column c at 64 + 16 c holds m[0..3][c].
    for col in 0..3 {
        for row in 0..3 {
            put(64 + 16 * col + 4 * row, (10 * row + col) as f32);
        }
    }
    put(108, 11.0);
    b[112] = 1;
    b
}

#[test]
fn compute_semantics_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let path = hlsl_path("exec_compute.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    use V::*;
    let expected = [
        I(3),
        I(-3),
        I(1),
        U(1),
        F(3.0),
        F(-1.5),
        F(3.0),
        F(1.0),
        F(12.0),
        I(5),
        I(6),
        I(0),
        F(1.0),
        F(2.0),
        F(4.0),
        F(6.0),
        F(8.0),
        F(10.0),
        F(11.0),
        F(21.0),
        F(12.0),
        F(10.0),
        F(1.0),
        F(416.0),
        F(20.0),
        F(-2.0),
        F(3.0),
        I(23),
        I(5),
        I(12),
        F(4.0),
        F(3.0),
        I(10),
        F(6.0),
        U(4),
        U(8),
        U(8),
        U(0x8000_0000),
        I(-1),
        I(3),
        I(3),
        U(2),
        F(2.5),
        F(1.0),
        F(1.0),
        I(11),
        F(7.0),
        F(1.5),
        F(2.0),
        F(0.75),
        U(10),
        I(-2),
        U(3),
        F(-3.0),
        I(1),
        F(2.0),
        I(-4),
        U(1),
        I(6),
        F(8.0),
        I(1),
        F(0.8),
        F(8.0),
        F(1.0),
        F(2.5),
        U(4),
        F(4.0),
        U(0),
        F(0.5),
        F(2.0),
        F(-0.75),
        F(-2.0),
        F(12.0),
        I(45),
        I(-4),
        U(6),
        I(3),
        I(1),
        I(8),
        F(1.0),
        I(0),
        F(3.5),
        F(2.0),
        F(11.0),
    ];
    let out = storage(&ctx, (expected.len() as u64 + 4) * 4);
    let ubo = Buffer::from_data(&ctx, raw::BufferUsageFlags::UNIFORM_BUFFER, &inputs()).unwrap();
    dispatch(
        &ctx,
        &entries[0].words,
        "Main",
        &[
            (BindingKind::StorageBuffer, Resource::Buffer(&out)),
            (BindingKind::UniformBuffer, Resource::Buffer(&ubo)),
        ],
    );
    let got = out.read_u32();
    let mut wrong = Vec::new();
    for (k, want) in expected.iter().enumerate() {
        if got[k] != want.bits() {
            wrong.push(format!(
                "result {k}: got {:#x} (i32 {}, f32 {}), want {want:?}",
                got[k],
                got[k] as i32,
                f32::from_bits(got[k])
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert_eq!(got[expected.len()], 0, "more results than expected");
}

/// Front-end constructs of the DXR corpus (default arguments, templates,
/// classes, inheritance, static members, operator[], sizeof, functional casts,
/// buffers passed to functions, namespaces, local constants, `return` of a
/// void call, a ConstantBuffer passed as its struct) compute what HLSL says
/// on the driver.
#[test]
fn front_end_constructs_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let path = hlsl_path("exec_frontend.hlsl");
    let entries = hlsl::compile(&path, &HlslOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let expected = [
        6.5f32, 2.5, 2.5, 8.0, 10.0, 3.5, 16.0, 7.0, 12.0, 56.0, 3.0, 4.0, 7.5, 7.0, 3.0, 4.5, 3.0,
        9.0, 3.0, 4.0, 6.0, 32.0, 2.5, 6.0,
    ];
    let out = storage(&ctx, (expected.len() as u64 + 4) * 4);
    // `sky`: color (1, 2, 3), intensity 0.5.
    let sky: Vec<u8> = [1.0f32, 2.0, 3.0, 0.5]
        .iter()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    let ubo = Buffer::from_data(&ctx, raw::BufferUsageFlags::UNIFORM_BUFFER, &sky).unwrap();
    dispatch(
        &ctx,
        &entries[0].words,
        "Main",
        &[
            (BindingKind::StorageBuffer, Resource::Buffer(&out)),
            (BindingKind::UniformBuffer, Resource::Buffer(&ubo)),
        ],
    );
    let got: Vec<f32> = out.read_u32().iter().map(|w| f32::from_bits(*w)).collect();
    assert_eq!(&got[..expected.len()], &expected[..]);
}

/// Geometry of the one-instance test scenes.
#[derive(Clone, Copy, Debug)]
enum Geom {
    /// A non-opaque triangle in the z = 1 plane; its hypotenuse is x + y = 0.
    Triangle,
    /// The non-opaque box around a sphere of radius 0.5 at (0, 0, 1).
    SphereBox,
}

/// One identity instance of `geom`.
fn scene(ctx: &Context, geom: Geom) -> AccelerationStructure {
    let blas = match geom {
        Geom::Triangle => AccelerationStructure::bottom_level(
            ctx,
            &[Geometry::Triangles {
                positions: &[[-0.9, -0.9, 1.0], [0.9, -0.9, 1.0], [-0.9, 0.9, 1.0]],
                indices: &[0, 1, 2],
                opaque: false,
            }],
        ),
        Geom::SphereBox => AccelerationStructure::bottom_level(
            ctx,
            &[Geometry::Aabbs {
                boxes: &[Aabb {
                    min: [-0.5, -0.5, 0.5],
                    max: [0.5, 0.5, 1.5],
                }],
                opaque: false,
            }],
        ),
    }
    .unwrap();
    AccelerationStructure::top_level(ctx, &[Instance::identity(&blas)]).unwrap()
}

/// Builds a ray-tracing pipeline (recursion depth 1) of `stages` and
/// `groups`, traces a 4×4 launch with `geom`'s scene at binding 0 and a
/// 256-byte storage buffer at binding 1, and returns that buffer's bytes.
fn trace(ctx: &Context, stages: &[ShaderStage<'_>], groups: &[Group], geom: Geom) -> Vec<u8> {
    trace_in(ctx, stages, groups, &scene(ctx, geom))
}

/// [`trace`] in the scene `tlas`.
fn trace_in(
    ctx: &Context,
    stages: &[ShaderStage<'_>],
    groups: &[Group],
    tlas: &AccelerationStructure,
) -> Vec<u8> {
    let out = storage(ctx, 16 * 16);
    let (layout, resources) = bindings(&[
        (
            BindingKind::AccelerationStructure,
            Resource::AccelerationStructure(tlas),
        ),
        (BindingKind::StorageBuffer, Resource::Buffer(&out)),
    ]);
    let pipeline = RayTracingPipeline::new(
        ctx,
        &RayTracingPipelineDesc {
            stages,
            groups,
            max_recursion_depth: 1,
            bindings: &layout,
            push_constant_size: 0,
            stack_size: None,
        },
    )
    .unwrap_or_else(|e| panic!("pipeline: {e}"));
    pipeline
        .trace_rays(&resources, 4, 4, 1)
        .unwrap_or_else(|e| panic!("trace: {e}"));
    out.read()
}

/// The stages of exec_pipeline.hlsl and their groups: miss shaders 1 and 2,
/// a triangle hit group of closest hit 3 and any hit 4.
const PIPELINE_STAGES: [(&str, Stage); 5] = [
    ("RG", Stage::RayGeneration),
    ("MissColor", Stage::Miss),
    ("MissProbe", Stage::Miss),
    ("Hit", Stage::ClosestHit),
    ("Filter", Stage::AnyHit),
];
const PIPELINE_GROUPS: [Group; 4] = [
    Group::General(0),
    Group::General(1),
    Group::General(2),
    Group::Triangles {
        closest_hit: Some(3),
        any_hit: Some(4),
    },
];

/// The stages of exec_procedural.hlsl: a procedural hit group of closest
/// hit 2 and intersection 3, and callable 4.
const PROCEDURAL_STAGES: [(&str, Stage); 5] = [
    ("Gen", Stage::RayGeneration),
    ("Miss", Stage::Miss),
    ("SphereHit", Stage::ClosestHit),
    ("Sphere", Stage::Intersection),
    ("Twice", Stage::Callable),
];
const PROCEDURAL_GROUPS: [Group; 4] = [
    Group::General(0),
    Group::General(1),
    Group::Procedural {
        intersection: 3,
        closest_hit: Some(2),
        any_hit: None,
    },
    Group::General(4),
];

/// Every stage of `list` from one module, under its own entry name.
fn one_module<'a>(words: &'a [u32], list: &'a [(&'a str, Stage)]) -> Vec<ShaderStage<'a>> {
    list.iter()
        .map(|(entry, stage)| ShaderStage {
            spirv: words,
            entry_point: entry,
            stage: *stage,
        })
        .collect()
}

/// Pixel centers of the 4×4 launches, shifted so none lies on an edge.
fn pixel(x: u32, y: u32) -> (f32, f32) {
    (
        (x as f32 + 0.5) / 4.0 * 2.0 - 1.0 + 0.1,
        (y as f32 + 0.5) / 4.0 * 2.0 - 1.0,
    )
}

/// Expected triangle result: barycentrics and t where the (any-hit filtered)
/// triangle is hit, else the miss value.
fn triangle_expectation(x: u32, y: u32, hit_w: f32, miss: [f32; 4]) -> [f32; 4] {
    let (px, py) = pixel(x, y);
    let (u, v) = ((px + 0.9) / 1.8, (py + 0.9) / 1.8);
    if px + py < 0.0 && u <= 0.5 {
        [u, v, 2.0, hit_w]
    } else {
        miss
    }
}

fn compare(got: &[[f32; 4]], want: impl Fn(u32, u32) -> [f32; 4]) {
    let mut wrong = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            let g = got[(y * 4 + x) as usize];
            let w = want(x, y);
            if g.iter().zip(w).any(|(a, b)| (a - b).abs() > 1e-4) {
                wrong.push(format!("pixel ({x}, {y}): got {g:?}, want {w:?}"));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// `n` RGBA32F values from the start of `bytes`.
fn read4(bytes: &[u8], n: usize) -> Vec<[f32; 4]> {
    bytes
        .chunks_exact(16)
        .take(n)
        .map(|c| {
            let f = |k: usize| f32::from_le_bytes([c[k], c[k + 1], c[k + 2], c[k + 3]]);
            [f(0), f(4), f(8), f(12)]
        })
        .collect()
}

fn hlsl_path(name: &str) -> PathBuf {
    common::root().join("tests/hlsl").join(name)
}

fn compile_whole(name: &str) -> Vec<u32> {
    hlsl::compile_file(&hlsl_path(name), &HlslOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
        .words
}

#[test]
fn ray_tracing_pipeline_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let words = compile_whole("exec_pipeline.hlsl");
    let stages = one_module(&words, &PIPELINE_STAGES);
    let got = read4(&trace(&ctx, &stages, &PIPELINE_GROUPS, Geom::Triangle), 16);
    // The any-hit shader ignores hits with u > 0.5; the second ray always
    // reaches miss shader 1, which adds 10.
    compare(&got, |x, y| {
        triangle_expectation(x, y, 11.0, [0.0, 0.0, 1.0, 10.0])
    });
    assert!(got.iter().any(|g| g[3] == 11.0) && got.iter().any(|g| g[3] == 10.0));
}

#[test]
fn intersection_and_callable_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let words = compile_whole("exec_procedural.hlsl");
    let stages = one_module(&words, &PROCEDURAL_STAGES);
    let got = read4(
        &trace(&ctx, &stages, &PROCEDURAL_GROUPS, Geom::SphereBox),
        16,
    );
    compare(&got, |x, y| {
        let (px, py) = pixel(x, y);
        let called = 2.0 * x as f32 + 1.0;
        let disc = 0.25 - (px * px + py * py);
        if disc > 0.0 {
            let s = disc.sqrt();
            [-2.0 * s, 2.0 - s, 7.0, called]
        } else {
            [0.0, 0.0, 0.0, 100.0 + called]
        }
    });
    assert!(got.iter().any(|g| g[2] == 7.0), "no sphere hits: {got:?}");
}

/// Runs exec_rayquery.hlsl's `entry` over the triangle scene; returns the
/// output buffer's bytes.
fn ray_query(ctx: &Context, words: &[u32], entry: &str) -> Vec<u8> {
    let tlas = scene(ctx, Geom::Triangle);
    let out = storage(ctx, 16 * 16);
    dispatch(
        ctx,
        words,
        entry,
        &[
            (
                BindingKind::AccelerationStructure,
                Resource::AccelerationStructure(&tlas),
            ),
            (BindingKind::StorageBuffer, Resource::Buffer(&out)),
        ],
    );
    out.read()
}

#[test]
fn ray_query_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    if !common::has_ray_query(&ctx) {
        return;
    }
    let words = compile_whole("exec_rayquery.hlsl");
    let got = read4(&ray_query(&ctx, &words, "Query"), 16);
    compare(&got, |x, y| {
        triangle_expectation(x, y, 1.0, [0.0, 0.0, 1.0, 0.0])
    });
}

/// Runs exec_memory.hlsl's `entry`: binding 0 a 1,024-byte buffer whose
/// first 64 words are 1000, 1001, …; binding 1 four counters. Returns both.
fn run_memory(ctx: &Context, words: &[u32], entry: &str) -> (Vec<u32>, Vec<u32>) {
    let init: Vec<u32> = (0..64).map(|i| 1000 + i).collect();
    let mut raw = storage(ctx, 1024);
    raw.write(0, rtlint::vk::bytes_of(&init)).unwrap();
    let counts = storage(ctx, 16);
    dispatch(
        ctx,
        words,
        entry,
        &[
            (BindingKind::StorageBuffer, Resource::Buffer(&raw)),
            (BindingKind::StorageBuffer, Resource::Buffer(&counts)),
        ],
    );
    (raw.read_u32(), counts.read_u32())
}

#[test]
fn groupshared_atomics_and_byte_address_buffers_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let words = compile_whole("exec_memory.hlsl");
    let (r, c) = run_memory(&ctx, &words, "Main");
    for i in 0..64u32 {
        assert_eq!(
            r[64 + i as usize],
            1000 + i + 2 * (63 - i),
            "word {}",
            64 + i
        );
    }
    assert_eq!(&r[128..130], &[2016, 7]);
    assert_eq!(&r[132..136], &[1003, 1002, 1001, 1000]);
    assert_eq!(&c[..3], &[63, 64, u32::MAX]);
    assert!((1..=64).contains(&c[3]), "compare-exchange stored {}", c[3]);
    assert_eq!(&r[192..194], &[128, 189]);
}

/// The 2×2 texture exec_textures.hlsl samples.
const TEXELS: [[f32; 4]; 4] = [
    [1.0, 0.0, 0.0, 1.0],
    [0.0, 2.0, 0.0, 1.0],
    [0.0, 0.0, 3.0, 1.0],
    [4.0, 4.0, 4.0, 1.0],
];

/// Runs exec_textures.hlsl's `entry`: binding 0 the 2×2 [`TEXELS`], binding
/// 1 a nearest sampler, binding 2 a 4×4 storage image, binding 3 the output
/// buffer of 16 float4s, whose bytes it returns.
fn run_textures(ctx: &Context, words: &[u32], entry: &str) -> Vec<u8> {
    let tex = StorageImage::new(ctx, 2, 2).unwrap();
    tex.write(ctx, &TEXELS).unwrap();
    let img = StorageImage::new(ctx, 4, 4).unwrap();
    let sampler = Sampler::nearest(ctx).unwrap();
    let out = storage(ctx, 16 * 16);
    dispatch(
        ctx,
        words,
        entry,
        &[
            (
                BindingKind::SampledImage,
                Resource::SampledImage(tex.view()),
            ),
            (BindingKind::Sampler, Resource::Sampler(sampler.raw())),
            (
                BindingKind::StorageImage,
                Resource::StorageImage(img.view()),
            ),
            (BindingKind::StorageBuffer, Resource::Buffer(&out)),
        ],
    );
    out.read()
}

#[test]
fn textures_and_storage_images_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    let words = compile_whole("exec_textures.hlsl");
    let got = read4(&run_textures(&ctx, &words, "Main"), 16);
    for (i, g) in got.iter().enumerate() {
        let (x, y) = (i % 4, i / 4);
        // Nearest sampling of the 2x2 texture at the 4x4 pixel centers,
        // plus a texel fetch, plus what the storage image read back.
        let sampled = TEXELS[(y / 2) * 2 + x / 2];
        let fetched = TEXELS[(y % 2) * 2 + x % 2];
        let stored = [x as f32, y as f32, 0.5, 1.0];
        let want: Vec<f32> = (0..4)
            .map(|c| sampled[c] + 10.0 * fetched[c] + 100.0 * stored[c])
            .collect();
        assert_eq!(g.to_vec(), want, "pixel {i}");
    }
}

/// Runs `entry` of `file` once and returns every output's bytes.
fn run_compute_case(ctx: &Context, words: &[u32], entry: &str, file: &str) -> Vec<Vec<u8>> {
    let bytes = |w: &[u32]| rtlint::vk::bytes_of(w).to_vec();
    match file {
        "exec_memory.hlsl" => {
            // Word 195 onward and the compare-exchange winner depend on scheduling.
            let (r, c) = run_memory(ctx, words, entry);
            vec![bytes(&r[..192]), bytes(&c[..3])]
        }
        "exec_textures.hlsl" => vec![run_textures(ctx, words, entry)],
        _ => unreachable!("no setup for {file}"),
    }
}

/// spirv-val's first complaint about `words`, if any.
fn invalid_spirv(words: &[u32]) -> Option<String> {
    rtlint_testkit::spirv_val(words, &[])
        .err()
        .map(|e| e.lines().next().unwrap_or("").to_string())
}

/// Slang's SPIR-V for one entry point of `file`, its `OpSource` language set
/// to Unknown (Slang's code 11 is newer than Debian's SPIR-V consumers).
fn slang_module(slang: &rtlint_testkit::Slang, file: &str, entry: &str, stage: Stage) -> Vec<u32> {
    let mut words = slang
        .compile_hlsl(
            &hlsl_path(file),
            entry,
            rtlint_testkit::stage_name(stage),
            &[],
        )
        .unwrap_or_else(|e| panic!("{file}: {e}"));
    rtlint_testkit::unknown_source_language(&mut words);
    words
}

/// The same HLSL compiled by Slang and by rtlint computes the same bytes on
/// the driver.
#[test]
fn differential_against_slang_on_the_driver() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    let Some(ctx) = common::device() else {
        return;
    };
    let mut compared = 0;
    for file in ["exec_memory.hlsl", "exec_textures.hlsl"] {
        let ours = compile_whole(file);
        let theirs = slang_module(&slang, file, "Main", Stage::Compute);
        // Compare only where Slang's module is valid: for `img[p].z *= 2.0`
        // Slang 2026.12 emits an OpImageTexelPointer to a vector, which
        // spirv-val and lavapipe reject.
        if let Some(why) = invalid_spirv(&theirs) {
            eprintln!("{file}: Slang's module is invalid, not compared: {why}");
            continue;
        }
        compared += 1;
        let a = run_compute_case(&ctx, &ours, "Main", file);
        // Slang names every entry point `main`.
        let b = run_compute_case(&ctx, &theirs, "main", file);
        assert_eq!(a, b, "{file}: rtlint and Slang disagree");
    }
    assert!(compared >= 1, "nothing was compared");
    // Inline ray tracing, where the driver has ray queries.
    if !ctx.info().ray_query {
        println!(
            "ray query part not run: {} lacks VK_KHR_ray_query",
            ctx.info().name
        );
        return;
    }
    let ours = compile_whole("exec_rayquery.hlsl");
    let theirs = slang_module(&slang, "exec_rayquery.hlsl", "Query", Stage::Compute);
    assert_eq!(invalid_spirv(&theirs), None);
    assert_eq!(
        ray_query(&ctx, &ours, "Query"),
        ray_query(&ctx, &theirs, "main"),
        "ray query: rtlint and Slang disagree"
    );
}

/// A pipeline test: file, scene, stages (entry name and stage), groups.
type Case = (
    &'static str,
    Geom,
    &'static [(&'static str, Stage)],
    &'static [Group],
);

/// The ray-tracing pipeline and the procedural/callable pipeline compiled by
/// Slang (one module per entry point) and by rtlint give the same bytes.
#[test]
fn ray_tracing_differential_against_slang_on_the_driver() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    let Some(ctx) = common::device() else {
        return;
    };
    let cases: [Case; 2] = [
        (
            "exec_pipeline.hlsl",
            Geom::Triangle,
            &PIPELINE_STAGES,
            &PIPELINE_GROUPS,
        ),
        (
            "exec_procedural.hlsl",
            Geom::SphereBox,
            &PROCEDURAL_STAGES,
            &PROCEDURAL_GROUPS,
        ),
    ];
    let mut compared = 0;
    for (file, geom, list, groups) in cases {
        let ours = compile_whole(file);
        let theirs: Vec<Vec<u32>> = list
            .iter()
            .map(|(entry, stage)| {
                let w = slang_module(&slang, file, entry, *stage);
                if let Some(why) = invalid_spirv(&w) {
                    panic!("{file}: Slang's {entry} is invalid: {why}");
                }
                w
            })
            .collect();
        let a = trace(&ctx, &one_module(&ours, list), groups, geom);
        let slang_stages: Vec<ShaderStage<'_>> = theirs
            .iter()
            .zip(list)
            .map(|(w, (_, stage))| ShaderStage {
                spirv: w,
                entry_point: "main",
                stage: *stage,
            })
            .collect();
        let b = trace(&ctx, &slang_stages, groups, geom);
        assert_eq!(a, b, "{file}: rtlint and Slang disagree");
        compared += 1;
    }
    assert_eq!(compared, 2);
}

/// 16-bit types (`-enable-16bit-types`) compute in 16 bits on the driver:
/// half results and matrices, `asfloat16`/`asuint16`/`asint16`, 16-bit
/// `ByteAddressBuffer.Load<T>`, a wave sum, int16 wrap-around, uint16 shifts, conversions both ways,
/// and 16-bit values read from a constant buffer.
#[test]
fn sixteen_bit_arithmetic_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    if !ctx.info().sixteen_bit {
        println!(
            "16-bit part not run: {} lacks shaderFloat16/shaderInt16/16-bit storage/subgroup extended types",
            ctx.info().name
        );
        return;
    }
    let opts = HlslOptions {
        enable_16bit_types: true,
        ..Default::default()
    };
    let words = hlsl::compile_file(&hlsl_path("exec_half.hlsl"), &opts)
        .unwrap_or_else(|e| panic!("{e}"))
        .words;
    let outs = run_half(&ctx, &words, "Main");
    let halves = |b: &Vec<u8>, n: usize| -> Vec<u16> {
        b.chunks(2)
            .take(n)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect()
    };
    // 1.75, 2.0, 2052.0 (2051 rounded to a half), 1.5, 2.625, -3.0, 0.1
    // rounded to a half (0.0999755859375), 11.0 (a half matrix product),
    // 2.5 (1.5 and 1.0 through their bits), 3.0 (a one-lane wave sum),
    // 9.0 (2 + 3 + 4 loaded from bytes 2, 4 and 6).
    assert_eq!(
        halves(&outs[0], 11),
        vec![
            0x3f00, 0x4000, 0x6802, 0x3e00, 0x4140, 0xc200, 0x2e66, 0x4980, 0x4100, 0x4200, 0x4880
        ]
    );
    // ..., and the bits of half -0.5 (0xb800) as an int16.
    let ints: Vec<i16> = halves(&outs[1], 5).iter().map(|v| *v as i16).collect();
    assert_eq!(ints, vec![-6, i16::MIN, -9, 1, 0xb800u16 as i16]);
    assert_eq!(
        halves(&outs[2], 5),
        vec![0xe000, 0xffff, 0x3e00, !7u16, 0x4400]
    );
    // (half)0.1 folded at compile time is the same half: 1638 / 2^14.
    let floats: Vec<f32> = outs[3]
        .chunks(4)
        .take(3)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(floats, vec![13.0, 1638.0 / 16384.0, 5.0]);
}

/// Runs exec_half.hlsl's `entry` once: its four output buffers' bytes.
fn run_half(ctx: &Context, words: &[u32], entry: &str) -> Vec<Vec<u8>> {
    let outs: Vec<Buffer> = (0..4).map(|_| storage(ctx, 64)).collect();
    // scale 0.5 (half 0x3800) at 0, count 7 at 2, neg -2 at 4, base 10.0 at 8.
    let mut cb = vec![0u8; 16];
    cb[0..2].copy_from_slice(&0x3800u16.to_le_bytes());
    cb[2..4].copy_from_slice(&7u16.to_le_bytes());
    cb[4..6].copy_from_slice(&(-2i16).to_le_bytes());
    cb[8..12].copy_from_slice(&10.0f32.to_le_bytes());
    let ubo = Buffer::from_data(ctx, raw::BufferUsageFlags::UNIFORM_BUFFER, &cb).unwrap();
    let mut list: Vec<(BindingKind, Resource)> = outs
        .iter()
        .map(|b| (BindingKind::StorageBuffer, Resource::Buffer(b)))
        .collect();
    list.push((BindingKind::UniformBuffer, Resource::Buffer(&ubo)));
    // Halves 1.0, 2.0, 3.0, 4.0 for the ByteAddressBuffer's 16-bit loads.
    let raw_bytes: Vec<u8> = [0x3c00u16, 0x4000, 0x4200, 0x4400]
        .iter()
        .flat_map(|h| h.to_le_bytes())
        .collect();
    let raw = Buffer::from_data(ctx, STORAGE, &raw_bytes).unwrap();
    list.push((BindingKind::StorageBuffer, Resource::Buffer(&raw)));
    dispatch(ctx, words, entry, &list);
    outs.iter().map(|b| b.read()).collect()
}

/// exec_half.hlsl compiled by Slang (whose `half` is always 16-bit) and by
/// rtlint with -enable-16bit-types writes the same bytes on the driver.
#[test]
fn sixteen_bit_differential_against_slang() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    let Some(ctx) = common::device() else {
        return;
    };
    if !ctx.info().sixteen_bit {
        println!(
            "16-bit part not run: {} lacks 16-bit support",
            ctx.info().name
        );
        return;
    }
    let opts = HlslOptions {
        enable_16bit_types: true,
        ..Default::default()
    };
    let ours = hlsl::compile_file(&hlsl_path("exec_half.hlsl"), &opts)
        .unwrap_or_else(|e| panic!("{e}"))
        .words;
    let theirs = slang_module(&slang, "exec_half.hlsl", "Main", Stage::Compute);
    if let Some(why) = invalid_spirv(&theirs) {
        panic!("Slang's exec_half module is invalid: {why}");
    }
    assert_eq!(
        run_half(&ctx, &ours, "Main"),
        run_half(&ctx, &theirs, "main"),
        "rtlint and Slang disagree on 16-bit arithmetic"
    );
}

/// The hit triangle's vertex positions through DXC's inline-SPIR-V built-in
/// (`VK_KHR_ray_tracing_position_fetch`), read from a structure built with
/// data access allowed: the face normal and a weighted sum of the positions
/// that any permutation or zeroed vertex would change.
#[test]
fn position_fetch_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    if !ctx.info().position_fetch {
        // An optional extension (lavapipe has it since Mesa 25.0): the
        // compile test still validates the module.
        println!(
            "position fetch not run: {} lacks VK_KHR_ray_tracing_position_fetch \
             (or the validation layer is older than it)",
            ctx.info().name
        );
        return;
    }
    let words = compile_whole("exec_position_fetch.hlsl");
    let stages = one_module(
        &words,
        &[
            ("Gen", Stage::RayGeneration),
            ("Miss", Stage::Miss),
            ("FaceNormal", Stage::ClosestHit),
        ],
    );
    let groups = [
        Group::General(0),
        Group::General(1),
        Group::Triangles {
            closest_hit: Some(2),
            any_hit: None,
        },
    ];
    let v = [[-0.9f32, -0.9, 1.0], [0.9, -0.9, 1.5], [-0.9, 0.9, 1.0]];
    let blas = AccelerationStructure::bottom_level_readable(
        &ctx,
        &[Geometry::Triangles {
            positions: &v,
            indices: &[0, 1, 2],
            opaque: true,
        }],
    )
    .unwrap();
    let tlas = AccelerationStructure::top_level(&ctx, &[Instance::identity(&blas)]).unwrap();
    let got = read4(&trace_in(&ctx, &stages, &groups, &tlas), 16);
    let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let (e1, e2) = (sub(v[1], v[0]), sub(v[2], v[0]));
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let s: Vec<f32> = (0..3)
        .map(|k| v[0][k] + 2.0 * v[1][k] + 3.0 * v[2][k])
        .collect();
    let hit = [
        n[0] / len,
        n[1] / len,
        n[2] / len,
        s[0] + 10.0 * s[1] + 100.0 * s[2],
    ];
    // The triangle covers x + y < 0 of the launch's (shifted) pixel centres.
    compare(&got, |x, y| {
        let (px, py) = pixel(x, y);
        if px + py < 0.0 {
            hit
        } else {
            [-1.0; 4]
        }
    });
    assert!(got.iter().any(|g| g[3] != -1.0) && got.iter().any(|g| g[3] == -1.0));
}

/// Shader execution reordering (`dx::HitObject`, `MaybeReorderThread`) on a
/// driver with `VK_NV_ray_tracing_invocation_reorder`: the hit object's
/// answers and the shaders `Invoke` runs match a plain trace of the scene.
#[test]
fn invocation_reorder_on_the_driver() {
    let Some(ctx) = common::device() else {
        return;
    };
    if !ctx.info().invocation_reorder {
        // An optional extension (NVIDIA's; lavapipe has none): the compile
        // test still validates ser.hlsl.
        println!(
            "invocation reorder not run: {} lacks VK_NV_ray_tracing_invocation_reorder \
             (or the validation layer is older than it)",
            ctx.info().name
        );
        return;
    }
    let words = compile_whole("exec_ser.hlsl");
    let stages = one_module(
        &words,
        &[
            ("Gen", Stage::RayGeneration),
            ("Miss", Stage::Miss),
            ("Sky", Stage::Miss),
            ("Hit", Stage::ClosestHit),
        ],
    );
    let groups = [
        Group::General(0),
        Group::General(1),
        Group::General(2),
        Group::Triangles {
            closest_hit: Some(3),
            any_hit: None,
        },
    ];
    let got = read4(&trace(&ctx, &stages, &groups, Geom::Triangle), 16);
    // A hit: barycentrics, t = 2 and the closest hit's 1 + 20. A miss: miss
    // shader 0 (2), then the second hit object's miss shader 1 (+3), + 10.
    compare(&got, |x, y| {
        let (px, py) = pixel(x, y);
        if px + py < 0.0 {
            [(px + 0.9) / 1.8, (py + 0.9) / 1.8, 2.0, 21.0]
        } else {
            [0.0, 0.0, -1.0, 15.0]
        }
    });
    assert!(got.iter().any(|g| g[3] == 21.0) && got.iter().any(|g| g[3] == 15.0));
}
