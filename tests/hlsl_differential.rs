#![cfg(feature = "vulkan")]
//! Differential test of rtlint's HLSL compiler against Slang on the real
//! driver: each case compiles the same HLSL entry points with both compilers,
//! validates every module with spirv-val, compares the reflected interface per
//! entry point, runs both builds with the same scene and bindings through
//! `rtlint::vk`, and compares the outputs (floats within 1/255, integers
//! exactly). Needs Slang, spirv-val and a ray-tracing device (the skip policy
//! of `rtlint_testkit`: a failure in CI, a `skipped:` line elsewhere).
//! `RTLINT_DIFF_DUMP=1` prints both readbacks of every case and writes every
//! module to `$TMPDIR/rtlint-diff/`.

mod common;

use rtlint::front::hlsl::{self, HlslOptions};
use rtlint::program::scalar::scalar_size;
use rtlint::program::Program;
use rtlint::shader::Language;
use rtlint::shader::Stage;
use rtlint::vk::{
    raw, Aabb, AccelerationStructure, Binding, BindingKind, Buffer, ComputePipeline, Context,
    Geometry, Group, Instance, RayTracingPipeline, RayTracingPipelineDesc, Resource, ShaderStage,
    StorageImage, IDENTITY,
};
use rtlint_testkit::stage_name;
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::Path;

/// Largest difference allowed between two float channels.
const TOLERANCE: f32 = 1.0 / 255.0;

/// How an output buffer is read and compared; a "pixel" is one element.
#[derive(Clone, Copy, Debug)]
enum Format {
    /// `float4` elements, channels within [`TOLERANCE`].
    F32x4,
    /// `float` elements, within [`TOLERANCE`].
    F32,
    /// `uint` words (which may hold `asuint` floats), compared exactly.
    U32,
}

/// Geometry in the top-level structure bound at binding 0.
#[derive(Clone, Copy, Debug)]
enum SceneKind {
    None,
    /// One non-opaque triangle at z = 1 (the scene of tests/hlsl_exec.rs).
    Triangle,
    /// One non-opaque box around a unit-diameter sphere centred at z = 1.
    SphereBox,
    /// An opaque floor (instance 0) under a floating triangle (instance 1).
    Shadow,
    /// One non-opaque quad mesh, twice: at z = 0 (instance 0) and, shifted, at z = 1 (instance 1).
    AlphaQuads,
    /// A quad of one front- and one back-facing triangle, and a procedural box.
    Mixed,
}

enum Data {
    Scene,
    Storage(Vec<u8>),
    Uniform(Vec<u8>),
    /// An `rgba32f` storage image of this width and height, cleared to zero.
    Image(u32, u32),
}

struct Res {
    binding: u32,
    data: Data,
    /// Compared after the run when set.
    compare: Option<Format>,
}

enum Shape {
    Compute {
        groups: [u32; 3],
    },
    Pipeline {
        /// Stage indices refer to the case's entry list.
        groups: Vec<Group>,
        depth: u32,
        launch: [u32; 2],
    },
}

