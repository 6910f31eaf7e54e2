// Iterative mirror reflections: the ray generation shader loops over bounces,
// the closest-hit shader only reports the surface, so the pipeline needs
// recursion depth 1 and the payload stays small.
enable wgpu_ray_tracing_pipeline;
enable primitive_index;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    _pad: u32,
}

// One entry per triangle: xyz = geometric normal, w = reflectivity.
struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo: vec4<f32>,
}

struct HitInfo {
    albedo: vec3<f32>,
    t: f32,
    normal: vec3<f32>,
    reflectivity: f32,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

var<ray_payload> hit: HitInfo;
var<incoming_ray_payload> incoming: HitInfo;

const MISS_T: f32 = -1.0;

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
    var origin = vec3<f32>(0.0, 1.0, 4.0);
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var color = vec3<f32>(0.0);
    var throughput = vec3<f32>(1.0);
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        traceRay(tlas, RayDesc(0x01u, 0xFFu, 0.001, 100.0, origin, dir), &hit);
        if hit.t < 0.0 {
            color += throughput * sky(dir);
            break;
        }
        let shade = max(dot(hit.normal, -dir), 0.0);
        color += throughput * hit.albedo * shade * (1.0 - hit.reflectivity);
        throughput *= hit.reflectivity;
        if hit.reflectivity <= 0.0 {
            break;
        }
        origin = origin + dir * hit.t + hit.normal * 0.001;
        dir = reflect(dir, hit.normal);
    }
    image[id.y * params.width + id.x] = pack_rgba8(color);
}

@miss
@incoming_payload(incoming)
fn miss() {
    incoming.t = MISS_T;
}

@closest_hit
@incoming_payload(incoming)
fn closest_hit(@builtin(primitive_index) prim: u32, @builtin(ray_t_current_max) t: f32) {
    let s = surfaces[prim];
    incoming.albedo = s.albedo.xyz;
    incoming.t = t;
    incoming.normal = s.normal_reflectivity.xyz;
    incoming.reflectivity = s.normal_reflectivity.w;
}
