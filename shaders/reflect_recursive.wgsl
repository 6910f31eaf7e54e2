// Recursive mirror reflections: the closest-hit shader traces the reflected
// ray itself, and a shadow ray when the scene has a light, so the pipeline
// needs recursion depth max_bounces + 2 and every level keeps a payload on
// the ray stack. Same scene, camera, shading and ray origins as
// reflect_iterative.wgsl; the two must produce the same image.
//
// naga gives every trace miss index 0, so the shadow ray shares the one miss
// shader: it runs only on a miss and overwrites the -1 the caller left in
// the payload; a hit runs no shader (SKIP_CLOSEST_HIT_SHADER). The shadow
// payload is a variable of its own, so naga's per-payload trace helper has
// constant flags at each site.
enable wgpu_ray_tracing_pipeline;
enable primitive_index;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    // FLAG_LIGHT | FLAG_ROBUST
    flags: u32,
    camera: vec4<f32>,
    // xyz: unit direction towards the light, w: ambient
    light: vec4<f32>,
    // t_min, t_max, throughput cut-off, fixed origin epsilon
    ray: vec4<f32>,
}

struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo_roughness: vec4<f32>,
}

// Radiance gathered along the ray, how many bounces led to it, and the
// product of the reflectivities on the way.
struct Radiance {
    color: vec3<f32>,
    depth: u32,
    throughput: f32,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

var<ray_payload> ray: Radiance;
// Shadow rays get a payload of their own (only `color.x` is used).
var<ray_payload> shadow: Radiance;
var<incoming_ray_payload> incoming: Radiance;

const FLAG_LIGHT: u32 = 1u;
const FLAG_ROBUST: u32 = 2u;
const RAY_FLAG_OPAQUE: u32 = 0x01u;
// OPAQUE | ACCEPT_FIRST_HIT_AND_END_SEARCH | SKIP_CLOSEST_HIT_SHADER
const SHADOW_FLAGS: u32 = 0x0Du;

fn sky(dir: vec3<f32>) -> vec3<f32> {
    let k = 0.5 * (dir.y + 1.0);
    return mix(vec3<f32>(1.0, 1.0, 1.0), vec3<f32>(0.5, 0.7, 1.0), k);
}

// RGBA8 with alpha 255; a colour with an infinite or NaN channel is written
// as 0 (alpha 0), so the image counts them. The exponent bits are tested:
// a compiler may assume no NaN in `c != c`.
fn pack_rgba8(c: vec3<f32>) -> u32 {
    if any((bitcast<vec3<u32>>(c) & vec3<u32>(0x7F800000u)) == vec3<u32>(0x7F800000u)) {
        return 0u;
    }
    let v = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return v.x | (v.y << 8u) | (v.z << 16u) | (255u << 24u);
}

// Wächter & Binder, Ray Tracing Gems ch. 6: move the origin a few ulps
// along the normal; a fixed epsilon when FLAG_ROBUST is off.
fn offset_ray(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if (params.flags & FLAG_ROBUST) == 0u {
        return p + n * params.ray.w;
    }
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    return select(p_i, p + (1.0 / 65536.0) * n, abs(p) < vec3<f32>(1.0 / 32.0));
}

@ray_generation
fn raygen(@builtin(ray_invocation_id) id: vec3<u32>) {
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size * 2.0 - 1.0;
    let origin = params.camera.xyz;
    let dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    ray.depth = 0u;
    ray.throughput = 1.0;
    traceRay(tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, params.ray.y, origin, dir), &ray);
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
    @builtin(instance_custom_data) first: u32,
    @builtin(primitive_index) prim: u32,
    @builtin(ray_t_current_max) t: f32,
    @builtin(world_ray_origin) origin: vec3<f32>,
    @builtin(world_ray_direction) dir: vec3<f32>,
) {
    let s = surfaces[first + prim];
    let reflectivity = s.normal_reflectivity.w;
    let n = select(-s.normal_reflectivity.xyz, s.normal_reflectivity.xyz, dot(s.normal_reflectivity.xyz, dir) < 0.0);
    let base = (1.0 - reflectivity) * s.albedo_roughness.xyz;
    let start = offset_ray(origin + dir * t, n);
    var color: vec3<f32>;
    if (params.flags & FLAG_LIGHT) != 0u {
        let ndl = dot(n, params.light.xyz);
        color = base * params.light.w;
        if ndl > 0.0 {
            shadow.color = vec3<f32>(-1.0);
            traceRay(tlas, RayDesc(SHADOW_FLAGS, 0xFFu, params.ray.x, params.ray.y, start, params.light.xyz), &shadow);
            if shadow.color.x >= 0.0 {
                color += base * ndl;
            }
        }
    } else {
        color = base * max(dot(n, -dir), 0.0);
    }
    // The guard that bounds the recursion: depth grows by one per level.
    let next = incoming.throughput * reflectivity;
    if next > params.ray.z && incoming.depth < params.max_bounces {
        ray.depth = incoming.depth + 1u;
        ray.throughput = next;
        // rtlint: allow(recursive-trace, reason = "the recursive reference: bounded by max_bounces; reflect_iterative.wgsl is the loop form")
        traceRay(tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, params.ray.y, start, reflect(dir, n)), &ray);
        color += reflectivity * ray.color;
    }
    incoming.color = color;
}
