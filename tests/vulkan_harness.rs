//! The Vulkan harness itself: device errors, acceleration structures of both
//! kinds with instance transforms, masks, custom indices and SBT offsets
//! (read back through ray queries in a compute pipeline), and the child
//! process runner.
//!
//! Like the smoke test, these need a ray-tracing device (the skip policy of
//! `rtlint_testkit::require`: a failure in CI, a `skipped:` line elsewhere).

#![cfg(feature = "vulkan")]

mod common;

use rtlint::reference::{self, Params, Scene};

/// The mirror scene as one mesh: `primitive_index` is the triangle's index.
fn mirror_scene() -> (Scene, Vec<[f32; 3]>, Vec<u32>) {
    let scene = Scene::load(&common::root().join("shaders/scenes/mirror.toml")).unwrap();
    let (positions, indices) = scene.world_mesh();
    (scene, positions, indices)
}

use rtlint::vk::{
    raw, run_in_child, run_in_child_with_timeout, Aabb, AccelerationStructure, Binding,
    BindingKind, Buffer, ComputePipeline, Context, ContextOptions, Error, Geometry, Group,
    Instance, RayTracingPipeline, RayTracingPipelineDesc, Resource, ShaderStage, Stage,
};
use std::time::{Duration, Instant};

/// `RayQueryIntersection` values as naga's WGSL names them.
const NONE: u32 = 0;
const TRIANGLE: u32 = 1;

const SCENE_CUSTOM: u32 = 7;
const BOX_CUSTOM: u32 = 9;
const BOX_SBT_OFFSET: u32 = 3;
const SCENE_MASK: u8 = 0x01;
const BOX_MASK: u8 = 0x02;
/// The box instance: object box [-1, 1]³ scaled by 2 in x, moved to
/// (10, 1, -3), so it covers x 8..12, y 0..2, z -4..-2 in the world.
const BOX_TRANSFORM: [[f32; 4]; 3] = [
    [2.0, 0.0, 0.0, 10.0],
    [0.0, 1.0, 0.0, 1.0],
    [0.0, 0.0, 1.0, -3.0],
];

/// With `RTLINT_VK_VALIDATION=1` and the Khronos layer installed, any
/// validation error fails the test that caused it.
fn assert_valid(ctx: &Context) {
    let errors = ctx.validation_errors();
    assert!(errors.is_empty(), "validation errors: {errors:#?}");
}

#[test]
fn missing_device_is_an_error_naming_what_is_missing() {
    let Some(real) = common::device() else {
        return;
    };
    let options = ContextOptions {
        device_name: Some("no such device".into()),
        ..ContextOptions::default()
    };
    let err = Context::with_options(&options).expect_err("no device has that name");
    let Error::NoDevice(reasons) = &err else {
        panic!("expected NoDevice, got {err:?}");
    };
    // Every device present is named with the reason it was passed over.
    assert!(
        reasons
            .iter()
            .any(|r| r.contains(&real.info().name) && r.contains("no such device")),
        "{reasons:?}"
    );
    assert!(err
        .to_string()
        .starts_with("no Vulkan device supports ray tracing pipelines:"));
}

/// Debian's validation layer (1.3.239) predates SPIR-V's source language
/// WGSL (10) and rejects the whole module for it, skipping its other checks.
/// The driver ignores `OpSource`, so under validation it is set to Unknown.
fn for_validation(ctx: &Context, mut words: Vec<u32>) -> Vec<u32> {
    if ctx.validation_enabled() {
        rtlint_testkit::unknown_source_language(&mut words);
    }
    words
}

/// A device under the Khronos validation layer (Debian:
/// vulkan-validationlayers, which scripts/setup installs), under the skip
/// policy.
fn validating_device() -> Option<Context> {
    common::device()?;
    let ctx = Context::with_options(&ContextOptions {
        validation: true,
        ..ContextOptions::default()
    })
    .expect("a device opens with validation asked for");
    let layer = if ctx.validation_enabled() {
        Ok(ctx)
    } else {
        Err("not installed (scripts/setup installs vulkan-validationlayers)")
    };
    rtlint_testkit::require("VK_LAYER_KHRONOS_validation", layer)
}

