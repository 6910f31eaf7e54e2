// Recursive mirror reflections: the closest-hit shader traces the reflected
// ray itself, so the pipeline needs recursion depth max_bounces + 1 and every
// level keeps a payload on the ray stack. Same scene, camera and shading as
// reflect_iterative.wgsl; the two must produce the same image.
enable wgpu_ray_tracing_pipeline;
enable primitive_index;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    _pad: u32,
}

struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo: vec4<f32>,
}

// Radiance gathered along the ray, and how many bounces led to it.
struct Radiance {
    color: vec3<f32>,
    depth: u32,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

var<ray_payload> ray: Radiance;
var<incoming_ray_payload> incoming: Radiance;

fn sky(dir: vec3<f32>) -> vec3<f32> {
    let k = 0.5 * (dir.y + 1.0);
    return mix(vec3<f32>(1.0, 1.0, 1.0), vec3<f32>(0.5, 0.7, 1.0), k);
}

fn pack_rgba8(c: vec3<f32>) -> u32 {
    let v = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return v.x | (v.y << 8u) | (v.z << 16u) | (255u << 24u);
}

@ray_generation
fn raygen(@builtin(ray_invocation_id) id: vec3<u32>) {
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size * 2.0 - 1.0;
    let origin = vec3<f32>(0.0, 1.0, 4.0);
    let dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    ray.depth = 0u;
    traceRay(tlas, RayDesc(0x01u, 0xFFu, 0.001, 100.0, origin, dir), &ray);
    image[id.y * params.width + id.x] = pack_rgba8(ray.color);
}

@miss
@incoming_payload(incoming)
fn miss(@builtin(world_ray_direction) dir: vec3<f32>) {
    incoming.color = sky(dir);
}

@closest_hit
@incoming_payload(incoming)
fn closest_hit(
    @builtin(primitive_index) prim: u32,
    @builtin(ray_t_current_max) t: f32,
    @builtin(world_ray_origin) origin: vec3<f32>,
    @builtin(world_ray_direction) dir: vec3<f32>,
) {
    let s = surfaces[prim];
    let normal = s.normal_reflectivity.xyz;
    let reflectivity = s.normal_reflectivity.w;
    let shade = max(dot(normal, -dir), 0.0);
    var color = s.albedo.xyz * shade * (1.0 - reflectivity);
    // The guard that bounds the recursion: depth grows by one per level.
    if reflectivity > 0.0 && incoming.depth < params.max_bounces {
        let hit = origin + dir * t + normal * 0.001;
        ray.depth = incoming.depth + 1u;
        traceRay(tlas, RayDesc(0x01u, 0xFFu, 0.001, 100.0, hit, reflect(dir, normal)), &ray);
        color += reflectivity * ray.color;
    }
    incoming.color = color;
}
