// Iterative mirror reflections: the ray generation shader loops over bounces,
// the closest-hit shader only reports the surface, so the pipeline needs
// recursion depth 1 and the payload stays small. Shadow rays (when the scene
// has a light) are traced from raygen too, with the same payload: the miss
// shader marks a miss, a hit runs no shader at all.
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

// One entry per triangle (instance custom index + primitive index):
// xyz = world-space geometric normal, w = reflectivity.
struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo_roughness: vec4<f32>,
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
// Shadow rays get a payload of their own (only `t` is used).
var<ray_payload> shadow: HitInfo;
var<incoming_ray_payload> incoming: HitInfo;

const MISS_T: f32 = -1.0;
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
    var origin = params.camera.xyz;
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var color = vec3<f32>(0.0);
    // The product of the reflectivities so far; the path stops once it is
    // not above the cut-off.
    var throughput = 1.0;
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        traceRay(tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, params.ray.y, origin, dir), &hit);
        if hit.t < 0.0 {
            color += throughput * sky(dir);
            break;
        }
        // What this surface adds per unit of light, and the next ray (the
        // shadow ray starts where the reflection does), all before the
        // shadow trace: the state kept across it stays within 64 bytes.
        let n = select(-hit.normal, hit.normal, dot(hit.normal, dir) < 0.0);
        let base = throughput * (1.0 - hit.reflectivity) * hit.albedo;
        throughput *= hit.reflectivity;
        origin = offset_ray(origin + dir * hit.t, n);
        let ndl = dot(n, params.light.xyz);
        let headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if (params.flags & FLAG_LIGHT) != 0u {
            color += base * params.light.w;
            if ndl > 0.0 {
                let lit = base * ndl;
                shadow.t = 0.0;
                traceRay(tlas, RayDesc(SHADOW_FLAGS, 0xFFu, params.ray.x, params.ray.y, origin, params.light.xyz), &shadow);
                if shadow.t < 0.0 {
                    color += lit;
                }
            }
        } else {
            color += base * headlight;
        }
        if !(throughput > params.ray.z) {
            break;
        }
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
fn closest_hit(
    @builtin(instance_custom_data) first: u32,
    @builtin(primitive_index) prim: u32,
    @builtin(ray_t_current_max) t: f32,
) {
    let s = surfaces[first + prim];
    incoming.albedo = s.albedo_roughness.xyz;
    incoming.t = t;
    incoming.normal = s.normal_reflectivity.xyz;
    incoming.reflectivity = s.normal_reflectivity.w;
}