/// The messenger collects what the layer reports.
#[test]
fn validation_layer_reports_misuse() {
    let Some(ctx) = validating_device() else {
        return;
    };
    assert_valid(&ctx);
    // A zero-sized buffer breaks VUID-VkBufferCreateInfo-size-00912.
    let info = raw::BufferCreateInfo::default()
        .size(0)
        .usage(raw::BufferUsageFlags::STORAGE_BUFFER);
    // SAFETY: deliberately invalid but harmless; destroyed at once if made.
    unsafe {
        if let Ok(b) = ctx.device().create_buffer(&info, None) {
            ctx.device().destroy_buffer(b, None);
        }
    }
    let errors = ctx.validation_errors();
    assert!(errors.iter().any(|e| e.contains("00912")), "{errors:#?}");
}

/// Dropping the harness's objects in any order destroys everything: the
/// layer's object tracker reports whatever is left at vkDestroyDevice, as the
/// deliberately leaked buffer shows. Needs the layer, like the test above.
#[test]
fn teardown_leaves_no_objects_behind() {
    let Some(ctx) = validating_device() else {
        return;
    };
    let open = || validating_device().expect("the layer was there a moment ago");
    let log = ctx
        .validation_log()
        .expect("a validating context has a log");
    let (_, positions, indices) = mirror_scene();
    let blas = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Triangles {
            positions: &positions,
            indices: &indices,
            opaque: true,
        }],
    )
    .unwrap();
    let tlas = AccelerationStructure::top_level(&ctx, &[Instance::identity(&blas)]).unwrap();
    // A compute pipeline too, where the device has ray queries (the probe's).
    if ctx.info().ray_query {
        let rays = [Ray::new([0.5, 0.5, 0.5], [0.0, -1.0, 0.0])];
        assert_eq!(probe(&ctx, &tlas, &rays)[0].kind, TRIANGLE);
    }
    // The context first, then what was made from it.
    drop(ctx);
    drop((blas, tlas));
    assert_eq!(log.errors(), Vec::<String>::new());

    let ctx = open();
    let log = ctx.validation_log().unwrap();
    let info = raw::BufferCreateInfo::default()
        .size(64)
        .usage(raw::BufferUsageFlags::STORAGE_BUFFER);
    // SAFETY: a valid buffer, leaked on purpose.
    unsafe { ctx.device().create_buffer(&info, None) }.unwrap();
    drop(ctx);
    let errors = log.errors();
    assert!(
        errors.iter().any(|e| e.contains("VkBuffer")),
        "the leaked buffer is reported: {errors:#?}"
    );
}

/// One ray as the probe shader reads it (48 bytes).
#[derive(Clone, Copy, Debug)]
struct Ray {
    origin: [f32; 3],
    dir: [f32; 3],
    t_min: f32,
    t_max: f32,
    mask: u8,
}

impl Ray {
    fn new(origin: [f32; 3], dir: [f32; 3]) -> Ray {
        Ray {
            origin,
            dir,
            t_min: 0.001,
            t_max: 100.0,
            mask: 0xFF,
        }
    }

    fn words(&self) -> [u32; 12] {
        let f = |x: f32| x.to_bits();
        let (o, d) = (self.origin, self.dir);
        [
            f(o[0]),
            f(o[1]),
            f(o[2]),
            f(self.t_min),
            f(d[0]),
            f(d[1]),
            f(d[2]),
            f(self.t_max),
            0, // no ray flags: opacity comes from the geometry
            u32::from(self.mask),
            0,
            0,
        ]
    }
}