struct Case {
    name: &'static str,
    file: &'static str,
    entries: Vec<(&'static str, Stage)>,
    shape: Shape,
    scene: SceneKind,
    resources: Vec<Res>,
    /// Constant buffers use HLSL packing where it differs from std140, as
    /// rtlint always does: Slang gets `-fvk-use-dx-layout` (which also packs
    /// structs in structured buffers tighter than DXC's default std430, so
    /// only where there are none), spirv-val `--scalar-block-layout` (the
    /// device has scalarBlockLayout on).
    dx_layout: bool,
}

fn zeros(bytes: usize) -> Data {
    Data::Storage(vec![0; bytes])
}

fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

fn out(binding: u32, bytes: usize, format: Format) -> Res {
    Res {
        binding,
        data: zeros(bytes),
        compare: Some(format),
    }
}

fn input(binding: u32, data: Data) -> Res {
    Res {
        binding,
        data,
        compare: None,
    }
}

/// Vertices of diff_alpha.hlsl's quad: `{float3 position; float2 uv;}` under
/// DXC's default structured-buffer layout (uv at 16, stride 32).
fn alpha_vertices() -> Vec<u8> {
    let mut b = Vec::new();
    for (p, uv) in QUAD
        .iter()
        .zip([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    {
        b.extend(f32_bytes(&[p[0], p[1], p[2], 0.0, uv[0], uv[1], 0.0, 0.0]));
    }
    b
}

const QUAD: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
const QUAD_INDICES: [u32; 6] = [0, 1, 2, 0, 2, 3];

/// `n` words, each the float value of its own index: a constant read back
/// names the word it was read from.
fn index_words(n: u32) -> Data {
    Data::Uniform(f32_bytes(&(0..n).map(|i| i as f32).collect::<Vec<_>>()))
}

/// Where both compilers put cbuffer_packing.hlsl's implicit `$Globals`.
const GLOBALS_BINDING: u32 = 2;

fn cases() -> Vec<Case> {
    use Stage::*;
    let gen = Group::General;
    let tri = |closest_hit, any_hit| Group::Triangles {
        closest_hit,
        any_hit,
    };
    let words = |n: u32| (0..n).flat_map(|i| (1000 + i).to_le_bytes()).collect();
    vec![
        Case {
            name: "shadow",
            file: "diff_shadow.hlsl",
            entries: vec![
                ("RayGen", RayGeneration),
                ("Miss", Miss),
                ("ShadowMiss", Miss),
                ("ClosestHit", ClosestHit),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), gen(2), tri(Some(3), None), tri(None, None)],
                depth: 2,
                launch: [32, 32],
            },
            scene: SceneKind::Shadow,
            resources: vec![
                input(0, Data::Scene),
                out(1, 32 * 32 * 16, Format::F32x4),
                input(2, Data::Uniform(f32_bytes(&[0.4, 1.0, 0.3, 0.2]))),
            ],
            dx_layout: false,
        },
        Case {
            name: "alpha",
            file: "diff_alpha.hlsl",
            entries: vec![
                ("RayGen", RayGeneration),
                ("Miss", Miss),
                ("Shade", ClosestHit),
                ("AlphaTest", AnyHit),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), tri(Some(2), Some(3))],
                depth: 1,
                launch: [24, 24],
            },
            scene: SceneKind::AlphaQuads,
            resources: vec![
                input(0, Data::Scene),
                input(1, Data::Storage(alpha_vertices())),
                input(
                    2,
                    Data::Storage(QUAD_INDICES.iter().flat_map(|i| i.to_le_bytes()).collect()),
                ),
                out(3, 24 * 24 * 2 * 16, Format::F32x4),
            ],
            dx_layout: false,
        },
        Case {
            name: "camera-shadow",
            file: "pipeline.hlsl",
            entries: vec![
                ("RayGen", RayGeneration),
                ("Miss", Miss),
                ("ShadowMiss", Miss),
                ("ClosestHit", ClosestHit),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), gen(2), tri(Some(3), None), tri(None, None)],
                depth: 2,
                launch: [32, 32],
            },
            scene: SceneKind::Shadow,
            resources: vec![
                input(0, Data::Scene),
                Res {
                    binding: 1,
                    data: Data::Image(32, 32),
                    compare: Some(Format::F32x4),
                },
                // Camera: viewInverse (column-major: one row per column, the
                // last holding the translation), lightDir, tMax.
                input(
                    2,
                    Data::Uniform(f32_bytes(&[
                        1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 3.0,
                        1.0, -0.4, -1.0, -0.3, 100.0,
                    ])),
                ),
            ],
            dx_layout: false,
        },
        Case {
            name: "callable",
            file: "callable.hlsl",
            entries: vec![
                ("Gen", RayGeneration),
                ("Checker", Callable),
                ("Tint", Callable),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), gen(2)],
                depth: 1,
                launch: [32, 16],
            },
            scene: SceneKind::None,
            resources: vec![Res {
                binding: 0,
                data: Data::Image(32, 16),
                compare: Some(Format::F32x4),
            }],
            dx_layout: false,
        },
        Case {
            name: "callable-specialized",
            file: "callable.hlsl",
            entries: vec![
                ("GenSpecialized", RayGeneration),
                ("Checker", Callable),
                ("Tint", Callable),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), gen(2)],
                depth: 1,
                launch: [8, 8],
            },
            scene: SceneKind::None,
            resources: vec![Res {
                binding: 0,
                data: Data::Image(8, 8),
                compare: Some(Format::F32x4),
            }],
            dx_layout: false,
        },
        Case {
            name: "triangle-anyhit",
            file: "exec_pipeline.hlsl",
            entries: vec![
                ("RG", RayGeneration),
                ("MissColor", Miss),
                ("MissProbe", Miss),
                ("Hit", ClosestHit),
                ("Filter", AnyHit),
            ],
            shape: Shape::Pipeline {
                groups: vec![gen(0), gen(1), gen(2), tri(Some(3), Some(4))],
                depth: 1,
                launch: [16, 16],
            },
            scene: SceneKind::Triangle,
            resources: vec![input(0, Data::Scene), out(1, 16 * 16 * 16, Format::F32x4)],
            dx_layout: false,
        },
        Case {
            name: "procedural-callable",
            file: "exec_procedural.hlsl",
            entries: vec![
                ("Gen", RayGeneration),
                ("Miss", Miss),
                ("SphereHit", ClosestHit),
                ("Sphere", Intersection),
                ("Twice", Callable),
            ],
            shape: Shape::Pipeline {
                groups: vec![
                    gen(0),
                    gen(1),
                    Group::Procedural {
                        intersection: 3,
                        closest_hit: Some(2),
                        any_hit: None,
                    },
                    gen(4),
                ],
                depth: 1,
                // The shader writes row-major with a fixed width of 4.
                launch: [4, 16],
            },
            scene: SceneKind::SphereBox,
            resources: vec![input(0, Data::Scene), out(1, 4 * 16 * 16, Format::F32x4)],
            dx_layout: false,
        },
        Case {
            name: "rayquery-triangle",
            file: "exec_rayquery.hlsl",
            entries: vec![("Query", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::Triangle,
            resources: vec![input(0, Data::Scene), out(1, 16 * 16, Format::F32x4)],
            dx_layout: false,
        },
        Case {
            name: "rayquery-occlusion",
            file: "rayquery.hlsl",
            entries: vec![("AmbientOcclusion", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::Mixed,
            resources: vec![
                input(0, Data::Scene),
                out(1, 8 * 64 * 4, Format::F32),
                // Params: origin, rayCount (bits), radius.
                input(
                    2,
                    Data::Uniform(f32_bytes(&[
                        0.0,
                        0.2,
                        0.0,
                        f32::from_bits(24),
                        4.0,
                        0.0,
                        0.0,
                        0.0,
                    ])),
                ),
            ],
            dx_layout: false,
        },
        Case {
            name: "compute-math",
            file: "diff_math.hlsl",
            entries: vec![("Main", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::None,
            resources: vec![out(0, 64 * 10 * 16, Format::F32x4)],
            dx_layout: false,
        },
        Case {
            name: "compute-frontend",
            file: "diff_frontend.hlsl",
            entries: vec![("Main", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::None,
            resources: vec![out(0, 64 * 4 * 16, Format::F32x4)],
            dx_layout: false,
        },
        Case {
            name: "compute-memory",
            file: "exec_memory.hlsl",
            entries: vec![("Main", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::None,
            resources: vec![
                Res {
                    binding: 0,
                    data: Data::Storage(words(256)),
                    compare: Some(Format::U32),
                },
                out(1, 16, Format::U32),
            ],
            dx_layout: false,
        },
        Case {
            name: "cbuffer-offsets",
            file: "diff_cbuffer.hlsl",
            entries: vec![("Main", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::None,
            resources: vec![input(0, index_words(80)), out(1, 40 * 4, Format::F32)],
            dx_layout: true,
        },
        Case {
            name: "cbuffer-globals",
            file: "cbuffer_packing.hlsl",
            entries: vec![("Main", Compute)],
            shape: Shape::Compute { groups: [1, 1, 1] },
            scene: SceneKind::None,
            resources: vec![
                input(0, index_words(32)),
                out(1, 2 * 4, Format::F32),
                input(GLOBALS_BINDING, index_words(8)),
            ],
            dx_layout: true,
        },
    ]
}

/// HLSL test shaders the differential test does not run, and why. Every
/// file in tests/hlsl must be in a case or here.
const NOT_RUN: &[(&str, &str)] = &[
    (
        "half.hlsl",
        "needs -enable-16bit-types, which the differential cases do not pass; \
         tests/hlsl_compile.rs checks its 16-bit types, capabilities and layouts",
    ),
    (
        "exec_half.hlsl",
        "needs -enable-16bit-types, which the differential cases do not pass; \
         tests/hlsl_exec.rs runs it against known values and against Slang",
    ),
    (
        "corpus_constructs.hlsl",
        "samples textures, uses device addresses and a pixel shader; tests/hlsl_compile.rs \
         checks each construct's instructions",
    ),
    (
        "pixel.hlsl",
        "a pixel shader: rtlint::vk has no graphics pipeline; tests/hlsl_compile.rs \
         compares its interface (built-ins, locations, Flat, execution mode) with Slang's",
    ),
    (
        "exec_compute.hlsl",
        "Slang 2026.12 rejects valid HLSL in it: a method assigns `this.count` without \
         `[mutating]`, the `(float2)q` truncating cast, unscoped enum constants (`MODE_C`); \
         diff_math.hlsl covers arithmetic and intrinsics, tests/hlsl_exec.rs runs it",
    ),
    (
        "language.hlsl",
        "Slang 2026.12 rejects the `(float3)c4` truncating cast, and it reads push \
         constants, which `ComputePipeline` does not set",
    ),
    (
        "exec_textures.hlsl",
        "samples a texture: rtlint::vk makes storage images only, no sampled images or samplers",
    ),
    (
        "anyhit_alpha.hlsl",
        "samples a texture and has no ray generation shader; diff_alpha.hlsl is the \
         alpha test over buffers",
    ),
    (
        "intersection_sphere.hlsl",
        "no ray generation shader, and it binds set 1 (rtlint::vk binds set 0); \
         exec_procedural.hlsl runs ReportHit with an attribute struct",
    ),
    (
        "resources.hlsl",
        "sampled textures, samplers, unbounded descriptor arrays and sets 1 and 2",
    ),
    (
        "attributes.hlsl",
        "attribute handling (hints, vk::image_format, inline-SPIR-V capabilities): checked structurally in tests/hlsl_compile.rs and walked in tests/hlsl_errors.rs",
    ),
    (
        "bindings_and_sizes.hlsl",
        "binds sets 7, 98 and 99 (rtlint::vk binds set 0); tests/hlsl_compile.rs checks the bindings",
    ),
    (
        "buffer_params.hlsl",
        "front-end construct (functions specialized per buffer): tests/hlsl_compile.rs checks the copies",
    ),
    (
        "default_params.hlsl",
        "front-end construct: tests/hlsl_compile.rs checks every call passes every parameter; tests/hlsl_exec.rs runs it",
    ),
    (
        "hlsl2021.hlsl",
        "samples a texture (rtlint::vk makes storage images only)",
    ),
    (
        "nested_records.hlsl",
        "front-end construct (static members, nested structs, inheritance): tests/hlsl_compile.rs checks the layouts",
    ),
    (
        "pack_matrix.hlsl",
        "front-end construct (matrix layout): tests/hlsl_compile.rs checks the decorations",
    ),
    (
        "ext_builtin_output.hlsl",
        "a pixel shader: rtlint::vk has no graphics pipeline; tests/hlsl_compile.rs checks \
         the built-in output's variable, decoration, store, capability and extension",
    ),
    (
        "ext_decorate.hlsl",
        "decorations (Restrict, RelaxedPrecision) that change no result; tests/hlsl_compile.rs \
         checks each OpDecorate and its target",
    ),
    (
        "bits_half.hlsl",
        "needs -enable-16bit-types, which the differential cases do not pass; \
         tests/hlsl_compile.rs checks that each count is of the zero-extended value",
    ),
    (
        "spec_half.hlsl",
        "needs -enable-16bit-types, which the differential cases do not pass; \
         tests/hlsl_compile.rs checks the spec constants' types, defaults and SpecIds",
    ),
    (
        "ext_instruction.hlsl",
        "its output depends on the shader clock; tests/hlsl_compile.rs checks each inline \
         instruction and its operands",
    ),
    (
        "position_fetch.hlsl",
        "checked for its built-in, capability and extension by tests/hlsl_compile.rs; \
         tests/hlsl_exec.rs runs exec_position_fetch.hlsl against hand-computed values",
    ),
    (
        "exec_position_fetch.hlsl",
        "tests/hlsl_exec.rs runs it against hand-computed values (face normal, weighted \
         sum of the vertex positions) on drivers with VK_KHR_ray_tracing_position_fetch",
    ),
    (
        "records.hlsl",
        "front-end construct (classes, static and out-of-line methods): tests/hlsl_compile.rs checks the calls",
    ),
    (
        "resource_helpers.hlsl",
        "samples textures (rtlint::vk makes storage images only)",
    ),
    (
        "resource_locals.hlsl",
        "samples textures (rtlint::vk makes storage images only)",
    ),
    (
        "exec_ser.hlsl",
        "needs shader invocation reorder, which lavapipe lacks; tests/hlsl_exec.rs runs it \
         against hand-computed values where the driver has it (NVIDIA)",
    ),
    (
        "ser.hlsl",
        "needs shader invocation reorder, which lavapipe lacks",
    ),
    (
        "shadow_compare.hlsl",
        "comparison samplers and a pixel shader (no sampled images or graphics pipeline in rtlint::vk)",
    ),
    (
        "sizeof_and_casts.hlsl",
        "front-end construct (sizeof, casts): tests/hlsl_compile.rs checks the folded constants",
    ),
    (
        "subobjects.hlsl",
        "DXR subobjects: tests/hlsl_compile.rs checks the data exposed",
    ),
    (
        "templates.hlsl",
        "front-end construct: tests/hlsl_compile.rs checks the instances",
    ),
    (
        "wave.hlsl",
        "wave intrinsics: tests/hlsl_compile.rs checks the instructions",
    ),
    (
        "windows_includes.hlsl",
        "include resolution: tests/hlsl_compile.rs checks the warning",
    ),
    (
        "exec_frontend.hlsl",
        "front-end constructs Slang does not all accept (default arguments on prototypes, \
         out-of-line methods); tests/hlsl_exec.rs runs it",
    ),
    (
        "classic",
        "a folder of classic entry points (stage given on the command line): \
         tests/hlsl_compile.rs compiles them",
    ),
    ("include", "a folder of include files"),
    (
        "dxc_suite",
        "a folder of shaders for what DXC's test suite found (pixel shaders, \
         decorations, capabilities): tests/hlsl_dxc_suite.rs checks them",
    ),
    (
        "rayquery_return.hlsl",
        "a function returning a ray query: tests/hlsl_compile.rs checks the call",
    ),
    (
        "texel_buffers.hlsl",
        "texel buffers (rtlint::vk binds no buffer views): tests/hlsl_compile.rs checks the images",
    ),
    (
        "descriptor_heaps.hlsl",
        "descriptor heaps: tests/hlsl_compile.rs checks the arrays and bindings",
    ),
    (
        "cbuffer_struct_tail.hlsl",
        "a member after a struct in a cbuffer: tests/hlsl_compile.rs checks the offsets \
         (diff_cbuffer.hlsl compares the same rule with Slang on the driver)",
    ),
    (
        "rayquery_params.hlsl",
        "ray queries passed to functions: tests/hlsl_compile.rs checks the parameters",
    ),
    (
        "int64.hlsl",
        "64-bit integers: tests/hlsl_compile.rs checks layouts, constants and conversions",
    ),
    ("common.hlsli", "an include file"),
];

fn build_scene(ctx: &Context, kind: SceneKind) -> Option<AccelerationStructure> {
    let tlas = |instances: &[Instance<'_>]| AccelerationStructure::top_level(ctx, instances);
    let blas = |g: &[Geometry<'_>]| AccelerationStructure::bottom_level(ctx, g);
    let r = match kind {
        SceneKind::None => return None,
        SceneKind::Triangle => {
            let b = blas(&[Geometry::Triangles {
                positions: &[[-0.9, -0.9, 1.0], [0.9, -0.9, 1.0], [-0.9, 0.9, 1.0]],
                indices: &[0, 1, 2],
                opaque: false,
            }])
            .unwrap();
            tlas(&[Instance::identity(&b)])
        }
        SceneKind::SphereBox => {
            let b = blas(&[Geometry::Aabbs {
                boxes: &[Aabb {
                    min: [-0.5, -0.5, 0.5],
                    max: [0.5, 0.5, 1.5],
                }],
                opaque: false,
            }])
            .unwrap();
            tlas(&[Instance::identity(&b)])
        }
        SceneKind::Shadow => {
            let floor = blas(&[Geometry::Triangles {
                positions: &[
                    [-4.0, 0.0, -4.0],
                    [-4.0, 0.0, 4.0],
                    [4.0, 0.0, 4.0],
                    [4.0, 0.0, -4.0],
                ],
                indices: &[0, 1, 2, 0, 2, 3],
                opaque: true,
            }])
            .unwrap();
            let occluder = blas(&[Geometry::Triangles {
                positions: &[[-0.8, 0.8, -0.5], [0.0, 0.8, 0.8], [0.8, 0.8, -0.5]],
                indices: &[0, 1, 2],
                opaque: true,
            }])
            .unwrap();
            tlas(&[
                Instance::identity(&floor),
                Instance {
                    custom_index: 1,
                    ..Instance::identity(&occluder)
                },
            ])
        }
        SceneKind::AlphaQuads => {
            let quad = blas(&[Geometry::Triangles {
                positions: &QUAD,
                indices: &QUAD_INDICES,
                opaque: false,
            }])
            .unwrap();
            let mut back = IDENTITY;
            back[0][3] = 0.125;
            back[2][3] = 1.0;
            tlas(&[
                Instance::identity(&quad),
                Instance {
                    transform: back,
                    custom_index: 1,
                    ..Instance::identity(&quad)
                },
            ])
        }
        SceneKind::Mixed => {
            // Seen from the origin (rays go towards +z), the first triangle
            // is wound one way and the second the other, so culling back
            // faces drops one of them.
            let quad = blas(&[Geometry::Triangles {
                positions: &[
                    [-2.0, -2.0, 1.0],
                    [0.0, -2.0, 1.0],
                    [0.0, 2.0, 1.0],
                    [-2.0, 2.0, 1.0],
                ],
                indices: &[0, 1, 2, 0, 3, 2],
                opaque: false,
            }])
            .unwrap();
            let boxes = blas(&[Geometry::Aabbs {
                boxes: &[Aabb {
                    min: [0.2, -2.0, 0.5],
                    max: [2.0, 2.0, 3.0],
                }],
                opaque: false,
            }])
            .unwrap();
            tlas(&[Instance::identity(&quad), Instance::identity(&boxes)])
        }
    };
    Some(r.unwrap())
}

fn vk_stage(s: Stage) -> rtlint::vk::Stage {
    use rtlint::vk::Stage as V;
    match s {
        Stage::RayGeneration => V::RayGeneration,
        Stage::Miss => V::Miss,
        Stage::ClosestHit => V::ClosestHit,
        Stage::AnyHit => V::AnyHit,
        Stage::Intersection => V::Intersection,
        Stage::Callable => V::Callable,
        other => panic!("{other:?} is not a ray-tracing pipeline stage"),
    }
}

/// Runs one build of a case (one module per entry point, in entry order) and
/// returns the bytes of every compared buffer, in resource order.
fn run(ctx: &Context, case: &Case, modules: &[Vec<u32>]) -> Vec<Vec<u8>> {
    let scene = build_scene(ctx, case.scene);
    let mut bindings = Vec::new();
    let mut buffers = Vec::new();
    let mut images = Vec::new();
    for r in &case.resources {
        let (kind, usage, bytes) = match &r.data {
            Data::Scene => {
                bindings.push(Binding::new(r.binding, BindingKind::AccelerationStructure));
                continue;
            }
            Data::Image(w, h) => {
                bindings.push(Binding::new(r.binding, BindingKind::StorageImage));
                images.push((r, StorageImage::new(ctx, *w, *h).unwrap()));
                continue;
            }
            Data::Storage(b) => (
                BindingKind::StorageBuffer,
                raw::BufferUsageFlags::STORAGE_BUFFER,
                b,
            ),
            Data::Uniform(b) => (
                BindingKind::UniformBuffer,
                raw::BufferUsageFlags::UNIFORM_BUFFER,
                b,
            ),
        };
        bindings.push(Binding::new(r.binding, kind));
        buffers.push((r, Buffer::from_data(ctx, usage, bytes).unwrap()));
    }
    let mut resources: Vec<(u32, Resource<'_>)> = buffers
        .iter()
        .map(|(r, b)| (r.binding, Resource::Buffer(b)))
        .chain(
            images
                .iter()
                .map(|(r, i)| (r.binding, Resource::StorageImage(i.view()))),
        )
        .collect();
    if let Some(s) = &scene {
        let at = case
            .resources
            .iter()
            .find(|r| matches!(r.data, Data::Scene))
            .expect("a scene needs a binding");
        resources.push((at.binding, Resource::AccelerationStructure(s)));
    }
    match &case.shape {
        Shape::Compute { groups } => {
            let p = ComputePipeline::new(ctx, &modules[0], case.entries[0].0, &bindings).unwrap();
            p.dispatch(&resources, groups[0], groups[1], groups[2])
                .unwrap();
        }
        Shape::Pipeline {
            groups,
            depth,
            launch,
        } => {
            let stages: Vec<ShaderStage<'_>> = case
                .entries
                .iter()
                .zip(modules)
                .map(|((name, stage), words)| ShaderStage {
                    spirv: words,
                    entry_point: name,
                    stage: vk_stage(*stage),
                })
                .collect();
            let p = RayTracingPipeline::new(
                ctx,
                &RayTracingPipelineDesc {
                    stages: &stages,
                    groups,
                    max_recursion_depth: *depth,
                    bindings: &bindings,
                    push_constant_size: 0,
                    stack_size: None,
                },
            )
            .unwrap();
            p.trace_rays(&resources, launch[0], launch[1], 1).unwrap();
        }
    }
    // In resource order, as the caller pairs them with the resources.
    case.resources
        .iter()
        .filter(|r| r.compare.is_some())
        .map(|r| {
            if let Some((_, b)) = buffers.iter().find(|(b, _)| b.binding == r.binding) {
                b.read()
            } else {
                let (_, i) = images.iter().find(|(i, _)| i.binding == r.binding).unwrap();
                let texels = i.read(ctx).unwrap();
                texels
                    .iter()
                    .flatten()
                    .flat_map(|x| x.to_le_bytes())
                    .collect()
            }
        })
        .collect()
}

/// What a module says about one entry point's interface.
#[derive(Debug, PartialEq, Eq)]
struct Interface {
    entry: String,
    stage: Stage,
    /// (set, binding, storage class) of every bound resource the entry uses.
    resources: BTreeSet<(u32, u32, String)>,
    /// Storage classes of the interface variables, less Private and Function:
    /// where a compiler keeps its temporaries is its own business.
    storage: BTreeSet<String>,
    /// (storage class, scalar size) of payload, hit attribute and callable data variables.
    blocks: BTreeSet<(String, u64)>,
}

fn interface(words: &[u32], file: &str) -> Interface {
    use spirv::StorageClass as S;
    let p: Program = rtlint::program::parse(words, Path::new(file), Language::Spirv)
        .unwrap_or_else(|e| panic!("{file}: {e:?}"));
    assert_eq!(
        p.entry_points.len(),
        1,
        "{file}: one entry point per module"
    );
    let ep = &p.entry_points[0];
    let mut i = Interface {
        entry: ep.name.clone(),
        stage: ep.stage,
        resources: BTreeSet::new(),
        storage: BTreeSet::new(),
        blocks: BTreeSet::new(),
    };
    // Only variables some function reads or writes count: Slang drops an
    // entry parameter the body never touches (an any-hit shader's unused
    // payload), rtlint keeps it, and neither changes what the shader does.
    let used: BTreeSet<u32> = p
        .functions
        .iter()
        .flat_map(|f| &p.insts[f.start..f.end])
        .flat_map(|inst| &inst.operands)
        .filter_map(|o| match o {
            rspirv::dr::Operand::IdRef(id) => Some(*id),
            _ => None,
        })
        .collect();
    for g in p
        .globals
        .iter()
        .filter(|g| ep.interface.contains(&g.id) && used.contains(&g.id))
    {
        let class = format!("{:?}", g.storage);
        if let (Some(set), Some(binding)) = (g.set, g.binding) {
            i.resources.insert((set, binding, class.clone()));
        }
        if matches!(
            g.storage,
            S::RayPayloadKHR
                | S::IncomingRayPayloadKHR
                | S::HitAttributeKHR
                | S::CallableDataKHR
                | S::IncomingCallableDataKHR
        ) {
            let size = scalar_size(&p, g.ty).unwrap_or_else(|| panic!("{file}: unsized {class}"));
            i.blocks.insert((class.clone(), size));
        }
        if !matches!(g.storage, S::Private | S::Function) {
            i.storage.insert(class);
        }
    }
    i
}

/// Differences between two readbacks: (elements compared, elements that
/// differ, largest channel difference; `f32::INFINITY` for an unequal word).
fn diff(format: Format, a: &[u8], b: &[u8]) -> (usize, usize, f32) {
    assert_eq!(a.len(), b.len());
    let words = |x: &[u8]| -> Vec<u32> {
        x.chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let (wa, wb) = (words(a), words(b));
    let channels = match format {
        Format::F32x4 => 4,
        Format::F32 | Format::U32 => 1,
    };
    let (mut differing, mut max) = (0, 0f32);
    for (ea, eb) in wa.chunks(channels).zip(wb.chunks(channels)) {
        let mut worst = 0f32;
        for (&x, &y) in ea.iter().zip(eb) {
            let d = match format {
                Format::U32 if x != y => f32::INFINITY,
                Format::U32 => 0.0,
                _ => {
                    let (fx, fy) = (f32::from_bits(x), f32::from_bits(y));
                    if x == y || (fx.is_nan() && fy.is_nan()) {
                        0.0
                    } else {
                        (fx - fy).abs()
                    }
                }
            };
            // A NaN on one side only is a difference.
            worst = worst.max(if d.is_nan() { f32::INFINITY } else { d });
        }
        if worst > TOLERANCE {
            differing += 1;
        }
        max = max.max(worst);
    }
    (wa.len() / channels, differing, max)
}

/// Cases whose outputs differ for a known compiler bug, with the reason; they
/// still compile, validate and compare interfaces, and their outputs are
/// still compared and printed, but a difference does not fail the test.
const KNOWN_DIFFERENCES: &[(&str, &str)] = &[];

#[test]
fn rtlint_and_slang_agree_on_the_driver() {
    let Some(slang) = rtlint_testkit::slang() else {
        return;
    };
    if !rtlint_testkit::tool("spirv-val") {
        return;
    }
    let Some(ctx) = common::device() else {
        return;
    };
    let dir = common::root().join("tests/hlsl");
    let cases = cases();

    // Every test shader is either run or listed with the reason it is not.
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    for f in &files {
        let run = cases.iter().any(|c| c.file == f);
        let listed = NOT_RUN.iter().any(|(n, _)| n == f);
        assert!(
            run != listed,
            "{f}: in a case {run}, listed as not run {listed}"
        );
    }

    let (mut validated_ours, mut validated_slang, mut compared, mut facts) = (0, 0, 0, 0);
    let (mut pixels, mut max_all) = (0usize, 0f32);
    let mut failures = String::new();
    for case in &cases {
        let path = dir.join(case.file);
        let ours = hlsl::compile(&path, &HlslOptions::default())
            .unwrap_or_else(|e| panic!("{}: rtlint: {e}", case.file));
        let mut ours_modules = Vec::new();
        let mut slang_modules = Vec::new();
        // Slang names every SPIR-V entry point `main` unless told otherwise,
        // and lays matrices out row-major unless told HLSL's default.
        let mut slang_args = vec![
            "-fvk-use-entrypoint-name".to_string(),
            "-matrix-layout-column-major".to_string(),
        ];
        let mut val_args: Vec<&str> = Vec::new();
        if case.dx_layout {
            slang_args.push("-fvk-use-dx-layout".into());
            val_args.push("--scalar-block-layout");
        }
        for (name, stage) in &case.entries {
            let mine = ours
                .iter()
                .find(|e| e.name == *name)
                .unwrap_or_else(|| panic!("{}: rtlint made no module for {name}", case.file))
                .words
                .clone();
            let theirs = slang
                .compile_hlsl(&path, name, stage_name(*stage), &slang_args)
                .unwrap_or_else(|e| panic!("{}: Slang: {e}", case.file));
            if let Err(e) = common::spirv_val_with(&mine, &val_args) {
                let _ = writeln!(failures, "{}:{name}: rtlint module invalid: {e}", case.file);
            }
            validated_ours += 1;
            if let Err(e) = common::spirv_val_with(&theirs, &val_args) {
                let _ = writeln!(failures, "{}:{name}: Slang module invalid: {e}", case.file);
            }
            validated_slang += 1;
            let (a, b) = (interface(&mine, case.file), interface(&theirs, case.file));
            assert_eq!(a.stage, *stage, "{}:{name}: rtlint's stage", case.file);
            if a != b {
                let _ = writeln!(
                    failures,
                    "{}:{name}: interfaces differ\n  rtlint {a:?}\n  Slang  {b:?}",
                    case.file
                );
            }
            facts += 2 + a.resources.len() + a.storage.len() + a.blocks.len();
            if std::env::var_os("RTLINT_DIFF_DUMP").is_some() {
                let dir = std::env::temp_dir().join("rtlint-diff");
                std::fs::create_dir_all(&dir).unwrap();
                for (who, w) in [("rtlint", &mine), ("slang", &theirs)] {
                    let bytes: Vec<u8> = w.iter().flat_map(|x| x.to_le_bytes()).collect();
                    std::fs::write(dir.join(format!("{}-{name}-{who}.spv", case.name)), bytes)
                        .unwrap();
                }
            }
            ours_modules.push(mine);
            slang_modules.push(theirs);
        }
        if !ctx.info().ray_query && ours_modules.iter().any(|m| declares_ray_query(m)) {
            // NVIDIA's driver: the other cases still run.
            println!(
                "case {:<20} not run: {} lacks VK_KHR_ray_query",
                case.name,
                ctx.info().name
            );
            continue;
        }
        if ctx.validation_enabled() {
            for m in ours_modules.iter_mut().chain(&mut slang_modules) {
                rtlint_testkit::unknown_source_language(m);
            }
        }
        // Under RTLINT_VK_VALIDATION=1 the Khronos layer checks each build's
        // modules and use: rtlint's must be clean; Slang's findings are
        // printed (its f32tof16 declares Float16 and Int16 capabilities
        // without the features, which lavapipe tolerates).
        let before = ctx.validation_errors().len();
        let got_ours = run(&ctx, case, &ours_modules);
        for e in &ctx.validation_errors()[before..] {
            let _ = writeln!(failures, "{}: rtlint build: {e}", case.name);
        }
        let before = ctx.validation_errors().len();
        let got_slang = run(&ctx, case, &slang_modules);
        for e in &ctx.validation_errors()[before..] {
            println!("  {}: Slang build, validation layer: {e}", case.name);
        }
        let (mut n, mut bad, mut max) = (0, 0, 0f32);
        for ((r, a), b) in case
            .resources
            .iter()
            .filter(|r| r.compare.is_some())
            .zip(&got_ours)
            .zip(&got_slang)
        {
            assert!(
                a.iter().any(|&x| x != 0),
                "{}: binding {} stayed zero; the case checks nothing",
                case.name,
                r.binding
            );
            let (cn, cbad, cmax) = diff(r.compare.unwrap(), a, b);
            if std::env::var_os("RTLINT_DIFF_DUMP").is_some() {
                // Both readbacks as floats, to see where a difference lies.
                let floats = |x: &[u8]| -> Vec<f32> {
                    x.chunks_exact(4)
                        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                        .collect()
                };
                eprintln!(
                    "{} binding {}\n  rtlint {:?}\n  Slang  {:?}",
                    case.name,
                    r.binding,
                    floats(a),
                    floats(b)
                );
            }
            n += cn;
            bad += cbad;
            max = max.max(cmax);
        }
        compared += 1;
        pixels += n;
        max_all = max_all.max(max);
        println!(
            "case {:<20} {:<22} entries {} pixels {:>5} differing {:>4} max diff {:.3e}",
            case.name,
            case.file,
            case.entries.len(),
            n,
            bad,
            max
        );
        if bad > 0 {
            match KNOWN_DIFFERENCES.iter().find(|(c, _)| *c == case.name) {
                Some((_, why)) => println!("  known difference: {why}"),
                None => {
                    let _ = writeln!(
                        failures,
                        "{}: {bad} of {n} pixels differ (max {max})",
                        case.name
                    );
                }
            }
        }
    }
    println!(
        "summary: {} cases, {} rtlint and {} Slang modules valid under spirv-val, {} pixels compared, max diff {:.3e}, {} interface facts compared",
        compared, validated_ours, validated_slang, pixels, max_all, facts
    );
    assert!(failures.is_empty(), "{failures}");
}

/// Whether a module declares `OpCapability RayQueryKHR`.
fn declares_ray_query(words: &[u32]) -> bool {
    let ray_query = spirv::Capability::RayQueryKHR as u32;
    let mut i = 5;
    while i + 1 < words.len() {
        let count = (words[i] >> 16) as usize;
        if words[i] & 0xffff == spirv::Op::Capability as u32 && words[i + 1] == ray_query {
            return true;
        }
        i += count.max(1);
    }
    false
}
