//! Traces one calibration pipeline with a chosen declared depth and stack
//! size, to find where a driver's default stack stops running (rule RT025).
//! Run each trial in its own process: a lost device does not come back.
//!
//! `cargo run --release --example stack_probe -- PIPELINE.toml DEPTH STACK|default [WIDTH HEIGHT [EXPECT]]`
//! With EXPECT, also counts the pixels whose value is EXPECT (the calibration
//! pipelines write 1000 + the number of recursion levels).
//! Prints one line `depth=D stack=S default_model=M result=ok|lost|error:...` and
//! exits 0 when the trace ran, 3 when the device was lost, 1 otherwise.

use rtlint::vk::{
    raw, AccelerationStructure, Buffer, Context, Geometry, Group, Instance, RayTracingPipeline,
    RayTracingPipelineDesc, Resource, ShaderStage, Stage,
};
use std::path::Path;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!("usage: stack_probe PIPELINE.toml DEPTH STACK|default [WIDTH HEIGHT]");
        std::process::exit(2);
    }
    let depth: u32 = a[2].parse().expect("depth");
    let stack: Option<u32> = (a[3] != "default").then(|| a[3].parse().expect("stack bytes"));
    let width: u32 = a.get(4).map_or(512, |s| s.parse().unwrap());
    let height: u32 = a.get(5).map_or(512, |s| s.parse().unwrap());
    let expect: Option<u32> = a.get(6).map(|s| s.parse().unwrap());
    let pipeline = rtlint::pipeline::load(Path::new(&a[1])).unwrap_or_else(|e| panic!("{e}"));
    let program = |s: &rtlint::pipeline::ShaderRef| &pipeline.program(s).expect("program").words;
    let (rg, ms, ch) = (
        &pipeline.raygen[0],
        &pipeline.miss[0],
        pipeline.hit_groups[0]
            .closest_hit
            .as_ref()
            .expect("closest hit"),
    );
    // What the model says the driver's default would be at this depth.
    let model = rtlint::analysis::stack_report(&pipeline);
    let per = |stage| {
        model
            .shaders
            .iter()
            .filter(|s| s.stage == stage)
            .map(|s| s.driver_model_bytes)
            .max()
            .unwrap_or(0)
    };
    use rtlint::shader::Stage as S;
    let m = rtlint::analysis::stack::StageMax {
        raygen: per(S::RayGeneration),
        closest_hit: per(S::ClosestHit),
        miss: per(S::Miss),
        ..Default::default()
    };
    let default_model = rtlint::analysis::stack::vulkan_default(&m, depth);
    let line = |result: &str| {
        println!(
            "depth={depth} stack={} default_model={default_model} result={result}",
            stack.map_or("default".to_string(), |s| s.to_string())
        )
    };
    let ctx = Context::new().unwrap_or_else(|e| {
        line(&format!("error:{e}"));
        std::process::exit(1)
    });
    // A quad in front of the camera so every ray hits and recurses once.
    let positions = [
        [-50.0, -50.0, 0.0],
        [50.0, -50.0, 0.0],
        [50.0, 50.0, 0.0],
        [-50.0, 50.0, 0.0],
    ];
    let indices = [0, 1, 2, 0, 2, 3];
    let blas = AccelerationStructure::bottom_level(
        &ctx,
        &[Geometry::Triangles {
            positions: &positions,
            indices: &indices,
            opaque: true,
        }],
    )
    .expect("blas");
    let tlas = AccelerationStructure::top_level(&ctx, &[Instance::identity(&blas)]).expect("tlas");
    let stages = [
        ShaderStage {
            spirv: program(rg),
            entry_point: &rg.entry,
            stage: Stage::RayGeneration,
        },
        ShaderStage {
            spirv: program(ms),
            entry_point: &ms.entry,
            stage: Stage::Miss,
        },
        ShaderStage {
            spirv: program(ch),
            entry_point: &ch.entry,
            stage: Stage::ClosestHit,
        },
    ];
    let groups = [
        Group::General(0),
        Group::General(1),
        Group::Triangles {
            closest_hit: Some(2),
            any_hit: None,
        },
    ];
    let rt = match RayTracingPipeline::new(
        &ctx,
        &RayTracingPipelineDesc {
            stages: &stages,
            groups: &groups,
            max_recursion_depth: depth,
            bindings: &[
                rtlint::vk::Binding::new(0, rtlint::vk::BindingKind::AccelerationStructure),
                rtlint::vk::Binding::new(1, rtlint::vk::BindingKind::StorageBuffer),
            ],
            push_constant_size: 0,
            stack_size: stack,
        },
    ) {
        Ok(rt) => rt,
        Err(e) => {
            line(&format!("error:pipeline:{e}"));
            std::process::exit(1)
        }
    };
    let out = Buffer::new(
        &ctx,
        u64::from(width * height) * 4,
        raw::BufferUsageFlags::STORAGE_BUFFER,
        1,
    )
    .expect("buffer");
    let resources = [
        (0, Resource::AccelerationStructure(&tlas)),
        (1, Resource::Buffer(&out)),
    ];
    match rt.trace_rays(&resources, width, height, 1) {
        Ok(t) => {
            let v = out.read_u32();
            let nonzero = v.iter().filter(|x| **x != 0).count();
            let correct = expect.map_or(String::new(), |e| {
                format!(
                    " correct={}/{}",
                    v.iter().filter(|x| **x == e).count(),
                    v.len()
                )
            });
            line(&format!(
                "ok gpu_ms={:.3} nonzero={nonzero}/{}{correct}",
                t.as_secs_f64() * 1e3,
                v.len()
            ));
        }
        Err(e) => {
            let lost = e.to_string().contains("DEVICE_LOST");
            line(&if lost {
                format!("lost ({e})")
            } else {
                format!("error:{e}")
            });
            std::process::exit(if lost { 3 } else { 1 });
        }
    }
}