/// What the probe shader reported for one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Probe {
    kind: u32,
    primitive: u32,
    custom: u32,
    instance: u32,
    geometry: u32,
    sbt_offset: u32,
    t: f32,
    aabb_candidates: u32,
    aabb_custom: u32,
    aabb_sbt_offset: u32,
}

fn probe(ctx: &Context, tlas: &AccelerationStructure, rays: &[Ray]) -> Vec<Probe> {
    let path = common::root().join("tests/shaders/ray_probe.wgsl");
    let source = std::fs::read_to_string(&path).unwrap();
    let spirv = rtlint::front::wgsl::compile(&source, &path).expect("the probe shader compiles");
    let spirv = for_validation(ctx, spirv);
    let bindings = [
        Binding::new(0, BindingKind::AccelerationStructure),
        Binding::new(1, BindingKind::StorageBuffer),
        Binding::new(2, BindingKind::StorageBuffer),
        Binding::new(3, BindingKind::UniformBuffer),
    ];
    let pipeline = ComputePipeline::new(ctx, &spirv, "main", &bindings).expect("compute pipeline");
    let words: Vec<u32> = rays.iter().flat_map(Ray::words).collect();
    let storage = raw::BufferUsageFlags::STORAGE_BUFFER;
    let ray_buf = Buffer::from_data(ctx, storage, &words).unwrap();
    let out = Buffer::new(ctx, rays.len() as u64 * 48, storage, 1).unwrap();
    let count = rays.len() as u32;
    let params = Buffer::from_data(
        ctx,
        raw::BufferUsageFlags::UNIFORM_BUFFER,
        &[count, 0, 0, 0],
    )
    .unwrap();
    pipeline
        .dispatch(
            &[
                (0, Resource::AccelerationStructure(tlas)),
                (1, Resource::Buffer(&ray_buf)),
                (2, Resource::Buffer(&out)),
                (3, Resource::Buffer(&params)),
            ],
            count.div_ceil(64),
            1,
            1,
        )
        .expect("dispatch");
    out.read_u32()
        .chunks_exact(12)
        .map(|w| Probe {
            kind: w[0],
            primitive: w[1],
            custom: w[2],
            instance: w[3],
            geometry: w[4],
            sbt_offset: w[5],
            aabb_candidates: w[6],
            aabb_custom: w[7],
            t: f32::from_bits(w[8]),
            aabb_sbt_offset: w[9],
        })
        .collect()
}

