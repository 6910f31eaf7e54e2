//! Uses what its build script made: the SPIR-V of each entry point and the
//! Rust types of the shaders' interfaces.

mod layouts {
    include!(concat!(env!("OUT_DIR"), "/layouts.rs"));
}

use layouts::{Camera, Payload, Push};

/// One SPIR-V module per entry point, written by `emit_spirv()`.
const RAYGEN: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/raygen.RayGen.spv"));
const MISS: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/miss.Miss.spv"));
const CLOSEST_HIT: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/closesthit.ClosestHit.spv"));

fn main() {
    let mut camera: Camera = bytemuck::Zeroable::zeroed();
    camera.viewInverse = glam::Mat4::IDENTITY;
    camera.projInverse = glam::Mat4::IDENTITY;
    camera.exposure = 1.0;
    let push = Push {
        frame: 0,
        time: 0.0,
        jitter: glam::Vec2::ZERO,
        tint: glam::Vec4::ONE,
    };
    let bytes: &[u8] = bytemuck::bytes_of(&camera);
    println!("Camera {} bytes", bytes.len());
    println!("Push {} bytes", bytemuck::bytes_of(&push).len());
    println!("Payload {} bytes", std::mem::size_of::<Payload>());
    for (name, spv) in [
        ("raygen", RAYGEN),
        ("miss", MISS),
        ("closesthit", CLOSEST_HIT),
    ] {
        println!("{name}: {} bytes of SPIR-V", spv.len());
    }
}