/// Builds the reflection scene and the box as two instances, casts camera
/// rays, rays past and through the box, and masked rays, and checks every
/// field the acceleration structures feed back.
#[test]
fn ray_queries_see_triangles_aabbs_transforms_and_masks() {
    let Some(ctx) = common::device() else {
        return;
    };
    // NVIDIA's driver (FIELD-NOTES) has ray-tracing pipelines but not
    // VK_KHR_ray_query; this test has nothing to run there.
    if !common::has_ray_query(&ctx) {
        return;
    }
    let (scene, positions, indices) = mirror_scene();
    let triangles = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Triangles {
            positions: &positions,
            indices: &indices,
            opaque: true,
        }],
    )
    .unwrap();
    let boxes = [Aabb {
        min: [-1.0; 3],
        max: [1.0; 3],
    }];
    let procedural = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Aabbs {
            boxes: &boxes,
            opaque: false,
        }],
    )
    .unwrap();
    let instances = [
        Instance {
            custom_index: SCENE_CUSTOM,
            mask: SCENE_MASK,
            ..Instance::identity(&triangles)
        },
        Instance {
            transform: BOX_TRANSFORM,
            custom_index: BOX_CUSTOM,
            mask: BOX_MASK,
            sbt_record_offset: BOX_SBT_OFFSET,
            ..Instance::identity(&procedural)
        },
    ];
    let tlas = AccelerationStructure::top_level(&ctx, &instances).unwrap();
    // The top level keeps the bottom levels alive.
    drop((triangles, procedural));

    // 1. Camera rays against the CPU intersection of the same scene.
    let params = Params::for_scene(&scene, 32, 32, 0);
    let mut rays = Vec::new();
    for y in 0..params.height {
        for x in 0..params.width {
            rays.push(Ray::new(
                scene.camera.to_array(),
                reference::camera_dir(&params, x, y).to_array(),
            ));
        }
    }
    let camera_rays = rays.len();
    // 2. Horizontal rays along -z at y = 1 across the box's x extent 8..12.
    let box_xs = [7.0, 7.5, 8.25, 9.0, 10.0, 11.0, 11.75, 12.5, 13.0];
    for x in box_xs {
        rays.push(Ray::new([x, 1.0, 5.0], [0.0, 0.0, -1.0]));
    }
    // 3. Masks: the box ray with the scene's mask, a floor ray with each mask.
    let masked = rays.len();
    rays.push(Ray {
        mask: SCENE_MASK,
        ..Ray::new([10.0, 1.0, 5.0], [0.0, 0.0, -1.0])
    });
    let floor_ray = |mask| Ray {
        mask,
        ..Ray::new([0.5, 0.5, 0.5], [0.0, -1.0, 0.0])
    };
    rays.push(floor_ray(SCENE_MASK));
    rays.push(floor_ray(BOX_MASK));
    // 4. The t range: the floor is 0.5 away, past t_max 0.4.
    rays.push(Ray {
        t_max: 0.4,
        ..floor_ray(0xFF)
    });

    let hits = probe(&ctx, &tlas, &rays);

    let mut compared = 0;
    for (ray, hit) in rays[..camera_rays].iter().zip(&hits) {
        let (cpu, margin) = reference::intersect(
            &scene,
            ray.origin.into(),
            ray.dir.into(),
            ray.t_min,
            ray.t_max,
        );
        assert_eq!(hit.aabb_candidates, 0, "camera rays pass far from the box");
        if margin < 1e-4 {
            continue; // see EDGE_EPSILON in vulkan_smoke.rs
        }
        compared += 1;
        match cpu {
            None => assert_eq!(hit.kind, NONE, "{ray:?}: {hit:?}"),
            Some(cpu) => {
                assert_eq!(hit.kind, TRIANGLE, "{ray:?}: {hit:?}");
                assert_eq!(hit.primitive, cpu.triangle, "{ray:?}");
                assert!(
                    (hit.t - cpu.t).abs() <= 1e-5 * cpu.t,
                    "{ray:?}: {} vs {}",
                    hit.t,
                    cpu.t
                );
                assert_eq!(
                    (hit.custom, hit.instance, hit.geometry, hit.sbt_offset),
                    (SCENE_CUSTOM, 0, 0, 0)
                );
            }
        }
    }
    assert!(
        compared > camera_rays - 8,
        "{compared} of {camera_rays} rays compared"
    );

    for (x, hit) in box_xs.iter().zip(&hits[camera_rays..]) {
        assert_eq!(
            hit.kind, NONE,
            "an unconfirmed AABB candidate is not committed"
        );
        // Implementations may offer AABBs conservatively, so only rays
        // clearly inside (≥ 0.25 in) or clearly outside (≥ 0.5 off) count.
        if (8.25..=11.75).contains(x) {
            assert_eq!(hit.aabb_candidates, 1, "x = {x}");
            assert_eq!(
                (hit.aabb_custom, hit.aabb_sbt_offset),
                (BOX_CUSTOM, BOX_SBT_OFFSET)
            );
        } else {
            assert_eq!(hit.aabb_candidates, 0, "x = {x}: outside the scaled box");
        }
    }
    let [box_masked, floor_scene, floor_box, floor_short] = &hits[masked..] else {
        unreachable!()
    };
    assert_eq!(
        box_masked.aabb_candidates, 0,
        "the box instance is masked out"
    );
    assert_eq!((floor_scene.kind, floor_scene.t), (TRIANGLE, 0.5));
    assert_eq!(floor_box.kind, NONE, "the scene instance is masked out");
    assert_eq!(floor_short.kind, NONE, "the floor is beyond t_max");
    assert_valid(&ctx);
}

fn load_spv(name: &str) -> Vec<u32> {
    let path = common::root()
        .join("tests/shaders/procedural")
        .join(format!("{name}.spv"));
    let bytes = std::fs::read(&path).expect("committed SPIR-V (tests/shaders/procedural/build.sh)");
    rtlint::program::words_from_bytes(&bytes, &path).unwrap()
}

/// A pipeline with every group kind: raygen, miss, a triangle hit group with
/// an any-hit shader that cuts out triangle 0, and a procedural hit group
/// whose intersection shader reports a unit sphere, placed behind the
/// triangles by an instance transform and chosen by its SBT record offset.
#[test]
fn procedural_and_any_hit_groups_trace_as_the_geometry_says() {
    let Some(ctx) = common::device() else {
        return;
    };
    let names = [
        ("probe.rgen", Stage::RayGeneration),
        ("probe.rmiss", Stage::Miss),
        ("triangle.rchit", Stage::ClosestHit),
        ("triangle.rahit", Stage::AnyHit),
        ("sphere.rint", Stage::Intersection),
        ("sphere.rchit", Stage::ClosestHit),
    ];
    let modules: Vec<Vec<u32>> = names.iter().map(|(n, _)| load_spv(n)).collect();
    let stages: Vec<ShaderStage<'_>> = modules
        .iter()
        .zip(names)
        .map(|(spirv, (_, stage))| ShaderStage {
            spirv,
            entry_point: "main",
            stage,
        })
        .collect();
    let groups = [
        Group::General(0),
        Group::General(1),
        Group::Triangles {
            closest_hit: Some(2),
            any_hit: Some(3),
        },
        Group::Procedural {
            intersection: 4,
            closest_hit: Some(5),
            any_hit: None,
        },
    ];
    let pipeline = RayTracingPipeline::new(
        &ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &groups,
            max_recursion_depth: 1,
            bindings: &[
                Binding::new(0, BindingKind::AccelerationStructure),
                Binding::new(1, BindingKind::StorageBuffer),
                Binding::new(2, BindingKind::StorageBuffer),
            ],
            push_constant_size: 0,
            stack_size: None,
        },
    )
    .expect("pipeline with procedural and any-hit groups");
    assert_eq!(pipeline.sbt().hit.groups, [2, 3]);

    // The query answers for every stage each group has; lavapipe inlines the
    // pipeline and says 4 for each (see vulkan_smoke.rs).
    let sizes = pipeline.group_stack_sizes();
    assert_eq!(
        (
            sizes[2].closest_hit.is_some(),
            sizes[2].any_hit.is_some(),
            sizes[2].intersection
        ),
        (true, true, None)
    );
    assert_eq!(
        (
            sizes[3].closest_hit.is_some(),
            sizes[3].any_hit,
            sizes[3].intersection.is_some()
        ),
        (true, None, true)
    );
    if ctx.info().name.starts_with("llvmpipe") {
        assert!(sizes
            .iter()
            .all(|s| [s.general, s.closest_hit, s.any_hit, s.intersection]
                .iter()
                .flatten()
                .all(|&v| v == 4)));
    }

    // Quad x, y in [-1, 1] at z = 0: triangle 0 below the diagonal y = x,
    // triangle 1 above; not opaque, so the any-hit shader runs.
    let positions = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    let quad = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Triangles {
            positions: &positions,
            indices: &[0, 1, 2, 0, 2, 3],
            opaque: false,
        }],
    )
    .unwrap();
    let unit_box = [Aabb {
        min: [-1.0; 3],
        max: [1.0; 3],
    }];
    let sphere = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Aabbs {
            boxes: &unit_box,
            opaque: true,
        }],
    )
    .unwrap();
    // The sphere: x scaled by 1.5, centred 3 behind the quad.
    let ellipsoid = [
        [1.5, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, -3.0],
    ];
    let tlas = AccelerationStructure::top_level(
        &ctx,
        &[
            Instance {
                custom_index: SCENE_CUSTOM,
                ..Instance::identity(&quad)
            },
            Instance {
                transform: ellipsoid,
                custom_index: BOX_CUSTOM,
                sbt_record_offset: 1,
                ..Instance::identity(&sphere)
            },
        ],
    )
    .unwrap();

    // Rays along -z from z = 5 over a grid; the expected answer is computed
    // here, skipping rays within 0.01 of an edge, the diagonal or the
    // ellipsoid's outline, where rounding decides.
    let mut rays = Vec::new();
    let n = 24;
    for j in 0..n {
        for i in 0..n {
            let x = -2.0 + 4.0 * (i as f32 + 0.5) / n as f32;
            let y = -2.0 + 4.0 * (j as f32 + 0.5) / n as f32;
            rays.push(Ray::new([x, y, 5.0], [0.0, 0.0, -1.0]));
        }
    }
    let words: Vec<u32> = rays.iter().flat_map(Ray::words).collect();
    let storage = raw::BufferUsageFlags::STORAGE_BUFFER;
    let ray_buf = Buffer::from_data(&ctx, storage, &words).unwrap();
    let out = Buffer::new(&ctx, rays.len() as u64 * 32, storage, 1).unwrap();
    pipeline
        .trace_rays(
            &[
                (0, Resource::AccelerationStructure(&tlas)),
                (1, Resource::Buffer(&ray_buf)),
                (2, Resource::Buffer(&out)),
            ],
            rays.len() as u32,
            1,
            1,
        )
        .expect("trace");
    let hits = out.read_u32();

    let mut counts = [0usize; 3];
    for (k, ray) in rays.iter().enumerate() {
        let [x, y, _] = ray.origin;
        let h = &hits[k * 8..k * 8 + 8];
        let (kind, primitive, custom, t, any_hits) = (h[0], h[1], h[2], f32::from_bits(h[3]), h[4]);
        let on_quad = x.abs() < 1.0 && y.abs() < 1.0;
        let r2 = (x / 1.5).powi(2) + y * y;
        let near = |d: f32| d.abs() < 0.01;
        if near(x.abs() - 1.0) || near(y.abs() - 1.0) || near(x - y) || near(r2 - 1.0) {
            continue;
        }
        let what = format!("ray at ({x}, {y}): {h:?}");
        // Any-hit runs for candidates on the non-opaque quad, at least once.
        assert_eq!(any_hits > 0, on_quad, "{what}");
        if on_quad && y > x {
            assert_eq!(
                (kind, primitive, custom, t),
                (1, 1, SCENE_CUSTOM, 5.0),
                "{what}"
            );
            counts[1] += 1;
        } else if r2 < 1.0 {
            let expected = 8.0 - (1.0 - r2).sqrt();
            assert_eq!((kind, primitive, custom), (2, 0, BOX_CUSTOM), "{what}");
            assert!(
                (t - expected).abs() < 1e-4,
                "{what}: t {t}, expected {expected}"
            );
            counts[2] += 1;
        } else {
            assert_eq!(kind, 0, "{what}");
            counts[0] += 1;
        }
    }
    // Every outcome is exercised by many rays.
    assert!(
        counts.iter().all(|&c| c > 30),
        "miss/triangle/sphere rays: {counts:?}"
    );
    assert_valid(&ctx);
}

/// A dispatch that outruns the fence timeout is an `Error::Timeout`, and
/// the context can then be dropped without waiting for the GPU. In a child:
/// lavapipe goes on computing until the process ends.
#[test]
fn fence_timeout_is_an_error_not_a_hang() {
    if common::device().is_none() {
        return;
    }
    if let Some(outcome) = run_in_child_with_timeout(
        "fence_timeout_is_an_error_not_a_hang",
        Duration::from_secs(120),
    ) {
        assert!(outcome.success(), "{outcome:?}");
        assert!(
            outcome.stdout.contains("timed out as expected"),
            "{outcome:?}"
        );
        return;
    }
    // Headroom for the short run, whose first dispatch includes Mesa's shader
    // compile (up to a second on a loaded 2-core machine); the long run needs
    // minutes.
    let ctx = Context::with_options(&ContextOptions {
        fence_timeout: Duration::from_secs(5),
        ..ContextOptions::default()
    })
    .unwrap();
    let path = common::root().join("tests/shaders/spin.wgsl");
    let source = std::fs::read_to_string(&path).unwrap();
    let spirv = for_validation(&ctx, rtlint::front::wgsl::compile(&source, &path).unwrap());
    let bindings = [
        Binding::new(0, BindingKind::StorageBuffer),
        Binding::new(1, BindingKind::UniformBuffer),
    ];
    let pipeline = ComputePipeline::new(&ctx, &spirv, "main", &bindings).unwrap();
    let out = Buffer::new(&ctx, 64 * 4, raw::BufferUsageFlags::STORAGE_BUFFER, 1).unwrap();
    let run = |iterations: u32| {
        let params = Buffer::from_data(
            &ctx,
            raw::BufferUsageFlags::UNIFORM_BUFFER,
            &[iterations, 0, 0, 0],
        )
        .unwrap();
        let resources = [(0, Resource::Buffer(&out)), (1, Resource::Buffer(&params))];
        pipeline.dispatch(&resources, 1, 1, 1)
    };
    // A short run finishes and computes what the CPU computes.
    run(1000).expect("a short dispatch finishes in time");
    let lcg = |mut x: u32| {
        for _ in 0..1000 {
            x = x.wrapping_mul(1664525).wrapping_add(1013904223);
        }
        x
    };
    assert_eq!(out.read_u32(), (0..64).map(lcg).collect::<Vec<_>>());
    // About 2^32 steps per thread: minutes on lavapipe.
    let start = Instant::now();
    let err = run(u32::MAX).expect_err("a four-billion-step loop outruns 5 s");
    assert!(matches!(err, Error::Timeout { .. }), "{err}");
    // The wait ends at the timeout, not when the GPU finishes.
    assert!(start.elapsed() < Duration::from_secs(60));
    drop((pipeline, out, ctx));
    println!("timed out as expected: {err}");
}

/// A child that dies of a signal is reported, not fatal to the test run:
/// what deep-recursion tests need on lavapipe.
#[test]
fn child_process_reports_a_crash() {
    if let Some(outcome) = run_in_child("child_process_reports_a_crash") {
        #[cfg(unix)]
        assert_eq!(outcome.signal, Some(6), "SIGABRT expected: {outcome:?}");
        assert!(!outcome.success());
        assert!(
            outcome.stderr.contains("child about to abort"),
            "{outcome:?}"
        );
        return;
    }
    eprintln!("child about to abort");
    std::process::abort();
}

/// A child that does GPU work and exits normally reports success, so GPU work
/// can be moved into children without losing results.
#[test]
fn child_process_runs_gpu_work() {
    if common::device().is_none() {
        return;
    }
    if let Some(outcome) = run_in_child("child_process_runs_gpu_work") {
        assert!(outcome.success(), "{outcome:?}");
        assert!(
            outcome
                .stdout
                .contains("child built acceleration structures"),
            "{outcome:?}"
        );
        return;
    }
    let Some(ctx) = common::device() else {
        return;
    };
    let (_, positions, indices) = mirror_scene();
    let blas = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Triangles {
            positions: &positions,
            indices: &indices,
            opaque: true,
        }],
    )
    .unwrap();
    AccelerationStructure::top_level(&ctx, &[Instance::identity(&blas)]).unwrap();
    assert_valid(&ctx);
    println!("child built acceleration structures");
}
